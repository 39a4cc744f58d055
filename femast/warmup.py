"""``femast warmup``: compile every femast kernel ahead, in this process.

Small models of each element family run once (a beam and truss cantilever, the ADAM bay with its
cables, latches and ball joints, the Rocaspect guyed mast with its shrouds, the latch law and the
effects' operators), so numba compiles their kernels into its on-disk cache (or loads them from
it): for CI images and cluster workers, whose first job should not wait for the compiler.  This
module sits above the application packages it exercises (adam, guyed, effects); nothing in the core
imports it.
"""

from __future__ import annotations

import time


def _warm_core():
    """A beam + truss cantilever with a rigid body, a load step and an arc-length step."""
    import femast as fm

    m = fm.Model("warmup")
    a = m.node(0.0, 0.0, 0.0)
    b = m.node(1.0, 0.0, 0.0)
    c = m.node(1.0, 0.5, 0.0)
    m.beam(a, b, fm.circular_tube(0.03, 0.026, E=70e9), up=(0, 0, 1), n=4)
    m.truss(b, c, EA=1e6)
    m.fix(a)
    m.fix(c)
    m.step("load", initial_increment=0.5).load(b, fz=-10.0, mx=1.0)
    fm.Analysis(m, None, progress=False, on_frame=lambda frame: None).run()


def _warm_adam():
    """The ADAM bay (cables over pulleys and latches, friction ball joints, joint springs, rigid
    bodies and ties) through its preload and a short twist."""
    import femast as fm
    from femast.adam import build_bay
    from femast.adam.steps import CONVERGENCE, add_idealised_torsion, add_initial_steps

    am = build_bay()
    add_initial_steps(am)
    add_idealised_torsion(am, 0.01, max_increment=0.5, unload=False)
    fm.Analysis(am.model, None, progress=False, convergence=CONVERGENCE, on_frame=lambda frame: None).run()


def _warm_guyed():
    """The Rocaspect guyed mast with its shroud cables: pretension and one small wrench."""
    from femast.guyed.fe_mast import MastFE

    MastFE(400.0, n_beam=4).run_wrenches([[1.0, 0.0, 0.0, 0.0, 0.0, 0.0]])


def _warm_laws():
    """The latch law and the hysteresis operators of the effects, called from Python."""
    import numpy as np

    from femast.effects.operators import play, proportional_play
    from femast.elements.latch_law import latch_force

    x = np.linspace(-1e-3, 1e-3, 5)
    latch_force(x, 1.0, derivative=True)
    play(x, 1e-4)
    proportional_play(x, 0.1)


PARTS = (
    ("core: beams, trusses, solver", _warm_core),
    ("ADAM bay: cables, latches, ball joints", _warm_adam),
    ("guyed mast: shroud cables", _warm_guyed),
    ("latch law and effect operators", _warm_laws),
)


def warmup(report=print) -> float:
    """Compile (or load from the cache) every femast kernel in this process; returns the wall time, s."""
    t_all = time.perf_counter()
    for what, fn in PARTS:
        t0 = time.perf_counter()
        fn()
        report(f"  {what}: {time.perf_counter() - t0:.1f} s")
    return time.perf_counter() - t_all
