"""Command line: ``femast run SCRIPT``, ``femast vtk RESULTS``, ``femast render RESULTS [PNG]``,
``femast info RESULTS``, ``femast warmup``; ``compare``, ``diagnose``, ``experiments``, ``effects``,
``examples`` (:mod:`femast.cli_experiments`); ``study`` (:mod:`femast.studies.cli`).  ``femast --help``
lists them, ``femast CMD --help`` explains each argument with its default.  ``femast --quiet CMD`` shows no progress bars."""

from __future__ import annotations

import argparse
import os
import runpy
import sys
from pathlib import Path

from .errors import FemastError


def _run(args):
    script = Path(args.script)
    if not script.exists():
        raise FemastError(f"no such script: {script}")
    script_args = list(args.script_args)
    restart = args.restart
    if "--restart" in script_args:  # femast run SCRIPT --restart FOLDER
        i = script_args.index("--restart")
        if i + 1 >= len(script_args):
            raise FemastError("--restart needs the results folder of the run to continue: --restart FOLDER")
        restart = script_args[i + 1]
        del script_args[i : i + 2]
    if restart is not None:
        # the analyses of the script whose results folder is RESTART continue from its restart point
        from .analysis.restart import ENV, require_point

        require_point(restart)  # (none there, or a link or FIFO in its place: named now, before the script runs)
        old = os.environ.get(ENV)
        os.environ[ENV] = str(restart)
    sys.argv = [str(script)] + script_args
    try:
        runpy.run_path(str(script), run_name="__main__")
    finally:
        if restart is not None:  # (main() may be called again in the same process)
            if old is None:
                os.environ.pop(ENV, None)
            else:
                os.environ[ENV] = old


def _vtk(args):
    from .post.vtk import export_vtk

    pvd = export_vtk(args.results, args.out, every=args.every)  # RESULTS/vtk, as export_vtk(res)
    print(f"wrote {pvd} (open it in ParaView; apply 'Warp By Vector' with U to see the deformed shape)")


def _frame_arg(text: str):
    """``--frame``: a frame number (negative counts from the end), ``last``, or ``max`` (largest
    displacement)."""
    t = text.strip().lower()
    if t in ("last", "max"):
        return t
    try:
        return int(t)
    except ValueError:
        raise argparse.ArgumentTypeError(f"--frame {text!r}: give a frame number, 'last' or 'max'") from None


def _render(args):
    from .post.render import largest_displacement_frame, render_png
    from .post.results import Results

    res = Results(args.results)
    if args.frame == "max":
        frame, umax = largest_displacement_frame(res)
        why = f"frame {frame} of {len(res)}, the largest displacement ({umax:.4g} m); --frame N|last for another"
    else:
        frame = len(res) - 1 if args.frame == "last" else args.frame
        if not -len(res) <= frame < len(res):
            raise FemastError(
                f"--frame {frame}: frame {frame} does not exist; {args.results} has {len(res)} frames "
                f"(0 to {len(res) - 1}); give a frame in that range, 'last' or 'max'"
            )
        frame = range(len(res))[frame]
        why = f"frame {frame} of {len(res)}"
    name = f"{Path(args.results).resolve().name}_frame{frame}.png"
    png = Path(args.png) if args.png else Path(args.out) / name
    png = render_png(res, png, frame=frame, scale=args.scale)
    print(f"wrote {png} ({why}; displacements x {args.scale:g})")


def _warmup(args):
    from .warmup import warmup

    print("compiling (or loading from numba's cache) every femast kernel:")
    t = warmup()
    print(f"done in {t:.1f} s; later runs load the kernels from the cache")


def _info(args):
    from .post.results import Results

    res = Results(args.results)
    print(f"{res.folder}: {len(res)} frames, {len(res.node_labels)} nodes, families: {', '.join(res.families)}")
    if res.summary:
        s = res.summary
        print(
            f"  status: {res.status}; increments {s.get('increments', 0)}, iterations {s.get('iterations', 0)}, "
            f"cutbacks {s.get('cutbacks', 0)}, wall time {s.get('wall_time', 0.0):.2f} s"
        )
        for st in s.get("steps", []):
            if "frequencies_hz" in st:
                print(f"  step {st['name']}: modes at {', '.join(f'{f:.4g}' for f in st['frequencies_hz'])} Hz")
                continue
            n, k = st.get("increments", 0), st.get("iterations", 0)
            print(f"  step {st['name']}: {n} increment{'' if n == 1 else 's'}, {k} iteration{'' if k == 1 else 's'}")
        if s.get("message"):
            print(f"  {s['message']}")
    else:
        print("  status: unknown (no readable summary.json)")


class _Intermixed(argparse.ArgumentParser):
    """A command's parser that takes its options anywhere among its positional arguments
    (``femast render RES --frame last shape.png`` as well as ``femast render RES shape.png --frame
    last``): argparse's ``parse_known_intermixed_args``.  A command taking a script's arguments
    verbatim (``run``) parses as usual."""

    _inside = False

    def parse_known_args(self, args=None, namespace=None):
        if self._inside or any(a.nargs in (argparse.REMAINDER, argparse.PARSER) for a in self._actions):
            return super().parse_known_args(args, namespace)
        self._inside = True  # (Python < 3.12 calls parse_known_args from the intermixed parse)
        try:
            return self.parse_known_intermixed_args(args, namespace)
        finally:
            self._inside = False


class _Help(argparse.ArgumentDefaultsHelpFormatter, argparse.RawDescriptionHelpFormatter):
    """Help text with each option's default (argparse's own, unless the help already says it)."""

    def _get_help_string(self, action):
        h = action.help or ""
        if "default" in h or action.default in (None, False, argparse.SUPPRESS) or not action.option_strings:
            return h
        return h + " (default: %(default)s)"


def build_parser() -> argparse.ArgumentParser:
    """femast's argument parser (every command; the lists in the help come from the registries)."""
    parser = argparse.ArgumentParser(
        prog="femast",
        description="Nonlinear FE for jointed deployable masts. `femast COMMAND --help` explains a command.",
        formatter_class=_Help,
    )
    parser.add_argument(
        "--quiet",
        action="store_true",
        help="no progress bars or first-run notices (they never show when stderr is not a terminal)",
    )
    parser.add_argument(
        "--debug",
        action="store_true",
        help="show the full Python traceback of an error (default: one line naming the item)",
    )
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND", parser_class=_Intermixed)
    p = sub.add_parser(
        "run",
        help="run a model or benchmark script",
        formatter_class=_Help,
        description="Run a Python script (a model, a benchmark) as `python SCRIPT ARGS` would.",
    )
    p.add_argument(
        "--restart",
        metavar="FOLDER",
        default=None,
        help="continue the run whose results folder is FOLDER from its last restart point "
        "(also accepted after SCRIPT; default: start afresh)",
    )
    p.add_argument("script", help="path of the Python script to run")
    p.add_argument("script_args", nargs=argparse.REMAINDER, help="arguments passed on to the script (default: none)")
    p.set_defaults(func=_run)
    p = sub.add_parser(
        "vtk",
        help="export a results folder to .vtu files and a .pvd series",
        formatter_class=_Help,
        description="Write one .vtu file per frame and a .pvd series for ParaView (open the .pvd, "
        "apply 'Warp By Vector' with U).",
    )
    p.add_argument("results", help="results folder written by an analysis (fm.solve(model, FOLDER))")
    p.add_argument(
        "--out",
        default=None,
        help="folder of the .vtu files and series.pvd (default: RESULTS/vtk, where export_vtk(results) writes them)",
    )
    p.add_argument("--every", type=int, default=1, help="write every n-th frame")
    p.set_defaults(func=_vtk)
    p = sub.add_parser(
        "render",
        help="render the deformed shape to PNG off-screen",
        formatter_class=_Help,
        description="Render one frame's deformed shape (coloured by |U|, over the undeformed "
        "shape) to a PNG, without a display.  By default the frame of largest "
        "displacement; the output says which frame it drew.",
    )
    p.add_argument("results", help="results folder written by an analysis")
    p.add_argument("png", nargs="?", default=None, help="PNG file to write (default: OUT/RESULTSNAME_frameN.png)")
    p.add_argument(
        "--out",
        default="render",
        help="folder of the PNG when no PNG is named (default: render, in the working directory)",
    )
    p.add_argument(
        "--frame",
        type=_frame_arg,
        default="max",
        help="frame number (negative from the end), 'last', or 'max' for the largest displacement",
    )
    p.add_argument("--scale", type=float, default=1.0, help="displacement magnification")
    p.set_defaults(func=_render)
    p = sub.add_parser(
        "info",
        help="summarise a results folder",
        formatter_class=_Help,
        description="Frames, nodes, element families and the run summary of a results folder.",
    )
    p.add_argument("results", help="results folder written by an analysis")
    p.set_defaults(func=_info)
    p = sub.add_parser(
        "warmup",
        help="compile every femast kernel now (for CI images and cluster workers)",
        formatter_class=_Help,
        description="Compile femast's numba kernels into numba's on-disk cache by running small "
        "models of every element family, so that the first real run does not wait "
        "for the compiler.  Quick when the cache is already written.",
    )
    p.set_defaults(func=_warmup)
    try:
        from .cli_experiments import register  # compare / diagnose, when present
    except ImportError:
        register = None
    if register is not None:
        register(sub, _Help)
    from .studies.cli import register as register_study  # femast study

    register_study(sub, _Help)
    for name, sp in sub.choices.items():  # --quiet also after the command (SUPPRESS: keeps the main one's value)
        if name != "run":
            sp.add_argument(
                "--quiet", action="store_true", default=argparse.SUPPRESS, help="no progress bars or first-run notices"
            )
    return parser


def main(argv=None):
    import warnings

    from . import progress

    format_warning, quiet = warnings.formatwarning, progress._QUIET
    warnings.formatwarning = _one_line_warnings(format_warning)
    try:
        return _main(argv)
    finally:  # main() called from Python (tests, notebooks): the caller's settings come back
        warnings.formatwarning = format_warning
        progress.set_quiet(quiet)


def _one_line_warnings(python_format):
    """A ``warnings.formatwarning`` that shows femast's own warnings (a partial frame in a results
    folder, a data file's oddity, a large stabilisation energy) as one line for a command's user,
    ``femast: warning: ...``, without the source line that raised it; others as ``python_format``."""

    def format_warning(message, category, filename, lineno, line=None):
        if category.__module__.startswith("femast"):
            return f"femast: warning: {message}\n"
        return python_format(message, category, filename, lineno, line)

    return format_warning


def _main(argv):
    parser = build_parser()
    argv = list(sys.argv[1:] if argv is None else argv)
    # --debug anywhere before a script's own arguments (``femast vtk R --debug``, ``femast --debug run S``)
    cut = argv.index("run") + 2 if "run" in argv else len(argv)
    debug = "--debug" in argv[:cut]
    argv = [a for a in argv[:cut] if a != "--debug"] + argv[cut:]
    args = parser.parse_args(argv)
    from . import progress

    progress.set_quiet(args.quiet)
    return _guarded(args.func, args, debug=debug or args.debug)


def _guarded(func, args, debug=False) -> int:
    """Run a command: every error becomes one line on stderr and exit code 2 (``--debug``: the
    traceback); a command returning an int exits with it; a closed output pipe (``femast info R | head -1``) ends the command silently."""
    from . import progress

    try:
        code = func(args)
    except BrokenPipeError:
        _silence_stdout()
        return 1
    except KeyboardInterrupt:
        progress.close_all()
        if debug:
            raise
        print("femast: interrupted", file=sys.stderr)
        return 130
    except SystemExit:
        raise
    except Exception as exc:
        progress.close_all()  # a bar left on the line would run into the message
        if debug:
            raise
        try:
            print(f"femast: error: {error_line(exc, getattr(args, 'script', None))}", file=sys.stderr)
        except BrokenPipeError:
            pass
        return 2
    try:
        sys.stdout.flush()
    except BrokenPipeError:
        _silence_stdout()
        return 1
    return code if isinstance(code, int) else 0  # a command may return its own exit code (femast study: 3)


def _silence_stdout():
    """After a broken pipe: point stdout at /dev/null so that Python's exit flush stays silent."""
    import os

    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
    except (OSError, ValueError):
        pass


def error_line(exc: BaseException, script=None) -> str:
    """One line for an error: a femast error's own message; an OS error's file and reason; any
    other error with where it happened (the line of ``script`` if it is there) and the hint to rerun
    with --debug."""
    if isinstance(exc, FemastError):
        return str(exc).replace("\n", " ")
    if isinstance(exc, OSError) and exc.filename is not None:
        return f"{exc.filename}: {exc.strerror or exc}; check the path and its permissions"
    where = ""
    tb = exc.__traceback__
    frames = []
    while tb is not None:
        frames.append((tb.tb_frame.f_code.co_filename, tb.tb_lineno))
        tb = tb.tb_next
    if script is not None:
        mine = [f for f in frames if Path(f[0]).resolve() == Path(script).resolve()]
        if mine:
            where = f"{script} line {mine[-1][1]}: "
    msg = str(exc).splitlines()[0] if str(exc) else ""
    return (
        f"{where}{type(exc).__name__}{': ' + msg if msg else ''} (not a femast error: rerun with "
        "--debug for the traceback, and report it if the input looks right)"
    )


if __name__ == "__main__":
    sys.exit(main())
