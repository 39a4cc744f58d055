"""Figures of ``compare`` and ``diagnose`` (matplotlib, Agg backend, PNG), in the style of
:mod:`femast.post.plotstyle`."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..post import plotstyle
from ..post.plotstyle import column_label, display_scale, fit_title, num  # noqa: F401  (display_scale: re-exported)
from .residuals import AT_NOISE


def verdict_words(v: dict) -> str:
    """The verdict as the command line says it: its conclusion up to the first ';' (the figures' title)."""
    text = (v.get("conclusion") or "").split(";")[0].strip()
    return text or "none of the candidates explains this"


def _load_label(label: str, load):
    """(label, factor) of the load panel: a label ending in an SI unit ("force (N)") shown in the unit
    that suits the load's size ("force (kN)")."""
    head, sep, unit = label.rpartition(" (")
    if sep and unit.endswith(")"):
        f, ul = display_scale(unit[:-1], load)
        return f"{head} ({ul})", f
    return label, 1.0


def _shade(color, amount: float):
    """``color`` mixed with white (``amount`` > 0) or black (< 0) by ``|amount|`` (0: unchanged)."""
    from matplotlib.colors import to_rgb

    rgb = np.asarray(to_rgb(color))
    target = 1.0 if amount > 0 else 0.0
    return tuple(rgb + abs(amount) * (target - rgb))


def _plt():
    return plotstyle.pyplot()


def _scales(exp, arrays: dict) -> dict:
    """(factor, unit label) per channel of ``arrays`` (channel -> values): channels of one SI unit
    share the unit that suits the largest of their values (70 um, 20 mm, 0.6 arcsec)."""
    by_unit = {}
    for c, v in arrays.items():
        by_unit.setdefault(exp.unit_of(c), []).append(np.ravel(np.asarray(v, dtype=float)))
    scale = {u: display_scale(u, np.concatenate(vs)) for u, vs in by_unit.items()}
    return {c: scale[exp.unit_of(c)] for c in arrays}


def _common_unit(scales: dict):
    """The display unit shared by every channel of ``scales`` (None if they differ)."""
    units = {ul for _, ul in scales.values()}
    return units.pop() if len(units) == 1 else None


def compare_figure(exp, data, result, png) -> Path:
    """Measured against model, the load path with its segments, and the residual along the path with
    the worst segments shaded."""
    plt = _plt()
    png = Path(png)
    rows = np.arange(data.n)
    fig = plt.figure(figsize=(12, 9.5))
    gs = fig.add_gridspec(3, 2, height_ratios=[1.35, 0.6, 1.0], width_ratios=[1, 1.6])
    ax0 = fig.add_subplot(gs[0, 0])
    ax1 = fig.add_subplot(gs[0, 1])
    ax2 = fig.add_subplot(gs[1, :])
    ax3 = fig.add_subplot(gs[2, :], sharex=ax2)
    pred = result.predicted
    shown = _scales(exp, {c: np.concatenate([np.ravel(data[c]), np.ravel(pred[c])]) for c in exp.channels})
    errors = _scales(
        exp, {c: np.concatenate([np.ravel(result.residuals[c]), np.ravel(result.noise[c])]) for c in exp.channels}
    )
    if exp.plot_measured:
        exp.plot_measured(ax0, data, pred, result.params, exp.options)
    else:
        c = exp.channels[0]
        f, ul = shown[c]
        ax0.plot(f * data[c], f * pred[c], ".", ms=3)
        lim = [f * min(data[c].min(), pred[c].min()), f * max(data[c].max(), pred[c].max())]
        ax0.plot(lim, lim, "k--", lw=0.8)
        ax0.set_xlabel("measured " + column_label(c, ul))
        ax0.set_ylabel("model " + column_label(c, ul))
    for i, c in enumerate(exp.channels):  # measured light, model dark: one hue per channel
        f, ul = shown[c]
        ax1.plot(rows, f * data[c], ".", ms=2 if data.n > 500 else 5, color=_shade(f"C{i}", 0.55), zorder=1)
        ax1.plot(rows, f * pred[c], "-", lw=1.1, color=_shade(f"C{i}", -0.45), label=column_label(c, ul), zorder=2)
    ax1.set_title("measured (light dots) and model (dark lines) along the path")
    ax1.set_xlabel("data row (time order)")
    uc = _common_unit(shown)
    ax1.set_ylabel(f"measured and model ({uc})" if uc else "measured and model (unit: legend)")
    ax1.legend(ncol=min(3, len(exp.channels)))
    lab, fl = _load_label(exp.load_label, result.load)
    s = fl * np.asarray(result.load, dtype=float)
    ax2.plot(rows, s, "-", color="0.3", lw=1.0)
    for kind, color in (("near-zero load", "C1"), ("reversal", "C4"), ("peak", "C2")):
        m = result.masks.get(kind)
        if m is not None and m.any():
            ax2.plot(rows[m], s[m], ".", ms=3, color=color, label=kind)
    ax2.set_ylabel(lab.replace(" (", "\n(", 1) if len(lab) > 24 else lab)  # a long label on two lines
    ax2.set_title("load along the path, segments marked", loc="left")
    if ax2.get_legend_handles_labels()[0]:  # a path with no marked rows has no legend; above the axes, off the data
        ax2.legend(ncol=3, loc="lower right", bbox_to_anchor=(1.0, 1.0), fontsize=8, frameon=False)
    for i, c in enumerate(exp.channels):
        f, ul = errors[c]
        ax3.plot(rows, f * result.residuals[c], "-", lw=0.8, color=f"C{i}", label=column_label(c, ul))
        if np.ndim(result.noise[c]):  # per-row noise (heteroscedastic model)
            ax3.plot(rows, f * result.noise[c], color=f"C{i}", ls=":", lw=0.7)
            ax3.plot(rows, -f * result.noise[c], color=f"C{i}", ls=":", lw=0.7)
        else:
            ax3.axhline(f * result.noise[c], color=f"C{i}", ls=":", lw=0.7)
            ax3.axhline(-f * result.noise[c], color=f"C{i}", ls=":", lw=0.7)
    worst = []  # shaded and numbered on the axes, named in the legend below them (labels never pile up)
    for k, seg in enumerate([w for w in result.worst[:3] if w["ratio"] > AT_NOISE]):
        worst.append(
            ax3.axvspan(
                seg["start_row"] - 0.5,
                seg["end_row"] + 0.5,
                color="C3",
                alpha=0.18 - 0.04 * k,
                lw=0,
                label=f"#{k + 1} {seg['kind']}, {seg['ratio']:.1f}x noise",
            )
        )
        ax3.text(
            0.5 * (seg["start_row"] + seg["end_row"]),
            0.98 - 0.08 * k,
            f"#{k + 1}",
            transform=ax3.get_xaxis_transform(),
            ha="center",
            va="top",
            fontsize=8,
            color="C3",
            clip_on=True,
            bbox=dict(boxstyle="round,pad=0.1", fc="white", ec="none", alpha=0.8),
        )
    ax3.set_xlabel("data row (time order)")
    ue = _common_unit(errors)
    ax3.set_ylabel(f"residual, measured - model ({ue})" if ue else "residual, measured - model (unit: legend)")
    ax3.set_title(
        fit_title(
            ax3,
            f"residual (dotted: noise floor); worst segments above {num(AT_NOISE)}x noise "
            f"shaded; RMS {num(result.ratio)}x noise",
        )
    )
    handles, _ = ax3.get_legend_handles_labels()
    plotstyle.legend_below(ax3, ncol=min(3, len(handles)), fontsize=8)
    eff = "+".join(result.effects) or "baseline"
    fig.suptitle(
        fit_title(
            fig,
            f"femast compare {exp.name} -- {Path(str(data.path).split()[-1]).name} -- model: "
            f"{eff}" + (" (fitted)" if result.fitted else " (given parameters)"),
            11.5,
        )
    )
    return plotstyle.save(fig, png, dpi=100)


def diagnose_figure(exp, data, result, png) -> Path:
    """Error of the baseline and of each candidate effect and pair over the noise (bars; the verdict's
    ratio: each channel's error over its own noise, so channels of different units -- m and rad --
    are never added), and the residual of the baseline and of the best candidate along the path."""
    from .verdict import pair_beats_members

    plt = _plt()
    png = Path(png)
    # (label, ratio to the noise, dBIC, green, failed, held-out ratio)
    entries = (
        [("baseline", result.baseline["ratio"], None, False, False, result.baseline.get("heldout_ratio"))]
        + [
            (
                r["effect"]
                + (f" ({r['form']})" if r.get("form") else "")
                + (", screened out" if r.get("screened") else ""),
                r.get("ratio"),
                r["delta_bic"],
                r["significant"],
                bool(r.get("failed")),
                r.get("heldout_ratio"),
            )
            for r in result.ranking
        ]
        + [
            (" + ".join(p["effects"]), p["ratio"], p["delta_bic"], pair_beats_members(p), False, p.get("heldout_ratio"))
            for p in (getattr(result, "pairs", None) or [])[:3]
        ]
    )
    fig, (ax0, ax1) = plt.subplots(
        1, 2, figsize=(13, max(4.0, 0.45 * len(entries) + 2)), gridspec_kw={"width_ratios": [1, 1.3]}
    )
    y = np.arange(len(entries))[::-1]
    colors = ["C0"] + [("C2" if e[3] else "0.65") for e in entries[1:]]
    ok = [not e[4] for e in entries]  # a refit that failed has no error to draw: it is named, not a bar
    ax0.barh(y[ok], [e[1] for e, k in zip(entries, ok) if k], color=[c for c, k in zip(colors, ok) if k])
    ax0.set_yticks(y)
    ax0.set_yticklabels([e[0] for e in entries], fontsize=9)
    ho = [(yy, e[5]) for yy, e in zip(y, entries) if e[5] is not None and np.isfinite(e[5])]
    if ho:  # held-out error: on data the fit has not seen, over the same noise
        ax0.plot([r for _, r in ho], [yy for yy, _ in ho], "kx", ms=7, label="held out (data the fit has not seen)")
    ax0.axvline(1.0, color="k", ls="--", lw=1, label="noise floor (1x)")
    ax0.axvline(
        result.at_noise, color="k", ls=":", lw=1, label=f"at-noise threshold, {num(result.at_noise, 2)} x noise"
    )
    right = max([e[1] for e, k in zip(entries, ok) if k] + [r for _, r in ho] + [1.0, result.at_noise])
    for yy, e in zip(y, entries):
        if e[4]:
            ax0.text(0.0, yy, "  refit failed", va="center", fontsize=8, color="C3")
        elif e[2] is not None:  # right of every bar, marker and line: never over the noise lines
            ax0.text(right, yy, f"  dBIC {e[2]:+.0f}", va="center", fontsize=8)
    ax0.set_xlabel("RMS error / noise after refit (each channel over its own noise, -)")
    ax0.set_xlim(0, 1.45 * right)
    v = result.verdict
    ax0.set_title(
        fit_title(
            ax0,
            f"{exp.name}: refit with each candidate and pair (green: significant, better held out; a pair: "
            f"better than its best member); verdict: {verdict_words(v)}",
        )
    )
    plotstyle.legend_below(ax0, ncol=2, fontsize=8)
    rows = np.arange(data.n)
    zb = np.asarray(getattr(result, "baseline_z", result.baseline_fit.fun)).reshape(len(exp.channels), -1)
    ax1.plot(rows, np.sqrt((zb**2).mean(0)), "-", lw=0.8, color="C0", label="baseline")
    if result.best_fit is not None:
        zc = np.concatenate(
            [result.best_fit.residuals[c] / np.broadcast_to(result.noise[c], (data.n,)) for c in exp.channels]
        ).reshape(len(exp.channels), -1)
        label = (
            " + ".join(v.get("missing_effects") or [])
            if len(v.get("missing_effects") or []) == 2
            else result.ranking[0]["effect"]
        )
        ax1.plot(rows, np.sqrt((zc**2).mean(0)), "-", lw=0.8, color="C2", label=f"with {label}")
    ax1.axhline(1.0, color="k", ls="--", lw=0.8)
    ax1.set_xlabel("data row (time order)")
    ax1.set_ylabel("|residual| / noise, RMS over channels (-)")
    ax1.set_title("residual along the path")
    ax1.legend()
    return plotstyle.save(fig, png, dpi=100)
