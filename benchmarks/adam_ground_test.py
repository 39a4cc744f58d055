"""Ground test of a vertical ADAM mast: the mast under its own weight, then the Table 1 load cycle.

    python -m femast.benchmarks.adam_ground_test [--bays 40] [--out results/adam_ground_test] [--docs]

ADAM (Stohlman & Pellegrino, Sec. I) names gravity, with friction, as one of the two primary
causes of static position errors in ground tests.  The mast stands vertical (base frame fixed,
z up) with the mass model of ``femast.adam.mass`` (CFRP members, steel cables, pulley-and-latch
units, corner pieces).  Steps: ``pretension`` (the stabilised initial step), ``weight`` (gravity
(0, 0, -9.81) m/s^2), then one Table 1 cycle (M+F, 0, -M-F, 0 at the tip); the same cycle runs
once more without gravity.  Prints

* the weight: the base reactions against the mass counted part by part;
* the longeron compression added by the weight, bay by bay, against the weight above / 4 (a
  uniform mast: the cable net is ~1000 times softer axially than the longerons);
* the tip shortening against sum_j W_above(j) l / (4 EA);
* the tip table of the cycle with and without gravity (um, arcsec) and the residuals;

and draws DIR/adam_ground_test.png (and docs/figures/ with --docs).
"""

from __future__ import annotations

import argparse
import shutil
import time
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

import femast as fm
from femast.adam import BayParameters, build_mast
from femast.adam.mass import CORNER_MASS, RHO_CFRP, UNIT_MASS, add_mass, cable_mass_per_length
from femast.adam.post import TABLE1_COLUMNS, tip_table
from femast.adam.steps import CONVERGENCE, add_initial_steps, add_table1_steps

ROOT = Path(__file__).resolve().parents[1]
G = 9.81


def hand_mass(am) -> float:
    """Mass (kg) counted part by part from the parameters (not from femast's mass model)."""
    p = am.params
    tube = lambda d, t: np.pi / 4 * (d**2 - (d - 2 * t) ** 2)  # noqa: E731
    longerons = 4 * am.n_bays * p.l * tube(p.longeron_d, p.longeron_t) * RHO_CFRP
    # battens: four per frame between the corner pieces (b - 2 corner each)
    battens = 4 * (am.n_bays + 1) * (p.b - 2 * p.corner) * tube(p.batten_d, p.batten_t) * RHO_CFRP
    # cables: per side a latch cable (two half diagonals) and two arms (two half diagonals)
    diag = np.hypot(p.b, p.l)
    cables = 4 * am.n_bays * 2 * diag * cable_mass_per_length(p.cable_EA)
    units = 4 * am.n_bays * UNIT_MASS
    corners = 4 * am.n_bays * CORNER_MASS  # the base corners are fixed (their mass is not in the model)
    return longerons + battens + cables + units + corners


def build(n_bays: int, gravity: bool):
    am = build_mast(n_bays, BayParameters())
    add_mass(am)
    add_initial_steps(am)
    if gravity:
        am.model.step("weight", initial_increment=0.5).gravity(g=(0.0, 0.0, -G))
    add_table1_steps(am, cycles=1, increments=1)  # one increment per step, as the Table 1 reproduction
    return am


def longeron_force(res, am, frame) -> np.ndarray:
    """(n_bays,) mean axial force of the four longerons of each bay, N (tension > 0)."""
    sf = res.frame(frame)["el/adam_longeron/section_forces"]  # (n_el, 2 ends, 6): N, Vy, Vz, T, My, Mz
    return sf[:, :, 0].reshape(am.n_bays, 4, -1).mean(axis=(1, 2))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--bays", type=int, default=40)
    ap.add_argument("--out", default="results/adam_ground_test")
    ap.add_argument("--docs", action="store_true", help="copy the figure to docs/figures/")
    args = ap.parse_args(argv)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    runs = {}
    for gravity in (True, False):
        am = build(args.bays, gravity)
        t0 = time.perf_counter()
        an = fm.Analysis(
            am.model, out / ("with_gravity" if gravity else "without"), progress=False, convergence=CONVERGENCE
        )
        res = an.run()
        runs[gravity] = (am, an, res, time.perf_counter() - t0)
    am, an, res, wall = runs[True]
    p = am.params
    steps = res.steps
    last = {s: i for i, s in enumerate(steps)}
    i_pre, i_w = last["pretension"], last["weight"]
    RF = res.frame(i_w)["RF"]
    W_fe = float(RF[:, 2].sum()) - float(res.frame(i_pre)["RF"][:, 2].sum())
    W_hand = hand_mass(am) * G
    print(f"vertical ADAM mast, {args.bays} bays, {args.bays * p.l:.2f} m, under gravity 9.81 m/s^2")
    print(f"weight carried by the base: {W_fe:.3f} N; parts counted by hand: {W_hand:.3f} N ({W_fe / W_hand - 1:+.2%})")
    dN = longeron_force(res, am, i_w) - longeron_force(res, am, i_pre)
    z_mid = (np.arange(args.bays) + 0.5) * p.l
    W_above = W_fe * (1.0 - (np.arange(args.bays) + 0.5) / args.bays)
    print("longeron force added by the weight (N, mean of the 4 longerons; tension > 0):")
    for j in (0, args.bays // 2, args.bays - 1):
        print(f"  bay {j + 1:3d}: {dN[j]:8.3f} N; -W_above/4 = {-W_above[j] / 4:8.3f} N")
    EA = p.longeron_E * np.pi / 4 * (p.longeron_d**2 - (p.longeron_d - 2 * p.longeron_t) ** 2)
    short_hand = float(np.sum(W_above * p.l / (4 * EA)))
    row = int(np.flatnonzero(res.node_labels == am.control)[0])
    short_fe = -(res.frame(i_w)["U"][row, 2] - res.frame(i_pre)["U"][row, 2])
    print(f"tip shortening: {short_fe * 1e6:.3f} um; sum W_above l / (4 EA) = {short_hand * 1e6:.3f} um")
    labels_g, vals_g = tip_table(res, am, reference_step="weight")
    am0, an0, res0, wall0 = runs[False]
    labels_0, vals_0 = tip_table(res0, am0, reference_step="pretension")
    print("\nTable 1 cycle at the tip (um, arcsec), relative to the state before the cycle:")
    print(f"{'load':>6} | " + " | ".join(f"{c:^19}" for c in TABLE1_COLUMNS))
    print(f"{'':>6} | " + " | ".join(f"{'gravity':>9} {'none':>9}" for _ in TABLE1_COLUMNS))
    for lab, a, b in zip(labels_g, vals_g, vals_0):
        print(f"{lab:>6} | " + " | ".join(f"{x:9.4g} {y:9.4g}" for x, y in zip(a, b)))
    print(
        f"\nresidual after the cycle: theta_z {vals_g[-1, 5]:.4g} arcsec with gravity, {vals_0[-1, 5]:.4g} without; "
        f"x {vals_g[-1, 0]:.4g} um with, {vals_0[-1, 0]:.4g} um without"
    )
    print(
        f"runs: {an.summary.increments} increments, {an.summary.iterations} iterations, {wall:.1f} s (gravity); "
        f"{an0.summary.increments} increments, {wall0:.1f} s (none)"
    )
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(10, 4.2))
    a1.plot(-dN, z_mid, "o", ms=3, label="femast: added longeron compression")
    a1.plot(W_above / 4, z_mid, "-", label="weight above / 4")
    a1.set_xlabel("added compression per longeron (N)")
    a1.set_ylabel("height of the bay (m)")
    a1.set_title(f"vertical {args.bays}-bay ADAM mast under its weight")
    a1.legend()
    x = np.arange(len(labels_g))
    a2.plot(x, vals_g[:, 5], "o-", label="with gravity")
    a2.plot(x, vals_0[:, 5], "s--", label="without gravity")
    a2.set_xticks(x, labels_g)
    a2.set_xlabel("load (Table 1 sequence)")
    a2.set_ylabel("tip rotation about z (arcsec)")
    a2.set_title("one Table 1 cycle on the ground")
    a2.legend()
    fig.tight_layout()
    png = out / "adam_ground_test.png"
    fig.savefig(png, dpi=110)
    print(f"figure: {png}")
    if args.docs:
        shutil.copy(png, ROOT / "docs" / "figures" / "adam_ground_test.png")


if __name__ == "__main__":
    main()
