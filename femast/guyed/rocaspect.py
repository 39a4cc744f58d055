"""The Rocaspect robot: published values and the geometry assumed where the paper is silent.

Published (the Rocaspect paper)
--------------------
* Frame 8.3 m x 6.8 m x 4.0 m; 4 masts, 2 cables each; platform 1.0 x 1.0 x 0.5 m, 50 kg.
* Beam L = 3.651 m, square tube s_out = 0.1 m, s_in = 0.094 m (Section IV-B-2).
* Initial platform pose [2.65 m, 2.5 m, 1.6 m, 0, 0, 0]; platform height <= 2 m.
* Shroud law x_s = [935353.664, 144.320, -0.000465] (:data:`femast.elements.shroud_law.ROCASPECT_X_S`).
* Table III 3R joint stiffnesses and the identified E of the beam model.

Assumed here (documented choices, not in the paper)
--------------------------------------------------
* Base frame at the foot of mast 1; masts at the corners (0, 0), (8.3, 0), (8.3, 6.8),
  (0, 6.8) m.  Each beam stands on a 0.349 m foot, so its base O_i is at z = 0.349 m and its
  top C_i3 at z = 4.0 m (the frame height) and |O_i C_i3| = L.
* Two point pulleys per mast, 0.1 m from the mast axis along the two frame edges meeting at
  the mast, 0.05 m below the top (z = 3.95 m).  Each cable returns vertically down the mast
  to its winch at z = 0.349 m, so v_ij = -z.
* Platform anchors at the box corners (+-0.5, +-0.5, +-0.25) m, crossed as on CoGiRo: on
  mast 1, cable 11 (pulley on the side of mast 2) goes to the upper corner (+0.5, -0.5,
  +0.25) and cable 12 (pulley on the side of mast 4) to the lower corner (-0.5, +0.5, -0.25);
  the other masts are mirror images about the planes x = 4.15 m and y = 3.4 m.  Among the 64
  corner choices with this symmetry, this one has the largest wrench-feasible workspace on a
  test grid of positions and orientations.
* Tension limits 20 N to 1500 N.
* Three shrouds per mast at 120 deg in plan, shroud 3 pointing away from the workspace and
  tied to the top C_i3 (e_i3 = 0); shrouds 1 and 2 tied 0.25 m lower on the tube wall.  The
  masts are free-standing, so the shrouds are tied to the mast's own foot: lower points D_ir
  on the ground at 0.6 m from the mast axis.  With this radius the complete model's lateral
  compliance at 1200 N is within about 25 % of the 3R model identified by the paper.
"""

from __future__ import annotations

import numpy as np

from ..elements.shroud_law import DyneemaLaw
from .cdpr import CdprGeometry
from .complete_mast import ShroudSet

FRAME = (8.3, 6.8, 4.0)
"""Frame size x, y, z, m."""
L_BEAM = 3.651
"""Beam length, m."""
S_OUT, S_IN = 0.1, 0.094
"""Outer and inner side of the square tube, m."""
PLATFORM_SIZE = (1.0, 1.0, 0.5)
"""Moving-platform box, m."""
PLATFORM_MASS = 50.0
"""Moving-platform mass, kg."""
POSE_0 = np.array([2.65, 2.5, 1.6, 0.0, 0.0, 0.0])
"""Initial pose of the identification trajectory (m, rad)."""
NU = 0.3
"""Poisson's ratio used by the paper to get G from E."""
E_NO_SHROUD = 6.55e10
"""Beam-model E identified without shrouds, Pa."""
E_1200N = 1.55e11
"""Beam-model E identified with 1200 N shroud pretension, Pa (shrouds lumped into E)."""
TABLE_III = {
    # test: (MP mass kg, pretension N or None for detached, k_theta1, k_theta2 in N m/rad)
    "1 and 8": (50.0, 1200.0, 271430.0, 230527.0),
    "2": (24.0, 1200.0, 260912.0, 248326.0),
    "3": (50.0, 800.0, 243201.0, 237652.0),
    "4": (50.0, 400.0, 219668.0, 218580.0),
    "5 and 9": (50.0, 0.0, 51224.0, 52847.0),
    "6": (24.0, 0.0, 42110.0, 56700.0),
    "7 and 10": (50.0, None, 75562.0, 63079.0),
}
"""The Rocaspect paper, Table III, joint stiffnesses (N m/rad; printed as N/m)."""

FOOT_HEIGHT = FRAME[2] - L_BEAM
PULLEY_OFFSET = 0.1
PULLEY_DROP = 0.05
SHROUD_RADIUS = 0.6
SHROUD_DROP = 0.25
_SIGNS = np.array([[-1, -1], [1, -1], [1, 1], [-1, 1]])  # mast corner relative to the frame centre


def mast_bases() -> np.ndarray:
    """Beam base points O_i (4, 3), m."""
    c = np.array([[0, 0], [FRAME[0], 0], [FRAME[0], FRAME[1]], [0, FRAME[1]]], dtype=float)
    return np.column_stack([c, np.full(4, FOOT_HEIGHT)])


def mast_tops() -> np.ndarray:
    """Mast top points C_i3 (4, 3), m."""
    t = mast_bases()
    t[:, 2] = FRAME[2]
    return t


def rocaspect_geometry(tau_min: float = 20.0, tau_max: float = 1500.0, mass: float = PLATFORM_MASS) -> CdprGeometry:
    """CDPR geometry of the 8.3 x 6.8 x 4.0 m Rocaspect set-up (module note); tensions in N, mass in kg."""
    tops = mast_tops()
    hx, hy, hz = (s / 2 for s in PLATFORM_SIZE)
    A, B, F, mast = [], [], [], []
    for i, (sx, sy) in enumerate(_SIGNS):
        a_x = tops[i] + [-sx * PULLEY_OFFSET, 0.0, -PULLEY_DROP]  # pulley towards the neighbour along x
        a_y = tops[i] + [0.0, -sy * PULLEY_OFFSET, -PULLEY_DROP]  # pulley towards the neighbour along y
        # corner signs relative to the mast: -s = far side, +s = near side
        b_x = [-sx * hx, sy * hy, hz]  # far in x, near in y, upper
        b_y = [sx * hx, -sy * hy, -hz]  # near in x, far in y, lower
        for a, b in ((a_x, b_x), (a_y, b_y)):
            A.append(a)
            B.append(b)
            F.append([a[0], a[1], FOOT_HEIGHT])
            mast.append(i)
    return CdprGeometry(
        np.array(A),
        np.array(B),
        np.array(F),
        np.array(mast),
        mast_bases(),
        mast_tops(),
        mass=mass,
        tau_min=tau_min,
        tau_max=tau_max,
    )


def rocaspect_shrouds(mast: int, pretension: float, law: DyneemaLaw | None = None) -> ShroudSet:
    """The three shrouds of mast ``mast`` (0-based) at equal tension ``pretension`` (N) (module note)."""
    top = mast_tops()[mast]
    sx, sy = _SIGNS[mast]
    out = np.arctan2(sy, sx)  # azimuth pointing away from the workspace
    az = out + np.deg2rad([120.0, -120.0, 0.0])
    dirs = np.column_stack([np.cos(az), np.sin(az), np.zeros(3)])
    upper = top + 0.5 * S_OUT * dirs + [0.0, 0.0, -SHROUD_DROP]
    upper[2] = top
    lower = top[None, :] * [1, 1, 0] + SHROUD_RADIUS * dirs
    return ShroudSet(upper, lower, pretension, law=law or DyneemaLaw())


def fig5a_trajectory(n_per_segment: int = 25) -> np.ndarray:
    """Platform trajectory in the spirit of the Rocaspect paper, Fig. 5a, poses (k, 6) in m and rad.

    From POSE_0: a 3.0 m x 1.8 m rectangle at z = 1.6 m (segments along x and y give the
    'wing-like' mast-top paths), then a diagonal climb to the far corner at z = 2.0 m (the
    the paper's height limit) and back (the 'straight diagonal' segment), orientation fixed.
    """
    x0, y0, z0 = POSE_0[:3]
    way = np.array(
        [
            [x0, y0, z0],
            [x0 + 3.0, y0, z0],
            [x0 + 3.0, y0 + 1.8, z0],
            [x0, y0 + 1.8, z0],
            [x0, y0, z0],
            [x0 + 3.0, y0 + 1.8, 2.0],
            [x0, y0, z0],
        ]
    )
    s = np.linspace(0.0, 1.0, n_per_segment, endpoint=False)
    pts = [w0 + s[:, None] * (w1 - w0) for w0, w1 in zip(way[:-1], way[1:])]
    pts.append(way[-1:])
    xyz = np.vstack(pts)
    return np.column_stack([xyz, np.zeros_like(xyz)])
