"""Mass matrices and prestressed modal analysis against closed forms, invariances and
bad input."""

import math

import numpy as np
import pytest

import femast as fm
from femast.errors import ModelError, StateError
from femast.modal import modal_analysis
from femast.modal.mass import assemble_mass, total_mass
from femast.verification import modal as vm


def _fresh(model):
    return fm.Analysis(model, None, progress=False, on_frame=lambda d: None)


# ------------------------------------------------------------------ closed forms (verification.py)
@pytest.mark.parametrize("cable", [True, False])
def test_taut_string(cable):
    rows, _ = vm.taut_string(cable=cable)
    for r in rows:
        assert r.passed, r  # 1e-3: the figure; the mesh (100 elements) is in the case name


def test_cantilever_modes():
    for r in vm.cantilever()[0]:
        assert r.passed, r


def test_pinned_beam_frequency_squared_linear_in_axial_force():
    rows, (ratios, f2, exact) = vm.pinned_beam_axial()
    for r in rows:
        assert r.passed, r
    assert f2[0] < 0 < f2[1]  # past the Euler load the straight state is unstable


def test_rigid_body_on_springs_and_pendulum():
    for r in vm.rigid_body_springs()[0] + vm.pendulum()[0]:
        assert r.passed, r


# ------------------------------------------------------------------ mass matrices
def _beam_model(angle=0.0, n=4, rho=2700.0):
    sec = fm.circular_tube(0.02, 0.016, E=70e9).with_(rho=rho)
    m = fm.Model("beam")
    d = np.array([math.cos(angle), math.sin(angle), 0.3])
    a, b = m.node(0, 0, 0), m.node(*(1.2 * d))
    m.beam(a, b, sec, up=(0, 0, 1), n=n)
    m.fix(a)
    m.step("s")
    return m, sec, 1.2 * np.linalg.norm(d)


def test_total_mass_of_beams_trusses_points():
    m, sec, L = _beam_model()
    c = m.node(0, 1, 0)
    m.truss(1, c, EA=1e5, mass_per_length=0.5)
    m.fix(c)
    m.point_mass(2, 0.7, inertia=1e-3)
    expected = sec.rho * sec.A * L + 0.5 * 1.0 + 0.7
    # sum of the translational block over all active DOFs (fixed ones included) = total mass
    assert total_mass(_fresh(m)) == pytest.approx(expected, rel=1e-12)  # round-off of a sum


def test_beam_mass_gives_rigid_body_kinetic_energy_in_any_orientation():
    """Consistent mass is exact for rigid motions: translation v gives m v^2, a spin w about an
    axis through the first node normal to the beam gives (m L^2 / 3) w^2, whatever the
    element's orientation (rotation of the local matrix)."""
    for angle in (0.0, 0.7, 2.1):
        m, sec, L = _beam_model(angle, n=3)
        an = _fresh(m)
        _, M = assemble_mass(an)
        dm = an.dofmap
        node, dof = dm.slots(np.arange(dm.n_active))
        X = an.X0[node]
        v = np.array([0.3, -0.2, 0.5])
        u = np.where(dof < 3, v[np.minimum(dof, 2)], 0.0)
        mass = sec.rho * sec.A * L
        assert u @ (M @ u) == pytest.approx(mass * v @ v, rel=1e-12)
        e = (an.X0[1] - an.X0[0]) / L
        w = np.cross(e, [0.0, 0.0, 1.0])
        w /= np.linalg.norm(w)
        vel = np.cross(w, X)  # rigid spin about node 1 (the origin)
        u = np.where(dof < 3, vel[np.arange(len(dof)), np.minimum(dof, 2)], w[np.clip(dof - 3, 0, 2)])
        # translational part m L^2/3 plus the torsional rotary inertia about the axis (0: w normal)
        assert u @ (M @ u) == pytest.approx(mass * L * L / 3.0, rel=1e-9)  # Hermite shape: exact


def test_point_mass_offset_is_parallel_axis():
    """A point mass with its centre c from the node: rotation about the node gives J + m (|c|^2 I - c c^T)."""
    m = fm.Model("pm")
    a, b = m.node(0, 0, 0), m.node(1, 0, 0)
    m.beam(a, b, fm.circular_tube(0.02, 0.01, E=1e9), n=1)
    m.fix(a)
    c = np.array([0.1, -0.2, 0.3])
    J = np.diag([0.01, 0.02, 0.03])
    m.point_mass(b, 2.0, inertia=J, offset=c)
    m.step("s")
    an = _fresh(m)
    Mf, _ = assemble_mass(an)
    eqs = an.dofmap.eq[an.model.index(b)]
    Mb = Mf.toarray()[np.ix_(eqs, eqs)]
    expect_rr = J + 2.0 * (c @ c * np.eye(3) - np.outer(c, c))
    np.testing.assert_allclose(Mb[3:, 3:], expect_rr, rtol=1e-14, atol=1e-15)
    # translation-rotation coupling: the momentum of a spin w is m (w x c)
    w = np.array([0.3, 0.1, -0.4])
    np.testing.assert_allclose(Mb[:3, 3:] @ w, 2.0 * np.cross(w, c), rtol=1e-14, atol=1e-15)


def test_frequencies_do_not_depend_on_the_orientation_of_a_prestressed_string():
    f = []
    for angle in (0.0, 0.9):
        m = fm.Model("s")
        e = np.array([math.cos(angle), math.sin(angle), 0.2])
        nodes = [m.node(*(k / 20 * e)) for k in range(21)]
        for p, q in zip(nodes[:-1], nodes[1:]):
            m.truss(p, q, EA=1e6, pretension=50.0, mass_per_length=0.02)
        m.fix(nodes[0])
        m.fix(nodes[-1])
        m.step("s")
        f.append(modal_analysis(_fresh(m), 4).frequencies)
    np.testing.assert_allclose(f[0], f[1], rtol=1e-9)  # invariance: round-off only


def test_modes_written_and_read(tmp_path):
    _, modes = vm.pendulum()
    path = modes.write(tmp_path, "pendulum")
    from femast.modal import Modes

    back = Modes.load(path)
    np.testing.assert_array_equal(back.eigenvalues, modes.eigenvalues)
    np.testing.assert_array_equal(back.shapes, modes.shapes)
    assert (tmp_path / "pendulum.csv").read_text().startswith("mode,f_hz")


# ------------------------------------------------------------------ bad input
def test_no_mass_anywhere_is_named():
    m, _, _ = _beam_model(rho=0.0)
    with pytest.raises(ModelError, match="no mass"):
        modal_analysis(_fresh(m), 2)


def test_too_many_modes_is_named():
    m, _, _ = _beam_model(n=2)
    with pytest.raises(ModelError, match="n_modes = 20 .* only 12 free DOFs"):
        modal_analysis(_fresh(m), 20)
    with pytest.raises(ModelError, match="whole number"):
        modal_analysis(_fresh(m), 0)


def test_unconverged_state_is_refused():
    m = fm.Model("unbalanced")
    a, b, c = m.node(0, 0, 0), m.node(1, 0, 0), m.node(2, 0, 0)
    m.truss(a, b, EA=1e5, pretension=100.0, mass_per_length=0.1)
    m.truss(b, c, EA=1e5, pretension=50.0, mass_per_length=0.1)  # node b pulled by 50 N net
    m.fix(a)
    m.fix(c)
    m.step("s")
    with pytest.raises(StateError, match=r"not converged .* node 2 ux"):
        modal_analysis(_fresh(m), 1)


def test_negative_density_is_named():
    with pytest.raises(ModelError, match=r"section 'circular tube': density rho=-1.0 kg/m\^3 must be"):
        fm.circular_tube(0.02, 0.01, E=1e9).with_(rho=-1.0)


def test_negative_mass_per_length_and_point_mass():
    m = fm.Model("x")
    a, b = m.node(0, 0, 0), m.node(1, 0, 0)
    with pytest.raises(ModelError, match=r"truss 1-2: mass_per_length = -0.1 kg/m"):
        m.truss(a, b, EA=1.0, mass_per_length=-0.1)
    with pytest.raises(ModelError, match="point mass at node 2: mass = -1"):
        m.point_mass(b, -1.0)
    with pytest.raises(ModelError, match="negative principal value"):
        m.point_mass(b, 1.0, inertia=(1.0, -1.0, 1.0))


def test_modes_of_every_saved_increment_follow_the_axial_load(tmp_path):
    """ModesRecorder: the pin-ended beam's first frequency at each increment of a load ramp
    against f0^2 (1 + P/P_E) (tolerance 1e-3 f0^2, as in the verification case), written to the
    results folder; and the animated VTK series of the last frame's modes."""
    from femast.modal.output import ModesRecorder, export_modes_vtk

    E, EI, EA, L = 1e4, 1.0, 1e6, 1.0
    sec = fm.Section(E=E, G=E / 2, A=EA / E, Iy=EI / E, Iz=EI / E, J=2 * EI / E, rho=E / EA)
    m = fm.Model("ramp")
    a, b = m.node(0, 0, 0), m.node(L, 0, 0)
    m.beam(a, b, sec, up=(0, 1, 0), n=48)
    m.fix(a, "ux", "uy", "uz", "rx")
    m.fix(b, "uy", "uz")
    PE = math.pi**2 * EI / L**2
    m.step("pull", initial_increment=0.25, max_increment=0.25).load(b, fx=0.8 * PE)
    an = fm.Analysis(m, tmp_path / "res", progress=False)
    rec = ModesRecorder(an, n_modes=2)
    an.run()
    P = np.array([0.0, 0.2, 0.4, 0.6, 0.8])
    f0sq = (math.pi / 2) ** 2
    f = rec.frequencies[:, 0]
    assert f.shape == (5,)
    np.testing.assert_allclose(f**2, f0sq * (1 + P), atol=1e-3 * f0sq)
    assert len(list((tmp_path / "res" / "modes").glob("frame_*.npz"))) == 5
    pvd = export_modes_vtk(rec.modes[-1], tmp_path / "vtk", n_frames=8)
    assert len(pvd) == 2 and len(list(pvd[0].parent.glob("*.vtu"))) == 8


def test_cable_device_family_with_mass_per_length_is_a_beaded_string():
    """A cable over 19 frictionless point pulleys (femast.elements.cable_devices) with a mass per
    length: lumped beads m' h on a string at tension T; the discrete closed form
    omega_n = 2 sqrt(T / (m' h^2)) sin(n pi / (2 N)) holds exactly (1e-6: the equilibrium check of
    the state; the transverse stiffness of a frictionless pulley is the string's T/h either side)."""
    from femast.elements.cable_devices import CableDeviceFamily, Pulley

    N, L, T, mpl = 20, 2.0, 150.0, 0.01
    m = fm.Model("cable over pulleys")
    labels = [m.node(L * k / N, 0, 0) for k in range(N + 1)]
    fam = CableDeviceFamily.pretensioned(np.arange(N + 1), m.coordinates, 1e6, T, [Pulley()] * (N - 1), name="cable")
    fam.nodes = np.asarray([labels])
    fam.mass_per_length = mpl
    m.add_family(fam)
    m.fix(labels[0])
    m.fix(labels[-1])
    for lab in labels[1:-1]:
        m.fix(lab, "ux")  # the pulleys slide the cable, not themselves: hold them along it
    m.step("hold")
    f = modal_analysis(_fresh(m), 4).frequencies.reshape(2, 2).mean(axis=1)
    h = L / N
    exact = [2 * math.sqrt(T / (mpl * h * h)) * math.sin(n * math.pi / (2 * N)) / (2 * math.pi) for n in (1, 2)]
    np.testing.assert_allclose(f, exact, rtol=1e-6)
