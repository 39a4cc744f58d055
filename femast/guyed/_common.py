"""Small helpers shared by the guyed-mast modules (cross-product matrices, input checks)."""

from __future__ import annotations

import math

import numpy as np

from ..elements.base import check_positive  # noqa: F401  (one copy, shared with the shroud law)
from ..errors import ModelError


def skew(v) -> np.ndarray:
    """Cross-product matrix [v]x (Table I of the Rocaspect paper): ``skew(a) @ b == np.cross(a, b)``.

    Works on a (3,) vector or a stack (..., 3) -> (..., 3, 3).
    """
    v = np.asarray(v, dtype=float)
    S = np.zeros(v.shape[:-1] + (3, 3))
    S[..., 0, 1] = -v[..., 2]
    S[..., 0, 2] = v[..., 1]
    S[..., 1, 0] = v[..., 2]
    S[..., 1, 2] = -v[..., 0]
    S[..., 2, 0] = -v[..., 1]
    S[..., 2, 1] = v[..., 0]
    return S


def check_vectors(name: str, value, shape_tail=(3,)) -> np.ndarray:
    """Return ``value`` as a finite float array whose trailing shape is ``shape_tail``."""
    arr = np.asarray(value, dtype=float)
    if arr.shape[-len(shape_tail) :] != tuple(shape_tail) or not np.all(np.isfinite(arr)):
        raise ModelError(
            f"{name} must be finite coordinates of shape (..., {', '.join(map(str, shape_tail))}) in m; "
            f"got shape {arr.shape}"
        )
    return arr


def unit_vectors(name: str, vec, labels=None, tol: float = 1e-9):
    """Unit vectors and lengths of a stack of vectors (n, 3); raise if any is shorter than ``tol`` m."""
    vec = np.asarray(vec, dtype=float)
    length = np.linalg.norm(vec, axis=-1)
    short = length < tol
    if np.any(short):
        k = int(np.flatnonzero(short.ravel())[0])
        label = labels[k] if labels is not None else f"#{k}"
        raise ModelError(
            f"{name} {label}: its two end points coincide (length {length.ravel()[k]:.3g} m); "
            "move one of them so the segment has a direction"
        )
    return vec / length[..., None], length


def fmt_pose(pose) -> str:
    """Human-readable pose (x, y, z in m; roll, pitch, yaw in degrees)."""
    p = np.asarray(pose, dtype=float).ravel()
    s = f"x={p[0]:.3f} m, y={p[1]:.3f} m, z={p[2]:.3f} m"
    if p.size >= 6:
        s += ", angles=({:.1f}, {:.1f}, {:.1f}) deg".format(*(math.degrees(a) for a in p[3:6]))
    return s
