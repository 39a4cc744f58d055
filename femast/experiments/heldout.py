"""Held-out validation: fit on some of the data, score the rest.

A model that explains the data it was fitted on may still not predict data it has not seen: an
effect with freedom to spare bends into the noise or into a structure it does not model. The test
of a mechanism is that it also lowers the error on data it was not fitted to.

Folds
-----
:func:`folds` splits a data set into parts that are left out one at a time:

* the **groups** of the data (stations, specimens, runs, files; :attr:`Measured.groups`):
  leave-one-group-out (neighbouring groups merged when there are more than ``MAX_FOLDS``);
* else the **cycles** of the load path: ``K`` contiguous blocks of whole cycles (between every second
  turning point of the load measure, :func:`~femast.experiments.residuals.turning_points`), ``K`` =
  ``FOLDS`` (4) or the number of cycles;
* else (one pass, fewer cycles than folds) ``K`` interleaved folds of short runs of rows
  (``MIN_FOLD_ROWS`` rows each, dealt to the folds in turn): contiguous blocks of one pass would
  each be a regime of its own (the latched zone of a latch pull, the peak of a ramp) that the
  other blocks say nothing about, and every model, right or wrong, would fail to extrapolate into
  it (a latch-pull pass with a hidden latch hysteresis: the baseline 6.7x the noise held out, the
  right effect 6.8x, against 1.4x and 0.85x fitted); interleaved, each fold is predicted from its
  neighbours on both sides, which tests the fit against the noise.

Each fold's fit sees the other rows only (:func:`~femast.experiments.fitting.fit` with ``rows``),
started from the fit on all the data; the model still runs along the whole path (its state at a
row depends on the rows before: friction, hysteresis) and the left-out rows are predicted. Every row
is left out once: the **held-out residual** is the residual of each row from the fit that did not
see it, and its ratio to the noise is :func:`~femast.experiments.residuals.robust_rms` of it
whitened by the noise model, as the fit's own ratio.
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import OptimizeResult

from .residuals import load_path, noise_floor, robust_rms, turning_points

FOLDS = 4  # folds of a data set without groups
MAX_FOLDS = 8  # at most this many folds (neighbouring groups merged)
MIN_FOLD_ROWS = 5  # fewest rows in a fold


def folds(exp, data, k: int | None = None) -> list:
    """The folds of ``data`` (module docstring): ``[(name, (n,) bool rows left out)]``; [] if the data
    are too short to leave anything out."""
    n = data.n
    groups = data.group_rows()
    if groups:
        if len(groups) > MAX_FOLDS:  # merge neighbours
            parts = np.array_split(np.arange(len(groups)), MAX_FOLDS)
            return [
                (
                    f"groups {groups[p[0]][0]}-{groups[p[-1]][0]}",
                    np.any([groups[i][1] for i in p], axis=0),
                )
                for p in parts
            ]
        return [(f"group {name}", rows) for name, rows in groups]
    k = int(k or FOLDS)
    if n < 2 * MIN_FOLD_ROWS:
        return []
    k = max(2, min(k, n // MIN_FOLD_ROWS))
    starts = np.array(_cycle_starts(exp, data))
    if len(starts) >= k:  # contiguous blocks of whole cycles, of about n / k rows each
        inner = sorted({int(starts[np.argmin(np.abs(starts - i * n / k))]) for i in range(1, k)} - {0})
        edges = [0, *inner, n]
        k = len(edges) - 1
        kind = "cycles"
    else:
        chunk = np.arange(n) // MIN_FOLD_ROWS % k  # short runs of rows dealt to the folds in turn
        return [(f"rows {i + 1} of every {k} runs of {MIN_FOLD_ROWS}", chunk == i) for i in range(k)]
    out = []
    for i in range(k):
        a, b = edges[i], edges[i + 1]
        if b - a >= MIN_FOLD_ROWS:
            m = np.zeros(n, bool)
            m[a:b] = True
            out.append((f"{kind} {a}-{b - 1}", m))
    return out if len(out) >= 2 else []


def _cycle_starts(exp, data) -> list:
    """Rows where the load path's cycles start (0 and every second confirmed turning point)."""
    s = np.asarray(load_path(exp, data), float)
    rng = float(np.ptp(s)) if s.size else 0.0
    if rng <= 0:
        return [0]
    tps, _ = turning_points(s, max(0.05 * rng, 5 * noise_floor(s)))
    return [0, *(int(t) + 1 for t in list(tps)[1::2])]


def assemble(exp, data, fold_list, fits) -> OptimizeResult:
    """The held-out residual of a model variant from its fold fits (one per fold, in order; module
    docstring): ``residuals`` ({channel: (n,)}, NaN on the rows of folds whose fit failed),
    ``failed`` (the names of those folds)."""
    res = {c: np.full(data.n, np.nan) for c in exp.channels}
    failed = []
    for (name, left_out), f in zip(fold_list, fits):
        if getattr(f, "failed", False):
            failed.append(name)
            continue
        for c in exp.channels:
            res[c][left_out] = f.residuals[c][left_out]
    return OptimizeResult(residuals=res, failed=failed)


def heldout_ratio(exp, residuals: dict, sigma: dict) -> float:
    """Robust RMS of the held-out residual whitened by ``sigma`` (rows of failed folds left out)."""
    z = np.concatenate([residuals[c] / sigma[c] for c in exp.channels])
    z = z[np.isfinite(z)]
    return robust_rms(z) if z.size else float("nan")


HO_MARGIN = 0.02  # a mechanism must lower the held-out ratio by at least 2 % (its scatter between redraws)


def heldout_check(d) -> None:
    """The held-out stage of ``diagnose`` (module docstring), on a
    :class:`~femast.experiments.diagnosis.Diagnosis`: the baseline, every significant candidate and
    the two best significant pairs are refitted once per fold (in parallel, on the refits' executor),
    each from its fit on all the data and with that fit's derivatives as its first Jacobian, and
    scored on the rows each fold left out.  Without a significant candidate or pair nothing is
    refitted (the check could only refuse one; ``d.heldout_ratio`` stays None).  Sets ``d.heldout_ratio`` (the baseline's) and, on the
    ranking's entries and the pairs, ``heldout_ratio`` and ``heldout_ok`` -- a candidate lowers the
    baseline's held-out ratio by ``HO_MARGIN``, a pair its best member's -- and makes the candidates
    that fail not significant (the reading says why)."""
    exp, data = d.exp, d.data
    cands = [e for e in d.ranking if e.get("significant")]
    best_pairs = [p for p in d.pairs if p.get("significant")][:2]
    if not cands and not best_pairs:
        return  # nothing the check could refuse: the verdict does not depend on it
    fold_list = folds(exp, data, 3 if exp.fit_options.get("expensive") else None)
    if not fold_list:
        return
    models = [("baseline", list(d.base_effects), d.baseline)]
    models += [(e["effect"], list(d.base_effects) + [e["spec"]], d.fits[e["effect"]]) for e in cands]
    models += [(" + ".join(p["effects"]), list(p["_fit"].effects), p["_fit"]) for p in best_pairs]
    sigma = d.weights
    specs = [
        {
            "effects": effects,
            "start": dict(zip(res.names, res.x)),
            # the fold's fit starts where the model's fit ended: its derivatives there are the
            # fold's first Jacobian (an expensive model saves a finite-difference run per parameter)
            "sensitivity": getattr(res, "sensitivity", None),
            "noise": sigma,
            "rows": ~left_out,
            "label": f"{name}, {fold} held out",
        }
        for name, effects, res in models
        for fold, left_out in fold_list
    ]
    results = d.refit(specs)
    k = len(fold_list)
    ratio = {}
    for i, (name, _, _) in enumerate(models):
        ho = assemble(exp, data, fold_list, results[i * k : (i + 1) * k])
        ratio[name] = (heldout_ratio(exp, ho.residuals, sigma), ho.failed)
    r0 = d.heldout_ratio = ratio["baseline"][0]
    for e in cands:
        r, failed = ratio[e["effect"]]
        e["heldout_ratio"], e["heldout_folds_failed"] = r, failed
        e["heldout_ok"] = bool(np.isfinite(r) and r < (1.0 - HO_MARGIN) * r0)
        if not e["heldout_ok"]:
            e["significant"] = False
            e["reading"] += (
                f" Held out, it does not lower the error on data its fit has not seen ({r:.2f}x against the "
                f"baseline's {r0:.2f}x): not kept."
            )
    by = {e["effect"]: e for e in d.ranking}
    for p in best_pairs:
        r, failed = ratio[" + ".join(p["effects"])]
        members = [by[m]["heldout_ratio"] for m in p["effects"] if "heldout_ratio" in by.get(m, {})]
        p["heldout_ratio"], p["heldout_folds_failed"] = r, failed
        p["heldout_ok"] = bool(np.isfinite(r) and r < (1.0 - HO_MARGIN) * min(members, default=r0))
