"""Linear-solver back-ends: the banded LAPACK factorisations, CHOLMOD and
PARDISO against a dense solve, their behaviour on unsymmetric, indefinite and singular matrices,
the automatic choice and the fall-back when an optional back-end is missing."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp

import femast as fm
from femast.analysis import Analysis
from femast.analysis.linalg import backends
from femast.analysis.linalg.banded import BandedFactor, band_of, band_rule
from femast.analysis.linalg.linear import SparseLU
from femast.errors import ModelError, SingularModelError


def chain_matrix(n=300, b=7, asym=0.0, shift=0.0, seed=1):
    """A random sparse band matrix M M^T + n I (symmetric positive definite) with a relative
    unsymmetric perturbation ``asym`` and a diagonal shift ``shift`` (independent of femast)."""
    rng = np.random.default_rng(seed)
    rows, cols, vals = [], [], []
    for i in range(n):
        for j in range(max(0, i - b // 2), i + 1):
            if rng.random() < 0.7 or i == j:
                rows.append(i)
                cols.append(j)
                vals.append(rng.normal())
    M = sp.csr_matrix((vals, (rows, cols)), shape=(n, n))
    A = (M @ M.T + sp.identity(n) * 1.0).tocsr()
    if asym:
        E = A.copy()
        E.data = rng.normal(size=E.nnz) * asym * np.abs(A.data).max()
        A = A + E
    if shift:
        A = A - shift * sp.identity(n)
    A = A.tocsr()
    A.sort_indices()
    return A


def backward_error(A, x, b):
    """Normwise backward error ||b - A x|| / (||A|| ||x|| + ||b||), infinity norms."""
    return np.abs(b - A @ x).max() / (abs(A).sum(axis=1).max() * np.abs(x).max() + np.abs(b).max())


def solve_with(A, backend, rhs):
    lu = SparseLU(backend=backend, pivot_check="always")
    lu.factorize(A)
    return lu, lu.solve(rhs)


@pytest.mark.parametrize("asym", [0.0, 1e-10])
def test_banded_cholesky_refined_to_the_exact_solution(asym):
    A = chain_matrix(asym=asym)
    b = np.random.default_rng(2).normal(size=A.shape[0])
    lu, x = solve_with(A, "banded", b)
    assert lu.engine == "banded" and lu._lu.kind == "cholesky"
    # the refinement stops at a backward error <= 1e-14 (BACKWARD_TOL); 1e-13 leaves round-off room
    assert backward_error(A, x, b) <= 1e-13
    x_ref = np.linalg.solve(A.toarray(), b)
    # the matrix is well conditioned (cond ~ 1e3): forward error ~ cond x backward error
    assert np.abs(x - x_ref).max() <= 1e-9 * np.abs(x_ref).max()


def test_banded_unsymmetric_uses_the_lu():
    A = chain_matrix(asym=1e-2)
    b = np.random.default_rng(3).normal(size=A.shape[0])
    lu, x = solve_with(A, "banded", b)
    assert lu._lu.kind == "lu"
    assert backward_error(A, x, b) <= 1e-14  # partial pivoting LU: backward stable (1e-16 x growth)


def test_banded_indefinite_falls_back_to_lu():
    A = chain_matrix()
    w = np.linalg.eigvalsh(A.toarray())
    A2 = (A - 0.5 * (w[3] + w[4]) * sp.identity(A.shape[0])).tocsr()  # 4 negative eigenvalues
    b = np.random.default_rng(4).normal(size=A.shape[0])
    lu, x = solve_with(A2, "banded", b)
    assert lu._lu.kind == "lu"
    assert backward_error(A2, x, b) <= 1e-14  # as above
    x_ref = np.linalg.solve(A2.toarray(), b)
    assert np.abs(x - x_ref).max() <= 1e-8 * np.abs(x_ref).max()  # cond ~ 1e5 here


@pytest.mark.parametrize("backend", ["superlu", "banded"])
def test_singular_and_nearly_singular_tangents_are_reported(backend):
    """A mechanism: one DOF decoupled from the rest with a zero (or 1e-20 relative) stiffness.  (A
    pivot 1e-15 of the largest is a stiffness contrast a model can have, judged against its own DOF:
    tests/analysis/test_singularity_judged_on_the_model.py; 1e-20 is below double precision.)"""
    A = chain_matrix().tolil()
    i = 150
    big = abs(A).max()
    for eps in (0.0, 1e-20):  # exactly singular, and a pivot below double precision against the largest
        S = A.copy()
        S[i, :] = 0.0
        S[:, i] = 0.0
        S[i, i] = eps * big
        S = S.tocsr()
        S.eliminate_zeros()
        if eps == 0.0:  # keep the diagonal entry in the pattern (an assembled tangent has it)
            S = (S + sp.csr_matrix(([1e-300], ([i], [i])), shape=S.shape)).tocsr()
            S.data[S.data == 1e-300] = 0.0
        with pytest.raises(SingularModelError):
            solve_with(S, backend, np.ones(S.shape[0]))


def test_band_rule_mast_yes_compact_mesh_no():
    # a chain of frames (mast-like): each node couples to its frame and the next
    n_frames, per = 200, 24
    blocks = sp.kron(sp.diags([1.0, 1.0, 1.0], [-1, 0, 1], shape=(n_frames, n_frames)), np.ones((per, per)))
    K = sp.csr_matrix(blocks)
    assert band_rule(K.shape[0], 2 * per - 1, K.nnz)
    # a 12 x 12 x 12 grid Laplacian (compact 3D mesh): its RCM band is ~ n^(2/3)
    g = 12
    L1 = sp.diags([1.0, 1.0, 1.0], [-1, 0, 1], shape=(g, g))
    I = sp.identity(g)
    L3 = (sp.kron(sp.kron(L1, I), I) + sp.kron(sp.kron(I, L1), I) + sp.kron(sp.kron(I, I), L1)).tocsr()
    lu = SparseLU(ordering="rcm")
    L3 = (L3 + 10 * sp.identity(g**3)).tocsr()
    lu.factorize(L3)
    assert not band_rule(L3.shape[0], band_of(lu._B.indptr, lu._B.indices), L3.nnz)
    # not banded, >= 1000 DOFs: PARDISO where installed, else SuperLU
    assert lu.chosen == "rcm" and lu.engine == ("pardiso" if backends.available("pardiso")[0] else "superlu")
    b = np.ones(L3.shape[0])
    assert backward_error(L3, lu.solve(b), b) <= 1e-14  # either LU is backward stable


def test_small_unbanded_model_stays_on_superlu():
    A = chain_matrix(n=300, b=7)
    P = sp.csr_matrix(np.random.default_rng(7).permutation(np.eye(300)))
    lu = SparseLU(ordering="mmd")  # not RCM: no band
    lu.factorize((P @ A @ P.T).tocsr())
    assert lu.engine == "superlu"  # 300 DOFs < PARDISO_MIN_DOFS


def test_unknown_backend_is_a_model_error():
    with pytest.raises(ModelError, match="pardisso"):
        SparseLU(backend="pardisso")


def test_missing_optional_backend_falls_back_with_a_message(monkeypatch):
    monkeypatch.setattr(backends, "available", lambda name: (False, "No module named 'pypardiso'"))
    A = chain_matrix()
    b = np.ones(A.shape[0])
    with pytest.warns(UserWarning, match="pip install 'femast\\[pardiso\\]'"):
        lu, x = solve_with(A, "pardiso", b)
    assert lu.engine == "superlu"
    assert backward_error(A, x, b) <= 1e-14  # SuperLU: backward stable


@pytest.mark.parametrize("backend", ["cholmod", "pardiso"])
@pytest.mark.parametrize("asym", [0.0, 1e-2])
def test_optional_backends_when_installed(backend, asym):
    if not backends.available(backend)[0]:
        pytest.skip(f"{backend} not installed")
    A = chain_matrix(asym=asym)
    b = np.random.default_rng(5).normal(size=A.shape[0])
    lu, x = solve_with(A, backend, b)
    assert lu.engine == backend
    # CHOLMOD: refined to BACKWARD_TOL or SuperLU's LU; PARDISO: LU with weighted matching
    assert backward_error(A, x, b) <= 1e-13


def mast_model(n_bays=6):
    """A small three-longeron beam mast with a tip torque and shear (fixed base)."""
    m = fm.Model("mast")
    sec = fm.circular_tube(0.02, 0.016, E=70e9)
    ang = np.radians([90, 210, 330])
    frames = [[m.node(0.5 * np.cos(a), 0.5 * np.sin(a), 1.0 * j) for a in ang] for j in range(n_bays + 1)]
    for j in range(n_bays):
        for k in range(3):
            m.beam(frames[j][k], frames[j + 1][k], sec, up=(1.0, 0.0, 0.0))  # longeron (along z)
            m.beam(frames[j + 1][k], frames[j + 1][(k + 1) % 3], sec)  # batten (horizontal)
            m.beam(frames[j][k], frames[j + 1][(k + 1) % 3], sec)  # diagonal
    for nd in frames[0]:
        m.fix(nd)
    st = m.step("load", initial_increment=0.25, max_increment=0.25)
    for k, nd in enumerate(frames[-1]):
        st.load(nd, fx=200.0, fy=300.0 * np.cos(ang[k]), fz=-100.0)
    return m, frames[-1]


def test_mast_auto_picks_banded_and_matches_superlu():
    runs = {}
    for be in ("superlu", "auto"):
        m, tip = mast_model()
        an = Analysis(m, None, progress=False, on_frame=lambda f: None, linear_solver=be)
        an.run()
        runs[be] = an
    assert runs["auto"].solver.engine == "banded"
    assert runs["auto"].summary.iterations == runs["superlu"].summary.iterations
    u = {k: a.x - a.X0 for k, a in runs.items()}
    # both solve each Newton step to a backward error ~1e-15; the converged states then differ
    # by round-off times the conditioning of the slender structure
    assert np.abs(u["auto"] - u["superlu"]).max() <= 1e-10 * np.abs(u["superlu"]).max()


@pytest.mark.parametrize("asym, shift", [(0.0, 0.0), (1e-10, 0.0), (1e-2, 0.0), (0.0, "indefinite")])
def test_band_storage_input_factorises_bit_for_bit_as_the_csc_input(asym, shift):
    """The matrix written straight into the band back-end's split band storage (as the assembler
    does for a mast) gives the very factorisation and solutions of the same values in B's CSC data:
    Cholesky (symmetric), Cholesky refined against B (1e-10 unsymmetric), LU (1e-2 unsymmetric),
    LU after a failed Cholesky (indefinite)."""
    A = chain_matrix(asym=asym)
    if shift == "indefinite":
        w = np.linalg.eigvalsh(A.toarray())
        A = (A - 0.5 * (w[3] + w[4]) * sp.identity(A.shape[0])).tocsr()
        A.sort_indices()
    B = A.tocsc()
    B.sort_indices()
    rhs = np.random.default_rng(5).normal(size=(3, A.shape[0]))
    csc = BandedFactor(B.copy())
    csc.factorize()
    direct = BandedFactor(B.copy())
    pos = direct.band_positions(np.arange(B.nnz))
    direct.band_values[:] = 0.0
    direct.band_values[pos] = B.data
    direct.factorize_band()
    assert csc.kind == direct.kind and csc.asymmetry == direct.asymmetry
    for b in rhs:
        assert np.array_equal(csc.solve(b), direct.solve(b))
    assert csc.refinements == direct.refinements and csc.fallbacks == direct.fallbacks
    assert direct.kind == ("lu" if asym == 1e-2 or shift else "cholesky")
    if asym == 1e-10:
        assert direct.refinements > 0  # the refinement against B (from the band storage) ran


def test_band_positions_through_the_permutation_compose_the_two_maps():
    """Positions of a matrix K's entries in the band storage of B = P K P^T (given B.data =
    K.data[gather]) are those of B's entries at the permuted positions."""
    from femast.analysis.linalg.ordering import permuted, permuted_positions

    K = chain_matrix(n=120, b=5, asym=1e-3)
    perm = np.random.default_rng(8).permutation(K.shape[0])
    B, gather = permuted(K, perm)
    f = BandedFactor(B)
    pos = np.random.default_rng(9).integers(-1, K.nnz, size=(30, 4, 4))
    np.testing.assert_array_equal(f.band_positions(pos, gather), f.band_positions(permuted_positions(gather, pos)))
    direct = f.band_positions(np.arange(B.nnz))
    assert np.unique(direct).size == B.nnz  # one slot per entry of B
