"""Derivatives and coordinates of the fits of expensive models (the FE experiments).

Every evaluation of such a model is an FE run (0.1-2 s), so a fit's cost is its number of runs.
:class:`_FEJacobian` takes forward differences with a floor on the step and Broyden secant updates
between them; :func:`_polish` makes sure the fit ends where a finite-difference Jacobian agrees
(and gives the covariance); :class:`_Coords` fits positive parameters spanning decades in log scale
and gives registered starts back bit for bit (so the run cache answers them).  Used by
:func:`femast.experiments.fitting.fit`.
"""

from __future__ import annotations

import math
import os
import sys
import time

import numpy as np
from scipy.optimize import least_squares


class _FEJacobian:
    """(fun, jac) for least_squares on an expensive model (an FE run per evaluation): forward
    differences of ``step x max(1, |u_i|)`` in the scaled parameters u (the ``diff_step`` of
    ``Experiment.fit_options``), and between them Broyden's rank-one secant updates.

    scipy's own ``diff_step`` is relative to ``|u_i|`` and falls back to 1.5e-8 at ``u_i = 0``, the
    start of an effect whose default is "absent" (a pretension error dT0 = 0): an FE model resolves
    that step no better than its Newton tolerance, and the derivative comes out with the wrong sign.
    Here the step never drops below ``step``; it is taken backwards where it would leave the upper
    bound.  The value at the point itself is reused from the last call of ``fun`` (scipy evaluates
    it just before asking for the Jacobian).

    ``secant``: after the first Jacobian, an accepted step s with residual change y updates it as
    J + (y - J s) s^T / (s^T s) (Broyden 1965; Dennis & Schnabel 1996, Sec. 8.1) instead of p more
    FE runs; a step the trust region rejected (the model did not follow the linearisation) makes
    the next Jacobian a finite-difference one again.  ``J0``: columns known at the start (NaN where
    not), e.g. the baseline's finite differences handed to a refit.
    ``runs`` counts the evaluations of ``fun`` (cache hits included); ``fd_at`` is the point of the
    last finite-difference Jacobian and ``fd_J`` that Jacobian."""

    def __init__(self, fun, step: float, lo, hi, secant: bool = True, J0=None):
        self.fun, self.step, self.lo, self.hi, self.secant = fun, float(step), lo, hi, secant
        self.last = {}
        self.J = self.u = self.f = None
        self.J0 = None if J0 is None else np.array(J0, float)
        self.since = 0  # evaluations since the last Jacobian (> 1: a rejected step)
        self.runs = 0
        self.fd_at = self.fd_J = None

    def value(self, u):
        key = np.asarray(u, float).tobytes()
        if key not in self.last:
            self.last.clear()
            self.runs += 1
            self.last[key] = self.fun(u)
        self.since += 1
        return self.last[key]

    def differences(self, u, f0, known=None):
        J = np.empty((f0.size, u.size))
        todo, points, steps = [], [], []
        for i in range(u.size):
            if known is not None and np.all(np.isfinite(known[:, i])):
                J[:, i] = known[:, i]
                continue
            h = self.step * max(1.0, abs(u[i]))
            if u[i] + h > self.hi[i]:
                h = -h
            up = u.copy()
            up[i] += h
            todo.append(i)
            points.append(up)
            steps.append(h)
        self.runs += len(points)
        for i, h, f in zip(todo, steps, evaluate_many(self.fun, points, f0.size)):
            J[:, i] = (f - f0) / h
        if known is None or not np.all(np.isfinite(known)):
            self.fd_at, self.fd_J = u.copy(), J.copy()
        return J

    def jac(self, u, *args):
        u = np.asarray(u, float)
        f0 = self.value(u)
        self.since -= 1  # scipy's value call before the Jacobian is not a trial step
        if self.J is None:
            known = self.J0 if self.J0 is not None and self.J0.shape == (f0.size, u.size) else None
            J = self.differences(u, f0, known)
        elif not self.secant or self.since > 1:
            J = self.differences(u, f0)
        else:
            s = u - self.u
            ss = float(s @ s)
            J = self.J if ss == 0.0 else self.J + np.outer((f0 - self.f) - self.J @ s, s) / ss
        self.J, self.u, self.f, self.since = J, u.copy(), f0, 0
        return J

    def at_solution(self, u):
        """(J by finite differences at ``u``, whether it had to be computed)."""
        u = np.asarray(u, float)
        if self.fd_at is not None and np.array_equal(self.fd_at, u):
            return self.fd_J, False
        return self.differences(u, self.value(u)), True


FORK_COLUMNS = True  # evaluate a Jacobian's finite-difference columns in this process and a forked one


def _fork_ok(n_points: int) -> bool:
    """Columns may be split with a forked child: several to compute, a second CPU, Linux's fork, this
    the main and only thread of a process that is not itself a worker of a pool (whose cores are taken:
    the refits of diagnose), and numba not running GNU OpenMP threads (a forked child of those aborts)."""
    if not FORK_COLUMNS or n_points < 2 or not hasattr(os, "fork") or (os.cpu_count() or 1) < 2:
        return False
    if not sys.platform.startswith("linux"):  # (where fork is multiprocessing's default; macOS: not safe)
        return False
    import multiprocessing
    import threading

    if multiprocessing.parent_process() is not None or threading.current_thread() is not threading.main_thread():
        return False
    if not _only_thread():
        return False
    try:
        import numba

        if numba.threading_layer() == "omp":
            return False
    except Exception:  # (ValueError while no parallel kernel has run: no threads)
        pass
    return True


def _only_thread() -> bool:
    """No other thread that might hold a lock the child needs (a Jupyter kernel's, a results writer's);
    tqdm's monitor only wakes every 10 s to check the bars, which the child does not draw."""
    import threading

    me = threading.current_thread()
    return all(t is me or type(t).__name__ == "TMonitor" for t in threading.enumerate())


def evaluate_many(fun, points, size: int) -> list:
    """``[fun(p) for p in points]`` (each a (size,) float array), the second half of the points in a
    forked child process while this one computes the first (a fit's finite-difference
    columns are independent FE runs, and during a fit in the main process the second CPU is idle; a
    forked child inherits the loaded kernels, the reference path and the model).  The child sends the
    values back as raw float64 bytes through a pipe and ends with ``os._exit``; if it fails, this process
    computes its points itself.  Serial when :func:`_fork_ok` says no."""
    if not _fork_ok(len(points)):
        return [fun(p) for p in points]
    import gc

    k = (len(points) + 1) // 2
    rd, wr = os.pipe()
    gc.freeze()  # (the child's collections skip the inherited heap: fewer copied pages; see refits.frozen_heap)
    try:
        pid = os.fork()
    except OSError:
        gc.unfreeze()
        os.close(rd)
        os.close(wr)
        return [fun(p) for p in points]
    if pid == 0:  # the child: its points, then exit without running any of the parent's exit handlers
        code = 1
        try:
            os.close(rd)
            os.environ["FEMAST_BACKGROUND_COMPILE"] = "0"  # (no requests to the parent's compile worker)
            from .. import progress

            progress.set_quiet(True)
            vals = [np.asarray(fun(p), dtype=np.float64).reshape(size) for p in points[k:]]
            data = np.concatenate(vals).tobytes()
            with os.fdopen(wr, "wb") as fh:
                fh.write(data)
            code = 0
        finally:
            os._exit(code)
    os.close(wr)
    mine = None
    t0 = time.monotonic()
    try:
        mine = [fun(p) for p in points[:k]]
    finally:
        # an error or Ctrl-C here: the child's points are not wanted, it is ended at once (no wait for
        # its runs, no orphan); else it gets CHILD_WAIT x this process's time for its share (a child
        # stuck on a lock that fork copied: killed, and its points computed here)
        wait_s = 0.0 if mine is None else max(CHILD_WAIT * (time.monotonic() - t0), CHILD_WAIT_MIN_S)
        data, status = _child_answer(pid, rd, wait_s)
        gc.unfreeze()
    n = len(points) - k
    if status == 0 and len(data) == 8 * size * n:
        theirs = list(np.frombuffer(data, dtype=np.float64).reshape(n, size).copy())
    else:
        theirs = [fun(p) for p in points[k:]]
    return mine + theirs


CHILD_WAIT = 4.0  # the forked child's share may take this many times this process's share ...
CHILD_WAIT_MIN_S = 300.0  # ... or this long (s), whichever is longer, before it is taken for stuck (a cold
#                           child may compile kernels in the foreground: tens of seconds)


def _child_answer(pid: int, rd: int, wait_s: float) -> tuple[bytes, int]:
    """(bytes the child wrote to the pipe ``rd`` until it closed it, its wait status), the child reaped;
    a child that has not closed the pipe within ``wait_s`` seconds (0: at once), or when this process
    is interrupted while waiting, is killed first (status then not 0).  ``rd`` is closed."""
    chunks = []
    end = time.monotonic() + wait_s
    closed = False
    try:
        while True:
            left = end - time.monotonic()
            if left <= 0.0 or not readable(rd, left):
                break
            chunk = os.read(rd, 1 << 16)
            if not chunk:
                closed = True
                break
            chunks.append(chunk)
    finally:
        if not closed:
            _kill(pid)
        os.close(rd)
        _, status = os.waitpid(pid, 0)
    return b"".join(chunks), status


def readable(fd: int, wait_s: float) -> bool:
    """``fd`` has data (or its other end was closed) within ``wait_s`` seconds (poll: no limit on the
    descriptor's number, unlike select's 1024)."""
    import select

    p = select.poll()
    p.register(fd, select.POLLIN | select.POLLHUP | select.POLLERR)
    return bool(p.poll(max(0, math.ceil(1000.0 * wait_s))))


def _kill(pid: int) -> None:
    import signal

    try:
        os.kill(pid, signal.SIGKILL)
    except ProcessLookupError:
        pass


def _forward_differences(fun, step: float, lo, hi):
    """(fun, jac) with forward differences at every Jacobian (no secant updates); see :class:`_FEJacobian`."""
    j = _FEJacobian(fun, step, lo, hi, secant=False)
    return j.value, j.jac


LOG_RANGE = 100.0  # a positive parameter whose bounds span this factor or more is fitted in log scale


class _Coords:
    """The fit's coordinates u of the parameters x: ``x / scale`` (linear), or ``ln(x / scale)`` for
    the parameters flagged ``log`` (expensive fits of positive parameters spanning decades: a
    stiffness or an axial rigidity, whose effect goes as 1/x: Gauss-Newton steps in ln x reach
    the minimum in fewer FE runs than steps in x).  ``start`` registers a start value so
    that ``to_x`` gives it back bit for bit (the run cache then answers it)."""

    def __init__(self, scale, log):
        self.scale, self.log = np.asarray(scale, float), np.asarray(log, bool)
        self.exact = {}

    def to_u(self, x):
        x = np.asarray(x, float)
        u = x / self.scale
        with np.errstate(divide="ignore", invalid="ignore"):
            u[self.log] = np.log(x[self.log] / self.scale[self.log])
        return u

    def to_x(self, u):
        u = np.asarray(u, float)
        hit = self.exact.get(u.tobytes())
        if hit is not None:
            return hit.copy()
        x = u * self.scale
        x[self.log] = self.scale[self.log] * np.exp(u[self.log])
        return x

    def dx_du(self, u):
        """dx/du at ``u`` (the chain rule of the Jacobian and the covariance)."""
        d = self.scale.copy()
        d[self.log] = self.scale[self.log] * np.exp(np.asarray(u, float)[self.log])
        return d

    def start(self, x, lo, hi):
        """The coordinates of start ``x`` (clipped into the bounds), remembered so that ``to_x`` returns
        exactly ``x``: a refit started from another fit's values asks the FE model for those values."""
        x = np.asarray(x, float)
        u = np.clip(self.to_u(x), lo, hi)
        if np.array_equal(np.clip(x, self.to_x(lo), self.to_x(hi)), x):
            self.exact[u.tobytes()] = x.copy()
        return u


POLISH_ROUNDS = 2
POLISH_MIN_DECREASE = 0.01  # half chi-square: a restart must promise more (0.14 standard errors of a parameter)


def _polish(sol, fj, fun, lo, hi, kw, min_decrease: float = 0.0):
    """The Jacobian at the solution by finite differences (for the covariance), and a restart of the fit
    from there, with that Jacobian, when its Gauss-Newton step (within the bounds) predicts a decrease
    of the cost beyond ``ftol`` of it and beyond ``min_decrease``: a secant Jacobian may have stopped
    the fit early.  With residuals whitened by the noise (a given noise model), the cost is half the
    chi-square, and a decrease d moves the parameters by about sqrt(2 d) standard errors
    (``POLISH_MIN_DECREASE`` = 0.01: 0.14 of one); a smaller predicted gain is not worth a restart."""
    extra = 0
    ftol = float(kw.get("ftol", 1e-8))
    for rnd in range(POLISH_ROUNDS + 1):
        J, _ = fj.at_solution(sol.x)
        f = fj.value(sol.x)
        step = np.linalg.lstsq(J, -f, rcond=None)[0]
        u_new = np.clip(sol.x + step, lo, hi)
        r = f + J @ (u_new - sol.x)
        predicted = sol.cost - 0.5 * float(r @ r)
        if rnd == POLISH_ROUNDS or not predicted > max(ftol * sol.cost, min_decrease):
            break
        fj.J, fj.J0 = None, J
        with np.errstate(all="ignore"):
            again = least_squares(fun, sol.x, bounds=(lo, hi), **kw)
        extra += again.nfev
        if again.cost <= sol.cost:
            sol = again
        else:
            break
    J, _ = fj.at_solution(sol.x)
    sol.jac = J
    sol.fun = fj.value(sol.x)
    sol.nfev_polish = extra
    return sol
