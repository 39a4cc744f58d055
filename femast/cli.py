"""Command line: ``femast run SCRIPT``, ``femast vtk RESULTS``, ``femast render RESULTS PNG``,
``femast info RESULTS``.  ``femast --help`` lists them."""

from __future__ import annotations

import argparse
import runpy
import sys
from pathlib import Path

from .errors import FemastError


def _run(args):
    script = Path(args.script)
    if not script.exists():
        raise FemastError(f"no such script: {script}")
    sys.argv = [str(script)] + list(args.script_args)
    runpy.run_path(str(script), run_name="__main__")


def _vtk(args):
    from .vtk import export_vtk

    pvd = export_vtk(args.results, args.out, every=args.every)
    print(f"wrote {pvd} (open it in ParaView; apply 'Warp By Vector' with U to see the deformed shape)")


def _render(args):
    from .render import render_png

    png = render_png(args.results, args.png, frame=args.frame, scale=args.scale)
    print(f"wrote {png}")


def _info(args):
    from .results import Results

    res = Results(args.results)
    print(f"{res.folder}: {len(res)} frames, {len(res.node_labels)} nodes, families: {', '.join(res.families)}")
    if res.summary:
        s = res.summary
        print(f"  status: {res.status}; increments {s.get('increments', 0)}, iterations {s.get('iterations', 0)}, "
              f"cutbacks {s.get('cutbacks', 0)}, wall time {s.get('wall_time', 0.0):.2f} s")
        for st in s.get("steps", []):
            print(f"  step {st['name']}: {st['increments']} increments, {st['iterations']} iterations")
        if s.get("message"):
            print(f"  {s['message']}")


def main(argv=None):
    parser = argparse.ArgumentParser(prog="femast", description="Nonlinear FE for jointed deployable masts")
    sub = parser.add_subparsers(dest="command", required=True)
    p = sub.add_parser("run", help="run a model or benchmark script")
    p.add_argument("script")
    p.add_argument("script_args", nargs=argparse.REMAINDER)
    p.set_defaults(func=_run)
    p = sub.add_parser("vtk", help="export a results folder to .vtu files and a .pvd series")
    p.add_argument("results")
    p.add_argument("--out", default=None, help="output folder (default RESULTS/vtk)")
    p.add_argument("--every", type=int, default=1, help="write every n-th frame")
    p.set_defaults(func=_vtk)
    p = sub.add_parser("render", help="render the deformed shape to PNG off-screen")
    p.add_argument("results")
    p.add_argument("png")
    p.add_argument("--frame", type=int, default=-1)
    p.add_argument("--scale", type=float, default=1.0, help="displacement magnification")
    p.set_defaults(func=_render)
    p = sub.add_parser("info", help="summarise a results folder")
    p.add_argument("results")
    p.set_defaults(func=_info)
    try:
        from .cli_experiments import register  # compare / diagnose (issue 7), when present
    except ImportError:
        register = None
    if register is not None:
        register(sub)
    args = parser.parse_args(argv)
    try:
        args.func(args)
    except FemastError as exc:
        print(f"femast: error: {exc}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
