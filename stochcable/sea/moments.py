"""Spectral moments and derived statistics of any one-sided spectrum on a grid.

m_n = ∫ ωⁿ S(ω) dω by the trapezoid rule on the given grid; Hs = 4√m0,
Tz = 2π√(m0/m2), Tm01 = 2π m0/m1, Tp at the grid peak and the bandwidth ε
(DESIGN.md "Wave spectra").  For sampled spectra of any kind (wave or response);
the closed-form moments of the Pierson–Moskowitz spectrum are in
:mod:`stochcable.sea.spectra`, which re-exports these.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from stochcable import validation as v
from stochcable.errors import InputError

__all__ = ["spectral_moments", "SpectrumStatistics", "spectrum_statistics"]


def spectral_moments(
    omega: ArrayLike, density: ArrayLike, orders: tuple[int, ...] = (0, 1, 2, 3, 4)
) -> np.ndarray:
    """Spectral moments m_n = ∫ ωⁿ S(ω) dω by the trapezoid rule on the given grid.

    Parameters
    ----------
    omega : array_like
        Frequency grid, strictly increasing, >= 0. [rad/s]
    density : array_like
        One-sided spectral density on the grid, >= 0. [unit²·s/rad]
    orders : tuple of int, default (0, 1, 2, 3, 4)
        Moment orders n. [-]

    Returns
    -------
    numpy.ndarray
        m_n for each order, shape (len(orders),). [unit²·(rad/s)ⁿ]

    Notes
    -----
    The integral is truncated to the grid: the tail beyond ω_max (for PM-type ω⁻⁵
    tails, m_n tail ≈ S(ω_max) ω_max^(n+1)/(4 − n)) is not included, and m4 of a ω⁻⁵
    spectrum grows logarithmically with ω_max.
    """
    w = v.float_array("omega", omega, "rad/s", nonnegative=True, increasing=True, min_size=2)
    s = v.float_array("density", density, "unit²·s/rad", nonnegative=True, min_size=2)
    if s.shape != w.shape:
        raise InputError(
            "density",
            density,
            "unit²·s/rad",
            f"must have the same length as omega ({w.size}), got {s.size}",
        )
    orders = tuple(int(n) for n in orders)
    return np.array([np.trapezoid(w**n * s, w) for n in orders])


@dataclass(frozen=True)
class SpectrumStatistics:
    """Moments and derived statistics of a one-sided spectrum.

    Attributes
    ----------
    m0, m1, m2, m3, m4 : float
        Spectral moments. [unit²·(rad/s)ⁿ]
    hs : float
        Significant height 4√m0. [unit]
    tz : float
        Mean zero-upcrossing period 2π√(m0/m2). [s]
    tm01 : float
        Mean period 2π m0/m1. [s]
    tp : float
        Peak period 2π/ω at the largest density on the grid. [s]
    bandwidth : float
        Cartwright–Longuet-Higgins ε = √(1 − m2²/(m0 m4)). [-]
    """

    m0: float
    m1: float
    m2: float
    m3: float
    m4: float
    hs: float
    tz: float
    tm01: float
    tp: float
    bandwidth: float

    def as_dict(self) -> dict[str, Any]:
        """Plain dict of the fields (floats)."""
        return asdict(self)


def spectrum_statistics(omega: ArrayLike, density: ArrayLike) -> SpectrumStatistics:
    """Moments (trapezoid on the grid) and derived statistics of a spectrum.

    Parameters
    ----------
    omega : array_like
        Frequency grid, strictly increasing, >= 0. [rad/s]
    density : array_like
        One-sided spectral density on the grid. [unit²·s/rad]

    Returns
    -------
    SpectrumStatistics
        m0…m4, Hs = 4√m0, Tz, Tm01, Tp (grid peak) and bandwidth ε. [see fields]
    """
    w = v.float_array("omega", omega, "rad/s", nonnegative=True, increasing=True, min_size=2)
    s = v.float_array("density", density, "unit²·s/rad", nonnegative=True, min_size=2)
    m = spectral_moments(w, s)
    m0, m1, m2, m3, m4 = (float(x) for x in m)
    if m0 <= 0.0:
        raise InputError("density", density, "unit²·s/rad", "must not be zero everywhere")
    i = int(np.argmax(s))
    tp = 2.0 * math.pi / w[i] if w[i] > 0 else math.inf
    tz = 2.0 * math.pi * math.sqrt(m0 / m2) if m2 > 0 else math.inf
    tm01 = 2.0 * math.pi * m0 / m1 if m1 > 0 else math.inf
    eps2 = 1.0 - m2 * m2 / (m0 * m4) if m4 > 0 else 0.0
    return SpectrumStatistics(
        m0=m0,
        m1=m1,
        m2=m2,
        m3=m3,
        m4=m4,
        hs=4.0 * math.sqrt(m0),
        tz=tz,
        tm01=tm01,
        tp=tp,
        bandwidth=math.sqrt(max(eps2, 0.0)),
    )
