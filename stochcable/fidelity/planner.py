"""Adaptive fidelity: model only what a scene needs (issue 7, item 2).

:func:`choose_fidelity` picks the frequency grid, the elements per segment, the kept
modes and the linearization tolerance of a scene for a target relative error of the
response standard deviations, and records every choice with its reason and its error
estimate in a :class:`FidelityPlan`; :func:`apply_fidelity` returns a new scene with
the plan's settings (the input scene is never modified).

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
    :data:`PILOT_INPUT_FRACTION` outside it) and is doubled up to
    :data:`PILOT_EXTENSIONS` times while the response tail beyond its top is not
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
    the string, seed 001 eq. 3.1.12).  The frequency error that matters is the
    variance-weighted one, so k is taken at the response's mean frequency
    ω₂ = √(m₂/m₀) (pilot) with ⟨1/c²⟩ over the suspended length: h ≤ √(24 ε_el)/(ω₂
    √⟨1/c²⟩), and h ≤ :data:`CUTOFF_KH`/k(ω_max) so no resonance of the band is
    spurious.  Touchdown: a node at the static touchdown (:func:`static_touchdowns`;
    the segment is split there) — the linear model's contact state is the static one,
    so a touchdown inside an element errs on the suspended length at first order
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
    integration, being added in :mod:`stochcable.dynamics.loads`), which removes this rule.
Modes
    With the static correction, a mode at ω_j contributes (ω/ω_j)² of its dynamic part
    beyond the quasi-static one; keeping the modes up to F·ω_max leaves ≈ C/F²
    (C = :data:`MODE_ERROR_CONSTANT`, from docs/BENCHMARKS.md: 0.24 % at F = 5).  F ≤ 5
    is the engine's "auto"; above :data:`DIRECT_MODES` modes the direct solve is used.
Linearization
    Tolerance = ε_lin: the fixed point's remaining error is at most about the last
    relative change of the σ, and the response σ is at most inversely proportional to
    the drag.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import Any, Callable

import numpy as np

from stochcable import validation as _v
from stochcable.scene.model import Scene, load_scene

__all__ = [
    "BUDGET",
    "Choice",
    "FidelityPlan",
    "spectrum_tail_frequency",
    "elements_wavelength",
    "points_per_bandwidth",
    "choose_fidelity",
    "apply_fidelity",
    "static_touchdowns",
]

#: Shares of the target error given to each part (sum 1). [-]
BUDGET: dict[str, float] = {"band": 0.3, "grid": 0.15, "elements": 0.35, "modes": 0.1,
                            "linearization": 0.1}
#: Variance fraction of each input spectrum left outside the pilot's first band. [-]
PILOT_INPUT_FRACTION = 1e-4
#: Same below the band: the pilot bounds the response below its first frequency by
#: S(ω₀)·ω₀, so it starts where the inputs are negligible. [-]
PILOT_LOW_FRACTION = 1e-9
#: Times the pilot's top frequency is doubled while the response tail is unbounded or
#: the pilot does not reach twice the ω_max it gives.
PILOT_EXTENSIONS = 4
#: Elements of the finite-element statics that locates a touchdown (when the closed
#: form does not apply and the scene's mesh is coarser). [-]
TOUCHDOWN_ELEMENTS = 200
#: Pilot frequencies (log spaced). [-]
PILOT_COUNT = 200
#: Pilot mesh: kh at the pilot's top frequency (frequency error (kh)²/24 ≈ 4 %). [-]
PILOT_KH = 1.0
#: Pilot elements per line at most (the pilot is a rough estimate). [-]
PILOT_MAX_ELEMENTS = 400
#: A power-law tail S ∝ ω^-p counts as bounded for p > 1 + MIN_TAIL_EXCESS. [-]
MIN_TAIL_EXCESS = 0.25
#: Largest kh at ω_max (consistent-mass cut-off is kh = √12 ≈ 3.5). [-]
CUTOFF_KH = 1.5
#: Modal truncation error ≈ MODE_ERROR_CONSTANT/F² with the static correction. [-]
MODE_ERROR_CONSTANT = 0.06
#: Engine's "auto" factor (stochcable.dynamics.line.AUTO_MODE_FACTOR). [-]
AUTO_FACTOR = 5.0
#: Above this many kept modes the direct solver is chosen. [-]
DIRECT_MODES = 40
#: Local refinement around a mode: ± this many half-power bandwidths. [-]
PEAK_HALF_WIDTHS = 4.0
#: A mode needs refinement when its bandwidth is below this many base spacings. [-]
PEAK_RESOLVED = 4.0


# ---------------------------------------------------------------------------- plan


@dataclass(frozen=True)
class Choice:
    """One setting of a plan.

    Attributes
    ----------
    setting : str
        Scene path of the setting ("analysis.omega.max", "lines[leg].segments[0].elements").
    value : Any
        The value chosen.
    reason : str
        Rule and numbers that gave it.
    error : float
        Estimated relative error of σ this setting leaves. [-]
    """

    setting: str
    value: Any
    reason: str
    error: float = 0.0

    def to_document(self) -> dict[str, Any]:
        return {"setting": self.setting, "value": _plain(self.value), "reason": self.reason,
                "error": float(self.error)}


@dataclass(frozen=True)
class FidelityPlan:
    """Settings chosen for a target error, each with its reason.

    Attributes
    ----------
    target_error : float
        Target relative error of the response σ. [-]
    omega_min, omega_max : float
        Frequency band. [rad/s]
    omega_count : int
        Points of the linear grid (finest spacing needed anywhere). [-]
    omega_values : tuple of float
        Non-uniform grid: base linear grid plus refinements around lightly damped
        modes. [rad/s]
    segments : dict of str to tuple
        Per line, the new segments as (source segment index, length [m], elements).
    solver : str
        "foss" or "direct".
    modes : "auto" or int
        Kept modes (Foss).
    tolerance : float
        Linearization tolerance. [-]
    choices : tuple of Choice
        Every choice with its reason and error estimate.
    error_estimate : dict of str to float
        Estimate per part ("band", "grid", "elements", "modes", "linearization") and
        "total" (their sum). [-]
    cost : dict of str to float
        "elements", "frequencies" (of the grid applied) and "elements_x_frequencies".
    omega_response : float
        ω₂ = √(m₂/m₀) of the pilot's response spectra (largest), used by the
        element rule. [rad/s]
    tail_bounded : bool
        False when a response spectrum still decays slower than ω⁻¹·²⁵ at the pilot's
        top: σ then depends on the band and the band estimate is a lower bound.
    pilot : dict
        The pilot analysis: elements, band, count, wall time [s].
    """

    target_error: float
    omega_min: float
    omega_max: float
    omega_count: int
    omega_values: tuple[float, ...]
    segments: dict[str, tuple[tuple[int, float, int], ...]]
    solver: str
    modes: Any
    tolerance: float
    choices: tuple[Choice, ...]
    error_estimate: dict[str, float]
    cost: dict[str, float]
    tail_bounded: bool = True
    omega_response: float = 0.0
    pilot: dict[str, Any] = field(default_factory=dict)

    def to_document(self) -> dict[str, Any]:
        """Plain JSON-ready form (for the result document's "fidelity")."""
        return {
            "target_error": self.target_error,
            "omega": {"min": self.omega_min, "max": self.omega_max,
                      "count": self.omega_count, "values_count": len(self.omega_values)},
            "segments": {k: [list(s) for s in v] for k, v in self.segments.items()},
            "solver": self.solver, "modes": self.modes, "tolerance": self.tolerance,
            "choices": [c.to_document() for c in self.choices],
            "error_estimate": dict(self.error_estimate), "cost": dict(self.cost),
            "tail_bounded": self.tail_bounded, "omega_response": self.omega_response,
            "pilot": _plain(self.pilot),
        }


def _plain(x: Any) -> Any:
    if isinstance(x, dict):
        return {k: _plain(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_plain(v) for v in x]
    if isinstance(x, (np.floating, np.integer)):
        return x.item()
    return x


# ------------------------------------------------------------------- closed forms


def _tail_exponent(w: np.ndarray, s: np.ndarray, top_fraction: float = 0.2) -> float:
    """p of a power-law fit S ∝ ω^-p to the top ``top_fraction`` of log ω."""
    lw = np.log(w)
    sel = (lw >= lw[-1] - top_fraction * (lw[-1] - lw[0])) & (s > 0)
    if np.count_nonzero(sel) < 3:
        return math.inf if s[-1] <= 0 else 0.0
    slope = np.polyfit(lw[sel], np.log(s[sel]), 1)[0]
    return float(-slope)


def _tail_above(w: np.ndarray, s: np.ndarray, p: float) -> np.ndarray:
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


def _tail_below(w: np.ndarray, s: np.ndarray) -> np.ndarray:
    """∫_0^{ω_i} S dω: trapezoid plus the first bin's S(ω_0)·ω_0 (bound for S rising
    at least linearly from 0 — the inputs of ocean spectra vanish faster)."""
    seg = 0.5 * (s[1:] + s[:-1]) * np.diff(w)
    return np.concatenate([[0.0], np.cumsum(seg)]) + s[0] * w[0]


def _crossing_up(w: np.ndarray, frac: np.ndarray, limit: float) -> float:
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


def _crossing_down(w: np.ndarray, frac: np.ndarray, limit: float) -> float:
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
        raise _v.InputError("density", f"shape {s.shape}", "unit²·s/rad",
                            f"must have the shape of omega {w.shape}")
    above = _tail_above(w, s, _tail_exponent(w, s))
    below = _tail_below(w, s)
    m0 = below[-1] + above[-1]
    if not np.isfinite(m0) or m0 <= 0.0:
        raise _v.InputError("density", "spectrum", "unit²·s/rad",
                            "must have a positive, finite variance (tail decaying faster "
                            "than 1/ω)")
    return _crossing_down(w, below / m0, frac), _crossing_up(w, above / m0, frac)


def elements_wavelength(length: float, omega: float, celerity: float,
                        frequency_error: float) -> int:
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
    A string discretized by linear elements with consistent mass (seed 001 eq. 3.1.12)
    has ω_h² = (c²/h²)·6(1 − cos kh)/(2 + cos kh) = c²k²(1 + (kh)²/12 + O(kh)⁴), so
    ω_h/ω − 1 = (kh)²/24.
    """
    L = _v.positive("length", length, "m")
    w = _v.positive("omega", omega, "rad/s")
    c = _v.positive("celerity", celerity, "m/s")
    e = _v.in_range("frequency_error", frequency_error, "-", 0.0, 0.5, lo_open=True)
    kh = math.sqrt(24.0 * e)
    return max(1, int(math.ceil(L * (w / c) / kh - 1e-9)))


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


# ------------------------------------------------------------------------- inputs


def _input_densities(scene: Scene) -> list[tuple[str, Callable[[np.ndarray], np.ndarray]]]:
    g = scene.environment.g
    out: list[tuple[str, Callable[[np.ndarray], np.ndarray]]] = []
    if scene.sea is not None:
        spec = scene.sea.spectrum
        out.append(("sea", lambda w, spec=spec: spec.spectral_density(w, g)))
    for line in scene.lines:
        for end in ("end_a", "end_b"):
            m = getattr(line, end).motion
            if m is None or m.rao is not None:
                continue
            for dof in ("surge", "sway", "heave"):
                spec = getattr(m, dof)
                if spec is not None:
                    out.append((f"{line.name}.{end}.{dof}",
                                lambda w, spec=spec: spec.spectral_density(w, g)))
    return out


_WIDE = np.geomspace(1e-4, 1e4, 16001)


def _input_band(scene: Scene, fraction: float) -> tuple[float, float, dict[str, tuple]]:
    """Union of the inputs' bands at ``fraction``, and per input (ω_lo, ω_hi, ω₂)."""
    per: dict[str, tuple] = {}
    for name, dens in _input_densities(scene):
        s = np.asarray(dens(_WIDE), dtype=float)
        s = np.where(np.isfinite(s), s, 0.0)
        lo, hi = spectrum_tail_frequency(_WIDE, s, fraction)
        m0 = np.trapezoid(s, _WIDE)
        w2 = math.sqrt(np.trapezoid(_WIDE**2 * s, _WIDE) / m0)
        per[name] = (lo, hi, w2)
    if not per:
        return 0.05, 2.0, per
    return (min(v[0] for v in per.values()), max(v[1] for v in per.values()), per)


# ------------------------------------------------------------------------- meshing


@dataclass(frozen=True, eq=False)
class _LineGeometry:
    """Static geometry of one line for the element rules: per segment a dict (length,
    ⟨1/c²⟩, suspended lengths, arc-length interval, touchdown), and the nodes' arc
    length and z (for the wave-load rule). [m]"""

    segments: list[dict[str, Any]]
    s_nodes: np.ndarray
    z_nodes: np.ndarray


def _segment_geometry(scene: Scene, statics: Any,
                      touchdown: dict[str, float | None] | None = None
                      ) -> dict[str, _LineGeometry]:
    """Per line and segment: length, ⟨1/c²⟩ over the suspended part, suspended length,
    arc-length interval, node z (for the wave-load rule) and the static touchdown
    (``touchdown`` overrides the statics' own, e.g. from a finer model)."""
    rho = scene.environment.rho
    out: dict[str, _LineGeometry] = {}
    for line in scene.lines:
        st = statics.lines[line.name]
        s_td = (touchdown or {}).get(line.name, st.touchdown)
        mesh = st.mesh
        grounded_el = st.grounded[1:] & st.grounded[:-1]
        susp_line = float(np.sum(mesh.l0[~grounded_el]))
        s_start = 0.0
        segs = []
        for i, seg in enumerate(line.segments):
            sel = mesh.segment == i
            m_t = seg.mass + seg.ca_normal * rho * math.pi * seg.diameter**2 / 4.0
            t = np.asarray(st.tension)[sel]
            free = sel & ~grounded_el
            tf = np.asarray(st.tension)[free]
            l0f = mesh.l0[free]
            if tf.size:
                # tension floor: 1 % of the segment's largest (a slack element has T = 0)
                tf = np.maximum(tf, 1e-2 * max(float(t.max()), 1e-300))
                inv_c2 = float(np.sum(l0f * m_t / tf) / np.sum(l0f))
            else:
                inv_c2 = 0.0
            segs.append({"length": seg.length, "inv_c2": inv_c2,
                         "suspended": float(np.sum(l0f)), "line_suspended": susp_line,
                         "s0": s_start, "s1": s_start + seg.length,
                         "grounded_any": bool(np.any(grounded_el[sel])),
                         "touchdown": s_td})
            s_start += seg.length
        out[line.name] = _LineGeometry(segs, np.asarray(mesh.s0), st.positions[:, 2].copy())
    return out


def static_touchdowns(scene: Scene | Any) -> dict[str, float | None]:
    """Static touchdown of every line, for placing a node there.

    Parameters
    ----------
    scene : Scene or document
        The scene.

    Returns
    -------
    dict of str to float or None
        Per line name, the unstretched arc length from end_a where the line leaves the
        seabed (None without seabed contact). [m]

    Notes
    -----
    The closed-form elastic catenary where it applies, else the finite-element statics
    on a mesh of at least :data:`TOUCHDOWN_ELEMENTS` elements (the scene's own mesh may
    be coarse: its 3-element FE statics puts the touchdown of tuah_1982_single_leg at
    157 ft instead of 165.7 ft), whose touchdown is interpolated from the vertical
    tension of the first suspended element (:mod:`stochcable.line.statics`).
    """
    from stochcable.line.statics import solve_statics

    scene = load_scene(scene)
    auto = solve_statics(scene)
    out: dict[str, float | None] = {}
    refine: dict[str, tuple[tuple[int, float, int], ...]] = {}
    for line in scene.lines:
        st = auto.lines[line.name]
        out[line.name] = st.touchdown
        n = sum(seg.elements for seg in line.segments)
        if st.touchdown is not None and st.method == "fe" and n < TOUCHDOWN_ELEMENTS:
            f = TOUCHDOWN_ELEMENTS / n
            refine[line.name] = tuple(
                (i, seg.length, max(1, int(math.ceil(seg.elements * f))))
                for i, seg in enumerate(line.segments))
    if refine:
        fine = solve_statics(_segments_scene(scene, refine, {}), method="fe")
        for name in refine:
            out[name] = fine.lines[name].touchdown
    return out


def _mesh_rules(scene: Scene, geo: dict[str, _LineGeometry], w2: float, wmax: float, eps_el: float,
                k_load: float | None, exact: bool
                ) -> tuple[dict[str, tuple[tuple[int, float, int], ...]], list[Choice], float]:
    """Segments (source, length, elements) per line by the element rules."""
    choices: list[Choice] = []
    out: dict[str, tuple[tuple[int, float, int], ...]] = {}
    # the string-wave and the wave-load rules get half of eps_el each
    eps_w = eps_el / 2.0 if (k_load and not exact) else eps_el
    kh2 = math.sqrt(24.0 * eps_w)
    err = 0.0
    z_load = (math.log(1.0 / eps_el) / k_load) if k_load else 0.0
    dz_load = math.sqrt(12.0 * eps_el / 2.0) / k_load if k_load else math.inf
    for line in scene.lines:
        segs = geo[line.name].segments
        s_nodes, z_nodes = geo[line.name].s_nodes, geo[line.name].z_nodes
        new: list[tuple[int, float, int]] = []
        for i, (seg, g) in enumerate(zip(line.segments, segs)):
            path = f"lines[{line.name}].segments[{i}].elements"
            if g["inv_c2"] > 0:
                sq = math.sqrt(g["inv_c2"])
                h_w2 = kh2 / (w2 * sq)
                h_cut = CUTOFF_KH / (wmax * sq)
            else:
                h_w2 = h_cut = math.inf
            h_td = (g["line_suspended"] * math.sqrt(eps_el) if g["grounded_any"]
                    else math.inf)
            h = min(h_w2, h_cut, h_td, g["length"])
            n = max(1, int(math.ceil(g["length"] / h - 1e-9)))
            rule = {h_w2: f"string wave at the response's ω₂ = {w2:.3g} rad/s: h ≤ "
                          f"√(24·{eps_w:.2g})·c/ω₂ = {h_w2:.3g} m",
                    h_cut: f"cut-off at ω_max = {wmax:.3g} rad/s: kh ≤ {CUTOFF_KH:g}, "
                           f"h ≤ {h_cut:.3g} m",
                    h_td: f"touchdown: h ≤ √{eps_el:.2g} × suspended length = {h_td:.3g} m",
                    g["length"]: "one element (no rule binds)"}[h]
            kh_eff = (h * w2 * math.sqrt(g["inv_c2"])) if g["inv_c2"] > 0 else 0.0
            e_seg = kh_eff**2 / 24.0 + (min(h, dz_load) * k_load) ** 2 / 12.0 \
                if (k_load and not exact) else kh_eff**2 / 24.0
            # wave-load rule: the part above z_load gets h ≤ dz_load
            wet_part = None  # (a, b) arc-length interval of the finely meshed top part
            if k_load and not exact:
                sel = (s_nodes >= g["s0"] - 1e-9) & (s_nodes <= g["s1"] + 1e-9)
                ss, zz = s_nodes[sel], z_nodes[sel]
                wet = zz > -z_load
                if np.all(wet):
                    if dz_load < h:
                        h = dz_load
                        n = max(1, int(math.ceil(g["length"] / h - 1e-9)))
                        rule = (f"wave loads (nodal kinematics e^(kz-ikx)): h ≤ "
                                f"√(12·{eps_el / 2:.2g})/k = {dz_load:.3g} m, k = {k_load:.3g} "
                                "rad/m")
                elif wet[-1] or wet[0]:
                    top_end = bool(wet[-1] and (not wet[0] or zz[-1] >= zz[0]))
                    if top_end:
                        j = int(np.flatnonzero(~wet)[-1])
                        l_top = g["s1"] - ss[j]
                    else:
                        j = int(np.flatnonzero(~wet)[0])
                        l_top = ss[j] - g["s0"]
                    if dz_load < h and 0.0 < l_top < g["length"]:
                        wet_part = ((g["s1"] - l_top, g["s1"]) if top_end
                                    else (g["s0"], g["s0"] + l_top))
            # touchdown rule: a node at the static touchdown.  The linear model's contact
            # state is the static one (grounded nodes on the seabed springs), so a
            # touchdown inside an element puts an O(h) error on the suspended length;
            # measured on tuah_1982_single_leg: fairlead σ −3.3 %, +2.0 %, −0.8 %, +0.5 %
            # at 56, 112, 224, 448 uniform elements, +0.09 %, +0.03 % at 56, 112 with a
            # node at the touchdown (then the √ε rule above bounds it).
            s_td = g.get("touchdown")
            cut_td = (s_td is not None and g["s0"] + 1e-6 * g["length"] < s_td
                      < g["s1"] - 1e-6 * g["length"])
            if wet_part is None and not cut_td:
                new.append((i, g["length"], n))
                choices.append(Choice(path, n, rule + f"; h = {g['length'] / n:.3g} m",
                                      e_seg))
                err = max(err, e_seg)
                continue
            cuts = sorted({g["s0"], g["s1"]}
                          | ({wet_part[0], wet_part[1]} if wet_part else set())
                          | ({float(s_td)} if cut_td else set()))
            parts, counts = [], []
            for a, b in zip(cuts[:-1], cuts[1:]):
                if b - a <= 1e-9 * g["length"]:
                    continue
                in_wet = wet_part is not None and wet_part[0] - 1e-9 <= a and \
                    b <= wet_part[1] + 1e-9
                hp = min(h, dz_load) if in_wet else h
                m = max(1, int(math.ceil((b - a) / hp - 1e-9)))
                parts.append((i, float(b - a), m))
                counts.append(m)
            new.extend(parts)
            why = []
            if wet_part is not None:
                why.append(f"wave-load depth {z_load:.3g} m (e^(kz) < {eps_el:.2g}, k = "
                           f"{k_load:.3g} rad/m): the part above it with h ≤ "
                           f"√(12·{eps_el / 2:.2g})/k = {dz_load:.3g} m")
            if cut_td:
                why.append(f"a node at the static touchdown s = {float(s_td):.4g} m")
            choices.append(Choice(
                path, counts,
                "split at " + " and ".join(why) + f"; elsewhere {rule} (lengths "
                + ", ".join(f"{L:.4g}" for _, L, _ in parts) + " m)", e_seg))
            err = max(err, e_seg)
        out[line.name] = tuple(new)
    return out, choices, err


def _segments_scene(scene: Scene, segments: dict[str, tuple[tuple[int, float, int], ...]],
                    update: dict[str, Any]) -> Scene:
    lines = []
    for line in scene.lines:
        spec = segments.get(line.name)
        if spec is None:
            lines.append(line)
            continue
        segs = tuple(line.segments[i].model_copy(update={"length": float(L),
                                                         "elements": int(n)})
                     for i, L, n in spec)
        lines.append(line.model_copy(update={"segments": segs}))
    analysis = scene.analysis.model_copy(update=update)
    new = scene.model_copy(update={"lines": tuple(lines), "analysis": analysis})
    return Scene.model_validate(new.model_dump())


# ------------------------------------------------------------------------ pilot


def _response_spectra(line_result: Any) -> dict[str, np.ndarray]:
    spectra = line_result.input_spectra
    out = {}
    for end in ("end_a", "end_b"):
        out[f"{line_result.name}.{end}.tension"] = np.einsum(
            "cw,cw->w", np.abs(line_result.end_tension_transfer[end]) ** 2, spectra)
    out[f"{line_result.name}.motion"] = np.einsum(
        "cnkw,cw->w", np.abs(line_result.motion_transfer) ** 2, spectra)
    return out


def _modal_bandwidths(line_result: Any, scene: Scene) -> tuple[np.ndarray, np.ndarray]:
    """Natural frequencies and half-power bandwidths 2ζω of the pilot's modes."""
    from stochcable.dynamics.loads import drag_matrix

    model, modes, rec = line_result.model, line_result.modes, line_result.linearization
    wn = np.asarray(modes.omega, dtype=float)
    if rec is None or wn.size == 0:
        return wn, np.zeros_like(wn)
    c = drag_matrix(model, rec.b_normal, rec.b_axial)
    phi = modes.shapes[model.free]
    cff = c[model.free][:, model.free]
    band = np.einsum("ij,ij->j", phi, cff @ phi)
    sd = scene.analysis.structural_damping
    band = band + sd.alpha + sd.beta * wn**2
    return wn, np.maximum(band, 0.0)


def _pilot(scene: Scene, statics: Any, geo: dict[str, _LineGeometry], w_lo: float, w_top: float,
           w2_guess: float, k_load: float | None, exact: bool) -> tuple[Any, dict, float]:
    from stochcable.analysis import analyze

    eps_pilot = PILOT_KH**2 / 24.0
    segs, _, _ = _mesh_rules(scene, geo, w_top, w_top, eps_pilot, k_load, exact)
    total = {k: sum(n for _, _, n in v) for k, v in segs.items()}
    for name, n in total.items():
        if n > PILOT_MAX_ELEMENTS:
            f = PILOT_MAX_ELEMENTS / n
            segs[name] = tuple((i, L, max(1, int(round(m * f)))) for i, L, m in segs[name])
    update = {"omega": scene.analysis.omega.model_copy(
                  update={"min": w_lo, "max": w_top, "count": PILOT_COUNT,
                          "spacing": "log"}),
              "solver": "direct", "modes": "auto", "timeseries": None,
              "linearization": scene.analysis.linearization.model_copy(
                  update={"tolerance": 1e-3})}
    pscene = _segments_scene(scene, segs, update)
    t0 = time.perf_counter()
    import warnings as _w
    with _w.catch_warnings():
        _w.simplefilter("ignore")
        res = analyze(pscene)
    wall = time.perf_counter() - t0
    info = {"elements": {k: sum(n for _, _, n in v) for k, v in segs.items()},
            "omega_min": w_lo, "omega_max": w_top, "count": PILOT_COUNT,
            "spacing": "log", "wall_s": wall}
    return res, info, wall


# ------------------------------------------------------------------------ public


def choose_fidelity(scene: Scene | Any, target_error: float = 0.01, *,
                    exact_wave_integration: bool = False,
                    allow_grid_values: bool | None = None) -> FidelityPlan:
    """Settings that meet a target error of the response σ at the least cost.

    Parameters
    ----------
    scene : Scene or document
        The scene; its own accuracy settings are ignored (except the solver's
        linearization method and structural damping).
    target_error : float, default 0.01
        Target relative error of the σ of end tensions and motions. [-]
    exact_wave_integration : bool, default False
        Whether the engine integrates the wave loads exactly over each element (then the
        wave-load element rule is dropped).
    allow_grid_values : bool, optional
        Use a non-uniform grid (``analysis.omega.values``); default: when
        ``OmegaGrid`` has a ``values`` field.

    Returns
    -------
    FidelityPlan

    Notes
    -----
    See the module docstring for the rules.  Cost: one static solve and one pilot
    analysis (log grid of :data:`PILOT_COUNT` points, mesh with kh = 1 at its top;
    doubled up to :data:`PILOT_EXTENSIONS` times while the response tail is unbounded
    or the pilot's top is below 2·ω_max).
    """
    from stochcable.sea.kinematics import wavenumber
    from stochcable.line.statics import solve_statics

    scene = load_scene(scene)
    eps = _v.in_range("target_error", target_error, "-", 0.0, 0.5, lo_open=True)
    share = {k: v * eps for k, v in BUDGET.items()}
    if allow_grid_values is None:
        allow_grid_values = _grid_values_supported()
    choices: list[Choice] = []
    env = scene.environment
    statics = solve_statics(scene, method="fe")
    geo = _segment_geometry(scene, statics, static_touchdowns(scene))
    # --- input band and the load wavenumber
    w_lo_in, w_hi_in, per = _input_band(scene, PILOT_INPUT_FRACTION)
    w_lo_in = min(w_lo_in, _input_band(scene, PILOT_LOW_FRACTION)[0])
    k_load = None
    if scene.sea is not None and "sea" in per:
        k_load = float(wavenumber(per["sea"][2], env.depth, env.g))
    w2_in = max((v[2] for v in per.values()), default=1.0)
    # --- pilot, extended while the response tail is unbounded
    w_top = w_hi_in
    pilot_wall = 0.0
    pilot_info: dict[str, Any] = {}
    for ext in range(PILOT_EXTENSIONS + 1):
        res, info, wall = _pilot(scene, statics, geo, w_lo_in, w_top, w2_in, k_load,
                                 exact_wave_integration)
        pilot_wall += wall
        pilot_info = {**info, "extensions": ext, "wall_s": pilot_wall}
        spectra: dict[str, np.ndarray] = {}
        for lr in res.lines.values():
            spectra.update(_response_spectra(lr))
        w = next(iter(res.lines.values())).omega
        bounded, worst_tail = True, 0.0
        for s in spectra.values():
            if s.max() <= 0:
                continue
            ab = _tail_above(w, s, _tail_exponent(w, s))
            m0 = ab[0] + _tail_below(w, s)[0]
            frac = (s[-1] * w[-1] / (_tail_exponent(w, s) - 1.0) / m0
                    if _tail_exponent(w, s) > 1 + MIN_TAIL_EXCESS else math.inf)
            worst_tail = max(worst_tail, frac)
            if not np.isfinite(ab[0]) or frac > share["band"]:
                bounded = False
        # the pilot must also *cover* [ω_max, 2·ω_max] (resonances in the tail make a
        # power-law extrapolation unreliable: on the chain it missed 3 % of the variance)
        covered = True
        if bounded:
            lim = 2.0 * share["band"] * 0.8
            for s in spectra.values():
                if s.max() <= 0:
                    continue
                ab = _tail_above(w, s, _tail_exponent(w, s))
                m0 = ab[0] + _tail_below(w, s)[0]
                if 2.0 * _crossing_up(w, ab / m0, lim) > w[-1] * (1 + 1e-9):
                    covered = False
        if (bounded and covered) or ext == PILOT_EXTENSIONS:
            break
        w_top *= 2.0
    # --- band from the response spectra
    lim_hi = 2.0 * share["band"] * 0.8  # variance fractions (σ error ≈ half)
    lim_lo = 2.0 * share["band"] * 0.2
    w_max, w_min, band_err, w2 = 0.0, math.inf, 0.0, 0.0
    detail = []
    for name, s in spectra.items():
        if s.max() <= 0:
            continue
        p = _tail_exponent(w, s)
        above = _tail_above(w, s, p)
        below = _tail_below(w, s)
        m0 = below[-1] + (above[-1] if np.isfinite(above[-1]) else 0.0)
        if m0 <= 0:
            continue
        fa = np.where(np.isfinite(above), above / m0, np.inf)
        hi = _crossing_up(w, fa, lim_hi)
        lo = _crossing_down(w, below / m0, lim_lo)
        w_max, w_min = max(w_max, hi), min(w_min, lo)
        m2 = np.trapezoid(w**2 * s, w)
        w2 = max(w2, math.sqrt(m2 / np.trapezoid(s, w)))
        detail.append(f"{name}: tail S ∝ ω^-{p:.2g} at the pilot top, ω_hi {hi:.3g}")
    if not detail:  # no response at all: keep the input band
        w_min, w_max, w2 = w_lo_in, w_hi_in, w2_in
    w_max = min(max(w_max, 1.05 * w_min), float(w[-1]))
    # band error actually left (variance fractions on the final band, /2 for σ)
    for s in spectra.values():
        if s.max() <= 0:
            continue
        p = _tail_exponent(w, s)
        above = _tail_above(w, s, p)
        below = _tail_below(w, s)
        m0 = below[-1] + (above[-1] if np.isfinite(above[-1]) else 0.0)
        fa = np.interp(math.log(w_max), np.log(w), np.where(np.isfinite(above), above, np.nan)
                       ) / m0
        fb = np.interp(math.log(w_min), np.log(w), below) / m0
        band_err = max(band_err, 0.5 * ((fa if np.isfinite(fa) else 1.0) + fb))
    tail_bounded = bool(bounded)
    tail_note = ("" if tail_bounded else
                 "; a response tail is NOT bounded at the pilot top "
                 f"{w[-1]:.3g} rad/s (decays slower than ω^-{1 + MIN_TAIL_EXCESS:g}, e.g. "
                 "an ω⁻⁵ end-motion spectrum driving inertia loads): σ depends on the band "
                 "and the band error is a lower bound")
    choices.append(Choice("analysis.omega.max", w_max,
                          f"response variance above ≤ {lim_hi:.2g} m0 (pilot to "
                          f"{w[-1]:.3g} rad/s + power-law tail); " + "; ".join(detail)
                          + tail_note, band_err))
    choices.append(Choice("analysis.omega.min", w_min,
                          f"response variance below ≤ {lim_lo:.2g} m0 (pilot from "
                          f"{w[0]:.3g} rad/s)", 0.0))
    # --- elements (final band)
    segs, el_choices, el_err = _mesh_rules(scene, geo, w2, w_max, share["elements"],
                                           k_load, exact_wave_integration)
    choices.extend(el_choices)
    # --- grid
    # half of the grid share for the peaks, half for the smooth input spectra
    n_bw = points_per_bandwidth(share["grid"] / 2.0)
    base = _base_count(scene, w_min, w_max, share["grid"])
    dw_base = (w_max - w_min) / (base - 1)
    peaks = []
    for lr in res.lines.values():
        wn, bw = _modal_bandwidths(lr, scene)
        for wj, bj in zip(wn, bw):
            if w_min <= wj <= w_max and bj > 0 and bj < PEAK_RESOLVED * dw_base:
                peaks.append((float(wj), float(bj)))
            elif w_min <= wj <= w_max and bj <= 0:
                peaks.append((float(wj), 1e-6 * float(wj)))
    dw_fine = min([dw_base] + [b / n_bw for _, b in peaks])
    count_lin = int(math.ceil((w_max - w_min) / dw_fine)) + 1
    values = _union_grid(w_min, w_max, base, peaks, n_bw)
    grid_err = 2.0 * math.exp(-math.pi * n_bw) + share["grid"] / 2.0
    use_values = bool(allow_grid_values) and len(values) < count_lin
    n_freq = len(values) if use_values else count_lin
    choices.append(Choice(
        "analysis.omega.count" if not use_values else "analysis.omega.values",
        n_freq,
        f"base linear spacing {dw_base:.3g} rad/s ({base} points: trapezoid of S, ω²S, "
        f"ω⁴S of the inputs within {share['grid'] / 2:.2g}); {len(peaks)} lightly damped "
        f"mode(s) in the band need {n_bw:.2g} points per half-power bandwidth "
        f"(2e^(-πN) ≤ {share['grid'] / 2:.2g})"
        + (f", narrowest {min(b for _, b in peaks):.3g} rad/s at "
           f"{min(peaks, key=lambda p: p[1])[0]:.3g} rad/s" if peaks else "")
        + ("; non-uniform union grid" if use_values else
           f"; linear grid at the finest spacing {dw_fine:.3g} rad/s"
           + (f" (a non-uniform grid would need {len(values)})" if len(values) < count_lin
              else "")),
        grid_err))
    # --- modes
    f_need = math.sqrt(MODE_ERROR_CONSTANT / share["modes"])
    n_el_total = max(sum(n for _, _, n in v) for v in segs.values())
    if f_need <= AUTO_FACTOR:
        solver, modes = "foss", "auto"
        mode_err = MODE_ERROR_CONSTANT / AUTO_FACTOR**2
        why = (f"Foss 'auto' keeps the modes up to {AUTO_FACTOR:g}·ω_max ≥ F·ω_max, F = "
               f"√({MODE_ERROR_CONSTANT:g}/{share['modes']:.2g}) = {f_need:.3g}")
    else:
        wn_all = np.concatenate([np.asarray(lr.modes_omega) for lr in res.lines.values()])
        n_keep = int(np.count_nonzero(wn_all <= f_need * w_max))
        if n_keep > DIRECT_MODES or n_keep >= n_el_total:
            solver, modes, mode_err = "direct", "auto", 0.0
            why = (f"{n_keep} modes up to F·ω_max (F = {f_need:.3g}) > {DIRECT_MODES}: the "
                   "direct solve is exact and cheaper")
        else:
            solver, modes = "foss", max(1, n_keep)
            mode_err = MODE_ERROR_CONSTANT / f_need**2
            why = f"modes up to F·ω_max, F = √(C/ε_modes) = {f_need:.3g} (pilot modes)"
    choices.append(Choice("analysis.solver", solver, why, 0.0))
    choices.append(Choice("analysis.modes", modes, why, mode_err))
    tol = share["linearization"]
    choices.append(Choice("analysis.linearization.tolerance", tol,
                          "fraction of the target: the fixed point's remaining error ≈ "
                          "the last relative change of the σ", tol))
    parts = {"band": band_err, "grid": grid_err, "elements": el_err, "modes": mode_err,
             "linearization": tol}
    parts["total"] = float(sum(parts.values()))
    n_el = sum(sum(n for _, _, n in v) for v in segs.values())
    cost = {"elements": float(n_el), "frequencies": float(n_freq),
            "elements_x_frequencies": float(n_el * n_freq)}
    return FidelityPlan(
        target_error=eps, omega_min=float(w_min), omega_max=float(w_max),
        omega_count=count_lin, omega_values=tuple(float(x) for x in values),
        segments=segs, solver=solver, modes=modes, tolerance=float(tol),
        choices=tuple(choices), error_estimate=parts, cost=cost,
        tail_bounded=tail_bounded, omega_response=float(w2), pilot=pilot_info,
    )


def _base_count(scene: Scene, w_min: float, w_max: float, eps: float) -> int:
    """Coarsest linear count whose trapezoid sums of S, ω²S, ω⁴S of every input on
    [w_min, w_max] are within eps/2 of a fine quadrature."""
    fine = np.linspace(w_min, w_max, 20001)
    dens = [np.asarray(d(fine), dtype=float) for _, d in _input_densities(scene)]
    refs = [[np.trapezoid(fine**p * s, fine) for p in (0, 2, 4)] for s in dens]

    def ok(n: int) -> bool:
        x = np.linspace(w_min, w_max, n)
        for s, r in zip(dens, refs):
            sx = np.interp(x, fine, s)
            for p, rp in zip((0, 2, 4), r):
                if rp > 0 and abs(np.trapezoid(x**p * sx, x) / rp - 1.0) > eps / 2.0:
                    return False
        return True

    lo, hi = 8, 16
    while not ok(hi) and hi < 20000:
        lo, hi = hi, 2 * hi
    while hi - lo > 1:
        mid = (lo + hi) // 2
        lo, hi = (lo, mid) if ok(mid) else (mid, hi)
    return hi


def _union_grid(w_min: float, w_max: float, base: int,
                peaks: list[tuple[float, float]], n_bw: float) -> np.ndarray:
    parts = [np.linspace(w_min, w_max, base)]
    for wj, bj in peaks:
        a, b = max(w_min, wj - PEAK_HALF_WIDTHS * bj), min(w_max, wj + PEAK_HALF_WIDTHS * bj)
        n = int(math.ceil((b - a) / (bj / n_bw))) + 1
        parts.append(np.linspace(a, b, max(n, 2)))
    x = np.unique(np.concatenate(parts))
    keep = np.concatenate([[True], np.diff(x) > 1e-9 * w_max])
    return x[keep]


def _grid_values_supported() -> bool:
    from stochcable.scene.model import OmegaGrid

    return "values" in getattr(OmegaGrid, "model_fields", {})


def apply_fidelity(scene: Scene | Any, plan: FidelityPlan) -> Scene:
    """A new scene with the plan's settings (the input is not modified).

    Parameters
    ----------
    scene : Scene or document
        The scene the plan was made for.
    plan : FidelityPlan

    Returns
    -------
    Scene
        Segments (possibly split, same properties) with the planned element counts, and
        ``analysis`` with the planned grid, solver, modes and tolerance; the
        non-uniform grid when ``OmegaGrid`` supports ``values`` and the plan chose it.
    """
    scene = load_scene(scene)
    if not isinstance(plan, FidelityPlan):
        raise _v.InputError("plan", type(plan).__name__, "-", "must be a FidelityPlan")
    use_values = any(c.setting == "analysis.omega.values" for c in plan.choices) and \
        _grid_values_supported()
    om: dict[str, Any] = {"min": plan.omega_min, "max": plan.omega_max,
                          "count": plan.omega_count, "spacing": "linear"}
    if use_values:  # pragma: no cover - needs the proposed OmegaGrid.values
        om = {"min": plan.omega_min, "max": plan.omega_max,
              "count": len(plan.omega_values), "values": list(plan.omega_values)}
    update = {"omega": scene.analysis.omega.model_copy(update=om),
              "solver": plan.solver, "modes": plan.modes,
              "linearization": scene.analysis.linearization.model_copy(
                  update={"tolerance": plan.tolerance})}
    return _segments_scene(scene, plan.segments, update)
