"""Modal analysis with few DOFs that carry mass: point masses on massless beams against the
flexibility (influence-coefficient) solution of Euler-Bernoulli cantilevers, both eigensolver paths,
and the message of a massless mechanism."""

import math

import numpy as np
import pytest

import femast as fm
from femast.errors import ModelError
from femast.modal import eigen, modal_analysis

E = 70e9
SECTION = fm.circular_tube(0.02, 0.016, E=E)
EI = E * SECTION.Iy
EA = E * SECTION.A


def _cantilever(L, n_beams, masses):
    """Massless cantilever along x, fixed at 0; ``masses`` {node index along the beam: kg}."""
    m = fm.Model("point masses on a massless cantilever")
    xs = np.linspace(0.0, L, n_beams + 1)
    nodes = [m.node(x, 0.0, 0.0) for x in xs]
    for a, b in zip(nodes[:-1], nodes[1:]):
        m.beam(a, b, SECTION)
    m.fix(nodes[0])
    for i, mass in masses.items():
        m.point_mass(nodes[i], mass)
    m.step("none")
    return fm.Analysis(m, None, progress=False, on_frame=lambda d: None), xs


def _flexibility_frequencies(a, mass):
    """Frequencies (Hz) of point masses ``mass`` at stations ``a`` (m) of a massless cantilever:
    bending (twice: y and z, round section) from the influence coefficients a_i^2 (3 a_j - a_i) / 6EI
    (a_i <= a_j), axial from min(a_i, a_j) / EA."""
    a = np.asarray(a, float)
    lo, hi = np.minimum.outer(a, a), np.maximum.outer(a, a)
    F_bend = lo**2 * (3 * hi - lo) / (6 * EI)
    F_ax = lo / EA
    out = []
    for F in (F_bend, F_bend, F_ax):
        # omega^2 from F M phi = phi / omega^2 (symmetric form M^1/2 F M^1/2)
        s = np.sqrt(np.asarray(mass, float))
        mu = np.linalg.eigvalsh(s[:, None] * F * s[None, :])
        out.append(1.0 / mu)
    return np.sort(np.sqrt(np.concatenate(out)) / (2 * math.pi))


@pytest.mark.parametrize("n_beams", [1, 4])
@pytest.mark.parametrize("n_modes", [1, 2, 3])
def test_point_mass_on_massless_cantilever(n_beams, n_modes):
    L, M = 1.3, 2.5
    an, _ = _cantilever(L, n_beams, {n_beams: M})
    f = modal_analysis(an, n_modes).frequencies
    bend = math.sqrt(3 * EI / L**3 / M) / (2 * math.pi)
    axial = math.sqrt(EA / L / M) / (2 * math.pi)
    expect = np.array([bend, bend, axial])[:n_modes]
    assert np.allclose(f, expect, rtol=1e-10, atol=0)


def test_masses_on_six_of_ten_nodes():
    """The issue's case: masses on 6 nodes of a massless 10-beam model (18 massed DOFs, fewer than
    ARPACK's default 20 Lanczos vectors)."""
    L = 2.0
    where = {2: 0.4, 4: 0.9, 5: 1.1, 7: 0.3, 9: 0.8, 10: 1.7}
    an, xs = _cantilever(L, 10, where)
    md = modal_analysis(an, 8)
    expect = _flexibility_frequencies(xs[list(where)], list(where.values()))[:8]
    assert md.n_mass == 18
    assert np.allclose(md.frequencies, expect, rtol=1e-9)


def test_lanczos_path_with_a_basis_from_the_massed_dofs(monkeypatch):
    """The Krylov path, forced on the one-mass problem: its basis (3 vectors) fits the 3 massed DOFs."""
    monkeypatch.setattr(eigen, "DENSE_MASSED", 0)
    L, M = 1.0, 2.0
    an, _ = _cantilever(L, 4, {4: M})
    f = modal_analysis(an, 1).frequencies
    assert f[0] == pytest.approx(math.sqrt(3 * EI / L**3 / M) / (2 * math.pi), rel=1e-9)


def test_dense_and_lanczos_paths_agree_on_a_massed_beam(monkeypatch):
    """A beam with its own (consistent) mass: the two paths give the same modes."""
    m = fm.Model("massed cantilever")
    a, b = m.node(0, 0, 0), m.node(1.0, 0, 0)
    m.beam(a, b, SECTION.with_(rho=2700.0), n=40)
    m.fix(a)
    m.step("none")
    an = fm.Analysis(m, None, progress=False, on_frame=lambda d: None)
    dense = modal_analysis(an, 6)
    monkeypatch.setattr(eigen, "DENSE_MASSED", 0)
    lanczos = modal_analysis(an, 6)
    assert np.allclose(dense.frequencies, lanczos.frequencies, rtol=1e-9)
    # the shapes span the same space (pairs of equal frequencies may mix within their plane)
    A = dense.shapes.reshape(6, -1).T
    B = lanczos.shapes.reshape(6, -1).T
    coef, *_ = np.linalg.lstsq(A, B, rcond=None)
    assert np.abs(A @ coef - B).max() < 1e-7 * np.abs(B).max()


def test_massless_mechanism_is_named():
    """A massless node held by two collinear trusses has no transverse stiffness: named."""
    m = fm.Model("string")
    a, b, c = m.node(0, 0, 0), m.node(1, 0, 0), m.node(2, 0, 0)
    m.truss(a, b, EA=1e5)
    m.truss(b, c, EA=1e5)
    m.fix(a)
    m.fix(c, "uy", "uz")
    m.point_mass(c, 1.0)
    m.step("none")
    an = fm.Analysis(m, None, progress=False, on_frame=lambda d: None)
    with pytest.raises(ModelError, match=r"without mass form a mechanism.*node 2 u[yz]"):
        modal_analysis(an, 1)
