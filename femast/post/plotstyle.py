"""One plotting style for every femast figure: matplotlib settings, axis labels with
units, rounded numbers, titles that fit, and saving.

    from femast import plotstyle
    plt = plotstyle.pyplot()                       # Agg backend + the femast style
    ax.set_ylabel(plotstyle.column_label("dx_m", "mm"))   # 'dx (mm)', not 'dx_m (mm)'
    ax.legend(...); ax.set_title(plotstyle.fit_title(ax, long_title))
    plotstyle.save(fig, "out/figure.png")

Rules: every axis says its quantity and the unit shown (:func:`axis_label`); data columns are
shown by their quantity, never their raw CSV name (:func:`column_label`); numbers in legends and
titles are rounded to what they mean (:func:`num`); a title wider than its axes is wrapped
(:func:`fit_title`); shape views are orthographic with the undeformed shape labelled
(:mod:`femast.post.render`, and :func:`equal_axes` for matplotlib shape plots).
"""

from __future__ import annotations

import math
import re
import textwrap
from pathlib import Path

STYLE = {
    "figure.dpi": 100,
    "savefig.dpi": 110,
    "font.size": 10,
    "axes.titlesize": 10.5,
    "axes.labelsize": 10,
    "legend.fontsize": 8.5,
    "xtick.labelsize": 9,
    "ytick.labelsize": 9,
    "axes.grid": True,
    "grid.alpha": 0.3,
    "axes.spines.top": False,
    "axes.spines.right": False,
    "legend.framealpha": 0.85,
    "figure.titlesize": 11.5,
}

# readable display units: values in SI unit u are shown as factor * value in the label unit
_SCALES = {"m": (1e3, "mm"), "rad": (1e3, "mrad"), "mm": (1.0, "mm"), "N": (1.0, "N"), "N m": (1.0, "N m")}

# unit suffixes of data column names (docs/experiments.md): "dx_m" is dx in m
_SUFFIX_UNITS = {
    "m": "m",
    "mm": "mm",
    "um": "um",
    "N": "N",
    "Nm": "N m",
    "kN": "kN",
    "deg": "deg",
    "rad": "rad",
    "s": "s",
    "Pa": "Pa",
    "MPa": "MPa",
    "J": "J",
}


def use() -> None:
    """Apply the femast style to matplotlib (Agg backend: no display needed)."""
    import matplotlib

    matplotlib.use("Agg")
    matplotlib.rcParams.update(STYLE)


def pyplot():
    """``matplotlib.pyplot`` with the femast style applied."""
    use()
    import matplotlib.pyplot as plt

    return plt


# units for the magnitude shown: (largest |value| below which the unit is used, factor, label),
# smallest first; above the last bound the SI unit itself
_BY_MAGNITUDE = {
    "m": ((1e-6, 1e9, "nm"), (1e-3, 1e6, "um"), (1.0, 1e3, "mm")),
    "rad": ((1e-3, 180.0 * 3600.0 / math.pi, "arcsec"), (0.05, 1e3, "mrad"), (math.inf, 180.0 / math.pi, "deg")),
    "N": ((1.0, 1e3, "mN"), (1e4, 1.0, "N"), (math.inf, 1e-3, "kN")),
    "N m": ((1.0, 1e3, "N mm"), (1e4, 1.0, "N m"), (math.inf, 1e-3, "kN m")),
    "Pa": ((1e3, 1.0, "Pa"), (1e6, 1e-3, "kPa"), (1e9, 1e-6, "MPa"), (math.inf, 1e-9, "GPa")),
}


def display_scale(unit: str, values=None):
    """(factor, label) to show values of SI ``unit`` in a readable unit: with ``values`` (an array
    or a number), the unit that suits their size (a largest |value| of 7e-5 m shows as 70 um,
    3e-6 rad as 0.6 arcsec, 0.02 m as 20 mm); without, the default (m -> mm, rad -> mrad)."""
    if values is None or unit not in _BY_MAGNITUDE:
        return _SCALES.get(unit, (1.0, unit))
    import numpy as np

    v = np.abs(np.asarray(values, dtype=float))
    v = v[np.isfinite(v)]
    top = float(v.max()) if v.size else 0.0
    if top == 0.0:
        return _SCALES.get(unit, (1.0, unit))
    for bound, factor, label in _BY_MAGNITUDE[unit]:
        if top < bound:
            return factor, label
    return 1.0, unit


def split_column(name: str):
    """(quantity, unit) of a data column name with a unit suffix: 'dx_m' -> ('dx', 'm'),
    'Mz_Nm' -> ('Mz', 'N m'), 'theta_deg' -> ('theta', 'deg'); (name, '') without one."""
    base, _, suffix = name.rpartition("_")
    if base and suffix in _SUFFIX_UNITS:
        return base, _SUFFIX_UNITS[suffix]
    return name, ""


def column_label(name: str, unit: str | None = None) -> str:
    """Label of data column ``name`` shown in ``unit`` (default: its own unit): 'dx (mm)'."""
    q, u = split_column(name)
    q = {"theta": "twist", "dT": "dT"}.get(q, q)
    u = unit if unit is not None else u
    return f"{q} ({u})" if u else q


def axis_label(quantity: str, unit: str = "") -> str:
    """'quantity (unit)'; dimensionless quantities say so: 'ratio (-)'."""
    return f"{quantity} ({unit or '-'})"


def num(x: float, sig: int = 3) -> str:
    """``x`` rounded to ``sig`` significant digits for a legend or title ('1.36', '2.2e+05')."""
    if x is None or not math.isfinite(x):
        return str(x)
    if x == 0:
        return "0"
    mag = math.floor(math.log10(abs(x)))
    if -3 <= mag < 5:
        return f"{round(x, sig - 1 - mag):.{max(0, sig - 1 - mag)}f}"
    return f"{x:.{sig - 1}e}"


def fit_title(ax_or_fig, text: str, fontsize: float | None = None) -> str:
    """``text`` wrapped onto as many lines as it needs to fit the width of ``ax_or_fig``."""
    import matplotlib

    fig = getattr(ax_or_fig, "figure", None) or ax_or_fig
    width_in = fig.get_figwidth()
    if hasattr(ax_or_fig, "get_position") and ax_or_fig is not fig:
        width_in *= ax_or_fig.get_position().width
    size = fontsize or matplotlib.rcParams["axes.titlesize"]
    if isinstance(size, str):
        size = 11.0
    chars = max(20, int(width_in * 72 / (0.55 * float(size))))  # ~0.55 em per character
    return "\n".join(textwrap.wrap(" ".join(text.split()), chars))


def equal_axes(ax) -> None:
    """Equal scales on x and y (a shape drawn in a plane keeps its proportions)."""
    ax.set_aspect("equal", adjustable="datalim")


def legend_below(ax, pad_pt: float = 4.0, **kwargs):
    """A legend centred under ``ax``, below its x tick labels and x label, never over them: the drop
    is measured in points from the drawn axis (a later layout, which moves axes but keeps the
    labels' offsets in points, keeps it clear).  Call it once the axis limits and labels are set;
    ``kwargs`` go to ``ax.legend`` (``ncol``, ``fontsize``...)."""
    from matplotlib.transforms import offset_copy

    fig = ax.figure
    drop_pt = 40.0  # tick labels and one line of label at the style's sizes, if the axis cannot be measured
    if hasattr(fig.canvas, "get_renderer"):
        fig.canvas.draw()
        box = ax.xaxis.get_tightbbox(fig.canvas.get_renderer())
        if box is not None:
            drop_pt = max(0.0, ax.bbox.y0 - box.y0) * 72.0 / fig.dpi
    anchor = offset_copy(ax.transAxes, fig=fig, y=-(drop_pt + pad_pt), units="points")
    return ax.legend(loc="upper center", bbox_to_anchor=(0.5, 0.0), bbox_transform=anchor, **kwargs)


def save(fig, png, dpi=None) -> Path:
    """Lay out ``fig`` (titles and labels inside the canvas), write ``png`` (folders made) and close it."""
    import matplotlib.pyplot as plt

    png = Path(png)
    png.parent.mkdir(parents=True, exist_ok=True)
    import warnings

    with warnings.catch_warnings():  # axes tight_layout cannot handle (colour bars, insets) keep their place
        warnings.simplefilter("ignore", UserWarning)
        try:
            fig.tight_layout()
        except Exception:  # a layout that cannot be tightened is saved as it is
            pass
    try:
        fig.savefig(png, dpi=dpi or STYLE["savefig.dpi"], bbox_inches="tight")
    except ValueError:  # a name with "$" (a user's effect, file or column) read as broken math: shown as typed
        literal(fig)
        fig.savefig(png, dpi=dpi or STYLE["savefig.dpi"], bbox_inches="tight")
    finally:
        plt.close(fig)
    return png


def literal(fig) -> None:
    """Show every text of ``fig`` that holds a "$" as typed, not as mathtext (a user's name such as
    ``$\\undefinedcmd{$`` is not maths and would stop the figure)."""
    from matplotlib.text import Text

    for t in fig.findobj(Text):
        if "$" in t.get_text():
            t.set_parse_math(False)


_RAW = re.compile(r"\b[A-Za-z]+_(?:m|mm|N|Nm|deg|rad|s)\b")


def raw_column_names(text: str) -> list[str]:
    """Raw data column names (``dx_m``) appearing in a label (what :func:`column_label` removes)."""
    return _RAW.findall(text or "")
