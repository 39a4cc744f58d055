"""femast against OpenSees on the same corotational truss mast (issue 8, items 1-2).

    python benchmarks/peers/compare_opensees.py [--bays 40 400] [--increments 10] [--repeat 3]

For each mast size, builds and solves the mast of ``mast.py`` (tip torsion + shear in K load
increments, full Newton) in femast and in OpenSeesPy, prints wall times (median of --repeat runs,
model building included), Newton iterations, the femast/OpenSees wall-time ratio, and checks that
the tip displacements agree to 1e-4 relative.  femast's numba kernels are compiled (or loaded from
the cache) on a 2-bay mast first; that JIT time is printed separately.

OpenSees is run with every linear system class that applies (UmfPack, SparseGeneral, BandGeneral,
ProfileSPD, ...); the ratio is taken against the fastest, and against UmfPack, OpenSees' general
sparse direct solver.

Newton tolerance.  femast: largest residual force (moment) <= 1e-6 x the largest nodal force
(moment), and the largest correction <= 1e-6 x the increment (Abaqus-like, relative).  OpenSees:
``NormUnbalance`` with an absolute tolerance, set to 1e-6 x the largest nodal force of the tip load
(relative to the same kind of reference).  Both converge quadratically; the displacement agreement
is limited by the formulations, not by the tolerances (tightening both changes the tip displacement
by < 1e-9 relative).

If openseespy is not installed (or cannot load libblas/liblapack), femast's numbers are printed
and the comparison is reported as skipped.
"""

from __future__ import annotations

import argparse
import os
import resource
import statistics
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from mast import build_mast  # noqa: E402
import femast_mast  # noqa: E402
import opensees_mast  # noqa: E402

OPENSEES_SYSTEMS = ("UmfPack", "SparseGeneral", "SparseSYM", "ProfileSPD")


def peak_rss_mb():
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def median_run(fn, repeat):
    runs = [fn() for _ in range(repeat)]
    walls = [r["wall"] for r in runs]
    best = runs[walls.index(statistics.median_low(walls))]
    best["walls"] = walls
    best["wall"] = statistics.median(walls)
    return best


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--bays", type=int, nargs="+", default=[40, 400])
    ap.add_argument("--increments", type=int, default=10)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--tol", type=float, default=1e-6)
    args = ap.parse_args(argv)
    ok_os, os_info = opensees_mast.available()
    jit = femast_mast.warm_up()
    print(f"femast JIT / numba cache load (2-bay warm-up, reported separately): {jit:.2f} s")
    if ok_os:
        print(f"OpenSeesPy {os_info}")
    else:
        print(f"OpenSeesPy NOT AVAILABLE ({os_info}): femast numbers only; comparison skipped.\n"
              "  install with: pip install openseespy  (Debian: apt-get install libblas3 liblapack3)")
    print("wall times: median of %d runs, model building included; machine load makes them noisy" % args.repeat)
    failures = []
    for nb in args.bays:
        mast = build_mast(nb)
        K = args.increments
        fm = median_run(lambda: femast_mast.solve(mast, K, tol=args.tol), args.repeat)
        an = fm.pop("analysis")
        print(f"\n{nb}-bay mast: {len(mast.X)} nodes, {len(mast.conn)} beam elements, {an.dofmap.n_free} free DOFs, "
              f"{K} load increments")
        print(f"  femast   : {fm['wall']:8.3f} s (build {fm['build']:.3f} s, solve {fm['analyze']:.3f} s), "
              f"{fm['iterations']} iterations, runs {', '.join(f'{w:.3f}' for w in fm['walls'])}")
        if not ok_os:
            continue
        tol_os = args.tol * float(abs(mast.P).max())
        results = {}
        for system in OPENSEES_SYSTEMS:
            r = median_run(lambda: opensees_mast.solve(mast, K, tol_os, system=system), args.repeat)
            results[system] = r
            flag = "" if r["ok"] else "  (did not converge)"
            print(f"  OpenSees {system:13s}: {r['wall']:8.3f} s (build {r['build']:.3f} s, analyze "
                  f"{r['analyze']:.3f} s), {r['iterations']} iterations{flag}")
        good = {s: r for s, r in results.items() if r["ok"]}
        fastest = min(good, key=lambda s: good[s]["wall"])
        ref = good[fastest]
        err = femast_mast.tip_error(fm["tip_u"], ref["tip_u"])
        ratio = fm["wall"] / ref["wall"]
        ratio_umf = fm["wall"] / good["UmfPack"]["wall"] if "UmfPack" in good else float("nan")
        print(f"  ratio femast/OpenSees: {ratio:.3f} (fastest OpenSees system, {fastest}; target <= 1.0), "
              f"{ratio_umf:.3f} against UmfPack")
        print(f"  tip displacement: femast {fm['tip_u'][0]}, OpenSees {ref['tip_u'][0]} (corner 0, m)")
        print(f"  largest tip displacement difference / largest tip displacement: {err:.2e} (target <= 1e-4)")
        if err > 1e-4:
            failures.append(f"{nb} bays: tip displacements differ by {err:.2e}")
        if ratio > 1.0:
            failures.append(f"{nb} bays: femast/OpenSees wall-time ratio {ratio:.2f} > 1")
    print(f"\npeak memory (max RSS of this process, both codes): {peak_rss_mb():.0f} MB")
    print("targets: " + ("all met" if not failures else "NOT MET: " + "; ".join(failures)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
