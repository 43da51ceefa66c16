"""Large rigid bodies coupled to lines (seed 001 §3.2.c and §3.3, Tuah 1982).

A large body (a buoy, a disc, a vessel) has six rigid degrees of freedom (three in a
planar x–z analysis); its equation of motion is seed 001 eq. 3.2.c.20,

    (M_B + A(ω)) ξ̈ + B(ω) ξ̇ + (K_R + K_C) ξ = F_exc(ω) e^{iωt} + F̄,

with the rigid-body mass M_B, the added mass A(ω) and radiation damping B(ω) of
diffraction–radiation theory, the hydrostatic restoring K_R, the stiffness of the
attached cables K_C, and the wave excitation F_exc (per unit wave amplitude).  Lines
attached to the body at a point r (relative to the body reference point) follow it
through the rigid link of seed 001 eqs. 3.3.6–3.3.7, u_end = T(r)·ξ, and their
equations are transformed with Tᵀ (eqs. 3.3.8–3.3.10) and assembled with the body's.

Degrees of freedom and signs
----------------------------
- 6 DOF (3-D): ξ = (surge, sway, heave, roll, pitch, yaw) = (u_x, u_y, u_z, θ_x, θ_y,
  θ_z): translations of the reference point along the global axes [m] and small
  rotations about the global axes through the reference point [rad], right-handed.
  (The seed's own order, surge–heave–sway in a y-up frame, is mapped onto this by its
  eq. 3.3.5; here z is up and no such map is needed.)
- 3 DOF (planar, in the x–z plane): ξ = (surge, heave, pitch) = (u_x, u_z, θ_y), pitch
  positive about +y (right-handed): a point ahead of the reference (+x) moves *down*
  for a positive pitch, a point above it (+z) moves toward +x.
- Generalized forces are (F_x, F_y, F_z, M_x, M_y, M_z) (planar: F_x, F_z, M_y),
  moments about the reference point.  Hydrodynamic matrices are taken about the same
  point (Capytaine's ``rotation_center``, WAMIT's origin of the body axes).

The coupled system
------------------
:func:`couple` assembles lines (:class:`stochcable.line.fem.FEModel`) and bodies into one
linear system over x = [line free DOFs …, body DOFs …].  With L_ℓ the sparse map from
x to all DOFs of line ℓ (identity on its free DOFs, T(r) on a body-attached end,
zero on a still-prescribed end) and P_ℓ the map from the prescribed DOFs p,

    K = Σ L_ℓᵀ K_ℓ L_ℓ + K_body,   K_p = Σ L_ℓᵀ K_ℓ P_ℓ      (seed 001 eq. 3.3.10)

and the same for M and C: the line end DOFs are eliminated in favour of the body DOFs
(K_cc = Tᵀ K_bb T, K_fc = K_fb T).  The frequency response is
Z(ω) x = F with Z(ω) = K − ω²(M + A(ω)) + iω(C + B(ω)) (:func:`solve_coupled_direct`).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np
import scipy.sparse as sp

from stochcable.validation import finite_scalar, float_array, nonnegative
from stochcable.errors import InputError, SolverError
from stochcable.line.fem import FEModel

__all__ = [
    "SPATIAL_DOFS",
    "PLANAR_DOFS",
    "PLANAR_INDEX",
    "FrequencyTable",
    "ExcitationTable",
    "RigidBody",
    "skew",
    "rigid_link_matrix",
    "rigid_body_mass_matrix",
    "attachment_geometric_stiffness",
    "body_excitation",
    "body_drag_damping",
    "LineLink",
    "CoupledSystem",
    "couple",
    "coupled_load",
    "expand_line",
    "constant_matrices",
    "solve_coupled_direct",
]

#: Names of the six rigid-body DOFs, in order (global axes, rotations about them).
SPATIAL_DOFS = ("surge", "sway", "heave", "roll", "pitch", "yaw")
#: Names of the three planar (x–z) DOFs, in order; pitch about +y.
PLANAR_DOFS = ("surge", "heave", "pitch")
#: Positions of the planar DOFs among the six: surge 0, heave 2, pitch 4.
PLANAR_INDEX = (0, 2, 4)

# Relative tolerance for a body-attached end node to lie where the body says.
_SYM_TOL = 1.0e-9
# Dense fallback of the direct solve up to this many coupled DOFs.
_DENSE_MAX = 3000


# ------------------------------------------------------------------ frequency tables


def _interp_weights(table: np.ndarray, x: np.ndarray, name: str, unit: str,
                    extrapolation: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Indices i, i+1 and weight t of the linear interpolation of x in a sorted table."""
    n = table.size
    if n == 1:
        z = np.zeros(x.shape, dtype=int)
        return z, z, np.zeros(x.shape)
    lo, hi = table[0], table[-1]
    slack = 1e-9 * max(abs(lo), abs(hi), 1e-300)
    if extrapolation == "error":
        out = (x < lo - slack) | (x > hi + slack)
        if out.any():
            bad = float(x[np.flatnonzero(out)[0]])
            raise InputError(name, bad, unit,
                             f"is outside the table [{lo:g}, {hi:g}]: extend the table or "
                             "use extrapolation='hold'")
    xc = np.clip(x, lo, hi)
    i = np.clip(np.searchsorted(table, xc, side="right") - 1, 0, n - 2)
    t = (xc - table[i]) / (table[i + 1] - table[i])
    return i, i + 1, t


@dataclass(frozen=True, eq=False)
class FrequencyTable:
    """Real matrices tabulated over angular frequency, linearly interpolated.

    Parameters
    ----------
    omega : array_like, shape (n,)
        Strictly increasing angular frequencies, >= 0. [rad/s]
    values : array_like, shape (n, d, d)
        A matrix per frequency (added mass [kg, kg·m, kg·m²] or radiation damping
        [N·s/m, N·s, N·m·s]).
    extrapolation : {"error", "hold"}
        Outside [omega[0], omega[-1]]: raise InputError, or hold the end values.
        A one-frequency table is constant everywhere.
    """

    omega: np.ndarray
    values: np.ndarray
    extrapolation: Literal["error", "hold"] = "error"

    def __post_init__(self) -> None:
        w = float_array("omega", self.omega, "rad/s", nonnegative=True, increasing=True)
        v = float_array("values", self.values, "-", ndim=3)
        if v.shape[0] != w.size or v.shape[1] != v.shape[2]:
            raise InputError("values", v.shape, "-",
                             f"must have shape ({w.size}, d, d): one square matrix per omega")
        if self.extrapolation not in ("error", "hold"):
            raise InputError("extrapolation", self.extrapolation, "-", "must be 'error' or 'hold'")
        object.__setattr__(self, "omega", w.copy())
        object.__setattr__(self, "values", v.copy())

    @property
    def size(self) -> int:
        """Matrix size d."""
        return int(self.values.shape[1])

    def at(self, omega: Any) -> np.ndarray:
        """Matrices at ``omega`` (n_w,), linear in ω, shape (n_w, d, d)."""
        x = np.atleast_1d(np.asarray(omega, dtype=float))
        i, j, t = _interp_weights(self.omega, x, "omega", "rad/s", self.extrapolation)
        return (1.0 - t)[:, None, None] * self.values[i] + t[:, None, None] * self.values[j]


def _heading_weights(table: np.ndarray, beta: float) -> tuple[int, int, float]:
    """Two table indices and a weight for heading beta [rad] (periodic tables)."""
    n = table.size
    two_pi = 2.0 * math.pi
    b = table[0] + (beta - table[0]) % two_pi
    tol = 1e-9
    if n == 1:
        if min(abs(b - table[0]), two_pi - abs(b - table[0])) <= tol:
            return 0, 0, 0.0
        raise InputError("heading", math.degrees(beta), "deg",
                         f"is not in the excitation table (one heading, "
                         f"{math.degrees(table[0]):g} deg): add headings to the table")
    if b <= table[-1] + tol:
        i = int(np.clip(np.searchsorted(table, b, side="right") - 1, 0, n - 2))
        t = float(np.clip((b - table[i]) / (table[i + 1] - table[i]), 0.0, 1.0))
        return i, i + 1, t
    gap = table[0] + two_pi - table[-1]
    if b >= table[0] + two_pi - tol:
        return 0, 0, 0.0
    if gap <= np.diff(table).max() * (1 + 1e-9):  # a full-circle table: wrap around
        return n - 1, 0, float((b - table[-1]) / gap)
    raise InputError("heading", math.degrees(beta), "deg",
                     f"is outside the excitation table's headings "
                     f"[{math.degrees(table[0]):g}, {math.degrees(table[-1]):g}] deg")


@dataclass(frozen=True, eq=False)
class ExcitationTable:
    """Wave excitation force RAOs over frequency and heading.

    Parameters
    ----------
    omega : array_like, shape (n_w,)
        Strictly increasing angular frequencies. [rad/s]
    heading : array_like, shape (n_h,)
        Strictly increasing wave headings, direction of travel from +x toward +y, in
        [heading[0], heading[0] + 2π). [rad]
    values : array_like, complex, shape (n_h, d, n_w)
        Force and moment per unit wave amplitude, time convention Re{X e^{iωt}}, phase
        relative to the incident wave elevation at the table's phase point (see
        :class:`RigidBody` ``excitation_point``). [N/m, N·m/m]
    extrapolation : {"error", "hold"}
        Outside the frequency range: raise, or hold the end values.

    Notes
    -----
    Linear interpolation of the real and imaginary parts in ω and in heading; headings
    wrap around when the table covers the full circle (its closing gap is no larger
    than its largest step), else a heading outside the table is an InputError.
    """

    omega: np.ndarray
    heading: np.ndarray
    values: np.ndarray
    extrapolation: Literal["error", "hold"] = "error"

    def __post_init__(self) -> None:
        w = float_array("omega", self.omega, "rad/s", nonnegative=True, increasing=True)
        h = float_array("heading", self.heading, "rad", increasing=True)
        if h.size > 1 and h[-1] - h[0] >= 2.0 * math.pi:
            raise InputError("heading", h, "rad", "must span less than 2π")
        v = np.asarray(self.values, dtype=complex)
        if v.ndim != 3 or v.shape[0] != h.size or v.shape[2] != w.size:
            raise InputError("values", v.shape, "-",
                             f"must have shape (n_heading={h.size}, d, n_omega={w.size})")
        if not np.isfinite(v).all():
            raise InputError("values", "non-finite", "N/m", "must be finite")
        if self.extrapolation not in ("error", "hold"):
            raise InputError("extrapolation", self.extrapolation, "-", "must be 'error' or 'hold'")
        object.__setattr__(self, "omega", w.copy())
        object.__setattr__(self, "heading", h.copy())
        object.__setattr__(self, "values", v.copy())

    @property
    def size(self) -> int:
        """Number of DOFs d."""
        return int(self.values.shape[1])

    def at(self, omega: Any, heading: float) -> np.ndarray:
        """Excitation at ``omega`` (n_w,) and one ``heading`` [rad], shape (d, n_w)."""
        x = np.atleast_1d(np.asarray(omega, dtype=float))
        beta = finite_scalar("heading", heading, "rad")
        a, b, s = _heading_weights(self.heading, beta)
        v = (1.0 - s) * self.values[a] + s * self.values[b]  # (d, n_w_table)
        i, j, t = _interp_weights(self.omega, x, "omega", "rad/s", self.extrapolation)
        return (1.0 - t)[None, :] * v[:, i] + t[None, :] * v[:, j]


# --------------------------------------------------------------------- rigid body


def skew(r: Any) -> np.ndarray:
    """Cross-product matrix [r]× with [r]× a = r × a, shape (3, 3)."""
    x, y, z = np.asarray(r, dtype=float)
    return np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])


def rigid_body_mass_matrix(mass: float, inertia: Any, cog: Any = (0.0, 0.0, 0.0),
                           planar: bool = False) -> np.ndarray:
    """Rigid-body mass matrix about the reference point.

    Parameters
    ----------
    mass : float
        Body mass. [kg]
    inertia : array_like, shape (3, 3)
        Inertia tensor about the centre of gravity, global axes. [kg·m²]
    cog : array_like, shape (3,)
        Centre of gravity relative to the reference point. [m]
    planar : bool
        Return the (surge, heave, pitch) 3×3 block.

    Returns
    -------
    ndarray, shape (6, 6) or (3, 3)
        [[m I, −m[c]×], [m[c]×, I_G − m[c]×[c]×]]. [kg, kg·m, kg·m²]

    Notes
    -----
    The kinetic energy ½m|v_G|² + ½ωᵀI_Gω with v_G = T(c)·[v; ω] (the rigid link of
    seed 001 eq. 3.3.7 to the centre of gravity) gives m T(c)ᵀT(c) + diag(0, I_G);
    −[c]×[c]× = |c|²I − c cᵀ is the parallel-axis term.  Seed 001 m_B of eq. 3.2.14.
    """
    c = np.asarray(cog, dtype=float)
    s = skew(c)
    m = float(mass)
    out = np.zeros((6, 6))
    out[:3, :3] = m * np.eye(3)
    out[:3, 3:] = -m * s
    out[3:, :3] = m * s
    out[3:, 3:] = np.asarray(inertia, dtype=float) - m * s @ s
    if planar:
        return out[np.ix_(PLANAR_INDEX, PLANAR_INDEX)]
    return out


def _square(name: str, value: Any, n: int, unit: str) -> np.ndarray:
    """A (n, n) matrix from a (6, 6) (reduced when n = 3) or (n, n) input; None -> 0."""
    if value is None:
        return np.zeros((n, n))
    a = float_array(name, value, unit, ndim=2)
    if a.shape == (6, 6) and n == 3:
        return a[np.ix_(PLANAR_INDEX, PLANAR_INDEX)].copy()
    if a.shape != (n, n):
        raise InputError(name, a.shape, unit, f"must be a ({n}, {n}) or (6, 6) matrix")
    return a.copy()


def _table_or_square(name: str, value: Any, n: int, unit: str) -> np.ndarray | FrequencyTable:
    if isinstance(value, FrequencyTable):
        if value.size == 6 and n == 3:
            return FrequencyTable(value.omega, value.values[:, PLANAR_INDEX][:, :, PLANAR_INDEX],
                                  value.extrapolation)
        if value.size != n:
            raise InputError(name, value.size, unit, f"table must hold ({n}, {n}) or (6, 6) matrices")
        return value
    return _square(name, value, n, unit)


def _vec3(name: str, value: Any, unit: str, default: float = 0.0) -> np.ndarray:
    if value is None:
        return np.full(3, default)
    a = float_array(name, value, unit)
    if a.shape != (3,):
        raise InputError(name, a.shape, unit, "must have 3 components (x, y, z)")
    return a.copy()


@dataclass(frozen=True, eq=False)
class RigidBody:
    """A large rigid body (seed 001 §3.2.c, eq. 3.2.c.20).

    Parameters
    ----------
    name : str
        Unique body name.
    position : array_like, shape (3,)
        Static position of the reference point (x, y, z), global frame, z up. [m]
    mass : float
        Mass. [kg]
    inertia : array_like, shape (3, 3), optional
        Inertia tensor about the centre of gravity, global axes (default zero).
        [kg·m²]
    cog : array_like, shape (3,), optional
        Centre of gravity relative to the reference point (default at it). [m]
    added_mass : array_like (d, d) or FrequencyTable, optional
        Added mass about the reference point, constant or tabulated over ω; d = 6, or
        3 or 6 (reduced to surge, heave, pitch) when planar. [kg, kg·m, kg·m²]
    radiation_damping : array_like (d, d) or FrequencyTable, optional
        Radiation damping, constant or over ω. [N·s/m, N·s, N·m·s]
    hydrostatic_stiffness : array_like (d, d), optional
        Hydrostatic and gravity restoring about the reference point (the weight's
        −m g z_G terms included, as WAMIT and Capytaine give it). [N/m, N, N·m]
    excitation : ExcitationTable, optional
        Wave excitation force per unit amplitude over ω and heading (seed 001 C_l of
        eq. 3.2.c.17).
    excitation_point : array_like, shape (2,), optional
        Horizontal offset (x, y) from the reference point of the point where the
        excitation table's phases are referred to the incident wave elevation
        (default the reference point itself). [m]
    drag_area : array_like, shape (3,), optional
        Quadratic drag Cd·A for relative velocities along x, y and z (a Morison
        element on the body), linearized by :func:`body_drag_damping`. [m²]
    drag_point : array_like, shape (3,), optional
        Point of application of the drag, relative to the reference point. [m]
    extra_stiffness, extra_damping : array_like (d, d), optional
        Additional linear stiffness and damping (e.g. a PTO, viscous roll damping).
    planar : bool
        Three DOFs (surge, heave, pitch) in the x–z plane instead of six.
    fixed_dofs : sequence of str, optional
        Names of DOFs held fixed (among ``dof_names``; default none): a constraint
        ξ_j ≡ 0 in the coupled dynamics (:mod:`stochcable.dynamics.coupled`), as the
        body statics hold them.

    Notes
    -----
    DOF order and signs: module docstring (``SPATIAL_DOFS``, ``PLANAR_DOFS``).  Every
    matrix is about the reference point.  The fields are validated and stored as
    arrays of the body's size (6×6 inputs are reduced when ``planar``).
    """

    name: str
    position: Any
    mass: float
    inertia: Any = None
    cog: Any = None
    added_mass: Any = None
    radiation_damping: Any = None
    hydrostatic_stiffness: Any = None
    excitation: ExcitationTable | None = None
    excitation_point: Any = None
    drag_area: Any = None
    drag_point: Any = None
    extra_stiffness: Any = None
    extra_damping: Any = None
    planar: bool = False
    fixed_dofs: Any = ()

    def __post_init__(self) -> None:
        if not isinstance(self.name, str) or not self.name:
            raise InputError("name", self.name, "-", "must be a non-empty string")
        if not isinstance(self.planar, (bool, np.bool_)):
            raise InputError("planar", self.planar, "-", "must be True or False")
        n = 3 if self.planar else 6
        put = object.__setattr__
        put(self, "planar", bool(self.planar))
        put(self, "position", _vec3("position", self.position, "m"))
        put(self, "mass", nonnegative("mass", self.mass, "kg"))
        inertia = np.zeros((3, 3)) if self.inertia is None else float_array(
            "inertia", self.inertia, "kg·m²", ndim=2)
        if inertia.shape != (3, 3):
            raise InputError("inertia", inertia.shape, "kg·m²", "must be a (3, 3) tensor")
        if not np.allclose(inertia, inertia.T, rtol=1e-9, atol=1e-12 * max(1.0, np.abs(inertia).max())):
            raise InputError("inertia", inertia, "kg·m²", "must be symmetric")
        if np.linalg.eigvalsh(inertia).min() < -1e-9 * max(1.0, np.abs(inertia).max()):
            raise InputError("inertia", inertia, "kg·m²", "must be positive semi-definite")
        put(self, "inertia", inertia.copy())
        put(self, "cog", _vec3("cog", self.cog, "m"))
        put(self, "added_mass", _table_or_square("added_mass", self.added_mass, n, "kg"))
        put(self, "radiation_damping",
            _table_or_square("radiation_damping", self.radiation_damping, n, "N·s/m"))
        put(self, "hydrostatic_stiffness",
            _square("hydrostatic_stiffness", self.hydrostatic_stiffness, n, "N/m"))
        put(self, "extra_stiffness", _square("extra_stiffness", self.extra_stiffness, n, "N/m"))
        put(self, "extra_damping", _square("extra_damping", self.extra_damping, n, "N·s/m"))
        exc = self.excitation
        if exc is not None:
            if not isinstance(exc, ExcitationTable):
                raise InputError("excitation", type(exc).__name__, "-", "must be an ExcitationTable")
            if exc.size == 6 and n == 3:
                exc = ExcitationTable(exc.omega, exc.heading, exc.values[:, PLANAR_INDEX, :],
                                      exc.extrapolation)
            elif exc.size != n:
                raise InputError("excitation", exc.size, "-", f"must have {n} or 6 DOFs")
            put(self, "excitation", exc)
        ep = np.zeros(2) if self.excitation_point is None else float_array(
            "excitation_point", self.excitation_point, "m")
        if ep.shape != (2,):
            raise InputError("excitation_point", ep.shape, "m", "must be (x, y)")
        put(self, "excitation_point", ep.copy())
        da = _vec3("drag_area", self.drag_area, "m²")
        if (da < 0).any():
            raise InputError("drag_area", da, "m²", "must be >= 0")
        put(self, "drag_area", da)
        put(self, "drag_point", _vec3("drag_point", self.drag_point, "m"))
        fixed = () if self.fixed_dofs is None else self.fixed_dofs
        if isinstance(fixed, str):
            fixed = (fixed,)
        fixed = tuple(fixed)
        names = PLANAR_DOFS if self.planar else SPATIAL_DOFS
        bad = [f for f in fixed if f not in names]
        if bad:
            raise InputError("fixed_dofs", list(fixed), "-",
                             f"must name DOFs of the body among {list(names)}; unknown {bad}")
        if len(set(fixed)) != len(fixed):
            raise InputError("fixed_dofs", list(fixed), "-", "must not repeat a DOF")
        put(self, "fixed_dofs", fixed)

    @property
    def free_index(self) -> np.ndarray:
        """Indices (in ``dof_names`` order) of the DOFs not in ``fixed_dofs``."""
        names = self.dof_names
        return np.array([i for i, n in enumerate(names) if n not in self.fixed_dofs],
                        dtype=int)

    @property
    def n_dof(self) -> int:
        """3 (planar) or 6."""
        return 3 if self.planar else 6

    @property
    def dof_names(self) -> tuple[str, ...]:
        """Names of the DOFs in order."""
        return PLANAR_DOFS if self.planar else SPATIAL_DOFS

    def mass_matrix(self) -> np.ndarray:
        """Rigid-body mass matrix about the reference point, (d, d) (:func:`rigid_body_mass_matrix`)."""
        return rigid_body_mass_matrix(self.mass, self.inertia, self.cog, self.planar)

    def added_mass_at(self, omega: Any) -> np.ndarray:
        """Added mass at ``omega`` (n_w,), shape (n_w, d, d). [kg, kg·m, kg·m²]"""
        return _matrix_at(self.added_mass, omega)

    def radiation_damping_at(self, omega: Any) -> np.ndarray:
        """Radiation damping at ``omega`` (n_w,), shape (n_w, d, d). [N·s/m, …]"""
        return _matrix_at(self.radiation_damping, omega)

    @property
    def frequency_dependent(self) -> bool:
        """True when the added mass or the radiation damping is tabulated over ω."""
        return isinstance(self.added_mass, FrequencyTable) or isinstance(
            self.radiation_damping, FrequencyTable)


def _matrix_at(a: np.ndarray | FrequencyTable, omega: Any) -> np.ndarray:
    w = np.atleast_1d(np.asarray(omega, dtype=float))
    if isinstance(a, FrequencyTable):
        return a.at(w)
    return np.broadcast_to(a, (w.size,) + a.shape).copy()


def body_excitation(body: RigidBody, omega: Any, heading: float,
                    wavenumber: Any | None = None) -> np.ndarray:
    """Wave excitation force on a body per unit wave amplitude.

    Parameters
    ----------
    body : RigidBody
        The body; its ``excitation`` table (zero when None).
    omega : array_like, shape (n_w,)
        Angular frequencies. [rad/s]
    heading : float
        Wave heading, direction of travel from +x toward +y. [rad]
    wavenumber : array_like, shape (n_w,), optional
        Wave numbers at ``omega`` (:func:`stochcable.sea.kinematics.wavenumber`); when
        given, the table is moved from its phase point to the global wave phase,
        times P = e^{−ik(x cos β + y sin β)} at the phase point (DESIGN.md "Linear
        wave kinematics").  Without it the phase stays referred to the phase point. [rad/m]

    Returns
    -------
    ndarray, complex, shape (n_w, d)
        Generalized force (forces, moments about the reference point). [N/m, N·m/m]
    """
    w = float_array("omega", omega, "rad/s", nonnegative=True)
    if body.excitation is None:
        return np.zeros((w.size, body.n_dof), dtype=complex)
    f = body.excitation.at(w, heading).T
    if wavenumber is not None:
        k = float_array("wavenumber", wavenumber, "rad/m", nonnegative=True)
        if k.shape != w.shape:
            raise InputError("wavenumber", k.shape, "rad/m", f"must have one value per omega ({w.size})")
        x = body.position[0] + body.excitation_point[0]
        y = body.position[1] + body.excitation_point[1]
        f = f * np.exp(-1j * k * (x * math.cos(heading) + y * math.sin(heading)))[:, None]
    return f


def body_drag_damping(body: RigidBody, rho: float, sigma: Any,
                      mean: Any | None = None) -> np.ndarray:
    """Linearized quadratic drag of a body as a damping matrix about its reference point.

    Parameters
    ----------
    body : RigidBody
        The body (``drag_area`` Cd·A per global direction at ``drag_point``).
    rho : float
        Water density. [kg/m³]
    sigma : array_like, shape (3,)
        Standard deviation of the relative velocity (fluid minus body) at the drag
        point along x, y, z. [m/s]
    mean : array_like, shape (3,), optional
        Mean relative velocity (current). [m/s]

    Returns
    -------
    ndarray, shape (d, d)
        Tᵀ diag(b) T with T = :func:`rigid_link_matrix` of the drag point. [N·s/m, …]

    Notes
    -----
    Per direction b = ρ CdA E|v| for v ~ N(U, σ²) (DESIGN.md "Drag linearization",
    :func:`stochcable.dynamics.linearization.drag_linear_current`); for U = 0 this is the seed
    form √(8/π)·½ρ CdA σ (seed 001 eq. 5.2.2).  The fluid load that goes with it is
    Tᵀ diag(b) v_fluid (wave velocity at the drag point).
    """
    from stochcable.dynamics.linearization import drag_linear_current

    rho = finite_scalar("rho", rho, "kg/m³")
    s = float_array("sigma", sigma, "m/s", nonnegative=True)
    u = np.zeros(3) if mean is None else float_array("mean", mean, "m/s")
    if s.shape != (3,) or u.shape != (3,):
        raise InputError("sigma", s.shape, "m/s", "sigma and mean must have 3 components")
    b = np.asarray(drag_linear_current(rho, body.drag_area, 1.0, s, u), dtype=float)
    t = rigid_link_matrix(body.drag_point)
    c = t.T @ np.diag(b) @ t
    if body.planar:
        return c[np.ix_(PLANAR_INDEX, PLANAR_INDEX)]
    return c


# ---------------------------------------------------------------------- rigid link


def rigid_link_matrix(r: Any, planar: bool = False) -> np.ndarray:
    """Small-motion map from body DOFs to the displacement of a body point.

    Parameters
    ----------
    r : array_like, shape (3,) (or (2,) = (x, z) when planar)
        The point relative to the body reference point. [m]
    planar : bool
        (2, 3) map from (surge, heave, pitch) to the point's (x, z) displacement.

    Returns
    -------
    ndarray, shape (3, 6) or (2, 3)
        T(r) = [I, −[r]×]: u_point = u + θ × r (3-D); planar
        [[1, 0, r_z], [0, 1, −r_x]] (pitch about +y). [-, m]

    Notes
    -----
    Seed 001 eqs. 3.3.6–3.3.7: the translation rows of Λ₁ = [[I, R], [0, I]] with R
    = −[r]× for r = X_2 − X_1 (eq. 3.3.7.b).  First order in the rotation: the finite
    rotation gives R(θ) r − r = θ × r + O(|θ|²|r|).  Forces F at the point map to the
    generalized force Tᵀ F = [F; r × F].
    """
    a = float_array("r", r, "m")
    if planar:
        if a.shape == (3,):
            rx, rz = a[0], a[2]
        elif a.shape == (2,):
            rx, rz = a
        else:
            raise InputError("r", a.shape, "m", "must be (x, y, z) or (x, z) when planar")
        return np.array([[1.0, 0.0, rz], [0.0, 1.0, -rx]])
    if a.shape != (3,):
        raise InputError("r", a.shape, "m", "must have 3 components (x, y, z)")
    t = np.zeros((3, 6))
    t[:, :3] = np.eye(3)
    t[:, 3:] = -skew(a)
    return t


def attachment_geometric_stiffness(force: Any, r: Any, planar: bool = False) -> np.ndarray:
    """Stiffness of a constant force carried by a body point when the body rotates.

    Parameters
    ----------
    force : array_like, shape (3,)
        Static force on the body at the point (e.g. the line end force). [N]
    r : array_like, shape (3,)
        The point relative to the reference point. [m]
    planar : bool
        The (surge, heave, pitch) 3×3 block.

    Returns
    -------
    ndarray, shape (6, 6) or (3, 3)
        Zero except the rotation block −[F]×[r]× = (F·r) I − r Fᵀ; planar: the pitch
        entry F_x r_x + F_z r_z. [N·m]

    Notes
    -----
    The moment about the reference of F at the rotated arm R(θ)r is
    M = (R r) × F; dM/dθ at θ = 0 with F held is (θ × r) × F = [F]×[r]× θ, and the
    restoring stiffness is its negative (the "moment of the end tension" term of the
    transformed body equation, seed 001 §3.3, eq. 3.3.4.e's K̄_B about the static
    state).  It is the exact Jacobian of the moment with respect to the rotation
    vector; it is not symmetric unless r ∥ F.  Summed over every static force on a
    body in equilibrium (lines, weight, buoyancy, environment) the antisymmetric
    parts, ½[Σ r × F]×, cancel.
    """
    f = float_array("force", force, "N")
    a = float_array("r", r, "m")
    if f.shape != (3,) or a.shape != (3,):
        raise InputError("force", f.shape, "N", "force and r must have 3 components")
    k = np.zeros((6, 6))
    k[3:, 3:] = float(f @ a) * np.eye(3) - np.outer(a, f)
    if planar:
        return k[np.ix_(PLANAR_INDEX, PLANAR_INDEX)]
    return k


# --------------------------------------------------------------------- coupling


@dataclass(frozen=True, eq=False)
class LineLink:
    """A line model and the bodies its ends are attached to.

    Parameters
    ----------
    name : str
        Line name (unique among the links).
    model : FEModel
        The line's finite-element model about its static shape; the attached end
        nodes must be among its prescribed (``fixed``) nodes.
    end_a, end_b : str, optional
        Name of the body the end is attached to; None keeps the end prescribed.  The
        attachment point is the end node's static position relative to the body's
        reference point.
    force_a, force_b : array_like, shape (3,), optional
        Static force the line exerts on the body at that end (LineStatics.force_a /
        force_b, which include current drag and the loads lumped on the end node);
        when None it is computed from the model: the end element's tension along it
        plus the weight and attachment loads lumped on the end node (no drag). [N]
    damping : matrix, shape (n_dof, n_dof), optional
        Damping on all model DOFs added to the model's seabed damping ``Cs``, e.g. the
        linearized drag of the line. [N·s/m]
    """

    name: str
    model: FEModel
    end_a: str | None = None
    end_b: str | None = None
    force_a: Any = None
    force_b: Any = None
    damping: Any = None


def _model_end_force(model: FEModel, end: str, g: float | None) -> np.ndarray:
    """Force a line exerts on the support at ``end`` from the model alone (no drag)."""
    mesh = model.mesh
    comps = list(model.components)
    e = np.zeros((model.n_elements, 3))
    e[:, comps] = model.tangents
    t = np.where(model.slack, 0.0, model.tension)
    if end == "end_a":
        f = t[0] * e[0]
        w_el, node = mesh.weight[0] * mesh.l0[0], 0
    else:
        f = -t[-1] * e[-1]
        w_el, node = mesh.weight[-1] * mesh.l0[-1], -1
    f = f.copy()
    f[2] -= 0.5 * w_el
    gg = 9.80665 if g is None else g
    f[2] += mesh.node_buoyancy[node] - mesh.node_mass[node] * gg
    return f


@dataclass(frozen=True, eq=False)
class CoupledSystem:
    """Lines and bodies assembled into one linear system (seed 001 eq. 3.3.10).

    Attributes
    ----------
    K, M, C : scipy.sparse.csr_array, shape (n, n)
        Stiffness (lines' tangent stiffness, body hydrostatic + extra stiffness and the
        attachment geometric stiffness), mass (lines' structural + added mass, rigid
        body mass) and frequency-independent damping (lines' seabed damping and link
        damping, body extra and drag damping) over x = [line free DOFs, body DOFs].
        Body added mass and radiation damping are not in M and C: see
        :meth:`body_hydrodynamics`.
    K_p, M_p, C_p : scipy.sparse.csr_array, shape (n, n_p)
        Coupling of x to the still-prescribed line DOFs p (fixed or moving ends).
    bodies : tuple of RigidBody
    lines : tuple of LineLink
    line_dofs : dict of str to ndarray of int
        Indices in x of each line's free DOFs (its model's ``free``, in order).
    body_dofs : dict of str to ndarray of int
        Indices in x of each body's DOFs.
    prescribed_dofs : dict of str to ndarray of int
        Indices in p of each line's still-prescribed model DOFs (model order).
    link_maps : dict of str to (L, P)
        Sparse maps u_line = L x + P p over all model DOFs of each line.
    geometric : dict of str to ndarray
        Per body the summed attachment geometric stiffness included in K.
    """

    K: sp.csr_array
    M: sp.csr_array
    C: sp.csr_array
    K_p: sp.csr_array
    M_p: sp.csr_array
    C_p: sp.csr_array
    bodies: tuple[RigidBody, ...]
    lines: tuple[LineLink, ...]
    line_dofs: dict[str, np.ndarray]
    body_dofs: dict[str, np.ndarray]
    prescribed_dofs: dict[str, np.ndarray]
    link_maps: dict[str, tuple[sp.csr_array, sp.csr_array]]
    geometric: dict[str, np.ndarray] = field(default_factory=dict)

    @property
    def n_dof(self) -> int:
        """Number of coupled DOFs n."""
        return int(self.K.shape[0])

    @property
    def n_prescribed(self) -> int:
        """Number of still-prescribed line DOFs n_p."""
        return int(self.K_p.shape[1])

    @property
    def body_index(self) -> np.ndarray:
        """Indices in x of all body DOFs, body order."""
        if not self.bodies:
            return np.zeros(0, dtype=int)
        return np.concatenate([self.body_dofs[b.name] for b in self.bodies])

    @property
    def frequency_dependent(self) -> bool:
        """True when some body's added mass or radiation damping varies with ω."""
        return any(b.frequency_dependent for b in self.bodies)

    def body_hydrodynamics(self, omega: Any) -> tuple[np.ndarray, np.ndarray]:
        """Added mass A(ω) and radiation damping B(ω) on the body DOFs.

        Returns
        -------
        A, B : ndarray, shape (n_w, n_b, n_b)
            Block-diagonal over the bodies, in the order of :attr:`body_index`.
        """
        w = np.atleast_1d(np.asarray(omega, dtype=float))
        nb = int(self.body_index.size)
        a = np.zeros((w.size, nb, nb))
        b = np.zeros((w.size, nb, nb))
        k = 0
        for body in self.bodies:
            d = body.n_dof
            a[:, k:k + d, k:k + d] = body.added_mass_at(w)
            b[:, k:k + d, k:k + d] = body.radiation_damping_at(w)
            k += d
        return a, b

    def asymmetry(self) -> float:
        """max|K − Kᵀ| / max|K|: nonzero when the static moments on a body do not
        balance within the model (see :func:`attachment_geometric_stiffness`). [-]"""
        d = abs(self.K - self.K.T)
        top = abs(self.K).max() if self.K.nnz else 0.0
        return float(d.max() / top) if top > 0 else 0.0


def couple(
    lines: Sequence[LineLink],
    bodies: Sequence[RigidBody],
    *,
    body_damping: Mapping[str, Any] | None = None,
    geometric_stiffness: bool = True,
    g: float | None = None,
) -> CoupledSystem:
    """Assemble lines and bodies into one linear system with rigid links.

    Parameters
    ----------
    lines : sequence of LineLink
        Line models and their body attachments.
    bodies : sequence of RigidBody
        The bodies (unique names); their dimensions must match the line models'
        (planar bodies with 2-D models, 6-DOF bodies with 3-D models).
    body_damping : mapping of str to array_like (d, d), optional
        Additional damping per body name (e.g. :func:`body_drag_damping`). [N·s/m, …]
    geometric_stiffness : bool
        Add the attachment geometric stiffness of the line end forces
        (:func:`attachment_geometric_stiffness`); default True.
    g : float, optional
        Gravity for the end forces computed from a model (default 9.80665). [m/s²]

    Returns
    -------
    CoupledSystem

    Raises
    ------
    InputError
        Duplicate names, an unknown body, an attached end that is not a prescribed
        node of its model, or a dimension mismatch.

    Notes
    -----
    Seed 001 §3.3: the attached end node's displacement is slaved to the body by
    u_end = T(r) ξ (eqs. 3.3.6–3.3.7, :func:`rigid_link_matrix`), and the line's
    equations are premultiplied by the transpose of the transformation (eqs.
    3.3.8–3.3.10): with L_ℓ the map from x to the line's DOFs,
    K = Σ L_ℓᵀ K_ℓ L_ℓ + K_B (so K_cc = Tᵀ K_bb T, K_fc = K_fb T), likewise M and C,
    and a line load f_ℓ enters as L_ℓᵀ f_ℓ (:func:`coupled_load`).  The rotation block
    of each body gets −[F]×[r]× for each attached end (F the static end force on the
    body), the linearization of the moment of a force whose arm rotates with the body.
    """
    bodies = tuple(bodies)
    lines = tuple(lines)
    names = [b.name for b in bodies]
    if len(set(names)) != len(names):
        raise InputError("bodies", names, "-", "body names must be unique")
    lnames = [ln.name for ln in lines]
    if len(set(lnames)) != len(lnames):
        raise InputError("lines", lnames, "-", "line names must be unique")
    by_name = {b.name: b for b in bodies}

    n_free = sum(int(ln.model.free.size) for ln in lines)
    n = n_free + sum(b.n_dof for b in bodies)
    line_dofs: dict[str, np.ndarray] = {}
    body_dofs: dict[str, np.ndarray] = {}
    k = 0
    for ln in lines:
        line_dofs[ln.name] = np.arange(k, k + ln.model.free.size)
        k += int(ln.model.free.size)
    for b in bodies:
        body_dofs[b.name] = np.arange(k, k + b.n_dof)
        k += b.n_dof

    geo = {b.name: np.zeros((b.n_dof, b.n_dof)) for b in bodies}
    pres: dict[str, np.ndarray] = {}
    maps: dict[str, tuple[sp.csr_array, sp.csr_array]] = {}
    plans = []
    n_p = 0
    for ln in lines:
        model = ln.model
        if not isinstance(model, FEModel):
            raise InputError(f"lines[{ln.name}].model", type(model).__name__, "-",
                             "must be a stochcable.line.fem.FEModel")
        fixed_nodes = set((model.fixed // model.dim).tolist())
        attached: dict[int, tuple[RigidBody, np.ndarray]] = {}
        for end, node in (("end_a", 0), ("end_b", model.n_nodes - 1)):
            bname = getattr(ln, end)
            if bname is None:
                continue
            if bname not in by_name:
                raise InputError(f"lines[{ln.name}].{end}", bname, "-",
                                 f"is not a body; bodies: {names}")
            body = by_name[bname]
            if node not in fixed_nodes:
                raise InputError(f"lines[{ln.name}].{end}", bname, "-",
                                 "the end node is free in the model: build it with the end "
                                 "prescribed (fixed_nodes)")
            if (model.dim == 2) != body.planar:
                raise InputError(f"lines[{ln.name}].{end}", bname, "-",
                                 f"a {model.dim}-D line model needs a "
                                 f"{'planar' if model.dim == 2 else '6-DOF'} body")
            r = model.positions[node] - body.position
            if body.planar and abs(r[1]) > _SYM_TOL * max(1.0, float(np.abs(r).max())):
                raise InputError(f"lines[{ln.name}].{end}", r.tolist(), "m",
                                 "a planar body's attachment must lie in its x–z plane")
            fgiven = getattr(ln, "force_a" if end == "end_a" else "force_b")
            f = (_model_end_force(model, end, g) if fgiven is None
                 else float_array(f"lines[{ln.name}].force_{end[-1]}", fgiven, "N"))
            if f.shape != (3,):
                raise InputError(f"lines[{ln.name}].force_{end[-1]}", f.shape, "N",
                                 "must have 3 components")
            if geometric_stiffness:
                geo[bname] = geo[bname] + attachment_geometric_stiffness(f, r, body.planar)
            attached[node] = (body, r)
        plans.append((ln, attached))

    for ln, attached in plans:
        model = ln.model
        d = model.dim
        rows, cols, vals = [], [], []
        # free DOFs: identity
        rows.append(model.free)
        cols.append(line_dofs[ln.name])
        vals.append(np.ones(model.free.size))
        still = []
        for dof in model.fixed:
            node = int(dof // d)
            if node in attached:
                continue
            still.append(int(dof))
        for node, (body, r) in attached.items():
            t = rigid_link_matrix(r, planar=body.planar)  # (d, n_b)
            ii, jj = np.nonzero(t)
            rows.append(d * node + ii)
            cols.append(body_dofs[body.name][jj])
            vals.append(t[ii, jj])
        L = sp.csr_array((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                         shape=(model.n_dof, n))
        still_arr = np.asarray(still, dtype=int)
        P = sp.csr_array((np.ones(still_arr.size), (still_arr, np.arange(still_arr.size))),
                         shape=(model.n_dof, still_arr.size))
        pres[ln.name] = np.arange(n_p, n_p + still_arr.size)
        n_p += still_arr.size
        maps[ln.name] = (L, P)

    def total(getter, body_part) -> tuple[sp.csr_array, sp.csr_array]:
        acc = sp.csr_array((n, n))
        acc_p = sp.csr_array((n, n_p))
        for ln in lines:
            L, P = maps[ln.name]
            a = getter(ln)
            LtA = (L.T @ a).tocsr()
            acc = acc + LtA @ L
            pp = sp.csr_array((n, n_p))
            if P.shape[1]:
                blk = (LtA @ P).tocoo()
                off = int(pres[ln.name][0])
                pp = sp.csr_array((blk.data, (blk.row, blk.col + off)), shape=(n, n_p))
            acc_p = acc_p + pp
        for b in bodies:
            idx = body_dofs[b.name]
            blk = sp.coo_array(body_part(b))
            acc = acc + sp.csr_array((blk.data, (idx[blk.row], idx[blk.col])), shape=(n, n))
        return acc.tocsr(), acc_p.tocsr()

    bd = {} if body_damping is None else dict(body_damping)
    for key in bd:
        if key not in by_name:
            raise InputError("body_damping", key, "-", f"is not a body; bodies: {names}")

    def line_c(ln: LineLink) -> Any:
        if ln.damping is None:
            return ln.model.Cs
        c = ln.damping
        if c.shape != (ln.model.n_dof, ln.model.n_dof):
            raise InputError(f"lines[{ln.name}].damping", c.shape, "N·s/m",
                             f"must be ({ln.model.n_dof}, {ln.model.n_dof})")
        return sp.csr_array(ln.model.Cs + sp.csr_array(c))

    K, K_p = total(lambda ln: ln.model.K,
                   lambda b: b.hydrostatic_stiffness + b.extra_stiffness + geo[b.name])
    M, M_p = total(lambda ln: (ln.model.M + ln.model.Ma).tocsr(), lambda b: b.mass_matrix())
    C, C_p = total(line_c, lambda b: b.extra_damping + (
        _square(f"body_damping[{b.name}]", bd[b.name], b.n_dof, "N·s/m") if b.name in bd
        else 0.0))
    for a in (K, M, C, K_p, M_p, C_p):
        a.eliminate_zeros()
    return CoupledSystem(K=K, M=M, C=C, K_p=K_p, M_p=M_p, C_p=C_p, bodies=bodies,
                         lines=lines, line_dofs=line_dofs, body_dofs=body_dofs,
                         prescribed_dofs=pres, link_maps=maps, geometric=geo)


# ------------------------------------------------------------------------- loads


def _rows_apply(a: Any, x: np.ndarray) -> np.ndarray:
    """Sparse (m, n) times x (n_w, n, ...) -> (n_w, m, ...)."""
    n_w, n = x.shape[:2]
    rest = x.shape[2:]
    flat = np.moveaxis(x.reshape(n_w, n, -1), 0, 1).reshape(n, -1)
    out = np.asarray(a @ flat)
    return np.moveaxis(out.reshape(out.shape[0], n_w, -1), 1, 0).reshape(n_w, out.shape[0], *rest)


def coupled_load(
    system: CoupledSystem,
    omega: Any,
    line_loads: Mapping[str, Any] | None = None,
    body_loads: Mapping[str, Any] | None = None,
    line_motions: Mapping[str, Any] | None = None,
) -> np.ndarray:
    """Load vector of the coupled system at every frequency.

    Parameters
    ----------
    system : CoupledSystem
    omega : array_like, shape (n_w,)
        Angular frequencies. [rad/s]
    line_loads : mapping of line name to array_like (n_w, n_dof_line[, k]), optional
        Loads on all model DOFs of a line (fluid loads); the share on a body-attached
        end node is carried to the body as Tᵀ f. [N]
    body_loads : mapping of body name to array_like (n_w, d[, k]), optional
        Generalized forces on a body (:func:`body_excitation`). [N, N·m]
    line_motions : mapping of line name to array_like (n_w, n_dof_line[, k]), optional
        Prescribed displacements on a line's model DOFs; the entries at its
        still-prescribed DOFs load the system by −(K_p − ω²M_p + iωC_p) p. [m]

    Returns
    -------
    ndarray, complex, shape (n_w, n[, k])
    """
    w = float_array("omega", omega, "rad/s", nonnegative=True)
    n_w, n = w.size, system.n_dof
    out = None

    def add(acc, v):
        return v if acc is None else acc + v

    for name, f in (line_loads or {}).items():
        if name not in system.link_maps:
            raise InputError("line_loads", name, "-", "is not a coupled line")
        f = np.asarray(f, dtype=complex)
        L, _ = system.link_maps[name]
        if f.shape[:2] != (n_w, L.shape[0]):
            raise InputError(f"line_loads[{name}]", f.shape, "N",
                             f"must start with ({n_w}, {L.shape[0]})")
        out = add(out, _rows_apply(L.T.tocsr(), f))
    for name, f in (body_loads or {}).items():
        if name not in system.body_dofs:
            raise InputError("body_loads", name, "-", "is not a coupled body")
        f = np.asarray(f, dtype=complex)
        idx = system.body_dofs[name]
        if f.shape[:2] != (n_w, idx.size):
            raise InputError(f"body_loads[{name}]", f.shape, "N",
                             f"must start with ({n_w}, {idx.size})")
        v = np.zeros((n_w, n) + f.shape[2:], dtype=complex)
        v[:, idx] = f
        out = add(out, v)
    if line_motions:
        p = None
        for name, u in line_motions.items():
            if name not in system.link_maps:
                raise InputError("line_motions", name, "-", "is not a coupled line")
            u = np.asarray(u, dtype=complex)
            _, P = system.link_maps[name]
            if u.shape[:2] != (n_w, P.shape[0]):
                raise InputError(f"line_motions[{name}]", u.shape, "m",
                                 f"must start with ({n_w}, {P.shape[0]})")
            if p is None:
                p = np.zeros((n_w, system.n_prescribed) + u.shape[2:], dtype=complex)
            p[:, system.prescribed_dofs[name]] = _rows_apply(P.T.tocsr(), u)
        if p is not None:
            extra = (1,) * (p.ndim - 2)
            ww = w.reshape((n_w, 1) + extra)
            z = (_rows_apply(system.K_p, p) - ww**2 * _rows_apply(system.M_p, p)
                 + 1j * ww * _rows_apply(system.C_p, p))
            out = add(out, -z)
    if out is None:
        return np.zeros((n_w, n), dtype=complex)
    return out


def expand_line(system: CoupledSystem, name: str, x: Any, p: Any | None = None) -> np.ndarray:
    """Displacement of all model DOFs of a line, u = L x + P p.

    Parameters
    ----------
    system : CoupledSystem
    name : str
        Line name.
    x : array_like, shape (n_w, n[, k])
        Coupled response (:func:`solve_coupled_direct`). [m, rad]
    p : array_like, shape (n_w, n_p[, k]), optional
        Prescribed displacements (zero when None). [m]

    Returns
    -------
    ndarray, complex, shape (n_w, n_dof_line[, k])
    """
    if name not in system.link_maps:
        raise InputError("name", name, "-", "is not a coupled line")
    L, P = system.link_maps[name]
    x = np.asarray(x, dtype=complex)
    u = _rows_apply(L, x)
    if p is not None and P.shape[1]:
        pp = np.asarray(p, dtype=complex)[:, system.prescribed_dofs[name]]
        u = u + _rows_apply(P, pp)
    return u


# ------------------------------------------------------------------------- solve


def constant_matrices(system: CoupledSystem, omega_ref: float
                      ) -> tuple[sp.csr_array, sp.csr_array, sp.csr_array]:
    """K, M + A(ω_ref) and C + B(ω_ref): constant matrices for modes and Foss.

    Parameters
    ----------
    system : CoupledSystem
    omega_ref : float
        Frequency at which the body added mass and radiation damping are frozen
        (typically the spectral peak or the body's natural frequency). [rad/s]

    Returns
    -------
    K, M_T, C_T : scipy.sparse.csr_array

    Notes
    -----
    Modal superposition and the Foss decomposition (seed 001 §5.3) need constant
    matrices; with A(ω), B(ω) varying they are exact only at ω_ref, so the direct
    solve (:func:`solve_coupled_direct`) is the reference whenever
    ``system.frequency_dependent``.
    """
    w = nonnegative("omega_ref", omega_ref, "rad/s")
    a, b = system.body_hydrodynamics(np.array([w]))
    idx = system.body_index
    n = system.n_dof

    def emb(blk: np.ndarray) -> sp.csr_array:
        c = sp.coo_array(blk)
        return sp.csr_array((c.data, (idx[c.row], idx[c.col])), shape=(n, n))

    return system.K, (system.M + emb(a[0])).tocsr(), (system.C + emb(b[0])).tocsr()


def _block(a: Any, rows: np.ndarray, cols: np.ndarray) -> Any:
    return a[rows][:, cols]


def solve_coupled_direct(
    system: CoupledSystem,
    F: Any,
    omega: Any,
    method: Literal["auto", "schur", "dense"] = "auto",
) -> np.ndarray:
    """Harmonic response of the coupled lines–bodies system at every frequency.

    Parameters
    ----------
    system : CoupledSystem
    F : array_like, complex, shape (n_w, n) or (n_w, n, k)
        Loads (:func:`coupled_load`). [N, N·m]
    omega : array_like, shape (n_w,)
        Angular frequencies. [rad/s]
    method : {"auto", "schur", "dense"}
        ``"schur"``: each line's free block solved by
        :func:`stochcable.dynamics.solvers.solve_direct` (banded, all frequencies at once),
        the body DOFs from the Schur complement; ``"dense"``: one batched dense solve
        (small systems); ``"auto"``: schur, falling back to dense (up to 3000 DOFs)
        when a line block alone is singular (a fixed-end line resonance).

    Returns
    -------
    ndarray, complex, same shape as F
        x(ω) = Z(ω)⁻¹ F(ω), Z = K − ω²(M + A(ω)) + iω(C + B(ω)). [m, rad]

    Raises
    ------
    SolverError
        When Z(ω) is singular (undamped resonance).

    Notes
    -----
    The direct solve of DESIGN.md "Solution" with the body's frequency-dependent added
    mass and radiation damping (seed 001 eq. 3.2.c.20) exact at every ω.  A body's
    ``fixed_dofs`` are constraints: those DOFs are removed from the system and their
    motion is exactly zero (their loads are reactions, not inputs).  The Foss
    decomposition needs constant matrices (:func:`constant_matrices`) and is exact
    only where A and B are constant.
    """
    w = float_array("omega", omega, "rad/s", nonnegative=True)
    f = np.asarray(F, dtype=complex)
    squeeze = f.ndim == 2
    if squeeze:
        f = f[:, :, None]
    n = system.n_dof
    if f.ndim != 3 or f.shape[:2] != (w.size, n):
        raise InputError("F", f.shape, "N", f"must have shape ({w.size}, {n}[, k])")
    if not np.isfinite(f).all():
        raise InputError("F", "non-finite", "N", "must be finite")
    if method not in ("auto", "schur", "dense"):
        raise InputError("method", method, "-", "must be 'auto', 'schur' or 'dense'")
    if method == "dense":
        x = _solve_dense(system, f, w)
    else:
        try:
            x = _solve_schur(system, f, w)
        except SolverError:
            if method == "schur" or n > _DENSE_MAX:
                raise
            x = _solve_dense(system, f, w)
    return x[:, :, 0] if squeeze else x


def _free_body(system: CoupledSystem) -> tuple[np.ndarray, np.ndarray]:
    """Global indices of the free body DOFs and, among ``body_index``, their positions
    (the bodies' ``fixed_dofs`` removed)."""
    J = system.body_index
    pos = np.concatenate([system.body_dofs[b.name][b.free_index] for b in system.bodies]
                         ) if system.bodies else np.zeros(0, dtype=int)
    where = np.searchsorted(J, pos) if np.all(np.diff(J) > 0) else np.array(
        [int(np.flatnonzero(J == p)[0]) for p in pos], dtype=int)
    return pos.astype(int), where.astype(int)


def _body_z(system: CoupledSystem, w: np.ndarray) -> np.ndarray:
    """Z_JJ(ω) on the body DOFs, (n_w, n_b, n_b)."""
    J = system.body_index
    a, b = system.body_hydrodynamics(w)
    k = _block(system.K, J, J).toarray()
    m = _block(system.M, J, J).toarray()
    c = _block(system.C, J, J).toarray()
    w2 = (w * w)[:, None, None]
    iw = (1j * w)[:, None, None]
    return k[None] - w2 * (m[None] + a) + iw * (c[None] + b)


def _solve_small(z: np.ndarray, g: np.ndarray, w: np.ndarray, what: str) -> np.ndarray:
    """Batched dense solve; SolverError where ||Z||·||x||/||F|| > 1e12 (the estimate of
    :func:`stochcable.dynamics.solvers.solve_direct`) or Z is exactly singular."""
    try:
        x = np.linalg.solve(z, g)
    except np.linalg.LinAlgError:
        est = np.linalg.cond(z)
    else:
        nz = np.linalg.norm(z, axis=(1, 2))
        nf = np.linalg.norm(g.reshape(w.size, -1), axis=1)
        nx = np.linalg.norm(x.reshape(w.size, -1), axis=1)
        with np.errstate(invalid="ignore", divide="ignore"):
            est = np.where(nf > 0, nz * nx / np.where(nf > 0, nf, 1.0), 0.0)
        est = np.where(np.isfinite(x.reshape(w.size, -1)).all(axis=1), est, np.inf)
    bad = ~(est <= 1e12)
    if bad.any():
        k = int(np.flatnonzero(bad)[0])
        raise SolverError(f"{what}: dynamic matrix singular to working precision at omega = "
                          f"{float(w[k]):.6g} rad/s (condition estimate {float(est[k]):.2e}; "
                          "undamped resonance); add damping or move the frequency")
    return x


def _solve_dense(system: CoupledSystem, f: np.ndarray, w: np.ndarray) -> np.ndarray:
    n = system.n_dof
    if n > _DENSE_MAX:
        raise InputError("method", "dense", "-",
                         f"the dense solve is limited to {_DENSE_MAX} DOFs (system has {n})")
    J = system.body_index
    a, b = system.body_hydrodynamics(w)
    k, m, c = system.K.toarray(), system.M.toarray(), system.C.toarray()
    w2 = (w * w)[:, None, None]
    iw = (1j * w)[:, None, None]
    z = k[None] - w2 * m[None] + iw * c[None]
    if J.size:
        z[np.ix_(np.arange(w.size), J, J)] += -w2 * a + iw * b
    free, _ = _free_body(system)
    keep = np.setdiff1d(np.arange(n), np.setdiff1d(J, free))   # fixed body DOFs out
    if keep.size == n:
        return _solve_small(z, f, w, "coupled direct solve")
    x = np.zeros_like(f)
    x[:, keep, :] = _solve_small(z[:, keep][:, :, keep], f[:, keep, :], w,
                                 "coupled direct solve")
    return x


def _solve_schur(system: CoupledSystem, f: np.ndarray, w: np.ndarray) -> np.ndarray:
    from stochcable.dynamics.solvers import solve_direct

    n_w, n, n_rhs = f.shape
    # the free body DOFs only: fixed ones stay exactly zero (constraints)
    J, where = _free_body(system)
    nb = J.size
    x = np.zeros_like(f)
    w2 = (w * w)[:, None, None]
    iw = (1j * w)[:, None, None]

    def z_of(rows: np.ndarray, cols: np.ndarray) -> np.ndarray:
        return (_block(system.K, rows, cols).toarray()[None]
                - w2 * _block(system.M, rows, cols).toarray()[None]
                + iw * _block(system.C, rows, cols).toarray()[None])

    if nb:
        s = _body_z(system, w)[:, where][:, :, where]
        g = f[:, J, :].copy()
    back = []  # (line DOFs, Z_II⁻¹ Z_IJ) for the back-substitution
    for ln in system.lines:
        I = system.line_dofs[ln.name]
        if I.size == 0:
            continue
        kii, mii, cii = (_block(a, I, I) for a in (system.K, system.M, system.C))
        rhs = np.concatenate([f[:, I, :], z_of(I, J)], axis=2) if nb else f[:, I, :]
        y = solve_direct(kii, mii, cii, rhs, w)
        x[:, I, :] = y[:, :, :n_rhs]
        if nb:
            z_ji = z_of(J, I)
            s = s - z_ji @ y[:, :, n_rhs:]
            g = g - z_ji @ y[:, :, :n_rhs]
            back.append((I, y[:, :, n_rhs:]))
    if nb:
        xb = _solve_small(s, g, w, "coupled direct solve (body Schur complement)")
        x[:, J, :] = xb
        for I, yb in back:
            x[:, I, :] -= yb @ xb
    return x
