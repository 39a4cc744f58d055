"""Built-in experiment ``tip-cycle``: ADAM mast under tip load cycles (Stohlman & Pellegrino, Sec. VII, Table 1).

Data format
-----------
==========  ====  ==========================================================================
column      unit  meaning
==========  ====  ==========================================================================
fx_N        N     applied tip force at the control node (centre of the top frame), base frame, x
fy_N        N     ... y
fz_N        N     ... z
mx_Nm       N m   applied tip moment about the control node, base frame, x
my_Nm       N m   ... y
mz_Nm       N m   ... z
ux_m        m     measured tip displacement of the control node, base frame, x
uy_m        m     ... y
uz_m        m     ... z
rx_rad      rad   measured tip rotation, small angles about the base axes, x
ry_rad      rad   ... y
rz_rad      rad   ... z
t_s         s     optional time
==========  ====  ==========================================================================

Each row is a quasi-static load state, rows in the order they were applied (Table 1: 0, M+F, 0,
-M-F, 0, ... with M = 6.8 N m about z and F = 14 N along x); the motion is measured from the
deployed, pretensioned mast at zero tip load before the first row.  Rows may sample the ramps
between the states (a load cycle recorded at 10-50 points).

Baseline model
--------------
The FE ADAM mast (:func:`femast.adam.build_mast`: ``n_bays`` bays, alternate folding,
friction ball joints, one cable/pulley/latch assembly per side and bay), base frame fixed,
cables pretensioned to equilibrium (:func:`femast.adam.steps.add_initial_steps`), then one
load-controlled step per row that changes the load (a row equal to the one before it repeats
its motion).  Predicted: the control node's displacement ``U`` and rotation ``URA`` relative to
the pretensioned state.

As for ``bay-torsion``, the baseline has frictionless ball joints (option ``ball_mu`` = 0; the
paper's model has 0.5), no latch hysteresis and the nominal pretension.  Fitted: the cable axial
rigidity ``cable_EA`` (N), one of the two bay parameters the paper does not give and docs/adam_mast.md
identified from Table 1.  The other, the longeron wall, is an option (``longeron_t_m``): the tip
motion hardly depends on it -- the mast carries a tip shear mostly by shear of its cable net -- so
tip data cannot determine it (10 % of wall changes ux by 0.02 % (2 bays) to 0.07 % (8 bays) and
only ry, itself 1e-6 to 1e-4 rad, by 6 %; 10 % of EA changes ux and rz by 9 %).  Fitting it along
made the fits ill-conditioned and the effects' uncertainties infinite.

Options: ``n_bays`` (40: the paper's 6.84 m mast; 2-8 for fast studies), ``fold`` (+1),
``alternate`` (True), ``longeron_t_m`` (the value identified from Table 1), ``pretension_N`` (170), ``ball_mu`` (0),
``ball_B_m`` (4e-3), ``latch_hysteresis_length_m`` (3e-4), ``increments_per_row`` (1), ``bay``
(dict of further :class:`~femast.adam.BayParameters` changes), ``max_fe_rows`` (60: longer files are run through
the turning points of the load and rows spread along the path, and interpolated between them),
``cache_dir`` (None; see :mod:`femast.experiments.fe_cache`), ``threads`` (1, numba threads of
parallel kernels during a run, see :class:`~femast.experiments.fe_cache.kernel_threads`).

The overall error is in m at the tip: rotations are weighted by the 40-bay length, 6.84 m,
whatever ``n_bays`` (``channel_weights``); fits whiten every channel by its own noise, so the
weights only affect the reported RMS.

Hooks (where effects act)
-------------------------
* ``bay_parameters`` -- value: dict of the bays' inputs (as bay-torsion: ``pretension``,
  ``cable_EA``, ``longeron_t``, ``mu``, ``B``, ``hysteresis_force``, ... and ``latch_*``);
* ``tip_loads`` -- value: (m, 6) loads ``[fx, fy, fz, mx, my, mz]`` (N, N m) of the m FE rows;
* ``tip_motion`` -- value: (n, 6) predicted ``[ux, uy, uz, rx, ry, rz]`` (m, rad) at every row.

Every hook call passes ``data``, ``options``, ``params`` and ``prep`` (``loads`` (n, 6), ``rows``
the FE rows, ``s`` the load-path coordinate, ``load`` the signed load measure, ``tau``).
"""

from __future__ import annotations

import time

import numpy as np

from femast import progress
from femast.errors import ConvergenceError, FemastError, ModelError
from femast.experiments.core import Column, Experiment, Measured, Parameter, prepared
from femast.experiments.fe_cache import cached, kernel_threads
from femast.experiments.residuals import turning_points

from .bay_torsion import FE_FIT_OPTIONS, adam_inputs, bay_parameters

L_MAST_40 = 6.84  # m, the 40-bay mast of Stohlman & Pellegrino, Sec. VII
LOADS = ("fx_N", "fy_N", "fz_N", "mx_Nm", "my_Nm", "mz_Nm")
MOTION = ("ux_m", "uy_m", "uz_m", "rx_rad", "ry_rad", "rz_rad")


# --------------------------------------------------------------------------- load path
def load_measure(data: Measured, options: dict) -> np.ndarray:
    """Signed tip load (N): the loads, moments divided by a 0.5 m lever (so 6.8 N m counts like
    13.6 N, Table 1's M and F alike), projected on their principal direction, the sign chosen so
    that the largest value is positive."""
    w = np.column_stack([data[c] for c in LOADS[:3]] + [data[c] / 0.5 for c in LOADS[3:]])
    if not np.any(w):
        return np.zeros(data.n)
    _, _, vt = np.linalg.svd(w, full_matrices=False)
    s = w @ vt[0]
    return s if s[np.argmax(np.abs(s))] > 0 else -s


def _prepare(data: Measured, options: dict) -> dict:
    loads = np.column_stack([data[c] for c in LOADS])
    s_load = load_measure(data, options)
    step = np.linalg.norm(np.diff(loads, axis=0) * np.array([1, 1, 1, 2, 2, 2]), axis=1)
    s = np.concatenate([[0.0], np.cumsum(step)]) + 1e-9 * np.arange(data.n)
    n, mx = data.n, int(options["max_fe_rows"])
    if n <= mx:
        rows = np.arange(n)
    else:
        rng = float(np.ptp(s_load))
        tps, _ = turning_points(s_load, max(0.02 * rng, 1e-12)) if rng > 0 else (np.array([], int), None)
        keep = {0, n - 1, *map(int, tps)}
        extra = max(mx - len(keep), 0)
        keep |= set(np.searchsorted(s, np.linspace(s[0], s[-1], extra + 2)[1:-1]).clip(0, n - 1).tolist())
        rows = np.array(sorted(keep), dtype=int)
    return {"loads": loads, "rows": rows, "s": s, "load": s_load, "tau": data.tau}


# --------------------------------------------------------------------------- FE run
def mast_inputs(params: dict, options: dict) -> dict:
    """The dict passed through the ``bay_parameters`` hook (baseline inputs of every bay, SI)."""
    from femast.adam.parameters import BayParameters

    d = adam_inputs(options, cable_EA=float(BayParameters().cable_EA), longeron_t=float(options["longeron_t_m"]))
    if "cable_EA" in params:
        d["cable_EA"] = float(params["cable_EA"])
    return d


def run_mast(
    inputs: dict,
    loads: np.ndarray,
    n_bays: int,
    fold: int = 1,
    alternate: bool = True,
    increments: int = 1,
    threads: int | None = 1,
) -> dict:
    """One FE run of the mast through the load states ``loads`` (m, 6) (uncached).

    Returns ``motion`` (m, 6) = [ux, uy, uz (m), rx, ry, rz (rad)] of the control node relative to
    the pretensioned state, ``bead`` (m, n_bays, 4) bead positions (m), ``zone`` (m, n_bays, 4),
    ``increments``, ``iterations``, ``wall_time``."""
    from femast.adam import build_mast
    from femast.adam.steps import CONVERGENCE, add_initial_steps
    from femast.analysis import Analysis

    t0 = time.perf_counter()
    am = build_mast(int(n_bays), bay_parameters(inputs), fold=int(fold), alternate=bool(alternate))
    add_initial_steps(am)
    loads = np.asarray(loads, float)
    m = len(loads)
    # one step per change of the load; a row equal to the previous one (to 1e-9 of the largest load:
    # round-off) repeats its state -- a step with no load change can fail the convergence test
    state = np.zeros(m, dtype=int)
    prev, names = np.zeros(6), []
    tol = 1e-9 * max(float(np.abs(loads).max()) if m else 0.0, 1e-300)
    for k in range(m):
        if k == 0 and np.all(np.abs(loads[0]) <= tol):
            state[k] = -1  # the pretensioned reference itself
            continue
        if k > 0 and np.all(np.abs(loads[k] - prev) <= tol):
            state[k] = state[k - 1]
            continue
        name = f"row{k}"
        st = am.model.step(
            name,
            initial_increment=1.0 / increments,
            max_increment=1.0 / increments,
            min_increment=1e-5,
            max_increments=1000,
        )
        st.load(am.control, **dict(zip(("fx", "fy", "fz", "mx", "my", "mz"), map(float, loads[k]))))
        names.append(name)
        state[k] = len(names) - 1
        prev = loads[k]
    fam = am.latch_family
    n_lat = 4 * am.n_bays
    row = am.model.index(am.control)
    steps, rec = [], []  # per converged increment, what this experiment needs (in memory: no read-back)

    def record(fr):
        steps.append(str(fr["step"]))
        rec.append(
            (
                np.concatenate([fr["U"][row], fr["URA"][row]]),
                fr[f"el/{fam}/bead_position"][:n_lat],
                fr[f"el/{fam}/latch_zone"][:n_lat],
            )
        )

    an = Analysis(am.model, None, progress=False, convergence=CONVERGENCE, on_frame=record)  # no files
    with kernel_threads(threads):
        an.run()
    i_ref = max(i for i, s in enumerate(steps) if not s.startswith("row"))
    ends = [max(i for i, s in enumerate(steps) if s == nm) for nm in names]
    ref, bead0, zone0 = rec[i_ref]
    got = [rec[i] for i in ends]
    motion = np.empty((m, 6))
    bead = np.empty((m, n_lat))
    zone = np.empty((m, n_lat), dtype=int)
    for k in range(m):
        mo, be, zo = (ref, bead0, zone0) if state[k] < 0 else got[state[k]]
        motion[k], bead[k], zone[k] = mo - ref, be, zo
    return {
        "motion": motion,
        "bead": bead.reshape(m, am.n_bays, 4),
        "zone": zone.reshape(m, am.n_bays, 4),
        "increments": an.summary.increments,
        "iterations": an.summary.iterations,
        "wall_time": time.perf_counter() - t0,
    }


def solve(inputs: dict, loads: np.ndarray, options: dict) -> dict:
    """:func:`run_mast`, cached; a failed run raises ModelError (a ValueError: a fit rejects the parameters)."""
    key = (
        inputs,
        np.asarray(loads, float),
        int(options["n_bays"]),
        int(options["fold"]),
        bool(options["alternate"]),
        int(options["increments_per_row"]),
    )

    def compute():
        progress.tick("FE runs")
        try:
            return run_mast(inputs, loads, *key[2:], threads=options.get("threads", 1))
        except (ConvergenceError, FemastError) as e:
            return {"error": f"tip-cycle FE run failed: {e}"}

    out = cached("tip-cycle", key, compute, options)
    if "error" in out:
        raise ModelError(out["error"])
    return out


def model(params: dict, data: Measured, effects, options: dict) -> dict:
    """FE mast through the measured tip loads (see the module docstring); returns the six tip
    motion channels (m, rad)."""
    prep = prepared(data, _prepare, options)
    ctx = dict(data=data, options=options, params=params, prep=prep)
    inputs = mast_inputs(params, options)
    if effects:
        inputs = effects.apply("bay_parameters", inputs, **ctx)
    rows = prep["rows"]
    loads = prep["loads"][rows]
    if effects:
        loads = effects.apply("tip_loads", loads, bay=inputs, **ctx)
    fe = solve(inputs, loads, options)
    mo = fe["motion"]
    if rows.size != data.n:
        mo = np.column_stack([np.interp(prep["s"], prep["s"][rows], mo[:, j]) for j in range(6)])
    if effects:
        mo = effects.apply("tip_motion", mo, bay=inputs, fe=fe, **ctx)
    return dict(zip(MOTION, mo.T))


def plot_measured(ax, data: Measured, predicted: dict, params: dict, options: dict) -> None:
    """Tip displacement x and tip twist (as L rz, L the mast height) against the signed tip load, mm."""
    from femast.adam.parameters import ADAM_BAY_HEIGHT

    s = prepared(data, _prepare, options)["load"]
    L = int(options["n_bays"]) * float(dict(options.get("bay") or {}).get("l", ADAM_BAY_HEIGHT))
    ax.plot(s, 1e3 * data["ux_m"], "o", ms=3.5, color="0.35", label="ux measured")
    ax.plot(s, 1e3 * predicted["ux_m"], "-", lw=1.2, color="C3", label="ux model")
    ax.plot(s, 1e3 * L * data["rz_rad"], "s", ms=3.0, color="0.6", label=f"{L:.3g} m x rz measured")
    ax.plot(s, 1e3 * L * predicted["rz_rad"], "--", lw=1.2, color="C0", label=f"{L:.3g} m x rz model")
    ax.axhline(0.0, color="0.8", lw=0.8)
    ax.axvline(0.0, color="0.8", lw=0.8)
    ax.set_xlabel("signed tip load (N; moments / 0.5 m)")
    ax.set_ylabel("tip motion (mm)")
    ax.set_title("mast tip under load cycles")
    ax.legend(fontsize=7)


def _defaults():
    from femast.adam.parameters import BayParameters

    p = BayParameters()
    return float(p.cable_EA), float(p.longeron_t)


_EA, _T = _defaults()

EXPERIMENT = Experiment(
    name="tip-cycle",
    title="ADAM mast under tip load cycles (Stohlman & Pellegrino, Sec. VII, Table 1; FE mast)",
    columns=tuple(
        Column(n, u, f"applied tip {'force' if u == 'N' else 'moment about the tip control node'}, base frame, {a}")
        for n, u, a in zip(LOADS, ("N",) * 3 + ("N m",) * 3, "xyzxyz")
    )
    + tuple(
        Column(
            n,
            u,
            f"measured tip {'displacement' if u == 'm' else 'rotation (small angle)'} of the "
            f"control node from the pretensioned state, base frame, {a}",
        )
        for n, u, a in zip(MOTION, ("m",) * 3 + ("rad",) * 3, "xyzxyz")
    ),
    channels=MOTION,
    parameters=(
        Parameter("cable_EA", "N", _EA, 2e3, 2e6, "axial rigidity of the bay cables (not in the paper)", scale=_EA),
    ),
    model=model,
    options={
        "n_bays": 40,
        "fold": 1,
        "alternate": True,
        "longeron_t_m": _T,
        "pretension_N": 170.0,
        "ball_mu": 0.0,
        "ball_B_m": 4e-3,
        "latch_hysteresis_length_m": 3e-4,
        "increments_per_row": 1,
        "bay": {},
        "max_fe_rows": 60,
        "cache_dir": None,
        "threads": 1,
    },
    hooks={
        "bay_parameters": "dict of the FE bays' inputs (BayParameters fields, latch_* for the latch law), SI",
        "tip_loads": "(m, 6) [fx, fy, fz (N), mx, my, mz (N m)] applied at the m FE rows",
        "tip_motion": "(n, 6) [ux, uy, uz (m), rx, ry, rz (rad)] predicted at every row",
    },
    doc=__doc__,
    prepare=_prepare,
    load_measure=load_measure,
    load_label="signed tip load (N)",
    plot_measured=plot_measured,
    channel_weights={"rx_rad": L_MAST_40, "ry_rad": L_MAST_40, "rz_rad": L_MAST_40},
    error_unit="m",
    min_rows=5,
    fit_options=dict(FE_FIT_OPTIONS),
    source="tip-cycle",
)

__all__ = ["EXPERIMENT", "LOADS", "MOTION", "load_measure", "mast_inputs", "model", "run_mast", "solve"]
