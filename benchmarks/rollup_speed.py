"""Speed of the FE core: a 1000-element cantilever rolled into a full circle by
M = 2 pi EI/L in 20 load increments.  Prints wall time, Newton iterations, time per
iteration and the split between assembly (element kernels + scatter into CSR) and the
sparse linear solve (factorisation + back-substitution) of the same matrices.

    python benchmarks/rollup_speed.py [--elements 1000] [--increments 20]
"""

import argparse
import math
import tempfile
import time

import numpy as np

import femast as fm
from femast.analysis import Analysis


def build(n_el, n_inc):
    sec = fm.Section(E=1e4, G=1e4 / 2.6, A=1.0, Iy=1e-4, Iz=1e-4, J=2e-4)  # EI = 1, L = 1
    m = fm.Model("rollup")
    a, b = m.node(0, 0, 0), m.node(1.0, 0, 0)
    m.beam(a, b, sec, up=(0, 1, 0), n=n_el)
    m.fix(a)
    m.step("roll", initial_increment=1.0 / n_inc, max_increment=1.0 / n_inc).load(b, mz=2 * math.pi)
    return m, b


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--elements", type=int, default=1000)
    ap.add_argument("--increments", type=int, default=20)
    args = ap.parse_args()
    # warm the numba cache / JIT with a tiny model first (compile time is reported separately)
    t0 = time.perf_counter()
    m, _ = build(4, 2)
    Analysis(m, tempfile.mkdtemp(), progress=False).run()
    jit = time.perf_counter() - t0
    m, tip = build(args.elements, args.increments)
    an = Analysis(m, tempfile.mkdtemp(), progress=False)
    t0 = time.perf_counter()
    res = an.run()
    wall = time.perf_counter() - t0
    s = an.summary
    X = res.positions(-1)[m.index(tip)]
    # the same matrix: time one assembly and one factorisation + solve in isolation
    reps = 20
    t0 = time.perf_counter()
    for _ in range(reps):
        responses = an.system.evaluate(None)
        an.assembler.forces([r.f for r in responses])
        K, _ = an.assembler.tangent([r.k for r in responses])
    t_asm = (time.perf_counter() - t0) / reps
    rhs = np.ones(K.shape[0])
    t0 = time.perf_counter()
    for _ in range(reps):
        an.solver.factorize(K)
        an.solver.solve(rhs)
    t_sol = (time.perf_counter() - t0) / reps
    B = an.solver._B  # the permuted matrix femast factorises: bare SuperLU on it is the floor
    t0 = time.perf_counter()
    for _ in range(reps):
        an.solver._factor_permuted(B).solve(rhs[an.solver._perm])
    t_bare = (time.perf_counter() - t0) / reps
    t_it = wall / s.iterations
    print(
        f"1000-element roll-up benchmark: {args.elements} elements, {an.dofmap.n_free} free DOFs, "
        f"{s.increments} increments"
    )
    print(f"  JIT / cache load (small warm-up model): {jit:8.3f} s")
    print(f"  wall time                             : {wall:8.3f} s")
    print(f"  Newton iterations                     : {s.iterations:8d}")
    print(f"  time per iteration                    : {t_it * 1e3:8.2f} ms")
    print(
        f"  in the run: assembly {s.assembly_time:.3f} s, linear solve {s.solve_time:.3f} s, "
        f"other {wall - s.assembly_time - s.solve_time:.3f} s"
    )
    print(
        f"  isolated, same matrix: assembly {t_asm * 1e3:.2f} ms, femast factorise + solve {t_sol * 1e3:.2f} ms "
        f"(bare SuperLU, same ordering: {t_bare * 1e3:.2f} ms, ordering {an.solver.chosen}) "
        f"-> ratio assembly/solve = {t_asm / t_sol:.2f} (target <= 1)"
    )
    print(f"  time per iteration / (factorise + solve) = {t_it / t_sol:.2f} (bare: {t_it / t_bare:.2f}; target <= 1.5)")
    print(f"  tip distance from root: {np.linalg.norm(X):.2e} m (closed circle: 0)")


if __name__ == "__main__":
    main()
