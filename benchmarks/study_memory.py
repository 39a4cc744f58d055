"""Memory of a large study: a 100 000-sample study never holds everything in
memory.  Runs a study of a cheap function (3 inputs, 2 outputs of which one an array of 8) for
10 000 and for 100 000 samples, each in a fresh process, and prints the peak resident memory
(ru_maxrss) of the run and of the report (percentiles, convergence, figures): if the results
were held in memory the 100 000-sample peak would grow by the size of the results
(100 000 x 13 floats = 10 MB of values, several times that as Python objects).

    python benchmarks/study_memory.py            # ~1-3 min on the shared 2-core machine
"""

import os
import shutil
import subprocess
import sys
import tempfile

CHILD = r"""
import resource, sys, time
import numpy as np
import femast.studies as st
from femast.studies.report import report

def f(a, b, c):
    return {"y": a * b + c, "v": np.full(8, a - c)}

n, folder = int(sys.argv[1]), sys.argv[2]
study = st.Study(run=f, inputs=[st.Normal("a", 0, 1), st.Uniform("b", 0, 1), st.Normal("c", 0, 2)],
                 outputs=["y", "v"], sampler="sobol", name="memory")
base = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
t = time.perf_counter()
s = st.run(study, folder, samples=n)
run_peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
t_run = time.perf_counter() - t
t = time.perf_counter()
report(folder, print_table=False)
rep_peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
print(f"{n:>7} samples: {s.ok} ok; peak RSS after imports {base / 1024:.0f} MB, after the run "
      f"{run_peak / 1024:.0f} MB ({t_run:.0f} s), after the report {rep_peak / 1024:.0f} MB "
      f"({time.perf_counter() - t:.0f} s); {len(list(__import__('pathlib').Path(folder).glob('chunks/*')))} chunk files")
"""


def main():
    print(f"load {os.getloadavg()[0]:.1f}")
    for n in (10_000, 100_000):
        folder = tempfile.mkdtemp(prefix="femast_study_mem_")
        try:
            subprocess.run([sys.executable, "-c", CHILD, str(n), folder], check=True)
        finally:
            shutil.rmtree(folder, ignore_errors=True)
    print(f"load {os.getloadavg()[0]:.1f}")


if __name__ == "__main__":
    main()
