"""Point masses of a model (:meth:`femast.model.Model.point_mass`): the input of modal analyses.

A point mass is a mass (kg) with rotary inertia (kg m^2, about its centre of mass, initial global
axes, rotated with the node) at a node, its centre of mass at an optional offset (m) from the node;
a rigid body's mass and inertia is a point mass at its reference node.  The mass matrices are
assembled by :mod:`femast.modal.mass`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import ModelError


@dataclass
class PointMassSpec:
    """A mass (kg) with rotary inertia (3x3, kg m^2, about its centre of mass, initial global
    axes) at ``node``, its centre of mass ``offset`` (m, initial global axes) from the node."""

    node: int
    mass: float
    inertia: np.ndarray
    offset: np.ndarray
    name: str = ""


def point_mass_spec(node, mass=0.0, inertia=None, offset=None, name="") -> PointMassSpec:
    """Validate a point mass: ``mass`` kg >= 0; ``inertia`` None, a scalar (kg m^2, isotropic),
    3 principal values along the global axes or a symmetric positive semi-definite 3x3 matrix;
    ``offset`` None or a 3-vector (m)."""
    who = name or f"point mass at node {node}"
    try:
        m = float(mass)
    except (TypeError, ValueError):
        raise ModelError(f"{who}: mass = {mass!r} is not a number (kg)") from None
    if not math.isfinite(m) or m < 0:
        raise ModelError(f"{who}: mass = {mass!r} kg must be finite and >= 0")
    if inertia is None:
        J = np.zeros((3, 3))
    else:
        a = np.asarray(inertia, dtype=float)
        if a.ndim == 0:
            J = float(a) * np.eye(3)
        elif a.shape == (3,):
            J = np.diag(a)
        elif a.shape == (3, 3):
            J = a.copy()
        else:
            raise ModelError(
                f"{who}: inertia must be a scalar, 3 principal values or a 3x3 matrix (kg m^2); got shape {a.shape}"
            )
        if not np.all(np.isfinite(J)):
            raise ModelError(f"{who}: inertia {inertia!r} is not finite")
        if not np.allclose(J, J.T, rtol=1e-12, atol=1e-15 * max(np.abs(J).max(), 1e-300)):
            raise ModelError(f"{who}: inertia matrix is not symmetric")
        if np.linalg.eigvalsh(J).min() < -1e-12 * max(np.abs(J).max(), 1e-300):
            raise ModelError(
                f"{who}: inertia {inertia!r} kg m^2 has a negative principal value; moments of inertia are >= 0"
            )
    c = np.zeros(3) if offset is None else np.asarray(offset, dtype=float).reshape(-1)
    if c.shape != (3,) or not np.all(np.isfinite(c)):
        raise ModelError(f"{who}: offset {offset!r} must be a finite 3-vector (m)")
    return PointMassSpec(int(node), m, J, c, name)
