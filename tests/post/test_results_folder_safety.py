"""A results folder that defends itself: nothing written or deleted through a symbolic link, one
writer at a time, FIFOs never read, a full disk named with a "failed" summary, damaged summaries
named instead of a raw error."""

import json
import os
import subprocess
import sys
import textwrap
import time
import warnings

import pytest

import femast as fm
from femast.cli import main
from femast.errors import ResultsWriteError
from femast.post.results import Results, ResultsWarning


def _cantilever(n_inc=4, n_el=4):
    m = fm.Model("folder")
    a, b = m.node(0, 0, 0), m.node(1, 0, 0)
    m.beam(a, b, fm.circular_tube(0.02, 0.016, E=70e9), n=n_el)
    m.fix(a)
    m.step("load", initial_increment=1.0 / n_inc, max_increment=1.0 / n_inc).load(b, fz=-50.0)
    return m


def _user_folder(path):
    """A folder of the user's own files (what a link in the results folder might point at)."""
    path.mkdir()
    files = {f"f{k}.npz": f"the user's file {k}\n" for k in range(6)}
    for name, text in files.items():
        (path / name).write_text(text)
    return files


def _unchanged(path, files):
    return sorted(p.name for p in path.iterdir()) == sorted(files) and all(
        (path / n).read_text() == t for n, t in files.items()
    )


@pytest.mark.parametrize("sub", ["restart", "frames"])
def test_a_sub_folder_linked_out_of_the_results_folder_is_refused_and_its_target_untouched(tmp_path, sub):
    user = tmp_path / "u"
    files = _user_folder(user)
    out = tmp_path / "r"
    out.mkdir()
    (out / sub).symlink_to(user, target_is_directory=True)
    with pytest.raises(fm.FemastError, match=rf"{sub} is a symbolic link to .*u, not a folder femast made"):
        fm.solve(_cantilever(), out, progress=False, restart_every=2)
    assert _unchanged(user, files)


@pytest.mark.parametrize(
    "name", ["summary.json.tmp", "status.sta", "restart/restart.json.tmp", "restart/state-1.npz.tmp", "mesh.npz"]
)
def test_a_link_planted_under_one_of_femasts_names_is_neither_followed_nor_removed(tmp_path, name):
    keep = tmp_path / "keep.txt"
    keep.write_text("the user's own file\n")
    out = tmp_path / "r"
    (out / "restart").mkdir(parents=True)
    (out / name).symlink_to(keep)
    with pytest.raises(fm.FemastError, match=rf"{name.split('/')[-1]} is a symbolic link to .*keep.txt"):
        fm.solve(_cantilever(), out, progress=False, restart_every=1)
    assert keep.read_text() == "the user's own file\n" and (out / name).is_symlink()


def test_the_clean_up_of_an_earlier_run_removes_only_femasts_own_files(tmp_path):
    out = tmp_path / "r"
    fm.solve(_cantilever(), out, progress=False, restart_every=1)
    mine = {out / "frames" / "notes.txt": "mine", out / "restart" / "my-plot.npz": "mine too"}
    for p, text in mine.items():
        p.write_text(text)
    fm.solve(_cantilever(), out, progress=False, restart_every=1)  # a new run into the same folder
    assert all(p.read_text() == text for p, text in mine.items())


_SLOW = textwrap.dedent(
    """
    import sys, time, femast as fm

    def build():
        m = fm.Model("slow")
        a, b = m.node(0, 0, 0), m.node(1, 0, 0)
        m.beam(a, b, fm.circular_tube(0.02, 0.016, E=70e9), n=4)
        m.fix(a)
        m.step("s", initial_increment=0.01, max_increment=0.01).load(b, fz=-50.0)
        return m

    slow = len(sys.argv) > 2 and sys.argv[2] == "slow"

    def pace(frame):
        if slow:
            print("frame", int(frame["increment"]), flush=True)
            time.sleep(0.1)

    fm.Analysis(build(), sys.argv[1], progress=False, restart_every=2, on_frame=pace).run()
    """
)


@pytest.fixture
def first_writer(tmp_path):
    """A run writing slowly into tmp_path/r in another process, 3 frames in; its Popen."""
    script = tmp_path / "slow.py"
    script.write_text(_SLOW)
    out = tmp_path / "r"
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([os.getcwd(), os.environ.get("PYTHONPATH", "")])}
    p = subprocess.Popen([sys.executable, str(script), str(out), "slow"], env=env, stdout=subprocess.PIPE, text=True)
    try:
        deadline = time.time() + 300  # (a cold start compiles the kernels)
        for line in p.stdout:
            if line.startswith("frame 4") or time.time() > deadline:
                break
        assert p.poll() is None, "the first run ended before the second one started"
        yield p, script, out
    finally:
        p.kill()
        p.wait()
        p.stdout.close()


def test_a_second_writer_and_a_restart_while_the_first_runs_are_refused(first_writer, capsys):
    p, script, out = first_writer
    frames_before = len(Results(out))
    with pytest.raises(fm.FemastError, match=rf"results folder '{out}' is being written by .*pid {p.pid}\b") as err:
        fm.solve(_cantilever(), out, progress=False)
    assert type(err.value).__name__ == "FolderInUseError"
    # femast run --restart R while R's run goes on: one line naming the folder and the other process
    assert main(["run", "--restart", str(out), str(script), str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and f"'{out}' is being written by another femast run (pid {p.pid}" in err[0], err
    assert p.poll() is None and len(Results(out)) >= frames_before  # the first run goes on untouched
    assert Results(out).mesh["X"].shape == (5, 3)
    # once the first run is gone (killed outright: its lock goes with it), the folder is free again
    p.kill()
    p.wait()
    res = fm.solve(_cantilever(), out, progress=False)
    assert res.status == "completed" and len(res) == 5


@pytest.mark.parametrize("name", ["summary.json", "mesh.npz", "frames/frames.npzs"])
def test_a_fifo_in_the_folder_is_refused_not_read(tmp_path, name):
    out = tmp_path / "r"
    fm.solve(_cantilever(), out, progress=False)
    (out / name).unlink()
    os.mkfifo(out / name)
    try:
        done = subprocess.run(
            [sys.executable, "-m", "femast.cli", "info", str(out)], capture_output=True, text=True, timeout=240
        )
    except subprocess.TimeoutExpired:
        pytest.fail(f"femast info hangs on a FIFO planted as {name}")
    said = done.stdout + done.stderr
    assert f"{name.split('/')[-1]} is a FIFO (named pipe)" in said and "Traceback" not in said, said


def test_femast_info_on_a_file_or_a_foreign_array_file_says_what_it_is(tmp_path, capsys):
    script = tmp_path / "model.py"
    script.write_text("print('a model')\n")
    assert main(["info", str(script)]) == 2
    assert (
        capsys.readouterr().err.strip()
        == f"femast: error: {script} is a file, not a results folder; give the folder an analysis wrote"
    )
    out = tmp_path / "r"
    fm.solve(_cantilever(), out, progress=False)
    (out / "mesh.npz").write_bytes(
        b"\x93NUMPY\x01\x00v\x00{'descr': '|O', 'fortran_order': False, 'shape': (1,), }" + b" " * 44
    )
    assert main(["info", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "mesh.npz is unreadable" in err[0] and "unsafely" not in err[0], err


@pytest.mark.parametrize(
    "summary, field",
    [
        ({"status": "completed", "completed": True, "wall_time": "abc"}, "'wall_time' = 'abc' is not a finite number"),
        ({"status": "done"}, "'status' = 'done' is not one of running, completed"),
        ({"status": "completed", "steps": [{"name": "s", "increments": -1}]}, "'steps[0].increments' = -1"),
        ({"status": "completed", "increments": 1.5}, "'increments' = 1.5 is not a whole number"),
        ("[" * 100_000 + "]" * 100_000, "the summary is not valid JSON"),
    ],
    ids=["wall_time", "status", "steps", "increments", "deep"],
)
def test_femast_info_names_a_damaged_summary_in_one_line(tmp_path, capsys, summary, field):
    out = tmp_path / "r"
    fm.solve(_cantilever(), out, progress=False)
    (out / "summary.json").write_text(summary if isinstance(summary, str) else json.dumps(summary))
    with pytest.warns(ResultsWarning) as warned:
        assert main(["info", str(out)]) == 0
    said = capsys.readouterr()
    assert "not a femast error" not in said.err and any(field in str(w.message) for w in warned), warned.list
    assert "status: unknown" in said.out and "5 frames" in said.out
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ResultsWarning)
        assert Results(out).status == "unknown"


def _mount_tmpfs(path, size):
    path.mkdir()
    try:
        done = subprocess.run(["mount", "-t", "tmpfs", "-o", f"size={size}", "tmpfs", str(path)], capture_output=True)
    except OSError:
        return False
    return done.returncode == 0


@pytest.mark.parametrize("restart_every", [None, 3])
def test_a_full_disk_is_a_results_write_error_and_a_failed_summary(tmp_path, restart_every, capsys):
    """A real full disk: a 900 kB tmpfs (root only; the suite runs as root in CI)."""
    disk = tmp_path / "disk"
    if not _mount_tmpfs(disk, "900k"):
        pytest.skip("cannot mount a tmpfs here (not root, or no mount permission)")
    try:
        out = disk / "r"
        m = _cantilever(n_inc=100, n_el=40)
        with pytest.raises(ResultsWriteError, match=rf"could not write results to '{out}': No space left on device"):
            fm.solve(m, out, progress=False, restart_every=restart_every)
        s = json.loads((out / "summary.json").read_text())
        assert s["status"] == "failed" and "No space left on device" in s["message"]
        assert not list(out.rglob("*.tmp"))
        with warnings.catch_warnings():
            warnings.simplefilter("error", ResultsWarning)  # no partial frame left either
            res = Results(out)
        assert res.status == "failed" and len(res) > 10
        assert [int(res.frame(i)["increment"]) for i in range(len(res))] == list(range(len(res)))
        assert main(["info", str(out)]) == 0 and "status: failed" in capsys.readouterr().out
    finally:
        subprocess.run(["umount", str(disk)], check=False)
