"""A battery of bad models, built and run through the API as a new user or an
adversary would.  Each must raise the named femast error whose message names the offending item
(node, DOF, element, step, property), never a raw numpy/Python exception, a NaN or silence."""

import math
import re

import numpy as np
import pytest

import femast as fm
from femast.elements.ball_joint import BallJointFamily
from femast.model.amplitudes import Amplitude


def _sec(**kw):
    return fm.circular_tube(0.02, 0.016, E=70e9, **kw)


def _run(m, out=None):
    return fm.solve(m, out, progress=False, on_frame=(lambda d: None) if out is None else None)


def _cantilever():
    m = fm.Model("c")
    a, b = m.node(0, 0, 0), m.node(1, 0, 0)
    m.beam(a, b, _sec(), n=2)
    m.fix(a)
    return m, a, b


def _truss_pair():
    m = fm.Model("t")
    a, b = m.node(0, 0, 0), m.node(1, 0, 0)
    m.truss(a, b, EA=1e5)
    m.fix(a)
    m.fix(b, "uy", "uz")
    return m, a, b


def _step_run(**options):
    def build():
        m, a, b = _cantilever()
        m.step("s", **options).load(b, fz=-1.0)
        _run(m)

    return build


def _modified_step(field, value):
    def build():
        m, a, b = _cantilever()
        s = m.step("s")
        s.load(b, fz=-1.0)
        setattr(s, field, value)  # set after creation: checked again when the analysis starts
        _run(m)

    return build


def _load(**comp):
    def build():
        m, a, b = _cantilever()
        m.step("s").load(b, **comp)

    return build


def _no_steps():
    m, a, b = _cantilever()
    _run(m)


def _no_elements():
    m = fm.Model("empty")
    a = m.node(0, 0, 0)
    m.step("s").load(a, fx=1.0)
    _run(m)


def _unconnected_load():
    m, a, b = _cantilever()
    c = m.node(5, 5, 5)
    m.step("s").load(c, fy=2.0)
    _run(m)


def _moment_on_truss():
    m, a, b = _truss_pair()
    m.step("s").load(b, fx=1.0, mz=3.0)
    _run(m)


def _rotation_on_truss():
    m, a, b = _truss_pair()
    m.step("s").prescribe(b, rx=0.1)
    _run(m)


def _mechanism():
    m = fm.Model()
    a, b = m.node(0, 0, 0), m.node(1, 0, 0)
    m.beam(a, b, _sec(), n=2)
    m.fix(a, "ux", "uy", "uz", "ry", "rz")
    m.step("s").load(b, fy=1.0)
    _run(m)


def _loaded_and_fixed():
    m, a, b = _cantilever()
    m.fix(b, "uz")
    m.step("s").load(b, fz=1.0)
    _run(m)


def _fixed_and_prescribed():
    m, a, b = _cantilever()
    m.step("s").prescribe(a, ux=0.01)
    _run(m)


def _same_family_name():
    m = fm.Model()
    a, b, c = m.node(0, 0, 0), m.node(1, 0, 0), m.node(2, 0, 0)
    m.beam(a, b, _sec(), family="x")
    m.truss(b, c, EA=1e5, family="x")
    m.fix(a)
    m.step("s").load(c, fx=1.0)
    _run(m)


def _out_is_a_file(tmp_path):
    def build():
        m, a, b = _cantilever()
        m.step("s").load(b, fz=-1.0)
        f = tmp_path / "taken.txt"
        f.write_text("x")
        _run(m, f)

    return build


def _out_under_a_file(tmp_path):
    def build():
        m, a, b = _cantilever()
        m.step("s").load(b, fz=-1.0)
        f = tmp_path / "plain"
        f.write_text("x")
        _run(m, f / "sub")

    return build


def _ball(**kw):
    def build():
        m = fm.Model()
        a, b = m.node(0, 0, 0), m.node(0, 0, 0)
        args = dict(nodes=np.array([[a, b]]), k_pen=1e6, k_stick=10.0)
        args.update(kw)
        m.add_family(BallJointFamily(**args))

    return build


def _m():
    return fm.Model("m")


E = fm.ModelError
CASES = [
    # nodes and labels
    ("node-nan", lambda: _m().node(0, float("nan"), 0), E, r"node 1 coordinate y = nan is not finite"),
    ("node-inf", lambda: _m().node(math.inf, 0, 0), E, r"node 1 coordinate x = inf is not finite"),
    ("node-1e200", lambda: _m().node(1e200, 0, 0), E, r"node 1 coordinate x = 1e\+200 m is beyond"),
    ("node-neg-1e16", lambda: _m().node(0, 0, -1e16), E, r"node 1 coordinate z = -1e\+16 m is beyond"),
    ("node-text", lambda: _m().node("abc", 0, 0), E, r"node 1 coordinate x = 'abc' is not a number"),
    ("node-none", lambda: _m().node(0, None, 0), E, r"coordinate y = None is not a number"),
    ("node-array", lambda: _m().node(np.zeros(2), 0, 0), E, r"coordinate x = array.* is not a number"),
    ("label-fraction", lambda: _m().node(0, 0, 0, label=1.5), E, r"node label = 1.5 must be a whole number"),
    ("label-text", lambda: _m().node(0, 0, 0, label="a"), E, r"node label = 'a' must be a whole number"),
    ("label-huge", lambda: _m().node(0, 0, 0, label=10**30), E, r"node label = .* too large"),
    (
        "label-twice",
        lambda: [m := _m(), m.node(0, 0, 0, label=3), m.node(1, 0, 0, label=3)],
        E,
        r"node 3 is defined twice",
    ),
    ("nodes-3x2", lambda: _m().nodes(np.zeros((3, 2))), E, r"nodes\(\): .*\(n, 3\) array.*shape \(3, 2\)"),
    ("nodes-2x4", lambda: _m().nodes(np.zeros((2, 4))), E, r"nodes\(\): .*shape \(2, 4\)"),
    ("nodes-3d", lambda: _m().nodes(np.zeros((2, 3, 1))), E, r"nodes\(\): .*shape \(2, 3, 1\)"),
    ("nodes-nan-row", lambda: _m().nodes([[0, 0, 0], [1, np.nan, 0]]), E, r"nodes\(\): row 1 coordinate y"),
    ("nodes-text", lambda: _m().nodes([["a", "b", "c"]]), E, r"nodes\(\): coordinates must be an \(n, 3\) array"),
    # elements
    ("beam-unknown-node", lambda: [m := _m(), m.beam(m.node(0, 0, 0), 99, _sec())], E, r"beam: unknown node 99"),
    (
        "beam-fraction-node",
        lambda: [m := _m(), m.node(0, 0, 0), m.node(1, 0, 0), m.beam(1, 1.5, _sec())],
        E,
        r"beam: node label 1.5 is not a whole number",
    ),
    (
        "beam-coincident",
        lambda: [m := _m(), m.beam(m.node(0, 0, 0), m.node(0, 0, 0), _sec())],
        E,
        r"beam 1-2: nodes 1 and 2 coincide",
    ),
    (
        "beam-up-parallel",
        lambda: [m := _m(), m.beam(m.node(0, 0, 0), m.node(0, 0, 1), _sec(), up=(0, 0, 1))],
        E,
        r"beam 1-2: up-vector .* parallel",
    ),
    (
        "beam-up-2-values",
        lambda: [m := _m(), m.beam(m.node(0, 0, 0), m.node(1, 0, 0), _sec(), up=(0, 1))],
        E,
        r"beam 1-2: up-vector .* must be 3 numbers",
    ),
    (
        "beam-up-nan",
        lambda: [m := _m(), m.beam(m.node(0, 0, 0), m.node(1, 0, 0), _sec(), up=(0, np.nan, 1))],
        E,
        r"beam 1-2: up-vector = nan",
    ),
    (
        "beam-n-zero",
        lambda: [m := _m(), m.beam(m.node(0, 0, 0), m.node(1, 0, 0), _sec(), n=0)],
        E,
        r"beam 1-2: number of elements n = 0 must be at least 1",
    ),
    (
        "beam-n-fraction",
        lambda: [m := _m(), m.beam(m.node(0, 0, 0), m.node(1, 0, 0), _sec(), n=2.5)],
        E,
        r"beam 1-2: number of elements n = 2.5 must be a whole number",
    ),
    (
        "beam-not-section",
        lambda: [m := _m(), m.beam(m.node(0, 0, 0), m.node(1, 0, 0), 70e9)],
        E,
        r"beam 1-2: section must be a femast Section",
    ),
    (
        "truss-EA-negative",
        lambda: [m := _m(), m.truss(m.node(0, 0, 0), m.node(1, 0, 0), EA=-5.0)],
        E,
        r"truss 1-2: EA = -5.0 N must be positive",
    ),
    (
        "truss-EA-nan",
        lambda: [m := _m(), m.truss(m.node(0, 0, 0), m.node(1, 0, 0), EA=float("nan"))],
        E,
        r"truss 1-2: EA = nan is not finite",
    ),
    (
        "truss-EA-1e300",
        lambda: [m := _m(), m.truss(m.node(0, 0, 0), m.node(1, 0, 0), EA=1e300)],
        E,
        r"truss 1-2: EA = 1e\+300 N is beyond",
    ),
    (
        "truss-EA-text",
        lambda: [m := _m(), m.truss(m.node(0, 0, 0), m.node(1, 0, 0), EA="1e5")],
        E,
        r"truss 1-2: EA = '1e5' is not a number",
    ),
    (
        "truss-L0-negative",
        lambda: [m := _m(), m.truss(m.node(0, 0, 0), m.node(1, 0, 0), EA=1e5, L0=-1)],
        E,
        r"truss 1-2: unstretched length L0 = -1.0 m must be positive",
    ),
    (
        "truss-L0-and-pretension",
        lambda: [m := _m(), m.truss(m.node(0, 0, 0), m.node(1, 0, 0), EA=1e5, L0=1, pretension=5)],
        E,
        r"truss 1-2: give L0 or pretension",
    ),
    (
        "truss-pretension-impossible",
        lambda: [m := _m(), m.truss(m.node(0, 0, 0), m.node(1, 0, 0), EA=1e5, pretension=-2e5)],
        E,
        r"truss 1-2: pretension",
    ),
    (
        "truss-coincident",
        lambda: [m := _m(), m.truss(m.node(0, 0, 0), m.node(0, 0, 0), EA=1e5)],
        E,
        r"truss 1-2: nodes 1 and 2 coincide",
    ),
    ("ball-joint-mu-negative", _ball(mu=-0.1), E, r"ball joint.*mu = -0.1"),
    (
        "ball-joint-nodes-shape",
        _ball(nodes=np.array([[1, 2, 3]])),
        E,
        r"ball joints 'ball_joint': nodes must be an \(n, 2\)",
    ),
    ("ball-joint-k-nan", _ball(k_pen=float("nan")), E, r"ball joint.*k_pen = nan"),
    # sections and materials
    (
        "section-E-nan",
        lambda: fm.Section(E=float("nan"), G=1, A=1, Iy=1, Iz=1, J=1, name="s1"),
        E,
        r"section 's1': property E=nan",
    ),
    (
        "section-E-text",
        lambda: fm.Section(E="70GPa", G=1, A=1, Iy=1, Iz=1, J=1, name="s2"),
        E,
        r"section 's2': property E='70GPa' is not a number",
    ),
    (
        "section-G-missing",
        lambda: fm.Section(E=1, G=None, A=1, Iy=1, Iz=1, J=1, name="s3"),
        E,
        r"section 's3': property G is missing",
    ),
    (
        "section-E-1e300",
        lambda: fm.Section(E=1e300, G=1, A=1, Iy=1, Iz=1, J=1, name="s4"),
        E,
        r"section 's4': property E=1e\+300 Pa is beyond",
    ),
    (
        "section-A-negative",
        lambda: fm.Section(E=1, G=1, A=-1e-4, Iy=1, Iz=1, J=1, name="s5"),
        E,
        r"section 's5': property A=-0.0001",
    ),
    (
        "section-J-zero",
        lambda: fm.Section(E=1, G=1, A=1, Iy=1, Iz=1, J=0.0, name="s6"),
        E,
        r"section 's6': property J=0.0",
    ),
    (
        "poisson-minus-one",
        lambda: fm.circular_tube(0.02, 0.016, E=70e9, nu=-1.0, name="t1"),
        E,
        r"section 't1': Poisson's ratio nu = -1 must be greater than -1",
    ),
    (
        "poisson-0.7",
        lambda: fm.circular_tube(0.02, 0.016, E=70e9, nu=0.7, name="t2"),
        E,
        r"section 't2': Poisson's ratio nu = 0.7 must be at most 0.5",
    ),
    (
        "E-string-helper",
        lambda: fm.circular_tube(0.02, 0.016, E="70e9", name="t3"),
        E,
        r"section 't3': Young's modulus E = '70e9' is not a number",
    ),
    (
        "E-negative-helper",
        lambda: fm.square_tube(0.02, 0.016, E=-1.0, name="t4"),
        E,
        r"section 't4': Young's modulus E = -1 Pa must be positive",
    ),
    (
        "inner-above-outer",
        lambda: fm.circular_tube(0.02, 0.03, E=70e9, name="t5"),
        E,
        r"section 't5': need 0 <= inner \(0.03\) < outer",
    ),
    ("outer-nan", lambda: fm.circular_tube(float("nan"), 0.01, E=70e9, name="t6"), E, r"section 't6': outer size=nan"),
    ("outer-text", lambda: fm.square_tube("2 cm", 0.01, E=70e9, name="t7"), E, r"section 't7': outer size='2 cm'"),
    # steps and increments
    ("period-zero", lambda: _m().step("p0", period=0.0), E, r"step 'p0': period = 0 s must be positive"),
    ("period-nan", lambda: _m().step("p1", period=float("nan")), E, r"step 'p1': period = nan is not finite"),
    ("period-negative", lambda: _m().step("p2", period=-1.0), E, r"step 'p2': period = -1 s must be positive"),
    ("initial-nan", _step_run(initial_increment=float("nan")), E, r"step 's': initial_increment = nan"),
    (
        "initial-negative",
        _step_run(initial_increment=-0.1),
        E,
        r"step 's': initial_increment = -0.1 s must be positive",
    ),
    (
        "min-above-max",
        _step_run(min_increment=0.5, max_increment=0.1),
        E,
        r"step 's': min_increment = 0.5 s is larger than max_increment = 0.1 s",
    ),
    (
        "initial-above-period",
        _step_run(initial_increment=2.0),
        E,
        r"step 's': initial_increment = 2 s is longer than the step period",
    ),
    (
        "initial-below-min",
        _step_run(initial_increment=0.01, min_increment=0.1),
        E,
        r"step 's': initial_increment = 0.01 s is smaller than min_increment",
    ),
    (
        "initial-above-max",
        _step_run(initial_increment=0.5, max_increment=0.1),
        E,
        r"step 's': initial_increment = 0.5 s is larger than max_increment",
    ),
    ("max-increments-zero", _step_run(max_increments=0), E, r"step 's': max_increments = 0 must be at least 1"),
    ("max-increments-fraction", _step_run(max_increments=2.5), E, r"step 's': max_increments = 2.5 must be a whole"),
    ("hit-time-outside", _step_run(hit_times=(2.0,)), E, r"step 's': hit time 2 s is outside the step"),
    ("unknown-step-option", _step_run(inital_increment=0.1), E, r"step 's': unknown option 'inital_increment'"),
    ("output-frequency-zero", _step_run(output_frequency=0), E, r"step 's': output_frequency = 0"),
    ("step-twice", lambda: [m := _m(), m.step("a"), m.step("a")], E, r"step 'a' is defined twice"),
    ("step-modified-nan", _modified_step("initial_increment", float("nan")), E, r"step 's': initial_increment = nan"),
    ("step-modified-negative-max", _modified_step("max_increment", -1.0), E, r"step 's': max_increment = -1 s"),
    # loads and boundary conditions
    ("load-nan", _load(fy=float("nan")), E, r"step 's': load fy on node 2 = nan is not finite"),
    ("load-1e300", _load(fz=1e300), E, r"step 's': load fz on node 2 = 1e\+300 N is beyond"),
    ("moment-1e20", _load(mz=-1e20), E, r"step 's': load mz on node 2 = -1e\+20 N m is beyond"),
    ("load-text", _load(fx="10"), E, r"step 's': load fx on node 2 = '10' is not a number"),
    ("load-unknown-component", _load(fw=1.0), E, r"step 's': unknown load component 'fw' on node 2"),
    ("load-empty", _load(), E, r"step 's': load on node 2 has no components"),
    (
        "prescribe-nan",
        lambda: [(mb := _cantilever()), mb[0].step("s").prescribe(mb[2], ux=float("nan"))],
        E,
        r"step 's': prescribed ux on node 2 = nan",
    ),
    ("load-unconnected-node", _unconnected_load, E, r"step 's': load fy on node 4: no element is connected"),
    ("moment-on-truss-node", _moment_on_truss, E, r"step 's': load mz on node 2: .*no stiffness to rz"),
    ("rotation-on-truss-node", _rotation_on_truss, E, r"step 's': prescribed value rx on node 2"),
    ("loaded-and-fixed", _loaded_and_fixed, E, r"step 's': node 2 uz is both loaded and fixed"),
    ("fixed-and-prescribed", _fixed_and_prescribed, E, r"step 's': node 1 ux is both fixed and prescribed"),
    ("fix-unknown-dof", lambda: [m := _m(), m.fix(m.node(0, 0, 0), "uw")], E, r"fix node 1: unknown DOF 'uw'"),
    ("fix-unknown-node", lambda: _m().fix(7), E, r"fix: unknown node 7"),
    ("load-unknown-node", lambda: _m().step("s").load(5, fx=1.0), E, r"load in step 's': unknown node 5"),
    ("no-steps", _no_steps, E, r"model 'c' has no steps"),
    ("no-elements", _no_elements, E, r"model 'empty' has no elements"),
    ("mechanism", _mechanism, fm.SingularModelError, r"singular.*node \d+ rx"),
    ("families-same-name", _same_family_name, E, r"two element families are named 'x'"),
    # constraints, amplitudes
    ("rigid-body-one-node", lambda: [m := _m(), m.rigid_body(m.node(0, 0, 0), [1])], E, r"rigid body 'rigid-1'"),
    ("tie-self", lambda: [m := _m(), m.tie(m.node(0, 0, 0), 1)], E, r"tie: node 1 tied to itself"),
    (
        "tie-unknown-dof",
        lambda: [m := _m(), m.node(0, 0, 0), m.node(0, 0, 0), m.tie(1, 2, "uq")],
        E,
        r"unknown DOF 'uq'",
    ),
    (
        "rotate-zero-axis",
        lambda: [(mb := _cantilever()), mb[0].step("s").rotate(mb[2], (0, 0, 0), 0.1)],
        E,
        r"step 's': rotation axis",
    ),
    ("amplitude-nan", lambda: Amplitude([0, 0.5, 1], [0, float("nan"), 1]), E, r"row 1 .* not finite"),
]


@pytest.mark.parametrize("name,build,error,message", CASES, ids=[c[0] for c in CASES])
def test_bad_model(name, build, error, message):
    with pytest.raises(error) as info:
        build()
    assert isinstance(info.value, fm.FemastError)
    assert re.search(message, str(info.value)), str(info.value)


@pytest.mark.parametrize("maker", [_out_is_a_file, _out_under_a_file], ids=["out-file", "out-under-file"])
def test_bad_results_folder(maker, tmp_path):
    with pytest.raises(fm.FemastError, match=r"(taken\.txt|plain/sub|plain\\sub)'"):
        maker(tmp_path)()


def test_battery_size():
    assert len(CASES) + 2 >= 60


def test_equilibrium_check_catches_a_lost_load_and_passes_a_balanced_one():
    from femast.model.validation import check_equilibrium

    x = np.array([[0.0, 0, 0], [1.0, 0, 0]])
    P = np.zeros((2, 6))
    P[1, 2] = -10.0  # 10 N down at the tip
    RF = np.zeros((2, 6))
    RF[0, 2], RF[0, 4] = 10.0, -10.0  # the clamp: 10 N up and the moment of the tip load
    r_free = np.zeros(6)
    free_dof = np.arange(6)
    check_equilibrium(x, P, RF, r_free, free_dof, "increment 1")  # balanced: silent
    with pytest.raises(fm.EquilibriumError, match=r"increment 3: the reactions do not balance .* node 2"):
        check_equilibrium(x, P, np.zeros((2, 6)), r_free, free_dof, "increment 3", labels=np.array([1, 2]))


def test_analysis_checks_the_balance_of_beam_and_truss_models():
    m, a, b = _cantilever()
    m.step("s").load(b, fz=-1.0)
    an = fm.Analysis(m, None, progress=False, on_frame=lambda d: None)
    assert an.system.check_balance  # every family self-equilibrated: checked each increment
    an.run()
