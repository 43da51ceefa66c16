"""The transport terms of a travelling line in the frequency-domain engine.

A line whose material travels at speed c along its static shape
(:mod:`stochcable.line.transport.matrices`) has the small-motion impedance

    Z(ω) = K + K_c − ω² M_T + iω (C + G),

with the symmetric centripetal stiffness K_c (the effective tension T − m c²) and the
skew-symmetric gyroscopic matrix G, whose element block is m c [[0, 1], [−1, 0]] ⊗ I.
The engine's node blocks (:mod:`stochcable.dynamics.model.blocks`) hold symmetric
matrices, so the two enter differently:

- K_c is symmetric: it is added to the model's K (:func:`travelling_system`), and every
  stage that reads K (loads of the moving ends, reactions, conditioning) has it;
- G is not: the line keeps the per-element coefficient g = m c (:attr:`LineSystem.gyro`)
  and the direct solve adds its free–free band (:func:`gyro_band`: the stacked banded
  LU, LAPACK ``gbsv``, is a general one, factored once per frequency), the load of the
  prescribed end motion (:func:`gyro_end_load`) and the reaction rows
  (:func:`gyro_end_rows`).  A travelling line is solved by the direct solve (the Foss
  form of the engine assumes symmetric matrices; the complex modes with left
  eigenvectors are in :mod:`stochcable.line.transport.modes`, the check of this solve).

The drag is linearized about the relative flow of the fluid and the *material*,
U − c e (Hu & Jin 2001, eq. 6): the line's mean current at the elements becomes
U − c e, so the axial drag acts on U_t − c as in the statics; the normal drag is
unchanged (c e has no normal component).

References
----------
Wickert, J. A. & Mote, C. D. (1990), Classical vibration analysis of axially moving
continua, Journal of Applied Mechanics 57, 738–744, eq. 1.

Hu, H. Y. & Jin, D. P. (2001), Non-linear dynamics of a suspended travelling cable
subject to transverse fluid excitation, Journal of Sound and Vibration 239(3),
515–529, eq. 6.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from stochcable.dynamics.model.solvers import band_from_blocks
from stochcable.line.fem import FEModel
from stochcable.line.transport.matrices import transport_matrices

__all__ = ["travelling_system", "gyro_band", "gyro_end_load", "gyro_end_rows"]


def travelling_system(
    model: FEModel, speed: float, tangents: np.ndarray, current_el: np.ndarray
) -> tuple[FEModel, np.ndarray, np.ndarray]:
    """The model, relative flow and gyroscopic coefficients of a travelling line.

    Parameters
    ----------
    model : FEModel
        The line's model about its static shape.
    speed : float
        Axial speed c, positive from end_a to end_b (below the critical speed). [m/s]
    tangents : ndarray, shape (n_el, 3)
        Element unit tangents, global frame. [-]
    current_el : ndarray, shape (n_el, 3)
        Current at the element midpoints. [m/s]

    Returns
    -------
    (FEModel, ndarray, ndarray)
        The model with K + K_c; the relative flow U − c e at the elements (n_el, 3)
        [m/s]; g = m c per element (n_el,), G's element block g [[0, 1], [−1, 0]] ⊗ I
        [N·s/m].
    """
    tr = transport_matrices(model, speed)
    return (
        replace(model, K=tr.K),
        current_el - tr.speed * tangents,
        tr.mass_per_length * tr.speed,
    )


def gyro_band(gyro: np.ndarray, d: int) -> np.ndarray:
    """LAPACK band storage (half-bandwidth 2d − 1) of the free–free block of G.

    Parameters
    ----------
    gyro : ndarray, shape (n_el,)
        g = m c per element. [N·s/m]
    d : int
        Components per node.

    Returns
    -------
    ndarray, shape (4d − 1, (n_el − 1)·d)
        G_ff in the band layout of :func:`~stochcable.dynamics.model.blocks.free_band`.
    """
    n_f = gyro.size - 1  # interior nodes 1 … n_el − 1
    eye = np.eye(d)[None]
    diag = np.zeros((n_f, d, d))
    lower = np.zeros((n_f, d, d))
    upper = np.zeros((n_f, d, d))
    # free node k is node k + 1: G[k+1, k] = −g_k (element k), G[k+1, k+2] = +g_{k+1}
    lower[1:] = -gyro[1:-1, None, None] * eye
    upper[:-1] = gyro[1:-1, None, None] * eye
    return band_from_blocks((diag, lower, upper))


def gyro_end_load(gyro: np.ndarray, ub: np.ndarray, omega: np.ndarray) -> np.ndarray:
    """The free-node load −iω (G U_p)_f of the prescribed end motion.

    Parameters
    ----------
    gyro : ndarray, shape (n_el,)
        g = m c per element. [N·s/m]
    ub : ndarray, complex, shape (2, d, n_w, n_ch)
        End motion of end_a and end_b. [m/unit]
    omega : ndarray, shape (n_w,)
        [rad/s]

    Returns
    -------
    (ndarray, ndarray)
        The load on the first and on the last free node, each (d, n_w, n_ch). [N/unit]
    """
    iw = (1j * omega)[:, None]
    # (G U_p) at node 1 = G[1, 0] u_a = −g_0 u_a; at node n − 2: G[n−2, n−1] u_b = g_last u_b
    return iw * gyro[0] * ub[0], -iw * gyro[-1] * ub[1]


def gyro_end_rows(
    gyro: np.ndarray, u_next: tuple[np.ndarray, np.ndarray], omega: np.ndarray
) -> np.ndarray:
    """iω (G U) at the end nodes' rows, to add to the reactions' impedance rows.

    Parameters
    ----------
    gyro : ndarray, shape (n_el,)
        g = m c per element. [N·s/m]
    u_next : (ndarray, ndarray)
        Displacement of node 1 and node n − 2, each (d, n_w, n_ch). [m/unit]
    omega : ndarray, shape (n_w,)
        [rad/s]

    Returns
    -------
    (ndarray, ndarray)
        Rows of end_a and end_b, each (d, n_w, n_ch). [N/unit]
    """
    iw = (1j * omega)[:, None]
    # (G U) at node 0 = G[0, 1] u_1 = g_0 u_1; at node n − 1 = G[n−1, n−2] u_{n−2} = −g_last u
    return iw * gyro[0] * u_next[0], -iw * gyro[-1] * u_next[1]
