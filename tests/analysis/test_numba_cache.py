"""femast.numba_cache: a cached kernel calling an njit helper of another file is recompiled after
the helper changes (numba alone keeps the old helper: numba issue #1833)."""

import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from femast import numba_cache

REPO = Path(__file__).resolve().parents[2]

CALLER = textwrap.dedent("""
    from numba import njit

    from .helper import helper


    @njit(cache=True)
    def caller(x):
        return helper(x) + 1.0
""")
HELPER = textwrap.dedent("""
    from numba import njit


    @njit({options})
    def helper(x):
        return x * {factor}
""")
RUN = textwrap.dedent("""
    import os, sys
    if os.environ.get("GUARD") == "1":
        from femast.numba_cache import check
        check(sys.argv[1], "pkg")
    import pkg.caller
    print(repr(pkg.caller.caller(1.0)))
""")


def _package(tmp_path, options):
    pkg = tmp_path / "pkg"
    pkg.mkdir()
    (pkg / "__init__.py").write_text("")
    (pkg / "caller.py").write_text(CALLER)
    (pkg / "helper.py").write_text(HELPER.format(options=options, factor="2.0"))
    return pkg


def _run(tmp_path, pkg, guard, numba_cache_dir=None):
    env = {k: v for k, v in os.environ.items() if k != "NUMBA_CACHE_DIR"}  # numba's in-tree __pycache__
    if numba_cache_dir is not None:
        env["NUMBA_CACHE_DIR"] = str(numba_cache_dir)
    env.update(PYTHONPATH=os.pathsep.join([str(tmp_path), str(REPO)]), GUARD="1" if guard else "0")
    out = subprocess.run(
        [sys.executable, "-c", RUN, str(pkg)], env=env, capture_output=True, text=True, check=True, timeout=300
    )
    return float(out.stdout.strip().splitlines()[-1])


@pytest.mark.parametrize("options", ["", "inline='always'"])
@pytest.mark.parametrize("guard", [False, True])
def test_edited_helper_in_another_file(tmp_path, options, guard):
    pkg = _package(tmp_path, options)
    assert _run(tmp_path, pkg, guard) == 3.0  # 1 * 2 + 1, compiled and cached
    assert list((pkg / "__pycache__").glob("caller.*.nbi"))
    (pkg / "helper.py").write_text(HELPER.format(options=options, factor="5.0"))
    # exact: small integers in doubles.  Without the guard numba loads caller's stale cache (the
    # old helper): this shows the bug is real on the installed numba.
    assert _run(tmp_path, pkg, guard) == (6.0 if guard else 3.0)


def test_edited_helper_with_numba_cache_dir(tmp_path):
    """The cache files are found through numba's locator wherever it puts them: NUMBA_CACHE_DIR."""
    pkg = _package(tmp_path, "inline='always'")
    cache = tmp_path / "numba-cache"
    assert _run(tmp_path, pkg, True, cache) == 3.0
    assert list(cache.rglob("caller.*.nbi")) and not list(pkg.rglob("*.nbi"))
    (pkg / "helper.py").write_text(HELPER.format(options="inline='always'", factor="5.0"))
    assert _run(tmp_path, pkg, True, cache) == 6.0


def test_two_processes_starting_at_once_after_an_edit(tmp_path):
    pkg = _package(tmp_path, "")
    assert _run(tmp_path, pkg, True) == 3.0
    (pkg / "helper.py").write_text(HELPER.format(options="", factor="5.0"))
    env = {k: v for k, v in os.environ.items() if k != "NUMBA_CACHE_DIR"}
    env.update(PYTHONPATH=os.pathsep.join([str(tmp_path), str(REPO)]), GUARD="1")
    procs = [
        subprocess.Popen(
            [sys.executable, "-c", RUN, str(pkg)], env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True
        )
        for _ in range(2)
    ]
    outs = [p.communicate(timeout=300) for p in procs]
    assert [p.returncode for p in procs] == [0, 0], [err for _, err in outs]
    assert [float(out.strip().splitlines()[-1]) for out, _ in outs] == [6.0, 6.0]


def test_unchanged_tree_deletes_nothing(tmp_path):
    pkg = _package(tmp_path, "")
    assert _run(tmp_path, pkg, True) == 3.0
    cached = sorted((pkg / "__pycache__").glob("caller.*.nb?"))
    assert cached
    assert numba_cache.check(str(pkg), "pkg") == []  # fast path: the tree stamp matches
    os.utime(pkg / "helper.py")  # a checkout touching mtimes only
    (pkg / "__pycache__" / numba_cache.TREE_STAMP).unlink()  # (and a lost tree stamp): slow path
    assert numba_cache.check(str(pkg), "pkg") == []
    assert sorted((pkg / "__pycache__").glob("caller.*.nb?")) == cached


def test_changed_helper_deletes_only_its_callers_cache(tmp_path):
    pkg = _package(tmp_path, "")
    (pkg / "other.py").write_text("from numba import njit\n\n\n@njit(cache=True)\ndef other(x):\n    return x\n")
    assert _run(tmp_path, pkg, True) == 3.0
    pycache = pkg / "__pycache__"
    (pycache / "other.other-5.py0.nbi").write_text("")  # stands for other's cache files
    (pkg / "helper.py").write_text(HELPER.format(options="", factor="5.0"))
    deleted = numba_cache.check(str(pkg), "pkg")
    assert deleted and all(Path(p).name.startswith("caller.") for p in deleted)
    assert not list(pycache.glob("caller.*.nb?")) and (pycache / "other.other-5.py0.nbi").exists()
    assert numba_cache.check(str(pkg), "pkg") == []  # stamped: once only


def test_unwritable_cache_and_files_gone_meanwhile(tmp_path, monkeypatch):
    pkg = _package(tmp_path, "")
    monkeypatch.setattr(numba_cache, "cache_dir", lambda py_file: None)  # numba: no writable locator
    assert numba_cache.check(str(pkg), "pkg") == []
    monkeypatch.undo()
    (pkg / "__pycache__").mkdir()
    (pkg / "__pycache__" / "caller.caller-7.py0.nbi").write_text("")
    real_remove = os.remove

    def remove(path):  # another process deleted it first
        real_remove(path)
        raise FileNotFoundError(path)

    monkeypatch.setattr(numba_cache.os, "remove", remove)
    assert numba_cache.check(str(pkg), "pkg") == []


def test_femast_table():
    """The dependencies found in femast itself include the known cross-file helpers."""
    root = Path(numba_cache.__file__).parent
    deps = {
        os.path.relpath(k, root): [os.path.relpath(d, root) for d in v]
        for k, v in numba_cache.dependencies(str(root), "femast").items()
    }
    assert "rotations.py" in deps["elements/_ball_joint_kernels.py"]  # logm_so3_into
    assert {"rotations.py", "elements/_stack.py"} <= set(deps["elements/beam_corot.py"])
    assert "latch.py" in deps["elements/_cable_kernels.py"]
    assert deps["rotations.py"] == []
