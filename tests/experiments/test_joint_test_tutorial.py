"""docs/joint_test.md runs as a user would run it, from an empty folder: the real SPC1 example,
fitted on its small cycles, predicts its large ones better with each mechanism the page adds, as
the page quotes; its figure is written."""

from doc_examples import run_python_blocks


def test_the_tutorial_runs_from_an_empty_folder(tmp_path):
    run_python_blocks("joint_test.md", cwd=tmp_path)
    assert (tmp_path / "joint_test_spc1.png").stat().st_size > 10_000
