"""Names and option values renamed to the words users know (the papers by name, "printed" for an
equation kept as printed) still work for one release: each old one gives the same result as its new
name, with a DeprecationWarning that names the new one and femast 0.3, the release that removes it."""

import importlib
import re
from dataclasses import replace

import numpy as np
import pytest

R_OC = np.array([0.05, -0.02, 3.651])
DW = np.array([[120.0, -40.0, -30.0, 5.0, -3.0, 1.0], [-60.0, 90.0, 10.0, -2.0, 4.0, 0.5]])


def _old_gives_new(old, new, call_old, call_new):
    with pytest.warns(DeprecationWarning, match=rf"{re.escape(old)} is now {re.escape(new)}.*femast 0\.3"):
        got = call_old()
    expected = call_new()
    if isinstance(expected, np.ndarray):
        np.testing.assert_array_equal(got, expected)
    else:
        assert got == expected


@pytest.mark.parametrize(
    "module, old, new",
    [
        ("femast.model.sections", "seed000_eq10_torsion_constant", "rocaspect_eq10_torsion_constant"),
        ("femast.guyed.identify", "seed_eq29_matrix", "rocaspect_eq29_matrix"),
        ("femast.elements.ball_joint_family", "SEED_MU", "ADAM_MU"),
        ("femast.elements.ball_joint_family", "SEED_B", "ADAM_B"),
        ("femast.elements.ball_joint", "SEED_MU", "ADAM_MU"),
        ("femast.elements.ball_joint", "SEED_B", "ADAM_B"),
        ("femast.elements.shroud_law", "SEED_X_S", "ROCASPECT_X_S"),
        ("femast.guyed", "SEED_X_S", "ROCASPECT_X_S"),
        ("femast.adam.parameters", "SEED_BAY_HEIGHT", "ADAM_BAY_HEIGHT"),
        ("femast.adam", "SEED_BAY_HEIGHT", "ADAM_BAY_HEIGHT"),
        ("femast.adam.post", "SEED_TABLE1", "ADAM_TABLE1"),
    ],
)
def test_an_old_module_name_warns_and_is_the_new_object(module, old, new):
    mod = importlib.import_module(module)
    with pytest.warns(DeprecationWarning, match=rf"{re.escape(module)}\.{old} is now {re.escape(module)}\.{new}"):
        got = getattr(mod, old)
    assert got is getattr(mod, new)
    with pytest.raises(AttributeError, match="no attribute 'SEED_NOTHING'"):
        _ = mod.SEED_NOTHING


def test_latch_parameters_seed_fit_is_adam_fit():
    from femast.elements.latch_law import LatchParameters

    _old_gives_new(
        "LatchParameters.seed_fit()", "LatchParameters.adam_fit()", LatchParameters.seed_fit, LatchParameters.adam_fit
    )
    assert LatchParameters.adam_fit().k == 100e3  # 100 N/mm, Stohlman & Pellegrino, Sec. III.C


def test_active_stiffness_form_seed_is_printed():
    from femast.guyed.complete_mast import ShroudSet, active_stiffness

    top = np.array([0.1, 0.2, 4.0])
    upper = top + np.array([[0.05, 0.0, -0.25], [-0.03, 0.04, -0.3], [0.0, 0.0, 0.0]])
    lower = np.array([[0.9, -0.3, 0.0], [-0.4, 0.8, 0.0], [-0.5, -0.6, 0.1]])
    shrouds = ShroudSet(upper, lower, np.array([900.0, 1200.0, 400.0]), law=None, stiffness=np.full(3, 2.5e5))
    _old_gives_new(
        "active_stiffness(form='seed')",
        "active_stiffness(form='printed')",
        lambda: active_stiffness(top, shrouds, form="seed"),
        lambda: active_stiffness(top, shrouds, form="printed"),
    )


def test_mast_section_torsion_seed_eq10_is_printed_eq10():
    from femast.guyed.cantilever import mast_section

    _old_gives_new(
        "mast_section(torsion='seed_eq10')",
        "mast_section(torsion='printed_eq10')",
        lambda: mast_section(7e10, torsion="seed_eq10", L=3.651).J,
        lambda: mast_section(7e10, torsion="printed_eq10", L=3.651).J,
    )


@pytest.mark.parametrize("function", ["jacobian_3r", "compliance_3r", "displacement_3r"])
def test_3r_seed_sign_is_printed_sign(function):
    from femast.guyed import mast_3r

    f = getattr(mast_3r, function)
    args = {
        "jacobian_3r": (R_OC,),
        "compliance_3r": ([2e5, 3e5, 1e6], R_OC),
        "displacement_3r": ([2e5, 3e5, 1e6], R_OC, DW),
    }
    _old_gives_new(
        f"{function}(seed_sign=...)",
        f"{function}(printed_sign=...)",
        lambda: f(*args[function], seed_sign=True),
        lambda: f(*args[function], printed_sign=True),
    )
    assert not np.array_equal(f(*args[function], printed_sign=True), f(*args[function]))  # the sign matters


@pytest.mark.parametrize("function", ["rocaspect_eq29_matrix", "fit_3r"])
def test_identification_seed_sign_is_printed_sign(function):
    from femast.guyed import identify
    from femast.guyed.mast_3r import displacement_3r

    dc = displacement_3r([2e5, 3e5, 1e6], R_OC, DW, printed_sign=True)
    f = getattr(identify, function)
    args = (DW, R_OC) if function == "rocaspect_eq29_matrix" else (DW, dc, R_OC)
    value = (lambda r: r) if function == "rocaspect_eq29_matrix" else (lambda r: tuple(np.round(r.x, 6)))
    _old_gives_new(
        f"{function}(seed_sign=...)",
        f"{function}(printed_sign=...)",
        lambda: value(f(*args, seed_sign=True)),
        lambda: value(f(*args, printed_sign=True)),
    )


def test_mast_top_path_kind_seed000_is_rocaspect_fig5a():
    from femast.rigs.synthetic import mast_top_path

    with pytest.warns(DeprecationWarning, match=r"kind='seed000'\) is now mast_top_path\(kind='rocaspect_fig5a'\)"):
        old = mast_top_path(n=60, kind="seed000")
    new = mast_top_path(n=60, kind="rocaspect_fig5a")
    assert old.keys() == new.keys() and all(np.array_equal(old[k], new[k]) for k in new)


def test_the_mast_top_option_seed_sign_is_printed_sign():
    from femast.experiments import get_experiment

    exp = get_experiment("mast-top")
    with pytest.warns(DeprecationWarning, match="option seed_sign of mast-top is now option printed_sign"):
        old = exp.with_options(seed_sign=True)
    assert old.options["printed_sign"] is True and "seed_sign" not in old.options


def test_effect_seed_is_source():
    from femast.effects import Effect

    with pytest.warns(DeprecationWarning, match=r"Effect\(seed=\.\.\.\) is now Effect\(source=\.\.\.\)"):
        e = Effect(name="x", title="x", physics="x.", seed="Stohlman & Pellegrino, Eq. 12")
    assert e.source == "Stohlman & Pellegrino, Eq. 12"
    assert replace(e, title="y").source == e.source  # dataclasses.replace keeps it, without a warning
    with pytest.warns(DeprecationWarning, match=r"Effect\.seed is now Effect\.source"):
        assert e.seed == e.source


def test_format_table1_seed_is_paper():
    from femast.adam.post import ADAM_TABLE1, format_table1

    labels, vals = ["0", "M+F"], np.zeros((2, 6))
    _old_gives_new(
        "format_table1(seed=...)",
        "format_table1(paper=...)",
        lambda: format_table1(labels, vals, seed=ADAM_TABLE1),
        lambda: format_table1(labels, vals, paper=ADAM_TABLE1),
    )


def test_compare_stiffness_result_reads_k_a_seed():
    from femast._moved import RenamedKeys

    # the result dict of femast.guyed.fe_mast.compare_stiffness (K_a_seed renamed K_a_printed)
    res = RenamedKeys({"K_a_printed": 1.0}, {"K_a_seed": "K_a_printed"}, "compare_stiffness(...)")
    with pytest.warns(
        DeprecationWarning, match=r"compare_stiffness\(\.\.\.\)\['K_a_seed'\] is now .*\['K_a_printed'\]"
    ):
        assert res["K_a_seed"] == 1.0
    with pytest.raises(KeyError):
        _ = res["K_b"]
    # get() and `in` see the old key too (a dict's get() would not call __missing__: None, silently)
    with pytest.warns(DeprecationWarning, match=r"\['K_a_seed'\] is now .*\['K_a_printed'\]") as got:
        assert res.get("K_a_seed") == 1.0
    assert got[0].filename == __file__  # the warning points at the line that used the old key
    with pytest.warns(DeprecationWarning, match=r"\['K_a_seed'\] is now"):
        assert "K_a_seed" in res
    assert res.get("K_b") is None and res.get("K_b", 2.0) == 2.0 and "K_b" not in res
    assert list(res) == ["K_a_printed"] and len(res) == 1


def test_plot_bay_torsion_seed_note_is_note(tmp_path, monkeypatch):
    from femast.adam import post
    from femast.post import plotstyle

    n = 8
    curve = {
        "step": ["twist"] * n,
        "theta": np.linspace(0.0, 0.05, n),
        "time": np.linspace(0.0, 1.0, n),
        "zone": np.zeros((n, 4), int),
        "M": -np.linspace(0.0, 30.0, n),
    }
    titles = []
    save = plotstyle.save

    def keep_titles(fig, png, dpi=None):
        titles.extend(ax.get_title(loc) for ax in fig.axes for loc in ("left", "center") if ax.get_title(loc))
        return save(fig, png, dpi)

    monkeypatch.setattr(plotstyle, "save", keep_titles)
    with pytest.warns(
        DeprecationWarning, match=r"plot_bay_torsion\(seed_note=\.\.\.\) is now plot_bay_torsion\(note=\.\.\.\)"
    ):
        post.plot_bay_torsion(curve, tmp_path / "old.png", seed_note="Stohlman & Pellegrino, Fig. 16")
    post.plot_bay_torsion(curve, tmp_path / "new.png", note="Stohlman & Pellegrino, Fig. 16")
    assert titles.count("Stohlman & Pellegrino, Fig. 16") == 2
