"""Example data shipped with femast (package data), usable from any folder.

    import femast.examples
    femast.examples.path("mast_top_example.csv")      # a pathlib.Path inside the installed package

On the command line the example of an experiment is its short name ``example``::

    femast compare mast-top example --fit

and ``femast examples`` lists the files (``--copy DIR`` copies them to a folder of yours).

=============================  ==============  ================================================
file                           experiment      what it is
=============================  ==============  ================================================
mast_top_example.csv           mast-top        500 samples of load cycles on a mast top (synthetic)
latch_pull_example.csv         latch-pull      two latch pull cycles (synthetic)
bay_torsion_example.csv        bay-torsion     moment-rotation test of one ADAM bay (synthetic)
bay_torsion_format.csv         bay-torsion     the bay-torsion format, schematic values only
tip_cycle_table1.csv           tip-cycle       Table 1 of Stohlman & Pellegrino (their FE prediction)
vibration_example.csv          vibration       latch resonance at nine tension settings (synthetic)
platform_pose_example.csv      platform-pose   commanded and measured platform poses (synthetic)
joint_test_spc1.csv            joint-test      cyclic test of a timber connection (real: SPC1; licence and notice beside it)
=============================  ==============  ================================================
"""

from __future__ import annotations

from pathlib import Path

from ..errors import DataFileError

FOLDER = Path(__file__).resolve().parent

# experiment -> its example data file (the short name ``example`` on the command line)
BY_EXPERIMENT = {
    "mast-top": "mast_top_example.csv",
    "latch-pull": "latch_pull_example.csv",
    "bay-torsion": "bay_torsion_example.csv",
    "tip-cycle": "tip_cycle_table1.csv",
    "vibration": "vibration_example.csv",
    "platform-pose": "platform_pose_example.csv",
    "joint-test": "joint_test_spc1.csv",
}

# files that travel with an example (the licence and notice of data made by others)
COMPANIONS = {"joint_test_spc1.csv": ("NOTICE-SPC1.txt", "LICENSE-SPC1-Apache-2.0.txt")}


def companions(name: str) -> list[Path]:
    """Paths of the files that must stay beside the example ``name`` when it is copied (its licence
    and notice: data made by others); [] for femast's own."""
    return [FOLDER / c for c in COMPANIONS.get(name, ())]


def names() -> list[str]:
    """File names of the shipped example data."""
    return sorted(p.name for p in FOLDER.glob("*.csv"))


def path(name: str) -> Path:
    """Path of the shipped example file ``name`` (e.g. ``"mast_top_example.csv"``)."""
    p = FOLDER / name
    if not p.is_file() or p.suffix != ".csv":
        raise DataFileError(f"no example data file '{name}' in femast; shipped: {', '.join(names())}")
    return p


def for_experiment(experiment: str) -> Path:
    """The example data file of a built-in experiment (what ``example`` means on the command line)."""
    try:
        return path(BY_EXPERIMENT[experiment])
    except KeyError:
        raise DataFileError(
            f"experiment '{experiment}' has no shipped example; examples exist for {', '.join(BY_EXPERIMENT)}"
        ) from None


def describe(name: str) -> str:
    """What an example file is: the first sentence of its leading comment block, on one line."""
    from ..text import first_sentence

    lines = []
    for line in path(name).read_text().splitlines():
        if not line.startswith("#"):
            break
        lines.append(line.lstrip("#").strip())
    return first_sentence(" ".join(lines))
