"""Checks and quality indicators of the linear model of one line: resolution of the
natural frequencies by the grid, of the wave kinematics by the mesh near the surface,
of the response tail by ω_max, and the snap / resonance / large-motion indicators
(:func:`line_indicators`), each with its warning.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from stochcable.dynamics.blocks import (
    add_blocks,
    block_matvec,
    line_prep,
    trapezoid_weights,
)
from stochcable.dynamics.line_loads import (
    drag_blocks,
)
from stochcable.dynamics.linearization import (
    borgman_variance_ratio,
)
from stochcable.dynamics.loads import (
    Channel,
    element_mean_square,
)
from stochcable.dynamics.second_order import irvine_lambda2
from stochcable.dynamics.system import (
    Damping,
    Linearization,
    LineSystem,
)
from stochcable.dynamics.variance import current_split
from stochcable.errors import (
    PhysicsWarning,
    ResolutionWarning,
    warn,
)
from stochcable.results.documents import (
    LineIndicators,
)
from stochcable.scene.units import unit_labels


@dataclass(frozen=True, eq=False)
class LineModes:
    """The natural modes that count for a line's indicators, when they are not its
    own fixed-end modes (a line on bodies: the coupled modes with a share of the
    line, :func:`stochcable.dynamics.coupled.results.line_modes`).

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


def _own_modes(system: LineSystem, damping: Damping, modes: LineModes | None) -> LineModes:
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


def resolution_check(
    system: LineSystem, damping: Damping, omega: np.ndarray, modes: LineModes | None = None
) -> None:
    """ResolutionWarning for natural frequencies inside the grid that the grid cannot
    resolve: nearest grid point farther than the local spacing, or a half-power
    bandwidth (2ζω_j ≈ φ_jᵀCφ_j for mass-normalized φ) narrower than the local spacing.
    ``modes``: the modes that count for the line (default its fixed-end modes)."""
    modes = _own_modes(system, damping, modes)
    wn = np.asarray(modes.omega)
    inside = np.flatnonzero((wn >= omega[0]) & (wn <= omega[-1]))
    if inside.size == 0 or omega.size < 2:
        return
    band = np.asarray(modes.bandwidth)[inside]
    dist, spacing = _nearest_spacing(omega, wn[inside])
    flagged = (dist > spacing) | (spacing > band)
    bad = [
        (modes.numbers[j] - 1, wn[j], b, dw)
        for j, b, dw, f in zip(inside, band, spacing, flagged)
        if f
    ]
    if not bad:
        return
    j, wj, b, dw = bad[0]
    width = omega[-1] - omega[0]
    need = int(math.ceil(width / max(b, 1e-12 * wj))) + 1 if b > 0 else None
    fix = (
        f"use analysis.omega.count >= {need} (or refine the grid around {wj:.4g} rad/s)"
        if need is not None and need < 10**7
        else "the mode has no damping: add drag or seabed damping (no analysis.omega grid "
        "resolves an undamped peak)"
    )
    more = f" and {len(bad) - 1} more mode(s)" if len(bad) > 1 else ""
    warn(
        f"line '{system.name}': the frequency grid (spacing {dw:.3g} rad/s near "
        f"{wj:.4g} rad/s) does not resolve {modes.label} {j + 1} at {wj:.4g} rad/s, whose "
        f"half-power bandwidth is {b:.3g} rad/s{more}; the resonance peak may be missed: "
        f"{fix}",
        ResolutionWarning,
        stacklevel=3,
    )


#: Largest ratio of the wave-velocity σ at the two ends of an element's wet part before
#: :func:`surface_resolution_check` warns.  The drag linearization takes one B ∝ σ per
#: element (seed 001 eq. 5.2.2) while σ decays like e^{k̄z} from the surface; on the
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
        "coefficient per element (seed 001 eq. 5.2.2): the element is long against the "
        "decay depth of the wave kinematics and the response there carries an error of "
        f"several %; use {need}, or elements spanning at most {dz * shrink:.3g} "
        f"{units.length} of depth near the surface",
        ResolutionWarning,
        stacklevel=3,
    )


# Fraction of m0 that S(ω_max)·ω_max may reach before the grid is said to cut the
# response spectrum (an ω⁻⁵ tail beyond ω_max holds S·ω/4 of it).
TAIL_FRACTION = 0.05


def tail_check(line: str, end: str, w: np.ndarray, dens: np.ndarray, m0: float) -> None:
    """ResolutionWarning when the end-tension spectrum is still large at ω_max."""
    if m0 <= 0.0:
        return
    ratio = float(dens[-1] * w[-1] / m0)
    if ratio > TAIL_FRACTION:
        warn(
            f"line '{line}': the {end} tension spectrum at the top of the grid "
            f"(omega.max = {w[-1]:.4g} rad/s) is still S·ω = {ratio:.2g} m0 "
            f"(threshold {TAIL_FRACTION:g}): the grid cuts the response and σ is "
            "underestimated; raise analysis.omega.max (end motion spectra with an ω⁻⁵ "
            "tail drive inertia loads whose spectrum decays only like ω⁻¹)",
            ResolutionWarning,
            stacklevel=3,
        )


# ------------------------------------------------------------------ quality indicators

#: Snap flag: mean − SNAP_SIGMAS·σ of the tension below zero at an element or end.
SNAP_SIGMAS = 3.0
#: Resonance flag: modal damping ratio below this inside the excitation band.
RESONANCE_DAMPING_RATIO = 0.01
#: The excitation band: where some input spectrum exceeds this fraction of its peak.
BAND_FRACTION = 0.01
#: Large-motion flag: node motion σ above this fraction of the line's sag.
MOTION_SAG_FRACTION = 0.1
#: ... on a line whose sag governs its stiffness: Irvine's λ² at least this.  The
#: elastic catenary's stiffness is (EA/L)/(1 + λ²/12) (Irvine 1981; seed 000 eq. 4.3):
#: below λ² = 1 the sag takes less than 8 % of it, so even a 30 % change of sag moves the
#: stiffness by a few % and a taut line carried by its fairlead stays linear (the taut
#: rope of docs/accuracy/lines.md: λ² = 0.05, motion 0.47 of its sag, FD = TD to 0.02 %).
MOTION_SAG_LAMBDA2 = 1.0


def _normal_acceleration_sigma(
    system: LineSystem, channels: tuple[Channel, ...], omega: np.ndarray
) -> np.ndarray:
    """σ of the fluid acceleration normal to each element, element mean square
    ω²(tr S − eᵀSe), S = ∫₀¹ Re(v vᴴ) dξ (:func:`element_mean_square`). [m/s²]"""
    e = system.frames[0]
    q = trapezoid_weights(omega)
    n_el = system.model.n_elements
    var = np.zeros(n_el)
    # tr S − eᵀSe = Σ_ij S_ij (I − eeᵀ)_ij: one product over the 9 entries (the trace
    # and a three-operand einsum were 0.2 ms on the chain)
    proj = (np.eye(3)[None] - e[:, :, None] * e[:, None, :]).reshape(n_el, 9)
    for ch in channels:
        wts = q * ch.spectrum * omega**2
        if ch.element_velocity_square is None and ch.element_square is not None:
            var += ch.element_square.projected_sum(proj.reshape(n_el, 3, 3), wts)  # (parts)
            continue
        sq = element_mean_square(ch)
        if sq is not None:
            dens = np.einsum("wek,ek->we", sq.reshape(sq.shape[0], n_el, 9), proj)
            var += np.clip(dens, 0.0, None).T @ wts
    return np.sqrt(var)


def _modal_damping_ratios(modes: LineModes) -> np.ndarray:
    """ζ_j = φ_jᵀCφ_j/(2ω_j) of the modes (mass-normalized φ). [-]"""
    band = np.asarray(modes.bandwidth)
    wn = np.asarray(modes.omega)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(wn > 0, band / (2.0 * np.where(wn > 0, wn, 1.0)), np.inf)


def line_indicators(
    system: LineSystem,
    channels: tuple[Channel, ...],
    linearization: Linearization,
    tension_std: np.ndarray,
    motion_std: np.ndarray,
    end_stats: Mapping[str, Any],
    modes: LineModes | None = None,
) -> LineIndicators:
    """Quality indicators of the linear model of one line, with PhysicsWarnings.

    Parameters
    ----------
    system : LineSystem
    channels : tuple of Channel
        Inputs on the analysis grid (their spectra define the excitation band).
    linearization : Linearization
        The converged drag (its record's σ and B).
    tension_std : ndarray, shape (n_el,)
        σ of the dynamic element tension. [N]
    motion_std : ndarray, shape (n_nodes, 3)
        σ of the node motions. [m]
    end_stats : mapping {"end_a", "end_b"} of ResponseStats
        End-tension statistics (mean and std). [N]
    modes : LineModes, optional
        The modes of the resonance indicator (default the line's fixed-end modes; a
        line on bodies: the coupled modes that count for it).

    Returns
    -------
    LineIndicators

    Warns
    -----
    PhysicsWarning
        - snap: T_mean − 3σ_T < 0 at an element or end ("snap loads likely; the
          linear model is out of its depth");
        - resonance: a mode inside the excitation band (some input spectrum above
          1 % of its peak) with modal damping ratio ζ < 1 %, named;
        - large motion: a node motion σ above 10 % of the sag.

    Notes
    -----
    Borgman ratio per element: :func:`stochcable.dynamics.linearization.borgman_variance_ratio`
    of the normal relative velocity (σ_n of the record, mean = the normal current;
    elements at rest, :func:`at_rest_zeroed`, take its σ → 0 limit).
    Drag/inertia: :func:`stochcable.dynamics.linearization.drag_inertia_ratio` in the form
    B_n σ_n / (ρ C_M (πD²/4) σ_an), B_n the record's normal coefficient, σ_an the σ
    of the fluid acceleration normal to the element (the sea channel).
    Modal damping ζ_j = φ_jᵀCφ_j/(2ω_j) with C = drag + seabed + structural damping
    (the diagonal of the modal damping; the coupling terms are ignored).
    Large motion: the tangent model (seed 001 §3) is linear about the static shape;
    the geometric stiffness of a sagging line depends on its sag at first order
    (T ≈ wL²/8·1/sag for a shallow catenary), so a motion σ of 10 % of the sag (a
    3σ excursion of 30 %) changes the stiffness by about as much as a linear model
    can tolerate; the sag is the largest distance of the static shape from the
    chord.  Only where the sag governs the stiffness: Irvine's λ² ≥ 1
    (:data:`MOTION_SAG_LAMBDA2`).  The diameter ratio is reported, not flagged (large
    motion over D means drag-dominated loading, the domain of the drag linearization).
    """
    w = linearization.response.omega
    borgman, d_i = _drag_ratios(system, channels, linearization.record, w)
    snap_margin, snap = _snap(system, tension_std, end_stats)
    resonances = _resonances(system, channels, linearization.damping, w, modes)
    m_max, sag, to_sag, to_d = _large_motion(system, motion_std)
    large = to_sag > MOTION_SAG_FRACTION and _sag_governs(system)
    flags = (["snap"] if snap else []) + (["resonance"] if resonances else [])
    flags += ["large_motion"] if large else []
    return LineIndicators(
        borgman_ratio=borgman,
        drag_inertia_ratio=d_i,
        snap_margin=snap_margin,
        snap_risk=snap,
        resonances=tuple(resonances),
        motion_std_max=m_max,
        sag=sag,
        motion_to_sag=float(to_sag),
        motion_to_diameter=to_d,
        flags=tuple(flags),
    )


#: An element's normal relative-velocity σ (and normal current) at most this fraction
#: of the line's largest is "at rest" for the indicators (:func:`at_rest_zeroed`).
AT_REST_FRACTION = 1.0e-6


def at_rest_zeroed(sigma: np.ndarray, current: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The elements' normal relative-velocity σ and normal current [m/s] with those at
    rest set to zero: σ ≤ :data:`AT_REST_FRACTION` × the largest σ of the line, and
    |U_n| ≤ the same fraction of max(largest |U_n|, largest σ).

    The grounded elements of a line on a penalty seabed move ever less away from the
    touchdown (σ falls by ~100 per element, to 1e-16 of the line's largest: round-off);
    the ratios of such σ and currents are round-off too, and would differ between
    machines.  At rest the indicators take their limits (Borgman ratio 1 with a
    current, 8/(3π) without; no drag force)."""
    s = np.asarray(sigma, dtype=float)
    u = np.asarray(current, dtype=float)
    top = float(s.max()) if s.size else 0.0
    s = np.where(s <= AT_REST_FRACTION * top, 0.0, s)
    u_top = max(float(np.abs(u).max()) if u.size else 0.0, top)
    return s, np.where(np.abs(u) <= AT_REST_FRACTION * u_top, 0.0, u)


def _drag_ratios(
    system: LineSystem, channels: tuple[Channel, ...], rec: Any, w: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Borgman variance ratio and drag/inertia ratio per element (:func:`line_indicators`
    Notes). [-]"""
    model = system.model
    mesh = model.mesh
    sigma, u_n = at_rest_zeroed(rec.sigma_normal, current_split(system)[2])
    borgman = np.atleast_1d(borgman_variance_ratio(sigma, u_n))
    s_an = _normal_acceleration_sigma(system, channels, w)
    drag_sigma = rec.b_normal * sigma
    inertia_sigma = model.rho * (1.0 + mesh.ca_normal) * math.pi * mesh.diameter**2 / 4.0 * s_an
    with np.errstate(divide="ignore", invalid="ignore"):
        d_i = np.where(
            inertia_sigma > 0,
            drag_sigma / np.where(inertia_sigma > 0, inertia_sigma, 1.0),
            np.where(drag_sigma > 0, np.inf, 0.0),
        )
    return borgman, d_i


def _snap(
    system: LineSystem, tension_std: np.ndarray, end_stats: Mapping[str, Any]
) -> tuple[float, bool]:
    """Snap margin min (mean − 3σ)/|mean| over the elements and ends, and whether some
    mean − 3σ < 0 (PhysicsWarning naming the worst place)."""
    mesh = system.model.mesh
    t_mean = np.asarray(system.statics.tension, dtype=float)
    means = np.concatenate([t_mean, [end_stats["end_a"].mean, end_stats["end_b"].mean]])
    sigmas = np.concatenate([tension_std, [end_stats["end_a"].std, end_stats["end_b"].std]])
    low = means - SNAP_SIGMAS * sigmas
    with np.errstate(divide="ignore", invalid="ignore"):
        margins = np.where(
            np.abs(means) > 0,
            low / np.abs(np.where(means != 0, means, 1.0)),
            np.where(low < 0, -np.inf, 0.0),
        )
    k = int(np.argmin(margins))
    snap = bool(np.any(low < 0))
    if snap:
        units = unit_labels(system.environment.g)
        where = (
            "end_a"
            if k == t_mean.size
            else "end_b"
            if k == t_mean.size + 1
            else f"element {k + 1} (s = {0.5 * (mesh.s0[k] + mesh.s0[k + 1]):.4g} {units.length})"
        )
        warn(
            f"line '{system.name}': the dynamic tension σ ({sigmas[k]:.4g} {units.force} "
            f"at {where}) exceeds 1/{SNAP_SIGMAS:g} of the mean tension ({means[k]:.4g} "
            f"{units.force}): mean − {SNAP_SIGMAS:g}σ < 0, snap loads likely; the linear "
            "model is out of its depth (threshold mean − 3σ >= 0): use a nonlinear "
            "time-domain analysis "
            "(stochcable.reference.cable) or increase the pretension",
            PhysicsWarning,
            stacklevel=4,
        )
    return float(margins[k]), snap


def _resonances(
    system: LineSystem,
    channels: tuple[Channel, ...],
    damping: Damping,
    w: np.ndarray,
    modes: LineModes | None = None,
) -> list[dict[str, Any]]:
    """Modes inside the excitation band with a modal damping ratio below
    ``RESONANCE_DAMPING_RATIO`` (PhysicsWarning naming the first)."""
    resonances: list[dict[str, Any]] = []
    modes = _own_modes(system, damping, modes)
    wn = np.asarray(modes.omega)
    spectra = [c.spectrum for c in channels if np.any(c.spectrum > 0)]
    if spectra and wn.size:
        inside = np.zeros(wn.size, dtype=bool)
        for spec in spectra:
            in_band = np.interp(wn, w, spec, left=0.0, right=0.0) >= BAND_FRACTION * spec.max()
            inside |= in_band
        zeta = _modal_damping_ratios(modes)
        for j in np.flatnonzero(inside & (zeta < RESONANCE_DAMPING_RATIO)):
            resonances.append(
                {
                    "mode": int(modes.numbers[j]),
                    "omega": float(wn[j]),
                    "damping_ratio": float(zeta[j]),
                }
            )
    if resonances:
        r0 = resonances[0]
        more = f" and {len(resonances) - 1} more" if len(resonances) > 1 else ""
        warn(
            f"line '{system.name}': {modes.label} {r0['mode']} ({r0['omega']:.4g} rad/s)"
            f"{more} lies in the excitation band with modal damping ratio "
            f"{r0['damping_ratio']:.2%} (threshold {RESONANCE_DAMPING_RATIO:.0%}): a "
            "near-undamped resonance whose response is set by damping the model may not "
            "represent; check the drag coefficients and add structural damping "
            "(analysis.structural_damping) or seabed damping where physical",
            PhysicsWarning,
            stacklevel=4,
        )
    return resonances


def _sag_governs(system: LineSystem) -> bool:
    """Whether the line's sag governs its stiffness: Irvine's λ² of the static shape at
    least :data:`MOTION_SAG_LAMBDA2` (once per line)."""
    if "sag_governs" not in system._cache:
        mesh = system.model.mesh
        lam2 = irvine_lambda2(
            system.model.positions, mesh.l0, mesh.ea, mesh.weight, system.statics.tension
        )
        system._cache["sag_governs"] = lam2 >= MOTION_SAG_LAMBDA2
    return system._cache["sag_governs"]


def _large_motion(system: LineSystem, motion_std: np.ndarray) -> tuple[float, float, float, float]:
    """Largest node motion σ [m], the sag of the static shape [m] (largest distance
    from the chord, once per line), and their ratio and the ratio to the diameter
    (PhysicsWarning above ``MOTION_SAG_FRACTION`` of the sag)."""
    model = system.model
    if "sag" not in system._cache:  # of the static shape: once per line
        pos = model.positions
        chord = pos[-1] - pos[0]
        cn = float(np.linalg.norm(chord))
        rel = pos - pos[0]
        if cn > 0:
            rel = rel - np.outer(rel @ (chord / cn), chord / cn)
        system._cache["sag"] = float(np.max(np.linalg.norm(rel, axis=1)))
    sag = system._cache["sag"]
    m_std = np.linalg.norm(motion_std, axis=1)
    m_max = float(m_std.max()) if m_std.size else 0.0
    to_sag = m_max / sag if sag > 0 else (np.inf if m_max > 0 else 0.0)
    to_d = m_max / float(np.max(model.mesh.diameter))
    if to_sag > MOTION_SAG_FRACTION and _sag_governs(system):
        units = unit_labels(system.environment.g)
        j = int(np.argmax(m_std))
        warn(
            f"line '{system.name}': the motion σ at node {j + 1} ({m_max:.3g} "
            f"{units.length}) is {to_sag:.2g} of the line's sag ({sag:.3g} "
            f"{units.length}), above the threshold {MOTION_SAG_FRACTION:g}: the "
            "linearization about the static shape is doubtful; check with a nonlinear "
            "time-domain analysis (stochcable.reference.cable)",
            PhysicsWarning,
            stacklevel=4,
        )
    return m_max, sag, to_sag, to_d
