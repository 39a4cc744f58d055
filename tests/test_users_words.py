"""The code, its docstrings, the benchmarks, the docs and the shipped examples call the papers by
their names -- "ADAM (Stohlman & Pellegrino), Eq. 12", "the Rocaspect paper, Eq. 25" -- never by the
tracker's words for them ("seed 001", "the seed's fit", "seed Fig. 6"), and carry no tracker issue
numbers.  A random-number ``seed`` is a correct word and stays; the old names kept for one release
(``seed_fit``, ``kind="seed000"``, ...: tests/test_renamed_names.py) are the only other use.
CLI output and figure texts are checked in tests/experiments/test_output_in_users_words.py;
CHANGELOG.md keeps the history and is not checked."""

import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
#: the papers called by the tracker's words
PAPER_AS_SEED = re.compile(
    r"seed ?0\d\d|\b[Tt]he seed'?s?\b(?!\s*=)|\b[Ss]eed,? (?:Sec|Fig|Eq|Table)|\bSeed\b|\bseed(?:'s)? (?:fit|values|law|text)\b"
)
ISSUE_NUMBER = re.compile(r"(?<!numba )\bissues? #?\d+|issue_\d+", re.IGNORECASE)  # another project's issue stays
#: the old names that warn for one release (tests/test_renamed_names.py), and this file's own patterns
OLD_NAMES = re.compile(r"seed000_eq10_torsion_constant|kind='seed000'|\"seed000\"")
#: files that name the old words on purpose: the tests of the renames and of the output's words
EXEMPT = {"tests/test_renamed_names.py", "tests/test_users_words.py", "tests/experiments/test_output_in_users_words.py"}


def _files():
    for folder, suffixes in (
        ("femast", (".py", ".csv")),
        ("benchmarks", (".py",)),
        ("docs", (".md",)),
        ("tests", (".py",)),
    ):
        for p in sorted((ROOT / folder).rglob("*")):
            if p.suffix in suffixes and "__pycache__" not in p.parts and "out" not in p.relative_to(ROOT).parts:
                yield p
    for name in ("README.md", "CONTRIBUTING.md"):
        yield ROOT / name


def _findings(pattern):
    out = []
    for p in _files():
        rel = p.relative_to(ROOT).as_posix()
        if rel in EXEMPT:
            continue
        for k, line in enumerate(p.read_text(encoding="utf-8", errors="replace").splitlines(), 1):
            if pattern.search(OLD_NAMES.sub("", line)):
                out.append(f"{rel}:{k}: {line.strip()[:120]}")
    return out


def test_the_patterns_find_what_they_should():
    found = [
        "latch of seed 001, Fig. 10",
        "the seed's fit",
        "(seed Sec. II.B.1)",
        "Seed Table III",
        "The seed gives",
        "tip_cycle_seed001",
        "see issue 17",
        "def test_json_schema_of_issue_7",
    ]
    assert not ISSUE_NUMBER.search("numba issue #1833")
    assert all(PAPER_AS_SEED.search(t) or ISSUE_NUMBER.search(t) for t in found)
    kept = ["rng = np.random.default_rng(seed)", "fixed seed; 2000 draws", "the seed = 3 of a design", 'kind="seed000"']
    assert not [t for t in kept if PAPER_AS_SEED.search(OLD_NAMES.sub("", t)) or ISSUE_NUMBER.search(t)]


@pytest.mark.parametrize("pattern", [PAPER_AS_SEED, ISSUE_NUMBER], ids=["papers by name", "no issue numbers"])
def test_code_docs_and_examples_speak_the_users_words(pattern):
    found = _findings(pattern)
    assert not found, f"{len(found)} line(s):\n" + "\n".join(found)
