"""The FE run cache stores data, never code; a corrupt or foreign entry is a miss."""

import pickle
import shutil

import numpy as np

from femast.experiments import fe_cache


class _Payload:
    """Unpickling this creates a file: the proof that a planted pickle ran code."""

    def __init__(self, marker):
        self.marker = marker

    def __reduce__(self):
        return (open, (self.marker, "w"))


def _value():
    return {
        "Mz": np.array([1.0, -2.5, 3e-17]),
        "zone": np.array([[0, 1], [2, 3]]),
        "increments": 7,
        "wall_time": 0.25,
        "note": "ok",
        "flag": True,
    }


def _compute_counter():
    calls = []

    def compute():
        calls.append(1)
        return _value()

    return compute, calls


_SECRET = fe_cache.run_secret("unit", ("p", 1.0))  # the MAC secret of _cached's entry


def _cached(tmp_path, compute, parts=("p", 1.0)):
    return fe_cache.cached("unit", parts, compute, {"cache_dir": str(tmp_path)})


def _entry(tmp_path):
    (path,) = tmp_path.glob("unit-*.npz")
    return path


def test_round_trip_is_bit_for_bit_and_from_disk(tmp_path):
    fe_cache.clear()
    compute, calls = _compute_counter()
    a = _cached(tmp_path, compute)
    fe_cache.clear()  # another process: only the disk entry is left
    b = _cached(tmp_path, compute)
    assert len(calls) == 1 and fe_cache.stats()["disk_hits"] == 1
    assert set(a) == set(b)
    for k in a:
        if isinstance(a[k], np.ndarray):
            assert a[k].dtype == b[k].dtype and np.array_equal(a[k], b[k])
        else:
            assert a[k] == b[k] and type(a[k]) is type(b[k])


def test_a_planted_pickle_is_never_loaded(tmp_path):
    fe_cache.clear()
    compute, calls = _compute_counter()
    _cached(tmp_path, compute)
    path = _entry(tmp_path)
    marker = tmp_path / "pwned"
    for planted in (path, path.with_suffix(".pkl")):  # under the entry's name, and the old pickle name
        planted.write_bytes(pickle.dumps(_Payload(str(marker))))
    fe_cache.clear()
    _cached(tmp_path, compute)
    assert not marker.exists()  # no code ran
    assert len(calls) == 2  # a miss: computed again
    assert fe_cache.read_entry(path, path.stem, _SECRET) is not None  # and the entry rewritten as data


def test_object_arrays_truncated_foreign_and_tampered_entries_are_misses(tmp_path):
    fe_cache.clear()
    compute, calls = _compute_counter()
    _cached(tmp_path, compute)
    path = _entry(tmp_path)
    good = path.read_bytes()
    key = path.stem
    # an npz holding an object array (loading it would need pickle)
    np.savez(path, __meta__=np.frombuffer(b"{}", np.uint8), a_Mz=np.array([{"x": 1}], dtype=object))
    assert fe_cache.read_entry(path, key, _SECRET) is None
    # truncated (a killed writer of an older version)
    path.write_bytes(good[: len(good) // 2])
    assert fe_cache.read_entry(path, key, _SECRET) is None
    # a valid entry of another run copied under this name
    other = tmp_path / "other"
    other.mkdir()
    fe_cache.cached("unit", ("q", 2.0), compute, {"cache_dir": str(other)})
    shutil.copy(_entry(other), path)
    assert fe_cache.read_entry(path, key, _SECRET) is None
    # one flipped byte in the arrays: the checksum differs (or the zip is unreadable)
    path.write_bytes(good)
    assert fe_cache.read_entry(path, key, _SECRET) is not None
    raw = bytearray(good)
    i = raw.find(np.array([1.0, -2.5]).tobytes())
    raw[i] ^= 0x01
    path.write_bytes(bytes(raw))
    assert fe_cache.read_entry(path, key, _SECRET) is None
    # and through cached(): a miss, computed again
    fe_cache.clear()
    n = len(calls)
    _cached(tmp_path, compute)
    assert len(calls) == n + 1


def test_values_that_are_not_plain_data_stay_in_memory(tmp_path):
    fe_cache.clear()
    out = fe_cache.cached("unit", ("r",), lambda: {"f": lambda: 1}, {"cache_dir": str(tmp_path)})
    assert callable(out["f"]) and not list(tmp_path.glob("*.npz"))
