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

The closed forms are first-order corrections: :func:`residuals_in_range` keeps a
residual out of the statistics where its variance exceeds
:data:`RESIDUAL_VARIANCE_LIMIT` times the linear one at an end (a line going slack),
and says so.
"""

from __future__ import annotations

import math
from collections.abc import Iterable

import numpy as np

from stochcable.errors import PhysicsWarning, warn
from stochcable.results.records import ResidualRecord, ResponseStats, stats_from_moments

__all__ = ["RESIDUAL_VARIANCE_LIMIT", "corrected_stats", "residuals_in_range"]

#: |residual variance| / linear variance of an end tension above which a residual is not
#: applied (the statistics stay the linear model's).  The bundled examples reach 0.41
#: (drag, taut wire); the time domain confirms the residuals up to 0.55 (a slack
#: chain's drag, anchor); the chain 2 m short of vertical (H → 0) reaches 8·10⁵
#: (geometric), where the time domain snaps (docs/manual/scene.rst, "Residuals out of
#: their range"). [-]
RESIDUAL_VARIANCE_LIMIT = 2.0


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


def residuals_in_range(
    name: str, records: dict[str, ResidualRecord], std: dict[str, float]
) -> dict[str, ResidualRecord]:
    """``records``, or, where a computed residual's variance exceeds
    :data:`RESIDUAL_VARIANCE_LIMIT` times the linear variance at an end, every record
    not applied (computed records replaced by ones not computed that say why), with a
    PhysicsWarning: the line is outside the range of the first-order closed forms, all
    taken about the same linear state (on the slack chain the drag residual alone also
    moves σ away from the time domain).

    Parameters
    ----------
    name : str
        The line's name (for the warning). [-]
    records : dict of str to ResidualRecord
        The residuals by kind name.
    std : dict {"end_a", "end_b"} of float
        σ of the linear model's end tensions. [N]

    Returns
    -------
    dict of str to ResidualRecord
        The same keys and records, or, out of range, records not computed.
    """
    ratios = [
        (_ratio(rec.variance[e], std[e]), kind, e)
        for kind, rec in records.items()
        if rec.computed
        for e in std
    ]
    ratio, worst, end = max(ratios, default=(0.0, "", ""))
    if ratio <= RESIDUAL_VARIANCE_LIMIT:
        return records
    x, y = f"{ratio:.3g}", f"{RESIDUAL_VARIANCE_LIMIT:g}"
    warn(
        f"line '{name}': the {worst.replace('_', ' ')} at {end} has {x} × the linear "
        f"variance, above the residuals' range {y} (RESIDUAL_VARIANCE_LIMIT): the "
        "first-order closed forms are out of their depth (a slack line?) and none is "
        "applied, the statistics are the linear model's; check with the nonlinear "
        "time-domain reference (stochcable.reference.cable), or make the line tauter "
        "(pretension) or its mesh finer",
        PhysicsWarning,
        stacklevel=4,
    )
    return {
        kind: ResidualRecord.not_computed(
            f"not applied: variance ratio {x} above its range {y} (at {end})"
            if kind == worst
            else f"not applied: the {worst.replace('_', ' ')}'s variance ratio {x} (at "
            f"{end}) is above the residuals' range {y}",
            std,
        )
        if rec.computed
        else rec
        for kind, rec in records.items()
    }


def _ratio(variance: float, std: float) -> float:
    """|variance| / std² (inf for a variance on a zero σ, 0 for none)."""
    v = abs(float(variance))
    return v / std**2 if std > 0.0 else (math.inf if v > 0.0 else 0.0)
