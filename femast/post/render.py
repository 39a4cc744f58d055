"""Off-screen PNG of the deformed shape with pyvista (no display needed)."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from .plotstyle import display_scale
from .results import Results


def render_png(
    results,
    png,
    frame: int = -1,
    scale: float = 1.0,
    show_undeformed: bool = True,
    color_by: str | None = "|U|",
    window_size=(1200, 900),
    title: str | None = None,
) -> Path:
    """Render frame ``frame`` of ``results`` to ``png``; displacements magnified by ``scale``.
    ``color_by``: '|U|' (displacement magnitude) or None.  Orthographic isometric view, the
    undeformed shape in grey and labelled, a vertical colour bar in the unit that suits the
    displacements (um, mm or m).  ``show_undeformed``: draw the initial shape in grey;
    ``window_size``: (width, height) of the image in pixels; ``title``: the caption (default: the
    folder, the frame and its step).  Returns the PNG's path."""
    if not os.environ.get("DISPLAY"):
        # headless: render through EGL, which VTK's wheels ship (no X server, no OSMesa needed)
        os.environ.setdefault("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow")
    import pyvista as pv

    pv.OFF_SCREEN = True
    res = results if isinstance(results, Results) else Results(results)
    fr = res.frame(frame)  # a FemastError naming the frame if it does not exist
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
    legend = []
    if show_undeformed:
        plotter.add_mesh(pv.PolyData(res.X, lines=lines), color="darkgray", line_width=2)
        legend.append(["undeformed shape", "darkgray"])
    deformed = pv.PolyData(pts, lines=lines)
    umag = np.linalg.norm(fr["U"], axis=1)
    factor, unit = display_scale("m", umag)  # um for um-scale motion, mm for mm-scale...
    bar = dict(
        title=f"displacement ({unit})",
        vertical=True,
        position_x=0.84,
        position_y=0.15,
        width=0.06,
        height=0.6,
        n_labels=5,
        fmt="%.3g",
        title_font_size=16,
        label_font_size=14,
        color="black",
    )
    if color_by == "|U|":
        deformed[bar["title"]] = factor * umag
        plotter.add_mesh(deformed, scalars=bar["title"], line_width=4, cmap="viridis", scalar_bar_args=bar)
        legend.append([f"deformed shape, displacements x {scale:g}", "coloured"])
    else:
        plotter.add_mesh(deformed, color="green", line_width=4)
        legend.append([f"deformed shape, displacements x {scale:g}", "green"])
    plotter.add_text(
        title or f"{res.folder.name}: frame {frame} of {len(res)} ({fr['step']})",
        font_size=9,
        color="black",
        position="upper_left",
    )
    plotter.add_text(
        ";   ".join(f"{c.replace('dark', '')}: {t}" for t, c in legend),
        font_size=9,
        color="black",
        position="lower_edge",
    )
    plotter.show_axes()
    plotter.camera_position = "iso"
    plotter.enable_parallel_projection()  # orthographic: a circle stays a circle, lengths compare
    plotter.reset_camera()
    plotter.camera.zoom(0.85)  # room for the title, the legend and the colour bar
    png = Path(png)
    png.parent.mkdir(parents=True, exist_ok=True)
    plotter.screenshot(str(png))
    plotter.close()
    return png


def largest_displacement_frame(results) -> tuple[int, float]:
    """(frame index, largest nodal |U| in m) of the frame of ``results`` (a Results or a results
    folder) whose largest nodal displacement magnitude is the largest of the run (the first such
    frame on ties)."""
    res = results if isinstance(results, Results) else Results(results)
    best, umax = 0, -1.0
    for i in range(len(res)):
        u = float(np.max(np.linalg.norm(res.frame(i)["U"], axis=1))) if len(res.X) else 0.0
        if u > umax:
            best, umax = i, u
    return best, umax
