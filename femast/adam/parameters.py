"""Parameters of an ADAM-type bay (Stohlman & Pellegrino): every dimension, section, material, pretension and
latch parameter, in SI units, with the source of each default value.

The paper gives the bay height (6.84 m / 40 bays = 0.171 m), the ball joints (mu = 0.5, B = 4 mm),
the latch (Sec. III.C fit), the range of cable pretensions (125-210 N, Figs. 13-14), the bay's
torsion test (about 3 degrees to unlatch three of four latches under about 35 N m, Figs. 16-17)
and the 40-bay tip response (Table 1).  It does not give the batten side, the member sections or
the cable EA; the defaults below are chosen to be consistent with what it gives (see
``docs/adam_bay.md``, table "Parameter choices", for the reasoning behind each one).
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field, fields, replace

from .._moved import renamed_attributes
from ..elements.cable_device_specs import Pulley, Sheave
from ..elements.latch_law import LatchParameters, contact_half_width, validate_latch_array
from ..errors import ModelError
from ..model.sections import Section, circular_tube

#: Bay height of Stohlman & Pellegrino, Sec. VII: 40 bays make a 6.84 m mast.
ADAM_BAY_HEIGHT = 6.84 / 40


@dataclass(frozen=True)
class BayParameters:
    """One ADAM bay (all SI).  See the module docstring and ``docs/adam_bay.md``.

    Geometry
    --------
    b : batten frame side, ball centre to ball centre, m.  Not in the paper: chosen so that the
        single-bay torsion test unlatches after about 3 degrees (Sec. V).
    l : longeron length, ball centre to ball centre, m; equal to the deployed bay height
        (Eq. 1 with theta_t = 0).  Stohlman & Pellegrino: 6.84 m / 40 = 0.171 m.
    corner : size of the rigid corner piece: the batten ends sit this far from the ball centre
        along the frame edges, m.

    Members (circular tubes: outer diameter, wall thickness, material)
    -----------------------------------------------------------------
    longeron_d, longeron_t : m.  longeron_E (Pa), longeron_nu.  Not in the paper: the wall is
        identified from Table 1 (``femast.adam.identify``).
    batten_d, batten_t, batten_E, batten_nu : same for the battens (frame members).

    Cables (one cable/pulley/latch assembly per side)
    -------------------------------------------------
    cable_EA : axial rigidity of the cables, N.  Not in the paper: identified from Table 1.
    pretension : cable tension of the deployed, latched bay before it comes to equilibrium, N
        (Figs. 13-14: 125-210 N).
    latch : :class:`~femast.elements.latch_law.LatchParameters` (Stohlman & Pellegrino, Sec. III.C fit by default).
    hysteresis_force, hysteresis_length : latch hysteresis near the latched state (N, m); 0
        switches it off (the paper's model).  See ``docs/cable_latch_element.md``.
    latch_mu_k : kinetic friction of the latch rollers (-); None (default): the latch's ``mu``, the
        paper's one coefficient (Sec. III.A: "the kinetic and static coefficients ... are assumed to
        be equal").  Below it, ``latch.mu`` is the static coefficient: a bead starts to slide at
        ``latch.mu`` and slides on at ``latch_mu_k``.
    pulley : the pulley of each side's pulley-and-latch unit (the paper's Sec. II.B.2): None
        (default) a frictionless pulley, the paper's element; or a
        :class:`~femast.elements.cable_devices.Sheave` (radius, pin_radius, mu): the wheel turns on
        its pin, and its bearing friction ``mu pin_radius / radius x |resultant|`` adds to the
        latch's jump.  ADAM's pulley is such a sheave, not a capstan drum (the cable does not slide
        on it); its bearing friction is 0 by default because the latch's friction (``latch.mu``) was
        fitted to pulls of the cable through the whole unit, pulley included (Sec. III.B), and
        holds it already.  See ``docs/adam_bay.md``.

    Joints
    ------
    seat : ``"seated"`` (default: the ball sits in its socket, held by the preload; the seat carries
        compression and opens in tension) or ``"tied"`` (the paper's two-way tie, a captive ball: the
        reproductions of the paper's figures use it).  See ``docs/ball_joint.md``.
    seat_clearance_radial : seated joints: radial play of the ball in its socket, m (default 0).
    seat_clearance_axial : seated joints: axial play from the seat to a retainer, m; None (default):
        no retainer, the seat opens freely in tension.
    mu, B : ball joint friction coefficient and ball end radius, m (Stohlman & Pellegrino, Sec. II.B.1: 0.5, 4 mm).
    mu_k : kinetic friction coefficient of the ball joints; None: the same as ``mu`` (the paper).
    joint_penalty_factor, joint_stick_factor : numerical stiffness factors of the ball joints
        (:func:`femast.elements.ball_joint.add_ball_joints`): k_pen = factor x EA/l and
        k_stick = factor x 4EI/l of the longeron.  1e3 (not the element's 1e4) keeps the round-off
        of the penalty forces below the force tolerance needed for 14 N tip loads; 3 (not 1e3)
        makes the stick band (|M| / k_stick, a few 1e-6 rad) wider than Newton's steps across it:
        with 1e3 the iterates of a joint whose equilibrium lies in the band jump from one slip
        direction to the other and the 40-bay pretension step does not converge (docs/adam_mast.md).

    Discretisation
    --------------
    n_longeron, n_batten : beam elements per longeron / batten.
    """

    b: float = 0.25
    l: float = ADAM_BAY_HEIGHT
    corner: float = 0.015
    longeron_d: float = 0.025
    longeron_t: float = 6.527e-3
    longeron_E: float = 120e9
    longeron_nu: float = 0.3
    batten_d: float = 0.020
    batten_t: float = 0.002
    batten_E: float = 120e9
    batten_nu: float = 0.3
    cable_EA: float = 3.4006e4
    pretension: float = 170.0
    latch: LatchParameters = field(default_factory=LatchParameters.adam_fit)
    hysteresis_force: float = 0.0
    hysteresis_length: float = 3e-4
    latch_mu_k: float | None = None
    pulley: Sheave | None = None
    mu: float = 0.5
    B: float = 0.004
    mu_k: float | None = None
    seat: str = "seated"
    seat_clearance_radial: float = 0.0
    seat_clearance_axial: float | None = None
    joint_penalty_factor: float = 1e3
    joint_stick_factor: float = 0.3
    joint_spring: float = 10.0
    n_longeron: int = 1
    n_batten: int = 1

    UNITS = {
        "b": "m",
        "l": "m",
        "corner": "m",
        "longeron_d": "m",
        "longeron_t": "m",
        "longeron_E": "Pa",
        "longeron_nu": "-",
        "batten_d": "m",
        "batten_t": "m",
        "batten_E": "Pa",
        "batten_nu": "-",
        "cable_EA": "N",
        "pretension": "N",
        "latch": "SI",
        "hysteresis_force": "N",
        "hysteresis_length": "m",
        "latch_mu_k": "-",
        "pulley": "-",
        "mu": "-",
        "B": "m",
        "mu_k": "-",
        "seat": "-",
        "seat_clearance_radial": "m",
        "seat_clearance_axial": "m",
        "joint_penalty_factor": "-",
        "joint_stick_factor": "-",
        "joint_spring": "N m/rad",
        "n_longeron": "-",
        "n_batten": "-",
    }

    def __post_init__(self):
        self.validate()

    # ------------------------------------------------------------------ checks
    def validate(self) -> BayParameters:
        """Raise :class:`ModelError` naming the first parameter that cannot describe a bay."""
        positive = (
            "b",
            "l",
            "longeron_d",
            "longeron_t",
            "longeron_E",
            "batten_d",
            "batten_t",
            "batten_E",
            "cable_EA",
            "B",
            "joint_penalty_factor",
            "joint_stick_factor",
            "hysteresis_length",
        )
        for name in positive:
            v = getattr(self, name)
            if not _is_number(v) or not (v > 0 and math.isfinite(v)):
                raise ModelError(f"BayParameters: {name} = {v!r} {self.UNITS[name]} must be a finite number > 0")
        for name in ("corner", "pretension", "mu", "hysteresis_force", "joint_spring", "seat_clearance_radial"):
            v = getattr(self, name)
            if not _is_number(v) or not (v >= 0 and math.isfinite(v)):
                raise ModelError(f"BayParameters: {name} = {v!r} {self.UNITS[name]} must be a finite number >= 0")
        if self.seat not in ("seated", "tied"):
            raise ModelError(f"BayParameters: seat = {self.seat!r}; use 'seated' (the physical default) or 'tied'")
        if self.mu_k is not None and (not _is_number(self.mu_k) or not (0 <= self.mu_k <= self.mu)):
            raise ModelError(
                f"BayParameters: mu_k = {self.mu_k!r} must lie in [0, mu = {self.mu:g}] (kinetic <= static), or be None"
            )
        ca = self.seat_clearance_axial
        if ca is not None and (not _is_number(ca) or not (ca >= 0 and math.isfinite(ca))):
            raise ModelError(f"BayParameters: seat_clearance_axial = {ca!r} m must be a finite number >= 0, or None")
        for name in ("seat_clearance_radial", "seat_clearance_axial"):
            v = getattr(self, name) or 0.0
            if v > 0.05 * self.l:
                raise ModelError(f"BayParameters: {name} = {v:g} m is implausible for a joint; clearances are in m")
            if v > 0 and self.seat == "tied":
                raise ModelError(f"BayParameters: {name} = {v:g} m needs seat='seated' (a tied joint has no play)")
        for name in ("longeron_nu", "batten_nu"):
            v = getattr(self, name)
            if not _is_number(v) or not (-1.0 < v < 0.5):
                raise ModelError(f"BayParameters: Poisson's ratio {name} = {v!r} must lie in (-1, 0.5)")
        for name in ("n_longeron", "n_batten"):
            v = getattr(self, name)
            if not isinstance(v, int) or isinstance(v, bool) or v < 1:
                raise ModelError(f"BayParameters: {name} = {v!r} must be an integer >= 1 (beam elements per member)")
        for pre in ("longeron", "batten"):
            d, t = getattr(self, f"{pre}_d"), getattr(self, f"{pre}_t")
            if 2 * t > d:
                raise ModelError(
                    f"BayParameters: {pre} wall {pre}_t = {t:g} m is more than half the outer "
                    f"diameter {pre}_d = {d:g} m; a solid rod has {pre}_t = {pre}_d / 2"
                )
        if self.l > math.sqrt(2.0) * self.b:
            raise ModelError(
                f"BayParameters: longeron l = {self.l:g} m longer than the frame diagonal "
                f"sqrt(2) b = {math.sqrt(2) * self.b:g} m: the bay cannot fold flat (Eq. 1 has no "
                "h = 0 solution); use a larger b or a shorter l"
            )
        if 2 * self.corner >= self.b:
            raise ModelError(
                f"BayParameters: corner pieces of {self.corner:g} m leave no batten on a "
                f"{self.b:g} m side (need 2 corner < b)"
            )
        if not isinstance(self.latch, LatchParameters):
            raise ModelError(
                f"BayParameters: latch must be a femast.elements.latch_law.LatchParameters, got {type(self.latch).__name__}"
            )
        validate_latch_array(self.latch.as_array(), "BayParameters.latch")
        if isinstance(self.pulley, Pulley):
            raise ModelError(
                f"BayParameters: pulley = {self.pulley!r}: ADAM's pulley turns on a pin (the cable does not "
                "slide on it), so a capstan drum or fixed pulley at the latch is not modelled; give "
                "pulley=Sheave(radius, pin_radius, mu) for its bearing friction, or None (frictionless)"
            )
        if self.pulley is not None and not isinstance(self.pulley, Sheave):
            raise ModelError(
                f"BayParameters: pulley must be None or a femast.elements.cable_devices.Sheave, got "
                f"{type(self.pulley).__name__}"
            )
        v = self.latch_mu_k
        if v is not None and (not _is_number(v) or not (0.0 <= v <= self.latch.mu)):
            raise ModelError(
                f"BayParameters: latch_mu_k = {v!r} must lie in [0, latch.mu = {self.latch.mu:g}] (kinetic <= static) or be None"
            )
        if self.hysteresis_force > 0 and self.latch.x_backstop >= contact_half_width(self.latch):
            raise ModelError(
                "BayParameters: latch hysteresis needs the backstop inside the roller contact "
                "zone (x_backstop < x_contact)"
            )
        if self.pretension >= self.cable_EA * 0.05:
            raise ModelError(
                f"BayParameters: pretension {self.pretension:g} N is more than 5% strain of the "
                f"cables (EA = {self.cable_EA:g} N); check the units (N)"
            )
        return self

    # ------------------------------------------------------------------ derived
    @property
    def longeron_section(self) -> Section:
        """Circular tube of the longerons (E, G, A, I, J)."""
        return circular_tube(
            self.longeron_d,
            self.longeron_d - 2 * self.longeron_t,
            E=self.longeron_E,
            nu=self.longeron_nu,
            name="ADAM longeron",
        )

    @property
    def batten_section(self) -> Section:
        """Circular tube of the battens."""
        return circular_tube(
            self.batten_d, self.batten_d - 2 * self.batten_t, E=self.batten_E, nu=self.batten_nu, name="ADAM batten"
        )

    @property
    def diagonal(self) -> float:
        """Length of a side's diagonal in the deployed bay, sqrt(b^2 + l^2), m."""
        return math.hypot(self.b, self.l)

    @property
    def stowed_angle(self) -> float:
        """Twist theta_t (rad) at which Eq. 1 gives h = 0 (the stowed, flat bay)."""
        return math.acos(1.0 - self.l**2 / self.b**2)

    def with_(self, **changes) -> BayParameters:
        """A copy with some parameters changed (validated)."""
        return replace(self, **changes)

    def as_dict(self) -> dict:
        """Plain dict (the latch as a dict of its own parameters)."""
        d = asdict(self)
        d["latch"] = asdict(self.latch)
        return d

    def table(self) -> list[tuple[str, object, str]]:
        """(name, value, unit) rows, for reports."""
        rows = []
        for f in fields(self):
            v = getattr(self, f.name)
            if f.name == "pulley" and v is not None:
                rows += [(f"pulley.{k}", val, "m" if "radius" in k else "-") for k, val in asdict(v).items()]
            elif f.name == "latch":
                for k, val in asdict(v).items():
                    rows.append((f"latch.{k}", val, "N/m" if k == "k" else ("-" if k == "mu" else "m")))
            else:
                rows.append((f.name, v, self.UNITS[f.name]))
        return rows


def _is_number(v) -> bool:
    try:
        float(v)
    except (TypeError, ValueError):
        return False
    return not isinstance(v, bool)


#: old names, kept for one release (they warn): femast 0.3 removes them
__getattr__ = renamed_attributes(__name__, {"SEED_BAY_HEIGHT": "ADAM_BAY_HEIGHT"})
