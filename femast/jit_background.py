"""First run without waiting for the compiler (issue 17): compile numba kernels in a background
process while the first, small analyses run the same kernels in the Python interpreter.

On a fresh install numba has nothing in its cache and compiling femast's kernels costs 10-15 s of
CPU (the beam kernel alone about 8 s, numba's front end in Python).  When a femast kernel with
``cache=True`` is called from Python and no compiled code for the call's argument types exists,
numba calls the dispatcher's ``_compile_for_args``; :func:`install` replaces that method on every
femast kernel by a :class:`_Hook` that

1. finds the compiled code on disk (an earlier run, or the background worker has finished): loads
   it, as numba would, and every later call runs compiled;
2. otherwise asks one background worker process (``python -m femast.jit_background``, started on
   first need, fed through a pipe) to compile the kernel for these argument types into numba's
   on-disk cache, and meanwhile runs the kernel's Python source (:func:`interpreted`) -- the same
   arithmetic in the same order on IEEE doubles, so the results are bit for bit those of the
   compiled kernel (tests/analysis/test_jit_background.py);
3. runs interpreted only while that is cheap: at most :data:`INTERPRET_MAX_ITEMS` array items in
   the arguments and the last interpreted call under :data:`INTERPRET_MAX_S` of CPU; for a larger
   model it waits for the worker if the worker has begun that kernel, and otherwise compiles it
   itself (the worker then skips it), so two kernels compile at once on two cores.

A claim file beside numba's cache index (``<index>.<sig hash>.femast-compiling``: the pid of the
process that will compile, and ``started`` once it has begun) marks a compile queued or in
progress, so a second femast process started meanwhile does not compile the same kernel again; a
claim whose process has died is ignored.  The worker compiles element kernels first (they cost the
most interpreted), and finishes its queue after the script has ended (the script's exit does not
wait for it: the next run finds the cache written).  ``FEMAST_JIT_LOG=FILE`` makes the worker log
each compile (kernel, CPU and wall time) as a JSON line.

Off (numba compiles in the calling process, as without this module) with
``FEMAST_BACKGROUND_COMPILE=0``, in the worker itself, in multiprocessing children (a pool of
analyses would start one worker each) and in ``femast warmup``.
"""

from __future__ import annotations

import atexit
import base64
import hashlib
import json
import os
import pickle
import subprocess
import sys
import time
import types as pytypes
from pathlib import Path

import numpy as np

INTERPRET_MAX_ITEMS = 20_000  # array items in a call's arguments above which it is not interpreted
INTERPRET_MAX_S = 0.1  # an interpreted call slower than this (s): later calls wait for the worker
_POLL_S = 0.02  # s between checks while waiting for the worker
_DEBUG = os.environ.get("FEMAST_JIT_DEBUG", "") not in ("", "0")

_hooked: dict[int, _Hook] = {}
_interpreted: dict[int, object] = {}
_worker: subprocess.Popen | None = None
_announce = None  # callable(str) printing the one notice (set by femast.jit)


def mode() -> str:
    """``"on"`` (compile in the background, interpret small calls meanwhile), ``"off"`` (numba
    compiles in this process: ``FEMAST_BACKGROUND_COMPILE=0``, the worker itself, multiprocessing
    children) or ``"interpret"`` (``FEMAST_BACKGROUND_COMPILE=interpret``: every hooked kernel
    without compiled code in memory runs in the interpreter, nothing is compiled -- for tests, and
    to step through a kernel with a debugger)."""
    value = os.environ.get("FEMAST_BACKGROUND_COMPILE", "1").strip().lower()
    if value == "interpret":
        return "interpret"
    if value in ("0", "", "no", "off", "false"):
        return "off"
    try:
        import multiprocessing

        if multiprocessing.parent_process() is not None:
            return "off"
    except (ImportError, AttributeError):  # pragma: no cover
        return "off"
    return "on"


def enabled() -> bool:
    """Kernels are hooked (:func:`mode` is not ``"off"``)."""
    return mode() != "off"


# --------------------------------------------------------------------------- interpreted kernels
def _python_equivalents():
    """numba-only callables a femast kernel may use, and what they do in plain Python."""
    import numba

    from .elements._stack import stack_buffer

    return {
        id(stack_buffer): lambda n: np.empty(n),  # scratch, written before it is read
        id(numba.carray): lambda buf, shape: buf.reshape(shape),
    }


def interpreted(dispatcher):
    """The Python function of a numba kernel with every numba kernel it calls by a global name
    replaced by that kernel's interpreted function (and the stack scratch of :mod:`.elements._stack`
    by numpy arrays), so it runs without compiling anything."""
    from numba.core.registry import CPUDispatcher

    key = id(dispatcher)
    if key in _interpreted:
        return _interpreted[key]
    f = dispatcher.py_func
    g = dict(f.__globals__)
    equivalents = _python_equivalents()
    out = pytypes.FunctionType(f.__code__, g, f.__name__, f.__defaults__, f.__closure__)
    _interpreted[key] = out  # before the recursion: a kernel may call itself
    for name, value in list(g.items()):
        if isinstance(value, CPUDispatcher):
            g[name] = interpreted(value)
        elif id(value) in equivalents:
            g[name] = equivalents[id(value)]
    return out


def _n_items(args) -> int:
    return sum(a.size for a in args if isinstance(a, np.ndarray))


# --------------------------------------------------------------------------- claims and the worker
def _index_path(dispatcher) -> str | None:
    try:
        return dispatcher._cache._cache_file._index_path
    except AttributeError:
        return None


def _claim_path(index: str, sig) -> str:
    return f"{index}.{hashlib.sha1(str(sig).encode()).hexdigest()[:10]}.femast-compiling"


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # pragma: no cover - someone else's live process
        return True
    return True


def _claim_state(claim: str) -> tuple[int, bool]:
    """(pid, started) of a live claim -- the process that will compile, and whether it has begun --
    or (0, False) when there is none or its process has died."""
    try:
        words = Path(claim).read_text().split()
        pid = int(words[0]) if words else 0
    except (OSError, ValueError):
        return 0, False
    if pid <= 0 or not _alive(pid):
        return 0, False
    return pid, "started" in words[1:]


def _claimed(claim: str) -> bool:
    """A live process is compiling this kernel for these types, or will."""
    return _claim_state(claim)[0] > 0


def _start_worker() -> subprocess.Popen:
    global _worker
    if _worker is not None and _worker.poll() is None:
        return _worker
    root = str(Path(__file__).resolve().parents[1])  # the folder holding this femast package
    env = dict(os.environ, FEMAST_BACKGROUND_COMPILE="0", FEMAST_QUIET="1")
    env["PYTHONPATH"] = os.pathsep.join([root] + [p for p in env.get("PYTHONPATH", "").split(os.pathsep) if p])
    _worker = subprocess.Popen(
        [sys.executable, "-m", "femast.jit_background"],
        stdin=subprocess.PIPE,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
        env=env,
        text=True,
    )
    atexit.register(_let_worker_finish, _worker)
    return _worker


def _let_worker_finish(worker: subprocess.Popen) -> None:
    """At exit: close the request pipe (the worker compiles what is queued, then ends by itself)
    and do not wait for it; ``returncode`` set so that Popen does not warn that it still runs."""
    try:
        worker.stdin.close()
    except OSError:
        pass
    if worker.poll() is None:
        worker.returncode = 0


def _request(dispatcher, sig, claim: str) -> bool:
    """Queue a compile on the worker; False if no worker could be started."""
    try:
        worker = _start_worker()
        Path(claim).write_text(str(worker.pid))
        line = json.dumps(
            {
                "module": dispatcher.py_func.__module__,
                "name": dispatcher.py_func.__name__,
                "sig": base64.b64encode(pickle.dumps(sig)).decode(),
                "claim": claim,
            }
        )
        worker.stdin.write(line + "\n")
        worker.stdin.flush()
    except (OSError, pickle.PicklingError, ValueError):
        return False
    return True


class _Hook:
    """Replaces ``dispatcher._compile_for_args``: numba's C dispatcher calls it when it has no
    compiled code for a call and then calls what it returns with the call's arguments."""

    def __init__(self, dispatcher):
        self.dispatcher = dispatcher
        self.original = dispatcher._compile_for_args
        self.index = _index_path(dispatcher)
        self.last_s = 0.0  # duration of the last interpreted call, s
        self.requested = set()  # claims this process has queued

    def __call__(self, *args, **kws):
        d = self.dispatcher
        how = mode()
        if how == "interpret" and not kws:
            return self._run_interpreted
        if kws or how == "off" or self.index is None:
            return self.original(*args, **kws)
        try:
            sig = tuple(d.typeof_pyval(a) for a in args)
        except Exception:  # noqa: BLE001 - numba reports the bad argument itself
            return self.original(*args)
        claim = _claim_path(self.index, sig)
        if not _claimed(claim):
            if os.path.exists(self.index) or claim in self.requested:
                return self.original(*args)  # on disk now (or the worker failed): load or compile
            if not _request(d, sig, claim):
                return self.original(*args)
            self.requested.add(claim)
            _notice()
        if _n_items(args) > INTERPRET_MAX_ITEMS or self.last_s > INTERPRET_MAX_S:
            return self._compiled_now(args, claim)  # too big to interpret
        return self._run_interpreted

    def _compiled_now(self, args, claim):
        """Wait for the worker if it has begun this kernel; otherwise take the claim over and
        compile here (the worker skips a request whose claim is no longer its own), so that two
        kernels compile at once on two cores."""
        pid, started = _claim_state(claim)
        if pid and not started and pid != os.getpid():
            try:
                Path(claim).write_text(f"{os.getpid()} started")
            except OSError:
                pass
            else:
                if _DEBUG:
                    print(f"jit_background: compiling {self.dispatcher.py_func.__name__} here", file=sys.stderr)
                try:
                    return self.original(*args)
                finally:
                    _remove(claim)
        if _DEBUG:
            print(f"jit_background: waiting for {self.dispatcher.py_func.__name__}", file=sys.stderr)
        while _claimed(claim):
            time.sleep(_POLL_S)
        return self.original(*args)

    def _run_interpreted(self, *args):
        t0 = time.process_time()  # CPU time: a loaded machine must not make a small model wait
        try:
            return interpreted(self.dispatcher)(*args)
        finally:
            self.last_s = time.process_time() - t0
            if _DEBUG:
                print(
                    f"jit_background: {self.dispatcher.py_func.__name__} interpreted in {self.last_s:.4f} s "
                    f"({_n_items(args)} items)",
                    file=sys.stderr,
                )


def _notice():
    if _announce is not None:
        _announce()


_installed_for = None  # the loaded femast modules at the last install (nothing new: no scan)


def install() -> int:
    """Hook every cacheable femast kernel of the loaded modules (idempotent); returns how many are
    hooked.  The scan of the modules' globals (~10 ms) runs again only when femast modules were
    loaded (or reloaded) since the last one: every Analysis calls this."""
    global _installed_for
    if not enabled():
        return 0
    loaded = frozenset(
        (name, id(mod)) for name, mod in list(sys.modules.items()) if name.startswith("femast") and mod is not None
    )
    if loaded == _installed_for:
        return len(_hooked)
    from .jit import _dispatchers

    _installed_for = loaded
    for _, d in _dispatchers():
        if id(d) not in _hooked and _index_path(d) is not None:
            hook = _Hook(d)
            d._compile_for_args = hook
            _hooked[id(d)] = hook
    return len(_hooked)


def uninstall() -> None:
    """Give every hooked kernel numba's own ``_compile_for_args`` back."""
    global _installed_for
    _installed_for = None
    for hook in _hooked.values():
        try:
            del hook.dispatcher._compile_for_args
        except AttributeError:  # pragma: no cover
            pass
    _hooked.clear()


# --------------------------------------------------------------------------- the worker process
def _priority(req) -> int:
    """Element kernels and the assembly scatter first: interpreted, they cost the most per call
    (the beam kernel ~0.8 ms per element, 15 ms per call of a 20-beam model) against 0.5 ms or less
    for the configuration update and the convergence maxima."""
    return 0 if req["module"].startswith(("femast.elements.", "femast.analysis.assembly")) else 1


def _remove(path: str) -> None:
    try:
        os.remove(path)
    except OSError:
        pass


def _compile(req) -> None:
    """Compile one request unless its claim has been taken over (the caller compiles it itself)."""
    import importlib

    claim = req["claim"]
    me = str(os.getpid())
    try:
        if Path(claim).read_text().split()[:1] != [me]:
            return
        Path(claim).write_text(f"{me} started")
    except OSError:
        return
    t0, c0 = time.perf_counter(), time.process_time()
    ok = False
    try:
        d = getattr(importlib.import_module(req["module"]), req["name"])
        d.compile(pickle.loads(base64.b64decode(req["sig"])))
        ok = True
    except Exception:  # noqa: BLE001 - the caller compiles it itself when no cache appears
        pass
    finally:
        _remove(claim)
        _log(
            {
                "kernel": f"{req['module']}.{req['name']}",
                "ok": ok,
                "cpu_s": time.process_time() - c0,
                "wall_s": time.perf_counter() - t0,
            }
        )


def _log(record: dict) -> None:
    """One JSON line per compile (and one at the end) to ``FEMAST_JIT_LOG`` if set (benchmarks/cold_start.py)."""
    path = os.environ.get("FEMAST_JIT_LOG")
    if path:
        with open(path, "a") as fh:
            fh.write(json.dumps(dict(record, pid=os.getpid(), time=time.time())) + "\n")


def _serve(stream) -> None:
    """Compile the requested kernels (one JSON line each) into numba's cache, dropping each claim
    when done: a reader thread queues the requests, and the next compile is the first of the
    highest :func:`_priority`; returns when the stream has ended and the queue is empty."""
    import threading

    pending, cond, ended = [], threading.Condition(), []

    def read():
        for line in stream:
            if line.strip():
                with cond:
                    pending.append(json.loads(line))
                    cond.notify()
        with cond:
            ended.append(True)
            cond.notify()

    threading.Thread(target=read, daemon=True).start()
    while True:
        with cond:
            while not pending and not ended:
                cond.wait()
            if not pending:
                return
            best = min(range(len(pending)), key=lambda i: (_priority(pending[i]), i))
            req = pending.pop(best)
        _compile(req)


if __name__ == "__main__":
    _log({"worker_started": True, "cpu_s": time.process_time()})
    _serve(sys.stdin)
    _log({"worker_done": True, "cpu_s": time.process_time()})
