"""docs/modal.md: the example runs and prints what the page quotes."""

import re

from doc_examples import quoted_in, run_python_blocks


def test_modal_page_example_runs(tmp_path, capsys):
    text = run_python_blocks("modal.md", cwd=tmp_path)
    out = capsys.readouterr().out
    quoted = re.findall(r"prints `([^`]+)`", text) + re.findall(r"^`(f1 at[^`]+)`", text, re.M)
    quoted += re.findall(r"and `(pulled: [^`]+)`", text)
    assert len(quoted) == 4
    for q in quoted:
        assert quoted_in(q, out), f"modal.md says it prints {q!r}"
    assert (tmp_path / "results" / "column" / "modes_vtk" / "mode_01" / "series.pvd").is_file()
    assert (tmp_path / "results" / "bead" / "modes" / "pulled_vtk" / "mode_01" / "series.pvd").is_file()
