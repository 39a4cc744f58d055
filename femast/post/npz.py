"""Frames as uncompressed ``.npz`` files built in memory.

A frame of a small model holds a couple of dozen small arrays; ``np.savez`` (through ``zipfile``)
spends about 1.5 ms on the bookkeeping of its members, more than a small model's increment costs.
:func:`npz_bytes` writes the same file -- a stored zip of ``<name>.npy`` members, version 1.0
headers, what ``np.savez`` writes and ``np.load`` reads -- straight into a byte buffer.  The frames
of a run repeat their names, dtypes and shapes from one increment to the next, so the zip's layout
(local headers, ``.npy`` headers, central directory) is laid out once per such signature and
kept: a frame then costs one copy of the layout, one copy of each array's bytes and one CRC-32
per member.

The frames of a run go into one file, the frame log (``frames/frames.npzs``), one record appended
per frame as its increment converges (:func:`record_bytes`, :func:`append_record`): a file created
and renamed per frame cost a small model's frame ~0.1-0.3 ms of system time, more than its
increment.  A record is ``b"FEMASTFR"``, the length n of its .npz as a little-endian uint64, and the
n bytes of the .npz; :func:`read_log` reads the frames back with numpy alone.
"""

from __future__ import annotations

import io
import mmap
import os
import struct
import zlib

import numpy as np
from numpy.lib import format as npformat

from .folder import open_regular, open_write, write_all, write_atomic

TMP_SUFFIX = ".tmp"  # partial files: "<name>.tmp", never matched by the readers' patterns
_MAX_MEMBER = 2**31 - 2**20  # a member beyond ~2 GB needs ZIP64: left to np.savez
_LAYOUTS: dict = {}  # signature -> _Layout
_MAX_LAYOUTS = 64  # signatures kept (a run has one or two per step)
_LOCAL = struct.Struct("<IHHHHHIIIHH")
_CENTRAL = struct.Struct("<IHHHHHHIIIHHHHHII")
_END = struct.Struct("<IHHHHIIH")
_CRC = struct.Struct("<I")


def npy_header(dtype, shape) -> bytes:
    """The .npy (version 1.0) header of a C-ordered array: magic, header length, the header dict
    padded to a multiple of 64 bytes (as np.save writes it)."""
    head = "{'descr': %r, 'fortran_order': False, 'shape': %r, }" % (npformat.dtype_to_descr(dtype), shape)  # noqa: UP031 (np.save's own layout)
    head += " " * (-(10 + len(head) + 1) % 64) + "\n"
    return b"\x93NUMPY\x01\x00" + struct.pack("<H", len(head)) + head.encode("latin1")


class _Layout:
    """The bytes of an .npz with members of given names, dtypes and shapes, the data left zero,
    and where each member's data and CRC go."""

    def __init__(self, signature):
        local, central, members, offset = [], [], [], 0
        for name, dtype, shape in signature:
            head = npy_header(dtype, shape)
            nbytes = int(np.prod(shape, dtype=np.int64)) * dtype.itemsize
            size = len(head) + nbytes
            fname = (name + ".npy").encode("utf8")
            loc = _LOCAL.pack(0x04034B50, 20, 0x800, 0, 0, 0x21, 0, size, size, len(fname), 0)
            cen = (
                _CENTRAL.pack(
                    0x02014B50, 20, 20, 0x800, 0, 0, 0x21, 0, size, size, len(fname), 0, 0, 0, 0, 0o600 << 16, offset
                )
                + fname
            )
            data_at = offset + len(loc) + len(fname) + len(head)
            # (data offset, data bytes, CRC of the .npy header, CRC position in the local header,
            #  index of the central entry: its CRC position is filled in below)
            members.append([data_at, nbytes, zlib.crc32(head), offset + 14, len(central)])
            local += (loc, fname, head, bytes(nbytes))
            central.append(cen)
            offset = data_at + nbytes
        cd_at = offset
        for m in members:  # the CRC field of a central entry is at byte 16 of it
            k = m[4]
            m[4] = cd_at + sum(len(c) for c in central[:k]) + 16
        cd = b"".join(central)
        end = _END.pack(0x06054B50, 0, 0, len(central), len(central), len(cd), cd_at, 0)
        self.template = b"".join(local) + cd + end
        self.members = [tuple(m) for m in members]


def _arrays(arrays: dict):
    """(signature, C-ordered arrays) of a frame dict, or None if a member needs np.savez."""
    sig, out = [], []
    for name, value in arrays.items():
        a = value if type(value) is np.ndarray else np.asanyarray(value)
        if a.dtype.hasobject or a.nbytes > _MAX_MEMBER:
            return None
        if a.ndim and not a.flags.c_contiguous:
            a = np.ascontiguousarray(a)
        sig.append((name, a.dtype, a.shape))
        out.append(a)
    return tuple(sig), out


def npz_bytes(arrays: dict) -> bytearray | None:
    """An uncompressed .npz of ``arrays`` (names to arrays or scalars) in memory: the members,
    dtypes, shapes and values np.savez would write.  None if an array needs np.savez (objects,
    members beyond 2 GB)."""
    got = _arrays(arrays)
    if got is None:
        return None
    sig, arrs = got
    layout = _LAYOUTS.get(sig)
    if layout is None:
        if len(_LAYOUTS) >= _MAX_LAYOUTS:
            _LAYOUTS.clear()
        layout = _LAYOUTS[sig] = _Layout(sig)
    buf = bytearray(layout.template)
    pack = _CRC.pack_into
    crc32 = zlib.crc32
    for a, (at, nbytes, head_crc, local_crc, central_crc) in zip(arrs, layout.members):
        data = a.tobytes()
        buf[at : at + nbytes] = data
        crc = crc32(data, head_crc)
        pack(buf, local_crc, crc)
        pack(buf, central_crc, crc)
    return buf


def npz_file_bytes(arrays: dict) -> bytes:
    """The bytes of an uncompressed .npz of ``arrays``: :func:`npz_bytes`, or np.savez's where it cannot."""
    data = npz_bytes(arrays)
    if data is None:
        buf = io.BytesIO()
        np.savez(buf, **arrays)
        data = buf.getvalue()
    return data


def atomic_savez(path, **arrays):
    """An .npz of ``arrays`` to ``path`` through a temporary file renamed into place (atomic on one
    filesystem: a reader sees the whole file or none; never through a link, femast/post/folder.py)."""
    write_atomic(path, npz_file_bytes(arrays))


# --------------------------------------------------------------------------- the frame log
LOG_NAME = "frames.npzs"  # frames/frames.npzs: every frame of a run, appended as it converges
RECORD_MAGIC = b"FEMASTFR"
_RECORD = struct.Struct("<8sQ")  # magic, length of the .npz that follows (bytes)


def record_bytes(arrays: dict) -> bytes:
    """One record of the frame log: the 16-byte record header (``b"FEMASTFR"``, the length as a
    little-endian uint64) and the frame as an .npz (np.savez's bytes where :func:`npz_bytes` cannot)."""
    data = npz_file_bytes(arrays)
    return _RECORD.pack(RECORD_MAGIC, len(data)) + data


def append_record(fd: int, record: bytes) -> None:
    """Append ``record`` to the log open as ``fd`` (O_APPEND) in one write (looped if it is short)."""
    write_all(fd, record)


def scan_log(path) -> tuple[list, int]:
    """The records of a frame log: ([(offset of the .npz, its length), ...], bytes left over at the end
    -- a record cut short by a run killed while writing it, or anything that is not a record).
    The headers are read through a memory map (no system call per record), or with a read per record
    where the file system cannot map the file.  Only a regular file is read (a FIFO or link: a
    FemastError, femast/post/folder.py)."""
    with open_regular(path) as fh:
        size = os.fstat(fh.fileno()).st_size
        if size < _RECORD.size:
            return [], size
        try:
            mm = mmap.mmap(fh.fileno(), 0, access=mmap.ACCESS_READ)
        except (OSError, ValueError):  # (a file system without mmap, or a file emptied since the fstat)

            def header(at):
                fh.seek(at)
                return _RECORD.unpack(fh.read(_RECORD.size))

            return _scan(header, size)
        with mm:  # (the map's length: a writer may have appended since the fstat)
            return _scan(lambda at: _RECORD.unpack_from(mm, at), len(mm))


def _scan(header, size: int) -> tuple[list, int]:
    """:func:`scan_log` of a file of ``size`` bytes whose record header at offset ``at`` is
    ``header(at)`` (magic, length)."""
    records = []
    head = _RECORD.size
    at = 0
    while at + head <= size:
        magic, length = header(at)
        if magic != RECORD_MAGIC or at + head + length > size:
            break
        records.append((at + head, length))
        at += head + length
    return records, size - at


def read_log(path):
    """Iterate over the frames of a frame log as dicts of arrays (what :func:`numpy.load` gives for
    each record's .npz); a partial last record is skipped.  Needs only numpy: the layout is a
    sequence of records, each ``b"FEMASTFR"``, a little-endian uint64 n, then n bytes of .npz."""
    records, _ = scan_log(path)
    with open_regular(path) as fh:
        for offset, length in records:
            fh.seek(offset)
            with np.load(io.BytesIO(fh.read(length)), allow_pickle=False) as z:
                yield {k: z[k] for k in z.files}


def truncate_log(path, keep: int) -> int:
    """Cut the frame log at ``path`` after its first ``keep`` records (a restarted run goes on from
    there); returns the number of whole records it had."""
    if keep < 0:
        raise ValueError(f"truncate_log: keep={keep} must be >= 0")
    records, rest = scan_log(path)
    if len(records) >= keep and (len(records) > keep or rest):
        end = records[keep - 1][0] + records[keep - 1][1] if keep else 0
        fd = open_write(path)
        try:
            os.ftruncate(fd, end)
        finally:
            os.close(fd)
    return len(records)
