"""A restart point read back from disk: every value checked before a run uses it.

``restart.json`` and the state files are files like any other: an editor, a script or a damaged
disk can leave anything in them.  A restart that trusted them could delete frames (a negative
frame count), read a file outside the folder (a ``state_file`` of ``../../x``) or start from a
state of another shape.  :func:`check_point` checks the JSON record against the model (types,
ranges, the file names femast writes, the counts consistent with each other) and
:func:`check_arrays` the arrays of the state against the analysis (shapes, finite values, the
step and increment the record names).  Each raises a FemastError naming the field and its value.
"""

from __future__ import annotations

import math
import numbers

import numpy as np

from ..errors import FemastError

FORMAT = "femast-restart-1"


def _shown(v) -> str:
    s = repr(v)
    return s if len(s) <= 60 else s[:57] + "..."


def _count(info, key, where, lo=0, hi=None):
    v = info.get(key)
    if not (isinstance(v, numbers.Integral) and not isinstance(v, bool) and v >= lo and (hi is None or v <= hi)):
        rng = f">= {lo}" if hi is None else f"from {lo} to {hi}"
        raise FemastError(f"{where}: '{key}' = {_shown(v)} is not a whole number {rng}")
    return int(v)


def check_point(info, where, analysis) -> dict:
    """``info`` (restart.json of file ``where``) if it is a restart point of ``analysis``' model
    that femast could have written, else a FemastError (module docstring)."""
    if not isinstance(info, dict):
        raise FemastError(f"{where}: a {type(info).__name__}, not a restart record")
    if info.get("format") != FORMAT:
        raise FemastError(f"{where}: format {_shown(info.get('format'))}, not {FORMAT}")
    names = [s.name for s in analysis.model.steps]
    n = len(analysis.system.X0)
    if info.get("n_nodes") != n or info.get("steps") != names:
        raise FemastError(
            f"{where}: the restart point belongs to another model ({_shown(info.get('n_nodes'))} nodes, steps "
            f"{_shown(info.get('steps'))}; this one: {n} nodes, steps {names}); restart with the model that wrote it"
        )
    if "initial" in info:
        if info["initial"] is not True:
            raise FemastError(f"{where}: 'initial' = {_shown(info['initial'])} is not true")
        return info
    step = _count(info, "step", where, 0, len(names) - 1)
    if info.get("step_name") != names[step]:
        raise FemastError(f"{where}: 'step_name' = {_shown(info.get('step_name'))} is not step {step}'s name")
    if not isinstance(info.get("step_done"), bool):
        raise FemastError(f"{where}: 'step_done' = {_shown(info.get('step_done'))} is not true or false")
    _count(info, "increment", where, 0, int(analysis.model.steps[step].max_increments))
    _count(info, "frames", where, 1)  # the initial frame at least (the frames on disk: checked by the writer)
    saves = _count(info, "saves", where, 1)
    _count(info, "every", where, 1)
    for key, stem in (("state_file", "state"), ("extra_file", "extra")):
        if info.get(key) != f"{stem}-{saves}.npz":  # the names femast writes, inside restart/
            raise FemastError(f"{where}: '{key}' = {_shown(info.get(key))} is not {stem}-{saves}.npz")
    zf = info.get("zero_force")
    if zf is not None:
        try:
            ok = isinstance(zf, str) and math.isfinite(v := float.fromhex(zf)) and v > 0
        except (ValueError, OverflowError):
            ok = False
        if not ok:
            raise FemastError(f"{where}: 'zero_force' = {_shown(zf)} is not a positive number in hex")
    s = info.get("summary")
    if not isinstance(s, dict):
        raise FemastError(f"{where}: 'summary' = {_shown(s)} is not a record")
    here = f"{where}, summary"
    for key in ("increments", "iterations", "cutbacks", "line_searches"):
        _count(s, key, here)
    _count(s, "step_iterations", here, 0, s["iterations"])
    steps = s.get("steps")
    done = step + (1 if info["step_done"] else 0)
    if not isinstance(steps, list) or len(steps) != done:
        raise FemastError(f"{here}: 'steps' = {_shown(steps)} is not a list of the {done} steps done")
    for k, st in enumerate(steps):
        if not isinstance(st, dict) or st.get("name") != names[k]:
            raise FemastError(f"{here}: steps[{k}] = {_shown(st)} is not the record of step '{names[k]}'")
        for key in ("increments", "iterations"):
            if key in st:
                _count(st, key, f"{here}, steps[{k}]")
    return info


def _array(a, shape, what, where):
    if a is None or not isinstance(a, np.ndarray) or a.dtype.kind != "f" or a.shape != shape:
        got = "missing" if a is None else f"{getattr(a, 'dtype', type(a).__name__)} {getattr(a, 'shape', '')}"
        raise FemastError(f"{where}: {what} is {got}, not a float array of shape {shape}")
    if not np.isfinite(a).all():
        raise FemastError(f"{where}: {what} holds NaN or infinite values")


def _number(v, what, where, positive=False, optional=False):
    if v is None and optional:
        return
    ok = isinstance(v, numbers.Real) and not isinstance(v, bool) and math.isfinite(v) and (not positive or v > 0)
    if not ok:
        raise FemastError(f"{where}: {what} = {_shown(v)} is not a finite{' positive' if positive else ''} number")


def check_arrays(state, step_start, reuse, analysis, where) -> None:
    """The state and the step's start values of a restart point (files in folder ``where``) fit
    ``analysis``: shapes, finite values, the step and increment of the record; else a FemastError."""
    sys_ = analysis.system
    n, nf = len(sys_.X0), sys_.n_free
    n_cons = sys_.dofmap.n_independent - nf
    w = f"{where}, state"
    for name, shape in (("x", (n, 3)), ("R", (n, 3, 3)), ("spin", (n, 3)), ("loads", (n, 6)), ("prescribed", (n, 6))):
        _array(getattr(state, name), shape, name, w)
    for name, shape in (("reactions", (n_cons,)), ("last_increment", (nf,)), ("damping", (nf,)), ("damping0", (nf,))):
        if getattr(state, name) is not None:
            _array(getattr(state, name), shape, name, w)
    if len(state.families) != len(analysis.families) or any(
        np.shape(a) != np.shape(f.initial_state()) for a, f in zip(state.families, analysis.families)
    ):
        raise FemastError(f"{w}: the element states are not those of this model's {len(analysis.families)} families")
    for k, a in enumerate(state.families):
        if np.asarray(a).dtype.kind in "fc" and not np.isfinite(a).all():
            raise FemastError(f"{w}: the state of element family {k + 1} holds NaN or infinite values")
    for name in ("lam", "total_time", "step_time", "strain_energy", "stabilization_energy"):
        _number(getattr(state, name), name, w)
    for name in ("size", "first_size"):
        _number(getattr(state, name), name, w, positive=True, optional=True)
    for name in ("last_size", "last_dlam"):
        _number(getattr(state, name), name, w, optional=True)
    for name in ("step", "increment", "easy", "version"):
        v = getattr(state, name)
        if not (isinstance(v, numbers.Integral) and not isinstance(v, bool) and v >= 0):
            raise FemastError(f"{w}: {name} = {_shown(v)} is not a whole number >= 0")
    for name, a in zip(("load_start", "pres_start"), step_start):
        _array(a, (n, 6), name, f"{where}, step start")
    if reuse is not None:
        _array(reuse[0], (n, 3), "reuse_x", f"{where}, factorisation point")
        _array(reuse[1], (n, 3, 3), "reuse_R", f"{where}, factorisation point")
