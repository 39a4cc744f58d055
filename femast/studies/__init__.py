"""Studies of uncertain inputs: run a model over the scatter of its inputs, store
every run, and report percentiles, convergence and sensitivity indices.

    import femast.studies as st
    study = st.Study(model=factory, inputs=[st.Normal("dL_m", 0.0, 5e-5)],
                     outputs=[st.NodeOutput("tip", node=tip, quantity="U")], sampler="sobol")
    summary = st.run(study, "studies/tip", samples=256, workers=2)
    res = st.load("studies/tip")

Modules: ``distributions`` (inputs), ``sampling`` (points, copula, Saltelli layout), ``outputs``
(what a femast run records), ``study`` (the definition), ``runners`` (serial / local processes /
dask), ``store`` (Parquet chunks), ``results`` (reading back), ``statistics``, ``figures``.
See docs/studies.md.
"""

from .distributions import Input, LogNormal, Normal, TruncatedNormal, Uniform, exponential_correlation
from .outputs import ElementOutput, NodeOutput
from .results import StudyResults, load
from .runners import RunSummary, run
from .statistics import bootstrap_ci, convergence, percentile, sobol_convergence, sobol_indices, upper_bound
from .study import Study

__all__ = [
    "Input",
    "Normal",
    "Uniform",
    "TruncatedNormal",
    "LogNormal",
    "exponential_correlation",
    "NodeOutput",
    "ElementOutput",
    "Study",
    "run",
    "RunSummary",
    "load",
    "StudyResults",
    "percentile",
    "upper_bound",
    "bootstrap_ci",
    "convergence",
    "sobol_indices",
    "sobol_convergence",
]
