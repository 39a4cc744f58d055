"""Experiments: measured data, a model of the test, ``compare`` and ``diagnose``.

The framework: an :class:`Experiment` pairs a data format (CSV columns with units) with a model
function, its fittable parameters and the hooks where physical effects (:mod:`femast.effects`)
act; :func:`compare` runs or fits a model variant along the measured path and shows where it
fails; :func:`diagnose` refits it with each candidate effect and says which one is missing.

The rigs: the built-in experiments live in :mod:`femast.rigs`, one module per rig,
each written as a user's own rig is (``mast-top``, ``latch-pull``, ``bay-torsion``,
``tip-cycle``, ``vibration``, ``platform-pose``); ``femast experiments`` lists them.

Typical use::

    import femast.examples
    from femast.experiments import get_experiment, read_data, compare, diagnose
    exp = get_experiment("mast-top")
    data = read_data(exp, femast.examples.path("mast_top_example.csv"))
    c = compare(exp, data, fit=True, out="out/mast")          # where does the model fail?
    d = diagnose(exp, data, out="out/mast")                   # which effect is missing?
    c2 = compare(exp, data, [d.verdict["best_candidate"]], fit=True, out="out/mast")  # error falls

See ``docs/experiments.md`` and ``docs/compare_and_diagnose.md``.
"""

from .. import effects as _effects  # noqa: F401  (registers the built-in effects)
from .compare import compare, format_compare
from .core import Column, EffectStack, Experiment, Measured, Parameter, prepared
from .data import from_arrays, read_data, write_data
from .diagnose import AT_NOISE, SIGNIFICANT_DBIC, diagnose, format_diagnose
from .fitting import fit, predict, run_model
from .history import plot_history, read_history
from .registry import experiment_from_source, get_experiment, list_experiments, register_experiment
from .residuals import noise_floor, turning_points

__all__ = [
    "Column",
    "Parameter",
    "Experiment",
    "Measured",
    "EffectStack",
    "prepared",
    "read_data",
    "from_arrays",
    "write_data",
    "get_experiment",
    "list_experiments",
    "register_experiment",
    "experiment_from_source",
    "compare",
    "format_compare",
    "diagnose",
    "format_diagnose",
    "fit",
    "predict",
    "run_model",
    "read_history",
    "plot_history",
    "AT_NOISE",
    "SIGNIFICANT_DBIC",
    "noise_floor",
    "turning_points",
]
