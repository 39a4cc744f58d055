"""Seated against tied ball joints, and static against kinetic friction (docs/ball_joint.md).

    femast run benchmarks/ball_joint_seat.py [--docs]

Prints (a) the axial force of a strut between two seats against the pull on its end, tied and
seated (with and without a retainer); (b) the longeron forces of one ADAM bay with a warp length
error (+-25 um) with the paper's tied joints and with seated joints, beside the bound the cables'
pretension sets; (c) a stick-slip loop with mu_s = 0.5, mu_k = 0.3 and its dissipation per cycle
against the closed form.  Draws the three panels to docs/figures/ball_joint_seat.png with --docs.
"""

from __future__ import annotations

import argparse
import tempfile
from pathlib import Path

import numpy as np

import femast as fm
from femast.adam import build_bay
from femast.adam.scatter import MastScatter
from femast.adam.steps import CONVERGENCE, add_initial_steps
from femast.elements.ball_joint import add_ball_joints, stick_slip_loop_energy

ROOT = Path(__file__).resolve().parents[1]
SEC = fm.circular_tube(0.02, 0.016, E=70e9)


def strut(seat, retainer=None, L=0.5, u0=2e-5):
    """Axial force (N, + tension) of a strut between two ball joints against the pull u (m) on its end."""
    m = fm.Model(f"strut, {seat}")
    b1, a1 = m.node(0, 0, 0), m.node(0, 0, 0)
    a2, b2 = m.node(L, 0, 0), m.node(L, 0, 0)
    m.beam(a1, a2, SEC, up=(0, 1, 0), n=4)
    extra = dict(seat="seated", clearance_axial=retainer) if seat == "seated" else {}
    add_ball_joints(m, [(a1, b1), (a2, b2)], 0.5, 0.004, **extra)
    m.fix(b1)
    m.fix(a1, "rx", "ry", "rz")
    m.fix(b2, "uy", "uz", "rx", "ry", "rz")
    m.step("push", max_increment=0.1).prescribe(b2, ux=-u0)
    m.step("pull", max_increment=0.02).prescribe(b2, ux=u0)
    res = fm.solve(m, tempfile.mkdtemp(), progress=False)
    return res.node_history(b2, "ux"), res.node_history(b2, "rfx")


def warped_bay(seat, delta=25e-6):
    am = build_bay(seat=seat, scatter=MastScatter(longeron_dL=np.array([[delta, -delta, delta, -delta]])))
    add_initial_steps(am, settle=True)
    frames = []
    fm.Analysis(am.model, None, progress=False, convergence=CONVERGENCE, on_frame=frames.append).run()
    fr = frames[-1]
    p = am.params
    d = np.hypot(p.b, p.l)
    sigma = float(np.sum(fr["el/adam_arm/N"])) * p.l / d  # the cables' pull on the top frame, N
    key = "el/adam_joint/normal_force" if seat == "seated" else "el/adam_joint/F"
    return fr[key].reshape(4, 2), sigma, 8 * p.pretension * p.l / d


def stick_slip(mu_s, mu_k, P=1000.0, A=0.02, ks=2500.0):
    m = fm.Model("stick-slip")
    b, a = m.node(0, 0, 0), m.node(0, 0, 0)
    add_ball_joints(m, [(a, b)], mu_s=mu_s, mu_k=mu_k, B=0.004, k_pen=1e8, k_stick=ks)
    m.fix(b)
    m.fix(a, "uy", "uz", "rx", "ry")
    m.step("press").load(a, fx=-P).prescribe(a, rz=0.0)
    amp = fm.Amplitude([0, 1, 3, 5], [0, 1, -1, 1])
    m.step("cycle", period=5.0, max_increment=0.02).prescribe(a, amplitude=amp, rz=A)
    res = fm.solve(m, tempfile.mkdtemp(), progress=False)
    t = res.time
    D = res.element_history("ball_joint", 1, "dissipated")
    i2, i6 = (int(np.argmin(np.abs(t - x))) for x in (2.0, 6.0))
    cyc = t >= 2.0 - 1e-12  # from +A on: the closed cycles
    th, M = -res.node_history(a, "rz"), res.element_history("ball_joint", 1, "moment")[:, 2]
    return th[cyc], M[cyc], D[i6] - D[i2]


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--docs", action="store_true", help="write docs/figures/ball_joint_seat.png")
    args = ap.parse_args(argv)

    print("(a) strut between two ball joints, 0.5 m aluminium tube: axial force at +-20 um of pull")
    curves = {}
    for label, seat, ret in (
        ("tied", "tied", None),
        ("seated", "seated", None),
        ("seated, retainer at 5 um", "seated", 5e-6),
    ):
        u, f = strut(seat, ret)
        curves[label] = (u, f)
        print(f"    {label:24s} push -20 um: {f[np.argmin(u)]:9.1f} N    pull +20 um: {f[np.argmax(u)]:9.3f} N")

    print("\n(b) one ADAM bay, longerons 0 and 2 longer, 1 and 3 shorter by 25 um (a warp)")
    bay = {}
    for seat in ("tied", "seated"):
        N, sigma, hand = warped_bay(seat)
        bay[seat] = N
        per = ", ".join(f"{N[k].max():.1f}" for k in range(4))
        print(f"    {seat:7s} joint force per longeron (N): {per}")
    print(f"    the cables' pull on the top frame: {sigma:.1f} N (by hand 8 T l / d = {hand:.1f} N)")
    print(
        f"    seated: each long longeron carries {bay['seated'][0, 0]:.1f} N = {bay['seated'][0, 0] / sigma:.4f} of it"
    )

    print("\n(c) one joint, |F| = 1000 N, turned +-0.02 rad: dissipation per cycle")
    loops = {}
    for mu_s, mu_k in ((0.5, 0.5), (0.5, 0.3)):
        th, M, D = stick_slip(mu_s, mu_k)
        loops[(mu_s, mu_k)] = (th, M)
        exact = stick_slip_loop_energy(mu_s, mu_k, 0.004, 1000.0, 0.02, 2500.0)
        print(f"    mu_s = {mu_s}, mu_k = {mu_k}: {D:.6f} J, closed form {exact:.6f} J")

    if not args.docs:
        return
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(1, 3, figsize=(13, 3.8))
    for label, (u, f) in curves.items():
        ax[0].plot(u * 1e6, f, "-", lw=1.5, label=label)
    ax[0].set(
        xlabel="pull on the strut's end (um)", ylabel="axial force (N, + tension)", title="(a) strut between two joints"
    )
    ax[0].legend(fontsize=8)
    x = np.arange(4)
    ax[1].bar(x - 0.2, bay["tied"].max(axis=1), 0.4, label="tied (the paper)")
    seated = bay["seated"].max(axis=1)
    ax[1].bar(x + 0.2, np.maximum(seated, 1e-1), 0.4, label="seated")
    for k in np.flatnonzero(seated == 0):
        ax[1].text(k + 0.2, 0.15, "open", ha="center", fontsize=8)
    ax[1].axhline(sigma, color="k", ls="--", lw=1, label="cables' pull on the frame")
    ax[1].set(yscale="log", xticks=x, xticklabels=["0 (+25 um)", "1 (-25 um)", "2 (+25 um)", "3 (-25 um)"])
    ax[1].set(xlabel="longeron (length error)", ylabel="joint force (N)", title="(b) ADAM bay with a warp")
    ax[1].legend(fontsize=8, loc="center right", framealpha=0.9)
    for (mu_s, mu_k), (th, M) in loops.items():
        ax[2].plot(th * 1e3, M, lw=1.2, label=f"mu_s = {mu_s}, mu_k = {mu_k}")
    ax[2].set(
        xlabel="relative rotation (mrad)", ylabel="friction moment (N m)", title="(c) static and kinetic friction"
    )
    ax[2].legend(fontsize=8)
    fig.tight_layout()
    out = ROOT / "docs" / "figures" / "ball_joint_seat.png"
    fig.savefig(out, dpi=110)
    print(f"\nwrote {out}")


if __name__ == "__main__":
    main()
