"""Excitation of a line: independent input channels and the hydrodynamic matrices.

The linear system of a line about its static shape (Tuah 1982, eqs. 5.1, 5.2.6) is

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
avoids by lumping, Tuah (1982), §3.2.a, comes from nodal direction cosines).  Lengths are
the unstretched lengths l0, as the added mass of :mod:`stochcable.line.fem`, so that a line
moving with a uniform fluid (Ü = A) feels exactly the Froude–Krylov force
ρ(πD²/4)(I − eeᵀ)A.  Attachments (buoys, clumps) get the isotropic inertia load
(buoyancy/g + added mass)·A and an isotropic linear drag B·(V − U̇) on their node.
The sea channel carries the wave velocity's consistent moments ∫ N_i v dξ and element
mean square ∫ Re(v vᴴ) dξ integrated exactly along the elements
(:mod:`stochcable.dynamics.loads.element_kinematics`), read by :func:`element_moments` and
:func:`element_mean_square` (hand-built channels: the nodal kinematics interpolated).

References
----------
Tuah, H. (1982), Cable dynamics in an ocean environment, PhD thesis, Oregon State University.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Literal

import numpy as np
import scipy.sparse as sp

from stochcable.dynamics.loads.element_kinematics import (
    ElementKinematics,
    element_frames,
    element_wave_kinematics,
)
from stochcable.dynamics.loads.element_parts import EndSquare, MomentParts, SquareParts
from stochcable.dynamics.loads.sea_channels import sea_channel_densities, spectrum_callable
from stochcable.errors import InputError
from stochcable.line.fem import FEModel
from stochcable.scene.model import Environment, Line, MotionRao, Scene
from stochcable.sea.kinematics import G_STANDARD, wave_kinematics_unchecked

__all__ = [
    "Channel",
    "channel_loads",
    "current_at_elements",
    "current_at_nodes",
    "drag_matrix",
    "element_frames",
    "element_mean_square",
    "element_moments",
    "embed",
    "inertia_matrix",
    "line_channels",
    "prescribed_motion",
    "wave_loads",
]

_DOF_AXIS = {"surge": 0, "sway": 1, "heave": 2}
_CONSISTENT = np.array([[1.0 / 3.0, 1.0 / 6.0], [1.0 / 6.0, 1.0 / 3.0]])
_LUMPED = np.array([[0.5, 0.0], [0.0, 0.5]])


class _LazyNodal:
    """A :class:`Channel` field (``velocity``/``acceleration``) that, when left None
    while the channel has a ``nodal`` callable, is computed from it on first access
    (both fields at once) and kept: the sea's nodal kinematics only drive the
    attachments' drag and inertia, which most lines do not have (docs/benchmarks/
    dynamics.md).  A dataclass descriptor field: None by default, set by :meth:`__set__`."""

    def __set_name__(self, owner: type, name: str) -> None:
        self._key = "_" + name

    def __get__(self, obj: Channel | None, objtype: type | None = None) -> np.ndarray | None:
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

    def __set__(self, obj: Channel, value: np.ndarray | None) -> None:
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
    element_velocity_parts, element_square : MomentParts, SquareParts or None
        The sea's element moments and mean square in their horizontal and vertical
        parts (:mod:`stochcable.dynamics.loads.element_parts`), what :func:`element_moments`
        and :func:`element_mean_square` form when ``element_velocity`` and
        ``element_velocity_square`` are None.
    element_ends : EndSquare or None
        The sea's |v|² at the element ends, formed on demand
        (:class:`~stochcable.dynamics.loads.element_kinematics.EndSquare`; read where
        ``element_end_square`` is None).
    element_end_square : ndarray or None, real, shape (n_omega, n_el, 2)
        |v|² at the ends of each element's wet part
        (:attr:`ElementKinematics.end_square`). [(m/s)²/m²]
    nodal : callable or None
        ``nodal() -> (velocity, acceleration)``: computes the nodal kinematics on first
        access of ``velocity`` or ``acceleration`` when both were left None (the sea
        channel of :func:`line_channels`); None: the fields are as given.
    heading : float or None
        Wave heading β of a sea channel with element kinematics (the drag residual
        integrates them over parts of elements,
        :mod:`stochcable.dynamics.residuals.drag_segments`); None otherwise. [rad]
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
    element_square: SquareParts | None = None
    element_velocity_parts: MomentParts | None = None
    element_ends: EndSquare | None = None
    nodal: Callable[[], tuple[np.ndarray, np.ndarray]] | None = field(default=None, repr=False)
    heading: float | None = None


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
    Kinematics: Tuah (1982), eqs. 5.2.8–5.2.11 (:func:`stochcable.sea.kinematics.wave_kinematics`)
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
                    f"lines[{line.name}].{end}.motion.rao",
                    "RAO table",
                    "-",
                    "an RAO is relative to the sea: the scene needs a 'sea' (or give the "
                    "end motion as spectra per DOF)",
                )
            raos[end] = m.rao
    if scene.sea is not None:
        # nodes resting on a penalty seabed sit slightly below z = -depth: evaluate
        # the kinematics on the seabed there
        pts = np.array(positions, dtype=float)
        pts[:, 2] = np.maximum(pts[:, 2], -env.depth)
        for name, heading, density in sea_channel_densities(scene.sea, env.g):
            el = element_wave_kinematics(w, pts, heading, env.depth, env.g)
            channels.append(
                Channel(
                    name=name,
                    kind="sea",
                    omega=w,
                    spectrum=density(w),
                    density=density,
                    motion_a=_end_rao(raos.get("end_a"), w, heading),
                    motion_b=_end_rao(raos.get("end_b"), w, heading),
                    element_velocity_parts=el.moments,
                    element_square=el.square,
                    element_ends=el.ends,
                    nodal=_sea_nodal(el, env.g),
                    heading=float(heading),
                )
            )
    for end in ("end_a", "end_b"):
        m = getattr(line, end).motion
        if m is None or m.rao is not None:
            continue
        for dof, axis in _DOF_AXIS.items():
            spec = getattr(m, dof)
            if spec is None:
                continue
            density = spectrum_callable(spec, env.g)
            unit = np.zeros((w.size, 3), dtype=complex)
            unit[:, axis] = 1.0
            channels.append(
                Channel(
                    name=f"{end}.{dof}",
                    kind="end_motion",
                    omega=w,
                    spectrum=density(w),
                    density=density,
                    motion_a=unit if end == "end_a" else None,
                    motion_b=unit if end == "end_b" else None,
                )
            )
    return tuple(channels)


def _end_rao(rao: MotionRao | None, omega: np.ndarray, heading: float) -> np.ndarray | None:
    """An end's motion RAO (n_omega, 3) for waves toward ``heading`` [rad], or None."""
    return None if rao is None else np.ascontiguousarray(rao.transfer(omega, heading).T)


def _sea_nodal(el: ElementKinematics, g: float) -> Callable[[], tuple[np.ndarray, np.ndarray]]:
    """The sea channel's nodal velocity and acceleration (n_omega, n_nodes, 3), on
    demand: :func:`stochcable.sea.kinematics.wave_kinematics_unchecked` of the validated
    frequencies, points and wavenumbers of the element kinematics (no second
    validation, wavenumber solve or pressure)."""

    def nodal() -> tuple[np.ndarray, np.ndarray]:
        _, _, _, vel, acc = wave_kinematics_unchecked(
            el.omega, el.wavenumber, el.positions, el.heading, el.depth, g
        )
        return (
            np.ascontiguousarray(np.transpose(vel, (2, 0, 1))),
            np.ascontiguousarray(np.transpose(acc, (2, 0, 1))),
        )

    return nodal


def element_moments(model: FEModel, channel: Channel) -> np.ndarray | None:
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
    if channel.element_velocity_parts is not None:
        return channel.element_velocity_parts.full()
    if channel.velocity is None:
        return None
    pat = _LUMPED if getattr(model, "mass_matrix", "consistent") == "lumped" else _CONSISTENT
    va, vb = channel.velocity[:, :-1], channel.velocity[:, 1:]
    return np.stack([pat[0, 0] * va + pat[0, 1] * vb, pat[1, 0] * va + pat[1, 1] * vb], axis=2)


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
    if channel.element_square is not None:
        return channel.element_square.full()
    if channel.velocity is None:
        return None
    va, vb = channel.velocity[:, :-1], channel.velocity[:, 1:]
    aa = np.einsum("wei,wej->weij", va, va.conj()).real
    bb = np.einsum("wei,wej->weij", vb, vb.conj()).real
    ab = np.einsum("wei,wej->weij", va, vb.conj()).real
    return (aa + bb) / 3.0 + (ab + np.swapaxes(ab, 2, 3)) / 6.0


# ------------------------------------------------------------------ element geometry


def embed(model: FEModel, values: np.ndarray) -> np.ndarray:
    """Model-DOF vectors (..., n_dof) -> node vectors (..., n_nodes, 3), zeros off-model."""
    lead = values.shape[:-1]
    out = np.zeros(lead + (model.n_nodes, 3), dtype=values.dtype)
    out[..., list(model.components)] = values.reshape(lead + (model.n_nodes, model.dim))
    return out


def _to_dofs(model: FEModel, node_vectors: np.ndarray) -> np.ndarray:
    """Node vectors (..., n_nodes, 3) -> model-DOF vectors (..., n_dof)."""
    sub = node_vectors[..., list(model.components)]
    return sub.reshape(sub.shape[:-2] + (model.n_dof,))


def _assemble(model: FEModel, blocks3: np.ndarray, node_diag: np.ndarray | None) -> sp.csr_array:
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
            el[:, a * d : (a + 1) * d, c * d : (c + 1) * d] = pattern[a, c] * b
    from stochcable.line.fem import chain_csr

    diag = np.repeat(node_diag, d) if node_diag is not None and np.any(node_diag) else None
    return chain_csr(el, model.n_nodes, d, diag)


def inertia_matrix(model: FEModel, g: float) -> sp.csr_array:
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
    Per unit length ρ(πD²/4)(1 + Can)(I − eeᵀ) (Tuah 1982, eq. 5.2.1, the B_I C_M term,
    C_M = 1 + Can); per attachment (buoyancy/g + added mass)·I.
    """
    blocks, node = inertia_blocks(model, g)
    return _assemble(model, blocks, node)


def drag_matrix(
    model: FEModel,
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
    Per unit length B_n(I − eeᵀ) + B_t eeᵀ (Tuah 1982, eq. 5.2.1 with B_DL, B_DT of
    eq. 5.2.2), or N B Nᵀ + B_t eeᵀ with N = [n1 n2] for the vector form.
    """
    return _assemble(model, _drag_blocks3(model, b_normal, b_axial), b_node)


def inertia_blocks(
    model: FEModel, g: float, e: np.ndarray | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """Morison inertia per unit length (n_el, 3, 3) and per attachment node (n_nodes,);
    ``e`` the element tangents when already at hand (:func:`element_frames`)."""
    mesh = model.mesh
    if e is None:
        e, _, _ = element_frames(model.positions)
    coef = model.rho * math.pi * mesh.diameter**2 / 4.0 * (1.0 + mesh.ca_normal)
    blocks = coef[:, None, None] * (np.eye(3)[None] - e[:, :, None] * e[:, None, :])
    return blocks, mesh.node_buoyancy / g + mesh.node_added_mass


def _drag_blocks3(model: FEModel, b_normal: np.ndarray, b_axial: np.ndarray) -> np.ndarray:
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
    model: FEModel,
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
    C_I = ρ(πD²/4)(1 + Can) (Tuah 1982, eq. 5.2.1, the B_I C_M and drag terms; B_j of
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
        el = np.einsum("weij,wesj->wesi", blk, mom)  # (n_w, n_el, 2, 3)
        nodes = np.zeros((w.size, model.n_nodes, 3), dtype=complex)
        nodes[:, :-1] += el[:, :, 0]
        nodes[:, 1:] += el[:, :, 1]
        if ch.velocity is not None:
            nodes += bnode[None, :, None] * ch.velocity
            nodes += node_mass[None, :, None] * ch.velocity * (1j * w)[:, None, None]
        out[:, :, i] = _to_dofs(model, nodes)
    return out


def prescribed_motion(model: FEModel, channels: tuple[Channel, ...], n_omega: int) -> np.ndarray:
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
    model: FEModel,
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
