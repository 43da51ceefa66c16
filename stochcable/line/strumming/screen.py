"""Strumming (vortex-induced vibration) of a line in a steady current, in the
frequency domain (Tuah (1982), §3.2.b).

A steady normal flow U_n past an element of diameter D sheds vortices at
ω_s = 2π·St·U_n/D (Tuah (1982), eq. 3.2.b.4).  A natural mode ω_n is a lock-in candidate
when its reduced velocity V_R = 2π U_n/(ω_n D) lies in the cross-flow band
3 ≤ V_R ≤ 16 of DNV-RP-C205 (2010) ch. 9 (:data:`CROSS_FLOW_BAND`); the nearest
candidates are balanced with the Skop–Griffin wake oscillator
(:mod:`stochcable.line.strumming.balance`).  A mode with a first-harmonic solution is
*locked in* and vibrates at its steady amplitude; one without is an *unlocked* mode
driven by the free wakes (C_L = C_L0 at ω_s), whose response is bounded by twice the
forced amplitude (the beat from rest, Tuah (1982), Example 6).  The vibration of a
locked-in mode magnifies the in-line drag: C_d/C_d0 = 1 + 1.043 (2 Y_rms/D)^0.65
(Vandiver 1983, :func:`drag_amplification_vandiver`).

:func:`strumming_screen` is the one entry point: one line's static shape, sections,
current and natural modes in, a :class:`StrummingTable` out.

References
----------
Griffin, O. M., Skop, R. A. and Ramberg, S. E. (1975), The resonant, vortex-excited
vibrations of structures and cable systems, Offshore Technology Conference, OTC 2319.
Tuah, H. (1982), Cable dynamics in an ocean environment, PhD thesis, Oregon State University.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from stochcable.errors import InputError
from stochcable.line.strumming.balance import (
    CROSS_FLOW_BAND,
    LIFT_DEFAULT,
    STROUHAL_DEFAULT,
    _check_positive,
    drag_amplification_vandiver,
    hydrodynamic_damping_ratio,
    lock_in_balance,
    reduced_damping,
    reduced_velocity,
    shedding_frequency,
    strouhal_roshko,
    wake_parameters,
)
from stochcable.validation import finite_scalar

if TYPE_CHECKING:
    from stochcable.design.curves import FatigueCurve

__all__ = [
    "CROSS_FLOW_BAND",
    "STROUHAL_DEFAULT",
    "LIFT_DEFAULT",
    "shedding_frequency",
    "strouhal_roshko",
    "reduced_velocity",
    "hydrodynamic_damping_ratio",
    "reduced_damping",
    "drag_amplification_vandiver",
    "amplitude_griffin",
    "StrummingInput",
    "ElementFlow",
    "element_flow",
    "StrummingMode",
    "StrummingTable",
    "strumming_screen",
]

#: Candidate modes balanced per line (nearest to the shedding frequency, Tuah
#: (1982), §3.2.b: "the natural frequency having a value closest to the shedding frequency"). [-]
_CANDIDATES = 3
#: Least share of a mode's modal mass that moves across the flow on shedding elements
#: for it to be a candidate (an in-line or axial mode is not excited by the lift). [-]
_MIN_SHARE = 0.05
#: A mode's modal lift below this fraction of the sum of its magnitudes is zero by
#: symmetry (what is left is round-off: 1e-16 of the terms, whose digits differ
#: between BLAS paths). [-]
_CANCELLATION = 1e-12


@dataclass(frozen=True, eq=False)
class StrummingInput:
    """One line's data for the screening (per element unless stated).

    Attributes
    ----------
    positions : ndarray, shape (n_nodes, 3)
        Static node positions. [m]
    current : ndarray, shape (n_el, 3)
        Steady current at the element midpoints. [m/s]
    diameter, cd_normal, mass, ca_normal, ea, l0 : ndarray, shape (n_el,)
        Diameter [m], normal drag coefficient [-], mass per length in air [kg/m],
        normal added-mass coefficient [-], axial stiffness [N], unstretched length [m].
    strouhal, lift : ndarray, shape (n_el,)
        St [-] (NaN: from the Reynolds number, :func:`strouhal_roshko`) and C_L0 [-]
        (lift 0 where strumming is suppressed).
    rho : float
        Water density. [kg/m³]
    viscosity : float
        Kinematic viscosity. [m²/s]
    structural_damping : ndarray, shape (n_el,)
        Structural damping ratio (ψ²-weighted into each mode's). [-]
    """

    positions: np.ndarray
    current: np.ndarray
    diameter: np.ndarray
    cd_normal: np.ndarray
    mass: np.ndarray
    ca_normal: np.ndarray
    ea: np.ndarray
    l0: np.ndarray
    strouhal: np.ndarray
    lift: np.ndarray
    rho: float
    viscosity: float
    structural_damping: np.ndarray | float = 0.0

    def __post_init__(self) -> None:
        n_el = np.asarray(self.l0).size
        for name, unit in (("diameter", "m"), ("viscosity", "m²/s")):
            _check_positive(name, np.asarray(getattr(self, name), dtype=float), unit)
        st = np.asarray(self.strouhal, dtype=float)
        _check_positive("strouhal", st[~np.isnan(st)], "-")
        lift = np.asarray(self.lift, dtype=float)
        if np.any(~np.isfinite(lift)) or np.any(lift < 0):
            raise InputError("lift_coefficient", float(lift.min()), "-", "C_L0 must be >= 0")
        zeta = np.asarray(self.structural_damping, dtype=float)
        if np.any(~np.isfinite(zeta)) or np.any(zeta < 0) or np.any(zeta >= 1):
            raise InputError("damping_ratio", self.structural_damping, "-", "must be in [0, 1)")
        for name in ("current", "diameter", "cd_normal", "mass", "ca_normal", "ea"):
            if np.asarray(getattr(self, name)).shape[0] != n_el:
                raise InputError(name, np.shape(getattr(self, name)), "-", f"needs {n_el} rows")


@dataclass(frozen=True, eq=False)
class StrummingMode:
    """One screened mode of a :class:`StrummingTable`.

    Attributes
    ----------
    index : int
        Mode index in the line's modes (0 = lowest). [-]
    omega_n : float
        Natural frequency. [rad/s]
    omega_s : float
        Shedding frequency where the mode is excited (ψ²-weighted mean). [rad/s]
    omega : float
        Response frequency (the lock-in frequency, or ω_s when unlocked). [rad/s]
    reduced_velocity : float
        V_R = 2π U_n/(ω_n D), ψ²-weighted. [-]
    locked : bool
        Whether the wake oscillator locks in (a harmonic-balance solution exists).
    resonant : bool
        Unlocked, but ω_s within the mode's half-power band |ω_s − ω_n| ≤ 2ξω_n: the
        free wakes drive a steady resonance (amplitude :func:`amplitude_griffin`).
    amplitude_over_d : float
        Largest cross-flow amplitude over the diameter: steady lock-in amplitude; for a
        resonant mode :func:`amplitude_griffin`; for another unlocked mode the beat
        bound (twice the forced amplitude). [-]
    damping_ratio, reduced_damping : float
        ξ (structural + hydrodynamic) and S_G of the mode. [-]
    displacement : ndarray, shape (n_nodes, 3)
        Steady amplitude of the node displacements (forced amplitude when unlocked). [m]
    tension_range : ndarray, shape (n_el,)
        Peak-to-peak dynamic effective tension of the strumming mode. [N]
    cycle_rate : float
        Stress cycles per second, ω/(2π) (an extra narrow-band component). [1/s]
    """

    index: int
    omega_n: float
    omega_s: float
    omega: float
    reduced_velocity: float
    locked: bool
    resonant: bool
    amplitude_over_d: float
    damping_ratio: float
    reduced_damping: float
    displacement: np.ndarray
    tension_range: np.ndarray
    cycle_rate: float

    def damage_rate(self, curve: FatigueCurve, to_quantity: float) -> np.ndarray:
        """Miner damage per second of the strumming cycles, per element.

        Parameters
        ----------
        curve : FatigueCurve
            The fatigue curve (:func:`stochcable.design.curves.fatigue_curve`).
        to_quantity : float
            Factor from tension to the curve's quantity
            (:func:`stochcable.design.curves.tension_to_curve_quantity`). [1/m² or 1/N]

        Returns
        -------
        ndarray, shape (n_el,)
            ν / N(S), S = ``to_quantity`` · tension range: the constant-amplitude
            narrow-band component to add to the wave-frequency damage rate. [1/s]
        """
        from stochcable.design.curves import FatigueCurve  # (fatigue only: not at import)

        if not isinstance(curve, FatigueCurve):
            raise InputError("curve", type(curve).__name__, "-", "must be a FatigueCurve")
        ranges = finite_scalar("to_quantity", to_quantity, "-") * self.tension_range
        return self.cycle_rate / curve.cycles_to_failure(ranges)

    def as_dict(self) -> dict:
        """JSON-ready dict (SI: rad/s, m, N, 1/s)."""
        return {
            "mode": self.index,
            "omega_n": self.omega_n,
            "omega_s": self.omega_s,
            "omega": self.omega,
            "reduced_velocity": self.reduced_velocity,
            "locked": self.locked,
            "resonant": self.resonant,
            "amplitude_over_d": self.amplitude_over_d,
            "damping_ratio": self.damping_ratio,
            "reduced_damping": self.reduced_damping,
            "tension_range": self.tension_range.tolist(),
            "cycle_rate": self.cycle_rate,
        }


@dataclass(frozen=True, eq=False)
class StrummingTable:
    """Strumming screening of one line (:func:`strumming_screen`).

    Attributes
    ----------
    modes : tuple of StrummingMode
        The screened candidate modes (in the lock-in band, nearest to ω_s first).
    omega_s : ndarray, shape (n_el,)
        Shedding frequency of every element (0 without flow or where suppressed). [rad/s]
    cd_normal : ndarray, shape (n_el,)
        Normal drag coefficient amplified by the governing mode's vibration. [-]
    governing : int or None
        Position in ``modes`` of the mode whose amplitude amplifies the drag: the
        strumming (locked-in or resonant) mode of largest amplitude.  None when no mode
        strums: an unlocked, non-resonant mode's wakes drift in phase along the line
        and its response decays (Tuah (1982), Example 6, tests/line/test_strumming.py), so the
        drag is not amplified.
    """

    modes: tuple[StrummingMode, ...]
    omega_s: np.ndarray
    cd_normal: np.ndarray
    governing: int | None

    @property
    def locked(self) -> tuple[StrummingMode, ...]:
        """The modes that strum: locked in, or resonant with the free wakes."""
        return tuple(m for m in self.modes if m.locked or m.resonant)

    def as_dict(self) -> dict:
        """JSON-ready dict for the result document."""
        return {
            "modes": [m.as_dict() for m in self.modes],
            "governing": self.governing,
            "cd_normal": self.cd_normal.tolist(),
            "omega_s": self.omega_s.tolist(),
        }


@dataclass(frozen=True, eq=False)
class ElementFlow:
    """The steady flow past every element (:func:`element_flow`).

    Attributes
    ----------
    tangent, lift_direction : ndarray, shape (n_el, 3)
        Unit tangent t and lift direction l = t × U_n/|U_n| (zero without flow). [-]
    speed : ndarray, shape (n_el,)
        Normal flow speed |U_n|. [m/s]
    length : ndarray, shape (n_el,)
        Static (stretched) element length. [m]
    lift_on : ndarray of bool, shape (n_el,)
        Elements that shed vortices (flow and C_L0 > 0).
    omega_s : ndarray, shape (n_el,)
        Shedding frequency (0 where the lift is off). [rad/s]
    q : ndarray, shape (n_el,)
        ½ρ D U_n² L, the lift force per unit C_L (0 where the lift is off). [N]
    strouhal : ndarray, shape (n_el,)
        The Strouhal number used (the given one, or from the Reynolds number). [-]
    """

    tangent: np.ndarray
    lift_direction: np.ndarray
    speed: np.ndarray
    length: np.ndarray
    lift_on: np.ndarray
    omega_s: np.ndarray
    q: np.ndarray
    strouhal: np.ndarray

    def along_lift(self, shape: np.ndarray) -> np.ndarray:
        """ψ_e = ½(φ_a + φ_b)·l_e of one node field ``shape`` (n_nodes, 3). [same unit]"""
        mid = 0.5 * (np.asarray(shape)[:-1] + np.asarray(shape)[1:])
        return np.einsum("ek,ek->e", self.lift_direction, mid)


def element_flow(line: StrummingInput) -> ElementFlow:
    """Normal flow, lift direction, shedding frequency and lift load of every element.

    Parameters
    ----------
    line : StrummingInput

    Returns
    -------
    ElementFlow
    """
    pos = np.asarray(line.positions, dtype=float)
    seg = np.diff(pos, axis=0)
    length = np.linalg.norm(seg, axis=1)
    t = seg / length[:, None]
    u = np.asarray(line.current, dtype=float)
    u_n = u - np.einsum("ij,ij->i", u, t)[:, None] * t
    speed = np.linalg.norm(u_n, axis=1)
    lift_on = (speed > 0) & (np.asarray(line.lift) > 0)
    ldir = np.zeros_like(t)
    ldir[lift_on] = np.cross(t[lift_on], u_n[lift_on]) / speed[lift_on, None]
    d = np.asarray(line.diameter, dtype=float)
    st = np.asarray(line.strouhal, dtype=float)
    st = np.where(np.isnan(st), strouhal_roshko(speed * d / line.viscosity), st)
    lift_on &= st > 0
    ldir[~lift_on] = 0.0
    omega_s = np.where(lift_on, 2.0 * math.pi * st * speed / d, 0.0)
    q = np.where(lift_on, 0.5 * line.rho * d * speed**2 * length, 0.0)
    return ElementFlow(t, ldir, speed, length, lift_on, omega_s, q, st)


def strumming_screen(line: StrummingInput, omega_n, shapes) -> StrummingTable:
    """Screen one line in a steady current for strumming.

    Parameters
    ----------
    line : StrummingInput
        Static shape, sections, current and strumming settings.
    omega_n : array_like, shape (count,)
        Natural frequencies (with added mass). [rad/s]
    shapes : array_like, shape (n_nodes, 3, count)
        Mode shapes, global x, y, z per node, normalized φᵀ M_T φ = 1. [kg^-1/2]

    Returns
    -------
    StrummingTable

    Notes
    -----
    Per element: tangent t, normal flow U_n = U − (U·t)t, lift direction
    l = t × U_n/|U_n|, ω_s = 2π St |U_n|/D.  Per mode: ψ_e = ½(φ_a + φ_b)·l_e, the
    ψ²-weighted U_n, D, m_T = m + C_a ρπD²/4 and ω_s; a candidate moves at least 5 %
    of its modal mass Σ m_T L ψ² across the flow and has V_R (:func:`reduced_velocity`)
    in :data:`CROSS_FLOW_BAND`; ξ = structural + :func:`hydrodynamic_damping_ratio`;
    S_G (:func:`reduced_damping`); the balance
    (:func:`~stochcable.line.strumming.balance.lock_in_balance`).  Unlocked: free wakes
    C_L0 at ω_s, A_f = |Σ q ψ C_L0|/|ω_n² − ω_s² + 2iξω_nω_s|, reported 2A_f.  The
    tension amplitude of element e is (EA/l0)·t·(φ_b − φ_a)·A (linear), its range twice
    that.  The drag of element e is amplified with Y_rms = A|ψ_e|/√2 of the governing
    (locked-in) mode.
    """
    flow = element_flow(line)
    w_n = np.asarray(omega_n, dtype=float)
    phi = np.asarray(shapes, dtype=float)
    t, ldir, speed = flow.tangent, flow.lift_direction, flow.speed
    lift_on, omega_s, q, length = flow.lift_on, flow.omega_s, flow.q, flow.length
    d = np.asarray(line.diameter, dtype=float)
    m_t = np.asarray(line.mass) + np.asarray(line.ca_normal) * line.rho * math.pi * d**2 / 4
    cd0 = np.asarray(line.cd_normal, dtype=float)
    if not np.any(lift_on) or w_n.size == 0:
        return StrummingTable((), omega_s, cd0.copy(), None)
    mid = 0.5 * (phi[:-1] + phi[1:])  # (n_el, 3, count)
    psi = np.einsum("ek,ekm->em", ldir, mid)  # (n_el, count)
    weight = psi**2 * length[:, None] * lift_on[:, None]
    total = weight.sum(axis=0)
    # share of the (unit) modal mass moving along the lift directions
    share = np.einsum("e,em->m", m_t * length * lift_on, psi**2)
    pick = np.flatnonzero((total > 0) & (w_n > 0) & (share >= _MIN_SHARE))
    wk_all = weight[:, pick] / total[pick]  # (n_el, picked): the ψ²L weights
    vr_all = reduced_velocity(speed @ wk_all, w_n[pick], d @ wk_all) if pick.size else pick
    in_band = (CROSS_FLOW_BAND[0] <= vr_all) & (vr_all <= CROSS_FLOW_BAND[1])
    cand = [
        (abs(math.log(w_n[k] / (wk_all[:, c] @ omega_s))), int(k), float(vr_all[c]), wk_all[:, c])
        for c, k in enumerate(pick)
        if in_band[c]
    ]
    cand.sort()
    stiff = np.asarray(line.ea) / np.asarray(line.l0)
    modes = []
    for _, k, vr, wk in cand[:_CANDIDATES]:
        modes.append(
            _screen_mode(
                line,
                k,
                w_n[k],
                vr,
                wk,
                psi[:, k],
                phi[:, :, k],
                q,
                d,
                m_t,
                omega_s,
                t,
                stiff,
                flow.strouhal,
            )
        )
    governing = None
    locked = [i for i, m in enumerate(modes) if m.locked or m.resonant]
    if locked:
        governing = max(locked, key=lambda i: modes[i].amplitude_over_d)
    cd = cd0.copy()
    if governing is not None:
        g = modes[governing]
        y_rms = np.abs(
            np.einsum("ek,ek->e", 0.5 * (g.displacement[:-1] + g.displacement[1:]), ldir)
        ) / math.sqrt(2.0)
        cd = np.where(lift_on, cd0 * drag_amplification_vandiver(y_rms / d), cd0)
    return StrummingTable(tuple(modes), omega_s, cd, governing)


def _screen_mode(line, k, w_n, vr, wk, psi, shape, q, d, m_t, omega_s, t, stiff, st_el):
    """The :class:`StrummingMode` of mode k (see :func:`strumming_screen`)."""
    zeta = np.broadcast_to(np.asarray(line.structural_damping, dtype=float), wk.shape)
    xi = float(wk @ zeta) + hydrodynamic_damping_ratio(
        line.rho, wk @ d, wk @ m_t, line.viscosity, w_n
    )
    st = float(wk @ st_el)
    sg = reduced_damping(wk @ m_t, xi, line.rho, wk @ d, st)
    params = wake_parameters(sg, xi)
    lift0 = np.asarray(line.lift, dtype=float)
    res = lock_in_balance(w_n, xi, psi, q, d, omega_s, lift0, params)
    ws_mode = float(wk @ omega_s)
    live = q > 0
    y_per_a = float(np.max(np.abs(psi[live]) / d[live]))  # Y_max/D per unit A
    resonant = False
    if res.locked:
        amp, omega, bound = res.amplitude, res.omega, 1.0
    else:
        terms = q * psi * lift0
        f = abs(np.sum(terms))
        if f <= _CANCELLATION * np.sum(np.abs(terms)):
            f = 0.0  # zero by symmetry (an antisymmetric mode in a uniform lift)
        amp = f / abs(w_n**2 - ws_mode**2 + 2j * xi * w_n * ws_mode)
        omega, bound = ws_mode, 2.0
        if abs(ws_mode - w_n) <= 2.0 * xi * w_n:
            # the free wakes drive the mode inside its half-power band: a steady
            # resonance at the Griffin–Skop–Ramberg amplitude (the wakes grow beyond
            # C_L0 there: the forced amplitude with C_L0 is below the time integration)
            resonant, bound = True, 1.0
            amp = amplitude_griffin(sg, _mode_shape_factor(psi, wk)) / y_per_a
    disp = amp * shape
    a_over_d = float(bound * amp * y_per_a)
    tension = stiff * np.abs(np.einsum("ek,ek->e", t, shape[1:] - shape[:-1])) * amp
    return StrummingMode(
        index=k,
        omega_n=float(w_n),
        omega_s=ws_mode,
        omega=float(omega),
        reduced_velocity=float(vr),
        locked=bool(res.locked),
        resonant=resonant,
        amplitude_over_d=a_over_d,
        damping_ratio=float(xi),
        reduced_damping=float(sg),
        displacement=disp,
        tension_range=2.0 * tension,
        cycle_rate=float(omega) / (2.0 * math.pi),
    )


def _mode_shape_factor(psi: np.ndarray, wk: np.ndarray) -> float:
    """γ = max|ψ| (Σ w ψ² / Σ w ψ⁴)^½ over the shedding elements (w ∝ ψ²L: use L)."""
    live = wk > 0
    length = wk[live] / psi[live] ** 2  # wk = ψ² L / Σ ψ² L, so this is ∝ L
    p = psi[live]
    return float(np.max(np.abs(p)) * math.sqrt(np.sum(length * p**2) / np.sum(length * p**4)))


def amplitude_griffin(reduced_damping_sg: float, shape_factor: float = 1.0) -> float:
    """Largest cross-flow amplitude of a locked-in mode over the diameter.

    Parameters
    ----------
    reduced_damping_sg : float
        S_G (>= 0). [-]
    shape_factor : float, optional
        Mode-shape factor γ = max|ψ| (∫ψ² / ∫ψ⁴)^½ (1 for a rigid cylinder, √(4/3)
        for a sine). [-]

    Returns
    -------
    float
        Y/D = 1.29 γ / (1 + 0.43 S_G)^3.35. [-]

    Notes
    -----
    Griffin, Skop & Ramberg (1975), OTC 2319 (Tuah (1982), ref. 20): the fit of measured
    resonant amplitudes of cylinders and cables against S_G that the wake oscillator's
    parameters (Tuah (1982), eq. 3.2.b.5) were calibrated to.
    """
    sg = finite_scalar("reduced_damping", reduced_damping_sg, "-")
    if sg < 0:
        raise InputError("reduced_damping", reduced_damping_sg, "-", "must be >= 0")
    return 1.29 * float(shape_factor) / (1.0 + 0.43 * sg) ** 3.35
