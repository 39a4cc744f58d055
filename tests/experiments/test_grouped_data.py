"""Grouped data: a group column or several files (stations, specimens, runs), the model run group by
group (path-dependent state starts at rest in each), time that restarts or runs on, a zero of its
own per group and channel counted in the information criterion, multi-axis load measures."""

import numpy as np
import pytest
import two_axis_rig as rig

from femast.errors import DataFileError
from femast.experiments import compare, fit, predict, read_data, write_data
from femast.experiments.data import combine
from femast.experiments.residuals import principal_load


def test_a_group_column_holds_any_labels_and_survives_a_round_trip(tmp_path):
    g = np.repeat(["tower A", "tower B"], [150, 150])
    data = rig.data(gap_x=0.0, n=300, groups=g)
    assert data.n_groups == 2 and data.group_names == ("tower A", "tower B")
    write_data(tmp_path / "d.csv", data, rig.RIG)
    back = read_data(rig.RIG, tmp_path / "d.csv")
    assert back.group_names == ("tower A", "tower B") and np.array_equal(back.groups, data.groups)
    assert "group" not in back.columns  # labels, not a measured column
    bad = (tmp_path / "d.csv").read_text().splitlines()
    bad[5] = bad[5].rsplit(",", 1)[0] + ","
    (tmp_path / "bad.csv").write_text("\n".join(bad) + "\n")
    with pytest.raises(DataFileError, match=r"line 6, column 'group': an empty cell"):
        read_data(rig.RIG, tmp_path / "bad.csv")


def test_files_are_groups_and_their_time_restarts_or_runs_on(tmp_path):
    t = np.linspace(0.0, 10.0, 100)
    for name, seed in (("run1", 1), ("run2", 2)):
        d = rig.data(gap_x=0.0, n=100, seed=seed)
        d.columns["t_s"] = t
        write_data(tmp_path / f"{name}.csv", d, rig.RIG)
    files = [tmp_path / "run1.csv", tmp_path / "run2.csv"]
    apart = read_data(rig.RIG, files)
    assert apart.group_names == ("run1", "run2") and apart.n == 200
    assert apart.tau[99] == 1.0 and apart.tau[100] == 0.0  # each test's own time
    on = read_data(rig.RIG, files, time_continuous=True)
    assert np.all(np.diff(on["t_s"]) > 0) and on["t_s"][100] == pytest.approx(10.0 + 10.0 / 99)
    assert on.tau[0] == 0.0 and on.tau[-1] == 1.0 and 0.45 < on.tau[99] < 0.55  # one test in two files
    sub = on.group_subsets()[1][1]  # a group alone keeps the whole test's time
    np.testing.assert_allclose(sub.tau, on.tau[100:])
    other = rig.data(gap_x=0.0, n=100)
    del other.columns["uy_mm"]
    with pytest.raises(DataFileError, match="differ from those of"):
        combine([apart, other])


def test_a_path_dependent_effect_starts_at_rest_in_every_group():
    g = np.repeat(["A", "B"], [200, 200])
    data = rig.data(gap_x=0.0, n=400, groups=g)
    eff = {"friction_hysteresis": {"F_f": 150.0}}
    both = predict(rig.RIG, data, dict(zip(("k_x", "k_y"), rig.K)), eff)
    for rows, part in data.group_subsets():
        alone = predict(rig.RIG, part.__class__(part.experiment, part.columns), dict(zip(("k_x", "k_y"), rig.K)), eff)
        np.testing.assert_array_equal(both["ux_mm"][rows], alone["ux_mm"])
    one_run = predict(rig.RIG, data.__class__(data.experiment, data.columns), dict(zip(("k_x", "k_y"), rig.K)), eff)
    assert not np.array_equal(one_run["ux_mm"][200:], both["ux_mm"][200:])  # run on, B starts where A ended


def test_a_zero_per_group_is_fitted_and_counted():
    g = np.repeat(["station 1", "station 2", "station 3"], [130, 130, 140])
    data = rig.data(gap_x=0.0, n=400, groups=g)
    shift = np.select([g == "station 2", g == "station 3"], [0.04, -0.03], 0.0)  # mm: sensors zeroed again
    data.columns["ux_mm"] = data["ux_mm"] + shift
    plain = fit(rig.RIG, data, start={"k_x": 2e6, "k_y": 3e6})
    data.offsets = True
    zeroed = fit(rig.RIG, data, start={"k_x": 2e6, "k_y": 3e6})
    assert zeroed.channel_rms["ux_mm"] < 1.2 * 5e-3 < 0.3 * plain.channel_rms["ux_mm"]
    assert zeroed.n_params == 2 + 3 * 2  # the stiffnesses and a zero per group and channel
    assert abs(zeroed.x[0] / rig.K[0] - 1) < 0.005
    c = compare(rig.RIG, data, fit=True)
    assert c.ratio < 1.3


def test_a_load_on_two_axes_is_segmented_along_its_principal_direction():
    s = np.sin(np.linspace(0, 4 * np.pi, 200))
    d = np.array([np.cos(0.5), np.sin(0.5)])
    L = np.outer(s, d) * 100.0
    np.testing.assert_allclose(principal_load(L), 100.0 * s * np.sign(s[np.argmax(np.abs(s))]), atol=1e-9)
    np.testing.assert_array_equal(principal_load(L[:, :1]), L[:, 0])
