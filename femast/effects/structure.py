"""Structural effects: beam bending flexibility in series with the base joint (seed 000 Eqs. 8-15)
and off-axis motion of the bay top (seed 001 Sec. VI)."""

from __future__ import annotations

from functools import lru_cache

import numpy as np

from ..experiments.core import Parameter
from ..guyed.cantilever import cantilever_compliance, mast_section
from .base import Effect, Implementation, register_effect


@lru_cache(maxsize=64)
def _unit_compliance(r_oc: tuple, s_out: float, s_in: float, nu: float) -> np.ndarray:
    """Translational rows of the cantilever compliance at E = 1 Pa (Eqs. 8-15): C(E) = C1 / E."""
    r = np.asarray(r_oc, dtype=float)
    L = float(np.linalg.norm(r))
    C1 = cantilever_compliance(L, mast_section(1.0, nu, s_out, s_in), axis=r)
    return C1[:3, :]


def _beam_mast_top(d, p, ctx):
    o = ctx["options"]
    C1 = _unit_compliance(tuple(float(v) for v in o["r_oc_m"]), float(o["s_out_m"]), float(o["s_in_m"]),
                          float(o["nu"]))
    return d + ctx["prep"]["dw"] @ C1.T / p["E"]


BEAM_FLEXIBILITY = register_effect(Effect(
    name="beam_flexibility",
    title="beam bending flexibility in series with the base joint",
    physics=(
        "The 3R model (seed 000 Eqs. 4-7) takes the mast as rigid on elastic base joints.  The mast is a "
        "square tube (s_out = 0.1 m, s_in = 0.094 m) whose own cantilever compliance (Eqs. 8-15, "
        ":mod:`femast.guyed.cantilever`) acts in series: dc = (J K^-1 J^T + C_beam(E)) dw.  Top forces alone "
        "cannot separate the two (both give a compliance proportional to the force); top moments can, since a "
        "beam turns its top by L M / EI and moves it by L^2 M / 2EI, a joint by L M / k."),
    signature="the ratio of the top displacement under a top moment to that under a top force differs from a "
              "rigid mast's; the error follows the top moments",
    acts_where=("peak",),
    seed="seed 000 Eqs. 8-15",
    implementations={
        "mast-top": Implementation(
            hook="top_displacement", order=50,
            parameters=(Parameter("E", "Pa", 7e10, 1e9, 1e14, "Young's modulus of the mast tube", scale=7e10,
                                  starts=(2e10, 2e11)),),
            apply=_beam_mast_top,
            doc="dc_T += C_beam(E)[:3] dw, the cantilever of length |r_oc| along r_oc with the section options "
                "s_out_m, s_in_m, nu; E at its upper bound means a rigid mast."),
        "tip-cycle": Implementation(hook="(pending)", parameters=(
            Parameter("EI_scale", "-", 1.0, 0.1, 10.0, "scale of the longerons' bending stiffness"),)),
    },
))


OFF_AXIS = register_effect(Effect(
    name="off_axis_motion",
    title="off-axis motion of the bay top",
    physics=(
        "The single-bay torsion rig of seed 001 (Sec. V-VI) does not keep the bay top on its axis: displacements "
        "of up to 1 cm in x and y were recorded, so the four latches do not unlatch together.  The idealised "
        "model drives the top by its rotation only; this effect drives it along the measured ux, uy (the "
        "seed's 'actual path', Fig. 17) or, when they are not measured, along a fitted eccentric axis."),
    signature="the latches do not act together: the moment-rotation curve has steps (one latch at a time) where "
              "the idealised model has one",
    acts_where=("loading", "unloading"),
    seed="seed 001 Sec. VI.B, Fig. 17",
    implementations={e: Implementation(hook="(pending)", parameters=(
        Parameter("ex", "m", 0.0, -0.02, 0.02, "eccentricity of the rotation axis along x"),
        Parameter("ey", "m", 0.0, -0.02, 0.02, "eccentricity of the rotation axis along y"),))
        for e in ("bay-torsion", "tip-cycle")},
))
