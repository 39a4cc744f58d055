"""Synthetic measurements with hidden effects, for tests, benchmarks and the tutorial data sets.

The truth is the experiment's own model with some effects switched on (and, for the
out-of-library case, a slow drift that no effect models), sampled along a load path, plus
Gaussian noise.  A diagnosis of such data must find the hidden effect.

* :func:`mast_top_path` -- wrench paths on a mast top (cycles, ramps with partial unloading,
  rotating direction, the the Rocaspect paper, Fig. 5a trajectory);
* :func:`mast_top_data` -- top displacements from the 3R model with hidden effects;
* :func:`latch_pull_data` -- pull-test passes (holds on the backstop, unlatching, latching)
  from the latch law with hidden effects.
"""

from __future__ import annotations

import numpy as np

from femast._moved import renamed
from femast.effects import resolve
from femast.elements.latch_law import LATCHING, UNLATCHING, latch_force
from femast.errors import ModelError
from femast.experiments.core import EffectStack, Measured
from femast.experiments.prediction import predict
from femast.experiments.registry import get_experiment


def _stack(exp, effects):
    effects = effects or {}
    items = []
    for name, impl in resolve(exp, list(effects)):
        vals = {p.name: float(p.default) for p in impl.parameters}
        vals.update(effects[name])
        items.append((name, impl, vals))
    return EffectStack(items)


# --------------------------------------------------------------------------- mast-top
def mast_top_path(
    n: int = 500,
    kind: str = "cycles",
    amplitude_N: float = 150.0,
    cycles: float = 4.0,
    angle_deg: float = 30.0,
    moment_Nm: float = 0.0,
    seed: int = 0,
) -> dict:
    """Wrench changes on a mast top, ``{fx_N, ..., mz_Nm}`` arrays (n,) in N and N m.

    kind : ``"cycles"`` (zero-mean force cycles along ``angle_deg`` with an amplitude that varies
        from cycle to cycle), ``"ramps"`` (piecewise-linear ramps with random turning loads, partial
        unloading and reversals away from zero), ``"rotating"`` (a force of varying magnitude whose
        direction turns), ``"rocaspect_fig5a"`` (the mast-1 wrench along the trajectory of Fig. 5a of the
        Rocaspect paper, repeated ``cycles`` times; ``"seed000"``, its old name, warns and is removed
        in femast 0.3).
    moment_Nm : amplitude of top moments out of phase with the force (an offset attachment);
        needed to separate beam bending from joint rotation.
    """
    if kind == "seed000":
        renamed("mast_top_path(kind='seed000')", "mast_top_path(kind='rocaspect_fig5a')")
        kind = "rocaspect_fig5a"
    rng = np.random.default_rng(seed)
    t = np.linspace(0.0, 1.0, n)
    a = np.radians(angle_deg)
    if kind == "cycles":
        env = 0.55 + 0.45 * np.abs(np.sin(np.pi * (0.5 + cycles * t / 2.0) * 0.73 + rng.uniform(0, 1)))
        F = amplitude_N * env * np.sin(2 * np.pi * cycles * t)
        fx, fy = F * np.cos(a), F * np.sin(a)
    elif kind == "ramps":
        k = max(int(round(2 * cycles)) + 1, 3)
        turns = rng.uniform(0.35, 1.0, k) * np.where(np.arange(k) % 2 == 0, 1.0, -1.0)
        turns[1::4] *= rng.uniform(-0.4, 0.2, turns[1::4].size) * -1  # some reversals away from zero
        knots = np.concatenate([[0.0], turns, [0.0]])
        F = amplitude_N * np.interp(t, np.linspace(0, 1, knots.size), knots)
        fx, fy = F * np.cos(a), F * np.sin(a)
    elif kind == "rotating":
        mag = amplitude_N * (0.6 + 0.4 * np.sin(2 * np.pi * 1.5 * t + rng.uniform(0, 6)))
        ang = a + 2 * np.pi * 0.5 * cycles * t
        F = mag * np.sin(2 * np.pi * cycles * t)
        fx, fy = F * np.cos(ang), F * np.sin(ang)
    elif kind == "rocaspect_fig5a":
        from femast.guyed.cdpr import trajectory_loads
        from femast.guyed.rocaspect import fig5a_trajectory, rocaspect_geometry

        _, wr = trajectory_loads(rocaspect_geometry(), fig5a_trajectory(12))
        dw = wr[:, 0] - wr[0, 0]
        one = np.linspace(0, 1, dw.shape[0])
        tt = (t * cycles) % 1.0
        w = np.column_stack([np.interp(tt, one, dw[:, j]) for j in range(6)])
        return dict(zip(("fx_N", "fy_N", "fz_N", "mx_Nm", "my_Nm", "mz_Nm"), w.T))
    else:
        raise ModelError(f"unknown path kind {kind!r}; use cycles, ramps, rotating or rocaspect_fig5a")
    fz = -0.3 * np.abs(F)
    ph = 2 * np.pi * cycles * t + np.pi / 2
    mx = moment_Nm * np.sin(ph) * np.cos(a + 1.0)
    my = moment_Nm * np.sin(ph) * np.sin(a + 1.0)
    mz = 0.1 * moment_Nm * np.sin(ph)
    return {"fx_N": fx, "fy_N": fy, "fz_N": fz, "mx_Nm": mx, "my_Nm": my, "mz_Nm": mz}


def mast_top_data(
    params=None, effects=None, path=None, noise_m: float = 5e-5, drift_m: float = 0.0, seed: int = 0, experiment=None
) -> tuple:
    """Synthetic mast-top data: the 3R model with hidden ``effects`` along ``path``, plus noise.

    params : baseline ``{k_theta1, k_theta2}`` (N m/rad; default 2.7e5, 2.3e5 as the Rocaspect paper, Table III).
    effects : ``{effect: {param: value}}`` hidden in the truth.
    path : wrench dict (:func:`mast_top_path`; default cycles).  noise_m : noise of each displacement, m.
    drift_m : amplitude of a slow thermal drift of the top (m) that no effect models.
    Returns ``(data, truth)`` with ``truth`` the noise-free displacements ``{dx_m, dy_m, dz_m}``.
    """
    exp = experiment or get_experiment("mast-top")
    rng = np.random.default_rng(seed + 1000)
    path = path or mast_top_path(seed=seed)
    n = len(path["fx_N"])
    zeros = {c: np.zeros(n) for c in exp.channels}
    data = Measured(exp.name, {**path, **zeros})
    truth = predict(exp, data, params or {"k_theta1": 2.7e5, "k_theta2": 2.3e5}, effects or {})
    if drift_m:
        tau = data.tau
        drift = drift_m * np.column_stack(
            [np.sin(0.5 * np.pi * tau), 0.7 * (1 - np.cos(np.pi * tau)), 0.3 * np.sin(np.pi * tau)]
        )
        truth = {c: truth[c] + drift[:, i] for i, c in enumerate(exp.channels)}
    noisy = {c: truth[c] + rng.normal(0.0, noise_m, n) for c in exp.channels}
    return Measured(exp.name, {**path, **noisy}), truth


# --------------------------------------------------------------------------- latch-pull
def latch_pull_data(
    params=None,
    effects=None,
    *,
    passes=2,
    n_move: int = 120,
    n_hold: int = 30,
    x_far_mm=(4.0, 3.2),
    T_hold_N: float = 40.0,
    noise_N: float = 0.5,
    noise_mm: float = 0.01,
    drift_N: float = 0.0,
    seed: int = 0,
    experiment=None,
) -> tuple:
    """Synthetic latch pull tests: the latch law (Stohlman & Pellegrino, Eq. 14) with hidden ``effects``, plus noise.

    Each pass: the bead sits latched on the backstop while the latching cable pulls it in to
    ``T_hold_N`` and releases (hold), the unlatching cable loads it until it moves (stick on the
    backstop) and pulls it out to ``x_far_mm`` (unlatching), then the latching cable pulls it back
    in to the backstop (latching).  ``n_move`` samples per pass direction, ``n_hold`` per hold.
    params : baseline ``{r, x_backstop, k, mu}`` (SI; default the paper's fit).
    drift_N : a slow drift of the load cell (N) that no effect models.
    Returns ``(data, truth)`` with the true bead positions (m) and force jumps (N).
    """
    exp = experiment or get_experiment("latch-pull")
    o = exp.options
    p = {**exp.defaults(), **(params or {})}
    pa = np.array([p["r"], p["x_backstop"], p["k"], p["mu"], o["h_m"], o["R_m"]])
    stack = _stack(exp, effects)
    xb = p["x_backstop"]
    rng = np.random.default_rng(seed + 2000)
    far = (
        np.broadcast_to(np.asarray(x_far_mm, float), (passes,))
        if np.ndim(x_far_mm) == 0
        else np.resize(np.asarray(x_far_mm, float), passes)
    )

    def branches(x, dT_for_ctx):
        X = np.concatenate([np.maximum(x, -xb), [-xb]])
        D = np.column_stack([latch_force(X, LATCHING, pa), latch_force(X, UNLATCHING, pa)])
        prep = {"x": x, "dT": dT_for_ctx, "tau": np.zeros(x.size)}
        D = stack.apply("branch_force", D, x=X, data=None, options=o, params=p, prep=prep)
        if o["one_sided"]:
            D = np.column_stack([np.minimum(D[:, 0], 0.0), np.maximum(D[:, 1], 0.0)])
        return D

    xs, dTs = [], []
    for k in range(passes):
        hold = -T_hold_N * np.sin(np.linspace(0, np.pi, n_hold))  # latched, pulled in and released
        xs.append(np.full(n_hold, -xb))
        dTs.append(hold)
        d_stop = branches(np.array([-xb]), np.zeros(1))[-1, 1]  # unlatching force to leave the backstop
        n_st = max(n_hold // 2, 3)
        xs.append(np.full(n_st, -xb))
        dTs.append(np.linspace(0.0, d_stop, n_st + 1)[1:])
        x_out = np.linspace(-xb, 1e-3 * far[k], n_move + 1)[1:]
        xs.append(x_out)
        dTs.append(branches(x_out, np.zeros(n_move))[:-1, 1])
        x_in = np.linspace(1e-3 * far[k], -xb, n_move + 1)[1:]
        xs.append(x_in)
        dTs.append(branches(x_in, np.zeros(n_move))[:-1, 0])
    xb_true = np.concatenate(xs)
    dT = np.concatenate(dTs)
    # measured position: invert the bead_position hook (fixed point; the built-in ones depend on dT only)
    x_meas = xb_true.copy()
    if stack.on("bead_position"):
        prep = {"dT": dT, "tau": np.zeros(dT.size)}
        for _ in range(50):
            prep["x"] = x_meas
            x_seen = stack.apply("bead_position", x_meas, data=None, options=o, params=p, prep=prep)
            x_meas = x_meas + (xb_true - x_seen)
    n = dT.size
    dT_meas = dT + rng.normal(0.0, noise_N, n)
    if drift_N:
        dT_meas = dT_meas + drift_N * np.sin(0.5 * np.pi * np.linspace(0, 1, n))
    x_mm = 1e3 * x_meas + rng.normal(0.0, noise_mm, n)
    return Measured(exp.name, {"x_mm": x_mm, "dT_N": dT_meas}), {"x_m": xb_true, "dT_N": dT}


# --------------------------------------------------------------------------- bay-torsion (FE)
def bay_torsion_path(
    n: int = 41,
    theta_max_deg: float = 3.2,
    kind: str = "cycle",
    cycles: float = 1.0,
    offaxis_mm: float = 0.0,
    seed: int = 0,
) -> dict:
    """Twist paths of the single-bay torsion test, ``{theta_deg}`` (and ``ux_m, uy_m`` when
    ``offaxis_mm`` > 0), n rows.

    kind : ``"cycle"`` (0 -> theta_max -> 0, ``cycles`` times), ``"partial"`` (out to theta_max,
        back to 45-60 % of it, out again to 80-100 %, back to 0: reversals away from zero),
        ``"release"`` (0 -> theta_max -> 0 with rows twice as dense near 0 and through the
        release of the latches, 1.9-2.8 degrees).
    offaxis_mm : a measured drift of the top-frame centre (the paper's up to 1 cm), growing with
        the twist: ``u = offaxis (sin(0.7 + seed), cos(0.7 + seed)) (theta / theta_max)^2``.
    """
    rng = np.random.default_rng(seed)
    if kind == "cycle":
        u = np.linspace(0.0, 2.0 * cycles, n)
        th = theta_max_deg * (1.0 - np.abs((u % 2.0) - 1.0))
    elif kind == "partial":
        a, b = rng.uniform(0.45, 0.6), rng.uniform(0.8, 1.0)
        knots = np.array([0.0, 1.0, a, b, 0.0]) * theta_max_deg
        length = np.concatenate([[0.0], np.cumsum(np.abs(np.diff(knots)))])
        th = np.interp(np.linspace(0.0, length[-1], n), length, knots)
    elif kind == "release":
        w = lambda x: 1.0 + 1.0 * (np.abs(x - 0.0) < 0.5) + 1.0 * ((x > 1.9) & (x < 2.8))  # noqa: E731
        grid = np.linspace(0.0, theta_max_deg, 2001)
        s = np.concatenate([[0.0], np.cumsum(w(grid[1:]) * np.diff(grid))])
        half = np.interp(np.linspace(0.0, s[-1], n // 2 + 1), s, grid)
        th = np.concatenate([half, half[-2::-1]])[:n] if n % 2 else np.concatenate([half, half[-2:0:-1]])
        th = th[:n]
    else:
        raise ModelError(f"unknown path kind {kind!r}; use cycle, partial or release")
    out = {"theta_deg": th}
    if offaxis_mm:
        f = (th / max(theta_max_deg, 1e-12)) ** 2
        out["ux_m"] = 1e-3 * offaxis_mm * np.sin(0.7 + seed) * f
        out["uy_m"] = 1e-3 * offaxis_mm * np.cos(0.7 + seed) * f
    return out


def bay_torsion_data(
    params=None, effects=None, path=None, noise_Nm: float = 0.2, drift_Nm: float = 0.0, seed: int = 0, experiment=None
) -> tuple:
    """Synthetic single-bay torsion data: the FE bay (the experiment's own model) with hidden
    ``effects`` along ``path`` (:func:`bay_torsion_path`), plus Gaussian noise ``noise_Nm`` on Mz.

    params : baseline ``{latch_k, latch_mu}`` (default the paper's pull-test fit).
    drift_Nm : amplitude of a slow drift of the load cell (N m) that no effect models.
    Returns ``(data, truth)`` with ``truth`` the noise-free ``{Mz_Nm}``."""
    exp = experiment or get_experiment("bay-torsion")
    path = dict(path or bay_torsion_path(seed=seed))
    n = len(path["theta_deg"])
    data = Measured(exp.name, {**path, "Mz_Nm": np.zeros(n)})
    truth = predict(exp, data, params or {}, effects or {})
    if drift_Nm:
        truth = {"Mz_Nm": truth["Mz_Nm"] + drift_Nm * np.sin(0.5 * np.pi * data.tau)}
    rng = np.random.default_rng(seed + 3000)
    return Measured(exp.name, {**path, "Mz_Nm": truth["Mz_Nm"] + rng.normal(0.0, noise_Nm, n)}), truth


# --------------------------------------------------------------------------- tip-cycle (FE)
def tip_cycle_path(
    points_per_ramp: int = 3,
    cycles: int = 2,
    M_Nm: float = 6.8,
    F_N: float = 14.0,
    kind: str = "table1",
    hold: int = 0,
    seed: int = 0,
) -> dict:
    """Tip load paths ``{fx_N, ..., mz_Nm}``: the sequence 0, +P, 0, -P, 0 ... with ``P`` = M about z and
    F along x (Stohlman & Pellegrino, Table 1), ``cycles`` times, each ramp sampled at ``points_per_ramp`` rows.
    hold : extra rows at every turning load and at every return to zero (the load held while the
    tip is measured, as in Table 1; the FE model repeats the state, so they cost nothing).

    kind : ``"table1"`` (every peak at full load), ``"varying"`` (peaks of 55-100 % of P, different
        from cycle to cycle, and a partial unloading to 30-50 % in each cycle: reversals away from
        zero), ``"shear"`` (F along a direction turning by 40 degrees per cycle, M at 30 %).
    """
    rng = np.random.default_rng(seed)
    knots = [np.zeros(6)]
    for c in range(cycles):
        for sign in (1.0, -1.0):
            if kind == "table1":
                a, part = 1.0, None
            elif kind == "varying":
                a, part = rng.uniform(0.55, 1.0), rng.uniform(0.3, 0.5)
            elif kind == "shear":
                a, part = 1.0, None
            else:
                raise ModelError(f"unknown path kind {kind!r}; use table1, varying or shear")
            ang = np.radians(40.0 * c) if kind == "shear" else 0.0
            m = (0.3 if kind == "shear" else 1.0) * M_Nm
            peak = sign * a * np.array([F_N * np.cos(ang), F_N * np.sin(ang), 0.0, 0.0, 0.0, m])
            knots.append(peak)
            if part is not None:
                knots.append(part * peak)
                knots.append(peak * rng.uniform(0.8, 1.0))
            knots.append(np.zeros(6))
    rows = [knots[0]] * (1 + hold)
    for a, b in zip(knots[:-1], knots[1:]):
        for k in range(1, points_per_ramp):
            rows.append(a + (b - a) * k / points_per_ramp)
        rows += [b] * (1 + hold)  # the knot itself, exactly (a hold must repeat it bit for bit)
    w = np.array(rows)
    return dict(zip(("fx_N", "fy_N", "fz_N", "mx_Nm", "my_Nm", "mz_Nm"), w.T))


def tip_cycle_data(
    params=None,
    effects=None,
    path=None,
    noise_m: float = 2e-6,
    noise_rad: float = 5e-6,
    drift_m: float = 0.0,
    seed: int = 0,
    experiment=None,
) -> tuple:
    """Synthetic tip-cycle data: the FE mast (the experiment's own model, its ``n_bays`` option) with
    hidden ``effects`` along the load ``path`` (:func:`tip_cycle_path`), plus Gaussian noise
    (``noise_m`` on displacements, ``noise_rad`` on rotations).

    params : baseline ``{cable_EA}``.  drift_m : a slow drift of the tip along x and y
    (m) that no effect models.  Returns ``(data, truth)`` with the noise-free channels."""
    exp = experiment or get_experiment("tip-cycle")
    path = dict(path or tip_cycle_path(seed=seed))
    n = len(path["fx_N"])
    data = Measured(exp.name, {**path, **{c: np.zeros(n) for c in exp.channels}})
    truth = predict(exp, data, params or {}, effects or {})
    if drift_m:
        tau = data.tau
        truth = {
            **truth,
            "ux_m": truth["ux_m"] + drift_m * np.sin(0.5 * np.pi * tau),
            "uy_m": truth["uy_m"] + 0.6 * drift_m * (1.0 - np.cos(np.pi * tau)),
        }
    rng = np.random.default_rng(seed + 4000)
    noisy = {c: truth[c] + rng.normal(0.0, noise_rad if c.endswith("_rad") else noise_m, n) for c in exp.channels}
    return Measured(exp.name, {**path, **noisy}), truth
