"""Frames of one run encoded from the analysis state without a frame dict.

A frame of a small model is a dozen small arrays and eight scalars.  Through the general path
(a dict of new arrays, then :func:`femast.post.npz.record_bytes`: the signature, a layout lookup,
a ``tobytes`` per member) each member costs a few Python operations: with its append and status
line a frame of the 45-degree bend cost ~70 us at load 7 on 2 cores, a sixth of its increment
(~50 us this way).  A run's frames repeat one signature, so
:class:`FrameCoder`, made from the run's first frame, keeps

* a float64 block holding U, R, UR, URA, RF and P back to back (filled in place from the state:
  one numpy call or compiled kernel per array, no allocation), and a byte view of each;
* the .npz layout of the signature (:class:`femast.post.npz._Layout`) with, per member, where
  its data and CRC-32s go;

and writes each frame by copying the block's byte views, the packed scalars and the element
outputs into a copy of the layout.  A frame whose scalars or element outputs differ in type,
dtype or shape from the first one's gets None, and the caller takes the general path.  The bytes
are those of the general path (tests/post/test_frame_writer.py compares them).
"""

from __future__ import annotations

import struct
import zlib

import numpy as np

from ..rotations import _rotation_vectors
from .npz import _LAYOUTS, _RECORD, RECORD_MAGIC, _arrays, _Layout

SCALARS = (
    "step",
    "increment",
    "time",
    "total_time",
    "load_factor",
    "iterations",
    "strain_energy",
    "stabilization_energy",
)
STATE = (("U", 3), ("R", 9), ("UR", 3), ("URA", 3), ("RF", 6), ("P", 6))  # (name, values per node)
_F8 = struct.Struct("<d")
_I8 = struct.Struct("<q")
_CRC = struct.Struct("<I")
_SIMPLE = np.dtype(float).str == "<f8" and np.asanyarray(0).dtype.str == "<i8"  # (a little-endian machine)


class FrameCoder:
    """Encodes the frames of one run from the state (see module docstring).  Made by :meth:`make`
    from the run's first frame dict; :meth:`record` returns a frame-log record or None."""

    def __init__(self, data: dict, n: int, sig):
        self.n = n
        self.types = tuple(type(data[k]) for k in SCALARS)
        self.el_keys = {}  # family -> its output names, in order
        for k in data:
            if k.startswith("el/"):
                fam, _, name = k[3:].partition("/")
                self.el_keys.setdefault(fam, []).append(name)
        self.el_keys = [(fam, tuple(names)) for fam, names in self.el_keys.items()]
        self.el_sig = [(a.dtype, a.shape) for k, a in zip([s[0] for s in sig], _arrays(data)[1]) if k.startswith("el/")]
        layout = _LAYOUTS.get(sig) or _Layout(sig)
        self.template = layout.template
        self.members = layout.members
        self.block = np.zeros(sum(w for _, w in STATE) * n)
        views, at = {}, 0
        for name, w in STATE:
            views[name] = self.block[at : at + w * n]
            at += w * n
        self.U = views["U"].reshape(n, 3)
        self.R = views["R"].reshape(n, 3, 3)
        self.UR = views["UR"].reshape(n, 3)
        self.URA = views["URA"].reshape(n, 3)
        self.RF = views["RF"].reshape(n, 6)
        self.P = views["P"].reshape(n, 6)
        raw = memoryview(self.block).cast("B")
        self.state_bytes, at = [], 0
        for _, w in STATE:
            self.state_bytes.append(raw[at : at + 8 * w * n])
            at += 8 * w * n

    @classmethod
    def make(cls, data: dict, n: int):
        """A coder for frames like ``data`` (a frame dict of the general path, in its key order), or
        None if its layout is not the one this coder writes."""
        if not _SIMPLE:  # pragma: no cover - a big-endian machine: the general path
            return None
        got = _arrays(data)
        if got is None:
            return None
        sig = got[0]
        names = [s[0] for s in sig]
        want = list(SCALARS) + [name for name, _ in STATE]
        if names[: len(want)] != want or not all(k.startswith("el/") for k in names[len(want) :]):
            return None
        for (_name, dtype, shape), (_, w) in zip(sig[len(SCALARS) :], STATE):
            if dtype != np.float64 or int(np.prod(shape)) != w * n or shape[0] != n:
                return None
        if any(t not in (str, int, float, np.float64, np.int64) for t in (type(data[k]) for k in SCALARS)):
            return None
        return cls(data, n, sig)

    def record(self, scalars, x, X0, R, spin, loads, cons_node, cons_dof, reactions, outputs) -> bytes | None:
        """The frame-log record of a frame: ``scalars`` in the order of :data:`SCALARS`, the state
        (positions ``x``, reference ``X0`` (n, 3), rotations ``R`` (n, 3, 3), spins (n, 3), loads
        (n, 6), the constrained DOFs' reactions or None) and the families' ``outputs`` (family name
        -> dict of arrays), or None if the frame does not fit this coder."""
        members = self.members
        data = []
        for v, t in zip(scalars, self.types):
            if type(v) is not t:
                return None
            if t is float or t is np.float64:
                data.append(_F8.pack(v))
            elif t is str:
                b = v.encode("utf-32-le")
                if len(b) != members[0][1] or not v or "\0" in v:
                    return None
                data.append(b)
            else:  # int, np.int64
                if not -(2**63) <= v < 2**63:
                    return None
                data.append(_I8.pack(v))
        np.subtract(x, X0, out=self.U)
        self.R[...] = R
        _rotation_vectors(self.R, self.UR)
        self.URA[...] = spin
        self.RF.fill(0.0)
        if reactions is not None:
            self.RF[cons_node, cons_dof] = reactions
        self.P[...] = loads
        data += self.state_bytes
        if len(outputs) != len(self.el_keys):
            return None
        els = []
        for (fam, keys), (name, out) in zip(self.el_keys, outputs.items()):
            if fam != name or tuple(out) != keys:
                return None
            els += out.values()
        for a, (dtype, shape) in zip(els, self.el_sig):
            if type(a) is not np.ndarray or a.dtype != dtype or a.shape != shape:
                return None
            data.append(a.tobytes())
        buf = bytearray(self.template)
        pack = _CRC.pack_into
        crc32 = zlib.crc32
        for d, (at, nbytes, head_crc, local_crc, central_crc) in zip(data, members):
            buf[at : at + nbytes] = d
            crc = crc32(d, head_crc)
            pack(buf, local_crc, crc)
            pack(buf, central_crc, crc)
        return _RECORD.pack(RECORD_MAGIC, len(buf)) + buf
