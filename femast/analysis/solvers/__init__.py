"""Old package, split by concept: the control strategies are in :mod:`femast.analysis.control`, the
convergence test is :mod:`femast.analysis.convergence`, the linear solvers are in
:mod:`femast.analysis.linalg`.  Each module here warns on import and goes in femast 0.3."""
