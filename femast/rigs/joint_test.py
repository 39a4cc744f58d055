"""Built-in experiment ``joint-test``: a connection pulled back and forth, load in, displacement out.

The test every connection of a jointed structure goes through: a force (or a moment) on the
connection, in cycles, and the displacement (or rotation) it drives -- a timber or steel
connection on an actuator, a bolted lap joint, a ball joint of a deployable mast turned by a
moment.  Written as a user's rig is (docs/your_own_rig.md); :func:`joint_test` makes the same rig
for a moment and a rotation, or for other column names.

Data format (force test, ``joint-test``)
----------------------------------------
=====  ====  ==================================================================
column unit  meaning
=====  ====  ==================================================================
F_N    N     the force on the connection (the actuator's load cell)
u_m    m     the displacement it drives (compared channel)
t_s    s     optional time; rows in time order
=====  ====  ==================================================================

Baseline model
--------------
A linear elastic connection: ``u = F / k``, ``k`` fitted (N/m).  Every mechanism of a real
connection is an effect on the load ``F`` and the displacement ``u`` (:mod:`femast.effects`):
``friction_hysteresis`` (slip at a threshold: play, Jenkins, Iwan forms), ``joint_clearance``
(a gap crossed at zero load), ``progressive_stiffness``, ``pretension_loss`` (stiffness falling
with time), ``pinching`` (slip through a gap crushed by embedment, held by friction) and
``degradation`` (stiffness and strength falling with the cumulative slip or the dissipated
energy, on this rig's ``damage`` hook).

The model, in the order the effects act::

    F_eff = effects.apply("damage", F)         # degradation: F / (1 - D), D from the slip history
    L     = effects.apply("load", F_eff)       # friction: the load the elastic part sees
    u     = effects.apply("displacement", L / k)   # clearance, pinching: slip added

Options: ``load_column`` ("F_N"), ``displacement_column`` ("u_m") name the columns (fixed per
experiment: use :func:`joint_test` for another pair).
"""

from __future__ import annotations

import numpy as np

from femast.effects import Quantity
from femast.effects.connections import add_connection_effects
from femast.experiments.core import Column, Experiment, Measured, Parameter, prepared

NAME = "joint-test"


def _prepare(data: Measured, options: dict) -> dict:
    return {"F": np.asarray(data[options["load_column"]], dtype=float)}


def model(params: dict, data: Measured, effects, options: dict) -> dict:
    """``u = F / k`` with the effects of the module docstring; returns ``{displacement column: u}``."""
    F = prepared(data, _prepare, options)["F"]
    k = float(params["k"])
    ctx = dict(data=data, options=options, params=params)
    if not effects:
        return {options["displacement_column"]: F / k}

    def respond(load):
        """The connection's displacement under ``load`` with every effect but the damage."""
        L = effects.apply("load", load, **ctx)
        return effects.apply("displacement", L / k, k=k, **ctx)

    F_eff = effects.apply("damage", F, respond=respond, k=k, **ctx) if effects.on("damage") else F
    return {options["displacement_column"]: respond(F_eff)}


def initial_guess(data: Measured, options: dict) -> dict:
    """Least-squares stiffness through the origin, ``k = sum F^2 / sum F u``, as the fit start."""
    F = prepared(data, _prepare, options)["F"]
    u = np.asarray(data[options["displacement_column"]], dtype=float)
    Fu = float(F @ u)
    return {"k": float(np.clip(F @ F / Fu, 1e-3, 1e15)) if Fu > 0 else 1e6}


def _plot_measured(load_label: str, disp_label: str, load_factor: float, disp_factor: float):
    def plot(ax, data: Measured, predicted: dict, params: dict, options: dict) -> None:
        """The hysteresis loops: load against displacement, measured and model."""
        F = prepared(data, _prepare, options)["F"]
        u = data[options["displacement_column"]]
        ax.plot(disp_factor * u, load_factor * F, "-", lw=0.5, color="0.55", label="measured")
        ax.plot(
            disp_factor * predicted[options["displacement_column"]],
            load_factor * F,
            "-",
            lw=0.7,
            color="C3",
            label="model",
        )
        ax.set_xlabel(disp_label)
        ax.set_ylabel(load_label)
        ax.set_title("connection: load against displacement")
        ax.legend(fontsize=8)

    return plot


def joint_test(
    name: str = NAME,
    load_column: str = "F_N",
    displacement_column: str = "u_m",
    *,
    moment: bool = False,
    load_scale: float | None = None,
    displacement_scale: float | None = None,
    title: str = "",
) -> Experiment:
    """The connection rig for a load column and a displacement column (SI units).

    moment : the load is a moment (N m) and the displacement a rotation (rad); default a force (N)
        and a displacement (m).  load_scale, displacement_scale : the largest load and displacement
        of a typical test (N or N m; m or rad), which size the effects' parameters (defaults 10 kN
        and 10 mm; 1 kN m and 10 mrad for a moment).  Pass the experiment to ``compare``/``diagnose``
        or save ``experiment = joint_test(...)`` in a script and pass the script's path.
    """
    lu, du = ("N m", "rad") if moment else ("N", "m")
    L = Quantity(
        lu,
        symbol="M" if moment else "F",
        scale=load_scale or (1e3 if moment else 1e4),
        doc="moment through the connection" if moment else "force through the connection",
    )
    D = Quantity(
        du,
        scale=displacement_scale or 1e-2,
        doc="rotation of the connection" if moment else "displacement of the connection",
    )
    exp = Experiment(
        name=name,
        title=title or f"{'moment-rotation' if moment else 'force-displacement'} test of a connection",
        columns=(
            Column(load_column, lu, "moment on the connection" if moment else "force on the connection"),
            Column(
                displacement_column,
                du,
                "rotation it drives (compared)" if moment else "displacement it drives (compared)",
            ),
        ),
        channels=(displacement_column,),
        parameters=(Parameter("k", f"{lu}/{du}", 1e6, 1e-3, 1e15, "elastic stiffness of the connection", scale=1e6),),
        model=model,
        options={"load_column": load_column, "displacement_column": displacement_column},
        hooks={"damage": f"F (n,) {lu}: the load every mechanism of the connection sees (degradation)"},
        quantities={"load": L, "displacement": D},
        doc=__doc__,
        prepare=_prepare,
        initial_guess=initial_guess,
        load_label=f"{'moment' if moment else 'force'} ({lu})",
        plot_measured=_plot_measured(
            "moment (N m)" if moment else "force (kN)",
            "rotation (mrad)" if moment else "displacement (mm)",
            1.0 if moment else 1e-3,
            1e3,
        ),
        error_unit=du,
        min_rows=10,
        source=NAME if name == NAME else "",
    )
    add_connection_effects(name, exp.quantities)
    return exp


EXPERIMENT = joint_test()
