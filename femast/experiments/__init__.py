"""Experiments: measured data, models of the test, ``compare`` and ``diagnose`` (issue 7).

An :class:`Experiment` pairs a data format (CSV columns with units) with a model function,
its fittable parameters and the hooks where physical effects (:mod:`femast.effects`) act.

Built-in experiments: ``mast-top`` (seed 000, 3R model), ``latch-pull`` (seed 001 latch law),
``bay-torsion`` (FE single ADAM bay, seed 001 Figs. 16-17), ``tip-cycle`` (FE ADAM mast under
tip load cycles, seed 001 Table 1) and ``vibration`` (measured natural frequencies against the
prestressed modal analysis, seed 001 Sec. IV), ``platform-pose`` (the CDPR platform on compliant
masts, seed 000 Fig. 7).

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

from . import bay_torsion, latch_pull, mast_top, platform_pose, tip_cycle, vibration  # noqa: E402  (built-in experiments)
from .core import Column, EffectStack, Experiment, Measured, Parameter, prepared
from .data import from_arrays, read_data, write_data
from .registry import experiment_from_source, get_experiment, list_experiments, register_experiment

for _e in (
    mast_top.EXPERIMENT,
    latch_pull.EXPERIMENT,
    bay_torsion.EXPERIMENT,
    tip_cycle.EXPERIMENT,
    vibration.EXPERIMENT,
    platform_pose.EXPERIMENT,
):
    register_experiment(_e)

from .. import effects as _effects  # noqa: E402,F401  (registers the built-in effects)
from .compare import compare, format_compare  # noqa: E402
from .diagnose import AT_NOISE, SIGNIFICANT_DBIC, diagnose, format_diagnose  # noqa: E402
from .fitting import fit, predict, run_model  # noqa: E402
from .history import plot_history, read_history  # noqa: E402

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
]
