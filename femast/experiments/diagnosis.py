"""The state of one diagnosis, shared by the stages of :func:`~femast.experiments.diagnose.diagnose`.

A :class:`Diagnosis` holds the experiment and data, the effects already in the model and the
candidates, the baseline fit and the noise model the fits are weighted and scored by, every refit
and where it came from, the ranking, the pairs, the held-out check and the verdict.  Its
:meth:`Diagnosis.refit` runs refits on the executor the user chose (:mod:`femast.experiments.refits`)
and :meth:`Diagnosis.score` scores a fit under the current noise model
(:func:`~femast.experiments.verdict.score`).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import OptimizeResult

from ..effects.base import applicable_effects, get_effect, resolve, split_form
from ..errors import ModelError
from .refits import _dispatch
from .verdict import score


def _reads_time(exp, name: str) -> bool:
    """True if the effect ``name`` acts on ``exp`` as a law in time (its implementation there needs it)."""
    impl = get_effect(name).implementation(exp)
    return impl is not None and "time" in impl.needs


def effect_names(names) -> list:
    """Effect names from a list or a comma-separated string."""
    if isinstance(names, str):
        return [e.strip() for e in names.split(",") if e.strip()]
    return list(names or ())


@dataclass
class Diagnosis:
    """What the stages of a diagnosis read and write (module docstring)."""

    exp: object
    data: object
    base_effects: list
    candidates: list
    sigma: dict | None = None  # the user's sensor uncertainties
    workers: int | None = None
    scheduler: object = None
    pool: object = None  # refit workers started with the diagnosis (femast.experiments.refits.refit_pool)
    untimed: list = field(default_factory=list)  # effects in time not tried: the data record no time
    screen: bool = True  # screen the candidates of an expensive model (femast.experiments.screening)
    # the baseline stage
    baseline: OptimizeResult | None = None
    models: dict = field(default_factory=dict)  # {channel: ChannelNoise}, the noise model of the moment
    t_base: float = 0.0
    payload: dict = field(default_factory=dict)  # what every refit needs (a worker rebuilds the experiment)
    # the candidates stage: (stage, effect, spec, effects, start) and its fit, in the same order
    jobs: list = field(default_factory=list)
    fits_list: list = field(default_factory=list)
    how: str = ""
    # the pairs stage: (x, y, fit)
    pair_fits: list = field(default_factory=list)
    # scored: the ranking (best first), the best fit of each candidate, the form check, the pairs
    ranking: list = field(default_factory=list)
    fits: dict = field(default_factory=dict)
    form_check: list = field(default_factory=list)
    pairs: list = field(default_factory=list)
    s0: dict = field(default_factory=dict)  # the baseline's score
    thr: float = 1.2  # at-noise threshold
    n_eff: float = 0.0
    analysis: dict = field(default_factory=dict)  # the baseline's segments (femast.experiments.compare.analyse)
    heldout_ratio: float | None = None
    verdict: dict = field(default_factory=dict)

    @classmethod
    def of(cls, exp, data, candidates, exclude, base_effects, **kw) -> Diagnosis:
        """A diagnosis of ``exp`` on ``data``: the effects already in the model checked, the candidates
        (every applicable effect not in it, or those given, less ``exclude``).  On an experiment
        recorded step by step along its protocol (``Experiment.row_clock`` False: a connection test)
        an effect that acts as a law in time (a stiffness lost over the test) is by default a
        candidate only on data that record the time (a ``t_s`` column): there the row number follows
        the load path, not the clock, and a law in it is a law of the stroke (``untimed`` lists those
        left out); named in ``candidates`` it runs on the row index."""
        base = [n for n, _ in resolve(exp, effect_names(base_effects))]
        in_model = {split_form(n)[0] for n in base}
        untimed = []
        if candidates is None:
            cands = [e.name for e in applicable_effects(exp) if e.name not in in_model]
            if not data.has_time and not exp.row_clock:  # the row number follows the load path, not the clock
                untimed = [c for c in cands if _reads_time(exp, c)]
                cands = [c for c in cands if c not in untimed]
        else:
            cands = [split_form(n)[0] for n, _ in resolve(exp, effect_names(candidates))]
            dup = set(cands) & in_model
            if dup:
                raise ModelError(f"candidate effect(s) {', '.join(sorted(dup))} are already in the model")
        excluded = {split_form(n)[0] for n, _ in resolve(exp, effect_names(exclude))}
        return cls(exp, data, base, [c for c in cands if c not in excluded], untimed=untimed, **kw)

    @property
    def channels(self) -> tuple:
        return tuple(self.exp.channels)

    @property
    def start(self) -> dict:
        """The baseline's fitted values, where every refit starts."""
        return dict(zip(self.baseline.names, self.baseline.x))

    @property
    def weights(self) -> dict:
        """``{channel: (n,) noise}`` of the current noise model."""
        return {c: self.models[c].sigma for c in self.channels}

    def score(self, fit) -> dict:
        """``{ratio, rss, ic, z}`` of a fit under the current noise model."""
        return score(fit, self.models, self.channels, self.data.n)

    def refit(self, specs, while_waiting=None) -> list:
        """Fits of ``specs`` (``[(effects, start)]`` or payload updates ``[dict]``) on the executor;
        a fit that fails comes back with ``failed = True``."""
        payloads = [
            {**self.payload, **s} if isinstance(s, dict) else {**self.payload, "effects": s[0], "start": s[1]}
            for s in specs
        ]
        fits, how = _dispatch(
            self.exp,
            self.data,
            payloads,
            self.start,
            self.payload["noise"],
            self.workers,
            self.scheduler,
            self.t_base,
            while_waiting=while_waiting,
            pool=self.pool,
        )
        self.how = self.how or how
        return list(fits)

    @property
    def noise_rms(self) -> float:
        """RMS of the noise in the error unit."""
        w = self.weights
        return float(np.sqrt(np.mean([np.mean((self.exp.weight(c) * w[c]) ** 2) for c in self.channels])))
