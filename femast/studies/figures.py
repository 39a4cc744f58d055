"""Figures of a study: the distribution of each output with its percentiles and their
confidence intervals, the convergence of the estimates with the number of samples, and the
Sobol' indices as a bar chart.  Values in SI units (the axis says which)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..post import plotstyle
from .statistics import convergence, percentile, sobol_convergence

MAX_PANELS = 6
_Q = (0.05, 0.5, 0.95, 0.99)


def _label(name, idx):
    return name + (str(list(idx)) if idx else "")


def _series(res, rep):
    """[(label, values, unit)] of the scalar output components that vary (first MAX_PANELS)."""
    out = []
    shapes = res.store.shapes
    for name in res.output_names:
        v = res.output(name, blocks=("A", "B") if res.sensitivity else ("A",))
        if len(v) < 2:
            continue
        shp = shapes.get(name, ())
        for idx in [()] if not shp else list(np.ndindex(*shp)):
            if np.ptp(v[(slice(None),) + idx]) == 0.0:  # the same in every sample (e.g. a reference step)
                continue
            out.append((res.component_label(name, idx), v[(slice(None),) + idx], res.units.get(name, "")))
            if len(out) >= MAX_PANELS:
                return out
    return out


def distribution_figure(series, png):
    """Histograms of ``series`` [(label, values, unit)] with the 5/50/95/99 % percentiles and their 95 %
    intervals (shaded)."""
    plt = plotstyle.pyplot()
    n = len(series)
    cols = min(n, 3)
    rows = (n + cols - 1) // cols
    fig, axes = plt.subplots(rows, cols, figsize=(4.2 * cols, 3.2 * rows), squeeze=False)
    for ax, (label, x, unit) in zip(axes.ravel(), series):
        ax.hist(x, bins=min(60, max(10, int(np.sqrt(len(x))))), color="0.75", edgecolor="0.5")
        for q, c in zip(_Q, ("C0", "C1", "C2", "C3")):
            p = percentile(x, q)
            ax.axvline(p["estimate"], color=c, lw=1.2, label=f"{q * 100:g} %: {plotstyle.num(p['estimate'])}")
            if np.isfinite(p["low"]) and np.isfinite(p["high"]):
                ax.axvspan(p["low"], p["high"], color=c, alpha=0.15)
        ax.set_xlabel(plotstyle.axis_label(label, unit))
        ax.set_ylabel("samples")
        ax.set_title(plotstyle.fit_title(ax, f"{label}: {len(x)} samples"))
        ax.legend(loc="best", fontsize=7.5)
    for ax in axes.ravel()[n:]:
        ax.set_visible(False)
    fig.tight_layout()
    return plotstyle.save(fig, png)


def convergence_figure(series, png):
    """Mean and 95 % percentile of each series against the number of samples, with their 95 %
    intervals."""
    plt = plotstyle.pyplot()
    n = len(series)
    cols = min(n, 3)
    rows = (n + cols - 1) // cols
    fig, axes = plt.subplots(rows, cols, figsize=(4.2 * cols, 3.2 * rows), squeeze=False)
    for ax, (label, x, unit) in zip(axes.ravel(), series):
        c = convergence(x, q=(0.95,))
        for key, col, txt in (("mean", "C0", "mean"), ("q0.95", "C2", "95 % percentile")):
            e = c[key]
            ax.plot(c["n"], e[:, 0], "o-", color=col, ms=3, label=txt)
            ax.fill_between(c["n"], e[:, 1], e[:, 2], color=col, alpha=0.2)
        ax.set_xscale("log", base=2)
        ax.set_xlabel("samples n")
        ax.set_ylabel(plotstyle.axis_label(label, unit))
        ax.set_title(plotstyle.fit_title(ax, f"{label}: estimate and 95 % interval"))
        ax.legend(loc="best")
    for ax in axes.ravel()[n:]:
        ax.set_visible(False)
    fig.tight_layout()
    return plotstyle.save(fig, png)


def sensitivity_figure(sobol: dict, png):
    """Bars of first-order (S1) and total (ST) indices with their bootstrap 95 % intervals, one
    panel per output component; ``sobol`` is {(name, idx): sobol_indices result}."""
    plt = plotstyle.pyplot()
    items = list(sobol.items())[:MAX_PANELS]
    n = len(items)
    cols = min(n, 3)
    rows = (n + cols - 1) // cols
    fig, axes = plt.subplots(rows, cols, figsize=(4.2 * cols, 3.2 * rows), squeeze=False)
    for ax, ((name, idx), s) in zip(axes.ravel(), items):
        k = len(s["names"])
        x = np.arange(k)
        for off, key, col, txt in ((-0.2, "S1", "C0", "first order S1"), (0.2, "ST", "C3", "total ST")):
            v = np.asarray(s[key])
            err = np.vstack([np.maximum(v - s[key + "_low"], 0), np.maximum(s[key + "_high"] - v, 0)])
            ax.bar(x + off, v, 0.38, color=col, yerr=err, capsize=3, label=txt)
        ax.set_xticks(x, s["names"], rotation=30 if k > 4 else 0)
        ax.axhline(0, color="0.3", lw=0.8)
        ax.set_ylabel("Sobol' index (1)")
        ax.set_title(plotstyle.fit_title(ax, f"{s.get('label', _label(name, idx))}: {s['n']} base samples"))
        ax.legend(loc="best")
    for ax in axes.ravel()[n:]:
        ax.set_visible(False)
    fig.tight_layout()
    return plotstyle.save(fig, png)


def sensitivity_convergence_figure(conv: dict, names, png, title=""):
    """S1 (dashed) and ST (solid) of each input against the number of base samples."""
    plt = plotstyle.pyplot()
    fig, ax = plt.subplots(figsize=(5.2, 3.6))
    for i, nm in enumerate(names):
        ax.plot(conv["n"], conv["ST"][:, i], "o-", ms=3, color=f"C{i}", label=f"{nm}: ST")
        ax.plot(conv["n"], conv["S1"][:, i], "s--", ms=3, color=f"C{i}", alpha=0.7, label=f"{nm}: S1")
    ax.set_xscale("log", base=2)
    ax.set_xlabel("base samples n")
    ax.set_ylabel("Sobol' index (1)")
    ax.axhline(0, color="0.3", lw=0.8)
    ax.set_title(plotstyle.fit_title(ax, title or "convergence of the indices"))
    ax.legend(loc="best", fontsize=7, ncol=2)
    fig.tight_layout()
    return plotstyle.save(fig, png)


def study_figures(res, rep=None) -> list:
    """Write the study's figures into ``<folder>/figures``; returns their paths."""
    folder = Path(res.folder) / "figures"
    series = _series(res, rep)
    pngs = []
    if series:
        pngs.append(distribution_figure(series, folder / "distributions.png"))
        pngs.append(convergence_figure(series, folder / "convergence.png"))
    if rep and rep.get("sobol"):
        pngs.append(sensitivity_figure(rep["sobol"], folder / "sensitivity.png"))
        (name, idx), s = next(iter(rep["sobol"].items()))
        fA, fB, fAB, _ = res.saltelli(name)
        sl = (slice(None),) + idx
        conv = sobol_convergence(fA[sl], fB[sl], fAB[(slice(None),) + sl])
        pngs.append(
            sensitivity_convergence_figure(
                conv, s["names"], folder / "sensitivity_convergence.png", f"{s.get('label', name)}: indices against n"
            )
        )
    return pngs
