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

The noise model of every channel (white, heteroscedastic, AR(1), given, checked against repeated
passes) is :mod:`femast.experiments.noise`; the significance rule and the verdict kinds
(``missing_effect``, ``missing_pair``, ``form_imperfect``, ``better_form``, ``nothing_missing``,
``not_explained``) are :mod:`femast.experiments.verdict`.
"""

from __future__ import annotations

import json
import time
from pathlib import Path

import numpy as np
from scipy.optimize import OptimizeResult

from .. import progress
from ..effects.base import applicable_effects, forms_of, get_effect, loaded_scripts, resolve, split_form
from ..errors import ModelError
from .compare import analyse
from .core import Experiment, Measured
from .figure_process import FigureProcess
from .figures import diagnose_figure, display_scale
from .fitting import fit, params_table, predict
from .noise import noise_model, pinned_rows

# the refits' executor (re-exported: diagnose.REFIT_NFEV, diagnose._mp_context, ... keep working)
from .refits import (  # noqa: F401
    _START_METHOD,
    REFIT_NFEV,
    SERIAL_BELOW_S,
    _dispatch,
    _mp_context,
    _refit_task,
    _run_tasks,
    _safe_fit,
    _serial_refits,
)
from .residuals import AT_NOISE, at_noise_threshold
from .rows import thin
from .units import check_data as check_units
from .verdict import MIN_SHARE, SIGNIFICANT_DBIC, conclude, flags, pair_candidates, robust_delta, score, share


# --------------------------------------------------------------------------- readings
def _kind_ratio(mask, z, nch):
    z = np.asarray(z).reshape(nch, -1)[:, mask]
    return float(np.sqrt(np.mean(z**2))) if z.size else float("nan")


def _reading(effect, entry, z0, zc, masks, nch, worst_kind, at_noise=AT_NOISE):
    eff = get_effect(effect)
    text = f"{eff.signature[0].upper()}{eff.signature[1:]}. " if eff.signature else ""
    form = f" (form {entry['form']})" if entry.get("form") else ""
    text += (
        f"Refitted with {eff.title}{form}, the error goes from {entry['baseline_ratio']:.2f}x to "
        f"{entry['ratio']:.2f}x the noise (explains {100 * entry['explained_fraction']:.0f} % of the excess; "
        f"delta BIC {entry['delta_bic']:+.1f})."
    )
    gains = []
    for kind, m in masks.items():
        if m.sum() >= 3:
            gains.append((_kind_ratio(m, z0, nch) - _kind_ratio(m, zc, nch), kind))
    if gains and entry["significant"]:
        g, kind = max(gains)
        if g > 0:
            text += f" The largest gain is in the {kind} segments."
    if worst_kind and worst_kind in eff.acts_where:
        text += f" The model fails most in the {worst_kind} segments, where this effect acts."
    if not entry["significant"]:
        text += (
            " Not significant: the data do not ask for it."
            if not entry["ic_gain"]
            else f" Not significant: it explains less than {100 * MIN_SHARE:.0f} % of the excess error."
        )
    elif entry["ratio"] > at_noise:
        text += " Structure remains after it."
    return text


def _remaining_where(masks, z, nch, thr, min_rows=3):
    """Kinds of segment where a fit's whitened residual is above the at-noise threshold, worst first."""
    out = [(r, k) for k, m in masks.items() if m.sum() >= min_rows and (r := _kind_ratio(m, z, nch)) > thr]
    return [f"{k} ({r:.1f}x)" for r, k in sorted(out, reverse=True)]


# --------------------------------------------------------------------------- diagnose
def diagnose(
    exp: Experiment,
    data: Measured,
    candidates=None,
    *,
    base_effects=(),
    workers=None,
    scheduler=None,
    out=None,
    pairs: bool = True,
    max_rows: int | None = None,
) -> OptimizeResult:
    """Refit the model with each candidate effect (every form), pairs of the best, and conclude.

    max_rows : above this many rows (default 10 000), every k-th row is used and a DataWarning
        says so (:mod:`femast.experiments.rows`).

    candidates : effect names to try (default: every effect applicable to the experiment and not in
        ``base_effects``); each is fitted in each of its forms (``effect/form``), the information
        criterion picks the form.  base_effects : effects already in the model being diagnosed
        (names or ``effect/form``); their other forms are refitted first (a shape mismatch).
    workers : local worker processes (default: the number of CPUs, unless the refits are estimated
        -- six times the baseline fit time each -- to take less than ``SERIAL_BELOW_S`` = 1 s in all,
        which is less than starting the processes costs; 1 runs in this process).
    scheduler : a dask.distributed scheduler address (``tcp://...``) or ``distributed.Client``.
    out : folder for ``diagnose.json``, ``diagnose.png`` and ``diagnose_report.html`` (self-contained,
        figures inlined; nothing written if None).
    pairs : refit pairs of the top candidates jointly (their verdict: femast.experiments.verdict).

    Returns an ``OptimizeResult`` with ``experiment``, ``n_samples``, ``noise`` (per channel: the
    per-row noise, (n,) arrays), ``noise_model`` (``{channel: ChannelNoise}``), ``noise_rms``,
    ``baseline`` (``{"rms", "ratio", "bic", "params", "effects"}``), ``baseline_fit``, ``ranking``
    (list of dicts, best first: ``effect``, ``form``, ``forms``, ``rms``, ``ratio``, ``delta_bic``,
    ``params``, ``ic_gain``, ``share_ok``, ``significant``, ``explained_fraction``, ``reading``,
    ``success``), ``fits`` (``{effect: fit result of its best form}``), ``pairs``, ``form_check``,
    ``best_fit``, ``verdict`` (see :mod:`femast.experiments.verdict`), ``report`` (the JSON
    document), ``executor``, ``files``, ``success``, ``message``.
    """
    exp.require_model("diagnose")
    data = thin(data, max_rows, "diagnose")  # a long record: every k-th row (femast.experiments.rows)
    check_units(exp, data)  # a unit mistake (mm under an m header) stops here, naming the column
    # the figure is drawn by a process forked now, which imports matplotlib while this one fits the
    # baseline on the other CPU (FE experiments, local refits; issue 21)
    figs = FigureProcess.start() if out is not None and scheduler is None and exp.fit_options.get("expensive") else None
    try:
        return _diagnose(
            exp,
            data,
            candidates,
            base_effects=base_effects,
            workers=workers,
            scheduler=scheduler,
            out=out,
            pairs=pairs,
            figs=figs,
        )
    finally:
        if figs is not None:
            figs.close()


def _diagnose(exp, data, candidates, *, base_effects, workers, scheduler, out, pairs, figs) -> OptimizeResult:
    if isinstance(base_effects, str):
        base_effects = [e for e in base_effects.split(",") if e.strip()]
    base_effects = [n for n, _ in resolve(exp, list(base_effects))]
    base_names = {split_form(n)[0] for n in base_effects}
    key = exp.effect_key
    if candidates is None:
        candidates = [e.name for e in applicable_effects(exp) if e.name not in base_names]
    else:
        candidates = [split_form(n)[0] for n, _ in resolve(exp, list(candidates))]
        dup = set(candidates) & base_names
        if dup:
            raise ModelError(f"candidate effect(s) {', '.join(sorted(dup))} are already in the model")
    t0 = time.perf_counter()
    with progress.task(f"diagnose: fitting the baseline {exp.name}" + "".join(" + " + e for e in base_effects)):
        baseline = fit(exp, data, base_effects)
    t_base = time.perf_counter() - t0
    nch, chans = len(exp.channels), exp.channels
    models = noise_model(exp, data, baseline, correlate=False, generic=False)  # weights of the refits
    sigma = {c: models[c].sigma for c in chans}
    if any(m.kind.startswith(("heteroscedastic", "given")) for m in models.values()):
        baseline = fit(
            exp, data, base_effects, start=dict(zip(baseline.names, baseline.x)), noise=sigma, given_start_clip=True
        )
    start = dict(zip(baseline.names, baseline.x))
    if exp.fit_options.get("expensive") and exp.options.get("fe_reference", False) is None:
        # the refits' reference run (the baseline model at its solution, femast.experiments.fe_reference),
        # here once: forked workers inherit it (and its converged path) instead of each running it
        predict(exp, data, baseline.params)
    payload0 = {
        "source": exp.source,
        "options": exp.options,
        "scripts": list(loaded_scripts()),
        "data_experiment": data.experiment,
        "columns": data.columns,
        "path": data.path,
        "lines": data.lines,
        "start": start,
        "noise": sigma,
        "sensitivity": getattr(baseline, "sensitivity", None),
    }  # seeds the refits' Jacobians (issue 21)
    # stage 1: the forms of the added effects (shape mismatch) and the default form of each candidate;
    # stage 2: the generalised forms of the candidates whose default form has an information-criterion
    # gain (under the null nothing does, and the generalised forms cannot gain where it did not),
    # started from the default form's fit
    jobs = []
    for b in base_effects:
        name, form = split_form(b)
        for alt in forms_of(name, key):
            if alt != b and alt != name + "/" + (form or ""):
                effs = [alt if e == b else e for e in base_effects]
                jobs.append(("form_check", name, alt, effs, start))
    for c in candidates:
        jobs.append(("candidate", c, c, base_effects + [c], start))
    payloads = [{**payload0, "effects": effs, "start": st} for *_, effs, st in jobs]
    # without a figure process, the report's matplotlib is imported while the worker processes refit
    fits_list, how = _dispatch(
        exp,
        data,
        payloads,
        start,
        sigma,
        workers,
        scheduler,
        t_base,
        while_waiting=_import_pyplot if out is not None and figs is None else None,
    )
    s_pre = score(baseline, models, chans, data.n)
    jobs2 = []
    for (stage, c, _spec, _, _), res in zip(jobs, fits_list):
        if stage != "candidate" or getattr(res, "failed", False):
            continue
        if score(res, models, chans, data.n)["ic"] - s_pre["ic"] >= SIGNIFICANT_DBIC:
            continue
        fitted = {k.split(".", 1)[1]: v for k, v in zip(res.names, res.x) if k.startswith(c + ".")}
        base_fit = {k: v for k, v in zip(res.names, res.x) if "." not in k}
        for alt in forms_of(c, key)[1:]:
            _, impl = resolve(exp, [alt])[0]
            st = {**base_fit, **{f"{alt}.{p.name}": fitted[p.name] for p in impl.parameters if p.name in fitted}}
            jobs2.append(("candidate", c, alt, base_effects + [alt], st))
    if jobs2:
        more, _ = _dispatch(
            exp,
            data,
            [{**payload0, "effects": effs, "start": st} for *_, effs, st in jobs2],
            start,
            sigma,
            workers,
            scheduler,
            t_base,
        )
        jobs += jobs2
        fits_list = list(fits_list) + list(more)
    ok = [f for f in fits_list if not getattr(f, "failed", False)]
    s0 = score(baseline, models, chans, data.n)  # under the noise model of the refits' weights
    r0, ic0 = s0["ratio"], s0["ic"]
    thr = at_noise_threshold(data.n, nch)
    a = analyse(exp, data, _with_noise(baseline, sigma))
    worst_kind = a["by_kind"][0]["kind"] if a["by_kind"] else None

    def entry_of(effect, spec, res):
        if getattr(res, "failed", False):
            return {
                "effect": effect,
                "form": _form(spec, effect, key),
                "rms": float(baseline.rms),
                "ratio": r0,
                "delta_bic": 0.0,
                "params": {},
                "significant": False,
                "ic_gain": False,
                "share_ok": False,
                "explained_fraction": 0.0,
                "baseline_params": {},
                "success": False,
                "at_bound": [],
                "failed": True,
                "spec": spec,
                "baseline_ratio": r0,
                "reading": f"The refit with {get_effect(effect).title} failed: {res.message}",
            }
        sc = score(res, models, chans, data.n)
        d, frac = sc["ic"] - ic0, share(r0, sc["ratio"])
        dr = robust_delta(s0["z"], sc["z"], data.n, models, int(baseline.n_params), int(res.n_params))
        table = params_table(res)
        return {
            "effect": effect,
            "form": _form(spec, effect, key),
            "spec": spec,
            "rms": float(res.rms),
            "ratio": sc["ratio"],
            "delta_bic": float(d),
            "explained_fraction": frac,
            **flags(d, frac, dr),
            "delta_bic_robust": float(dr),
            "params": {k.split(".", 1)[1]: v for k, v in table.items() if k.startswith(spec + ".")},
            "baseline_params": {k: v for k, v in table.items() if "." not in k},
            "baseline_ratio": r0,
            "success": bool(res.success),
            "at_bound": list(res.at_bound),
            "n_params": int(res.n_params),
            "_z": sc["z"],
        }

    def rank():
        """(ranking, fits, form_check) of the refits under the current noise model."""
        by_effect, fc, fts = {}, [], {}
        for (stage, effect, spec, *_), res in zip(jobs, fits_list):
            e = entry_of(effect, spec, res)
            if stage == "form_check":
                fc.append(
                    {
                        k: e[k]
                        for k in ("effect", "form", "ratio", "delta_bic", "explained_fraction", "significant", "params")
                    }
                )
            else:
                by_effect.setdefault(effect, []).append((e, res))
        out = []
        for effect, items in by_effect.items():
            good = [it for it in items if not it[0].get("failed")]
            e, res = min(good, key=lambda it: it[0]["delta_bic"]) if good else items[0]
            e["forms"] = [
                {
                    "form": x["form"],
                    "ratio": x["ratio"],
                    "delta_bic": x["delta_bic"],
                    "n_params": x.get("n_params", 0),
                    **({"failed": True} if x.get("failed") else {}),
                }
                for x, _ in items
            ]
            if not e.get("failed"):
                e["reading"] = _reading(effect, e, s0["z"], e["_z"], a["masks"], nch, worst_kind, thr)
            fts[effect] = res
            out.append(e)
        out.sort(key=lambda e: (e.get("failed", False), e["delta_bic"]))
        return out, fts, fc

    def pair_entry(x, y, res, by):
        sc = score(res, models, chans, data.n)
        d, frac = sc["ic"] - ic0, share(r0, sc["ratio"])
        dr = robust_delta(s0["z"], sc["z"], data.n, models, int(baseline.n_params), int(res.n_params))
        order = list(by)
        x, y = sorted((x, y), key=order.index)  # the better-ranked member first
        return {
            "effects": [x, y],
            "forms": [by[x]["form"], by[y]["form"]],
            "ratio": sc["ratio"],
            "rms": float(res.rms),
            "delta_bic": float(d),
            "explained_fraction": frac,
            **flags(d, frac, dr),
            "gain_over_best_single": float(d - min(by[x]["delta_bic"], by[y]["delta_bic"])),
            "share_over_best_single": float(frac - max(by[x]["explained_fraction"], by[y]["explained_fraction"])),
            "_fit": res,
        }

    ranking, fits, form_check = rank()
    # pairs of the top candidates with an information-criterion gain, fitted jointly
    pair_fits = []
    top = pair_candidates(ranking)
    if pairs and top and r0 > thr:
        by = {e["effect"]: e for e in ranking}
        combos = [(x, y) for i, x in enumerate(top) for y in top[i + 1 :]]
        # and the best with every other candidate: a second mechanism whose own gain the first one's
        # larger error hides (forward selection); not for the FE experiments, where a refit costs
        # a minute of FE runs (their few rows rarely show a second mechanism without its own gain)
        if not exp.fit_options.get("expensive"):
            combos += [(top[0], e["effect"]) for e in ranking if not e.get("failed") and e["effect"] not in top]
        pl = []
        for x, y in combos:
            st = dict(start)
            for z in (x, y):
                st.update({f"{by[z]['spec']}.{k}": v["value"] for k, v in by[z]["params"].items()})
            pl.append({**payload0, "start": st, "effects": base_effects + [by[x]["spec"], by[y]["spec"]]})
        pfits, _ = _dispatch(exp, data, pl, start, sigma, workers, scheduler, t_base)
        pair_fits = [(x, y, res) for (x, y), res in zip(combos, pfits) if not getattr(res, "failed", False)]
    # final noise model from the residual of the best model (femast.experiments.noise), everything rescored
    cands = [baseline, *ok, *(res for *_, res in pair_fits)]
    best_res = min(cands, key=lambda f: score(f, models, chans, data.n)["rss"])
    models = noise_model(exp, data, best_res, pinned=pinned_rows(baseline, chans))
    sigma = {c: models[c].sigma for c in chans}
    s0 = score(baseline, models, chans, data.n)
    r0, ic0 = s0["ratio"], s0["ic"]
    n_eff = min(m.n_eff for m in models.values())
    thr = at_noise_threshold(int(round(n_eff)), nch)
    a = analyse(exp, data, _with_noise(baseline, sigma))
    worst_kind = a["by_kind"][0]["kind"] if a["by_kind"] else None
    ranking, fits, form_check = rank()
    by = {e["effect"]: e for e in ranking}
    pair_list = sorted((pair_entry(x, y, res, by) for x, y, res in pair_fits), key=lambda p: p["delta_bic"])
    best_e = next((e for e in ranking if e["significant"]), None)
    where = _remaining_where(a["masks"], best_e["_z"] if best_e else s0["z"], nch, thr)
    titles = {e["effect"]: get_effect(e["effect"]).title for e in ranking}
    pairs_json = [{k: v for k, v in p.items() if not k.startswith("_")} for p in pair_list]
    verdict = conclude(r0, thr, ranking, pairs_json, form_check, titles, where)
    base_table = params_table(baseline)
    noise_rms = float(np.sqrt(np.mean([np.mean((exp.weight(c) * sigma[c]) ** 2) for c in chans])))
    public = (
        "effect",
        "rms",
        "delta_bic",
        "params",
        "significant",
        "ratio",
        "explained_fraction",
        "reading",
        "form",
        "forms",
        "ic_gain",
        "share_ok",
        "delta_bic_robust",
    )
    report = {
        "experiment": exp.name,
        "n_samples": int(data.n),
        "noise_rms": noise_rms,
        "baseline": {
            "rms": float(baseline.rms),
            "params": base_table,
            "ratio": float(r0),
            "effects": list(base_effects),
            "bic": float(ic0),
        },
        "ranking": [
            {**{k: e[k] for k in public if k in e}, **({"failed": True} if e.get("failed") else {})} for e in ranking
        ],
        "verdict": verdict,
        "data": str(data.path),
        "error_unit": exp.error_unit,
        "noise": {c: float(np.sqrt(np.mean(sigma[c] ** 2))) for c in chans},
        "noise_model": {c: models[c].to_json() for c in chans},
        "n_eff": float(n_eff),
        "pairs": pairs_json,
        "form_check": form_check,
        "baseline_worst_kinds": a["by_kind"][:3],
        "baseline_signatures": a["signatures"][:3],
        "executor": how,
        "at_noise": thr,
    }
    best_fit = None
    if verdict["kind"] == "missing_pair" and pair_list:
        best_fit = pair_list[0]["_fit"]
    elif ranking and not ranking[0].get("failed"):
        best_fit = fits[ranking[0]["effect"]]
    result = OptimizeResult(
        experiment=exp.name,
        n_samples=data.n,
        noise=sigma,
        noise_model=models,
        noise_rms=noise_rms,
        baseline={
            "rms": float(baseline.rms),
            "ratio": float(r0),
            "bic": float(ic0),
            "params": base_table,
            "effects": list(base_effects),
        },
        baseline_fit=baseline,
        baseline_z=s0["z"],
        ranking=ranking,
        fits=fits,
        pairs=pair_list,
        form_check=form_check,
        best_fit=best_fit,
        verdict=verdict,
        report=report,
        executor=how,
        files={},
        at_noise=thr,
        n_eff=n_eff,
        success=bool(baseline.success) and all(e["success"] for e in ranking),
        message=verdict["conclusion"],
        by_kind=a["by_kind"],
        signatures=a["signatures"],
    )
    if out is not None:
        out = Path(out)
        out.mkdir(parents=True, exist_ok=True)
        png = out / "diagnose.png"
        if figs is None or not figs.draw(diagnose_figure, exp, data, result, png):
            diagnose_figure(exp, data, result, png)
        result.files["png"] = str(png)
        result.files["json"] = str(out / "diagnose.json")
        result.files["html"] = str(out / "diagnose_report.html")
        report["files"] = result.files
        Path(result.files["json"]).write_text(json.dumps(report, indent=2))
        from .report import diagnose_report

        diagnose_report(exp, data, result, out)
    return result


def _import_pyplot():
    from ..post.plotstyle import pyplot

    pyplot()


def _form(spec: str, effect: str, key: str) -> str:
    """Form name of an effect spec ("" for a one-form effect; the default form's name otherwise)."""
    f = split_form(spec)[1]
    if f:
        return f
    impl = get_effect(effect).implementations.get(key)
    return impl.form if impl else ""


def _with_noise(res: OptimizeResult, sigma: dict) -> OptimizeResult:
    """A shallow copy of a fit result with the per-row noise of the noise model."""
    r = OptimizeResult(dict(res))
    r.noise = sigma
    return r


def format_diagnose(exp: Experiment, result: OptimizeResult) -> str:
    """Plain-text summary of a diagnosis (what ``femast diagnose`` prints)."""
    f, ul = display_scale(exp.error_unit)
    b = result.baseline
    lines = [
        f"femast diagnose: {exp.name} on {result.report['data']} ({result.n_samples} samples; refits: "
        f"{result.executor})",
        f"  noise floor {f * result.noise_rms:.4g} {ul}; baseline"
        f"{' + ' + '+'.join(b['effects']) if b['effects'] else ''} RMS {f * b['rms']:.4g} {ul} "
        f"({b['ratio']:.2f}x noise)",
    ]
    if result.by_kind:
        lines.append(
            "  the model fails most in: " + ", ".join(f"{k['kind']} ({k['ratio']:.1f}x)" for k in result.by_kind[:3])
        )
    nm = getattr(result, "noise_model", None) or {}
    for c, m in nm.items():
        lines.append(f"  noise of {c}: {m.kind} -- {m.reason}")
    lines.append(
        f"  {'rank':>4s}  {'effect':<22s} {'form':<10s} {'RMS':>10s} {'x noise':>8s} {'dBIC':>9s} "
        f"{'share':>6s}  sig  parameters"
    )
    for i, e in enumerate(result.ranking):
        if e.get("failed"):
            lines.append(f"  {i + 1:>4d}  {e['effect']:<22s} {'refit failed':>10s}  {e['reading'][:90]}")
            continue
        ps = ", ".join(
            f"{k} = {v['value']:.4g}" + (f" +- {v['stderr']:.2g}" if v["stderr"] is not None else "") + f" {v['unit']}"
            for k, v in e["params"].items()
        )
        lines.append(
            f"  {i + 1:>4d}  {e['effect']:<22s} {e.get('form') or '-':<10s} {f * e['rms']:>10.4g} "
            f"{e['ratio']:>8.2f} {e['delta_bic']:>9.1f} {100 * e['explained_fraction']:>5.0f}%  "
            f"{'yes' if e['significant'] else ' no'}  {ps}"
        )
    for p in (getattr(result, "pairs", None) or [])[:3]:
        lines.append(
            f"  pair  {' + '.join(p['effects']):<33s} {f * p['rms']:>10.4g} {p['ratio']:>8.2f} "
            f"{p['delta_bic']:>9.1f} {100 * p['explained_fraction']:>5.0f}%  "
            f"{'yes' if p['significant'] else ' no'}"
        )
    for fc in getattr(result, "form_check", None) or []:
        lines.append(
            f"  form check of the added {fc['effect']}: form {fc['form']} {fc['ratio']:.2f}x noise, dBIC "
            f"{fc['delta_bic']:+.1f}{' (significant)' if fc['significant'] else ''}"
        )
    if result.ranking:
        lines.append(f"  reading of #1: {result.ranking[0]['reading']}")
    lines.append(f"  verdict: {result.verdict['conclusion']} [{result.verdict.get('kind')}]")
    if result.files:
        lines.append("  wrote " + ", ".join(result.files.values()))
    return "\n".join(lines)
