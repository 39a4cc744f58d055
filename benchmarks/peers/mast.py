"""The elastic 3D truss mast shared by the peer benchmarks (femast and OpenSeesPy build the
same thing from these arrays).

An ``n_bays`` mast with a square cross-section of side ``b`` and bays of height ``h``: frames
j = 0..n at z = j h, four corners each (corner k at polar angle 45 + 90 k degrees).  Members,
all elastic corotational Euler-Bernoulli beam-columns, one element per member:

* longerons (corner k of frame j to corner k of frame j + 1),
* battens (corner k to corner k + 1 of frames 1..n; the base frame is fixed),
* diagonals (corner k of frame j to corner k + 1 of frame j + 1, one per side and bay).

The four base corners are fixed.  The tip frame carries a torque T about z (four tangential
corner forces T / (4 r), r = b / sqrt 2) and a shear S along x (S / 4 per corner), applied in
K equal load increments.  Loads are scaled with the number of bays (T ~ 1/n, S ~ 1/n^2) so
that the tip twist and tip deflection / height stay about the same from 40 to 1000 bays: the
Newton work per increment is comparable and the table measures the cost of size alone.
Loads are dead (fixed directions) in both codes.  SI units.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

E_AL = 70e9
NU = 0.3
G_AL = E_AL / (2 * (1 + NU))


def tube(d_out, d_in):
    """A, Iy = Iz, J of a circular tube (m^2, m^4)."""
    A = np.pi / 4 * (d_out**2 - d_in**2)
    I = np.pi / 64 * (d_out**4 - d_in**4)
    return dict(A=A, Iy=I, Iz=I, J=2 * I)


SECTIONS = {"longeron": tube(0.030, 0.026), "batten": tube(0.025, 0.021), "diagonal": tube(0.012, 0.008)}


@dataclass
class Mast:
    n_bays: int
    X: np.ndarray  # (n_nodes, 3) node coordinates; node label = row + 1
    conn: np.ndarray  # (n_el, 2) node rows
    kind: list  # member kind per element ("longeron", "batten", "diagonal")
    up: np.ndarray  # (n_el, 3) local y direction (femast up-vector, orthogonal to the member)
    fixed: np.ndarray  # node rows fixed in all six DOFs
    tip: np.ndarray  # node rows of the tip frame
    P: np.ndarray  # (n_tip, 3) tip corner forces at full load, N


def build_mast(n_bays: int, b: float = 1.0, h: float = 1.0, torque40: float = 3.0e3, shear40: float = 300.0):
    """The mast arrays.  ``torque40`` (N m) and ``shear40`` (N) are the loads of the 40-bay mast."""
    ang = np.deg2rad(45 + 90 * np.arange(4))
    r = b / np.sqrt(2)
    corners = np.column_stack([r * np.cos(ang), r * np.sin(ang), np.zeros(4)])
    X = np.concatenate([corners + [0, 0, j * h] for j in range(n_bays + 1)])
    node = lambda j, k: 4 * j + (k % 4)  # noqa: E731
    conn, kind, up = [], [], []
    for j in range(n_bays):
        for k in range(4):
            conn.append((node(j, k), node(j + 1, k)))
            kind.append("longeron")
            up.append(corners[k] / r)  # radial
        for k in range(4):
            conn.append((node(j + 1, k), node(j + 1, k + 1)))
            kind.append("batten")
            up.append((0.0, 0.0, 1.0))
        for k in range(4):
            conn.append((node(j, k), node(j + 1, k + 1)))
            kind.append("diagonal")
            n_side = corners[k] + corners[(k + 1) % 4]  # outward normal of side k
            up.append(n_side / np.linalg.norm(n_side))
    scale = 40.0 / n_bays
    T = torque40 * scale
    S = shear40 * scale**2
    tip = np.array([node(n_bays, k) for k in range(4)])
    tangential = np.column_stack([-np.sin(ang), np.cos(ang), np.zeros(4)])
    P = T / (4 * r) * tangential + np.array([S / 4, 0.0, 0.0])
    return Mast(n_bays, X, np.array(conn), kind, np.array(up, float), np.arange(4), tip, P)


def local_frame(x1, x2, up):
    """(e1, e2, e3) of a member: e1 along it, e2 = ``up`` made orthogonal, e3 = e1 x e2."""
    e1 = (x2 - x1) / np.linalg.norm(x2 - x1)
    e2 = up - (up @ e1) * e1
    e2 /= np.linalg.norm(e2)
    return e1, e2, np.cross(e1, e2)
