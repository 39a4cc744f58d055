"""Checks of a drawn matplotlib figure that a reader would make by eye: no legend over an axis label,
tick labels or another legend, and every line listed in a legend at least partly inside its axes.

The checks read the geometry matplotlib itself computes when it draws (window extents in display
pixels, the lines' data through their own transforms), so they hold for any backend and any DPI.
"""

from __future__ import annotations

import numpy as np

TOLERANCE_PX = 1.0  # boxes touching within a pixel do not overlap


def _draw(fig):
    if not hasattr(fig.canvas, "get_renderer"):  # a figure closed by pyplot: draw it with Agg as saved
        from matplotlib.backends.backend_agg import FigureCanvasAgg

        FigureCanvasAgg(fig)
    fig.canvas.draw()
    return fig.canvas.get_renderer()


def _overlap(a, b) -> bool:
    """True if two display boxes overlap by more than ``TOLERANCE_PX`` in both directions."""
    dx = min(a.x1, b.x1) - max(a.x0, b.x0)
    dy = min(a.y1, b.y1) - max(a.y0, b.y0)
    return dx > TOLERANCE_PX and dy > TOLERANCE_PX


def _texts(fig, renderer):
    """(description, box) of every visible, non-empty axis label, tick label and title."""
    out = []
    for i, ax in enumerate(fig.axes):
        if not ax.get_visible():
            continue
        for name, t in (("x label", ax.xaxis.label), ("y label", ax.yaxis.label), ("title", ax.title)):
            if t.get_visible() and t.get_text():
                out.append((f"axes {i} {name} {t.get_text()!r}", t.get_window_extent(renderer)))
        for axis, name in ((ax.xaxis, "x tick labels"), (ax.yaxis, "y tick labels")):
            boxes = [t.get_window_extent(renderer) for t in axis.get_ticklabels() if t.get_visible() and t.get_text()]
            out += [(f"axes {i} {name}", b) for b in boxes]
    return out


def _legends(fig):
    legs = [leg for ax in fig.axes for leg in ([ax.get_legend()] if ax.get_legend() else [])]
    return legs + list(fig.legends)


def legend_overlaps(fig) -> list[str]:
    """Descriptions of every legend that covers an axis label, a tick label, a title or another legend
    (empty when the figure is clean)."""
    renderer = _draw(fig)
    texts = _texts(fig, renderer)
    legs = [(leg, leg.get_window_extent(renderer)) for leg in _legends(fig) if leg.get_visible()]
    bad = []
    for k, (leg, box) in enumerate(legs):
        names = ", ".join(t.get_text() for t in leg.get_texts())[:60]
        for what, tb in texts:
            if _overlap(box, tb):
                bad.append(f"legend [{names}] covers {what}")
        for _, box2 in legs[k + 1 :]:
            if _overlap(box, box2):
                bad.append(f"legend [{names}] covers another legend")
    return bad


def _line_points_px(line) -> np.ndarray:
    xy = np.asarray(line.get_xydata(), dtype=float).reshape(-1, 2)
    xy = xy[np.isfinite(xy).all(axis=1)]
    return line.get_transform().transform(xy) if len(xy) else xy


def legend_lines_outside(fig) -> list[str]:
    """Labels of the lines a legend lists that show no point inside their axes (a noise-floor line
    named in the legend but drawn beyond the axis limits, say)."""
    _draw(fig)
    bad = []
    for ax in fig.axes:
        leg = ax.get_legend()
        if leg is None:
            continue
        listed = {t.get_text() for t in leg.get_texts()}
        box = ax.bbox
        for line in ax.get_lines():
            if line.get_label() not in listed or not line.get_visible():
                continue
            px = _line_points_px(line)
            inside = (
                (px[:, 0] >= box.x0 - TOLERANCE_PX)
                & (px[:, 0] <= box.x1 + TOLERANCE_PX)
                & (px[:, 1] >= box.y0 - TOLERANCE_PX)
                & (px[:, 1] <= box.y1 + TOLERANCE_PX)
            )
            if not inside.any():
                bad.append(f"line {line.get_label()!r} is listed in the legend but lies outside its axes")
    return bad


def lines_clipped(fig, share: float = 0.0) -> list[str]:
    """Labels of the data lines of which more than ``share`` of the points fall outside their axes
    (reference lines drawn across the axes, such as ``axhline``, are judged by the same rule)."""
    _draw(fig)
    bad = []
    for i, ax in enumerate(fig.axes):
        box = ax.bbox
        for line in ax.get_lines():
            if not line.get_visible():
                continue
            px = _line_points_px(line)
            if not len(px):
                continue
            outside = (
                (px[:, 0] < box.x0 - TOLERANCE_PX)
                | (px[:, 0] > box.x1 + TOLERANCE_PX)
                | (px[:, 1] < box.y0 - TOLERANCE_PX)
                | (px[:, 1] > box.y1 + TOLERANCE_PX)
            )
            if outside.mean() > share:
                bad.append(f"axes {i}: {outside.mean():.0%} of line {line.get_label()!r} lies outside the axes")
    return bad


def figure_problems(fig) -> list[str]:
    """Everything the three checks find."""
    return legend_overlaps(fig) + legend_lines_outside(fig) + lines_clipped(fig)
