"""The example in docs/guyed_masts.md runs and prints what the page says it prints."""

import sys
from pathlib import Path


def test_docs_examples_print_what_the_page_quotes(tmp_path):
    # both examples and their quoted Output blocks, number by number (doc_examples.check_output:
    # the equilibrium residual is round-off, bounded at 1e-9 N rather than compared; scipy's
    # termination message after ';' is not compared)
    from doc_examples import run_python_blocks

    text = run_python_blocks("guyed_masts.md", cwd=tmp_path)
    assert text.count("Output:") == 2


def test_benchmark_accepts_a_fourth_model():
    import importlib.util

    import numpy as np

    path = Path(__file__).resolve().parents[2] / "benchmarks" / "guyed_mast_models.py"
    spec = importlib.util.spec_from_file_location("guyed_mast_models", path)
    bench = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = bench  # dataclasses look their module up there
    spec.loader.exec_module(bench)
    models = {**bench.MODELS, "FE": lambda case, dw: 0.5 * bench.predict_3r(case, dw)}  # stand-in 4th model
    res = bench.compute(models, n_per_segment=4)
    assert "FE" in bench.table(res)
    for _case, pred in res["pred"].items():
        assert set(pred) == {"3R", "beam", "complete", "FE"}
        # the trajectory ends at the initial pose: zero wrench change, zero displacement (round-off)
        for d in pred.values():
            np.testing.assert_allclose(d[-1], 0.0, atol=1e-12)
    # detached shrouds: the complete model is the bare beam with the same E (pinv round-off)
    nos = res["pred"]["no shrouds"]
    np.testing.assert_allclose(nos["complete"], nos["beam"], rtol=1e-8, atol=1e-12)
