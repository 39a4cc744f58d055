"""A user element written against the documented contract runs in a model."""

import re
from pathlib import Path

import numpy as np
import pytest

from femast.rotations import expm_so3
from femast.testing import fd_tangent

DOC = Path(__file__).resolve().parents[2] / "docs" / "user_elements.md"


@pytest.fixture(scope="module")
def page(tmp_path_factory):
    import os

    src = re.search(r"```python\n(.*?)```", DOC.read_text(), re.S).group(1)
    ns = {"__name__": "__doc_example__"}
    cwd = os.getcwd()
    os.chdir(tmp_path_factory.mktemp("uel"))
    try:
        exec(compile(src, str(DOC), "exec"), ns)
    finally:
        os.chdir(cwd)
    return ns


def test_example_under_60_lines():
    src = re.search(r"```python\n(.*?)```", DOC.read_text(), re.S).group(1)
    assert len(src.strip().splitlines()) <= 60


def test_spring_in_a_model_solves_the_cubic(page):
    # independent reference: the real root of 10 t + 40 t^3 = 30 (numpy.roots); Newton tol 1e-6
    roots = np.roots([40.0, 0.0, 10.0, -30.0])
    theta = roots[np.abs(roots.imag) < 1e-12].real[0]
    res, b = page["res"], page["b"]
    assert res.node_history(b, "rz")[-1] == pytest.approx(theta, rel=1e-8)


def test_spring_tangent_matches_finite_differences(page):
    fam = page["TorsionSprings"]([[0, 1]], k=[10.0], k3=[40.0])
    rng = np.random.default_rng(0)
    x = np.zeros((2, 3))
    R = np.array([expm_so3(rng.normal(size=3)), expm_so3(rng.normal(size=3))])
    K = fam.evaluate(x, R, None).k[0]
    Kfd = fd_tangent(fam, x, R)[0]
    assert np.abs(K - Kfd).max() <= 1e-6 * np.abs(K).max()  # central FD, h = 1e-6: ~1e-10
