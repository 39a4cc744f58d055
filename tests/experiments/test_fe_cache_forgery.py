"""An FE cache entry rewritten by someone without the run's inputs (other values, its checksum
recomputed from what the file and its name show) is a miss, never a hit: the run is computed again."""

import hashlib
import hmac
import io
import json

import numpy as np

from femast.experiments import fe_cache


def _true_value():
    return {"Mz": np.array([1.081, -0.5, 0.25]), "increments": 7, "note": "ok"}


def _forge(path):
    """Rewrite the entry at ``path`` as an attacker would: other values, and every checksum field
    recomputed from the file's own key (the documented SHA-256 of key, scalars and arrays, and an
    HMAC keyed by what the file and its name reveal)."""
    with np.load(path, allow_pickle=False) as z:
        meta = json.loads(bytes(z["__meta__"]).decode())
        arrays = {k[2:]: z[k] for k in z.files if k.startswith("a_")}
    arrays["Mz"] = arrays["Mz"] * 5.0  # a forged result
    key, scalars = meta["key"], meta["scalars"]
    for field, h in (("sha256", hashlib.sha256(key.encode())), ("mac", hmac.new(key.encode(), key.encode(), "sha256"))):
        h.update(json.dumps(scalars, sort_keys=True).encode())
        for name in sorted(arrays):
            a = np.ascontiguousarray(arrays[name])
            h.update(f"{name}|{a.dtype.str}|{a.shape}|".encode())
            h.update(a.tobytes())
        meta[field] = h.hexdigest()
    buf = io.BytesIO()
    np.savez(
        buf, __meta__=np.frombuffer(json.dumps(meta).encode(), np.uint8), **{f"a_{k}": a for k, a in arrays.items()}
    )
    path.write_bytes(buf.getvalue())


def test_a_rewritten_entry_with_its_checksum_recomputed_is_a_miss(tmp_path):
    fe_cache.clear()
    calls = []

    def compute():
        calls.append(1)
        return _true_value()

    options = {"cache_dir": str(tmp_path)}
    first = fe_cache.cached("bay-torsion", ("inputs", 1.5), compute, options)
    (path,) = tmp_path.glob("bay-torsion-*.npz")
    _forge(path)
    fe_cache.clear()  # another process: only the disk entry is left
    again = fe_cache.cached("bay-torsion", ("inputs", 1.5), compute, options)
    assert len(calls) == 2 and fe_cache.stats()["disk_hits"] == 0  # computed again, not read
    np.testing.assert_array_equal(again["Mz"], first["Mz"])
    # the entry is rewritten with the true values, and is a hit from then on
    fe_cache.clear()
    third = fe_cache.cached("bay-torsion", ("inputs", 1.5), compute, options)
    assert len(calls) == 2 and fe_cache.stats()["disk_hits"] == 1
    np.testing.assert_array_equal(third["Mz"], first["Mz"])
