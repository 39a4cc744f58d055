"""The compiled helpers of the Newton loop against the numpy/scipy expressions they replace."""

import numpy as np
import scipy.sparse as sp
from scipy.linalg import expm

from femast.analysis.configuration import update_configuration
from femast.analysis.convergence import field_abs_max, force_moment_abs_max
from femast.analysis.linalg.linear import _unpermute
from femast.model.constraints import transpose_times
from femast.rotations import skew

RNG = np.random.default_rng(11)


def test_field_maxima_equal_numpys_masked_maxima_and_flag_nan_and_empty_fields():
    v = RNG.standard_normal(40)
    is_rot = RNG.random(40) < 0.4
    t, r = field_abs_max(v, is_rot)
    assert t == np.abs(v[~is_rot]).max() and r == np.abs(v[is_rot]).max()  # a max is exact
    assert field_abs_max(v, np.zeros(40, bool))[1] == -1.0  # no rotational DOF
    v[7] = np.nan
    assert all(np.isnan(field_abs_max(v, is_rot)))  # never "converged"


def test_force_and_moment_maxima_of_six_per_node_vectors():
    f = RNG.standard_normal((9, 12))
    fe = f.reshape(9, 2, 6)
    assert force_moment_abs_max(f) == (np.abs(fe[:, :, :3]).max(), np.abs(fe[:, :, 3:]).max())
    assert force_moment_abs_max(np.zeros((0, 12))) == (0.0, 0.0)


def test_transpose_times_gives_scipys_product_bit_for_bit():
    T = sp.random(60, 25, density=0.1, random_state=3, format="csr")
    v = RNG.standard_normal(60)
    assert np.array_equal(transpose_times(T, v), T.T @ v)  # same order of summation


def test_unpermute_scatters_and_reports_the_largest_entry_or_nan():
    y = RNG.standard_normal(30)
    perm = RNG.permutation(30)
    x = np.empty(30)
    assert _unpermute(y, perm, x) == np.abs(y).max()
    ref = np.empty(30)
    ref[perm] = y
    assert np.array_equal(x, ref)
    y[4] = np.inf
    assert np.isnan(_unpermute(y, perm, np.empty(30)))


def test_configuration_update_adds_translations_and_spins_and_rotates_by_the_exponential():
    n = 4
    x, spin = RNG.standard_normal((n, 3)), RNG.standard_normal((n, 3))
    R = np.array([expm(skew(w)) for w in RNG.standard_normal((n, 3))])
    free_node, free_dof = np.array([0, 0, 1, 2, 2, 2]), np.array([0, 4, 2, 3, 4, 5])
    cons_node, cons_dof = np.array([3]), np.array([1])
    du, dc = 0.1 * RNG.standard_normal(6), np.array([0.05])
    x0, s0, R0 = x.copy(), spin.copy(), R.copy()
    update_configuration(x, spin, R, np.empty((n, 3)), free_node, free_dof, du, cons_node, cons_dof, dc)
    W = np.zeros((n, 3))
    W[0, 1], W[2] = du[1], du[3:]
    np.testing.assert_array_equal(x, x0 + [[du[0], 0, 0], [0, 0, du[2]], [0, 0, 0], [0, dc[0], 0]])
    np.testing.assert_array_equal(spin, s0 + W)
    for i in range(n):  # Rodrigues in the kernel against scipy's matrix exponential
        np.testing.assert_allclose(R[i], expm(skew(W[i])) @ R0[i], rtol=0, atol=1e-14)  # round-off of 3x3 products


def test_stack_buffers_are_separate_arrays_of_the_requested_size():
    from numba import carray, njit

    from femast.elements._stack import stack_buffer

    @njit
    def fill(v):
        a = carray(stack_buffer(3), (3,))
        b = carray(stack_buffer(9), (3, 3))
        for i in range(3):
            a[i] = v[i]
            for j in range(3):
                b[i, j] = -v[i] * v[j]
        return a.sum(), b.sum()

    assert fill(np.array([1.0, 2.0, 3.0])) == (6.0, -36.0)  # writing b left a intact


def _constrained_analysis():
    """A rigid body (reference + 2 nodes), a translation tie, an all-DOF tie and a one-rotation tie."""
    import tempfile

    import femast as fm
    from femast.analysis import Analysis

    m = fm.Model("ties")
    sec = fm.circular_tube(0.02, 0.016, E=70e9, nu=0.33)
    a, b, c = m.node(0, 0, 0), m.node(1, 0, 0), m.node(1, 1, 0)
    d, e, f, g = m.node(1, 1, 0), m.node(1, 1, 0), m.node(1, 1, 0), m.node(0, 1, 1)
    for p, q in ((a, b), (b, c), (c, g), (d, g), (e, g), (f, g)):
        m.beam(p, q, sec, up=(0, 0, 1))
    ref = m.node(0.5, 0.5, 0.5)
    m.rigid_body(ref, [b, g])
    m.tie(c, d)  # translations
    m.tie(c, e, "all")  # R_e = R_c
    m.tie(c, f, "rz")  # one rotation component
    m.fix(a)
    m.step("s").load(ref, fx=1.0)
    return Analysis(m, tempfile.mkdtemp(), progress=False)


def test_slave_update_equals_the_numpy_expressions_it_replaces():
    an = _constrained_analysis()
    c = an.constraints
    n = len(an.x)
    x = an.X0 + RNG.standard_normal((n, 3))
    R = np.array([expm(skew(w)) for w in RNG.standard_normal((n, 3))])
    spin = RNG.standard_normal((n, 3))
    xr, Rr, sr = x.copy(), R.copy(), spin.copy()
    s, r = c.rigid_slave[:, 0], c.rigid_slave[:, 1]  # the expressions of the numpy version
    xr[s] = xr[r] + np.einsum("nij,nj->ni", Rr[r], c.X_rel)
    Rr[s], sr[s] = Rr[r], sr[r]
    for sl, ms, dof in c.tie:
        if dof < 3:
            xr[sl, dof] = c.X0[sl, dof] + (xr[ms, dof] - c.X0[ms, dof])
        else:
            sr[sl, dof - 3] = sr[ms, dof - 3]
    full = {}
    for sl, ms, dof in c.tie:
        if dof >= 3:
            full.setdefault((sl, ms), set()).add(dof)
    for (sl, ms), ds in full.items():
        if len(ds) == 3:
            Rr[sl] = Rr[ms]
    assert len(c.rigid_slave) == 2 and len(full) == 2  # the model has what the test is about
    c.update_slaves(x, R, spin)
    assert np.array_equal(R, Rr) and np.array_equal(spin, sr)  # copies
    # R_r X_rel: 3-term sums, which einsum may order otherwise (2 ulp of the largest term)
    np.testing.assert_allclose(x, xr, rtol=0, atol=4 * np.finfo(float).eps * np.abs(xr).max())


def test_geometric_values_equal_the_numpy_expression_they_replace():
    an = _constrained_analysis()
    c = an.constraints
    x = an.X0 + RNG.standard_normal(an.X0.shape)
    f_net = RNG.standard_normal(an.dofmap.n_active)
    s, r = c.rigid_slave[:, 0], c.rigid_slave[:, 1]
    d = x[s] - x[r]
    eqs = c._slave_trans_eq
    f = np.where(eqs >= 0, f_net[np.maximum(eqs, 0)], 0.0)
    B = d[:, :, None] * f[:, None, :] - np.einsum("ki,ki->k", f, d)[:, None, None] * np.eye(3)
    # f.d: 3-term sums, which einsum may order otherwise (2 ulp of the largest term)
    np.testing.assert_allclose(
        c.geometric_values(x, f_net), B.ravel(), rtol=0, atol=4 * np.finfo(float).eps * np.abs(B).max()
    )
