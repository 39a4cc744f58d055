"""Latch hysteresis near the latched state (Stohlman & Pellegrino, Sec. III.C and conclusion).

Stohlman & Pellegrino fit one curve near the fully latched configuration ("the model assumes no hysteresis
in this region", Fig. 10) and concludes that the latch model must be refined because the bay
keeps a residual rotation at zero moment (Figs. 16-17).  This effect adds a friction band that
is widest with the bead seated against the backstop and fades over a length ``ell`` as it moves
out: ``dT_in -= F_h w``, ``dT_out += F_h w``, ``w = exp(-(x + x_backstop) / ell)``.  The bead
then sticks near the latched state and keeps a residual position when dT returns to zero.

The shape of the fade is not known from the paper: the form ``shaped`` replaces the exponential by
the family ``w = max(1 - gamma d / ell, 0)^(1 / gamma)`` (``d = x + x_backstop``), which is the
exponential at ``gamma = 0``, a linear fade reaching zero at ``d = ell`` at ``gamma = 1``, a slower,
hyperbolic tail for ``gamma < 0`` and a fade that ends more abruptly for ``gamma > 1``.
"""

from __future__ import annotations

import numpy as np

from .base import Effect, Implementation, register_effect
from .parameters import Parameter


def _latch_hysteresis_fe(bay, p, ctx):
    return {**bay, "hysteresis_force": float(p["F_h"])}


def fade(d, ell: float, gamma: float = 0.0) -> np.ndarray:
    """Fade weight ``max(1 - gamma d / ell, 0)^(1 / gamma)`` of the distance ``d`` >= 0 (m) from the
    backstop (``exp(-d / ell)`` at gamma = 0, exactly for |gamma| < 1e-9); ell in m, gamma dimensionless."""
    d = np.maximum(np.asarray(d, dtype=float), 0.0) / ell
    if abs(gamma) < 1e-9:
        return np.exp(-d)
    base = np.maximum(1.0 - gamma * d, 0.0)
    with np.errstate(divide="ignore"):
        return base ** (1.0 / gamma)


def _latch_hysteresis(D, p, ctx):
    x = ctx["x"]
    xb = ctx["params"]["x_backstop"]
    w = fade(x + xb, p["ell"], p.get("gamma", 0.0))
    D = D.copy()
    D[:, 0] -= p["F_h"] * w
    D[:, 1] += p["F_h"] * w
    return D


LATCH_HYSTERESIS = register_effect(
    Effect(
        name="latch_hysteresis",
        title="latch hysteresis near the latched state",
        physics=__doc__.split("\n\n", 1)[1].strip(),
        signature="latching and unlatching curves differ near the backstop, where the baseline has a single curve; "
        "the error is concentrated in the latched zones (a)-(b) of Stohlman & Pellegrino, Fig. 6",
        acts_where=("zone (a) at backstop", "zone (b) behind roller axis", "near-zero load"),
        source="Stohlman & Pellegrino, Sec. III.C, Sec. VIII",
        implementations={
            "latch-pull": Implementation(
                hook="branch_force",
                order=30,
                parameters=(
                    Parameter(
                        "F_h",
                        "N",
                        5.0,
                        0.0,
                        200.0,
                        "extra friction force with the bead seated",
                        scale=5.0,
                        starts=(1.0, 20.0),
                    ),
                    Parameter(
                        "ell",
                        "m",
                        3e-4,
                        2e-5,
                        5e-3,
                        "length over which it fades out of the latch",
                        scale=3e-4,
                        starts=(1e-4, 1e-3),
                    ),
                ),
                apply=_latch_hysteresis,
                form="exponential",
                doc="dT_in -= F_h w, dT_out += F_h w, w = exp(-max(x + x_backstop, 0) / ell).",
                forms={
                    "shaped": Implementation(
                        hook="branch_force",
                        order=30,
                        parameters=(
                            Parameter(
                                "F_h",
                                "N",
                                5.0,
                                0.0,
                                200.0,
                                "extra friction force with the bead seated",
                                scale=5.0,
                                starts=(1.0, 20.0, 5.0),
                            ),
                            Parameter(
                                "ell",
                                "m",
                                3e-4,
                                2e-5,
                                5e-3,
                                "length scale of the fade out of the latch",
                                scale=3e-4,
                                starts=(1e-4, 1e-3, 3e-4),
                            ),
                            Parameter(
                                "gamma",
                                "-",
                                0.0,
                                -2.0,
                                3.0,
                                "shape of the fade: 0 exponential, 1 linear, < 0 slower tail",
                                scale=0.5,
                                starts=(1.0, -0.5, 0.0),
                            ),
                        ),
                        apply=_latch_hysteresis,
                        doc="dT_in -= F_h w, dT_out += F_h w, w = max(1 - gamma d / ell, 0)^(1/gamma), d = max(x + "
                        "x_backstop, 0) (gamma = 0: the exponential form).",
                    )
                },
            ),
            **{
                e: Implementation(
                    hook="bay_parameters",
                    order=30,
                    parameters=(
                        Parameter(
                            "F_h",
                            "N",
                            5.0,
                            0.0,
                            200.0,
                            "extra friction force of a latch with the bead "
                            "seated (fade-out length: option latch_hysteresis_length_m)",
                            scale=5.0,
                        ),
                    ),
                    apply=_latch_hysteresis_fe,
                    doc="the FE latches (cable/latch element, femast.elements.latch_law hysteresis option) get hysteresis_force = F_h, "
                    "fading over the option latch_hysteresis_length_m (3e-4 m); it acts only on beads that have left "
                    "the backstop.",
                )
                for e in ("bay-torsion", "tip-cycle")
            },
        },
    )
)
