"""Pose of a CDPR platform carried by compliant masts (the Rocaspect paper, Fig. 7).

The controller works in a rigid frame: for the commanded pose ``p_c`` it computes, with the
exit geometry measured at calibration, the cable lengths (with the swivel-pulley kinematics of
:mod:`.pulley_kinematics`) and a tension distribution ``tau_c`` (Eq. 2, tension limits), and
winds each cable to the unstretched length ``l0_j = l_j(p_c) / (1 + tau_c,j / EA)``.  In the
rigid frame the platform would sit exactly at ``p_c``.  The real masts deflect under the cable
wrenches (Eq. 7), their tops carry the pulleys, the exit points move, and the platform settles at
the pose ``p`` where platform, cables and masts are in equilibrium together:

* platform (Eq. 2): ``sum_j tau_j (-u_j) + m g = 0`` and the moments about its origin;
* cables: ``tau_j = EA (l_j - l0_j) / l0_j``, ``l_j = |D_j - F_j| + r beta_j + |B_j - E_j|``
  (winch F_j to the swivel entry D_j, wrap, free span to the anchor B_j);
* masts: ``dc_i = C_i (w_i - w_i,cal) + delta_i`` -- the top displacement (m, rad) of a linear
  compliance model (3R Eqs. 4-6, cantilever Eqs. 8-15, beam + shrouds Eqs. 16-26) or of the FE
  guyed mast (its condensed tangent plus the nonlinear remainder ``delta_i`` from the FE run),
  relative to the calibration state; ``w_i`` the wrench of its cables on the pulleys (Eq. 7, moments
  about the displaced top).  The pulley entry D_j and swivel axis move with the mast top.

Unknowns: the platform translation and small rotation from ``p_c`` (6) and the mast top
displacements (6 per mast); Newton with a finite-difference Jacobian (the system is small and
smooth), continued along a trajectory.  Output: the pose error ``p - p_c`` (what the rigid-frame
controller does not see), the tensions, and the exit points at equilibrium (what a controller
should use instead of the calibrated ones).

Assumptions (not in the paper): steel cables of EA = 1.0e6 N (about 4 mm), swivel pulleys of
radius 0.03 m with vertical axes through the calibrated exit points, cables returning vertically to
winches at the mast feet (as :mod:`.rocaspect`).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field

import numpy as np
from scipy.spatial.transform import Rotation

from ..errors import ModelError
from ._common import fmt_pose
from .cdpr import CdprGeometry, tension_distribution
from .pose_equilibrium import _jacobian_batch, _newton, _newton_batch, _rot, _System
from .pulley_kinematics import swivel_exit

CABLE_EA = 1.0e6
"""Assumed axial rigidity of the Rocaspect cables, N (about a 4 mm steel rope)."""
PULLEY_RADIUS = 0.03
"""Assumed swivel-pulley radius, m."""


@dataclass(frozen=True)
class CableRobot:
    """A CDPR whose exit pulleys sit on masts.

    geom : :class:`~.cdpr.CdprGeometry`; its ``exit_points`` are the swivel entry points D_j as
        calibrated (m) and ``winch_points`` the winches F_j (m).
    EA : cable axial rigidity, N.  pulley_radius : m (0: point exits, the Rocaspect paper, Eq. 1).
    """

    geom: CdprGeometry
    EA: float = CABLE_EA
    pulley_radius: float = PULLEY_RADIUS

    def __post_init__(self):
        if not (np.isfinite(self.EA) and self.EA > 0):
            raise ModelError(f"cable EA = {self.EA!r} N must be finite and > 0")
        if not (np.isfinite(self.pulley_radius) and self.pulley_radius >= 0):
            raise ModelError(f"pulley radius = {self.pulley_radius!r} m must be finite and >= 0")

    @property
    def axes(self) -> np.ndarray:
        """Unit swivel axes (m, 3): from the winch up to the pulley."""
        d = self.geom.exit_points - self.geom.winch_points
        return d / np.linalg.norm(d, axis=1)[:, None]


@dataclass
class MastSet:
    """The masts of the robot as seen by the platform solve.

    name : label.  compliance : (n, 6, 6) top compliances (m/N, ... rad/(N m)), about each top,
    base axes; zeros for rigid masts.  fe : optional list of :class:`~.fe_mast.MastFE` (one per
    mast, equilibrated) whose nonlinear response replaces the linear one (``compliance`` is then
    their condensed tangent)."""

    name: str
    compliance: np.ndarray
    fe: list | None = None


@dataclass
class PoseSolution:
    """Equilibrium at one commanded pose (SI: m, rad, N).

    pose : (6,) actual pose [x, y, z, roll, pitch, yaw].  error : (6,) [dx, dy, dz] (m) and the
    rotation vector of R R_c^T (rad).  tension : (m,) N.  exit_points : (m, 3) exit points E_j at
    equilibrium, m.  top_displacement : (n, 6) mast tops from calibration (m, rad).  wrench : (n, 6)
    cable wrenches on the masts (N, N m).  feasible : False when no tension distribution exists or
    a cable would go slack; ``reason`` says which.
    """

    pose: np.ndarray
    error: np.ndarray
    tension: np.ndarray
    exit_points: np.ndarray
    top_displacement: np.ndarray
    wrench: np.ndarray
    feasible: bool = True
    reason: str = ""
    iterations: int = 0


def controller(robot: CableRobot, pose_c, tau=None, method: str = "barycenter"):
    """What the rigid-frame controller sets at the commanded pose: the rigid exit geometry, the tension
    distribution (Eq. 2 with the swivel-pulley exit points and the tension limits, or ``tau`` given, N)
    and the unstretched cable lengths l0 (m).  Raises ModelError when no distribution exists."""
    g = robot.geom
    p = np.asarray(pose_c, float)
    R = _rot(p[3:])
    B = g.anchor_points @ R.T + p[:3]
    ex = swivel_exit(g.exit_points, robot.axes, B, robot.pulley_radius)
    if tau is None:
        gE = dataclasses.replace(g, exit_points=ex["E"], winch_points=g.winch_points + (ex["E"] - g.exit_points))
        tau = tension_distribution(gE, p, method=method).tau
    tau = np.asarray(tau, float)
    if tau.shape != (g.n_cables,) or np.any(~np.isfinite(tau)):
        raise ModelError(f"give one finite tension (N) per cable ({g.n_cables}); got {tau!r}")
    if np.any(tau <= 0):
        raise ModelError(f"commanded tensions {tau} N: a cable cannot push (tension must be > 0 N)")
    length = np.linalg.norm(g.winch_points - g.exit_points, axis=1) + ex["length"]
    return tau, length / (1.0 + tau / robot.EA)


def rigid_masts(n: int = 4) -> MastSet:
    """Rigid masts (zero compliance)."""
    return MastSet("rigid", np.zeros((n, 6, 6)))


def solve_pose(
    robot: CableRobot,
    masts: MastSet,
    pose_c,
    *,
    tau=None,
    w_cal=None,
    delta=None,
    z0=None,
    method: str = "barycenter",
    J=None,
    control=None,
) -> PoseSolution:
    """Equilibrium of platform, cables and masts at the commanded pose ``pose_c`` ([x, y, z] m, angles rad).

    tau : commanded tensions (N) or None (Eq. 2 distribution).  w_cal : (n, 6) mast wrenches at
    calibration (default: zero, i.e. displacements from the unloaded masts).  delta : (n, 6) nonlinear
    remainder of FE masts (m, rad).  z0 : start (from the previous pose of a trajectory, or the same
    pose in the previous pass).  J : a Jacobian of the unknowns to start from.  control : what
    :func:`controller` returned for this pose (it depends on the commanded pose and tensions only;
    a trajectory computes it once per pose for all its passes).
    An infeasible pose is returned with ``feasible=False`` and the reason, not raised."""
    g = robot.geom
    p = np.asarray(pose_c, float).ravel()
    if p.size == 3:
        p = np.concatenate([p, np.zeros(3)])
    if p.size != 6 or not np.all(np.isfinite(p)):
        raise ModelError(f"commanded pose {pose_c!r} must be [x, y, z] (m) or [x, y, z, roll, pitch, yaw] (m, rad)")
    n = g.n_masts
    C = np.asarray(masts.compliance, float)
    if C.shape != (n, 6, 6):
        raise ModelError(f"mast set '{masts.name}': compliance must be ({n}, 6, 6), one per mast; got {C.shape}")
    nan = np.full(6, np.nan)
    if tau is not None:
        tau = np.asarray(tau, float)
        if tau.shape != (g.n_cables,) or np.any(~np.isfinite(tau)) or np.any(tau <= 0):
            raise ModelError(
                f"commanded tensions {tau} N: give one finite tension > 0 N per cable ({g.n_cables}); "
                "a cable cannot push"
            )
    try:
        tau_c, l0 = controller(robot, p, tau, method) if control is None else control
        if isinstance(tau_c, ModelError):
            raise tau_c
    except ModelError as exc:
        return PoseSolution(
            nan,
            nan,
            np.full(g.n_cables, np.nan),
            np.full((g.n_cables, 3), np.nan),
            np.full((n, 6), np.nan),
            np.full((n, 6), np.nan),
            False,
            str(exc),
        )
    sys = _system(robot, masts, p, l0, w_cal, delta)
    start = np.zeros(6 + 6 * n) if z0 is None else z0
    try:
        z, s, it, J = _newton(sys, start, J)
    except (ModelError, np.linalg.LinAlgError):
        z, s, it, J = _newton(sys, np.zeros(6 + 6 * n), None, full=True)  # plain Newton from the commanded pose
    return _solution(g, p, z, s, it, J)


def _system(robot, masts, p, l0, w_cal, delta) -> _System:
    n = robot.geom.n_masts
    return _System(
        robot, masts, p, l0, np.zeros((n, 6)) if w_cal is None else w_cal, np.zeros((n, 6)) if delta is None else delta
    )


def _solution(g, p, z, s, it, J) -> PoseSolution:
    """The pose solution of the converged unknowns ``z`` and state ``s`` at commanded pose ``p``."""
    rotvec = z[3:6]
    pose = np.concatenate([s["t"], Rotation.from_matrix(s["R"]).as_euler("xyz")])
    sol = PoseSolution(pose, np.concatenate([z[:3], rotvec]), s["tau"], s["E"], s["dc"], s["wrench"], True, "", it)
    sol._z, sol._J = z, J
    if np.any(s["tau"] <= 0):
        k = int(np.argmin(s["tau"]))
        sol.feasible = False
        sol.reason = (
            f"cable {g.labels[k]} goes slack (tension {s['tau'][k]:.3g} N) at the equilibrium reached from "
            f"the commanded pose ({fmt_pose(p)}): the cables cannot hold the platform there"
        )
    return sol


@dataclass
class TrajectoryResult:
    """Pose errors along a trajectory (k poses).  commanded (k, 6); pose (k, 6); error (k, 6) (m, rad);
    tension (k, m) N; exit_points (k, m, 3) m; top_displacement (k, n, 6); feasible (k,) bool;
    reasons (list of str); fe_passes: number of FE corrections (0 for linear masts)."""

    commanded: np.ndarray
    pose: np.ndarray
    error: np.ndarray
    tension: np.ndarray
    exit_points: np.ndarray
    top_displacement: np.ndarray
    wrench: np.ndarray
    feasible: np.ndarray
    reasons: list = field(default_factory=list)
    fe_passes: int = 0

    @property
    def position_error(self) -> np.ndarray:
        """|dx, dy, dz| per pose, m."""
        return np.linalg.norm(self.error[:, :3], axis=1)

    @property
    def orientation_error(self) -> np.ndarray:
        """|rotation vector| per pose, rad."""
        return np.linalg.norm(self.error[:, 3:], axis=1)


def _controls(robot, poses, tau, method) -> list:
    """:func:`controller` at every pose of a trajectory: ``(tau_c, l0)``, or ``(error, None)`` where it
    has no tension distribution (the pose is then infeasible in every pass)."""
    out = []
    for k, p in enumerate(poses):
        try:
            out.append(controller(robot, p, None if tau is None else tau[k], method))
        except ModelError as exc:
            out.append((exc, None))
    return out


def _pass(robot, masts, poses, tau, w_cal, delta, method, progress, controls, previous=None):
    """One pass along the trajectory.  All poses at once (:func:`~femast.guyed.pose_equilibrium._newton_batch`:
    one batched residual evaluation per iteration) when the controller holds every pose: each pose
    from its commanded pose or, given the ``previous`` pass, from its own solution there (the passes
    differ by a small remainder).  Else, or if that does not converge, and with a ``progress`` bar,
    pose by pose, each from the previous pose's solution."""
    if progress is None and all(c[1] is not None for c in controls):
        if previous is None or all(s.feasible for s in previous):
            batch = _batch_pass(robot, masts, poses, w_cal, delta, controls, previous)
            if batch is not None:
                return batch
    sols = []
    z = J = None
    it = poses if progress is None else progress(poses)
    for k, p in enumerate(it):
        if previous is not None and previous[k].feasible:
            z, J = previous[k]._z, previous[k]._J
        s = solve_pose(
            robot,
            masts,
            p,
            tau=None if tau is None else tau[k],
            w_cal=w_cal,
            delta=None if delta is None else delta[k],
            z0=z,
            method=method,
            J=J,
            control=controls[k],
        )
        if s.feasible:
            z, J = s._z, s._J
        sols.append(s)
    return sols


def _batch_pass(robot, masts, poses, w_cal, delta, controls, previous):
    """The poses of a pass solved together, from their solutions in the ``previous`` pass or (None)
    from their commanded poses; None when that does not converge (the caller then solves them one
    by one)."""
    systems = [
        _system(robot, masts, np.asarray(p, float), l0, w_cal, None if delta is None else delta[k])
        for k, (p, (_, l0)) in enumerate(zip(poses, controls))
    ]
    stk = _System.stack(systems)
    try:
        if previous is None:
            Z0 = np.zeros((len(systems), 6 + 6 * robot.geom.n_masts))
            J0 = _jacobian_batch(stk, Z0)
        else:
            Z0, J0 = np.array([s._z for s in previous]), np.array([s._J for s in previous])
        Z, st, its, J = _newton_batch(stk, Z0, J0)
    except (ModelError, np.linalg.LinAlgError):
        return None
    out = []
    for k, p in enumerate(poses):
        sol = _solution(robot.geom, np.asarray(p, float), Z[k], {key: v[k] for key, v in st.items()}, int(its[k]), J[k])
        out.append(sol)
    return out


def _fe_response(masts: MastSet):
    def response(hist, w_cal):
        out = np.empty_like(hist)
        for i, fe in enumerate(masts.fe):
            run = fe.run_wrenches(np.vstack([w_cal[i], hist[:, i]]))
            out[:, i] = run["u"][1:] - run["u"][0]
        return out

    return response


def pose_trajectory(
    robot: CableRobot,
    masts: MastSet,
    poses,
    *,
    tensions=None,
    calibrate=None,
    method: str = "barycenter",
    response=None,
    fe_tol: float = 1e-6,
    max_fe_passes: int = 6,
    progress=None,
) -> TrajectoryResult:
    """Pose errors along ``poses`` (k, 3|6).  The exit geometry is calibrated at ``calibrate`` (default
    the first pose): the masts' displacements are counted from their state there.  tensions : (k, m)
    commanded tensions, N, or None (Eq. 2).

    Nonlinear masts: ``response(w_hist, w_cal) -> dc (k, n, 6)`` gives the top displacements (m, rad)
    for the wrench history ``w_hist`` (k, n, 6) from the calibration wrenches ``w_cal`` (n, 6); FE
    masts (``masts.fe``) bring their own.  The first pass uses the linear ``masts.compliance``; then
    the remainder ``response - C (w - w_cal)`` is fed back and the pass repeated until the tops move
    by less than ``fe_tol`` (m, rad; 1 um is 1e-4 of the pose errors of the Rocaspect).  progress : e.g. ``tqdm`` (wrapper of an iterable) or None."""
    poses = np.atleast_2d(np.asarray(poses, float))
    if poses.shape[1] == 3:
        poses = np.hstack([poses, np.zeros((len(poses), 3))])
    if tensions is not None:
        tensions = np.asarray(tensions, float)
        if tensions.shape != (len(poses), robot.geom.n_cables):
            raise ModelError(
                f"tensions must be (k, m) = ({len(poses)}, {robot.geom.n_cables}) in N; got {tensions.shape}"
            )
    cal = poses[0] if calibrate is None else np.asarray(calibrate, float)
    # the calibration state: the wrench the masts carry at the calibration pose (rigid-frame model)
    c0 = solve_pose(
        robot,
        rigid_masts(robot.geom.n_masts),
        cal,
        method=method,
        tau=None if (tensions is None or calibrate is not None) else tensions[0],
    )
    if not c0.feasible:
        raise ModelError(f"the calibration pose is infeasible: {c0.reason}")
    w_cal = c0.wrench
    delta = None
    controls = _controls(robot, poses, tensions, method)
    sols = _pass(robot, masts, poses, tensions, w_cal, delta, method, progress, controls)
    passes = 0
    if masts.fe is not None and response is None:
        response = _fe_response(masts)
    if response is not None:
        # Each pass feeds back the remainder of the nonlinear response over the compliance in use.  That
        # compliance is updated by the secant least-squares fit of the response to the wrench changes, so
        # the remainder is the nonlinear part only (a remainder that is a whole extra compliance, e.g. a
        # mast-top effect, would otherwise be amplified by the cable stiffness and diverge).
        lin = MastSet(masts.name, masts.compliance.copy(), masts.fe)
        dc_prev = None
        for passes in range(1, max_fe_passes + 1):
            wr = np.array([s.wrench for s in sols])
            ok = np.array([s.feasible for s in sols])
            hist = np.where(ok[:, None, None], wr, w_cal[None])
            dw = hist - w_cal
            dc = response(hist, w_cal)
            for i in range(dw.shape[1]):
                rem = dc[:, i] - dw[:, i] @ lin.compliance[i].T
                scale = np.abs(dw[:, i]).max()
                if scale > 0:
                    A = np.linalg.lstsq(dw[:, i] / scale, rem, rcond=1e-8)[0].T / scale
                    lin.compliance[i] += A
            delta = dc - np.einsum("nij,knj->kni", lin.compliance, dw)
            change = np.inf if passes == 1 else np.abs(dc - dc_prev).max()
            dc_prev = dc
            if change < fe_tol:
                break  # the tops of the last pass are those of the response: converged
            sols = _pass(robot, lin, poses, tensions, w_cal, delta, method, progress, controls, sols)
    pick = lambda key: np.array([getattr(s, key) for s in sols])  # noqa: E731
    return TrajectoryResult(
        poses,
        pick("pose"),
        pick("error"),
        pick("tension"),
        pick("exit_points"),
        pick("top_displacement"),
        pick("wrench"),
        pick("feasible"),
        [s.reason for s in sols],
        passes,
    )
