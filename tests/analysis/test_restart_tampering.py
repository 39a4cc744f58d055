"""A restart point read back from disk is checked before it is used: edited or damaged values in
restart.json or the state files are refused with an error naming the field, and nothing on disk is
changed by the refused restart (no frame deleted, no file outside the folder read)."""

import io
import json
import os
import shutil

import numpy as np
import pytest

import femast as fm
from femast.post.npz import LOG_NAME, scan_log


def _build():
    m = fm.Model("tamper")
    a, b = m.node(0, 0, 0), m.node(1, 0, 0)
    m.beam(a, b, fm.circular_tube(0.02, 0.016, E=70e9), n=4)
    m.fix(a)
    m.step("bend", initial_increment=0.1, max_increment=0.1).load(b, fz=-400.0)
    return m


@pytest.fixture
def stopped(tmp_path):
    """A run stopped after increment 6 with a restart point at increment 4: its folder."""
    out = tmp_path / "r"

    def stop(frame):
        if frame["increment"] == 6:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        fm.Analysis(_build(), out, progress=False, restart_every=4, on_frame=stop).run()
    return out


def _frames(out):
    return len(scan_log(out / "frames" / LOG_NAME)[0])


def _edit(out, **changes):
    path = out / "restart" / "restart.json"
    info = json.loads(path.read_text())
    info.update(changes)
    path.write_text(json.dumps(info))
    return info


def _restart(out):
    return fm.Analysis(_build(), out, progress=False, restart=out).run()


@pytest.mark.parametrize(
    "changes, named",
    [
        ({"frames": -1}, "'frames' = -1 is not a whole number >= 1"),
        ({"frames": "3"}, "'frames' = '3' is not a whole number"),
        ({"frames": 2.0}, "'frames' = 2.0 is not a whole number"),
        ({"step": 7}, "'step' = 7 is not a whole number from 0 to 0"),
        ({"step_done": "yes"}, "'step_done' = 'yes' is not true or false"),
        ({"every": 0}, "'every' = 0 is not a whole number >= 1"),
        ({"increment": 10**6}, "'increment' = 1000000 is not a whole number from 0 to 1000"),
        ({"zero_force": "not hex"}, "'zero_force' = 'not hex' is not a positive number"),
        ({"summary": {"increments": 4}}, "'iterations' = None is not a whole number"),
        ({"state_file": "state-9.npz"}, "'state_file' = 'state-9.npz' is not state-1.npz"),
    ],
)
def test_an_edited_restart_record_is_refused_and_the_folder_kept(stopped, changes, named):
    frames = _frames(stopped)
    _edit(stopped, **changes)
    with pytest.raises(fm.FemastError, match="the restart point is refused") as err:
        _restart(stopped)
    assert named in str(err.value) and "run the analysis again from the start" in str(err.value)
    assert _frames(stopped) == frames  # the refused restart deleted no frame


def test_a_state_file_outside_the_folder_is_never_read(stopped, tmp_path):
    outside = tmp_path / "outside"
    shutil.copy(stopped / "restart" / "state-1.npz", outside)  # a valid state, out of the folder
    frames = _frames(stopped)
    _edit(stopped, state_file="../../outside")
    with pytest.raises(fm.FemastError, match=r"'state_file' = '../../outside' is not state-1.npz"):
        _restart(stopped)
    assert _frames(stopped) == frames


@pytest.mark.parametrize("kind", ["fifo", "link"])
def test_a_restart_record_that_is_not_a_regular_file_is_named_not_called_missing(stopped, tmp_path, kind, capsys):
    from femast.cli import main

    record = stopped / "restart" / "restart.json"
    outside = tmp_path / "outside.json"
    outside.write_text(record.read_text())  # (a valid record, out of the folder)
    record.unlink()
    if kind == "fifo":
        os.mkfifo(record)  # (opening it for reading would wait for a writer: never opened)
    else:
        record.symlink_to(outside)
    what = "a FIFO (named pipe)" if kind == "fifo" else f"a symbolic link to {outside}"
    with pytest.raises(fm.FemastError, match="the restart point is refused") as err:
        _restart(stopped)
    assert f"restart.json is {what}, not a file femast made" in str(err.value)
    script = tmp_path / "model.py"
    script.write_text("raise SystemExit('the script ran')\n")
    assert main(["run", "--restart", str(stopped), str(script)]) == 2  # refused before the script runs
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and f"restart.json is {what}" in err[0] and "no restart point" not in err[0], err


@pytest.mark.parametrize(
    "field, value, named",
    [
        ("x", "nan", "x holds NaN or infinite values"),
        ("x", "shape", "x is float64 (4, 3), not a float array of shape (5, 3)"),
        ("step_time", "nan", "step_time = nan is not a finite number"),
        ("increment", 3, "the state is at step 0 increment 3, restart.json says step 0 increment 4"),
    ],
)
def test_a_tampered_state_file_is_refused(stopped, field, value, named):
    path = stopped / "restart" / "state-1.npz"
    with np.load(path) as z:
        data = {k: z[k] for k in z.files}
    if value == "nan":
        data[field] = np.full_like(data[field], np.nan)
    elif value == "shape":
        data[field] = data[field][:-1]
    else:
        data[field] = np.array(value)
    buf = io.BytesIO()
    np.savez(buf, **data)
    path.write_bytes(buf.getvalue())
    with pytest.raises(fm.FemastError, match="the restart point is refused") as err:
        _restart(stopped)
    assert named in str(err.value)


def test_an_untouched_restart_point_still_restarts(stopped):
    res = _restart(stopped)
    ref = fm.solve(_build(), stopped.parent / "ref", progress=False)
    assert res.status == "completed" and len(res) == len(ref) == 11
    assert np.array_equal(res.frame(-1)["U"], ref.frame(-1)["U"])
