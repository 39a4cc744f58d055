"""The equilibrium of platform, cables and masts at a commanded pose: its residuals and their Newton solve.

:class:`_System` gives the residuals of the unknowns ``z`` = platform translation and small rotation
from the commanded pose (6) and the mast-top displacements (6 per mast) -- the platform's
equilibrium (the Rocaspect paper, Eq. 2), the cable law and the masts' compliance (Eq. 7) -- for one
pose or a batch of unknowns; :func:`_newton` solves one pose (a finite-difference Jacobian, reused
while it contracts fast), :func:`_newton_batch` many poses at once, each with its own Jacobian (the
passes of a trajectory after the first, whose poses start from their own solutions: one residual
evaluation per iteration for all poses instead of one per pose).  Used by
:mod:`femast.guyed.platform_pose`, which documents the model.
"""

from __future__ import annotations

import copy

import numpy as np
from scipy.spatial.transform import Rotation

from ..errors import ModelError
from .cdpr import GRAVITY
from .pulley_kinematics import swivel_exit


def _rot(angles):
    return Rotation.from_euler("xyz", angles).as_matrix()


def _cross(a, b):
    """Row-wise cross product (faster than numpy.cross for these small stacks)."""
    return np.stack(
        [
            a[..., 1] * b[..., 2] - a[..., 2] * b[..., 1],
            a[..., 2] * b[..., 0] - a[..., 0] * b[..., 2],
            a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0],
        ],
        axis=-1,
    )


def _rotvec_batch(V):
    """Rotation matrices (k, 3, 3) of rotation vectors V (k, 3), rad (Rodrigues)."""
    th = np.sqrt(np.einsum("ki,ki->k", V, V))
    K = np.zeros((len(V), 3, 3))
    K[:, 0, 1], K[:, 0, 2], K[:, 1, 2] = -V[:, 2], V[:, 1], -V[:, 0]
    K[:, 1, 0], K[:, 2, 0], K[:, 2, 1] = V[:, 2], -V[:, 1], V[:, 0]
    small = th < 1e-8
    ths = np.where(small, 1.0, th)
    a = np.where(small, 1.0, np.sin(ths) / ths)
    b = np.where(small, 0.5, (1.0 - np.cos(ths)) / ths**2)
    return np.eye(3) + a[:, None, None] * K + b[:, None, None] * (K @ K)


class _System:
    """Residuals of platform + cables + masts at one commanded pose (module note): ``robot`` a
    :class:`~femast.guyed.platform_pose.CableRobot`, ``masts`` a :class:`~femast.guyed.platform_pose.MastSet`,
    ``pose_c`` (6,) m and rad, ``l0`` (m,) unstretched cable lengths (m), ``w_cal`` (n, 6) mast
    wrenches at calibration, ``delta`` (n, 6) nonlinear remainder of the masts (m, rad)."""

    def __init__(self, robot, masts, pose_c, l0, w_cal, delta):
        g = robot.geom
        self.robot, self.g = robot, g
        self.Rc = _rot(pose_c[3:])
        self.tc = np.asarray(pose_c[:3], float)
        self.l0 = l0
        self.C = masts.compliance
        self.w_cal = w_cal
        self.delta = delta
        self.mast = g.mast_of_cable
        self.n = g.n_masts
        self.D0 = g.exit_points
        self.F = g.winch_points
        self.top0 = g.mast_tops
        self.fg = np.array([0.0, 0.0, -g.mass * GRAVITY])
        self.gather = (np.arange(self.n)[:, None] == self.mast[None, :]).astype(float)  # (n, m) cable -> mast
        self.w0 = robot.axes

    def take(self, rows) -> _System:
        """The stacked system of the poses ``rows`` of this one (built by :meth:`stack`)."""
        out = copy.copy(self)
        out.tc, out.Rc, out.l0, out.delta = self.tc[rows], self.Rc[rows], self.l0[rows], self.delta[rows]
        return out

    @staticmethod
    def stack(systems) -> _System:
        """One system of the poses of ``systems`` (same robot, masts and calibration; a row of the
        unknowns per pose): their commanded poses, cable lengths and remainders stacked."""
        out = copy.copy(systems[0])
        out.tc = np.stack([s.tc for s in systems])
        out.Rc = np.stack([s.Rc for s in systems])
        out.l0 = np.stack([np.asarray(s.l0, float) for s in systems])
        out.delta = np.stack([np.asarray(s.delta, float) for s in systems])
        return out

    def state(self, z):
        """Geometry, tensions and mast wrenches for unknowns z (N,) or a batch (k, N)."""
        z = np.asarray(z, float)
        single = z.ndim == 1
        Z = z[None] if single else z
        k = Z.shape[0]
        t = self.tc + Z[:, :3]
        R = _rotvec_batch(Z[:, 3:6]) @ self.Rc  # (k, 3, 3)
        dc = Z[:, 6:].reshape(k, self.n, 6)
        dT, dR = dc[:, self.mast, :3], dc[:, self.mast, 3:]
        D = self.D0 + dT + _cross(dR, self.D0 - self.top0[self.mast])
        w = self.w0 + _cross(dR, self.w0)
        w /= np.linalg.norm(w, axis=-1)[..., None]
        Rb = np.einsum("kij,mj->kmi", R, self.g.anchor_points)
        B = Rb + t[:, None, :]
        m = self.mast.size
        ex = swivel_exit(D.reshape(-1, 3), w.reshape(-1, 3), B.reshape(-1, 3), self.robot.pulley_radius)
        u, E, C = (ex[key].reshape(k, m, 3) for key in ("u", "E", "C"))
        DF = self.F - D
        lDF = np.linalg.norm(DF, axis=-1)
        length = lDF + ex["length"].reshape(k, m)
        tau = self.robot.EA * (length - self.l0) / self.l0
        v = DF / lDF[..., None]
        fp = tau[..., None] * (u + v)  # force of each cable on its pulley (Eq. 7)
        top = self.top0 + dc[:, :, :3]
        mom = _cross(C - top[:, self.mast], fp)
        wr = np.einsum("nm,kmj->knj", self.gather, np.concatenate([fp, mom], axis=-1))
        out = dict(t=t, R=R, dc=dc, tau=tau, u=u, Rb=Rb, E=E, wrench=wr)
        return {key: val[0] for key, val in out.items()} if single else out

    def residual(self, z):
        """Residuals (N,) (or (k, N) for a batch of z) and the state."""
        z = np.asarray(z, float)
        single = z.ndim == 1
        s = self.state(z[None] if single else z)
        f = -(s["tau"][..., None] * s["u"])
        cog = np.einsum("kij,j->ki", s["R"], self.g.cog)
        rp = np.concatenate([f.sum(axis=1) + self.fg, _cross(s["Rb"], f).sum(axis=1) + _cross(cog, self.fg)], axis=1)
        rm = s["dc"] - np.einsum("nij,knj->kni", self.C, s["wrench"] - self.w_cal) - self.delta
        r = np.concatenate([rp, rm.reshape(len(rp), -1)], axis=1)
        if single:
            return r[0], {key: val[0] for key, val in s.items()}
        return r, s


def _jacobian(sys: _System, z):
    """Central finite differences (h = 1e-7: truncation ~h^2, round-off ~1e-16/h relative), all columns
    in one batched evaluation."""
    h = 1e-7
    N = z.size
    Z = np.vstack([z + h * np.eye(N), z - h * np.eye(N)])
    r = sys.residual(Z)[0]
    return (r[:N] - r[N:]).T / (2 * h)


def _newton(sys: _System, z0, J=None, tol=1e-11, max_iter=60, full=False):
    """Newton with a finite-difference Jacobian, reused (from the previous pose of a trajectory, too)
    while it contracts fast and refreshed when it does not.  Returns z, state, iterations, J."""
    z = z0.copy()
    age = 0
    if J is None:
        J = _jacobian(sys, z)
    last = np.inf
    for it in range(max_iter):
        r, s = sys.residual(z)
        dz = np.linalg.solve(J, -r)
        step = np.abs(dz).max()
        if age > 0 and (full or step > 0.8 * last):
            J = _jacobian(sys, z)  # slow contraction: refresh the Jacobian
            age = 0
            dz = np.linalg.solve(J, -r)
            step = np.abs(dz).max()
        z += dz
        age += 1
        last = step
        if step < tol:
            r, s = sys.residual(z)
            return z, s, it + 1, J
    raise ModelError(
        f"platform/cable/mast equilibrium did not converge in {max_iter} iterations (last correction {step:.3g})"
    )


def _jacobian_batch(stk: _System, Z):
    """:func:`_jacobian` of every row of ``Z`` (k, N), pose i of the stacked system ``stk`` at row i:
    (k, N, N), all columns of all poses in one batched evaluation."""
    h = 1e-7
    k, N = Z.shape
    E = h * np.eye(N)
    Zp = np.concatenate([Z[:, None, :] + E, Z[:, None, :] - E], axis=1).reshape(k * 2 * N, N)
    r = stk.take(np.repeat(np.arange(k), 2 * N)).residual(Zp)[0].reshape(k, 2 * N, N)
    return np.transpose(r[:, :N] - r[:, N:], (0, 2, 1)) / (2 * h)


def _newton_batch(stk: _System, Z0, J, tol=1e-11, max_iter=60):
    """:func:`_newton` for the k poses of the stacked system ``stk`` at once (row i of ``Z0`` (k, N)
    and of ``J`` (k, N, N): pose i's start and Jacobian), each pose with its own Jacobian refreshes
    and its own convergence, one batched residual evaluation per iteration.  Returns Z, the
    stacked state, iterations (k,), J; raises ModelError if a pose does not converge."""
    Z, J = np.array(Z0, float), np.array(J, float)
    k = len(Z)
    age = np.zeros(k, int)
    last = np.full(k, np.inf)
    its = np.zeros(k, int)
    active = np.arange(k)
    for it in range(max_iter):
        r = stk.take(active).residual(Z[active])[0]
        dz = np.linalg.solve(J[active], -r[..., None])[..., 0]
        step = np.abs(dz).max(axis=1)
        slow = (age[active] > 0) & (step > 0.8 * last[active])
        if slow.any():  # slow contraction: refresh those poses' Jacobians
            j = active[slow]
            J[j] = _jacobian_batch(stk.take(j), Z[j])
            age[j] = 0
            dz[slow] = np.linalg.solve(J[j], -r[slow][..., None])[..., 0]
            step[slow] = np.abs(dz[slow]).max(axis=1)
        Z[active] += dz
        age[active] += 1
        last[active] = step
        its[active] = it + 1
        active = active[step >= tol]
        if not active.size:
            return Z, stk.residual(Z)[1], its, J
    raise ModelError(
        f"platform/cable/mast equilibrium did not converge in {max_iter} iterations at {active.size} pose(s)"
    )
