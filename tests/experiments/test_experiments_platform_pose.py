"""The platform-pose experiment: baselines, mast-top effects, bad input."""

import numpy as np
import pytest

from femast.errors import ModelError
from femast.experiments import compare, get_experiment, predict
from femast.experiments.data import from_arrays
from femast.guyed.cantilever import cantilever_compliance, mast_section
from femast.guyed.mast_sets import mast_set, masts_3r
from femast.guyed.platform_pose import CableRobot, MastSet, pose_trajectory
from femast.guyed.rocaspect import L_BEAM, fig5a_trajectory, rocaspect_geometry

ROBOT = CableRobot(rocaspect_geometry())
TRAJ = fig5a_trajectory(2)


def data_from(pose, traj=TRAJ, exp=None):
    exp = exp or get_experiment("platform-pose")
    return from_arrays(
        exp, x_cmd_m=traj[:, 0], y_cmd_m=traj[:, 1], z_cmd_m=traj[:, 2], x_m=pose[:, 0], y_m=pose[:, 1], z_m=pose[:, 2]
    )


def test_baseline_is_the_platform_pose_solver():
    ref = pose_trajectory(ROBOT, masts_3r(1200.0), TRAJ)
    pred = predict(get_experiment("platform-pose"), data_from(ref.pose))
    np.testing.assert_allclose(
        np.column_stack([pred[c] for c in ("x_m", "y_m", "z_m")]), ref.pose[:, :3], atol=1e-12
    )  # the same solve (Newton to 1e-11)


def test_mast_top_effect_applies_and_equals_its_linear_equivalent():
    """beam_flexibility adds a cantilever in series with the 3R joints (translations): the experiment with
    the effect must land where the platform solve with that summed compliance lands."""
    E = 5e11
    C = masts_3r(1200.0).compliance.copy()
    C[:, :3, :] += cantilever_compliance(L_BEAM, mast_section(E))[:3, :]
    ref = pose_trajectory(ROBOT, MastSet("3R + beam", C), TRAJ)
    exp = get_experiment("platform-pose")
    pred = predict(exp, data_from(ref.pose), {"compliance_scale": 1.0}, {"beam_flexibility": {"E": E}})
    got = np.column_stack([pred[c] for c in ("x_m", "y_m", "z_m")])
    base = np.column_stack([v for v in predict(exp, data_from(ref.pose)).values()])
    assert np.abs(ref.pose[:, :3] - base).max() > 1e-3  # the effect moves the platform by mm
    np.testing.assert_allclose(
        got, ref.pose[:, :3], atol=1e-9
    )  # a linear effect: the secant compliance is exact after one pass


def test_fitted_baseline_follows_data_from_another_model():
    """Data from the beam+shroud masts (a different model than the 3R baseline) with noise: fitting the
    3R compliance scale lowers the error to about the noise."""
    truth = pose_trajectory(ROBOT, mast_set("beam+shroud", 400.0), TRAJ)
    rng = np.random.default_rng(3)
    meas = truth.pose[:, :3] + 2e-4 * rng.standard_normal((len(TRAJ), 3))
    exp = get_experiment("platform-pose", pretension_N=400.0)
    data = data_from(meas, exp=exp)
    r0 = compare(exp, data, history=False)
    r1 = compare(exp, data, fit=True, history=False)
    assert r1.rms < r0.rms
    assert r1.rms < 5 * 2e-4  # near the noise (the models differ in shape, not only in scale)


def test_bad_input():
    exp = get_experiment("platform-pose")
    cols = dict(
        x_cmd_m=TRAJ[:, 0],
        y_cmd_m=TRAJ[:, 1],
        z_cmd_m=TRAJ[:, 2],
        x_m=TRAJ[:, 0],
        y_m=TRAJ[:, 1],
        z_m=TRAJ[:, 2],
        tau1_N=np.full(len(TRAJ), 100.0),
    )
    with pytest.raises(ModelError, match="all eight tension columns"):
        predict(exp, from_arrays(exp, **cols))
    with pytest.raises(ModelError, match="act on the 3R mast model"):
        predict(get_experiment("platform-pose", mast_model="beam"), data_from(TRAJ), None, ["beam_flexibility"])
    far = TRAJ.copy()
    far[3, :3] = [4.15, 3.4, 3.9]  # no tension distribution there
    with pytest.raises(ModelError, match="row 3"):
        predict(exp, data_from(far, traj=far))
