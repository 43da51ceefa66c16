"""Fatigue (S-N and T-N) curves as data: the DNV and API mooring curves and user curves.

A curve gives the number of cycles to failure of a constant-amplitude range,
N = a·S^(−m), with one or two segments (slope change at a transition range) and an
optional endurance limit (ranges at or below it do no damage).  Its *quantity* is either
a stress range on a nominal area [Pa] (DNV-OS-E301 style) or a tension range divided by
the minimum breaking strength [-] (API RP 2SK style); :func:`tension_to_curve_quantity`
gives the factor that turns a tension [N] into that quantity.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from stochcable import validation as v
from stochcable.errors import InputError

__all__ = [
    "FatigueCurve",
    "CurveSegment",
    "fatigue_curve",
    "fatigue_curve_user",
    "curve_names",
    "tension_to_curve_quantity",
]

_QUANTITIES = {"stress": "Pa", "tension_ratio": "-"}

# DNV-OS-E301 (October 2010, Ch.2 Sec.2 Table D1 "S-N fatigue curve parameters"; the
# same values in DNVGL-OS-E301, July 2015 and later):
# N = a_D·S^(−m), S the nominal stress range in MPa.
_DNV = {
    "dnv-studlink": ("stud chain", 1.2e11, 3.0),
    "dnv-studless": ("studless chain", 6.0e10, 3.0),
    "dnv-six-strand": ("stranded (six-strand) rope", 3.4e14, 4.0),
    "dnv-spiral-strand": ("spiral rope", 1.7e17, 4.8),
}
# API RP 2SK 3rd ed. (October 2005) fatigue section, T-N curves N·R^M = K, R = tension range/MBS.
# Chain: K independent of the mean load.  Wire ropes: log10 K = a − b·Lm, Lm the ratio
# of the mean load to the MBS.
_API_CHAIN = {
    "api-studlink": ("common studlink chain", 1000.0, 3.0),
    "api-studless": ("common studless chain", 316.0, 3.0),
}
_API_ROPE = {
    "api-six-strand": ("six/multi-strand rope", 3.20, 2.79, 4.09),
    "api-spiral-strand": ("spiral strand rope", 3.25, 3.43, 5.05),
}
_DNV_SOURCE = (
    "DNV-OS-E301 Position Mooring (Oct. 2010) Ch.2 Sec.2 D, Table D1 "
    "(= DNVGL-OS-E301 (2015)): {what}, a_D = {a:.3g} MPa^m, m = {m:g}; "
    "stress range on the nominal area, converted to Pa"
)
_API_SOURCE = (
    "API RP 2SK 3rd ed. (2005), fatigue T-N curve N·R^M = K: {what}, {k}, M = {m:g}; "
    "R = tension range / MBS"
)


@dataclass(frozen=True)
class CurveSegment:
    """One power-law segment of a fatigue curve, N = a·S^(−m) for lower < S <= upper.

    Attributes
    ----------
    lower : float
        Lower end of the range interval (the endurance limit, a transition or 0).
        [curve unit]
    upper : float
        Upper end (``inf`` for the top segment). [curve unit]
    slope : float
        Inverse slope m. [-]
    log10_a : float
        log10 of the intercept a in the curve's unit (a in [unit^m]). [-]
    """

    lower: float
    upper: float
    slope: float
    log10_a: float


@dataclass(frozen=True)
class FatigueCurve:
    """A one- or two-slope fatigue curve N = a·S^(−m) with an optional endurance limit.

    Attributes
    ----------
    name : str
        Catalogue name (``"dnv-studless"``) or the user's name. [-]
    source : str
        Citation of the standard, edition and table the constants come from. [-]
    quantity : {"stress", "tension_ratio"}
        What S is: a stress range on the nominal area [Pa] or a tension range divided
        by the minimum breaking strength [-]. [-]
    slopes : tuple of float
        Inverse slopes m_k, high-range segment first. [-]
    log10_intercepts : tuple of float
        log10 a_k in the curve's unit (SI: S in Pa for ``"stress"``), one per slope. [-]
    transition : float or None
        Range where the two segments meet (two-slope curves only). [unit]
    endurance_limit : float or None
        Ranges at or below it do no damage (infinite life). [unit]
    unit : str
        Unit of S: ``"Pa"`` or ``"-"``. [-]

    Notes
    -----
    Miner's rule with N(S) = a_k S^(−m_k) on segment k.  The sources give log10 a with
    S in MPa; a curve in Pa has log10 a_Pa = log10 a_MPa + 6 m (S_MPa = S_Pa/10⁶).
    """

    name: str
    source: str
    quantity: str
    slopes: tuple[float, ...]
    log10_intercepts: tuple[float, ...]
    transition: float | None = None
    endurance_limit: float | None = None
    unit: str = "Pa"

    def __post_init__(self) -> None:
        _check_quantity(self.quantity)
        if self.unit != _QUANTITIES[self.quantity]:
            raise InputError(
                "unit",
                self.unit,
                "-",
                f"must be {_QUANTITIES[self.quantity]!r} for {self.quantity}",
            )
        n = len(self.slopes)
        if n not in (1, 2) or len(self.log10_intercepts) != n:
            raise InputError(
                "slopes", self.slopes, "-", "one or two slopes, one log10 intercept each"
            )
        for m in self.slopes:
            v.positive("slopes", m, "-")
        for la in self.log10_intercepts:
            v.finite_scalar("log10_intercepts", la, "-")
        if (n == 2) != (self.transition is not None):
            raise InputError(
                "transition", self.transition, self.unit, "is given exactly for two-slope curves"
            )
        if self.transition is not None:
            v.positive("transition", self.transition, self.unit)
        if self.endurance_limit is not None:
            v.positive("endurance_limit", self.endurance_limit, self.unit)

    def segments(self) -> tuple[CurveSegment, ...]:
        """The power-law segments covering (endurance limit, ∞), highest range first.

        Returns
        -------
        tuple of CurveSegment
            One per slope; the spectral methods integrate the range PDF over each.
        """
        floor = self.endurance_limit or 0.0
        if len(self.slopes) == 1:
            return (CurveSegment(floor, math.inf, self.slopes[0], self.log10_intercepts[0]),)
        t = float(self.transition)  # two slopes always carry a transition
        return (
            CurveSegment(max(t, floor), math.inf, self.slopes[0], self.log10_intercepts[0]),
            CurveSegment(floor, max(t, floor), self.slopes[1], self.log10_intercepts[1]),
        )

    def cycles_to_failure(self, ranges: ArrayLike) -> np.ndarray:
        """Cycles to failure N(S) of constant-amplitude ranges (vectorized).

        Parameters
        ----------
        ranges : array_like
            Ranges S >= 0 (peak to trough) in the curve's quantity. [unit]

        Returns
        -------
        numpy.ndarray
            N(S), same shape; ``inf`` for S = 0 and S at or below the endurance
            limit. [-]
        """
        s = v.float_array("ranges", ranges, self.unit, ndim=None, nonnegative=True)
        out = np.full(s.shape, math.inf)
        for seg in self.segments():
            sel = (s > seg.lower) & (s <= seg.upper) & (s > 0.0)
            out[sel] = 10.0 ** (seg.log10_a - seg.slope * np.log10(s[sel]))
        return out

    def damage(self, ranges: ArrayLike, counts: ArrayLike | None = None) -> float:
        """Miner's sum Σ n_i/N(S_i) of counted ranges.

        Parameters
        ----------
        ranges : array_like
            Cycle ranges. [unit]
        counts : array_like, optional
            Number of cycles of each range (1 each if omitted; 0.5 for half cycles). [-]

        Returns
        -------
        float
            Damage D (failure at D = 1). [-]
        """
        n = self.cycles_to_failure(ranges)
        c = (
            np.ones_like(n)
            if counts is None
            else v.float_array("counts", counts, "-", ndim=None, nonnegative=True)
        )
        if c.shape != n.shape:
            raise InputError("counts", counts, "-", f"must have the shape of ranges {n.shape}")
        return float(np.sum(c / n))


def _check_quantity(quantity: str) -> str:
    q = str(quantity)
    if q not in _QUANTITIES:
        raise InputError("quantity", quantity, "-", f"must be one of {sorted(_QUANTITIES)}")
    return q


def fatigue_curve_user(
    name: str,
    *,
    quantity: str,
    slope: float,
    log10_a: float,
    slope2: float | None = None,
    transition_cycles: float | None = None,
    endurance_limit: float | None = None,
    source: str = "user curve",
) -> FatigueCurve:
    """A user fatigue curve with one or two slopes and an optional endurance limit.

    Parameters
    ----------
    name : str
        Name of the curve. [-]
    quantity : {"stress", "tension_ratio"}
        Stress range on a nominal area in Pa, or tension range / MBS. [-]
    slope : float
        Inverse slope m1 of the high-range segment, > 0. [-]
    log10_a : float
        log10 a1 with S in the curve's unit (Pa or -). [-]
    slope2 : float, optional
        Inverse slope m2 of the low-range segment (two-slope curve), > 0. [-]
    transition_cycles : float, optional
        N where the slope changes (e.g. 10⁷ in DNV-RP-C203); required with ``slope2``.
        [-]
    endurance_limit : float, optional
        Range at or below which no damage occurs, > 0. [Pa or -]
    source : str, default "user curve"
        Citation. [-]

    Returns
    -------
    FatigueCurve
        The second intercept follows from continuity at the transition:
        log10 a2 = log10 a1 + (m2 − m1) log10 S_t, S_t = (a1/N_t)^(1/m1).
    """
    q = _check_quantity(quantity)
    unit = _QUANTITIES[q]
    m1 = v.positive("slope", slope, "-")
    la1 = v.finite_scalar("log10_a", log10_a, "-")
    limit = (
        None if endurance_limit is None else v.positive("endurance_limit", endurance_limit, unit)
    )
    if slope2 is None:
        if transition_cycles is not None:
            raise InputError(
                "transition_cycles", transition_cycles, "-", "needs slope2 (a two-slope curve)"
            )
        return FatigueCurve(str(name), str(source), q, (m1,), (la1,), None, limit, unit)
    m2 = v.positive("slope2", slope2, "-")
    if transition_cycles is None:
        raise InputError("transition_cycles", None, "-", "is required with slope2")
    n_t = v.positive("transition_cycles", transition_cycles, "-")
    log_st = (la1 - math.log10(n_t)) / m1
    la2 = la1 + (m2 - m1) * log_st
    return FatigueCurve(str(name), str(source), q, (m1, m2), (la1, la2), 10.0**log_st, limit, unit)


def curve_names() -> tuple[str, ...]:
    """Names of the catalogue curves accepted by :func:`fatigue_curve`."""
    return tuple(_DNV) + tuple(_API_CHAIN) + tuple(_API_ROPE)


def fatigue_curve(name: str, *, mean_load_ratio: float | None = None) -> FatigueCurve:
    """A catalogue fatigue curve by name.

    Parameters
    ----------
    name : str
        One of ``dnv-studlink``, ``dnv-studless``, ``dnv-six-strand``,
        ``dnv-spiral-strand`` (DNV-OS-E301 S-N curves, stress range in Pa on the
        nominal area) and ``api-studlink``, ``api-studless``, ``api-six-strand``,
        ``api-spiral-strand`` (API RP 2SK T-N curves, tension range / MBS). [-]
    mean_load_ratio : float, optional
        Lm = mean tension / MBS, in [0, 1); required by the API wire-rope curves,
        whose intercept depends on it (log10 K = a − b·Lm), refused for the others. [-]

    Returns
    -------
    FatigueCurve

    Notes
    -----
    DNV-OS-E301 (2010) Ch.2 Sec.2 Table D1 / DNVGL-OS-E301 (2015),
    N = a_D S^(−m), S in MPa: stud chain a_D = 1.2·10¹¹, m = 3.0; studless chain
    6.0·10¹⁰, 3.0; stranded rope 3.4·10¹⁴, 4.0; spiral rope 1.7·10¹⁷, 4.8.  Stored in
    Pa: log10 a = log10 a_D + 6 m.  The table and section numbers in the ``source``
    strings are as recalled and were not checked against the standards' texts.  The
    chain values were confirmed against two
    independent secondary sources (a DNV-GL ``qats`` example and a mooring-fatigue
    calculator page quoting OS-E301); the rope values are from the standard as recalled
    and could not be confirmed from a second source here — check them against your
    edition before design use.

    API RP 2SK 3rd ed. (2005), fatigue section, N R^M = K, R = tension range / MBS: common
    studlink chain M = 3.0, K = 1000; common studless chain M = 3.0, K = 316;
    six/multi-strand rope M = 4.09, log10 K = 3.20 − 2.79 Lm; spiral strand rope
    M = 5.05, log10 K = 3.25 − 3.43 Lm.  Not confirmed from a second source here
    either.  None of the catalogue curves has an endurance limit (DNV and API give none
    for mooring components in sea water).
    """
    key = str(name).strip().lower()
    if key in _DNV:
        what, a_d, m = _DNV[key]
        _no_mean_load(key, mean_load_ratio)
        source = _DNV_SOURCE.format(what=what, a=a_d, m=m)
        return FatigueCurve(key, source, "stress", (m,), (math.log10(a_d) + 6.0 * m,), unit="Pa")
    if key in _API_CHAIN:
        what, k, m = _API_CHAIN[key]
        _no_mean_load(key, mean_load_ratio)
        source = _API_SOURCE.format(what=what, k=f"K = {k:g}", m=m)
        return FatigueCurve(key, source, "tension_ratio", (m,), (math.log10(k),), unit="-")
    if key in _API_ROPE:
        what, a, b, m = _API_ROPE[key]
        if mean_load_ratio is None:
            raise InputError(
                "mean_load_ratio",
                None,
                "-",
                f"is required by {key} (log10 K = {a:g} − {b:g}·Lm, Lm = mean tension / MBS)",
            )
        lm = v.in_range("mean_load_ratio", mean_load_ratio, "-", 0.0, 1.0, hi_open=True)
        log_k = a - b * lm
        source = _API_SOURCE.format(
            what=what, k=f"log10 K = {a:g} − {b:g}·Lm with Lm = {lm:g}", m=m
        )
        return FatigueCurve(key, source, "tension_ratio", (m,), (log_k,), unit="-")
    raise InputError("name", name, "-", f"must be one of {list(curve_names())}")


def _no_mean_load(key: str, mean_load_ratio: float | None) -> None:
    if mean_load_ratio is not None:
        raise InputError(
            "mean_load_ratio",
            mean_load_ratio,
            "-",
            f"applies only to the API rope curves, not {key}",
        )


def tension_to_curve_quantity(
    curve: FatigueCurve,
    *,
    nominal_diameter: float | None = None,
    nominal_area: float | None = None,
    mbs: float | None = None,
) -> float:
    """Factor that turns a tension [N] into the curve's quantity.

    Parameters
    ----------
    curve : FatigueCurve
        The curve.
    nominal_diameter : float, optional
        Chain bar diameter d, for the DNV chain curves (nominal area 2·πd²/4). [m]
    nominal_area : float, optional
        Nominal cross-section area, for any ``"stress"`` curve (required for the rope
        curves: the metallic area of the rope). [m²]
    mbs : float, optional
        Minimum breaking strength, for ``"tension_ratio"`` curves. [N]

    Returns
    -------
    float
        1/A [1/m²] for a stress curve (S = T/A in Pa), 1/MBS [1/N] for a tension-ratio
        curve.  A tension spectrum is multiplied by its square.

    Notes
    -----
    DNV-OS-E301 (2010) Ch.2 Sec.2 D: the nominal stress is the tension over the
    nominal cross-section; for chain the area of the two legs of a link, 2·πd²/4 with
    d the bar diameter.  For wire ropes the standard refers to the rope's nominal
    (metallic) cross-section, which depends on its construction: give
    ``nominal_area`` (from the manufacturer) — a diameter alone is refused.
    """
    if not isinstance(curve, FatigueCurve):
        raise InputError("curve", type(curve).__name__, "-", "must be a FatigueCurve")
    if curve.quantity == "tension_ratio":
        if mbs is None:
            raise InputError("mbs", None, "N", f"is required by {curve.name} (tension range / MBS)")
        return 1.0 / v.positive("mbs", mbs, "N")
    if nominal_area is not None:
        if nominal_diameter is not None:
            raise InputError(
                "nominal_diameter", nominal_diameter, "m", "give nominal_area or nominal_diameter"
            )
        return 1.0 / v.positive("nominal_area", nominal_area, "m²")
    if nominal_diameter is None:
        raise InputError(
            "nominal_area", None, "m²", f"is required by {curve.name} (stress on the nominal area)"
        )
    if curve.name not in ("dnv-studlink", "dnv-studless"):
        raise InputError(
            "nominal_diameter",
            nominal_diameter,
            "m",
            f"defines the nominal area of DNV chain only; give nominal_area for {curve.name}",
        )
    d = v.positive("nominal_diameter", nominal_diameter, "m")
    return 1.0 / (2.0 * math.pi * d * d / 4.0)
