"""Experiments whose data format is defined but whose model is pending: ``bay-torsion`` and ``tip-cycle``.

Both need the FE model of the ADAM mast (seed 001), built on the FE core.  Their column layouts
are fixed here so that data can be collected and checked (``femast.experiments.read_data``)
now; ``compare`` and ``diagnose`` refuse them with a clear error until a model is plugged in
with the same contract (see ``docs/experiments.md``, "Plugging in the FE experiments").
"""

from __future__ import annotations

from .core import Column, Experiment

L_MAST_40 = 6.84  # m, the 40-bay mast of seed 001 Sec. VII

BAY_TORSION = Experiment(
    name="bay-torsion",
    title="single-bay moment-rotation test (seed 001 Sec. V-VI, Figs. 16-17)",
    columns=(
        Column("theta_deg", "deg", "rotation of the top batten frame about the bay axis z, relative to the "
                                   "deployed state (seed 001 Fig. 3 theta_t)"),
        Column("ux_m", "m", "measured off-axis translation of the top frame centre, x (drives the FE control "
                            "node along the 'actual path' of Fig. 17 when present)", required=False),
        Column("uy_m", "m", "measured off-axis translation of the top frame centre, y", required=False),
        Column("Mz_Nm", "N m", "moment about z applied to the top frame (Figs. 16-17)"),
    ),
    channels=("Mz_Nm",),
    model=None,
    doc=("Pending a model: the FE model of the ADAM single bay (B33 longerons and battens, rigid corners, "
         "friction ball joints, cable/pulley/latch elements) is not built yet.\n\n"
         "Model contract once built: drive the control node at the top-frame centre through theta_deg about z "
         "(and ux_m, uy_m when measured, otherwise hold x, y: the idealised path of Fig. 16) with the four "
         "bottom corners fixed, and predict the reaction moment Mz_Nm.  Suggested fitted parameters: the cable "
         "pretension T0 (N, seed 001 Eq. 16), the latch parameters r, x_backstop, k, mu (Eq. 14), the ball-joint "
         "friction mu (-).  Suggested hooks: 'latch_law' (branches of Eq. 14), 'ball_joint' (friction moment), "
         "'control_path' (theta, ux, uy of the control node), 'cable_law' (tension-elongation of the cables)."),
    load_measure=None,
    load_label="Mz (N m)",
    error_unit="N m",
    min_rows=10,
    source="bay-torsion",
)

_TIP_LOADS = (("fx_N", "N", "x"), ("fy_N", "N", "y"), ("fz_N", "N", "z"), ("mx_Nm", "N m", "x"),
              ("my_Nm", "N m", "y"), ("mz_Nm", "N m", "z"))
_TIP_MOTION = (("ux_m", "m", "x"), ("uy_m", "m", "y"), ("uz_m", "m", "z"), ("rx_rad", "rad", "x"),
               ("ry_rad", "rad", "y"), ("rz_rad", "rad", "z"))

TIP_CYCLE = Experiment(
    name="tip-cycle",
    title="40-bay mast under tip load cycles (seed 001 Sec. VII, Table 1)",
    columns=tuple(Column(n, u, f"applied tip {'force' if u == 'N' else 'moment about the tip control node'}, "
                                f"base frame, {a}") for n, u, a in _TIP_LOADS)
    + tuple(Column(n, u, f"measured tip {'displacement' if u == 'm' else 'rotation (small angle)'} of the "
                         f"control node, base frame, {a}") for n, u, a in _TIP_MOTION),
    channels=tuple(n for n, _, _ in _TIP_MOTION),
    model=None,
    doc=("Pending a model: the FE model of the 40-bay ADAM mast (seed 001 Sec. VII) is not built yet.\n\n"
         "Model contract once built: apply the tip loads fx..mz (N, N m) row by row as a quasi-static load path "
         "at the tip control node (e.g. the sequence 0, M+F, 0, -M-F, ... of Table 1 with M = 6.8 N m about z and "
         "F = 14 N along x) and predict the tip displacements ux..uz (m) and rotations rx..rz (rad).  The "
         "overall error is in m at the tip: rotations are weighted by the mast length 6.84 m.  Suggested hooks: "
         "as bay-torsion, plus 'bay' (per-bay properties)."),
    channel_weights={"rx_rad": L_MAST_40, "ry_rad": L_MAST_40, "rz_rad": L_MAST_40},
    error_unit="m",
    min_rows=5,
    source="tip-cycle",
)
