"""Response spectra and short-term statistics of Gaussian responses (DESIGN.md "Outputs").

Spectra are one-sided in omega: ``m_n = int_0^inf omega^n S(omega) d omega``.

Linear combinations of responses (e.g. the effective tension of an element from the
displacements of its two nodes, or a reaction from several DOFs) are formed on the
transfer functions, ``H_T = sum_k c_k H_k``, and only then squared:
``S_T = |H_T|^2 S``.  Adding the auto-spectra ``|H_k|^2 S`` would drop the
cross-spectra ``H_k conj(H_l) S`` (:func:`cross_spectrum`) and is wrong for
correlated responses.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields
from typing import Any

import numpy as np

from stochcable import validation as _v
from stochcable.errors import InputError

__all__ = [
    "response_spectrum",
    "cross_spectrum",
    "ResponseStatistics",
    "response_statistics_unchecked",
    "response_statistics",
    "statistics_from_moments",
]

_EULER_GAMMA = 0.5772156649015329


def response_spectrum(transfer: np.ndarray, input_spectrum: np.ndarray) -> np.ndarray:
    r"""Response spectral density ``S_x = |H|^2 S`` (broadcasting).

    Parameters
    ----------
    transfer : array_like, complex, shape (..., n_omega)
        Transfer function per unit input amplitude, frequency on the last axis.
        [response unit / input unit]
    input_spectrum : array_like, shape (n_omega,) or broadcastable
        One-sided input spectral density, e.g. the wave spectrum. [input unit²·s/rad]

    Returns
    -------
    ndarray
        One-sided response spectral density. [response unit²·s/rad]

    Notes
    -----
    DESIGN.md "Outputs": ``S_x = |H_x|^2 S_eta``.
    """
    h = np.asarray(transfer)
    s = _v.float_array(
        "input_spectrum", input_spectrum, "unit^2*s/rad", ndim=None, nonnegative=True
    )
    return np.abs(h) ** 2 * s


def cross_spectrum(
    transfer_a: np.ndarray, transfer_b: np.ndarray, input_spectrum: np.ndarray
) -> np.ndarray:
    r"""Cross-spectral density ``S_ab = H_a conj(H_b) S`` of two responses to one input.

    Parameters
    ----------
    transfer_a, transfer_b : array_like, complex, shape (..., n_omega)
        Transfer functions of the two responses. [response unit / input unit]
    input_spectrum : array_like, shape (n_omega,) or broadcastable
        One-sided input spectral density. [input unit²·s/rad]

    Returns
    -------
    ndarray, complex
        One-sided cross-spectral density; its real part integrates to the
        covariance of the two responses. [unit_a·unit_b·s/rad]

    Notes
    -----
    ``S_{a+b} = S_aa + S_bb + 2 Re S_ab``; prefer forming ``H_a + H_b`` directly.
    """
    s = _v.float_array(
        "input_spectrum", input_spectrum, "unit^2*s/rad", ndim=None, nonnegative=True
    )
    return np.asarray(transfer_a) * np.conj(np.asarray(transfer_b)) * s


@dataclass(frozen=True, eq=False)
class ResponseStatistics:
    """Short-term statistics of a zero-mean stationary Gaussian response.

    Every field has the leading shape of the density passed to
    :func:`response_statistics` (a float for a single spectrum).

    Attributes
    ----------
    m0, m1, m2, m4 : float or ndarray
        Spectral moments ``int omega^n S d omega``. [unit²·(rad/s)^n]
    std : float or ndarray
        Standard deviation ``sqrt(m0)``. [unit]
    tz : float or ndarray
        Mean zero-up-crossing period ``2 pi sqrt(m0/m2)``; 0 where ``m0 = 0`` or
        ``m2 = 0``. [s]
    significant : float or ndarray
        Significant value (single amplitude) ``2 std``. [unit]
    bandwidth : float or ndarray
        Spectral bandwidth ``sqrt(1 - m2²/(m0 m4))`` (Cartwright & Longuet-Higgins);
        0 where ``m0 m4 = 0``. [-]
    mpm : float or ndarray
        Rayleigh most probable maximum over ``duration``: ``std sqrt(2 ln N)``,
        ``N = duration / tz``. [unit]
    expected_max : float or ndarray
        Expected maximum ``std (sqrt(2 ln N) + gamma / sqrt(2 ln N))``
        (Cartwright & Longuet-Higgins 1956, large N). [unit]
    n_cycles : float or ndarray
        ``N = duration / tz`` (0 where ``tz = 0``). [-]
    duration : float
        Duration of the short-term sea state. [s]
    """

    m0: Any
    m1: Any
    m2: Any
    m4: Any
    std: Any
    tz: Any
    significant: Any
    bandwidth: Any
    mpm: Any
    expected_max: Any
    n_cycles: Any
    duration: float

    def as_dict(self) -> dict[str, Any]:
        """Fields as floats or nested lists (JSON-ready)."""
        out: dict[str, Any] = {}
        for f in fields(self):
            val = getattr(self, f.name)
            out[f.name] = float(val) if np.ndim(val) == 0 else np.asarray(val).tolist()
        return out


def response_statistics(
    omega: np.ndarray, density: np.ndarray, duration: float = 10800.0
) -> ResponseStatistics:
    r"""Spectral moments and extreme-value statistics of a Gaussian response.

    Parameters
    ----------
    omega : array_like, shape (n_omega,)
        Angular frequencies, strictly increasing, >= 0, possibly non-uniform. [rad/s]
    density : array_like, shape (..., n_omega)
        One-sided spectral density, >= 0, frequency on the last axis.
        [unit²·s/rad]
    duration : float, optional
        Duration for the maxima (default three hours). [s]

    Returns
    -------
    ResponseStatistics

    Notes
    -----
    Moments by the trapezoid rule on the given grid.  ``Tz = 2 pi sqrt(m0/m2)``;
    ``N = duration / Tz`` response cycles; for a narrow-band response the maxima
    are Rayleigh distributed and the largest of ``N`` has its mode at
    ``std sqrt(2 ln N)`` (most probable maximum) and mean
    ``std (sqrt(2 ln N) + 0.5772 / sqrt(2 ln N))``.  No NaN is produced: where
    ``m0 = 0`` or ``m2 = 0`` the period, ``N`` and the maxima are 0; where
    ``N < 1`` the most probable maximum is 0; the asymptotic expected maximum is
    held at its value at ``2 ln N = 1`` (``1.577 std``) for ``N < e^{1/2}``.
    """
    return response_statistics_unchecked(*check_response_spectrum(omega, density, duration))


def check_response_spectrum(
    omega: np.ndarray, density: np.ndarray, duration: float
) -> tuple[np.ndarray, np.ndarray, float]:
    """The checks of :func:`response_statistics` (its parameters, same units): float
    arrays and the duration, or an InputError naming the parameter."""
    w = _v.float_array("omega", omega, "rad/s", nonnegative=True, increasing=True, min_size=2)
    s = _v.float_array("density", density, "unit^2*s/rad", ndim=None, nonnegative=True)
    dur = _v.positive("duration", duration, "s")
    if s.ndim == 0 or s.shape[-1] != w.size:
        raise InputError(
            "density", s, "unit^2*s/rad", f"must have the frequency axis last with {w.size} entries"
        )
    return w, s, dur


def response_statistics_unchecked(w: np.ndarray, s: np.ndarray, dur: float) -> ResponseStatistics:
    """:func:`response_statistics` of validated float arrays (w increasing, s >= 0 with
    the frequency axis last of w's size, dur > 0): the pipeline's grids are validated
    once at the boundary."""
    if s.ndim == 1:
        return _statistics_1d(w, s, dur)
    m0 = np.trapezoid(s, w, axis=-1)
    m1 = np.trapezoid(s * w, w, axis=-1)
    m2 = np.trapezoid(s * w**2, w, axis=-1)
    m4 = np.trapezoid(s * w**4, w, axis=-1)
    std = np.sqrt(m0)
    ok = (m0 > 0) & (m2 > 0)
    tz = np.where(
        ok, 2.0 * math.pi * np.sqrt(np.divide(m0, m2, out=np.ones_like(m0), where=ok)), 0.0
    )
    n_cyc = np.where(ok, dur / np.where(ok, tz, 1.0), 0.0)
    ln_n = np.log(np.maximum(n_cyc, 1.0))
    root = np.sqrt(2.0 * ln_n)
    mpm = std * root
    r1 = np.maximum(root, 1.0)
    expected = np.where(ok, std * (r1 + _EULER_GAMMA / r1), 0.0)
    den = m0 * m4
    pos = den > 0
    eps2 = 1.0 - np.divide(m2**2, den, out=np.ones_like(den), where=pos)
    bandwidth = np.where(pos, np.sqrt(np.clip(eps2, 0.0, 1.0)), 0.0)

    def out(x: np.ndarray) -> Any:
        return float(x) if np.ndim(x) == 0 else x

    return ResponseStatistics(
        m0=out(m0),
        m1=out(m1),
        m2=out(m2),
        m4=out(m4),
        std=out(std),
        tz=out(tz),
        significant=out(2.0 * std),
        bandwidth=out(bandwidth),
        mpm=out(mpm),
        expected_max=out(expected),
        n_cycles=out(n_cyc),
        duration=dur,
    )


def _statistics_1d(w: np.ndarray, s: np.ndarray, dur: float) -> ResponseStatistics:
    """:func:`response_statistics_unchecked` of one spectrum (s of shape (n,)): the four trapezoid
    moments as ONE row-wise reduction of the same products and sums as
    ``np.trapezoid`` (the same bits), and the scalar formulas on floats (numpy's
    0-d array operations were most of the time of a call)."""
    d = np.diff(w)
    y = np.empty((4, w.size))
    y[0] = s
    np.multiply(s, w, out=y[1])
    np.multiply(s, w**2, out=y[2])
    np.multiply(s, w**4, out=y[3])
    m0, m1, m2, m4 = (float(m) for m in (d * (y[:, 1:] + y[:, :-1]) / 2.0).sum(axis=-1))
    return statistics_from_moments(m0, m1, m2, m4, dur)


def statistics_from_moments(
    m0: float, m1: float, m2: float, m4: float, dur: float
) -> ResponseStatistics:
    """The statistics of a Gaussian response with spectral moments ``m0`` … ``m4``
    [unit²·(rad/s)ⁿ] over a storm of ``dur`` [s] (the formulas of
    :func:`response_statistics`), e.g. of a spectrum in parts on different grids whose
    moments add."""
    m0, m1, m2, m4 = (float(m) for m in (m0, m1, m2, m4))
    std = math.sqrt(max(m0, 0.0))
    ok = m0 > 0 and m2 > 0
    tz = 2.0 * math.pi * math.sqrt(m0 / m2) if ok else 0.0
    n_cyc = dur / tz if ok else 0.0
    root = math.sqrt(2.0 * float(np.log(max(n_cyc, 1.0))))
    r1 = max(root, 1.0)
    expected = std * (r1 + _EULER_GAMMA / r1) if ok else 0.0
    den = m0 * m4
    bandwidth = math.sqrt(min(max(1.0 - m2 * m2 / den, 0.0), 1.0)) if den > 0 else 0.0
    return ResponseStatistics(
        m0=m0,
        m1=m1,
        m2=m2,
        m4=m4,
        std=std,
        tz=tz,
        significant=2.0 * std,
        bandwidth=bandwidth,
        mpm=std * root,
        expected_max=expected,
        n_cycles=n_cyc,
        duration=dur,
    )
