"""Reading a study's results back: ``femast.studies.load(folder)``.

res = load("studies/tip")
x = res.output("tip_u")            # (n_ok, ...) values of the successful base samples (block A)
res.inputs("mu")                   # the matching input values
res.failures()                     # [(run, reason), ...] every failed run
"""

from __future__ import annotations

import numpy as np

from ..errors import StudyError
from .store import Store


class StudyResults:
    """The results of the study in ``folder`` (reads the columns it is asked for)."""

    def __init__(self, folder):
        self.store = Store(folder)
        self.folder = self.store.folder
        m = self.store.manifest
        self.spec = m["spec"]
        self.samples = m["samples"]
        self.input_names = [x["name"] for x in self.spec["design"]["inputs"]]
        self.output_names = list(self.spec["outputs"])
        self.units = dict(self.spec.get("units", {}))
        self.labels = dict(self.spec.get("labels", {}))
        self.sensitivity = bool(self.spec["design"]["sensitivity"])

    def component_label(self, name: str, idx: tuple) -> str:
        """'tip_u[M+F#1, ux]' for component ``idx`` of output ``name`` (indices where an axis has
        no names)."""
        if not idx:
            return name
        axes = self.labels.get(name, [])
        parts = []
        for k, i in enumerate(idx):
            names = axes[k] if k < len(axes) else None
            parts.append(str(names[i]) if names is not None and i < len(names) else str(i))
        return f"{name}[{', '.join(parts)}]"

    @property
    def runs_per_sample(self) -> int:
        return len(self.input_names) + 2 if self.sensitivity else 1

    def _check(self, name, kind):
        names = self.output_names if kind == "output" else self.input_names
        if name not in names:
            raise StudyError(f"{self.folder}: no {kind} {name!r}; its {kind}s are {', '.join(names)}")

    def table(self, columns) -> dict:
        """{column: array} of every run on disk (sorted by run), for the given columns."""
        return self.store.read(columns)

    def output(self, name: str, blocks=("A",), ok_only: bool = True) -> np.ndarray:
        """Values of output ``name`` of the runs of ``blocks`` ('A': the plain samples; with
        sensitivity 'B' are independent samples too); (n, *shape), failed runs left out (or NaN
        with ok_only=False)."""
        self._check(name, "output")
        t = self.store.read([name, "block", "status"])
        sel = np.isin(t["block"].astype(str), list(blocks))
        if ok_only:
            sel &= t["status"] == "ok"
        return t[name][sel]

    def inputs(self, name: str, blocks=("A",), ok_only: bool = True) -> np.ndarray:
        """Values of input ``name`` for the same runs as :meth:`output`."""
        self._check(name, "input")
        t = self.store.read([name, "block", "status"])
        sel = np.isin(t["block"].astype(str), list(blocks))
        if ok_only:
            sel &= t["status"] == "ok"
        return t[name][sel]

    def failures(self) -> list:
        """[(run, reason)] of every failed run."""
        t = self.store.read(["status", "error"])
        bad = t["status"] != "ok"
        return list(zip(t["run"][bad].tolist(), t["error"][bad].tolist()))

    def counts(self) -> dict:
        """{'runs': on disk, 'ok': ..., 'failed': ..., 'expected': samples x runs per sample}."""
        t = self.store.read(["status"])
        ok = int(np.sum(t["status"] == "ok"))
        return {
            "runs": len(t["run"]),
            "ok": ok,
            "failed": len(t["run"]) - ok,
            "expected": self.samples * self.runs_per_sample,
        }

    def saltelli(self, name: str) -> tuple:
        """The sensitivity layout of output ``name``: (fA, fB, fAB, dropped) with fA, fB (n, ...)
        and fAB (k, n, ...) over the base samples whose k + 2 runs all succeeded; ``dropped`` is the
        number of base samples left out because one of their runs failed."""
        if not self.sensitivity:
            raise StudyError(
                f"{self.folder}: the study was run without sensitivity=True; run it with "
                "sensitivity=True to get Sobol' indices"
            )
        self._check(name, "output")
        t = self.store.read([name, "base", "status"])
        m = self.runs_per_sample
        n = self.samples
        full = np.zeros(n * m, dtype=bool)
        ok = np.zeros(n * m, dtype=bool)
        full[t["run"]] = True
        ok[t["run"]] = t["status"] == "ok"
        good = ok.reshape(n, m).all(axis=1)
        present = full.reshape(n, m).all(axis=1)
        vals = np.full((n * m,) + t[name].shape[1:], np.nan)
        vals[t["run"]] = t[name]
        vals = vals.reshape((n, m) + t[name].shape[1:])[good]
        return vals[:, 0], vals[:, 1], np.moveaxis(vals[:, 2:], 1, 0), int(np.sum(present & ~good))


def load(folder) -> StudyResults:
    """The results of the study in ``folder``."""
    return StudyResults(folder)
