"""Structural effects: beam bending flexibility in series with the base joint (the Rocaspect paper, Eqs. 8-15)
and off-axis motion of the bay top (Stohlman & Pellegrino, Sec. VI, hook ``control_path`` of bay-torsion)."""

from __future__ import annotations

from functools import lru_cache

import numpy as np

from ..guyed.cantilever import cantilever_compliance, mast_section
from .base import Effect, Implementation, register_effect
from .parameters import Parameter


@lru_cache(maxsize=64)
def _unit_compliance(r_oc: tuple, s_out: float, s_in: float, nu: float) -> np.ndarray:
    """Translational rows of the cantilever compliance at E = 1 Pa (Eqs. 8-15): C(E) = C1 / E."""
    r = np.asarray(r_oc, dtype=float)
    L = float(np.linalg.norm(r))
    C1 = cantilever_compliance(L, mast_section(1.0, nu, s_out, s_in), axis=r)
    return C1[:3, :]


def _beam_mast_top(d, p, ctx):
    o = ctx["options"]
    C1 = _unit_compliance(tuple(float(v) for v in o["r_oc_m"]), float(o["s_out_m"]), float(o["s_in_m"]), float(o["nu"]))
    return d + ctx["prep"]["dw"] @ C1.T / p["E"]


BEAM_FLEXIBILITY = register_effect(
    Effect(
        name="beam_flexibility",
        title="beam bending flexibility in series with the base joint",
        physics=(
            "The 3R model (the Rocaspect paper, Eqs. 4-7) takes the mast as rigid on elastic base joints.  The mast is a "
            "square tube (s_out = 0.1 m, s_in = 0.094 m) whose own cantilever compliance (Eqs. 8-15, "
            ":mod:`femast.guyed.cantilever`) acts in series: dc = (J K^-1 J^T + C_beam(E)) dw.  Top forces alone "
            "cannot separate the two (both give a compliance proportional to the force); top moments can, since a "
            "beam turns its top by L M / EI and moves it by L^2 M / 2EI, a joint by L M / k."
        ),
        signature="the ratio of the top displacement under a top moment to that under a top force differs from a "
        "rigid mast's; the error follows the top moments",
        acts_where=("peak",),
        source="the Rocaspect paper, Eqs. 8-15",
        implementations={
            "mast-top": Implementation(
                hook="top_displacement",
                order=50,
                parameters=(
                    Parameter(
                        "E", "Pa", 7e10, 1e9, 1e14, "Young's modulus of the mast tube", scale=7e10, starts=(2e10, 2e11)
                    ),
                ),
                apply=_beam_mast_top,
                doc="dc_T += C_beam(E)[:3] dw, the cantilever of length |r_oc| along r_oc with the section options "
                "s_out_m, s_in_m, nu; E at its upper bound means a rigid mast.",
            ),
        },
    )
)


def _turn_about(drive, cx: float, cy: float):
    """The control path with the top frame turned about a vertical axis through (cx, cy) (m, from the
    bay axis) instead of the bay axis: the control node moves by (I - R(theta)) c on top of the path."""
    th = drive[:, 0]
    c, s = np.cos(th), np.sin(th)
    out = np.array(drive, dtype=float, copy=True)
    out[:, 1] += cx - (c * cx - s * cy)
    out[:, 2] += cy - (s * cx + c * cy)
    return out


def _off_axis_bay(drive, p, ctx):
    """The rig's axis at (e_x, e_y) from the bay axis: any direction."""
    return _turn_about(drive, float(p["e_x"]), float(p["e_y"]))


def _off_axis_bay_side(drive, p, ctx):
    """The rig's axis at p["e"] from the bay axis, towards the centre of side ``options["off_axis_side"]``."""
    k = int(ctx["options"].get("off_axis_side", 0))
    a = np.pi / 2 + k * np.pi / 2
    return _turn_about(drive, p["e"] * np.cos(a), p["e"] * np.sin(a))


OFF_AXIS = register_effect(
    Effect(
        name="off_axis_motion",
        title="off-axis motion of the bay top",
        physics=(
            "The single-bay torsion rig of Stohlman & Pellegrino (Sec. V-VI) does not keep the bay top on its axis: displacements "
            "of up to 1 cm in x and y were recorded, so the four latches do not unlatch together.  The idealised "
            "model drives the top by its rotation only (the baseline of bay-torsion follows ux, uy when they are "
            "measured); this effect turns the top frame about a vertical axis at a distance e from the bay axis, "
            "so the top centre moves by (I - R(theta)) c on top of the driven path, c = (e_x, e_y) in any direction "
            "(a square bay repeats itself every 90 degrees, so c and c turned by 90 degrees fit equally well; a "
            "direction between two sides is another rig).  Without ux, uy this is the unmeasured drift of the rig; "
            "with them, a measurement point off the frame centre."
        ),
        signature="the latches do not release together: the moment differs where they leave the rollers (zone (c)) "
        "and around release and relatching, where the idealised model has one sharp step",
        acts_where=("latch release/relatch", "zone (c) in front of roller axis", "zone (d) no contact"),
        source="Stohlman & Pellegrino, Sec. VI.B, Fig. 17",
        implementations={
            "bay-torsion": Implementation(
                hook="control_path",
                order=50,
                parameters=(
                    Parameter(
                        "e_x",
                        "m",
                        0.0,
                        -0.05,
                        0.05,
                        "x of the rig's rotation axis from the bay axis",
                        scale=0.01,
                        starts=(0.007, -0.007),
                    ),
                    Parameter(
                        "e_y",
                        "m",
                        0.01,
                        -0.05,
                        0.05,
                        "y of the rig's rotation axis from the bay axis",
                        scale=0.01,
                        starts=(0.007, 0.007),
                    ),
                ),
                apply=_off_axis_bay,
                form="free",
                doc="[ux, uy] += (I - R(theta)) c, c = (e_x, e_y): the rig turns the top about a vertical axis at "
                "c, in any direction (the distance is |c|).",
                forms={
                    "side": Implementation(
                        hook="control_path",
                        order=50,
                        parameters=(
                            Parameter(
                                "e",
                                "m",
                                0.01,
                                0.0,
                                0.05,
                                "distance of the rig's rotation axis from the bay axis (towards the centre of side "
                                "off_axis_side)",
                                scale=0.01,
                            ),
                        ),
                        apply=_off_axis_bay_side,
                        doc="[ux, uy] += (I - R(theta)) c, c = e (cos a, sin a), a = 90 + 90 k degrees for side k = "
                        "option off_axis_side (side 0: +y): the direction known, only the distance fitted.",
                    )
                },
            ),
        },
    )
)
