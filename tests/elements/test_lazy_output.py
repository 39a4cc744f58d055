"""Element outputs computed only when read (femast.elements.base.LazyOutput)."""

import numpy as np

from femast.elements.base import LazyOutput


def test_lazy_output_computes_once_on_first_read():
    calls = []

    def make():
        calls.append(1)
        return {"a": np.arange(3.0), "b": np.ones(2)}

    out = LazyOutput(make)
    assert calls == []  # nothing computed by building it
    assert "a" in out and len(out) == 2
    assert sorted(out) == ["a", "b"]
    np.testing.assert_array_equal(out["a"], [0.0, 1.0, 2.0])
    assert dict(out.items())["b"].tolist() == [1.0, 1.0]
    assert calls == [1]  # and only once, however often it is read


def test_lazy_outputs_are_those_of_their_own_evaluation():
    """Outputs read after a later evaluation at another configuration are still those of the first:
    the lazy dicts of the cable/latch and ball-joint families capture no shared buffer."""
    from femast.adam import build_bay
    from femast.adam.parameters import BayParameters
    from femast.analysis import build_families

    am = build_bay(BayParameters())
    fams = [f for f in build_families(am.model) if f.name in (am.latch_family, "adam_joint")]
    assert len(fams) == 2
    x0 = am.model.coordinates
    R = np.tile(np.eye(3), (len(x0), 1, 1))
    x1 = x0 + 1e-4 * np.random.default_rng(1).standard_normal(x0.shape)  # 0.1 mm: a small motion
    for fam in fams:
        st = fam.initial_state()
        first = fam.evaluate(x0, R, st)
        eager = {k: np.array(v, copy=True) for k, v in LazyOutput(first.output._make).items()}
        second = fam.evaluate(x1, R, st)
        assert any(not np.array_equal(second.output[k], eager[k], equal_nan=True) for k in eager), fam.name
        for k, v in eager.items():
            np.testing.assert_array_equal(first.output[k], v, err_msg=f"{fam.name} {k}")  # same bits
