"""Outputs a study records from each femast run: a node's displacement, rotation or reaction, an
element quantity, at the end of chosen steps (the load levels of the load history), optionally
relative to the end of another step (e.g. the pretensioned state; the residual after unloading
is the value at the end of the unloading step relative to the state before loading).

    NodeOutput("tip_u", node=tip, quantity="U")                      # (n_steps, 3), m
    NodeOutput("tip_rz", node=tip, quantity="URA", components="z",
               at=["load", "unload"], relative_to="pretension")       # (2,), rad
    ElementOutput("N_max", family="truss", key="N", reduce="absmax")  # (n_steps,), N

Each output is checked against the model (node, step and family names, the quantity) before the
study runs any sample.  Values are SI (m, rad, N, N m).
"""

from __future__ import annotations

import numpy as np

from ..errors import StudyError

NODE_QUANTITIES = {"U": "xyz", "UR": "xyz", "URA": "xyz", "RF": ("fx", "fy", "fz", "mx", "my", "mz")}
_AXES = {"U": ("ux", "uy", "uz"), "UR": ("rx", "ry", "rz"), "URA": ("rx", "ry", "rz")}
REDUCTIONS = ("max", "min", "absmax", "mean", "sum")


def _check_name(name):
    if not isinstance(name, str) or not name.isidentifier():
        raise StudyError(f"output name {name!r} is not a Python identifier; use letters, digits and _")
    return name


class _StepOutput:
    """An output taken at the end of steps ``at`` (None: every step; a str: one step, no step axis)
    relative to the end of step ``relative_to`` (None: absolute; 'initial': the unloaded start)."""

    def __init__(self, name, at, relative_to):
        self.name = _check_name(name)
        self.at = at
        self.relative_to = relative_to

    def steps(self, model) -> list:
        """The step names the output reads (checked against the model's steps)."""
        names = [s.name for s in model.steps]
        want = names if self.at is None else ([self.at] if isinstance(self.at, str) else list(self.at))
        if not want:
            raise StudyError(
                f"output '{self.name}': at = {self.at!r} names no step; give step names or None (every step)"
            )
        for s in want + ([self.relative_to] if self.relative_to is not None else []):
            if s != "initial" and s not in names:
                raise StudyError(
                    f"output '{self.name}': the model has no step {s!r}; its steps are "
                    f"{', '.join(repr(n) for n in names)} (and 'initial', the unloaded start)"
                )
        return want

    def labels(self, model) -> list:
        """Names along each axis of the value (None: an axis without names)."""
        lab = [] if isinstance(self.at, str) else [self.steps(model)]
        return lab + self._component_labels()

    def _component_labels(self) -> list:
        return []

    def needed(self, model) -> list:
        return self.steps(model) + ([self.relative_to] if self.relative_to is not None else [])

    def finish(self, model, record: dict) -> np.ndarray:
        """The output's value from ``record`` ({step: extracted value at its end})."""
        want = self.steps(model)
        for s in self.needed(model):
            if s not in record:
                raise StudyError(f"output '{self.name}': step {s!r} produced no frame (frequency step?)")
        v = np.array([record[s] for s in want], dtype=float)
        if self.relative_to is not None:
            v = v - np.asarray(record[self.relative_to], dtype=float)
        return v[0] if isinstance(self.at, str) else v


class NodeOutput(_StepOutput):
    """Node ``node``'s ``quantity`` at the end of steps ``at``.

    quantity : 'U' (displacement, m), 'URA' (accumulated rotation, rad: differences of it are the
        rotation between two states), 'UR' (total rotation vector, rad) or 'RF' (reaction, N and
        N m; zero on free DOFs).
    components : None (all: 3, or 6 for RF), one name ('x', 'z', 'rz', 'fx', ...) giving no
        component axis, or a list of names.
    Shape of the value: (n_steps, n_components), without the step axis when ``at`` is one step name
    and without the component axis when ``components`` is one name.
    """

    def __init__(self, name: str, node: int, quantity: str = "U", components=None, at=None, relative_to=None):
        super().__init__(name, at, relative_to)
        if quantity not in NODE_QUANTITIES:
            raise StudyError(
                f"output '{name}': quantity {quantity!r} is not a node quantity; use one of "
                f"{', '.join(NODE_QUANTITIES)}"
            )
        self.node, self.quantity = node, quantity
        names = list(NODE_QUANTITIES[quantity])
        alias = list(_AXES.get(quantity, ()))
        comps = components if components is not None else names
        single = isinstance(comps, str)
        idx = []
        for c in [comps] if single else list(comps):
            if c in names:
                idx.append(names.index(c))
            elif c in alias:
                idx.append(alias.index(c))
            else:
                raise StudyError(
                    f"output '{name}': component {c!r} of {quantity} does not exist; use "
                    f"{', '.join(names)}" + (f" (or {', '.join(alias)})" if alias else "")
                )
        self.components = idx[0] if single else np.array(idx)
        if quantity == "RF":
            kinds = {"N" if i < 3 else "N m" for i in (idx if not single else [idx[0]])}
            self.unit = kinds.pop() if len(kinds) == 1 else "N, N m"
        else:
            self.unit = "m" if quantity == "U" else "rad"

    def _component_labels(self):
        if np.ndim(self.components) == 0:
            return []
        names = list(_AXES.get(self.quantity, NODE_QUANTITIES[self.quantity]))
        return [[names[i] for i in self.components]]

    def check(self, model, families=None):
        model._check_node(self.node, f"output '{self.name}'")  # ModelError names the node
        self.steps(model)

    def extract(self, model, frame):
        return np.array(frame[self.quantity][model.index(self.node), self.components], dtype=float)


class ElementOutput(_StepOutput):
    """Element quantity ``key`` of element family ``family`` (the ``el/<family>/<key>`` arrays of
    the frames, e.g. 'N' of trusses) at the end of steps ``at``.

    elements : None (every element of the family) or positions in the family.
    component : an index into the per-element axes, e.g. for beams' ``section_forces`` (n_el, 2 ends,
        [N, Vy, Vz, T, My, Mz]) ``(0, 0)`` is N at end 1 and ``(slice(None), slice(4, 6))`` the
        bending moments at both ends; None: all.
    reduce : None (the array), or 'max', 'min', 'absmax', 'mean', 'sum' over what is selected.
    unit : the unit of the quantity, for tables and figures (e.g. 'N').
    """

    def __init__(
        self,
        name: str,
        family: str,
        key: str,
        elements=None,
        reduce: str | None = None,
        at=None,
        relative_to=None,
        unit: str = "",
        component=None,
    ):
        super().__init__(name, at, relative_to)
        self.unit = str(unit)
        self.component = None if component is None else (component if isinstance(component, tuple) else (component,))
        if reduce is not None and reduce not in REDUCTIONS:
            raise StudyError(
                f"output '{name}': reduce = {reduce!r} is unknown; use None or one of {', '.join(REDUCTIONS)}"
            )
        self.family, self.key, self.elements, self.reduce = family, key, elements, reduce

    def check(self, model, families=None):
        self.steps(model)
        if families is None:
            return
        if self.family not in families:
            raise StudyError(
                f"output '{self.name}': the model has no element family {self.family!r}; its families "
                f"are {', '.join(repr(f) for f in families)}"
            )
        keys = families[self.family]
        if self.key not in keys:
            raise StudyError(
                f"output '{self.name}': family {self.family!r} has no output {self.key!r}; it has "
                f"{', '.join(repr(k) for k in keys)}"
            )
        shape = keys[self.key]
        if self.component is not None:
            try:
                np.empty(shape)[(slice(None),) + self.component]
            except IndexError:
                raise StudyError(
                    f"output '{self.name}': component {self.component} is outside the per-element "
                    f"shape {shape[1:]} of {self.family}/{self.key}; index within it"
                ) from None

    def _component_labels(self):
        return [] if self.reduce is not None else [None]

    def extract(self, model, frame):
        v = np.asarray(frame[f"el/{self.family}/{self.key}"], dtype=float)
        if self.elements is not None:
            v = v[np.asarray(self.elements)]
        if self.component is not None:
            try:
                v = v[(slice(None),) + self.component]
            except IndexError:
                raise StudyError(
                    f"output '{self.name}': component {self.component} is outside the per-element "
                    f"shape {v.shape[1:]} of {self.family}/{self.key}"
                ) from None
        if self.reduce is None:
            return v.copy()
        if self.reduce == "absmax":
            return float(np.max(np.abs(v)))
        return float(getattr(np, self.reduce)(v))


def family_outputs(model, analysis_options: dict) -> dict:
    """{family name: {output key: array shape}} of ``model`` (its families evaluated once at the start)."""
    from ..analysis import Analysis

    an = Analysis(
        model,
        None,
        progress=False,
        on_frame=lambda fr: None,
        **{k: v for k, v in analysis_options.items() if k not in ("progress", "on_frame")},
    )
    sys_ = an.system
    responses = sys_.evaluate(sys_.committed_context())
    return {f.name: {k: np.shape(v) for k, v in r.output.items()} for f, r in zip(an.families, responses)}


class Recorder:
    """An ``on_frame`` recorder keeping, for each output, its extracted value at the latest frame of
    each step it needs (so, after the run, the value at the step's end)."""

    def __init__(self, model, outputs):
        self.model, self.outputs = model, list(outputs)
        self.needs = [set(o.needed(model)) for o in self.outputs]
        self.record = [dict() for _ in self.outputs]

    def __call__(self, frame):
        step = str(frame["step"])
        for o, need, rec in zip(self.outputs, self.needs, self.record):
            if step in need:
                rec[step] = o.extract(self.model, frame)

    def values(self) -> dict:
        return {o.name: o.finish(self.model, rec) for o, rec in zip(self.outputs, self.record)}
