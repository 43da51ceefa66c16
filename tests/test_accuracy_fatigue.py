"""The fatigue and non-Gaussian helpers of the accuracy page (benchmarks/accuracy_fatigue.py),
against closed forms: Parseval, a sinusoid's rainflow and narrow-band damage, the
Hermite model's normalization (Gauss–Hermite quadrature) and its narrow-band damage
factor (quadrature over the Rayleigh amplitudes), the largest of N Rayleigh maxima."""

from __future__ import annotations

import importlib.util
import math
import sys

import numpy as np
import pytest
from _paths import ROOT
from scipy import integrate, special

from stochcable.design.curves import fatigue_curve, tension_to_curve_quantity
from stochcable.design.spectral_fatigue import damage_rate_dirlik

SCRIPT = ROOT / "benchmarks" / "accuracy_fatigue.py"


def _load():
    spec = importlib.util.spec_from_file_location("accuracy_fatigue", SCRIPT)
    mod = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = mod
    spec.loader.exec_module(mod)
    return mod


af = _load()
DT = 0.05  # [s] the page's sampling
N = 4000  # one 200 s period


def _sine(amplitude: float, j: int) -> np.ndarray:
    t = DT * np.arange(N)
    return 7.0 + amplitude * np.cos(2.0 * math.pi * j * t / (N * DT) + 0.3)


def test_periodic_density_is_parseval_and_puts_a_line_on_its_frequency():
    rng = np.random.default_rng(5)
    x = rng.normal(size=N)
    w, s = af.periodic_density(x, DT)
    assert np.sum(s) * (w[1] - w[0]) == pytest.approx(x.var(), rel=1e-12)
    w, s = af.periodic_density(_sine(2.0, 31), DT)
    assert w[np.argmax(s)] == pytest.approx(2.0 * math.pi * 31 / (N * DT))
    assert np.max(s) * (w[1] - w[0]) == pytest.approx(2.0, rel=1e-12)  # A²/2


def test_surrogates_keep_the_spectrum_line_by_line_and_the_mean():
    rng = np.random.default_rng(7)
    x = np.cumsum(rng.normal(size=N))
    sur = af.phase_randomized(x, np.random.default_rng(1), 3)
    _, s0 = af.periodic_density(x, DT)
    for y in sur:
        assert y.mean() == pytest.approx(x.mean(), rel=1e-12)
        np.testing.assert_allclose(af.periodic_density(y, DT)[1], s0, rtol=1e-9, atol=1e-12)
        assert not np.allclose(y, x)  # the phases changed


def test_sine_rainflow_and_narrow_band_dirlik():
    """A sinusoid of amplitude A with j cycles in the record: the rainflow damage is
    j·(2A·k)^m/a per period; Dirlik on its one-line spectrum is the narrow-band
    (Rayleigh) damage ν0·(2√2 σ)^m Γ(1 + m/2)/a, σ = A/√2."""
    curve = fatigue_curve("dnv-studless")
    k = tension_to_curve_quantity(curve, nominal_diameter=0.12)
    amp, j = 1.0e5, 31
    x = _sine(amp, j)
    spec = af.periodic_density(x, DT)
    r = af.damage_rates([x], DT, spec, curve, k)
    m, log_a = curve.slopes[0], curve.log10_intercepts[0]
    period = N * DT
    assert r["rainflow"][0] == pytest.approx(j * (2 * amp * k) ** m / 10**log_a / period, rel=1e-3)
    sigma = amp * k / math.sqrt(2.0)
    nb = (j / period) * (2 * math.sqrt(2) * sigma) ** m * special.gamma(1 + m / 2) / 10**log_a
    assert r["dirlik_td"][0] == pytest.approx(nb, rel=1e-9)
    assert r["dirlik"] == pytest.approx(nb, rel=1e-9)


def test_hermite_model_is_normalized_and_reduces_to_the_gaussian():
    assert af.hermite_coefficients(0.0, 3.0) == (0.0, 0.0, 1.0)
    h3, h4, kappa = af.hermite_coefficients(0.4, 3.6)
    assert (h3, h4) == pytest.approx((0.4 / 6, 0.6 / 24))
    u, wq = np.polynomial.hermite_e.hermegauss(40)
    wq = wq / math.sqrt(2 * math.pi)
    x = af.hermite_level(u, h3, h4, kappa)
    assert np.sum(wq * x) == pytest.approx(0.0, abs=1e-12)  # zero mean
    assert np.sum(wq * x * x) == pytest.approx(1.0, rel=1e-12)  # κ normalizes
    # the fit is first order in the moments: at the page's sizes (|α3| ≤ 0.1,
    # α4 − 3 ≤ 0.2) it returns α3 within 4 % and α4 within 0.02 (h3² adds to it)
    for a3, a4 in ((0.1, 3.1), (0.05, 3.15), (0.0, 3.2)):
        x = af.hermite_level(u, *af.hermite_coefficients(a3, a4))
        assert np.sum(wq * x**3) == pytest.approx(a3, rel=0.04, abs=1e-12)
        assert np.sum(wq * x**4) == pytest.approx(a4, abs=0.02)


def test_hermite_damage_factor_is_the_rayleigh_expectation_for_a_narrow_band():
    """One line: Dirlik's amplitudes are Rayleigh, so the factor is
    E[(κ(u + h4(u³ − 3u)))^m]/E[u^m] over u ~ Rayleigh, by quadrature."""
    w = np.linspace(0.5, 0.7, 201)
    s = np.exp(-(((w - 0.6) / 0.002) ** 2))
    _, h4, kappa = af.hermite_coefficients(0.0, 3.5)
    m = 3.0
    assert af.hermite_damage_factor(w, s, m, 0.0, 1.0) == pytest.approx(1.0, rel=1e-9)

    def rayleigh(f):
        return integrate.quad(lambda u: f(u) * u * math.exp(-u * u / 2), 0.0, 40.0)[0]

    want = rayleigh(lambda u: abs(kappa * (u + h4 * (u**3 - 3 * u))) ** m) / rayleigh(
        lambda u: u**m
    )
    assert want > 1.0
    assert af.hermite_damage_factor(w, s, m, h4, kappa) == pytest.approx(want, rel=5e-3)


def test_expected_maximum_of_n_rayleigh_maxima():
    """√(2 ln N) + γ/√(2 ln N) against E[max] = ∫(1 − F^N) of N independent Rayleigh
    maxima: within 1.5 % at N = 20 (200 s at Tz 10 s) and 0.5 % at N = 1000."""
    for n, tol in ((20, 0.015), (1000, 0.005)):
        exact = integrate.quad(lambda x, n=n: 1.0 - (1.0 - math.exp(-x * x / 2)) ** n, 0, 20)[0]
        assert af.gaussian_expected_maximum(10.0, 10.0 * n) == pytest.approx(exact, rel=tol)


def test_flife_dirlik_is_the_library_s_on_a_broad_band():
    """Two peaks (α2 ≈ 0.5): FLife's Dirlik with the amplitude intercept a/2^m is the
    library's to round-off (the page's check column)."""
    curve = fatigue_curve("dnv-six-strand")
    w = np.linspace(0.05, 6.0, 600)
    s = np.exp(-(((w - 0.6) / 0.1) ** 2)) + 0.3 * np.exp(-(((w - 3.0) / 0.3) ** 2))
    s = s * 1e14  # [Pa²·s/rad]
    want = float(damage_rate_dirlik(w, s, curve))
    assert af.dirlik_flife(w, s, curve) == pytest.approx(want, rel=1e-9)
