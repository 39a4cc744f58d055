"""Sources of error in the model: member length errors (lack of fit) and thermal strain.

A beam or truss element whose stress-free length differs from the distance between its nodes is
modelled by a *length factor* s per element: the element is stress free at the length ``L s``,
with L its reference length (a beam: the initial distance of its nodes; a truss or cable: its
unstretched length L0).  Two sources make s:

* a length error dL (m; an element property, as a lack of fit): s = 1 + dL / L;
* a thermal strain alpha (T - T_init), with alpha the coefficient of thermal expansion (1/K),
  T_init the initial temperature (as Abaqus ``*INITIAL CONDITIONS, TYPE=TEMPERATURE``) and T the
  temperature of the current increment (``step.temperature``, as Abaqus ``*TEMPERATURE``):
  s = (1 + dL / L) (1 + alpha (T - T_init)).

The strain stays measured on L (small-strain additive split, Abaqus' eps_mech = eps - eps_th):
N = EA (l - L s) / L.  So a clamped bar heated by dT carries exactly N = -EA alpha dT and a free
one grows by exactly alpha dT L.  Temperatures are in K or degC: only differences enter.  The
temperature is uniform over an element (no gradient through the section: no thermal bending).

A step's temperatures ramp from those at the start of the step to the given values linearly in
step time, or as ``T_start + a(t) (T - T_start)`` with an amplitude a(t) (a ramp factor: an
amplitude 0 -> 1 -> 0 is a thermal cycle back to the start temperature).  Temperatures not
redefined in a later step stay.  Length errors act from the start of the first step, or, with
``step.ramp_length_errors()``, grow over that step linearly in step time (s = 1 + (t / period) dL / L
in it, 1 before it): a misfit closed at assembly, which a cut-back increment then closes less of
(as Abaqus resolves an interference fit over a step).

:class:`FieldLoads` is what the analysis uses: it writes the length factors of the beam and
truss families at each increment (femast/analysis/control/).
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import ModelError
from .amplitudes import Amplitude

# No structural material expands by more than ~1e-4 per K: a larger value is a units slip
# (e.g. ppm/K given as 1/K would be 1e6 times too large, 1/degC as percent 100 times).
ALPHA_LIMIT_PER_K = 1e-3


def _number(value, what, unit):
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ModelError(f"{what} = {value!r} is not a number; give a finite value in {unit}") from None
    if not math.isfinite(v):
        raise ModelError(f"{what} = {value!r} is not finite; give a finite value in {unit}")
    return v


def _element_table(model):
    """{label: (kind, spec)} of the model's beam and truss elements, and of the elements of its cable
    families (families with a ``length_factor``: cable/latch, cable-device): key ``(family name,
    row)``, spec the node labels of the cable."""
    table = {b.label: ("beam", b) for b in model.beams}
    table.update({t.label: ("truss", t) for t in model.trusses})
    for fam in model.families:
        if hasattr(fam, "length_factor"):
            for row, nodes in enumerate(np.asarray(fam.nodes).tolist()):
                table[(fam.name, row)] = ("cable", nodes)
    return table


def _midpoint(model, kind, spec):
    nodes = spec.nodes if kind in ("beam", "truss") else spec
    return np.mean([model.xyz(n) for n in nodes], axis=0)


def select_elements(model, what, elements=None, family=None, where=None) -> list[int]:
    """Labels of the beam and truss elements picked by ``elements`` (a label or labels), ``family``
    (a family name or names) and ``where`` (a function of the element's midpoint (3,), m, returning
    True inside the region); none given: all of them.  The criteria given must all hold."""
    table = _element_table(model)
    if elements is not None:
        labels = []
        for e in np.atleast_1d(np.asarray(elements, dtype=object)).tolist():
            try:
                ok = float(e) == int(e) and int(e) in table and table[int(e)][0] != "cable"
            except (TypeError, ValueError):
                ok = False
            if not ok:
                raise ModelError(
                    f"{what}: {e!r} is not a beam or truss element of model '{model.name}' "
                    "(length errors and thermal strain apply to elements made with model.beam "
                    "or model.truss, or to whole cable families with family=; use the labels "
                    "model.beam and model.truss return)"
                )
            labels.append(int(e))
    else:
        labels = [e for e in table if table[e][0] != "cable"]
    if family is not None:
        fams = {family} if isinstance(family, str) else set(family)
        cable_fams = {e[0] for e in table if table[e][0] == "cable"}
        known = {spec.family for kind, spec in table.values() if kind != "cable"} | cable_fams
        unknown = fams - known
        if unknown:
            raise ModelError(
                f"{what}: no beam or truss family named {sorted(unknown)} (nor a cable family); the model has "
                f"{sorted(known)}"
            )
        if elements is None:
            labels += [e for e in table if table[e][0] == "cable" and e[0] in fams]
        labels = [e for e in labels if (e[0] if table[e][0] == "cable" else table[e][1].family) in fams]
    if where is not None:
        if not callable(where):
            raise ModelError(
                f"{what}: where = {where!r} must be a function of an element midpoint (m) "
                "returning True inside the region"
            )
        labels = [e for e in labels if bool(where(_midpoint(model, *table[e])))]
    if not labels:
        raise ModelError(f"{what}: the selection picks no element; check elements=, family= and where=")
    return labels


def _values(value, labels, what, unit):
    """One value per label from a scalar or a sequence as long as ``labels``."""
    v = np.atleast_1d(np.asarray(value, dtype=object))
    if v.size == 1:
        return [_number(v[0], what, unit)] * len(labels)
    if v.size != len(labels):
        raise ModelError(f"{what}: {v.size} values for {len(labels)} elements; give one value or one per element")
    return [_number(x, f"{what} of element {e}", unit) for x, e in zip(v.tolist(), labels)]


def set_length_errors(model, elements, dL_m) -> list[int]:
    """Length error dL (m) of ``elements``: each is stress free at its reference length + dL."""
    table = _element_table(model)
    labels = select_elements(model, "length error", elements=elements)
    for e, dL in zip(labels, _values(dL_m, labels, "length error", "m")):
        kind, spec = table[e]
        L = _reference_length(model, kind, spec)
        if not dL > -L:
            raise ModelError(
                f"length error of element {e}: {dL} m would make its stress-free length "
                f"{L + dL:.6g} m (reference {L:.6g} m) non-positive"
            )
        model.length_errors[e] = dL
    return labels


def set_expansion(model, alpha_per_K, elements=None, family=None, where=None) -> list[int]:
    """Coefficient of thermal expansion alpha (1/K) of the selected elements."""
    labels = select_elements(model, "thermal expansion", elements, family, where)
    for e, a in zip(labels, _values(alpha_per_K, labels, "thermal expansion alpha_per_K", "1/K")):
        if abs(a) > ALPHA_LIMIT_PER_K:
            raise ModelError(
                f"thermal expansion of element {e}: alpha = {a} 1/K is beyond any structural "
                f"material (|alpha| <= {ALPHA_LIMIT_PER_K:g} 1/K); give it in 1/K (e.g. 23e-6 for "
                "aluminium, -0.5e-6 for carbon fibre along the fibres)"
            )
        model.expansion[e] = a
    return labels


def set_initial_temperature(model, T, elements=None, family=None, where=None) -> list[int]:
    """Initial temperature (K or degC) of the selected elements (default 0 everywhere)."""
    labels = select_elements(model, "initial temperature", elements, family, where)
    for e, t in zip(labels, _values(T, labels, "initial temperature", "K or degC")):
        model.initial_temperatures[e] = t
    return labels


def add_step_temperature(step, T, elements=None, family=None, where=None, amplitude=None):
    """Temperature (K or degC) of the selected elements at the end of ``step`` (see module docstring)."""
    model = step._model
    what = f"step '{step.name}': temperature"
    labels = select_elements(model, what, elements, family, where)
    if amplitude is not None and not isinstance(amplitude, Amplitude):
        raise ModelError(f"{what}: amplitude must be a femast Amplitude (got {type(amplitude).__name__})")
    values = _values(T, labels, what, "K or degC")
    step.temperatures.append((tuple(labels), tuple(values), amplitude))
    return step


def _reference_length(model, kind, spec) -> float:
    a, b = model.xyz(spec.nodes[0]), model.xyz(spec.nodes[1])
    L = float(np.linalg.norm(b - a))
    if kind == "truss":
        if spec.L0 is not None:
            return spec.L0
        if spec.pretension is not None:
            return L / (1.0 + spec.pretension / spec.EA)
    return L


def has_fields(model) -> bool:
    return bool(model.length_errors or any(getattr(s, "temperatures", None) for s in model.steps))


class FieldLoads:
    """The length factors of a model's beam, truss and cable families over the analysis (module
    docstring).

    families : the analysis' element families (``build_families``: the beam and truss families first,
    carrying the element ``labels``, then copies of the model's own families; the cable families
    among them get their own length-factor arrays here, so the model's families are not touched)."""

    def __init__(self, model, families):
        self.model = model
        n_user = len(model.families)
        builtin = families[: len(families) - n_user]
        cables = [f for f in families[len(families) - n_user :] if hasattr(f, "length_factor")]
        for f in cables:
            f.length_factor = np.ones(f.nodes.shape[0])
        self.families = [f for f in builtin if hasattr(f, "length_factor")] + cables
        where = {}
        for k, fam in enumerate(self.families):
            if k >= len(self.families) - len(cables):
                for row in range(fam.nodes.shape[0]):
                    where[(fam.name, row)] = (k, row)
                continue
            for row, lab in enumerate(np.asarray(fam.labels).tolist()):
                where[int(lab)] = (k, row)
        self.where = where
        self.base = []  # 1 + dL / L per element
        self.alpha = []  # 1/K
        self.T_init = []  # K or degC
        for fam in self.families:
            L = fam.l0 if hasattr(fam, "l0") else fam.L0
            self.base.append(np.ones(len(L)))
            self.alpha.append(np.zeros(len(L)))
            self.T_init.append(np.zeros(len(L)))
        for lab, dL in model.length_errors.items():
            k, row = where[lab]
            fam = self.families[k]
            L = fam.l0[row] if hasattr(fam, "l0") else fam.L0[row]
            self.base[k][row] = 1.0 + dL / L
        for lab, a in model.expansion.items():
            k, row = where[lab]
            self.alpha[k][row] = a
        for lab, t in model.initial_temperatures.items():
            k, row = where[lab]
            self.T_init[k][row] = t
        # temperatures at the start of each step
        self.starts = []
        T = [t.copy() for t in self.T_init]
        for _step in model.steps:
            self.starts.append([t.copy() for t in T])
            T = self.temperatures(len(self.starts) - 1, 1.0)
        self.current = None
        # the step over which the length errors grow (step.ramp_length_errors), None: from the start
        self.ramp = next((i for i, st in enumerate(model.steps) if getattr(st, "ramps_length_errors", False)), None)
        for k, fam in enumerate(self.families):
            np.copyto(fam.length_factor, self.length_error_factors(0, 0.0)[k])

    def length_error_factors(self, step_index, frac) -> list:
        """1 + r dL / L per element (per family) at fraction ``frac`` of step ``step_index``: r = 1, or
        with a ramp step r = 0 before it, ``frac`` in it and 1 after it."""
        if self.ramp is None or step_index > self.ramp:
            return self.base
        r = 0.0 if step_index < self.ramp else float(frac)
        return [1.0 + r * (b - 1.0) for b in self.base]

    def temperatures(self, step_index, frac) -> list:
        """Element temperatures (per family) at fraction ``frac`` of step ``step_index``'s time."""
        step = self.model.steps[step_index]
        start = self.starts[step_index]
        T = [t.copy() for t in start]
        for labels, values, amp in getattr(step, "temperatures", ()):
            r = frac if amp is None else float(amp(frac * step.period))
            for lab, v in zip(labels, values):
                k, row = self.where[lab]
                T[k][row] = start[k][row] + r * (v - start[k][row])
        return T

    def set(self, step_index, frac) -> bool:
        """Write the length factors at fraction ``frac`` of the step; True if any changed."""
        changed = False
        T = self.temperatures(step_index, frac)
        base = self.length_error_factors(step_index, frac)
        for k, fam in enumerate(self.families):
            s = base[k] * (1.0 + self.alpha[k] * (T[k] - self.T_init[k]))
            if not np.array_equal(s, fam.length_factor):
                np.copyto(fam.length_factor, s)
                changed = True
        return changed

    def thermal_strain(self, step_index, frac) -> dict:
        """{element label (a cable's: (family, row)): alpha (T - T_init)} at fraction ``frac`` of a step (dimensionless)."""
        T = self.temperatures(step_index, frac)
        return {
            lab: float(self.alpha[k][row] * (T[k][row] - self.T_init[k][row])) for lab, (k, row) in self.where.items()
        }


def check_controls(model):
    """A step that changes temperatures must follow step time (load or displacement control)."""
    for step in model.steps:
        if (
            (getattr(step, "temperatures", None) or getattr(step, "ramps_length_errors", False))
            and step.control is not None
            and (getattr(step.control, "arc_length", False) or hasattr(step.control, "plan"))
        ):
            raise ModelError(
                f"step '{step.name}': temperatures follow step time (and so do ramped length errors); they "
                f"cannot be used with {type(step.control).__name__} (use load or displacement control for that step)"
            )
