"""Cantilever beam model of the bare mast (the Rocaspect paper, Eqs. 8-15).

The mast's metal beam is a square tube clamped at its base O_i and loaded at its
top C_i3.  Its tip compliance in the beam frame F_be (x_be along the beam) is
Eq. 8; it is rotated into the base frame with Eqs. 12-14 and maps the top wrench
``dw = [f ; m]`` (N; N m about the top) to the top displacement ``dc`` (m; rad),
Eq. 15.

Torsion constant (Eq. 10)
-------------------------
Eq. 10 as printed, ``J = s_out L (s_out^2 + L^2)/12``, is the polar moment of a
solid s_out x L rectangle: it grows with the beam length and is about 1.5e5 times
Bredt's torsion constant of the 0.1 m x 3 mm tube.  The default here is
:func:`femast.model.sections.square_tube` (Bredt, ``J = t (s_out - t)^3``);
``torsion="printed_eq10"`` uses the printed value for comparison.

Eq. 14 is printed ``C_bi = R_aug C_be bR_b^aug``; the last factor must be the
transpose ``R_aug^T`` (the extraction of the paper lost it): a compliance transforms
as ``R C R^T``.
"""

from __future__ import annotations

import numpy as np

from .._moved import renamed
from ..errors import ModelError
from ..model.sections import Section, rocaspect_eq10_torsion_constant, square_tube
from ._common import check_positive, check_vectors

#: Eq. 13: beam frame -> base frame for a vertical mast (x_be = z_b, y_be = y_b, z_be = -x_b).
R_BE_VERTICAL = np.array([[0.0, 0.0, -1.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]])


def mast_section(
    E: float, nu: float = 0.3, s_out: float = 0.1, s_in: float = 0.094, torsion: str = "bredt", L: float | None = None
) -> Section:
    """Square-tube section of the mast beam (Eqs. 9-11); E in Pa, sides in m.

    ``torsion="bredt"`` (default) uses the correct closed-section torsion constant;
    ``torsion="printed_eq10"`` replaces it with Eq. 10 as printed, which needs the beam length L (m)
    (``"seed_eq10"``, its old name, warns and is removed in femast 0.3).
    G = E / (2 (1 + nu)) as in Section IV-B-2 of the Rocaspect paper.
    """
    if torsion == "seed_eq10":
        renamed("mast_section(torsion='seed_eq10')", "mast_section(torsion='printed_eq10')")
        torsion = "printed_eq10"
    check_positive("Young's modulus E", E, "Pa")
    sec = square_tube(s_out, s_in, E, nu, name="mast beam")
    if torsion == "bredt":
        return sec
    if torsion == "printed_eq10":
        if L is None:
            raise ModelError("torsion='printed_eq10' needs the beam length L (m): Eq. 10 depends on it")
        check_positive("beam length L", L, "m")
        return sec.with_(J=rocaspect_eq10_torsion_constant(s_out, L))
    raise ModelError(f"unknown torsion option {torsion!r}; use 'bredt' or 'printed_eq10'")


def cantilever_compliance_local(L: float, section: Section) -> np.ndarray:
    """Tip compliance C_be (6, 6) of a cantilever of length L (m) in its own frame (Eq. 8).

    Order ``[ux, uy, uz, rx, ry, rz]`` versus ``[Fx, Fy, Fz, Mx, My, Mz]`` with x along the beam;
    units m/N, m/(N m), rad/N, rad/(N m).
    """
    L = float(check_positive("beam length L", L, "m"))
    E, G = section.E, section.G
    C = np.zeros((6, 6))
    C[0, 0] = L / (E * section.A)
    C[1, 1] = L**3 / (3 * E * section.Iz)
    C[1, 5] = C[5, 1] = L**2 / (2 * E * section.Iz)
    C[2, 2] = L**3 / (3 * E * section.Iy)
    C[2, 4] = C[4, 2] = -(L**2) / (2 * E * section.Iy)
    C[3, 3] = L / (G * section.J)
    C[4, 4] = L / (E * section.Iy)
    C[5, 5] = L / (E * section.Iz)
    return C


def beam_rotation(axis=(0.0, 0.0, 1.0)) -> np.ndarray:
    """Rotation bR_be (3, 3) from the beam frame to the base frame, x_be along ``axis``.

    For a vertical axis this is Eq. 13 exactly.  Otherwise y_be is the base y axis made
    orthogonal to the axis (or the base x axis if the beam is along y).
    """
    x = check_vectors("beam axis", axis).reshape(3)
    n = np.linalg.norm(x)
    if n == 0.0:
        raise ModelError("beam axis has zero length; give the direction from base O_i to top C_i3")
    x = x / n
    ref = np.array([0.0, 1.0, 0.0]) if abs(x[1]) < 0.9 else np.array([1.0, 0.0, 0.0])
    y = ref - (ref @ x) * x
    y /= np.linalg.norm(y)
    return np.column_stack([x, y, np.cross(x, y)])


def cantilever_compliance(L: float, section: Section, axis=(0.0, 0.0, 1.0)) -> np.ndarray:
    """Tip compliance C_bi (6, 6) in the base frame, ``R_aug C_be R_aug^T`` (Eqs. 12-14).

    L in m; ``axis`` the beam direction from base to top (default vertical, Eq. 13).
    """
    R = beam_rotation(axis)
    Ra = np.zeros((6, 6))
    Ra[:3, :3] = Ra[3:, 3:] = R
    return Ra @ cantilever_compliance_local(L, section) @ Ra.T


def cantilever_stiffness(L: float, section: Section, axis=(0.0, 0.0, 1.0)) -> np.ndarray:
    """Tip stiffness K_i4 = C_bi^-1 (6, 6) of Eq. 18, in N/m, N/rad, N m/m, N m/rad."""
    return np.linalg.inv(cantilever_compliance(L, section, axis))


def cantilever_compliance_parts(L: float, section: Section, axis=(0.0, 0.0, 1.0)):
    """Split the base-frame compliance as ``C_bi = C_E / E + C_G / G`` (the matrix of Eq. 30).

    Returns ``(C_E, C_G)`` (6, 6): C_E in Pa m/N etc. (bending and axial terms times E),
    C_G in Pa rad/(N m) (the torsion term times G).  ``[C_E dw, C_G dw]`` is the paper's
    identification matrix A_be of Eq. 30 for the unknowns ``[1/E, 1/G]`` (the paper writes
    ``[E, G]``, but the displacements are linear in the compliances 1/E and 1/G, not in E, G).
    """
    unit = section.with_(E=1.0, G=1.0)
    C = cantilever_compliance(L, unit, axis)
    Ra = np.zeros((6, 6))
    Ra[:3, :3] = Ra[3:, 3:] = beam_rotation(axis)
    Cg_local = np.zeros((6, 6))
    Cg_local[3, 3] = float(L) / section.J
    C_G = Ra @ Cg_local @ Ra.T
    return C - C_G, C_G


def displacement_beam(C_b, dw) -> np.ndarray:
    """Top displacement ``dc = C_bi dw`` (Eq. 15) for wrenches dw (..., 6) in N, N m; returns m, rad."""
    return np.asarray(dw, dtype=float) @ np.asarray(C_b).T
