"""A user's rig for the experiments tests: a connection loaded along two axes (force in, displacement
out), written as docs/your_own_rig.md writes one, and a data generator that shares no code or
functional form with the library's effects: a gap crossed by a soft centring spring
(``clip(F / k_c, -g, g)``, not the library's ``tanh``), with holds (repeated rows) and groups."""

import numpy as np

from femast.effects import Parameter, Quantity
from femast.experiments import Column, Experiment, from_arrays

K = (2e6, 3e6)  # N/m, the springs along x and y


def _model(params, data, effects, options):
    F = np.column_stack([data["Fx_N"], data["Fy_N"]])
    F_eff = effects.apply("load", F) if effects else F
    u = F_eff / np.array([params["k_x"], params["k_y"]])
    if effects:
        u = effects.apply("displacement", u)
    return {"ux_mm": 1e3 * u[:, 0], "uy_mm": 1e3 * u[:, 1]}


RIG = Experiment(
    name="two-axis-joint",
    title="a connection loaded along two axes",
    columns=(
        Column("Fx_N", "N", "force along x"),
        Column("Fy_N", "N", "force along y"),
        Column("ux_mm", "mm", "displacement along x"),
        Column("uy_mm", "mm", "displacement along y"),
    ),
    channels=("ux_mm", "uy_mm"),
    parameters=(
        Parameter("k_x", "N/m", 1e6, 1e3, 1e9, "stiffness along x"),
        Parameter("k_y", "N/m", 1e6, 1e3, 1e9, "stiffness along y"),
    ),
    model=_model,
    quantities={
        "load": Quantity("N", axes=("x", "y"), scale=1e3, doc="force on the connection"),
        "displacement": Quantity("m", axes=("x", "y"), scale=1e-3, doc="displacement of the connection"),
    },
    error_unit="mm",
)


def loads(n=400, cycles=4.0, hold=1):
    """Force path (n,) x 2 in N: sines along x and y; ``hold`` > 1 repeats every row that many times."""
    t = np.linspace(0.0, cycles, max(n // hold, 2))
    F = np.column_stack([800.0 * np.sin(2 * np.pi * t), 600.0 * np.sin(2 * np.pi * t + 1.0)])
    return np.repeat(F, hold, axis=0)


def data(gap_x=2e-4, noise_mm=5e-3, n=400, hold=1, seed=3, spikes=0, groups=None):
    """Measured data of the rig: springs K, a gap along x (m, half width), white noise (mm), optional
    spikes (30 noise levels), holds (every load state measured ``hold`` times) and a group column."""
    rng = np.random.default_rng(seed)
    F = loads(n, hold=hold)
    n = len(F)
    ux = F[:, 0] / K[0] + np.clip(F[:, 0] / 1e5, -gap_x, gap_x)
    uy = F[:, 1] / K[1]
    ex, ey = rng.normal(0, noise_mm, n), rng.normal(0, noise_mm, n)
    if spikes:
        i = rng.choice(n, spikes, replace=False)
        ex[i] += rng.choice([-1, 1], spikes) * 30 * noise_mm
    cols = dict(Fx_N=F[:, 0], Fy_N=F[:, 1], ux_mm=1e3 * ux + ex, uy_mm=1e3 * uy + ey)
    if groups is not None:
        cols["group"] = groups
    return from_arrays(RIG, **cols)
