"""compare and diagnose speak the user's words and draw figures a reader can read.

For every experiment with shipped example data, what ``femast compare``/``femast diagnose`` print,
the text of their HTML report and every text of every figure they draw carry no project-internal
words: no "seed 001", "seed sign", "issue 17" and no internal verdict keys such as
``[form_imperfect]`` or ``missing_pair`` (the JSON report keeps its keys; people read the
sentence).  Every figure passes the checks of :mod:`figure_geometry`: no legend over an axis label,
a tick label or another legend, and every line a legend lists at least partly inside its axes.
"""

import html
import re

import pytest
from figure_geometry import figure_problems

from femast import examples
from femast.cli import main
from femast.post import plotstyle

VERDICT_KEYS = ("missing_effect", "missing_pair", "form_imperfect", "better_form", "nothing_missing", "not_explained")
INTERNAL = re.compile(
    r"(?<!random )\bseed\b|seed ?0\d\d|\bissue \d+|" + "|".join(VERDICT_KEYS),
    re.IGNORECASE,
)
EXPERIMENTS = sorted(examples.BY_EXPERIMENT)
CHEAP = ["mast-top", "latch-pull", "vibration"]  # diagnose in seconds; the FE experiments' run as slow tests


def internal_words(text: str) -> list[str]:
    """The project-internal words in ``text`` with a little context."""
    return [text[max(0, m.start() - 30) : m.end() + 30].replace("\n", " ") for m in INTERNAL.finditer(text)]


def test_the_pattern_finds_what_it_should():
    assert internal_words("verdict: mechanism found [form_imperfect]")
    assert internal_words("Mz (N m, seed sign)") and internal_words("FE bay of issue 5")
    assert internal_words("tip_cycle_seed001_table1.csv") and internal_words("(seed 001 Eq. 15)")
    assert not internal_words("0.2 mm Gaussian noise (random seed 7); mechanism found, form imperfect")


@pytest.fixture
def drawn(monkeypatch):
    """Every figure femast saves during the test: (png name, problems, texts)."""
    seen = []
    save = plotstyle.save

    def checked_save(fig, png, dpi=None):
        out = save(fig, png, dpi)  # laid out and written as the user gets it
        texts = " | ".join(t.get_text() for t in fig.findobj(lambda a: hasattr(a, "get_text")) if t.get_text())
        seen.append((out.name, figure_problems(fig), texts))
        return out

    monkeypatch.setattr(plotstyle, "save", checked_save)
    return seen


def _page_text(path) -> str:
    """The visible text of an HTML report (tags, and the images' base64 data, removed)."""
    text = path.read_text(encoding="utf-8")
    text = re.sub(r'src="data:[^"]*"', "", text)
    return html.unescape(re.sub(r"<[^>]+>", " ", text))


def _check(command, name, tmp_path, capsys, drawn):
    out = tmp_path / name
    extra = ["--workers", "1"] if command == "diagnose" else []
    assert main([command, name, "example", "--out", str(out), *extra]) == 0
    printed = capsys.readouterr()
    _assert_in_users_words(printed.out + printed.err, out, drawn)


def _assert_in_users_words(printed, out, drawn):
    """What a command printed, the HTML pages it wrote in ``out`` and the figures it drew (``drawn``)."""
    problems = [f"printed: {w}" for w in internal_words(printed)]
    for page in out.glob("*.html"):
        problems += [f"{page.name}: {w}" for w in internal_words(_page_text(page))]
    assert drawn, "no figure drawn"
    for png, geometry, texts in drawn:
        problems += [f"{png}: {g}" for g in geometry]
        problems += [f"{png} text: {w}" for w in internal_words(texts)]
    assert not problems, "\n".join(problems)


@pytest.mark.parametrize("name", EXPERIMENTS)
def test_compare_on_every_example(name, example_run):
    # `femast compare NAME example`, run once per session for the tests that read it
    run = example_run("compare", name)
    _assert_in_users_words(run.stdout + run.stderr, run.out, run.drawn)


@pytest.mark.parametrize("name", CHEAP)
def test_diagnose_on_the_quick_examples(name, example_run):
    # `femast diagnose NAME example --workers 1`, run once per session for the tests that read it
    run = example_run("diagnose", name)
    _assert_in_users_words(run.stdout + run.stderr, run.out, run.drawn)


@pytest.mark.slow
@pytest.mark.parametrize("name", [n for n in EXPERIMENTS if n not in CHEAP])
def test_diagnose_on_the_fe_examples(name, tmp_path, capsys, drawn):
    _check("diagnose", name, tmp_path, capsys, drawn)


def test_the_figure_checks_see_what_a_reader_sees(tmp_path):
    plt = plotstyle.pyplot()
    fig, ax = plt.subplots()
    ax.plot([0, 1], [0, 1], label="data")
    ax.axhline(0.5, ls="--", label="noise floor")
    ax.set_xlabel("x (mm)")
    ax.legend(loc="upper left")
    plotstyle.save(fig, tmp_path / "clean.png")
    assert figure_problems(fig) == []
    fig, ax = plt.subplots()
    ax.plot([0, 1], [0, 1], label="data")
    ax.axhline(5.0, ls="--", label="noise floor")  # beyond the limits set next
    ax.set_ylim(0, 1)
    ax.set_xlabel("x (mm)")
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.02))  # below the axes, over the label
    plotstyle.save(fig, tmp_path / "bad.png")
    problems = figure_problems(fig)
    assert any("covers axes 0 x label" in p for p in problems)
    assert any("'noise floor' is listed in the legend but lies outside" in p for p in problems)


def test_diagnose_figure_keeps_its_noise_lines_and_legend_clear(tmp_path, drawn):
    """Every error below the at-noise threshold (a model already at the noise): the threshold and
    noise-floor lines stay inside the axes, the legend clear of the x label, the verdict in words."""
    from types import SimpleNamespace

    import numpy as np

    from femast.experiments import get_experiment
    from femast.experiments.figures import diagnose_figure

    exp = get_experiment("mast-top")
    n = 40
    ranking = [
        {"effect": name, "form": None, "ratio": ratio, "delta_bic": dbic, "significant": False, "heldout_ratio": None}
        for name, ratio, dbic in (("joint_clearance", 1.05, -3.0), ("friction_hysteresis", 1.1, 1.0))
    ]
    result = SimpleNamespace(
        baseline={"ratio": 1.15, "heldout_ratio": 1.1},
        ranking=ranking,
        pairs=[],
        noise_rms=2.0e-6,
        at_noise=2.0,  # the threshold beyond every bar
        verdict={
            "kind": "nothing_missing",
            "missing_effects": [],
            "conclusion": "nothing is missing: the model is at the noise floor (1.15x noise) and no candidate is "
            "significant",
        },
        baseline_z=np.ones(len(exp.channels) * n),
        baseline_fit=SimpleNamespace(fun=np.ones(len(exp.channels) * n)),
        best_fit=None,
        noise={c: 2.0e-6 for c in exp.channels},
    )
    diagnose_figure(exp, SimpleNamespace(n=n), result, tmp_path / "diagnose.png")
    ((png, problems, texts),) = drawn
    assert problems == []
    words = " ".join(texts.split())  # the title wraps to its axes
    assert "RMS error / noise after refit" in words and "nothing is missing" in words
