"""Output of modal analyses: mode shapes as animated VTK series for ParaView, and the
modes of every saved increment of a static analysis.

``export_modes_vtk(modes, folder)`` writes, per mode, ``mode_NN/series.pvd`` with ``n_frames``
.vtu files over one period: points at the state's positions, point data ``U`` = scale x
sin(2 pi k / n_frames) x the mode's translations (m; ParaView: "Warp By Vector" on U, then play
the time series in a loop), ``mode_shape`` (the unscaled, mass-normalised translations) and
``mode_rotation``.  Cells: one block of lines per element family.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

import meshio
import numpy as np

from ..errors import StateError


def _cells(modes):
    cells = []
    for conn in modes.cells.values():
        conn = np.asarray(conn)
        if conn.shape[1] == 1:
            continue
        if conn.shape[1] == 2:
            cells.append(("line", conn))
        else:  # cables over pulleys: consecutive segments
            cells.append(("line", np.column_stack([conn[:, :-1].ravel(), conn[:, 1:].ravel()])))
    return cells


def export_modes_vtk(modes, folder, n_frames: int = 24, scale: float | None = None, which=None) -> list[Path]:
    """Write the animated series of ``modes`` (:class:`femast.modal.Modes`) under ``folder``;
    ``scale`` (m per unit of the mass-normalised shape; default: largest translation = 5 % of the
    model's size); ``which``: 0-based mode indices (default all).  Returns the .pvd paths."""
    folder = Path(folder)
    cells = _cells(modes)
    size = float(np.ptp(modes.x, axis=0).max()) or 1.0
    paths = []
    for k in range(len(modes)) if which is None else which:
        shape = modes.shapes[k]
        amp = float(np.abs(shape[:, :3]).max())
        s = scale if scale is not None else (0.05 * size / amp if amp > 0 else 1.0)
        sub = folder / f"mode_{k + 1:02d}"
        sub.mkdir(parents=True, exist_ok=True)
        root = ET.Element("VTKFile", type="Collection", version="0.1")
        coll = ET.SubElement(root, "Collection")
        f = float(modes.frequencies[k])
        period = 1.0 / abs(f) if f != 0 else 1.0
        for i in range(n_frames):
            phase = np.sin(2 * np.pi * i / n_frames)
            mesh = meshio.Mesh(
                modes.x,
                cells,
                point_data={
                    "U": s * phase * shape[:, :3],
                    "mode_shape": shape[:, :3],
                    "mode_rotation": shape[:, 3:],
                    "node_label": modes.node_labels.astype(float),
                },
            )
            name = f"frame_{i:03d}.vtu"
            mesh.write(sub / name)
            ET.SubElement(coll, "DataSet", timestep=repr(period * i / n_frames), part="0", file=name)
        pvd = sub / "series.pvd"
        ET.ElementTree(root).write(pvd, xml_declaration=True)
        paths.append(pvd)
    return paths


class ModesRecorder:
    """``on_frame`` recorder computing the modes at every saved increment of a static analysis.

    Usage::

        an = fm.Analysis(model, "results/run")
        rec = ModesRecorder(an, n_modes=6)          # chains any on_frame already set
        an.run()
        rec.frequencies                              # (n_frames, n_modes) Hz

    Each frame's modes are written to ``<results>/modes/frame_NNNNNN.npz/.csv`` (if the analysis
    writes a folder) and kept in ``rec.modes``; the initial frame of a model whose pretension is
    out of balance has no modes (None; its frequencies NaN)."""

    def __init__(self, analysis, n_modes: int = 10, **options):
        from .modes import modal_analysis

        self._modal = modal_analysis
        self.analysis = analysis
        self.n_modes = n_modes
        self.options = options
        self.modes = []
        self.frames = []
        out = getattr(analysis, "output", None)
        if out is not None and hasattr(out, "recorders"):  # the analysis package: an observer's list
            self._chain = None
            out.recorders.append(self)
        else:
            self._chain = analysis.on_frame
            analysis.on_frame = self

    def __call__(self, data):
        if self._chain is not None:
            self._chain(data)
        i = len(self.frames)
        label = f"step '{data['step']}' increment {data['increment']}"
        try:
            m = self._modal(self.analysis, self.n_modes, label=label, **self.options)
        except StateError:
            if i > 0:  # a converged increment must be in equilibrium: a real failure
                raise
            m = None  # the initial state of a model whose pretension is out of balance
        self.modes.append(m)
        self.frames.append((str(data["step"]), int(data["increment"]), float(data["total_time"])))
        if self.analysis.out is not None and m is not None:
            m.write(Path(self.analysis.out) / "modes", f"frame_{i:06d}")

    @property
    def frequencies(self) -> np.ndarray:
        """(n_frames, n_modes) frequencies, Hz."""
        return np.array([m.frequencies if m is not None else np.full(self.n_modes, np.nan) for m in self.modes])
