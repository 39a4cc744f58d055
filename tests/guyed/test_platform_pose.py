"""CDPR platform pose on compliant masts (femast.guyed.platform_pose; the Rocaspect paper, Fig. 7)."""

import math

import numpy as np
import pytest

from femast.errors import ModelError
from femast.guyed.mast_sets import mast_set, masts_3r
from femast.guyed.platform_pose import CableRobot, MastSet, pose_trajectory, rigid_masts, solve_pose
from femast.guyed.pulley_kinematics import swivel_exit
from femast.guyed.rocaspect import POSE_0, fig5a_trajectory, rocaspect_geometry

ROBOT = CableRobot(rocaspect_geometry())
TRAJ = fig5a_trajectory(4)


def random_rotation(seed):
    q = np.random.default_rng(seed).standard_normal(4)
    q /= np.linalg.norm(q)
    w, x, y, z = q
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )


# ---------------------------------------------------------------- pulley kinematics
@pytest.mark.parametrize("seed", [0, 5])
def test_swivel_exit_closed_form(seed):
    """Anchor level with the pulley centre, L beyond it: the cable comes up the axis, wraps
    pi - arccos(r/L) and leaves at angle arccos(r/L) from the horizontal (tangent from an external point)."""
    Q = random_rotation(seed)
    r, L = 0.05, 2.0
    D = np.array([[0.3, 0.1, 1.0]])
    w = (Q @ [0, 0, 1.0])[None]
    hdir = Q @ [1.0, 0, 0]
    B = D + (r + L) * hdir
    ex = swivel_exit(D, w, B, r)
    th = math.acos(r / L)
    np.testing.assert_allclose(ex["C"], D + r * hdir, atol=1e-15)
    np.testing.assert_allclose(ex["E"], D + r * hdir + r * (math.cos(th) * hdir + math.sin(th) * w[0]), atol=1e-14)
    assert ex["beta"][0] == pytest.approx(math.pi - th, abs=1e-14)
    assert ex["free"][0] == pytest.approx(math.sqrt(L * L - r * r), rel=1e-14)
    # tangency: the free span is perpendicular to the radius at E
    assert abs((B[0] - ex["E"][0]) @ (ex["E"][0] - ex["C"][0])) < 1e-14


def test_point_exit_limit_and_bad_geometry():
    D = np.array([[0.0, 0, 0]])
    w = np.array([[0.0, 0, 1]])
    B = np.array([[1.0, 0.5, -2.0]])
    ex = swivel_exit(D, w, B, 0.0)
    np.testing.assert_allclose(ex["E"], D, atol=0)
    assert ex["length"][0] == pytest.approx(np.linalg.norm(B - D), rel=1e-15)
    with pytest.raises(ModelError, match="on the swivel axis"):
        swivel_exit(D, w, np.array([[0.0, 0, -3.0]]), 0.03)
    with pytest.raises(ModelError, match="impossible wrap angle"):
        swivel_exit(D, w, np.array([[0.03, 0, 0.001]]), 0.03)


# ---------------------------------------------------------------- consistency
def test_rigid_masts_give_zero_error():
    res = pose_trajectory(ROBOT, rigid_masts(), TRAJ)
    assert res.feasible.all()
    # Newton to 1e-11 m/rad on the platform; the rigid frame is the controller's own model
    assert np.abs(res.error).max() < 1e-10
    np.testing.assert_allclose(res.pose, TRAJ, atol=1e-10)


def test_equilibrium_holds_and_calibration_pose_has_no_error():
    m = masts_3r(1200.0)
    res = pose_trajectory(ROBOT, m, TRAJ)
    assert np.abs(res.error[0]).max() < 1e-10  # calibrated there
    k = 7
    # platform equilibrium recomputed from the outputs (Eq. 2): cables along E -> B plus gravity
    from scipy.spatial.transform import Rotation

    R = Rotation.from_euler("xyz", res.pose[k, 3:]).as_matrix()
    B = ROBOT.geom.anchor_points @ R.T + res.pose[k, :3]
    u = (B - res.exit_points[k]) / np.linalg.norm(B - res.exit_points[k], axis=1)[:, None]
    f = -(res.tension[k][:, None] * u)
    F = f.sum(axis=0) + [0, 0, -ROBOT.geom.mass * 9.81]
    M = np.cross(B - res.pose[k, :3], f).sum(axis=0)
    assert np.abs(F).max() < 1e-6 and np.abs(M).max() < 1e-6  # N, N m: Newton tolerance 1e-11 m x 2e5 N/m
    # and the masts: dc = C (w - w_cal) for the linear model
    assert res.position_error[k] > 1e-3  # a real effect (mm level): the check above is not vacuous


def test_small_compliance_agrees_with_linearisation_to_second_order():
    """Scale the 3R compliance by eps: the pose error is eps e1 + O(eps^2), so halving eps halves the
    error to first order and quarters the remainder e(eps) - 2 e(eps/2)."""
    base = masts_3r(1200.0).compliance
    pose = TRAJ[9]

    def err(eps):
        res = pose_trajectory(ROBOT, MastSet("scaled", eps * base), np.vstack([TRAJ[0], pose]))
        return res.error[1]

    # the expansion parameter is eps x (cable stiffness / mast stiffness ~ 100): eps <= 2e-3 keeps it <= 0.2
    e = {eps: err(eps) for eps in (2e-3, 1e-3, 5e-4)}
    d1 = np.abs(e[2e-3] - 2 * e[1e-3]).max()
    d2 = np.abs(e[1e-3] - 2 * e[5e-4]).max()
    assert np.abs(e[5e-4]).max() > 1000 * d2  # the first-order term dominates
    assert d1 / d2 == pytest.approx(4.0, rel=0.05)  # second order (5 %: third-order terms ~0.2 x, Newton 1e-11 m)


def test_models_order_and_pretension_trend():
    """More shroud pretension stiffens the 3R masts (Table III) and shrinks the pose error."""
    errs = [pose_trajectory(ROBOT, masts_3r(p), TRAJ).position_error.max() for p in (400.0, 1200.0)]
    assert errs[1] < errs[0]


# ---------------------------------------------------------------- bad input / infeasible poses
def test_pose_the_cables_cannot_hold_is_reported():
    s = solve_pose(ROBOT, rigid_masts(), [4.15, 3.4, 3.9])  # just under the pulleys: no tension distribution
    assert not s.feasible
    assert "no cable tension distribution" in s.reason
    res = pose_trajectory(ROBOT, rigid_masts(), np.vstack([POSE_0, [4.15, 3.4, 3.9, 0, 0, 0], POSE_0]))
    np.testing.assert_array_equal(res.feasible, [True, False, True])
    assert np.isnan(res.error[1]).all() and np.abs(res.error[2]).max() < 1e-10


def test_bad_inputs():
    with pytest.raises(ModelError, match="commanded pose"):
        solve_pose(ROBOT, rigid_masts(), [1.0, 2.0])
    with pytest.raises(ModelError, match="one per mast"):
        solve_pose(ROBOT, MastSet("x", np.zeros((3, 6, 6))), POSE_0)
    with pytest.raises(ModelError, match="cannot push"):
        solve_pose(ROBOT, rigid_masts(), POSE_0, tau=-np.ones(8))
    with pytest.raises(ModelError, match="unknown mast model"):
        mast_set("truss", 0.0)
    with pytest.raises(ModelError, match="Table III"):
        masts_3r(500.0)
    with pytest.raises(ModelError, match="pulley radius"):
        CableRobot(rocaspect_geometry(), pulley_radius=-0.1)


def test_docs_page_examples_run(tmp_path):
    from doc_examples import run_python_blocks

    run_python_blocks("platform_pose.md", cwd=tmp_path)


def test_fe_masts_converge_and_agree_with_the_complete_model():
    """FE guyed masts (nonlinear, fed back through secant passes) against the linear beam + shroud model at
    1200 N on a short path: the passes converge and the errors agree within 15 % (the FE adds the beam's
    geometric stiffness and the shrouds' progressive law, a few percent at 1200 N)."""
    traj = fig5a_trajectory(2)[:5]
    fe = pose_trajectory(ROBOT, mast_set("FE", 1200.0), traj)
    lin = pose_trajectory(ROBOT, mast_set("beam+shroud", 1200.0), traj)
    assert 1 <= fe.fe_passes < 6 and fe.feasible.all()
    np.testing.assert_allclose(fe.position_error[1:], lin.position_error[1:], rtol=0.15)


def test_passes_solve_all_poses_at_once_to_the_same_equilibria(monkeypatch):
    """A trajectory with a nonlinear mast response is solved in passes.  Without a progress bar every
    pass solves all its poses at once (one batched residual evaluation per Newton iteration), the
    first from the commanded poses, the others each pose from its own solution in the pass before;
    with one, pose by pose, each from the previous pose's solution: the same equilibria, in far fewer
    evaluations.  The response is a stiffening spring written for the test: C w (1 - |w| / w_s)."""
    import femast.guyed.pose_equilibrium as pe

    lin = masts_3r(1200.0)
    w_s = 4e4  # N: the compliance falls by a few % at the wrenches of this trajectory

    def response(hist, w_cal):
        dw = hist - w_cal
        scale = 1.0 - np.linalg.norm(dw[..., :3], axis=-1, keepdims=True) / w_s
        return np.einsum("nij,knj->kni", lin.compliance, dw) * scale

    calls = []
    residual = pe._System.residual
    monkeypatch.setattr(pe._System, "residual", lambda self, z: calls.append(1) or residual(self, z))
    batched = pose_trajectory(ROBOT, lin, TRAJ, response=response)
    n_batched = len(calls)
    calls.clear()
    one_by_one = pose_trajectory(ROBOT, lin, TRAJ, response=response, progress=list)
    n_single = len(calls)
    assert batched.fe_passes >= 2 and batched.fe_passes == one_by_one.fe_passes
    assert batched.feasible.all() and np.abs(batched.pose - one_by_one.pose).max() < 1e-9  # m, rad: converged both
    assert np.abs(batched.error[1:, :3]).max() > 1e-3  # a mm-level pose error: the comparison is not vacuous
    assert n_batched < 0.3 * n_single
    # the linear masts too: one pass, all poses at once
    calls.clear()
    lin_batched = pose_trajectory(ROBOT, lin, TRAJ)
    n_batched = len(calls)
    calls.clear()
    lin_single = pose_trajectory(ROBOT, lin, TRAJ, progress=list)
    assert n_batched < 0.5 * len(calls)
    np.testing.assert_allclose(lin_batched.pose, lin_single.pose, atol=1e-9)
