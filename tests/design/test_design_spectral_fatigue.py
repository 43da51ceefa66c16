"""Tests of stochcable.design.spectral_fatigue: closed forms, FLife, scaling, shapes."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
from scipy import integrate, special

from stochcable.design import (
    damage_rate,
    damage_rate_benasciutti_tovo,
    damage_rate_dirlik,
    damage_rate_narrow_band,
    damage_rate_wirsching_light,
    fatigue_curve,
    fatigue_curve_user,
    spectral_moments_along,
)
from stochcable.errors import InputError
from stochcable.sea.moments import spectral_moments
from stochcable.sea.spectra import spectrum_jonswap

METHODS = {
    "narrow_band": damage_rate_narrow_band,
    "wirsching_light": damage_rate_wirsching_light,
    "dirlik": damage_rate_dirlik,
    "benasciutti_tovo": damage_rate_benasciutti_tovo,
}
W = np.linspace(0.02, 3.0, 800)
STRESS = 20e6  # std of the stress process [Pa]


def _narrow():
    """JONSWAP (Hs 6 m, Tp 10 s, γ 3.3) scaled to a stress spectrum of σ = 20 MPa."""
    s = spectrum_jonswap(W, 6.0, 10.0)
    return s * STRESS**2 / np.trapezoid(s, W)


def _wide():
    """Two peaks: the JONSWAP sea plus a low-frequency component at 0.12 rad/s with
    the same variance (as slow drift of a moored vessel)."""
    lf = np.exp(-0.5 * ((W - 0.12) / 0.02) ** 2)
    return _narrow() + lf * STRESS**2 / np.trapezoid(lf, W)


def test_moments_equal_sea_moments():
    dens = np.stack([_narrow(), _wide()])
    mom = spectral_moments_along(W, dens)
    for i in range(2):
        ref = spectral_moments(W, dens[i], orders=(0, 1, 2, 4))
        got = [mom[k][i] for k in ("m0", "m1", "m2", "m4")]
        # the same trapezoid rule summed in another order: round-off
        np.testing.assert_allclose(got, ref, rtol=1e-13)


@pytest.mark.parametrize("name", ["dnv-studless", "dnv-spiral-strand"])
def test_narrow_band_closed_form(name):
    c = fatigue_curve(name)
    m = c.slopes[0]
    a = 10.0 ** c.log10_intercepts[0]
    for dens in (_narrow(), _wide()):
        m0, m2 = spectral_moments(W, dens, orders=(0, 2))
        nu0 = math.sqrt(m2 / m0) / (2 * math.pi)
        closed = nu0 * (2 * math.sqrt(2 * m0)) ** m * special.gamma(1 + m / 2) / a
        # the same formula through log-gamma and incomplete gamma: round-off only
        assert float(damage_rate_narrow_band(W, dens, c)) == pytest.approx(closed, rel=1e-12)


def _flife_life(spectrum, method, c_amp, k):
    """Life [s] from FLife on the same spectrum.  FLife takes a one-sided PSD in Hz,
    G(f) = 2π S(ω) at f = ω/2π (the same variance and moments), and curves in
    amplitudes, N = C s^-k: with ranges S = 2s, C = a/2^m."""
    import FLife

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        sd = FLife.SpectralData(input={"PSD": 2 * np.pi * spectrum, "f": W / (2 * np.pi)})
        est = {
            "narrow_band": lambda: FLife.Narrowband(sd).get_life(c_amp, k),
            "wirsching_light": lambda: FLife.WirschingLight(sd).get_life(c_amp, k),
            "dirlik": lambda: FLife.Dirlik(sd).get_life(c_amp, k),
            "benasciutti_tovo": lambda: FLife.TovoBenasciutti(sd).get_life(
                c_amp, k, method="method 2"
            ),
        }[method]
        return est()


@pytest.mark.parametrize("method", sorted(METHODS))
@pytest.mark.parametrize("which", ["narrow", "wide"])
def test_matches_flife(method, which):
    dens = _narrow() if which == "narrow" else _wide()
    dens_mpa = dens / 1e12  # FLife in MPa, the curve's table units
    a_d, m = 6.0e10, 3.0  # DNV studless chain, a_D in MPa^m
    c = fatigue_curve("dnv-studless")
    ours = float(METHODS[method](W, dens, c))  # stress in Pa, curve in Pa
    theirs = 1.0 / _flife_life(dens_mpa, method, a_d / 2**m, m)
    # the same formulas on the same trapezoid moments: agreement to round-off
    assert ours == pytest.approx(theirs, rel=1e-10)


def test_dispatcher_and_vectorized_rows():
    c = fatigue_curve("dnv-six-strand")
    dens = np.stack([_narrow(), np.zeros_like(W), _wide(), 0.25 * _wide()])
    for name, fn in METHODS.items():
        many = damage_rate(W, dens, c, method=name)
        assert many.shape == (4,)
        assert many[1] == 0.0 and np.isfinite(many).all()  # zero spectrum: no damage, no NaN
        rows = [float(fn(W, d, c)) for d in dens]
        np.testing.assert_allclose(many, rows, rtol=1e-13)
        cube = fn(W, dens.reshape(2, 2, -1), c)
        np.testing.assert_allclose(cube, many.reshape(2, 2), rtol=1e-13)
    assert damage_rate(W, _wide(), c, "Benasciutti-Tovo") == damage_rate_benasciutti_tovo(
        W, _wide(), c
    )


@pytest.mark.parametrize("method", sorted(METHODS))
def test_damage_scales_as_std_to_the_m(method):
    c = fatigue_curve("dnv-spiral-strand")  # m = 4.8
    base = float(METHODS[method](W, _wide(), c))
    scaled = float(METHODS[method](W, 9.0 * _wide(), c))  # σ × 3
    # single slope, no endurance limit: exactly 3^m (round-off)
    assert scaled / base == pytest.approx(3.0**4.8, rel=1e-12)


def test_narrow_band_is_upper_bound_of_the_wide_band_methods():
    c = fatigue_curve("dnv-studless")
    nb = float(damage_rate_narrow_band(W, _wide(), c))
    for fn in (damage_rate_dirlik, damage_rate_benasciutti_tovo, damage_rate_wirsching_light):
        assert float(fn(W, _wide(), c)) < nb


def _two_slope():
    # stress in Pa: m1 = 3 above, m2 = 5 below the range at 10^7 cycles, endurance limit
    return fatigue_curve_user(
        "two-slope",
        quantity="stress",
        slope=3.0,
        log10_a=math.log10(6.0e10) + 18.0,
        slope2=5.0,
        transition_cycles=1e7,
        endurance_limit=5e6,
    )


def _quad_damage(pdf_amplitude, rate, curve):
    """rate·∫ p_A(s)/N(2s) ds by adaptive quadrature (independent of the closed forms),
    split at the endurance limit and the slope change."""
    pts = sorted({curve.endurance_limit / 2, curve.transition / 2})
    edges = [0.0, *pts, 40 * STRESS]

    def f(s):
        n = curve.cycles_to_failure(np.array([2 * s]))[0]
        return pdf_amplitude(s) / n if math.isfinite(n) else 0.0

    total = sum(
        integrate.quad(f, lo, hi, epsabs=0, epsrel=1e-12, limit=200)[0]
        for lo, hi in zip(edges[:-1], edges[1:], strict=True)
    )
    return rate * total


def test_two_slope_and_endurance_limit_against_quadrature():
    import FLife

    c = _two_slope()
    dens = _wide()
    m0, m2, m4 = spectral_moments(W, dens, orders=(0, 2, 4))
    nu0 = math.sqrt(m2 / m0) / (2 * math.pi)
    nup = math.sqrt(m4 / m2) / (2 * math.pi)

    # narrow band: Rayleigh amplitudes
    def rayleigh(s):
        return s / m0 * math.exp(-s * s / (2 * m0))

    nb = _quad_damage(rayleigh, nu0, c)
    # quadrature to 1e-12 relative on smooth pieces: agreement to 1e-8
    assert float(damage_rate_narrow_band(W, dens, c)) == pytest.approx(nb, rel=1e-8)

    # Dirlik: FLife's amplitude PDF (an independent implementation of Dirlik's PDF)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        sd = FLife.SpectralData(input={"PSD": 2 * np.pi * dens, "f": W / (2 * np.pi)})
        dk = FLife.Dirlik(sd)
    dirlik = _quad_damage(lambda s: float(dk.get_PDF(s)), nup, c)
    assert float(damage_rate_dirlik(W, dens, c)) == pytest.approx(dirlik, rel=1e-8)

    # the endurance limit and the shallower low-range slope only lower the damage
    single = fatigue_curve("dnv-studless")
    assert float(damage_rate_dirlik(W, dens, c)) < float(damage_rate_dirlik(W, dens, single))


def test_single_frequency_process_falls_back_to_narrow_band():
    dens = np.zeros_like(W)
    dens[300] = 1e14  # all variance on one grid line: α2 = 1
    c = fatigue_curve("dnv-studless")
    nb = float(damage_rate_narrow_band(W, dens, c))
    assert nb > 0.0
    for fn in (damage_rate_dirlik, damage_rate_benasciutti_tovo, damage_rate_wirsching_light):
        # α2 = 1 up to round-off: the wide-band corrections vanish
        assert float(fn(W, dens, c)) == pytest.approx(nb, rel=1e-6)


def test_errors():
    c = fatigue_curve("dnv-studless")
    with pytest.raises(InputError, match="method = 'rainflow': must be one of"):
        damage_rate(W, _narrow(), c, method="rainflow")
    with pytest.raises(InputError, match="curve = 'str': must be a FatigueCurve"):
        damage_rate_dirlik(W, _narrow(), "dnv-studless")
    with pytest.raises(InputError, match="density.*frequency axis last with 800 entries"):
        damage_rate_dirlik(W, _narrow()[:-1], c)
    with pytest.raises(InputError, match="density.*must be >= 0"):
        damage_rate_dirlik(W, -_narrow(), c)
    with pytest.raises(InputError, match="omega.*must be strictly increasing"):
        damage_rate_narrow_band(W[::-1], _narrow(), c)
    with pytest.raises(InputError, match="density.*must be finite"):
        damage_rate_narrow_band(W, np.full_like(W, np.nan), c)
