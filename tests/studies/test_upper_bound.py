"""The one-sided distribution-free upper bound of a quantile (femast.studies.upper_bound) against
the binomial sums written out, and its coverage by simulation."""

import math

import numpy as np
import pytest

import femast.studies as st
from femast.errors import StudyError


def binom_cdf(k, n, q):
    return sum(math.comb(n, i) * q**i * (1 - q) ** (n - i) for i in range(k + 1))


def test_59_runs_bound_the_95th_percentile_by_their_largest():
    x = np.arange(1.0, 60.0)
    b = st.upper_bound(x, 0.95)
    assert b["needed"] == 59  # 0.95^59 = 0.0485 < 0.05 < 0.95^58 = 0.0510
    assert b["rank"] == 59 and b["high"] == 59.0
    assert b["coverage"] == pytest.approx(1 - 0.95**59, rel=1e-12)
    assert math.isnan(st.upper_bound(x[:58], 0.95)["high"])


@pytest.mark.parametrize("n, q", [(100, 0.95), (200, 0.9), (40, 0.5)])
def test_rank_is_the_smallest_with_the_asked_coverage(n, q):
    b = st.upper_bound(np.linspace(0, 1, n), q)
    u = b["rank"]
    assert binom_cdf(u - 1, n, q) >= 0.95 > binom_cdf(u - 2, n, q)
    assert b["coverage"] == pytest.approx(binom_cdf(u - 1, n, q), rel=1e-10)


def test_coverage_by_simulation():
    rng = np.random.default_rng(7)
    n, reps = 100, 4000
    highs = np.array([st.upper_bound(rng.random(n), 0.95)["high"] for _ in range(reps)])
    cover = st.upper_bound(np.zeros(n), 0.95)["coverage"]
    freq = np.mean(highs >= 0.95)  # the uniform's 95th percentile is 0.95
    assert freq == pytest.approx(cover, abs=4 * math.sqrt(cover * (1 - cover) / reps))


def test_bad_quantile_is_named():
    with pytest.raises(StudyError, match="quantile"):
        st.upper_bound([1.0, 2.0], 95)
