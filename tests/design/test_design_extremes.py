"""Tests of stochcable.design.extremes: short-term MPM, long-term distribution and
return levels (closed forms, the project's MPM convention, Monte Carlo)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from stochcable.design import (
    long_term_exceedance,
    maxima_exceedance_short_term,
    maximum_exceedance_rayleigh,
    mpm_short_term,
    return_level,
)
from stochcable.design.extremes import SECONDS_PER_YEAR
from stochcable.errors import InputError
from stochcable.results.statistics import response_statistics
from stochcable.sea.spectra import spectrum_jonswap

THREE_HOURS = 10800.0
# a small 3-state diagram: probabilities, mean tension [N], σ [N], Tz [s]
P3 = np.array([0.6, 0.3, 0.1])
MEAN3 = np.array([1.0e6, 1.1e6, 1.3e6])
STD3 = np.array([5.0e4, 1.0e5, 2.0e5])
TZ3 = np.array([7.0, 8.5, 10.0])


def test_mpm_equals_response_statistics():
    w = np.linspace(0.05, 3.0, 400)
    stats = response_statistics(w, spectrum_jonswap(w, 6.0, 10.0) * 1e10, THREE_HOURS)
    mpm = mpm_short_term(0.0, stats.std, stats.tz, THREE_HOURS)
    assert mpm == pytest.approx(stats.mpm, rel=1e-15)
    assert mpm_short_term(2.5e6, stats.std, stats.tz, THREE_HOURS) == pytest.approx(
        2.5e6 + stats.mpm, rel=1e-15
    )
    # vectorized, and N < 1 or Tz = 0 (no cycles) hold the MPM at the mean
    out = mpm_short_term([0.0, 1.0, 1.0], [1.0, 2.0, 2.0], [10.0, 2e4, 0.0], THREE_HOURS)
    np.testing.assert_allclose(out, [math.sqrt(2 * math.log(1080.0)), 1.0, 1.0], rtol=1e-15)


def test_short_term_exceedance_at_the_mpm():
    mpm = mpm_short_term(1e6, 1e5, 8.0, THREE_HOURS)
    # N Q(mpm) = 1: P(X_max > mpm) = 1 − e^{-1}
    p = maxima_exceedance_short_term(mpm, 1e6, 1e5, 8.0, THREE_HOURS)
    assert float(p) == pytest.approx(1.0 - math.exp(-1.0), rel=1e-13)
    assert float(maxima_exceedance_short_term(0.9e6, 1e6, 1e5, 8.0, THREE_HOURS)) == 1.0
    # zero response: the maximum is the mean
    assert float(maxima_exceedance_short_term(1.0, 1.0, 0.0, 8.0, THREE_HOURS)) == 0.0
    assert float(maxima_exceedance_short_term(0.5, 1.0, 0.0, 8.0, THREE_HOURS)) == 1.0


@pytest.mark.parametrize("formulation", ["all_maxima", "storm_maximum"])
def test_one_state_diagram_reproduces_the_short_term_mpm(formulation):
    mean, std, tz = 1.2e6, 1.5e5, 9.0
    years = THREE_HOURS / SECONDS_PER_YEAR
    level = return_level(years, [1.0], [mean], [std], [tz], formulation=formulation)
    # Brent's method to ~1e-15 relative in x
    assert level == pytest.approx(mpm_short_term(mean, std, tz, THREE_HOURS), rel=1e-12)
    # the same with a bandwidth of 0 (Cartwright–Longuet-Higgins reduces to Rayleigh)
    level0 = return_level(years, [1.0], [mean], [std], [tz], bandwidth=[0.0])
    assert level0 == pytest.approx(level, rel=1e-12)


def test_long_term_exceedance_monte_carlo_all_maxima():
    rng = np.random.default_rng(20261124)
    n = 400_000
    # a random maximum: its state drawn in proportion to p_i ν_i, then a Rayleigh maximum
    w = P3 / TZ3
    state = rng.choice(3, size=n, p=w / w.sum())
    x = MEAN3[state] + STD3[state] * np.sqrt(-2.0 * np.log1p(-rng.random(n)))
    levels = np.array([1.05e6, 1.2e6, 1.5e6, 1.8e6])
    q = long_term_exceedance(levels, P3, MEAN3, STD3, TZ3)
    emp = (x[:, None] > levels).mean(axis=0)
    # binomial sampling error: 4.5 standard errors
    se = np.sqrt(q * (1 - q) / n)
    np.testing.assert_array_less(np.abs(emp - q), 4.5 * se)


def test_long_term_exceedance_monte_carlo_bandwidth():
    # Cartwright & Longuet-Higgins (1956): a maximum of a process of bandwidth ε is
    # distributed as ε ξ + √(1 − ε²) η, ξ standard normal, η standard Rayleigh
    rng = np.random.default_rng(7)
    n = 400_000
    eps = np.array([0.3, 0.5, 0.7])
    w = P3 / (TZ3 * np.sqrt(1 - eps**2))  # rate of maxima
    state = rng.choice(3, size=n, p=w / w.sum())
    u = eps[state] * rng.standard_normal(n) + np.sqrt(1 - eps[state] ** 2) * np.sqrt(
        -2.0 * np.log1p(-rng.random(n))
    )
    x = MEAN3[state] + STD3[state] * u
    levels = np.array([0.9e6, 1.1e6, 1.4e6])
    q = long_term_exceedance(levels, P3, MEAN3, STD3, TZ3, bandwidth=eps)
    emp = (x[:, None] > levels).mean(axis=0)
    se = np.sqrt(q * (1 - q) / n)
    np.testing.assert_array_less(np.abs(emp - q), 4.5 * se)
    # one maximum of one state, the same representation
    q1 = maximum_exceedance_rayleigh(1.1e6, MEAN3[0], STD3[0], bandwidth=0.5)
    u1 = 0.5 * rng.standard_normal(n) + math.sqrt(0.75) * np.sqrt(-2 * np.log(rng.random(n)))
    emp1 = np.mean(MEAN3[0] + STD3[0] * u1 > 1.1e6)
    assert abs(emp1 - float(q1)) < 4.5 * math.sqrt(float(q1) * (1 - float(q1)) / n)


def test_storm_maximum_monte_carlo():
    rng = np.random.default_rng(11)
    n = 200_000
    state = rng.choice(3, size=n, p=P3)
    # the largest of K ~ Poisson(T/Tz) Rayleigh maxima: CDF F^K, sampled by inversion
    k = rng.poisson(THREE_HOURS / TZ3[state])
    v = rng.random(n)
    u = np.sqrt(-2.0 * np.log1p(-(v ** (1.0 / np.maximum(k, 1)))))
    x = np.where(k > 0, MEAN3[state] + STD3[state] * u, -np.inf)
    levels = np.array([1.2e6, 1.4e6, 1.8e6, 2.1e6])
    q = long_term_exceedance(levels, P3, MEAN3, STD3, TZ3, formulation="storm_maximum")
    emp = (x[:, None] > levels).mean(axis=0)
    se = np.sqrt(q * (1 - q) / n)
    np.testing.assert_array_less(np.abs(emp - q), 4.5 * se)


def test_return_level_properties_and_vectorization():
    years = 100.0
    x100 = return_level(years, P3, MEAN3, STD3, TZ3)
    # the defining equation: N_R Q_LT(x) = 1
    n_r = years * SECONDS_PER_YEAR * np.sum(P3 / TZ3)
    assert n_r * float(long_term_exceedance(x100, P3, MEAN3, STD3, TZ3)) == pytest.approx(
        1.0, rel=1e-9
    )
    x1 = return_level(1.0, P3, MEAN3, STD3, TZ3)
    assert x1 < x100
    # above every state's 3-h MPM (each state occurs for many 3-h periods in 100 years)
    assert x100 > np.max(mpm_short_term(MEAN3, STD3, TZ3, THREE_HOURS))
    # probabilities are weights relative to their sum
    assert return_level(years, 2 * P3, MEAN3, STD3, TZ3) == pytest.approx(x100, rel=1e-12)
    # several response locations at once (states first): equal to one at a time
    std2 = np.stack([STD3, 1.3 * STD3], axis=1)
    both = return_level(years, P3, MEAN3[:, None], std2, TZ3[:, None])
    assert both.shape == (2,)
    assert both[0] == pytest.approx(x100, rel=1e-12)
    assert both[1] == pytest.approx(return_level(years, P3, MEAN3, 1.3 * STD3, TZ3), rel=1e-12)
    q = long_term_exceedance(np.array([[1.5e6], [1.6e6]]), P3, MEAN3[:, None], std2, TZ3[:, None])
    assert q.shape == (2, 2)
    # a state of zero probability does not change anything
    x_extra = return_level(
        years,
        [*P3, 0.0],
        [*MEAN3, 9e9],
        [*STD3, 9e9],
        [*TZ3, 5.0],
    )
    assert x_extra == pytest.approx(x100, rel=1e-12)


def test_errors():
    with pytest.raises(InputError, match="probabilities.*must not all be zero"):
        long_term_exceedance(1.0, [0.0, 0.0], [0, 0], [1, 1], [5, 5])
    with pytest.raises(InputError, match="probabilities.*must be >= 0"):
        long_term_exceedance(1.0, [-0.5, 1.5], [0, 0], [1, 1], [5, 5])
    with pytest.raises(InputError, match="mean.*must have the 2 states on their first axis"):
        long_term_exceedance(1.0, [0.5, 0.5], [0, 0, 0], [1, 1, 1], [5, 5, 5])
    with pytest.raises(InputError, match="mean.*must broadcast together"):
        long_term_exceedance(1.0, [0.5, 0.5], [0, 0], [1, 1, 1], [5, 5])
    with pytest.raises(InputError, match="std.*must be >= 0"):
        long_term_exceedance(1.0, [0.5, 0.5], [0, 0], [1, -1], [5, 5])
    with pytest.raises(InputError, match="tz.*some state with p > 0 must have Tz > 0"):
        long_term_exceedance(1.0, [0.5, 0.5], [0, 0], [1, 1], [0, 0])
    with pytest.raises(InputError, match="bandwidth.*must be in \\[0, 1\\)"):
        long_term_exceedance(1.0, [0.5, 0.5], [0, 0], [1, 1], [5, 5], bandwidth=1.0)
    with pytest.raises(InputError, match="formulation = 'peaks': must be one of"):
        long_term_exceedance(1.0, [1.0], [0], [1], [5], formulation="peaks")
    with pytest.raises(InputError, match="state_duration = 0.0 \\[s\\]: must be > 0"):
        long_term_exceedance(1.0, [1.0], [0], [1], [5], state_duration=0.0)
    with pytest.raises(InputError, match="years = -1.0 \\[year\\]: must be > 0"):
        return_level(-1.0, [1.0], [0], [1], [5])
    with pytest.raises(InputError, match="years.*is shorter than the mean time between maxima"):
        return_level(1.0 / SECONDS_PER_YEAR, [1.0], [0], [1], [5])
    with pytest.raises(InputError, match="duration = 0.0 \\[s\\]: must be > 0"):
        mpm_short_term(0.0, 1.0, 5.0, 0.0)
    with pytest.raises(InputError, match="tz.*must be >= 0"):
        maxima_exceedance_short_term(1.0, 0.0, 1.0, -5.0, 100.0)
    with pytest.raises(InputError, match="x.*must be finite"):
        maximum_exceedance_rayleigh(np.nan, 0.0, 1.0)
