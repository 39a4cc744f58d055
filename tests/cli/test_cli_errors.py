"""No raw tracebacks from the CLI.  Every error is one line on stderr naming the
item, exit code 2; a closed output pipe is silent; --debug shows the traceback."""

import os
import subprocess
import sys
import textwrap

import pytest

import femast as fm
from femast.cli import main


@pytest.fixture(scope="module")
def results(tmp_path_factory):
    folder = tmp_path_factory.mktemp("cli") / "r"
    m = fm.Model()
    a, b = m.node(0, 0, 0), m.node(1, 0, 0)
    m.beam(a, b, fm.circular_tube(0.02, 0.016, E=70e9), n=2)
    m.fix(a)
    m.step("s", initial_increment=0.5).load(b, fz=-1.0)
    fm.solve(m, folder, progress=False)
    return folder


def _one_line_error(capsys, argv, *needles):
    assert main(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("femast: error: "), err
    for n in needles:
        assert n in err[0], err[0]
    return err[0]


def test_render_missing_frame(results, capsys, tmp_path):
    _one_line_error(
        capsys,
        ["render", str(results), str(tmp_path / "x.png"), "--frame", "99"],
        "frame 99 does not exist",
        "3 frames",
    )


def test_vtk_every_zero(results, capsys):
    _one_line_error(capsys, ["vtk", str(results), "--every", "0"], "every = 0", "whole number >= 1")


def test_info_of_a_non_folder(capsys, tmp_path):
    _one_line_error(capsys, ["info", str(tmp_path / "nothing")], "nothing", "not a femast results folder")


def test_script_with_a_bad_model(capsys, tmp_path):
    script = tmp_path / "model.py"
    script.write_text("import femast as fm\nfm.circular_tube(0.02, 0.016, E=70e9, nu=-1.0)\n")
    _one_line_error(capsys, ["run", str(script)], "Poisson's ratio nu = -1")


def test_script_with_a_raw_error_names_its_line(capsys, tmp_path):
    script = tmp_path / "oops.py"
    script.write_text("x = 1\ny = {}\nz = y['missing']\n")
    _one_line_error(capsys, ["run", str(script)], "oops.py line 3", "KeyError", "--debug")


def test_debug_shows_the_traceback(results):
    with pytest.raises(fm.FemastError, match="every = 0"):
        main(["--debug", "vtk", str(results), "--every", "0"])
    with pytest.raises(fm.FemastError, match="every = 0"):
        main(["vtk", str(results), "--every", "0", "--debug"])


def test_broken_pipe_is_silent(results):
    """``femast info R | head -0``: the reader has gone before femast writes."""
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([os.getcwd(), os.environ.get("PYTHONPATH", "")])}
    code = textwrap.dedent(f"""
        import sys
        from femast.cli import main
        r, w = __import__("os").pipe()
        __import__("os").close(r)                       # nobody reads: every write is a broken pipe
        __import__("os").dup2(w, sys.stdout.fileno())
        sys.exit(main(["info", {str(results)!r}]))
    """)
    p = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, timeout=120)
    assert p.stderr == "", p.stderr
    assert p.returncode == 1
