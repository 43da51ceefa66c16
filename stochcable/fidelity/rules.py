"""The error → resolution rules of the adaptive fidelity planner.

Closed forms that turn a share of the target error into a resolution — the band of a
spectrum (:func:`spectrum_tail_frequency`), elements per wavelength
(:func:`elements_wavelength`), grid points per resonance bandwidth
(:func:`points_per_bandwidth`) — the power-law tail model they share, the non-uniform
grid (:func:`union_grid`) and the tuning constants.  :mod:`stochcable.fidelity.planner`
applies them to a scene.

The error budget ε (relative error of σ) is split into parts (:data:`BUDGET`); each
rule below keeps its part below its share, and the plan's estimate is the sum of the
parts' estimates.

Rules
-----
Band (ω_min, ω_max)
    From the *response* spectra of a cheap pilot analysis (end tensions and the
    line-summed motion), not only from the input spectra: an end-motion spectrum with an
    ω⁻⁵ tail drives inertia loads ∝ ω², so the tension spectrum decays like ω⁻¹ up to
    the first axial resonance of the line and only fast beyond it.  The pilot's grid
    starts at the input spectra's frequency band (variance fraction
    :data:`~stochcable.fidelity.pilot.PILOT_INPUT_FRACTION` outside it) and is doubled
    up to :data:`~stochcable.fidelity.pilot.PILOT_EXTENSIONS` times while the response
    tail beyond its top is not
    bounded or its top is below twice the ω_max it gives (a power-law extrapolation
    misses resonances in the tail).  Four doublings reach the axial regime of a chain
    driven by a PM (ω⁻⁵) fairlead motion: its tension spectrum decays like ω⁻¹ up to
    the first axial resonances (≈ 15 rad/s on chain_catenary) and like ω^-2…ω^-3
    beyond (axial impedance, T ∝ ωx); two doublings stopped at 26.6 rad/s, in the ω⁻¹
    regime, and could not bound the band.  Tail model beyond the pilot's top ω_t:
    S(ω) = S(ω_t)(ω/ω_t)^(-p), p fitted
    to the top fifth (in log ω) of the pilot's spectrum; truncated variance
    S(ω_t)·ω_t/(p − 1) for p > 1 + :data:`MIN_TAIL_EXCESS`, else *unbounded* (reported:
    the linear model's σ then depends on the band).  ω_max is the lowest frequency
    above which the response variance (pilot part + tail bound) is below the band share
    of the budget; ω_min likewise from below (variance below ω is bounded by the pilot's
    lowest bin, where the inputs vanish).
Grid (count and spacing)
    The trapezoid rule on a Lorentzian resonance peak of half-power bandwidth b = 2ζω_j
    sampled every Δω has the relative error 2·exp(−π b/Δω) (Poisson summation of the
    Cauchy density), so N = ln(2/ε_grid)/π points per bandwidth suffice; ζ_j from the
    pilot's modes and linearized drag (plus Rayleigh damping; the seabed damping is
    left out, which only narrows b: conservative).  The smooth input spectra set the
    base spacing: the coarsest linear grid whose trapezoid sums of S, ω²S and ω⁴S
    match a fine quadrature to ε_grid.  The non-uniform grid is the union of the base
    grid and local refinements ±:data:`PEAK_HALF_WIDTHS` bandwidths around each
    lightly damped mode; it is used when ``OmegaGrid`` accepts ``values``, else the
    linear grid with the finest spacing.
Elements
    Transverse string waves c = √(T/m_t), m_t = m + C_a ρ πD²/4: linear elements with
    consistent mass have the dispersion ω_h = ω(1 + (kh)²/24) (Rayleigh quotient of
    the string, Tuah (1982), eq. 3.1.12).  The frequency error that matters is the
    variance-weighted one, so k is taken at the response's mean frequency
    ω₂ = √(m₂/m₀) (pilot) with ⟨1/c²⟩ over the suspended length: h ≤ √(24 ε_el)/(ω₂
    √⟨1/c²⟩), and h ≤ :data:`CUTOFF_KH`/k(ω_max) so no resonance of the band is
    spurious.  Touchdown: a node at the static touchdown
    (:func:`~stochcable.fidelity.meshing.static_touchdowns`; the segment is split
    there) — the linear model's contact state is the static one, so a touchdown
    inside an element errs on the suspended length at first order
    (tuah_1982_single_leg: fairlead σ −3.3 %, +2.0 %, −0.8 %, +0.5 % at 56, 112, 224,
    448 uniform elements, not converging like (kh)²) — and h ≤ suspended length · √ε_el
    (with the node in place the error is second order: +0.33 %, +0.09 % at 28, 56
    elements).  Wave loads: kinematics are
    taken at the nodes and interpolated linearly, so an element of length h
    integrates e^{kz − ikx} with a relative error of about (kh)²/12: elements above the
    depth where e^{kz} < ε_el (k at the sea's ω₂) get h ≤ √(12 ε_el)/k (on the taut
    wire, whose loads vary along x, the observed anchor-tension error is 0.5× this
    estimate), realized by splitting the segment into a top
    sub-segment (same properties) — unless ``exact_wave_integration`` (element-exact
    integration, being added in :mod:`stochcable.dynamics.loads.channels`), which removes this rule.
Modes
    With the static correction, a mode at ω_j contributes (ω/ω_j)² of its dynamic part
    beyond the quasi-static one; keeping the modes up to F·ω_max leaves ≈ C/F²
    (C = :data:`MODE_ERROR_CONSTANT`, from docs/BENCHMARKS.md: 0.24 % at F = 5).  F ≤ 5
    is the engine's "auto"; above :data:`DIRECT_MODES` modes the direct solve is used.
Linearization
    Tolerance = ε_lin: the fixed point's remaining error is at most about the last
    relative change of the σ, and the response σ is at most inversely proportional to
    the drag.

References
----------
Tuah, H. (1982), Cable dynamics in an ocean environment, PhD thesis, Oregon State University.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from stochcable import validation as _v

__all__ = [
    "BUDGET",
    "MIN_TAIL_EXCESS",
    "CUTOFF_KH",
    "MODE_ERROR_CONSTANT",
    "AUTO_FACTOR",
    "DIRECT_MODES",
    "PEAK_HALF_WIDTHS",
    "PEAK_RESOLVED",
    "spectrum_tail_frequency",
    "elements_wavelength",
    "grid_points",
    "points_per_bandwidth",
    "tail_exponent",
    "tail_above",
    "tail_below",
    "crossing_up",
    "crossing_down",
    "union_grid",
]

#: Shares of the target error given to each part (sum 1). [-]
BUDGET: dict[str, float] = {
    "band": 0.3,
    "grid": 0.15,
    "elements": 0.35,
    "modes": 0.1,
    "linearization": 0.1,
}
#: A power-law tail S ∝ ω^-p counts as bounded for p > 1 + MIN_TAIL_EXCESS. [-]
MIN_TAIL_EXCESS = 0.25
#: Largest kh at ω_max (consistent-mass cut-off is kh = √12 ≈ 3.5). [-]
CUTOFF_KH = 1.5
#: Modal truncation error ≈ MODE_ERROR_CONSTANT/F² with the static correction. [-]
MODE_ERROR_CONSTANT = 0.06
#: Engine's "auto" factor (stochcable.dynamics.model.system.AUTO_MODE_FACTOR). [-]
AUTO_FACTOR = 5.0
#: Above this many kept modes the direct solver is chosen. [-]
DIRECT_MODES = 40
#: Local refinement around a mode: ± this many half-power bandwidths. [-]
PEAK_HALF_WIDTHS = 4.0
#: A mode needs refinement when its bandwidth is below this many base spacings. [-]
PEAK_RESOLVED = 4.0


# ------------------------------------------------------------------- closed forms


def tail_exponent(w: np.ndarray, s: np.ndarray, top_fraction: float = 0.2) -> float:
    """p of a power-law fit S ∝ ω^-p to the top ``top_fraction`` of log ω."""
    lw = np.log(w)
    sel = (lw >= lw[-1] - top_fraction * (lw[-1] - lw[0])) & (s > 0)
    if np.count_nonzero(sel) < 3:
        return math.inf if s[-1] <= 0 else 0.0
    slope = np.polyfit(lw[sel], np.log(s[sel]), 1)[0]
    return float(-slope)


def tail_above(w: np.ndarray, s: np.ndarray, p: float) -> np.ndarray:
    """∫_{ω_i}^∞ S dω for every grid point: trapezoid on the grid plus the power-law
    tail S(ω_t)ω_t/(p − 1) beyond the top (inf when p <= 1 + MIN_TAIL_EXCESS)."""
    seg = 0.5 * (s[1:] + s[:-1]) * np.diff(w)
    inner = np.concatenate([np.cumsum(seg[::-1])[::-1], [0.0]])
    if s[-1] <= 0.0:
        tail = 0.0
    elif p > 1.0 + MIN_TAIL_EXCESS:
        tail = s[-1] * w[-1] / (p - 1.0)
    else:
        tail = math.inf
    return inner + tail


def tail_below(w: np.ndarray, s: np.ndarray) -> np.ndarray:
    """∫_0^{ω_i} S dω: trapezoid plus the first bin's S(ω_0)·ω_0 (bound for S rising
    at least linearly from 0 — the inputs of ocean spectra vanish faster)."""
    seg = 0.5 * (s[1:] + s[:-1]) * np.diff(w)
    return np.concatenate([[0.0], np.cumsum(seg)]) + s[0] * w[0]


def crossing_up(w: np.ndarray, frac: np.ndarray, limit: float) -> float:
    """Lowest ω (log-interpolated) from which ``frac`` (decreasing) stays <= limit."""
    bad = np.flatnonzero(frac > limit)
    if bad.size == 0:
        return float(w[0])
    i = int(bad[-1])
    if i >= w.size - 1:
        return float(w[-1])
    f0, f1 = frac[i], frac[i + 1]
    t = 1.0 if not np.isfinite(f0) or f0 == f1 else (f0 - limit) / (f0 - f1)
    return float(math.exp(math.log(w[i]) + t * (math.log(w[i + 1]) - math.log(w[i]))))


def crossing_down(w: np.ndarray, frac: np.ndarray, limit: float) -> float:
    """Highest ω (log-interpolated) up to which ``frac`` (increasing) stays <= limit."""
    bad = np.flatnonzero(frac > limit)
    if bad.size == 0:
        return float(w[-1])
    i = int(bad[0])
    if i == 0:
        return float(w[0])
    f0, f1 = frac[i - 1], frac[i]
    t = (limit - f0) / (f1 - f0) if f1 != f0 else 0.0
    return float(math.exp(math.log(w[i - 1]) + t * (math.log(w[i]) - math.log(w[i - 1]))))


def spectrum_tail_frequency(omega: Any, density: Any, fraction: float) -> tuple[float, float]:
    """Band [ω_lo, ω_hi] outside which a spectrum holds at most ``fraction`` of m0 on
    each side.

    Parameters
    ----------
    omega : array_like
        Increasing frequencies covering the spectrum. [rad/s]
    density : array_like
        One-sided spectral density at ``omega``. [unit²·s/rad]
    fraction : float
        Variance fraction allowed above ω_hi (and, separately, below ω_lo). [-]

    Returns
    -------
    (float, float)
        ω_lo and ω_hi. [rad/s]

    Notes
    -----
    Beyond the last sample the tail S(ω_t)(ω/ω_t)^-p, p fitted to the top fifth of
    log ω, holds S(ω_t)·ω_t/(p − 1) (an ω⁻⁵ tail: S·ω/4).  For Pierson–Moskowitz the
    exact result is ω_hi = ω_p (1.25/(−ln(1 − fraction)))^{1/4}, since
    ∫_ω^∞ S = m0 (1 − exp(−1.25 (ω_p/ω)⁴)) (DESIGN.md "Wave spectra").
    """
    w = _v.float_array("omega", omega, "rad/s", positive=True, increasing=True, min_size=3)
    s = _v.float_array("density", density, "unit²·s/rad", nonnegative=True)
    frac = _v.in_range("fraction", fraction, "-", 0.0, 0.5, lo_open=True, hi_open=True)
    if s.shape != w.shape:
        raise _v.InputError(
            "density", f"shape {s.shape}", "unit²·s/rad", f"must have the shape of omega {w.shape}"
        )
    above = tail_above(w, s, tail_exponent(w, s))
    below = tail_below(w, s)
    m0 = below[-1] + above[-1]
    if not np.isfinite(m0) or m0 <= 0.0:
        raise _v.InputError(
            "density",
            "spectrum",
            "unit²·s/rad",
            "must have a positive, finite variance (tail decaying faster than 1/ω)",
        )
    return crossing_down(w, below / m0, frac), crossing_up(w, above / m0, frac)


def elements_wavelength(
    length: float, omega: float, celerity: float, frequency_error: float
) -> int:
    """Linear elements with consistent mass for a string-wave frequency error.

    Parameters
    ----------
    length : float
        Segment length. [m]
    omega : float
        Frequency to resolve. [rad/s]
    celerity : float
        Transverse wave speed √(T/m_t). [m/s]
    frequency_error : float
        Relative frequency error allowed. [-]

    Returns
    -------
    int
        ceil(length·k/(kh)_max), k = ω/c, (kh)_max = √(24·frequency_error), at least 1.

    Notes
    -----
    A string discretized by linear elements with consistent mass (Tuah (1982), eq. 3.1.12)
    has ω_h² = (c²/h²)·6(1 − cos kh)/(2 + cos kh) = c²k²(1 + (kh)²/12 + O(kh)⁴), so
    ω_h/ω − 1 = (kh)²/24.
    """
    L = _v.positive("length", length, "m")
    w = _v.positive("omega", omega, "rad/s")
    c = _v.positive("celerity", celerity, "m/s")
    e = _v.in_range("frequency_error", frequency_error, "-", 0.0, 0.5, lo_open=True)
    kh = math.sqrt(24.0 * e)
    return max(1, int(math.ceil(L * (w / c) / kh - 1e-9)))


def grid_points(span: float, dw: float) -> int:
    """Points of a linear grid over ``span`` [rad/s] with spacing at most ``dw``
    [rad/s]: a base grid's own spacing span/(n − 1) gives n again (the quotient's
    round-off above n − 1, 199.00000000000003, asked for one point more than a limit)."""
    return int(math.ceil(span / dw * (1.0 - 1e-12))) + 1


def points_per_bandwidth(error: float) -> float:
    """Grid points per half-power bandwidth for a trapezoid error of a resonance peak.

    Parameters
    ----------
    error : float
        Relative error of the peak's area allowed. [-]

    Returns
    -------
    float
        N = ln(2/error)/π. [-]

    Notes
    -----
    A Lorentzian L(ω) = (γ/π)/((ω − ω_j)² + γ²), half-power bandwidth b = 2γ,
    sampled every Δω: by Poisson summation Σ Δω L(ω_j + nΔω + δ) = 1 + 2 Σ_m
    e^{−2πmγ/Δω} cos(2πmδ/Δω), so the relative error is at most ≈ 2e^{−π b/Δω}.
    """
    e = _v.in_range("error", error, "-", 0.0, 1.0, lo_open=True, hi_open=True)
    return max(1.0, math.log(2.0 / e) / math.pi)


def union_grid(
    w_min: float, w_max: float, base: int, peaks: list[tuple[float, float]], n_bw: float
) -> np.ndarray:
    """The base linear grid of ``base`` points on [w_min, w_max] united with, around
    every (ω_j, b_j) of ``peaks``, ± :data:`PEAK_HALF_WIDTHS` bandwidths sampled at
    b_j/n_bw (points closer than 1e-9·w_max merged). [rad/s]"""
    parts = [np.linspace(w_min, w_max, base)]
    for wj, bj in peaks:
        a, b = max(w_min, wj - PEAK_HALF_WIDTHS * bj), min(w_max, wj + PEAK_HALF_WIDTHS * bj)
        n = int(math.ceil((b - a) / (bj / n_bw))) + 1
        parts.append(np.linspace(a, b, max(n, 2)))
    x = np.unique(np.concatenate(parts))
    keep = np.concatenate([[True], np.diff(x) > 1e-9 * w_max])
    return x[keep]
