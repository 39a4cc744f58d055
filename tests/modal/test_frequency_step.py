"""The ``frequency`` step of model scripts."""

import math

import numpy as np
import pytest

import femast as fm
from femast.errors import ModelError
from femast.modal import Modes


def _string(n=40, T=80.0, mpl=0.02, L=1.0):
    m = fm.Model("string")
    nodes = [m.node(L * k / n, 0, 0) for k in range(n + 1)]
    for p, q in zip(nodes[:-1], nodes[1:]):
        m.truss(p, q, EA=1e6, pretension=T, mass_per_length=mpl)
    m.fix(nodes[0])
    m.fix(nodes[-1], "uy", "uz")  # ux: prescribed in the tests' static step
    return m, nodes


def test_frequency_steps_before_and_after_a_static_step(tmp_path):
    """Initial state (T = 80 N), then the end pulled by 4e-5 m: T = 80 + (EA + 80) 4e-5 / L =
    120.0032 N.  The string's first frequency follows f = 1/(2L) sqrt(T/m') (consistent trusses, 40
    elements: 2.6e-4 of mesh error; 1e-3 tolerance)."""
    m, nodes = _string()
    m.frequency_step("initial modes", n_modes=2, vtk=True)
    m.step("pull").prescribe(nodes[-1], ux=4e-5)
    m.frequency_step("loaded modes", n_modes=2)
    an = fm.Analysis(m, tmp_path / "res", progress=False)
    an.run()
    f0 = an.modes["initial modes"].frequencies[0]
    f1 = an.modes["loaded modes"].frequencies[0]
    assert f0 == pytest.approx(0.5 * math.sqrt(80.0 / 0.02), rel=1e-3)
    assert f1 == pytest.approx(0.5 * math.sqrt(120.0032 / 0.02), rel=1e-3)
    back = Modes.load(tmp_path / "res" / "modes" / "loaded modes.npz")
    np.testing.assert_array_equal(back.frequencies, an.modes["loaded modes"].frequencies)
    assert (tmp_path / "res" / "modes" / "initial modes_vtk" / "mode_01" / "series.pvd").is_file()
    kinds = [s.get("kind", "static") for s in an.summary.steps]
    assert kinds == ["frequency", "static", "frequency"]


def test_frequency_step_takes_no_loads():
    m, nodes = _string()
    s = m.frequency_step("modes")
    with pytest.raises(ModelError, match="frequency step: it applies no loads"):
        s.load(nodes[1], fx=1.0)
    with pytest.raises(ModelError, match="n_modes = 0"):
        m.frequency_step("more", n_modes=0)
