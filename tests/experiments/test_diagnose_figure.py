"""diagnose.png and the diagnose text say what the verdict says, whatever the channels' units.

The tip-cycle experiment compares displacements (m) and rotations (rad).  Its verdict's ratio is
the RMS of each channel's error over that channel's own noise; an RMS of all channels in metres
against a noise floor in metres is another number (the rotations' noise, times the mast length,
dominated it: a baseline at 3.86x the noise was drawn as a 13 mm bar under a 25 mm noise floor).
The figure draws the ratios, the text gives each channel its own unit.
"""

import re
from types import SimpleNamespace

import numpy as np
import pytest

from femast.experiments import get_experiment
from femast.experiments.diagnose_report import format_diagnose
from femast.experiments.figures import diagnose_figure
from femast.post import plotstyle

N = 13


def _entry(effect, ratio, dbic, significant, heldout=None):
    return {
        "effect": effect,
        "form": None,
        "ratio": ratio,
        "rms": 0.0,
        "delta_bic": dbic,
        "significant": significant,
        "heldout_ratio": heldout,
        "explained_fraction": 0.5,
        "params": {},
        "reading": "",
    }


def _pair(effects, ratio, dbic, gain_over_best, share_over_best):
    return {
        "effects": list(effects),
        "ratio": ratio,
        "rms": 0.0,
        "delta_bic": dbic,
        "significant": True,
        "heldout_ok": True,
        "heldout_ratio": None,
        "explained_fraction": 0.9,
        "gain_over_best_single": gain_over_best,
        "share_over_best_single": share_over_best,
    }


def _tip_cycle_result():
    exp = get_experiment("tip-cycle")
    # one channel far off its noise (ux: 12 mm against 0.9 mm), one with a large noise (rz)
    residuals = {c: np.full(N, 1e-9) for c in exp.channels}
    noise = {c: np.full(N, 1e-9) for c in exp.channels}
    residuals["ux_m"], noise["ux_m"] = np.full(N, 12e-3), np.full(N, 0.9e-3)
    residuals["rz_rad"], noise["rz_rad"] = np.full(N, 4e-3), np.full(N, 8.8e-3)
    ranking = [
        _entry("joint_clearance", 1.1, -700.0, True, heldout=1.2),
        _entry("pretension_loss", 3.79, -1.3, False),
        _entry("latch_hysteresis", 3.6, -40.0, True),
    ]
    pairs = [
        _pair(("joint_clearance", "latch_hysteresis"), 1.05, -705.0, -5.0, 0.02),  # no better than its best member
        _pair(("joint_clearance", "pretension_loss"), 0.98, -760.0, -60.0, 0.15),  # significantly better
    ]
    conclusion = (
        "missing effect: joint_clearance (a gap); with it the error falls from 3.86x to 1.10x the noise; "
        "also consistent with the data: latch_hysteresis"
    )
    result = SimpleNamespace(
        experiment=exp.name,
        n_samples=N,
        executor="this process",
        report={"data": "tip.csv"},
        baseline={"rms": 13e-3, "ratio": 3.86, "effects": [], "heldout_ratio": 3.97, "bic": 0.0, "params": {}},
        baseline_fit=SimpleNamespace(residuals=residuals, fun=np.ones(len(exp.channels) * N)),
        baseline_z=np.ones(len(exp.channels) * N),
        noise=noise,
        noise_rms=24.8e-3,
        noise_model={},
        at_noise=1.7,
        ranking=ranking,
        pairs=pairs,
        form_check=[],
        by_kind=[],
        best_fit=None,
        verdict={"kind": "missing_effect", "missing_effects": ["joint_clearance"], "conclusion": conclusion},
        files={},
    )
    return exp, result


@pytest.fixture
def figure(monkeypatch, tmp_path):
    """The diagnose figure of the tip-cycle result, as drawn: (figure, bar axes, result)."""
    seen = []
    save = plotstyle.save

    def keep(fig, png, dpi=None):
        seen.append(fig)
        return save(fig, png, dpi)

    monkeypatch.setattr(plotstyle, "save", keep)
    exp, result = _tip_cycle_result()
    diagnose_figure(exp, SimpleNamespace(n=N), result, tmp_path / "diagnose.png")
    (fig,) = seen
    return fig, fig.axes[0], result


def _bars(ax):
    """{y label: (width, colour)} of the horizontal bars."""
    labels = {round(t.get_position()[1]): t.get_text() for t in ax.get_yticklabels()}
    return {labels[round(p.get_y() + p.get_height() / 2)]: (p.get_width(), p.get_facecolor()) for p in ax.patches}


def test_bars_are_the_verdicts_ratios_against_a_noise_floor_at_one(figure):
    fig, ax, result = figure
    bars = _bars(ax)
    assert bars["baseline"][0] == pytest.approx(3.86)  # the verdict's 3.86x, not 13 mm against 25 mm
    assert bars["joint_clearance"][0] == pytest.approx(1.1)
    vlines = sorted(line.get_xdata()[0] for line in ax.get_lines() if line.get_linestyle() in ("--", ":"))
    assert vlines == pytest.approx([1.0, 1.7])  # the noise floor and the at-noise threshold
    (held_out,) = [line for line in ax.get_lines() if line.get_marker() == "x"]
    assert sorted(held_out.get_xdata()) == pytest.approx([1.2, 3.97])
    assert "noise" in ax.get_xlabel() and "mm" not in ax.get_xlabel()


def test_a_pair_is_green_only_if_it_beats_its_best_member(figure):
    fig, ax, _ = figure
    bars = _bars(ax)
    green, grey = np.array([0.17254902, 0.62745098, 0.17254902, 1.0]), np.array([0.65, 0.65, 0.65, 1.0])
    assert np.allclose(bars["joint_clearance + pretension_loss"][1], green, atol=0.01)
    assert np.allclose(bars["joint_clearance + latch_hysteresis"][1], grey, atol=0.01)
    assert np.allclose(bars["joint_clearance"][1], green, atol=0.01)


def test_labels_stand_clear_of_bars_and_noise_lines_and_the_title_says_the_verdict(figure):
    fig, ax, _ = figure
    labels = [t for t in ax.texts if "dBIC" in t.get_text()]
    assert len(labels) == 5  # three candidates, two pairs
    right = max([p.get_width() for p in ax.patches] + [3.97, 1.7])
    assert all(t.get_position()[0] >= right for t in labels)
    assert ax.get_xlim()[1] > right
    title = " ".join(ax.get_title().split())  # wrapped to the axes
    assert "missing effect: joint_clearance" in title and "missing:" not in title.replace("missing effect", "")


def test_text_gives_each_channel_in_its_own_unit():
    exp, result = _tip_cycle_result()
    text = format_diagnose(exp, result)
    baseline = re.search(
        r"baseline: ([\d.]+)x the noise \(each channel's error over its own noise; held out ([\d.]+)x\)", text
    )
    assert baseline and [float(v) for v in baseline.groups()] == pytest.approx([3.86, 3.97], rel=1e-3)
    assert "noise floor" not in text  # no RMS of metres and radians together
    # each channel in its own unit: 12 mm against 0.9 mm (12 / 0.9 = 13.33x), 4 mrad against 8.8 mrad
    for channel, unit, rms, noise in (("ux_m", "mm", 12.0, 0.9), ("rz_rad", "mrad", 4.0, 8.8)):
        line = re.search(rf"{channel}: RMS error ([\d.]+) {unit}, noise ([\d.]+) {unit} \(([\d.]+)x\)", text)
        assert line, channel
        got_rms, got_noise, got_ratio = (float(v) for v in line.groups())
        assert [got_rms, got_noise] == pytest.approx([rms, noise], rel=2e-3), channel
        assert got_ratio == pytest.approx(rms / noise, abs=0.005), channel  # printed to two decimals


def test_ranking_has_no_rms_of_metres_and_radians_together():
    exp, result = _tip_cycle_result()
    for e in result.ranking:  # an RMS a pooled table would print as a length
        e["rms"] = 0.0123
    text = format_diagnose(exp, result)
    rows = [line.split() for line in text.splitlines() if line.strip()[:1].isdigit() or line.strip().startswith("pair")]
    assert rows and all("12.3" not in r and "0.0123" not in r for r in rows)
    first = next(r for r in rows if r[1] == result.ranking[0]["effect"])
    assert first[3] == "-" and float(first[4]) == pytest.approx(result.ranking[0]["ratio"], abs=0.005)


def test_one_scale_only_where_every_channel_is_in_the_error_unit():
    assert not get_experiment("tip-cycle").one_scale  # m and rad (rotations weighted by the mast length)
    assert all(get_experiment(n).one_scale for n in ("mast-top", "latch-pull", "joint-test", "bay-torsion"))
