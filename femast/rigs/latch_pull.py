"""Built-in experiment ``latch-pull``: pull test of one roller latch (Stohlman & Pellegrino, Sec. III.B-C).

Data format
-----------
======  ====  =================================================================================
column  unit  meaning
======  ====  =================================================================================
x_mm    mm    bead position, cable stretch removed (Stohlman & Pellegrino, Eq. 15), positive outside the latch
              ("distance to latch" of Stohlman & Pellegrino, Figs. 6 and 10; the backstop is at -x_backstop)
dT_N    N     force jump across the latch ``dT = T2 - T1`` (Eq. 5; > 0 pulls the bead out)
side    -     optional: the loaded cable of the pass, ``out`` (or +1: the outer cable pulls, the
              unlatching rig, ``dT >= 0``) or ``in`` (or -1: the inner cable through the backstop
              pulls, the latching rig, ``dT <= 0``)
t_s     s     optional time
======  ====  =================================================================================

Rows are in time order; a file may hold several latching and unlatching passes, partial passes
reversed part-way, and holds against the backstop.  The direction of motion of the loaded
cable's grip is taken from the x path: a reversal is confirmed when x moves back by more than
``max(5 noise, 5 % of its range)`` (or the ``turn_threshold_m`` option); the bead counts as
possibly at rest within ``max(3 noise, 1 % of the range)`` of the turning point.

The loaded side is a property of the test pass, not of the direction of motion (Stohlman & Pellegrino, Sec.
III.B: "only two diagonally opposed cables were loaded at a time, leaving the cable on the other
side of the latch slack").  Without a ``side`` column it is inferred from the sign of dT
(:func:`infer_side`): each row with ``|dT|`` above 5 noise and 5 % of the peak names its side; a change
of side is placed at the farthest point the old pass reached (outermost x after an outer-cable pass,
innermost after an inner-cable one).

Baseline model
--------------
The latch law of Stohlman & Pellegrino, Eqs. 12-14 (:mod:`femast.elements.latch_law`) with ``r``, ``x_backstop``, ``k``,
``mu`` fitted and ``h``, ``R`` options (measured; defaults 1.5 mm and 2.4 mm as in the paper).
Each sample is compared with the nearest state the law allows along the path
(:func:`admissible_band`):

* loaded cable taut, bead moving: the branch of Eq. 14 in the direction of motion, ``dT_in(x)``
  moving in, ``dT_out(x)`` moving out -- whichever the loaded cable is.  An outer cable reversed
  behind the roller axis (zone (b)) holds the bead back on the latching branch ``dT_in > 0``; an
  inner cable reversed in front of ``x = mu y`` (zone (c)) holds it on ``dT_out < 0``;
* with ``one_sided`` (the paper's rig, default) the loaded cable can only pull: both branches are
  clipped to its half-line (``dT >= 0`` outer, ``<= 0`` inner).  Where the cable would have to
  push, it goes slack (``dT = 0``) and the bead is held by the rollers' static friction where it
  stopped, or runs ahead of the cable to where it is held or onto the backstop; the cable takes
  it up again when its grip comes back to the bead;
* bead at rest just after a reversal: any ``dT`` in the static band ``[dT_in(x), dT_out(x)]``
  (Eq. 9, third case), clipped to the loaded side;
* bead on the backstop: any ``dT <= dT_out(-x_backstop)`` (clipped to the loaded side); a sample
  off the backstop by ``dx`` counts ``backstop_N_per_m * dx`` of error (default 5e4 N/m = 0.5 N
  per 0.01 mm, the ratio of the force and position noise of the paper's rig).

The predicted ``dT_N`` is the force of that nearest admissible state, so ``dT_N - predicted`` is
the error of the sample in N.  The FE cable/latch element (:mod:`femast.elements.cable_latch`)
solves the same law with the same stick/slip/slack states from the cable's geometry; see
``docs/experiments.md`` (latch-pull) for how the two relate and the check of one partial-reversal
path against an FE run.

Hooks (where effects act)
-------------------------
* ``bead_position`` -- value ``x`` (n,) m, the bead position the law sees (stretch-removal
  errors, clearance of the latch body, cable hysteresis);
* ``branch_force`` -- value ``D`` (n + 1, 2) N, the latching and unlatching branches
  ``[dT_in, dT_out]`` at the positions ``ctx["x"]`` (the samples, then the backstop), before the
  one-sided clipping (friction, latch hysteresis).

Every hook call passes ``data``, ``options``, ``params`` and ``prep`` (``x`` m, ``dT`` N,
``sigma`` (n,) direction +1 out / -1 in, ``rest`` (n,) bool, ``side`` (n,) loaded side +1 outer /
-1 inner cable, ``tau``).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from femast.elements.latch_law import LATCHING, UNLATCHING, LatchParameters, contact_half_width, latch_force, latch_zone
from femast.errors import DataFileError
from femast.experiments.core import Column, Experiment, Measured, Parameter, prepared
from femast.experiments.residuals import noise_floor, turning_points

SIDE_OUT = 1  # the outer cable (section 2) is loaded: unlatching rig, dT = T2 >= 0
SIDE_IN = -1  # the inner cable (section 1, through the backstop) is loaded: latching rig, dT = -T1 <= 0


SIDE_WINDOW = 5  # rows of the running median the loaded side is read from (spikes of up to 2 rows ignored)


def running_median(v, window: int) -> np.ndarray:
    """Median of each row's centred window of ``window`` (odd) rows, the ends padded with the end values."""
    h = window // 2
    p = np.pad(np.asarray(v, float), h, mode="edge")
    return np.median(np.lib.stride_tricks.sliding_window_view(p, window), axis=1)


def infer_side(x, dT) -> np.ndarray:
    """Loaded side (+1 outer cable, -1 inner cable) of each row, inferred from the sign of dT.

    x : bead positions (n,), m.  dT : force jumps (n,), N.
    A one-sided rig can only give ``dT >= 0`` with the outer cable loaded and ``dT <= 0`` with
    the inner one (Stohlman & Pellegrino, Sec. III.B), so every row with ``|dT|`` above 5 noise (the noise of dT
    from its second differences) and above 5 % of the largest ``|dT|`` names its side (the second
    differences see only a third of the variance of serially correlated noise -- AR(1), phi = 0.6 --,
    whose excursions out of contact then passed "5 noise" and turned the side in mid-pass; a loaded
    pass reaches tens of N, 5 % of its peak is many times the noise).  The rows are read through the
    running median of ``SIDE_WINDOW`` = 5 rows: a loaded pass lasts many samples, while a spike of the
    load cell (one or two samples of the wrong sign, electrical interference, a loose connector) does not
    move a median of five and so cannot turn the side.  Between the last decisive row of one sign and
    the first of the other the loaded cable changes; the change is placed just after the farthest
    point reached in the old pass's direction of pull (the outermost x when the outer cable was
    loaded, the innermost when the inner one was), where the rig is turned round.  Rows before the
    first decisive row take its side; without any decisive row every row is +1.
    """
    x = np.asarray(x, float)
    dT = np.asarray(dT, float)
    n = dT.size
    med = running_median(dT, SIDE_WINDOW)
    thr = max(5.0 * noise_floor(dT), 0.05 * float(np.max(np.abs(med), initial=0.0)), 1e-9)
    dec = np.flatnonzero(np.abs(med) > thr)
    side = np.full(n, SIDE_OUT, dtype=np.int64)
    if dec.size == 0:
        return side
    sg = np.where(med[dec] > 0, SIDE_OUT, SIDE_IN)
    cur, start = int(sg[0]), 0
    for a, b, sa, sb in zip(dec[:-1], dec[1:], sg[:-1], sg[1:]):
        if sb == sa:
            continue
        seg = np.arange(a, b)  # rows a..b-1: the switch falls after one of them
        k = int(seg[np.argmax(sa * x[seg])])
        side[start : k + 1] = cur
        cur, start = int(sb), k + 1
    side[start:] = cur
    return side


def _side_column(data: Measured) -> np.ndarray | None:
    if "side" not in data:
        return None
    s = data["side"]
    bad = np.flatnonzero((s != SIDE_OUT) & (s != SIDE_IN))
    if bad.size:
        i = int(bad[0])
        raise DataFileError(
            f"{data.path} line {int(data.lines[i])}, column 'side': {s[i]:g} is not a loaded side; "
            "write 'out' (or +1: outer cable loaded, unlatching rig) or 'in' (or -1: inner cable "
            "loaded, latching rig)"
        )
    return s.astype(np.int64)


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
    for t in [0, *tps]:  # the bead sticks while the grip turns: rows within h_rest of the turning point
        j = t
        while j < data.n and abs(x[j] - x[t]) <= h_rest:
            rest[j] = True
            j += 1
        j = t - 1
        while t > 0 and j >= 0 and abs(x[j] - x[t]) <= h_rest:
            rest[j] = True
            j -= 1
    # position of the grip at its last turning point (row 0 before the first)
    last = np.zeros(data.n, np.int64)
    last[np.asarray(tps, dtype=np.int64)] = np.asarray(tps, dtype=np.int64)
    x_turn = x[np.maximum.accumulate(last)]
    side = _side_column(data)
    side_given = side is not None
    if side is None:
        side = infer_side(x, dT)
    return {
        "x": x,
        "dT": dT,
        "sigma": sigma,
        "rest": rest,
        "tau": data.tau,
        "noise_x": sx,
        "turn_m": float(h),
        "turning_points": tps,
        "side": side,
        "side_given": side_given,
        "rest_m": float(h_rest),
        "x_turn": x_turn,
    }


@njit(cache=True)
def admissible_band(x, sigma, rest, side, D, one_sided, h_rest, x_stop, x_turn):
    """Interval [lo, hi] (N) of the force jump each row admits off the backstop, following the bead.

    x (n,) m, sigma (n,) direction of motion of the loaded cable's end (+1 out, -1 in), rest (n,)
    bool (just after a reversal), side (n,) loaded side (+1 outer, -1 inner cable), D (n, 2) N the
    branches [dT_in, dT_out] at x (Eq. 14 with effects), one_sided (the paper's rig), h_rest (m)
    the position noise within which a slack cable may be taking up again, x_stop = -x_backstop (m),
    x_turn (n,) m the position at the last turning point of the grip (the bead's when it stuck).

    With the loaded cable taut the bead is at x: a moving bead gives the branch of its direction,
    a bead at rest after a reversal any dT in the static band [dT_in, dT_out] (Eq. 9, third case).
    The loaded cable can only pull (``side * dT >= 0``): both branches are clipped to that half-line.
    A moving bead whose branch the cable would have to push (``side * D < 0``) leaves the cable:
    the cable goes slack (dT = 0) and the bead stays where static friction holds it (parked at x_p,
    the turning point where it stuck), or runs ahead of the cable to where it is held or onto the
    backstop (x_p taken where the cable let go: on the way on to the bead the clipped law is 0).
    The cable takes the bead again when its end comes back to x_p (within h_rest: any dT of the
    band from 0 there, tension building at rest).  A change of side starts a new pass with the
    new cable taut.  An outer cable whose grip goes on inwards behind the seated bead
    (x <= x_stop) goes slack: the backstop holds the bead.
    """
    n = x.shape[0]
    lo = np.empty(n)
    hi = np.empty(n)
    engaged = True
    xp = 0.0
    for i in range(n):
        s = side[i]
        if i > 0 and s != side[i - 1]:
            engaged = True
        a_in = D[i, 0]
        a_out = D[i, 1]
        if one_sided:
            if s > 0:
                a_in = max(a_in, 0.0)
                a_out = max(a_out, 0.0)
            else:
                a_in = min(a_in, 0.0)
                a_out = min(a_out, 0.0)
        blo = min(a_in, a_out)
        bhi = max(a_in, a_out)
        if one_sided and not engaged:
            gap = s * (x[i] - xp)  # > 0: the cable's end has come back past the parked bead
            if gap > h_rest:
                engaged = True
            elif gap >= -h_rest:
                lo[i] = min(blo, 0.0)
                hi[i] = max(bhi, 0.0)
                continue
            else:
                lo[i] = 0.0
                hi[i] = 0.0
                continue
        if rest[i]:
            lo[i] = blo
            hi[i] = bhi
            continue
        v = D[i, 1] if sigma[i] > 0 else D[i, 0]
        if one_sided and s > 0 and sigma[i] < 0 and x[i] <= x_stop:
            # the outer cable follows its grip in behind the seated bead: slack, the backstop holds
            engaged = False
            xp = x_stop
            lo[i] = 0.0
            hi[i] = 0.0
        elif one_sided and s * v < 0.0:
            engaged = False
            # grip moving against the pull: the bead stays where the cable held it at the turn;
            # grip moving with the pull: the bead runs ahead of it from here
            xp = x_turn[i] if s * sigma[i] < 0 else x[i]
            lo[i] = 0.0
            hi[i] = 0.0
        else:
            lo[i] = v
            hi[i] = v
    return lo, hi


def model(params: dict, data: Measured, effects, options: dict) -> dict:
    """Latch law (Stohlman & Pellegrino, Eqs. 12-14) along the measured path with effect hooks; returns ``{dT_N}`` in N."""
    prep = prepared(data, _prepare, options)
    r, xb, k, mu = (float(params[n]) for n in ("r", "x_backstop", "k", "mu"))
    p = np.array([r, xb, k, mu, float(options["h_m"]), float(options["R_m"])])
    ctx = dict(data=data, options=options, params=params, prep=prep)
    x = effects.apply("bead_position", prep["x"], **ctx) if effects else prep["x"]
    X = np.concatenate([np.maximum(x, -xb), [-xb]])
    D = np.column_stack([latch_force(X, LATCHING, p), latch_force(X, UNLATCHING, p)])
    if effects:
        D = effects.apply("branch_force", D, x=X, **ctx)
    one = bool(options["one_sided"])
    side = prep["side"]
    lo, hi = admissible_band(
        x,
        prep["sigma"].astype(np.float64),
        prep["rest"],
        side,
        np.ascontiguousarray(D[:-1], dtype=np.float64),
        one,
        float(prep["rest_m"]),
        -xb,
        prep["x_turn"],
    )
    d_stop = D[-1, 1]
    hi_stop = np.where(side > 0, max(d_stop, 0.0), min(d_stop, 0.0)) if one else np.full(x.size, d_stop)
    dT = prep["dT"]
    r_curve = dT - np.clip(dT, lo, hi)
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


ZONE_KINDS = (
    "zone (a) at backstop",
    "zone (b) behind roller axis",
    "zone (c) in front of roller axis",
    "zone (d) no contact",
)


def extra_segments(data: Measured, params: dict, options: dict):
    """Latch zones of Stohlman & Pellegrino, Fig. 6 along the path (from the fitted law) and the direction of motion."""
    prep = prepared(data, _prepare, options)
    p = LatchParameters(
        r=params["r"],
        x_backstop=params["x_backstop"],
        k=params["k"],
        mu=params["mu"],
        h=float(options["h_m"]),
        R=float(options["R_m"]),
    )
    x = prep["x"]
    tol = max(3.0 * prep["noise_x"], 2e-5)
    zone = latch_zone(x, p)
    zone = np.where(x <= -p.x_backstop + tol, 0, zone)
    out = [(ZONE_KINDS[z], zone == z) for z in range(4)]
    out += [("latching (dx < 0)", prep["sigma"] < 0), ("unlatching (dx > 0)", prep["sigma"] > 0)]
    return out


def plot_measured(ax, data: Measured, predicted: dict, params: dict, options: dict) -> None:
    """dT against bead position, measured against model (Stohlman & Pellegrino, Fig. 10 style)."""
    prep = prepared(data, _prepare, options)
    up = prep["sigma"] > 0
    out = prep["side"] > 0
    for m, c, lab in (
        (up & out, "C0", "moving out"),
        (~up & out, "C2", "moving in"),
        (up & ~out, "C1", "moving out"),
        (~up & ~out, "C4", "moving in"),
    ):
        if m.any():
            ax.plot(
                data["x_mm"][m],
                data["dT_N"][m],
                ".",
                ms=2.5,
                color=c,
                label=f"measured, {'outer' if c in ('C0', 'C2') else 'inner'} cable, {lab}",
            )
    ax.plot(data["x_mm"], predicted["dT_N"], "-", lw=1.0, color="C3", label="model (path order)")
    ax.set_xlabel("distance to latch x (mm)")
    ax.set_ylabel("dT (N)")
    ax.set_title("latch pull test")
    ax.legend(fontsize=7)


def noise_covariates(data: Measured, params: dict, options: dict, fit=None) -> dict:
    """What the force noise varies with: the signed slope s = d dT / dx (N/m) of the fitted
    law's branch in the direction of motion at each sample.  Eq. 15 removes the cable stretch C T
    from the measured distance with the measured force, so the load-cell noise e_T enters x as
    well: a row's residual is e_T (1 + s C) - s e_d (e_d the distance noise), a variance quadratic
    in s (femast.experiments.noise); the noise is largest on the steep latching branch.  On the
    backstop the residual is ``backstop_N_per_m (x + x_backstop)``, so there the covariate is that
    stiffness: the returned covariate is the sensitivity dr/dx of each row's residual (N/m)."""
    prep = prepared(data, _prepare, options)
    p = np.array(
        [float(params[n]) for n in ("r", "x_backstop", "k", "mu")] + [float(options["h_m"]), float(options["R_m"])]
    )
    x = np.maximum(prep["x"], -p[1])
    direction = np.where(prep["sigma"] > 0, UNLATCHING, LATCHING)
    _, slope = latch_force(x, direction, p, derivative=True)
    # at the backstop the residual is backstop_N_per_m x (x + x_backstop): its sensitivity to x
    tol = max(3.0 * prep["noise_x"], 2e-5)
    q = np.where(prep["x"] <= -p[1] + tol, float(options["backstop_N_per_m"]), -slope)
    return {"dT_N": {"sensitivity of the residual to x (Eq. 15 puts the load-cell noise into x)": q}}


def path_coordinate(data: Measured, options: dict) -> np.ndarray:
    """The bead position x (m): the rig drives it along repeated latching and unlatching passes."""
    return prepared(data, _prepare, options)["x"]


EXPERIMENT = Experiment(
    name="latch-pull",
    title="latch pull test (Stohlman & Pellegrino, Eqs. 12-15)",
    columns=(
        Column("x_mm", "mm", "bead position, cable stretch removed (Eq. 15), positive outside the latch"),
        Column("dT_N", "N", "force jump across the latch T2 - T1 (Eq. 5)"),
        Column(
            "side",
            "-",
            "optional loaded side of the pass: out (+1, outer cable pulls, unlatching rig) or "
            "in (-1, inner cable pulls, latching rig); default inferred from the sign of dT",
            required=False,
            codes=(("out", 1.0), ("in", -1.0)),
        ),
    ),
    channels=("dT_N",),
    parameters=(
        Parameter("r", "m", 1.1e-3, 1e-5, 2e-2, "roller radius", scale=1e-3),
        Parameter("x_backstop", "m", 2.0e-3, 1e-5, 2e-2, "distance of the backstop behind the roller axis", scale=1e-3),
        Parameter("k", "N/m", 1e5, 10.0, 1e9, "stiffness of one roller's cantilever", scale=1e5),
        Parameter("mu", "-", 0.07, 0.0, 0.45, "roller-bead friction coefficient", scale=0.1),
    ),
    model=model,
    options={
        "h_m": 1.5e-3,
        "R_m": 2.4e-3,
        "one_sided": True,
        "backstop_N_per_m": 5e4,
        "cable_compliance_m_per_N": 2.5e-6,
        "turn_threshold_m": None,
    },
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
    path_coordinate=path_coordinate,
    error_unit="N",
    min_rows=10,
    source="latch-pull",
)
