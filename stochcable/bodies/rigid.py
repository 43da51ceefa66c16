"""Large rigid bodies coupled to lines (Tuah (1982), §3.2.c and §3.3).

A large body (a buoy, a disc, a vessel) has six rigid degrees of freedom (three in a
planar x–z analysis); its equation of motion is Tuah (1982), eq. 3.2.c.20,

    (M_B + A(ω)) ξ̈ + B(ω) ξ̇ + (K_R + K_C) ξ = F_exc(ω) e^{iωt} + F̄,

with the rigid-body mass M_B, the added mass A(ω) and radiation damping B(ω) of
diffraction–radiation theory, the hydrostatic restoring K_R, the stiffness of the
attached cables K_C, and the wave excitation F_exc (per unit wave amplitude).  Lines
attached to the body at a point r (relative to the body reference point) follow it
through the rigid link of Tuah (1982), eqs. 3.3.6–3.3.7, u_end = T(r)·ξ, and their
equations are transformed with Tᵀ (eqs. 3.3.8–3.3.10) and assembled with the body's.

Degrees of freedom and signs
----------------------------
- 6 DOF (3-D): ξ = (surge, sway, heave, roll, pitch, yaw) = (u_x, u_y, u_z, θ_x, θ_y,
  θ_z): translations of the reference point along the global axes [m] and small
  rotations about the global axes through the reference point [rad], right-handed.
  (Tuah's (1982) own order, surge–heave–sway in a y-up frame, is mapped onto this by its
  eq. 3.3.5; here z is up and no such map is needed.)
- 3 DOF (planar, in the x–z plane): ξ = (surge, heave, pitch) = (u_x, u_z, θ_y), pitch
  positive about +y (right-handed): a point ahead of the reference (+x) moves *down*
  for a positive pitch, a point above it (+z) moves toward +x.
- Generalized forces are (F_x, F_y, F_z, M_x, M_y, M_z) (planar: F_x, F_z, M_y),
  moments about the reference point.  Hydrodynamic matrices are taken about the same
  point (Capytaine's ``rotation_center``, WAMIT's origin of the body axes).

Lines and bodies are assembled into one linear system by
:func:`stochcable.bodies.coupling.couple`.

References
----------
Tuah, H. (1982), Cable dynamics in an ocean environment, PhD thesis, Oregon State University.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from stochcable.bodies.tables import ExcitationTable, FrequencyTable
from stochcable.errors import InputError
from stochcable.validation import float_array, nonnegative

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
    "link_matrix",
    "geometric_stiffness",
    "body_excitation",
    "square_matrix",
]

#: Names of the six rigid-body DOFs, in order (global axes, rotations about them).
SPATIAL_DOFS = ("surge", "sway", "heave", "roll", "pitch", "yaw")
#: Names of the three planar (x–z) DOFs, in order; pitch about +y.
PLANAR_DOFS = ("surge", "heave", "pitch")
#: Positions of the planar DOFs among the six: surge 0, heave 2, pitch 4.
PLANAR_INDEX = (0, 2, 4)


# --------------------------------------------------------------------- rigid body


def skew(r: Any) -> np.ndarray:
    """Cross-product matrix [r]× with [r]× a = r × a, shape (3, 3)."""
    x, y, z = np.asarray(r, dtype=float)
    return np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])


def rigid_body_mass_matrix(
    mass: float, inertia: Any, cog: Any = (0.0, 0.0, 0.0), planar: bool = False
) -> np.ndarray:
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
    Tuah (1982), eq. 3.3.7 to the centre of gravity) gives m T(c)ᵀT(c) + diag(0, I_G);
    −[c]×[c]× = |c|²I − c cᵀ is the parallel-axis term.  Tuah's (1982) m_B of eq. 3.2.14.
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


def square_matrix(name: str, value: Any, n: int, unit: str) -> np.ndarray:
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
            return FrequencyTable(
                value.omega, value.values[:, PLANAR_INDEX][:, :, PLANAR_INDEX], value.extrapolation
            )
        if value.size != n:
            raise InputError(
                name, value.size, unit, f"table must hold ({n}, {n}) or (6, 6) matrices"
            )
        return value
    return square_matrix(name, value, n, unit)


def _vec3(name: str, value: Any, unit: str, default: float = 0.0) -> np.ndarray:
    if value is None:
        return np.full(3, default)
    a = float_array(name, value, unit)
    if a.shape != (3,):
        raise InputError(name, a.shape, unit, "must have 3 components (x, y, z)")
    return a.copy()


@dataclass(frozen=True, eq=False)
class RigidBody:
    """A large rigid body (Tuah (1982), §3.2.c, eq. 3.2.c.20).

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
        Wave excitation force per unit amplitude over ω and heading (Tuah's (1982) C_l of
        eq. 3.2.c.17).
    excitation_point : array_like, shape (2,), optional
        Horizontal offset (x, y) from the reference point of the point where the
        excitation table's phases are referred to the incident wave elevation
        (default the reference point itself). [m]
    drag_area : array_like, shape (3,), optional
        Quadratic drag Cd·A for relative velocities along x, y and z (a Morison
        element on the body), linearized as
        :func:`stochcable.reference.bodies.body_drag_damping` (the engine's drag
        linearization, :mod:`stochcable.dynamics.groups`). [m²]
    drag_point : array_like, shape (3,), optional
        Point of application of the drag, relative to the reference point. [m]
    extra_stiffness, extra_damping : array_like (d, d), optional
        Additional linear stiffness and damping (e.g. a PTO, viscous roll damping).
    planar : bool
        Three DOFs (surge, heave, pitch) in the x–z plane instead of six.
    fixed_dofs : sequence of str, optional
        Names of DOFs held fixed (among ``dof_names``; default none): a constraint
        ξ_j ≡ 0 in the coupled dynamics (:mod:`stochcable.dynamics.groups`), as the
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
        inertia = (
            np.zeros((3, 3))
            if self.inertia is None
            else float_array("inertia", self.inertia, "kg·m²", ndim=2)
        )
        if inertia.shape != (3, 3):
            raise InputError("inertia", inertia.shape, "kg·m²", "must be a (3, 3) tensor")
        if not np.allclose(
            inertia, inertia.T, rtol=1e-9, atol=1e-12 * max(1.0, np.abs(inertia).max())
        ):
            raise InputError("inertia", inertia, "kg·m²", "must be symmetric")
        if np.linalg.eigvalsh(inertia).min() < -1e-9 * max(1.0, np.abs(inertia).max()):
            raise InputError("inertia", inertia, "kg·m²", "must be positive semi-definite")
        put(self, "inertia", inertia.copy())
        put(self, "cog", _vec3("cog", self.cog, "m"))
        put(self, "added_mass", _table_or_square("added_mass", self.added_mass, n, "kg"))
        put(
            self,
            "radiation_damping",
            _table_or_square("radiation_damping", self.radiation_damping, n, "N·s/m"),
        )
        put(
            self,
            "hydrostatic_stiffness",
            square_matrix("hydrostatic_stiffness", self.hydrostatic_stiffness, n, "N/m"),
        )
        put(
            self,
            "extra_stiffness",
            square_matrix("extra_stiffness", self.extra_stiffness, n, "N/m"),
        )
        put(self, "extra_damping", square_matrix("extra_damping", self.extra_damping, n, "N·s/m"))
        exc = self.excitation
        if exc is not None:
            if not isinstance(exc, ExcitationTable):
                raise InputError(
                    "excitation", type(exc).__name__, "-", "must be an ExcitationTable"
                )
            if exc.size == 6 and n == 3:
                exc = ExcitationTable(
                    exc.omega, exc.heading, exc.values[:, PLANAR_INDEX, :], exc.extrapolation
                )
            elif exc.size != n:
                raise InputError("excitation", exc.size, "-", f"must have {n} or 6 DOFs")
            put(self, "excitation", exc)
        ep = (
            np.zeros(2)
            if self.excitation_point is None
            else float_array("excitation_point", self.excitation_point, "m")
        )
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
            raise InputError(
                "fixed_dofs",
                list(fixed),
                "-",
                f"must name DOFs of the body among {list(names)}; unknown {bad}",
            )
        if len(set(fixed)) != len(fixed):
            raise InputError("fixed_dofs", list(fixed), "-", "must not repeat a DOF")
        put(self, "fixed_dofs", fixed)

    @property
    def free_index(self) -> np.ndarray:
        """Indices (in ``dof_names`` order) of the DOFs not in ``fixed_dofs``."""
        names = self.dof_names
        return np.array([i for i, n in enumerate(names) if n not in self.fixed_dofs], dtype=int)

    @property
    def n_dof(self) -> int:
        """3 (planar) or 6."""
        return 3 if self.planar else 6

    @property
    def dof_names(self) -> tuple[str, ...]:
        """Names of the DOFs in order."""
        return PLANAR_DOFS if self.planar else SPATIAL_DOFS

    def mass_matrix(self) -> np.ndarray:
        """Rigid-body mass matrix about the reference point, (d, d)
        (:func:`rigid_body_mass_matrix`)."""
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
            self.radiation_damping, FrequencyTable
        )


def _matrix_at(a: np.ndarray | FrequencyTable, omega: Any) -> np.ndarray:
    w = np.atleast_1d(np.asarray(omega, dtype=float))
    if isinstance(a, FrequencyTable):
        return a.at(w)
    return np.broadcast_to(a, (w.size,) + a.shape).copy()


def body_excitation(
    body: RigidBody, omega: Any, heading: float, wavenumber: Any | None = None
) -> np.ndarray:
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
            raise InputError(
                "wavenumber", k.shape, "rad/m", f"must have one value per omega ({w.size})"
            )
        x = body.position[0] + body.excitation_point[0]
        y = body.position[1] + body.excitation_point[1]
        f = f * np.exp(-1j * k * (x * math.cos(heading) + y * math.sin(heading)))[:, None]
    return f


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
    Tuah (1982), eqs. 3.3.6–3.3.7: the translation rows of Λ₁ = [[I, R], [0, I]] with R
    = −[r]× for r = X_2 − X_1 (eq. 3.3.7.b).  First order in the rotation: the finite
    rotation gives R(θ) r − r = θ × r + O(|θ|²|r|).  Forces F at the point map to the
    generalized force Tᵀ F = [F; r × F].
    """
    a = float_array("r", r, "m")
    if planar:
        if a.shape not in ((3,), (2,)):
            raise InputError("r", a.shape, "m", "must be (x, y, z) or (x, z) when planar")
    elif a.shape != (3,):
        raise InputError("r", a.shape, "m", "must have 3 components (x, y, z)")
    return link_matrix(a, planar)


def link_matrix(a: np.ndarray, planar: bool) -> np.ndarray:
    """:func:`rigid_link_matrix` of a checked point: a finite float array ``a`` of
    shape (3,), or (3,) or (2,) = (x, z) when planar [m].  For the inner loops (the
    body statics at every trial pose)."""
    if planar:
        if a.shape == (3,):
            rx, rz = a[0], a[2]
        else:
            rx, rz = a
        return np.array([[1.0, 0.0, rz], [0.0, 1.0, -rx]])
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
    transformed body equation, Tuah (1982), §3.3, eq. 3.3.4.e's K̄_B about the static
    state).  It is the exact Jacobian of the moment with respect to the rotation
    vector; it is not symmetric unless r ∥ F.  Summed over every static force on a
    body in equilibrium (lines, weight, buoyancy, environment) the antisymmetric
    parts, ½[Σ r × F]×, cancel.
    """
    f = float_array("force", force, "N")
    a = float_array("r", r, "m")
    if f.shape != (3,) or a.shape != (3,):
        raise InputError("force", f.shape, "N", "force and r must have 3 components")
    return geometric_stiffness(f, a, planar)


def geometric_stiffness(f: np.ndarray, a: np.ndarray, planar: bool) -> np.ndarray:
    """:func:`attachment_geometric_stiffness` of a checked force ``f`` [N] and point
    ``a`` [m], finite float arrays of shape (3,).  For the inner loops (the body
    statics at every trial pose)."""
    k = np.zeros((6, 6))
    k[3:, 3:] = float(f @ a) * np.eye(3) - np.outer(a, f)
    if planar:
        return k[np.ix_(PLANAR_INDEX, PLANAR_INDEX)]
    return k
