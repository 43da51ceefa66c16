"""Directional spreading of a short-crested sea: spreading functions, their discrete
directions, and directional realizations.

A short-crested sea has the directional spectrum S(ω, θ) = S(ω) D(θ − θ̄), ∫D dθ = 1
(DNV-RP-C205 (2021) §3.5.8; frequency-independent spreading).  The functions here are
pure numerics on arrays (the sea layer): the spreading functions ``spreading_<model>``
[1/rad], their discretization into a :class:`DirectionSet` of headings and weights
(``directions_<model>``: each weight the exact integral of D over its bin (from the
closed-form distribution function, an incomplete beta function), each heading the
D-weighted centroid of its bin, so that direction sums of smooth functions
err by O(Δθ²) and a spreading that narrows to zero width puts all its weight at the
mean heading: the long-crested sea), the directional moments, and the realization of a
short-crested sea as independent long-crested components, one per direction, each
with the spectrum w_k S(ω) (the "double sum" of DSA/NSA, Tuah (1982), §5.1 per direction).

Angles are in radians here; headings follow DESIGN.md (from +x toward +y, the
direction the waves travel).

References
----------
Tuah, H. (1982), Cable dynamics in an ocean environment, PhD thesis, Oregon State University.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from stochcable import validation as v
from stochcable.errors import InputError
from stochcable.sea.kinematics import G_STANDARD, wave_kinematics
from stochcable.sea.limits import SPREADING_EXPONENT_MAX
from stochcable.sea.realization import SeaRealization, simulate_sea, synthesize

__all__ = [
    "DirectionSet",
    "spreading_cos2s",
    "spreading_cosn",
    "directions_cos2s",
    "directions_cosn",
    "directions_table",
    "moments_cos2s",
    "moments_cosn",
    "simulate_sea_directional",
    "velocity_timeseries_directional",
]

#: Gauss–Legendre points per bin of the bin integrals (exact for polynomials of
#: degree 63: the spreading functions are smooth within a bin). [-]
_GAUSS = 32


@dataclass(frozen=True, eq=False)
class DirectionSet:
    """Discrete directions of a short-crested sea.

    Attributes
    ----------
    heading : ndarray, shape (K,)
        Headings, increasing. [rad]
    weight : ndarray, shape (K,)
        Share of the variance travelling in each direction, ≥ 0, sum 1. [-]
    """

    heading: np.ndarray
    weight: np.ndarray

    @property
    def count(self) -> int:
        """Number of directions K. [-]"""
        return int(self.heading.size)

    def moments(self, mean: float = 0.0) -> dict[str, float]:
        """Directional moments about ``mean`` [rad]: a_n = Σ w cos nΔθ, b_n = Σ w sin nΔθ
        for n = 1, 2 (Δθ = θ − mean). [-]"""
        d = self.heading - mean
        w = self.weight
        return {
            "a1": float(w @ np.cos(d)),
            "b1": float(w @ np.sin(d)),
            "a2": float(w @ np.cos(2 * d)),
            "b2": float(w @ np.sin(2 * d)),
        }


def _cos2s_norm(s: float) -> float:
    """C(s) = Γ(s + 1)/(2√π Γ(s + ½)), ∫_{−π}^{π} C cos^{2s}(θ/2) dθ = 1. [1/rad]"""
    from scipy.special import gammaln  # (here: a long-crested sea does without)

    return math.exp(gammaln(s + 1.0) - gammaln(s + 0.5)) / (2.0 * math.sqrt(math.pi))


def _cosn_norm(n: float) -> float:
    """C(n) = Γ(n/2 + 1)/(√π Γ(n/2 + ½)), ∫_{−π/2}^{π/2} C cosⁿθ dθ = 1. [1/rad]"""
    from scipy.special import gammaln  # (here: a long-crested sea does without)

    return math.exp(gammaln(0.5 * n + 1.0) - gammaln(0.5 * n + 0.5)) / math.sqrt(math.pi)


def _wrap(x: np.ndarray) -> np.ndarray:
    """Angles to (−π, π]. [rad]"""
    return -((-x + math.pi) % (2.0 * math.pi) - math.pi)


def spreading_cos2s(theta: ArrayLike, mean: float, s: float) -> np.ndarray:
    """Cosine-2s (Longuet-Higgins) spreading function.

    Parameters
    ----------
    theta : array_like
        Headings. [rad]
    mean : float
        Mean heading θ̄. [rad]
    s : float
        Spreading exponent, in (0, 1e6] (larger: narrower). [-]

    Returns
    -------
    ndarray
        D(θ) = C(s) cos^{2s}((θ − θ̄)/2), C(s) = Γ(s + 1)/(2√π Γ(s + ½)). [1/rad]

    Notes
    -----
    Longuet-Higgins, Cartwright & Smith (1963); DNV-RP-C205 (2021) §3.5.8.  Its
    moments are a1 = s/(s + 1), a2 = s(s − 1)/((s + 1)(s + 2)) (:func:`moments_cos2s`).
    """
    s = _exponent("s", s)
    mean = v.finite_scalar("mean", mean, "rad")
    th = v.float_array("theta", theta, "rad", ndim=None)
    c = np.abs(np.cos(0.5 * _wrap(th - mean)))
    return _cos2s_norm(s) * c ** (2.0 * s)


def spreading_cosn(theta: ArrayLike, mean: float, n: float) -> np.ndarray:
    """Cosine-power spreading function (DNV-RP-C205).

    Parameters
    ----------
    theta : array_like
        Headings. [rad]
    mean : float
        Mean heading θ̄. [rad]
    n : float
        Spreading exponent, in (0, 1e6] (DNV-RP-C205: 2–4 wind sea, ≥ 6 swell). [-]

    Returns
    -------
    ndarray
        D(θ) = Γ(n/2 + 1)/(√π Γ(n/2 + ½)) cosⁿ(θ − θ̄) for |θ − θ̄| ≤ π/2, else 0.
        [1/rad]

    Notes
    -----
    DNV-RP-C205 (2021) eq. 3.5.21.  Moments a1 = Γ(n/2 + 1)²/(Γ(n/2 + ½)Γ(n/2 + 3/2)),
    a2 = n/(n + 2) (:func:`moments_cosn`).
    """
    n = _exponent("n", n)
    mean = v.finite_scalar("mean", mean, "rad")
    th = v.float_array("theta", theta, "rad", ndim=None)
    d = _wrap(th - mean)
    out = _cosn_norm(n) * np.abs(np.cos(d)) ** n
    return np.where(np.abs(d) <= 0.5 * math.pi, out, 0.0)


def moments_cos2s(s: float) -> dict[str, float]:
    """Directional moments of :func:`spreading_cos2s` about its mean (closed form). [-]"""
    s = _exponent("s", s)
    return {
        "a1": s / (s + 1.0),
        "b1": 0.0,
        "a2": s * (s - 1.0) / ((s + 1.0) * (s + 2.0)),
        "b2": 0.0,
    }


def moments_cosn(n: float) -> dict[str, float]:
    """Directional moments of :func:`spreading_cosn` about its mean (closed form). [-]"""
    from scipy.special import gammaln  # (here: a long-crested sea does without)

    n = _exponent("n", n)
    a1 = math.exp(2.0 * gammaln(0.5 * n + 1.0) - gammaln(0.5 * n + 0.5) - gammaln(0.5 * n + 1.5))
    return {"a1": a1, "b1": 0.0, "a2": n / (n + 2.0), "b2": 0.0}


def _binned(
    cdf: Callable[[np.ndarray], np.ndarray],
    density: Callable[[np.ndarray], np.ndarray],
    lo: float,
    hi: float,
    count: int,
) -> DirectionSet:
    """``count`` equal bins on [lo, hi] (relative to the mean): weight = ∫_bin D from the
    closed-form distribution function ``cdf`` (exact however narrow D is), heading =
    ∫_bin θD/∫_bin D by Gauss–Legendre (where D is too narrow for the rule to see it
    in a bin: the bin's point nearest the mean); bins of zero weight are left out."""
    x, gw = np.polynomial.legendre.leggauss(_GAUSS)
    edges = np.linspace(lo, hi, count + 1)
    half = 0.5 * np.diff(edges)
    mid = 0.5 * (edges[1:] + edges[:-1])
    th = mid[:, None] + half[:, None] * x[None, :]  # (count, _GAUSS)
    d = density(th)
    w0 = (d * gw).sum(axis=1)
    nearest = np.clip(0.0, edges[:-1], edges[1:])
    centroid = np.divide((d * th * gw).sum(axis=1), w0, out=nearest, where=w0 > 0)
    w = np.maximum(np.diff(cdf(edges)), 0.0)
    keep = w > 0  # (bins a very narrow spreading leaves empty carry nothing)
    return DirectionSet(heading=centroid[keep], weight=w[keep] / w.sum())


def _exponent(name: str, value: float) -> float:
    """A spreading exponent (s of cos-2s, n of cosⁿ): in (0, SPREADING_EXPONENT_MAX]. [-]"""
    return v.in_range(name, value, "-", 0.0, SPREADING_EXPONENT_MAX, lo_open=True)


def _count(count: int) -> int:
    return v.positive_int("count", count)


def directions_cos2s(mean: float, s: float, count: int = 16) -> DirectionSet:
    """Discrete directions of :func:`spreading_cos2s`: ``count`` equal bins over the
    circle centred on the mean (an odd count puts a bin on the mean). [rad, -]"""
    from scipy.special import betainc  # (here: a long-crested sea does without)

    s = _exponent("s", s)
    mean = v.finite_scalar("mean", mean, "rad")
    count = _count(count)

    def cdf(t: np.ndarray) -> np.ndarray:
        # ∫_0^φ C cos^{2s}(θ/2) dθ = ½ I_{sin²(φ/2)}(½, s + ½) (u = sin²(θ/2))
        return 0.5 * np.sign(t) * betainc(0.5, s + 0.5, np.sin(0.5 * t) ** 2)

    ds = _binned(cdf, lambda t: spreading_cos2s(t, 0.0, s), -math.pi, math.pi, count)
    return DirectionSet(heading=ds.heading + mean, weight=ds.weight)


def directions_cosn(mean: float, n: float, count: int = 16) -> DirectionSet:
    """Discrete directions of :func:`spreading_cosn`: ``count`` equal bins over its
    support |θ − θ̄| ≤ π/2 (an odd count puts a bin on the mean). [rad, -]"""
    from scipy.special import betainc  # (here: a long-crested sea does without)

    n = _exponent("n", n)
    mean = v.finite_scalar("mean", mean, "rad")
    count = _count(count)

    def cdf(t: np.ndarray) -> np.ndarray:
        # ∫_0^φ C cosⁿθ dθ = ½ I_{sin²φ}(½, (n + 1)/2) (u = sin²θ), |φ| ≤ π/2
        return 0.5 * np.sign(t) * betainc(0.5, 0.5 * (n + 1.0), np.sin(t) ** 2)

    ds = _binned(cdf, lambda t: spreading_cosn(t, 0.0, n), -0.5 * math.pi, 0.5 * math.pi, count)
    return DirectionSet(heading=ds.heading + mean, weight=ds.weight)


def directions_table(heading: ArrayLike, weight: ArrayLike) -> DirectionSet:
    """A spreading given as a table of headings and relative weights, normalized.

    Parameters
    ----------
    heading : array_like, shape (K,)
        Distinct headings. [rad]
    weight : array_like, shape (K,)
        Relative weights, ≥ 0, not all zero. [-]

    Returns
    -------
    DirectionSet
        Sorted by heading, weights divided by their sum.
    """
    h = v.float_array("heading", heading, "rad", ndim=1)
    w = v.float_array("weight", weight, "-", ndim=1)
    if h.size == 0 or w.shape != h.shape:
        raise InputError(
            "weight", f"{w.size} values", "-", f"must give one weight per heading ({h.size})"
        )
    if np.any(w < 0):
        raise InputError("weight", w.tolist(), "-", "must be >= 0")
    total = float(w.sum())
    if not total > 0:
        raise InputError(
            "weight", w.tolist(), "-", "must not all be zero (the spreading cannot be normalized)"
        )
    if np.unique(h).size != h.size:
        raise InputError("heading", h.tolist(), "rad", "must be distinct")
    order = np.argsort(h)
    return DirectionSet(heading=h[order], weight=w[order] / total)


def simulate_sea_directional(
    density: Callable[[np.ndarray], np.ndarray],
    directions: DirectionSet,
    duration: float,
    dt: float,
    method: str = "dsa",
    rng: np.random.Generator | int | None = None,
) -> tuple[SeaRealization, ...]:
    """A short-crested sea as independent long-crested realizations, one per direction.

    Parameters
    ----------
    density : callable
        The point spectrum ω → S(ω). [m²·s/rad]
    directions : DirectionSet
        Headings and weights (:func:`directions_cos2s`, ...).
    duration, dt : float
        As :func:`~stochcable.sea.realization.simulate_sea`. [s]
    method : {"dsa", "nsa"}
    rng : numpy.random.Generator or int, optional
        One generator; each direction draws from its own child stream. [-]

    Returns
    -------
    tuple of SeaRealization
        Direction k with the spectrum w_k S(ω) (amplitudes √(2 w_k S Δω) under DSA):
        the elevation is their sum, its spectrum S(ω); a response is the sum of each
        direction's response to its realization.
    """
    if not isinstance(directions, DirectionSet):
        raise InputError("directions", type(directions).__name__, "-", "must be a DirectionSet")
    gen = rng if isinstance(rng, np.random.Generator) else np.random.default_rng(rng)
    return tuple(
        simulate_sea(lambda w, f=float(wk): f * density(w), duration, dt, method, child)
        for wk, child in zip(directions.weight, gen.spawn(directions.count))
    )


def velocity_timeseries_directional(
    realizations: tuple[SeaRealization, ...],
    directions: DirectionSet,
    points: ArrayLike,
    depth: float = np.inf,
    g: float = G_STANDARD,
) -> np.ndarray:
    """Fluid velocity at points in a short-crested sea: the sum over directions of
    each direction's linear kinematics (Tuah (1982), eqs. 5.2.8–5.2.9) driven by its
    realization, shape (n_points, 3, N_t). [m/s]"""
    if len(realizations) != directions.count:
        raise InputError(
            "realizations",
            len(realizations),
            "-",
            f"must be one per direction ({directions.count})",
        )
    out = None
    for real, beta in zip(realizations, directions.heading):
        kin = wave_kinematics(real.omega, points, float(beta), depth, g)
        u = synthesize(real, kin.velocity)
        out = u if out is None else out + u
    return out
