"""Figure of the generator's mechanism forms (noise-free), for the docs page (numpy + matplotlib)."""

from __future__ import annotations

import numpy as np

from . import mechanisms as mech
from . import noise as nz
from .cases import EQ15
from .rigs import latch_law


def gallery(path) -> str:
    """Draw one panel per mechanism family, each with its forms, and save a PNG at ``path``."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(2, 3, figsize=(13, 7.5))
    k = 2.5e5
    m = np.concatenate([np.linspace(0, 30, 150), np.linspace(30, -30, 300), np.linspace(-30, 30, 300)])
    a = ax[0, 0]
    u, _ = mech.smooth_load_controlled(m, k, mech.dahl_tangent(10.0, 3e5))
    a.plot(1e3 * u, m, label="Dahl (F_c 10 N m)")
    u, _ = mech.smooth_load_controlled(m, k, mech.bouc_wen_tangent(10.0, 5e-5, 2.0))
    a.plot(1e3 * u, m, label="Bouc-Wen (n 2)")
    u, _ = mech.jenkins_load_controlled(m, k, 2.5e5, 10.0)
    a.plot(1e3 * u, m, label="Jenkins (k_s = k)")
    a.set_title("joint friction (load controlled)")
    a.set_xlabel("joint rotation (mrad)")
    a.set_ylabel("moment (N m)")
    a = ax[0, 1]
    ms = np.linspace(-30, 30, 601)
    a.plot(1e3 * (ms / k + mech.clearance_tanh(ms, 1e-4, 6.0)), ms, label="tanh (m0 6 N m)")
    a.plot(1e3 * (ms / k + mech.clearance_hertz(ms, 1e-4, 2e4, 5.7e7)), ms, label="play + Hertz contact")
    a.plot(1e3 * (ms / k + mech.clearance_piecewise(ms, 1e-4, 2.5e4, 5e6)), ms, label="piecewise-linear")
    a.set_title("clearance")
    a.set_xlabel("joint rotation (mrad)")
    a = ax[0, 2]
    a.plot(1e3 * mech.duffing_rotation(ms, k, 1e8 * k), ms, label="cubic (Duffing)")
    a.plot(1e3 * mech.asinh_rotation(ms, k, 12.0), ms, label="asinh")
    a.plot(1e3 * ms / k, ms, "k:", lw=0.8, label="linear")
    a.plot(1e3 * mech.loop_quadratic(m, 1.0) / k, m, label="cable loop, quadratic")
    a.plot(1e3 * mech.loop_power(m, 1.0) / k, m, label="cable loop, power")
    a.set_title("stiffening and cable loops")
    a.set_xlabel("joint rotation (mrad)")
    a = ax[1, 0]
    tau = np.linspace(0, 1, 200)
    a.plot(tau, mech.compliance_drift(tau, 0.6, "exp"), label="creep (exp)")
    a.plot(tau, mech.compliance_drift(tau, 0.25, "step"), label="slip (step)")
    a.set_title("pretension loss: compliance factor")
    a.set_xlabel("normalised time")
    a = ax[1, 1]
    x = np.linspace(-2e-3, 4e-3, 600)
    s = x + 2e-3
    for form, F, ell in (("gauss", 8.0, 4e-4), ("linear", 7.0, 6e-4), ("lorentz", 8.0, 2.5e-4)):
        a.plot(1e3 * x, np.maximum(latch_law(x, 1) + F * mech.fade(s, ell, form), 0), label=f"band, {form} fade")
    a.plot(1e3 * x, np.maximum(latch_law(x, 1), 0), "k:", lw=0.8, label="published latch law, unlatching")
    a.plot(1e3 * x, np.minimum(latch_law(x, -1), 0), "k--", lw=0.8, label="published latch law, latching")
    a.set_xlim(-2.1, 1.0)
    a.set_title("latch hysteresis near the latched state")
    a.set_xlabel("x (mm)")
    a.set_ylabel("dT (N)")
    a = ax[1, 2]
    xs = np.linspace(-2e-3, 2.3e-3, 800)
    for d, lab in ((1, "unlatching"), (-1, "latching")):
        f = latch_law(xs, d)
        sd = np.sqrt(nz.eq15_residual_variance(np.gradient(f, xs), EQ15["C"], EQ15["sigma_T"], EQ15["sigma_d"]))
        a.plot(1e3 * xs, sd, label=lab)
    a.axhline(EQ15["sigma_T"], color="k", ls=":", lw=0.8, label="load cell alone")
    a.set_title("Eq. 15 noise: residual std along the law")
    a.set_xlabel("x (mm)")
    a.set_ylabel("std of dT residual (N)")
    for a in ax.ravel():
        a.legend(fontsize=7)
        a.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return str(path)
