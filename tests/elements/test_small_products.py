"""The element kernels' 3x3 products (femast/elements/_mat3.py): the right products, and a fused
multiply-add that rounds once."""

from fractions import Fraction

import numpy as np
import pytest
from numba import njit

from femast.elements import _mat3


@njit(cache=True)
def _fma(a, b, c):
    return _mat3.fma(a, b, c)


def test_fma_rounds_once():
    # (1 + 2^-30)(1 - 2^-30) - 1 = -2^-60 exactly; a product rounded first gives 0
    a, b = 1.0 + 2.0**-30, 1.0 - 2.0**-30
    assert a * b - 1.0 == 0.0
    assert _fma(a, b, -1.0) == -(2.0**-60)
    rng = np.random.default_rng(1)
    for a, b, c in rng.standard_normal((200, 3)):
        exact = Fraction(a) * Fraction(b) + Fraction(c)
        assert _fma(a, b, c) == float(exact)  # Fraction -> float rounds to nearest


def _exact(L, R):
    """L @ R in rational arithmetic, rounded once to float."""
    return np.array([[float(sum(Fraction(a) * Fraction(b) for a, b in zip(row, col))) for col in R.T] for row in L])


def _within_one_rounding_per_term(got, L, R):
    """Each entry within 3 roundings (a fused chain of three terms rounds at most three times) of the
    exact product."""
    exact = _exact(L, R)
    bound = 3 * np.finfo(float).eps * (np.abs(L) @ np.abs(R))
    return np.all(np.abs(got - exact) <= bound)


@pytest.mark.parametrize(
    "name, left, right",
    [
        ("mm", lambda A: A, lambda B: B),
        ("mm_at", lambda A: A.T, lambda B: B),
        ("mm_bt", lambda A: A, lambda B: B.T),
        ("mm_atbt", lambda A: A.T, lambda B: B.T),
    ],
)
def test_matrix_products(name, left, right):
    rng = np.random.default_rng(2)
    f = getattr(_mat3, name)
    for _ in range(50):
        A, B = rng.standard_normal((2, 3, 3))
        out = np.empty((3, 3))
        f(A, B, out)
        assert _within_one_rounding_per_term(out, left(A), right(B))


def test_matrix_vector_products_and_skew():
    rng = np.random.default_rng(3)
    for _ in range(50):
        A = rng.standard_normal((3, 3))
        x = rng.standard_normal(3)
        out = np.empty(3)
        _mat3.mv(A, x, out)
        assert _within_one_rounding_per_term(out[:, None], A, x[:, None])
        _mat3.mtv(A, x, out)
        assert _within_one_rounding_per_term(out[:, None], A.T, x[:, None])
        S = np.full((3, 3), np.nan)
        _mat3.skew_into(x, S)
        # [x]x y = x cross y, for each basis vector y
        for y in np.eye(3):
            assert np.array_equal(S @ y, np.cross(x, y))
