"""Short- and long-term extremes of a linear Gaussian response.

Short term (one stationary sea state): the maxima of a zero-mean Gaussian process
above its mean are Rayleigh distributed (narrow band) or follow Cartwright &
Longuet-Higgins (1956) with the spectral bandwidth ε; the largest of the N maxima of a
duration has P(X_max > x) = 1 − exp(−N Q(x)) (maxima as a Poisson stream), and the
most probable maximum is the level with N Q = 1, mean + σ√(2 ln N) — the project's
convention (``stochcable.results.statistics.ResponseStatistics.mpm``).

Long term (a scatter diagram of sea states i with probabilities p_i): the
distribution of a random maximum is the mixture of the short-term ones weighted by
the number of maxima per state (all-maxima / "long-term distribution of individual
maxima"), Q_LT(x) = Σ p_i ν_i Q_i(x)/Σ p_i ν_i, and the N-year level is the x that
the maxima of N years exceed once on average.
"""

from __future__ import annotations

import copy
import math

import numpy as np
from numpy.typing import ArrayLike
from scipy.special import ndtr

from stochcable import validation as v
from stochcable.errors import InputError

__all__ = [
    "SECONDS_PER_YEAR",
    "maximum_exceedance_rayleigh",
    "maxima_exceedance_short_term",
    "mpm_short_term",
    "long_term_exceedance",
    "return_level",
]

SECONDS_PER_YEAR = 365.25 * 86400.0
"""Length of a (Julian) year used to turn return periods into numbers of maxima. [s]"""

_FORMULATIONS = ("all_maxima", "storm_maximum")


def _array(name: str, value: ArrayLike, unit: str, nonnegative: bool = False) -> np.ndarray:
    return v.float_array(name, value, unit, ndim=None, nonnegative=nonnegative)


def _bandwidth(bandwidth: ArrayLike | None) -> np.ndarray | None:
    if bandwidth is None:
        return None
    eps = _array("bandwidth", bandwidth, "-", nonnegative=True)
    if (eps >= 1.0).any():
        raise InputError("bandwidth", bandwidth, "-", "must be in [0, 1)")
    return eps


def _q_maxima(
    x: np.ndarray, mean: np.ndarray, std: np.ndarray, eps: np.ndarray | None
) -> np.ndarray:
    """P(a maximum > x) for arrays that broadcast; std = 0 gives 0 above the mean."""
    pos = std > 0.0
    u = (x - mean) / np.where(pos, std, 1.0)
    rayleigh = np.where(u > 0.0, np.exp(-0.5 * np.square(np.maximum(u, 0.0))), 1.0)
    if eps is None:
        q = rayleigh
    else:
        e = np.where(eps > 0.0, eps, 1.0)
        root = np.sqrt(1.0 - np.square(eps))
        clh = ndtr(-u / e) + root * np.exp(-0.5 * u * u) * ndtr(u * root / e)
        q = np.where(eps > 0.0, clh, rayleigh)
    return np.where(pos, q, np.where(x < mean, 1.0, 0.0))


def _maxima_rate(tz: np.ndarray, eps: np.ndarray | None) -> np.ndarray:
    """Mean rate of maxima: 1/Tz (narrow band) or 1/(Tz √(1 − ε²)); 0 where Tz = 0."""
    period = tz if eps is None else tz * np.sqrt(1.0 - np.square(eps))
    return np.where(period > 0.0, 1.0 / np.where(period > 0.0, period, 1.0), 0.0)


def maximum_exceedance_rayleigh(
    x: ArrayLike, mean: ArrayLike, std: ArrayLike, bandwidth: ArrayLike | None = None
) -> np.ndarray:
    r"""Probability that one maximum of a Gaussian process exceeds x.

    Parameters
    ----------
    x : array_like
        Level. [unit]
    mean : array_like
        Mean of the process. [unit]
    std : array_like
        Standard deviation, >= 0. [unit]
    bandwidth : array_like, optional
        Spectral bandwidth ε = √(1 − m2²/(m0 m4)) in [0, 1); ``None`` (or 0) gives
        the narrow-band Rayleigh distribution. [-]

    Returns
    -------
    numpy.ndarray
        Q(x), broadcast shape of the inputs. [-]

    Notes
    -----
    Narrow band: Q = exp(−u²/2) for u = (x − mean)/σ > 0, 1 below the mean.  With ε
    (Cartwright & Longuet-Higgins 1956, eq. 13; every maximum, positive or negative):
    Q = Φ(−u/ε) + √(1 − ε²) e^{−u²/2} Φ(u√(1 − ε²)/ε).
    """
    xx = _array("x", x, "unit")
    mu = _array("mean", mean, "unit")
    sd = _array("std", std, "unit", nonnegative=True)
    return _q_maxima(xx, mu, sd, _bandwidth(bandwidth))


def _short_term_inputs(tz: ArrayLike, duration: float) -> tuple[np.ndarray, float]:
    return _array("tz", tz, "s", nonnegative=True), v.positive("duration", duration, "s")


def maxima_exceedance_short_term(
    x: ArrayLike,
    mean: ArrayLike,
    std: ArrayLike,
    tz: ArrayLike,
    duration: float,
    bandwidth: ArrayLike | None = None,
) -> np.ndarray:
    r"""Probability that the largest maximum within ``duration`` exceeds x.

    Parameters
    ----------
    x : array_like
        Level. [unit]
    mean : array_like
        Mean of the response. [unit]
    std : array_like
        Standard deviation of the response, >= 0. [unit]
    tz : array_like
        Mean zero-upcrossing period, >= 0 (0: no cycles). [s]
    duration : float
        Duration of the sea state, > 0. [s]
    bandwidth : array_like, optional
        Spectral bandwidth ε in [0, 1) (Cartwright–Longuet-Higgins maxima at the rate
        1/(Tz√(1 − ε²))); ``None``: Rayleigh maxima at the rate 1/Tz. [-]

    Returns
    -------
    numpy.ndarray
        P(X_max > x) = 1 − exp(−N Q(x)), N = duration × rate of maxima. [-]

    Notes
    -----
    The maxima are taken as a Poisson stream (independent, rare at high levels), so
    P(X_max <= x) = exp(−N Q(x)) (the upcrossing/Poisson approximation, e.g. Naess &
    Moan 2013, *Stochastic Dynamics of Marine Structures*, Cambridge University
    Press).  At the most probable maximum of
    :func:`mpm_short_term` (narrow band) N Q = 1 and P = 1 − 1/e.
    """
    xx = _array("x", x, "unit")
    mu = _array("mean", mean, "unit")
    sd = _array("std", std, "unit", nonnegative=True)
    t, dur = _short_term_inputs(tz, duration)
    eps = _bandwidth(bandwidth)
    n = dur * _maxima_rate(t, eps)
    return -np.expm1(-n * _q_maxima(xx, mu, sd, eps))


def mpm_short_term(
    mean: ArrayLike, std: ArrayLike, tz: ArrayLike, duration: float
) -> np.ndarray | float:
    r"""Rayleigh most probable maximum of a Gaussian response over a duration.

    Parameters
    ----------
    mean : array_like
        Mean of the response. [unit]
    std : array_like
        Standard deviation, >= 0. [unit]
    tz : array_like
        Mean zero-upcrossing period, >= 0 (0: no cycles, the MPM is the mean). [s]
    duration : float
        Duration, > 0 (10800 s for the 3-h MPM). [s]

    Returns
    -------
    float or numpy.ndarray
        mean + σ √(2 ln N), N = duration/Tz (held at the mean for N < 1). [unit]

    Notes
    -----
    The convention of ``ResponseStatistics.mpm`` (its ``std√(2 ln N)`` is the
    dynamic part; here the mean is added, as in the result document's ``mpm_3h``).
    """
    mu = _array("mean", mean, "unit")
    sd = _array("std", std, "unit", nonnegative=True)
    t, dur = _short_term_inputs(tz, duration)
    n = np.where(t > 0.0, dur / np.where(t > 0.0, t, 1.0), 0.0)
    out = mu + sd * np.sqrt(2.0 * np.log(np.maximum(n, 1.0)))
    return float(out) if out.ndim == 0 else out


class _Diagram:
    """Validated scatter-diagram arrays: states on axis 0, response locations after."""

    def __init__(
        self,
        probabilities: ArrayLike,
        mean: ArrayLike,
        std: ArrayLike,
        tz: ArrayLike,
        bandwidth: ArrayLike | None,
        state_duration: float,
        formulation: str,
    ) -> None:
        p = v.float_array("probabilities", probabilities, "-", nonnegative=True)
        total = float(p.sum())
        if not total > 0.0:
            raise InputError("probabilities", probabilities, "-", "must not all be zero")
        checked = (
            _array("mean", mean, "unit"),
            _array("std", std, "unit", nonnegative=True),
            _array("tz", tz, "s", nonnegative=True),
        )
        try:
            mu, sd, t = np.broadcast_arrays(*checked)
        except ValueError:
            raise InputError(
                "mean", np.shape(mean), "-", "mean, std and tz must broadcast together"
            ) from None
        if mu.ndim == 0 or mu.shape[0] != p.size:
            raise InputError(
                "mean",
                mu.shape,
                "-",
                f"mean, std and tz must have the {p.size} states on their first axis",
            )
        eps = _bandwidth(bandwidth)
        if eps is not None:
            try:
                eps = np.broadcast_to(eps, mu.shape)
            except ValueError:
                raise InputError(
                    "bandwidth", eps.shape, "-", f"must broadcast to the states' shape {mu.shape}"
                ) from None
        self.trailing = mu.shape[1:]
        self.p = p / total
        self.mean, self.std, self.eps = mu, sd, eps
        self.rate = _maxima_rate(t, eps)
        self.duration = v.positive("state_duration", state_duration, "s")
        form = str(formulation).strip().lower().replace("-", "_")
        if form not in _FORMULATIONS:
            raise InputError("formulation", formulation, "-", f"must be one of {_FORMULATIONS}")
        self.formulation = form
        weight = np.tensordot(self.p, self.rate, axes=(0, 0))  # Σ p_i ν_i per location
        if not (weight > 0.0).all():
            raise InputError("tz", tz, "s", "some state with p > 0 must have Tz > 0")
        self.weight = weight

    def at(self, idx: tuple) -> _Diagram:
        """The diagram of one response location (trailing index idx)."""
        sub = copy.copy(self)
        sel = (slice(None),) + idx
        sub.mean, sub.std, sub.rate = self.mean[sel], self.std[sel], self.rate[sel]
        sub.eps = None if self.eps is None else self.eps[sel]
        sub.trailing = ()
        sub.weight = self.weight[idx]
        return sub

    def exceedance(self, x: np.ndarray) -> np.ndarray:
        """Long-term exceedance, shape broadcast(x.shape, trailing)."""
        k = max(x.ndim - len(self.trailing), 0)

        def st(a: np.ndarray | None) -> np.ndarray | None:
            return None if a is None else a.reshape(a.shape[:1] + (1,) * k + a.shape[1:])

        p = self.p.reshape((-1,) + (1,) * (k + len(self.trailing)))
        mu, sd, rate, eps = st(self.mean), st(self.std), st(self.rate), st(self.eps)
        q = _q_maxima(x[np.newaxis], mu, sd, eps)
        if self.formulation == "all_maxima":
            return np.sum(p * rate * q, axis=0) / np.sum(p * rate, axis=0)
        return np.sum(p * -np.expm1(-self.duration * rate * q), axis=0)


def long_term_exceedance(
    x: ArrayLike,
    probabilities: ArrayLike,
    mean: ArrayLike,
    std: ArrayLike,
    tz: ArrayLike,
    *,
    state_duration: float = 10800.0,
    bandwidth: ArrayLike | None = None,
    formulation: str = "all_maxima",
) -> np.ndarray:
    r"""Long-term probability of exceeding x over a scatter diagram.

    Parameters
    ----------
    x : array_like
        Level(s); broadcast against the response locations (the axes of ``mean``
        after the first). [unit]
    probabilities : array_like, shape (n_states,)
        Occurrence probabilities p_i >= 0 of the sea states (taken relative to their
        sum). [-]
    mean, std, tz : array_like, shape (n_states, ...)
        Per state (and response location): mean, standard deviation (>= 0) and mean
        zero-upcrossing period (>= 0) of the response. [unit, unit, s]
    state_duration : float, default 10800
        Duration of one sea state (``"storm_maximum"`` only; it cancels in the
        all-maxima distribution). [s]
    bandwidth : array_like, optional
        Spectral bandwidth per state, in [0, 1) (see
        :func:`maxima_exceedance_short_term`); ``None``: Rayleigh maxima. [-]
    formulation : {"all_maxima", "storm_maximum"}, default "all_maxima"
        ``"all_maxima"``: probability that a random maximum exceeds x,
        Q_LT = Σ p_i ν_i Q_i(x)/Σ p_i ν_i, ν_i the rate of maxima.
        ``"storm_maximum"``: probability that the largest maximum of a random sea state
        of ``state_duration`` exceeds x, Σ p_i [1 − exp(−ν_i T Q_i(x))]. [-]

    Returns
    -------
    numpy.ndarray
        Exceedance probability, shape broadcast(x.shape, mean.shape[1:]). [-]

    Notes
    -----
    The all-maxima (individual maxima) long-term distribution of a linear response,
    the "all short-term maxima" approach of DNV-RP-C205 (long-term response of a
    linear system) and of Naess & Moan (2013), *Stochastic Dynamics of Marine
    Structures*, chapter on long-term response: every maximum of every state is a
    sample, so states weigh by p_i ν_i.  The storm-maximum form is the long-term
    distribution of the short-term extremes, as in the same references.  (Section
    numbers are not given: they could not be checked against the texts here.)
    """
    d = _Diagram(probabilities, mean, std, tz, bandwidth, state_duration, formulation)
    xx = _array("x", x, "unit")
    return d.exceedance(xx)


def _solve_level(d: _Diagram, years: float) -> float:
    """The level of one response location exceeded on average once in ``years``."""
    seconds = years * SECONDS_PER_YEAR
    if d.formulation == "all_maxima":
        n_events = seconds * float(d.weight)  # maxima in the return period
        per_event = 1.0
    else:
        n_events = seconds / d.duration  # sea states in the return period
        per_event = float(np.max(d.duration * d.rate))  # most maxima in one state

    def g(xv: float) -> float:
        q = float(d.exceedance(np.asarray(xv)))
        if d.formulation == "all_maxima":
            return n_events * q - 1.0
        return -n_events * math.log1p(-min(q, 1.0 - 1e-16)) - 1.0

    # above mean + σ u_hi every Q_i < 2 e^{-u²/2} keeps the expected count below 1/2
    u_hi = math.sqrt(2.0 * math.log(4.0 * max(n_events * per_event, 1.0)))
    live = d.p > 0.0
    lo = float(np.min((d.mean - 10.0 * d.std)[live]))
    hi = float(np.max((d.mean + (u_hi + 1.0) * d.std)[live]))
    if not g(lo) > 0.0:
        raise InputError(
            "years",
            years,
            "year",
            "is shorter than the mean time between maxima (between sea states for "
            "'storm_maximum'): no level is exceeded once on average",
        )
    if not g(hi) < 0.0:
        return hi  # the states with p > 0 have σ = 0: the level is their largest mean
    scale = max(abs(lo), abs(hi), float(np.max(d.std)))
    from scipy.optimize import brentq  # (imported here: the package stays light)

    return brentq(g, lo, hi, xtol=1e-15 * scale, rtol=4.0 * np.finfo(float).eps, maxiter=500)


def return_level(
    years: float,
    probabilities: ArrayLike,
    mean: ArrayLike,
    std: ArrayLike,
    tz: ArrayLike,
    *,
    state_duration: float = 10800.0,
    bandwidth: ArrayLike | None = None,
    formulation: str = "all_maxima",
) -> np.ndarray | float:
    r"""N-year most probable maximum: the level exceeded on average once in ``years``.

    Parameters
    ----------
    years : float
        Return period, > 0 (e.g. 100; 10800/SECONDS_PER_YEAR for three hours). [year]
    probabilities, mean, std, tz, state_duration, bandwidth, formulation
        As :func:`long_term_exceedance`.

    Returns
    -------
    float or numpy.ndarray
        The level, shape mean.shape[1:] (a float for one response location). [unit]

    Notes
    -----
    All maxima: the number of maxima in the return period is
    N_R = years·SECONDS_PER_YEAR·Σ p_i ν_i and the level solves N_R Q_LT(x) = 1.  One
    state with p = 1 and a return period equal to the state's duration gives
    N_R = T/Tz and x = mean + σ√(2 ln N_R), the short-term MPM, exactly.  Storm
    maximum: with n = years·SECONDS_PER_YEAR/state_duration states, the level solves
    F_LT(x)^n = e^{−1} (exceeded once on average by the n storm maxima, Poisson), which
    for one state also gives the short-term MPM.  Solved by Brent's method on a
    bracket from min(mean − 10σ) to max(mean + σ(√(2 ln 4N) + 1)).
    """
    yrs = v.positive("years", years, "year")
    d = _Diagram(probabilities, mean, std, tz, bandwidth, state_duration, formulation)
    out = np.empty(d.trailing)
    for idx in np.ndindex(*d.trailing):
        out[idx] = _solve_level(d.at(idx), yrs)
    return float(out) if out.ndim == 0 else out
