"""Length errors (lack of fit), thermal strain and per-element device parameters of the cable
families: cable/latch (Stohlman & Pellegrino, Eqs. 2-5) and cable over devices."""

import numpy as np
import pytest

import femast as fm
from femast.analysis import Analysis
from femast.elements.base import IncrementContext
from femast.elements.cable_devices import CableDeviceFamily, Clamp, Latch, Pulley
from femast.elements.cable_latch import BACKSTOP, CableLatchFamily
from femast.elements.latch_law import LatchParameters
from femast.errors import ModelError
from femast.testing import fd_tangent

P = LatchParameters.adam_fit()
X3 = np.array([[-0.40, 0.0, 0.0], [0.0, 0.12, 0.02], [0.45, 0.01, 0.0]])
EA = 2.0e4  # N
T0 = 50.0  # N
LS = np.linalg.norm(np.diff(X3, axis=0), axis=1)  # section lengths, m
STRETCH = 1.0 + T0 / EA


def _eval(fam, X=X3, state=None):
    st = fam.initial_state() if state is None else state
    return fam.evaluate(X, None, st, IncrementContext())


def _trans(K):
    idx = np.array([6 * a + c for a in range(K.shape[-1] // 6) for c in range(3)])
    return K[..., idx[:, None], idx[None, :]]


# ------------------------------------------------------------------ length errors, closed forms
def test_pulley_cable_with_a_short_section_gains_EA_d_over_the_loop():
    """A cable over a frictionless pulley between rigid anchors, pretensioned at T0; the cable in
    section 0 is d too short.  Exact: T = EA (L / (L0 - d) - 1) in both sections (strain on the
    unstretched length); to first order T0 + EA d / L0 over the whole loop."""
    d = 0.05e-3
    for fam in (
        CableLatchFamily.pretensioned([[0, 1, 2]], X3, EA=EA, T0=T0, length_error=[-d, 0.0]),
        CableDeviceFamily.pretensioned([[0, 1, 2]], X3, EA, T0, [Pulley()], length_error=[-d, 0.0]),
    ):
        T = _eval(fam).output["tension"][0]
        L, L0 = LS.sum(), LS.sum() / STRETCH
        exact = EA * (L / (L0 - d) - 1.0)
        np.testing.assert_allclose(T, [exact, exact], rtol=1e-12)  # round-off of the pulley solve
        # the first-order statement of the issue: the change is EA d / L0 up to O(d / L0)
        assert abs((T[0] - T0) / (EA * d / L0) - 1.0) < 2 * (d / L0 + T0 / EA)


def test_latch_cable_short_before_the_latch_changes_only_that_side():
    """Bead held by the backstop: the sections either side are independent.  Section 0 (through
    the backstop) d too short: T_A = EA (L_A / (L_A / stretch - d) - 1), T_B stays T0."""
    d = 0.05e-3
    fam = CableLatchFamily.pretensioned([[0, 1, 2]], X3, EA=EA, T0=T0, latch_node=1, latch=P, length_error=[[-d, 0.0]])
    r = _eval(fam)
    TA, TB = r.output["tension"][0]
    np.testing.assert_allclose(TA, EA * (LS[0] / (LS[0] / STRETCH - d) - 1.0), rtol=1e-12)  # round-off
    np.testing.assert_allclose(TB, T0, rtol=1e-12)
    assert r.state[0, 1] == BACKSTOP
    # an error after the latch acts on the other side only
    fam = CableLatchFamily.pretensioned([[0, 1, 2]], X3, EA=EA, T0=T0, latch_node=1, latch=P, length_error=[[0.0, -d]])
    TA, TB = _eval(fam).output["tension"][0]
    np.testing.assert_allclose([TA, TB], [T0, EA * (LS[1] / (LS[1] / STRETCH - d) - 1.0)], rtol=1e-12)


def test_clamped_cable_sections_take_their_own_errors():
    """A clamp grips the cable: each section is a cable of its own, T_i = EA (L_i / (L0_i + d_i) - 1)."""
    d = np.array([0.03e-3, -0.07e-3])
    fam = CableDeviceFamily.pretensioned([[0, 1, 2]], X3, EA, T0, [Clamp()], length_error=d)
    T = _eval(fam).output["tension"][0]
    np.testing.assert_allclose(T, EA * (LS / (LS / STRETCH + d) - 1.0), rtol=1e-12)  # round-off


# ------------------------------------------------------------------ thermal strain through an analysis
def _cable_model(kind, dT, alpha=12e-6, increments=4):
    m = fm.Model(f"heated {kind}")
    nodes = [m.node(*p) for p in X3]
    for nd in nodes:
        m.fix(nd)
    extra = m.node(-1.4, 0.0, 0.0)  # a stress-free bar on a roller: the model needs a free DOF
    m.truss(nodes[0], extra, EA=1e3)
    m.fix(extra, "uy", "uz")
    XL = np.vstack([np.zeros(3), X3])  # coordinates indexed by node label (labels 1..3)
    if kind == "latch":
        fam = CableLatchFamily.pretensioned([nodes], XL, EA=EA, T0=T0, latch_node=1, latch=P, name="c")
    elif kind == "pulley":
        fam = CableLatchFamily.pretensioned([nodes], XL, EA=EA, T0=T0, name="c")
    else:
        fam = CableDeviceFamily.pretensioned([nodes], XL, EA, T0, [Clamp()], name="c")
    m.add_family(fam)
    m.thermal_expansion(alpha, family="c")
    m.step("heat", initial_increment=1.0 / increments, max_increment=1.0 / increments).temperature(dT, family="c")
    frames = []
    an = Analysis(m, None, progress=False, on_frame=frames.append)
    an.run()
    return an, frames


@pytest.mark.parametrize("kind", ["pulley", "latch", "clamp"])
def test_heated_cable_between_rigid_anchors_follows_the_closed_form_and_goes_force_free(kind):
    """T_i(t) = EA max(L_i / L0_i(s) - 1, 0), s = 1 + alpha dT t (ramp in step time), L0_i(s) = s L0_i:
    the heated cable relaxes; at alpha dT = T0 / EA it has grown by exactly its pretension stretch
    and carries no force (free thermal expansion).  With the bead held by the backstop (x = -x_b, a
    fixed place in the latch) the cable before the latch is s Lb of heated cable from the anchor to
    the bead plus x_b from the bead to the latch node: L0_A(s) = s Lb + x_b, L0_B = s L0 - L0_A."""
    alpha = 12e-6
    dT = (STRETCH - 1.0) / alpha  # the cable grows to the anchors' distance
    an, frames = _cable_model(kind, dT, alpha)
    heat = [f for f in frames if f["step"] == "heat"]
    assert len(heat) == 4
    for f in heat:
        s = 1.0 + alpha * dT * float(f["total_time"])  # one step of period 1: step time = total time
        if kind == "latch":
            xb = P.x_backstop
            Lb = LS[0] / STRETCH - xb
            L0A = s * Lb + xb
            L0s = np.array([L0A, s * LS.sum() / STRETCH - L0A])
        else:
            L0s = s * LS / STRETCH
        T = f["el/c/tension"][0]
        # round-off of L / L0 - 1 (1e-16) times EA, against T0 = 50 N
        np.testing.assert_allclose(T, EA * np.maximum(LS / L0s - 1.0, 0.0), rtol=1e-9, atol=1e-9 * T0)
    if kind != "latch":
        assert np.abs(heat[-1]["el/c/tension"]).max() <= 1e-9 * T0  # force free (round-off)


def test_temperature_selection_names_cable_families():
    m = fm.Model("m")
    nodes = [m.node(*p) for p in X3]
    m.add_family(CableLatchFamily.pretensioned([nodes], np.vstack([np.zeros(3), X3]), EA=EA, T0=T0, name="c"))
    with pytest.raises(ModelError, match=r"no beam or truss family named \['d'\] \(nor a cable family\).*'c'"):
        m.thermal_expansion(1e-5, family="d")
    assert m.thermal_expansion(1e-5, family="c") == [("c", 0)]
    with pytest.raises(ModelError, match="picks no element"):
        m.thermal_expansion(1e-5, family="c", where=lambda p: p[0] > 1.0)


def test_model_families_are_not_changed_by_an_analysis():
    an, _ = _cable_model("pulley", 100.0)
    fam = an.model.families[0]
    assert np.all(fam.length_factor == 1.0)  # the analysis heated its own copy


# ------------------------------------------------------------------ tangents with errors and heat
@pytest.mark.parametrize(
    "make",
    [
        lambda: CableLatchFamily.pretensioned(
            [[0, 1, 2]], X3, EA=EA, T0=T0, latch_node=1, latch=P, x0=0.4e-3, length_error=[[3e-5, -2e-5]]
        ),
        lambda: CableDeviceFamily.pretensioned(
            [[0, 1, 2]], X3, EA, T0, [Latch(P, x0=0.4e-3)], length_error=[[3e-5, -2e-5]]
        ),
        lambda: CableDeviceFamily.pretensioned([[0, 1, 2]], X3, EA, T0, [Pulley(mu=0.2)], length_error=[[3e-5, -2e-5]]),
    ],
)
def test_tangent_matches_central_differences_with_errors_and_heat(make):
    fam = make()
    fam.length_factor[:] = 1.0 + 2e-4
    Xp = X3 + np.array([[0, 0, 0], [2e-4, -1e-4, 0], [0, 0, 0]])
    st = fam.initial_state()
    r = fam.evaluate(Xp, None, st, IncrementContext())
    Kfd = fd_tangent(fam, Xp, None, st, h=1e-7, dofs=range(3))
    scale = np.abs(r.k).max()
    # central differences, h = 1e-7 m: truncation h^2 f''' and round-off eps f / h, both < 1e-6 of K
    np.testing.assert_allclose(_trans(r.k[0]), _trans(Kfd[0]), rtol=0, atol=2e-6 * scale)


# ------------------------------------------------------------------ per-element device parameters
def test_per_element_latch_parameters_equal_separate_families():
    """device_values: a batch of two latches with different k and mu gives, element by element,
    what two families built with those parameters give."""
    from dataclasses import replace

    X = np.vstack([X3, X3 + [0, 0, 1.0]])
    nodes = [[0, 1, 2], [3, 4, 5]]
    k = [P.k, 1.7 * P.k]
    mu = [P.mu, 0.12]
    Xd = X.copy()
    Xd[[1, 4]] += [1.0e-3, 2.5e-3, 0]  # pull the beads out of the latch
    batch = CableDeviceFamily.pretensioned(nodes, X, EA, T0, [Latch(P)], device_values={0: {"k": k, "mu": mu}})
    rb = batch.evaluate(Xd, None, batch.initial_state(), IncrementContext())
    for e in range(2):
        one = CableDeviceFamily.pretensioned([nodes[e]], X, EA, T0, [Latch(replace(P, k=k[e], mu=mu[e]))])
        r1 = one.evaluate(Xd, None, one.initial_state(), IncrementContext())
        np.testing.assert_array_equal(rb.f[e], r1.f[0])  # same arithmetic, element by element
        np.testing.assert_array_equal(rb.state[e], r1.state[0])


@pytest.mark.parametrize(
    "kw, words",
    [
        (dict(device_values={0: {"k": [1e5, -1.0]}}), r"device 0 \(Latch\), element 1: latch parameter k"),
        (dict(device_values={0: {"spring": 1.0}}), r"unknown parameter 'spring'"),
        (dict(device_values={3: {"k": 1.0}}), r"device 3; the devices are 0..0"),
        (dict(length_error=[1.0, 2.0, 3.0]), r"length_error must be one value per section"),
    ],
)
def test_bad_device_values_and_length_errors_name_the_item(kw, words):
    X = np.vstack([X3, X3 + [0, 0, 1.0]])
    with pytest.raises(ModelError, match=words):
        CableDeviceFamily.pretensioned([[0, 1, 2], [3, 4, 5]], X, EA, T0, [Latch(P)], **kw)


def test_cable_latch_length_error_that_removes_the_cable_names_the_element():
    with pytest.raises(ModelError, match=r"cable_latch element 1: length errors"):
        CableLatchFamily.pretensioned(
            [[0, 1, 2], [0, 1, 2]], X3, EA=EA, T0=T0, latch_node=1, latch=P, length_error=[[0, 0], [-0.5, 0.0]]
        )
    with pytest.raises(ModelError, match=r"length_error of section 1 = nan"):
        CableLatchFamily.pretensioned([[0, 1, 2]], X3, EA=EA, T0=T0, length_error=[0.0, np.nan])
