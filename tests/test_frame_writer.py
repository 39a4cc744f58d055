"""Frames written as a zip built in memory (issue 21, item 3): the same members, dtypes, shapes and
values as np.savez, a valid zip, and np.savez's own path for what it cannot write."""

import io
import os
import zipfile

import numpy as np

from femast.post.results import _atomic_savez, _npz_bytes


def _frame():
    rng = np.random.default_rng(0)
    return {"step": "bend", "increment": 7, "time": 0.35, "load_factor": np.float64(0.35), "iterations": 4,
            "U": rng.normal(size=(9, 3)), "R": rng.normal(size=(9, 3, 3)),
            "F": np.asfortranarray(rng.normal(size=(4, 3))), "S": rng.normal(size=(6, 4))[:, ::2],
            "empty": np.zeros((0, 6)), "flags": np.array([True, False]), "zone": np.arange(8, dtype=np.int32),
            "big_endian": np.arange(3, dtype=">f8"), "el/beam/section_forces": rng.normal(size=(8, 2, 6))}


def test_frame_bytes_load_like_np_savez(tmp_path):
    frame = _frame()
    _atomic_savez(tmp_path / "f.npz", **frame)
    ref = io.BytesIO()
    np.savez(ref, **frame)
    with np.load(tmp_path / "f.npz", allow_pickle=False) as got, np.load(io.BytesIO(ref.getvalue())) as want:
        assert sorted(got.files) == sorted(want.files)
        for k in want.files:
            assert got[k].dtype == want[k].dtype and got[k].shape == want[k].shape, k
            assert np.array_equal(got[k], want[k]), k
    with zipfile.ZipFile(tmp_path / "f.npz") as z:
        assert z.testzip() is None                      # every member's CRC checks
    assert not list(tmp_path.glob("*.tmp"))             # written through a temporary name, renamed


def test_object_arrays_fall_back_to_np_savez(tmp_path):
    assert _npz_bytes({"a": np.array([1, "x"], dtype=object)}) is None
    # the writer then uses np.savez, which refuses nothing here; np.load needs allow_pickle to read it
    _atomic_savez(tmp_path / "o.npz", a=np.array([1, "x"], dtype=object))
    with np.load(tmp_path / "o.npz", allow_pickle=True) as z:
        assert z["a"].tolist() == [1, "x"]


def test_repeated_layout_new_values(tmp_path):
    """Frames of one signature (names, dtypes, shapes) share a cached zip layout: every frame must
    still carry its own values and CRCs (np.load checks each member's CRC-32)."""
    rng = np.random.default_rng(1)
    for k in range(3):
        frame = _frame()
        frame["U"] = rng.normal(size=(9, 3))
        frame["increment"] = k
        frame["step"] = "b" + "x" * k            # a str of another length: another dtype, another layout
        _atomic_savez(tmp_path / f"{k}.npz", **frame)
        with np.load(tmp_path / f"{k}.npz", allow_pickle=False) as got:
            assert np.array_equal(got["U"], frame["U"]) and int(got["increment"]) == k
            assert str(got["step"]) == frame["step"]
        with zipfile.ZipFile(tmp_path / f"{k}.npz") as z:
            assert z.testzip() is None


def test_frame_log_records_truncation_and_old_folders(tmp_path):
    """The frame log: records read back as written; a restart cuts it after its frames (and a
    partial record); a folder of one file per frame becomes a log of the same frames."""
    from femast.post.npz import append_record, read_log, record_bytes, scan_log, truncate_log
    from femast.post.results import _log_from_files

    frames = [dict(_frame(), increment=k) for k in range(4)]
    log = tmp_path / "frames.npzs"
    fd = os.open(log, os.O_WRONLY | os.O_CREAT | os.O_APPEND)
    for fr in frames:
        append_record(fd, record_bytes(fr))
    os.write(fd, record_bytes(frames[0])[:50])     # a record cut short
    os.close(fd)
    got = list(read_log(log))
    assert [int(g["increment"]) for g in got] == [0, 1, 2, 3]
    assert all(np.array_equal(g["U"], f["U"]) for g, f in zip(got, frames))
    assert scan_log(log)[1] == 50
    assert truncate_log(log, 2) == 4
    assert [int(g["increment"]) for g in read_log(log)] == [0, 1] and scan_log(log)[1] == 0
    old = tmp_path / "old"
    old.mkdir()
    for k, fr in enumerate(frames):
        np.savez(old / f"{k + 1:06d}.npz", **fr)
    _log_from_files(old, old / "frames.npzs")
    assert [int(g["increment"]) for g in read_log(old / "frames.npzs")] == [0, 1, 2, 3]
