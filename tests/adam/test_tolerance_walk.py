"""The closed-form random walk of the longerons' length tolerances (femast.adam.tolerance_walk)
against an independent Monte Carlo of the same sums, and its one-bay kinematics against the FE bay.

The Monte Carlo shares no formula with the module: each bay's top-frame plane comes from a least-
squares fit through the four longeron ends (tied) or from the equilibrium of a rigid frame pressed
onto them (seated: a small quadratic programme, solved by enumerating its active sets), and the
bays are chained with exact rotation matrices; the tip's errors are read off the chain."""

import itertools
import math

import numpy as np
import pytest

from femast.adam.build import corner_xy
from femast.adam.tolerance_walk import (
    abs_normal_quantile,
    bay_moments,
    bay_pose,
    lateral_weight,
    rayleigh_quantile,
    tolerance_walk,
)
from femast.errors import ModelError

A, B, L = 0.05e-3, 0.25, 0.171  # tolerance (m), frame side (m), bay height (m)
XY = corner_xy(B)  # (4, 2) corner positions


def plane_tied(d):
    """Least-squares plane z = h + sx x + sy y through the four ends: (h, sx, sy)."""
    G = np.column_stack([np.ones(4), XY])
    coef, *_ = np.linalg.lstsq(G, d.reshape(-1, 4).T, rcond=None)
    return coef.T.reshape(d.shape[:-1] + (3,))


def plane_seated(d, eps=1e-3):
    """A rigid frame pressed down (unit force at its centre) onto the four ends, held level by a weak
    rotational spring eps: min h + eps/2 (sx^2 + sy^2) s.t. h + sx x_k + sy y_k >= d_k, in units of
    A (heights) and B (plan positions), where eps < 1 cannot trade height for tilt.  The KKT system
    of every active set with 1-3 constraints; keep the feasible one with the least objective."""
    flat = d.reshape(-1, 4) / A
    m = len(flat)
    G = np.column_stack([np.ones(4), XY / B])  # rows: constraint gradients
    best = np.full((m, 3), np.nan)
    best_obj = np.full(m, np.inf)
    for k in (1, 2, 3):
        for act in itertools.combinations(range(4), k):
            Ga = G[list(act)]  # (k, 3)
            K = np.zeros((3 + k, 3 + k))
            K[1, 1] = K[2, 2] = eps
            K[:3, 3:] = -Ga.T  # grad f - Ga^T lambda = 0, grad f = (1, eps sx, eps sy)
            K[3:, :3] = Ga  # Ga z = d_act
            if abs(np.linalg.det(K)) < 1e-30:
                continue
            rhs = np.zeros((m, 3 + k))
            rhs[:, 0] = -1.0
            rhs[:, 3:] = flat[:, list(act)]
            sol = rhs @ np.linalg.inv(K).T  # one matrix per active set: invert once
            z, lam = sol[:, :3], sol[:, 3:]
            feasible = np.all(z @ G.T >= flat - 1e-9, axis=1) & np.all(lam >= -1e-9, axis=1)
            obj = z[:, 0] + 0.5 * eps * (z[:, 1] ** 2 + z[:, 2] ** 2)
            take = feasible & (obj < best_obj)
            best[take], best_obj[take] = z[take], obj[take]
    assert np.all(np.isfinite(best)), "every frame finds its rest"
    return (best * np.array([A, A / B, A / B])).reshape(d.shape[:-1] + (3,))


def rotation(w):
    """(m, 3, 3) rotation matrices of rotation vectors w (m, 3) (Rodrigues)."""
    th = np.linalg.norm(w, axis=1)
    k = w / np.where(th > 0, th, 1.0)[:, None]
    Kx = np.zeros((len(w), 3, 3))
    Kx[:, 0, 1], Kx[:, 0, 2], Kx[:, 1, 2] = -k[:, 2], k[:, 1], -k[:, 0]
    Kx = Kx - np.swapaxes(Kx, 1, 2)
    s, c = np.sin(th)[:, None, None], np.cos(th)[:, None, None]
    return np.eye(3) + s * Kx + (1 - c) * Kx @ Kx


def chain(d, seat):
    """Tip of masts with longeron errors d (samples, bays, 4): (axial error, |tilt|, |lateral|)."""
    planes = plane_tied(d) if seat == "tied" else plane_seated(d)
    h, sx, sy = planes[..., 0], planes[..., 1], planes[..., 2]
    m, n = d.shape[:2]
    R = np.broadcast_to(np.eye(3), (m, 3, 3)).copy()
    p = np.zeros((m, 3))
    for j in range(n):
        w = np.column_stack([sy[:, j], -sx[:, j], np.zeros(m)])  # the frame's normal tilts by grad z
        Rb = rotation(w)
        # the top centre, in the bottom frame: up by l + h, and sideways as the bay pivots at mid-height
        local = Rb @ np.array([0.0, 0.0, 0.5 * L])
        local[:, 2] += 0.5 * L + h[:, j]
        p = p + np.einsum("mij,mj->mi", R, local)
        R = R @ Rb
    tilt_vec = np.column_stack([R[:, 2, 1] - R[:, 1, 2], R[:, 0, 2] - R[:, 2, 0]]) / 2  # small: sin
    return p[:, 2] - n * L, np.linalg.norm(tilt_vec, axis=1), np.linalg.norm(p[:, :2], axis=1)


@pytest.mark.parametrize("seat", ["tied", "seated"])
def test_one_bay_pose_matches_the_independent_plane(seat):
    d = np.random.default_rng(11).uniform(-A, A, (2000, 4))
    h, w = bay_pose(d, B, seat)
    planes = plane_tied(d) if seat == "tied" else plane_seated(d)
    np.testing.assert_allclose(h, planes[:, 0], rtol=0, atol=1e-9 * A)
    np.testing.assert_allclose(w[:, 0], planes[:, 2], rtol=0, atol=1e-6 * A / B)
    np.testing.assert_allclose(w[:, 1], -planes[:, 1], rtol=0, atol=1e-6 * A / B)


@pytest.mark.parametrize("seat", ["tied", "seated"])
def test_one_bay_moments_match_sampled_moments(seat):
    d = np.random.default_rng(5).uniform(-A, A, (200_000, 4))
    planes = plane_tied(d) if seat == "tied" else plane_seated(d)
    mom = bay_moments(A, B, seat)
    h = planes[:, 0]
    # sampling errors: mean A / 800, variance and E|w|^2 about 0.4 %
    assert abs(h.mean() - mom["mean_h"]) < 3e-3 * A
    assert h.var() == pytest.approx(mom["var_h"], rel=0.01)
    assert np.mean(planes[:, 1] ** 2 + planes[:, 2] ** 2) == pytest.approx(mom["tilt_ms"], rel=0.01)


@pytest.mark.parametrize(
    "seat, n, samples",
    [("tied", 40, 20000), ("seated", 40, 10000), pytest.param("seated", 350, 3000, marks=pytest.mark.slow)],
)
def test_walk_quantiles_match_a_monte_carlo_of_the_chained_bays(seat, n, samples):
    d = np.random.default_rng(n + len(seat)).uniform(-A, A, (samples, n, 4))
    axial, tilt, lateral = chain(d, seat)
    walk = tolerance_walk(n, A, seat=seat)
    q = walk.quantiles(0.95)
    # the 95th percentile of `samples` draws: relative standard error 0.5 % (20000) to 1.3 % (3000)
    tol = 4 * 0.5e-2 * math.sqrt(20000 / samples)
    assert np.quantile(np.abs(axial), 0.95) == pytest.approx(q["axial"], rel=tol)
    assert np.quantile(tilt, 0.95) == pytest.approx(q["tilt"], rel=tol)
    assert np.quantile(lateral, 0.95) == pytest.approx(q["lateral"], rel=tol)
    assert np.mean(axial) == pytest.approx(walk.axial_mean, abs=4 * walk.axial_sd / math.sqrt(samples))
    assert np.std(axial) == pytest.approx(walk.axial_sd, rel=4 / math.sqrt(2 * samples))
    # the whole distribution, not only the 95th percentile: Kolmogorov distance below 1.6 / sqrt(N)
    for what, x in (("axial", np.abs(axial)), ("tilt", tilt), ("lateral", lateral)):
        x = np.sort(x)
        F = walk.cdf(what, x)
        ecdf = np.arange(1, len(x) + 1) / len(x)
        assert np.max(np.abs(F - ecdf)) < 1.6 / math.sqrt(len(x)) + 0.005, what


def test_the_project_tolerances_give_the_stated_percentiles():
    """a = 0.05 mm, b = 0.25 m, l = 0.171 m, tied joints, first order: 179 um, 369 arcsec (40 bays)
    and 529 um, 1091 arcsec (350 bays) by hand: 1.96 a sqrt(n / 12) and 2.448 a sqrt(n / 3) / b."""
    arcsec = 180 / math.pi * 3600
    for n, axial_um, tilt_as in ((40, 179, 369), (350, 529, 1091)):
        q = tolerance_walk(n, A, seat="tied", lean=False).quantiles(0.95)
        assert q["axial"] * 1e6 == pytest.approx(1.959964 * A * math.sqrt(n / 12) * 1e6, rel=1e-6)
        assert round(q["axial"] * 1e6) == axial_um
        assert round(q["tilt"] * arcsec) == tilt_as
        # the lateral sum: sum_k (k + 1/2)^2 = n (4 n^2 - 1) / 12; a bay tilting about its base: (k + 1)^2
        assert lateral_weight(n) == pytest.approx(n * (4 * n * n - 1) / 12, rel=1e-12)
        assert lateral_weight(n, 1.0) == pytest.approx(n * (n + 1) * (2 * n + 1) / 6, rel=1e-12)


def test_quantile_helpers_against_scipy():
    from scipy import stats

    x = abs_normal_quantile(1.0, 2.0, 0.9)
    assert stats.norm.cdf(x, 1, 2) - stats.norm.cdf(-x, 1, 2) == pytest.approx(0.9, abs=1e-12)
    assert rayleigh_quantile(3.0, 0.95) == pytest.approx(stats.rayleigh.ppf(0.95, scale=3.0), rel=1e-12)


def test_bad_input_is_named():
    with pytest.raises(ModelError, match="seat"):
        tolerance_walk(40, A, seat="glued")
    with pytest.raises(ModelError, match="give it in m"):
        tolerance_walk(40, 0.05, seat="tied")
    with pytest.raises(ModelError, match="n_bays"):
        tolerance_walk(0, A, seat="tied")
    with pytest.raises(ModelError, match="4 values"):
        bay_pose(np.zeros(3), B, "tied")


def bay_parameters(seat):
    """BayParameters with the joints' seat (parameters without a seat field tie their joints)."""
    from femast.adam import BayParameters

    if "seat" in BayParameters.__dataclass_fields__:
        return BayParameters(seat=seat)
    if seat != "tied":
        pytest.skip("these BayParameters have tied joints only")
    return BayParameters()


@pytest.mark.parametrize("seat", ["tied", "seated"])
def test_one_bay_pose_matches_the_fe_bay(seat):
    """The FE bay (elastic members, cables, joints) against the rigid kinematics of bay_pose: the
    rise and tilt of the top frame, and the sideways shift of its centre, c l (w x e_z) with c = 1/2."""
    import femast as fm
    from femast.adam import build_mast
    from femast.adam.steps import CONVERGENCE, add_initial_steps

    p = bay_parameters(seat)

    def deployed(dL):
        am = build_mast(1, p, scatter=None if dL is None else dict(longeron_dL=dL))
        add_initial_steps(am, settle=True)
        row, frames = am.model.index(am.control), []
        fm.Analysis(am.model, None, progress=False, convergence=CONVERGENCE, on_frame=frames.append).run()
        return frames[-1]["U"][row], frames[-1]["URA"][row]

    d = np.random.default_rng(3).uniform(-A, A, 4)  # rests on three legs when seated
    u0, r0 = deployed(None)
    u, r = deployed(d[None])
    h, w = bay_pose(d, p.b, seat)
    du, dw = u - u0, (r - r0)[:2]
    # a seated frame on three legs loads them unevenly: their elastic shortening (the preload of a
    # side, ~2 x 192 N, over EA / l = 2.6e8 N/m) lowers it by under 1.5 um and tilts it by under
    # 1.5 um over the half diagonal (8 urad); tied legs share the warp symmetrically
    k_leg = p.longeron_section.E * p.longeron_section.A / p.l
    slack = 0.0 if seat == "tied" else 2 * 2 * 192.0 / k_leg
    assert du[2] == pytest.approx(h, abs=slack + 1e-3 * A)
    np.testing.assert_allclose(dw, w, rtol=0, atol=slack / (p.b / math.sqrt(2)) + 1e-3 * np.abs(w).max())
    lateral = 0.5 * p.l * np.array([dw[1], -dw[0]])
    np.testing.assert_allclose(du[:2], lateral, rtol=0, atol=0.01 * np.abs(lateral).max())
