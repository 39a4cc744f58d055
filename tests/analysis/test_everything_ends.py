"""Everything ends: cutback and growth factors and the arc-length bounds are validated (no factor
that never shrinks an increment, no NaN), a step gives up after a bounded number of cutbacks, and
the status file cannot grow without bound (one line per attempt, notes cut to one short line)."""

import numpy as np
import pytest

import femast as fm
from femast.elements.base import ElementFamily, ElementResponse


def _cantilever():
    m = fm.Model("ends")
    a, b = m.node(0, 0, 0), m.node(1, 0, 0)
    m.beam(a, b, fm.circular_tube(0.02, 0.016, E=70e9), n=2)
    m.fix(a)
    m.step("load").load(b, fz=-50.0)
    return m


@pytest.mark.parametrize(
    "options, named",
    [
        ({"cutback": 1.0}, "cutback = 1 must be"),
        ({"cutback": 0.0}, "cutback = 0 must be"),
        ({"cutback": -0.5}, "cutback = -0.5 must be"),
        ({"cutback": float("nan")}, "cutback = nan is not finite"),
        ({"growth": float("nan")}, "growth = nan is not finite"),
        ({"growth": 0.5}, "growth = 0.5 must be"),
        ({"growth": float("inf")}, "growth = inf is not finite"),
        ({"easy_iterations": 0}, "easy_iterations = 0 must be at least 1"),
        ({"max_cutbacks": 0}, "max_cutbacks = 0 must be at least 1"),
        ({"line_search": "sometimes"}, "line_search = 'sometimes'"),
    ],
)
def test_increment_factors_are_validated(options, named):
    with pytest.raises(fm.ModelError, match="Analysis") as err:
        fm.Analysis(_cantilever(), None, progress=False, on_frame=print, **options)
    assert named in str(err.value)


@pytest.mark.parametrize(
    "options, named",
    [
        ({"max_arc": float("nan")}, "max_arc = nan is not finite"),
        ({"min_arc": 0.0}, "min_arc = 0 must be positive"),
        ({"min_arc": 2.0}, "min_arc = 2 must be at most 1"),
        ({"max_arc": 0.5}, "max_arc = 0.5 must be at least 1"),
        ({"initial_load_factor": float("inf")}, "initial_load_factor = inf is not finite"),
        ({"max_load_factor": float("nan")}, "max_load_factor = nan is not finite"),
        ({"desired_iterations": 0}, "desired_iterations = 0 must be at least 1"),
        ({"rotation_scale": -1.0}, "rotation_scale = -1 m must be positive"),
    ],
)
def test_arc_length_bounds_are_validated(options, named):
    with pytest.raises(fm.ModelError, match="ArcLength") as err:
        fm.ArcLength(**options)
    assert named in str(err.value)


class _NeverConverges(ElementFamily):
    """A spring whose forces are NaN in every increment attempt: each fails at once, whatever its size."""

    name = "never"
    active_dofs = (0, 1, 2)

    def __init__(self, nodes):
        self.nodes = np.asarray(nodes, dtype=np.int64)

    def evaluate(self, x, R, state, ctx=None):
        f, K = np.zeros((1, 12)), np.zeros((1, 12, 12))
        if ctx is not None and ctx.dtime > 0:  # (the initial frame is evaluated with dtime 0)
            f[:] = np.nan
        K[0, :3, :3] = K[0, 6:9, 6:9] = np.eye(3) * 1e3
        K[0, :3, 6:9] = K[0, 6:9, :3] = -np.eye(3) * 1e3
        return ElementResponse(f=f, k=K, state=state)


def test_a_step_gives_up_after_a_bounded_number_of_cutbacks(tmp_path):
    """A cutback factor close to 1 and a tiny minimum increment would take ~6500 cutbacks to reach
    the minimum; the step stops after max_cutbacks and says so, and status.sta stays small."""
    m = fm.Model("stuck")
    a, b = m.node(0, 0, 0), m.node(1, 0, 0)
    m.add_family(_NeverConverges([[a, b]]))
    m.fix(a)
    m.step("pull", min_increment=1e-300).load(b, fx=1.0)
    with (
        np.errstate(all="ignore"),
        pytest.raises(fm.ConvergenceError, match="step 'pull': 200 cutbacks in this step") as err,
    ):
        fm.solve(m, tmp_path / "r", progress=False, cutback=0.9, max_cutbacks=200)
    assert "max_cutbacks" in str(err.value) and "returned NaN or infinite internal forces" in str(err.value)
    lines = (tmp_path / "r" / "status.sta").read_text().splitlines()
    assert len(lines) <= 200 + 2 and max(len(x) for x in lines) <= 100 + 300 + 5


def test_the_default_bound_on_cutbacks_ends_a_stuck_step(tmp_path):
    m = fm.Model("stuck")
    a, b = m.node(0, 0, 0), m.node(1, 0, 0)
    m.add_family(_NeverConverges([[a, b]]))
    m.fix(a)
    m.step("pull", min_increment=1e-300).load(b, fx=1.0)
    with np.errstate(all="ignore"), pytest.raises(fm.ConvergenceError, match="step 'pull': 1000 cutbacks in this step"):
        fm.solve(m, tmp_path / "r", progress=False, cutback=0.9)
    n = len((tmp_path / "r" / "status.sta").read_text().splitlines())
    assert n <= 1000 + 2  # (0.9 would take ~6600 cutbacks to reach 1e-300)
