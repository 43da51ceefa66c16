"""Tests of stochcable.sea.spectra against closed forms and independent quadrature."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
from scipy.integrate import quad
from scipy.optimize import minimize_scalar

from stochcable.errors import InputError
from stochcable.sea import spectra as sp

# Published constants (rounded in their sources)
PM_TZ_TP_PUBLISHED = 0.7104  # DESIGN.md / DNV-RP-C205 Tz = 0.7104 Tp for PM
PM_WIND_HS_PUBLISHED = 0.21  # Pierson & Moskowitz 1964: Hs = 0.21 U19.5²/g
PM_WIND_WP_PUBLISHED = 0.877  # ωp = 0.877 g/U19.5
ITTC_1978_A, ITTC_1978_B = 173.0, 691.0  # ISSC: 173 Hs²/T1⁴ ω⁻⁵ exp(−691/(T1⁴ω⁴))


def _quad_moment(f, n, wp):
    """∫₀^∞ ωⁿ f(ω) dω by adaptive quadrature split at the peak (independent of the grid)."""
    g = lambda w: w**n * float(f(np.array([w]))[0])  # noqa: E731
    parts = [
        quad(g, 0.0, wp, limit=400, epsabs=0, epsrel=1e-12)[0],
        quad(g, wp, 20 * wp, limit=400, epsabs=0, epsrel=1e-12)[0],
        quad(g, 20 * wp, np.inf, limit=400)[0],
    ]
    return sum(parts)


@pytest.mark.parametrize("hs,tp", [(6.0, 10.0), (0.5, 3.0), (15.0, 18.0)])
def test_pm_m0_closed_form(hs, tp):
    wp = 2 * math.pi / tp
    m0 = _quad_moment(lambda w: sp.spectrum_pierson_moskowitz(w, hs, tp), 0, wp)
    # quad tolerance 1e-12 per piece; closed form m0 = Hs²/16 is exact
    assert m0 == pytest.approx(hs * hs / 16.0, rel=1e-10)


def test_pm_moments_and_tz_closed_form():
    hs, tp = 6.0, 10.0
    wp = 2 * math.pi / tp
    closed = sp.moments_pierson_moskowitz(hs, tp, orders=(0, 1, 2, 3))
    for n in range(4):
        num = _quad_moment(lambda w: sp.spectrum_pierson_moskowitz(w, hs, tp), n, wp)
        assert num == pytest.approx(closed[n], rel=1e-9)  # quadrature error only
    tz = 2 * math.pi * math.sqrt(closed[0] / closed[2])
    assert tz / tp == pytest.approx(sp.PM_TZ_OVER_TP, rel=1e-14)
    # the published 0.7104 is rounded to 4 digits
    assert abs(sp.PM_TZ_OVER_TP - PM_TZ_TP_PUBLISHED) < 5e-5


def test_pm_statistics_on_grid_truncation_bound():
    from scipy.special import gammainc

    hs, tp = 6.0, 10.0
    wp = 2 * math.pi / tp
    w = np.linspace(0, 20 * wp, 40001)
    st = sp.spectrum_statistics(w, sp.spectrum_pierson_moskowitz(w, hs, tp))
    # Moments truncated at ω_max in closed form: the tail above ω_max is the lower incomplete
    # gamma part, m_n(ω_max) = m_n [1 − P(1 − n/4, (5/4)(ωp/ω_max)⁴)]; what remains is the
    # trapezoid error, O(Δω²) with Δω = ωp/2000: < 1e-7 relative.
    x = 1.25 * (wp / w[-1]) ** 4
    closed = sp.moments_pierson_moskowitz(hs, tp) * (1 - gammainc(1 - np.arange(4) / 4, x))
    np.testing.assert_allclose([st.m0, st.m1, st.m2, st.m3], closed, rtol=1e-7)
    assert st.hs == pytest.approx(hs, rel=1e-5)  # m0 tail 7.8e-6 of m0
    assert st.tp == pytest.approx(tp, rel=1e-3)  # grid peak within Δω/ωp
    assert st.tz == pytest.approx(2 * math.pi * math.sqrt(closed[0] / closed[2]), rel=1e-7)
    assert st.tm01 == pytest.approx(2 * math.pi * closed[0] / closed[1], rel=1e-7)
    assert 0 < st.bandwidth < 1
    assert set(st.as_dict()) == {
        "m0",
        "m1",
        "m2",
        "m3",
        "m4",
        "hs",
        "tz",
        "tm01",
        "tp",
        "bandwidth",
    }


@pytest.mark.parametrize(
    "fn",
    [
        lambda w: sp.spectrum_pierson_moskowitz(w, 6.0, 10.0),
        lambda w: sp.spectrum_jonswap(w, 6.0, 10.0, 3.3),
        lambda w: sp.spectrum_jonswap(w, 6.0, 10.0, 7.0),
    ],
)
def test_peak_at_omega_p(fn):
    wp = 2 * math.pi / 10.0
    res = minimize_scalar(
        lambda w: -float(fn(np.array([w]))[0]),
        bounds=(0.5 * wp, 1.5 * wp),
        method="bounded",
        options={"xatol": 1e-10},
    )
    assert res.x == pytest.approx(wp, rel=1e-6)  # xatol-limited


@pytest.mark.parametrize("gamma", [1.0, 3.3, 7.0])
def test_jonswap_hs_exact(gamma):
    hs, tp = 6.0, 10.0
    f = lambda w: sp.spectrum_jonswap(w, hs, tp, gamma)  # noqa: E731
    m0 = _quad_moment(f, 0, 2 * math.pi / tp)
    # normalization by the exact integral: only quad's error (~1e-12) remains
    assert 4 * math.sqrt(m0) == pytest.approx(hs, rel=1e-10)


def test_jonswap_gamma1_equals_pm_and_other_sigmas():
    w = np.linspace(0, 4, 801)
    np.testing.assert_array_equal(
        sp.spectrum_jonswap(w, 4.0, 8.0, 1.0), sp.spectrum_pierson_moskowitz(w, 4.0, 8.0)
    )
    f = lambda x: sp.spectrum_jonswap(x, 3.0, 7.0, 5.0, 0.2, 0.3)  # noqa: E731
    assert _quad_moment(f, 0, 2 * math.pi / 7) == pytest.approx(9 / 16, rel=1e-10)


def test_m0_and_wind_forms():
    w = np.linspace(0, 3, 301)
    np.testing.assert_allclose(
        sp.spectrum_pierson_moskowitz_m0(w, 36 / 16, 2 * math.pi / 10),
        sp.spectrum_pierson_moskowitz(w, 6.0, 10.0),
        rtol=1e-14,
    )
    g, u = 9.80665, 15.0
    f = lambda x: sp.spectrum_pierson_moskowitz_wind(x, u, g)  # noqa: E731
    wp = (0.74 * 0.8) ** 0.25 * g / u
    m0 = _quad_moment(f, 0, wp)
    # published rounded constants (2–3 digits)
    assert 4 * math.sqrt(m0) == pytest.approx(PM_WIND_HS_PUBLISHED * u * u / g, rel=1e-2)
    assert wp == pytest.approx(PM_WIND_WP_PUBLISHED * g / u, rel=1e-3)
    # and the formula itself, evaluated directly
    x = np.array([0.3, 0.8, 2.0])
    direct = 0.0081 * g**2 * x**-5 * np.exp(-0.74 * (g / (u * x)) ** 4)
    np.testing.assert_allclose(f(x), direct, rtol=1e-13)


def test_bretschneider_and_issc():
    w = np.linspace(0.05, 3, 300)
    np.testing.assert_array_equal(
        sp.spectrum_bretschneider(w, 5.0, 9.0), sp.spectrum_pierson_moskowitz(w, 5.0, 9.0)
    )
    hs, t1 = 5.0, 8.0
    f = lambda x: sp.spectrum_issc(x, hs, t1)  # noqa: E731
    wp = 2 * math.pi * sp.PM_TM01_OVER_TP / t1
    m0, m1 = _quad_moment(f, 0, wp), _quad_moment(f, 1, wp)
    assert m0 == pytest.approx(hs * hs / 16, rel=1e-10)
    assert 2 * math.pi * m0 / m1 == pytest.approx(t1, rel=1e-9)
    # ITTC's rounded constants agree to their 3 digits
    itt = ITTC_1978_A * hs**2 / t1**4 * w**-5 * np.exp(-ITTC_1978_B / (t1**4 * w**4))
    assert np.max(np.abs(f(w) - itt)) / f(w).max() < 5e-3


def test_ochi_hubble():
    p = dict(hs1=3.0, tp1=15.0, lambda1=2.5, hs2=4.0, tp2=8.0, lambda2=1.5)
    f = lambda x: sp.spectrum_ochi_hubble(x, **p)  # noqa: E731
    g = lambda w: float(f(np.array([w]))[0])  # noqa: E731
    m0 = (
        sum(
            quad(g, a, b, limit=400, epsabs=0, epsrel=1e-12)[0]
            for a, b in ((0, 0.42), (0.42, 0.79), (0.79, 20))
        )
        + quad(g, 20, np.inf)[0]
    )
    assert m0 == pytest.approx((9 + 16) / 16, rel=1e-10)
    # λ = 1 is Pierson–Moskowitz
    w = np.linspace(0, 3, 301)
    pm = sp.spectrum_pierson_moskowitz(w, 6, 10)
    # log-space vs direct evaluation: round-off of exp(log) ~ 1e-13 relative
    np.testing.assert_allclose(
        sp.spectrum_ochi_hubble(w, 6, 10, 1, 0, 5, 1), pm, rtol=1e-12, atol=1e-14 * pm.max()
    )
    # large λ: no overflow, still finite
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        s = sp.spectrum_ochi_hubble(w, 2, 12, 80.0, 1, 6, 0.5)
    assert np.isfinite(s).all()


def test_nonpositive_omega_zero_no_warning():
    w = np.array([-1.0, 0.0, 1e-300, 1e-3, 0.6])
    with warnings.catch_warnings(), np.errstate(all="raise", under="ignore"):
        warnings.simplefilter("error")
        for s in (
            sp.spectrum_pierson_moskowitz(w, 6, 10),
            sp.spectrum_jonswap(w, 6, 10),
            sp.spectrum_issc(w, 6, 8),
            sp.spectrum_pierson_moskowitz_wind(w, 20.0),
            sp.spectrum_ochi_hubble(w, 3, 15, 2, 4, 8, 1),
            sp.spectrum_table(w, [0.0, 0.5, 1.0], [1.0, 2.0, 0.5]),
        ):
            assert s[0] == 0.0 and s[1] == 0.0 and np.isfinite(s).all()
            assert s[-1] > 0


def test_shape_preserved():
    w = np.linspace(0.1, 2, 12).reshape(3, 4)
    assert sp.spectrum_jonswap(w, 6, 10).shape == (3, 4)
    assert sp.spectrum_pierson_moskowitz(0.6, 6, 10).shape == ()


def test_table_interpolation():
    wt, st = [0.2, 0.5, 1.0], [0.0, 2.0, 1.0]
    s = sp.spectrum_table([0.1, 0.2, 0.35, 0.75, 1.0, 1.2], wt, st)
    np.testing.assert_allclose(s, [0.0, 0.0, 1.0, 1.5, 1.0, 0.0], rtol=1e-15)


def test_spectral_moments_box():
    # box S = 1 on [1, 2]: m_n = (2^(n+1) − 1)/(n+1); sampled as a fine table
    w = np.linspace(0.5, 2.5, 200001)
    s = sp.spectrum_table(w, [1.0 - 1e-9, 1.0, 2.0, 2.0 + 1e-9], [0.0, 1.0, 1.0, 0.0])
    m = sp.spectral_moments(w, s)
    exact = np.array([(2.0 ** (n + 1) - 1) / (n + 1) for n in range(5)])
    np.testing.assert_allclose(m, exact, rtol=2e-5)  # edges resolved to Δω = 1e-5
    st = sp.spectrum_statistics(w, s)
    eps = math.sqrt(1 - exact[2] ** 2 / (exact[0] * exact[4]))
    assert st.bandwidth == pytest.approx(eps, rel=1e-3)


@pytest.mark.parametrize(
    "call,match",
    [
        (
            lambda: sp.spectrum_pierson_moskowitz([1.0], 0.0, 10),
            r"hs = 0.0 \[m\]: must be >= 1e-06",
        ),
        (
            lambda: sp.spectrum_pierson_moskowitz([1.0], -1.0, 10),
            r"hs = -1.0 \[m\]: must be >= 1e-06",
        ),
        (lambda: sp.spectrum_pierson_moskowitz([1.0], 6, 0.0), r"tp = 0.0 \[s\]: must be >= 0.001"),
        (
            lambda: sp.spectrum_pierson_moskowitz([1.0], float("nan"), 10),
            r"hs = nan \[m\]: must be finite",
        ),
        (lambda: sp.spectrum_pierson_moskowitz([np.inf], 6, 10), r"omega .*must be finite"),
        (lambda: sp.spectrum_jonswap([1.0], 6, 10, gamma=0.5), r"gamma = 0.5: must be >= 1"),
        (lambda: sp.spectrum_jonswap([1.0], 6, 10, sigma_a=0.0), r"sigma_a = 0.0: must be >= 0.0"),
        (lambda: sp.spectrum_pierson_moskowitz_m0([1.0], -2, 0.5), r"m0 = -2.*must be >= 6.25e-14"),
        (lambda: sp.spectrum_pierson_moskowitz_wind([1.0], 0.0), r"wind_speed = 0.0 \[m/s\]"),
        (lambda: sp.spectrum_issc([1.0], 6, -8), r"t1 = -8 \[s\]: must be >= 0.001"),
        (
            lambda: sp.spectrum_ochi_hubble([1.0], 0, 10, 1, 0, 5, 1),
            r"hs1 and hs2 must not both be 0",
        ),
        (
            lambda: sp.spectrum_ochi_hubble([1.0], 1, 10, 0, 1, 5, 1),
            r"lambda1 = 0: must be >= 0.01",
        ),
        # values that are positive but would overflow or underflow float64 (found by
        # schemathesis through the service): rejected with the accepted range
        (
            lambda: sp.spectrum_ochi_hubble([1.0], 5e-324, 10, 1, 1, 5, 1),
            r"hs1 = 5e-324 \[m\]: must be 0 or >= 1e-06",
        ),
        (
            lambda: sp.spectrum_pierson_moskowitz([1.0], 6, 5e-324),
            r"tp = 5e-324 \[s\]: must be >= 0.001",
        ),
        (lambda: sp.spectrum_issc([1.0], 6, 5e-324), r"t1 = 5e-324 \[s\]: must be >= 0.001"),
        (
            lambda: sp.spectrum_table([1.0], [0.0, 1.0, 0.5], [1, 1, 1]),
            r"omega_table .*strictly increasing",
        ),
        (
            lambda: sp.spectrum_table([1.0], [0.0, 1.0, 1.0], [1, 1, 1]),
            r"omega_table .*strictly increasing",
        ),
        (lambda: sp.spectrum_table([1.0], [-1.0, 1.0], [1, 1]), r"omega_table .*must be >= 0"),
        (lambda: sp.spectrum_table([1.0], [0.0, 1.0], [1, -1]), r"density_table .*must be >= 0"),
        (lambda: sp.spectrum_table([1.0], [0.0, 1.0], [1, 1, 1]), r"density_table .*same length"),
        (lambda: sp.spectrum_table([1.0], [0.0, np.nan], [1, 1]), r"omega_table .*must be finite"),
        (lambda: sp.spectrum_statistics([0, 1, 2], [0, 0, 0]), r"density .*zero everywhere"),
        (lambda: sp.spectral_moments([0, 1, 2], [0, 1]), r"density .*same length"),
        (lambda: sp.moments_pierson_moskowitz(6, 10, orders=(4,)), r"0 <= n < 4"),
    ],
)
def test_errors(call, match):
    with pytest.raises(InputError, match=match):
        call()


def test_omega_grid():
    w = sp.omega_grid(10.0, 100)
    assert w[0] == pytest.approx(w[-1] / 100) and w[-1] == pytest.approx(6 * 2 * math.pi / 10)
    assert sp.omega_grid(10.0, 4, omega_max=2.0).tolist() == [0.5, 1.0, 1.5, 2.0]


def test_jonswap_peak_band_is_bitwise_the_full_product() -> None:
    """The peak factor evaluated in its live band only (``spectra._apply_peak``) gives
    the same bits as γ^r over every point (outside the band the PM shape is cut to 0
    or r underflows to 0, γ^r = 1.0): on the mesh check's 16001-point grid, an analysis
    grid, a grid through 0 and an unordered 2-D array, for PM-like to narrow peaks;
    the cached normalization integral is its uncached value."""
    from stochcable.fidelity.pilot import _WIDE

    rng = np.random.default_rng(3)
    grids = [_WIDE, np.linspace(0.05, 4.9, 400), np.linspace(0.0, 10.0, 1001),
             rng.uniform(0.0, 5.0, (7, 33))]  # fmt: skip
    for gamma, sa, sb in [(3.3, 0.07, 0.09), (1.5, 0.001, 0.002), (20.0, 1.0, 1.0),
                          (2.0, 0.3, 0.01)]:  # fmt: skip
        for hs, tp in [(1.0, 6.0), (10.0, 15.0), (4.3, 9.7)]:
            wp = 2.0 * math.pi / tp
            c = (1.0 / 16.0) / sp._jonswap_integral.__wrapped__(gamma, sa, sb)
            for w in grids:
                full = sp._pm_shape(w, wp, c * 5.0 / 16.0 * hs * hs / wp)
                full *= sp._jonswap_peak(w / wp, gamma, sa, sb)
                got = sp.spectrum_jonswap(w, hs, tp, gamma, sa, sb)
                assert got.shape == full.shape
                assert got.tobytes() == full.tobytes()
