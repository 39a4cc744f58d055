"""Registry of experiments: built-in names and user scripts.

``get_experiment(name_or_path, **options)`` returns a registered experiment by name or loads a
user script (a ``.py`` file defining a module-level ``experiment``; it may also register
effects).  ``register_experiment`` adds one under its name (a script may also do that and then
be referred to by name in the same process).

The built-in rigs (:mod:`femast.rigs`) sit above this framework and are registered the way an
installed package of rigs is: through the ``femast.experiments`` entry point group
(``pyproject.toml``: ``[project.entry-points."femast.experiments"]``), whose entries name a sequence
of experiments (or one); the registry loads every entry on first use, femast's own first.  The
framework itself imports no rig.
"""

from __future__ import annotations

from dataclasses import replace
from importlib.metadata import entry_points
from pathlib import Path

from ..effects.scripts import load_script
from ..errors import FemastError, ModelError, did_you_mean
from .core import Experiment

#: the entry point group that installed packages (femast's built-in rigs first) register experiments in
ENTRY_POINTS = "femast.experiments"

_EXPERIMENTS: dict[str, Experiment] = {}
_BUILTIN_LOADED = False


def _load_builtin() -> None:
    """Register the experiments of every installed package's ``femast.experiments`` entry points
    (femast's built-in rigs first) on first use of the registry: importing them imports their
    models (the ADAM and guyed-mast builders), which ``import femast.experiments`` alone does not need."""
    global _BUILTIN_LOADED
    if _BUILTIN_LOADED:
        return
    _BUILTIN_LOADED = True
    found = sorted(entry_points(group=ENTRY_POINTS), key=lambda ep: ep.dist is None or ep.dist.name != "femast")
    if not any(ep.dist is not None and ep.dist.name == "femast" for ep in found):
        raise FemastError(
            f"femast's built-in experiments are not registered (no '{ENTRY_POINTS}' entry point of femast): "
            "the installed package metadata is out of date; reinstall femast (pip install -e . in a source checkout)"
        )
    for ep in found:
        try:
            loaded = ep.load()
        except Exception as e:
            raise FemastError(
                f"the experiments of entry point '{ep.name} = {ep.value}' (package {ep.dist.name if ep.dist else '?'}) "
                f"do not load: {type(e).__name__}: {e}"
            ) from e
        for experiment in (loaded,) if isinstance(loaded, Experiment) else loaded:
            register_experiment(experiment)


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
