"""Units of measured data: unit-scaled copies of every shipped example stop compare and diagnose
with one line naming the column and the likely unit; headers in another unit (dx_mm) and the
--units override are converted by pint to the same data as the original."""

import re
from pathlib import Path

import numpy as np
import pytest

from femast import examples
from femast.cli import main
from femast.errors import DataFileError
from femast.experiments import compare, get_experiment, list_experiments, read_data
from femast.experiments import units as U
from femast.experiments.fitting import predict

EXAMPLES = [e.name for e in list_experiments() if e.name in examples.BY_EXPERIMENT]
# the mistake made on every channel of one kind: (dimension, the unit the values are really in,
# the factor on values in the experiment's unit, the header suffix that says so)
MISTAKES = {
    "[length]": ("mm", 1e3, "mm"),
    "[angle]": ("deg", 180.0 / np.pi, "deg"),
    "[torque]": ("N*mm", 1e3, "Nmm"),
    "[force]": ("lbf", 1.0 / 4.4482216152605, "lbf"),
    "[frequency]": ("kHz", 1e-3, "kHz"),
}


def _copy(exp, folder: Path, name: str, scale: dict, rename: dict) -> Path:
    """The example of ``exp`` with the columns in ``scale`` multiplied and the headers in ``rename`` renamed."""
    lines, header, out = examples.for_experiment(exp.name).read_text().splitlines(), None, []
    for line in lines:
        if line.startswith("#") or not line.strip():
            out.append(line)
            continue
        cells = line.split(",")
        if header is None:
            header = cells
            out.append(",".join(rename.get(h, h) for h in cells))
            continue
        out.append(",".join(repr(float(v) * scale[h]) if h in scale else v for h, v in zip(header, cells)))
    path = folder / name
    path.write_text("\n".join(out) + "\n")
    return path


def _kinds(exp):
    """{dimension: [channels]} of the measured channels of ``exp`` whose unit has a likely mistake."""
    kinds = {}
    for c in exp.channels:
        d = U.dimension(exp.unit_of(c))
        if d in MISTAKES and exp.unit_of(c) in ("m", "rad", "N", "N m", "Hz"):
            kinds.setdefault(d, []).append(c)
    return kinds


CASES = [(n, d) for n in EXAMPLES for d in _kinds(get_experiment(n))]


def test_every_example_has_a_case():
    assert {n for n, _ in CASES} == set(EXAMPLES)


@pytest.mark.parametrize("name, kind", CASES, ids=[f"{n}-{d.strip('[]')}" for n, d in CASES])
def test_unit_scaled_example_is_stopped_naming_the_column_and_unit(name, kind, tmp_path):
    exp = get_experiment(name)
    unit, f, suffix = MISTAKES[kind]
    chans = _kinds(exp)[kind]
    bad = _copy(exp, tmp_path, "scaled.csv", {c: f for c in chans}, {})
    with pytest.raises(DataFileError) as err:
        compare(exp, read_data(exp, bad))
    msg = str(err.value)
    named = re.search(r"column '(\w+)'", msg).group(1)
    assert named in chans and "\n" not in msg and f"--units {named}=" in msg
    original = read_data(exp, examples.for_experiment(name))
    s0, _ = U.scale(original[named], predict(exp, original)[named])
    if 0.5 < s0 < 2.0:  # where the default model is within 2x of the example, the unit is the right one
        assert f"values in {unit}" in msg and f"--units {named}={suffix}" in msg, msg
    # the header in that unit (dx_mm) reads the same numbers as the original, converted by pint
    renamed = _copy(
        exp, tmp_path, "renamed.csv", {c: f for c in chans}, {c: f"{U.split(c)[0]}_{suffix}" for c in chans}
    )
    for data in (read_data(exp, renamed), read_data(exp, bad, units={c: suffix for c in chans})):
        for c in exp.channels:
            np.testing.assert_allclose(data[c], original[c], rtol=1e-12, atol=0.0)
    # naming the header's own unit confirms it: no check for those columns
    confirmed = read_data(exp, bad, units={c: U.split(c)[1] for c in chans})
    assert set(confirmed.cache[U.CONFIRMED]) == set(chans)
    U.check_data(exp, confirmed)


def test_the_cli_stops_with_one_line_and_accepts_the_fix(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    exp = get_experiment("mast-top")
    mm = {c: 1e3 for c in ("dx_m", "dy_m", "dz_m")}
    _copy(exp, tmp_path, "mm.csv", mm, {})
    for cmd in ("compare", "diagnose"):
        assert main([cmd, "mast-top", "mm.csv"]) == 2
        err = capsys.readouterr().err.strip()
        assert err.startswith("femast: error: mm.csv: column 'dx_m' is ~1000 times") and len(err.splitlines()) == 1
    assert main(["compare", "mast-top", "mm.csv", "--units", "dx_m=mm,dy_m=mm,dz_m=mm", "--json"]) == 0
    _copy(exp, tmp_path, "mm_header.csv", mm, {"dx_m": "dx_mm", "dy_m": "dy_mm", "dz_m": "dz_mm"})
    assert main(["compare", "mast-top", "mm_header.csv", "--json"]) == 0


@pytest.mark.parametrize(
    "units, message",
    [
        ("dx_m", "give COLUMN=UNIT"),
        ("dq_m=mm", "has no column 'dq_m'"),
        ("dx_m=N", "N is not a unit of dx_m (m)"),
    ],
)
def test_bad_unit_overrides_are_named(units, message):
    exp = get_experiment("mast-top")
    with pytest.raises(DataFileError, match=re.escape(message)):
        read_data(exp, examples.for_experiment("mast-top"), units=units)


def test_a_header_in_a_unit_of_another_kind_is_refused(tmp_path):
    exp = get_experiment("mast-top")
    p = _copy(exp, tmp_path, "kind.csv", {}, {"dx_m": "dx_N"})
    with pytest.raises(DataFileError, match=r"column 'dx_N' is in N, which is not a unit of dx_m \(m\)"):
        read_data(exp, p)


@pytest.mark.parametrize(
    "unit, s, r, expected",
    [
        ("m", 1000.0, 0.99, "mm"),
        ("m", 39.4, 0.99, "inch"),
        ("N", 0.2248, 0.99, "lbf"),
        ("N", 0.2248, 0.6, None),  # a small factor needs shapes that agree well
        ("N", 0.25, 0.99, None),  # ... and a scale within 5 % of it
        ("rad", 8.8, 1.0, None),  # the tip-cycle example's ry: a model difference, no unit
        ("N m", 1000.0, 0.6, "N*mm"),
        ("m", 1000.0, 0.2, None),  # the model does not explain the shape: nothing to conclude
    ],
)
def test_likely_units(unit, s, r, expected):
    hit = U.likely_unit(unit, s, r)
    assert (hit[0] if hit else None) == expected
