"""The mast of :mod:`mast` in OpenSeesPy: elasticBeamColumn elements with the Corotational
geometric transformation, load control in K increments, full Newton.

OpenSeesPy is an optional benchmark dependency (``pip install openseespy``; on Debian it needs
``apt-get install libblas3 liblapack3``).  :func:`available` says whether it imports.
"""

from __future__ import annotations

import time

import numpy as np
from mast import E_AL, G_AL, SECTIONS, local_frame

_IMPORT_ERROR = None
try:  # pragma: no cover - optional
    import openseespy.opensees as ops
except Exception as exc:  # ImportError, or OSError for a missing libblas/liblapack
    ops = None
    _IMPORT_ERROR = f"{type(exc).__name__}: {exc}"


def available():
    """(True, version) or (False, why)."""
    if ops is None:
        return False, _IMPORT_ERROR
    return True, ops.version() if hasattr(ops, "version") else "?"


def build(mast):
    ops.wipe()
    ops.model("basic", "-ndm", 3, "-ndf", 6)
    for i, x in enumerate(mast.X):
        ops.node(i + 1, *map(float, x))
    for i in mast.fixed:
        ops.fix(int(i) + 1, 1, 1, 1, 1, 1, 1)
    transf = {}
    for e, (a, b) in enumerate(mast.conn):
        _, _, e3 = local_frame(mast.X[a], mast.X[b], mast.up[e])
        # OpenSees: vecxz lies in the local x-z plane, local y = vecxz x x; vecxz = e3 gives the
        # same local y (femast's up-vector) and z axes as femast.
        key = tuple(np.round(e3, 12))
        if key not in transf:
            transf[key] = len(transf) + 1
            ops.geomTransf("Corotational", transf[key], *map(float, e3))
        s = SECTIONS[mast.kind[e]]
        ops.element(
            "elasticBeamColumn",
            e + 1,
            int(a) + 1,
            int(b) + 1,
            s["A"],
            E_AL,
            G_AL,
            s["J"],
            s["Iy"],
            s["Iz"],
            transf[key],
        )
    ops.timeSeries("Linear", 1)
    ops.pattern("Plain", 1, 1)
    for i, p in zip(mast.tip, mast.P):
        ops.load(int(i) + 1, *map(float, p), 0.0, 0.0, 0.0)


def solve(mast, n_inc, tol, system="UmfPack", numberer="RCM"):
    """Build and solve; returns dict(wall, build, analyze, iterations, tip_u (n_tip, 3), ok)."""
    t0 = time.perf_counter()
    build(mast)
    ops.constraints("Plain")
    ops.numberer(numberer)
    if system == "Umfpack-lvalue":
        ops.system("UmfPack", "-lvalueFact", 10)
    else:
        ops.system(system)
    # absolute test on the 2-norm of the unbalanced force vector (forces and moments)
    ops.test("NormUnbalance", tol, 25, 0)
    ops.algorithm("Newton")
    ops.integrator("LoadControl", 1.0 / n_inc)
    ops.analysis("Static")
    t1 = time.perf_counter()
    iters = 0
    ok = 0
    for _ in range(n_inc):
        ok = ops.analyze(1)
        iters += ops.testIter()
        if ok != 0:
            break
    t2 = time.perf_counter()
    tip_u = np.array([ops.nodeDisp(int(i) + 1)[:3] for i in mast.tip])
    ops.wipe()
    return dict(wall=t2 - t0, build=t1 - t0, analyze=t2 - t1, iterations=iters, tip_u=tip_u, ok=ok == 0)
