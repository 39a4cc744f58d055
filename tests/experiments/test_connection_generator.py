"""The independent generator of connection tests (BWBN model, benchmarks/generalisation/connection.py)
against its closed forms; it imports no femast code (checked in test_generalisation_generator.py)."""

import sys
from dataclasses import replace
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "benchmarks"))

from generalisation.connection import BWBN, bwbn_driven, cyclic_protocol  # noqa: E402


def test_monotone_stroke_of_the_plain_model_is_the_exponential():
    c = BWBN()
    u = np.linspace(0.0, 0.02, 201)
    F, z, e = bwbn_driven(u, c, state=True)
    k = c.beta + c.gamma
    np.testing.assert_allclose(z, -np.expm1(-k * u) / k, rtol=1e-9, atol=1e-15)
    np.testing.assert_allclose(e, (u - z) / k, rtol=1e-8, atol=1e-15)
    np.testing.assert_allclose(F, c.alpha * c.k0 * u + (1 - c.alpha) * c.k0 * z, rtol=1e-12)


def test_pinched_tangent_is_lowered_by_the_severity_at_the_slip_lock_level():
    c = BWBN(zeta_s=0.6, p=1e9, q=0.3, psi=0.4e-3, lam=0.5)
    u = np.concatenate(
        [np.linspace(0, 0.01, 401), np.linspace(0.01, -0.01, 801)[1:], np.linspace(-0.01, 0.01, 1601)[1:]]
    )
    _, z, e = bwbn_driven(u, c, substeps=4, state=True)
    k = c.beta + c.gamma
    z_u = 1.0 / k
    i = 1200 + int(np.argmin(np.abs(z[1200:] - c.q * z_u)))  # on the last (rising) branch
    slope = (z[i + 1] - z[i - 1]) / (u[i + 1] - u[i - 1])
    unpinched = 1.0 - abs(z[i]) * (c.beta * np.sign(z[i]) + c.gamma)
    np.testing.assert_allclose(slope, (1 - c.zeta_s) * unpinched, rtol=2e-3)


def test_degraded_tangent_through_zero_is_A_over_eta():
    c = BWBN(dA=200.0, deta=300.0)
    u = np.concatenate([np.linspace(0, 0.01, 201), np.linspace(0.01, -0.01, 2001)[1:]])
    _, z, e = bwbn_driven(u, c, substeps=4, state=True)
    i = 200 + int(np.argmin(np.abs(z[200:])))  # z crosses 0 on the way down
    slope = (z[i + 1] - z[i - 1]) / (u[i + 1] - u[i - 1])
    np.testing.assert_allclose(slope, (1 - c.dA * e[i]) / (1 + c.deta * e[i]), rtol=2e-3)
    # the plain model reloads with slope 1 through z = 0
    _, z0, _ = bwbn_driven(u, replace(c, dA=0.0, deta=0.0), substeps=4, state=True)
    j = 200 + int(np.argmin(np.abs(z0[200:])))
    np.testing.assert_allclose((z0[j + 1] - z0[j - 1]) / (u[j + 1] - u[j - 1]), 1.0, rtol=2e-3)


def test_protocol_has_a_primary_and_trailing_cycles_per_amplitude():
    u, cycle = cyclic_protocol([1e-3, 2e-3], trailing=2, step=0.05e-3)
    assert u[0] == 0.0 and u[-1] == 0.0 and cycle.max() == 5
    np.testing.assert_allclose([u[cycle == k].max() for k in range(6)], [1e-3, 0.75e-3, 0.75e-3, 2e-3, 1.5e-3, 1.5e-3])
    assert np.max(np.abs(np.diff(u))) <= 0.05e-3 + 1e-15
