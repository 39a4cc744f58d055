"""Deployment of a scattered ADAM mast on seated ball joints: a sample that failed to deploy when its
members' length errors acted in full from the start of the pretension step.

data/scattered_mast_10_bays.npz is one sample of the stated scatter (femast.adam.shape_study.SCATTER,
flat per-element arrays as a study stores them) for 10 bays: the shape-accuracy benchmark's run 43
(independent samples, seed 1).  With the whole lack of fit at step time 0, its pretension step
stopped at time 0 after every cutback (no convergence in 25 iterations: the misfit pressed
longerons tens of micrometres into their seats in the first increment whatever its size).  The
initial step now closes the misfit over the step (``step.ramp_length_errors()``)."""

from pathlib import Path

import numpy as np
import pytest

import femast as fm
from femast.adam import build_mast
from femast.adam.shape_study import as_scatter
from femast.adam.steps import CONVERGENCE, add_initial_steps

SAMPLE = Path(__file__).parent / "data" / "scattered_mast_10_bays.npz"
N_BAYS = 10


@pytest.fixture(scope="module")
def deployed():
    values = dict(np.load(SAMPLE))
    am = build_mast(N_BAYS, scatter=as_scatter(values, N_BAYS))
    steps = add_initial_steps(am, settle=True)
    frames = []
    fm.Analysis(am.model, None, progress=False, convergence=CONVERGENCE, on_frame=frames.append).run()
    return am, steps, frames


def test_the_initial_step_ramps_the_misfit(deployed):
    am, steps, _ = deployed
    assert steps[0].ramps_length_errors and not steps[1].ramps_length_errors
    assert len(am.model.length_errors) > 0  # the sample's longerons and battens carry length errors


def test_the_sample_deploys_to_the_end_of_both_initial_steps(deployed):
    _, _, frames = deployed
    last = frames[-1]
    assert str(last["step"]) == "equilibrium" and float(last["time"]) == pytest.approx(1.0)


def test_each_bay_rests_on_its_longerons_with_what_its_cables_pull(deployed):
    """Statics of a cut through bay j just above its latch units: the part above carries no load, so
    the four top seats of the bay's longerons push up exactly as hard as the bay's eight arm cables
    pull down (the longerons are vertical to ~1e-4 rad, their seats' normals along them).  Seats only
    push: every normal force is >= 0 and none exceeds the bay's pull; where the lack of fit lifts a
    longeron off a seat, that seat carries nothing."""
    am, _, frames = deployed
    fr = frames[-1]
    xyz = am.model.coordinates + fr["U"]  # deployed positions (rows: node_labels order), m
    N = fr["el/adam_joint/normal_force"].reshape(N_BAYS, 4, 2)  # (bay, corner, bottom/top seat)
    contact = fr["el/adam_joint/contact"].reshape(N_BAYS, 4, 2)
    arm = fr["el/adam_arm/N"].reshape(N_BAYS, 4, 2)  # tensions, N
    assert np.all(N >= 0.0)
    assert np.all(N[contact == 0] == 0.0)
    assert np.sum(contact == 0) > 0  # the case has open seats
    for j in range(N_BAYS):
        pull = 0.0
        for k in range(4):
            u = xyz[am.model.index(am.units[j, k])]
            tops = [am.corners[j + 1, k], am.corners[j + 1, (k + 1) % 4]]
            if am.folds[j] < 0:
                tops = tops[::-1]
            for a, t in enumerate(tops):
                d = xyz[am.model.index(t)] - u
                pull += arm[j, k, a] * d[2] / np.linalg.norm(d)
        assert np.sum(N[j, :, 1]) == pytest.approx(pull, rel=5e-4)
        assert np.max(N[j]) <= pull
