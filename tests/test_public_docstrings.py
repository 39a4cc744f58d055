"""The user's API explains itself: every public function and method a model script calls names
each of its parameters in its docstring, with the unit of every number it takes."""

import inspect
import re

import pytest

import femast as fm
from femast.model.model import Step
from femast.post.render import largest_displacement_frame, render_png
from femast.post.results import Results
from femast.post.vtk import export_vtk

# the control strategies' protocol methods (setup, plan, dlambda...) are the analysis' side, not a script's
_SCRIPT_CLASSES = (fm.Model, Step, Results)
_NOT_PARAMETERS = {"self", "cls", "args", "kwargs", "options"}
# a unit said in parentheses "(m)", "(N m, global axes)", after a comma ", Pa.", or "dimensionless"
_UNITS = re.compile(
    r"\((?:[^()]*\b(?:m|N|N m|Pa|rad|s|K|kg|kg/m|1/K|Hz|m\^\d|kg m\^2|degC)\b[^()]*)\)"
    r"|, (?:Pa|m\^\d|m|N|rad|s|kg/m\^3)\b|dimensionless"
)


def _public():
    for name in fm.__all__:
        obj = getattr(fm, name)
        if inspect.isfunction(obj) or (isinstance(obj, type) and not issubclass(obj, Exception)):
            yield name, obj
    for cls in _SCRIPT_CLASSES:
        for name, f in vars(cls).items():
            if not name.startswith("_") and inspect.isfunction(f):
                yield f"{cls.__name__}.{name}", f
    for f in (export_vtk, render_png, largest_displacement_frame):
        yield f.__name__, f


PUBLIC = sorted(dict(_public()).items())


@pytest.mark.parametrize("name, obj", PUBLIC, ids=[n for n, _ in PUBLIC])
def test_every_parameter_is_named_in_the_docstring(name, obj):
    doc = inspect.getdoc(obj) or ""
    assert doc, f"{name} has no docstring"
    try:
        params = [p for p in inspect.signature(obj).parameters if p not in _NOT_PARAMETERS]
    except (TypeError, ValueError):
        params = []
    missing = [p for p in params if not re.search(rf"\b{re.escape(p)}\b", doc)]
    assert not missing, f"{name}: the docstring does not say what {missing} are"


@pytest.mark.parametrize("name, obj", PUBLIC, ids=[n for n, _ in PUBLIC])
def test_numbers_come_with_their_units(name, obj):
    """A callable taking a float (annotated or defaulted) says a unit in parentheses somewhere."""
    try:
        sig = inspect.signature(obj)
    except (TypeError, ValueError):
        return
    floats = [
        p
        for p in sig.parameters.values()
        if p.annotation in (float, "float", "float | None") or isinstance(p.default, float)
    ]
    if floats:
        assert _UNITS.search(inspect.getdoc(obj) or ""), f"{name} takes {[p.name for p in floats]} without a unit"
