"""Latch pull tests reversed part-way: the latch-pull model against independent rig data
and against an FE run of one cable/latch element; writes docs/figures/latch_pull_partial_reversal.png.

    python benchmarks/latch_pull_partial.py

Data: ``benchmarks/latch_rig.py`` (quasi-static rig from Stohlman & Pellegrino, Eqs. 7-11, no femast code),
0.5 N and 2 um noise.  FE: a femast Model with one cable/latch element (Stohlman & Pellegrino, Eqs. 2-5, two
sections, latch at the middle node on a 1e9 N/m mount), the outer grip driven by a prescribed
displacement, the inner section slack.  Prints the RMS error / noise of each null case for the
model with the loaded side (this issue) and with the old rule (clipping by the direction of motion).
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
from latch_rig import SeedLatch, paths, simulate, to_columns  # noqa: E402

ADAM_FIT = {"r": 1.1e-3, "x_backstop": 2.0e-3, "k": 1e5, "mu": 0.07}


def fe_partial_unlatching(
    x_turn: float = -0.8e-3, EA: float = 2.0e5, L_in: float = 0.3, L_out: float = 0.5, increment: float = 0.004
):
    """FE pull test: outer cable pulls the bead off the backstop to ``x_turn`` (m), then the grip
    returns 0.05 mm behind its start (inner section slack throughout).

    Returns dict: ``x`` bead position of the element (m), ``x15`` Eq. 15 position from the grip
    distance and tension with the loaded length (m), ``T`` (n, 2) section tensions (N), ``dT`` (N),
    ``status`` latch status (0 stick, +1 slip out, -1 slip in, 2 backstop)."""
    import femast as fm
    from femast.elements.cable_latch import CableLatchFamily
    from femast.elements.latch_law import LatchParameters, latch_force

    P = LatchParameters.adam_fit()
    m = fm.Model("latch pull test")
    Lb = L_in - P.x_backstop  # material coordinate of the bead: seated on the backstop
    a, latch, grip = m.node(-(L_in - 0.01), 0, 0), m.node(0, 0, 0), m.node(L_out * (1 + 1e-6), 0, 0)
    frame = m.node(-0.1, 0, 0)
    m.fix(a)
    m.fix(frame)
    m.fix(latch, "uy", "uz", "rx", "ry", "rz")
    m.fix(grip, "uy", "uz", "rx", "ry", "rz")
    m.truss(frame, latch, EA=1e8)  # the latch body on a stiff mount, 1e9 N/m
    m.add_family(
        CableLatchFamily([[a, latch, grip]], EA=EA, L0=L_in + L_out, latch_node=1, bead=Lb, latch=P, name="cable")
    )
    T_turn = float(latch_force(x_turn, +1, P))
    u = (x_turn + P.x_backstop) + T_turn * (L_out + x_turn) / EA  # grip travel to put the bead at x_turn
    amp = fm.Amplitude([0.0, 0.5, 1.0], [0.0, 1.0, -0.05e-3 / u])
    m.step("out and back", initial_increment=increment, max_increment=increment).prescribe(grip, ux=u, amplitude=amp)
    with tempfile.TemporaryDirectory() as tmp:
        res = fm.Analysis(m, tmp, progress=False).run()
        if not res.summary["completed"]:
            raise RuntimeError(f"FE pull test did not converge: {res.summary['message']}")
        x = res.element_history("cable", 1, "bead_position")
        T = res.element_history("cable", 1, "tension")
        status = res.element_history("cable", 1, "latch_status")
        d = L_out * (1 + 1e-6) + res.node_history(grip, "ux") - res.node_history(latch, "ux")
    L_loaded = L_in + L_out - Lb  # unstretched cable from the bead (at x = 0) to the grip
    x15 = d / (1.0 + T[:, 1] / EA) - L_loaded  # Eq. 15 with the loaded length (the paper: constant length)
    return {"x": x, "x15": x15, "T": T, "dT": T[:, 1] - T[:, 0], "status": status}


def direction_rule(x, dT, params):
    """The latch-pull prediction of the direction of motion for a moving bead: branch of the direction of motion
    clipped to that direction's sign (for the figure only)."""
    from femast.elements.latch_law import latch_force

    p = np.array([params["r"], params["x_backstop"], params["k"], params["mu"], 1.5e-3, 2.4e-3])
    sig = np.sign(np.gradient(x))
    sig[sig == 0] = 1
    D = latch_force(np.maximum(x, -params["x_backstop"]), sig, p)
    return np.where(sig > 0, np.maximum(D, 0.0), np.minimum(D, 0.0))


def main():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from femast.experiments import compare, from_arrays, get_experiment, predict

    exp = get_experiment("latch-pull")
    latch = SeedLatch()
    print("null cases (independent rig data, 0.5 N / 2 um noise, the published latch fit):")
    print(f"  {'case':32s} {'rows':>5s} {'RMS/noise drawn':>16s} {'RMS/noise est.':>15s}")
    runs = {}
    for name, (knots, side, x0) in paths(latch).items():
        run = simulate(latch, knots, side, x_start=x0)
        cols = to_columns(run, noise_N=0.5, noise_mm=0.002, seed=5)
        data = from_arrays(exp, **cols)
        c = compare(exp, data, params=ADAM_FIT)
        drawn = np.sqrt(np.mean((cols["dT_N"] - run["dT"]) ** 2))
        print(f"  {name:32s} {data.n:5d} {c.rms / drawn:16.3f} {c.ratio:15.3f}")
        runs[name] = (run, cols, predict(exp, data, ADAM_FIT)["dT_N"])

    fe = fe_partial_unlatching()
    data = from_arrays(exp, x_mm=1e3 * fe["x15"], dT_N=fe["dT"], side=np.ones(fe["dT"].size))
    pred = predict(exp, data, ADAM_FIT)["dT_N"]
    print(
        f"FE partial unlatching (zone b, {fe['dT'].size} increments): max |model - FE| = "
        f"{np.abs(pred - fe['dT']).max():.2e} N"
    )

    fig, axes = plt.subplots(1, 3, figsize=(15, 4.6))
    for ax, name in zip(
        axes, ("partial unlatching, zone (b)", "partial unlatching, zone (c)", "partial latching, zone (c)")
    ):
        run, cols, p = runs[name]
        ax.plot(cols["x_mm"], cols["dT_N"], ".", ms=2, color="0.6", label="independent rig data (0.5 N noise)")
        ax.plot(cols["x_mm"], p, "-", lw=1.0, color="C3", label="latch-pull model, loaded side")
        ax.plot(
            1e3 * run["x_meas"],
            direction_rule(run["x_meas"], run["dT"], ADAM_FIT),
            "--",
            lw=0.8,
            color="C0",
            label="before: clipped by direction of motion",
        )
        if name.endswith("zone (b)"):
            ax.plot(
                1e3 * fe["x15"],
                fe["dT"],
                "o",
                ms=3,
                mfc="none",
                color="k",
                markevery=4,
                label="FE run, cable/latch element",
            )
        ax.axhline(0, color="k", lw=0.5)
        ax.set_title(name + (" (outer cable loaded)" if "unlatching" in name else " (inner cable loaded)"), fontsize=9)
        ax.set_xlabel("bead position x (mm), Eq. 15")
        ax.set_ylabel("dT = T2 - T1 (N)")
        ax.set_xlim(-2.2, 3.0)
        ax.legend(fontsize=6.5, loc="lower left" if "latching, zone" in name and "un" not in name else "upper right")
    fig.tight_layout()
    out = HERE.parent / "docs" / "figures" / "latch_pull_partial_reversal.png"
    fig.savefig(out, dpi=120)
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
