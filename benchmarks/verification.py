"""Verification of the FE core: prints the table of every case (reference, femast,
error) and writes load-displacement plots against the references and a VTK series.

    python benchmarks/verification.py [--out benchmarks/out/verification]
"""

import argparse
import math
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
from femast.post import plotstyle  # noqa: E402  (the one femast figure style)

plotstyle.use()
import matplotlib.pyplot as plt
import numpy as np

from femast import progress
from femast import verification as v
from femast.post.render import render_png
from femast.post.vtk import export_vtk
from femast.verification import references as ref


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--out", default="benchmarks/out/verification")
    args = ap.parse_args()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    rows = []
    fig, axes = plt.subplots(2, 2, figsize=(12, 9))
    bar = progress.counter(8, "verification cases", unit="cases")  # per case; erased when done

    def case(name):
        bar.set_postfix_str(name, refresh=True)

    def done():
        bar.update(1)

    case("roll-up, one turn")

    # roll-up: deformed shapes at several load levels
    r1, res = v.roll_up(n_elements=16, turns=1, out_dir=out)
    rows += r1
    ax = axes[0, 0]
    chain = np.argsort(res.X[:, 0])  # nodes along the beam (the tip was created second)
    for i in range(0, len(res), 4):
        X = res.positions(i)[chain]
        ax.plot(X[:, 0], X[:, 1], "o-", ms=3, label=f"M = {res.frame(i)['time']:.2f} x 2 pi EI/L")
    s = np.linspace(0, 1, 200)
    x, y, _ = ref.pure_bending_shape(2 * math.pi, 1.0, 1.0, s)
    ax.plot(x, y, "k--", lw=1, label="exact circle")
    ax.set_aspect("equal")
    ax.set_xlabel("x / L (-)")
    ax.set_ylabel("y / L (-)")
    ax.set_title("Cantilever under end moment (16 elements)")
    ax.legend(fontsize=7)
    done()
    case("roll-up, two turns")
    rows += v.roll_up(n_elements=16, turns=2, out_dir=out)[0]
    done()
    pvd = export_vtk(res, out / "rollup_vtk")
    render_png(res, out / "rollup_shape.png", title="roll-up under M = 2 pi EI/L")

    # elastica
    case("elastica")
    r2, res = v.elastica(n_elements=20, out_dir=out)
    rows += r2
    ax = axes[0, 1]
    tip = res.node_labels[1]
    k = res.scalar_history("time") * 10
    ax.plot(-res.node_history(tip, "uy"), k, "o", ms=4, label="femast v/L")
    ax.plot(-res.node_history(tip, "ux"), k, "s", ms=4, label="femast u/L")
    kk = np.linspace(0.05, 10, 80)
    ex = [ref.elastica_tip_load(q) for q in kk]
    ax.plot([e.v_over_L for e in ex], kk, "k-", lw=1, label="elastica (exact)")
    ax.plot([e.u_over_L for e in ex], kk, "k--", lw=1)
    ax.set_xlabel("tip displacement / L (-)")
    ax.set_ylabel("load P L^2 / EI (-)")
    ax.set_title("Cantilever under a dead end load (20 elements)")
    ax.legend(fontsize=8)

    done()
    # 45-degree bend
    case("45-degree bend")
    r3, res = v.bend45(n_elements=16, out_dir=out)
    rows += r3
    ax = axes[1, 0]
    tipn = res.node_labels[-1]
    P = res.scalar_history("time") * 600
    X0 = res.X[-1]
    for c, name in enumerate("xyz"):
        ax.plot(P, X0[c] + res.node_history(tipn, "u" + name), "o-", ms=3, label=f"femast tip {name}")
    for _author, table in ref.BEND45_PUBLISHED.items():
        for load, pos in table.items():
            ax.plot([load] * 3, pos, "k+", ms=8)
    ax.plot([], [], "k+", label="published (Bathe-Bolourchi, Simo-Vu-Quoc, Crisfield, ...)")
    ax.set_xlabel("tip load P (consistent units of the case: R = 100, E = 1e7)")
    ax.set_ylabel("tip coordinate (same length unit as R)")
    ax.set_title("45-degree bend (16 elements)")
    ax.legend(fontsize=8)

    done()
    case("linear compliance")
    rows += v.linear_compliance(out_dir=out)[0]
    done()

    # Euler column
    case("Euler column")
    r5, res = v.euler_column(n_elements=16, out_dir=out)
    rows += r5
    ax = axes[1, 1]
    mid = res.node_labels[8]
    w = res.node_history(mid, "uy") + 1e-3
    ax.plot(w, res.scalar_history("load_factor"), "o", ms=3, label="femast, e0 = L/1000")
    al = np.linspace(0.01, 1.9, 100)
    pb = np.array([ref.euler_column_postbuckling(a) for a in al])
    ax.plot(pb[:, 1], pb[:, 0], "k-", lw=1, label="elastica (perfect column)")
    ww = np.linspace(0.001, 0.02, 50)
    ax.plot(ww, 1 - 1e-3 / ww, "k--", lw=1, label="linear amplification e0/(1-P/Pcr)")
    ax.set_xlabel("midspan deflection / L (-)")
    ax.set_ylabel("load P / P_cr (-)")
    ax.set_ylim(0, 1.3)
    ax.set_title("Pinned column with imperfection (displacement control)")
    ax.legend(fontsize=8)

    done()
    case("figures")
    fig.tight_layout()
    plotstyle.save(fig, out / "verification.png", dpi=110)
    done()
    case("modal cases")
    rows += modal_cases(out)
    done()
    bar.close()
    table = v.format_table(rows)
    print(table)
    (out / "verification_table.txt").write_text(table + "\n")
    n_bad = sum(not r.passed for r in rows)
    print(
        f"\n{len(rows) - n_bad} of {len(rows)} checks within tolerance; figures in {out}/verification.png, "
        f"VTK series {pvd}"
    )
    return 1 if n_bad else 0


def modal_cases(out):
    """Modal analysis against closed forms; figure modal_verification.png."""
    from femast.verification import modal as vm

    rows = []
    fig, axes = plt.subplots(1, 3, figsize=(15, 4.5))
    r, modes = vm.taut_string()
    rows += r
    rows += vm.taut_string(cable=False)[0]
    ax = axes[0]
    order = np.argsort(modes.x[:, 0])
    for k in (0, 2, 4):
        yz = modes.shapes[k, order, 1:3]  # a mode of a degenerate (y, z) pair: w(x) along one direction
        w = yz @ np.linalg.svd(yz, full_matrices=False)[2][0]
        ax.plot(
            modes.x[order, 0],
            w * np.sign(w[len(w) // 4 or 1]),  # errors: the table, not the legend
            label=f"f = {plotstyle.num(modes.frequencies[k], 4)} Hz (exact {25 * (k // 2 + 1):.0f} Hz)",
        )
    ax.set_xlabel("x (m)")
    ax.set_ylabel("transverse mode shape (mass-normalised, m/sqrt(kg))")
    ax.set_title("Taut string, T = 100 N, m' = 0.01 kg/m, 100 cables")
    ax.legend(fontsize=8)
    r, modes = vm.cantilever()
    rows += r
    f_exact = [row.reference for row in r]  # the closed forms of the table (Euler-Bernoulli cantilever)
    ax = axes[1]
    order = np.argsort(modes.x[:, 0])
    for k in (0, 2, 4):
        yz = modes.shapes[k, order, 1:3]
        w = yz @ np.linalg.svd(yz, full_matrices=False)[2][0]
        ax.plot(
            modes.x[order, 0],
            w / w[np.argmax(np.abs(w))],
            label=f"f = {plotstyle.num(modes.frequencies[k], 4)} Hz (exact {plotstyle.num(f_exact[k // 2], 4)} Hz)",
        )
    ax.set_xlabel("x / L (-)")
    ax.set_ylabel("transverse mode shape, 1 at its largest (-)")
    ax.set_title("Cantilever, EI = m = L = 1, 20 beams")
    ax.legend(fontsize=8)
    r, (ratios, f2, exact) = vm.pinned_beam_axial()
    rows += r
    ax = axes[2]
    pp = np.linspace(-1.3, 1.0, 50)
    ax.plot(pp, exact[ratios == 0][0] * (1 + pp), "k-", lw=1, label="exact: f0^2 (1 + P/P_E)")
    ax.plot(ratios, f2, "o", label="femast, 48 beams (sign(f) f^2)")
    ax.axhline(0, color="0.6", lw=0.8)
    ax.axvline(-1, color="0.6", lw=0.8, ls="--")
    ax.set_xlabel("axial force P / P_E (-, tension > 0)")
    ax.set_ylabel("f_1^2 (Hz^2)")
    ax.set_title("Pin-ended beam under axial force")
    ax.legend(fontsize=8)
    rows += vm.rigid_body_springs()[0]
    rows += vm.pendulum()[0]
    plotstyle.save(fig, out / "modal_verification.png", dpi=110)
    return rows


if __name__ == "__main__":
    raise SystemExit(main())
