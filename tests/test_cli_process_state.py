"""femast.cli.main called from Python (tests, notebooks) leaves the interpreter as it found it: the
garbage collector's thresholds that the command raises for its own short process (issue 21) come
back, and the heap that compare/diagnose freeze for a quick exit is given back to the collector."""

import gc

from femast.cli import main


def test_main_restores_the_collector(tmp_path, capsys):
    before = gc.get_threshold()
    assert gc.get_freeze_count() == 0
    assert main(["compare", "mast-top", "example", "--out", str(tmp_path / "o"), "--json"]) == 0
    capsys.readouterr()
    assert gc.get_threshold() == before
    assert gc.get_freeze_count() == 0   # (compare froze the heap before its exit)
