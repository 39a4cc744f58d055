"""Figure of the effect families: the loop or curve each form of an effect draws.

    python benchmarks/effect_families.py        # writes docs/figures/effect_families.png

Panels: joint friction on a load cycle (play: rigid stick; jenkins: finite stick stiffness; iwan:
distributed micro-slip, smooth Masing loops), clearance (sharp against fitted closing scales),
the fade of the latch hysteresis (gamma = 0 exponential, 1 linear, -1 hyperbolic, 2 abrupt), the
progressive stiffness (linear / quadratic), the pretension loss (linear / saturating) and the
cable hysteresis (play: one proportional play; iwan: fibre groups with a distribution of friction
coefficients, smooth returns, every loop closing at zero load).  The
curves are the effect operators themselves (femast.effects), unit joint stiffness.
"""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from femast.effects.latch import fade  # noqa: E402
from femast.effects.operators import iwan, jenkins, play, proportional_iwan, proportional_play  # noqa: E402

OUT = Path(__file__).resolve().parents[1] / "docs" / "figures" / "effect_families.png"


def main() -> Path:
    u = np.concatenate(
        [
            np.linspace(0, 100, 201),
            np.linspace(100, -100, 401),
            np.linspace(-100, 100, 401),
            np.linspace(100, 40, 121),
            np.linspace(40, 70, 61),
        ]
    )
    fig, ax = plt.subplots(1, 5, figsize=(21, 4.2))
    a = ax[0]
    a.plot(u, u, color="0.7", lw=1, label="elastic joint")
    a.plot(u, play(u, 15.0), label="play (M_f = 15): rigid stick")
    a.plot(u, jenkins(u, 15.0, 0.4), label="jenkins (alpha = 0.4): stick stiffness")
    a.plot(u, iwan(u, 30.0, 1.0, 0.0), label="iwan (M_f = 30, beta = 1): micro-slip")
    a.plot(u, iwan(u, 30.0, 4.0, 0.2), label="iwan (beta = 4, alpha = 0.2)")
    a.set_xlabel("joint moment m (N m)")
    a.set_ylabel("moment on the elastic joint, k theta (N m)")
    a.set_title("friction_hysteresis forms (load cycle with an inner loop)")
    a.legend(fontsize=7)
    a.grid(alpha=0.3)
    a = ax[1]
    m = np.linspace(-60, 60, 601)
    ms = 0.01 * 60
    a.plot(m, 1e3 * 1e-4 * np.tanh(m / ms), label="sharp: m_s = 1 % of max |m|")
    for mc in (5.0, 15.0, 40.0):
        a.plot(m, 1e3 * 1e-4 * np.tanh(m / mc), label=f"smooth: M_c = {mc:g} N m")
    a.set_xlabel("joint moment m (N m)")
    a.set_ylabel("extra rotation (mrad), c = 0.1 mrad")
    a.set_title("joint_clearance forms")
    a.legend(fontsize=7)
    a.grid(alpha=0.3)
    a = ax[2]
    d = np.linspace(0, 1.2e-3, 400)
    for g, lab in (
        (0.0, "exponential (gamma = 0, default form)"),
        (1.0, "linear (gamma = 1)"),
        (-1.0, "hyperbolic (gamma = -1)"),
        (2.0, "abrupt (gamma = 2)"),
    ):
        a.plot(1e3 * d, fade(d, 3e-4, g), label=lab)
    a.set_xlabel("bead distance from the backstop d (mm)")
    a.set_ylabel("share of F_h, w")
    a.set_title("latch_hysteresis/shaped: fade, ell = 0.3 mm")
    a.legend(fontsize=7)
    a.grid(alpha=0.3)
    a = ax[3]
    mm = np.linspace(0, 400, 200)
    a.plot(mm, 1 / (1 + 1e-3 * mm), label="progressive linear: 1/(1 + beta |m|)")
    a.plot(mm, 1 / (1 + 5e-4 * mm + 2e-6 * mm**2), label="progressive quadratic (+ beta2 m^2)")
    tau = np.linspace(0, 1, 200)
    a2 = a.twiny()
    a2.plot(tau, 1 / (1 - 0.2 * tau), "--", color="C2", label="pretension linear (lam = 0.2)")
    a2.plot(
        tau,
        1 / (1 - 0.2 * -np.expm1(-tau / 0.15) / -np.expm1(-1 / 0.15)),
        "--",
        color="C3",
        label="pretension saturating (t_c = 0.15)",
    )
    a.set_xlabel("joint moment |m| (N m) -- solid")
    a2.set_xlabel("normalised time tau -- dashed")
    a.set_ylabel("compliance / baseline compliance")
    a.legend(fontsize=7, loc="lower left")
    a2.legend(fontsize=7, loc="upper left")
    a.grid(alpha=0.3)
    a = ax[4]
    c = np.concatenate(
        [
            np.linspace(0, 100, 201),
            np.linspace(100, 0, 201),
            np.linspace(0, -60, 121),
            np.linspace(-60, 0, 121),
            np.linspace(0, 70, 141),
            np.linspace(70, 30, 81),
            np.linspace(30, 60, 61),
        ]
    )
    a.plot(c, c, color="0.7", lw=1, label="no hysteresis")
    a.plot(c, proportional_play(c, 0.2), label="play (eta = 0.2)")
    a.plot(c, proportional_iwan(c, 0.5, 1.0, 0.0), label="iwan (eta = 0.5, beta = 1)")
    a.plot(c, proportional_iwan(c, 0.9, 0.5, 0.2), label="iwan (eta = 0.9, beta = 0.5, alpha = 0.2)")
    a.set_xlabel("load through the rope, joint moment m (N m)")
    a.set_ylabel("load on the elastic part (N m)")
    a.set_title("cable_hysteresis forms (close at 0)")
    a.legend(fontsize=7)
    a.grid(alpha=0.3)
    fig.tight_layout()
    OUT.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(OUT, dpi=90)
    plt.close(fig)
    print(f"wrote {OUT}")
    return OUT


if __name__ == "__main__":
    main()
