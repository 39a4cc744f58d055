"""Cable over devices: the verification figures and errors of docs/cable_devices.md.

    PYTHONPATH=$PWD python benchmarks/cable_devices.py [--out docs/figures]

1. A capstan pulley (mu = 0.3, wrap pi/2 from the geometry): one end pulled out then back in; the
   tension ratio T_out/T_in against the band exp(+-mu phi) (Euler-Eytelwein).
2. Two latches on one cable (Stohlman & Pellegrino's latch law, k = 100 and 30 N/mm): pulled until both release; the
   jumps T_{i+1} - T_i against the peaks of Eq. 14.
3. A frictionless pulley of radius 0.2 m moved along a path: cable length conserved and the
   tension against T = EA (L_geom/L0 - 1) with the closed-form wrapped length.
"""

from __future__ import annotations

import argparse
import math
import time
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from femast.elements.base import IncrementContext  # noqa: E402
from femast.elements.cable_devices import CableDeviceFamily, Latch, Pulley  # noqa: E402
from femast.elements.latch_law import LatchParameters, latch_force  # noqa: E402

EA = 1.0e5


def run(fam, X0, moves):
    """Evaluate the element along a path of node moves (k, n_nodes, 3), committing each state."""
    st = fam.initial_state()
    out = []
    for dX in moves:
        r = fam.evaluate(X0 + dX, None, st, IncrementContext())
        st = r.state
        out.append((r.output["tension"][0].copy(), r.state[0].copy(), dict(r.output)))
    return out


def capstan(ax):
    mu = 0.3
    X = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.2, 0.0]])
    fam = CableDeviceFamily.pretensioned([[0, 1, 2]], X, EA, 100.0, [Pulley(mu=mu)])
    u = np.r_[np.linspace(0, 0.01, 101), np.linspace(0.01, -0.004, 141)]
    moves = np.zeros((len(u), 3, 3))
    moves[:, 2, 1] = u
    res = run(fam, X, moves)
    with np.errstate(divide="ignore", invalid="ignore"):  # both sides slack at the end of the return stroke
        ratio = np.array([T[1] / T[0] for T, _, _ in res])
    mode = np.array([s[1] for _, s, _ in res])
    lim = math.exp(mu * math.pi / 2)
    err = max(abs(ratio[mode == 1] / lim - 1).max(), abs(ratio[mode == -1] * lim - 1).max())
    ax.plot(u[:101] * 1e3, ratio[:101], "C0-", label="pull out")
    ax.plot(u[100:] * 1e3, ratio[100:], "C1-", label="then back in")
    for v in (lim, 1 / lim):
        ax.axhline(v, color="k", ls="--", lw=0.8)
    ax.text(0.0, lim * 1.02, r"$e^{\mu\varphi}$", fontsize=9)
    ax.text(0.0, 1 / lim * 1.02, r"$e^{-\mu\varphi}$", fontsize=9)
    ax.set_xlabel("displacement of the pulled end, mm")
    ax.set_ylabel(r"$T_{out}/T_{in}$")
    ax.set_title(f"capstan pulley, mu = {mu}, wrap pi/2 from the geometry", fontsize=9)
    ax.legend(fontsize=8)
    return err


def two_latches(ax):
    P1 = LatchParameters.adam_fit()
    P2 = LatchParameters(r=1.1e-3, x_backstop=2.0e-3, k=30e3, mu=0.07, h=1.5e-3, R=2.4e-3)
    X = np.array([[0.0, 0, 0], [0.5, 0, 0], [5.5, 0, 0], [6.0, 0, 0]])
    fam = CableDeviceFamily.pretensioned([[0, 1, 2, 3]], X, 2.0e4, 5.0, [Latch(P1), Latch(P2)])
    u = np.linspace(0.0, 0.06, 2001)[1:]
    moves = np.zeros((len(u), 4, 3))
    moves[:, 3, 0] = u
    res = run(fam, X, moves)
    jumps = np.array([[T[1] - T[0], T[2] - T[1]] for T, _, _ in res])
    xs = np.linspace(-2e-3, 3e-3, 20001)
    peaks = [latch_force(xs, 1, P).max() for P in (P1, P2)]
    ax.plot(u * 1e3, jumps[:, 1], "C1-", label="latch B (k = 30 N/mm): $T_2 - T_1$")
    ax.plot(u * 1e3, jumps[:, 0], "C0-", label="latch A (k = 100 N/mm): $T_1 - T_0$")
    for p, c in zip(peaks, ("C0", "C1")):
        ax.axhline(p, color=c, ls="--", lw=0.8)
    ax.set_xlabel("displacement of the pulled end, mm")
    ax.set_ylabel("tension jump across the latch, N")
    ax.set_title("two latches released one after the other (dashed: Eq. 14 peaks)", fontsize=9)
    ax.legend(fontsize=8)
    return [abs(jumps[:, k].max() / peaks[k] - 1) for k in (0, 1)]


def sized_pulley(ax):
    r = 0.2
    X = np.array([[0.0, 2.0, 0.0], [1.0, 0.0, 0.0], [2.0, 2.0, 0.0]])
    fam = CableDeviceFamily.pretensioned([[0, 1, 2]], X, EA, 100.0, [Pulley(radius=r)])
    t = np.linspace(0, 1.2, 61)
    moves = np.zeros((len(t), 3, 3))
    moves[:, 1] = np.column_stack([t, -0.3 * t, 0.1 * t])
    res = run(fam, X, moves)
    dL0, dT, wrap = [], [], []
    for (T, _st, o), mv in zip(res, moves):
        Xp = X + mv
        a, b = Xp[0] - Xp[1], Xp[2] - Xp[1]
        da, db = np.linalg.norm(a), np.linalg.norm(b)
        phi = 2 * math.pi - math.acos(a @ b / (da * db)) - math.acos(r / da) - math.acos(r / db)
        Lg = math.sqrt(da**2 - r**2) + math.sqrt(db**2 - r**2) + r * phi
        dL0.append(abs(o["unstretched_length"][0].sum() - fam.L0[0]) / fam.L0[0])
        dT.append(abs(T[0] / (EA * (Lg / fam.L0[0] - 1)) - 1))
        wrap.append(o["wrap_angle"][0, 0])
    ax.plot(t, np.degrees(wrap), "C2-")
    ax.set_xlabel("pulley centre moved along (1, -0.3, 0.1), m")
    ax.set_ylabel("wrap angle, deg")
    ax.set_title(f"pulley of radius {r} m: wrap angle follows the geometry", fontsize=9)
    return max(dL0), max(dT)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default="docs/figures", help="folder for the PNG figures")
    args = ap.parse_args(argv)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    fig, axs = plt.subplots(1, 3, figsize=(15, 4.2))
    e_cap = capstan(axs[0])
    e_lat = two_latches(axs[1])
    e_len, e_T = sized_pulley(axs[2])
    fig.tight_layout()
    path = out / "cable_devices.png"
    fig.savefig(path, dpi=110)
    print(f"capstan ratio in slip vs exp(+-mu phi): max relative error {e_cap:.2e}")
    print(f"two latches: largest jump vs Eq. 14 peak: A {e_lat[0]:.2e}, B {e_lat[1]:.2e} (load step 3e-5 m)")
    print(f"sized pulley: |sum l0 - L0|/L0 max {e_len:.1e}; tension vs closed-form wrapped length {e_T:.1e}")
    print(f"figure: {path}  ({time.perf_counter() - t0:.1f} s)")


if __name__ == "__main__":
    main()
