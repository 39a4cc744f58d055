"""``femast study S --scheduler tcp://...`` against a real ``dask scheduler`` and ``dask worker``
started as separate processes (not an in-process client): the same results as a serial run."""

import subprocess
import sys
import textwrap

import numpy as np
import pytest
from dask_processes import dask_cluster

import femast.studies as st

pytest.importorskip("distributed")

STUDY = textwrap.dedent(
    """
    import numpy as np
    import femast.studies as st

    def ishigami(x1, x2, x3):
        return {"y": np.sin(x1) + 7 * np.sin(x2) ** 2 + 0.1 * x3 ** 4 * np.sin(x1)}

    study = st.Study(run=ishigami, inputs=[st.Uniform(n, -np.pi, np.pi) for n in ("x1", "x2", "x3")],
                     outputs=["y"], sensitivity=True, name="ishigami", seed=7)
    """
)


def test_cli_study_on_a_separate_dask_scheduler_and_worker(tmp_path):
    script = tmp_path / "ishigami_study.py"
    script.write_text(STUDY)
    with dask_cluster(tmp_path) as address:
        p = subprocess.run(
            [
                sys.executable,
                "-m",
                "femast.cli",
                "study",
                str(script),
                "--samples",
                "16",
                "--scheduler",
                address,
                "--out",
                str(tmp_path / "dask"),
                "--no-report",
            ],
            cwd=tmp_path,
            capture_output=True,
            text=True,
            timeout=600,
        )
        assert p.returncode == 0, p.stderr + (tmp_path / "dask.log").read_text()
        assert "dask worker(s)" in p.stdout and "complete" in p.stdout
    ns = {}
    exec(STUDY, ns)
    st.run(ns["study"], tmp_path / "serial", samples=16)
    a = st.load(tmp_path / "serial").table(["y", "x1", "x2", "x3", "block"])
    b = st.load(tmp_path / "dask").table(["y", "x1", "x2", "x3", "block"])
    for k in a:
        assert np.array_equal(a[k], b[k]), k
