"""``femast compare``, ``diagnose``, ``experiments``, ``effects``, ``examples``,
registered by :mod:`femast.cli`.

::

    femast compare EXPERIMENT DATA.csv [--effects a,b] [--fit] [--params-from RUN] [--sigma CH=V,...]
                   [--out DIR] [--json]
    femast diagnose EXPERIMENT DATA.csv [--out DIR] [--json] [--workers N] [--scheduler ADDRESS]
                    [--effects a,b] [--candidates a,b] [--exclude a,b] [--sigma CH=V,...]
    femast experiments [--json]            femast effects [EXPERIMENT] [--json]
    femast examples [--copy DIR]

EXPERIMENT is a registered name (``femast experiments`` lists them) or the path of a Python script
defining ``experiment``; DATA is a CSV file or ``example`` (the experiment's shipped example,
:mod:`femast.examples`).  Outputs go to ``--out``, by default ``./compare/EXPERIMENT_DATASTEM``
(``./diagnose/...``) in the working directory.  An ``--effects`` entry
is an effect name, ``SCRIPT.py`` (every effect the script registers) or ``SCRIPT.py:name``.
``diagnose --effects`` names the effects already in the model being diagnosed (after adding the missing effect, diagnose the new model); ``--candidates`` / ``--exclude`` choose
the effects it tries.
"""

from __future__ import annotations

import json
from pathlib import Path


def _effect_names(arg):
    from .effects.scripts import effects_of_script, load_script

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


def _sigmas(arg) -> dict:
    """``--sigma dx_m=2e-5,dy_m=2e-5`` -> ``{"dx_m": 2e-5, "dy_m": 2e-5}`` (checked by the noise model)."""
    from .errors import ModelError

    out = {}
    for item in (arg or "").split(","):
        if not item.strip():
            continue
        name, eq, value = item.partition("=")
        if not eq:
            raise ModelError(f"--sigma {item!r}: give CHANNEL=VALUE in the channel's unit, e.g. --sigma dx_m=2e-5")
        try:
            out[name.strip()] = float(value)
        except ValueError:
            raise ModelError(f"--sigma {item!r}: {value.strip()!r} is not a number") from None
    return out


def experiment_rows() -> list[dict]:
    """Every registered experiment: name, title, its example data file (or None), its effects."""
    from . import examples
    from .effects import applicable_effects
    from .experiments import list_experiments
    from .text import first_sentence

    return [
        {
            "name": e.name,
            "title": e.title,
            "physics": first_sentence(e.doc) if e.doc else e.title,
            "example": examples.BY_EXPERIMENT.get(e.name),
            "effects": [f.name for f in applicable_effects(e)],
        }
        for e in list_experiments()
    ]


def effect_rows(experiment=None) -> list[dict]:
    """Every registered effect (or those applicable to ``experiment``, an Experiment): name, title, one
    sentence of physics, the registered experiments it applies to, the quantities its mechanism needs."""
    from .effects import list_effects
    from .experiments import list_experiments
    from .text import first_sentence

    experiments = list_experiments()
    rows = []
    for e in list_effects():
        if experiment is not None and not e.applies_to(experiment):
            continue
        m = e.mechanism
        rows.append(
            {
                "name": e.name,
                "title": e.title,
                "physics": first_sentence(e.physics),
                "experiments": [x.name for x in experiments if e.applies_to(x)],
                "quantities": [k for k in ("load", "displacement", "time", "temperature") if k in (m.hook, *m.needs)]
                if m is not None
                else [],
                "source": e.source,  # the paper and equation it comes from
            }
        )
    return rows


def _experiments(args):
    rows = experiment_rows()
    if args.json:
        print(json.dumps(rows, indent=2))
        return
    from .text import hanging

    print(
        hanging(
            "experiments", "(femast compare|diagnose EXPERIMENT DATA.csv; DATA 'example' uses the shipped example):", 0
        )
    )
    pad = 2 + max(len(r["name"]) for r in rows) + 1
    for r in rows:
        print(hanging(f"  {r['name']}", r["title"], pad))
        print(hanging("", f"example data: {r['example'] or '(none shipped)'}; effects: {', '.join(r['effects'])}", pad))


def _effects(args):
    exp = None
    if args.experiment:
        from .experiments import get_experiment

        exp = get_experiment(args.experiment)
    rows = effect_rows(exp)
    if args.json:
        print(json.dumps(rows, indent=2))
        return
    from .text import hanging

    print(f"effects{' of ' + exp.name if exp else ''} (femast compare ... --effects NAME[,NAME]):")
    pad = 2 + max((len(r["name"]) for r in rows), default=0) + 1
    for r in rows:
        where = r["experiments"] + ([f"any rig with {' + '.join(r['quantities'])}"] if r["quantities"] else [])
        print(hanging(f"  {r['name']}", f"{r['title']} [{', '.join(where)}]", pad))
        print(hanging("", r["physics"], pad))


def _examples(args):
    import shutil

    from . import examples

    if args.copy:
        dest = Path(args.copy)
        dest.mkdir(parents=True, exist_ok=True)
        extra = 0
        for n in examples.names():
            shutil.copy(examples.path(n), dest / n)
            for c in examples.companions(n):  # the licence and notice of data made by others
                shutil.copy(c, dest / c.name)
                extra += 1
        licences = f" and {extra} licence files" if extra else ""
        print(f"copied {len(examples.names())} example files{licences} to {dest}")
        return
    by_file = {v: k for k, v in examples.BY_EXPERIMENT.items()}
    from .text import hanging

    print(f"example data shipped with femast (in {examples.FOLDER}):")
    pad = 2 + max(len(n) for n in examples.names()) + 1
    for n in examples.names():
        use = f" ('example' for {by_file[n]})" if n in by_file else ""
        print(hanging(f"  {n}", examples.describe(n) + use, pad))


def resolve_data(exp, data: str):
    """(path to read, name to show) of the DATA argument: a file, or ``example`` for the experiment's
    shipped example (:mod:`femast.examples`)."""
    from . import examples

    if data == "example":
        p = examples.for_experiment(exp.name)
        return p, f"example {p.name}"
    if not Path(data).exists() and data in examples.names():
        return examples.path(data), f"example {data}"
    return Path(data), data


def _check_order(args) -> None:
    """``femast compare example mast-top``: the experiment and the data the wrong way round."""
    from .errors import FemastError
    from .experiments import list_experiments

    names = {e.name for e in list_experiments()}
    first = args.experiment
    second = args.data[0] if isinstance(args.data, list) else args.data
    if first not in names and not first.endswith(".py") and (second in names or second.endswith(".py")):
        raise FemastError(
            f"'{first}' is not an experiment but '{second}' is: the experiment comes first, then the data "
            f"(femast {args.command} {second} {first})"
        )


def _setup(args):
    from dataclasses import replace

    from .experiments import get_experiment, read_data

    _check_order(args)
    exp = get_experiment(args.experiment)
    effects = _effect_names(getattr(args, "effects", None))
    exp.require_model(f"femast {args.command}")
    items = args.data if isinstance(args.data, list) else [args.data]
    found = [resolve_data(exp, d) for d in items]
    paths, shown = [f[0] for f in found], [f[1] for f in found]
    data = read_data(
        exp, paths, getattr(args, "units", None), time_continuous=args.continuous_time, offsets=args.group_offsets
    )
    if len(paths) == 1:
        data = replace(data, path=shown[0])
    stem = Path(shown[0].split()[-1]).stem + (f"_and_{len(paths) - 1}_more" if len(paths) > 1 else "")
    out = Path(args.out) if args.out else Path(args.command) / f"{exp.name}_{stem}"
    return exp, data, effects, out


def params_from(run) -> tuple:
    """(parameters ``{name: value}``, effects) of an earlier compare: its output folder or compare.json."""
    from .errors import ModelError

    path = Path(run)
    if path.is_dir():
        path = path / "compare.json"
    if not path.is_file():
        raise ModelError(
            f"--params-from {run}: no compare.json there; give a compare output folder or its compare.json"
        )
    try:
        rep = json.loads(path.read_text())
        params = {k: float(v["value"]) for k, v in rep["params"].items()}
        effects = list(rep.get("effects", []))
    except (ValueError, KeyError, TypeError) as e:
        raise ModelError(f"--params-from {path}: not a compare report ({type(e).__name__}: {e})") from None
    return params, effects


def _compare(args):
    from .experiments import compare, format_compare

    exp, data, effects, out = _setup(args)
    params = None
    if args.params_from:
        params, run_effects = params_from(args.params_from)
        effects = effects or run_effects
    res = compare(
        exp, data, effects, fit=args.fit, params=params, out=out, sigma=_sigmas(args.sigma), max_rows=args.max_rows
    )
    print(json.dumps(res.report, indent=2) if args.json else format_compare(exp, res))


def _diagnose(args):
    from .experiments import diagnose, format_diagnose

    exp, data, effects, out = _setup(args)
    res = diagnose(
        exp,
        data,
        _effect_names(args.candidates) if args.candidates else None,
        exclude=_effect_names(args.exclude),
        base_effects=effects,
        sigma=_sigmas(args.sigma),
        workers="auto" if args.workers is None else args.workers,
        scheduler=args.scheduler,
        out=out,
        max_rows=args.max_rows,
        screen=not args.no_screen,
    )
    print(json.dumps(res.report, indent=2) if args.json else format_diagnose(exp, res))


def register(subparsers, fmt=None) -> None:
    """Add ``compare``, ``diagnose``, ``experiments``, ``effects`` and ``examples`` to femast's parser;
    the lists in the help come from the registries."""
    from .effects import list_effects
    from .experiments import list_experiments

    exps = ", ".join(e.name for e in list_experiments())
    effs = ", ".join(e.name for e in list_effects())
    kw = {"formatter_class": fmt} if fmt else {}
    exp_help = (
        f"built-in experiment ({exps}; `femast experiments` says what each is) or the path of a Python "
        "script defining `experiment`"
    )
    data_help = (
        "measured data, a CSV file with a header row (formats: `femast experiments`, docs/experiments.md), "
        "or 'example' for the example shipped with femast; several files are one data set, each file a "
        "group (a station, specimen or run)"
    )
    continuous_help = (
        "the files (or groups) are one test whose time goes on from one to the next (default: separate "
        "tests, time restarts in each)"
    )
    offsets_help = (
        "fit a zero of its own for every group and channel, e.g. sensors zeroed at each station (default: no)"
    )
    units_help = (
        "the unit the values of a column are in when its header says another, COLUMN=UNIT[,...] "
        "(e.g. dx_m=mm; a header may also carry the unit itself, dx_mm); naming the header's own unit "
        "(dx_m=m) confirms it and skips the size check of that column (default: the headers' units)"
    )
    out_help = "output folder (default: ./%(prog_cmd)s/EXPERIMENT_DATASTEM in the working directory)"
    sigma_help = (
        "sensor uncertainty of channels, CHANNEL=VALUE[,...] in the channel's unit, e.g. dx_m=2e-5 (default: "
        "sigma_ columns, else the repeatability of repeated rows, else estimated from the residual)"
    )
    p = subparsers.add_parser(
        "compare",
        help="run a model along measured data and show where it fails",
        **kw,
        description="Run the model of EXPERIMENT along the measured path of DATA (fitting its parameters "
        "with --fit); print the overall and per-channel RMS error, the noise floor and the worst "
        "segments of the path; write compare.png, compare.json and append to history.jsonl in the "
        "output folder.  Example: femast compare mast-top example --fit",
    )
    p.add_argument("experiment", help=exp_help)
    p.add_argument("data", nargs="+", help=data_help)
    p.add_argument("--continuous-time", action="store_true", help=continuous_help)
    p.add_argument("--group-offsets", action="store_true", help=offsets_help)
    p.add_argument(
        "--effects",
        default=None,
        help=f"comma-separated effects to switch on: names ({effs}; "
        "`femast effects EXPERIMENT`), SCRIPT.py or SCRIPT.py:name "
        "(default: none)",
    )
    p.add_argument(
        "--fit",
        action="store_true",
        help="fit the model and effect parameters (default: run with the default parameters)",
    )
    p.add_argument("--out", default=None, help=out_help % {"prog_cmd": "compare"})
    p.add_argument("--sigma", default=None, help=sigma_help)
    p.add_argument(
        "--params-from",
        metavar="RUN",
        default=None,
        help="take the parameters (and effects) of an earlier compare, its output folder or compare.json: fit on "
        "one data set, score another (with --fit: start the fit there) (default: the model's defaults)",
    )
    p.add_argument("--units", default=None, help=units_help)
    p.add_argument(
        "--max-rows",
        type=int,
        default=10_000,
        help="rows used at most: a longer record is thinned to every k-th row, and femast says so",
    )
    p.add_argument("--json", action="store_true", help="print the JSON report instead of the text summary")
    p.set_defaults(func=_compare)
    p = subparsers.add_parser(
        "diagnose",
        help="rank the physical effects the model may be missing",
        **kw,
        description="Fit the model of EXPERIMENT, refit it with each applicable candidate effect (in parallel), "
        "rank them by BIC and conclude: the missing effect, 'nothing is missing' or 'none of the "
        "candidates explains this'. Writes diagnose.png and diagnose.json in the output folder.  "
        "Example: femast diagnose mast-top example",
    )
    p.add_argument("experiment", help=exp_help)
    p.add_argument("data", nargs="+", help=data_help)
    p.add_argument("--continuous-time", action="store_true", help=continuous_help)
    p.add_argument("--group-offsets", action="store_true", help=offsets_help)
    p.add_argument("--out", default=None, help=out_help % {"prog_cmd": "diagnose"})
    p.add_argument("--sigma", default=None, help=sigma_help)
    p.add_argument("--units", default=None, help=units_help)
    p.add_argument(
        "--max-rows",
        type=int,
        default=10_000,
        help="rows used at most: a longer record is thinned to every k-th row, and femast says so",
    )
    p.add_argument("--json", action="store_true", help="print the JSON report instead of the text summary")
    p.add_argument(
        "--workers",
        type=int,
        default=None,
        help="local worker processes (default: all CPUs, or none when the refits are quick)",
    )
    p.add_argument(
        "--scheduler",
        default=None,
        help="dask.distributed scheduler address tcp://host:port (default: local processes)",
    )
    p.add_argument(
        "--effects", default=None, help="comma-separated effects already in the model being diagnosed (default: none)"
    )
    p.add_argument(
        "--candidates",
        default=None,
        help="comma-separated effects to try: names, SCRIPT.py or SCRIPT.py:name (default: every effect that "
        "applies to the experiment)",
    )
    p.add_argument("--exclude", default=None, help="comma-separated effects not to try (default: none)")
    p.add_argument(
        "--no-screen",
        action="store_true",
        help="refit every candidate in full (default: on an FE experiment, a candidate whose linearised gain "
        "cannot be significant is screened out after one model run per start and new parameter)",
    )
    p.set_defaults(func=_diagnose)
    p = subparsers.add_parser(
        "experiments",
        help="list the experiments compare/diagnose know, one line each",
        **kw,
        description="List every registered experiment with what it models, its shipped "
        "example data and the effects implemented for it.",
    )
    p.add_argument("--json", action="store_true", help="print a JSON list instead of text")
    p.set_defaults(func=_experiments)
    p = subparsers.add_parser(
        "effects",
        help="list the physical effects (all, or those of one experiment)",
        **kw,
        description="List the registered effects with one sentence of physics each and "
        "the experiments they are implemented for.",
    )
    p.add_argument(
        "experiment",
        nargs="?",
        default=None,
        help=f"only the effects implemented for this experiment ({exps}; default: all)",
    )
    p.add_argument("--json", action="store_true", help="print a JSON list instead of text")
    p.set_defaults(func=_effects)
    p = subparsers.add_parser(
        "examples",
        help="list the example data shipped with femast",
        **kw,
        description="List the example data files installed with femast (usable as "
        "'example' in compare/diagnose, or femast.examples.path(NAME) in "
        "Python).",
    )
    p.add_argument("--copy", metavar="DIR", default=None, help="copy them to folder DIR (default: only list them)")
    p.set_defaults(func=_examples)
