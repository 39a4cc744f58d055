"""Data sets too long to fit row by row: compare and diagnose work on every k-th row.

A fit and a diagnosis cost time in proportion to the rows (every model evaluation runs along the
whole path, and a diagnosis makes hundreds of them), while their statistics need far fewer rows
than a logger writes in an hour: the noise floor of a channel is known to ~1 % from 10 000 rows,
and an effect that changes the fit by more than the noise changes it on every 100th row too.
Above :data:`MAX_ROWS` rows, compare and diagnose therefore use every k-th row (k the smallest
that leaves at most MAX_ROWS), and say so (a ``DataWarning`` naming the file, the rows read and the
rows used).  Decimating keeps the noise as it is (a subsample of white noise is white noise of the
same level; correlated noise becomes less correlated), where averaging bins of rows would shrink
it and move the noise floor; the rows kept still point at their file lines.  The path must be
sampled finely enough that every k-th row still follows it (a logger at a few hundred Hz on a
quasi-static test is); pass ``max_rows`` (``--max-rows``) to use more.
"""

from __future__ import annotations

import math
import warnings

import numpy as np

from .data import DataWarning
from .units import CONFIRMED

MAX_ROWS = 10_000  # rows compare and diagnose use at most (every k-th row above)


def thin(data, max_rows: int | None = None, what: str = "compare"):
    """``data`` itself when it has at most ``max_rows`` rows (default :data:`MAX_ROWS`), else its
    every k-th row (module docstring), with a DataWarning saying so."""
    limit = MAX_ROWS if max_rows is None else int(max_rows)
    if limit < 1:
        raise ValueError(f"max_rows = {max_rows!r}: give a whole number >= 1")
    n = data.n
    if n <= limit:
        return data
    k = math.ceil(n / limit)
    rows = np.arange(0, n, k)
    warnings.warn(
        f"{data.path}: {n} rows; {what} uses one row in {k} ({rows.size} rows): the noise floor, fits and "
        f"tests are those of the subsample (--max-rows N to use more)",
        DataWarning,
        stacklevel=3,
    )
    sub = data.subset(rows)
    sub.cache.update({k: v for k, v in data.cache.items() if k == CONFIRMED})  # --units dx_m=m still holds
    return sub
