"""The Rocaspect mast in the FE core: the Dyneema shroud cable family and the FE mast checked term by term
against the analytic complete-mast model."""

import numpy as np
import pytest

import femast as fm
from femast.elements.shroud_cable import ShroudCableFamily, add_shrouds, unstretched_length
from femast.elements.shroud_law import DyneemaLaw, axial_rigidity_tangent, strain_from_tension, tension_from_strain
from femast.errors import ModelError
from femast.guyed.cantilever import mast_section
from femast.guyed.complete_mast import active_stiffness
from femast.guyed.fe_mast import (
    MastFE,
    beam_column_geometric_stiffness,
    compare_stiffness,
    relative_difference,
    rotation_scaling,
)
from femast.guyed.rocaspect import E_NO_SHROUD, L_BEAM, mast_tops
from femast.rotations import expm_so3
from femast.testing import fd_tangent

LAW = DyneemaLaw()


def _random_shrouds(rng, strains, offsets=True):
    # disconnected elements (so each FD column moves one element only), rotated nodes, offsets
    n = len(strains)
    X = rng.normal(size=(2 * n, 3)) * 2.0
    nodes = np.arange(2 * n).reshape(n, 2)
    off = rng.normal(size=(n, 2, 3)) * 0.3 if offsets else None
    R = np.array([expm_so3(rng.normal(size=3)) for _ in range(2 * n)])
    o = np.zeros((n, 2, 3)) if off is None else off
    p = X[nodes] + np.einsum("enij,enj->eni", R[nodes], o)
    length = np.linalg.norm(p[:, 1] - p[:, 0], axis=1)
    fam = ShroudCableFamily(nodes, length / (1.0 + np.asarray(strains)), LAW, offsets=off)
    return fam, X, R


# ----------------------------------------------------------------------------- the element
def test_shroud_tangent_matches_finite_differences():
    rng = np.random.default_rng(7)
    # strains from slight to 1 % (~9 kN) with offsets and arbitrary rotations, plus a slack rope
    fam, x, R = _random_shrouds(rng, [1e-4, 1.3e-3, 4e-3, 1e-2, -2e-3])
    r = fam.evaluate(x, R, None)
    assert r.output["slack"].tolist() == [0, 0, 0, 0, 1]
    Kfd = fd_tangent(fam, x, R)
    for e in range(fam.n_elements):
        scale = max(np.abs(r.k[e]).max(), 1.0)
        # central FD, h = 1e-6 m/rad on lengths ~2 m: truncation ~h^2 |f'''| and round-off
        # ~1e-16 |f| / h, both below 1e-7 of the largest entry
        np.testing.assert_allclose(r.k[e], Kfd[e], atol=1e-7 * scale)
    assert np.all(r.k[4] == 0.0) and np.all(r.f[4] == 0.0)  # slack: no force, no stiffness


def test_shroud_tangent_parts_add_up_and_material_part_is_the_law():
    rng = np.random.default_rng(1)
    fam, x, R = _random_shrouds(rng, [2e-3, 5e-3])
    parts = {}
    for p in ("full", "material", "geometric", "none"):
        fam.tangent_parts = p
        parts[p] = fam.evaluate(x, R, None)
    fam.tangent_parts = "full"
    np.testing.assert_allclose(
        parts["material"].k + parts["geometric"].k, parts["full"].k, rtol=0, atol=1e-12 * np.abs(parts["full"].k).max()
    )  # round-off of a sum
    assert np.all(parts["none"].k == 0.0)
    out = parts["full"].output
    # tension and material tangent are Eq. 25 / Eq. 27 of femast.elements.shroud_law (same formulas)
    np.testing.assert_allclose(out["tension"], tension_from_strain(LAW, out["strain"]), rtol=1e-13)
    B = parts["full"].f / out["tension"][:, None]
    kt = np.einsum("ei,eij,ej->e", B, parts["material"].k, B) / np.einsum("ei,ei->e", B, B) ** 2
    np.testing.assert_allclose(kt, axial_rigidity_tangent(LAW, out["tension"]) / fam.L0, rtol=1e-12)
    assert not fam.symmetric and np.abs(parts["full"].k - np.swapaxes(parts["full"].k, 1, 2)).max() > 1.0


def test_energy_is_the_potential_of_the_tension():
    fam = ShroudCableFamily([[0, 1]], 2.0, LAW)
    R = np.tile(np.eye(3), (2, 1, 1))

    def energy_tension(l):
        r = fam.evaluate(np.array([[0.0, 0, 0], [l, 0, 0]]), R, None)
        return r.energy[0], r.output["tension"][0]

    l, h = 2.006, 1e-6
    dE = (energy_tension(l + h)[0] - energy_tension(l - h)[0]) / (2 * h)
    # 5-point Gauss rule on a smooth law (error ~1e-13) and FD truncation ~h^2: 1e-7 is ample
    assert dE == pytest.approx(energy_tension(l)[1], rel=1e-7)
    assert energy_tension(1.99)[0] == 0.0


def test_pretension_given_as_tension_or_unstretched_length():
    m = fm.Model()
    a, b, c = m.node(0, 0, 0), m.node(3.0, 0, 4.0), m.node(0, 3.0, 4.0)
    fam = add_shrouds(m, [(a, b)], tension=1200.0, name="t")
    L0 = float(unstretched_length(LAW, 1200.0, 5.0))
    assert fam.L0[0] == pytest.approx(5.0 / (1 + strain_from_tension(LAW, 1200.0)), rel=1e-15)
    fam2 = add_shrouds(m, [(a, c)], L0=L0, name="l")
    X = m.coordinates
    R = np.tile(np.eye(3), (3, 1, 1))
    for f in (fam, fam2):  # labels are indices here: labels 1..3 -> rows 0..2
        g = ShroudCableFamily(np.asarray(f.nodes) - 1, f.L0, LAW)
        # inversion of Eq. 27 is exact to round-off
        assert g.evaluate(X, R, None).output["tension"][0] == pytest.approx(1200.0, rel=1e-11)
    # offsets move the attachment points: the tension refers to the offset geometry
    fam3 = add_shrouds(m, [(a, b)], tension=400.0, offsets=[[0.0, 0.0, 1.0], [0.0, 0.0, 0.0]], name="o")
    assert fam3.L0[0] == pytest.approx(float(unstretched_length(LAW, 400.0, np.hypot(3.0, 3.0))), rel=1e-15)


def test_bad_input_gives_clear_model_errors():
    m = fm.Model()
    a, b, c = m.node(0, 0, 0), m.node(1.0, 0, 0), m.node(0, 0, 0.0 + 1e-15)
    with pytest.raises(ModelError, match="k0.*positive"):
        ShroudCableFamily([[0, 1]], 1.0, [0.0, 144.0, 0.0])
    with pytest.raises(ModelError, match="k0.*positive"):
        ShroudCableFamily([[0, 1]], 1.0, [-5e5, 144.0, 0.0])
    with pytest.raises(ModelError, match="k0.*positive"):
        DyneemaLaw(k0=-1.0)
    for L0 in (0.0, -1.0, np.nan):
        with pytest.raises(ModelError, match="unstretched length L0.*> 0"):
            ShroudCableFamily([[0, 1]], L0, LAW)
    with pytest.raises(ModelError, match="attachment points coincide"):
        add_shrouds(m, [(a, c)], tension=100.0)
    with pytest.raises(ModelError, match="attachment points coincide"):  # an offset brings the ends together
        add_shrouds(m, [(a, b)], tension=100.0, offsets=[[1.0, 0.0, 0.0], [0.0, 0.0, 0.0]])
    with pytest.raises(ModelError, match="tension -5.0 N must be >= 0"):
        add_shrouds(m, [(a, b)], tension=-5.0)
    with pytest.raises(ModelError, match="L0 or the tension, not both"):
        add_shrouds(m, [(a, b)], tension=5.0, L0=1.0)
    fam = ShroudCableFamily([[0, 1]], 1.0, LAW)
    with pytest.raises(ModelError, match="end points coincide"):
        fam.evaluate(np.zeros((2, 3)), np.tile(np.eye(3), (2, 1, 1)), None)
    with pytest.raises(ModelError, match="beyond the range of the rope law"):  # k1 eps > 1: no finite root
        ShroudCableFamily([[0, 1]], 1.0, [1e6, 200.0, 0.0]).evaluate(
            np.array([[0.0, 0, 0], [1.01, 0, 0]]), np.tile(np.eye(3), (2, 1, 1)), None
        )
    with pytest.raises(ModelError, match="pretension.*>= 0"):
        MastFE(-10.0)


# ----------------------------------------------------------------------------- the mast, term by term
@pytest.fixture(scope="module")
def cmp1200():
    return compare_stiffness(1200.0)


@pytest.fixture(scope="module")
def cmp400():
    return compare_stiffness(400.0)


def test_equilibrium_tensions_are_the_pretension(cmp1200, cmp400):
    # Newton on L0 stops at 1e-9 relative (Newton's equilibrium tolerance is 1e-9 too)
    np.testing.assert_allclose(cmp1200["state"].tension, 1200.0, rtol=2e-9)
    np.testing.assert_allclose(cmp400["state"].tension, 400.0, rtol=2e-9)


def test_beam_and_passive_parts_match_to_1e6(cmp1200, cmp400):
    # cubic Euler-Bernoulli elements are nodally exact for tip loads, so the condensed bare-beam
    # stiffness is Eq. 8 inverted up to round-off; the material tangent of the ropes is Eq. 24 with
    # the tangent Eq. 25: 1e-6 is the requirement (measured ~1e-14)
    for c in (cmp1200, cmp400):
        assert c["rel_beam"] < 1e-6
        assert c["rel_passive0"] < 1e-6  # shrouds taut at 0 N, nominal geometry: K_p(tau = 0)
        assert c["rel_passive"] < 1e-6  # at the pretensioned equilibrium
        assert c["rel_shroud"] < 1e-6  # K_a + K_p together


def test_active_part_matches_with_the_same_conventions(cmp1200, cmp400):
    # same conventions: FE equilibrium geometry and tensions, spins about C_i3, corrected Eq. 26.
    # Measured ~1e-10: K_a,FE is a difference of condensed matrices whose axial entries are ~2e7 N/m
    for c in (cmp1200, cmp400):
        assert c["rel_active"] < 1e-6
        # the printed Eq. 26 differs, and only in its moment/rotation block (see docs)
        d = rotation_scaling() @ (c["K_a_printed"] - c["K_a_FE"]) @ rotation_scaling()
        assert np.abs(d[3:, 3:]).max() > 0.1 * np.abs(rotation_scaling() @ c["K_a"] @ rotation_scaling()).max()
        assert np.abs(d[:3, :]).max() < 1e-6 * np.abs(c["K_a"]).max()
        assert np.abs(d[:, :3]).max() < 1e-6 * np.abs(c["K_a"]).max()


def test_active_asymmetry_is_balanced_by_the_beam(cmp1200):
    # K_a is not symmetric (the shroud moment turns with the top); at equilibrium the FE total is,
    # because the beam's geometric stiffness carries the opposite skew part (end moment of the beam)
    c = cmp1200
    skew_a = c["K_a"] - c["K_a"].T
    assert np.abs(skew_a).max() > 1.0  # N m, not round-off
    skew_geo = c["K_geo"] - c["K_geo"].T
    np.testing.assert_allclose(skew_geo, -skew_a, atol=1e-6 * np.abs(skew_a).max())  # equilibrium at 1e-9
    K = c["K_FE"]
    assert np.abs(K - K.T).max() < 1e-6 * np.abs(skew_a).max()


def test_beam_geometric_stiffness_from_axial_compression(cmp1200, cmp400):
    # the beam carries the vertical resultant of the three shrouds; its lateral geometric stiffness is
    # ~ -6P/(5L): -1.17 kN/m at 1200 N, -0.39 kN/m at 400 N, the size of K_a[0,0] and of opposite sign
    for c, P_expect in ((cmp1200, 3561.3), (cmp400, 1187.1)):
        P = -c["beam_N"]
        assert P == pytest.approx(P_expect, rel=1e-4)  # geometry of rocaspect.py, printed to 5 digits
        kx = c["K_geo"][0, 0]
        assert kx == pytest.approx(-6 * P / (5 * L_BEAM), rel=0.01)  # 16 elements: 0.5 % below the limit
        assert kx < 0 < c["K_a"][0, 0] and abs(kx) / c["K_a"][0, 0] == pytest.approx(1.27, abs=0.01)


def test_fe_geometric_stiffness_converges_to_the_beam_column():
    # pure axial dead load on the bare beam: FE geometric stiffness vs the exact beam-column
    P = 3561.3
    sec = mast_section(E_NO_SHROUD)
    EI = sec.E * sec.Iy
    exact = beam_column_geometric_stiffness(L_BEAM, EI, P)
    errs = []
    for n in (8, 16):
        fe = MastFE(None, n_beam=n)
        fe.solve()
        K0 = fe.top_stiffness()
        fe.solve([[0, 0, -P, 0, 0, 0]])
        G = fe.top_stiffness() - K0
        S = rotation_scaling()
        errs.append(np.abs(S @ (G - exact) @ S).max() / np.abs(S @ exact @ S).max())
    # O(1/n^2) discretisation (the corotational beam has only the chord 'string' term per element),
    # plus ~0.2 % from the axial shortening that the inextensible closed form ignores
    assert errs[1] < 0.01
    assert errs[0] > 2.0 * errs[1]


def test_nominal_analytic_model_versus_fe(cmp1200):
    # the paper's K_m (nominal geometry, no beam geometric stiffness) against the FE tangent:
    # the lateral difference is the beam's geometric softening, ~13 % of the lateral stiffness
    c = cmp1200
    lat = np.ix_([0, 1], [0, 1])
    diff = c["K_m_nominal"][lat] - c["K_FE"][lat]
    np.testing.assert_allclose(np.diag(diff), -np.diag(c["K_geo"][lat]), rtol=0.02)  # + geometry change 1e-3


def test_small_loads_follow_the_fe_tangent_and_large_loads_slacken_shrouds():
    fe = MastFE(400.0, n_beam=8)
    fe.equilibrate()
    K = fe.top_stiffness()
    w = np.array([262.4, 246.0, -671.8, -22.7, 19.1, -0.46])  # mast-1 cable wrench at the initial pose
    out = fe.run_wrenches([1e-3 * w, 1.0 * w])
    du = out["u"][0] - out["u0"]
    lin = np.linalg.solve(K, 1e-3 * w)
    # second-order error ~ load factor 1e-3 (relative); measured 2e-4
    np.testing.assert_allclose(du[:3], lin[:3], rtol=0, atol=1e-3 * np.abs(lin[:3]).max())
    assert out["tension"][1][:2].max() == 0.0 and out["tension"][1][2] > 400.0  # shrouds 1, 2 slack


def test_wall_attachment_variant_runs_and_is_slightly_softer():
    # physical attachment of shrouds 1-2 on the tube wall 0.25 m below the top: the top 0.25 m of tube
    # now bends, which the rigid-top convention of the analytic model ignores
    top = MastFE(1200.0, n_beam=16)
    top.equilibrate()
    wall = MastFE(1200.0, n_beam=16, attach="wall")
    wall.equilibrate()
    np.testing.assert_allclose(wall.state().tension, 1200.0, rtol=2e-9)
    c_top = np.linalg.inv(top.top_stiffness())[0, 0]
    c_wall = np.linalg.inv(wall.top_stiffness())[0, 0]
    assert c_top < c_wall < 1.01 * c_top  # measured +0.07 %: the rigid-top assumption is harmless
    assert np.allclose(top.top_point, mast_tops()[0])
    assert (
        relative_difference(active_stiffness(top.state().top, top.analytic_shrouds()), top.stiffness_parts()["K_a_FE"])
        < 1e-6
    )


def test_docs_fe_example_runs_and_matches_its_printed_output():
    import contextlib
    import io
    import re
    from pathlib import Path

    text = (Path(__file__).resolve().parents[2] / "docs" / "guyed_masts.md").read_text()
    section = text.split("## The FE mast")[1].split("\n## ")[0]
    code = re.search(r"```python\n(.*?)```", section, re.S).group(1)
    expected = re.search(r"Output:\n\n```\n(.*?)```", section, re.S).group(1).strip().splitlines()
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        exec(compile(code, "guyed_masts.md (FE example)", "exec"), {})
    got = out.getvalue().strip().splitlines()
    assert len(got) == len(expected)
    from doc_examples import assert_same_numbers

    for q, p in zip(expected, got):  # to one unit of the last printed digit (0.01 mm, 0.1 N)
        assert_same_numbers(q, p)
