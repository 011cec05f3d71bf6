"""Chi-square quantiles against scipy."""

from __future__ import annotations

import mpmath
import pytest
from scipy import stats

from lqe_helpers.distributions import chi2_quantile


@pytest.mark.parametrize("df", [0.5, 1, 2, 3, 4, 7, 10, 30, 101, 1800, 54_000, 540_000])
@pytest.mark.parametrize("probability", [1e-6, 0.025, 0.3, 0.5, 0.975, 1 - 1e-9])
def test_chi2_quantile_matches_scipy(df: float, probability: float) -> None:
    assert chi2_quantile(probability, df) == pytest.approx(stats.chi2.ppf(probability, df),
                                                           rel=1e-9)


@pytest.mark.parametrize(
    ("args", "message"),
    [((0.0, 2), r"^probability must be a finite number > 0, got 0.0$"),
     ((1.0, 2), r"^probability must be in \[1e-15, 1 − 1e-15\], got 1.0$"),
     ((0.5, 0.1), r"^df must be >= 0.5, got 0.1$"),
     ((0.5, 0), r"^df must be a finite number > 0, got 0$"),
     ((0.5, float("inf")), r"^df must be a finite number > 0, got inf$"),
     ((0.5, True), r"^df must be a number > 0, got True: a boolean")],
)
def test_chi2_quantile_refuses_what_is_not_a_probability_or_df(args, message: str) -> None:
    with pytest.raises(ValueError, match=message):
        chi2_quantile(*args)


@pytest.mark.parametrize("probability", [1e-6, 0.025, 0.975])
@pytest.mark.slow
def test_chi2_quantile_for_ten_million_degrees_of_freedom(probability: float) -> None:
    # scipy's ppf is 0.8 % off in the far tail here; the reference is P(df/2, x/2) summed
    # as its series in 30-digit arithmetic.
    mpmath.mp.dps = 30
    a = mpmath.mpf(5_000_000)
    x = mpmath.mpf(chi2_quantile(probability, 10**7)) / 2
    total, term, n = mpmath.mpf(0), 1 / a, 0
    while term > total * mpmath.mpf(10) ** -25 or n < 10:
        total += term
        n += 1
        term *= x / (a + n)
    if x >= a:  # above the mean: P from its complement's expansion is not needed here
        assert probability > 0.5
        assert chi2_quantile(probability, 10**7) == pytest.approx(
            stats.chi2.ppf(probability, 10**7), rel=1e-9)
        return
    lower_tail = total * mpmath.exp(a * mpmath.log(x) - x - mpmath.loggamma(a))
    assert float(lower_tail) == pytest.approx(probability, rel=1e-6)
