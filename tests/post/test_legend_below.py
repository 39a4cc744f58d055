"""plotstyle.legend_below: a legend under the axes that never covers the x tick labels or the x
label, whatever the axes' height (a fixed fraction of the axes did, on short axes)."""

import pytest
from figure_geometry import figure_problems

from femast.post import plotstyle


@pytest.mark.parametrize("height_in", [2.0, 4.0, 9.0])
def test_legend_below_clears_the_x_label(height_in, tmp_path):
    plt = plotstyle.pyplot()
    fig, ax = plt.subplots(figsize=(6.0, height_in))
    ax.barh([0, 1, 2], [2.3, 2.1, 2.2], label="error")
    ax.axvline(2.0, ls="--", color="k", label="noise floor")
    ax.axvline(4.0, ls=":", color="k", label="at-noise threshold")
    ax.set_xlim(0, 5.4)
    ax.set_xlabel("RMS error after refit (um)")
    leg = plotstyle.legend_below(ax, ncol=2, fontsize=8)
    plotstyle.save(fig, tmp_path / "f.png")
    assert figure_problems(fig) == []
    renderer = fig.canvas.get_renderer()
    # under the label, not beside it: the legend's top is below the label's bottom
    assert leg.get_window_extent(renderer).y1 <= ax.xaxis.label.get_window_extent(renderer).y0
