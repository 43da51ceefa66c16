"""Winterstein's Hermite model of a mildly non-Gaussian response, for its extremes and
its fatigue damage.

A response x (standardized: zero mean, unit σ) with skewness α3 and kurtosis α4 is
modelled as a monotone cubic of a standard Gaussian process u,

    x = κ[u + h3(u² − 1) + h4(u³ − 3u)],
    h3 = α3/6,  h4 = (α4 − 3)/24,  κ = 1/√(1 + 2h3² + 6h4²)

(the first-order moment fit; κ makes the variance of x exactly 1).  A level u of the
Gaussian process (its most probable maximum, a return level, in σ) maps to the level
:func:`hermite_level` of the non-Gaussian one; a Gaussian cycle of amplitude a (from −a
to a about the mean) to one of amplitude κ[a + h4(a³ − 3a)] (h3 cancels in a cycle
symmetric about the mean), so the narrow-band damage with an S–N slope m is the
Gaussian one times :func:`hermite_fatigue_factor_narrow_band`.

The moments are the caller's: the frequency-domain analysis gives the corrected
spectrum (σ, the spectral moments), not the skewness and kurtosis of the response.

References
----------
Winterstein, S. R. (1988), Nonlinear vibration models for extremes and fatigue, J.
Eng. Mech. 114(10), 1772–1790, eqs. 6–8 (the model and its coefficients) and 20–22
(fatigue of the narrow-band process).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from stochcable.errors import InputError

__all__ = [
    "HERMITE_RANGE",
    "HermiteModel",
    "hermite_fatigue_factor_narrow_band",
    "hermite_level",
    "hermite_model_winterstein",
]

#: The Gaussian levels |u| ≤ HERMITE_RANGE over which the model must be monotone: the
#: expected largest of 10⁸ Rayleigh maxima is 6.1 σ. [σ]
HERMITE_RANGE = 6.0


@dataclass(frozen=True)
class HermiteModel:
    """Winterstein's Hermite model of a standardized non-Gaussian process.

    Attributes
    ----------
    h3 : float
        Coefficient of the second Hermite polynomial, α3/6. [-]
    h4 : float
        Coefficient of the third Hermite polynomial, (α4 − 3)/24. [-]
    kappa : float
        Scale 1/√(1 + 2h3² + 6h4²) that makes the variance 1. [-]
    """

    h3: float
    h4: float
    kappa: float


def hermite_model_winterstein(skewness: float, kurtosis: float) -> HermiteModel:
    """The Hermite model of a process with skewness α3 and kurtosis α4 (module notes).

    Parameters
    ----------
    skewness : float
        α3 of the response (0 for a Gaussian). [-]
    kurtosis : float
        α4 of the response (3 for a Gaussian, not the excess). [-]

    Returns
    -------
    HermiteModel

    Raises
    ------
    InputError
        A moment not finite, or a pair whose model is not monotone over the Gaussian
        levels |u| ≤ :data:`HERMITE_RANGE` (the first-order fit is for mildly
        non-Gaussian responses: |h3|, |h4| small).

    References
    ----------
    Winterstein (1988), Nonlinear vibration models for extremes and fatigue, eqs. 6–8.
    """
    for name, value in (("skewness", skewness), ("kurtosis", kurtosis)):
        if not math.isfinite(float(value)):
            raise InputError(name, value, "-", "must be finite")
    h3 = float(skewness) / 6.0
    h4 = (float(kurtosis) - 3.0) / 24.0
    # g'(u)/κ = 1 + 2h3·u + 3h4(u² − 1), a quadratic: its minimum on [−r, r] is at an
    # end or at its vertex
    r = HERMITE_RANGE
    points = [-r, r] + ([-h3 / (3.0 * h4)] if h4 > 0.0 and abs(h3 / (3.0 * h4)) < r else [])
    if min(1.0 + 2.0 * h3 * u + 3.0 * h4 * (u * u - 1.0) for u in points) <= 0.0:
        raise InputError(
            "skewness, kurtosis",
            (skewness, kurtosis),
            "-",
            f"must give a Hermite model monotone over |u| <= {r:g} (a mildly non-Gaussian "
            "response: the first-order fit of Winterstein 1988)",
        )
    return HermiteModel(h3, h4, 1.0 / math.sqrt(1.0 + 2.0 * h3 * h3 + 6.0 * h4 * h4))


def hermite_level(u: ArrayLike, model: HermiteModel) -> np.ndarray:
    """The level of the non-Gaussian process that corresponds to the level ``u`` of the
    Gaussian one, κ[u + h3(u² − 1) + h4(u³ − 3u)].

    Parameters
    ----------
    u : array_like
        Levels of the standard Gaussian process (e.g. its most probable maximum over a
        storm, in σ above the mean). [σ]
    model : HermiteModel
        :func:`hermite_model_winterstein`.

    Returns
    -------
    ndarray
        The same levels of the standardized non-Gaussian process. [σ]

    References
    ----------
    Winterstein (1988), Nonlinear vibration models for extremes and fatigue, eq. 6.
    """
    u = np.asarray(u, dtype=float)
    return model.kappa * (u + model.h3 * (u * u - 1.0) + model.h4 * (u**3 - 3.0 * u))


def hermite_fatigue_factor_narrow_band(slope: float, model: HermiteModel) -> float:
    """Damage of the narrow-band Hermite process over that of the Gaussian one with the
    same σ and zero-crossing rate, for an S–N slope m: E[a_H^m]/E[a^m], the Gaussian
    amplitudes a Rayleigh-distributed and each mapped to κ[a + h4(a³ − 3a)].

    Parameters
    ----------
    slope : float
        S–N slope m (> 0). [-]
    model : HermiteModel
        :func:`hermite_model_winterstein`.

    Returns
    -------
    float
        The factor on the Gaussian damage (1 for a Gaussian). [-]

    References
    ----------
    Winterstein (1988), Nonlinear vibration models for extremes and fatigue, eqs. 20–22.
    """
    m = float(slope)
    if not (math.isfinite(m) and m > 0.0):
        raise InputError("slope", slope, "-", "must be finite and > 0")
    # Rayleigh density a·exp(−a²/2) on [0, 12]: its mass beyond is exp(−72) ≈ 5e-32; a
    # 0.0005 σ step integrates a^m·p(a) to < 1e-9 (trapezoid, smooth, zero at both ends)
    a = np.linspace(0.0, 12.0, 24001)
    p = a * np.exp(-0.5 * a * a)
    amp = model.kappa * (a + model.h4 * (a**3 - 3.0 * a))
    return float(np.trapezoid(np.abs(amp) ** m * p, a) / np.trapezoid(a**m * p, a))
