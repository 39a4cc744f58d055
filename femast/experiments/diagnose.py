"""``diagnose``: which physical effect is the model most likely missing?

The baseline (the experiment's model, plus any effects already switched on) is fitted and the
noise floor of every channel is estimated from its residual.  Then the model is refitted once
per candidate effect -- every applicable effect not yet in the model -- with the same noise
weights.  The refits are independent and run in parallel (:mod:`femast.experiments.refits`): local
processes by default (:class:`concurrent.futures.ProcessPoolExecutor`), a dask.distributed cluster
when a scheduler address (or a ``distributed.Client``) is given.  With the default number of workers a
diagnosis whose refits are estimated to take under a second in all runs in the calling process:
starting worker processes would cost more than it saves (the FE experiments are the ones that
need the workers).

Ranking and verdict
-------------------
Candidates are ranked by ``delta_bic = BIC(candidate) - BIC(baseline)`` (see
:func:`~femast.experiments.fitting.bic`), which rewards explained error and penalises each added
parameter by ``ln n``.  A candidate is *significant* when ``delta_bic < -10`` ("very strong"
evidence on the Kass-Raftery scale; for one added parameter and n = 1500 residuals this needs a
chi-square drop of 17, i.e. p < 4e-5 under the null), also without the 2 % of rows that gain most,
and it explains at least 10 % of the excess error (:mod:`femast.experiments.verdict`).  A model
is *at the noise floor* when its RMS error is at most ``AT_NOISE = 1.2`` times the noise: the white-noise estimate scatters by a
few % for a few hundred samples, and 1.2 leaves room for that; a structured error whose RMS is
0.66 of the noise lifts the total to 1.2x, so structure smaller than that is not claimed.  For
short data sets the estimate scatters more (the FE experiments have 40-80 rows: +-15-20 %), and
the threshold is raised to the 95th percentile of what a perfect model gives on pure noise of that
size (:func:`~femast.experiments.residuals.at_noise_threshold`: 1.38 for 45 rows of one channel;
1.2 from about 120 rows, or fewer with several channels); it is ``at_noise`` in the result and
the JSON report (with serially correlated noise it is computed for the effective sample size).

A candidate is kept only if it also lowers the error on data its fit has not seen, and a pair only
if it beats its best member there too (:mod:`femast.experiments.heldout`).

The noise model of every channel (given, repeatability, or from the residual: white,
heteroscedastic, AR(1), checked against repeated passes) is :mod:`femast.experiments.noise`, the
same as ``compare``'s; the significance rule and the verdict kinds
(``missing_effect``, ``missing_pair``, ``form_imperfect``, ``better_form``, ``nothing_missing``,
``not_explained``) are :mod:`femast.experiments.verdict`.
"""

from __future__ import annotations

import time
from contextlib import nullcontext

from scipy.optimize import OptimizeResult

from .. import progress
from ..effects.base import get_effect
from ..effects.scripts import loaded_scripts
from .baseline import fit_with_noise
from .candidates import fit_candidates, rank, remaining_where
from .compare import analyse
from .core import Experiment, Measured
from .diagnose_report import diagnosis_result, format_diagnose  # noqa: F401  (format_diagnose: re-exported)
from .diagnosis import Diagnosis
from .heldout import heldout_check
from .noise import noise_model, pinned_rows
from .pairs import fit_pairs, score_pairs

# the refits' executor (re-exported: diagnose.REFIT_NFEV, ... keep working)
from .refits import (  # noqa: F401
    REFIT_NFEV,
    SERIAL_BELOW_S,
    _dispatch,
    _refit_task,
    _run_tasks,
    _safe_fit,
    _serial_refits,
    refit_pool,
)
from .residuals import AT_NOISE, at_noise_threshold, load_path  # noqa: F401  (AT_NOISE: re-exported)
from .rows import thin
from .screening import refit_unscreened
from .time_dependence import creep_overrules, reads_time, time_check
from .units import check_data as check_units
from .verdict import SIGNIFICANT_DBIC, conclude  # noqa: F401  (SIGNIFICANT_DBIC: re-exported)


def diagnose(
    exp: Experiment,
    data: Measured,
    candidates=None,
    *,
    exclude=(),
    base_effects=(),
    sigma=None,
    workers=None,
    scheduler=None,
    out=None,
    pairs: bool = True,
    heldout: bool = True,
    max_rows: int | None = None,
    screen: bool = True,
) -> OptimizeResult:
    """Refit the model with each candidate effect (every form), pairs of the best, and conclude.

    candidates : effect names to try (default: every effect applicable to the experiment and not in
        ``base_effects``); each is fitted in each of its forms (``effect/form``), the information
        criterion picks the form.  exclude : effect names not to try (e.g. one whose refit is known
        to fail, or a mechanism the rig cannot have).
    sigma : ``{channel: level}`` the sensor uncertainty of channels (their units; ``sigma_`` columns
        give it per row): the noise model's first source (:mod:`femast.experiments.noise`).
    base_effects : effects already in the model being diagnosed (names or ``effect/form``); their
        other forms are refitted first (a shape mismatch).
    workers : where the refits run: None (default) in this process; N on N worker processes
        (:mod:`femast.workers`; a script run as ``python script.py`` keeps its work under ``if
        __name__ == "__main__":``); ``"auto"`` (the default of ``femast diagnose``) one per CPU, or
        this process when the refits are estimated -- six times the baseline fit time each -- to
        take less than ``SERIAL_BELOW_S`` = 1 s in all (never for the FE experiments).
    scheduler : a dask.distributed scheduler address (``tcp://...``) or ``distributed.Client``.
    out : folder for ``diagnose.json``, ``diagnose.png`` and ``diagnose_report.html`` (self-contained,
        figures inlined; nothing written if None).
    pairs : refit pairs of the top candidates jointly (their verdict: femast.experiments.verdict).
    heldout : check the baseline, every significant candidate and the best pairs on held-out data
        (:mod:`femast.experiments.heldout`: leave-one-group-out, else leave-one-block-of-cycles-out):
        a candidate is kept only if it lowers the held-out error, a pair only if it beats its best
        member held out too.
    max_rows : above this many rows (default 10 000), every k-th row is used and a DataWarning
        says so (:mod:`femast.experiments.rows`).
    screen : on an expensive (FE) experiment, a candidate whose linearisation at the start of its refit
        shows that it cannot be significant is not refitted in full (:mod:`femast.experiments.screening`);
        False refits every candidate in full.

    The stages, in order (each a function of its module, reading and writing a
    :class:`~femast.experiments.diagnosis.Diagnosis`): the baseline fit and the noise model its refits
    are weighted by (:func:`_baseline`); the candidates, each in its forms
    (:mod:`femast.experiments.candidates`); the pairs (:mod:`femast.experiments.pairs`); the noise
    model of the best model, by which everything is scored (:func:`_noise_model`); the held-out check
    (:mod:`femast.experiments.heldout`); the verdict (:mod:`femast.experiments.verdict`); the report
    (:mod:`femast.experiments.diagnose_report`).

    Returns an ``OptimizeResult`` with ``experiment``, ``n_samples``, ``noise`` (per channel: the
    per-row noise, (n,) arrays), ``noise_model`` (``{channel: ChannelNoise}``), ``noise_rms``,
    ``baseline`` (``{"rms", "ratio", "bic", "params", "effects", "heldout_ratio"}``), ``baseline_fit``,
    ``ranking`` (list of dicts, best first: ``effect``, ``form``, ``forms``, ``rms``, ``ratio``,
    ``heldout_ratio``, ``heldout_ok``, ``delta_bic``, ``params``, ``ic_gain``, ``share_ok``,
    ``significant``, ``explained_fraction``, ``reading``, ``success``, ``failed``), ``fits`` (``{effect: fit result of its best form}``), ``pairs``, ``form_check``,
    ``best_fit``, ``verdict`` (see :mod:`femast.experiments.verdict`), ``report`` (the JSON
    document), ``executor``, ``files``, ``success``, ``message``.
    """
    exp.require_model("diagnose")
    data = thin(data, max_rows, "diagnose")  # a long record: every k-th row (femast.experiments.rows)
    check_units(exp, data)  # a unit mistake (mm under an m header) stops here, naming the column
    # the refit workers of an FE experiment start now: they import femast and the rig while this
    # process fits the baseline
    pool = refit_pool(exp, workers, scheduler)
    with pool if pool is not None else nullcontext():
        return _diagnose(
            exp,
            data,
            candidates,
            exclude=exclude,
            base_effects=base_effects,
            sigma=sigma,
            workers=workers,
            scheduler=scheduler,
            out=out,
            pairs=pairs,
            heldout=heldout,
            pool=pool,
            screen=screen,
        )


def _diagnose(
    exp, data, candidates, *, exclude, base_effects, sigma, workers, scheduler, out, pairs, heldout, pool, screen
) -> OptimizeResult:
    d = Diagnosis.of(
        exp,
        data,
        candidates,
        exclude,
        base_effects,
        sigma=sigma,
        workers=workers,
        scheduler=scheduler,
        pool=pool,
        screen=screen,
    )
    _baseline(d)
    # the report's matplotlib is imported while the worker processes refit
    fit_candidates(d, while_waiting=_import_pyplot if out is not None else None)
    rank(d)
    if pairs:
        fit_pairs(d)
    _noise_model(d)
    if refit_unscreened(d):  # a candidate screened out under the first noise model that could pass under this one
        rank(d)
        score_pairs(d)
    if heldout:
        heldout_check(d)
    _verdict(d)
    return diagnosis_result(d, out)


def _baseline(d: Diagnosis) -> None:
    """The baseline fit and the noise model that weights every refit
    (:func:`~femast.experiments.baseline.fit_with_noise`), and what the refits need."""
    exp, data = d.exp, d.data
    t0 = time.perf_counter()
    with progress.task(f"diagnose: fitting the baseline {exp.name}" + "".join(" + " + e for e in d.base_effects)):
        d.baseline, d.models = fit_with_noise(exp, data, d.base_effects, sigma=d.sigma)
    d.t_base = time.perf_counter() - t0
    d.payload = {
        "source": exp.source,
        "options": exp.options,
        "scripts": list(loaded_scripts()),
        "data": data,
        "start": d.start,
        "noise": d.weights,
        "sensitivity": getattr(d.baseline, "sensitivity", None),  # seeds the refits' Jacobians
    }
    _score_baseline(d, at_noise_threshold(data.n, len(d.channels)))


def _score_baseline(d: Diagnosis, thr: float) -> None:
    d.s0 = d.score(d.baseline)
    d.thr = thr
    d.analysis = analyse(d.exp, d.data, _with_noise(d.baseline, d.weights))


def _noise_model(d: Diagnosis) -> None:
    """The noise model from the residual of the best model (baseline, candidate or pair: its residual
    is the closest to the noise), by which everything is scored again."""
    fits = [
        d.baseline,
        *(f for f in d.fits_list if not getattr(f, "failed", False)),  # a screened one: where its refit stopped
        *(r for *_, r in d.pair_fits),
    ]
    best = min(fits, key=lambda f: d.score(f)["rss"])
    d.models = noise_model(d.exp, d.data, best, pinned=pinned_rows(d.baseline, d.channels), sigma=d.sigma)
    d.n_eff = min(m.n_eff for m in d.models.values())
    _score_baseline(d, at_noise_threshold(int(round(d.n_eff)), len(d.channels)))
    rank(d)
    score_pairs(d)


def _verdict(d: Diagnosis) -> None:
    """The verdict (:func:`~femast.experiments.verdict.conclude`) from the ranking, the pairs that
    passed the held-out check and the form check, overruled where the response moves at constant load
    (:func:`~femast.experiments.time_dependence.creep_overrules`)."""
    best = next((e for e in d.ranking if e["significant"]), None)
    where = remaining_where(d, best["_z"] if best else d.s0["z"])
    titles = {e["effect"]: get_effect(e["effect"]).title for e in d.ranking}
    pairs = [{k: v for k, v in p.items() if not k.startswith("_")} for p in d.pairs if p.get("heldout_ok", True)]
    verdict = conclude(d.s0["ratio"], d.thr, d.ranking, pairs, d.form_check, titles, where)
    # the holds of the test: a response that moves at constant load rules out rate-independent answers
    check = time_check(load_path(d.exp, d.data), {c: d.data[c] for c in d.channels}, d.weights)
    d.verdict = creep_overrules(verdict, check, lambda name: reads_time(d.exp, name))


def _import_pyplot():
    from ..post.plotstyle import pyplot

    pyplot()


def _with_noise(res: OptimizeResult, sigma: dict) -> OptimizeResult:
    """A shallow copy of a fit result with the per-row noise of the noise model."""
    r = OptimizeResult(dict(res))
    r.noise = sigma
    return r
