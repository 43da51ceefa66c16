"""Transport terms of a travelling line in the time-domain reference
(:mod:`stochcable.reference.cable`).

Formulation: the material derivative on a mesh fixed along the path.  The nodes of the
time-domain model are points of the line's path, not of its material: the material
flows through them at speed c (positive from end_a to end_b), so the ends stay at
their guides (the vessel's chute, the seabed touchdown) and remain prescribed nodes.
A Lagrangian mesh riding with the material would instead have elements entering and
leaving through the ends.  The acceleration of the material at a path point s is then
the material derivative

    D²x/Dt² = (∂/∂t + c ∂/∂s)² x = ẍ + 2c ẋ′ + c² x″,

and m D²x/Dt² puts, beside M ẍ, the gyroscopic (Coriolis) force 2 m c ẋ′ and the
centripetal force m c² x″.  Their Galerkin forms on the 2-node elements are those of
:mod:`stochcable.line.transport.matrices` (Wickert & Mote 1990, eq. 1): per element
G_e = m c [[0, 1], [−1, 0]] ⊗ I and K_c,e = −(m c²/l) [[1, −1], [−1, 1]] ⊗ I, with m
the structural mass per unit current length m₀ l0/l and l the static element length;
the water's added mass does not travel.  Both are linear in the motion and are added to
the residual as G u̇ + K_c (x − x_s) with constant matrices (the geometric
nonlinearity of the elements is untouched).

They act on the displacement from the static shape x_s, not on x: the centripetal load
m c² κ of the steady travel on the curved static shape is left out here as it is in the
statics and in the frequency-domain model (:mod:`stochcable.line.transport.matrices`; exact for
a straight line, an error of order m c²/T on a sagged one), so the time-domain model
starts from the same equilibrium the frequency-domain model linearizes about.

The drag sees the relative velocity of the fluid and the *material*, whose velocity at
a path point is u̇ + c e (Hu & Jin 2001, eq. 6): :class:`~stochcable.reference.
cable_model.LineModel` subtracts c e in its drag (only the axial drag changes: c e has
no normal component).

References
----------
Wickert, J. A. & Mote, C. D. (1990), Classical vibration analysis of axially moving
continua, Journal of Applied Mechanics 57, 738–744, eq. 1.

Hu, H. Y. & Jin, D. P. (2001), Non-linear dynamics of a suspended travelling cable
subject to transverse fluid excitation, Journal of Sound and Vibration 239(3),
515–529, eq. 6.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import scipy.sparse as sp

from stochcable.errors import InputError
from stochcable.line.elements import STIFFNESS_PATTERN, expand_blocks
from stochcable.line.transport.matrices import GYRO_PATTERN
from stochcable.line.transport.relative_flow import steady_lift_force

__all__ = ["TransportTerms", "transport_terms", "check_transport_speed", "lift_nodal_forces"]


@dataclass(frozen=True, eq=False)
class TransportTerms:
    """The constant transport matrices of a time-domain line model.

    Attributes
    ----------
    speed : float
        Axial speed c. [m/s]
    G, Kc : scipy.sparse.csr_matrix, shape (N, N)
        Gyroscopic (skew) and centripetal matrices on all DOFs. [N·s/m], [N/m]
    G_band, Kc_band : ndarray, shape (2u + 1, N)
        The same in the model's LAPACK band storage.
    mass_per_length : ndarray, shape (n_el,)
        Travelling mass per unit current length m₀ l0/l. [kg/m]
    """

    speed: float
    G: sp.csr_matrix
    Kc: sp.csr_matrix
    G_band: np.ndarray
    Kc_band: np.ndarray
    mass_per_length: np.ndarray

    def force(self, X: np.ndarray, V: np.ndarray, x_static: np.ndarray) -> np.ndarray:
        """G u̇ + K_c (x − x_s) on all DOFs (flat), for flat X, V, x_s. [N]"""
        return self.G @ V + self.Kc @ (X - x_static)

    def jacobian_band(self, c2: float, fr: slice) -> np.ndarray:
        """Band of ∂(force)/∂Δu of a Newmark step with u̇ = c2·Δu + …, free columns."""
        return (c2 * self.G_band + self.Kc_band)[:, fr]


def transport_terms(model: Any, speed: float) -> TransportTerms:
    """The transport matrices of a :class:`~stochcable.reference.cable_model.LineModel`.

    Parameters
    ----------
    model : LineModel
        The time-domain model (its static shape ``x_static``, mesh and assembly).
    speed : float
        Axial speed c, positive from end_a to end_b. [m/s]

    Returns
    -------
    TransportTerms
    """
    c = float(speed)
    d = model.dim
    length = np.linalg.norm(np.diff(model.x_static, axis=0), axis=1)
    m = model.mesh.mass * model.l0 / length
    eye = np.eye(d)[None]
    g_el = expand_blocks((m * c)[:, None, None] * eye, GYRO_PATTERN)
    kc_el = expand_blocks((-m * c * c / length)[:, None, None] * eye, STIFFNESS_PATTERN)
    return TransportTerms(
        speed=c,
        G=model.sparse_matrix(g_el, None),
        Kc=model.sparse_matrix(kc_el, None),
        G_band=model.band_matrix(g_el, None),
        Kc_band=model.band_matrix(kc_el, None),
        mass_per_length=m,
    )


def check_transport_speed(terms: TransportTerms, tension: np.ndarray, name: str) -> None:
    """InputError when |c| reaches √(T/m) of an element of the static start.

    Parameters
    ----------
    terms : TransportTerms
    tension : ndarray, shape (n_el,)
        Static element tension. [N]
    name : str
        Line name, for the message.
    """
    ratio = np.maximum(tension, 0.0) / terms.mass_per_length
    j = int(np.argmin(ratio))
    crit = float(np.sqrt(ratio[j]))
    if abs(terms.speed) >= crit:
        raise InputError(
            "axial_speed",
            terms.speed,
            "m/s",
            f"|c| must be below the critical speed √(T/m) = {crit:.4g} m/s of line "
            f"'{name}' (element {j}): above it the travelling line diverges",
        )


def lift_nodal_forces(model: Any, e: np.ndarray, w: np.ndarray) -> np.ndarray | None:
    """Nodal forces of the steady lift of the relative flow in the time-domain model.

    Parameters
    ----------
    model : LineModel
        The time-domain model (its ``mesh.cl_steady``, quadrature, static shape).
    e : ndarray, shape (n_el, d)
        Element unit tangents the drag uses. [-]
    w : ndarray, shape (n_el, n_g, d)
        Relative velocity of the fluid and the material at the quadrature points,
        U + v − u̇ − c e. [m/s]

    Returns
    -------
    ndarray, shape (n_nodes, d), or None
        The consistent nodal forces l0 Σ_g w_g N_a f_L(w_g) [N]; None without lift
        (no coefficient, or a planar model: no lift in the plane).

    Notes
    -----
    f_L = ½ρC_L D |w|² (ẑ·m̂) m̂, m̂ ∥ e × w_n (:func:`stochcable.line.transport.
    relative_flow.steady_lift_force`), evaluated with the instantaneous relative flow,
    on the elements whose static midpoint is under water (as the frequency-domain
    model, whose dry elements see no current); no Jacobian (the Newton iterations
    converge on the drag's).
    """
    cl = getattr(model.mesh, "cl_steady", None)
    if cl is None or model.dim != 3 or not np.any(cl):
        return None
    wet = 0.5 * (model.x_static[:-1, 2] + model.x_static[1:, 2]) <= 0.0
    coef = 0.5 * model.rho * cl * model.mesh.diameter * wet
    ne, ng, d = w.shape
    ee = np.repeat(e, ng, axis=0)
    c = model.speed
    f = steady_lift_force(ee, w.reshape(-1, d) + c * ee, c, np.repeat(coef, ng))
    nodal = model.l0[:, None, None] * np.einsum(
        "g,ga,egd->ead", model.gauss_w, model.gauss_N, f.reshape(ne, ng, d)
    )
    out = np.zeros((ne + 1, d))
    out[:-1] += nodal[:, 0]
    out[1:] += nodal[:, 1]
    return out
