"""Three-elastic-joint (3R) mast model (the Rocaspect paper, Eqs. 4-7).

The mast is a rigid body hinged at its base O_i by three perpendicular elastic joints
about the base-frame axes i, j, k, of stiffness ``k_theta = [k1, k2, k3]`` in N m/rad
(the paper's Table III prints "N/m"; a rotational joint stiffness is N m/rad).  A
wrench ``dw = [f ; m]`` applied at the top C_i3 (N; N m about C_i3) moves the top by
``dc = [dc_T ; dc_R]`` (m; rad):

    dc = J K^-1 J^T dw                                   (Eqs. 4-5)

Correction to Eq. 6
-------------------
A small rotation ``dtheta`` about the base axis e_k moves the top by
``dtheta e_k x r`` with ``r = O_i C_i3``; the translational block of J must therefore
be ``[i x r, j x r, k x r]``.  The paper prints ``[r x i, r x j, r x k]``, the opposite
sign.  The sign cancels in the force-to-translation block ``J_T K^-1 J_T^T`` but flips
the force/moment coupling blocks, i.e. the tilt of the top produced by a horizontal
force and the top translation produced by a moment.  With the corrected J, ``J^T dw``
is the moment about O_i of the top wrench projected on each joint axis, as statics
requires (``i . (m + r x f)``).  ``printed_sign=True`` reproduces the printed sign for
comparison (``seed_sign=``, its old name, warns and is removed in femast 0.3).
"""

from __future__ import annotations

import numpy as np

from .._moved import renamed
from ._common import check_positive, check_vectors


def printed_sign_of(printed_sign: bool, seed_sign: bool | None, where: str) -> bool:
    """``printed_sign``, or the old keyword ``seed_sign`` of ``where`` with its DeprecationWarning."""
    if seed_sign is None:
        return bool(printed_sign)
    renamed(f"{where}(seed_sign=...)", f"{where}(printed_sign=...)", stacklevel=4)
    return bool(seed_sign)


def jacobian_3r(r_oc, printed_sign: bool = False, *, seed_sign: bool | None = None) -> np.ndarray:
    """Mast Jacobian J (6, 3) of Eq. 6 (corrected sign, see module note).

    r_oc : (3,) vector from the base O_i to the top C_i3, m.
    Column k maps a unit joint rotation (rad) about base axis e_k to the top twist
    ``[e_k x r_oc ; e_k]`` (m/rad; rad/rad).
    """
    printed_sign = printed_sign_of(printed_sign, seed_sign, "jacobian_3r")
    r = check_vectors("r_oc (vector from mast base O_i to top C_i3)", r_oc).reshape(3)
    E = np.eye(3)
    top = np.cross(r, E) if printed_sign else np.cross(E, r)  # rows: e_k x r (or r x e_k)
    return np.vstack([top.T, E])


def compliance_3r(k_theta, r_oc, printed_sign: bool = False, *, seed_sign: bool | None = None) -> np.ndarray:
    """Compliance C_theta = J K_theta^-1 J^T (6, 6) of Eq. 5, in m/N, m/(N m), rad/N, rad/(N m).

    k_theta : (3,) joint stiffnesses about the base x, y, z axes, N m/rad; ``np.inf`` makes a
        joint rigid (e.g. the torsion joint, which the paper could not identify).
    r_oc : (3,) vector O_i C_i3, m.
    """
    printed_sign = printed_sign_of(printed_sign, seed_sign, "compliance_3r")
    k = check_positive("3R joint stiffness k_theta", k_theta, "N m/rad", allow_inf=True).reshape(3)
    J = jacobian_3r(r_oc, printed_sign)
    return (J / k) @ J.T


def displacement_3r(k_theta, r_oc, dw, printed_sign: bool = False, *, seed_sign: bool | None = None) -> np.ndarray:
    """Top displacement ``dc = C_theta dw`` (Eq. 4) for wrenches dw (..., 6) in N, N m; returns m, rad."""
    printed_sign = printed_sign_of(printed_sign, seed_sign, "displacement_3r")
    return np.asarray(dw, dtype=float) @ compliance_3r(k_theta, r_oc, printed_sign).T
