"""The statistically linearized drag of a rigid body at its drag point (Tuah 1982, eq.
5.2.2 form, with the current) and its damping on the body DOFs through the rigid link
of the drag point (Tuah 1982, eq. 3.3.6).

References
----------
Tuah, H. (1982), Cable dynamics in an ocean environment, PhD thesis, Oregon State University.
"""

from __future__ import annotations

import math

import numpy as np

from stochcable.bodies.rigid import PLANAR_INDEX, RigidBody, rigid_link_matrix
from stochcable.dynamics.linearization.formulas import drag_linear_current, drag_linear_harmonic

__all__ = ["body_drag_matrix", "linear_body_drag"]


def body_drag_matrix(body: RigidBody, b: np.ndarray) -> np.ndarray:
    """Linear drag at the drag point as a damping on the body DOFs.

    Parameters
    ----------
    body : RigidBody
        Its ``drag_point`` and ``planar``.
    b : ndarray, shape (3,)
        Linear drag coefficient per direction x, y, z. [N·s/m]

    Returns
    -------
    ndarray, shape (d, d)
        Tᵀ diag(b) T, T the rigid link of the drag point (Tuah 1982, eq. 3.3.6). [N·s/m, …]
    """
    t = rigid_link_matrix(body.drag_point)
    c = t.T @ (b[:, None] * t)
    if body.planar:
        c = c[np.ix_(PLANAR_INDEX, PLANAR_INDEX)]
    return c


def linear_body_drag(
    body: RigidBody, rho: float, sigma: np.ndarray, mean: np.ndarray, method: str
) -> tuple[np.ndarray, np.ndarray]:
    """Statistically linearized drag of a body at its drag point.

    Parameters
    ----------
    body : RigidBody
        ``drag_area`` (per direction) and ``drag_point``.
    rho : float
        Water density. [kg/m³]
    sigma : ndarray, shape (3,)
        σ of the relative velocity per direction. [m/s]
    mean : ndarray, shape (3,)
        Mean relative velocity (the current at the drag point). [m/s]
    method : str
        ``"harmonic"`` (amplitude √2·σ) or the current-aware stochastic form.

    Returns
    -------
    b : ndarray, shape (3,)
        Linear drag per direction (Tuah 1982, eq. 5.2.2 form). [N·s/m]
    c : ndarray, shape (d, d)
        :func:`body_drag_matrix` of ``b``.
    """
    if method == "harmonic":
        b = np.asarray(
            drag_linear_harmonic(rho, body.drag_area, 1.0, math.sqrt(2.0) * sigma), dtype=float
        )
    else:
        b = np.asarray(drag_linear_current(rho, body.drag_area, 1.0, sigma, mean), dtype=float)
    return np.broadcast_to(b, (3,)).copy(), body_drag_matrix(body, b)
