"""The Hermite coefficients of the quadratic drag |v|v of a Gaussian velocity
(:mod:`.drag_residual`, module notes): a_k(μ) of g(μ + x) = |μ + x|(μ + x), x ~ N(0, 1),
in closed form, and the lumped orders that carry the higher orders' variance."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

__all__ = ["HERMITE_ORDER", "LUMPED_ORDER", "hermite_coefficients", "lumped_coefficients"]

#: Highest Hermite order kept: k = 2 … 5 carry all but 0.7 % of the residual variance
#: of zero-mean drag (k = 3: 4/(3π) = 0.424 of 3 − 8/π = 0.454). [-]
HERMITE_ORDER = 5
#: Orders of the default evaluation: 2 and 3, each carrying the variance of the higher
#: orders of its parity (:func:`lumped_coefficients`). [-]
LUMPED_ORDER = 3


def hermite_coefficients(mu: Any, order: int = HERMITE_ORDER) -> np.ndarray:
    """Hermite coefficients a_k(μ) of g(μ + x) = |μ + x|(μ + x), x ~ N(0, 1).

    Parameters
    ----------
    mu : array_like, shape (n,)
        Mean over standard deviation of the relative velocity, U/σ. [-]
    order : int
        Highest order k.

    Returns
    -------
    ndarray, shape (n, order + 1)
        a_k = E[g(μ + x) He_k(x)]/k! (probabilists' Hermite polynomials) in closed form
        (Stein's lemma, a_k = E[g⁽ᵏ⁾(μ + x)]/k!, with g' = 2|y|, g'' = 2 sgn y and
        g⁽³⁾ = 4δ(y)): a₀ = (μ² + 1)s + 2μφ(μ), a₁ = 2(μs + 2φ(μ)) = 2E|μ + x| (the
        Borgman coefficient over cσ), a₂ = s and a_k = 4He_{k−3}(−μ)φ(μ)/k! for k ≥ 3,
        s = 2Φ(μ) − 1 = erf(μ/√2) (equal to the quadrature of E[g·He_k]/k! to
        round-off).  The callers clip μ to ±10: beyond, the kink lies more than 10σ out
        (weight e^-50) and g is the polynomial ±(μ + x)², whose residual coefficients no
        longer change (a₂ = ±1, a_k = 0 for k ≥ 3).
    """
    m = np.atleast_1d(np.asarray(mu, dtype=float))
    s = np.array([math.erf(x / math.sqrt(2.0)) for x in m.tolist()]).reshape(m.shape)
    phi = np.exp(-0.5 * m * m) / math.sqrt(2.0 * math.pi)
    out = np.empty((m.size, order + 1))
    firsts = [(m * m + 1.0) * s + 2.0 * m * phi, 2.0 * (m * s + 2.0 * phi), s]
    for k in range(min(order, 2) + 1):
        out[:, k] = firsts[k]
    he_prev, he = np.zeros_like(m), np.ones_like(m)  # He_n(−μ): He_{n+1} = x·He_n − n·He_{n−1}
    for k in range(3, order + 1):
        out[:, k] = 4.0 * he * phi / math.factorial(k)
        he_prev, he = he, -m * he - (k - 3) * he_prev
    return out


def lumped_coefficients(mu: Any, order: int = LUMPED_ORDER) -> np.ndarray:
    """Hermite coefficients (as :func:`hermite_coefficients`) up to ``order`` whose two
    highest (one odd, one even) carry the variance of all higher orders of their
    parity: k!·a_k² of the top odd order is Σ_{j odd ≥ k} j!·a_j², of the top even order
    likewise (sign of a_k kept).

    The sums are closed: Σ_j j!·a_j² = E[g(μ + x)²] = μ⁴ + 6μ² + 3 over all orders, its
    even part E[g(μ + x)·(g(μ + x) + g(μ − x))]/2 (He_j(−x) = (−1)^j He_j(x)).  A panel's
    residual variance is then exact, and the lags' shape of the orders above ``order``
    is that of the top order of their parity (their cross-covariances are taken as
    ρ^order, not ρ^j: tested against the orders kept one by one)."""
    m = np.atleast_1d(np.asarray(mu, dtype=float))
    out = hermite_coefficients(m, order)
    total = m**4 + 6.0 * m**2 + 3.0
    even = 0.5 * (total + _mirror_moment(m))
    tails = {0: even - out[:, 0] ** 2, 1: total - even - out[:, 1] ** 2}
    for k in (order, order - 1):
        if k < 2:
            continue
        below = sum(math.factorial(j) * out[:, j] ** 2 for j in range(k % 2 + 2, k, 2))
        tail = np.maximum(tails[k % 2] - below, 0.0)
        sign = np.where(out[:, k] < 0.0, -1.0, 1.0)
        out[:, k] = sign * np.sqrt(tail / math.factorial(k))
    return out


def _mirror_moment(m: np.ndarray) -> np.ndarray:
    """E[g(μ + x)·g(μ − x)] = E[sgn(μ² − x²)(μ² − x²)²], x ~ N(0, 1), in closed form:
    E[(μ² − x²)²] = μ⁴ − 2μ² + 3 less twice its part over |x| > |μ|, whose moments are
    T₀ = erfc(a/√2), T₂ = 2aφ(a) + T₀, T₄ = 2(a³ + 3a)φ(a) + 3T₀ (a = |μ|)."""
    a = np.abs(m)
    t0 = np.array([math.erfc(x / math.sqrt(2.0)) for x in a.tolist()]).reshape(a.shape)
    phi = np.exp(-0.5 * a * a) / math.sqrt(2.0 * math.pi)
    t2 = 2.0 * a * phi + t0
    t4 = 2.0 * (a**3 + 3.0 * a) * phi + 3.0 * t0
    m2 = m * m
    return m2 * m2 - 2.0 * m2 + 3.0 - 2.0 * (m2 * m2 * t0 - 2.0 * m2 * t2 + t4)
