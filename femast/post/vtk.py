"""VTK output of a results folder: one .vtu per frame (meshio) and a .pvd time series.

Points are the reference coordinates; point data ``U`` (m) lets ParaView's
"Warp By Vector" show the deformed shape, ``UR`` and ``URA`` are rotation vectors and
accumulated spins (rad), ``RF`` reactions.  Each element family is one block of line
cells; cell data carries the family's outputs (e.g. beam ``N``, ``T``, ``My``, ``Mz``
at end 1 and 2, truss ``N``), zero-filled on cells of other families.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

import meshio
import numpy as np

from ..elements.beam_corot import SECTION_FORCE_NAMES
from ..errors import FemastError
from .results import Results


def _cell_fields(frame, families, sizes):
    """Flatten element outputs into named scalar cell fields, one array per block."""
    fields = {}
    for b, fam in enumerate(families):
        for key, val in frame.items():
            prefix = f"el/{fam}/"
            if not key.startswith(prefix):
                continue
            name = key[len(prefix) :]
            val = np.asarray(val)
            if not np.issubdtype(val.dtype, np.number):
                continue
            if name == "section_forces":
                cols = {f"{c}{end + 1}": val[:, end, j] for end in range(2) for j, c in enumerate(SECTION_FORCE_NAMES)}
            elif val.ndim == 1:
                cols = {name: val}
            else:
                flat = val.reshape(val.shape[0], -1)
                cols = {f"{name}_{j}": flat[:, j] for j in range(flat.shape[1])}
            for cname, col in cols.items():
                fields.setdefault(cname, [np.zeros(n) for n in sizes])[b] = col.astype(float)
    return fields


def export_vtk(results, folder=None, every: int = 1) -> Path:
    """Write ``<folder>/frame_000001.vtu``... and ``<folder>/series.pvd`` from ``results``
    (a :class:`~femast.post.results.Results` or a results folder), every ``every``-th frame.
    ``folder`` defaults to ``<results folder>/vtk`` (where ``femast vtk RESULTS`` writes too).
    Point data: ``U`` (m), ``UR`` and ``URA`` (rad), ``RF`` (N, N m); cell data: each family's
    outputs (N, N m).  Returns the .pvd path."""
    if isinstance(every, bool) or not isinstance(every, (int, np.integer)) or every < 1:
        raise FemastError(f"every = {every!r}: give a whole number >= 1 (write every n-th frame)")
    res = results if isinstance(results, Results) else Results(results)
    folder = Path(folder) if folder is not None else res.folder / "vtk"
    if folder.exists() and not folder.is_dir():
        raise FemastError(f"VTK output folder '{folder}' is an existing file; give another folder")
    folder.mkdir(parents=True, exist_ok=True)
    label_to_row = {int(l): i for i, l in enumerate(res.node_labels)}
    cells, families = [], []
    for fam in res.families:
        conn = np.vectorize(label_to_row.get)(res.mesh[f"conn/{fam}"])
        if conn.shape[1] == 2:
            cells.append(("line", conn))
        else:  # multi-node elements (cables over pulleys): polyline drawn as consecutive segments
            cells.append(("line", np.column_stack([conn[:, :-1].ravel(), conn[:, 1:].ravel()])))
        families.append(fam)
    sizes = [c[1].shape[0] for c in cells]
    root = ET.Element("VTKFile", type="Collection", version="0.1")
    coll = ET.SubElement(root, "Collection")
    for i in range(0, len(res), every):
        fr = res.frame(i)
        fields = _cell_fields(fr, families, sizes)
        # multi-node families were split into segments: repeat their per-element values
        for b, fam in enumerate(families):
            n_el = res.mesh[f"conn/{fam}"].shape[0]
            if sizes[b] != n_el:
                for name in fields:
                    col = fields[name][b]
                    fields[name][b] = np.repeat(col, sizes[b] // n_el) if col.size == n_el else np.zeros(sizes[b])
        mesh = meshio.Mesh(
            res.X,
            cells,
            point_data={
                "U": fr["U"],
                "UR": fr["UR"],
                "URA": fr["URA"],
                "RF": fr["RF"][:, :3],
                "RM": fr["RF"][:, 3:],
                "node_label": res.node_labels.astype(float),
            },
            cell_data={**fields, "family": [np.full(n, b, dtype=float) for b, n in enumerate(sizes)]},
        )
        name = f"frame_{i:06d}.vtu"
        mesh.write(folder / name)
        ET.SubElement(coll, "DataSet", timestep=repr(float(fr["total_time"])), part="0", file=name)
    pvd = folder / "series.pvd"
    ET.ElementTree(root).write(pvd, xml_declaration=True)
    return pvd
