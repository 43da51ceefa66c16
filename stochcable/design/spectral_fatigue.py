"""Spectral fatigue: damage rate of a stationary Gaussian process from its spectrum.

Four estimators of the rainflow damage rate D/T [1/s] of a zero-mean Gaussian process
with one-sided spectrum S(ω) under a fatigue curve (:class:`~.curves.FatigueCurve`):
narrow band (Rayleigh ranges), Wirsching–Light (narrow band × an empirical factor),
Dirlik (an exponential-and-Rayleigh range PDF fitted to simulations) and
Benasciutti–Tovo (a weighted mean of the narrow-band and range-counting damage).

Every range PDF here is a weighted sum of Rayleigh and exponential densities, so the
Miner integral over each power-law segment of a curve, between the endurance limit,
the slope-change range and infinity, has a closed form in incomplete gamma functions:
two-slope curves and endurance limits are integrated exactly, not by quadrature.
Each function is vectorized over the leading axes of ``density`` (shape
(..., n_omega)).
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
from numpy.typing import ArrayLike
from scipy.special import gammaincc, gammaln

from stochcable import validation as v
from stochcable.errors import InputError

from .curves import FatigueCurve

__all__ = [
    "damage_rate",
    "damage_rate_narrow_band",
    "damage_rate_wirsching_light",
    "damage_rate_dirlik",
    "damage_rate_benasciutti_tovo",
    "spectral_moments_along",
]

_TWO_PI = 2.0 * math.pi
# threshold below which a Dirlik coefficient (D1 or the denominator of R) is taken as
# zero: both vanish together only for a single-frequency (α2 = 1) process
_DEGENERATE = 1e-12


def spectral_moments_along(omega: ArrayLike, density: ArrayLike) -> dict[str, np.ndarray]:
    """Spectral moments m0, m1, m2, m4 of spectra along their last axis.

    Parameters
    ----------
    omega : array_like, shape (n_omega,)
        Frequencies, strictly increasing, >= 0. [rad/s]
    density : array_like, shape (..., n_omega)
        One-sided spectral densities, >= 0. [unit²·s/rad]

    Returns
    -------
    dict of numpy.ndarray
        ``m0``, ``m1``, ``m2``, ``m4``, each of shape (...). [unit²·(rad/s)ⁿ]

    Notes
    -----
    The trapezoid rule on the given grid, as
    :func:`stochcable.sea.moments.spectral_moments` (which takes one spectrum),
    applied along the last axis as one product with the trapezoid weights (equal to
    ``np.trapezoid`` up to the order of the sums, i.e. to round-off).
    """
    w = v.float_array("omega", omega, "rad/s", nonnegative=True, increasing=True, min_size=2)
    s = v.float_array("density", density, "unit²·s/rad", ndim=None, nonnegative=True)
    if s.ndim == 0 or s.shape[-1] != w.size:
        raise InputError(
            "density",
            density,
            "unit²·s/rad",
            f"must have the frequency axis last with {w.size} entries (the size of omega)",
        )
    # trapezoid weights q_j, so that m_n = Σ_j q_j ω_j^n S_j: one matrix product for
    # the four moments of every spectrum
    d = np.diff(w)
    q = np.zeros_like(w)
    q[:-1] += 0.5 * d
    q[1:] += 0.5 * d
    basis = np.stack([q, q * w, q * w * w, q * w**4], axis=-1)
    m = s @ basis
    return {"m0": m[..., 0], "m1": m[..., 1], "m2": m[..., 2], "m4": m[..., 3]}


def _check_curve(curve: object) -> FatigueCurve:
    if not isinstance(curve, FatigueCurve):
        raise InputError("curve", type(curve).__name__, "-", "must be a FatigueCurve")
    return curve


def _safe(x: np.ndarray, ok: np.ndarray) -> np.ndarray:
    """x where ok, 1 elsewhere (so that divisions and logs of masked entries are finite)."""
    return np.where(ok, x, 1.0)


def _rayleigh_part(scale: np.ndarray, m: float, lo: float, hi: float, log10_a: float) -> np.ndarray:
    """∫_lo^hi S^m p(S) dS / a for Rayleigh ranges p = S/σ² exp(−S²/2σ²), σ = scale > 0.

    = (2σ²)^{m/2} Γ(1 + m/2) [Q(1 + m/2, lo²/2σ²) − Q(1 + m/2, hi²/2σ²)] / a, Q the
    regularized upper incomplete gamma function.
    """
    k = 1.0 + 0.5 * m
    two_var = 2.0 * scale * scale
    log_pre = 0.5 * m * np.log(two_var) + gammaln(k) - math.log(10.0) * log10_a
    upper = 0.0 if math.isinf(hi) else gammaincc(k, hi * hi / two_var)
    lower = 1.0 if lo <= 0.0 else gammaincc(k, lo * lo / two_var)
    return np.exp(log_pre) * (lower - upper)


def _exponential_part(
    scale: np.ndarray, m: float, lo: float, hi: float, log10_a: float
) -> np.ndarray:
    """∫_lo^hi S^m p(S) dS / a for exponential ranges p = exp(−S/θ)/θ, θ = scale > 0.

    = θ^m Γ(1 + m) [Q(1 + m, lo/θ) − Q(1 + m, hi/θ)] / a.
    """
    k = 1.0 + m
    log_pre = m * np.log(scale) + gammaln(k) - math.log(10.0) * log10_a
    upper = 0.0 if math.isinf(hi) else gammaincc(k, hi / scale)
    lower = 1.0 if lo <= 0.0 else gammaincc(k, lo / scale)
    return np.exp(log_pre) * (lower - upper)


def _mixture_damage(
    curve: FatigueCurve,
    parts: list[tuple[str, np.ndarray, np.ndarray]],
    factor: Callable[[float], np.ndarray] | None = None,
) -> np.ndarray:
    """Σ_segments Σ_parts rate·weight·E[S^m; segment]/a (× factor(m) per segment)."""
    total = 0.0
    for seg in curve.segments():
        seg_sum = 0.0
        for kind, weight, scale in parts:
            f = _rayleigh_part if kind == "rayleigh" else _exponential_part
            seg_sum = seg_sum + weight * f(scale, seg.slope, seg.lower, seg.upper, seg.log10_a)
        if factor is not None:
            seg_sum = seg_sum * factor(seg.slope)
        total = total + seg_sum
    return total


class _Process:
    """Moments and band parameters of validated spectra, with a mask of the spectra
    that do cycle (m0 > 0 and m2 > 0); masked entries hold harmless values."""

    def __init__(self, omega: ArrayLike, density: ArrayLike) -> None:
        mom = spectral_moments_along(omega, density)
        m0, m1, m2, m4 = mom["m0"], mom["m1"], mom["m2"], mom["m4"]
        self.ok = (m0 > 0.0) & (m2 > 0.0) & (m4 > 0.0)
        ok = self.ok
        m0, m1, m2, m4 = (_safe(x, ok) for x in (m0, m1, m2, m4))
        self.sigma = np.sqrt(m0)
        self.nu0 = np.sqrt(m2 / m0) / _TWO_PI
        self.nup = np.sqrt(m4 / m2) / _TWO_PI
        self.alpha1 = np.minimum(m1 / np.sqrt(m0 * m2), 1.0)
        self.alpha2 = np.minimum(m2 / np.sqrt(m0 * m4), 1.0)
        self.xm = m1 / m0 * np.sqrt(m2 / m4)

    def finish(self, damage: np.ndarray) -> np.ndarray:
        return np.where(self.ok, damage, 0.0)


def damage_rate_narrow_band(
    omega: ArrayLike, density: ArrayLike, curve: FatigueCurve
) -> np.ndarray:
    r"""Narrow-band (Rayleigh) damage rate of a Gaussian process.

    Parameters
    ----------
    omega : array_like, shape (n_omega,)
        Frequencies, strictly increasing, >= 0. [rad/s]
    density : array_like, shape (..., n_omega)
        One-sided spectrum of the curve's quantity (stress [Pa²·s/rad] or tension
        ratio [s/rad]). [unit²·s/rad]
    curve : FatigueCurve
        Fatigue curve.

    Returns
    -------
    numpy.ndarray
        Damage per unit time, shape (...); 0 for a zero spectrum. [1/s]

    Notes
    -----
    Cycles at the zero-upcrossing rate ν0 = √(m2/m0)/2π with Rayleigh amplitudes
    (ranges S = 2A, p(S) = S/(4m0) exp(−S²/8m0)).  For a single slope without
    endurance limit D/T = ν0 (2√(2 m0))^m Γ(1 + m/2)/a (Bendat 1964; e.g.
    DNV-RP-C203 (2016) §F.11).  Conservative against rainflow counting for wide-band
    processes.
    """
    c = _check_curve(curve)
    p = _Process(omega, density)
    return p.finish(_mixture_damage(c, [("rayleigh", p.nu0, 2.0 * p.sigma)]))


def _wirsching_light_factor(alpha2: np.ndarray) -> Callable[[float], np.ndarray]:
    eps = np.sqrt(np.clip(1.0 - alpha2 * alpha2, 0.0, 1.0))

    def factor(m: float) -> np.ndarray:
        a = 0.926 - 0.033 * m
        b = 1.587 * m - 2.323
        return a + (1.0 - a) * (1.0 - eps) ** b

    return factor


def damage_rate_wirsching_light(
    omega: ArrayLike, density: ArrayLike, curve: FatigueCurve
) -> np.ndarray:
    r"""Wirsching–Light damage rate: narrow band times an empirical band factor.

    Parameters
    ----------
    omega, density, curve
        As :func:`damage_rate_narrow_band`.

    Returns
    -------
    numpy.ndarray
        Damage per unit time, shape (...). [1/s]

    Notes
    -----
    Wirsching & Light (1980), "Fatigue under wide band random stresses", J. Struct.
    Div. ASCE 106(7): D = λ(m, ε) D_NB with λ = a(m) + (1 − a(m))(1 − ε)^{b(m)},
    a = 0.926 − 0.033 m, b = 1.587 m − 2.323, ε = √(1 − α2²),
    α2 = m2/√(m0 m4).  For a two-slope curve the factor of each segment's slope
    multiplies that segment's narrow-band damage (a project choice; it reduces to the
    original for one slope).
    """
    c = _check_curve(curve)
    p = _Process(omega, density)
    parts = [("rayleigh", p.nu0, 2.0 * p.sigma)]
    return p.finish(_mixture_damage(c, parts, _wirsching_light_factor(p.alpha2)))


def damage_rate_dirlik(omega: ArrayLike, density: ArrayLike, curve: FatigueCurve) -> np.ndarray:
    r"""Dirlik damage rate of a Gaussian process.

    Parameters
    ----------
    omega, density, curve
        As :func:`damage_rate_narrow_band`.

    Returns
    -------
    numpy.ndarray
        Damage per unit time, shape (...). [1/s]

    Notes
    -----
    Dirlik (1985), "Application of computers in fatigue analysis", PhD thesis,
    University of Warwick.  With Z = S/(2√m0), x_m = (m1/m0)√(m2/m4),
    γ = α2 = m2/√(m0 m4):
    D1 = 2(x_m − γ²)/(1 + γ²), R = (γ − x_m − D1²)/(1 − γ − D1 + D1²),
    D2 = (1 − γ − D1 + D1²)/(1 − R), D3 = 1 − D1 − D2,
    Q = 1.25(γ − D3 − D2 R)/D1, and the rainflow range PDF
    p(Z) = D1/Q e^{−Z/Q} + D2 Z/R² e^{−Z²/2R²} + D3 Z e^{−Z²/2}, counted at the rate
    of peaks ν_p = √(m4/m2)/2π.  For a single-frequency process (γ = 1, where D1 and
    the denominator of R vanish; numerically D1 or the denominator below 1e-12, or
    R >= 1 or Q <= 0, which the moment inequalities exclude otherwise) the narrow-band
    result is returned.
    """
    c = _check_curve(curve)
    p = _Process(omega, density)
    g = p.alpha2
    d1 = np.maximum(2.0 * (p.xm - g * g) / (1.0 + g * g), 0.0)
    den = 1.0 - g - d1 + d1 * d1
    regular = p.ok & (d1 > _DEGENERATE) & (den > _DEGENERATE)
    d1s, dens = _safe(d1, regular), _safe(den, regular)
    r = (g - p.xm - d1s * d1s) / dens
    regular &= r < 1.0
    r = np.where(regular, r, 0.5)
    d2 = dens / (1.0 - r)
    d3 = 1.0 - d1s - d2
    q = 1.25 * (g - d3 - d2 * r) / d1s
    regular &= q > 0.0
    q = _safe(q, regular)
    two_sigma = 2.0 * p.sigma
    parts = [
        ("exponential", p.nup * d1s, two_sigma * q),
        ("rayleigh", p.nup * d2, two_sigma * _safe(np.abs(r), np.abs(r) > 0.0)),
        ("rayleigh", p.nup * d3, two_sigma),
    ]
    dirlik = _mixture_damage(c, parts)
    narrow = _mixture_damage(c, [("rayleigh", p.nu0, two_sigma)])
    return p.finish(np.where(regular, dirlik, narrow))


def damage_rate_benasciutti_tovo(
    omega: ArrayLike, density: ArrayLike, curve: FatigueCurve
) -> np.ndarray:
    r"""Benasciutti–Tovo damage rate (the 2005 weighting).

    Parameters
    ----------
    omega, density, curve
        As :func:`damage_rate_narrow_band`.

    Returns
    -------
    numpy.ndarray
        Damage per unit time, shape (...). [1/s]

    Notes
    -----
    Benasciutti & Tovo (2005), "Spectral methods for lifetime prediction under wide-band
    stationary random processes", Int. J. Fatigue 27(8), 867–877: the rainflow damage
    is approximated by b·D_LC + (1 − b)·D_RC, D_LC the level-crossing (narrow-band)
    damage (rate ν0, Rayleigh ranges of scale 2σ) and D_RC the range-counting damage
    (rate ν_p, Rayleigh ranges of scale 2σα2), with
    b = (α1 − α2)[1.112(1 + α1α2 − (α1 + α2)) e^{2.11 α2} + (α1 − α2)]/(α2 − 1)²,
    α_i = m_i/√(m0 m_{2i}), clipped to [0, 1] (a weight).  For one slope this is
    D = [b + (1 − b) α2^{m−1}] D_NB, the form of FLife's ``TovoBenasciutti``
    ('method 2').  A single-frequency process (α2 = 1) gives D_NB.
    """
    c = _check_curve(curve)
    p = _Process(omega, density)
    a1, a2 = p.alpha1, p.alpha2
    wide = p.ok & (a2 < 1.0 - _DEGENERATE)
    a2s = np.where(wide, a2, 0.5)
    b = (
        (a1 - a2s)
        * (1.112 * (1.0 + a1 * a2s - (a1 + a2s)) * np.exp(2.11 * a2s) + (a1 - a2s))
        / (a2s - 1.0) ** 2
    )
    b = np.where(wide, np.clip(b, 0.0, 1.0), 1.0)
    two_sigma = 2.0 * p.sigma
    parts = [
        ("rayleigh", b * p.nu0, two_sigma),
        ("rayleigh", (1.0 - b) * p.nup, two_sigma * a2s),
    ]
    return p.finish(_mixture_damage(c, parts))


_METHODS = {
    "narrow_band": damage_rate_narrow_band,
    "wirsching_light": damage_rate_wirsching_light,
    "dirlik": damage_rate_dirlik,
    "benasciutti_tovo": damage_rate_benasciutti_tovo,
}


def damage_rate(
    omega: ArrayLike, density: ArrayLike, curve: FatigueCurve, method: str = "dirlik"
) -> np.ndarray:
    """Damage rate of a Gaussian process by the named spectral method.

    Parameters
    ----------
    omega, density, curve
        As :func:`damage_rate_narrow_band`.
    method : {"dirlik", "benasciutti_tovo", "wirsching_light", "narrow_band"}
        Spectral method (hyphens accepted for underscores). [-]

    Returns
    -------
    numpy.ndarray
        Damage per unit time, shape (...). [1/s]
    """
    key = str(method).strip().lower().replace("-", "_")
    if key not in _METHODS:
        raise InputError("method", method, "-", f"must be one of {sorted(_METHODS)}")
    return _METHODS[key](omega, density, curve)
