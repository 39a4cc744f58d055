"""Linear solvers of the tangent: the sparse LU and its back-ends.

* :mod:`.linear`: :class:`~.linear.SparseLU`, the solver the analysis uses: fill-reducing ordering
  once per sparsity pattern, refactorisation of the values, refinement, singular-pivot checks;
* :mod:`.ordering`: the orderings (COLAMD via SuperLU, reverse Cuthill-McKee) and the permuted
  pattern;
* :mod:`.backends`: who factorises the permuted matrix (SuperLU, LAPACK band, dense LAPACK,
  CHOLMOD, PARDISO) and the automatic choice;
* :mod:`.banded`: the LAPACK band factorisations (Cholesky, LU);
* :mod:`.dense`: the dense LAPACK LU for small tangents.
"""
