"""Results folders that never lie (atomic files, partial files ignored with a
warning, a summary that says "completed" only after the last increment), and a kill-and-read test."""

import json
import os
import signal
import struct
import subprocess
import sys
import textwrap
import time
import warnings

import numpy as np
import pytest

import femast as fm
from femast.post.npz import LOG_NAME, RECORD_MAGIC, read_log, scan_log
from femast.post.results import Results, ResultsWarning


def _cantilever(n_inc=4, load=-50.0):
    m = fm.Model("truth")
    a, b = m.node(0, 0, 0), m.node(1, 0, 0)
    m.beam(a, b, fm.circular_tube(0.02, 0.016, E=70e9), n=4)
    m.fix(a)
    m.step("load", initial_increment=1.0 / n_inc, max_increment=1.0 / n_inc).load(b, fz=load)
    return m, b


def _frames_on_disk(out):
    log = out / "frames" / LOG_NAME
    return len(scan_log(log)[0]) if log.exists() else 0


def _summary(folder):
    return json.loads((folder / "summary.json").read_text())


def test_completed_run_says_completed(tmp_path):
    m, b = _cantilever()
    res = fm.solve(m, tmp_path / "r", progress=False)
    s = _summary(tmp_path / "r")
    assert s["status"] == "completed" and s["completed"] is True and res.status == "completed"
    assert not list((tmp_path / "r" / "frames").glob("*.tmp"))
    assert len(res) == 5 and len(list(read_log(tmp_path / "r" / "frames" / LOG_NAME))) == 5


def test_summary_is_running_during_the_run_and_replaces_a_stale_one(tmp_path):
    out = tmp_path / "r"
    m, _ = _cantilever()
    fm.solve(m, out, progress=False)
    assert _summary(out)["status"] == "completed"
    seen = []
    m2, _ = _cantilever()
    fm.solve(m2, out, progress=False, on_frame=lambda d: seen.append(_summary(out)["status"]))
    assert seen and set(seen) == {"running"}  # the earlier run's "completed" is gone from the start
    assert _summary(out)["status"] == "completed"


def test_ctrl_c_is_interrupted(tmp_path, capsys):
    m, _ = _cantilever()

    def stop(d):
        if d["increment"] == 2:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        fm.solve(m, tmp_path / "r", progress=True, on_frame=stop)
    s = _summary(tmp_path / "r")
    assert s["status"] == "interrupted" and s["completed"] is False
    assert "analysis completed" not in capsys.readouterr().out
    assert Results(tmp_path / "r").status == "interrupted"


def test_singular_first_increment_is_failed_with_reason(tmp_path, capsys):
    m = fm.Model()
    a, b = m.node(0, 0, 0), m.node(1, 0, 0)
    m.beam(a, b, fm.circular_tube(0.02, 0.016, E=70e9), n=2)
    m.fix(a, "ux", "uy", "uz", "ry", "rz")  # torsion left free: a mechanism
    m.step("s").load(b, fy=1.0)
    with pytest.raises(fm.SingularModelError):
        fm.solve(m, tmp_path / "r", progress=True)
    s = _summary(tmp_path / "r")
    assert s["status"] == "failed" and "SingularModelError" in s["message"] and "rx" in s["message"]
    out = capsys.readouterr().out
    assert "analysis completed" not in out and "FAILED" in out


def test_raw_exception_is_failed(tmp_path):
    m, _ = _cantilever()

    def boom(d):
        if d["increment"] == 1:
            raise RuntimeError("user callback broke")

    with pytest.raises(RuntimeError):
        fm.solve(m, tmp_path / "r", progress=False, on_frame=boom)
    s = _summary(tmp_path / "r")
    assert s["status"] == "failed" and "user callback broke" in s["message"]


def test_partial_and_corrupt_frames(tmp_path):
    """The frame log (frames/frames.npzs): a record cut short by a kill is ignored with a warning,
    a damaged record is an error naming the frame."""
    m, b = _cantilever()
    res = fm.solve(m, tmp_path / "r", progress=False)
    log = tmp_path / "r" / "frames" / LOG_NAME
    last = res.frame(-1)["U"].copy()
    whole = log.read_bytes()
    with open(log, "ab") as fh:  # a sixth frame, killed half-way through its write
        fh.write(RECORD_MAGIC + struct.pack("<Q", 4000) + b"PK\x03\x04 half a zip")
    with pytest.warns(ResultsWarning, match=r"frames\.npzs \(a partial last frame"):
        r2 = Results(tmp_path / "r")
    assert len(r2) == 5 and np.array_equal(r2.frame(-1)["U"], last)
    assert r2.node_history(b, "uz").shape == (5,)
    # frame 3's .npz starts 16 bytes after the end of frame 2's record: overwrite its zip signature
    offsets = []
    pos = 0
    while pos < len(whole):
        n = struct.unpack("<Q", whole[pos + 8 : pos + 16])[0]
        offsets.append(pos + 16)
        pos += 16 + n
    damaged = bytearray(whole)
    damaged[offsets[3] : offsets[3] + 4] = b"XXXX"
    log.write_bytes(bytes(damaged))
    r3 = Results(tmp_path / "r")
    with pytest.raises(fm.FemastError, match=r"frames\.npzs: frame 3 is unreadable"):
        r3.frame(3)
    with pytest.raises(fm.FemastError, match=r"frame 99 does not exist; the folder has 5 frames"):
        r2.frame(99)


def test_folder_of_one_file_per_frame_still_reads(tmp_path):
    """Folders written before the frame log (frames/000001.npz, ...): read as before, partial
    files ignored with a warning naming them, a damaged file an error naming it."""
    m, b = _cantilever()
    res = fm.solve(m, tmp_path / "r", progress=False)
    frames = tmp_path / "r" / "frames"
    last = res.frame(-1)["U"].copy()
    for k, fr in enumerate(read_log(frames / LOG_NAME)):
        np.savez(frames / f"{k + 1:06d}.npz", **fr)
    (frames / LOG_NAME).unlink()
    (frames / "000006.npz.tmp").write_bytes(b"PK\x03\x04 half a zip")
    (frames / "000007.tmp.npz").write_bytes(b"PK\x03\x04 half a zip (older femast's name)")
    with pytest.warns(ResultsWarning, match=r"000006\.npz\.tmp"):
        r2 = Results(tmp_path / "r")
    assert len(r2) == 5 and np.array_equal(r2.frame(-1)["U"], last)
    assert r2.node_history(b, "uz").shape == (5,)
    (frames / "000004.npz").write_bytes(b"not a zip at all")  # frame 3 (frame 0 is 000001)
    with pytest.warns(ResultsWarning):
        r3 = Results(tmp_path / "r")
    with pytest.raises(fm.FemastError, match=r"000004\.npz: frame 3 is unreadable"):
        r3.frame(3)


def test_out_is_an_existing_file(tmp_path):
    m, _ = _cantilever()
    f = tmp_path / "file.txt"
    f.write_text("x")
    with pytest.raises(fm.FemastError, match=r"file\.txt' is an existing file"):
        fm.solve(m, f, progress=False)


# the child scripts' model: a cantilever loaded in 10 000 tiny increments, so that a run is still
# going when the test kills it ({n}: beam elements)
_SLOW_CANTILEVER = """
    m = fm.Model("kill")
    a = m.node(0, 0, 0)
    b = m.node(1, 0, 0)
    m.beam(a, b, fm.circular_tube(0.02, 0.016, E=70e9), n={n})
    m.fix(a)
    m.step("s", initial_increment=1e-4, max_increment=1e-4, max_increments=100000).load(b, fz=-50.0)
"""

_KILL_SCRIPT = textwrap.dedent(
    """
    import sys, femast as fm
"""
    + _SLOW_CANTILEVER.format(n=20)
    + """
    fm.solve(m, sys.argv[1], progress=False)
"""
)


def test_kill_9_and_read(tmp_path):
    """A run killed outright: every frame on disk reads, the summary says "running" but the
    reader reports "interrupted" (its process is gone), and no partial file is taken for a frame."""
    out = tmp_path / "r"
    script = tmp_path / "run.py"
    script.write_text(_KILL_SCRIPT)
    # a stale "completed" summary from an earlier run must not survive the kill
    out.mkdir()
    (out / "summary.json").write_text(json.dumps({"status": "completed", "completed": True}))
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([os.getcwd(), os.environ.get("PYTHONPATH", "")])}
    p = subprocess.Popen([sys.executable, str(script), str(out)], env=env)
    try:
        deadline = time.time() + 120
        while time.time() < deadline and _frames_on_disk(out) < 15:
            time.sleep(0.05)
        assert p.poll() is None, "the run ended before it could be killed"
    finally:
        p.send_signal(signal.SIGKILL)
        p.wait()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ResultsWarning)  # a *.tmp may or may not be left
        res = Results(out)
    assert len(res) >= 15
    assert _summary(out)["status"] == "running" and res.status == "interrupted"
    U = np.array([res.frame(i)["U"] for i in range(len(res))])  # every frame reads
    assert np.all(np.isfinite(U))
    inc = res.scalar_history("increment")
    assert np.array_equal(inc, np.arange(len(res)))  # consecutive: nothing lost before the last


_REPORT_SCRIPT = textwrap.dedent(
    """
    import sys, time, femast as fm
    import femast.post.writer as results
    from femast.analysis.output import Observer

    write = results.append_record
    def slow_disk(fd, record):   # a disk slower than the analysis: writes must not fall behind
        time.sleep(0.002)
        write(fd, record)
    results.append_record = slow_disk

    class Report(Observer):   # told after the results writer: the run's word that an increment converged
        def converged(self, an, step, increment, *args):
            sys.stdout.write(f"{increment} {float(an.x[-1, 2] - an.X0[-1, 2]).hex()}\\n")
            sys.stdout.flush()

"""
    + _SLOW_CANTILEVER.format(n=4)
    + """
    fm.Analysis(m, sys.argv[1], progress=False, observers=[Report()]).run()
"""
)


@pytest.mark.parametrize("reports, delay_s", [(3, 0.0), (40, 0.0137)])
def test_kill_9_loses_no_increment_the_run_reported_converged(tmp_path, reports, delay_s):
    """The durability rule: a frame is the operating system's before anyone hears that its increment
    converged (no fsync: a process kill, unlike a power cut, loses nothing written).  A child run
    on a slow disk (2 ms per write) reports each converged increment (number and tip deflection) on
    a pipe; it is killed with SIGKILL at an arbitrary moment; every increment it reported is then in
    the frame log with the reported deflection, bit for bit, and so is every increment named in
    status.sta.  (femast before session 8 queued frames to a writer thread and fails this.)"""
    out = tmp_path / "r"
    script = tmp_path / "run.py"
    script.write_text(_REPORT_SCRIPT)
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([os.getcwd(), os.environ.get("PYTHONPATH", "")])}
    p = subprocess.Popen([sys.executable, str(script), str(out)], env=env, stdout=subprocess.PIPE)
    lines = []
    try:
        while len(lines) < reports:
            line = p.stdout.readline()
            assert line, "the run ended before it could be killed"
            lines.append(line)
        time.sleep(delay_s)  # (the kill lands anywhere in an increment, not just after a report)
    finally:
        p.send_signal(signal.SIGKILL)
        p.wait()
    lines += p.stdout.read().splitlines(keepends=True)  # what it reported before it died
    p.stdout.close()
    reported = [line.split() for line in lines if line.endswith(b"\n")]
    assert len(reported) >= reports
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ResultsWarning)  # a record cut short by the kill may be left
        res = Results(out)
    assert len(res) >= len(reported) + 1  # the initial frame and every reported increment
    for inc, uz in reported:
        fr = res.frame(int(inc))
        assert int(fr["increment"]) == int(inc)
        assert fr["U"][-1, 2] == float.fromhex(uz.decode())  # the converged state, not a later one
    sta = [line.split() for line in (out / "status.sta").read_text().splitlines()[1:]]
    named = [int(row[1]) for row in sta if len(row) >= 8]
    assert named and max(named) <= len(res) - 1  # a status line never runs ahead of its frame


def test_the_frame_log_reads_where_it_cannot_be_memory_mapped(tmp_path, monkeypatch):
    """scan_log maps the log to read its record headers; on a file system that cannot map files
    (some network and FUSE mounts) it reads them one by one: the same records, the torn tail too."""
    import mmap

    from femast.post import npz

    log = tmp_path / "frames.npzs"
    frames = [{"U": np.full((2, 3), float(k)), "step": "s"} for k in range(3)]
    with open(log, "wb") as fh:
        for fr in frames:
            fh.write(npz.record_bytes(fr))
        fh.write(npz.record_bytes(frames[0])[:40])  # a record cut short
    mapped = npz.scan_log(log)

    def no_mmap(*args, **kw):
        raise OSError(19, "No such device")  # what mmap gives on a file system without it

    monkeypatch.setattr(mmap, "mmap", no_mmap)
    read = npz.scan_log(log)
    assert read == mapped and len(read[0]) == 3 and read[1] == 40
    got = list(npz.read_log(log))
    assert [float(g["U"][0, 0]) for g in got] == [0.0, 1.0, 2.0]
