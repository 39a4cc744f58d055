"""Progress for waits a person sits through: tqdm bars on stderr, erased when done.

Bars show only when stderr is a terminal and femast is not quiet (``femast --quiet``,
:func:`set_quiet`, or the environment variable ``FEMAST_QUIET=1``), so logs, pipes and test
output never get bar text; a bar is closed (and erased) before an error propagates, so it is
never mixed into the error message.

* :func:`task` -- a bar for one piece of work of unknown length (a fit): it counts the model
  evaluations (:func:`tick` from :func:`femast.experiments.prediction.predict`) and shows the FE runs
  as they happen (:func:`tick` ``("FE runs")`` from the FE experiments).
* :func:`items` -- a bar over a known list (the cases of a benchmark, the refits of diagnose),
  naming the item being worked on.
* :class:`Relays` and :func:`relay_to` -- progress from worker processes: a worker's :func:`tick`
  calls go to a small file of its task, which the parent reads while it waits, so a bar over
  tasks that run elsewhere (diagnose's refits) moves with every model run inside them.

A terminal that reports no width (``script``, some CI consoles: 0 columns) cannot draw a bar; there,
and wherever ``FEMAST_PROGRESS=plain`` is set (a log file), progress is plain text instead: a line
every few seconds (:data:`PLAIN_INTERVAL_S`) with the count, the elapsed time and, when the total
is known, the estimated time left.
"""

from __future__ import annotations

import contextlib
import os
import shutil
import sys
import tempfile

_QUIET = False
_ACTIVE = []  # stack of (bar, counts) of the open tasks, innermost last
_RELAY = None  # file this process's ticks are also appended to (a worker's task), or None


def set_quiet(quiet: bool = True) -> None:
    """Switch every femast progress bar (and the first-run compile notice) off or back on."""
    global _QUIET
    _QUIET = bool(quiet)


def enabled() -> bool:
    """True when bars should show: not quiet and stderr is a terminal."""
    if _QUIET or os.environ.get("FEMAST_QUIET", "").strip() not in ("", "0"):
        return False
    try:
        return sys.stderr.isatty()
    except (AttributeError, ValueError):
        return False


def quiet() -> bool:
    """True when femast should print no notices either (``--quiet`` or FEMAST_QUIET)."""
    return _QUIET or os.environ.get("FEMAST_QUIET", "").strip() not in ("", "0")


PLAIN_INTERVAL_S = 5.0  # seconds between two lines of plain-text progress


def plain() -> bool:
    """True when progress is written as plain lines: ``FEMAST_PROGRESS=plain`` (not quiet), or
    stderr a terminal that reports no width (0 columns), where a bar would not show."""
    if quiet():
        return False
    if os.environ.get("FEMAST_PROGRESS", "").strip().lower() == "plain":
        return True
    if not enabled():
        return False
    try:
        return os.get_terminal_size(sys.stderr.fileno()).columns <= 0
    except (AttributeError, ValueError, OSError):
        return False


def _bar(**kw):
    if plain():
        return PlainProgress(**kw)
    from tqdm.auto import tqdm

    return tqdm(disable=not enabled(), leave=False, file=sys.stderr, dynamic_ncols=True, **kw)


def _clock(seconds: float) -> str:
    m, s = divmod(int(round(seconds)), 60)
    return f"{m // 60}:{m % 60:02d}:{s:02d}" if m >= 60 else f"{m}:{s:02d}"


# the plain lines of this process's bars on the default clock, as one stream: (the time of the last
# line, or of the start of the stretch of work; bars open; when the last one closed)
_PLAIN = {"last": None, "open": 0, "closed_at": None}


def _plain_clock() -> float:
    import time

    return time.monotonic()


class PlainProgress:
    """Progress as plain text lines on stderr, one every ``interval`` seconds at most (the first
    after ``interval`` too: a short wait prints nothing), ``desc: 12/40 refits, 3 FE runs
    [0:25 elapsed, ~1:02 left]``.  The methods a tqdm bar offers that femast uses.

    On the default clock the bars of a process are one stream: ``interval`` counts from the last
    line any of them printed, so a run of short tasks one after the other (six refits of 4 s each)
    still prints a line every ``interval`` instead of none; a stretch of work starts again (a first
    line only after ``interval``) when a bar opens ``interval`` after the last one closed."""

    disable = False

    def __init__(self, desc="", total=None, unit="it", interval=None, file=None, clock=None, **_):
        self._shared = clock is None
        self._time = clock or _plain_clock
        self.desc, self.total, self.unit, self.n, self.postfix = desc, total, unit, 0, ""
        self.interval = PLAIN_INTERVAL_S if interval is None else interval
        self.file = file or sys.stderr
        self.start = self._last = self._time()
        self._closed = False
        if self._shared:
            idle = _PLAIN["closed_at"] is None or self.start - _PLAIN["closed_at"] >= self.interval
            if _PLAIN["open"] <= 0 and idle:
                _PLAIN["last"] = self.start  # a new stretch of work
            _PLAIN["open"] += 1
            self._last = _PLAIN["last"]

    def line(self) -> str:
        """The progress line as it stands."""
        now = self._time() - self.start
        n = f"{self.n:.1f}" if self.n != int(self.n) else f"{int(self.n)}"  # tasks partly done: 3.4/12
        count = f"{n}/{self.total}" if self.total else n
        when = f"{_clock(now)} elapsed"
        if self.total and 0 < self.n < self.total:
            when += f", ~{_clock(now * (self.total - self.n) / self.n)} left"
        post = f", {self.postfix}" if self.postfix else ""
        return f"{self.desc}: {count}{self.unit}{post} [{when}]"

    def _maybe_print(self):
        last = _PLAIN["last"] if self._shared else self._last
        if self._time() - last >= self.interval:
            self._last = self._time()
            if self._shared:
                _PLAIN["last"] = self._last
            try:
                print(self.line(), file=self.file, flush=True)
            except (OSError, ValueError):
                pass

    def update(self, k=1):
        self.n += k
        self._maybe_print()

    def set_postfix_str(self, s="", refresh=True):
        self.postfix = str(s)
        self._maybe_print()

    def refresh(self):
        self._maybe_print()

    def close(self):
        if self._shared and not self._closed:
            _PLAIN["open"] -= 1
            _PLAIN["closed_at"] = self._time()
        self._closed = True

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
        return False


@contextlib.contextmanager
def task(desc: str, unit: str = "evaluations", delay: float = 0.0):
    """A bar counting the :func:`tick` calls made inside the ``with`` block (innermost task gets them);
    ``delay`` (s): shown only once the work has taken that long."""
    bar = _bar(
        desc=desc, unit=f" {unit}", total=None, bar_format="{desc}: {n_fmt}{unit} [{elapsed}]{postfix}", delay=delay
    )
    entry = (bar, {})
    _ACTIVE.append(entry)
    try:
        yield bar
    finally:
        _ACTIVE.remove(entry)
        bar.close()


def tick(kind: str | None = None) -> None:
    """One unit of work done: the innermost :func:`task` counts it (``kind`` None) or shows the
    running count of ``kind`` (e.g. "FE runs") beside its own; a worker relaying to its parent
    (:func:`relay_to`) also appends it to its relay file.  No-op outside a task and a relay."""
    if _RELAY is not None:
        try:
            with open(_RELAY, "ab") as fh:  # one byte per tick: an append of this size is atomic
                fh.write(b"e" if kind is None else b"f")
        except OSError:  # the parent has gone or removed its folder: progress is not worth an error
            pass
    if not _ACTIVE:
        return
    bar, counts = _ACTIVE[-1]
    if kind is None:
        bar.update(1)
    else:
        counts[kind] = counts.get(kind, 0) + 1
        bar.set_postfix_str(", ".join(f"{v} {k}" for k, v in counts.items()), refresh=True)


def items(seq, desc: str, name=str, unit: str = "it"):
    """Iterate over ``seq`` with a bar of ``len(seq)`` steps whose postfix names the current item
    (``name(item)``)."""
    seq = list(seq)
    bar = _bar(desc=desc, total=len(seq), unit=f" {unit}")
    try:
        for item in seq:
            bar.set_postfix_str(str(name(item)), refresh=True)
            yield item
            bar.update(1)
    finally:
        bar.close()


def relay_to(path) -> None:
    """From now on append this process's :func:`tick` calls to the file ``path`` (a path from
    :meth:`Relays.path` in the parent); ``None`` stops."""
    global _RELAY
    _RELAY = None if path is None else str(path)


class Relays:
    """The parent's side of :func:`relay_to`: one small file per task in a private temporary folder
    (removed by :meth:`close`), counted on demand.  Use as a context manager."""

    def __init__(self):
        self.folder = tempfile.mkdtemp(prefix="femast-progress-")

    def path(self, key) -> str:
        """The relay file of task ``key`` (give it to the task, which calls :func:`relay_to`)."""
        return os.path.join(self.folder, f"{key}.ticks")

    def counts(self, key) -> tuple[int, int]:
        """(model evaluations, FE runs) task ``key`` has reported so far."""
        try:
            with open(self.path(key), "rb") as fh:
                data = fh.read()
        except OSError:
            return 0, 0
        return data.count(b"e"), data.count(b"f")

    def close(self) -> None:
        shutil.rmtree(self.folder, ignore_errors=True)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
        return False


def task_fraction(done: int, expected: float, cap: float = 0.9) -> float:
    """Share of a running task done after ``done`` of about ``expected`` units, at most ``cap``
    (a task is finished only when it says so)."""
    if done <= 0 or not expected or expected <= 0:
        return 0.0
    return min(cap, done / float(expected))


def as_completed(futures, desc: str, unit: str = "tasks", relays=None, name=None, poll_s: float = 0.5):
    """Yield ``futures`` (:mod:`concurrent.futures`) as they finish, with a bar of ``len(futures)``
    steps that also moves while they run: with ``relays`` (:class:`Relays`, task ``i`` relaying to
    ``relays.path(i)``), a running task counts as the share of its model evaluations in the
    evaluations a finished task took on average (at most 0.9 of a step; before any has finished, the
    share of the most any running task has done), so the bar and its estimate of the time left
    advance with every inner model run, not only when a whole task ends.  ``name(i)``: the label of
    task ``i`` shown when it finishes."""
    import concurrent.futures as cf

    futures = list(futures)
    index = {id(f): i for i, f in enumerate(futures)}
    pending, done_evals, shown, last = set(futures), [], 0.0, ""
    bar = _bar(
        desc=desc,
        total=len(futures),
        unit=f" {unit}",
        bar_format="{desc}: {percentage:3.0f}%|{bar}| {postfix} [{elapsed}<{remaining}]",
    )
    try:
        while pending:
            finished, pending = cf.wait(pending, timeout=poll_s, return_when=cf.FIRST_COMPLETED)
            counts = [relays.counts(i) for i in range(len(futures))] if relays is not None else []
            done_evals += [counts[index[id(f)]][0] for f in finished if counts]
            if finished and name is not None:
                last = f"last: {name(index[id(finished.copy().pop())])}"
            partial = 0.0
            if counts and pending:
                running = [counts[index[id(f)]][0] for f in pending]
                expected = sum(done_evals) / len(done_evals) if done_evals else 2.0 * max(running)
                partial = sum(task_fraction(n, expected) for n in running)
            position = len(futures) - len(pending) + partial
            if position > shown:
                bar.update(position - shown)
                shown = position
            runs = f"{sum(c[0] for c in counts)} model runs" if counts else ""
            fe = sum(c[1] for c in counts)
            post = ", ".join(
                s
                for s in (
                    f"{len(futures) - len(pending)} of {len(futures)} finished",
                    runs,
                    fe and f"{fe} FE runs",
                    last,
                )
                if s
            )
            bar.set_postfix_str(post, refresh=True)
            yield from finished
    finally:
        bar.close()


def counter(total: int, desc: str, unit: str = "it"):
    """A bar of ``total`` steps to update by hand (``bar.update(1)``, ``bar.set_postfix_str``);
    use as a context manager."""
    return _bar(desc=desc, total=total, unit=f" {unit}")


def close_all() -> None:
    """Close (erase) every open bar, e.g. before an error message is printed."""
    try:
        from tqdm import tqdm
    except ImportError:  # pragma: no cover
        return
    for bar in list(getattr(tqdm, "_instances", ())):
        bar.close()
    del _ACTIVE[:]
