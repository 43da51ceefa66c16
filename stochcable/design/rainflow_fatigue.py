"""Rainflow fatigue: Miner's sum of the rainflow-counted ranges of a time series.

The counting is fatpack's (``fatpack.find_rainflow_ranges``, ASTM E1049 four-point
rainflow on the reversals, with the residue closed by counting it against itself),
not a hand-written one; this module validates, counts and sums.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from stochcable import validation as v
from stochcable.errors import InputError

from .curves import FatigueCurve

__all__ = ["rainflow_ranges", "damage_rainflow"]


def rainflow_ranges(series: ArrayLike, *, n_classes: int = 4096) -> np.ndarray:
    """Rainflow cycle ranges of a time series (residue closed as full cycles).

    Parameters
    ----------
    series : array_like, shape (n,)
        Time series of the curve's quantity (stress or tension ratio), n >= 3. [unit]
    n_classes : int, default 4096
        Number of load classes fatpack divides the (min, max) span into; reversals
        are taken on the class mid-levels, so ranges carry an error below one class
        width (max − min)/n_classes and excursions smaller than one class are
        dropped. [-]

    Returns
    -------
    numpy.ndarray
        Ranges of the full cycles (empty if the series has no cycle). [unit]

    Notes
    -----
    ``fatpack.find_rainflow_ranges`` counts the cycles of the series and then of its
    residue concatenated with itself, i.e. the record is treated as one period of a
    periodic signal — exact for a DSA/NSA realization, which is periodic in its
    record length.
    """
    import fatpack

    y = v.float_array("series", series, "unit", min_size=3)
    k = v.positive_int("n_classes", n_classes, minimum=2)
    if not np.ptp(y) > 0.0:
        return np.zeros(0)
    try:
        return np.asarray(fatpack.find_rainflow_ranges(y, k=k), dtype=float)
    except (ValueError, IndexError):
        # fatpack raises when the series has no full cycle (e.g. monotonic)
        return np.zeros(0)


def damage_rainflow(
    series: ArrayLike,
    curve: FatigueCurve,
    *,
    duration: float | None = None,
    n_classes: int = 4096,
) -> float:
    """Miner's sum of the rainflow ranges of a time series.

    Parameters
    ----------
    series : array_like, shape (n,)
        Time series of the curve's quantity: stress [Pa] on the nominal area for a
        ``"stress"`` curve, tension/MBS [-] for a ``"tension_ratio"`` curve. [unit]
    curve : FatigueCurve
        Fatigue curve.
    duration : float, optional
        Length of the record; if given the damage per unit time D/duration is
        returned. [s]
    n_classes : int, default 4096
        Load classes of the counting (see :func:`rainflow_ranges`). [-]

    Returns
    -------
    float
        Σ 1/N(S_i) over the counted cycles [-], or per unit time [1/s] with
        ``duration``.

    Notes
    -----
    Palmgren–Miner linear damage, D = Σ n_i/N(S_i), with N from
    :meth:`FatigueCurve.cycles_to_failure`; the mean of a cycle is ignored (as the
    DNV and API mooring curves do).
    """
    if not isinstance(curve, FatigueCurve):
        raise InputError("curve", type(curve).__name__, "-", "must be a FatigueCurve")
    dur = None if duration is None else v.positive("duration", duration, "s")
    ranges = rainflow_ranges(series, n_classes=n_classes)
    d = curve.damage(ranges) if ranges.size else 0.0
    return d / dur if dur is not None else d
