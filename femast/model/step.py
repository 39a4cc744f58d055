"""Steps of a model (as Abaqus *STEP): a static step's loads, prescribed values, temperatures and
increment options, and the script verbs that fill them (``step.load``, ``prescribe``, ``rotate``,
``follow``, ``temperature``)."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..elements.base import DOF_NAMES
from ..errors import ModelError
from . import validation
from .amplitudes import Amplitude
from .gravity import _step_gravity
from .specs import _DOF_INDEX, _LOAD_INDEX, LOAD_NAMES


def _finite(value, what, unit=""):
    """A finite number within validation.MAX_MAGNITUDE of its SI unit, or a ModelError naming ``what``."""
    return validation.number(value, what, unit)


@dataclass
class Condition:
    """A load or prescribed value on one DOF: ``magnitude`` at the end of the step (or the
    factor-1 value of its amplitude)."""

    node: int
    dof: int
    magnitude: float
    amplitude: Amplitude | None = None


@dataclass
class Step:
    """A static step (as an Abaqus *STEP, *STATIC).

    period : step time, s (pseudo-time for static steps).
    initial_increment, min_increment, max_increment : increments of step time, s.
    max_increments : most increments allowed in the step.
    control : None (load / prescribed-displacement control) or a control strategy such as
        :class:`femast.analysis.control.DisplacementControl`.
    stabilize : None, or a :class:`femast.analysis.control.stabilize.Stabilize`.
    hit_times : step times (s) at which an increment must end (amplitude table points
        are added automatically).
    output_frequency : write a frame (and call the analysis' ``on_frame``) every this many
        increments and at the step's last increment (Abaqus *OUTPUT, FREQUENCY); 1 (default):
        every increment.  Frames cost a small model more than its Newton iterations;
        a run that gives up still writes its last converged increment.
    """

    name: str
    period: float = 1.0
    initial_increment: float | None = None
    min_increment: float | None = None
    max_increment: float | None = None
    max_increments: int = 1000
    control: object = None
    stabilize: object = None
    hit_times: tuple = ()
    output_frequency: int = 1
    loads: list = field(default_factory=list)
    prescribed: list = field(default_factory=list)
    temperatures: list = field(default_factory=list)  # (labels, values K or degC, amplitude)
    ramps_length_errors: bool = False  # the model's length errors grow over this step (ramp_length_errors)
    _model: object = field(default=None, repr=False)  # the Model the step belongs to

    def load(self, node, amplitude: Amplitude | None = None, **components):
        """Nodal force/moment on ``node`` at the end of the step: ``step.load(n, fx=10.0, mz=-2.0)``;
        ``components`` fx, fy, fz (N) and mx, my, mz (N m), global axes, fixed directions.  The load
        ramps linearly in step time, or follows ``amplitude`` (an :class:`Amplitude` of step time).
        A load not redefined in a later step stays applied."""
        self._model._check_node(node, f"load in step '{self.name}'")
        if not components:
            raise ModelError(f"step '{self.name}': load on node {node} has no components; give e.g. fx=1.0")
        for name, value in components.items():
            if name.lower() not in _LOAD_INDEX:
                raise ModelError(
                    f"step '{self.name}': unknown load component '{name}' on node {node}; use {', '.join(LOAD_NAMES)}"
                )
            v = _finite(
                value, f"step '{self.name}': load {name} on node {node}", "N" if name.lower()[0] == "f" else "N m"
            )
            self.loads.append(Condition(node, _LOAD_INDEX[name.lower()], v, amplitude))
        return self

    def prescribe(self, node, amplitude: Amplitude | None = None, **components):
        """Prescribed displacement/rotation of ``node`` at the end of the step: ``step.prescribe(n, ux=0.01,
        rz=0.05)``; ``components`` ux, uy, uz (m) and rx, ry, rz (rad), reached linearly in step time
        or along ``amplitude``.  A prescribed rotation component is the accumulated spin about that
        global axis (exact when the other two rotation components are held)."""
        self._model._check_node(node, f"prescribed motion in step '{self.name}'")
        if not components:
            raise ModelError(f"step '{self.name}': prescribe on node {node} has no components; give e.g. ux=0.0")
        for name, value in components.items():
            if name.lower() not in _DOF_INDEX:
                raise ModelError(f"step '{self.name}': unknown DOF '{name}' on node {node}; use {', '.join(DOF_NAMES)}")
            v = _finite(
                value, f"step '{self.name}': prescribed {name} on node {node}", "m" if name.lower()[0] == "u" else "rad"
            )
            dof = _DOF_INDEX[name.lower()]
            validation.prescribed_once(self.prescribed, node, dof, v, f"step '{self.name}'")
            self.prescribed.append(Condition(node, dof, v, amplitude))
        return self


def _step_temperature(self, T, elements=None, family=None, where=None, amplitude: Amplitude | None = None):
    """Temperature ``T`` (K or degC; one value or one per element) of beam and truss elements at the
    end of the step (as Abaqus *TEMPERATURE): picked by ``elements`` (labels), ``family`` (name) and
    ``where`` (a function of the element midpoint, m: a region); none: all.  With a coefficient of
    thermal expansion (:meth:`Model.thermal_expansion`) it strains the elements by
    alpha (T - T_init).  It ramps from the step's start temperature linearly in step time, or as
    ``T_start + a(t) (T - T_start)`` with an ``amplitude`` a(t); see :mod:`femast.model.thermal`."""
    from .thermal import add_step_temperature

    return add_step_temperature(self, T, elements, family, where, amplitude)


def _step_ramp_length_errors(self):
    """Apply the model's length errors (lack of fit, :meth:`Model.length_error`) gradually over this
    step, linearly in step time: none act before the step, all after it.  Without it they act in
    full from the start of the first step.  Use it where a misfit is closed at assembly (as Abaqus
    resolves an interference fit over a step, *CONTACT INTERFERENCE, SHRINK): a cut-back increment
    then closes less of the misfit.  One step per model; see :mod:`femast.model.thermal`."""
    for other in self._model.steps:
        if other.ramps_length_errors and other is not self:
            raise ModelError(
                f"step '{self.name}': the length errors already ramp over step '{other.name}'; "
                "they can ramp over one step only"
            )
    self.ramps_length_errors = True
    return self


def _step_rotate(self, node, axis, angle: float, amplitude: Amplitude | None = None):
    """Prescribe a rotation of ``node`` by ``angle`` (rad) about the fixed global ``axis`` (any
    direction) at the end of the step: the three rotation components are driven together, which
    is exact for a rotation about a fixed axis.  The angle is reached linearly in step time, or
    along ``amplitude`` (an :class:`Amplitude` of step time)."""
    a = np.asarray(axis, dtype=float)
    if a.shape != (3,) or not np.all(np.isfinite(a)) or np.linalg.norm(a) == 0:
        raise ModelError(f"step '{self.name}': rotation axis {axis!r} must be a non-zero 3-vector")
    a = a / np.linalg.norm(a)
    return self.prescribe(node, amplitude=amplitude, rx=angle * a[0], ry=angle * a[1], rz=angle * a[2])


def _step_follow(self, node, times, **tables):
    """Drive DOFs of ``node`` along measured time tables: ``step.follow(n, t, rz=theta, ux=x)``
    with ``times`` (step time, s) and one array of values (m, rad) per DOF; increments end at
    every table time."""
    for name, values in tables.items():
        self.prescribe(node, amplitude=Amplitude(times, values, name=f"{name} of node {node}"), **{name: 1.0})
    return self


Step.rotate = _step_rotate
Step.temperature = _step_temperature
Step.ramp_length_errors = _step_ramp_length_errors
Step.follow = _step_follow
Step.gravity = _step_gravity
