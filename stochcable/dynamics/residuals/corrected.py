"""The end-tension statistics with the residuals of the linear model: the spectral
moments of the linear spectrum plus those of every residual's variance lines.

The residuals are uncorrelated with the linear response at every lag (Hermite
orthogonality for the drag's orders ≥ 2, odd Gaussian moments for the geometric
forces; Roberts and Spanos, "Random Vibration and Statistical Linearization", §5), so
the spectrum of the corrected tension is the sum of the linear spectrum and the
residuals' spectra, and so are its moments m_n = ∫ωⁿS dω: the linear ones on the
analysis grid (trapezoid), the residuals' as sums over their lines (Σ ωⁿ·v), which
reach the superharmonics above the analysis band.  σ, Tz, the bandwidth and the
Rayleigh maxima follow from the moments as for any Gaussian response
(:func:`stochcable.results.records.stats_from_moments`): the residuals'
non-Gaussian part (skewness, kurtosis) does not enter them.
"""

from __future__ import annotations

from collections.abc import Iterable

import numpy as np

from stochcable.results.records import ResidualRecord, ResponseStats, stats_from_moments

__all__ = ["corrected_stats"]


def corrected_stats(
    linear: ResponseStats, end: str, records: Iterable[ResidualRecord], duration: float
) -> ResponseStats:
    """The statistics of the end tension at ``end`` with the residuals of ``records``
    (module notes).

    Parameters
    ----------
    linear : ResponseStats
        The linear model's statistics of that end tension.
    end : str
        "end_a" or "end_b".
    records : iterable of ResidualRecord
        The computed residuals (their ``lines``; records not computed add nothing).
    duration : float
        The storm duration of ``mpm`` and ``expected_max``. [s]

    Returns
    -------
    ResponseStats
        The same mean; the moments with the residuals' and every statistic from them.
    """
    m = np.array([linear.m0, linear.m1, linear.m2, linear.m4], dtype=float)
    for rec in records:
        for omega, lines in rec.lines:
            v = np.asarray(lines[end], dtype=float)
            m += [float(np.sum(v * omega**n)) for n in (0, 1, 2, 4)]
    m[0] = max(m[0], 0.0)  # (a negative misfit change is clipped at the linear σ², as σ)
    return stats_from_moments(m, linear.mean, duration)
