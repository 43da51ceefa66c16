"""Tests of stochcable.results.statistics: response spectra, moments and maxima."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import special

from stochcable.errors import InputError
from stochcable.results.statistics import (
    cross_spectrum,
    response_spectrum,
    response_statistics,
)

# DESIGN.md "Wave spectra": Tz = 0.7104 Tp for Pierson-Moskowitz (4-digit constant)
PM_TZ_OVER_TP = 0.7104


def _pm(w, hs, wp):
    """Pierson-Moskowitz in (Hs, wp), written out here (DESIGN.md)."""
    w = np.asarray(w, float)
    out = np.zeros_like(w)
    p = w > 0
    out[p] = 5.0 / 16.0 * hs**2 * wp**4 * w[p] ** -5 * np.exp(-1.25 * (wp / w[p]) ** 4)
    return out


def test_pm_moments_against_closed_forms():
    # m_n = (5/64) Hs^2 wp^n (5/4)^((n-4)/4) Gamma(1 - n/4)  (substitute x = 1.25 (wp/w)^4)
    hs, wp, top = 6.0, 2 * math.pi / 10.0, 12.0
    w = np.linspace(0.0, top, 60001)
    st = response_statistics(w, _pm(w, hs, wp))

    def closed(n):
        return 5.0 / 64.0 * hs**2 * wp**n * 1.25 ** ((n - 4) / 4) * special.gamma(1 - n / 4)

    def tail(n):  # int_top^inf of the w^(n-5) asymptote; next order is (wp/top)^4 ~ 7e-6 smaller
        return 5.0 / 16.0 * hs**2 * wp**4 * top ** (n - 4) / (4 - n)

    assert closed(0) == pytest.approx(hs**2 / 16.0, rel=1e-15)  # m0 = Hs^2/16 exactly
    # trapezoid with h = 2e-4 on a smooth integrand: ~1e-9; the leading-order tail model
    # leaves ~1e-8 of m1 (next tail term)
    for n, got in ((0, st.m0), (1, st.m1), (2, st.m2)):
        assert got == pytest.approx(closed(n) - tail(n), rel=3e-8)
    assert st.std == pytest.approx(math.sqrt(st.m0), rel=1e-15)
    assert st.significant == pytest.approx(2.0 * st.std, rel=1e-15)
    tz_exact = 2 * math.pi * math.sqrt(closed(0) / closed(2))
    assert tz_exact == pytest.approx(PM_TZ_OVER_TP * 10.0, rel=1e-4)  # 4-digit constant
    tz_trunc = 2 * math.pi * math.sqrt((closed(0) - tail(0)) / (closed(2) - tail(2)))
    assert st.tz == pytest.approx(tz_trunc, rel=1e-8)
    assert st.n_cycles == pytest.approx(10800.0 / st.tz, rel=1e-14)
    assert st.mpm == pytest.approx(st.std * math.sqrt(2 * math.log(10800.0 / st.tz)), rel=1e-14)


def test_nonuniform_grid_trapezoid():
    # geometric grid: trapezoid on the given nodes, compared with a uniform fine grid
    hs, wp = 3.0, 0.9
    wg = np.geomspace(0.2, 10.0, 3000)
    wu = np.linspace(0.2, 10.0, 200001)
    a = response_statistics(wg, _pm(wg, hs, wp))
    b = response_statistics(wu, _pm(wu, hs, wp))
    # O(h^2) trapezoid error with h/w ~ 1.3e-3 on the geometric grid: ~1e-6 relative
    for name in ("m0", "m1", "m2", "m4"):
        assert getattr(a, name) == pytest.approx(getattr(b, name), rel=1e-5)


def test_most_probable_and_expected_maximum_monte_carlo():
    # maxima of N independent Rayleigh peaks with scale sigma: compare the sample mean of
    # the largest with std (sqrt(2 ln N) + gamma/sqrt(2 ln N)) and its mode with
    # std sqrt(2 ln N)
    rng = np.random.default_rng(42)
    sigma, n_peaks, n_trials = 1.5, 1000, 4000
    w = np.linspace(0.0, 2.0, 2001)
    # narrow rectangular spectrum at w0 with variance sigma^2, chosen so N = 1000
    dens = np.where(np.abs(w - 1.0) < 0.01, sigma**2 / 0.02, 0.0)
    st = response_statistics(w, dens, duration=1.0)
    duration = n_peaks * st.tz
    st = response_statistics(w, dens, duration=duration)
    assert st.n_cycles == pytest.approx(n_peaks, rel=1e-12)
    peaks = st.std * np.sqrt(-2.0 * np.log(rng.uniform(size=(n_trials, n_peaks))))
    maxima = peaks.max(axis=1)
    # the rectangle's trapezoid variance differs from sigma^2 by the edge nodes: use st.std
    se = maxima.std() / math.sqrt(n_trials)
    # asymptotic (Gumbel) formula: its own error at N = 1000 is ~0.3 % of the mean
    assert abs(maxima.mean() - st.expected_max) < 4 * se + 0.005 * st.expected_max
    # exact mode of the max of N Rayleigh: F^N density peak; compare with the formula
    x = np.linspace(2.0, 7.0, 200001) * st.std
    cdf = 1 - np.exp(-0.5 * (x / st.std) ** 2)
    pdf = np.gradient(cdf**n_peaks, x)
    mode = x[np.argmax(pdf)]
    # sqrt(2 ln N) is the mode of the Gumbel limit; the exact mode solves
    # x^2 = 2 ln N - 2 ln(1 - 1/x^2) ~ 2 ln N + 1/ln N, i.e. is higher by the factor
    # sqrt(1 + 1/(2 ln^2 N)) (0.52 % at N = 1000); next order ~1e-4
    ln_n = math.log(n_peaks)
    assert st.mpm * math.sqrt(1 + 1 / (2 * ln_n**2)) == pytest.approx(mode, rel=5e-4)
    assert abs(st.mpm / mode - 1) > 4e-3  # the formula is the asymptotic mode, not exact
    assert st.mpm == pytest.approx(st.std * math.sqrt(2 * math.log(n_peaks)), rel=1e-12)


def test_zero_spectrum_gives_zeros_not_nan():
    w = np.linspace(0.0, 1.0, 11)
    st = response_statistics(w, np.zeros((2, 11)))
    for name, val in st.as_dict().items():
        assert np.all(np.isfinite(val)), name
    assert np.all(st.std == 0) and np.all(st.tz == 0) and np.all(st.mpm == 0)
    # short duration (N < 1): maxima finite
    dens = np.where(np.abs(w - 0.5) < 0.2, 1.0, 0.0)
    st = response_statistics(w, dens, duration=1.0)
    assert st.n_cycles < 1 and st.mpm == 0.0
    assert st.expected_max == pytest.approx((1 + 0.5772156649) * st.std)


def test_vectorized_leading_axes_and_bandwidth():
    w = np.linspace(0.0, 5.0, 5001)
    dens = np.stack([_pm(w, hs, 1.0) for hs in (1.0, 2.0, 4.0)])
    st = response_statistics(w, dens)
    assert st.std.shape == (3,)
    np.testing.assert_allclose(st.std / st.std[0], [1.0, 2.0, 4.0], rtol=1e-12)  # linear in Hs
    np.testing.assert_allclose(st.tz, st.tz[0], rtol=1e-12)  # shape-only
    # narrow band: bandwidth -> 0 ; a rectangle [a, b]: closed-form moments
    a, b = 1.0, 3.0
    wr = np.linspace(a, b, 20001)
    one = response_statistics(wr, np.ones_like(wr))
    m0, m2, m4 = b - a, (b**3 - a**3) / 3, (b**5 - a**5) / 5
    # trapezoid of w^4 on 20001 nodes: relative error ~h^2 ~ 1e-8
    assert one.bandwidth == pytest.approx(math.sqrt(1 - m2**2 / (m0 * m4)), rel=1e-7)
    d = st.as_dict()
    assert isinstance(d["std"], list) and len(d["std"]) == 3


def test_response_spectrum_and_linear_combination_on_transfer_functions():
    rng = np.random.default_rng(0)
    w = np.linspace(0.1, 3.0, 300)
    s = _pm(w, 2.0, 1.0)
    h1 = rng.standard_normal(w.size) + 1j * rng.standard_normal(w.size)
    h2 = rng.standard_normal(w.size) + 1j * rng.standard_normal(w.size)
    s1 = response_spectrum(h1, s)
    np.testing.assert_allclose(s1, (h1.real**2 + h1.imag**2) * s, rtol=1e-14)
    # S_{1+2} = S11 + S22 + 2 Re S12 (cross-spectrum identity)
    s_sum = response_spectrum(h1 + h2, s)
    via = response_spectrum(h1, s) + response_spectrum(h2, s) + 2 * cross_spectrum(h1, h2, s).real
    np.testing.assert_allclose(s_sum, via, rtol=1e-12, atol=1e-14 * s_sum.max())
    # broadcasting over leading axes
    hh = np.stack([h1, h2])
    assert response_spectrum(hh, s).shape == (2, w.size)


def test_input_errors():
    w = np.linspace(0.0, 1.0, 5)
    with pytest.raises(InputError, match=r"density .*5 entries"):
        response_statistics(w, np.ones(4))
    with pytest.raises(InputError, match=r"omega .*strictly increasing"):
        response_statistics(w[::-1], np.ones(5))
    with pytest.raises(InputError, match=r"duration .*s\].*> 0"):
        response_statistics(w, np.ones(5), duration=0.0)
    with pytest.raises(InputError, match=r"density .*>= 0"):
        response_statistics(w, -np.ones(5))


@pytest.mark.parametrize("duration", [10800.0, 600.0, 0.5])
def test_single_spectrum_equals_the_batched_form_to_the_bit(duration):
    """One spectrum (the scalar path) against the same spectrum as a row of a 2-D
    density (the array path): the same statistics to the bit, including the zero cases
    (m0 = 0, m2 = 0 through a spectrum only at ω = 0, N < 1)."""
    rng = np.random.default_rng(7)
    w = np.r_[0.0, np.sort(rng.uniform(0.01, 4.0, 150))]
    cases = [
        rng.uniform(0.0, 2.0, w.size) ** 3,
        np.zeros(w.size),
        np.r_[1.0, np.zeros(w.size - 1)],
        np.exp(-(((w - 1.0) / 0.05) ** 2)),
    ]
    for s in cases:
        one = response_statistics(w, s, duration)
        row = response_statistics(w, s[None, :], duration)
        for f in (
            "m0",
            "m1",
            "m2",
            "m4",
            "std",
            "tz",
            "significant",
            "bandwidth",
            "mpm",
            "expected_max",
            "n_cycles",
        ):
            assert isinstance(getattr(one, f), float)
            assert getattr(one, f) == float(getattr(row, f)[0]), f
