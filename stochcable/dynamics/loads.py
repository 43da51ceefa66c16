"""Excitation of a line: independent input channels and the hydrodynamic matrices.

The linear system of a line about its static shape (seed 001 eqs. 5.1, 5.2.6) is

    M_T Ü + (C_d + C_s) U̇ + K U = C_d V + B_I A          (all DOFs, U total motion)

with V, A the fluid velocity and acceleration at the nodes, C_d the linearized drag
damping (which also multiplies V: the drag acts on the relative velocity V − U̇),
B_I the Morison inertia matrix ρ(πD²/4)(1 + Can)(I − eeᵀ) per unit length and C_s the
seabed damping.  The end DOFs are prescribed: U = [U_f; u_b] and the free rows read

    (K_ff − ω² M_T,ff + iω C_ff) U_f = [C_d V + B_I A]_f − (K_fb − ω² M_T,fb + iω C_fb) u_b.

Input channels
--------------
The excitation is split into mutually independent (uncorrelated) input channels, each
with a one-sided input spectrum S_i(ω) [m²·s/rad] and a description per unit input
(:class:`Channel`):

- ``"sea"`` (when the scene has a sea): per metre of wave amplitude, the wave particle
  velocity and acceleration at every node (:func:`stochcable.sea.kinematics.wave_kinematics`
  at the static node positions, heading, depth, g), plus the end motions given as RAO
  tables, which are coherent with the waves and therefore belong to the same channel.
  RAO phases are relative to the wave elevation at the global origin (x = y = 0), the
  reference of the kinematics' phase P = e^{−ik(x cos β + y sin β)}.
- ``"<end>.<dof>"`` (``"end_b.surge"``, …): each end-motion *spectrum* DOF is its own
  channel with a unit prescribed displacement of that end along x (surge), y (sway) or
  z (heave).  These channels are taken as uncorrelated with the sea and with each other
  (the scene gives no cross-spectra); a vessel motion correlated with the waves must be
  given as an RAO table.

Response spectra are then S_x(ω) = Σ_i |H_{x,i}(ω)|² S_i(ω).

Distribution over the elements
------------------------------
The drag damping and the inertia matrix (for nodal accelerations) are distributed over
each element like the model's mass (consistent [[1/3, 1/6], [1/6, 1/3]]·l0 by default,
lumped [[1/2, 0], [0, 1/2]]·l0 when the model is lumped), with the element direction
constant over the element, so the matrices are symmetric (the non-symmetry the seed
avoids by lumping, seed 001 §3.2.a, comes from nodal direction cosines).  Lengths are
the unstretched lengths l0, as the added mass of :mod:`stochcable.line.fem`, so that a line
moving with a uniform fluid (Ü = A) feels exactly the Froude–Krylov force
ρ(πD²/4)(I − eeᵀ)A.  Attachments (buoys, clumps) get the isotropic inertia load
(buoyancy/g + added mass)·A and an isotropic linear drag B·(V − U̇) on their node.

Wave loads integrated exactly along the elements
------------------------------------------------
The wave kinematics decay like e^{kz} with depth and turn like e^{−ikx} along the wave:
over an element much longer than 1/k (near the surface at high frequency) their linear
interpolation between the nodes is far off (the inclined guy of docs/ACCURACY.md: its
26 m top element at z = 0 against 1/k = 0.6 m at 4 rad/s overestimated the fairlead
tension σ by 77 %).  Along a straight element from node a to node b, ξ = s/l ∈ [0, 1],
the kinematics per unit amplitude are sums of exponentials e^{E(ξ)} with E linear in
ξ (deep water: E = k z(ξ) − i k χ(ξ), χ = x cos β + y sin β; finite depth: cosh and
sinh as two exponentials).  :func:`element_wave_kinematics` integrates them in closed
form over the wet part of each element (split at z = 0; the dry part gets no load):

- the consistent (work-equivalent) moments ∫ N_a v dξ, ∫ N_b v dξ with N_a = 1 − ξ,
  N_b = ξ, so the element's Morison load on node i is
  l0·[ρ(πD²/4)(1 + Can)(I − eeᵀ)·iω + B_n(I − eeᵀ) + B_t eeᵀ]·∫ N_i v dξ
  (:func:`wave_loads`; B constant per element);
- the element mean square ∫ Re(v vᴴ) dξ, from which the drag linearization takes the
  σ of the relative velocity as an element mean (:mod:`stochcable.dynamics.line`).

The moments are the exact consistent load for both mass-matrix options: for a uniform
field they equal the lumped ½·l0 weights, so the Froude–Krylov balance above holds
either way.  Channels without these element data (built by hand) fall back on the
linear interpolation of their nodal kinematics with the model's mass pattern.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np
import scipy.sparse as sp

from stochcable.errors import InputError
from stochcable import validation as v
from stochcable.sea.kinematics import G_STANDARD, _depth, _nodal_kinematics, _wavenumber
from stochcable.scene.model import Environment, Line, Scene

__all__ = [
    "Channel",
    "ElementKinematics",
    "element_wave_kinematics",
    "element_moments",
    "element_mean_square",
    "wave_loads",
    "line_channels",
    "element_frames",
    "inertia_matrix",
    "drag_matrix",
    "channel_loads",
    "prescribed_motion",
    "embed",
    "current_at_elements",
    "current_at_nodes",
]

_DOF_AXIS = {"surge": 0, "sway": 1, "heave": 2}
_CONSISTENT = np.array([[1.0 / 3.0, 1.0 / 6.0], [1.0 / 6.0, 1.0 / 3.0]])
_LUMPED = np.array([[0.5, 0.0], [0.0, 0.5]])


class _LazyNodal:
    """A :class:`Channel` field (``velocity``/``acceleration``) that, when left None
    while the channel has a ``nodal`` callable, is computed from it on first access
    (both fields at once) and kept: the sea's nodal kinematics only drive the
    attachments' drag and inertia, which most lines do not have (0.35 ms of the
    chain).  A dataclass descriptor field: the default is None and ``__init__`` stores
    the value through :meth:`__set__`."""

    def __set_name__(self, owner: type, name: str) -> None:
        self._key = "_" + name

    def __get__(self, obj: Any, objtype: Any = None) -> Any:
        if obj is None:
            return None  # the dataclass default
        d = obj.__dict__
        val = d.get(self._key)
        if val is None and d.get("nodal") is not None:
            if d.get("_velocity") is None and d.get("_acceleration") is None:
                vel, acc = d["nodal"]()
                d["_velocity"], d["_acceleration"] = vel, acc
            val = d.get(self._key)
        return val

    def __set__(self, obj: Any, value: Any) -> None:
        obj.__dict__[self._key] = value


@dataclass(frozen=True, eq=False)
class Channel:
    """One independent input of a line's linear system, per unit input.

    Attributes
    ----------
    name : str
        ``"sea"`` or ``"end_a.surge"`` … ``"end_b.heave"``.
    kind : {"sea", "end_motion", "none"}
        The sea (waves and RAO end motions), one end-motion spectrum DOF, or a
        placeholder with a zero spectrum (a line without excitation).
    omega : ndarray, shape (n_omega,)
        Frequencies the arrays below are sampled at. [rad/s]
    spectrum : ndarray, shape (n_omega,)
        One-sided input spectrum S_i(ω). [m²·s/rad]
    density : callable
        ω -> S_i(ω) (for time-series synthesis on another grid). [m²·s/rad]
    velocity : ndarray or None, complex, shape (n_omega, n_nodes, 3)
        Fluid velocity at the nodes per unit input (None: no fluid motion). [(m/s)/m]
    acceleration : ndarray or None, complex, shape (n_omega, n_nodes, 3)
        Fluid acceleration at the nodes per unit input. [(m/s²)/m]
    motion_a, motion_b : ndarray or None, complex, shape (n_omega, 3)
        Prescribed displacement (x, y, z) of end_a / end_b per unit input. [m/m]
    element_velocity : ndarray or None, complex, shape (n_omega, n_el, 2, 3)
        Consistent moments ∫₀¹ N_a v dξ, ∫₀¹ N_b v dξ of the fluid velocity along each
        element (:func:`element_wave_kinematics`); the acceleration moments are iω
        times these (linear kinematics).  None: interpolate the nodal values. [(m/s)/m]
    element_velocity_square : ndarray or None, real, shape (n_omega, n_el, 3, 3)
        Element mean ∫₀¹ Re(v vᴴ) dξ of the fluid velocity. [(m/s)²/m²]
    element_end_square : ndarray or None, real, shape (n_omega, n_el, 2)
        |v|² at the ends of each element's wet part
        (:attr:`ElementKinematics.end_square`). [(m/s)²/m²]
    nodal : callable or None
        ``nodal() -> (velocity, acceleration)``: computes the nodal kinematics on first
        access of ``velocity`` or ``acceleration`` when both were left None (the sea
        channel of :func:`line_channels`); None: the fields are as given.
    """

    name: str
    kind: Literal["sea", "end_motion", "none"]
    omega: np.ndarray
    spectrum: np.ndarray
    density: Callable[[np.ndarray], np.ndarray]
    velocity: np.ndarray | None = _LazyNodal()  # type: ignore[assignment]
    acceleration: np.ndarray | None = _LazyNodal()  # type: ignore[assignment]
    motion_a: np.ndarray | None = None
    motion_b: np.ndarray | None = None
    element_velocity: np.ndarray | None = None
    element_velocity_square: np.ndarray | None = None
    element_end_square: np.ndarray | None = None
    nodal: Callable[[], tuple[np.ndarray, np.ndarray]] | None = field(
        default=None, repr=False)


def _spectrum_callable(spec: Any, g: float) -> Callable[[np.ndarray], np.ndarray]:
    def density(w: np.ndarray) -> np.ndarray:
        w = np.asarray(w, dtype=float)
        out = np.zeros_like(w)
        pos = w > 0
        out[pos] = spec.spectral_density(w[pos], g)
        return out

    return density


def line_channels(
    scene: Scene, line: Line, positions: np.ndarray, omega: np.ndarray
) -> tuple[Channel, ...]:
    """Input channels of one line sampled on ``omega``.

    Parameters
    ----------
    scene : Scene
        The scene (environment, sea).
    line : Line
        The line (its end motions).
    positions : ndarray, shape (n_nodes, 3)
        Static node positions, where the wave kinematics are evaluated. [m]
    omega : ndarray, shape (n_omega,)
        Frequencies, > 0. [rad/s]

    Returns
    -------
    tuple of Channel
        ``"sea"`` first (if the scene has a sea), then one channel per end-motion
        spectrum DOF in the order end_a, end_b × surge, sway, heave.

    Raises
    ------
    InputError
        If an end motion is an RAO table but the scene has no sea.

    Notes
    -----
    Kinematics: seed 001 eqs. 5.2.8–5.2.11 (:func:`stochcable.sea.kinematics.wave_kinematics`)
    at the nodes, and integrated exactly along the straight elements between them
    (:func:`element_wave_kinematics`).  Nodes resting on a penalty seabed slightly below
    z = −depth are moved onto it.
    """
    env = scene.environment
    w = np.asarray(omega, dtype=float)
    channels: list[Channel] = []
    raos = {}
    for end in ("end_a", "end_b"):
        m = getattr(line, end).motion
        if m is not None and m.rao is not None:
            if scene.sea is None:
                raise InputError(
                    f"lines[{line.name}].{end}.motion.rao", "RAO table", "-",
                    "an RAO is relative to the sea: the scene needs a 'sea' (or give the "
                    "end motion as spectra per DOF)",
                )
            raos[end] = np.ascontiguousarray(m.rao.transfer(w).T)  # (n_omega, 3)
    if scene.sea is not None:
        density = _spectrum_callable(scene.sea.spectrum, env.g)
        # nodes resting on a penalty seabed sit slightly below z = -depth: evaluate
        # the kinematics on the seabed there
        pts = np.array(positions, dtype=float)
        pts[:, 2] = np.maximum(pts[:, 2], -env.depth)
        el = element_wave_kinematics(w, pts, scene.sea.heading_rad, env.depth, env.g)
        channels.append(Channel(
            name="sea", kind="sea", omega=w, spectrum=density(w), density=density,
            motion_a=raos.get("end_a"), motion_b=raos.get("end_b"),
            element_velocity=el.velocity, element_velocity_square=el.velocity_square,
            element_end_square=el.end_square, nodal=_sea_nodal(el, env.g),
        ))
    for end in ("end_a", "end_b"):
        m = getattr(line, end).motion
        if m is None or m.rao is not None:
            continue
        for dof, axis in _DOF_AXIS.items():
            spec = getattr(m, dof)
            if spec is None:
                continue
            density = _spectrum_callable(spec, env.g)
            unit = np.zeros((w.size, 3), dtype=complex)
            unit[:, axis] = 1.0
            channels.append(Channel(
                name=f"{end}.{dof}", kind="end_motion", omega=w, spectrum=density(w),
                density=density,
                motion_a=unit if end == "end_a" else None,
                motion_b=unit if end == "end_b" else None,
            ))
    return tuple(channels)


def _sea_nodal(el: "ElementKinematics", g: float
               ) -> Callable[[], tuple[np.ndarray, np.ndarray]]:
    """The sea channel's nodal velocity and acceleration (n_omega, n_nodes, 3), on
    demand: :func:`stochcable.sea.kinematics.wave_kinematics` from the validated
    frequencies, points and wavenumbers of the element kinematics (no second
    validation, wavenumber solve or pressure)."""
    def nodal() -> tuple[np.ndarray, np.ndarray]:
        _, _, _, vel, acc = _nodal_kinematics(el.omega, el.wavenumber, el.positions,
                                              el.heading, el.depth, g)
        return (np.ascontiguousarray(np.transpose(vel, (2, 0, 1))),
                np.ascontiguousarray(np.transpose(acc, (2, 0, 1))))

    return nodal


# ------------------------------------------------- wave kinematics along the elements

# |x| below which φ1 and ψ are summed as series (full relative precision; above it the
# closed forms lose at most ~1e-16·(1 + |e^x|)/|x| absolutely, harmless as |e^x| <= 1).
_SERIES_RADIUS = 0.5
# 15 terms: the remainder x^15/16! < 2e-18 for |x| < 0.5.
_SERIES_TERMS = 15
_PHI1_COEF = np.array([1.0 / math.factorial(n + 1) for n in range(_SERIES_TERMS)])
_PSI_COEF = np.array([1.0 / (math.factorial(n) * (n + 2)) for n in range(_SERIES_TERMS)])


def _series(x: np.ndarray, coef: np.ndarray) -> np.ndarray:
    out = np.full(x.shape, coef[-1], dtype=x.dtype)
    for c in coef[-2::-1]:
        out *= x
        out += c
    return out


def _phi1_psi(x: np.ndarray, want_psi: bool = True) -> tuple[np.ndarray, np.ndarray | None]:
    """φ1(x) = ∫₀¹ e^{xu} du = (e^x − 1)/x and ψ(x) = ∫₀¹ u e^{xu} du
    = ((x − 1)e^x + 1)/x², elementwise for Re x <= 0 (real or complex).

    Series (Horner, ``_SERIES_TERMS`` terms) for |x| < ``_SERIES_RADIUS``, where the
    closed forms cancel; closed forms (with expm1) elsewhere."""
    small = np.abs(x) < _SERIES_RADIUS
    # closed forms everywhere (no gather/scatter of the large part), then the series
    # over the small entries (where the closed forms cancel, 0/0 at x = 0)
    with np.errstate(divide="ignore", invalid="ignore"):
        if np.iscomplexobj(x):
            # e^x − 1 where the closed forms are kept (|x| >= 0.5, Re x <= 0: |e^x − 1|
            # >= 0.49, so the subtraction costs at most ~3 ulp); numpy's complex expm1
            # is 2.4x slower than its exp (0.27 ms per call on the chain)
            em1 = np.exp(x)
            em1 -= 1.0
        else:
            em1 = np.expm1(x)
        phi = em1 / x
        psi = None
        if want_psi:
            psi = em1 * (x - 1.0)
            psi += x
            psi /= x * x                                   # ((x − 1)e^x + 1)/x²
    if small.any():
        xs = x[small]
        phi[small] = _series(xs, _PHI1_COEF)
        if want_psi:
            psi[small] = _series(xs, _PSI_COEF)
    return phi, psi


def _moment_argument(alpha: np.ndarray, p: np.ndarray, q: np.ndarray) -> np.ndarray:
    """The argument x of φ1 and ψ in :func:`_exp_moments` (Re x <= 0)."""
    s = np.where(alpha.real >= 0.0, -1.0, 1.0)
    if np.all(p == 0.0) and np.all(q == 1.0):
        return s * alpha
    return s * alpha * (q - p)


def _exp_moments(e0: np.ndarray, alpha: np.ndarray, p: np.ndarray, q: np.ndarray,
                 phi_psi: tuple[np.ndarray, np.ndarray] | None = None
                 ) -> tuple[np.ndarray, np.ndarray]:
    """∫_p^q (1 − ξ) e^{e0 + αξ} dξ and ∫_p^q ξ e^{e0 + αξ} dξ, elementwise.

    The exponential is factored at the endpoint c where Re(e0 + αξ) is largest (q when
    Re α >= 0, else p), so with t = |ξ − c|, x = −α(q − p) or α(q − p) (Re x <= 0):
    ∫_p^q e^{…} = e^{e0 + αc} L φ1(x) and ∫_p^q ξ e^{…} = e^{e0 + αc}(c L φ1(x) ± L² ψ(x)),
    L = q − p — never an overflow, whatever α·L (the integrand's largest value
    e^{Re(e0 + αc)} is <= 1 for wave kinematics).  L = 0 gives zeros.  ``phi_psi``:
    (φ1(x), ψ(x)) when the caller has them (x of :func:`_moment_argument`)."""
    length = q - p
    grow = alpha.real >= 0.0
    s = np.where(grow, -1.0, 1.0)
    if np.all(p == 0.0) and np.all(q == 1.0):
        # every element wet over its whole length (L = 1, c = 0 or 1): the general
        # expressions below with the factors 1 and 0 dropped — the same numbers
        # (x·1 and 0 + x are exact), a third fewer complex passes
        f1, f2 = _phi1_psi(s * alpha) if phi_psi is None else phi_psi
        ref = np.exp(np.where(grow, e0 + alpha, e0))
        d12 = f1 - f2
        return ref * np.where(grow, f2, d12), ref * np.where(grow, d12, f2)
    c = np.where(grow, q, p)
    f1, f2 = _phi1_psi(s * alpha * length) if phi_psi is None else phi_psi
    ref = np.exp(e0 + alpha * c)
    t1 = length * f1
    t2 = s * (length * length) * f2
    return ref * ((1.0 - c) * t1 - t2), ref * (c * t1 + t2)


def _exp_integral(e0: np.ndarray, alpha: np.ndarray, p: np.ndarray, q: np.ndarray,
                  phi: np.ndarray | None = None) -> np.ndarray:
    """∫_p^q e^{e0 + αξ} dξ for real e0, α (as :func:`_exp_moments`, factored at the
    larger endpoint).  ``phi``: φ1 of the argument −|α|(q − p) when the caller has it
    (the same for α and −α)."""
    length = q - p
    grow = alpha >= 0.0
    c = np.where(grow, q, p)
    if phi is None:
        phi, _ = _phi1_psi(np.where(grow, -alpha, alpha) * length, want_psi=False)
    return np.exp(e0 + alpha * c) * length * phi


@dataclass(frozen=True, eq=False)
class ElementKinematics:
    """Linear wave kinematics integrated along straight elements, per unit amplitude.

    Attributes
    ----------
    omega : ndarray, shape (n_omega,)
        [rad/s]
    wavenumber : ndarray, shape (n_omega,)
        [rad/m]
    positions : ndarray, shape (n_nodes, 3)
        Node positions; element j joins nodes j and j + 1. [m]
    heading : float
        [rad]
    depth : float
        [m]
    wet_fraction : ndarray, shape (n_el,)
        Fraction of each element below z = 0 (only that part is loaded). [-]
    velocity : ndarray, complex, shape (n_omega, n_el, 2, 3)
        ∫₀¹ N_a v dξ and ∫₀¹ N_b v dξ (N_a = 1 − ξ, N_b = ξ, ξ = s/l), v = 0 above
        z = 0. [(m/s)/m]
    velocity_square : ndarray, real, shape (n_omega, n_el, 3, 3)
        ∫₀¹ Re(v vᴴ) dξ, the element mean of the velocity's second moment. [(m/s)²/m²]
    end_square : ndarray, real, shape (n_omega, n_el, 2)
        |v|² at the two ends of each element's wet part (the lower-ξ end first; the
        waterline point for an element crossing it; 0 for a dry element). [(m/s)²/m²]
    """

    omega: np.ndarray
    wavenumber: np.ndarray
    positions: np.ndarray
    heading: float
    depth: float
    wet_fraction: np.ndarray
    velocity: np.ndarray
    velocity_square: np.ndarray
    end_square: np.ndarray

    @property
    def acceleration(self) -> np.ndarray:
        """∫ N_i a dξ = iω ∫ N_i v dξ, shape (n_omega, n_el, 2, 3). [(m/s²)/m]"""
        return self.velocity * (1j * self.omega)[:, None, None, None]


def element_wave_kinematics(
    omega: Any,
    positions: Any,
    heading: float = 0.0,
    depth: float = np.inf,
    g: float = G_STANDARD,
) -> ElementKinematics:
    """Linear wave kinematics integrated exactly along the straight elements of a line.

    Parameters
    ----------
    omega : array_like
        Angular frequencies, >= 0, 1-D. [rad/s]
    positions : array_like
        Node positions (x, y, z), shape (n_nodes, 3), n_nodes >= 2; element j joins
        nodes j and j + 1; z >= −depth. [m]
    heading : float, default 0.0
        Wave heading β from +x toward +y. [rad]
    depth : float, default inf
        Water depth h. [m]
    g : float, default 9.80665
        Acceleration of gravity. [m/s²]

    Returns
    -------
    ElementKinematics
        Consistent moments and element mean square of the fluid velocity.

    Raises
    ------
    InputError
        Invalid frequencies, positions (shape, below the seabed), heading, depth or g.

    Notes
    -----
    Kinematics of seed 001 eqs. 5.2.8–5.2.11 in the DESIGN.md convention
    (:func:`stochcable.sea.kinematics.wave_kinematics`): with χ = x cos β + y sin β,
    E₁ = k z − i k χ, E₂ = −k(z + 2h) − i k χ and D = 1 − e^{−2kh},

        u_h = ω (e^{E₁} + e^{E₂})/D (along β),   u_z = iω (e^{E₁} − e^{E₂})/D,

    (deep water: D = 1 and no E₂ term).  Along the element r(ξ) = r_a + ξ(r_b − r_a)
    each E is linear in ξ, so the moments ∫ N_i e^{E(ξ)} dξ over the wet part
    ξ ∈ [p, q] (z(ξ) <= 0; the element is split at the waterline) are closed forms
    (:func:`_exp_moments`, series near α·L = 0, no overflow for large |α|·L).  The
    mean square uses |u_h|² = ω² (e^{2E₁ᵣ} + 2e^{−2kh} + e^{2E₂ᵣ})/D² and
    |u_z|² = ω² (e^{2E₁ᵣ} − 2e^{−2kh} + e^{2E₂ᵣ})/D² (E_ᵣ the real parts; the phases of
    the two terms coincide): its absolute error is ~1e-16 of the largest |v|² on the
    element (the vertical part in very shallow water, kh < 1e-4, carries a relative
    error ~1e-16/(kh)²).  At ω = 0 the finite-depth horizontal velocity takes its limit
    √(g/h), as in :func:`~stochcable.sea.kinematics.wave_kinematics`.
    """
    w = v.float_array("omega", omega, "rad/s", nonnegative=True)
    pts = np.asarray(positions, dtype=float)
    if pts.ndim != 2 or pts.shape[1] != 3 or pts.shape[0] < 2:
        raise InputError("positions", positions, "m", "must have shape (n_nodes >= 2, 3)")
    pts = v.float_array("positions", pts, "m", ndim=2)
    beta = v.finite_scalar("heading", heading, "rad")
    h = _depth(depth)
    g = v.positive("g", g, "m/s²")
    z = pts[:, 2]
    if not math.isinf(h) and (z < -h).any():
        i = int(np.flatnonzero(z < -h)[0])
        raise InputError("positions", positions, "m",
                         f"z must be >= -depth = {-h:g} (node {i} has z = {z[i]:g})")
    k = _wavenumber(w, h, g)
    return _element_kinematics(w, k, pts, beta, h, g)


def _complex(re: np.ndarray, im: np.ndarray) -> np.ndarray:
    """re + i·im in one pass (no complex temporaries)."""
    out = np.empty(re.shape, dtype=complex)
    out.real = re
    out.imag = im
    return out


def _element_kinematics(w: np.ndarray, k: np.ndarray, pts: np.ndarray, beta: float,
                        h: float, g: float) -> ElementKinematics:
    """:func:`element_wave_kinematics` without validation."""
    cb, sb = math.cos(beta), math.sin(beta)
    za, zb = pts[:-1, 2], pts[1:, 2]
    chi = pts[:, 0] * cb + pts[:, 1] * sb
    # wet part ξ ∈ [p, q] of each element (z <= 0 wet, as the nodal kinematics)
    with np.errstate(divide="ignore", invalid="ignore"):
        cross = np.where(za != zb, za / (za - zb), 0.0)
    wet_a, wet_b = za <= 0.0, zb <= 0.0
    p = np.where(wet_a, 0.0, np.where(wet_b, cross, 0.0))
    q = np.where(wet_b, 1.0, np.where(wet_a, cross, 0.0))
    # frequency-major (n_w, n_el) arrays throughout: the outputs' layout, so they are
    # written without transposes (the same products, operands swapped)
    p, q = np.clip(p, 0.0, 1.0)[None, :], np.clip(q, 0.0, 1.0)[None, :]
    length = q - p
    dz = np.multiply.outer(k, zb - za)
    phase0 = -np.multiply.outer(k, chi[:-1])   # imaginary parts of the exponents
    dphase = -np.multiply.outer(k, chi[1:] - chi[:-1])
    kza = np.multiply.outer(k, za)
    alpha1 = _complex(dz, dphase)
    f12 = _phi1_psi(_moment_argument(alpha1, p, q))
    ma1, mb1 = _exp_moments(_complex(kza, phase0), alpha1, p, q, f12)
    two_dz = 2.0 * dz
    phi_k, _ = _phi1_psi(np.where(two_dz >= 0.0, -two_dz, two_dz) * length, want_psi=False)
    k1 = _exp_integral(2.0 * kza, two_dz, p, q, phi_k)      # ∫ e^{2kz} dξ
    zero_w = w == 0.0
    z_ends = (za[:, None] + (zb - za)[:, None] * np.hstack([p.T, q.T]))   # (n_el, 2)
    z_ends = np.minimum(z_ends, 0.0)
    e1_ends = np.exp(2.0 * np.multiply.outer(k, z_ends))             # (n_w, n_el, 2)
    if math.isinf(h):
        coef = w.astype(complex)[:, None]
        mh = (ma1 * coef, mb1 * coef)
        mz = (ma1 * (1j * w)[:, None], mb1 * (1j * w)[:, None])
        ch2 = sh2 = k1 * (w * w)[:, None]
        ends = 2.0 * e1_ends * (w * w)[:, None, None]
    else:
        e2a = -np.multiply.outer(k, za + 2.0 * h)
        # the second exponent's slope −dz + i·dphase: where dz ≠ 0 the sign s of
        # _exp_moments flips with Re α, so its argument is the conjugate of the first
        # one's and so are φ1 and ψ (exp, products, quotients and the series commute
        # with conjugation in IEEE arithmetic); where dz = 0 it is the same argument
        # (up to the sign of a zero real part).  Tested equal to the direct evaluation.
        flip = dz != 0.0
        f12_2 = tuple(np.where(flip, f.conj(), f) for f in f12)
        ma2, mb2 = _exp_moments(_complex(e2a, phase0), _complex(-dz, dphase), p, q, f12_2)
        # ∫ e^{−2k(z+2h)} dξ: its φ1 argument −|2dz|·L is the first one's
        k2 = _exp_integral(2.0 * e2a, -two_dz, p, q, phi_k)
        den = -np.expm1(-2.0 * k * h)
        with np.errstate(divide="ignore", invalid="ignore"):
            c = np.where(zero_w, 0.0, w / np.where(zero_w, 1.0, den))
            cross2 = (2.0 * np.exp(-2.0 * k * h))[:, None] * length
            c2 = (c * c)[:, None]
            ch2 = (k1 + k2 + cross2) * c2
            sh2 = np.clip(k1 + k2 - cross2, 0.0, None) * c2
        e2_ends = np.exp(-2.0 * np.multiply.outer(k, z_ends + 2.0 * h))
        ends = 2.0 * (e1_ends + e2_ends) * c2[:, :, None]        # ω²(ch² + sh²)
        mh = ((ma1 + ma2) * c[:, None], (mb1 + mb2) * c[:, None])
        ic = (1j * c)[:, None]
        mz = ((ma1 - ma2) * ic, (mb1 - mb2) * ic)
        if zero_w.any():  # long-wave limit: u_h = √(g/h) uniform, u_z = 0
            u0 = math.sqrt(g / h)
            side_b = 0.5 * (q * q - p * p)
            mh[0][zero_w, :] = u0 * (length - side_b)
            mh[1][zero_w, :] = u0 * side_b
            ch2[zero_w, :] = u0 * u0 * length
            ends[zero_w] = u0 * u0
    n_w, n_el = ma1.shape
    vel = np.empty((n_w, n_el, 2, 3), dtype=complex)
    for side in range(2):
        vel[:, :, side, 0] = mh[side] * cb
        vel[:, :, side, 1] = mh[side] * sb
        vel[:, :, side, 2] = mz[side]
    sq = np.zeros((n_w, n_el, 3, 3))
    sq[:, :, 0, 0] = ch2 * (cb * cb)
    sq[:, :, 1, 1] = ch2 * (sb * sb)
    sq[:, :, 0, 1] = sq[:, :, 1, 0] = ch2 * (cb * sb)
    sq[:, :, 2, 2] = sh2
    wet = length[0]
    ends = np.where((length > 0.0)[:, :, None], ends, 0.0)
    for a in (w, k, pts, wet, vel, sq, ends):
        a.setflags(write=False)
    return ElementKinematics(omega=w, wavenumber=k, positions=pts, heading=beta, depth=h,
                             wet_fraction=wet, velocity=vel, velocity_square=sq,
                             end_square=ends)


def element_moments(model: Any, channel: Channel) -> np.ndarray | None:
    """Consistent moments of a channel's fluid velocity along the model's elements.

    Parameters
    ----------
    model : FEModel
        The line model (its mass pattern for the fallback).
    channel : Channel

    Returns
    -------
    ndarray or None, complex, shape (n_omega, n_el, 2, 3)
        ``channel.element_velocity`` when present, else the model's mass pattern
        applied to the nodal velocities (P = [[1/3, 1/6], [1/6, 1/3]] consistent,
        [[1/2, 0], [0, 1/2]] lumped: the linear interpolation); None without fluid
        velocity. [(m/s)/m]
    """
    if channel.element_velocity is not None:
        return channel.element_velocity
    if channel.velocity is None:
        return None
    pat = _LUMPED if getattr(model, "mass_matrix", "consistent") == "lumped" else _CONSISTENT
    va, vb = channel.velocity[:, :-1], channel.velocity[:, 1:]
    return np.stack([pat[0, 0] * va + pat[0, 1] * vb, pat[1, 0] * va + pat[1, 1] * vb],
                    axis=2)


def element_mean_square(channel: Channel) -> np.ndarray | None:
    """Element mean ∫₀¹ Re(v vᴴ) dξ of a channel's fluid velocity.

    Parameters
    ----------
    channel : Channel

    Returns
    -------
    ndarray or None, real, shape (n_omega, n_el, 3, 3)
        ``channel.element_velocity_square`` when present, else that of the linear
        interpolation of the nodal velocities,
        Re[(v_a v_aᴴ + v_b v_bᴴ)/3 + (v_a v_bᴴ + v_b v_aᴴ)/6]; None without fluid
        velocity. [(m/s)²/m²]
    """
    if channel.element_velocity_square is not None:
        return channel.element_velocity_square
    if channel.velocity is None:
        return None
    va, vb = channel.velocity[:, :-1], channel.velocity[:, 1:]
    aa = np.einsum("wei,wej->weij", va, va.conj()).real
    bb = np.einsum("wei,wej->weij", vb, vb.conj()).real
    ab = np.einsum("wei,wej->weij", va, vb.conj()).real
    return (aa + bb) / 3.0 + (ab + np.swapaxes(ab, 2, 3)) / 6.0


# ------------------------------------------------------------------ element geometry


def element_frames(positions: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Unit tangent and two unit normals of every element, global frame.

    Parameters
    ----------
    positions : ndarray, shape (n_nodes, 3)
        Static node positions. [m]

    Returns
    -------
    e, n1, n2 : ndarray, shape (n_el, 3)
        Tangent (node j to j+1); n2 the horizontal normal e × ẑ normalized (ŷ for a
        vertical element), out of the plane for a line in a vertical plane; n1 = n2 × e,
        the normal in the element's vertical plane. [-]
    """
    d = np.diff(positions, axis=0)
    e = d / np.linalg.norm(d, axis=1)[:, None]
    n2 = _cross(e, np.array([0.0, 0.0, 1.0]))
    nn = np.linalg.norm(n2, axis=1)
    vertical = nn < 1e-12
    n2 = np.where(vertical[:, None], np.array([0.0, 1.0, 0.0]), n2 / np.where(vertical, 1.0, nn)[:, None])
    n1 = _cross(n2, e)
    return e, n1, n2


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Row-wise a × b of 3-vectors: np.cross's products and differences in its order
    (the same numbers), without its generic axis handling (≈ 20 µs a call)."""
    a0, a1, a2 = a[..., 0], a[..., 1], a[..., 2]
    b0, b1, b2 = b[..., 0], b[..., 1], b[..., 2]
    out = np.empty(np.broadcast_shapes(a.shape, b.shape))
    out[..., 0] = a1 * b2 - a2 * b1
    out[..., 1] = a2 * b0 - a0 * b2
    out[..., 2] = a0 * b1 - a1 * b0
    return out


def embed(model: Any, values: np.ndarray) -> np.ndarray:
    """Model-DOF vectors (..., n_dof) -> node vectors (..., n_nodes, 3), zeros off-model."""
    lead = values.shape[:-1]
    out = np.zeros(lead + (model.n_nodes, 3), dtype=values.dtype)
    out[..., list(model.components)] = values.reshape(lead + (model.n_nodes, model.dim))
    return out


def _to_dofs(model: Any, node_vectors: np.ndarray) -> np.ndarray:
    """Node vectors (..., n_nodes, 3) -> model-DOF vectors (..., n_dof)."""
    sub = node_vectors[..., list(model.components)]
    return sub.reshape(sub.shape[:-2] + (model.n_dof,))


def _assemble(model: Any, blocks3: np.ndarray, node_diag: np.ndarray | None) -> sp.csr_array:
    """Assemble per-unit-length 3×3 element matrices (n_el, 3, 3) times the mass
    distribution pattern·l0, plus an isotropic per-node diagonal, on the model DOFs."""
    comps = list(model.components)
    d = model.dim
    b = blocks3[:, comps][:, :, comps] * model.l0[:, None, None]
    pattern = _LUMPED if getattr(model, "mass_matrix", "consistent") == "lumped" else _CONSISTENT
    n_el = b.shape[0]
    el = np.empty((n_el, 2 * d, 2 * d))
    for a in range(2):
        for c in range(2):
            el[:, a * d:(a + 1) * d, c * d:(c + 1) * d] = pattern[a, c] * b
    from stochcable.line.fem import _chain_csr  # the node blocks straight into CSR (no COO sort)

    diag = np.repeat(node_diag, d) if node_diag is not None and np.any(node_diag) else None
    return _chain_csr(el, model.n_nodes, d, diag)


def inertia_matrix(model: Any, g: float) -> sp.csr_array:
    """Morison inertia matrix B_I: load = B_I·A for nodal fluid accelerations A.

    Parameters
    ----------
    model : FEModel
        The line model (positions, mesh, rho, mass distribution).
    g : float
        Gravity, to turn attachment buoyancy into displaced mass. [m/s²]

    Returns
    -------
    scipy.sparse.csr_array, shape (n_dof, n_dof)
        [kg]

    Notes
    -----
    Per unit length ρ(πD²/4)(1 + Can)(I − eeᵀ) (seed 001 eq. 5.2.1, the B_I C_M term,
    C_M = 1 + Can); per attachment (buoyancy/g + added mass)·I.
    """
    blocks, node = inertia_blocks(model, g)
    return _assemble(model, blocks, node)


def drag_matrix(
    model: Any,
    b_normal: np.ndarray,
    b_axial: np.ndarray,
    b_node: np.ndarray | None = None,
) -> sp.csr_array:
    """Linearized drag damping matrix C_d of a line.

    Parameters
    ----------
    model : FEModel
        The line model.
    b_normal : ndarray, shape (n_el,) or (n_el, 2, 2)
        Normal linear drag per unit length: a scalar per element (isotropic in the
        normal plane) or a 2×2 matrix in the element's (n1, n2) normal basis
        (:func:`element_frames`). [N·s/m²]
    b_axial : ndarray, shape (n_el,)
        Axial linear drag per unit length. [N·s/m²]
    b_node : ndarray, shape (n_nodes,), optional
        Isotropic linear drag of the attachments. [N·s/m]

    Returns
    -------
    scipy.sparse.csr_array, shape (n_dof, n_dof)
        [N·s/m]

    Notes
    -----
    Per unit length B_n(I − eeᵀ) + B_t eeᵀ (seed 001 eq. 5.2.1 with B_DL, B_DT of
    eq. 5.2.2), or N B Nᵀ + B_t eeᵀ with N = [n1 n2] for the vector form.
    """
    return _assemble(model, _drag_blocks3(model, b_normal, b_axial), b_node)


def inertia_blocks(model: Any, g: float, e: np.ndarray | None = None
                    ) -> tuple[np.ndarray, np.ndarray]:
    """Morison inertia per unit length (n_el, 3, 3) and per attachment node (n_nodes,);
    ``e`` the element tangents when already at hand (:func:`element_frames`)."""
    mesh = model.mesh
    if e is None:
        e, _, _ = element_frames(model.positions)
    coef = model.rho * math.pi * mesh.diameter**2 / 4.0 * (1.0 + mesh.ca_normal)
    blocks = coef[:, None, None] * (np.eye(3)[None] - e[:, :, None] * e[:, None, :])
    return blocks, mesh.node_buoyancy / g + mesh.node_added_mass


def _drag_blocks3(model: Any, b_normal: np.ndarray, b_axial: np.ndarray) -> np.ndarray:
    """Linear drag per unit length B_n(I − eeᵀ) + B_t eeᵀ (or N B Nᵀ + B_t eeᵀ), (n_el, 3, 3)."""
    e, n1, n2 = element_frames(model.positions)
    eet = e[:, :, None] * e[:, None, :]
    bn = np.asarray(b_normal, dtype=float)
    if bn.ndim == 1:
        blocks = bn[:, None, None] * (np.eye(3)[None] - eet)
    else:
        nmat = np.stack([n1, n2], axis=2)  # (n_el, 3, 2)
        blocks = nmat @ bn @ np.swapaxes(nmat, 1, 2)
    return blocks + np.asarray(b_axial, dtype=float)[:, None, None] * eet


def wave_loads(
    model: Any,
    channels: tuple[Channel, ...],
    b_normal: np.ndarray,
    b_axial: np.ndarray,
    b_node: np.ndarray | None = None,
    *,
    g: float = G_STANDARD,
) -> np.ndarray:
    """Morison wave loads (inertia and linearized drag) integrated along the elements.

    Parameters
    ----------
    model : FEModel
        The line model.
    channels : tuple of Channel
        Inputs on a common grid.
    b_normal : ndarray, shape (n_el,) or (n_el, 2, 2)
        Normal linear drag per unit length (as :func:`drag_matrix`). [N·s/m²]
    b_axial : ndarray, shape (n_el,)
        Axial linear drag per unit length. [N·s/m²]
    b_node : ndarray, shape (n_nodes,), optional
        Isotropic linear drag of the attachments. [N·s/m]
    g : float, default 9.80665
        Gravity, to turn attachment buoyancy into displaced mass. [m/s²]

    Returns
    -------
    ndarray, complex, shape (n_omega, n_dof, n_ch)
        Load per unit input on all DOFs (the prescribed end motion not included). [N/unit]

    Notes
    -----
    Node i of element j gets l0_j·[iω C_I(I − eeᵀ) + B_j]·∫₀¹ N_i v dξ with
    C_I = ρ(πD²/4)(1 + Can) (seed 001 eq. 5.2.1, the B_I C_M and drag terms; B_j of
    eq. 5.2.2 constant over the element) and the moments of :func:`element_moments`
    (exact for the sea channel, :func:`element_wave_kinematics`); attachments get
    (buoyancy/g + added mass)·A + b_node·V at their node.
    """
    n_omega = channels[0].omega.size if channels else 0
    out = np.zeros((n_omega, model.n_dof, len(channels)), dtype=complex)
    inertia, node_mass = inertia_blocks(model, g)
    drag = _drag_blocks3(model, b_normal, b_axial)
    bnode = np.zeros(model.n_nodes) if b_node is None else np.asarray(b_node, dtype=float)
    l0 = model.l0[:, None, None]
    for i, ch in enumerate(channels):
        mom = element_moments(model, ch)
        if mom is None:
            continue
        w = ch.omega
        blk = (l0 * drag)[None] + (1j * w)[:, None, None, None] * (l0 * inertia)[None]
        el = np.einsum("weij,wesj->wesi", blk, mom)   # (n_w, n_el, 2, 3)
        nodes = np.zeros((w.size, model.n_nodes, 3), dtype=complex)
        nodes[:, :-1] += el[:, :, 0]
        nodes[:, 1:] += el[:, :, 1]
        if ch.velocity is not None:
            nodes += bnode[None, :, None] * ch.velocity
            nodes += node_mass[None, :, None] * ch.velocity * (1j * w)[:, None, None]
        out[:, :, i] = _to_dofs(model, nodes)
    return out


def prescribed_motion(model: Any, channels: tuple[Channel, ...], n_omega: int) -> np.ndarray:
    """Prescribed displacements of the fixed DOFs, shape (n_omega, n_fixed, n_ch). [m/unit]"""
    n_ch = len(channels)
    nodes = np.zeros((n_omega, n_ch, model.n_nodes, 3), dtype=complex)
    for i, ch in enumerate(channels):
        if ch.motion_a is not None:
            nodes[:, i, 0, :] = ch.motion_a
        if ch.motion_b is not None:
            nodes[:, i, -1, :] = ch.motion_b
    u = _to_dofs(model, nodes)  # (n_omega, n_ch, n_dof)
    return np.ascontiguousarray(np.swapaxes(u[:, :, model.fixed], 1, 2))


def channel_loads(
    model: Any,
    channels: tuple[Channel, ...],
    c_drag: sp.csr_array,
    b_inertia: sp.csr_array,
) -> np.ndarray:
    """Fluid loads C_d·V + B_I·A from the NODAL kinematics, shape (n_omega, n_dof, n_ch).
    [N/unit]

    The kinematics are linearly interpolated along each element (the loads are the
    mass-pattern products of the assembled matrices): the analysis uses the exact
    element integrals of :func:`wave_loads` instead, which this equals when the
    kinematics are uniform.  The prescribed end motion is not included (it enters
    through the coupling blocks of the dynamic matrix, see the module docstring).
    """
    n_omega = channels[0].omega.size if channels else 0
    out = np.zeros((n_omega, model.n_dof, len(channels)), dtype=complex)
    for i, ch in enumerate(channels):
        if ch.velocity is not None:
            v = _to_dofs(model, ch.velocity)  # (n_omega, n_dof)
            out[:, :, i] += (c_drag @ v.T).T
        if ch.acceleration is not None:
            a = _to_dofs(model, ch.acceleration)
            out[:, :, i] += (b_inertia @ a.T).T
    return out


def current_at_elements(environment: Environment, positions: np.ndarray) -> np.ndarray:
    """Current velocity at the element midpoints, shape (n_el, 3). [m/s]"""
    mid = 0.5 * (positions[1:] + positions[:-1])
    return environment.current_velocity(mid[:, 2])


def current_at_nodes(environment: Environment, positions: np.ndarray) -> np.ndarray:
    """Current velocity at the nodes, shape (n_nodes, 3). [m/s]"""
    return environment.current_velocity(positions[:, 2])
