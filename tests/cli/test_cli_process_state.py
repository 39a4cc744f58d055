"""femast.cli.main called from Python (tests, notebooks) leaves the interpreter as it found it (the
garbage collector's settings untouched), and femast's warnings reach a command's user as one line
each."""

import gc
import os
import subprocess
import sys
from pathlib import Path

from femast.cli import main

ROOT = Path(__file__).resolve().parents[2]


def test_main_restores_the_collector(tmp_path, capsys):
    before = gc.get_threshold()
    assert gc.get_freeze_count() == 0
    assert main(["compare", "mast-top", "example", "--out", str(tmp_path / "o"), "--json"]) == 0
    capsys.readouterr()
    assert gc.get_threshold() == before
    assert gc.get_freeze_count() == 0


def test_a_partial_frame_is_one_warning_line_on_the_command_line(tmp_path, capsys):
    """`femast info` of a folder whose last frame was cut short (a kill, a full disk): the frames
    before it are listed, and the reader's warning is one `femast: warning:` line, not Python's
    file:line and source line."""
    import femast as fm
    from femast.post.npz import LOG_NAME

    m = fm.Model("cut")
    a, b = m.node(0, 0, 0), m.node(1, 0, 0)
    m.beam(a, b, fm.circular_tube(0.02, 0.016, E=70e9), n=2)
    m.fix(a)
    m.step("s", initial_increment=0.5, max_increment=0.5).load(b, fz=-10.0)
    fm.solve(m, tmp_path / "r", progress=False)
    with open(tmp_path / "r" / "frames" / LOG_NAME, "ab") as fh:
        fh.write(b"FEMASTFR\x00\x10\x00\x00\x00\x00\x00\x00PK")  # a record cut short
    # a fresh process: pytest records warnings instead of printing them
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")])}
    p = subprocess.run(
        [sys.executable, "-m", "femast.cli", "info", str(tmp_path / "r")],
        env=env,
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert p.returncode == 0 and "3 frames" in p.stdout  # the initial state and the two increments, before the cut
    lines = [l for l in p.stderr.splitlines() if "partial" in l]
    assert len(lines) == 1 and lines[0].startswith("femast: warning:") and "partial last frame" in lines[0]
    assert "cli.py" not in p.stderr
