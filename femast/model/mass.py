"""The mass model: element mass matrices of the families, point masses and rigid bodies.

Used by the modal analysis (:mod:`femast.modal.mass` assembles these blocks on the analysis' DOF
numbering and reduces them through its constraints) and by gravity (:mod:`femast.model.gravity`:
the body force of a uniform acceleration is the mass matrix times that acceleration).

Where the mass comes from (all SI):

* corotational beams: the consistent mass of the cubic Euler-Bernoulli beam (Przemieniecki 1968,
  Eq. 11.41) with mass per length ``rho A`` (kg/m, from :attr:`Section.rho` or the beam's
  ``mass_per_length``) and torsional rotary inertia ``rho (Iy + Iz)`` per length (kg m), rotated
  from the element's current corotated frame (the same frame as the stiffness: chord and mean
  nodal y axis), so a prestressed, displaced state has its mass in the right directions;
* trusses: the consistent mass ``m/6 [[2, 1], [1, 2]]`` per translation direction (``m`` = mass
  per length x initial length);
* cables (tension-only trusses) and any family with a ``mass_per_length`` attribute (kg/m; e.g.
  the cable/latch family, whose node rows are the nodes along one cable): lumped, each section's
  ``m' L / 2`` to its two end nodes (translations);
* families with a ``mass_matrices(X0, x, R)`` method: their own (n_el, 6 nn, 6 nn) matrices;
* point masses (:meth:`Model.point_mass`): mass (kg), rotary inertia (kg m^2, about the centre of
  mass, initial global axes, rotated with the node) and an optional centre-of-mass offset (m),
  which couples translation and rotation; a rigid body's mass and inertia is a point mass at its
  reference node.

Lengths are those of the initial geometry: the mass of a section does not change when it
stretches (a pretensioned cable's mass per length is that of the model as drawn).
Rotary inertia on a DOF no element stiffens (e.g. at a truss-only node) is dropped, as the DOF
is not in the model.  Per-element work is batched numba kernels (``cache=True``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit

from ..errors import ModelError


# ------------------------------------------------------------------------------ point masses
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


def _point_mass_matrices(specs, index, R):
    """(n, 6, 6) mass matrices of point masses at their nodes' current rotations R."""
    n = len(specs)
    M = np.zeros((n, 6, 6))
    if n == 0:
        return M
    idx = np.array([index(s.node) for s in specs])
    Rn = R[idx]
    m = np.array([s.mass for s in specs])
    J = np.einsum("nij,njk,nlk->nil", Rn, np.array([s.inertia for s in specs]), Rn)
    c = np.einsum("nij,nj->ni", Rn, np.array([s.offset for s in specs]))
    S = np.zeros((n, 3, 3))
    S[:, 0, 1], S[:, 0, 2], S[:, 1, 2] = -c[:, 2], c[:, 1], -c[:, 0]
    S[:, 1, 0], S[:, 2, 0], S[:, 2, 1] = c[:, 2], -c[:, 1], c[:, 0]
    # v_c = v - S w : T = m/2 |v - S w|^2 + w^T J_c w / 2
    M[:, :3, :3] = m[:, None, None] * np.eye(3)
    M[:, :3, 3:] = -m[:, None, None] * S
    M[:, 3:, :3] = m[:, None, None] * S
    M[:, 3:, 3:] = J - m[:, None, None] * np.einsum("nij,njk->nik", S, S)
    return M


# ------------------------------------------------------------------------------ kernels
@njit(cache=True)
def beam_mass_kernel(nodes, x, R, E0, l0, mass_per_length, rotary_per_length, out):
    """Consistent mass (n, 12, 12) of corotational beams in global axes at configuration (x, R).

    Local matrix (Przemieniecki Eq. 11.41, DOFs u v w tx ty tz per node): axial m/6 [2 1; 1 2],
    torsion I_p/6 [2 1; 1 2], bending m/420 [156 22l 54 -13l; ...] in both planes; m = rho A l,
    I_p = rho (Iy + Iz) l.  Rotated with the current corotated frame (chord, mean nodal y)."""
    n = nodes.shape[0]
    Ml = np.zeros((12, 12))
    Rr = np.zeros((3, 3))
    for e in range(n):
        a, b = nodes[e, 0], nodes[e, 1]
        l = l0[e]
        m = mass_per_length[e] * l
        Ip = rotary_per_length[e] * l
        # current frame
        d0, d1, d2 = x[b, 0] - x[a, 0], x[b, 1] - x[a, 1], x[b, 2] - x[a, 2]
        ln = math.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
        r1 = (d0 / ln, d1 / ln, d2 / ln)
        q = [0.0, 0.0, 0.0]
        for i in range(3):
            for k in range(3):
                q[i] += 0.5 * (R[a, i, k] + R[b, i, k]) * E0[e, k, 1]
        r3 = (r1[1] * q[2] - r1[2] * q[1], r1[2] * q[0] - r1[0] * q[2], r1[0] * q[1] - r1[1] * q[0])
        n3 = math.sqrt(r3[0] ** 2 + r3[1] ** 2 + r3[2] ** 2)
        r3 = (r3[0] / n3, r3[1] / n3, r3[2] / n3)
        r2 = (r3[1] * r1[2] - r3[2] * r1[1], r3[2] * r1[0] - r3[0] * r1[2], r3[0] * r1[1] - r3[1] * r1[0])
        for i in range(3):
            Rr[i, 0], Rr[i, 1], Rr[i, 2] = r1[i], r2[i], r3[i]
        Ml[:, :] = 0.0
        Ml[0, 0] = Ml[6, 6] = m / 3.0
        Ml[0, 6] = Ml[6, 0] = m / 6.0
        Ml[3, 3] = Ml[9, 9] = Ip / 3.0
        Ml[3, 9] = Ml[9, 3] = Ip / 6.0
        c = m / 420.0
        # bending in the local x-y plane: v1, tz1, v2, tz2
        idx = (1, 5, 7, 11)
        sgn = 1.0
        for plane in range(2):
            if plane == 1:  # x-z plane: w1, ty1, w2, ty2 (rotation sign opposite)
                idx = (2, 4, 8, 10)
                sgn = -1.0
            i0, i1, i2, i3 = idx
            Ml[i0, i0] = Ml[i2, i2] = 156.0 * c
            Ml[i1, i1] = Ml[i3, i3] = 4.0 * l * l * c
            Ml[i0, i2] = Ml[i2, i0] = 54.0 * c
            Ml[i1, i3] = Ml[i3, i1] = -3.0 * l * l * c
            Ml[i0, i1] = Ml[i1, i0] = sgn * 22.0 * l * c
            Ml[i2, i3] = Ml[i3, i2] = -sgn * 22.0 * l * c
            Ml[i0, i3] = Ml[i3, i0] = -sgn * 13.0 * l * c
            Ml[i1, i2] = Ml[i2, i1] = sgn * 13.0 * l * c
        # global = blockdiag(Rr) Ml blockdiag(Rr)^T
        for A in range(4):
            for B in range(4):
                for i in range(3):
                    for j in range(3):
                        s = 0.0
                        for k in range(3):
                            for kk in range(3):
                                s += Rr[i, k] * Ml[3 * A + k, 3 * B + kk] * Rr[j, kk]
                        out[e, 3 * A + i, 3 * B + j] = s


@njit(cache=True)
def truss_mass_kernel(nodes, X0, mass_per_length, lumped, out):
    """Truss mass (n, 12, 12): consistent m/6 [2 1; 1 2] per direction, or lumped m/2 at each end
    (``lumped``), m = mass per length x initial length."""
    for e in range(nodes.shape[0]):
        a, b = nodes[e, 0], nodes[e, 1]
        L = math.sqrt((X0[b, 0] - X0[a, 0]) ** 2 + (X0[b, 1] - X0[a, 1]) ** 2 + (X0[b, 2] - X0[a, 2]) ** 2)
        m = mass_per_length[e] * L
        for i in range(3):
            if lumped[e]:
                out[e, i, i] = out[e, 6 + i, 6 + i] = 0.5 * m
            else:
                out[e, i, i] = out[e, 6 + i, 6 + i] = m / 3.0
                out[e, i, 6 + i] = out[e, 6 + i, i] = m / 6.0


@njit(cache=True)
def chain_lumped_mass_kernel(nodes, X0, mass_per_length, out):
    """Lumped mass (n, 6 nn, 6 nn) of cables running through the nodes of each row in order:
    each section's m' L / 2 (L in the initial geometry) to the translations of its two ends."""
    n, nn = nodes.shape
    for e in range(n):
        for s in range(nn - 1):
            a, b = nodes[e, s], nodes[e, s + 1]
            L = math.sqrt((X0[b, 0] - X0[a, 0]) ** 2 + (X0[b, 1] - X0[a, 1]) ** 2 + (X0[b, 2] - X0[a, 2]) ** 2)
            h = 0.5 * mass_per_length[e] * L
            for i in range(3):
                out[e, 6 * s + i, 6 * s + i] += h
                out[e, 6 * (s + 1) + i, 6 * (s + 1) + i] += h


# ------------------------------------------------------------------------------ families
class _MassBlock:
    """Element mass matrices of one family (``nodes`` as the assembler expects)."""

    def __init__(self, name, nodes, matrices):
        self.name, self.nodes, self.matrices = name, np.ascontiguousarray(nodes, np.int64), matrices


def _per_element(value, n, what):
    a = (
        np.broadcast_to(np.asarray(value, dtype=float), (n,)).copy()
        if np.ndim(value) == 0 or np.size(value) == n
        else None
    )
    if a is None:
        raise ModelError(f"{what}: give one value or one per element ({n}); got {np.size(value)}")
    bad = np.flatnonzero(~np.isfinite(a) | (a < 0))
    if bad.size:
        raise ModelError(f"{what} = {a[bad[0]]!r} (element {bad[0]}) must be finite and >= 0 (kg/m)")
    return a


def family_mass_blocks(model, families, x, R, X0):
    """Mass blocks of every element family that carries mass, plus the point masses."""
    from ..elements.beam_corot import BeamFamily
    from ..elements.truss import TrussFamily

    beams = {b.label: b for b in model.beams}
    trusses = {t.label: t for t in model.trusses}
    blocks = []
    for f in families:
        if isinstance(f, BeamFamily) and all(int(l) in beams for l in f.labels):
            specs = [beams[int(l)] for l in f.labels]
            mpl = np.array(
                [
                    s.mass_per_length
                    if getattr(s, "mass_per_length", None) is not None
                    else s.section.rho * s.section.A
                    for s in specs
                ]
            )
            rot = np.array([m / s.section.A * (s.section.Iy + s.section.Iz) for m, s in zip(mpl, specs)])
            if not mpl.any():
                continue
            M = np.zeros((f.n_elements, 12, 12))
            beam_mass_kernel(
                f.nodes,
                np.ascontiguousarray(x),
                np.ascontiguousarray(R),
                np.ascontiguousarray(f.E0),
                np.ascontiguousarray(f.l0, dtype=float),
                mpl,
                rot,
                M,
            )
            blocks.append(_MassBlock(f.name, f.nodes, M))
        elif isinstance(f, TrussFamily) and all(int(l) in trusses for l in f.labels):
            specs = [trusses[int(l)] for l in f.labels]
            mpl = np.array([getattr(s, "mass_per_length", 0.0) or 0.0 for s in specs])
            if not mpl.any():
                continue
            M = np.zeros((f.n_elements, 12, 12))
            truss_mass_kernel(f.nodes, X0, mpl, np.ascontiguousarray(f.tension_only, dtype=np.bool_), M)
            blocks.append(_MassBlock(f.name, f.nodes, M))
        elif hasattr(f, "mass_matrices"):
            M = np.asarray(f.mass_matrices(X0, x, R), dtype=float)
            nn = f.nodes.shape[1]
            if M.shape != (f.n_elements, 6 * nn, 6 * nn) or not np.all(np.isfinite(M)):
                raise ModelError(
                    f"element family '{f.name}': mass_matrices() must return finite (n_el, {6 * nn}, "
                    f"{6 * nn}) matrices (kg, kg m, kg m^2); got shape {M.shape}"
                )
            blocks.append(_MassBlock(f.name, f.nodes, M))
        elif getattr(f, "mass_per_length", None) is not None:
            mpl = _per_element(f.mass_per_length, f.n_elements, f"element family '{f.name}': mass_per_length")
            if not mpl.any():
                continue
            nn = f.nodes.shape[1]
            M = np.zeros((f.n_elements, 6 * nn, 6 * nn))
            chain_lumped_mass_kernel(f.nodes, X0, mpl, M)
            blocks.append(_MassBlock(f.name, f.nodes, M))
    pms = list(getattr(model, "point_masses", []))
    if pms:
        nodes = np.array([[model.index(p.node)] for p in pms], dtype=np.int64)
        blocks.append(_MassBlock("point masses", nodes, _point_mass_matrices(pms, model.index, R)))
    return blocks
