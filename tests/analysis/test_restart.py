"""Restart (Abaqus *RESTART).  A run stopped or killed at any moment and
continued from its last restart point writes the uninterrupted run's frames, bit for bit."""

import os
import random
import signal
import subprocess
import sys
import textwrap
import time

import numpy as np
import pytest

import femast as fm
from femast.post.npz import LOG_NAME, scan_log
from femast.post.results import Results

MODEL = textwrap.dedent("""
    import femast as fm

    def build():
        m = fm.Model("restart")
        a, b = m.node(0, 0, 0), m.node(1.0, 0, 0)
        m.beam(a, b, fm.circular_tube(0.02, 0.016, E=70e9), up=(0, 0, 1), n=8)
        m.fix(a)
        # large deflection (nonlinear: several Newton iterations per increment), then partly back
        m.step("bend", initial_increment=0.05, max_increment=0.05).load(b, fz=-400.0, my=30.0)
        m.step("back", initial_increment=0.1, max_increment=0.1).load(b, fz=-100.0, my=0.0, fy=50.0)
        return m, b
""")
_ns = {}
exec(MODEL, _ns)
build = _ns["build"]


def _frames_equal(a: Results, b: Results):
    assert len(a) == len(b)
    for i in range(len(a)):
        fa, fb = a.frame(i), b.frame(i)
        assert set(fa) == set(fb), i
        for k in fa:
            x, y = np.asarray(fa[k]), np.asarray(fb[k])
            assert x.dtype == y.dtype and x.shape == y.shape, (i, k)
            assert x.tobytes() == y.tobytes(), f"frame {i}, {k} differs"  # bit for bit


@pytest.fixture(scope="module")
def reference(tmp_path_factory):
    out = tmp_path_factory.mktemp("restart") / "ref"
    m, _ = build()
    return fm.solve(m, out, progress=False)


def test_stopped_run_restarted_equals_the_uninterrupted_one(reference, tmp_path):
    out = tmp_path / "run"
    m, _ = build()

    def stop(frame):  # Ctrl-C in the second step, between restart points (every 3 increments)
        if frame["step"] == "back" and frame["increment"] == 5:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        fm.Analysis(m, out, progress=False, restart_every=3, on_frame=stop).run()
    assert Results(out).status == "interrupted" and len(Results(out)) < len(reference)
    m2, _ = build()
    res = fm.Analysis(m2, out, progress=False, restart=out).run()
    assert res.status == "completed"
    _frames_equal(reference, res)


def test_restart_errors_name_the_folder(tmp_path):
    m, _ = build()
    with pytest.raises(fm.FemastError, match=r"no restart point .*restart_every"):
        fm.Analysis(m, tmp_path / "none", progress=False, restart=tmp_path / "none").run()
    out = tmp_path / "r"
    fm.solve(build()[0], out, progress=False, restart_every=5)
    other = fm.Model("other")
    a, b = other.node(0, 0, 0), other.node(1, 0, 0)
    other.beam(a, b, fm.circular_tube(0.02, 0.016, E=70e9))
    other.fix(a)
    other.step("s").load(b, fz=-1.0)
    with pytest.raises(fm.FemastError, match=r"belongs to another model"):
        fm.Analysis(other, out, progress=False, restart=out).run()
    with pytest.raises(fm.ModelError, match=r"restart_every = 0"):
        fm.Analysis(build()[0], tmp_path / "x", progress=False, restart_every=0)


def _frames_on_disk(frames):
    """Whole frames in a results folder's frame log (0 before it exists)."""
    log = frames / LOG_NAME
    return len(scan_log(log)[0]) if log.exists() else 0


def _env():
    return {**os.environ, "PYTHONPATH": os.pathsep.join([os.getcwd(), os.environ.get("PYTHONPATH", "")])}


@pytest.mark.slow
def test_kill_9_at_random_moments_then_restart(reference, tmp_path):
    """kill -9 at random moments (several kills of one run, restarts killed too), then
    ``femast run SCRIPT --restart FOLDER`` to the end: the uninterrupted run's frames, bit for bit."""
    rng = random.Random(16)
    kills = restarts = 0
    for trial in range(4):
        out = tmp_path / f"k{trial}"
        script = tmp_path / f"run{trial}.py"
        script.write_text(
            MODEL
            + textwrap.dedent(f"""
            import sys
            m, _ = build()
            fm.Analysis(m, {str(out)!r}, progress=False, restart_every=1).run()
        """)
        )
        cmd = [sys.executable, str(script)]
        for _attempt in range(3):
            frames = out / "frames"
            have = _frames_on_disk(frames)
            p = subprocess.Popen(cmd, env=_env())
            # kill at a random moment of the run: once a random number of new frames is on disk (the
            # start-up, imports and numba's cache, takes seconds on a busy machine), plus a random delay
            target = min(have + rng.randint(1, 10), len(reference) - 1)
            deadline = time.time() + 300
            while p.poll() is None and time.time() < deadline and _frames_on_disk(frames) < target:
                time.sleep(0.01)
            time.sleep(rng.uniform(0.0, 0.05))
            if p.poll() is None:
                p.send_signal(signal.SIGKILL)
                kills += 1
            p.wait()
            cmd = [sys.executable, "-m", "femast.cli", "run", str(script), "--restart", str(out)]
            if (out / "restart" / "restart.json").exists():
                restarts += 1
                continue
            cmd = [sys.executable, str(script)]  # killed before the first restart point: start over
        p = subprocess.run(cmd, env=_env(), capture_output=True, text=True, timeout=600)
        assert p.returncode == 0, p.stderr
        res = Results(out)
        assert res.status == "completed"
        _frames_equal(reference, res)
    assert kills >= 3 and restarts >= 3, (kills, restarts)  # the test did kill and restart runs


def test_cli_run_restart(reference, tmp_path, capsys):
    """``femast run SCRIPT --restart FOLDER``: the script's analysis into FOLDER continues."""
    from femast.cli import main

    out = tmp_path / "cli"
    script = tmp_path / "job.py"
    script.write_text(
        MODEL
        + textwrap.dedent(f"""
        import sys
        m, _ = build()
        def stop(frame):
            if "--stop" in sys.argv and frame["step"] == "bend" and frame["increment"] == 9:
                raise KeyboardInterrupt
        fm.Analysis(m, {str(out)!r}, progress=False, restart_every=2, on_frame=stop).run()
    """)
    )
    assert main(["run", str(script), "--stop"]) == 130  # Ctrl-C: "femast: interrupted"
    assert "interrupted" in capsys.readouterr().err
    assert main(["run", str(script), "--restart", str(out)]) == 0
    assert os.environ.get("FEMAST_RESTART") is None
    _frames_equal(reference, Results(out))
    assert main(["run", str(script), "--restart", str(tmp_path / "nowhere")]) == 2
    assert "no restart point" in capsys.readouterr().err


@pytest.mark.skipif(not os.path.isdir("/proc/self/fd"), reason="names fsync'd files through /proc")
def test_a_restart_point_makes_the_frames_it_names_durable_first(tmp_path, monkeypatch):
    """Frames are not fsync'd one by one (a process kill loses nothing written; docs/results.md),
    but a restart point is meant to survive a power cut too: the frame log is fsync'd before each
    restart.json that names its frames, and no fsync happens between restart points."""
    synced = []
    real = os.fsync

    def fsync(fd):
        synced.append(os.path.basename(os.readlink(f"/proc/self/fd/{fd}")))
        real(fd)

    monkeypatch.setattr(os, "fsync", fsync)
    m, _ = build()
    fm.Analysis(m, tmp_path / "run", progress=False, restart_every=5).run()
    points = [i for i, name in enumerate(synced) if name.startswith("restart.json")]
    assert len(points) >= 4  # the start (names no frame), every 5 increments of 20 + 10, the steps' ends
    assert LOG_NAME not in synced[: points[0]]
    for i in points[1:]:
        assert LOG_NAME in synced[:i][-3:], synced  # the log, just before (with the point's own files)
    assert synced.count(LOG_NAME) == len(points) - 1  # and only then
