"""Connection effects: pinching (slip through a gap with friction) and degradation (a damage law).

* ``pinching`` -- acts on the displacement a connection's load drives (its law:
  :mod:`femast.effects.gap_slip`), its parameters named and sized by the rig's load and
  displacement quantities (``F_y`` on a force, ``M_y`` on a moment).
* ``degradation`` -- stiffness and strength falling with the slip history (the damage law of
  :mod:`femast.effects.damage`).  A damage changes the load every mechanism of the connection sees
  (``F / (1 - D)``) and depends on their slip, so the model must run its mechanisms again for a
  trial damage: it acts on a rig's own ``damage`` hook, which a rig provides by passing its load
  through ``effects.apply("damage", load, respond=..., k=...)`` before the rest of its model, with
  ``respond(load) -> displacement`` the rest of its model (every other effect included) and ``k``
  its elastic stiffness (docs/joint_test.md, "Your own connection test").

Both are connection mechanisms: they apply to the rigs that say they test a connection --
``joint-test``, the rigs made by :func:`~femast.rigs.joint_test.joint_test`, and any
rig that calls :func:`add_connection_effects` with its name and quantities -- not to every rig
with a load and a displacement (a mast top's base joints are not dowelled timber).
"""

from __future__ import annotations

import numpy as np

from .base import Effect, Implementation, register_effect
from .damage import degrade
from .gap_slip import gap_slip
from .parameters import Parameter


# ----------------------------------------------------------------------------- pinching
def _pinching(u, p, ctx):
    q = ctx["quantities"]["load"]
    ell = q.letter
    return u + gap_slip(ctx["load"], p[f"{ell}_y"], p["k_e"], p[f"{ell}_f"], p["k_g"])


def _stiffness_unit(q) -> str:
    L, D = q["load"], q["displacement"]
    return f"{L.unit}/{D.unit}"


def _pinching_params(q):
    L, D = q["load"], q["displacement"]
    ell = L.letter
    k = L.scale / D.scale  # a stiffness of the test's size: the largest load over the largest displacement
    ku = _stiffness_unit(q)
    return (
        Parameter(
            f"{ell}_y",
            L.unit,
            0.3 * L.scale,
            1e-3 * L.scale,
            10 * L.scale,
            "load at which the connector starts to crush the material beside it (embedment onset)",
            scale=0.3 * L.scale,
            starts=(0.1 * L.scale, 0.6 * L.scale),
        ),
        Parameter(
            "k_e",
            ku,
            k,
            1e-3 * k,
            1e3 * k,
            "bearing stiffness of the crushed zone (the embedment strength grows by k_e per unit of crushed depth)",
            scale=k,
            starts=(0.2 * k, 5 * k),
        ),
        Parameter(
            f"{ell}_f",
            L.unit,
            0.05 * L.scale,
            0.0,
            10 * L.scale,
            "friction of the connector sliding through its gap (used up to the embedment onset)",
            scale=0.05 * L.scale,
            starts=(0.01 * L.scale, 0.2 * L.scale),
        ),
        Parameter(
            "k_g",
            ku,
            0.1 * k,
            0.0,
            1e3 * k,
            "bending stiffness of the connector across its gap (0: a sharp slip; used up to k_e)",
            scale=0.1 * k,
            starts=(0.0, k),
        ),
    )


# the pinching of a connection rig (add_connection_effects): parameters from its quantities
PINCHING_IMPLEMENTATION = Implementation(
    hook="displacement",
    needs=("load",),
    order=35,
    parameters=_pinching_params,
    apply=_pinching,
    doc="u += s, s the connector's slip through its gap (femast.effects.gap_slip): hole edges at +e_p, -e_n "
    "grown by embedment, e = <L - L_y> / k_e; inside the gap at rest where |L - k_g s| <= L_f (L_y, L_f "
    "named F_y, F_f on a force, M_y, M_f on a moment).",
)

PINCHING = register_effect(
    Effect(
        name="pinching",
        title="pinching: slip through a gap with friction",
        physics=(
            "A dowel-type connector (nail, screw, bolt) crushes the material beside it once the load exceeds its "
            "embedment strength F_y + k_e e, leaving a gap of the crushed depth e on each side it was pushed to.  "
            "Back across zero load it slides through that gap held only by friction F_f and the bending of its own "
            "shank (k_g), then stiffens where it meets the other edge: the hysteresis loop narrows near zero load "
            "(pinches), by more the larger the past excursions (femast.effects.gap_slip)."
        ),
        signature="after large excursions the measured displacement runs ahead of the model at small loads of either "
        "sign (a soft, nearly flat stretch of the loop through zero load) and the envelope bends over past a load",
        acts_where=("near-zero load", "reversal", "peak"),
        source="dowel-type connections of timber engineering (embedment and slack)",
        implementations={},
    )
)


# ----------------------------------------------------------------------------- degradation
def _degradation(driver):
    def apply(F, p, ctx):
        respond, k = ctx["respond"], ctx["k"]

        def slip_of(F_eff):
            return np.asarray(respond(F_eff), dtype=float) - F_eff / k

        X_d = p["S_d"] if driver == "slip" else p["E_d"]
        _, F_eff = degrade(F, slip_of, p["D_max"], X_d, driver)
        return F_eff

    return apply


def _damage_max():
    return Parameter(
        "D_max",
        "-",
        0.3,
        0.0,
        0.95,
        "largest damage: stiffness and strength fall to (1 - D_max) of the undamaged connection's",
        scale=0.3,
        starts=(0.1, 0.6),
    )


def _slip_params(q):
    D = q["displacement"]
    return (
        _damage_max(),
        Parameter(
            "S_d",
            D.unit,
            10 * D.scale,
            1e-3 * D.scale,
            1e4 * D.scale,
            "cumulative slip over which the damage grows to 63 % of D_max",
            scale=10 * D.scale,
            starts=(D.scale, 100 * D.scale),
        ),
    )


def _energy_params(q):
    L, D = q["load"], q["displacement"]
    e = L.scale * D.scale
    unit = "J" if (L.unit, D.unit) in (("N", "m"), ("N m", "rad")) else f"{L.unit} {D.unit}"
    return (
        _damage_max(),
        Parameter(
            "E_d",
            unit,
            10 * e,
            1e-3 * e,
            1e4 * e,
            "energy dissipated by slip over which the damage grows to 63 % of D_max",
            scale=10 * e,
            starts=(e, 100 * e),
        ),
    )


def damage_hook(quantities: dict, form: str = "slip") -> Implementation:
    """The ``degradation`` implementation on a rig's own ``damage`` hook, its parameters named and
    sized from the rig's ``quantities`` (``form`` "slip" or "energy": the damage's measure)."""
    slip = Implementation(
        hook="damage",
        order=10,
        parameters=_slip_params(quantities),
        apply=_degradation("slip"),
        form="slip",
        doc="L -> L / (1 - D) for every mechanism of the connection, D = D_max (1 - exp(-S / S_d)), S the "
        "cumulative slip of the connection (its displacement less the elastic part), solved along the path "
        "(femast.effects.damage).",
        forms={
            "energy": Implementation(
                hook="damage",
                order=10,
                parameters=_energy_params(quantities),
                apply=_degradation("energy"),
                doc="as the slip form with D = D_max (1 - exp(-E / E_d)), E the energy the load dissipates on the "
                "slip (sum of L ds).",
            )
        },
    )
    return slip if form == "slip" else slip.forms[form]


def add_connection_effects(experiment: str, quantities: dict, degradation: bool = True) -> None:
    """Make ``pinching`` (and ``degradation`` unless False: the rig's model must provide the
    ``damage`` hook, module docstring) apply to the rig named ``experiment``, their parameters from
    the rig's ``quantities`` (``{"load": Quantity, "displacement": Quantity}``)."""
    from .base import add_implementation

    add_implementation("pinching", experiment, PINCHING_IMPLEMENTATION)
    if degradation:
        add_implementation("degradation", experiment, damage_hook(quantities))


DEGRADATION = register_effect(
    Effect(
        name="degradation",
        title="stiffness and strength degradation (damage with cumulative slip or dissipated energy)",
        physics=(
            "Cycling wears and crushes the contacts of a connection: its stiffness and the strength of its slip "
            "mechanisms fall together, as a damage D (0 <= D < 1) that makes the undamaged connection carry the "
            "effective load L / (1 - D) (continuum damage mechanics).  D grows with the cumulative slip (form "
            "slip) or with the energy dissipated by slip (form energy) and saturates at D_max: the trailing "
            "cycles at one amplitude reach less load with a softer reloading (femast.effects.damage)."
        ),
        signature="the model is too stiff and too strong late in the test and after large cycles: the error grows "
        "with the history (repeated cycles at one amplitude drift apart), largest at the peaks",
        acts_where=("peak", "loading", "unloading"),
        source="continuum damage mechanics (Kachanov); energy damage index (Park & Ang)",
        implementations={},
    )
)
