"""Arc-length verification cases, shared by tests and benchmarks/arc_length.py.

Each returns the femast path (displacement of the loaded point along the load, load) and the
independent reference from :mod:`femast.verification.references`."""

from __future__ import annotations

import tempfile

from ..analysis import Analysis
from ..analysis.control.arclength import ArcLength
from ..model import Model
from ..model.sections import Section
from . import references as ref


def _planar(m):
    """Fix the out-of-plane DOFs (uz, rx, ry) of every node of a planar x-y model."""
    for lab in m.node_labels:
        m.fix(int(lab), "uz", "rx", "ry")


def von_mises_truss(a=1.0, h=0.1, EA=1e6, out=None, progress=False):
    """Shallow two-bar truss, apex load downward, through snap-through to w = 2.5 h."""
    m = Model("von Mises truss")
    left, right, apex = m.node(-a, 0, 0), m.node(a, 0, 0), m.node(0, h, 0)
    m.truss(left, apex, EA=EA)
    m.truss(right, apex, EA=EA)
    m.fix(left)
    m.fix(right)
    m.fix(apex, "ux", "uz")  # the symmetric path of the analytic solution
    (w1, P1), _ = ref.von_mises_truss_limit_points(a, h, EA)
    step = m.step(
        "snap",
        max_increments=400,
        control=ArcLength(initial_load_factor=0.05, max_load_factor=10.0, max_arc=2.0, monitor=(apex, "uy", -2.5 * h)),
    )
    step.load(apex, fy=-P1)
    res = Analysis(m, out or tempfile.mkdtemp(), progress=progress).run()
    w = -res.node_history(apex, "uy")
    P = res.scalar_history("load_factor") * P1
    return dict(w=w, P=P, P_exact=ref.von_mises_truss_load(w, a, h, EA), P_limit=P1, h=h, results=res)


def lee_frame(n_per_member=10, out=None, progress=False):
    """Lee's frame (L = 120, E = 7.2e6, A = 6, I = 2, load 24 from the knee), pinned supports."""
    p = ref.LEE_FRAME
    L, E, A, I, off = p["L"], p["E"], p["A"], p["I"], p["load_offset"]
    sec = Section(E=E, G=E / 2.6, A=A, Iy=I, Iz=I, J=2 * I, name="Lee")
    m = Model("Lee frame")
    base, knee, load_pt, end = m.node(0, 0, 0), m.node(0, L, 0), m.node(off, L, 0), m.node(L, L, 0)
    m.beam(base, knee, sec, up=(1, 0, 0), n=n_per_member)
    m.beam(knee, load_pt, sec, up=(0, 1, 0), n=max(2, n_per_member // 5))
    m.beam(load_pt, end, sec, up=(0, 1, 0), n=n_per_member)
    _planar(m)
    m.fix(base, "ux", "uy")
    m.fix(end, "ux", "uy")
    P_ref = 2e4
    step = m.step(
        "load",
        max_increments=300,
        control=ArcLength(initial_load_factor=0.1, max_load_factor=5.0, monitor=(load_pt, "uy", -90.0)),
    )
    step.load(load_pt, fy=-P_ref)
    res = Analysis(m, out or tempfile.mkdtemp(), progress=progress).run()
    v = -res.node_history(load_pt, "uy")
    u = res.node_history(load_pt, "ux")
    P = res.scalar_history("load_factor") * P_ref
    return dict(u=u, v=v, P=P, results=res)


def williams_toggle(n_per_member=8, out=None, progress=False):
    """Williams' toggle (clamped, half span 12.943 in, rise 0.386 in, 0.753 x 0.243 in section,
    E = 10.3e6 psi), apex load."""
    p = ref.WILLIAMS_TOGGLE
    a, h, E, b, d = p["half_span"], p["rise"], p["E"], p["b"], p["d"]
    sec = Section(E=E, G=E / 2.6, A=b * d, Iy=b * d**3 / 12, Iz=b * d**3 / 12, J=b * d**3 / 3, name="toggle")
    m = Model("Williams toggle")
    left, apex, right = m.node(-a, 0, 0), m.node(0, h, 0), m.node(a, 0, 0)
    m.beam(left, apex, sec, up=(0, 0, 1), n=n_per_member)
    m.beam(apex, right, sec, up=(0, 0, 1), n=n_per_member)
    _planar(m)
    m.fix(left)
    m.fix(right)
    P_ref = 50.0
    step = m.step(
        "load",
        max_increments=300,
        control=ArcLength(initial_load_factor=0.05, max_load_factor=2.0, monitor=(apex, "uy", -0.6)),
    )
    step.load(apex, fy=-P_ref)
    res = Analysis(m, out or tempfile.mkdtemp(), progress=progress).run()
    v = -res.node_history(apex, "uy")
    P = res.scalar_history("load_factor") * P_ref
    return dict(v=v, P=P, results=res)
