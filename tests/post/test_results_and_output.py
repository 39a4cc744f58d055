"""Results on disk, histories, VTK series, PNG rendering and the CLI."""

import io
import json
import xml.etree.ElementTree as ET

import meshio
import numpy as np
import pytest

import femast as fm
from femast.cli import main
from femast.post.render import render_png
from femast.post.vtk import export_vtk


@pytest.fixture(scope="module")
def cantilever_results(tmp_path_factory):
    out = tmp_path_factory.mktemp("res") / "cantilever"
    m = fm.Model("cantilever")
    a, b = m.node(0, 0, 0), m.node(2.0, 0, 0)
    sec = fm.circular_tube(0.05, 0.04, E=70e9)
    m.beam(a, b, sec, up=(0, 0, 1), n=8)
    m.fix(a)
    m.step("up", initial_increment=0.5).load(b, fz=10.0)
    m.step("down", initial_increment=0.5).load(b, fz=-10.0)
    res = fm.solve(m, out, progress=False)
    return m, a, b, sec, res


def test_histories_match_linear_theory_and_reactions_balance(cantilever_results):
    m, a, b, sec, res = cantilever_results
    assert res.steps == ["initial", "up", "up", "down", "down"]
    uz = res.node_history(b, "uz")
    # 10 N on a 2 m tube: deflection/L ~ 1e-3, so small-deflection theory PL^3/3EI holds to ~1e-5
    assert uz[2] == pytest.approx(10.0 * 8 / (3 * sec.E * sec.Iz), rel=1e-4)
    assert uz[-1] == pytest.approx(-uz[2], rel=1e-4)
    # reaction force balances the load exactly; reaction moment = P L (lever arm shortens by ~1e-6)
    np.testing.assert_allclose(res.node_history(a, "rfz"), -res.node_history(b, "fz"), atol=1e-6)
    assert res.node_history(a, "rmy")[2] == pytest.approx(20.0, rel=1e-5)
    N = res.element_history("beam", 1, "section_forces")
    assert N.shape == (len(res), 2, 6)


def test_frames_are_plain_npz_readable_without_femast(cantilever_results):
    m, a, b, sec, res = cantilever_results
    # the frame log read with numpy alone: records of b"FEMASTFR", a little-endian uint64 n, n bytes of .npz
    raw = (res.folder / "frames" / "frames.npzs").read_bytes()
    blobs, at = [], 0
    while at < len(raw):
        assert raw[at : at + 8] == b"FEMASTFR"
        n = int(np.frombuffer(raw[at + 8 : at + 16], "<u8")[0])
        blobs.append(raw[at + 16 : at + 16 + n])
        at += 16 + n
    assert len(blobs) == len(res)
    with np.load(io.BytesIO(blobs[2])) as f:
        assert str(f["step"]) == "up" and f["U"].shape == (9, 3) and f["R"].shape == (9, 3, 3)
    summary = json.loads((res.folder / "summary.json").read_text())
    assert summary["completed"] and summary["increments"] == 4
    # the increments are part of the run; the rest (results set-up, initial frame) is not nothing
    assert 0 < summary["increment_time"] < summary["wall_time"]
    # status lines come from the results thread, in order, all there once the run is over
    lines = (res.folder / "status.sta").read_text().splitlines()
    total_times = [float(ln.split()[5]) for ln in lines[1:]]
    assert len(lines) == 5 and all(a < b for a, b in zip(total_times, total_times[1:]))  # header + 4, in order


def test_vtk_series(cantilever_results, tmp_path):
    m, a, b, sec, res = cantilever_results
    pvd = export_vtk(res, tmp_path / "vtk")
    files = [d.get("file") for d in ET.parse(pvd).getroot().iter("DataSet")]
    assert len(files) == len(res)
    mesh = meshio.read(tmp_path / "vtk" / files[2])
    np.testing.assert_array_equal(mesh.point_data["U"], res.frame(2)["U"])
    assert "My1" in mesh.cell_data and mesh.cells[0].data.shape == (8, 2)


def test_render_png_and_cli(cantilever_results, tmp_path, capsys):
    m, a, b, sec, res = cantilever_results
    png = render_png(res, tmp_path / "shape.png", scale=50)
    data = png.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n" and len(data) > 5000
    assert main(["render", str(res.folder), str(tmp_path / "cli.png"), "--scale", "10"]) == 0
    assert (tmp_path / "cli.png").exists()
    assert main(["info", str(res.folder)]) == 0
    assert "increments 4" in capsys.readouterr().out
    assert main(["vtk", str(res.folder), "--out", str(tmp_path / "v")]) == 0
    assert main(["info", str(tmp_path / "nowhere")]) == 2
    assert "not a femast results folder" in capsys.readouterr().err
