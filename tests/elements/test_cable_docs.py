"""The code examples of docs/cable_latch_element.md and docs/latch_identification.md run."""

import pytest
from doc_examples import run_python_blocks


@pytest.mark.parametrize("name", ["cable_latch_element.md", "latch_identification.md"])
def test_doc_examples_run(name):
    run_python_blocks(name)
