"""The floor of the Newton loop: femast's own parts in a loop written for one model.

    python benchmarks/newton_floor.py [--bays 40] [--repeat 3]

Solves the truss mast of ``benchmarks/peers/mast.py`` (10 load increments) twice per repeat: with a
minimal Newton loop that calls femast's beam kernel, force and tangent scatters, SuperLU binding,
solution check and configuration update directly, writing one frame per increment, and then with
``femast.analysis.Analysis``.  It prints the time per iteration over the SuperLU time of the same
run for both.  The gap is the cost of the general Newton loop (steps, controls, prescribed values,
constraints, stabilisation, line search, checks): what a compiled loop for this one kind of model
could save.  The minimal loop must reach the same tip displacements (printed).

Only for unconstrained models of one beam family under load control; it reads internals of the
analysis (the solver's permuted matrix and positions) and is a measurement, not a solver.
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "peers"))


def minimal_run(mast, n_inc):
    """Solve with the minimal loop; returns (seconds, iterations, SuperLU seconds, tip displacements)."""
    import femast_mast
    import scipy.sparse as sp
    from scipy.sparse.linalg._dsolve._superlu import gstrf

    from femast.analysis import Analysis
    from femast.analysis.assembly import _scatter_matrix, _scatter_vector
    from femast.analysis.configuration import update_configuration
    from femast.analysis.convergence import Convergence, force_moment_abs_max
    from femast.analysis.linalg.linear import _unpermute
    from femast.analysis.linalg.ordering import permuted_positions
    from femast.elements.beam_corot import beam_family_kernel
    from femast.post.results import ResultsWriter
    from femast.rotations import rotation_vectors

    m, _ = femast_mast.model(mast, n_inc)
    out = tempfile.mkdtemp(prefix="femast_floor_")
    tol = 1e-6
    an = Analysis(m, out, progress=False, convergence=Convergence(force_tol=tol, disp_tol=tol))
    fam, solver, nf = an.families[0], an.solver, an.dofmap.n_free
    eqs = an.assembler.eqs[0]
    pos = permuted_positions(solver._gather, an.assembler.pos_ff[0])  # into the permuted CSC matrix B
    B, perm = solver._B, solver._perm
    ind, ptr = B.indices.astype(np.intc), B.indptr.astype(np.intc)
    opts = dict(
        DiagPivotThresh=solver.pivot_threshold, ColPerm="NATURAL", PanelSize=None, Relax=None, SymmetricMode=True
    )
    P_end = np.zeros((len(an.X0), 6))
    for c in m.steps[0].loads:
        P_end[m.index(c.node), c.dof] = c.magnitude
    P_free = P_end[an.act_node, an.act_dof][:nf]
    x, R, spin, W = an.x, an.R, an.spin, np.zeros_like(an.spin)
    n, L = fam.n_elements, an.length
    no_i, no_f = np.zeros(0, np.int64), np.zeros(0)
    F = np.zeros(an.dofmap.n_active)
    writer = ResultsWriter(out, m, an.families)
    t0 = time.perf_counter()
    iters, slu = 0, 0.0
    for inc in range(1, n_inc + 1):
        P = P_free * inc / n_inc
        Du = np.zeros(nf)
        du = None
        while True:
            f, K = np.empty((n, 12)), np.empty((n, 12, 12))
            sf, energy = np.empty((n, 2, 6)), np.empty(n)
            beam_family_kernel(
                fam.nodes, x, R, fam.E0, fam.l0, fam.EA, fam.GJ, fam.EIy, fam.EIz, fam.length_factor, f, K, sf, energy
            )
            F[:] = 0.0
            _scatter_vector(f, eqs, F)
            r = P - F[:nf]
            if du is not None:  # femast's convergence test, with the analysis' reference forces
                fm, mm = force_moment_abs_max(f)
                if an.convergence.check(r, du, Du, an.is_rot, max(fm, 1e-2 * mm / L), max(mm, 1e-2 * fm * L), L, iters)[
                    0
                ]:
                    break
            B.data[:] = 0.0
            _scatter_matrix(K, pos, B.data)
            ts = time.perf_counter()
            lu = gstrf(nf, B.nnz, B.data, ind, ptr, csc_construct_func=sp.csc_array, ilu=False, options=opts)
            y = lu.solve(r[perm])
            slu += time.perf_counter() - ts
            du = np.empty(nf)
            if not _unpermute(y, perm, du) < np.inf:
                raise FloatingPointError("non-finite correction")
            update_configuration(x, spin, R, W, an.free_node, an.free_dof, du, no_i, no_i, no_f)
            Du += du
            iters += 1
        writer.frame(
            U=x - an.X0,
            R=R.copy(),
            UR=rotation_vectors(R),
            URA=spin.copy(),
            P=P_end * inc / n_inc,
            RF=np.zeros((len(x), 6)),
            **{"el/beam/section_forces": sf},
        )
        writer.status("load", inc, 1, iters, inc / n_inc, inc / n_inc, 1 / n_inc, inc / n_inc)
    seconds = time.perf_counter() - t0
    writer.close({})
    return seconds, iters, slu, x[mast.tip] - an.X0[mast.tip]


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--bays", type=int, default=40)
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args(argv)
    import femast_mast
    from mast import build_mast

    femast_mast.warm_up()
    mast = build_mast(args.bays)
    ref = femast_mast.solve(mast, 10)
    minimal_run(mast, 10)
    print(f"{args.bays}-bay mast, 10 load increments; time per Newton iteration / SuperLU time in the same run")
    for _ in range(args.repeat):
        sec, it, slu, tip = minimal_run(mast, 10)
        r = femast_mast.solve(mast, 10)
        s = r["analysis"].summary
        slu_a = r["analysis"].solver.superlu_seconds
        print(
            f"  minimal loop: {1e3 * sec / it:6.3f} ms/iteration, ratio {sec / slu:.2f} ({it} iterations, "
            f"tip differs from the analysis' by {np.abs(tip - ref['tip_u']).max():.1e} m)   "
            f"Analysis: {1e3 * s.increment_time / r['iterations']:6.3f} ms/iteration, ratio "
            f"{s.increment_time / slu_a:.2f} over the increments, {r['analyze'] / slu_a:.2f} over the run"
        )


if __name__ == "__main__":
    sys.exit(main())
