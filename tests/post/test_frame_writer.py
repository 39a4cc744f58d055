"""Frames written as a zip built in memory: the same members, dtypes, shapes and
values as np.savez, a valid zip, and np.savez's own path for what it cannot write."""

import io
import os
import zipfile

import numpy as np

from femast.post.npz import atomic_savez as _atomic_savez
from femast.post.npz import npz_bytes as _npz_bytes


def _frame():
    rng = np.random.default_rng(0)
    return {
        "step": "bend",
        "increment": 7,
        "time": 0.35,
        "load_factor": np.float64(0.35),
        "iterations": 4,
        "U": rng.normal(size=(9, 3)),
        "R": rng.normal(size=(9, 3, 3)),
        "F": np.asfortranarray(rng.normal(size=(4, 3))),
        "S": rng.normal(size=(6, 4))[:, ::2],
        "empty": np.zeros((0, 6)),
        "flags": np.array([True, False]),
        "zone": np.arange(8, dtype=np.int32),
        "big_endian": np.arange(3, dtype=">f8"),
        "el/beam/section_forces": rng.normal(size=(8, 2, 6)),
    }


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
        assert z.testzip() is None  # every member's CRC checks
    assert not list(tmp_path.glob("*.tmp"))  # written through a temporary name, renamed


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
        frame["step"] = "b" + "x" * k  # a str of another length: another dtype, another layout
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
    os.write(fd, record_bytes(frames[0])[:50])  # a record cut short
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


def _two_step_bend(n_el=6):
    import femast as fm

    m = fm.Model("coder")
    ang = np.linspace(0.0, np.pi / 4, n_el + 1)
    n = m.nodes(np.column_stack([1 - np.cos(ang), np.sin(ang), np.zeros_like(ang)]))
    m.beams(np.column_stack([n[:-1], n[1:]]), fm.circular_tube(0.02, 0.016, E=70e9), up=(0.0, 0.0, 1.0))
    m.fix(n[0])
    m.step("bend", initial_increment=0.25, max_increment=0.25).load(n[-1], fz=-300.0)
    m.step("and_twist", initial_increment=0.5, max_increment=0.5).load(n[-1], fz=-300.0, mx=20.0)
    m.step("back", initial_increment=0.5).load(n[-1], fz=0.0, mx=0.0)  # the first name's length again
    return m


def test_frames_encoded_from_the_state_are_the_general_paths_bytes(tmp_path, monkeypatch):
    """A run's frames written by FrameCoder (from the state, no frame dict) and by the general path
    (a frame dict through record_bytes): the frame logs are identical byte for byte -- three
    steps, two step-name lengths (the coder is made again), reactions, element outputs."""
    import femast as fm
    from femast.analysis import output
    from femast.post import frame_coder
    from femast.post.npz import LOG_NAME

    made = []
    real = frame_coder.FrameCoder.make
    monkeypatch.setattr(output.FrameCoder, "make", classmethod(lambda cls, data, n: made.append(1) or real(data, n)))
    res = fm.solve(_two_step_bend(), tmp_path / "coder", progress=False)
    assert 2 <= len(made) <= 4  # the initial frame, then a step name of another length (not every frame)
    monkeypatch.setattr(output.FrameCoder, "make", classmethod(lambda cls, data, n: None))
    plain = fm.solve(_two_step_bend(), tmp_path / "plain", progress=False)
    assert len(res) == len(plain) == 1 + 4 + 2 + 2
    a = (tmp_path / "coder" / "frames" / LOG_NAME).read_bytes()
    b = (tmp_path / "plain" / "frames" / LOG_NAME).read_bytes()
    assert a == b
    assert np.abs(res.frame(-3)["RF"]).max() > 0 and np.abs(res.frame(5)["UR"]).max() > 0


def test_frame_coder_declines_a_frame_unlike_its_first():
    """Another type, dtype, shape or output name than the first frame's: None (the general path)."""
    from femast.post.frame_coder import FrameCoder

    n = 3
    rng = np.random.default_rng(3)
    st = dict(
        x=rng.normal(size=(n, 3)),
        X0=rng.normal(size=(n, 3)),
        R=np.tile(np.eye(3), (n, 1, 1)),
        spin=rng.normal(size=(n, 3)),
        loads=rng.normal(size=(n, 6)),
        cons_node=np.array([0, 0]),
        cons_dof=np.array([0, 4]),
        reactions=np.array([1.5, -2.0]),
    )
    out = {"beam": {"section_forces": rng.normal(size=(2, 2, 6))}}
    scalars = ("s", 1, 0.5, 0.5, 0.5, 3, 1.25, 0.0)
    RF = np.zeros((n, 6))
    RF[[0, 0], [0, 4]] = [1.5, -2.0]
    from femast.rotations import rotation_vectors

    data = dict(
        zip(
            (
                "step",
                "increment",
                "time",
                "total_time",
                "load_factor",
                "iterations",
                "strain_energy",
                "stabilization_energy",
            ),
            scalars,
        )
    )
    data.update(
        U=st["x"] - st["X0"],
        R=st["R"],
        UR=rotation_vectors(st["R"]),
        URA=st["spin"],
        RF=RF,
        P=st["loads"],
        **{"el/beam/section_forces": out["beam"]["section_forces"]},
    )
    coder = FrameCoder.make(data, n)
    args = [st[k] for k in ("x", "X0", "R", "spin", "loads", "cons_node", "cons_dof", "reactions")]
    from femast.post.npz import record_bytes

    assert coder.record(scalars, *args, out) == record_bytes(data)
    assert coder.record(("t",) + scalars[1:], *args, out) is not None  # same length: fine
    assert coder.record(("st",) + scalars[1:], *args, out) is None  # another length
    assert coder.record(scalars[:2] + (np.float32(0.5),) + scalars[3:], *args, out) is None  # another type
    assert coder.record(scalars[:1] + (True,) + scalars[2:], *args, out) is None
    assert coder.record(scalars, *args, {"beam": {"forces": out["beam"]["section_forces"]}}) is None
    assert coder.record(scalars, *args, {"beam": {"section_forces": np.zeros((3, 2, 6))}}) is None
    assert FrameCoder.make({**data, "extra": np.zeros(2)}, n) is None  # not the layout it writes
