"""User scripts that register effects (and may define an experiment), loaded once per process.

Their resolved paths are remembered so that the worker processes of ``diagnose`` load them too.
"""

from __future__ import annotations

import hashlib
import importlib.util
import sys
from pathlib import Path

from ..errors import ModelError
from .base import list_effects

_SCRIPTS: list[str] = []  # scripts loaded in this process (re-loaded by worker processes)
_SCRIPT_EFFECTS: dict[str, list] = {}  # script path -> names of the effects it registered


def registry() -> tuple:
    """Names of the registered effects."""
    return tuple(e.name for e in list_effects())


def load_script(path) -> object:
    """Import a user script (experiment and/or effects) once per process and return the module.

    The script registers effects with :func:`~femast.effects.register_effect` and may define ``experiment``.
    Its resolved path is remembered so that worker processes of ``diagnose`` load it too.
    """
    p = Path(path).resolve()
    if not p.is_file():
        raise ModelError(f"no such script: {path}")
    modname = "femast_user_" + hashlib.sha1(str(p).encode()).hexdigest()[:12]
    if modname in sys.modules:
        return sys.modules[modname]
    spec = importlib.util.spec_from_file_location(modname, p)
    module = importlib.util.module_from_spec(spec)
    sys.modules[modname] = module
    before = set(registry())
    try:
        spec.loader.exec_module(module)
    except Exception:
        del sys.modules[modname]
        raise
    _SCRIPT_EFFECTS[str(p)] = [n for n in registry() if n not in before]
    if str(p) not in _SCRIPTS:
        _SCRIPTS.append(str(p))
    return module


def effects_of_script(path) -> list:
    """Names of the effects a script registered when it was loaded (loads it if needed)."""
    load_script(path)
    return list(_SCRIPT_EFFECTS.get(str(Path(path).resolve()), []))


def loaded_scripts() -> tuple:
    """Resolved paths of the user scripts loaded in this process."""
    return tuple(_SCRIPTS)
