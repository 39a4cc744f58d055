"""Cache of the forward solves of the FE experiments (``bay-torsion``, ``tip-cycle``).

A finite-element run along a measured path takes about a second for a single bay and several for
a mast, and a fit asks for the same run more than once: the final prediction repeats the last
accepted evaluation, the noise re-estimation of :func:`~femast.experiments.fitting.fit` restarts
from the solution, ``compare`` then asks for the latch zones of the fitted model, and a second
``compare`` or ``diagnose`` on the same data repeats the baseline fit.  :func:`cached` keys every
run by a SHA-1 of everything that defines it (the model inputs and the drive path, bit for bit)
and keeps

* the last ``MEMORY_ENTRIES`` runs of this process in memory (always), and
* every run as a small ``.npz`` file in a folder, shared between processes and sessions, when the
  experiment option ``cache_dir`` or the environment variable ``FEMAST_FE_CACHE`` names one
  (worker processes of ``diagnose`` then reuse each other's runs, and a repeated command is
  nearly free).

The disk entries hold data, never code: a run's dict of numeric arrays, numbers and
strings is stored as the arrays of an ``.npz`` (no object arrays; read with ``allow_pickle=False``)
plus a JSON header in the same file with the entry's key, the scalars and a MAC of them: an
HMAC-SHA-256 of the key, scalars and arrays whose secret is a second digest of the run's inputs
(:func:`run_secret`, SHA-256 in its own domain).  The file's name holds only the SHA-1 of the
inputs, so whoever rewrites an entry (other values, the checksum recomputed) cannot make a MAC that
matches without the inputs themselves, and the rewritten entry is a miss.  A file that is
truncated, corrupt, of another format, or whose key or MAC does not match (a file planted, copied
or edited in the folder) is a miss: the run is computed again and the entry rewritten.  A value
that is not such a dict stays in memory only.

A cached run is returned as a fresh copy, so callers may modify it.  ``STATS`` counts hits and
misses (``stats()``; ``clear()`` empties the memory cache and resets the counts).
"""

from __future__ import annotations

import copy
import hashlib
import hmac
import io
import json
import numbers
import os
import time
from collections import OrderedDict
from pathlib import Path

import numpy as np

MEMORY_ENTRIES = 256
ENV = "FEMAST_FE_CACHE"
RUN_LOG = "FEMAST_FE_RUN_LOG"
_MEM: OrderedDict = OrderedDict()
STATS = {"hits": 0, "disk_hits": 0, "misses": 0}


def _feed(h, obj) -> None:
    if isinstance(obj, np.ndarray):
        a = np.ascontiguousarray(obj)
        h.update(f"nd{a.dtype.str}{a.shape}".encode())
        h.update(a.tobytes())
    elif isinstance(obj, dict):
        h.update(b"{")
        for k in sorted(obj, key=str):
            h.update(repr(k).encode())
            _feed(h, obj[k])
        h.update(b"}")
    elif isinstance(obj, (list, tuple)):
        h.update(b"(")
        for v in obj:
            _feed(h, v)
        h.update(b")")
    elif isinstance(obj, float):
        h.update(float(obj).hex().encode())  # bit for bit
    else:
        h.update(repr(obj).encode())


def key_of(*parts) -> str:
    """SHA-1 hex digest of nested tuples/dicts of numbers, strings and arrays (floats bit for bit)."""
    h = hashlib.sha1()
    for p in parts:
        _feed(h, p)
    return h.hexdigest()


def cache_dir(options: dict | None = None) -> Path | None:
    """The disk cache folder: option ``cache_dir``, else ``$FEMAST_FE_CACHE``, else None (memory only)."""
    d = (options or {}).get("cache_dir") or os.environ.get(ENV)
    return Path(d) if d else None


def run_key(kind: str, key_parts) -> str:
    """The cache key of run ``key_parts`` of ``kind``."""
    return f"{kind}-{key_of(kind, key_parts)}"


def run_secret(kind: str, key_parts) -> bytes:
    """The secret of the MAC of run ``key_parts``' entry: a SHA-256 of the inputs in a domain of its
    own, which neither the entry nor its name (the SHA-1 of the inputs) reveals."""
    h = hashlib.sha256(b"femast-fe-cache-mac\0")
    for p in (kind, key_parts):
        _feed(h, p)
    return h.digest()


def cached(kind: str, key_parts, compute, options: dict | None = None, refresh: bool = False):
    """``compute()`` once per distinct ``key_parts`` (see the module docstring); returns a copy.
    refresh : compute even if cached (a run whose side products are needed: a reference path) and
    store the new value."""
    key = run_key(kind, key_parts)
    if key in _MEM and not refresh:
        _MEM.move_to_end(key)
        STATS["hits"] += 1
        return copy.deepcopy(_MEM[key])
    folder = cache_dir(options)
    path = folder / f"{key}.npz" if folder else None
    secret = run_secret(kind, key_parts) if folder else None
    if path is not None and path.is_file() and not refresh:
        value = read_entry(path, key, secret)
        if value is not None:
            STATS["disk_hits"] += 1
            _remember(key, value)
            return copy.deepcopy(value)
    STATS["misses"] += 1
    t0 = time.perf_counter()
    value = compute()
    _log_run(kind, key, time.perf_counter() - t0)
    _remember(key, value)
    if path is not None:
        write_entry(path, key, value, secret)
    return copy.deepcopy(value)


def _log_run(kind: str, key: str, seconds: float) -> None:
    """One line per computed run to ``$FEMAST_FE_RUN_LOG`` when set (benchmarks count the FE runs of a
    fit or a diagnosis across its worker processes: ``benchmarks/diagnose_speed.py``): pid, kind, key,
    seconds, the run's end (Unix time, s) and the CPU seconds of this process so far."""
    log = os.environ.get(RUN_LOG)
    if log:
        with open(log, "a") as fh:
            fh.write(f"{os.getpid()} {kind} {key[-12:]} {seconds:.4f} {time.time():.4f} {time.process_time():.3f}\n")


FORMAT = "femast-fe-cache 2"  # (1: an unkeyed SHA-256, which whoever rewrote an entry could recompute)


def _digest(key: str, arrays: dict, scalars: dict, secret: bytes) -> str:
    h = hmac.new(secret, key.encode(), hashlib.sha256)
    h.update(json.dumps(scalars, sort_keys=True).encode())
    for name in sorted(arrays):
        a = np.ascontiguousarray(arrays[name])
        h.update(f"{name}|{a.dtype.str}|{a.shape}|".encode())
        h.update(a.tobytes())
    return h.hexdigest()


def _split(value):
    """(arrays, scalars) of a storable value: a dict with str keys of numeric/bool arrays, numbers,
    strings and bools; None if the value is anything else (it then stays in memory only)."""
    if not isinstance(value, dict):
        return None
    arrays, scalars = {}, {}
    for k, v in value.items():
        if not isinstance(k, str) or k.startswith("__"):
            return None
        if isinstance(v, np.ndarray):
            if v.dtype.kind not in "biuf":
                return None
            arrays[k] = v
        elif isinstance(v, (bool, np.bool_)):
            scalars[k] = bool(v)
        elif isinstance(v, numbers.Integral):
            scalars[k] = int(v)
        elif isinstance(v, numbers.Real):
            if not np.isfinite(float(v)):  # JSON has no NaN/inf
                return None
            scalars[k] = float(v)
        elif isinstance(v, str):
            scalars[k] = v
        else:
            return None
    return arrays, scalars


def write_entry(path: Path, key: str, value, secret: bytes) -> bool:
    """Store ``value`` (see :func:`_split`) as entry ``key`` at ``path`` atomically, its MAC made with
    ``secret`` (:func:`run_secret`); False if it cannot be stored as data (then nothing is written)."""
    parts = _split(value)
    if parts is None:
        return False
    arrays, scalars = parts
    meta = {
        "format": FORMAT,
        "key": key,
        "scalars": scalars,
        "arrays": sorted(arrays),
        "mac": _digest(key, arrays, scalars, secret),
    }
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    buf = io.BytesIO()
    np.savez(
        buf,
        __meta__=np.frombuffer(json.dumps(meta).encode(), dtype=np.uint8),
        **{f"a_{name}": a for name, a in arrays.items()},
    )
    tmp = path.with_name(f"{path.name}.{os.getpid()}.tmp")
    with open(tmp, "wb") as fh:
        fh.write(buf.getvalue())
    os.replace(tmp, path)  # atomic: concurrent workers never read half a file
    return True


def read_entry(path: Path, key: str, secret: bytes):
    """The value stored as entry ``key`` at ``path``, or None (a miss) if the file is missing,
    truncated, corrupt, of another format, holds object arrays, or its key or MAC (made with
    ``secret``, :func:`run_secret`) differ."""
    try:
        with np.load(path, allow_pickle=False) as z:
            meta = json.loads(bytes(z["__meta__"]).decode())
            if not isinstance(meta, dict) or meta.get("format") != FORMAT or meta.get("key") != key:
                return None
            names = meta["arrays"]
            if sorted(z.files) != sorted(["__meta__"] + [f"a_{n}" for n in names]):
                return None
            arrays = {n: z[f"a_{n}"] for n in names}
        scalars = meta["scalars"]
        mac = meta["mac"]
        if not isinstance(scalars, dict) or not isinstance(mac, str):
            return None
        if not hmac.compare_digest(_digest(key, arrays, scalars, secret), mac):
            return None
    except Exception:  # anything unreadable is a miss, never a crash
        return None
    return {**arrays, **scalars}


def _remember(key, value) -> None:
    _MEM[key] = value
    _MEM.move_to_end(key)
    while len(_MEM) > MEMORY_ENTRIES:
        _MEM.popitem(last=False)


def stats() -> dict:
    """Counts of memory hits, disk hits and misses (computed runs) in this process."""
    return dict(STATS)


def clear() -> None:
    """Empty the memory cache and reset the counts (the disk folder is left alone)."""
    _MEM.clear()
    for k in STATS:
        STATS[k] = 0


class kernel_threads:
    """Context manager running numba's parallel kernels on ``n`` threads, then restoring the
    previous count.  femast's own element kernels are serial at present (a parallel ball-joint
    kernel made a single-bay run 3x slower on a busy machine, and a parallel beam kernel gained
    at most 3 %, docs/performance.md); the setting matters for user elements with parallel
    kernels.  The FE experiments run on one thread: the refits of ``diagnose`` already use every
    core (its workers are spawned, so numba's thread pool in this process does not matter to them)."""

    def __init__(self, n: int | None = 1):
        self.n = n
        self.old = None

    def __enter__(self):
        if self.n:
            try:
                import numba

                self.old = numba.get_num_threads()
                numba.set_num_threads(max(1, min(int(self.n), numba.config.NUMBA_NUM_THREADS)))
            except Exception:  # numba without threading support: nothing to do
                self.old = None
        return self

    def __exit__(self, *exc):
        if self.old is not None:
            import numba

            numba.set_num_threads(self.old)
        return False
