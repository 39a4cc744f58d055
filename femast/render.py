"""Off-screen PNG of the deformed shape with pyvista (no display needed)."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from .results import Results


def render_png(results, png, frame: int = -1, scale: float = 1.0, show_undeformed: bool = True,
               color_by: str | None = "|U|", window_size=(1200, 900), title: str | None = None) -> Path:
    """Render frame ``frame`` of ``results`` to ``png``; displacements magnified by ``scale``.
    ``color_by``: '|U|' (displacement magnitude, m) or None."""
    if not os.environ.get("DISPLAY"):
        # headless: render through EGL, which VTK's wheels ship (no X server, no OSMesa needed)
        os.environ.setdefault("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow")
    import pyvista as pv

    pv.OFF_SCREEN = True
    res = results if isinstance(results, Results) else Results(results)
    fr = res.frame(frame)   # a FemastError naming the frame if it does not exist
    frame = range(len(res))[int(frame)]
    label_to_row = {int(l): i for i, l in enumerate(res.node_labels)}
    segs = []
    for fam in res.families:
        conn = np.vectorize(label_to_row.get)(res.mesh[f"conn/{fam}"])
        segs.append(np.column_stack([conn[:, :-1].ravel(), conn[:, 1:].ravel()]))
    segs = np.concatenate(segs)
    lines = np.column_stack([np.full(len(segs), 2), segs]).ravel()
    pts = res.X + scale * fr["U"]
    plotter = pv.Plotter(off_screen=True, window_size=window_size)
    plotter.set_background("white")
    if show_undeformed:
        plotter.add_mesh(pv.PolyData(res.X, lines=lines), color="lightgray", line_width=2)
    deformed = pv.PolyData(pts, lines=lines)
    if color_by == "|U|":
        deformed["|U| (m)"] = np.linalg.norm(fr["U"], axis=1)
        plotter.add_mesh(deformed, scalars="|U| (m)", line_width=4, cmap="viridis")
    else:
        plotter.add_mesh(deformed, color="green", line_width=4)
    plotter.add_text(title or f"{res.folder.name}: frame {frame}, {fr['step']}, scale {scale:g}", font_size=10,
                     color="black")
    plotter.show_axes()
    plotter.camera_position = "iso"
    png = Path(png)
    png.parent.mkdir(parents=True, exist_ok=True)
    plotter.screenshot(str(png))
    plotter.close()
    return png
