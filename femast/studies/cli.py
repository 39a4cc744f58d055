"""``femast study SCRIPT --samples N [--workers N | --scheduler ADDRESS]``.

SCRIPT is a Python file that defines ``study`` (a :class:`femast.studies.Study`); it is run with
``__name__ == "__femast_study__"`` (not ``"__main__"``), so the script's own main block does not
run.  The results go to ``--out`` (default ``studies/<script name>``); running the same command
again resumes an interrupted study.
"""

from __future__ import annotations

import runpy
from pathlib import Path

from ..errors import StudyError
from ..workers import cpu_count

EXIT_FAILED_SAMPLES = 3


def script_path(text) -> Path:
    """The file of a study script: a path, or the name of an installed module
    (``femast.benchmarks.study_guyed``: the docs' studies, from any folder)."""
    p = Path(text)
    if p.is_file():
        return p
    name = str(text)
    if p.suffix != ".py" and all(part.isidentifier() for part in name.split(".")):
        import importlib.util

        try:
            spec = importlib.util.find_spec(name)
        except (ImportError, ValueError):
            spec = None
        if spec is not None and spec.origin and spec.origin.endswith(".py"):
            return Path(spec.origin)
    raise StudyError(f"no such study script: {p} (give the path of a .py file or an installed module's name)")


def load_script(path) -> Study:  # noqa: F821
    """The ``study`` defined by the script at ``path``."""
    from .study import Study

    p = script_path(path)
    ns = runpy.run_path(str(p), run_name="__femast_study__")
    s = ns.get("study")
    if not isinstance(s, Study):
        found = [k for k, v in ns.items() if isinstance(v, Study)]
        hint = f"; it defines {', '.join(found)}: name it 'study'" if found else ""
        raise StudyError(f"{p} defines no 'study' (a femast.studies.Study){hint}")
    return s


def _study(args):
    from .report import report
    from .runners import run

    if args.workers is not None and args.scheduler is not None:
        raise StudyError("give --workers (local processes) or --scheduler (a dask cluster), not both")
    study = load_script(args.script)
    out = args.out or str(Path("studies") / script_path(args.script).stem)
    workers = args.workers if args.workers is not None else cpu_count()
    try:
        s = run(study, out, samples=args.samples, workers=workers, scheduler=args.scheduler, chunk_size=args.chunk_size)
    except KeyboardInterrupt:
        import sys

        from .. import progress

        progress.close_all()
        print(
            f"femast study: interrupted; the finished runs are in {out}: run the same command again to resume",
            file=sys.stderr,
        )
        raise
    print(s)
    if s.complete and not args.no_report:
        report(out, print_table=True)
    from .results import load

    failed = load(out).counts()["failed"]  # this call's and any stored before a resume
    if failed:
        import sys

        print(
            f"femast study: {failed} run(s) FAILED; exit code {EXIT_FAILED_SAMPLES} "
            f"(reasons: femast.studies.load('{out}').failures())",
            file=sys.stderr,
        )
        return EXIT_FAILED_SAMPLES
    return 0


def register(sub, help_formatter):
    p = sub.add_parser(
        "study",
        help="run a study of uncertain inputs (percentiles, sensitivity)",
        formatter_class=help_formatter,
        description="Run the femast.studies.Study named 'study' in SCRIPT for N samples, in local "
        "processes or on a dask cluster; the results are stored as they come (run the "
        "same command again to resume) and summarised with figures.  Exit code 0: "
        "every run succeeded; 3: some runs failed (listed by femast.studies.load(OUT)"
        ".failures()); 2: the study could not run; 130: interrupted.",
    )
    p.add_argument(
        "script",
        help="Python file defining study = femast.studies.Study(...), or an installed module's name "
        "(femast.benchmarks.study_guyed)",
    )
    p.add_argument(
        "--samples",
        type=int,
        required=True,
        help="number of base samples N (with sensitivity, N x (k+2) runs; a power of 2 keeps Sobol' points balanced)",
    )
    p.add_argument("--workers", type=int, default=None, help="local worker processes (default: the number of cores)")
    p.add_argument(
        "--scheduler",
        default=None,
        help="address of a dask.distributed scheduler, e.g. tcp://host:8786 (default: local processes)",
    )
    p.add_argument("--out", default=None, help="results folder (default: studies/SCRIPTNAME)")
    p.add_argument(
        "--chunk-size", type=int, default=None, help="runs per stored chunk (default: about 20 chunks per worker)"
    )
    p.add_argument("--no-report", action="store_true", help="do not print the percentiles nor write the figures")
    p.set_defaults(func=_study)
