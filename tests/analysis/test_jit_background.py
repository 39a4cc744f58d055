"""Kernels compiled in a background process while the first run interprets them (issue 17,
femast/jit_background.py): the interpreted kernels give bit for bit the compiled results, and the
worker fills numba's cache so that the next call loads it instead of compiling."""

import json
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[2]
# The start of a child script that lists the kernels compiled in its own process (compiled_here).
COMPILE_LISTENER = textwrap.dedent("""
    from numba.core import event
    compiled_here = []
    class L(event.Listener):
        def on_start(self, ev): compiled_here.append(ev.data["dispatcher"].py_func.__name__)
        def on_end(self, ev): pass
    event.register("numba:compile", L())
""")

# A beam cantilever with a truss brace, bent and twisted through large rotations, then unloaded:
# every kernel of the core path (beam and truss families, configuration update, assembly,
# convergence maxima, rotation vectors for the output).
MODEL = textwrap.dedent("""
    import numpy as np
    import femast as fm

    def run():
        m = fm.Model("bg")
        a = m.node(0.0, 0.0, 0.0)
        b = m.node(1.0, 0.0, 0.0)
        c = m.node(1.0, 0.5, 0.0)
        m.beam(a, b, fm.circular_tube(0.03, 0.026, E=70e9), up=(0, 0, 1), n=6)
        m.truss(b, c, EA=1e5)
        m.fix(a)
        m.fix(c)
        m.step("load", initial_increment=0.25).load(b, fz=-300.0, mx=20.0)
        frames = []
        an = fm.Analysis(m, None, progress=False, on_frame=lambda fr: frames.append(fr))
        an.run()
        return np.concatenate([np.ravel(an.x), np.ravel(an.R)]), an.summary.iterations
""")


def _child(code, env_extra, cwd):
    env = dict(os.environ, PYTHONPATH=str(ROOT), FEMAST_QUIET="1", **env_extra)
    p = subprocess.run([sys.executable, "-c", code], env=env, cwd=cwd, capture_output=True, text=True, timeout=600)
    assert p.returncode == 0, p.stderr[-3000:]
    return p.stdout


# The ADAM bay: cables over pulleys with latches, friction ball joints, joint springs, rigid
# bodies and ties, through its preload and a short twist.
ADAM = textwrap.dedent("""
    import numpy as np
    import femast as fm
    from femast.adam import build_bay
    from femast.adam.steps import CONVERGENCE, add_idealised_torsion, add_initial_steps

    def run():
        am = build_bay()
        add_initial_steps(am)
        add_idealised_torsion(am, 0.01, max_increment=0.5, unload=False)
        an = fm.Analysis(am.model, None, progress=False, convergence=CONVERGENCE, on_frame=lambda fr: None)
        an.run()
        return np.concatenate([np.ravel(an.x), np.ravel(an.R)]), an.summary.iterations
""")


@pytest.mark.parametrize("model", [MODEL, ADAM], ids=["beams-truss", "adam-bay"])
def test_interpreted_kernels_give_the_compiled_results_bit_for_bit(tmp_path, model):
    """Same arithmetic in the same order on IEEE doubles: the final state of a large-rotation run
    is identical to the last bit, and so is the number of Newton iterations."""
    (tmp_path / "model_bg.py").write_text(model)
    code = (
        "import sys, json, numpy as np; sys.path.insert(0, '.'); from model_bg import run; "
        "import femast.jit_background as jb; v, it = run(); "
        "print(json.dumps({'v': v.tolist(), 'it': it, 'n_hooked': len(jb._hooked)}))"
    )
    compiled = json.loads(_child(code, {"FEMAST_BACKGROUND_COMPILE": "0"}, tmp_path))
    interp = json.loads(_child(code, {"FEMAST_BACKGROUND_COMPILE": "interpret"}, tmp_path))
    assert compiled["n_hooked"] == 0 and interp["n_hooked"] > 5
    assert interp["it"] == compiled["it"]
    assert np.array_equal(np.array(interp["v"]), np.array(compiled["v"]))  # bit for bit, no tolerance


def test_worker_fills_the_cache_and_the_next_call_loads_it(tmp_path):
    """With an empty cache the first call runs interpreted (nothing compiled in this process), a
    worker compiles the kernel into the cache and drops its claim, and the next call loads the
    compiled code from the cache (a cache hit, still no compile here)."""
    code = COMPILE_LISTENER + textwrap.dedent("""
        import json, time, glob, numpy as np
        import femast
        from femast import jit, rotations
        jit.prepare()
        R = rotations.expm_so3.py_func(np.array([0.3, -0.2, 0.5]))
        first = rotations.logm_so3(R)
        d = rotations.logm_so3
        hook = d._compile_for_args
        claims = glob.glob(hook.index + ".*.femast-compiling")
        t0 = time.time()
        while glob.glob(hook.index + ".*.femast-compiling") and time.time() - t0 < 300:
            time.sleep(0.1)
        second = rotations.logm_so3(R)
        print(json.dumps({"first": first.tolist(), "second": second.tolist(), "claims": len(claims),
                          "compiled_here": compiled_here, "signatures": len(d.signatures),
                          "hits": sum(d.stats.cache_hits.values())}))
    """)
    out = json.loads(
        _child(code, {"NUMBA_CACHE_DIR": str(tmp_path / "cache"), "FEMAST_BACKGROUND_COMPILE": "1"}, tmp_path)
    )
    assert out["claims"] == 1  # the worker was asked, the call did not wait
    assert out["compiled_here"] == []  # nothing compiled in this process
    assert out["signatures"] == 1 and out["hits"] == 1  # the second call loaded the worker's code
    assert out["first"] == out["second"]  # interpreted and compiled: the same bits
    assert list((tmp_path / "cache").rglob("*logm_so3*.nbi"))


def test_off_in_the_worker_and_by_environment(monkeypatch):
    from femast import jit_background as jb

    monkeypatch.setenv("FEMAST_BACKGROUND_COMPILE", "0")
    assert jb.mode() == "off" and not jb.enabled()
    monkeypatch.setenv("FEMAST_BACKGROUND_COMPILE", "interpret")
    assert jb.mode() == "interpret"
    monkeypatch.setenv("FEMAST_BACKGROUND_COMPILE", "1")
    assert jb.mode() == "on"


def test_worker_compiles_element_kernels_first():
    from femast import jit_background as jb

    reqs = [{"module": "femast.analysis.configuration"}, {"module": "femast.elements.beam_corot"}]
    assert sorted(range(2), key=lambda i: (jb._priority(reqs[i]), i)) == [1, 0]


def test_helpers_of_interpreted_kernels_are_interpreted_not_compiled(tmp_path):
    """The band solver's residual kernels share an inlined helper (their maxima), and the two
    scatter encodings one kernel: run interpreted (an empty cache), they compile nothing in the
    foreground, the helper included, and give the direct sums' results."""
    code = COMPILE_LISTENER + textwrap.dedent("""
        import json, numpy as np, scipy.sparse as sp
        from femast import jit_background
        from femast.analysis import assembly
        from femast.analysis.solvers import banded
        jit_background.install()
        rng = np.random.default_rng(1)
        n, b = 12, 2
        B = sp.diags([rng.normal(size=n - abs(d)) for d in range(-b, b + 1)], range(-b, b + 1)).tocsc()
        B.sort_indices()
        x, rhs, r = rng.normal(size=n), rng.normal(size=n), np.empty(n)
        csc = banded._residual(B.indptr, B.indices, B.data, x, rhs, r)
        r_csc = r.copy()
        L, U = np.zeros((b + 1, n)), np.zeros((b + 1, n))
        D = B.toarray()
        for d in range(b + 1):
            L[d, :n - d] = np.diagonal(D, -d)
            U[d, :n - d] = np.diagonal(D, d)
        split = banded._residual_split(L, U, x, rhs, r)
        k = rng.normal(size=(3, 2, 2))
        pos = np.array([[[0, 1], [-1, 2]], [[0, 1], [2, -1]], [[3, 3], [-1, 0]]])
        plain = np.zeros(4)
        assembly._scatter_matrix(k, pos, plain)
        data = np.full(4, 7.0)    # the first entry of each position assigns: no zeroing needed
        assembly._scatter_matrix(k, assembly.assigning_positions([pos], 4)[0], data)
        print(json.dumps({"compiled_here": compiled_here, "csc": list(csc), "split": list(split),
                          "r_csc": r_csc.tolist(), "r": r.tolist(), "ref": (rhs - D @ x).tolist(), "rhs": rhs.tolist(),
                          "rows": float(np.abs(D).sum(axis=1).max()), "data": data.tolist(), "plain": plain.tolist(),
                          "k": k.tolist()}))
    """)
    out = json.loads(
        _child(code, {"NUMBA_CACHE_DIR": str(tmp_path / "cache"), "FEMAST_BACKGROUND_COMPILE": "interpret"}, tmp_path)
    )
    assert out["compiled_here"] == []
    assert out["csc"] == out["split"] and out["r"] == out["r_csc"]  # the same sums in the same order
    ref = np.array(out["ref"])
    assert np.allclose(out["r"], ref, rtol=0, atol=1e-14 * np.abs(ref).max())  # r = rhs - B x to round-off
    assert out["csc"][0] == np.abs(out["r"]).max() and np.isclose(out["csc"][1], out["rows"], rtol=1e-15)
    assert out["csc"][3] == np.abs(out["rhs"]).max()
    k = np.array(out["k"])
    # -1 is outside; the sums of the entries at each position, in scatter order
    expected = [
        k[0, 0, 0] + k[1, 0, 0] + k[2, 1, 1],
        k[0, 0, 1] + k[1, 0, 1],
        k[0, 1, 1] + k[1, 1, 0],
        k[2, 0, 0] + k[2, 0, 1],
    ]
    assert out["plain"] == expected and out["data"] == expected  # same order: the same bits
