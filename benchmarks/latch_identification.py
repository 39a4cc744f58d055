"""Latch identification from pull tests (Stohlman & Pellegrino, Figs. 9-10, Eq. 15), on synthetic data.

The "measured" tests are simulated with the cable/latch element for a known latch
(the paper's fit), with noise on the cable end distance (5 um) and the tension
(0.3 N).  The script removes the cable stretch (Eq. 15), fits r, x_backstop, k, mu
with h and R given, prints the estimates with their standard errors, checks them
against a Monte-Carlo spread, and draws the analogue of Figs. 9 and 10.

Run:  python benchmarks/latch_identification.py  ->  benchmarks/out/latch_identification.png
"""

from __future__ import annotations

import copy
import shutil
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
from femast.post import plotstyle  # noqa: E402  (the one femast figure style)

plotstyle.use()
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from femast.elements.latch_law import LATCHING, UNLATCHING, LatchParameters, latch_force  # noqa: E402
from femast.latch_identification import fit_pull_tests, simulate_pull_test  # noqa: E402

OUT = Path(__file__).resolve().parent / "out"
DOCS = Path(__file__).resolve().parents[1] / "docs" / "figures"
SIG_D, SIG_T, EA = 5e-6, 0.3, 2.0e5


def noisy(tests, rng):
    out = []
    for t in tests:
        t = copy.copy(t)
        t.d = t.d + rng.normal(0.0, SIG_D, t.d.size)
        t.T = t.T + rng.normal(0.0, SIG_T, t.T.size)
        out.append(t)
    return out


def main(n_monte_carlo: int = 50) -> dict:
    true = LatchParameters.adam_fit()
    theta = np.array([true.r, true.x_backstop, true.k, true.mu])
    clean = [simulate_pull_test(true, d, EA=EA, n_steps=300) for d in (UNLATCHING, LATCHING)]
    tests = noisy(clean, np.random.default_rng(2024))
    res = fit_pull_tests(tests, h=true.h, R=true.R, sigma_T=SIG_T, sigma_x=SIG_D)
    est = np.array(
        [
            fit_pull_tests(noisy(clean, np.random.default_rng(s)), h=true.h, R=true.R, sigma_T=SIG_T, sigma_x=SIG_D).x
            for s in range(n_monte_carlo)
        ]
    )
    mc_std = est.std(axis=0)
    units = {"r": (1e3, "mm"), "x_backstop": (1e3, "mm"), "k": (1e-3, "N/mm"), "mu": (1.0, "-")}
    print(f"{'param':>10s} {'true':>9s} {'fit':>9s} {'stderr':>9s} {'MC std':>9s} {'z':>6s}")
    rows = {}
    for i, name in enumerate(res.names):
        f, u = units[name]
        z = (res.x[i] - theta[i]) / res.stderr[i]
        print(
            f"{name:>10s} {theta[i] * f:9.4f} {res.x[i] * f:9.4f} {res.stderr[i] * f:9.4f} "
            f"{mc_std[i] * f:9.4f} {z:6.2f}  {u}"
        )
        rows[name] = dict(true=theta[i], fit=res.x[i], stderr=res.stderr[i], mc_std=mc_std[i])
    print(
        f"reduced chi-square {res.chi2_reduced:.3f}, {res.used.sum()} of {res.used.size} points used, "
        f"{res.nfev} evaluations, {res.message}"
    )

    fig, axs = plt.subplots(1, 2, figsize=(11, 4.4), sharey=True)
    mm = 1e3
    for t, c in zip(tests, ("tab:red", "tab:blue")):
        raw = t.sign * (t.d - t.d0)
        axs[0].plot(raw * mm, t.dT(), ".", ms=2.5, color=c, alpha=0.5)
        axs[0].plot(t.bead_position() * mm, t.dT(), ".", ms=2.5, color="k", alpha=0.5)
    axs[0].plot([], [], ".", color="0.5", label="raw: sign (d - d0)")
    axs[0].plot([], [], ".", color="k", label="stretch removed (Eq. 15)")
    axs[0].set_title("Fig. 9 analogue: synthetic pull tests", fontsize=10)
    axs[0].legend(fontsize=8)
    x = np.linspace(-res.params.x_backstop, 4e-3, 1500)
    used = res.used
    axs[1].plot(res.x_data[used] * mm, res.dT_data[used], ".", ms=2.5, color="0.4", label="data used in the fit")
    axs[1].plot(res.x_data[~used] * mm, res.dT_data[~used], "x", ms=3, color="0.7", label="slack cable (not used)")
    for d, c, lab in ((UNLATCHING, "tab:red", "unlatching"), (LATCHING, "tab:blue", "latching")):
        fit = latch_force(x, d, res.params)
        axs[1].plot(x * mm, fit, color=c, lw=1.8, label=f"fit, {lab}")
        axs[1].plot(x * mm, latch_force(x, d, true), "--", color=c, lw=0.8)
    axs[1].axvline(-res.params.x_backstop * mm, color="k", lw=1.5, label="fitted backstop")
    axs[1].plot([], [], "--", color="0.3", lw=0.8, label="true law")
    txt = "\n".join(
        f"{n} = {rows[n]['fit'] * units[n][0]:.4g} ± {rows[n]['stderr'] * units[n][0]:.2g} {units[n][1]}"
        for n in res.names
    )
    axs[1].text(
        0.98, 0.97, txt, transform=axs[1].transAxes, ha="right", va="top", fontsize=8, bbox=dict(fc="w", ec="0.7")
    )
    axs[1].set_title("Fig. 10 analogue: least-squares fit (h, R given)", fontsize=10)
    axs[1].legend(fontsize=7, loc="lower left")
    for ax in axs:
        ax.axhline(0, color="k", lw=0.4)
        ax.set_xlabel("distance to latch (mm)")
        ax.set_xlim(-2.6, 4.2)
    axs[0].set_ylabel(r"$\Delta T$ (N)")
    fig.tight_layout()
    OUT.mkdir(parents=True, exist_ok=True)
    png = OUT / "latch_identification.png"
    plotstyle.save(fig, png, dpi=150)
    plt.close(fig)
    DOCS.mkdir(parents=True, exist_ok=True)
    shutil.copy(png, DOCS / "latch_identification.png")
    return {"rows": rows, "chi2_reduced": res.chi2_reduced, "png": str(png)}


if __name__ == "__main__":
    main()
