"""Sample points of a study: Monte Carlo, Latin hypercube or Sobol' points of the unit cube
(scipy.stats.qmc), a Gaussian copula for correlated inputs, and Saltelli's layout of the runs
when sensitivity indices are wanted.

Every run has an index r.  Without sensitivity, run r is base sample r.  With sensitivity
(k inputs, a per-member input counting as one group) each base sample i draws a point of twice
the dimension, split into rows A_i and B_i, and makes k + 2 runs: A_i, B_i and A_i with the
columns of input g taken from B_i (AB_i^g), run r = i (k + 2) + j (Saltelli 2002, Saltelli et al.
2010).  The points of a run depend only on (sampler, seed, r) -- and on N for the Latin
hypercube -- so a study can stop, resume or be extended (Monte Carlo, Sobol') with more
samples, and the points of a chunk of runs are made without the others.

Correlations (a Gaussian copula): the unit numbers of correlated scalar inputs are mapped to
standard normals z = Phi^-1(u), correlated by the Cholesky factor of the given correlation
matrix (z' = L z) and mapped back (u' = Phi(z')), then through each input's own ppf: each input
keeps its marginal distribution and the normal scores have the given correlation.  Latin
hypercube strata and Sobol' balance hold for the uncorrelated inputs only.  Sobol' indices need
independent inputs, so a study with correlations cannot ask for them.
"""

from __future__ import annotations

import warnings

import numpy as np
from scipy import special

from ..errors import StudyError

SAMPLERS = ("sobol", "lhs", "mc")
MC_BLOCK = 1024  # base samples per Monte Carlo random stream (the points do not depend on N)


class Design:
    """Where each run of a study samples its inputs.

    inputs : the :class:`~femast.studies.distributions.Input` list.
    sampler : 'sobol' (scrambled Sobol' sequence; N a power of 2 keeps its balance), 'lhs' (Latin
        hypercube of the N base samples) or 'mc' (plain Monte Carlo).
    seed : the random seed (scrambling, permutations, Monte Carlo streams).
    sensitivity : lay the runs out for first-order and total Sobol' indices (k + 2 runs per base
        sample, k = number of inputs).
    correlation : {(name_a, name_b): rho} between scalar inputs (a Gaussian copula), or None.
    """

    def __init__(
        self, inputs, sampler: str = "sobol", seed: int = 1, sensitivity: bool = False, correlation: dict | None = None
    ):
        self.inputs = list(inputs)
        if sampler not in SAMPLERS:
            raise StudyError(f"sampler {sampler!r} is unknown; use one of {', '.join(SAMPLERS)}")
        self.sampler = sampler
        if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
            raise StudyError(f"seed = {seed!r} must be a whole number >= 0")
        self.seed = int(seed)
        self.sensitivity = bool(sensitivity)
        self.slices = {}
        c = 0
        for x in self.inputs:
            self.slices[x.name] = slice(c, c + x.dims)
            c += x.dims
        self.dims = c
        self.correlation = dict(correlation or {})
        self._copula = self._cholesky()
        if self._copula is not None and self.sensitivity:
            raise StudyError(
                "Sobol' sensitivity indices assume independent inputs; drop correlation= or "
                "sensitivity=True (the indices of correlated inputs are not defined this way)"
            )
        self._lhs = None
        self._sobol = None

    # ------------------------------------------------------------ layout
    @property
    def runs_per_sample(self) -> int:
        """Runs per base sample: 1, or k + 2 with sensitivity."""
        return len(self.inputs) + 2 if self.sensitivity else 1

    def block_names(self) -> list:
        """Name of block j of a base sample: 'A', 'B', then 'AB:<input>' per input (sensitivity)."""
        if not self.sensitivity:
            return ["A"]
        return ["A", "B"] + [f"AB:{x.name}" for x in self.inputs]

    def spec(self) -> dict:
        """Plain description for the study manifest."""
        return {
            "sampler": self.sampler,
            "seed": self.seed,
            "sensitivity": self.sensitivity,
            "correlation": sorted([list(k) + [float(v)] for k, v in self.correlation.items()]),
            "inputs": [x.spec() for x in self.inputs],
        }

    # ------------------------------------------------------------ copula
    def _cholesky(self):
        if not self.correlation:
            return None
        names = {x.name: x for x in self.inputs}
        order = []
        for key, rho in self.correlation.items():
            if not (isinstance(key, tuple) and len(key) == 2):
                raise StudyError(f"correlation key {key!r} must be a pair of input names, e.g. ('a', 'b')")
            for n in key:
                if n not in names:
                    raise StudyError(
                        f"correlation {key}: '{n}' is not an input of the study (inputs: {', '.join(names)})"
                    )
                if names[n].size is not None:
                    raise StudyError(
                        f"correlation {key}: '{n}' is a per-member input (size {names[n].size}); "
                        "correlations are between scalar inputs"
                    )
                if n not in order:
                    order.append(n)
            if key[0] == key[1]:
                raise StudyError(f"correlation {key}: an input is fully correlated with itself; pair two inputs")
            try:
                r = float(rho)
            except (TypeError, ValueError):
                raise StudyError(f"correlation {key} = {rho!r} is not a number") from None
            if not -1.0 < r < 1.0:
                raise StudyError(f"correlation {key} = {rho!r} must lie strictly between -1 and 1")
        C = np.eye(len(order))
        for (a, b), rho in self.correlation.items():
            i, j = order.index(a), order.index(b)
            C[i, j] = C[j, i] = float(rho)
        try:
            L = np.linalg.cholesky(C)
        except np.linalg.LinAlgError:
            raise StudyError(
                f"the correlations {self.correlation} are not a valid correlation matrix (not positive "
                "definite); lower the coefficients so that they are consistent"
            ) from None
        cols = [self.slices[n].start for n in order]
        return cols, L

    def _correlate(self, u):
        if self._copula is None:
            return u
        cols, L = self._copula
        z = special.ndtri(np.clip(u[:, cols], 1e-12, 1 - 1e-12))
        u = u.copy()
        u[:, cols] = special.ndtr(z @ L.T)
        return u

    # ------------------------------------------------------------ points
    def base_points(self, start: int, stop: int, n_total: int) -> np.ndarray:
        """Unit-cube points of base samples start..stop-1 ((stop - start, dims or 2 dims))."""
        d = self.dims * (2 if self.sensitivity else 1)
        if self.sampler == "mc":
            out = []
            for b in range(start // MC_BLOCK, (stop - 1) // MC_BLOCK + 1):
                pts = np.random.default_rng([self.seed, b]).random((MC_BLOCK, d))
                lo, hi = max(start - b * MC_BLOCK, 0), min(stop - b * MC_BLOCK, MC_BLOCK)
                out.append(pts[lo:hi])
            return np.concatenate(out) if out else np.zeros((0, d))
        if self.sampler == "sobol":
            from scipy.stats import qmc  # (here: 0.45 s to import)

            eng = qmc.Sobol(d, scramble=True, seed=self.seed)
            if start:
                eng.fast_forward(start)
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", UserWarning)  # balance warning: documented, N may be any
                return eng.random(stop - start)
        # Latin hypercube: the N x d design is made once (it depends on N)
        if self._lhs is None or len(self._lhs) != n_total:
            from scipy.stats import qmc

            self._lhs = qmc.LatinHypercube(d, seed=self.seed).random(n_total)
        return self._lhs[start:stop]

    def points(self, runs, n_total: int):
        """For run indices ``runs`` (ascending): (base, block, u) with u the (len(runs), dims) unit
        numbers of each run (copula applied)."""
        runs = np.asarray(runs, dtype=np.int64)
        m = self.runs_per_sample
        base, block = runs // m, runs % m
        if len(runs) == 0:
            return base, block, np.zeros((0, self.dims))
        lo, hi = int(base.min()), int(base.max()) + 1
        P = self.base_points(lo, hi, n_total)[base - lo]
        d = self.dims
        if not self.sensitivity:
            return base, block, self._correlate(P)
        A, B = P[:, :d], P[:, d:]
        u = A.copy()
        u[block == 1] = B[block == 1]
        for g, x in enumerate(self.inputs):
            sel = block == 2 + g
            sl = self.slices[x.name]
            u[sel, sl] = B[sel, sl]
        return base, block, u

    def values(self, u) -> dict:
        """Input values for unit numbers ``u`` ((n, dims)): {name: (n,) or (n, size)}."""
        return {x.name: x.value(u[:, self.slices[x.name]]) for x in self.inputs}
