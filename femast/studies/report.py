"""The end-of-study report: percentiles with their intervals for every output (each
component of an array output), Sobol' indices when the study has them, and the figures
(:mod:`femast.studies.figures`)."""

from __future__ import annotations

import numpy as np

from .results import load
from .statistics import percentile, sobol_indices

QUANTILES = (0.05, 0.5, 0.95, 0.99)
MAX_COMPONENTS = 30  # components of an array output listed in the table and given indices


def _components(shape):
    return [()] if not shape else list(np.ndindex(*shape))


def summary_rows(res, quantiles=QUANTILES, confidence=0.95) -> list:
    """[(label, n, {q: percentile dict}, unit)] for every output component (first MAX_COMPONENTS;
    a last row says how many more there are)."""
    rows = []
    shapes = res.store.shapes
    for name in res.output_names:
        v = res.output(name, blocks=("A", "B") if res.sensitivity else ("A",))
        if len(v) == 0:
            rows.append((name, 0, {}, res.units.get(name, "")))
            continue
        comps = _components(shapes.get(name, ()))
        for idx in comps[:MAX_COMPONENTS]:
            x = v[(slice(None),) + idx]
            rows.append(
                (
                    res.component_label(name, idx),
                    len(x),
                    {q: percentile(x, q, confidence) for q in quantiles},
                    res.units.get(name, ""),
                )
            )
        if len(comps) > MAX_COMPONENTS:
            rows.append((f"{name}: {len(comps) - MAX_COMPONENTS} more components", 0, None, ""))
    return rows


def format_rows(rows) -> str:
    lines = [
        f"{'output':<24} {'unit':<6} {'n':>6} " + " ".join(f"{format(q * 100, 'g') + ' %':>30}" for q in QUANTILES)
    ]
    for label, n, ps, unit in rows:
        if ps is None:
            lines.append(f"({label}: femast.studies.load(FOLDER).output(NAME) has them all)")
            continue
        if not ps:
            lines.append(f"{label:<24} {unit or '-':<6} {n:>6}  (no successful sample)")
            continue
        cells = [f"{p['estimate']:.4g} [{p['low']:.4g}, {p['high']:.4g}]" for p in ps.values()]
        lines.append(f"{label:<24} {unit or '-':<6} {n:>6} " + " ".join(f"{c:>30}" for c in cells))
    return "\n".join(lines)


def report(folder, print_table: bool = True, figures: bool = True) -> dict:
    """Print the percentiles table (estimate [95 % interval], SI units) and, with sensitivity, the
    indices of each scalar output component (first MAX_COMPONENTS); write the figures into
    ``folder``/figures.  Returns {'rows', 'sobol', 'figures'}."""
    res = load(folder)
    rows = summary_rows(res)
    out = {"rows": rows, "sobol": {}, "figures": []}
    if print_table:
        print(
            "percentiles: estimate [95 % confidence interval] (samples of blocks A"
            + (" and B)" if res.sensitivity else ")")
            + "; NaN: too few samples for that bound"
        )
        print(format_rows(rows))
    if res.sensitivity:
        shapes = res.store.shapes
        for name in res.output_names:
            fA, fB, fAB, dropped = res.saltelli(name)
            if len(fA) < 2:
                continue
            scale = np.max(np.abs(np.concatenate([fA.ravel(), fB.ravel()]))) if fA.size else 0.0
            for idx in _components(shapes.get(name, ()))[:MAX_COMPONENTS]:
                sl = (slice(None),) + idx
                lab = res.component_label(name, idx)
                if np.std(np.concatenate([fA[sl], fB[sl]])) <= 1e-9 * scale:
                    if print_table:
                        print(
                            f"sensitivity of {lab}: does not vary beyond round-off "
                            f"(1e-9 of the output's largest value); no indices"
                        )
                    continue
                try:
                    s = sobol_indices(fA[sl], fB[sl], fAB[(slice(None),) + sl], names=res.input_names)
                except Exception as exc:  # a constant component has no indices
                    if print_table:
                        print(f"sensitivity of {lab}: {exc}")
                    continue
                s["dropped"] = dropped
                s["label"] = lab
                out["sobol"][(name, idx)] = s
                if print_table:
                    print(
                        f"sensitivity of {lab} ({s['n']} complete samples"
                        + (f", {dropped} left out: a run failed" if dropped else "")
                        + "):"
                    )
                    for i, nm in enumerate(s["names"]):
                        print(
                            f"  {nm:<20} S1 = {s['S1'][i]:6.3f} [{s['S1_low'][i]:6.3f}, {s['S1_high'][i]:6.3f}]"
                            f"   ST = {s['ST'][i]:6.3f} [{s['ST_low'][i]:6.3f}, {s['ST_high'][i]:6.3f}]"
                        )
    if figures:
        from .figures import study_figures

        out["figures"] = study_figures(res, out)
        if print_table and out["figures"]:
            print("figures: " + ", ".join(str(f) for f in out["figures"]))
    return out
