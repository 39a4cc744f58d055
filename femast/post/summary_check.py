"""A run summary read back from ``summary.json``: every value femast relies on checked.

The summary is a file on disk; anything may have happened to it (an editor, a tool, a copy cut
short).  :func:`check_summary` returns the summary if every field femast reads has the type and
range it writes (a status of the four known ones, counts as whole numbers >= 0, times as finite
numbers, steps as a list of records with a name), or raises a FemastError naming the file, the
field and the value.  Fields femast does not read are kept as they are.
"""

from __future__ import annotations

import math
import numbers

from ..errors import FemastError

STATUSES = ("running", "completed", "failed", "interrupted")
_COUNTS = ("increments", "iterations", "cutbacks", "line_searches", "pid")
_TIMES = ("wall_time", "increment_time", "assembly_time", "solve_time", "started", "strain_energy")
_TEXTS = ("message", "host")


def _bad(where, field, value, want) -> FemastError:
    shown = repr(value)
    shown = shown if len(shown) <= 60 else shown[:57] + "..."
    return FemastError(f"{where}: '{field}' = {shown} is not {want}; the file is damaged or was edited")


def is_count(v) -> bool:
    """A whole number >= 0 (not a bool, not a float)."""
    return isinstance(v, numbers.Integral) and not isinstance(v, bool) and v >= 0


def is_number(v) -> bool:
    """A finite real number (not a bool)."""
    return isinstance(v, numbers.Real) and not isinstance(v, bool) and math.isfinite(v)


def check_summary(s, where) -> dict:
    """``s`` (a summary parsed from file ``where``) if valid, else a FemastError (module docstring)."""
    if not isinstance(s, dict):
        raise FemastError(
            f"{where}: the summary is {type(s).__name__}, not a record; the file is damaged or was edited"
        )
    if "status" in s and s["status"] not in STATUSES:
        raise _bad(where, "status", s["status"], f"one of {', '.join(STATUSES)}")
    if "completed" in s and not isinstance(s["completed"], bool):
        raise _bad(where, "completed", s["completed"], "true or false")
    for k in _COUNTS:
        if k in s and not is_count(s[k]):
            raise _bad(where, k, s[k], "a whole number >= 0")
    for k in _TIMES:
        if k in s and not is_number(s[k]):
            raise _bad(where, k, s[k], "a finite number")
    for k in _TEXTS:
        if k in s and not isinstance(s[k], str):
            raise _bad(where, k, s[k], "a text")
    steps = s.get("steps", [])
    if not isinstance(steps, list):
        raise _bad(where, "steps", steps, "a list of steps")
    for k, st in enumerate(steps):
        field = f"steps[{k}]"
        if not isinstance(st, dict) or not isinstance(st.get("name"), str):
            raise _bad(where, field, st, "a step record with a name")
        for c in ("increments", "iterations"):
            if c in st and not is_count(st[c]):
                raise _bad(where, f"{field}.{c}", st[c], "a whole number >= 0")
        freqs = st.get("frequencies_hz", [])
        if not isinstance(freqs, list) or not all(is_number(f) for f in freqs):
            raise _bad(where, f"{field}.frequencies_hz", freqs, "a list of numbers")
    return s
