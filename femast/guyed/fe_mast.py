"""The Rocaspect mast in the FE core, checked against the analytic complete-mast model (the Rocaspect paper).

Model (SI units)
----------------
* The 3.651 m square tube (:func:`femast.guyed.cantilever.mast_section`, Bredt torsion constant) as
  ``n_beam`` corotational beam elements from the base O_i (clamped: all six DOFs fixed, as the
  cantilever of Eqs. 8-15 and the complete model of Eqs. 16-26 assume) to the top C_i3.
* Three Dyneema shrouds (:class:`femast.elements.shroud_cable.ShroudCableFamily`, the Eq. 25 law)
  from their upper attachment points C_ir to the ground anchors D_ir of
  :func:`femast.guyed.rocaspect.rocaspect_shrouds` (anchors fixed).
  - ``attach="top"`` (default, the analytic convention of Fig. 3): the points C_ir are rigid offsets
    ``e_r = C_ir - C_i3`` of the top node, so the top is the rigid body the paper's model assumes.
  - ``attach="wall"``: shrouds 1 and 2 are tied to a beam node 0.25 m below the top through a 0.05 m
    rigid offset to the tube wall (the physical mast); the top segment of the tube is then flexible.
* Sources of error: ``length_error`` (m, per shroud) cuts the shrouds that much longer
  than the pretension asks (lack of fit; negative: shorter, tighter); ``temperature_change_K`` heats
  the shrouds and the tube by dT in a step ``"thermal"`` after the pretension, with the expansion
  coefficients ``shroud_alpha_per_K`` and ``beam_alpha_per_K`` (1/K; the paper gives none: Dyneema
  is about -12e-6 /K along the fibre, aluminium +23e-6 /K).
* Pretension: the shroud tensions *at the pretensioned equilibrium* equal ``pretension`` (the paper
  measures them there).  :meth:`MastFE.equilibrate` adjusts the unstretched lengths until they do
  (the beam shortens and bends under the shroud loads, which relaxes the shrouds by a few percent).

Stiffness decomposition at a converged state (:meth:`MastFE.stiffness_parts`)
------------------------------------------------------------------------------
The shrouds act only on the top node (their anchors are fixed), so the top stiffness obtained by
condensing the FE tangent to the six top DOFs (:meth:`femast.analysis.Analysis.condensed_stiffness`)
is ``K_FE = K_beam,stressed + K_shroud`` exactly, and the shroud family's tangent can be switched
part by part (``tangent_parts``) at the same configuration:

* ``K_beam,stressed``: shroud tangent off -- the beam alone, with its axial compression and bending;
* ``K_p,FE``: material part only (``(d tau / d l) B B^T``), the FE counterpart of Eq. 24;
* ``K_a,FE``: geometric part only (the ropes and their arms turning at constant tension), Eq. 26;
* ``K_geo = K_beam,stressed - K_beam,unstressed``: the beam's own geometric stiffness from its
  axial compression (and the small bending from the unbalanced shroud wrench) that the paper omits.

The analytic terms are evaluated with the same conventions: top and attachment points at the FE
equilibrium (deformed) positions, tensions from the FE, spins about C_i3, tangent rope stiffness.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .._moved import RenamedKeys
from ..analysis import Analysis
from ..analysis.convergence import Convergence
from ..elements.shroud_cable import ShroudCableFamily, unstretched_length
from ..elements.shroud_law import DyneemaLaw
from ..errors import ModelError
from ..model import Model
from .cantilever import cantilever_stiffness, mast_section
from .complete_mast import ShroudSet, active_stiffness, passive_stiffness
from .rocaspect import E_NO_SHROUD, L_BEAM, SHROUD_DROP, mast_bases, mast_tops, rocaspect_shrouds

SHROUD_FAMILY = "shroud"
BEAM_FAMILY = "mast_beam"
TIGHT = Convergence(force_tol=1e-9, disp_tol=1e-9, max_iterations=40)
"""Newton tolerances used here: equilibrium to 1e-9 of the largest nodal force (round-off floor ~5e-11)."""


def rotation_scaling(L: float = L_BEAM) -> np.ndarray:
    """S = diag(1, 1, 1, 1/L, 1/L, 1/L): ``S K S`` puts every entry of a 6x6 top stiffness in N/m."""
    return np.diag([1.0, 1.0, 1.0, 1.0 / L, 1.0 / L, 1.0 / L])


def relative_difference(A, B, L: float = L_BEAM) -> float:
    """max |A - B| / max |B| after scaling rotations by L (all entries in N/m); inf if B is 0 and A is not."""
    S = rotation_scaling(L)
    d = np.abs(S @ (np.asarray(A) - np.asarray(B)) @ S).max()
    ref = np.abs(S @ np.asarray(B) @ S).max()
    return float(d / ref) if ref > 0 else (0.0 if d == 0 else np.inf)


@dataclass
class FEState:
    """A converged FE state of the mast (all SI, global axes).

    top : (3,) top C_i3, m.  R_top : (3, 3) its rotation.  upper : (q, 3) shroud upper end points, m.
    lower : (q, 3) anchors, m.  tension : (q,) N.  beam_N : (n_beam,) beam axial forces, N (tension +).
    """

    top: np.ndarray
    R_top: np.ndarray
    upper: np.ndarray
    lower: np.ndarray
    tension: np.ndarray
    beam_N: np.ndarray
    displacement: np.ndarray = field(default=None)


class MastFE:
    """FE model of mast ``mast`` (0-based) of the Rocaspect robot (module note).

    pretension : shroud tension at the pretensioned equilibrium, N (``None``: shrouds detached;
        ``0.0``: shrouds installed exactly taut at zero tension).
    E : Young's modulus of the beam, Pa (default the paper's no-shroud value, as the complete model).
    n_beam : number of beam elements (the beam's geometric stiffness converges as 1/n_beam^2).
    law : Dyneema law (default the paper's x_s).
    attach : "top" (shroud points rigidly on the top, the analytic convention) or "wall".
    length_error : lack of fit per shroud, m (scalar or 3 values; module note).
    temperature_change_K : uniform temperature change of shrouds and tube in a step ``"thermal"``
        after the pretension, K (0: no such step); ``shroud_alpha_per_K``, ``beam_alpha_per_K``:
        their coefficients of thermal expansion, 1/K.
    shroud_hysteresis : the shrouds' loading/unloading difference (Fig. 4a) as a law of the FE shroud
        (:mod:`femast.elements.shroud_hysteresis`): the loop half-width eta (-, 0 <= eta < 1; 0: the
        paper's single curve); ``shroud_stick_rigidity``: its stick rigidity, N (default 10 k0).
        The pretension is then reached on the loading branch.
    """

    def __init__(
        self,
        pretension: float | None = 1200.0,
        *,
        mast: int = 0,
        E: float = E_NO_SHROUD,
        n_beam: int = 16,
        law: DyneemaLaw | None = None,
        attach: str = "top",
        convergence: Convergence | None = None,
        length_error=None,
        temperature_change_K: float = 0.0,
        shroud_alpha_per_K: float = 0.0,
        beam_alpha_per_K: float = 0.0,
        shroud_hysteresis: float = 0.0,
        shroud_stick_rigidity: float | None = None,
    ):
        if pretension is not None and not (np.isfinite(pretension) and pretension >= 0.0):
            raise ModelError(f"shroud pretension {pretension!r} N must be finite and >= 0 (None: no shrouds)")
        if attach not in ("top", "wall"):
            raise ModelError(f"attach={attach!r}; use 'top' (rigid top, the analytic convention) or 'wall'")
        if int(n_beam) < 1:
            raise ModelError(f"n_beam = {n_beam!r}: need at least one beam element")
        self.pretension = pretension
        self.mast = int(mast)
        self.E = float(E)
        self.section = mast_section(self.E)
        self.n_beam = int(n_beam)
        self.law = law or DyneemaLaw()
        self.attach = attach
        self.convergence = convergence or TIGHT
        self.base_point = mast_bases()[self.mast]
        self.top_point = mast_tops()[self.mast]
        self.shrouds_nominal = None if pretension is None else rocaspect_shrouds(self.mast, pretension, self.law)
        if not (np.isfinite(shroud_hysteresis) and 0.0 <= shroud_hysteresis < 1.0):
            raise ModelError(f"MastFE shroud_hysteresis = {shroud_hysteresis!r} must be in [0, 1) (0: off)")
        self.shroud_hysteresis = float(shroud_hysteresis)
        self.shroud_stick_rigidity = shroud_stick_rigidity
        self.L0 = None
        if self.shrouds_nominal is not None:
            sh = self.shrouds_nominal
            length = np.linalg.norm(sh.lower - sh.upper, axis=1)
            # (on the loading branch the law's own tension is tension / (1 + eta))
            tau_law = sh.tension / (1.0 + self.shroud_hysteresis)
            self.L0 = np.asarray(unstretched_length(self.law, tau_law, length), dtype=float)
        if length_error is not None and self.shrouds_nominal is None:
            raise ModelError("length_error is given but the mast has no shrouds (pretension=None)")
        self.length_error = length_error
        for what, v in (
            ("temperature_change_K", temperature_change_K),
            ("shroud_alpha_per_K", shroud_alpha_per_K),
            ("beam_alpha_per_K", beam_alpha_per_K),
        ):
            if not np.isfinite(v):
                raise ModelError(f"MastFE {what} = {v!r} is not finite")
        self.temperature_change_K = float(temperature_change_K)
        self.alpha = {SHROUD_FAMILY: float(shroud_alpha_per_K), BEAM_FAMILY: float(beam_alpha_per_K)}
        self.analysis: Analysis | None = None
        self._frames = []  # per converged increment of the last solve: (step, top [u, spins], tensions)

    # ----------------------------------------------------------------- model
    def build(self, wrenches=(), step_names=None) -> Model:
        """The FE model: a pretension step (then ``"thermal"`` with a temperature change), then one step
        per top wrench ``[fx, fy, fz, mx, my, mz]`` (N, N m about the top; dead loads at the top node,
        reached linearly within the step)."""
        m = Model(f"Rocaspect mast {self.mast + 1}")
        base = m.node(*self.base_point)
        top_z = self.top_point[2]
        if self.shrouds_nominal is not None and self.attach == "wall":
            # beam node at the height of the lower shroud ties, elements kept near-uniform
            z_tie = top_z - SHROUD_DROP
            n_top = max(1, int(round(self.n_beam * SHROUD_DROP / L_BEAM)))
            tie = m.node(self.top_point[0], self.top_point[1], z_tie)
            top = m.node(*self.top_point)
            m.beam(base, tie, self.section, up=(0.0, 1.0, 0.0), n=max(1, self.n_beam - n_top), family=BEAM_FAMILY)
            m.beam(tie, top, self.section, up=(0.0, 1.0, 0.0), n=n_top, family=BEAM_FAMILY)
        else:
            top = m.node(*self.top_point)
            tie = top
            m.beam(base, top, self.section, up=(0.0, 1.0, 0.0), n=self.n_beam, family=BEAM_FAMILY)
        m.fix(base)
        self.base, self.top = base, top
        self.anchors = []
        if self.shrouds_nominal is not None:
            sh = self.shrouds_nominal
            pairs, offsets = [], []
            for r in range(sh.upper.shape[0]):
                d = m.node(*sh.lower[r])
                m.fix(d)
                self.anchors.append(d)
                at_top = self.attach == "top" or np.allclose(sh.upper[r], self.top_point)
                a = top if at_top else tie
                pairs.append((a, d))
                offsets.append([sh.upper[r] - m.xyz(a), np.zeros(3)])
            fam = ShroudCableFamily(
                np.array(pairs),
                self.L0,
                self.law,
                offsets=np.array(offsets),
                name=SHROUD_FAMILY,
                length_error=self.length_error,
                hysteresis=self.shroud_hysteresis,
                stick_rigidity=self.shroud_stick_rigidity,
            )
            m.add_family(fam)
        m.step("pretension")
        if self.temperature_change_K != 0.0:
            heated = [f for f, a in self.alpha.items() if a != 0.0 and (f == BEAM_FAMILY or self.anchors)]
            for f in heated:
                m.thermal_expansion(self.alpha[f], family=f)
            st = m.step("thermal")
            if heated:
                st.temperature(self.temperature_change_K, family=heated)
        names = step_names or [f"load{k + 1:04d}" for k in range(len(wrenches))]
        for name, w in zip(names, np.asarray(wrenches, dtype=float).reshape(-1, 6)):
            m.step(name).load(top, **dict(zip(("fx", "fy", "fz", "mx", "my", "mz"), w)))
        return m

    def solve(self, wrenches=(), out=None) -> Analysis:
        """Run the pretension step (and the load steps); keeps and returns the :class:`Analysis`.
        out : a results folder, or None (default) to write no files (the top's motion and the shroud
        tensions of every converged increment are kept in memory for :meth:`run_wrenches`)."""
        model = self.build(wrenches)
        row = model.index(self.top)
        key = f"el/{SHROUD_FAMILY}/tension"
        self._frames = []

        def record(fr):
            self._frames.append(
                (
                    str(fr["step"]),
                    np.concatenate([fr["U"][row], fr["URA"][row]]),
                    np.asarray(fr.get(key, np.zeros(0)), dtype=float),
                )
            )

        an = Analysis(model, out, convergence=self.convergence, progress=False, on_frame=record)
        an.run()
        self.analysis = an
        return an

    def equilibrate(self, tol: float = 1e-9, max_iter: int = 30) -> Analysis:
        """Solve the pretension step with unstretched lengths adjusted so that every shroud carries
        ``pretension`` (relative ``tol``) at the equilibrium (after the ``"thermal"`` step if there is
        one).  With length errors the nominal lengths are tuned so that the erroneous ropes carry the
        target: tensioning to a measured force in the field removes the lack of fit.

        Newton on L0 with the exact sensitivity of the equilibrium tensions (the shrouds load only
        the top, so with K the condensed top stiffness, B_r the top part of shroud r's B vector,
        k_r = EA_t / L0 and c_r = d tau / d L0 at fixed length = -EA_t l / L0^2):
        ``d tau / d L0 = diag(c) - diag(k) B^T K^-1 B diag(c)``.  (The plain fixed point
        ``L0 <- l_eq / (1 + eps(target))`` contracts only by ~0.6 per iteration here.)"""
        from ..elements.shroud_law import axial_rigidity_tangent

        if self.shrouds_nominal is None or self.pretension == 0.0:
            return self.solve()
        target = self.shrouds_nominal.tension
        for _ in range(max_iter):
            an = self.solve()
            st = self.state()
            err = np.abs(st.tension - target).max() / target.max()
            if err <= tol:
                return an
            d = st.lower - st.upper
            length = np.linalg.norm(d, axis=1)
            e = d / length[:, None]
            B = -np.vstack([e.T, np.cross(st.upper - st.top, e).T])  # (6, q): dl_r = B_r . du_top
            eta = self.shroud_hysteresis  # on the loading branch: (1 + eta) of the law's slope
            EAt = (1.0 + eta) * axial_rigidity_tangent(self.law, st.tension / (1.0 + eta))
            fam = self._family(SHROUD_FAMILY)
            Lf = fam.stress_free_lengths()  # (L0 + dL) s: with length errors and heat
            s = Lf / (self.L0 + fam.length_error)
            k = EAt / Lf
            c = -EAt * length / Lf**2 * s
            K = self.top_stiffness("full")
            J = np.diag(c) - (k[:, None] * (B.T @ np.linalg.solve(K, B))) * c[None, :]
            self.L0 = self.L0 - np.linalg.solve(J, st.tension - target)
        raise ModelError(
            f"shroud pretension did not settle to {tol:g} in {max_iter} iterations "
            f"(tensions {st.tension} N, target {target} N)"
        )

    def run_wrenches(self, wrenches) -> dict:
        """Nonlinear response to a sequence of top wrenches (k, 6) (N, N m about the top, dead loads),
        applied one step each after the pretension (and thermal) step (keep :meth:`equilibrate`'s unstretched lengths:
        call it first).  Returns a dict with, at the end of the pretension (or thermal) step (``"u0"``) and of each
        load step (``"u"``, (k, 6)): the top displacement [ux, uy, uz] (m) and accumulated spins (rad)
        from the initial geometry, and the shroud tensions ``"tension0"``, ``"tension"`` (k, q) in N."""
        wrenches = np.asarray(wrenches, dtype=float).reshape(-1, 6)
        # a step that repeats the previous load is skipped (its state is the previous one): the core's
        # displacement-correction test cannot pass when the increment is pure round-off
        scale = max(float(np.abs(wrenches).max(initial=0.0)), 1.0)
        prev = np.zeros(6)
        step_of = np.empty(len(wrenches), dtype=int)
        unique = []
        for k, w in enumerate(wrenches):
            if unique and np.abs(w - prev).max() <= 1e-12 * scale or not unique and not np.any(w):
                step_of[k] = len(unique) - 1
                continue
            unique.append(w)
            prev = w
            step_of[k] = len(unique) - 1
        self.solve(np.array(unique).reshape(-1, 6))
        last = {fr[0]: i for i, fr in enumerate(self._frames)}

        def pick(i):
            return self._frames[i][1], self._frames[i][2]

        u0, t0 = pick(last.get("thermal", last["pretension"]))
        picked = [pick(last[f"load{k + 1:04d}"]) for k in range(len(unique))]
        picked.insert(0, (u0, t0))  # step_of = -1: no load yet
        sel = [picked[j + 1] for j in step_of]
        return {
            "u0": u0,
            "tension0": t0,
            "u": np.array([p[0] for p in sel]).reshape(-1, 6),
            "tension": np.array([p[1] for p in sel]).reshape(len(wrenches), -1),
        }

    # ----------------------------------------------------------------- state
    def _family(self, name):
        for f in self.analysis.families:
            if f.name == name:
                return f
        return None

    def state(self) -> FEState:
        """The current (last converged) state of :attr:`analysis`."""
        an = self.analysis
        if an is None:
            raise ModelError("solve the model first (MastFE.solve or MastFE.equilibrate)")
        it = an.model.index(self.top)
        beam = self._family(BEAM_FAMILY)
        sf = beam.evaluate(an.x, an.R, None).output["section_forces"][:, 0, 0]
        sh = self._family(SHROUD_FAMILY)
        if sh is not None:
            p = sh.end_points(an.x, an.R)
            committed = an.state.families[an.families.index(sh)]  # (the loading/unloading option's state)
            tau = sh.evaluate(an.x, an.R, committed).output["tension"]
            upper, lower = p[:, 0], p[:, 1]
        else:
            upper = lower = np.zeros((0, 3))
            tau = np.zeros(0)
        disp = np.concatenate([an.x[it] - an.X0[it], an.spin[it]])
        return FEState(an.x[it].copy(), an.R[it].copy(), upper, lower, tau, sf, disp)

    def top_stiffness(self, parts: str = "full") -> np.ndarray:
        """Top stiffness (6, 6) (N/m, N, N m/rad; spins about the top) of the current state, with
        the shroud tangent restricted to ``parts`` ("full", "material", "geometric", "none")."""
        sh = self._family(SHROUD_FAMILY)
        if sh is None:
            if parts not in ("full", "none"):
                raise ModelError(f"this mast has no shrouds: tangent part {parts!r} is undefined")
            return self.analysis.condensed_stiffness(self.top)
        old = sh.tangent_parts
        try:
            sh.tangent_parts = parts
            return self.analysis.condensed_stiffness(self.top)
        finally:
            sh.tangent_parts = old

    def analytic_shrouds(self, tension=None) -> ShroudSet:
        """The analytic ShroudSet at the FE state: deformed attachment points, FE (or given) tensions."""
        st = self.state()
        return ShroudSet(st.upper, st.lower, st.tension if tension is None else tension, law=self.law)

    def stiffness_parts(self) -> dict:
        """FE stiffness terms at the current state (module note), each (6, 6)."""
        out = {"K_FE": self.top_stiffness("full"), "K_beam_stressed": self.top_stiffness("none")}
        if self._family(SHROUD_FAMILY) is not None:
            out["K_p_FE"] = self.top_stiffness("material") - out["K_beam_stressed"]
            out["K_a_FE"] = self.top_stiffness("geometric") - out["K_beam_stressed"]
        return out


def beam_column_tip_stiffness(L: float, EI: float, P: float) -> np.ndarray:
    """Exact tip stiffness (2, 2) of a clamped Euler-Bernoulli column of length L (m), bending
    stiffness EI (N m^2), under an axial *compression* P (N, fixed direction), for the tip lateral
    displacement w and slope w' versus the lateral force H and moment M (EI w'' = M at the tip).

    From ``w'' + k^2 w = (H (L - x) + M + P w_L) / EI``, ``k^2 = P / EI``:
    ``w_L = (H (tan u / k - L) + M (1 / cos u - 1)) / P`` and
    ``w'_L = ((H L + M + P w_L) k sin u + H (cos u - 1)) / P`` with u = k L; P -> 0 gives the cantilever
    ``EI / L^3 [[12, -6 L], [-6 L, 4 L^2]]`` and the leading geometric term ``-P / (30 L) [[36, -3 L], [-3 L, 4 L^2]]``.
    """
    if P <= 0:
        raise ModelError(f"beam_column_tip_stiffness: P = {P!r} N must be a positive compression")
    k = np.sqrt(P / EI)
    u = k * L
    C = np.empty((2, 2))
    for j, (H, M) in enumerate(((1.0, 0.0), (0.0, 1.0))):
        wL = (H * (np.tan(u) / k - L) + M * (1.0 / np.cos(u) - 1.0)) / P
        C[0, j] = wL
        C[1, j] = ((H * L + M + P * wL) * k * np.sin(u) + H * np.cos(u) - H) / P
    return np.linalg.inv(C)


def beam_column_geometric_stiffness(L: float, EI: float, P: float) -> np.ndarray:
    """Geometric part (6, 6) of the top stiffness of a vertical clamped column under compression P (N):
    the exact beam-column tip stiffness minus the P = 0 cantilever, in the base frame (ux, uy, uz,
    rx, ry, rz).  Only the bending blocks: (ux, ry) and (uy, rx), where w = uy has slope -rx."""
    K0 = EI / L**3 * np.array([[12.0, -6.0 * L], [-6.0 * L, 4.0 * L**2]])
    dK = beam_column_tip_stiffness(L, EI, P) - K0
    out = np.zeros((6, 6))
    for (t, r), s in (((0, 4), 1.0), ((1, 3), -1.0)):
        T = np.diag([1.0, s])
        blk = T @ dK @ T
        out[np.ix_([t, r], [t, r])] = blk
    return out


def analytic_beam_stiffness(E: float = E_NO_SHROUD) -> np.ndarray:
    """Cantilever stiffness K_beam = C_b^-1 (Eqs. 8-18) of the mast tube, vertical (Eq. 13)."""
    return cantilever_stiffness(L_BEAM, mast_section(E))


def compare_stiffness(
    pretension: float = 1200.0,
    *,
    E: float = E_NO_SHROUD,
    n_beam: int = 16,
    law: DyneemaLaw | None = None,
    attach: str = "top",
) -> dict:
    """Term-by-term comparison of the FE top stiffness with the analytic K_m = K_beam + K_a + K_p.

    Returns a dict of (6, 6) matrices and scalar relative differences (:func:`relative_difference`):

    * ``K_beam`` (analytic) and ``K_beam_FE`` (FE, no shrouds): ``rel_beam``;
    * ``K_p0`` (analytic, tau = 0, nominal geometry) and ``K_p0_FE`` (FE shrouds taut at 0 N minus
      the bare beam): ``rel_passive0``;
    * at the pretensioned equilibrium: ``K_p`` / ``K_p_FE`` (``rel_passive``), ``K_a`` / ``K_a_FE``
      (``rel_active``), the shroud sum (``rel_shroud``), ``K_geo`` (the beam's own geometric
      stiffness), ``K_m`` (analytic at the FE state), ``K_FE``, ``K_m_nominal`` (analytic at the
      nominal geometry and tension, corrected Eq. 26) and ``K_a_printed`` (printed Eq. 26 at the FE state; ``K_a_seed``, its old
      name, warns and is removed in femast 0.3);
    * ``state``: the FE state, ``beam_N``: the mean axial force in the beam, N.
    """
    law = law or DyneemaLaw()
    bare = MastFE(None, E=E, n_beam=n_beam, law=law)
    bare.solve()
    K_beam_FE = bare.top_stiffness()
    K_beam = analytic_beam_stiffness(E)
    res = {"K_beam": K_beam, "K_beam_FE": K_beam_FE, "rel_beam": relative_difference(K_beam_FE, K_beam)}

    taut = MastFE(0.0, E=E, n_beam=n_beam, law=law, attach=attach)
    taut.solve()
    res["K_p0_FE"] = taut.top_stiffness() - K_beam_FE
    res["K_p0"] = passive_stiffness(taut.top_point, taut.shrouds_nominal)
    res["rel_passive0"] = relative_difference(res["K_p0_FE"], res["K_p0"])

    fe = MastFE(pretension, E=E, n_beam=n_beam, law=law, attach=attach)
    fe.equilibrate()
    parts = fe.stiffness_parts()
    st = fe.state()
    sh = fe.analytic_shrouds()
    res.update(parts)
    res["state"] = st
    res["beam_N"] = float(np.mean(st.beam_N))
    res["K_p"] = passive_stiffness(st.top, sh)
    res["K_a"] = active_stiffness(st.top, sh)
    res["K_a_printed"] = active_stiffness(st.top, sh, form="printed")
    res["K_geo"] = parts["K_beam_stressed"] - K_beam_FE
    res["K_m"] = K_beam + res["K_a"] + res["K_p"]
    nominal = rocaspect_shrouds(fe.mast, pretension, law)
    res["K_m_nominal"] = K_beam + active_stiffness(fe.top_point, nominal) + passive_stiffness(fe.top_point, nominal)
    res["rel_passive"] = relative_difference(res["K_p_FE"], res["K_p"])
    res["rel_active"] = relative_difference(res["K_a_FE"], res["K_a"])
    res["rel_shroud"] = relative_difference(parts["K_FE"] - parts["K_beam_stressed"], res["K_a"] + res["K_p"])
    res["fe"] = fe
    return RenamedKeys(res, {"K_a_seed": "K_a_printed"}, "compare_stiffness(...)")
