"""The mast of :mod:`mast` in femast: one beam family, load control in K increments."""

from __future__ import annotations

import tempfile
import time

import numpy as np
from mast import E_AL, G_AL, SECTIONS

import femast as fm
from femast.analysis import Analysis


def model(mast, n_inc):
    secs = {k: fm.Section(E=E_AL, G=G_AL, **v) for k, v in SECTIONS.items()}
    m = fm.Model(f"mast{mast.n_bays}")
    labels = np.asarray(m.nodes(mast.X))
    m.beams(labels[mast.conn], [secs[k] for k in mast.kind], up=mast.up)  # one call, checked at once
    for i in mast.fixed:
        m.fix(labels[i])
    step = m.step("load", initial_increment=1.0 / n_inc, max_increment=1.0 / n_inc)
    for i, p in zip(mast.tip, mast.P):
        step.load(labels[i], fx=p[0], fy=p[1], fz=p[2])
    return m, labels


def solve(mast, n_inc, tol=1e-6, out=None, disp_tol=None, predicted=True):
    """Build and solve; returns dict(wall, build, analyze, cpu_analyze, iterations, tip_u, analysis)
    (seconds: wall clock, except cpu_analyze: CPU time of this process during the solve).
    ``tol``: relative force tolerance; ``disp_tol``: relative correction tolerance (default ``tol``;
    ``inf``: no correction test, as OpenSees' NormUnbalance); ``predicted``: accept on the predicted next
    correction (``Convergence(predicted=)``)."""
    out = out or tempfile.mkdtemp(prefix="femast_peer_")
    t0 = time.perf_counter()
    m, labels = model(mast, n_inc)
    an = Analysis(
        m,
        out,
        progress=False,
        convergence=fm.Convergence(force_tol=tol, disp_tol=tol if disp_tol is None else disp_tol, predicted=predicted),
    )
    t1 = time.perf_counter()
    c1 = time.process_time()
    an.run()
    t2 = time.perf_counter()
    c2 = time.process_time()
    tip_u = an.x[mast.tip] - an.X0[mast.tip]
    return dict(
        wall=t2 - t0,
        build=t1 - t0,
        analyze=t2 - t1,
        cpu_analyze=c2 - c1,
        iterations=an.summary.iterations,
        increments=an.summary.increments,
        tip_u=tip_u,
        analysis=an,
    )


def warm_up():
    """JIT compile / load the numba cache on a 2-bay mast; returns the seconds it took."""
    from mast import build_mast

    t0 = time.perf_counter()
    solve(build_mast(2), 2)
    return time.perf_counter() - t0


def tip_error(u_a, u_b):
    """Largest tip displacement difference over the largest tip displacement."""
    return float(np.abs(u_a - u_b).max() / np.abs(u_b).max())
