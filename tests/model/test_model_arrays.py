"""Model.beams / Model.trusses / Model.nodes from arrays: the same model and the
same solution, bit for bit, as the per-element builders; bad input named by element."""

import numpy as np
import pytest

import femast as fm
from femast.analysis import Analysis
from femast.analysis.families import build_families
from femast.elements.beam_corot import element_frame, element_frames
from femast.errors import ModelError


def _mast_arrays(n_bays=3, b=1.0, h=0.8):
    """A small square mast: corner coordinates, member pairs (rows), kinds and up-vectors.  Written
    here (not taken from femast) so the two builders get the same plain arrays."""
    ang = np.deg2rad(45 + 90 * np.arange(4))
    r = b / np.sqrt(2)
    corners = np.column_stack([r * np.cos(ang), r * np.sin(ang), np.zeros(4)])
    X = np.concatenate([corners + [0, 0, j * h] for j in range(n_bays + 1)])
    pairs, kind, up = [], [], []
    for j in range(n_bays):
        for k in range(4):
            pairs.append((4 * j + k, 4 * (j + 1) + k))
            kind.append(0)
            up.append(corners[k] / r)
            pairs.append((4 * (j + 1) + k, 4 * (j + 1) + (k + 1) % 4))
            kind.append(1)
            up.append((0, 0, 1.0))
            pairs.append((4 * j + k, 4 * (j + 1) + (k + 1) % 4))
            kind.append(2)
            up.append((corners[k] + corners[(k + 1) % 4]) / np.linalg.norm(corners[k] + corners[(k + 1) % 4]))
    return X, np.array(pairs), np.array(kind), np.array(up, float)


SECS = [
    fm.circular_tube(0.030, 0.026, E=70e9),
    fm.circular_tube(0.025, 0.021, E=70e9),
    fm.circular_tube(0.012, 0.008, E=70e9),
]
FAMS = ["longeron", "batten", "diagonal"]


def _finish(m, labels, n_bays):
    for i in range(4):
        m.fix(labels[i])
    step = m.step("twist", initial_increment=0.25, max_increment=0.25)
    for k in range(4):
        step.load(labels[4 * n_bays + k], fx=40.0, fy=-25.0 * (k % 2), mz=3.0)
    return m


def _per_element(n_bays=3):
    X, pairs, kind, up = _mast_arrays(n_bays)
    m = fm.Model("mast")
    labels = [m.node(*x) for x in X]
    for e, (a, b) in enumerate(pairs):
        m.beam(
            labels[a],
            labels[b],
            SECS[kind[e]],
            up=tuple(up[e]),
            family=FAMS[kind[e]],
            length_error_m=1e-4 if e == 5 else 0.0,
        )
    return _finish(m, labels, n_bays)


def _arrays(n_bays=3):
    X, pairs, kind, up = _mast_arrays(n_bays)
    m = fm.Model("mast")
    labels = np.asarray(m.nodes(X))
    dL = np.zeros(len(pairs))
    dL[5] = 1e-4
    m.beams(labels[pairs], [SECS[k] for k in kind], up=up, family=[FAMS[k] for k in kind], length_error_m=dL)
    return _finish(m, labels, n_bays)


def _solve(m):
    an = Analysis(m, None, progress=False, on_frame=lambda f: None)
    an.run()
    return an


def test_beams_from_arrays_make_the_same_model_and_solution_bit_for_bit():
    a, b = _per_element(), _arrays()
    assert a.node_labels.tolist() == b.node_labels.tolist()
    assert np.array_equal(a.coordinates, b.coordinates)
    assert len(a.beams) == len(b.beams) == 36
    for p, q in zip(a.beams, b.beams):
        assert (p.label, p.nodes, p.section, p.family, p.mass_per_length) == (
            q.label,
            q.nodes,
            q.section,
            q.family,
            q.mass_per_length,
        )
        assert np.array_equal(p.up, q.up)
    assert a.length_errors == b.length_errors == {6: 1e-4}
    for fa, fb in zip(build_families(a), build_families(b)):
        assert fa.name == fb.name
        for k in ("nodes", "E0", "l0", "EA", "GJ", "EIy", "EIz", "labels"):
            assert np.array_equal(getattr(fa, k), getattr(fb, k)), k
    sa, sb = _solve(a), _solve(b)
    assert sa.summary.iterations == sb.summary.iterations
    assert np.array_equal(sa.x, sb.x) and np.array_equal(sa.R, sb.R)
    assert np.abs(sa.x - sa.X0).max() > 1e-4  # the load does move the mast (the comparison is not vacuous)


def test_shared_values_and_per_element_values_agree():
    X, pairs, kind, up = _mast_arrays(1)
    sel = pairs[kind == 1]  # battens: one shared up-vector and section
    m1, m2 = fm.Model("a"), fm.Model("b")
    l1, l2 = np.asarray(m1.nodes(X)), np.asarray(m2.nodes(X))
    e1 = m1.beams(l1[sel], SECS[1], up=(0, 0, 1), mass_per_length=0.5)
    e2 = m2.beams(
        l2[sel], [SECS[1]] * len(sel), up=np.tile([0, 0, 1.0], (len(sel), 1)), mass_per_length=np.full(len(sel), 0.5)
    )
    assert e1.tolist() == e2.tolist() == [1, 2, 3, 4]
    for p, q in zip(m1.beams, m2.beams):
        assert (p.nodes, p.section, p.mass_per_length) == (q.nodes, q.section, q.mass_per_length)
        assert np.array_equal(p.up, q.up)


def _truss_model(bulk):
    """A pretensioned cable net: a square of four fixed corners and a centre node, cables of
    mixed L0 / pretension / stress-free, one strut."""
    X = np.array([[0, 0, 0], [2, 0, 0], [2, 2, 0], [0, 2, 0], [1, 1, 0.1]], float)
    pairs = np.array([[0, 4], [1, 4], [2, 4], [3, 4], [0, 2]])
    EA = np.array([1e5, 2e5, 1e5, 3e5, 5e6])
    m = fm.Model("net")
    if bulk:
        n = np.asarray(m.nodes(X))
        L = np.linalg.norm(X[4] - X[0])
        m.trusses(n[pairs[:2]], EA[:2], L0=[0.999 * L, 0.998 * L], tension_only=True, alpha_per_K=[0.0, 2e-5])
        m.trusses(
            n[pairs[2:4]],
            EA[2:4],
            pretension=[50.0, 80.0],
            tension_only=np.array([True, True]),
            mass_per_length=[0.1, 0.2],
        )
        m.trusses(n[pairs[4:]], EA[4:], family="strut", length_error_m=-1e-3)
    else:
        n = [m.node(*x) for x in X]
        L = np.linalg.norm(X[4] - X[0])
        m.truss(n[0], n[4], EA[0], L0=0.999 * L, tension_only=True)
        m.truss(n[1], n[4], EA[1], L0=0.998 * L, tension_only=True, alpha_per_K=2e-5)
        m.truss(n[2], n[4], EA[2], pretension=50.0, tension_only=True, mass_per_length=0.1)
        m.truss(n[3], n[4], EA[3], pretension=80.0, tension_only=True, mass_per_length=0.2)
        m.truss(n[0], n[2], EA[4], family="strut", length_error_m=-1e-3)
    for i in range(4):
        m.fix(n[i])
    m.fix(n[4], "rotations")
    step = m.step("heat and load", initial_increment=0.5)
    step.load(n[4], fz=-30.0)
    step.temperature(40.0)
    return m


def test_trusses_from_arrays_make_the_same_model_and_solution_bit_for_bit():
    a, b = _truss_model(False), _truss_model(True)
    assert [vars(t) for t in a.trusses] == [vars(t) for t in b.trusses]
    assert (a.length_errors, a.expansion) == (b.length_errors, b.expansion)
    sa, sb = _solve(a), _solve(b)
    assert np.array_equal(sa.x, sb.x)
    assert abs(sa.x[4, 2] - sa.X0[4, 2]) > 1e-4  # the centre does sag under the load


def test_element_frames_equal_element_frame_bit_for_bit():
    rng = np.random.default_rng(7)
    x1, x2, up = rng.normal(size=(200, 3)), rng.normal(size=(200, 3)), rng.normal(size=(200, 3))
    up[3] = x2[3] - x1[3]  # parallel: flagged, like element_frame's None
    E0, parallel = element_frames(x1, x2, up)
    assert parallel.tolist() == [element_frame(x1[i], x2[i], up[i]) is None for i in range(200)]
    for i in np.flatnonzero(~parallel):
        assert np.array_equal(E0[i], element_frame(x1[i], x2[i], up[i]))


def test_nodes_continue_the_labels_like_node_calls():
    m1, m2 = fm.Model("a"), fm.Model("b")
    for m in (m1, m2):
        m.node(0, 0, 0, label=10)
    m1.nodes([[1, 0, 0], [2, 0, 0]])
    m2.node(1, 0, 0)
    m2.node(2, 0, 0)
    assert m1.node_labels.tolist() == m2.node_labels.tolist() == [10, 11, 12]
    assert m1.node(3, 0, 0) == 13


@pytest.mark.parametrize(
    "nodes, kwargs, words",
    [
        ([[1, 2], [2, 99]], {}, ["element 1", "nodes 2-99", "unknown node 99", "model.node"]),
        ([[1, 2], [3, 3]], {}, ["element 1", "coincide"]),
        ([[1, 2], [2, 3]], {"up": [[0, 0, 1], [0, np.nan, 1]]}, ["element 1", "not finite"]),
        ([[1, 2], [2, 3]], {"up": [[0, 0, 1], [0, 1, 0]]}, ["element 1", "parallel", "up-vector"]),
        ([[1.0, 2.0], [np.nan, 3.0]], {}, ["element 1", "not a node label"]),
        ([[1, 2, 3]], {}, ["(n_elements, 2)", "shape (1, 3)"]),
        ([[1, 2], [2, 3]], {"section": "tube"}, ["Section"]),
        ([[1, 2], [2, 3]], {"mass_per_length": [0.1, -1.0]}, ["element 1", "mass_per_length", ">= 0"]),
        ([[1, 2], [2, 3]], {"family": ["a"]}, ["one name", "(2)"]),
    ],
)
def test_bad_beam_arrays_name_the_element_and_the_fix(nodes, kwargs, words):
    m = fm.Model("m")
    m.nodes([[0, 0, 0], [0, 1, 0], [0, 2, 0]])
    kw = dict(section=SECS[0], up=(0, 0, 1))
    kw.update(kwargs)
    with pytest.raises(ModelError) as err:
        m.beams(np.array(nodes), **kw)
    for w in words:
        assert w in str(err.value), (w, str(err.value))
    assert not m.beams  # nothing added by a refused call


@pytest.mark.parametrize(
    "kwargs, words",
    [
        ({"EA": [1e5, 0.0]}, ["element 1", "EA", "> 0"]),
        ({"EA": 1e5, "L0": 1.0, "pretension": 1.0}, ["L0 or pretension"]),
        ({"EA": 1e5, "pretension": [0.0, -2e5]}, ["element 1", "impossible"]),
        ({"EA": 1e5, "tension_only": [1, 0]}, ["tension_only", "bool"]),
        ({"EA": 1e5, "L0": [1.0, np.inf]}, ["element 1", "L0", "finite"]),
    ],
)
def test_bad_truss_arrays_name_the_element_and_the_fix(kwargs, words):
    m = fm.Model("m")
    m.nodes([[0, 0, 0], [0, 1, 0], [0, 2, 0]])
    with pytest.raises(ModelError) as err:
        m.trusses(np.array([[1, 2], [2, 3]]), **kwargs)
    for w in words:
        assert w in str(err.value), (w, str(err.value))
    assert not m.trusses
