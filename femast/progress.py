"""Progress for waits a person sits through: tqdm bars on stderr, erased when done.

Bars show only when stderr is a terminal and femast is not quiet (``femast --quiet``,
:func:`set_quiet`, or the environment variable ``FEMAST_QUIET=1``), so logs, pipes and test
output never get bar text; a bar is closed (and erased) before an error propagates, so it is
never mixed into the error message.

* :func:`task` -- a bar for one piece of work of unknown length (a fit): it counts the model
  evaluations (:func:`tick` from :func:`femast.experiments.fitting.predict`) and shows the FE runs
  as they happen (:func:`tick` ``("FE runs")`` from the FE experiments).
* :func:`items` -- a bar over a known list (the cases of a benchmark, the refits of diagnose),
  naming the item being worked on.
"""

from __future__ import annotations

import contextlib
import os
import sys

_QUIET = False
_ACTIVE = []  # stack of (bar, counts) of the open tasks, innermost last


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


def _bar(**kw):
    from tqdm.auto import tqdm

    return tqdm(disable=not enabled(), leave=False, file=sys.stderr, dynamic_ncols=True, **kw)


@contextlib.contextmanager
def task(desc: str, unit: str = "evaluations"):
    """A bar counting the :func:`tick` calls made inside the ``with`` block (innermost task gets them)."""
    bar = _bar(desc=desc, unit=f" {unit}", total=None, bar_format="{desc}: {n_fmt}{unit} [{elapsed}]{postfix}")
    entry = (bar, {})
    _ACTIVE.append(entry)
    try:
        yield bar
    finally:
        _ACTIVE.remove(entry)
        bar.close()


def tick(kind: str | None = None) -> None:
    """One unit of work done: the innermost :func:`task` counts it (``kind`` None) or shows the
    running count of ``kind`` (e.g. "FE runs") beside its own.  No-op outside a task."""
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
