"""Mistakes in a model are refused where they enter, with one line naming the item and the real
cause: a node label that is not a whole number, a DOF prescribed twice in a step, a rigid body that
lists its own reference node, a beam far from the origin for its length, an element a billionth of
the model's size, a user element returning arrays of the wrong shape or NaN forces."""

import numpy as np
import pytest

import femast as fm
from femast.cli import error_line
from femast.elements.base import ElementFamily, ElementResponse
from femast.elements.shroud_cable import add_shrouds


def test_a_node_label_that_is_not_a_whole_number_is_refused():
    m = fm.Model("x")
    m.node(0, 0, 0)
    m.node(1, 0, 0)
    with pytest.raises(fm.ModelError, match=r"shroud 1 \(nodes 1-2.7\): node label 2.7 is not a whole number"):
        add_shrouds(m, [[1, 2.7]], tension=10.0)  # (not a shroud on nodes 1-2)
    assert not m.families


def test_a_dof_prescribed_twice_in_one_step_is_refused():
    m = fm.Model("x")
    b = m.node(1, 0, 0)
    with pytest.raises(
        fm.ModelError, match=r"step 's': node 1 ux is prescribed twice in this step \(0.1 m, then 0.2 m\)"
    ):
        m.step("s").prescribe(b, ux=0.1).prescribe(b, ux=0.2)
    m.step("t").prescribe(b, ux=0.1)
    m.step("u").prescribe(b, ux=0.2)  # (a later step may change it)


def test_a_rigid_body_listing_its_own_reference_node_is_refused():
    m = fm.Model("x")
    a, b = m.node(0, 0, 0), m.node(1, 0, 0)
    with pytest.raises(fm.ModelError, match=r"node 1 is its reference node and also listed among the nodes it carries"):
        m.rigid_body(a, [a, b])


def test_a_beam_far_from_the_origin_is_named_for_what_it_is():
    m = fm.Model("far")
    a, b = m.node(1e12, 0, 0), m.node(1e12 + 1, 0, 0)
    with pytest.raises(fm.ModelError) as err:
        m.beam(a, b, fm.circular_tube(0.02, 0.016, E=70e9))
    msg = str(err.value)
    assert "are 1e+12 m from the origin but only 1 m apart" in msg and "near the origin" in msg
    assert "coincide" not in msg
    with pytest.raises(fm.ModelError, match="from the origin but only 1 m apart"):
        m.truss(a, b, EA=1e5)
    with pytest.raises(fm.ModelError, match=r"beam 1-3: nodes 1 and 3 coincide \(length 0 m\)"):  # (truly)
        m.beam(a, m.node(1e12, 0, 0), fm.circular_tube(0.02, 0.016, E=70e9))


def test_an_element_a_billionth_of_the_model_is_named_not_called_a_mechanism():
    m = fm.Model("short")
    a, b, c = m.node(0, 0, 0), m.node(1, 0, 0), m.node(1 + 1e-9, 0, 0)
    sec = fm.circular_tube(0.02, 0.016, E=70e9)
    m.beam(a, b, sec, n=4)
    m.beam(b, c, sec)
    m.fix(a)
    m.step("load").load(c, fz=-50.0)
    with pytest.raises(fm.ModelError) as err:
        fm.Analysis(m, None, progress=False, on_frame=print)
    msg = str(err.value)
    assert "beam element 5 (nodes 2-3)" in msg and "is 1e-09 m long, 1e-09 of the model's size 1 m" in msg
    assert "mechanism" not in msg and "Merge its nodes" in msg


class _Springs(ElementFamily):
    name = "my springs"
    active_dofs = (0, 1, 2)

    def __init__(self, nodes, wrong_shape=False, nan=False):
        self.nodes = np.asarray(nodes, dtype=np.int64)
        self.wrong_shape, self.nan = wrong_shape, nan

    def evaluate(self, x, R, state, ctx=None):
        m = 6 if self.wrong_shape else 12  # (one node's worth for two nodes)
        f = np.full((1, m), np.nan) if self.nan else np.zeros((1, m))
        return ElementResponse(f=f, k=np.eye(m)[None] * 1e3, state=state)


def _spring_model(**kw):
    m = fm.Model("springs")
    a, b = m.node(0, 0, 0), m.node(1, 0, 0)
    m.add_family(_Springs([[a, b]], **kw))
    m.fix(a)
    m.step("pull").load(b, fx=1.0)
    return m


def test_a_user_element_returning_wrong_shapes_is_named_not_called_a_mechanism():
    with pytest.raises(fm.ModelError) as err:
        fm.solve(_spring_model(wrong_shape=True), None, progress=False, on_frame=print)
    msg = str(err.value)
    assert "element family 'my springs' returned f of shape (1, 6) and k of shape (1, 6, 6)" in msg
    assert "need f (1, 12) and k (1, 12, 12)" in msg and "mechanism" not in msg


def test_a_user_element_returning_nan_is_a_femast_error_naming_it(tmp_path):
    with pytest.raises(fm.FemastError) as err:
        fm.solve(_spring_model(nan=True), tmp_path / "r", progress=False)
    line = error_line(err.value)
    assert "element family 'my springs' returned NaN or infinite internal forces for element 1 (nodes 1, 2)" in line
    assert "not a femast error" not in line
    assert fm.Results(tmp_path / "r").status == "failed"
