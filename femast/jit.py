"""The first-run compile of femast's numba kernels: a notice when it happens, and ``femast warmup``.

numba compiles each kernel the first time it is called and keeps it in its on-disk cache (beside
the installed package, or in ``NUMBA_CACHE_DIR``); only kernels a model calls are compiled.  On a
fresh install the first analysis therefore meets the compiler.  :func:`prepare` (called by every
:class:`femast.Analysis`) hands that compile to a background worker process while small analyses
run the kernels uncompiled (:mod:`femast.jit_background`), and prints once per process, only if
something is actually being compiled, ::

    femast: compiling femast kernels in a background process, first run only, ~12 s; small analyses
    run uncompiled meanwhile (`femast warmup` compiles ahead)

to stderr (or "compiling femast kernels, first run only, ~12 s" when numba compiles in the
process: ``FEMAST_BACKGROUND_COMPILE=0``, kernels called outside an analysis); ``femast --quiet``
or ``FEMAST_QUIET=1`` silences it.  The estimate is the sum of the measured cold-compile CPU times
(:data:`COMPILE_S`) of the kernels of the loaded femast modules whose cache is missing.

:func:`warmup` compiles every kernel ahead, in this process, by running small models of each
element family (for CI images and cluster workers, whose first job should not pay for it).
"""

from __future__ import annotations

import os
import sys
import threading
import time

# cold compile CPU time of the main kernels, s (numba 0.68, one core of the development machine,
# recorded with numba's compile events; benchmarks/cold_start.py measures the whole first run).
COMPILE_S = {
    "femast.elements.beam_corot.beam_family_kernel": 8.5,  # 11-12 s before the end loops
    "femast.analysis.configuration.update_configuration": 1.9,
    "femast.rotations.apply_spins": 1.0,
    "femast.analysis.convergence.force_moment_abs_max": 0.9,
    "femast.rotations._rotation_vectors": 0.6,
}

_announced = False
_installed = False

# Set-up kernels (run once per analysis: assembly pattern, orderings, position maps) run as plain
# Python on inputs up to this many items: a small model then never compiles them (nor queues them
# for the background compile, which would delay the element kernels' compile), at a few ms of
# Python; larger inputs call the compiled kernel.
SETUP_PYTHON_MAX = 20_000  # inner-loop iterations (~10 ms of Python)


# Set-up kernels that return new arrays computed from their arguments alone and write none of them
# (qualified names): on the plain-Python path their results are remembered by a digest of the
# arguments, so a process that builds the same small model again and again (the FE fits of
# femast.experiments: 50-60 runs of one bay in a diagnosis) computes its pattern once
# (the bay's assembly pattern is 12 ms of its 82 ms per run in Python).
MEMO_KERNELS = frozenset({"femast.analysis.assembly._pattern_kernel", "femast.analysis.linalg.ordering._permuted_csc"})
MEMO_ENTRIES = 16
_MEMO: dict = {}
_MEMO_LOCK = threading.Lock()  # (models built in threads: a Study on dask threads)


def _memo_key(kernel, args):
    import hashlib

    import numpy as np

    h = hashlib.sha1(f"{kernel.py_func.__module__}.{kernel.py_func.__name__}".encode())
    for a in args:
        if isinstance(a, np.ndarray):
            a = np.ascontiguousarray(a)
            h.update(f"|{a.dtype.str}{a.shape}|".encode())
            h.update(a.tobytes())
        else:
            h.update(f"|{type(a).__name__}:{a!r}".encode())
    return h.digest()


def _copy_result(result):
    import numpy as np

    if isinstance(result, tuple):
        return tuple(r.copy() if isinstance(r, np.ndarray) else r for r in result)
    return result.copy() if isinstance(result, np.ndarray) else result


def setup_call(kernel, n_items: int, *args):
    """``kernel(*args)`` for a set-up kernel: its plain-Python function when ``n_items`` (about the
    number of its inner-loop iterations) is at most :data:`SETUP_PYTHON_MAX` (integer results, or
    sums in the same order: the same bits).  The plain-Python results of the kernels named in
    :data:`MEMO_KERNELS` are remembered (the last :data:`MEMO_ENTRIES`, keyed by a SHA-1 of the
    arguments' bytes, dtypes and shapes) and returned as copies."""
    if n_items > SETUP_PYTHON_MAX:
        return kernel(*args)
    if f"{kernel.py_func.__module__}.{kernel.py_func.__name__}" not in MEMO_KERNELS:
        return kernel.py_func(*args)
    key = _memo_key(kernel, args)
    hit = _MEMO.get(key)
    if hit is None:
        hit = kernel.py_func(*args)
        kept = _copy_result(hit)
        with _MEMO_LOCK:
            while _MEMO and len(_MEMO) >= MEMO_ENTRIES:
                _MEMO.pop(next(iter(_MEMO)))  # the oldest entry
            _MEMO[key] = kept
        return hit
    return _copy_result(hit)


def _dispatchers():
    """(qualified name, dispatcher) of every cacheable, non-inlined numba kernel of the loaded
    femast modules."""
    try:
        from numba.core.registry import CPUDispatcher
    except ImportError:  # pragma: no cover
        return []
    seen, out = set(), []
    for mod_name, mod in list(sys.modules.items()):
        if not mod_name.startswith("femast") or mod is None:
            continue
        for obj in list(vars(mod).values()):
            if isinstance(obj, CPUDispatcher) and id(obj) not in seen:
                seen.add(id(obj))
                if obj.targetoptions.get("inline", "never") != "never" or getattr(obj, "_cache", None) is None:
                    continue
                if not obj.py_func.__module__.startswith("femast"):
                    continue
                out.append((f"{obj.py_func.__module__}.{obj.py_func.__name__}", obj))
    return out


def uncached(dispatchers=None):
    """Qualified names of the kernels (default: those of the loaded femast modules) with no
    compiled code on disk yet."""
    names = []
    for name, d in dispatchers if dispatchers is not None else _dispatchers():
        try:
            index = d._cache._cache_file._index_path
        except AttributeError:  # another numba cache layout: assume compiled
            continue
        if not os.path.exists(index) and not d.signatures:
            names.append(name)
    return names


def estimate_s(names) -> float:
    """Estimated compile time of ``names``, s: the measured costs of the big kernels (the small
    ones, 0.2-0.4 s each, are not counted: a loaded module's kernel is not always called)."""
    return sum(COMPILE_S.get(n, 0.0) for n in names)


def _announce(background: bool = False) -> None:
    """Print the compile notice once per process (unless quiet)."""
    global _announced
    if _announced:
        return
    _announced = True
    from .progress import quiet

    if quiet():
        return
    est = max(estimate_s(uncached()), 1.0)
    if background:
        print(
            f"femast: compiling femast kernels in a background process, first run only, ~{est:.0f} s; "
            "small analyses run uncompiled meanwhile (`femast warmup` compiles ahead)",
            file=sys.stderr,
            flush=True,
        )
    else:
        print(
            f"femast: compiling femast kernels, first run only, ~{est:.0f} s (`femast warmup` does it ahead)",
            file=sys.stderr,
            flush=True,
        )


def _on_compile(event):
    if _announced or not event.is_start:
        return
    try:
        mod = event.data["dispatcher"].py_func.__module__
    except (KeyError, AttributeError):
        return
    if mod.startswith("femast"):
        _announce()


def prepare() -> None:
    """Before an analysis: the compile notice is armed and every loaded femast kernel compiles in a
    background process on first use (:mod:`femast.jit_background`)."""
    watch()
    from . import jit_background

    jit_background._announce = lambda: _announce(background=True)
    jit_background.install()


def watch() -> None:
    """Print the compile notice the first time numba compiles a femast kernel in this process."""
    global _installed
    if _installed:
        return
    _installed = True
    try:
        from numba.core import event
    except ImportError:  # pragma: no cover
        return

    class _Listener(event.Listener):
        def on_start(self, ev):
            _on_compile(ev)

        def on_end(self, ev):
            pass

    event.register("numba:compile", _Listener())


# --------------------------------------------------------------------------- warm-up
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
    """The guyed mast of the Rocaspect paper with its shroud cables: pretension and one small wrench."""
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
    before = os.environ.get("FEMAST_BACKGROUND_COMPILE")
    os.environ["FEMAST_BACKGROUND_COMPILE"] = "0"  # compile here, not in a background worker
    try:
        for what, fn in PARTS:
            t0 = time.perf_counter()
            fn()
            report(f"  {what}: {time.perf_counter() - t0:.1f} s")
    finally:
        if before is None:
            del os.environ["FEMAST_BACKGROUND_COMPILE"]
        else:
            os.environ["FEMAST_BACKGROUND_COMPILE"] = before
    return time.perf_counter() - t_all
