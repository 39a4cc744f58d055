"""The report stage of ``diagnose``: the result, ``diagnose.json``, ``diagnose.png``, the HTML report
and the text summary ``femast diagnose`` prints (:func:`format_diagnose`)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
from scipy.optimize import OptimizeResult

from .core import Experiment
from .figures import diagnose_figure, display_scale
from .fitting import params_table
from .residuals import robust_rms
from .verdict import pair_beats_members

#: the fields of a ranking entry in the JSON report
PUBLIC = (
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
    "heldout_ratio",
    "heldout_ok",
    "skipped",
    "screened",
)


def diagnosis_result(d, out=None) -> OptimizeResult:
    """The result of a diagnosis (see :func:`~femast.experiments.diagnose.diagnose`), its files
    written to ``out``."""
    exp, data, chans = d.exp, d.data, d.channels
    sigma_w = d.weights
    base_table = params_table(d.baseline)
    baseline = {
        "rms": float(d.baseline.rms),
        "params": base_table,
        "ratio": float(d.s0["ratio"]),
        "effects": list(d.base_effects),
        "bic": float(d.s0["ic"]),
        "heldout_ratio": d.heldout_ratio,
    }
    pairs_json = [{k: v for k, v in p.items() if not k.startswith("_")} for p in d.pairs]
    report = {
        "experiment": exp.name,
        "n_samples": int(data.n),
        "noise_rms": d.noise_rms,
        "baseline": baseline,
        "ranking": [
            {**{k: e[k] for k in PUBLIC if k in e}, **({"failed": True} if e.get("failed") else {})} for e in d.ranking
        ],
        "verdict": d.verdict,
        "data": str(data.path),
        "error_unit": exp.error_unit,
        "noise": {c: float(np.sqrt(np.mean(sigma_w[c] ** 2))) for c in chans},
        "noise_model": {c: d.models[c].to_json() for c in chans},
        "n_eff": float(d.n_eff),
        "pairs": pairs_json,
        "form_check": d.form_check,
        "baseline_worst_kinds": d.analysis["by_kind"][:3],
        "baseline_signatures": d.analysis["signatures"][:3],
        "executor": d.how,
        "at_noise": d.thr,
        "untimed": list(d.untimed),
    }
    v = d.verdict
    best_fit = None
    if len(v.get("missing_effects") or []) == 2:  # a pair found (at the noise or with its forms imperfect)
        best_fit = next((p["_fit"] for p in d.pairs if p["effects"] == v["missing_effects"]), None)
    elif d.ranking and not d.ranking[0].get("failed") and not d.ranking[0].get("screened"):
        best_fit = d.fits[d.ranking[0]["effect"]]
    result = OptimizeResult(
        experiment=exp.name,
        n_samples=data.n,
        noise=sigma_w,
        noise_model=d.models,
        noise_rms=d.noise_rms,
        baseline={k: baseline[k] for k in ("rms", "ratio", "bic", "params", "effects", "heldout_ratio")},
        baseline_fit=d.baseline,
        baseline_z=d.s0["z"],
        ranking=d.ranking,
        fits=d.fits,
        pairs=d.pairs,
        form_check=d.form_check,
        best_fit=best_fit,
        verdict=v,
        report=report,
        executor=d.how,
        files={},
        at_noise=d.thr,
        n_eff=d.n_eff,
        untimed=list(d.untimed),
        success=bool(d.baseline.success) and all(e["success"] for e in d.ranking),
        message=v["conclusion"],
        by_kind=d.analysis["by_kind"],
        signatures=d.analysis["signatures"],
    )
    if out is not None:
        out = Path(out)
        out.mkdir(parents=True, exist_ok=True)
        png = out / "diagnose.png"
        diagnose_figure(exp, data, result, png)
        result.files["png"] = str(png)
        result.files["json"] = str(out / "diagnose.json")
        result.files["html"] = str(out / "diagnose_report.html")
        report["files"] = result.files
        Path(result.files["json"]).write_text(json.dumps(report, indent=2))
        from .report import diagnose_report

        diagnose_report(exp, data, result, out)
    return result


def _ho(ratio, prefix: str = "") -> str:
    """A held-out ratio for the text report ("" / "-" where none was computed)."""
    if ratio is None or not np.isfinite(ratio):
        return "" if prefix else "-"
    return f"{prefix}{ratio:.2f}" + ("x" if prefix else "")


def format_diagnose(exp: Experiment, result: OptimizeResult) -> str:
    """Plain-text summary of a diagnosis (what ``femast diagnose`` prints)."""
    f, ul = display_scale(exp.error_unit)
    b = result.baseline
    lines = [
        f"femast diagnose: {exp.name} on {result.report['data']} ({result.n_samples} samples; refits: "
        f"{result.executor})",
    ]
    named = f"baseline{' + ' + '+'.join(b['effects']) if b['effects'] else ''}"
    if exp.one_scale:  # every channel in the error unit: one RMS and one noise floor say it
        lines.append(
            f"  noise floor {f * result.noise_rms:.4g} {ul}; {named} RMS {f * b['rms']:.4g} {ul} "
            f"({b['ratio']:.2f}x noise{_ho(b.get('heldout_ratio'), '; held out ')})"
        )
    else:  # channels of different units (m and rad) or weights: each against its own noise
        lines.append(
            f"  {named}: {b['ratio']:.2f}x the noise (each channel's error over its own noise"
            f"{_ho(b.get('heldout_ratio'), '; held out ')})"
        )
        for c in exp.channels:
            r, s = np.asarray(result.baseline_fit.residuals[c], float), np.asarray(result.noise[c], float)
            fc, uc = display_scale(exp.unit_of(c), np.abs(r))
            lines.append(
                f"    {c}: RMS error {fc * np.sqrt(np.mean(r**2)):.4g} {uc}, noise {fc * np.sqrt(np.mean(s**2)):.4g} "
                f"{uc} ({robust_rms(r / s):.2f}x)"
            )
    if result.by_kind:
        lines.append(
            "  the model fails most in: " + ", ".join(f"{k['kind']} ({k['ratio']:.1f}x)" for k in result.by_kind[:3])
        )
    nm = getattr(result, "noise_model", None) or {}
    for c, m in nm.items():
        fc, uc = display_scale(exp.unit_of(c))
        lines.append(f"  noise of {c}: {fc * m.sigma_rms:.4g} {uc} from {m.source} ({m.kind}) -- {m.reason}")
        if m.disagree:
            lines.append(
                "    the sources disagree: " + ", ".join(f"{k} {fc * v:.4g} {uc}" for k, v in m.levels.items())
            )
    # channels of different units (m and rad) have no pooled RMS: each is over its own noise (x noise)
    rms_of = (lambda r: f"{f * r:>10.4g}") if exp.one_scale else (lambda r: f"{'-':>10s}")
    lines.append(
        f"  {'rank':>4s}  {'effect':<22s} {'form':<10s} {'RMS':>10s} {'x noise':>8s} "
        f"{'held out':>8s} {'dBIC':>9s} {'share':>6s}  sig  parameters"
    )
    for i, e in enumerate(result.ranking):
        if e.get("failed"):
            lines.append(f"  {i + 1:>4d}  {e['effect']:<22s} {'refit failed':>10s}  {e['reading'][:90]}")
            continue
        ps = ", ".join(
            f"{k} = {v['value']:.4g}" + (f" +- {v['stderr']:.2g}" if v["stderr"] is not None else "") + f" {v['unit']}"
            for k, v in e["params"].items()
        )
        if e.get("screened"):
            ps = "screened out: not refitted in full (its reading says why)"
        lines.append(
            f"  {i + 1:>4d}  {e['effect']:<22s} {e.get('form') or '-':<10s} {rms_of(e['rms'])} "
            f"{e['ratio']:>8.2f} {_ho(e.get('heldout_ratio')):>8s} {e['delta_bic']:>9.1f} "
            f"{100 * e['explained_fraction']:>5.0f}%  "
            f"{'yes' if e['significant'] else ' no'}  {ps}"
        )
    for p in (getattr(result, "pairs", None) or [])[:3]:
        lines.append(
            f"  pair  {' + '.join(p['effects']):<33s} {rms_of(p['rms'])} {p['ratio']:>8.2f} "
            f"{_ho(p.get('heldout_ratio')):>8s} {p['delta_bic']:>9.1f} {100 * p['explained_fraction']:>5.0f}%  "
            f"{'yes' if pair_beats_members(p) else ' no'}"
        )
    for fc in getattr(result, "form_check", None) or []:
        lines.append(
            f"  form check of the added {fc['effect']}: form {fc['form']} {fc['ratio']:.2f}x noise, dBIC "
            f"{fc['delta_bic']:+.1f}{' (significant)' if fc['significant'] else ''}"
        )
    if getattr(result, "untimed", None):
        lines.append(
            f"  not tried: {', '.join(result.untimed)} (a law in time; the data have no t_s column, and on this "
            "rig the row number follows the load path, not the clock: add t_s, or name it with --candidates)"
        )
    if result.ranking:
        lines.append(f"  reading of #1: {result.ranking[0]['reading']}")
    lines.append(f"  verdict: {result.verdict['conclusion']}")
    if result.files:
        lines.append("  wrote " + ", ".join(result.files.values()))
    return "\n".join(lines)
