"""``femast compare`` and ``femast diagnose`` (issue 7), registered by :mod:`femast.cli`.

::

    femast compare EXPERIMENT DATA.csv [--effects a,b] [--fit] [--out DIR] [--json]
    femast diagnose EXPERIMENT DATA.csv [--out DIR] [--json] [--workers N] [--scheduler ADDRESS]
                    [--effects a,b]

EXPERIMENT is a built-in name (``mast-top``, ``latch-pull``; ``bay-torsion`` and ``tip-cycle`` are
both FE models of femast.adam) or the path of a Python script defining ``experiment``.  An ``--effects`` entry
is an effect name, ``SCRIPT.py`` (every effect the script registers) or ``SCRIPT.py:name``.
``diagnose --effects`` names the effects already in the model being diagnosed (an extension of
issue 7: after adding the missing effect, diagnose the new model).
"""

from __future__ import annotations

import json
from pathlib import Path


def _effect_names(arg):
    from .effects.base import effects_of_script, load_script

    names = []
    for item in (arg or "").split(","):
        item = item.strip()
        if not item:
            continue
        if ":" in item and item.split(":", 1)[0].endswith(".py"):
            script, name = item.rsplit(":", 1)
            load_script(script)
            names.append(name)
        elif item.endswith(".py"):
            names += effects_of_script(item)
        else:
            names.append(item)
    return names


def _setup(args):
    from .experiments import get_experiment, read_data

    exp = get_experiment(args.experiment)
    effects = _effect_names(getattr(args, "effects", None))
    exp.require_model(f"femast {args.command}")
    data = read_data(exp, args.data)
    out = Path(args.out) if args.out else Path("femast_out") / f"{exp.name}_{Path(args.data).stem}"
    return exp, data, effects, out


def _compare(args):
    from .experiments import compare, format_compare

    exp, data, effects, out = _setup(args)
    res = compare(exp, data, effects, fit=args.fit, out=out)
    print(json.dumps(res.report, indent=2) if args.json else format_compare(exp, res))


def _diagnose(args):
    from .experiments import diagnose, format_diagnose

    exp, data, effects, out = _setup(args)
    res = diagnose(exp, data, base_effects=effects, workers=args.workers, scheduler=args.scheduler, out=out)
    print(json.dumps(res.report, indent=2) if args.json else format_diagnose(exp, res))


def register(subparsers) -> None:
    """Add the ``compare`` and ``diagnose`` sub-commands to femast's argument parser."""
    p = subparsers.add_parser(
        "compare", help="run a model along measured data and show where it fails",
        description="Run the model of EXPERIMENT along the measured path of DATA.csv (fitting its parameters "
                    "with --fit); print the overall and per-channel RMS error, the noise floor and the worst "
                    "segments of the path; write compare.png, compare.json and append to history.jsonl in DIR.")
    p.add_argument("experiment", help="built-in experiment name (mast-top, latch-pull) or a Python script path")
    p.add_argument("data", help="measured data, CSV with a header row (see docs/experiments.md)")
    p.add_argument("--effects", default=None, help="comma-separated effects to switch on (names, SCRIPT.py or "
                                                   "SCRIPT.py:name)")
    p.add_argument("--fit", action="store_true", help="fit the model and effect parameters")
    p.add_argument("--out", default=None, help="output folder (default femast_out/EXPERIMENT_DATASTEM)")
    p.add_argument("--json", action="store_true", help="print the JSON report instead of the text summary")
    p.set_defaults(func=_compare)
    p = subparsers.add_parser(
        "diagnose", help="rank the physical effects the model may be missing",
        description="Fit the model of EXPERIMENT, refit it with each applicable candidate effect (in parallel), "
                    "rank them by BIC and conclude: the missing effect, 'nothing is missing' or 'none of the "
                    "candidates explains this'. Writes diagnose.png and diagnose.json in DIR.")
    p.add_argument("experiment", help="built-in experiment name (mast-top, latch-pull) or a Python script path")
    p.add_argument("data", help="measured data, CSV with a header row")
    p.add_argument("--out", default=None, help="output folder (default femast_out/EXPERIMENT_DATASTEM)")
    p.add_argument("--json", action="store_true", help="print the JSON report instead of the text summary")
    p.add_argument("--workers", type=int, default=None, help="local worker processes (default: all CPUs)")
    p.add_argument("--scheduler", default=None, help="dask.distributed scheduler address (tcp://host:port)")
    p.add_argument("--effects", default=None, help="effects already in the model being diagnosed")
    p.set_defaults(func=_diagnose)
