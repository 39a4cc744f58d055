"""Registry of experiments: built-in names and user scripts.

``get_experiment(name_or_path, **options)`` returns a built-in experiment by name or loads a
user script (a ``.py`` file defining a module-level ``experiment``; it may also register
effects).  ``register_experiment`` adds one under its name (a script may also do that and then
be referred to by name in the same process).
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

from ..effects.scripts import load_script
from ..errors import ModelError, did_you_mean
from .core import Experiment

_EXPERIMENTS: dict[str, Experiment] = {}
_BUILTIN_LOADED = False


def _load_builtin() -> None:
    """Register the built-in rigs (:data:`femast.experiments.rigs.BUILT_IN`) on first use of the
    registry: importing them imports their models (the ADAM and guyed-mast builders), which
    ``import femast.experiments`` alone does not need."""
    global _BUILTIN_LOADED
    if not _BUILTIN_LOADED:
        _BUILTIN_LOADED = True
        from .rigs import BUILT_IN

        for rig in BUILT_IN:
            register_experiment(rig.EXPERIMENT)


def register_experiment(experiment: Experiment, replace_existing: bool = False) -> Experiment:
    """Register ``experiment`` under its name.

    A name already taken raises unless ``replace_existing`` or the registered one is pending a
    model (so the FE experiments can be plugged in over their placeholders)."""
    _load_builtin()
    if not isinstance(experiment, Experiment):
        raise ModelError(f"register_experiment needs an Experiment, got {type(experiment).__name__}")
    old = _EXPERIMENTS.get(experiment.name)
    if old is not None and old is not experiment and not (replace_existing or old.pending):
        raise ModelError(
            f"an experiment called '{experiment.name}' is already registered; choose another name "
            "or pass replace_existing=True"
        )
    if not experiment.source:
        experiment = replace(experiment, source=experiment.name)
    _EXPERIMENTS[experiment.name] = experiment
    return experiment


def list_experiments() -> tuple:
    """All registered experiments (built-in first)."""
    _load_builtin()
    return tuple(_EXPERIMENTS.values())


def _from_script(path: Path) -> Experiment:
    module = load_script(path)
    exp = getattr(module, "experiment", None)
    if not isinstance(exp, Experiment):
        raise ModelError(
            f"script {path} defines no module-level `experiment` (an femast.experiments.Experiment); "
            "see docs/experiments.md, 'Adding an experiment'"
        )
    return replace(exp, source=str(Path(path).resolve()))


def get_experiment(name_or_path, **options) -> Experiment:
    """A built-in or registered experiment by name, or the ``experiment`` of a user script (.py path).

    options : changes to the experiment's options (geometry...); unknown names raise ModelError.
    """
    _load_builtin()
    key = str(name_or_path)
    if key.endswith(".py") or Path(key).suffix == ".py":
        if not Path(key).is_file():
            raise ModelError(f"no such experiment script: {key}")
        exp = _from_script(Path(key))
    else:
        try:
            exp = _EXPERIMENTS[key]
        except KeyError:
            raise ModelError(
                f"unknown experiment '{key}'{did_you_mean(key, _EXPERIMENTS)}; accepted: "
                f"{', '.join(_EXPERIMENTS)} or the path of a Python script defining `experiment`"
            ) from None
    return exp.with_options(**options) if options else exp


def experiment_from_source(source: str, options: dict) -> Experiment:
    """Rebuild an experiment from its ``source`` and options (used by worker processes)."""
    exp = get_experiment(source)
    return replace(exp, options=dict(options))
