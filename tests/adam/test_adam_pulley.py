"""The pulley of the ADAM pulley-and-latch unit (BayParameters.pulley): a frictionless pulley (the paper's
element, the default) or a bearing sheave, whose friction rho |F| (rho = mu pin_radius / radius, F the
resultant of the two tensions on the pin) adds to the latch's jump."""

import numpy as np
import pytest

import femast as fm
from femast.adam import BayParameters, build_bay, build_mast
from femast.adam.post import bay_curve
from femast.adam.steps import CONVERGENCE, add_idealised_torsion, add_initial_steps
from femast.elements.cable_devices import Drum, Pulley, Sheave
from femast.elements.cable_latch import CableLatchFamily
from femast.elements.latch_law import ZONE_FREE, latch_zone
from femast.errors import ModelError

RADIUS, PIN = 0.01, 0.002  # m: a sheave and its pin


def _twist(pulley, tmp_path):
    am = build_bay(BayParameters(pulley=pulley))
    add_initial_steps(am, hold_control=("ux", "uy"))
    add_idealised_torsion(am, theta_max=np.radians(3.5), max_increment=0.02)
    frames = []
    fm.Analysis(am.model, tmp_path, progress=False, convergence=CONVERGENCE, on_frame=frames.append).run()
    return am, frames, fm.Results(tmp_path)


@pytest.fixture(scope="module")
def paper(tmp_path_factory):
    return _twist(None, tmp_path_factory.mktemp("paper"))


def test_the_default_is_the_papers_frictionless_element(paper):
    am, _, _ = paper
    assert BayParameters().pulley is None
    assert isinstance(am.latch, CableLatchFamily)


def test_a_frictionless_sheave_reproduces_the_papers_element(paper, tmp_path):
    am, _, res = paper
    _, _, res_s = _twist(Sheave(RADIUS, PIN, mu=0.0), tmp_path)
    a, b = bay_curve(res, am), bay_curve(res_s, am)
    assert len(a["M"]) == len(b["M"])
    np.testing.assert_allclose(b["M"], a["M"], rtol=1e-6, atol=1e-6 * np.abs(a["M"]).max())
    np.testing.assert_allclose(b["bead"], a["bead"], atol=1e-9)  # m
    assert np.array_equal(b["zone"], a["zone"])


def test_a_bearing_sheave_adds_rho_F_while_the_cable_runs_free(paper, tmp_path):
    """Once a bead is out of the rollers (zone d) the latch adds nothing: the whole jump across the
    unit is the bearing's, T2 - T1 = sigma rho |F| while the cable runs (sigma the direction), with
    |F| = sqrt(T1^2 + T2^2 - 2 T1 T2 cos phi), phi the wrap angle.  The bay then also resists more
    before its latches let go."""
    mu = 0.3
    rho = mu * PIN / RADIUS
    am, frames, res = _twist(Sheave(RADIUS, PIN, mu=mu), tmp_path)
    checked = 0
    for fr in frames[1:]:
        T = fr["el/adam_latch/tension"]  # (4, 2) N
        x = fr["el/adam_latch/bead_position"][:, 0]  # m
        mode = fr["el/adam_latch/device_mode"][:, 0]
        phi = fr["el/adam_latch/wrap_angle"][:, 0]  # rad
        F = np.sqrt(T[:, 0] ** 2 + T[:, 1] ** 2 - 2 * T[:, 0] * T[:, 1] * np.cos(phi))
        running = (latch_zone(x, am.params.latch) == ZONE_FREE) & (np.abs(mode) == 1)
        np.testing.assert_allclose((T[:, 1] - T[:, 0])[running], (mode * rho * F)[running], rtol=1e-9, atol=1e-9)
        checked += int(running.sum())
    assert checked > 10
    peak_paper = np.abs(bay_curve(paper[2], paper[0])["M"]).max()
    assert np.abs(bay_curve(res, am)["M"]).max() > 1.05 * peak_paper


@pytest.mark.parametrize("device", [Drum(mu=0.3), Pulley(radius=0.01), "sheave"])
def test_a_drum_or_anything_else_is_refused_by_name(device):
    with pytest.raises(ModelError, match="pulley"):
        BayParameters(pulley=device)


def test_scattered_latches_reach_the_sheave_family():
    k = np.array([[90e3, 95e3, 100e3, 105e3], [110e3, 115e3, 85e3, 80e3]])  # N/m per latch
    mu = np.full((2, 4), 0.06)
    am = build_mast(2, BayParameters(pulley=Sheave(RADIUS, PIN, mu=0.2)), scatter={"latch_k": k, "latch_mu": mu})
    P = am.latch.P[:, 0]  # (8 latches, parameter row): r, x_backstop, k, mu_s, ..., mu_k (9), rho_k, rho_s
    np.testing.assert_array_equal(P[:, 2], k.ravel())
    np.testing.assert_array_equal(P[:, 3], mu.ravel())
    np.testing.assert_array_equal(P[:, 9], mu.ravel())
    np.testing.assert_allclose(P[:, 10:12], 0.2 * PIN / RADIUS)
