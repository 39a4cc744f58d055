"""The fast paths of the Newton loop give the same answers as the plain ones.

* converged responses of path-independent families reused at the next increment's start;
* the symbolic analysis (ordering) done from the assembly pattern at set-up;
* K_ff assembled straight into the linear solver's permuted matrix;
* frames written as increments converge (every one on disk, a write error raised at once);
* a NaN in an element tangent named in the error, although element matrices are not scanned.
"""

import json
import os

import numpy as np
import pytest
import scipy.sparse as sp
import scipy.sparse.linalg as spla

import femast as fm
from femast.analysis import Analysis
from femast.analysis.linalg.linear import SparseLU
from femast.elements.base import ElementFamily, ElementResponse
from femast.errors import ConvergenceError
from femast.post.results import ResultsWriter


def _frame_model(n_bays=3):
    """A small 3D frame under a tip torque and shear: beams only, 4 load increments."""
    m = fm.Model("frame")
    sec = fm.circular_tube(0.02, 0.018, E=70e9)
    corners = [(0, 0), (1, 0), (1, 1), (0, 1)]
    rows = [[m.node(x, y, float(z)) for x, y in corners] for z in range(n_bays + 1)]
    for z in range(n_bays + 1):
        for i in range(4):
            if z > 0:
                m.beam(rows[z - 1][i], rows[z][i], sec, up=(1, 1, 0))
                m.beam(rows[z - 1][i], rows[z][(i + 1) % 4], sec, up=(0, 0, 1))
            m.beam(rows[z][i], rows[z][(i + 1) % 4], sec, up=(0, 0, 1))
    for a in rows[0]:
        m.fix(a)
    st = m.step("load", initial_increment=0.25, max_increment=0.25)
    for a, (fx, fy) in zip(rows[-1], [(0, -1), (1, 0), (0, 1), (-1, 0)]):
        st.load(a, fx=300.0 * fx + 100.0, fy=300.0 * fy)
    return m, rows


class _Counting:
    """Count evaluations of every family of an analysis."""

    def __init__(self, an):
        self.calls = 0
        for f in an.families:
            original = f.evaluate

            def evaluate(*args, _original=original, **kw):
                self.calls += 1
                return _original(*args, **kw)

            f.evaluate = evaluate


def test_reused_responses_save_one_evaluation_per_increment_and_change_nothing(tmp_path):
    m, rows = _frame_model()
    # tangent="full": a path-dependent family also stops "auto" from reusing the last factorisation
    # (newton.py), which is not what is compared here
    fast = Analysis(m, tmp_path / "fast", progress=False, tangent="full")
    count = _Counting(fast)
    fast.run()
    # one evaluation per Newton iteration, plus the first increment's start (plus the initial frame)
    assert count.calls == fast.summary.iterations + 2
    slow = Analysis(m, tmp_path / "slow", progress=False, tangent="full")
    for f in slow.families:
        f.path_independent = False  # the instance attribute hides the class's True
    count_slow = _Counting(slow)
    slow.run()
    assert count_slow.calls == slow.summary.iterations + slow.summary.increments + 1
    # the reused response is the very response of that configuration: identical, bit for bit
    assert slow.summary.iterations == fast.summary.iterations
    np.testing.assert_array_equal(fast.x, slow.x)
    np.testing.assert_array_equal(fast.R, slow.R)


def test_direct_assembly_into_the_solver_matches_a_csr_tangent(tmp_path):
    m, rows = _frame_model()
    an = Analysis(m, tmp_path / "r", progress=False)
    assert an.solver.chosen == "rcm" and an.solver.analyses == 1  # ordering chosen at set-up
    an.run()
    assert an.solver.analyses == 1  # never re-analysed
    resp = an.system.evaluate(None)
    an.system.residual(resp, an.loads)
    K, _ = an.system.tangent(resp, with_fc=False)
    Kfc, none = an.system.factorize_tangent(resp, with_fc=False)
    assert Kfc is None and none is None  # went straight into the solver's matrix
    rhs = np.random.default_rng(1).normal(size=K.shape[0])
    x_direct = an.solver.solve(rhs)
    x_ref = spla.spsolve(K.tocsc(), rhs)
    # same matrix, same pivots up to ordering: agreement to round-off times the condition number
    np.testing.assert_allclose(x_direct, x_ref, rtol=1e-8, atol=1e-12 * np.abs(x_ref).max())


def _grid_laplacian(n):
    """3D n^3 grid Laplacian plus identity: compact, not chain-like (RCM envelope >> nnz)."""
    one = sp.diags([-np.ones(n - 1), 2 * np.ones(n), -np.ones(n - 1)], [-1, 0, 1])
    eye = sp.identity(n)
    L = sp.kron(sp.kron(one, eye), eye) + sp.kron(sp.kron(eye, one), eye) + sp.kron(sp.kron(eye, eye), one)
    return (L + sp.identity(n**3)).tocsr()


def test_rcm_kept_from_the_pattern_only_when_its_envelope_bounds_the_fill():
    # a banded (chain-like) matrix: the RCM envelope holds nnz(K) entries, RCM is kept at once
    n = 200
    band = sp.diags(
        [np.ones(n - 2), -np.ones(n - 1), 4 * np.ones(n), -np.ones(n - 1), np.ones(n - 2)], [-2, -1, 0, 1, 2]
    ).tocsr()
    s = SparseLU()
    assert s.analyse(band) == "rcm"
    s.factorize(band)
    b = np.arange(n, dtype=float)
    np.testing.assert_allclose(band @ s.solve(b), b, rtol=1e-12)  # well conditioned (diag. dominant)
    # a compact 3D grid: envelope >> 2 nnz, so the choice is left to trial factorisations
    G = _grid_laplacian(8)
    s = SparseLU()
    assert s.analyse(G) is None and s.chosen is None
    s.factorize(G)
    assert s.chosen == "mmd"  # minimum degree beats RCM on a 3D grid
    b = np.ones(G.shape[0])
    np.testing.assert_allclose(G @ s.solve(b), b, rtol=1e-10)  # condition number ~25


def test_direct_superlu_call_gives_splus_factorisation_bit_for_bit():
    # an unsymmetric matrix with weak diagonals, so that threshold pivoting interchanges rows
    rng = np.random.default_rng(3)
    n = 120
    K = (sp.random(n, n, density=0.05, random_state=rng) + sp.diags(rng.uniform(-1e-3, 1.0, n))).tocsr()
    K = (K + abs(K).T * 0.0).tocsr()  # structurally symmetric, as femast tangents are
    K.sort_indices()
    s = SparseLU(ordering="rcm")
    assert s.analyse(K) == "rcm"
    s.values[:] = K.data[s._gather]
    s.factorize_values()  # the direct binding
    B = s._B
    ref = spla.splu(B, permc_spec="NATURAL", diag_pivot_thresh=s.pivot_threshold, options=dict(SymmetricMode=True))
    b = rng.standard_normal(n)
    assert np.array_equal(s._lu.solve(b), ref.solve(b))  # same pivots, same arithmetic
    assert np.array_equal(s._lu.perm_r, ref.perm_r) and s._lu.nnz == ref.nnz
    assert np.any(ref.perm_r != np.arange(n))  # rows were interchanged


def test_out_none_writes_nothing_and_passes_the_same_frames_to_the_recorder(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    m, rows = _frame_model()
    on_disk = fm.Analysis(m, tmp_path / "r", progress=False).run()
    recorded = []
    assert fm.Analysis(m, None, progress=False, on_frame=recorded.append).run() is None
    assert sorted(p.name for p in tmp_path.iterdir()) == ["r"]  # no folder, frame or status file
    assert len(recorded) == len(on_disk) == 1 + 4
    for i, fr in enumerate(recorded):  # the same solution, bit for bit (writing does not change it)
        np.testing.assert_array_equal(fr["U"], on_disk.frame(i)["U"])
        np.testing.assert_array_equal(fr["el/beam/section_forces"], on_disk.frame(i)["el/beam/section_forces"])
    with pytest.warns(UserWarning, match="keeps no results"):
        an = fm.Analysis(m, None, progress=False)
    an.run()
    np.testing.assert_array_equal(an.x - an.X0, recorded[-1]["U"])  # the final state is kept


def test_writer_keeps_every_frame_and_reports_a_write_error_at_once(tmp_path):
    m, rows = _frame_model()
    recorded = []
    res = fm.Analysis(m, tmp_path / "r", progress=False, on_frame=recorded.append).run()
    assert len(res) == 1 + 4  # the initial frame and the 4 increments, all on disk after the run
    u = [res.frame(i)["U"] for i in range(len(res))]
    assert all(np.abs(a - b).max() > 0 for a, b in zip(u, u[1:]))  # distinct frames, in order
    # the recorder saw exactly what is on disk, frame by frame
    assert len(recorded) == len(res)
    for i, fr in enumerate(recorded):
        disk = res.frame(i)
        assert set(fr) == set(disk)
        for key in fr:
            np.testing.assert_array_equal(np.asarray(fr[key]), disk[key])

    class Frozen:
        node_labels = np.array([1])
        coordinates = np.zeros((1, 3))

    if not os.path.exists("/dev/full"):
        pytest.skip("no /dev/full to stand for a full disk")
    w = ResultsWriter(tmp_path / "w", Frozen(), [])
    os.close(w._log)
    w._log = os.open("/dev/full", os.O_WRONLY)  # the frame log's disk is full (ENOSPC)
    with pytest.raises(OSError, match="could not write results"):  # at the frame, not later
        w.frame(U=np.zeros((1, 3)))
    assert w.count == 0
    w.close({"status": "completed", "completed": True})  # a run that went on would not be "completed"
    s = json.loads((tmp_path / "w" / "summary.json").read_text())
    assert s["status"] == "failed" and "No space left" in s["message"]


def test_a_full_disk_at_the_start_is_a_named_error_and_a_failed_summary(tmp_path, monkeypatch):
    """The mesh cannot be written (the disk is full when the run starts): a femast error naming the
    folder (not a raw OSError), and the summary says "failed" (not "running" forever)."""
    if not os.path.exists("/dev/full"):
        pytest.skip("no /dev/full to stand for a full disk")
    import femast.post.writer as results
    from femast.errors import FemastError, ResultsWriteError

    def full_disk(path, **arrays):  # the OS's own ENOSPC
        with open("/dev/full", "wb") as fh:
            fh.write(b"x" * 8192)
            fh.flush()

    monkeypatch.setattr(results, "_atomic_savez", full_disk)
    m, _ = _frame_model(1)
    with pytest.raises(ResultsWriteError, match=r"could not write results to '.*r'.*No space left") as err:
        fm.Analysis(m, tmp_path / "r", progress=False).run()
    assert isinstance(err.value, FemastError) and isinstance(err.value, OSError)  # (caught as either)
    s = json.loads((tmp_path / "r" / "summary.json").read_text())
    assert s["status"] == "failed" and "No space left" in s["message"]
    assert not list((tmp_path / "r").glob("*.tmp"))


class _NaNTangent(ElementFamily):
    """A spring between the x DOFs of its two nodes whose tangent carries a NaN off the diagonal."""

    name = "broken_spring"
    active_dofs = (0, 1, 2)

    def __init__(self, nodes):
        self.nodes = np.asarray(nodes, dtype=np.int64).reshape(1, 2)

    def evaluate(self, x, R, state, ctx=None):
        f = np.zeros((1, 12))
        k = np.zeros((1, 12, 12))
        k[0, 0, 0] = k[0, 6, 6] = 1e3
        k[0, 0, 6] = np.nan
        k[0, 6, 0] = -1e3
        return ElementResponse(f=f, k=k, state=state)


def test_a_nan_in_an_element_tangent_is_named(tmp_path):
    m = fm.Model("nan")
    a, b, c = m.node(0, 0, 0), m.node(1, 0, 0), m.node(2, 0, 0)
    m.truss(a, b, EA=1e6)
    m.truss(b, c, EA=1e6)
    m.fix(a)
    for n in (b, c):
        m.fix(n, "uy", "uz")
    m.add_family(_NaNTangent([b, c]))
    m.step("pull").load(c, fx=1.0)
    with pytest.raises(ConvergenceError, match="non-finite tangent stiffness in element family 'broken_spring'"):
        fm.solve(m, tmp_path / "r", progress=False)


def test_reduced_tangent_matches_the_sparse_product():
    # T^T K T + G on the fixed pattern against scipy's product, random values on random patterns
    from femast.analysis.reduction import ReducedTangent

    rng = np.random.default_rng(3)
    n_act, n_ind, nf = 40, 30, 24
    K = sp.random(n_act, n_act, density=0.15, random_state=4, format="csr") + sp.identity(n_act, format="csr")
    K.sort_indices()
    T = (
        sp.random(n_act, n_ind, density=0.06, random_state=5, format="csr") + sp.eye(n_act, n_ind, format="csr")
    ).tocsr()
    T.sort_indices()
    g_rows, g_cols = rng.integers(0, n_ind, 12), rng.integers(0, n_ind, 12)
    red = ReducedTangent(K, T, g_rows, g_cols, nf)
    for _ in range(2):  # refilled in place with new values on the same patterns
        K.data[:] = rng.normal(size=K.nnz)
        T.data[:] = rng.normal(size=T.nnz)
        g = rng.normal(size=12)
        K_ff, K_fc = red.fill(K.data, T.data, g)
        full = (T.T @ K @ T + sp.csr_matrix((g, (g_rows, g_cols)), shape=(n_ind, n_ind))).toarray()
        # same sums in another order: agreement to round-off of O(10) terms of size O(1)
        np.testing.assert_allclose(K_ff.toarray(), full[:nf, :nf], atol=1e-12)
        np.testing.assert_allclose(K_fc.toarray(), full[:nf, nf:], atol=1e-12)


def test_reduced_tangent_of_a_model_set_up_again_reuses_its_layout():
    """A second model with the same patterns (the FE fits' runs) reuses the layout of the reduced
    blocks; each keeps its own values, both T^T K T + G."""
    from femast.analysis.reduction import ReducedTangent

    rng = np.random.default_rng(7)
    n_act, n_ind, nf = 30, 24, 18

    def patterns(seed):
        K = sp.random(n_act, n_act, density=0.2, random_state=seed, format="csr") + sp.identity(n_act, format="csr")
        T = (sp.random(n_act, n_ind, density=0.08, random_state=seed + 1, format="csr") + sp.eye(n_act, n_ind)).tocsr()
        K.sort_indices()
        T.sort_indices()
        return K, T

    K1, T1 = patterns(11)
    K2, T2 = patterns(11)  # the same patterns, other arrays
    g_rows, g_cols = rng.integers(0, n_ind, 10), rng.integers(0, n_ind, 10)
    first = ReducedTangent(K1, T1, g_rows, g_cols, nf)
    again = ReducedTangent(K2, T2, g_rows.copy(), g_cols.copy(), nf)
    assert again.pa is first.pa and again.pos is first.pos
    assert again.data is not first.data and again.K_ff.indices is not first.K_ff.indices
    for K, T, red in ((K1, T1, first), (K2, T2, again)):
        K.data[:] = rng.normal(size=K.nnz)
        T.data[:] = rng.normal(size=T.nnz)
        g = rng.normal(size=10)
        K_ff, K_fc = red.fill(K.data, T.data, g)
        full = (T.T @ K @ T + sp.csr_matrix((g, (g_rows, g_cols)), shape=(n_ind, n_ind))).toarray()
        np.testing.assert_allclose(K_ff.toarray(), full[:nf, :nf], atol=1e-12)
        np.testing.assert_allclose(K_fc.toarray(), full[:nf, nf:], atol=1e-12)
    assert not np.array_equal(first.data, again.data)  # filled independently
    K3, T3 = patterns(21)  # another pattern: its own layout
    assert ReducedTangent(K3, T3, g_rows, g_cols, nf).pa is not first.pa


def _cantilever(freq, **step_options):
    m = fm.Model("frequency")
    a, b = m.node(0, 0, 0), m.node(1, 0, 0)
    m.beam(a, b, fm.circular_tube(0.02, 0.016, E=70e9), n=4)
    m.fix(a)
    m.step("load", initial_increment=0.1, max_increment=0.1, output_frequency=freq, **step_options).load(b, fz=-50.0)
    m.step("back", initial_increment=0.25, max_increment=0.25).load(b, fz=0.0)
    return m


def test_output_frequency_writes_every_nth_and_the_last_increment_of_a_step(tmp_path):
    every = fm.solve(_cantilever(1), tmp_path / "every", progress=False)
    sparse = fm.solve(_cantilever(3), tmp_path / "sparse", progress=False)
    assert sparse.steps == ["initial"] + ["load"] * 4 + ["back"] * 4
    assert sparse.scalar_history("increment").tolist() == [0, 3, 6, 9, 10, 1, 2, 3, 4]
    same = [0, 3, 6, 9, 10, 11, 12, 13, 14]  # the frames of the every-increment run at those increments
    for i, j in enumerate(same):  # the solution does not depend on what is written
        np.testing.assert_array_equal(sparse.frame(i)["U"], every.frame(j)["U"])
        np.testing.assert_array_equal(sparse.frame(i)["RF"], every.frame(j)["RF"])


def test_a_run_that_gives_up_writes_its_last_converged_increment(tmp_path):
    every = fm.solve(_cantilever(1), tmp_path / "every", progress=False)
    with pytest.raises(ConvergenceError, match="max_increments=5"):
        fm.solve(_cantilever(3, max_increments=5), tmp_path / "sparse", progress=False)
    sparse = fm.Results(tmp_path / "sparse")
    assert sparse.scalar_history("increment").tolist() == [0, 3, 5]  # 5: written when the step gave up
    np.testing.assert_array_equal(sparse.frame(2)["U"], every.frame(5)["U"])
    np.testing.assert_array_equal(sparse.frame(2)["RF"], every.frame(5)["RF"])


def test_output_frequency_in_an_arc_length_step_keeps_its_last_increment(monkeypatch):
    import femast.verification.arclength as va

    full = va.von_mises_truss()["results"]
    orig = va.Model.step
    # the same truss and arc-length step, with a frame every 7 increments
    monkeypatch.setattr(va.Model, "step", lambda self, name=None, **kw: orig(self, name, output_frequency=7, **kw))
    sparse = va.von_mises_truss()["results"]
    n = len(full) - 1
    assert sparse.scalar_history("increment").tolist() == [0] + list(range(7, n, 7)) + ([n] if n % 7 else [])
    np.testing.assert_array_equal(sparse.frame(len(sparse) - 1)["U"], full.frame(n)["U"])


@pytest.mark.parametrize("bad", [0, -2, 1.5, True])
def test_output_frequency_must_be_a_positive_whole_number(bad):
    with pytest.raises(fm.ModelError, match="step 'load': output_frequency"):
        _cantilever(bad)


def test_sparse_lu_solves_matrices_inside_and_outside_the_analysed_pattern():
    rng = np.random.default_rng(9)
    n = 30
    A = sp.random(n, n, density=0.15, random_state=9, format="csr") + 10 * sp.eye(n, format="csr")
    A = (A + A.T).tocsr()
    s = SparseLU(ordering="mmd")
    s.factorize(A)
    b = rng.standard_normal(n)
    np.testing.assert_allclose(s.solve(b), spla.spsolve(A.tocsc(), b), rtol=1e-12)  # well conditioned
    # a pattern inside the analysed one (entries dropped), refilled in place twice
    sub = A.copy()
    sub.data[np.abs(sub.data) < 0.3] = 0.0
    sub.eliminate_zeros()
    assert sub.nnz < A.nnz
    for scale in (1.0, 2.0):
        sub.data *= scale
        s.factorize(sub)
        np.testing.assert_allclose(s.solve(b), spla.spsolve(sub.tocsc(), b), rtol=1e-12)
    assert s.analyses == 1  # no new ordering for a sub-pattern
    # an entry outside it: the union is analysed once, then solved
    i, j = np.argwhere(A.toarray() == 0)[0]  # a structural zero of A
    out = (A + sp.csr_matrix(([1e-3, 1e-3], ([i, j], [j, i])), shape=(n, n))).tocsr()
    assert out.nnz > A.nnz
    s.factorize(out)
    np.testing.assert_allclose(s.solve(b), spla.spsolve(out.tocsc(), b), rtol=1e-12)
    assert s.analyses == 2
