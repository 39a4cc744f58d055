"""Does ``femast diagnose`` hold on data it has never seen?

Runs ``diagnose`` on every case of :mod:`generalisation.cases` -- mast-top and latch-pull data
made by an independent generator (``benchmarks/generalisation/``, numpy only, no femast code)
whose mechanisms are written in other functional forms than femast's effects (Dahl, Bouc-Wen,
Jenkins friction; tanh, Hertz, piecewise-linear clearance; cubic and asinh stiffening;
zero-closing cable loops; creep and slip pretension loss; Timoshenko and stepped beams;
Gaussian, linear and Lorentzian latch bands; ...), under white, heteroscedastic (Stohlman & Pellegrino
Eq. 15) and AR(1) noise, with pairs of mechanisms, out-of-library mechanisms and 20 noise
redraws of each null case -- then prints a confusion table and the score, writes figures and a
JSON of per-run results to ``benchmarks/out/diagnose_generalisation/``.

Scoring rule
------------
Each run's diagnose report is read as a verdict: ``missing`` X ("missing effect: X"),
``form_imperfect`` X ("mechanism found, form imperfect"), ``not_explained``, or ``nothing``
("nothing is missing") (adapter :func:`generalisation.scoring.read_verdict`: structured fields
when the report has them, else the conclusion text).

* single-mechanism case X: right iff the verdict is ``missing`` or ``form_imperfect`` naming X
  alone;
* two-mechanism case {X, Y}: right iff the verdict is ``missing`` or ``form_imperfect`` naming
  exactly {X, Y};
* out-of-library case: right iff the verdict is ``not_explained`` or ``form_imperfect`` (no
  "missing effect" claim, no "nothing is missing");
* null redraw: right iff the verdict is ``nothing``; anything else is a false alarm.

``score`` = (right non-null cases + sum over null cases of the fraction of their redraws that are
right) / (non-null cases + null cases): each null case weighs as one case.  ``false-alarm rate``
= wrong null redraws / all null redraws.  Targets: score >= 95 %, false alarms <= 5 %.
Each run diagnoses the baseline model once (no effects added: one round, as a new user would).

Usage::

    python benchmarks/diagnose_generalisation.py             # every case (154 runs)
    python benchmarks/diagnose_generalisation.py --quick     # a smoke subset (14 runs)
    python benchmarks/diagnose_generalisation.py --stratified  # every family on every rig, every null (73 runs)
    python benchmarks/diagnose_generalisation.py --cases 'lp_*,mt_friction*' --redraws 5

Options: ``--workers N`` worker processes (:mod:`femast.workers`; default one per CPU, 1 runs in
this process), ``--out DIR``, ``--redraws N`` (null
redraws, default 20), ``--quick`` (one case per mechanism family and 3 null redraws per null
case), ``--stratified`` (each mechanism family once on each rig, the misses of real use, every
null case -- every noise type -- with 5 redraws), ``--cases`` comma-separated names or shell
patterns, ``--resume`` (keep the runs already in ``OUT/runs.jsonl``, where every run is appended as
it ends: a run stopped half-way keeps what it did).
"""

from __future__ import annotations

import argparse
import fnmatch
import json
import os
import resource
import site
import subprocess
import sys
import time
import zlib
from concurrent.futures import as_completed
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

from generalisation.cases import CASES, Case, generate  # noqa: E402
from generalisation.gallery import gallery  # noqa: E402
from generalisation.scoring import is_right, read_verdict, score  # noqa: E402

QUICK = (
    "mt_friction_jenkins",
    "mt_clearance_tanh",
    "mt_progressive_asinh",
    "mt_pair_clearance_friction",
    "mt_ool_thermal_drift",
    "lp_latch_band_gauss",
    "lp_stretch_twoslope",
    "lp_ool_ripple",
    "mt_null_white",
    "lp_null_eq15",
)
QUICK_REDRAWS = 3
STRATIFIED = (  # each family once per rig (mast top, latch pull, joint test), the misses of real use, every null
    "mt_friction_jenkins",
    "mt_clearance_hertz",
    "mt_progressive_asinh",
    "mt_cable_loop_power",
    "mt_pretension_step",
    "mt_beam_stepped",
    "mt_pair_clearance_friction",
    "mt_ool_viscous",
    "mt_guys_slack",
    "mt_friction_preisach",
    "mt_creep_log",
    "mt_clearance_x_only",
    "lp_friction_boucwen",
    "lp_latch_band_lorentz",
    "lp_clearance_piecewise",
    "lp_stretch_twoslope",
    "lp_cable_loop_quadratic",
    "lp_pair_friction_clearance",
    "lp_ool_zero_drift",
    "jt_bwbn_plain",
    "jt_bwbn_pinched",
    "jt_bwbn_degrading",
    "jt_clearance_hertz",
)
STRATIFIED_REDRAWS = 5


def seed_of(case: str, redraw: int) -> int:
    """Reproducible seed of one draw (independent of the order the runs execute in)."""
    return zlib.crc32(f"{case}/{redraw}".encode()) & 0x7FFFFFFF


def run_one(case: Case, redraw: int) -> dict:
    """Generate one draw of ``case`` and diagnose it; returns a result row (JSON-ready)."""
    from femast.experiments import diagnose, from_arrays, get_experiment

    t0, c0 = time.perf_counter(), time.process_time()
    cols = generate(case, seed_of(case.name, redraw))
    exp = get_experiment(case.experiment)
    data = from_arrays(exp, **cols)
    row = {
        "case": case.name,
        "redraw": redraw,
        "experiment": case.experiment,
        "expect": case.expect,
        "expected_effects": list(case.effects),
        "noise": case.noise,
        "n": case.n,
        "path": case.path,
    }
    try:
        import inspect

        extra = {"pairs": True} if "pairs" in inspect.signature(diagnose).parameters else {}
        res = diagnose(exp, data, workers=1, **extra)
        report = json.loads(json.dumps(res.report, default=float))
    except Exception as exc:  # a failure of diagnose is a wrong verdict, reported as such
        row.update(
            kind="error",
            effects=[],
            conclusion=f"diagnose failed: {type(exc).__name__}: {exc}",
            right=False,
            baseline_ratio=None,
            ranking=[],
            wall_s=time.perf_counter() - t0,
            cpu_s=time.process_time() - c0,
        )
        return row
    v = read_verdict(report)
    row.update(
        kind=v["kind"],
        effects=v["effects"],
        conclusion=v["conclusion"],
        right=bool(is_right(case.expect, case.effects, v)),
        baseline_ratio=report.get("baseline", {}).get("ratio"),
        ranking=[
            {k: e.get(k) for k in ("effect", "ratio", "delta_bic", "significant", "explained_fraction")}
            for e in report.get("ranking", [])
        ],
        verdict_fields=report.get("verdict", {}),
        noise_model={
            c: (m.get("kind") if isinstance(m, dict) else m) for c, m in (report.get("noise_model") or {}).items()
        },
        wall_s=time.perf_counter() - t0,
        cpu_s=time.process_time() - c0,
    )
    return row


def select(patterns: str | None, quick: bool, stratified: bool = False) -> list:
    """The cases to run: ``--cases`` patterns, else the quick or stratified subset, or all."""
    cases = list(CASES)
    if patterns:
        pats = [p.strip() for p in patterns.split(",") if p.strip()]
        cases = [c for c in cases if any(fnmatch.fnmatch(c.name, p) or p == c.name for p in pats)]
        if not cases:
            raise SystemExit(f"--cases {patterns!r} matches no case; cases: {', '.join(c.name for c in CASES)}")
    elif quick:
        cases = [c for c in cases if c.name in QUICK]
    elif stratified:
        cases = [c for c in cases if c.name in STRATIFIED or c.expect == "null"]
    return cases


def run_all(cases, redraws: int, workers: int | None, progress: bool = True, log: Path | None = None) -> list:
    """Run every (case, redraw) with a tqdm bar: in this process for ``workers=1``, else on femast's
    worker pool (:mod:`femast.workers`; None: one worker per CPU, at most one per run); rows in
    case order.  log : a JSON-lines file each row is appended to as its run ends; the runs already
    in it are not run again (their rows are returned with the others)."""
    from femast import workers as femast_workers

    jobs = [(c, r) for c in cases for r in range(redraws if c.expect == "null" else c.redraws)]
    rows = []
    if log is not None and log.exists():
        wanted = {(c.name, r) for c, r in jobs}
        for line in log.read_text().splitlines():
            try:
                row = json.loads(line)
            except ValueError:  # a line cut short by a stop: that run runs again
                continue
            if (row["case"], row["redraw"]) in wanted:
                rows.append(row)
                wanted.discard((row["case"], row["redraw"]))
        jobs = [(c, r) for c, r in jobs if (c.name, r) in wanted]

    def keep(row):
        rows.append(row)
        if log is not None:
            with open(log, "a") as f:
                f.write(json.dumps(row, default=float) + "\n")

    n = 1 if workers == 1 else femast_workers.worker_count(workers, tasks=len(jobs))
    bar = None
    if progress:
        from tqdm import tqdm

        bar = tqdm(total=len(jobs), desc="diagnose runs", unit="run")
    if workers == 1:
        for c, r in jobs:
            keep(run_one(c, r))
            if bar:
                bar.update()
    else:
        # the workers import this file as the module ``diagnose_generalisation`` (its folder on their
        # path), whether it runs as a script or as ``python -m femast.benchmarks...``
        import diagnose_generalisation as this

        with femast_workers.Pool(n, initializer=site.addsitedir, initargs=(str(HERE),), name="benchmark") as pool:
            futs = [pool.submit(this.run_one, c, r) for c, r in jobs]
            for f in as_completed(futs):
                keep(f.result())
                if bar:
                    bar.update()
    if bar:
        bar.close()
    order = {c.name: i for i, c in enumerate(cases)}
    rows.sort(key=lambda r: (order[r["case"]], r["redraw"]))
    return rows


def truth_label(row) -> str:
    """Row label of the confusion table: the hidden effect(s), 'out of library' or 'null'."""
    if row["expect"] == "null":
        return "null"
    if row["expect"] == "ool":
        return "out of library"
    if row["expect"] == "time":
        return "out of library (time)"
    return " + ".join(sorted(row["expected_effects"]))  # as the verdict columns


def verdict_label(row) -> str:
    """Column label: the named effect(s) of a claim, or the kind of a no-claim verdict."""
    k = row["kind"]
    if k in ("missing", "form_imperfect"):
        return ("~" if k == "form_imperfect" else "") + " + ".join(row["effects"] or ["?"])
    return {"not_explained": "not explained", "nothing": "nothing missing"}.get(k, k)


def confusion(rows):
    """(row labels, column labels, counts (r, c)) of truth against verdict."""
    rl = list(dict.fromkeys(truth_label(r) for r in rows))
    cl = sorted(
        set(verdict_label(r) for r in rows), key=lambda s: (s in ("not explained", "nothing missing"), s.lstrip("~"), s)
    )
    M = np.zeros((len(rl), len(cl)), int)
    for r in rows:
        M[rl.index(truth_label(r)), cl.index(verdict_label(r))] += 1
    return rl, cl, M


def format_table(rows) -> str:
    """Per-case lines and the confusion table as text."""
    out = ["per case (verdict; ~X = 'mechanism found, form imperfect: X'):"]
    by = {}
    for r in rows:
        by.setdefault(r["case"], []).append(r)
    for case, rs in by.items():
        right = sum(r["right"] for r in rs)
        if len(rs) == 1:
            r = rs[0]
            base = f"{r['baseline_ratio']:.2f}x" if r["baseline_ratio"] is not None else "-"
            out.append(f"  {'ok ' if r['right'] else 'BAD'} {case:32s} base {base:>7s} -> {verdict_label(r)}")
        else:
            labels = {}
            for r in rs:
                labels[verdict_label(r)] = labels.get(verdict_label(r), 0) + 1
            txt = ", ".join(f"{k} x{v}" for k, v in sorted(labels.items(), key=lambda kv: -kv[1]))
            out.append(f"  {right:2d}/{len(rs):<2d} {case:30s} {txt}")
    rl, cl, M = confusion(rows)
    w = max(len(s) for s in rl) + 2
    out.append("")
    out.append("confusion table (rows: what is in the data; columns: what diagnose said; runs):")
    out.append(" " * w + " ".join(f"[{i}]".rjust(5) for i in range(len(cl))))
    for i, lab in enumerate(rl):
        out.append(lab.ljust(w) + " ".join(f"{v:5d}" if v else "    ." for v in M[i]))
    out.append("columns: " + "; ".join(f"[{i}] {c}" for i, c in enumerate(cl)))
    return "\n".join(out)


def ranked_first(rows) -> tuple:
    """(right, total) over single-mechanism runs of 'the hidden mechanism is ranked first' -- a
    secondary figure: the ranking can be right where the verdict is not."""
    single = [r for r in rows if r["expect"] == "effect"]
    right = sum(bool(r["ranking"]) and r["ranking"][0]["effect"] == r["expected_effects"][0] for r in single)
    return right, len(single)


def figures(rows, summary, out: Path) -> list:
    """Confusion heat map and per-case ratio chart (PNG); returns the paths."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    paths = []
    rl, cl, M = confusion(rows)
    fig, ax = plt.subplots(figsize=(max(7, 0.55 * len(cl) + 4), max(4, 0.36 * len(rl) + 2)))
    share = M / np.maximum(M.sum(axis=1, keepdims=True), 1)
    ax.imshow(share, cmap="Blues", vmin=0, vmax=1, aspect="auto")
    for i in range(len(rl)):
        for j in range(len(cl)):
            if M[i, j]:
                ax.text(
                    j,
                    i,
                    str(M[i, j]),
                    ha="center",
                    va="center",
                    fontsize=8,
                    color="white" if share[i, j] > 0.6 else "black",
                )
    ax.set_xticks(range(len(cl)), cl, rotation=40, ha="right", fontsize=8)
    ax.set_yticks(range(len(rl)), rl, fontsize=8)
    ax.set_xlabel("verdict of diagnose (~X: form imperfect, X named)")
    ax.set_ylabel("hidden in the data")
    ax.set_title(
        f"diagnose on independent data: score {100 * summary['score']:.0f} % (target 95), "
        f"false alarms {100 * summary['false_alarm_rate']:.0f} % (target 5)",
        fontsize=9,
    )
    fig.tight_layout()
    p = out / "confusion.png"
    fig.savefig(p, dpi=110)
    plt.close(fig)
    paths.append(p)

    single = [r for r in rows if r["expect"] != "null"]
    nulls = {}
    for r in rows:
        if r["expect"] == "null":
            nulls.setdefault(r["case"], []).append(r)
    fig, (a1, a2) = plt.subplots(
        1, 2, figsize=(13, max(4, 0.27 * len(single) + 1.5)), gridspec_kw={"width_ratios": [3, 1]}
    )
    y = np.arange(len(single))
    base = [r["baseline_ratio"] or np.nan for r in single]
    best = [min([e["ratio"] for e in r["ranking"] if e.get("ratio") is not None] or [np.nan]) for r in single]
    col = ["C2" if r["right"] else "C3" for r in single]
    a1.barh(y, base, color="0.8", label="baseline")
    a1.scatter(best, y, c=col, zorder=3, s=18, label="best single candidate (green: verdict right)")
    a1.axvline(1.0, color="k", lw=0.8, ls="--")
    a1.set_yticks(y, [f"{r['case']} -> {verdict_label(r)}" for r in single], fontsize=7)
    a1.invert_yaxis()
    a1.set_xscale("log")
    from matplotlib.ticker import FixedLocator, FuncFormatter, NullLocator

    a1.xaxis.set_major_locator(FixedLocator([0.8, 1, 1.2, 1.5, 2, 3, 4, 6, 8, 10, 20, 40, 100]))
    a1.xaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
    a1.xaxis.set_minor_locator(NullLocator())
    a1.set_xlabel("RMS error / noise floor (as diagnose estimates it)")
    from femast.post import plotstyle

    plotstyle.legend_below(a1, ncol=2, fontsize=7)  # never over the bars
    names = list(nulls)
    fa = [sum(not r["right"] for r in nulls[n]) / len(nulls[n]) for n in names]
    a2.barh(np.arange(len(names)), fa, color="C3")
    a2.axvline(0.05, color="k", ls="--", lw=0.8)
    for i, n in enumerate(names):
        wrong = sum(not r["right"] for r in nulls[n])
        a2.text(0.02, i, f"{wrong}/{len(nulls[n])}", va="center", fontsize=8)
    a2.set_yticks(np.arange(len(names)), [f"{n} ({len(nulls[n])} redraws)" for n in names], fontsize=7)
    a2.invert_yaxis()
    a2.set_xlim(0, 1)
    a2.set_xlabel("false-alarm rate (target 0.05)")
    fig.tight_layout()
    p = out / "cases.png"
    fig.savefig(p, dpi=110)
    plt.close(fig)
    paths.append(p)
    return paths


def _commit() -> str:
    try:
        return subprocess.run(
            ["git", "-C", str(HERE), "rev-parse", "--short", "HEAD"], capture_output=True, text=True, timeout=10
        ).stdout.strip()
    except Exception:
        return "?"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="a smoke subset with 3 null redraws")
    ap.add_argument(
        "--stratified",
        action="store_true",
        help=f"each family once per rig, the misses of real use, every null case ({STRATIFIED_REDRAWS} redraws)",
    )
    ap.add_argument("--resume", action="store_true", help="keep the runs already in OUT/runs.jsonl")
    ap.add_argument("--cases", help="comma-separated case names or shell patterns (e.g. 'lp_*')")
    ap.add_argument("--redraws", type=int, help="noise redraws of each null case (default 20; 3 with --quick)")
    ap.add_argument(
        "--workers", type=int, help="worker processes (femast.workers; default: one per CPU; 1: in this process)"
    )
    ap.add_argument("--out", default=str(HERE / "out" / "diagnose_generalisation"), help="output folder")
    ap.add_argument("--no-figures", action="store_true", help="skip the PNG figures")
    ap.add_argument(
        "--docs", action="store_true", help="also copy the figures to docs/figures/diagnose_generalisation_*.png"
    )
    a = ap.parse_args(argv)
    cases = select(a.cases, a.quick, a.stratified)
    default = QUICK_REDRAWS if a.quick else STRATIFIED_REDRAWS if a.stratified and not a.cases else 20
    redraws = a.redraws if a.redraws is not None else default
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    log = out / "runs.jsonl"
    if not a.resume and log.exists():
        log.unlink()
    commit = _commit()  # the code the runs use (HEAD when they start)
    t0 = time.perf_counter()
    rows = run_all(cases, redraws, a.workers, progress=True, log=log)
    wall = time.perf_counter() - t0
    summary = score(rows)
    summary.update(
        commit=commit,
        wall_s=wall,
        workers=a.workers,
        runs=len(rows),
        cpu_s_runs=float(sum(r["cpu_s"] for r in rows)),
        cpu_s_parent=resource.getrusage(resource.RUSAGE_SELF).ru_utime,
        load=os.getloadavg(),
        quick=a.quick,
        stratified=a.stratified,
        cases_filter=a.cases,
        redraws=redraws,
    )
    print(format_table(rows))
    print()
    print(
        f"score: {100 * summary['score']:.1f} % of {summary['cases']} cases right "
        f"({summary['non_null_right']:.0f}/{summary['non_null_cases']} mechanism cases; null cases by the "
        f"fraction of their redraws right)  [target >= 95 %]"
    )
    print(
        f"false-alarm rate: {100 * summary['false_alarm_rate']:.1f} % ({summary['false_alarms']} of "
        f"{summary['null_runs']} null redraws not called 'nothing is missing')  [target <= 5 %]"
    )
    rf = ranked_first(rows)
    summary["ranked_first"] = {"right": rf[0], "of": rf[1]}
    print(f"secondary: the hidden mechanism is ranked first in {rf[0]} of {rf[1]} single-mechanism cases")
    print(
        f"{len(rows)} runs in {wall:.0f} s wall with {a.workers} workers, {summary['cpu_s_runs']:.0f} s CPU in "
        f"the runs; load average {summary['load'][0]:.1f}; commit {summary['commit']}"
    )
    timing = {}
    for e in sorted(set(r["experiment"] for r in rows)):
        ts = [(r["cpu_s"], r["wall_s"], r["n"]) for r in rows if r["experiment"] == e]
        cpu, wall = np.array([t[0] for t in ts]), np.array([t[1] for t in ts])
        timing[e] = {
            "cpu_median_s": float(np.median(cpu)),
            "cpu_max_s": float(cpu.max()),
            "wall_median_s": float(np.median(wall)),
            "wall_max_s": float(wall.max()),
        }
        print(
            f"diagnose per run, {e}: CPU median {np.median(cpu):.1f} s, max {cpu.max():.1f} s; wall median "
            f"{np.median(wall):.1f} s, max {wall.max():.1f} s (one process per run, {a.workers} at once)"
        )
    summary["timing"] = timing
    paths = [] if a.no_figures else figures(rows, summary, out) + [Path(gallery(out / "forms.png"))]
    if a.docs and paths:
        import shutil

        for p in paths:
            shutil.copy(p, HERE.parent / "docs" / "figures" / f"diagnose_generalisation_{p.name}")
    (out / "results.json").write_text(json.dumps({"summary": summary, "runs": rows}, indent=1, default=float))
    print(f"wrote {out / 'results.json'}" + "".join(f", {p}" for p in paths))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
