"""Built-in experiment ``latch-pull``: pull test of one roller latch (seed 001, Sec. III.B-C).

Data format
-----------
======  ====  =================================================================================
column  unit  meaning
======  ====  =================================================================================
x_mm    mm    bead position, cable stretch removed (seed 001 Eq. 15), positive outside the latch
              ("distance to latch" of seed 001 Figs. 6 and 10; the backstop is at -x_backstop)
dT_N    N     force jump across the latch ``dT = T2 - T1`` (Eq. 5; > 0 pulls the bead out)
t_s     s     optional time
======  ====  =================================================================================

Rows are in time order; a file may hold several latching and unlatching passes and holds
against the backstop.  The direction of motion of the bead is taken from the x path: a
reversal is confirmed when x moves back by more than ``max(5 noise, 5 % of its range)`` (or the
``turn_threshold_m`` option); the bead counts as possibly at rest until it has moved
``max(3 noise, 1 % of the range)`` from the turning point.

Baseline model
--------------
The latch law of seed 001 Eqs. 12-14 (:mod:`femast.latch`) with ``r``, ``x_backstop``, ``k``,
``mu`` fitted and ``h``, ``R`` options (measured; defaults 1.5 mm and 2.4 mm as in the seed).
Each sample is compared with the nearest state the law allows (as in
:mod:`femast.latch_identification`):

* moving bead: the branch of Eq. 14 in the direction of motion, ``dT_in(x)`` latching,
  ``dT_out(x)`` unlatching (clipped to the sign the pulling cable can give when the option
  ``one_sided`` is True, the seed's rig);
* bead at rest just after a reversal: any ``dT`` in the static band ``[dT_in(x), dT_out(x)]``;
* bead on the backstop: any ``dT <= dT_out(-x_backstop)``; a sample off the backstop by ``dx``
  counts ``backstop_N_per_m * dx`` of error (default 5e4 N/m = 0.5 N per 0.01 mm, the ratio of the
  force and position noise of the seed's rig).

The predicted ``dT_N`` is the force of that nearest admissible state, so ``dT_N - predicted`` is
the error of the sample in N.

Hooks (where effects act)
-------------------------
* ``bead_position`` -- value ``x`` (n,) m, the bead position the law sees (stretch-removal
  errors, clearance of the latch body, cable hysteresis);
* ``branch_force`` -- value ``D`` (n + 1, 2) N, the latching and unlatching branches
  ``[dT_in, dT_out]`` at the positions ``ctx["x"]`` (the samples, then the backstop), before the
  one-sided clipping (friction, latch hysteresis).

Every hook call passes ``data``, ``options``, ``params`` and ``prep`` (``x`` m, ``dT`` N,
``sigma`` (n,) direction +1 unlatching / -1 latching, ``rest`` (n,) bool, ``tau``).
"""

from __future__ import annotations

import numpy as np

from ..latch import LATCHING, UNLATCHING, LatchParameters, contact_half_width, latch_force, latch_zone
from .core import Column, Experiment, Measured, Parameter, prepared
from .residuals import noise_floor, turning_points


def _prepare(data: Measured, options: dict) -> dict:
    LatchParameters(h=float(options["h_m"]), R=float(options["R_m"])).validate("latch-pull options (h_m, R_m)")
    x = 1e-3 * data["x_mm"]
    dT = data["dT_N"].copy()
    sx = noise_floor(x)
    h = options.get("turn_threshold_m")
    if h is None:
        h = max(5.0 * sx, 0.05 * float(np.ptp(x)), 1e-9)
    tps, sigma = turning_points(x, float(h))
    h_rest = max(3.0 * sx, 0.01 * float(np.ptp(x)), 1e-9)
    rest = np.zeros(data.n, bool)
    for t in [0, *tps]:
        j = t
        while j < data.n and abs(x[j] - x[t]) <= h_rest:
            rest[j] = True
            j += 1
    return {"x": x, "dT": dT, "sigma": sigma, "rest": rest, "tau": data.tau, "noise_x": sx, "turn_m": float(h),
            "turning_points": tps}


def model(params: dict, data: Measured, effects, options: dict) -> dict:
    """Latch law (seed 001 Eqs. 12-14) along the measured path with effect hooks; returns ``{dT_N}`` in N."""
    prep = prepared(data, _prepare, options)
    r, xb, k, mu = (float(params[n]) for n in ("r", "x_backstop", "k", "mu"))
    p = np.array([r, xb, k, mu, float(options["h_m"]), float(options["R_m"])])
    ctx = dict(data=data, options=options, params=params, prep=prep)
    x = effects.apply("bead_position", prep["x"], **ctx) if effects else prep["x"]
    X = np.concatenate([np.maximum(x, -xb), [-xb]])
    D = np.column_stack([latch_force(X, LATCHING, p), latch_force(X, UNLATCHING, p)])
    if effects:
        D = effects.apply("branch_force", D, x=X, **ctx)
    if options["one_sided"]:
        D = np.column_stack([np.minimum(D[:, 0], 0.0), np.maximum(D[:, 1], 0.0)])
    Dn, hi_stop = D[:-1], D[-1, 1]
    dT = prep["dT"]
    r_curve = dT - np.where(prep["sigma"] > 0, Dn[:, 1], Dn[:, 0])
    r_rest = dT - np.clip(dT, np.minimum(Dn[:, 0], Dn[:, 1]), np.maximum(Dn[:, 0], Dn[:, 1]))
    r_curve = np.where(prep["rest"] & (np.abs(r_rest) < np.abs(r_curve)), r_rest, r_curve)
    hx = (x + xb) * float(options["backstop_N_per_m"])
    over = dT - hi_stop
    r_stop = np.where(over > 0, np.where(hx >= 0, 1.0, -1.0) * np.hypot(hx, over), hx)
    res = np.where(np.abs(r_stop) < np.abs(r_curve), r_stop, r_curve)
    return {"dT_N": dT - res}


def initial_guess(data: Measured, options: dict) -> dict:
    """Data-driven start of r, x_backstop, k, mu (as :func:`femast.latch_identification.initial_guess`).

    x_backstop from the smallest bead position; r from the largest |x| with a force above 5 noise
    (the contact half-width, Eq. 6 with delta = 0); k from the peak force by proportion to the law
    at k = 1e5 N/m; mu = 0.05."""
    prep = prepared(data, _prepare, options)
    x, dT = prep["x"], prep["dT"]
    h, R = float(options["h_m"]), float(options["R_m"])
    xb = max(-float(np.min(x)), 1e-5)
    loaded = x[np.abs(dT) > 5.0 * max(noise_floor(dT), 1e-3)]
    xc = float(np.max(np.abs(loaded))) if loaded.size else 2.0e-3
    r = float(np.clip((xc**2 - R**2 + h**2) / (2 * (R - h)), 0.1 * R, 5 * R))
    ref = LatchParameters(r=r, x_backstop=xb, k=1e5, mu=0.05, h=h, R=R)
    xg = np.linspace(-xb, contact_half_width(ref), 501)
    peak = float(np.abs(latch_force(xg, UNLATCHING, ref)).max())
    k = 1e5 * float(np.max(np.abs(dT))) / peak if peak > 0 else 1e5
    return {"r": r, "x_backstop": xb, "k": float(np.clip(k, 10.0, 1e9)), "mu": 0.05}


def load_measure(data: Measured, options: dict) -> np.ndarray:
    """The force jump dT (N)."""
    return data["dT_N"]


ZONE_KINDS = ("zone (a) at backstop", "zone (b) behind roller axis", "zone (c) in front of roller axis",
              "zone (d) no contact")


def extra_segments(data: Measured, params: dict, options: dict):
    """Latch zones of seed 001 Fig. 6 along the path (from the fitted law) and the direction of motion."""
    prep = prepared(data, _prepare, options)
    p = LatchParameters(r=params["r"], x_backstop=params["x_backstop"], k=params["k"], mu=params["mu"],
                        h=float(options["h_m"]), R=float(options["R_m"]))
    x = prep["x"]
    tol = max(3.0 * prep["noise_x"], 2e-5)
    zone = latch_zone(x, p)
    zone = np.where(x <= -p.x_backstop + tol, 0, zone)
    out = [(ZONE_KINDS[z], zone == z) for z in range(4)]
    out += [("latching (dx < 0)", prep["sigma"] < 0), ("unlatching (dx > 0)", prep["sigma"] > 0)]
    return out


def plot_measured(ax, data: Measured, predicted: dict, params: dict, options: dict) -> None:
    """dT against bead position, measured against model (seed 001 Fig. 10 style)."""
    prep = prepared(data, _prepare, options)
    up = prep["sigma"] > 0
    ax.plot(data["x_mm"][up], data["dT_N"][up], ".", ms=2.5, color="C0", label="measured, unlatching")
    ax.plot(data["x_mm"][~up], data["dT_N"][~up], ".", ms=2.5, color="C2", label="measured, latching")
    ax.plot(data["x_mm"], predicted["dT_N"], "-", lw=1.0, color="C3", label="model (path order)")
    ax.set_xlabel("distance to latch x (mm)")
    ax.set_ylabel("dT (N)")
    ax.set_title("latch pull test")
    ax.legend(fontsize=7)


def noise_covariates(data: Measured, params: dict, options: dict, fit=None) -> dict:
    """What the force noise grows with (issue 14): the slope |d dT / dx| (N/m) of the fitted law's
    branch in the direction of motion at each sample.  Eq. 15 removes the cable stretch T L / EA
    from the measured distance, so the load-cell noise enters x as well, and a noise dx in x shows
    in the force as (d dT / dx) dx: the noise is largest on the steep latching branch."""
    prep = prepared(data, _prepare, options)
    p = np.array([float(params[n]) for n in ("r", "x_backstop", "k", "mu")] + [float(options["h_m"]),
                                                                              float(options["R_m"])])
    x = np.maximum(prep["x"], -p[1])
    direction = np.where(prep["sigma"] > 0, UNLATCHING, LATCHING)
    _, slope = latch_force(x, direction, p, derivative=True)
    return {"dT_N": {"slope of the latch law (Eq. 15 puts the load-cell noise into x)": np.abs(slope)}}


EXPERIMENT = Experiment(
    name="latch-pull",
    title="latch pull test (seed 001 Eqs. 12-15)",
    columns=(Column("x_mm", "mm", "bead position, cable stretch removed (Eq. 15), positive outside the latch"),
             Column("dT_N", "N", "force jump across the latch T2 - T1 (Eq. 5)")),
    channels=("dT_N",),
    parameters=(
        Parameter("r", "m", 1.1e-3, 1e-5, 2e-2, "roller radius", scale=1e-3),
        Parameter("x_backstop", "m", 2.0e-3, 1e-5, 2e-2, "distance of the backstop behind the roller axis",
                  scale=1e-3),
        Parameter("k", "N/m", 1e5, 10.0, 1e9, "stiffness of one roller's cantilever", scale=1e5),
        Parameter("mu", "-", 0.07, 0.0, 0.45, "roller-bead friction coefficient", scale=0.1),
    ),
    model=model,
    options={"h_m": 1.5e-3, "R_m": 2.4e-3, "one_sided": True, "backstop_N_per_m": 5e4,
             "cable_compliance_m_per_N": 2.5e-6, "turn_threshold_m": None},
    hooks={
        "bead_position": "x (n,) m: bead position seen by the latch law",
        "branch_force": "D (n + 1, 2) N: [dT_in, dT_out] at ctx['x'] (samples, then the backstop)",
    },
    doc=__doc__,
    prepare=_prepare,
    initial_guess=initial_guess,
    load_measure=load_measure,
    load_label="dT (N)",
    extra_segments=extra_segments,
    plot_measured=plot_measured,
    noise_covariates=noise_covariates,
    error_unit="N",
    min_rows=10,
    source="latch-pull",
)
