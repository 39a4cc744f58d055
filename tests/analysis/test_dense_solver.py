"""The dense LAPACK LU for small tangents: solutions against numpy's dense solve,
unsymmetric, indefinite and singular matrices, the automatic rule (dense up to DENSE_MAX_DOFS) and
an analysis through it against SuperLU."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp
from test_linear_backends import backward_error, chain_matrix

import femast as fm
from femast.analysis import Analysis
from femast.analysis.linalg import backends, dense
from femast.analysis.linalg.linear import SparseLU
from femast.errors import SingularModelError


def solve(A, backend, b, pivot_check="always"):
    lu = SparseLU(backend=backend, pivot_check=pivot_check)
    lu.factorize(A)
    return lu, lu.solve(b)


@pytest.mark.parametrize("asym", [0.0, 1e-2])
def test_dense_lu_solves_like_numpy(asym):
    A = chain_matrix(n=40, b=7, asym=asym)
    b = np.random.default_rng(2).normal(size=40)
    for backend in ("dense", "auto"):  # 40 DOFs: the automatic rule takes the dense LU
        lu, x = solve(A, backend, b)
        assert lu.engine == "dense"
        # LU with partial pivoting: backward stable (~1e-16 x a small growth factor)
        assert backward_error(A, x, b) <= 1e-14
        x_ref = np.linalg.solve(A.toarray(), b)
        # cond(A) ~ 1e2 here: forward error ~ cond x backward error, 1e-12 leaves room
        assert np.abs(x - x_ref).max() <= 1e-12 * np.abs(x_ref).max()


def test_dense_lu_indefinite():
    A = chain_matrix(n=50)
    w = np.linalg.eigvalsh(A.toarray())
    A2 = (A - 0.5 * (w[2] + w[3]) * sp.identity(50)).tocsr()  # 3 negative eigenvalues: a limit point passed
    b = np.random.default_rng(4).normal(size=50)
    lu, x = solve(A2, "auto", b)
    assert lu.engine == "dense"
    assert backward_error(A2, x, b) <= 1e-14  # as above
    x_ref = np.linalg.solve(A2.toarray(), b)
    # the shift leaves cond ~ 1e3-1e4: forward error ~ cond x 1e-16
    assert np.abs(x - x_ref).max() <= 1e-9 * np.abs(x_ref).max()


def test_dense_lu_singular_is_reported():
    A = chain_matrix(n=40).tolil()
    big = abs(A).max()
    for eps in (0.0, 1e-20):  # exactly singular, and a pivot below double precision against the largest
        S = A.copy()
        S[20, :] = 0.0
        S[:, 20] = 0.0
        S[20, 20] = eps * big
        S = S.tocsr()
        if eps == 0.0:  # keep the diagonal entry in the pattern (an assembled tangent has it)
            S = (S + sp.csr_matrix(([1e-300], ([20], [20])), shape=S.shape)).tocsr()
            S.data[S.data == 1e-300] = 0.0
        with pytest.raises(SingularModelError):
            solve(S, "dense", np.ones(40))
        with pytest.raises(SingularModelError):  # the first factorisation of a pattern is always tested
            solve(S, "auto", np.ones(40), pivot_check="auto")


def test_rule_dense_up_to_the_limit_then_band_or_superlu():
    n = dense.DENSE_MAX_DOFS
    for size, want in ((n, "dense"), (n + 1, "banded")):
        lu = SparseLU()
        lu.factorize(chain_matrix(n=size, b=7))
        assert lu.engine == want, size
    # just above the limit and not banded (a random symmetric pattern, minimum degree): SuperLU
    rng = np.random.default_rng(5)
    R = sp.random(n + 1, n + 1, density=0.3, random_state=rng)
    A = (R @ R.T + (n + 1) * sp.identity(n + 1)).tocsr()
    lu = SparseLU(ordering="mmd")
    lu.factorize(A)
    assert lu.engine == "superlu"


def test_forced_dense_beyond_its_limit_falls_back(monkeypatch):
    monkeypatch.setattr(backends, "DENSE_FORCED_MAX", 30)
    with pytest.warns(UserWarning, match="beyond its limit"):
        lu, x = solve(chain_matrix(n=40), "dense", np.ones(40))
    assert lu.engine == "superlu"


def bend(n_el=8):
    """The 45-degree bend (Bathe-Bolourchi): 8 beams, 48 DOFs, a tip load out of its plane."""
    m = fm.Model("bend")
    ang = np.linspace(0.0, np.pi / 4, n_el + 1)
    n = np.asarray(m.nodes(np.column_stack([100 * (1 - np.cos(ang)), 100 * np.sin(ang), 0 * ang])))
    m.beams(
        np.column_stack([n[:-1], n[1:]]),
        fm.Section(E=1e7, G=5e6, A=1.0, Iy=1 / 12, Iz=1 / 12, J=0.140577),
        up=(0.0, 0.0, 1.0),
    )
    m.fix(n[0])
    m.step("load", initial_increment=0.1, max_increment=0.1).load(n[-1], fz=600.0)
    return m


def test_bend_through_the_dense_lu_matches_superlu():
    runs = {}
    for be in ("superlu", "auto"):
        an = Analysis(bend(), None, progress=False, on_frame=lambda f: None, linear_solver=be)
        an.run()
        runs[be] = an
    assert runs["auto"].solver.engine == "dense"
    assert runs["auto"].summary.iterations == runs["superlu"].summary.iterations
    u = {k: a.x - a.X0 for k, a in runs.items()}
    # both solve each Newton step to a backward error ~1e-16; the converged states differ by
    # round-off times the conditioning of the slender cantilever
    assert np.abs(u["auto"] - u["superlu"]).max() <= 1e-10 * np.abs(u["superlu"]).max()
