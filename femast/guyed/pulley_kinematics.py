"""Swivel-pulley kinematics of a CDPR cable exit (the Rocaspect paper: "pulley kinematics ... taken into account").

The cable comes up from its winch along the swivel axis ``w`` (unit) of the pulley, enters the
pulley groove at the point D on that axis, wraps the pulley of radius r and leaves towards the
platform anchor B.  The pulley turns about the swivel axis so that its plane contains ``w`` and
B.  With ``h`` the unit vector from the axis towards B, perpendicular to ``w``, the pulley centre
is ``C = D + r h``.  In the plane (h, w) about C, with B at (b_h, b_w), d = |B - C|:

    theta_E = atan2(b_w, b_h) + arccos(r / d)            (exit point E = C + r (cos, sin) theta_E)
    beta = pi - theta_E                                   (wrap angle, rad)
    free length |B - E| = sqrt(d^2 - r^2)

(the cable enters at angle pi, moving along +w, i.e. clockwise in this plane).  r = 0 gives a
point exit A = D and beta = the angle between w and the cable.  SI units: m, rad.
"""

from __future__ import annotations

import numpy as np

from ..errors import ModelError


def swivel_exit(D, w, B, r: float):
    """Exit geometry of cables over swivel pulleys, vectorised over cables.

    D : (m, 3) entry points on the swivel axes, m.  w : (m, 3) unit swivel axes (direction in which
    the cable arrives from its winch).  B : (m, 3) platform anchor points, m.  r : pulley radius, m.

    Returns dict: ``E`` (m, 3) exit points, m; ``C`` (m, 3) pulley centres, m; ``beta`` (m,) wrap
    angles, rad; ``free`` (m,) free cable lengths |B - E|, m; ``u`` (m, 3) unit vectors from E to B;
    ``length`` (m,) cable length from D to B (arc + free), m.
    Raises ModelError when B lies on the swivel axis (the pulley plane is undefined) or inside the
    pulley circle (no tangent: an impossible wrap).
    """
    D = np.asarray(D, float)
    w = np.asarray(w, float)
    B = np.asarray(B, float)
    BD = B - D
    along = np.einsum("ij,ij->i", BD, w)
    perp = BD - along[:, None] * w
    pn = np.linalg.norm(perp, axis=1)
    if np.any(pn <= 1e-9):
        k = int(np.flatnonzero(pn <= 1e-9)[0])
        raise ModelError(
            f"cable {k}: the platform anchor lies on the swivel axis of its pulley: the pulley "
            "plane is undefined; move the pose away from the mast"
        )
    h = perp / pn[:, None]
    C = D + r * h
    bh = pn - r
    bw = along
    d = np.hypot(bh, bw)
    if np.any(d <= r * (1 + 1e-12)):
        k = int(np.flatnonzero(d <= r * (1 + 1e-12))[0])
        raise ModelError(
            f"cable {k}: the platform anchor is {d[k]:.4g} m from the centre of a pulley of radius {r:.4g} m: "
            "no tangent exists (impossible wrap angle)"
        )
    theta = np.arctan2(bw, bh) + np.arccos(np.clip(r / d, -1.0, 1.0))
    beta = np.pi - theta
    E = C + r * (np.cos(theta)[:, None] * h + np.sin(theta)[:, None] * w)
    free = np.sqrt(d * d - r * r)
    u = (B - E) / free[:, None]
    return {"E": E, "C": C, "beta": beta, "free": free, "u": u, "length": free + r * beta}
