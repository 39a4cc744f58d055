"""Deployment kinematics of an ADAM bay (Stohlman & Pellegrino, Sec. II.A, Eq. 1).

With rigid longerons of length l (ball centre to ball centre) between square frames of side b
whose top frame turns by theta_t about the bay axis, a top corner moves on a circle of radius
b / sqrt(2): the square of its horizontal distance to the bottom corner below it is
2 (b^2 / 2)(1 - cos theta_t) = b^2 (1 - cos theta_t), so the height h between the frames obeys

    h^2 = l^2 - b^2 (1 - cos theta_t) = b^2 cos theta_t - (b^2 - l^2)        (Eq. 1)
"""

from __future__ import annotations

import numpy as np

from ..errors import ModelError


def eq1_height(theta, b: float, l: float):
    """Bay height h (m) at twist theta (rad) from Eq. 1; NaN beyond the stowed angle (h^2 < 0,
    with a round-off allowance of 1e-12 b^2)."""
    if not (b > 0 and l > 0):
        raise ModelError(f"eq1_height: b = {b!r} m and l = {l!r} m must be > 0")
    h2 = b**2 * np.cos(np.asarray(theta, dtype=float)) - (b**2 - l**2)
    return np.where(h2 >= -1e-12 * b**2, np.sqrt(np.clip(h2, 0.0, None)), np.nan)


def eq1_twist(h, b: float, l: float):
    """Twist theta_t (rad, >= 0) at which the bay has height h (m), Eq. 1 inverted."""
    if not (b > 0 and l > 0):
        raise ModelError(f"eq1_twist: b = {b!r} m and l = {l!r} m must be > 0")
    c = (np.asarray(h, dtype=float) ** 2 + b**2 - l**2) / b**2
    return np.arccos(np.clip(c, -1.0, 1.0))
