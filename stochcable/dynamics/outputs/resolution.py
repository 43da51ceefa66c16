"""Resolution checks of the linear model of one line, each with its warning: of the
natural frequencies by the frequency grid (:func:`resolution_check`, the trapezoid
rule's error on a resonant peak: :func:`peak_quadrature_error`), of the wave kinematics
by the mesh near the surface (:func:`surface_resolution_check`) and of the response
tail by ω_max where the excitation goes on above it (:func:`tail_check`,
:func:`excitation_end`).  The quality indicators of the response are in
:mod:`stochcable.dynamics.outputs.indicators`.

References
----------
Tuah, H. (1982), Cable dynamics in an ocean environment, PhD thesis, Oregon State University.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from stochcable.dynamics.loads.channels import Channel
from stochcable.dynamics.model.blocks import add_blocks, block_matvec, line_prep, trapezoid_weights
from stochcable.dynamics.model.system import Damping, LineSystem
from stochcable.dynamics.solve.line_loads import drag_blocks
from stochcable.errors import ResolutionWarning, warn
from stochcable.scene.units import unit_labels


@dataclass(frozen=True, eq=False)
class LineModes:
    """The natural modes that count for a line's indicators, when they are not its
    own fixed-end modes (a line on bodies: the coupled modes with a share of the
    line, :func:`stochcable.dynamics.groups.results.line_modes`).

    Attributes
    ----------
    numbers : ndarray of int, shape (n,)
        1-based numbers of the modes in their list (the messages name them).
    omega : ndarray, shape (n,)
        Natural frequencies. [rad/s]
    bandwidth : ndarray, shape (n,)
        Half-power bandwidths 2ζω = φᵀCφ (mass-normalized φ). [rad/s]
    label : str
        How the messages call them ("coupled mode").
    """

    numbers: np.ndarray
    omega: np.ndarray
    bandwidth: np.ndarray
    label: str = "coupled mode"


def own_modes(system: LineSystem, damping: Damping, modes: LineModes | None) -> LineModes:
    """``modes``, or the line's own fixed-end modes with their bandwidths."""
    if modes is not None:
        return modes
    wn = np.asarray(system.modes.omega)
    return LineModes(np.arange(1, wn.size + 1), wn, modal_bandwidths(system, damping), "mode")


def modal_bandwidths(system: LineSystem, damping: Damping) -> np.ndarray:
    """φ_jᵀCφ_j of every computed mode (mass-normalized φ; C = structural damping +
    ``damping``): the half-power bandwidth 2ζ_jω_j, (n_modes,), cached on the damping
    (the resolution check and the indicators both use it). [rad/s]"""
    if "modal_band" not in damping._cache:
        prep = line_prep(system)
        c = add_blocks(prep.S, drag_blocks(system, damping))
        phi = np.ascontiguousarray(system.modes.shapes[system.model.free])
        damping._cache["modal_band"] = np.einsum(
            "ij,ij->j", phi, prep.free_rows(block_matvec(c, prep.nodes(phi)))
        )
    return damping._cache["modal_band"]


def _nearest_spacing(omega: np.ndarray, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Distance of each x (inside the increasing grid) to its nearest grid point and
    the local spacing there, ``np.gradient(omega)`` at that point (central difference
    inside, one-sided at the ends; the same bits), without the (n_x, n_omega) argmin
    matrix: the nearest point is one of the two around the insertion point (the lower
    of two equidistant ones, as argmin). [rad/s]"""
    n = omega.size
    hi = np.searchsorted(omega, x)
    lo = np.maximum(hi - 1, 0)
    d_lo, d_hi = np.abs(omega[lo] - x), np.abs(omega[hi] - x)
    near = np.where(d_lo <= d_hi, lo, hi)
    a, b = np.maximum(near - 1, 0), np.minimum(near + 1, n - 1)
    spacing = (omega[b] - omega[a]) / np.where((near > 0) & (near < n - 1), 2.0, 1.0)
    return np.minimum(d_lo, d_hi), spacing


#: Largest error of the trapezoid rule on a resonant peak before :func:`resolution_check`
#: warns. [-]  On a uniform grid of spacing Δω the rule integrates a Lorentzian peak of
#: half-power bandwidth b to within ±(coth(πb/(2Δω)) − 1) (Poisson summation; the sign
#: depends on where the peak falls between two frequencies): 1 % at Δω = 0.59 b, 4.5 %
#: at the inclined guy's 0.83 b (its mode 2, ζ = 0.67 %; the frequency-domain end
#: tension σ 4 % off the time domain's, docs/ACCURACY.md), 9 % at Δω = b.
RESONANCE_PEAK_ERROR = 0.01


def peak_quadrature_error(bandwidth: ArrayLike, spacing: ArrayLike) -> np.ndarray:
    """Largest relative error of the trapezoid rule on a resonant peak.

    Parameters
    ----------
    bandwidth : array_like
        Half-power bandwidth b = 2ζω of the mode. [rad/s]
    spacing : array_like
        Grid spacing Δω near the mode. [rad/s]

    Returns
    -------
    ndarray
        coth(πb/(2Δω)) − 1 (inf for b = 0). [-]

    Notes
    -----
    |H|² of a mode near resonance is the Lorentzian 1/((ω − ω_j)² + (b/2)²), whose
    trapezoid sum over an unbounded uniform grid is, by Poisson summation, the integral
    times sinh(a)/(cosh(a) − cos θ) with a = πb/Δω and θ the peak's offset from the grid
    (in units of 2π/Δω): at most coth(a/2), at least tanh(a/2).
    """
    a = np.pi * np.asarray(bandwidth, dtype=float) / np.asarray(spacing, dtype=float)
    with np.errstate(divide="ignore"):
        return np.where(a > 0, 1.0 / np.tanh(np.maximum(a, 1e-300) / 2.0) - 1.0, np.inf)


def resolution_check(
    system: LineSystem, damping: Damping, omega: np.ndarray, modes: LineModes | None = None
) -> None:
    """ResolutionWarning for natural frequencies inside the grid that the grid cannot
    resolve: nearest grid point farther than the local spacing, or a half-power
    bandwidth (2ζω_j ≈ φ_jᵀCφ_j for mass-normalized φ) so narrow against the local
    spacing that the trapezoid rule may be off by more than ``RESONANCE_PEAK_ERROR`` on
    the peak (:func:`peak_quadrature_error`).  ``modes``: the modes that count for the
    line (default its fixed-end modes)."""
    modes = own_modes(system, damping, modes)
    wn = np.asarray(modes.omega)
    inside = np.flatnonzero((wn >= omega[0]) & (wn <= omega[-1]))
    if inside.size == 0 or omega.size < 2:
        return
    band = np.asarray(modes.bandwidth)[inside]
    dist, spacing = _nearest_spacing(omega, wn[inside])
    err = peak_quadrature_error(band, spacing)
    flagged = (dist > spacing) | (err > RESONANCE_PEAK_ERROR)
    bad = [
        (modes.numbers[j] - 1, wn[j], b, dw, e)
        for j, b, dw, e, f in zip(inside, band, spacing, err, flagged)
        if f
    ]
    if not bad:
        return
    j, wj, b, dw, e = bad[0]
    width = omega[-1] - omega[0]
    # the spacing of RESONANCE_PEAK_ERROR: πb/Δω = 2 artanh(1/(1 + error))
    step = math.pi * b / (2.0 * math.atanh(1.0 / (1.0 + RESONANCE_PEAK_ERROR)))
    need = int(math.ceil(width / max(step, 1e-12 * wj))) + 1 if b > 0 else None
    fix = (
        f"use analysis.omega.count >= {need} (or refine the grid around {wj:.4g} rad/s)"
        if need is not None and need < 10**7
        else "the mode has no damping: add drag or seabed damping (no analysis.omega grid "
        "resolves an undamped peak)"
    )
    more = f" and {len(bad) - 1} more mode(s)" if len(bad) > 1 else ""
    off = f"up to ±{e:.1%}" if math.isfinite(e) else "arbitrarily"
    warn(
        f"line '{system.name}': the frequency grid (spacing {dw:.3g} rad/s near "
        f"{wj:.4g} rad/s) does not resolve {modes.label} {j + 1} at {wj:.4g} rad/s, whose "
        f"half-power bandwidth is {b:.3g} rad/s{more}: the trapezoid rule is off by {off} "
        f"on its resonance peak (threshold {RESONANCE_PEAK_ERROR:.0%}): {fix}",
        ResolutionWarning,
        stacklevel=3,
    )


#: Largest ratio of the wave-velocity σ at the two ends of an element's wet part before
#: :func:`surface_resolution_check` warns.  The drag linearization takes one B ∝ σ per
#: element (Tuah 1982, eq. 5.2.2) while σ decays like e^{k̄z} from the surface; on the
#: inclined guy (docs/ACCURACY.md) the ratio of its top element is 2.18 / 1.59 / 1.32 /
#: 1.17 at 40 / 80 / 160 / 320 elements, and the fairlead tension σ is off its
#: 320-element value by +8.6 / +2.9 / +0.46 % (with uniform B the 40-element value is
#: within 0.7 %: the loads themselves are exact).
SURFACE_SIGMA_RATIO = 2.0
#: Ratio the warning's fix aims at (≈ 3 % on the guy's fairlead tension σ).
SURFACE_TARGET_RATIO = 1.5
#: Elements whose larger end σ is below this fraction of the line's largest are not
#: checked (their drag hardly loads the line).
SURFACE_MATTERS_FRACTION = 0.25


def surface_resolution_check(
    system: LineSystem,
    channels: tuple[Channel, ...],
    omega: np.ndarray,
    q: np.ndarray | None = None,
) -> None:
    """ResolutionWarning when the wave-velocity σ varies by more than
    ``SURFACE_SIGMA_RATIO`` along an element that matters (larger end σ at least
    ``SURFACE_MATTERS_FRACTION`` of the line's largest): one drag coefficient per element
    cannot follow it (the wave loads are integrated exactly; the linearized B is not).
    ``q``: the trapezoid weights of ``omega`` when the caller has them."""
    if q is None:
        q = trapezoid_weights(omega)
    var = None
    for ch in channels:
        if not np.any(ch.spectrum > 0):
            continue
        if ch.element_end_square is not None:
            v_ = np.einsum("wes,w->es", ch.element_end_square, q * ch.spectrum)
        elif ch.element_ends is not None:  # (the sea's, formed block by block)
            v_ = ch.element_ends.weighted(q * ch.spectrum)
        else:
            continue
        var = v_ if var is None else var + v_
    if var is None:
        return
    sig = np.sqrt(np.clip(var, 0.0, None))
    hi, lo = sig.max(axis=1), sig.min(axis=1)
    top = float(hi.max())
    if top <= 0.0:
        return
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.where(lo > 0, hi / np.where(lo > 0, lo, 1.0), np.inf)
    bad = (hi >= SURFACE_MATTERS_FRACTION * top) & (ratio > SURFACE_SIGMA_RATIO)
    if not bad.any():
        return
    j = int(np.argmax(np.where(bad, ratio, 0.0)))
    r = float(ratio[j])
    mesh = system.model.mesh
    seg = int(mesh.segment[j])
    n_seg = int(np.count_nonzero(mesh.segment == seg))
    pos = system.positions
    units = unit_labels(system.environment.g)
    za, zb = float(min(pos[j, 2], 0.0)), float(min(pos[j + 1, 2], 0.0))
    dz = abs(zb - za)
    shrink = math.log(SURFACE_TARGET_RATIO) / math.log(r) if math.isfinite(r) else 0.0
    need = (
        f"at least {int(math.ceil(n_seg / shrink))} elements on segment {seg} (now {n_seg})"
        if shrink > 0
        else "more elements"
    )
    more = int(np.count_nonzero(bad)) - 1
    others = f" ({more} more element(s) likewise)" if more > 0 else ""
    warn(
        f"line '{system.name}': the wave-velocity σ varies by a factor {r:.3g} along "
        f"element {j + 1} (z from {za:.4g} to {zb:.4g} {units.length}; threshold "
        f"{SURFACE_SIGMA_RATIO:g}){others}, but the drag linearization takes one drag "
        "coefficient per element (Tuah 1982, eq. 5.2.2): the element is long against the "
        "decay depth of the wave kinematics and the response there carries an error of "
        f"several %; use {need}, or elements spanning at most {dz * shrink:.3g} "
        f"{units.length} of depth near the surface",
        ResolutionWarning,
        stacklevel=3,
    )


# Fraction of m0 that S(ω_max)·ω_max may reach before the grid is said to cut the
# response spectrum (an ω⁻⁵ tail beyond ω_max holds S·ω/4 of it).
TAIL_FRACTION = 0.05


#: The probe grid of :func:`excitation_end` over ω_max (formed once: it runs for every
#: sea state of a load-case set). [-]
_PROBE = np.geomspace(1.0 + 1e-9, 1e3, 400)


def excitation_end(channels: tuple[Channel, ...], omega: np.ndarray) -> float:
    """The frequency above which no input of the line excites it. [rad/s]

    An input whose density (``Channel.density``) vanishes above the grid ends at its
    last non-zero frequency on the grid; one that does not is followed on a geometric
    probe grid up to 1000 ω_max and bisected to where it vanishes: inf when it does not
    (an analytic spectrum).  The largest over the inputs (ω_max without any)."""
    top = float(omega[-1])
    probe = top * _PROBE
    end = 0.0
    for ch in channels:
        spectrum = np.asarray(ch.spectrum)
        if not np.any(spectrum > 0):
            continue
        if np.asarray(ch.density(probe[-1:]))[0] > 0:  # (still on at the probe's top)
            return math.inf
        above = np.flatnonzero(np.asarray(ch.density(probe)) > 0)
        if above.size == 0:
            end = max(end, float(omega[np.flatnonzero(spectrum > 0)[-1]]))
        else:  # bisect to where it vanishes (to 1e-9 relative)
            lo, hi = float(probe[above[-1]]), float(probe[above[-1] + 1])
            while hi - lo > 1e-9 * hi:
                mid = 0.5 * (lo + hi)
                lo, hi = (mid, hi) if ch.density(np.array([mid]))[0] > 0 else (lo, mid)
            end = max(end, hi)
    return end if end > 0.0 else top


def tail_check(
    line: str,
    end: str,
    w: np.ndarray,
    dens: np.ndarray,
    m0: float,
    input_end: float = math.inf,
) -> None:
    """ResolutionWarning when the end-tension spectrum is still large at ω_max and the
    excitation goes on above it (``input_end``, :func:`excitation_end`: a band-limited
    input that ends at the grid's top excites nothing the grid cuts). [rad/s]"""
    if m0 <= 0.0 or input_end <= w[-1] * (1.0 + 1e-9):
        return
    ratio = float(dens[-1] * w[-1] / m0)
    if ratio > TAIL_FRACTION:
        where = (
            f"the excitation goes on to {input_end:.4g} rad/s: raise analysis.omega.max to it"
            if math.isfinite(input_end)
            else "the excitation has no upper end (an analytic spectrum): raise analysis.omega.max"
        )
        warn(
            f"line '{line}': the {end} tension spectrum at the top of the grid "
            f"(omega.max = {w[-1]:.4g} rad/s) is still S·ω = {ratio:.2g} m0 "
            f"(threshold {TAIL_FRACTION:g}): the grid cuts the response and σ is "
            f"underestimated; {where} (end motion spectra with an ω⁻⁵ tail drive inertia "
            "loads whose spectrum decays only like ω⁻¹), or band-limit the input there",
            ResolutionWarning,
            stacklevel=3,
        )
