"""One-sided wave spectra S(ω) and their moments.

Every spectrum is a pure function of the angular frequency ω [rad/s] returning the
one-sided spectral density [m²·s/rad] (or [unit²·s/rad] in consistent units) with the
same shape as ``omega``.  Frequencies ω <= 0 give zero density (no NaN, no warning).
Conventions (DESIGN.md "Wave spectra"): m_n = ∫₀^∞ ωⁿ S(ω) dω, Hs = 4√m0,
Tz = 2π√(m0/m2), Tm01 = 2π m0/m1.  The moments and statistics of a sampled spectrum
(:func:`spectral_moments`, :func:`spectrum_statistics`) are in :mod:`stochcable.sea.moments`
and re-exported here; the accepted ranges of the parameters in :mod:`stochcable.sea.limits`.

References
----------
Tuah, H. (1982), Cable dynamics in an ocean environment, PhD thesis, Oregon State
University, §5.1 and §6.5 (Pierson–Moskowitz, m0 = 28 ft², ωp = 0.5 rad/s).
Pierson, W. J. and Moskowitz, L. (1964), A proposed spectral form for fully developed
wind seas based on the similarity theory of S. A. Kitaigorodskii, J. Geophys. Res. 69(24).
Hasselmann, K. et al. (1973), Measurements of wind-wave growth and swell decay during
the Joint North Sea Wave Project (JONSWAP), Dtsch. Hydrogr. Z. A8(12).
Ochi, M. K. and Hubble, E. N. (1976), Six-parameter wave spectra, Proc. 15th ICCE.
ITTC (1978), 15th ITTC Seakeeping Committee (ISSC / ITTC two-parameter spectrum).
"""

from __future__ import annotations

import functools
import math

import numpy as np
from numpy.typing import ArrayLike

from stochcable import validation as v
from stochcable.errors import InputError
from stochcable.sea.limits import (
    GAMMA_RANGE,
    HEIGHT_RANGE,
    M0_RANGE,
    OMEGA_P_RANGE,
    PERIOD_RANGE,
    SHAPE_RANGE,
    SIGMA_RANGE,
    WIND_SPEED_RANGE,
)
from stochcable.sea.moments import SpectrumStatistics, spectral_moments, spectrum_statistics

__all__ = [
    "G_STANDARD",
    "PM_TZ_OVER_TP",
    "PM_TM01_OVER_TP",
    "spectrum_pierson_moskowitz",
    "spectrum_pierson_moskowitz_m0",
    "spectrum_pierson_moskowitz_wind",
    "spectrum_jonswap",
    "spectrum_bretschneider",
    "spectrum_issc",
    "spectrum_ochi_hubble",
    "spectrum_table",
    "spectral_moments",
    "spectrum_statistics",
    "moments_pierson_moskowitz",
    "SpectrumStatistics",
    "omega_grid",
]

G_STANDARD = 9.80665
"""Standard gravity. [m/s²]"""

PM_TZ_OVER_TP = (5.0 * math.pi / 4.0) ** -0.25
"""Tz/Tp of the Pierson–Moskowitz shape, (5π/4)^(-1/4) = 0.71040... [-]"""

PM_TM01_OVER_TP = 1.0 / ((5.0 / 4.0) ** 0.25 * math.gamma(0.75))
"""Tm01/Tp of the Pierson–Moskowitz shape, 1/((5/4)^(1/4) Γ(3/4)) = 0.77154... [-]"""

# Below x = ω/ωp = 0.15 the PM factor exp(-1.25 x⁻⁴) underflows to exactly 0.0 in
# float64 (1.25/0.15⁴ = 2469 > 745), so those entries are left at zero and x⁻⁵ never
# overflows.
_PM_X_MIN = 0.15

# Gauss–Legendre nodes for the JONSWAP normalization integral (see _jonswap_integral).
_GL_X, _GL_W = np.polynomial.legendre.leggauss(80)


def _omega_array(omega: ArrayLike) -> np.ndarray:
    """Float array of ω (any shape); NaN/inf rejected."""
    w = np.asarray(omega, dtype=float)
    if not np.isfinite(w).all():
        raise InputError("omega", omega, "rad/s", "must be finite (not NaN or inf)")
    return w


def _pm_shape(w: np.ndarray, omega_p: float, scale: float) -> np.ndarray:
    """scale · x⁻⁵ exp(−1.25 x⁻⁴), x = ω/ωp, zero where x < 0.15 (incl. ω <= 0).

    In-place arithmetic on one output and one work array (this runs on 2^19-point
    grids in the sea simulation).
    """
    shape = w.shape
    w = w.reshape(-1)
    x_min = _PM_X_MIN * omega_p
    out = np.maximum(w, x_min)
    np.divide(omega_p, out, out=out)  # r = ωp/ω
    tmp = np.multiply(out, out)
    tmp *= tmp  # r⁴
    out *= tmp  # r⁵
    tmp *= -1.25
    np.exp(tmp, out=tmp)  # exp(−1.25 r⁴), 0.0 below x = 0.2
    out *= tmp
    out *= scale
    if out.size and w.min() < x_min:
        np.copyto(out, 0.0, where=w < x_min)
    return out.reshape(shape)


def spectrum_pierson_moskowitz(omega: ArrayLike, hs: float, tp: float) -> np.ndarray:
    """Pierson–Moskowitz spectrum in significant wave height and peak period.

    Parameters
    ----------
    omega : array_like
        Angular frequencies. [rad/s]
    hs : float
        Significant wave height, 4√m0. [m]
    tp : float
        Peak period, 2π/ωp. [s]

    Returns
    -------
    numpy.ndarray
        One-sided spectral density, same shape as ``omega``. [m²·s/rad]

    Notes
    -----
    S(ω) = (5/16) Hs² ωp⁴ ω⁻⁵ exp[−(5/4)(ωp/ω)⁴], ωp = 2π/Tp (DESIGN.md; the
    two-parameter form of Pierson & Moskowitz 1964 used by Tuah (1982), §6.5).
    Closed forms: m0 = Hs²/16, m_n = (Hs²/64) ωpⁿ (5/4)^(n/4) Γ(1 − n/4) for n < 4
    (:func:`moments_pierson_moskowitz`), Tz = (5π/4)^(−1/4) Tp = 0.7104 Tp, peak at ωp.
    """
    hs = v.in_range("hs", hs, "m", *HEIGHT_RANGE)
    tp = v.in_range("tp", tp, "s", *PERIOD_RANGE)
    w = _omega_array(omega)
    wp = 2.0 * math.pi / tp
    return _pm_shape(w, wp, 5.0 / 16.0 * hs * hs / wp)


def spectrum_pierson_moskowitz_m0(omega: ArrayLike, m0: float, omega_p: float) -> np.ndarray:
    """Pierson–Moskowitz spectrum in zeroth moment and peak frequency (Tuah's (1982) form).

    Parameters
    ----------
    omega : array_like
        Angular frequencies. [rad/s]
    m0 : float
        Zeroth spectral moment (variance of the elevation), Hs²/16. [m²]
    omega_p : float
        Peak angular frequency. [rad/s]

    Returns
    -------
    numpy.ndarray
        One-sided spectral density. [m²·s/rad]

    Notes
    -----
    S(ω) = 5 m0 ωp⁴ ω⁻⁵ exp[−(5/4)(ωp/ω)⁴], the PM shape with Hs = 4√m0; Tuah
    (1982), §6.5 (Fig. 6.5-6) uses m0 = 28 ft², ωp = 0.5 rad/s (Hurricane Carla record).
    """
    m0 = v.in_range("m0", m0, "m²", *M0_RANGE)
    wp = v.in_range("omega_p", omega_p, "rad/s", *OMEGA_P_RANGE)
    w = _omega_array(omega)
    return _pm_shape(w, wp, 5.0 * m0 / wp)


def spectrum_pierson_moskowitz_wind(
    omega: ArrayLike, wind_speed: float, g: float = G_STANDARD
) -> np.ndarray:
    """Pierson–Moskowitz fully developed sea from the wind speed at 19.5 m.

    Parameters
    ----------
    omega : array_like
        Angular frequencies. [rad/s]
    wind_speed : float
        Mean wind speed 19.5 m above the sea surface. [m/s]
    g : float, default 9.80665
        Acceleration of gravity. [m/s²]

    Returns
    -------
    numpy.ndarray
        One-sided spectral density. [m²·s/rad]

    Notes
    -----
    S(ω) = α g² ω⁻⁵ exp[−0.74 (g/(U ω))⁴], α = 0.0081 (Pierson & Moskowitz 1964).
    This is the PM shape with ωp = (0.74·4/5)^(1/4) g/U and m0 = α g²/(4·0.74) (g/U)⁻⁴.
    """
    u = v.in_range("wind_speed", wind_speed, "m/s", *WIND_SPEED_RANGE)
    g = v.positive("g", g, "m/s²")
    w = _omega_array(omega)
    alpha = 0.0081
    wp = (0.74 * 4.0 / 5.0) ** 0.25 * g / u
    # α g² ω⁻⁵ e^{-0.74 (g/Uω)^4} = α g² ωp⁻⁵ x⁻⁵ e^{-1.25 x⁻⁴}
    return _pm_shape(w, wp, alpha * g * g / wp**5)


#: Half-width of the JONSWAP peak factor's live band in σ (:func:`_apply_peak`): beyond
#: it −d²/2 < −745.2, so r = exp(−d²/2) underflows to 0.0 and γ^r = 1.0 exactly. [-]
_PEAK_BAND = 40.0


def _jonswap_peak(x: np.ndarray, gamma: float, sigma_a: float, sigma_b: float) -> np.ndarray:
    """γ^r with r = exp(−(x−1)²/(2σ²)), σ = σa for x <= 1 else σb (x = ω/ωp)."""
    sigma = np.where(x <= 1.0, sigma_a, sigma_b)
    d = (x - 1.0) / sigma
    return np.exp(math.log(gamma) * np.exp(-0.5 * d * d))


def _apply_peak(
    out: np.ndarray, w: np.ndarray, wp: float, gamma: float, sigma_a: float, sigma_b: float
) -> None:
    """``out *= γ^r`` (:func:`_jonswap_peak`, x = ω/ωp) in place, evaluated only in the
    peak's live band ``_PM_X_MIN`` <= x <= 1 + ``_PEAK_BAND``·σb, x >= 1 −
    ``_PEAK_BAND``·σa: outside it ``out`` is 0 (the PM shape's cut) or γ^r is 1.0
    exactly, so the product is the same to the bit as over every point (on the mesh
    check's 16001-point grid of :func:`stochcable.fidelity.pilot.sea_omega2` a fifth
    of the points)."""
    x = w.reshape(-1) / wp
    lo = max(_PM_X_MIN, 1.0 - _PEAK_BAND * sigma_a)
    live = np.flatnonzero((x >= lo) & (x <= 1.0 + _PEAK_BAND * sigma_b))
    if live.size == x.size:
        out *= _jonswap_peak(w / wp, gamma, sigma_a, sigma_b)
    elif live.size:
        flat = out.reshape(-1)
        flat[live] *= _jonswap_peak(x[live], gamma, sigma_a, sigma_b)


@functools.lru_cache(maxsize=256)
def _jonswap_integral(gamma: float, sigma_a: float, sigma_b: float) -> float:
    """I = ∫₀^∞ (5/16) x⁻⁵ e^{−1.25x⁻⁴} γ^r(x) dx (x = ω/ωp); I = 1/16 for γ = 1.

    Written as 1/16 + ∫ (5/16) x⁻⁵ e^{−1.25x⁻⁴} (γ^r − 1) dx; the second integrand is
    confined to |x − 1| < 12σ (γ^r − 1 < 1e-28 outside), integrated with 80-point
    Gauss–Legendre on each side of the kink at x = 1: exact to round-off.
    """
    if gamma == 1.0:
        return 1.0 / 16.0
    total = 1.0 / 16.0
    for lo, hi in ((max(_PM_X_MIN, 1.0 - 12.0 * sigma_a), 1.0), (1.0, 1.0 + 12.0 * sigma_b)):
        if hi <= lo:
            continue
        x = 0.5 * (hi - lo) * _GL_X + 0.5 * (hi + lo)
        pm = 5.0 / 16.0 * x**-5 * np.exp(-1.25 * x**-4)
        f = pm * np.expm1(
            math.log(gamma) * np.exp(-0.5 * ((x - 1.0) / np.where(x <= 1.0, sigma_a, sigma_b)) ** 2)
        )
        total += 0.5 * (hi - lo) * float(_GL_W @ f)
    return total


def spectrum_jonswap(
    omega: ArrayLike,
    hs: float,
    tp: float,
    gamma: float = 3.3,
    sigma_a: float = 0.07,
    sigma_b: float = 0.09,
) -> np.ndarray:
    """JONSWAP spectrum normalized so that 4√m0 equals ``hs`` exactly.

    Parameters
    ----------
    omega : array_like
        Angular frequencies. [rad/s]
    hs : float
        Significant wave height, 4√m0. [m]
    tp : float
        Peak period. [s]
    gamma : float, default 3.3
        Peak enhancement factor, in [1, 20] (γ = 1 is Pierson–Moskowitz). [-]
    sigma_a : float, default 0.07
        Spectral width below the peak (ω <= ωp), in [0.001, 1]. [-]
    sigma_b : float, default 0.09
        Spectral width above the peak (ω > ωp), in [0.001, 1]. [-]

    Returns
    -------
    numpy.ndarray
        One-sided spectral density. [m²·s/rad]

    Notes
    -----
    S(ω) = C(γ) S_PM(ω; Hs, Tp) γ^r, r = exp[−(ω − ωp)²/(2σ²ωp²)] (Hasselmann et al.
    1973), with C = (1/16)/I where I = ∫ (5/16)x⁻⁵e^{−1.25x⁻⁴}γ^r dx is evaluated by
    Gauss–Legendre quadrature to round-off (not the approximate 1 − 0.287 ln γ), so
    m0 = Hs²/16 for every γ, σa, σb.
    """
    hs = v.in_range("hs", hs, "m", *HEIGHT_RANGE)
    tp = v.in_range("tp", tp, "s", *PERIOD_RANGE)
    gamma = v.in_range("gamma", gamma, "-", *GAMMA_RANGE)
    sigma_a = v.in_range("sigma_a", sigma_a, "-", *SIGMA_RANGE)
    sigma_b = v.in_range("sigma_b", sigma_b, "-", *SIGMA_RANGE)
    w = _omega_array(omega)
    wp = 2.0 * math.pi / tp
    c = (1.0 / 16.0) / _jonswap_integral(gamma, sigma_a, sigma_b)
    out = _pm_shape(w, wp, c * 5.0 / 16.0 * hs * hs / wp)
    if gamma != 1.0:
        _apply_peak(out, w, wp, gamma, sigma_a, sigma_b)
    return out


def spectrum_bretschneider(omega: ArrayLike, hs: float, tp: float) -> np.ndarray:
    """Bretschneider (two-parameter) spectrum in Hs and Tp.

    Parameters
    ----------
    omega : array_like
        Angular frequencies. [rad/s]
    hs : float
        Significant wave height. [m]
    tp : float
        Peak period. [s]

    Returns
    -------
    numpy.ndarray
        One-sided spectral density. [m²·s/rad]

    Notes
    -----
    S(ω) = (5/16) Hs² ωp⁴ ω⁻⁵ exp[−(5/4)(ωp/ω)⁴]: the same shape as
    :func:`spectrum_pierson_moskowitz`, with Hs and Tp independent (a developing or
    decaying sea) rather than tied to a wind speed.
    """
    return spectrum_pierson_moskowitz(omega, hs, tp)


def spectrum_issc(omega: ArrayLike, hs: float, t1: float) -> np.ndarray:
    """ISSC / ITTC two-parameter spectrum in Hs and the mean period T1 = Tm01.

    Parameters
    ----------
    omega : array_like
        Angular frequencies. [rad/s]
    hs : float
        Significant wave height. [m]
    t1 : float
        Mean period T1 = Tm01 = 2π m0/m1. [s]

    Returns
    -------
    numpy.ndarray
        One-sided spectral density. [m²·s/rad]

    Notes
    -----
    ITTC (1978): S = 173 Hs² T1⁻⁴ ω⁻⁵ exp(−691 T1⁻⁴ ω⁻⁴); the rounded constants are the
    PM shape with Tp = T1/0.77154 (``PM_TM01_OVER_TP``), which is used here so that
    m0 = Hs²/16 and Tm01 = T1 exactly.
    """
    hs = v.in_range("hs", hs, "m", *HEIGHT_RANGE)
    t1 = v.in_range("t1", t1, "s", *PERIOD_RANGE)
    w = _omega_array(omega)
    wp = 2.0 * math.pi / (t1 / PM_TM01_OVER_TP)  # Tp = T1/0.77154 may pass PERIOD_RANGE
    return _pm_shape(w, wp, 5.0 / 16.0 * hs * hs / wp)


def spectrum_ochi_hubble(
    omega: ArrayLike,
    hs1: float,
    tp1: float,
    lambda1: float,
    hs2: float,
    tp2: float,
    lambda2: float,
) -> np.ndarray:
    """Ochi–Hubble six-parameter (two-peak: swell + wind sea) spectrum.

    Parameters
    ----------
    omega : array_like
        Angular frequencies. [rad/s]
    hs1, hs2 : float
        Significant wave heights of the low- and high-frequency components. [m]
    tp1, tp2 : float
        Peak periods of the components. [s]
    lambda1, lambda2 : float
        Shape parameters (peakedness; λ = 1 is Pierson–Moskowitz). [-]

    Returns
    -------
    numpy.ndarray
        One-sided spectral density. [m²·s/rad]

    Notes
    -----
    Ochi & Hubble (1976):
    S(ω) = ¼ Σⱼ [((4λⱼ+1)/4) ωⱼ⁴]^λⱼ / Γ(λⱼ) · Hsⱼ² / ω^(4λⱼ+1) · exp[−((4λⱼ+1)/4)(ωⱼ/ω)⁴],
    ωⱼ = 2π/Tpⱼ, evaluated in logarithms (no overflow for large λ).  Each term
    integrates to Hsⱼ²/16 exactly, so m0 = (Hs1² + Hs2²)/16.
    """
    pars = []
    for j, (hs, tp, lam) in enumerate(((hs1, tp1, lambda1), (hs2, tp2, lambda2)), start=1):
        hs = v.in_range(f"hs{j}", hs, "m", 0.0, HEIGHT_RANGE[1])
        if 0.0 < hs < HEIGHT_RANGE[0]:
            raise InputError(f"hs{j}", hs, "m", f"must be 0 or >= {HEIGHT_RANGE[0]:g}")
        tp = v.in_range(f"tp{j}", tp, "s", *PERIOD_RANGE)
        lam = v.in_range(f"lambda{j}", lam, "-", *SHAPE_RANGE)
        pars.append((hs, tp, lam))
    if pars[0][0] == 0.0 and pars[1][0] == 0.0:
        raise InputError("hs1", hs1, "m", "hs1 and hs2 must not both be 0")
    w = _omega_array(omega)
    out = np.zeros(w.shape)
    for hs, tp, lam in pars:
        if hs == 0.0:
            continue
        wp = 2.0 * math.pi / tp
        c = (4.0 * lam + 1.0) / 4.0
        # c ωp⁴ x⁻⁴ underflows exp below x = (c/745)^(1/4); skip those (and ω <= 0).
        x_min = (c / 800.0) ** 0.25 * wp
        mask = w > x_min
        lw = np.log(w[mask] / wp)
        # ¼ c^λ ωp^(4λ) Hs² ω^(−4λ−1) e^{−c (ωp/ω)^4}, with ω = x ωp
        logs = (
            math.log(0.25 * hs * hs / wp)
            + lam * math.log(c)
            - math.lgamma(lam)
            - (4.0 * lam + 1.0) * lw
            - c * np.exp(-4.0 * lw)
        )
        out[mask] += np.exp(logs)
    return out


def _table(omega_table: ArrayLike, density_table: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    wt = v.float_array(
        "omega_table", omega_table, "rad/s", nonnegative=True, increasing=True, min_size=2
    )
    st = v.float_array("density_table", density_table, "m²·s/rad", nonnegative=True, min_size=2)
    if st.shape != wt.shape:
        raise InputError(
            "density_table",
            density_table,
            "m²·s/rad",
            f"must have the same length as omega_table ({wt.size}), got {st.size}",
        )
    return wt, st


def spectrum_table(
    omega: ArrayLike, omega_table: ArrayLike, density_table: ArrayLike
) -> np.ndarray:
    """User-tabulated spectrum, linearly interpolated, zero outside the table.

    Parameters
    ----------
    omega : array_like
        Angular frequencies. [rad/s]
    omega_table : array_like
        Tabulated frequencies, strictly increasing, >= 0. [rad/s]
    density_table : array_like
        Tabulated one-sided density, >= 0, same length. [m²·s/rad]

    Returns
    -------
    numpy.ndarray
        One-sided spectral density. [m²·s/rad]
    """
    wt, st = _table(omega_table, density_table)
    w = _omega_array(omega)
    out = np.interp(w, wt, st, left=0.0, right=0.0)
    out[w <= 0.0] = 0.0
    return out


def moments_pierson_moskowitz(
    hs: float, tp: float, orders: tuple[int, ...] = (0, 1, 2, 3)
) -> np.ndarray:
    """Closed-form moments of the Pierson–Moskowitz spectrum (orders < 4).

    Parameters
    ----------
    hs : float
        Significant wave height. [m]
    tp : float
        Peak period. [s]
    orders : tuple of int, default (0, 1, 2, 3)
        Moment orders n < 4. [-]

    Returns
    -------
    numpy.ndarray
        m_n = (Hs²/64) ωpⁿ (5/4)^(n/4) Γ(1 − n/4). [m²·(rad/s)ⁿ]
    """
    hs = v.in_range("hs", hs, "m", *HEIGHT_RANGE)
    tp = v.in_range("tp", tp, "s", *PERIOD_RANGE)
    wp = 2.0 * math.pi / tp
    res = []
    for n in orders:
        n = int(n)
        if n >= 4 or n < 0:
            raise InputError("orders", orders, "-", "closed-form PM moments need 0 <= n < 4")
        # (5/16) Hs² ωp⁴ · ¼ B^((n−4)/4) Γ(1 − n/4), B = (5/4) ωp⁴
        b = 1.25 * wp**4
        res.append(5.0 / 64.0 * hs * hs * wp**4 * b ** ((n - 4) / 4.0) * math.gamma(1.0 - n / 4.0))
    return np.array(res)


def omega_grid(tp: float, count: int = 200, omega_max: float | None = None) -> np.ndarray:
    """Default frequency grid for a spectrum with peak period ``tp``.

    Parameters
    ----------
    tp : float
        Peak period. [s]
    count : int, default 200
        Number of frequencies. [-]
    omega_max : float, optional
        Largest frequency; default 6 ωp (PM keeps ω⁻⁵ tail < 0.1 % of m0 above it). [rad/s]

    Returns
    -------
    numpy.ndarray
        ω_i = i ω_max/count, i = 1 … count (zero excluded). [rad/s]
    """
    tp = v.in_range("tp", tp, "s", *PERIOD_RANGE)
    count = v.positive_int("count", count, minimum=2)
    if omega_max is None:
        omega_max = 6.0 * 2.0 * math.pi / tp
    omega_max = v.positive("omega_max", omega_max, "rad/s")
    return omega_max / count * np.arange(1, count + 1)
