"""``diagnose``: which physical effect is the model most likely missing?

The baseline (the experiment's model, plus any effects already switched on) is fitted and the
noise floor of every channel is estimated from its residual.  Then the model is refitted once
per candidate effect -- every applicable effect not yet in the model -- with the same noise
weights.  The refits are independent and run in parallel: local processes by default
(:class:`concurrent.futures.ProcessPoolExecutor`), a dask.distributed cluster when a scheduler
address (or a ``distributed.Client``) is given.  With the default number of workers a
diagnosis whose refits are estimated to take under a second in all runs in the calling process:
starting worker processes would cost more than it saves (the FE experiments are the ones that
need the workers).

Ranking and verdict
-------------------
Candidates are ranked by ``delta_bic = BIC(candidate) - BIC(baseline)`` (see
:func:`~femast.experiments.fitting.bic`), which rewards explained error and penalises each added
parameter by ``ln n``.  A candidate is *significant* when ``delta_bic < -10`` ("very strong"
evidence on the Kass-Raftery scale; for one added parameter and n = 1500 residuals this needs a
chi-square drop of 17, i.e. p < 4e-5 under the null).  A model is *at the noise floor* when its
RMS error is at most ``AT_NOISE = 1.2`` times the noise: the white-noise estimate scatters by a
few % for a few hundred samples, and 1.2 leaves room for that; a structured error whose RMS is
0.66 of the noise lifts the total to 1.2x, so structure smaller than that is not claimed.  For
short data sets the estimate scatters more (the FE experiments have 40-80 rows: +-15-20 %), and
the threshold is raised to the 95th percentile of what a perfect model gives on pure noise of that
size (:func:`~femast.experiments.residuals.at_noise_threshold`: 1.38 for 45 rows of one channel;
1.2 from about 120 rows, or fewer with several channels); it is ``at_noise`` in the result and
the JSON report.

* no significant candidate and the baseline at the noise floor -> "nothing is missing"
  (``missing_effect`` null, ``explained`` true);
* the best candidate significant and at the noise floor -> it is the missing effect
  (``explained`` true);
* otherwise -> "none of the candidates explains this" (``missing_effect`` null, ``explained``
  false; ``best_candidate`` names the one that helps most, if any is significant).
"""

from __future__ import annotations

import json
import multiprocessing
import os
import time
from concurrent.futures import ProcessPoolExecutor, as_completed
from pathlib import Path

import numpy as np
from scipy.optimize import OptimizeResult

from .. import progress
from ..effects.base import applicable_effects, get_effect, load_script, loaded_scripts, resolve
from ..errors import FemastError, ModelError
from .compare import analyse
from .core import Experiment, Measured
from .figures import diagnose_figure, display_scale
from .fitting import fit, params_table
from .residuals import AT_NOISE, at_noise_threshold

SIGNIFICANT_DBIC = -10.0
_START_METHOD = None  # multiprocessing start method of the local pool (None: the platform's default)
SERIAL_BELOW_S = 1.0  # default workers: refit in this process when the refits should take less than this (s)


# --------------------------------------------------------------------------- refit tasks
def _refit_task(payload: dict) -> OptimizeResult:
    """One refit (runs in a worker process or on a dask worker)."""
    from .registry import experiment_from_source

    for script in payload["scripts"]:
        load_script(script)
    exp = experiment_from_source(payload["source"], payload["options"])
    data = Measured(payload["data_experiment"], payload["columns"], payload["path"], payload["lines"])
    res = _safe_fit(exp, data, payload["effects"], start=payload["start"], noise=payload["noise"])
    res.pid = os.getpid()
    return res


def _safe_fit(exp, data, effects, start, noise) -> OptimizeResult:
    """:func:`fit`, or a result with ``failed = True`` and the error as ``message`` when the model
    cannot be evaluated even at the start of the refit (an FE run that does not converge with the
    effect's default parameters): one failed candidate must not end the whole diagnosis."""
    try:
        return fit(exp, data, effects, start=start, noise=noise)
    except (ValueError, FemastError, FloatingPointError, ZeroDivisionError) as e:
        return OptimizeResult(failed=True, success=False, message=f"{type(e).__name__}: {e}", effects=tuple(effects))


def _rebuildable(exp: Experiment) -> bool:
    """True if a worker can rebuild ``exp`` from its source name/script and options."""
    if not exp.source:
        return False
    try:
        from .registry import experiment_from_source

        other = experiment_from_source(exp.source, exp.options)
    except Exception:
        return False
    return other.name == exp.name and other.model is exp.model


def _mp_context():
    """Start method of the local pool: ``_START_METHOD`` if set; else 'forkserver' once numba has
    started GNU OpenMP threads in this process (the FE experiments' ``kernel_threads`` does, and so
    would a parallel user kernel; forking after that aborts the child: "fork() called from a process
    already using GNU OpenMP"); else the platform's default (fork on Linux: the fastest start)."""
    if _START_METHOD:
        return multiprocessing.get_context(_START_METHOD)
    try:
        import numba

        layer = numba.threading_layer()  # ValueError while no parallel kernel has run
    except Exception:
        layer = None
    if layer == "omp" and "forkserver" in multiprocessing.get_all_start_methods():
        return multiprocessing.get_context("forkserver")
    return None


def _run_tasks(payloads, workers, scheduler):
    """Run the refits; returns (results, how) with ``how`` describing the executor used."""
    if scheduler is not None:
        try:
            from distributed import Client
        except ImportError:
            raise ModelError("--scheduler needs dask.distributed: pip install 'dask[distributed]' "
                             "(the femast extra 'dist')") from None
        own = not isinstance(scheduler, Client)
        client = Client(scheduler) if own else scheduler
        try:
            address = client.scheduler.address if client.scheduler is not None else str(scheduler)
            from distributed import as_completed as dask_completed

            futures = client.map(_refit_task, payloads, pure=False)
            names = {f.key: _candidate(p) for f, p in zip(futures, payloads)}
            with progress.counter(len(futures), "diagnose: refits on the cluster", unit="refits") as bar:
                for fut in dask_completed(futures):
                    bar.set_postfix_str(f"done: {names[fut.key]}", refresh=False)
                    bar.update(1)
            results = client.gather(futures)
        finally:
            if own:
                client.close()
        return list(results), f"dask.distributed at {address}"
    n = (os.cpu_count() or 1) if workers is None else int(workers)
    if n < 1:
        raise ModelError(f"--workers must be >= 1, got {workers}")
    n = min(n, len(payloads))
    if n <= 1:
        return _serial_refits(payloads), "serial (1 process)"
    with ProcessPoolExecutor(max_workers=n, mp_context=_mp_context()) as pool:
        futures = [pool.submit(_refit_task, p) for p in payloads]
        with progress.counter(len(futures), f"diagnose: refits on {n} processes", unit="refits") as bar:
            for fut in as_completed(futures):
                bar.set_postfix_str(f"done: {_candidate(payloads[futures.index(fut)])}", refresh=False)
                bar.update(1)
        results = [fut.result() for fut in futures]
    return results, f"{n} local processes"


def _candidate(payload) -> str:
    return payload["effects"][-1]


def _serial_refits(payloads):
    """The refits one after the other in this process, a progress bar per refit naming its candidate."""
    results = []
    for i, p in enumerate(payloads):
        with progress.task(f"diagnose: refit {i + 1}/{len(payloads)} with {_candidate(p)}"):
            results.append(_refit_task(p))
    return results


# --------------------------------------------------------------------------- readings
def _kind_ratio(mask, fun, nch):
    z = fun.reshape(nch, -1)[:, mask]
    return float(np.sqrt(np.mean(z**2))) if z.size else float("nan")


def _reading(effect, entry, base_fit, cand_fit, masks, nch, worst_kind, at_noise=AT_NOISE):
    eff = get_effect(effect)
    r0, rc = base_fit.ratio, cand_fit.ratio
    text = f"{eff.signature[0].upper()}{eff.signature[1:]}. " if eff.signature else ""
    text += (f"Refitted with {eff.title}, the error goes from {r0:.2f}x to {rc:.2f}x the noise "
             f"(explains {100 * entry['explained_fraction']:.0f} % of the excess; delta BIC {entry['delta_bic']:+.1f}).")
    gains = []
    for kind, m in masks.items():
        if m.sum() >= 3:
            gains.append((_kind_ratio(m, base_fit.fun, nch) - _kind_ratio(m, cand_fit.fun, nch), kind))
    if gains and entry["significant"]:
        g, kind = max(gains)
        if g > 0:
            text += f" The largest gain is in the {kind} segments."
    if worst_kind and worst_kind in eff.acts_where:
        text += f" The model fails most in the {worst_kind} segments, where this effect acts."
    if not entry["significant"]:
        text += " Not significant: the data do not ask for it."
    elif rc > at_noise:
        text += " Structure remains after it."
    return text


# --------------------------------------------------------------------------- diagnose
def diagnose(exp: Experiment, data: Measured, candidates=None, *, base_effects=(), workers=None, scheduler=None,
             out=None) -> OptimizeResult:
    """Refit the model with each candidate effect, rank them and conclude (see the module docstring).

    candidates : effect names to try (default: every effect applicable to the experiment and not in
        ``base_effects``).  base_effects : effects already in the model being diagnosed.
    workers : local worker processes (default: the number of CPUs, unless the refits are estimated
        -- twice the baseline fit time each -- to take less than ``SERIAL_BELOW_S`` = 1 s in all, which
        is less than starting the processes costs; 1 runs in this process).
    scheduler : a dask.distributed scheduler address (``tcp://...``) or ``distributed.Client``.
    out : folder for ``diagnose.json``, ``diagnose.png`` and ``diagnose_report.html`` (self-contained,
        figures inlined; nothing written if None).

    Returns an ``OptimizeResult`` with ``experiment``, ``n_samples``, ``noise`` (per channel),
    ``noise_rms``, ``baseline`` (``{"rms", "ratio", "bic", "params", "effects"}``), ``baseline_fit``,
    ``ranking`` (list of dicts, best first: ``effect``, ``rms``, ``ratio``, ``delta_bic``, ``params``,
    ``significant``, ``explained_fraction``, ``reading``, ``success``), ``fits`` (``{effect: fit
    result}``), ``best_fit``, ``verdict`` (``missing_effect``, ``explained``, ``best_candidate``,
    ``alternatives``, ``conclusion``), ``report`` (the JSON document), ``executor``, ``files``,
    ``success``, ``message``.
    """
    exp.require_model("diagnose")
    if isinstance(base_effects, str):
        base_effects = [e for e in base_effects.split(",") if e.strip()]
    base_effects = [n for n, _ in resolve(exp, list(base_effects))]
    if candidates is None:
        candidates = [e.name for e in applicable_effects(exp) if e.name not in base_effects]
    else:
        candidates = [n for n, _ in resolve(exp, list(candidates))]
        dup = set(candidates) & set(base_effects)
        if dup:
            raise ModelError(f"candidate effect(s) {', '.join(sorted(dup))} are already in the model")
    t0 = time.perf_counter()
    with progress.task(f"diagnose: fitting the baseline {exp.name}" + "".join(" + " + e for e in base_effects)):
        baseline = fit(exp, data, base_effects)
    t_base = time.perf_counter() - t0
    sigma = baseline.noise
    start = dict(zip(baseline.names, baseline.x))
    payload0 = {"source": exp.source, "options": exp.options, "scripts": list(loaded_scripts()),
                "data_experiment": data.experiment, "columns": data.columns, "path": data.path,
                "lines": data.lines, "start": start, "noise": sigma}
    payloads = [{**payload0, "effects": base_effects + [c]} for c in candidates]
    if payloads and not _rebuildable(exp):
        fits_list = []
        for i, p in enumerate(payloads):
            with progress.task(f"diagnose: refit {i + 1}/{len(payloads)} with {_candidate(p)}"):
                fits_list.append(_safe_fit(exp, data, p["effects"], start=start, noise=sigma))
        how = "serial (experiment defined in memory: worker processes cannot rebuild it)"
    elif (payloads and workers is None and scheduler is None and not exp.fit_options.get("expensive")
          and 6.0 * t_base * len(payloads) < SERIAL_BELOW_S):
        fits_list = _serial_refits(payloads)
        how = f"serial (refits estimated at {6.0 * t_base * len(payloads):.2f} s: cheaper than starting processes)"
    elif payloads:
        fits_list, how = _run_tasks(payloads, workers, scheduler)
    else:
        fits_list, how = [], "no candidates"
    a = analyse(exp, data, baseline)
    worst_kind = a["by_kind"][0]["kind"] if a["by_kind"] else None
    nch = len(exp.channels)
    r0 = baseline.ratio
    thr = at_noise_threshold(data.n, nch)
    ranking, fits = [], {}
    for name, res in zip(candidates, fits_list):
        fits[name] = res
        if getattr(res, "failed", False):
            ranking.append({"effect": name, "rms": float(baseline.rms), "ratio": float(r0), "delta_bic": 0.0,
                            "params": {}, "significant": False, "explained_fraction": 0.0, "baseline_params": {},
                            "success": False, "at_bound": [], "failed": True,
                            "reading": f"The refit with {get_effect(name).title} failed: {res.message}"})
            continue
        d = float(res.bic - baseline.bic)
        excess0 = r0**2 - 1.0
        frac = float(np.clip((r0**2 - res.ratio**2) / excess0, 0.0, 1.0)) if excess0 > 0 else 0.0
        table = params_table(res)
        entry = {"effect": name, "rms": float(res.rms), "ratio": float(res.ratio), "delta_bic": d,
                 "params": {k.split(".", 1)[1]: v for k, v in table.items() if k.startswith(name + ".")},
                 "significant": bool(d < SIGNIFICANT_DBIC), "explained_fraction": frac,
                 "baseline_params": {k: v for k, v in table.items() if "." not in k},
                 "success": bool(res.success), "at_bound": list(res.at_bound)}
        entry["reading"] = _reading(name, entry, baseline, res, a["masks"], nch, worst_kind, thr)
        ranking.append(entry)
    ranking.sort(key=lambda e: (e.get("failed", False), e["delta_bic"]))
    best = ranking[0] if ranking and ranking[0]["significant"] else None
    base_ok = r0 <= thr
    alternatives = [e["effect"] for e in ranking[1:] if best and e["significant"] and e["ratio"] <= thr
                    and e["delta_bic"] - best["delta_bic"] < 10.0]
    f, ul = display_scale(exp.error_unit)
    if best is None:
        missing, explained = None, base_ok
        if base_ok:
            conclusion = (f"nothing is missing: the model is at the noise floor ({r0:.2f}x noise) and no candidate "
                          "is significant")
        else:
            conclusion = (f"none of the candidates explains this: the model is {r0:.2f}x the noise and no candidate "
                          "effect reduces the error significantly")
    elif best["ratio"] <= thr:
        missing, explained = best["effect"], True
        conclusion = (f"missing effect: {best['effect']} ({get_effect(best['effect']).title}); with it the error "
                      f"falls from {r0:.2f}x to {best['ratio']:.2f}x the noise")
        if alternatives:
            conclusion += f"; also consistent with the data: {', '.join(alternatives)}"
    else:
        missing, explained = None, False
        conclusion = (f"none of the candidates explains this: the best, {best['effect']}, brings the error from "
                      f"{r0:.2f}x to {best['ratio']:.2f}x the noise but structure remains (an effect outside the "
                      "library, or several at once: add the best one and diagnose again)")
    verdict = {"missing_effect": missing, "explained": bool(explained),
               "best_candidate": best["effect"] if best else None, "alternatives": alternatives,
               "conclusion": conclusion}
    base_table = params_table(baseline)
    noise_rms = float(baseline.noise_rms)
    report = {
        "experiment": exp.name,
        "n_samples": int(data.n),
        "noise_rms": noise_rms,
        "baseline": {"rms": float(baseline.rms), "params": base_table, "ratio": float(r0),
                     "effects": list(base_effects), "bic": float(baseline.bic)},
        "ranking": [{**{k: e[k] for k in ("effect", "rms", "delta_bic", "params", "significant", "ratio",
                                          "explained_fraction", "reading")}, **({"failed": True} if e.get("failed")
                                                                               else {})} for e in ranking],
        "verdict": verdict,
        "data": str(data.path),
        "error_unit": exp.error_unit,
        "noise": {c: float(sigma[c]) for c in exp.channels},
        "baseline_worst_kinds": a["by_kind"][:3],
        "baseline_signatures": a["signatures"][:3],
        "executor": how,
        "at_noise": thr,
    }
    result = OptimizeResult(
        experiment=exp.name, n_samples=data.n, noise=sigma, noise_rms=noise_rms,
        baseline={"rms": float(baseline.rms), "ratio": float(r0), "bic": float(baseline.bic),
                  "params": base_table, "effects": list(base_effects)},
        baseline_fit=baseline, ranking=ranking, fits=fits,
        best_fit=fits[ranking[0]["effect"]] if ranking and not ranking[0].get("failed") else None,
        verdict=verdict, report=report, executor=how, files={}, at_noise=thr,
        success=bool(baseline.success) and all(e["success"] for e in ranking), message=conclusion,
        by_kind=a["by_kind"], signatures=a["signatures"])
    if out is not None:
        out = Path(out)
        out.mkdir(parents=True, exist_ok=True)
        result.files["png"] = str(diagnose_figure(exp, data, result, out / "diagnose.png"))
        result.files["json"] = str(out / "diagnose.json")
        result.files["html"] = str(out / "diagnose_report.html")
        report["files"] = result.files
        Path(result.files["json"]).write_text(json.dumps(report, indent=2))
        from .report import diagnose_report

        diagnose_report(exp, data, result, out)
    return result


def format_diagnose(exp: Experiment, result: OptimizeResult) -> str:
    """Plain-text summary of a diagnosis (what ``femast diagnose`` prints)."""
    f, ul = display_scale(exp.error_unit)
    b = result.baseline
    lines = [f"femast diagnose: {exp.name} on {result.report['data']} ({result.n_samples} samples; refits: "
             f"{result.executor})",
             f"  noise floor {f * result.noise_rms:.4g} {ul}; baseline"
             f"{' + ' + '+'.join(b['effects']) if b['effects'] else ''} RMS {f * b['rms']:.4g} {ul} "
             f"({b['ratio']:.2f}x noise)"]
    if result.by_kind:
        lines.append("  the model fails most in: " + ", ".join(f"{k['kind']} ({k['ratio']:.1f}x)"
                                                          for k in result.by_kind[:3]))
    lines.append(f"  {'rank':>4s}  {'effect':<22s} {'RMS':>10s} {'x noise':>8s} {'dBIC':>9s}  sig  parameters")
    for i, e in enumerate(result.ranking):
        if e.get("failed"):
            lines.append(f"  {i + 1:>4d}  {e['effect']:<22s} {'refit failed':>10s}  {e['reading'][:90]}")
            continue
        ps = ", ".join(f"{k} = {v['value']:.4g}" + (f" +- {v['stderr']:.2g}" if v["stderr"] is not None else "")
                       + f" {v['unit']}" for k, v in e["params"].items())
        lines.append(f"  {i + 1:>4d}  {e['effect']:<22s} {f * e['rms']:>10.4g} {e['ratio']:>8.2f} "
                     f"{e['delta_bic']:>9.1f}  {'yes' if e['significant'] else ' no'}  {ps}")
    if result.ranking:
        lines.append(f"  reading of #1: {result.ranking[0]['reading']}")
    lines.append(f"  verdict: {result.verdict['conclusion']}")
    if result.files:
        lines.append("  wrote " + ", ".join(result.files.values()))
    return "\n".join(lines)
