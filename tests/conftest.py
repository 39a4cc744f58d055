"""The test suite's environment: tests/ on sys.path (the shared helpers such as doc_examples import
from every test folder), and figures drawn without a display."""

import os
import sys
from pathlib import Path

os.environ.setdefault("MPLBACKEND", "Agg")
sys.path.insert(0, str(Path(__file__).resolve().parent))
