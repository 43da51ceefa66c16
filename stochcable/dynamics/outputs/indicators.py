"""Quality indicators of the linear model of one line: the snap / resonance /
large-motion indicators and the drag ratios (:func:`line_indicators`), each with its
warning.  The checks of the grid's and the mesh's resolution are in
:mod:`stochcable.dynamics.outputs.resolution`.

References
----------
Bliet, A. (1984), Dynamic analysis of single span cables, PhD thesis, Massachusetts
Institute of Technology.
Tuah, H. (1982), Cable dynamics in an ocean environment, PhD thesis, Oregon State University.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import numpy as np

from stochcable.dynamics.linearization.formulas import (
    borgman_variance_ratio,
)
from stochcable.dynamics.linearization.variance import current_split
from stochcable.dynamics.loads.channels import (
    Channel,
    element_mean_square,
)
from stochcable.dynamics.model.blocks import (
    trapezoid_weights,
)
from stochcable.dynamics.model.system import (
    Damping,
    Linearization,
    LineSystem,
)
from stochcable.dynamics.outputs.resolution import LineModes, own_modes
from stochcable.dynamics.residuals.second_order import irvine_lambda2
from stochcable.errors import (
    PhysicsWarning,
    warn,
)
from stochcable.results.documents import (
    LineIndicators,
)
from stochcable.results.records import LinearizationRecord, ResponseStats
from stochcable.scene.units import unit_labels

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
#: elastic catenary's stiffness is (EA/L)/(1 + λ²/12) (Irvine 1981; Bliet (1984), eq. 4.3):
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
    # (of the line's static frames: formed once per line, not at each sea state)
    if "normal_projector" not in system._cache:
        system._cache["normal_projector"] = (
            np.eye(3)[None] - e[:, :, None] * e[:, None, :]
        ).reshape(n_el, 9)
    proj = system._cache["normal_projector"]
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
    end_stats: Mapping[str, ResponseStats],
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
    Borgman ratio per element:
    :func:`stochcable.dynamics.linearization.formulas.borgman_variance_ratio`
    of the normal relative velocity (σ_n of the record, mean = the normal current;
    elements at rest, :func:`at_rest_zeroed`, take its σ → 0 limit).
    Drag/inertia: :func:`stochcable.dynamics.linearization.formulas.drag_inertia_ratio` in the form
    B_n σ_n / (ρ C_M (πD²/4) σ_an), B_n the record's normal coefficient, σ_an the σ
    of the fluid acceleration normal to the element (the sea channel).
    Modal damping ζ_j = φ_jᵀCφ_j/(2ω_j) with C = drag + seabed + structural damping
    (the diagonal of the modal damping; the coupling terms are ignored).
    Large motion: the tangent model (Tuah 1982, §3) is linear about the static shape;
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
    system: LineSystem, channels: tuple[Channel, ...], rec: LinearizationRecord, w: np.ndarray
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
    system: LineSystem, tension_std: np.ndarray, end_stats: Mapping[str, ResponseStats]
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
    modes = own_modes(system, damping, modes)
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
