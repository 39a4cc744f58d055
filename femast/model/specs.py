"""The model's plain records: DOF and load names, and the beam and truss specifications a script's
elements are kept as until an analysis builds their families."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..elements.base import DOF_NAMES
from ..errors import ModelError
from .sections import Section

LOAD_NAMES = ("fx", "fy", "fz", "mx", "my", "mz")
_DOF_INDEX = {n: i for i, n in enumerate(DOF_NAMES)}
_LOAD_INDEX = {n: i for i, n in enumerate(LOAD_NAMES)}


def dof_index(name: str) -> int:
    """Index 0..5 of a DOF name (ux, uy, uz, rx, ry, rz) or a load name (fx .. mz)."""
    key = str(name).lower()
    if key in _DOF_INDEX:
        return _DOF_INDEX[key]
    if key in _LOAD_INDEX:
        return _LOAD_INDEX[key]
    raise ModelError(f"unknown DOF '{name}'; use one of {', '.join(DOF_NAMES)} (or loads {', '.join(LOAD_NAMES)})")


@dataclass
class BeamSpec:
    label: int
    nodes: tuple
    section: Section
    up: np.ndarray
    family: str
    mass_per_length: float | None = None  # kg/m; None: section.rho * section.A


@dataclass
class TrussSpec:
    label: int
    nodes: tuple
    EA: float
    L0: float | None
    pretension: float | None
    tension_only: bool
    family: str
    mass_per_length: float = 0.0  # kg/m (modal analyses)
