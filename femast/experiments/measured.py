"""Measured data of an experiment: columns in their units, rows in time order, in groups.

A data set may hold several **groups** -- stations, specimens, test runs, files -- each a path of
its own: the model runs group by group (a path-dependent state starts relaxed in every group,
:func:`~femast.experiments.prediction.predict`), held-out validation leaves one group out at a time
(:mod:`femast.experiments.heldout`), and with ``offsets`` every group gets its own zero in every
channel (a station whose sensors were zeroed again), counted in the information criterion.

**Time** is ``t_s`` (else the row index), normalised to [0, 1] for the effects that act with time
(:attr:`Measured.tau`): over each group (``time_continuous`` False: the groups are separate
tests) or over the whole data set (True: one test recorded in several files or runs, whose time
goes on from one to the next).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


@dataclass
class Measured:
    """Measured data of one experiment: ``columns[name]`` (n,) float arrays, rows in time order.

    path : the file it came from (or ``"<arrays>"``, or the files joined by ", ").  lines : file line
    number of each row (1-based), used to point at rows in reports and errors.  groups : (n,) int
    group of each row (0, 1, ...) or None (one group); group_names : the label of each group.
    time_continuous : the time of the groups runs on (one test in several parts) rather than
    restarting in each.  offsets : fit a zero of its own for every group and channel.  ``cache``
    holds quantities an experiment prepares once per data set (see ``Experiment.prepare``).
    """

    experiment: str
    columns: dict
    path: str = "<arrays>"
    lines: np.ndarray | None = None
    cache: dict = field(default_factory=dict, repr=False, compare=False)
    groups: np.ndarray | None = None
    group_names: tuple = ()
    time_continuous: bool = False
    offsets: bool = False
    time_span: tuple | None = None

    def __post_init__(self):
        self.columns = {k: np.asarray(v, dtype=float) for k, v in self.columns.items()}
        if self.lines is None:
            self.lines = np.arange(2, self.n + 2)  # header on line 1
        if self.groups is not None:
            self.groups = np.asarray(self.groups, dtype=int)
            self.group_names = tuple(self.group_names) or tuple(str(g) for g in range(int(self.groups.max()) + 1))

    def __getitem__(self, name: str) -> np.ndarray:
        return self.columns[name]

    def __contains__(self, name: str) -> bool:
        return name in self.columns

    @property
    def n(self) -> int:
        """Number of rows (samples)."""
        return len(next(iter(self.columns.values()))) if self.columns else 0

    @property
    def n_groups(self) -> int:
        """Number of groups (1 without a group column)."""
        return 1 if self.groups is None else len(np.unique(self.groups))

    @property
    def time(self) -> np.ndarray:
        """Time of every row: ``t_s`` (s), else the row index."""
        t = self.columns.get("t_s")
        return np.asarray(t, float) if t is not None else np.arange(self.n, dtype=float)

    @property
    def has_time(self) -> bool:
        """True if the data record the time of each row (a ``t_s`` column): without it the row index
        stands in for the time (the order of the rows, not their spacing)."""
        return "t_s" in self.columns

    @property
    def tau(self) -> np.ndarray:
        """Normalised time in [0, 1] (from ``t_s`` if present, else the row index), dimensionless: over
        each group, or over the whole data set when ``time_continuous`` (module docstring)."""
        t = self.time
        if self.groups is not None and not self.time_continuous and self.n_groups > 1:
            out = np.zeros(self.n)
            for g in np.unique(self.groups):
                rows = self.groups == g
                out[rows] = _normalised(t[rows], None)
            return out
        return _normalised(t, self.time_span)

    def group_rows(self) -> list:
        """``[(label, (n,) bool)]`` of the groups, in order of appearance ([] for one group)."""
        if self.groups is None or self.n_groups < 2:
            return []
        return [(self.group_names[g], self.groups == g) for g in dict.fromkeys(self.groups.tolist())]

    def group_subsets(self) -> list:
        """``[(rows, Measured)]`` of the groups (cached): what the model runs on, group by group."""
        key = ("group subsets",)
        if key not in self.cache:
            self.cache[key] = [(rows, self.subset(rows)) for _, rows in self.group_rows()]
        return self.cache[key]

    def subset(self, rows) -> Measured:
        """A copy restricted to ``rows`` (index array or mask), with an empty cache; its time stays
        normalised as in the whole data set when that time is continuous."""
        rows = np.asarray(rows)
        span = self.time_span
        if self.time_continuous and span is None and self.n:
            span = (float(self.time.min()), float(self.time.max()))
        return Measured(
            self.experiment,
            {k: v[rows] for k, v in self.columns.items()},
            self.path,
            self.lines[rows],
            groups=None if self.groups is None else self.groups[rows],
            group_names=self.group_names,
            time_continuous=self.time_continuous,
            offsets=self.offsets,
            time_span=span,
        )

    def __getstate__(self):  # the cache is rebuilt where it is needed (worker processes)
        d = dict(self.__dict__)
        d["cache"] = {}
        return d


def _normalised(t, span) -> np.ndarray:
    t0, t1 = (float(t.min()), float(t.max())) if span is None and t.size else (span or (0.0, 0.0))
    return (t - t0) / (t1 - t0) if t1 > t0 else np.zeros(t.size)
