"""The damage law of connection degradation against closed forms and an independent scalar solve."""

import numpy as np
import pytest
from scipy.optimize import brentq

from femast.effects.damage import cumulative_slip, damage, degrade, dissipated_energy
from femast.effects.operators import play
from femast.errors import ConvergenceError


def test_law_is_linear_at_first_and_saturates():
    assert damage(0.0, 0.4, 2e-3) == 0.0
    np.testing.assert_allclose(damage(2e-3, 0.4, 2e-3), 0.4 * (1 - np.exp(-1.0)), rtol=1e-15)
    np.testing.assert_allclose(damage(1e-9, 0.4, 2e-3) / 1e-9, 0.4 / 2e-3, rtol=1e-6)
    np.testing.assert_allclose(damage(1.0, 0.4, 2e-3), 0.4, rtol=1e-15)
    with pytest.raises(ValueError, match="D_max < 1"):
        damage(1.0, 1.0, 1.0)


def test_slip_and_energy_measures_of_a_rigid_plastic_slider():
    # a triangle wave of amplitude A: every half cycle slides 2 A; at a constant friction r the work is r S
    A, r = 3e-3, 500.0
    s = np.concatenate([np.linspace(0, A, 101), np.linspace(A, -A, 201)[1:], np.linspace(-A, A, 201)[1:]])
    S = cumulative_slip(s)
    np.testing.assert_allclose(S[-1], 5 * A, rtol=1e-12)
    F = r * np.sign(np.gradient(s))
    E = dissipated_energy(F, s)
    interior = np.r_[0:99, 101:299, 301:500]  # rows away from the two reversals
    np.testing.assert_allclose(np.diff(E)[interior], r * np.abs(np.diff(s))[interior], rtol=1e-9)


def _hardening_slider(r, H):
    """Slip of a slider of strength r with linear kinematic hardening H under force control."""
    return lambda F_eff: play(F_eff, r) / H


def test_degraded_slider_matches_a_scalar_solve_at_every_peak():
    # ramps 0 -> +F_m -> -F_m -> ... ; with damage driven by cumulative slip the slip at the end of
    # each ramp solves s = (F/(1 - D(S0 + |s - s0|)) -+ r) / H, one scalar equation per ramp
    r, H, F_m, D_max, X_d = 2e3, 1e6, 8e3, 0.5, 0.1
    n = 20000
    ramps = [np.linspace(0, F_m, n + 1)]
    for k in range(5):
        a, b = (F_m, -F_m) if k % 2 == 0 else (-F_m, F_m)
        ramps.append(np.linspace(a, b, 2 * n + 1)[1:])
    F = np.concatenate(ramps)
    D, F_eff = degrade(F, _hardening_slider(r, H), D_max, X_d, "slip")
    s = play(F_eff, r) / H
    ends = np.cumsum([len(x) for x in ramps]) - 1
    s0, S0 = 0.0, 0.0
    for k, i in enumerate(ends):
        sign = 1.0 if k % 2 == 0 else -1.0
        f = sign * F_m

        def g(x, s0=s0, S0=S0, f=f, sign=sign):
            return x - (f / (1 - damage(S0 + abs(x - s0), D_max, X_d)) - sign * r) / H

        lo, hi = (s0, s0 + 1.0) if sign > 0 else (s0 - 1.0, s0)
        s_end = brentq(g, lo, hi, xtol=1e-14)
        np.testing.assert_allclose(s[i], s_end, rtol=2e-6, atol=1e-10)
        S0 += abs(s_end - s0)
        s0 = s_end
    assert np.all(np.diff(D) >= -1e-15) and 0.2 < D[-1] < 0.45


def test_energy_driver_of_the_slider():
    r, H, F_m, D_max, X_d = 2e3, 1e6, 8e3, 0.5, 40.0
    F = np.concatenate([np.linspace(0, F_m, 4001), np.linspace(F_m, -F_m, 8001)[1:]])
    D, F_eff = degrade(F, _hardening_slider(r, H), D_max, X_d, "energy")
    s = play(F_eff, r) / H
    np.testing.assert_allclose(D, damage(dissipated_energy(F, s), D_max, X_d), atol=1e-9)
    assert D[-1] > D[4000] > 0.0


def test_no_damage_leaves_the_load_alone_and_runaway_is_reported():
    F = np.linspace(0, 1e4, 50)
    D, F_eff = degrade(F, _hardening_slider(1e3, 1e6), 0.0, 1e-3)
    assert not D.any() and F_eff is F or np.array_equal(F_eff, F)
    with pytest.raises(ConvergenceError, match="did not settle in 2 passes"):
        degrade(F, _hardening_slider(1e3, 1e6), 0.5, 1e-4, max_passes=2)
