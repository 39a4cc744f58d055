"""Built-in experiment ``platform-pose``: commanded pose, tensions and measured pose of the Rocaspect
platform on its compliant masts (the Rocaspect paper, Fig. 7).

Data format
-----------
==============  ====  ========================================================================
column          unit  meaning
==============  ====  ========================================================================
x_cmd_m         m     commanded platform position (rigid-frame controller), base frame, x
y_cmd_m         m     ... y
z_cmd_m         m     ... z
roll_cmd_rad    rad   commanded orientation, fixed-axis x-y-z angles (optional, default 0)
pitch_cmd_rad   rad   ... (optional)
yaw_cmd_rad     rad   ... (optional)
tau1_N..tau8_N  N     commanded cable tensions, cables 11, 12, 21, ... 42 (optional: all eight or
                      none; without them the Eq. 2 barycentric distribution, 20-1500 N)
x_m             m     measured platform position (e.g. laser tracker), x
y_m             m     ... y
z_m             m     ... z
==============  ====  ========================================================================

The first row is the calibration pose: the controller's exit geometry is the one measured there.

Baseline model
--------------
:func:`femast.guyed.platform_pose.pose_trajectory`: platform + cables + masts in equilibrium with
swivel pulleys, the masts given by the ``mast_model`` option (``"3R"`` default, ``"beam"``,
``"beam+shroud"``, ``"FE"``; :mod:`femast.guyed.mast_sets`) at ``pretension_N``.  Fitted:
``compliance_scale`` (-), a factor on the mast compliance (1 = the model as identified).

Options: ``mast_model``, ``pretension_N`` (1200), ``EA_N`` (1.0e6), ``pulley_radius_m`` (0.03),
``mass_kg`` (50).

Mast effects
------------
The effects of ``mast-top`` apply (``effects_from="mast-top"``) with the 3R baseline: after a pass
with the linear masts, each mast's wrench history (from calibration) runs through the ``mast-top``
model with the effects (its quantities ``load``, ``displacement`` and hook ``top_displacement``); the
difference of its top translations from the linear 3R ones is fed back into the equilibrium, and
the pass repeated until the tops move by less than 1 um (as the FE masts are).
"""

from __future__ import annotations

import numpy as np

from femast.errors import ModelError
from femast.experiments.core import Column, Experiment, Measured, Parameter
from femast.experiments.data import from_arrays

from . import mast_top

POSE_IN = ("x_cmd_m", "y_cmd_m", "z_cmd_m", "roll_cmd_rad", "pitch_cmd_rad", "yaw_cmd_rad")
TENSIONS = tuple(f"tau{j}_N" for j in range(1, 9))
CHANNELS = ("x_m", "y_m", "z_m")
_CACHE: dict = {}


def _masts(options):
    from femast.guyed.mast_sets import mast_set

    key = (options["mast_model"], float(options["pretension_N"]))
    if key not in _CACHE:
        _CACHE[key] = mast_set(*key)
    return _CACHE[key]


def _inputs(data: Measured):
    poses = np.column_stack([data[c] if c in data.columns else np.zeros(data.n) for c in POSE_IN])
    have = [c in data.columns for c in TENSIONS]
    if any(have) and not all(have):
        raise ModelError("platform-pose: give all eight tension columns tau1_N..tau8_N or none")
    tau = np.column_stack([data[c] for c in TENSIONS]) if all(have) else None
    return poses, tau


def _mast_top_response(w_hist, w_cal, k_theta, effects, i):
    """Top translations (k, 3) of mast i by the mast-top model (3R + effects) for its wrench history."""
    from femast.guyed.rocaspect import mast_bases, mast_tops

    dw = w_hist - w_cal
    cols = dict(zip(mast_top.WRENCH, dw.T))
    cols.update({c: np.zeros(len(dw)) for c in mast_top.DISPLACEMENT})
    exp = mast_top.EXPERIMENT
    d = from_arrays(exp, **cols)
    opts = dict(exp.options, r_oc_m=tuple(mast_tops()[i] - mast_bases()[i]))
    params = {"k_theta1": k_theta[0], "k_theta2": k_theta[1]}
    out = mast_top.model(params, d, effects, opts)
    return np.column_stack([out[c] for c in mast_top.DISPLACEMENT])


def model(params: dict, data: Measured, effects, options: dict) -> dict:
    """Platform pose on compliant masts (module docstring); returns ``{x_m, y_m, z_m}`` in m."""
    from femast.guyed.mast_sets import _TEST_OF
    from femast.guyed.platform_pose import CableRobot, MastSet, pose_trajectory
    from femast.guyed.rocaspect import TABLE_III, rocaspect_geometry

    poses, tau = _inputs(data)
    base = _masts(options)
    s = float(params["compliance_scale"])
    masts = MastSet(base.name, s * base.compliance, fe=base.fe)
    robot = CableRobot(
        rocaspect_geometry(mass=float(options["mass_kg"])),
        EA=float(options["EA_N"]),
        pulley_radius=float(options["pulley_radius_m"]),
    )
    response = None
    if effects:
        if options["mast_model"] != "3R":
            raise ModelError("platform-pose: the mast-top effects act on the 3R mast model; use mast_model='3R'")
        k_theta = np.array(TABLE_III[_TEST_OF[float(options["pretension_N"])]][2:4]) / s

        def response(hist, w_cal):
            # 3R with the effects for the translations; the linear 3R rotations
            dc = np.einsum("nij,knj->kni", masts.compliance, hist - w_cal)
            for i in range(hist.shape[1]):
                dc[:, i, :3] = _mast_top_response(hist[:, i], w_cal[i], k_theta, effects, i)
            return dc

    res = pose_trajectory(robot, masts, poses, tensions=tau, response=response)
    bad = np.flatnonzero(~res.feasible)
    if bad.size:
        raise ModelError(f"platform-pose: row {bad[0]}: {res.reasons[bad[0]]}")
    return {"x_m": res.pose[:, 0], "y_m": res.pose[:, 1], "z_m": res.pose[:, 2]}


def plot_measured(ax, data: Measured, predicted: dict, params: dict, options: dict) -> None:
    """Plan view of the platform's position error (measured and model minus commanded), mm."""
    ex = 1e3 * (data["x_m"] - data["x_cmd_m"])
    ey = 1e3 * (data["y_m"] - data["y_cmd_m"])
    ax.plot(ex, ey, ".", ms=3, color="0.35", label="measured - commanded")
    ax.plot(
        1e3 * (predicted["x_m"] - data["x_cmd_m"]),
        1e3 * (predicted["y_m"] - data["y_cmd_m"]),
        "-",
        color="C3",
        lw=1.2,
        label="model - commanded",
    )
    ax.set_xlabel("x error (mm)")
    ax.set_ylabel("y error (mm)")
    ax.set_title("platform position error, plan view")
    ax.set_aspect("equal", adjustable="datalim")
    ax.legend(fontsize=8)


def load_measure(data: Measured, options: dict) -> np.ndarray:
    """Distance of the commanded position from the calibration (first) pose, m."""
    p = np.column_stack([data[c] for c in POSE_IN[:3]])
    return np.linalg.norm(p - p[0], axis=1)


EXPERIMENT = Experiment(
    name="platform-pose",
    title="CDPR platform pose on compliant masts (the Rocaspect paper, Fig. 7)",
    columns=(
        Column("x_cmd_m", "m", "commanded platform position, base frame, x"),
        Column("y_cmd_m", "m", "commanded platform position, y"),
        Column("z_cmd_m", "m", "commanded platform position, z"),
        Column("roll_cmd_rad", "rad", "commanded roll (fixed x)", required=False),
        Column("pitch_cmd_rad", "rad", "commanded pitch (fixed y)", required=False),
        Column("yaw_cmd_rad", "rad", "commanded yaw (fixed z)", required=False),
        *(
            Column(c, "N", f"commanded tension of cable {j} (all eight or none)", required=False)
            for j, c in enumerate(TENSIONS, 1)
        ),
        Column("x_m", "m", "measured platform position, x"),
        Column("y_m", "m", "measured platform position, y"),
        Column("z_m", "m", "measured platform position, z"),
    ),
    channels=CHANNELS,
    parameters=(
        Parameter(
            "compliance_scale",
            "-",
            1.0,
            0.05,
            20.0,
            "factor on the mast compliance of the baseline mast model",
            scale=1.0,
        ),
    ),
    model=model,
    options={"mast_model": "3R", "pretension_N": 1200.0, "EA_N": 1.0e6, "pulley_radius_m": 0.03, "mass_kg": 50.0},
    hooks={"top_displacement": mast_top.EXPERIMENT.hooks["top_displacement"]},
    quantities=dict(mast_top.EXPERIMENT.quantities),
    doc=__doc__,
    load_measure=load_measure,
    load_label="distance from the calibration pose (m)",
    plot_measured=plot_measured,
    error_unit="m",
    min_rows=5,
    effects_from="mast-top",
    fit_options={"expensive": True, "max_nfev_per_param": 15, "diff_step": 1e-4},
    source="platform-pose",
)
