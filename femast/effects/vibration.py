"""Effects that shift natural frequencies, for the ``vibration`` experiment.

* ``pretension_loss`` (the built-in effect of :mod:`femast.effects.cables` gets a ``vibration``
  implementation): the cables carry ``dT0`` more (< 0: less) than set or fitted;
* ``added_mass``: mass moving with the unit that the model leaves out (shaker sting, sensor);
* ``joint_stick``: a joint or fitting that sticks adds stiffness against the drive direction
  (the baseline's joints slip freely, or there are none).
"""

from __future__ import annotations

import numpy as np

from .base import Effect, Implementation, add_implementation, list_effects, register_effect
from .parameters import Parameter


def _loss(T, p, ctx):
    return np.maximum(T + p["dT0"], 1e-3)


def _added(m, p, ctx):
    return m + p["added"]


def _stick(model, p, ctx):
    """A spring k_stick (N/m) from the drive node to ground along the drive direction: a stress-free
    truss of length 0.1 m and EA = 0.1 k_stick (no stiffness across it)."""
    drive, d = ctx["drive"], np.asarray(ctx["direction"], float)
    d = d / np.linalg.norm(d)
    g = model.node(*(model.xyz(drive) + 0.1 * d))
    model.truss(drive, g, EA=max(float(p["k_stick"]), 1e-9) * 0.1, family="joint_stick_spring")
    model.fix(g)
    return model


def _register(effect: Effect) -> Effect:
    """Register ``effect``, or add its ``vibration`` implementation to a registered one of that name."""
    if any(e.name == effect.name for e in list_effects()):
        return add_implementation(effect.name, "vibration", effect.implementations["vibration"])
    return register_effect(effect)


# the built-in pretension_loss effect (femast/effects/cables.py) gets its vibration implementation
PRETENSION_LOSS = _register(
    Effect(
        name="pretension_loss",
        title="pretension error or loss",
        physics="",
        implementations={
            "vibration": Implementation(
                hook="tension",
                order=20,
                parameters=(
                    Parameter(
                        "dT0",
                        "N",
                        -5.0,
                        -150.0,
                        150.0,
                        "error of the cable tension against the setting or the fitted pretension (< 0: a loss)",
                        scale=10.0,
                    ),
                ),
                apply=_loss,
                doc="T -> T + dT0 for every static state (the out-of-plane f^2 shifts by dT0 / T of itself, "
                "most at low tension)",
            )
        },
    )
)

ADDED_MASS = _register(
    Effect(
        name="added_mass",
        title="added mass at the unit (shaker sting, sensor, fittings)",
        physics="Mass moving with the unit that the model leaves out: m -> m + added; every frequency falls by "
        "the same factor sqrt(m / (m + added)) at the out-of-plane mode.",
        signature="measured frequencies below the model by a constant fraction at every tension",
        source="Stohlman & Pellegrino, Sec. IV (the shaker drives the latch through a force sensor)",
        implementations={
            "vibration": Implementation(
                hook="unit_mass",
                order=20,
                parameters=(Parameter("added", "kg", 0.002, -0.01, 0.5, "mass added at the unit", scale=0.005),),
                apply=_added,
                doc="m -> m + added",
            )
        },
    )
)

JOINT_STICK = _register(
    Effect(
        name="joint_stick",
        title="joint or attachment sticking (stiffness the slipping baseline lacks)",
        physics="A joint that sticks (instead of slipping) or a fitting that holds the unit adds stiffness k_stick "
        "against the out-of-plane motion: f^2 = (sum T_i/L_i + k_stick) / (4 pi^2 m).",
        signature="measured frequencies above the model, most at low tension (a positive intercept of f^2 "
        "against tension)",
        source="Stohlman & Pellegrino, Sec. II.B.1 (ball joints stick below mu B |F|)",
        implementations={
            "vibration": Implementation(
                hook="model",
                order=20,
                parameters=(
                    Parameter("k_stick", "N/m", 200.0, 0.0, 1e6, "stiffness of the sticking joint", scale=500.0),
                ),
                apply=_stick,
                doc="a spring k_stick from the drive node to ground along the drive direction",
            )
        },
    )
)
