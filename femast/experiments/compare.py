"""``compare``: run (or fit) a model variant along the measured path and localise where it fails.

:func:`compare` returns a scipy-like result and, given an output folder, writes
``compare.json`` (the report), ``compare.png`` (measured against model, the load path, the
residual with the worst segments shaded) and appends the run to ``history.jsonl`` (plotted
in ``history.png``).
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
from scipy.optimize import OptimizeResult

from .. import progress
from .baseline import fit_with_noise, plain_params, run_variant, score_with_noise
from .core import Experiment, Measured
from .figures import compare_figure, display_scale
from .fitting import fit as _fit
from .fitting import params_table
from .history import append_history, plot_history
from .noise import noise_model
from .residuals import (  # noqa: F401  (principal_load: compare's name for it, kept)
    TURN_FRACTION,
    load_path,
    noise_floor,
    principal_load,
    segment_path,
    segment_report,
    signatures,
    turning_points,
)
from .rows import thin
from .units import check_data as check_units


def analyse(exp: Experiment, data: Measured, run: OptimizeResult) -> dict:
    """Segments, per-kind and worst-segment errors and residual signatures of a model run."""
    s = load_path(exp, data)
    ns = noise_floor(s)
    extra = exp.extra_segments(data, run.params, exp.options) if exp.extra_segments else ()
    segments, masks = segment_path(s, ns, extra)
    weights = {c: exp.weight(c) for c in exp.channels}
    by_kind, worst = segment_report(segments, masks, run.residuals, run.noise, weights, data.lines)
    rng = float(np.ptp(s))
    _, direction = turning_points(s, max(TURN_FRACTION * rng, 5 * ns)) if rng > 0 else (None, np.ones(data.n))
    sig = signatures(s, direction, data.tau, run.residuals, run.noise)
    return {
        "load": s,
        "segments": segments,
        "masks": masks,
        "by_kind": by_kind,
        "worst": worst,
        "signatures": sig,
        "direction": direction,
    }


def compare(
    exp: Experiment,
    data: Measured,
    effects=(),
    *,
    fit: bool = False,
    params=None,
    out=None,
    history: bool = True,
    noise=None,
    sigma=None,
    max_rows: int | None = None,
) -> OptimizeResult:
    """Run the model variant (baseline + ``effects``) along the measured path of ``data``.

    fit : fit the baseline and effect parameters (:func:`~femast.experiments.fitting.fit`);
        otherwise use ``params`` (baseline ``{name: value}`` and ``"effect.param"`` entries, e.g. the
        ``params_table`` of another compare, fitted on other data: fit here, predict there) or the
        defaults.
    sigma : ``{channel: level}`` the sensor uncertainty of channels (their units), e.g. from the
        datasheet; ``sigma_<channel>`` columns give it per row.  Without either, the noise comes from
        repeated rows or, as the fallback, from the residual (:mod:`femast.experiments.noise`).
    noise : ``{channel: level or (n,) levels}`` fixed weights of the fit (overrides the noise model's).
    out : output folder for ``compare.json``, ``compare.png``, ``history.jsonl``, ``history.png`` and
        ``compare_report.html`` (self-contained, figures inlined; nothing is written if None).
        history : append the run to the history file.
    max_rows : above this many rows (default 10 000), every k-th row is used and a DataWarning
        says so (:mod:`femast.experiments.rows`).

    Returns an ``OptimizeResult`` with ``experiment``, ``n_samples``, ``effects``, ``fitted``,
    ``run`` (the model run/fit result), ``params`` (``{name: value}`` of every parameter: the
    baseline's and ``effect.param`` ones -- what ``params=`` of another compare takes: fit here,
    predict there), ``effect_params`` (``{effect: {name: value}}``), ``params_table`` (``{name:
    {value, stderr, unit}}``, the same names; ``params=`` takes it too),
    ``rms`` (error unit), ``channel_rms``, ``noise`` (per channel, (n,) levels), ``noise_model``
    (``{channel: ChannelNoise}``, with its source), ``noise_rms``, ``ratio`` (robust RMS of the
    residual over the noise), ``by_kind`` and ``worst`` (segments, worst first), ``signatures``,
    ``report`` (JSON dict), ``files``, ``version`` (in the history, or None), ``success``, ``message``.
    """
    exp.require_model("compare")
    data = thin(data, max_rows, "compare")  # a long record: every k-th row (femast.experiments.rows)
    check_units(exp, data)  # a unit mistake (mm under an m header) stops here, naming the column
    if isinstance(effects, str):
        effects = [e for e in effects.split(",") if e.strip()]
    effects = list(effects)
    params = plain_params(params)
    for k in params:  # the effects of "effect.param" entries are switched on
        e = k.split(".", 1)[0]
        if "." in k and e not in effects:
            effects.append(e)
    variant = exp.name + "".join(" + " + e for e in effects)
    with progress.task(f"{'fitting' if fit else 'running'} {variant}"):
        if noise is not None:
            run = _fit(exp, data, effects, noise=noise) if fit else run_variant(exp, data, effects, params, noise)
        else:
            run, _ = fit_with_noise(
                exp, data, effects, sigma=sigma, fitted=fit, params=params, start=params if fit and params else None
            )
    if fit and getattr(run, "fe_reference", None) is not None:  # the fit's FE runs answer the zones and figures
        exp = exp.with_options(fe_reference=run.fe_reference)
    models = noise_model(exp, data, run, sigma=sigma)
    sc = score_with_noise(exp, data, run, models)
    run = _judged(run, sc)
    a = analyse(exp, data, run)
    report = {
        "experiment": exp.name,
        "data": str(data.path),
        "n_samples": int(data.n),
        "effects": list(run.effects),
        "fit": bool(fit),
        "params": params_table(run),
        "error_unit": exp.error_unit,
        "rms": run.rms,
        "noise_rms": run.noise_rms,
        "ratio": run.ratio,
        "bic": run.bic,
        "channels": {
            c: {
                "rms": run.channel_rms[c],
                "noise": models[c].sigma_rms,
                "ratio": sc.channel_ratio[c],
                "unit": exp.unit_of(c),
            }
            for c in exp.channels
        },
        "noise_model": {c: models[c].to_json() for c in exp.channels},
        "n_eff": sc.n_eff,
        "segments_by_kind": a["by_kind"],
        "worst_segments": a["worst"][:5],
        "signatures": a["signatures"][:3],
        "message": run.message,
        "success": bool(run.success),
        "at_noise": sc.at_noise,
    }
    files, version = {}, None
    if out is not None:
        out = Path(out)
        out.mkdir(parents=True, exist_ok=True)
        if history:
            version = append_history(
                out,
                {
                    k: report[k]
                    for k in (
                        "experiment",
                        "data",
                        "n_samples",
                        "effects",
                        "fit",
                        "params",
                        "error_unit",
                        "rms",
                        "noise_rms",
                        "ratio",
                        "bic",
                    )
                }
                | {"channel_rms": {c: run.channel_rms[c] for c in exp.channels}},
            )
            report["version"] = version
    result = OptimizeResult(
        experiment=exp.name,
        data=str(data.path),
        n_samples=data.n,
        effects=tuple(run.effects),
        fitted=bool(fit),
        run=run,
        params=dict(zip(run.names, (float(x) for x in run.x))),
        effect_params=run.effect_params,
        params_table=report["params"],
        predicted=run.predicted,
        residuals=run.residuals,
        rms=run.rms,
        channel_rms=run.channel_rms,
        noise=run.noise,
        noise_model=models,
        noise_rms=run.noise_rms,
        ratio=run.ratio,
        channel_ratio=sc.channel_ratio,
        at_noise=sc.at_noise,
        bic=run.bic,
        load=a["load"],
        segments=a["segments"],
        masks=a["masks"],
        by_kind=a["by_kind"],
        worst=a["worst"],
        signatures=a["signatures"],
        report=report,
        files=files,
        version=version,
        success=bool(run.success),
        message=run.message,
        x=run.x,
        stderr=run.stderr,
        names=run.names,
    )
    if out is not None:
        files["json"] = str(out / "compare.json")
        files["png"] = str(compare_figure(exp, data, result, out / "compare.png"))
        if history:
            files["history"] = str(out / "history.jsonl")
            files["history_png"] = str(plot_history(out))
        from .report import compare_report

        files["html"] = str(out / "compare_report.html")  # named in the JSON it inlines nothing of
        report["files"] = files
        Path(files["json"]).write_text(json.dumps(report, indent=2))
        compare_report(exp, data, result, out)
    return result


def _judged(run: OptimizeResult, sc: OptimizeResult) -> OptimizeResult:
    """A shallow copy of a run with the noise, level and ratio of the noise model it is judged by."""
    r = OptimizeResult(dict(run))
    r.noise, r.noise_rms, r.ratio = sc.noise, sc.noise_rms, sc.ratio
    return r


def _fmt(v, unit):
    f, ul = display_scale(unit)
    return f"{f * v:.4g} {ul}"


def format_compare(exp: Experiment, result: OptimizeResult) -> str:
    """Plain-text summary of a compare result (what ``femast compare`` prints)."""
    r = result.report
    lines = [
        f"femast compare: {exp.name} on {result.data} ({result.n_samples} samples)",
        f"  model: {'+'.join(result.effects) or 'baseline'}"
        + (" (parameters fitted)" if result.fitted else " (given parameters, not fitted)"),
    ]
    if result.fitted and not result.success:
        lines.append(f"  warning: the fit did not converge: {result.message}")
    for name, p in r["params"].items():
        se = f" +- {p['stderr']:.3g}" if p["stderr"] is not None and result.fitted else ""
        lines.append(f"    {name:>22s} = {p['value']:.6g}{se} {p['unit']}")
    if exp.one_scale:
        lines.append(
            f"  overall RMS error {_fmt(result.rms, exp.error_unit)}; noise floor "
            f"{_fmt(result.noise_rms, exp.error_unit)} -> {result.ratio:.2f}x noise"
        )
    else:  # channels of different units: each against its own noise (below)
        lines.append(f"  overall: {result.ratio:.2f}x the noise (each channel's error over its own noise)")
    for c in exp.channels:
        u = exp.unit_of(c)
        m = result.noise_model[c]
        lines.append(
            f"    {c:>8s}: RMS {_fmt(result.channel_rms[c], u)}, noise {_fmt(m.sigma_rms, u)} from "
            f"{m.source} ({result.channel_ratio[c]:.2f}x)"
        )
        if m.disagree:
            lines.append(
                f"    {'':>8s}  noise sources disagree: " + ", ".join(f"{k} {_fmt(v, u)}" for k, v in m.levels.items())
            )
    lines.append("  error by kind of segment (x noise):")
    for k in result.by_kind:
        lines.append(f"    {k['kind']:>30s}: {k['ratio']:6.2f}x  ({k['n']} samples)")
    lines.append("  worst segments:")
    for k, s in enumerate(result.worst[:5]):
        lines.append(
            f"    #{k + 1} {s['kind']:>28s}: rows {s['start_row']}-{s['end_row']} (file lines "
            f"{s.get('first_line', '?')}-{s.get('last_line', '?')}), {s['ratio']:.2f}x noise, RMS "
            f"{_fmt(s['rms'], exp.error_unit)}"
        )
    at = r.get("at_noise", 1.2)
    if result.ratio > at and result.signatures and result.signatures[0]["fraction"] > 0.2:
        sg = result.signatures[0]
        lines.append(f"  reading: {100 * sg['fraction']:.0f} % of the excess error is {sg['reading']}")
    elif result.ratio <= at:
        lines.append("  reading: the model is at the noise floor")
    if result.files:
        lines.append("  wrote " + ", ".join(result.files.values()))
    return "\n".join(lines)
