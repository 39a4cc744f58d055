"""The results of a study on disk: Parquet chunks written as samples finish.

A study folder holds ``study.json`` (the study's description, the number of base samples, the
shapes of the outputs) and ``chunks/*.parquet``, one file per finished chunk of runs, each
written to a temporary name and renamed (a killed study leaves no half file).  One row per run:

    run, base, block ('A', 'B', 'AB:<input>'), status ('ok' / 'failed'), error (the reason of a
    failure), seconds (wall time of the run), worker, then one column per input and per output
    (a float, or a list of floats for a per-member input or an array output, flattened in C
    order; the shape is in study.json).

A failed run keeps its inputs and its reason; its outputs are null.  Reading takes the columns
it needs from every chunk (pyarrow.dataset), so statistics of one output of 100 000 samples never
load the others.
"""

from __future__ import annotations

import json
import os
from pathlib import Path

import numpy as np

from ..errors import StudyError

RESERVED = ("run", "base", "block", "status", "error", "seconds", "worker")
MANIFEST = "study.json"


def _pa():
    try:
        import pyarrow as pa
        import pyarrow.parquet as pq
    except ImportError:  # pragma: no cover - pyarrow is in the test extra
        raise StudyError(
            "femast studies store their results with pyarrow, which is not installed; "
            "pip install pyarrow (or femast[study])"
        ) from None
    return pa, pq


class Store:
    """A study folder (created if missing).  ``spec`` is the study's description: a folder that
    already holds a different study is refused (resume only the same study)."""

    def __init__(self, folder, spec: dict | None = None, samples: int | None = None):
        self.folder = Path(folder)
        self.chunks = self.folder / "chunks"
        path = self.folder / MANIFEST
        if path.exists():
            self.manifest = json.loads(path.read_text())
            if spec is not None and self.manifest["spec"] != json.loads(json.dumps(spec)):
                raise StudyError(
                    f"{self.folder} holds another study (different inputs, outputs or design); give "
                    "a new folder, or delete it to start afresh"
                )
            if samples is not None and samples != self.manifest["samples"]:
                old = self.manifest["samples"]
                if spec is not None and spec["design"]["sampler"] == "lhs":
                    raise StudyError(
                        f"{self.folder}: a Latin hypercube of {old} samples cannot be resumed with "
                        f"{samples}; its points depend on N (use --samples {old}, or a new folder)"
                    )
                if samples < old:
                    raise StudyError(f"{self.folder} already has a study of {old} samples; give --samples >= {old}")
                self.manifest["samples"] = samples
                self._write_manifest()
        else:
            if spec is None:
                raise StudyError(f"{self.folder}: no study there ({MANIFEST} missing)")
            names = [x["name"] for x in spec["design"]["inputs"]] + list(spec["outputs"])
            bad = [n for n in names if n in RESERVED]
            if bad:
                raise StudyError(
                    f"{', '.join(bad)}: reserved column name(s) of the results; rename (reserved: "
                    f"{', '.join(RESERVED)})"
                )
            self.folder.mkdir(parents=True, exist_ok=True)
            self.manifest = {"spec": json.loads(json.dumps(spec)), "samples": samples, "shapes": {}}
            self._write_manifest()
        self.chunks.mkdir(exist_ok=True)

    def _write_manifest(self):
        tmp = self.folder / (MANIFEST + ".tmp")
        tmp.write_text(json.dumps(self.manifest, indent=1))
        os.replace(tmp, self.folder / MANIFEST)

    @property
    def samples(self) -> int:
        return self.manifest["samples"]

    @property
    def shapes(self) -> dict:
        return {k: tuple(v) for k, v in self.manifest["shapes"].items()}

    # ------------------------------------------------------------ writing
    def write(self, rows: list, input_names, input_sizes: dict) -> tuple:
        """Append the runs ``rows`` (dicts: run, base, block, status, error, seconds, worker, inputs,
        outputs) as one chunk.  An output whose shape differs from the first recorded one makes its
        run failed (with the reason).  Returns (ok, failed) counts."""
        pa, pq = _pa()
        shapes = self.manifest["shapes"]
        new_shape = False
        for r in rows:
            if r["status"] != "ok":
                continue
            for k, v in r["outputs"].items():
                shp = list(np.shape(v))
                if k not in shapes:
                    shapes[k], new_shape = shp, True
                elif shapes[k] != shp:
                    r["status"] = "failed"
                    r["error"] = (
                        f"StudyError: output '{k}' has shape {tuple(shp)}, earlier samples "
                        f"{tuple(shapes[k])}; an output must have the same shape in every sample"
                    )
        if new_shape:
            self._write_manifest()
        outs = list(self.manifest["spec"]["outputs"])
        cols = {c: [r[c] for r in rows] for c in RESERVED}
        for n in input_names:
            vals = [r["inputs"][n] for r in rows]
            cols[n] = vals if input_sizes[n] is None else [np.asarray(v, float).ravel().tolist() for v in vals]
        for k in outs:
            shp = shapes.get(k)
            vals = []
            for r in rows:
                v = r["outputs"].get(k) if r["status"] == "ok" else None
                if v is None:
                    vals.append(None)
                elif shp is not None and len(shp) == 0:
                    vals.append(float(v))
                else:
                    vals.append(np.asarray(v, float).ravel().tolist())
            cols[k] = vals
        fields = [
            pa.field("run", pa.int64()),
            pa.field("base", pa.int64()),
            pa.field("block", pa.string()),
            pa.field("status", pa.string()),
            pa.field("error", pa.string()),
            pa.field("seconds", pa.float64()),
            pa.field("worker", pa.string()),
        ]
        for n in input_names:
            fields.append(pa.field(n, pa.float64() if input_sizes[n] is None else pa.list_(pa.float64())))
        for k in outs:
            shp = shapes.get(k)
            if shp is None:  # no sample has given it yet (a chunk of failed runs): nulls, typed by later chunks
                fields.append(pa.field(k, pa.null()))
            else:
                fields.append(pa.field(k, pa.float64() if len(shp) == 0 else pa.list_(pa.float64())))
        table = pa.table({f.name: pa.array(cols[f.name], type=f.type) for f in fields})
        first = min(r["run"] for r in rows)
        name = f"chunk-{first:010d}-{len(rows)}.parquet"
        tmp = self.chunks / (name + ".tmp")
        pq.write_table(table, tmp)
        os.replace(tmp, self.chunks / name)
        ok = sum(r["status"] == "ok" for r in rows)
        return ok, len(rows) - ok

    # ------------------------------------------------------------ reading
    def files(self) -> list:
        return sorted(self.chunks.glob("chunk-*.parquet"))

    def read(self, columns) -> dict:
        """{column: numpy array} over every chunk, rows sorted by run.  List columns (per-member
        inputs, array outputs) come back as (n, ...) arrays in their recorded shape (NaN where null)."""
        pa, pq = _pa()
        files = self.files()
        columns = list(dict.fromkeys(["run"] + list(columns)))
        if not files:
            return {c: np.zeros(0) for c in columns}
        tables = [pq.read_table(f, columns=columns) for f in files]
        table = pa.concat_tables(tables, promote_options="permissive")
        order = np.argsort(table.column("run").to_numpy())
        out = {}
        shapes = self.shapes
        sizes = {x["name"]: x["size"] for x in self.manifest["spec"]["design"]["inputs"]}
        for c in columns:
            col = table.column(c)
            if pa.types.is_null(col.type):  # an output no sample has given (all failed)
                out[c] = np.full(len(col), np.nan)[order]
            elif pa.types.is_list(col.type):
                shp = shapes.get(c) or ((sizes[c],) if sizes.get(c) else None)
                width = int(np.prod(shp)) if shp else 0
                col = col.combine_chunks()
                valid = ~np.asarray(col.is_null().to_numpy(zero_copy_only=False), dtype=bool)
                flat = np.asarray(col.flatten().to_numpy(zero_copy_only=False), dtype=float)  # non-null rows
                arr = np.full((len(col), width), np.nan)
                arr[valid] = flat.reshape(int(valid.sum()), width)
                out[c] = arr.reshape((len(col),) + tuple(shp or (0,)))[order]
            elif pa.types.is_floating(col.type):
                out[c] = np.asarray(col.to_numpy(zero_copy_only=False), dtype=float)[order]
            else:
                out[c] = np.asarray(col.to_pylist(), dtype=object if not pa.types.is_integer(col.type) else np.int64)[
                    order
                ]
        return out

    def done_runs(self) -> np.ndarray:
        """Run indices already on disk (ok or failed)."""
        return np.sort(self.read(["run"])["run"]).astype(np.int64)
