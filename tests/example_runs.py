"""The shipped examples' compare and diagnose, run once per test session for every test that reads them.

``femast compare NAME example`` and ``femast diagnose NAME example --workers 1`` of a shipped
example take seconds to tens of seconds; the tutorial's transcript, the user's-words checks, the
JSON schema and the HTML reports each read the same runs.  :func:`run_example` runs one through the
command line, as a user does, recording what it prints and the checks of every figure it draws
(:mod:`figure_geometry`); the session fixture ``example_run`` of tests/conftest.py keeps one run per
command and experiment.  The tests read its folder and text; none writes there."""

import contextlib
import io
import json
from pathlib import Path
from types import SimpleNamespace


def run_example(command: str, name: str, folder: Path) -> SimpleNamespace:
    """Run ``femast compare NAME example --out FOLDER`` or ``femast diagnose NAME example --out FOLDER
    --workers 1``; returns SimpleNamespace(out, stdout, stderr, report (compare.json or diagnose.json),
    drawn: [(png name, figure problems, the figure's texts)])."""
    import pytest
    from figure_geometry import figure_problems

    from femast.cli import main
    from femast.post import plotstyle

    drawn, save = [], plotstyle.save

    def checked_save(fig, png, dpi=None):
        out = save(fig, png, dpi)  # laid out and written as the user gets it
        texts = " | ".join(t.get_text() for t in fig.findobj(lambda a: hasattr(a, "get_text")) if t.get_text())
        drawn.append((out.name, figure_problems(fig), texts))
        return out

    out, err = io.StringIO(), io.StringIO()
    with pytest.MonkeyPatch.context() as mp, contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        mp.setattr(plotstyle, "save", checked_save)
        extra = ["--workers", "1"] if command == "diagnose" else []
        code = main([command, name, "example", "--out", str(folder), *extra])
    assert code == 0, f"femast {command} {name} example: exit {code}\n{out.getvalue()}\n{err.getvalue()}"
    report = json.loads((folder / f"{command}.json").read_text())
    return SimpleNamespace(out=folder, stdout=out.getvalue(), stderr=err.getvalue(), report=report, drawn=drawn)
