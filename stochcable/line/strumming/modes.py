"""The natural modes the strumming screening needs, from a line's FE model.

The screening (:func:`stochcable.line.strumming.screen.strumming_screen`) takes mode shapes as
global x, y, z displacements per node.  A 3-D model's modes are that already.  A 2-D
model (the in-plane x–z model of a planar scene) has no out-of-plane modes, but a
current in the plane of the line sheds vortices that lift it *out* of the plane; those
modes are added here from the out-of-plane part of the same FE model: the geometric
stiffness (T/l)·[[1, −1], [−1, 1]] per element (the elastic part EA e eᵀ has no
out-of-plane component for an in-plane element) with the consistent mass
m l0 [[1/3, 1/6], [1/6, 1/3]] plus the normal added mass Ca ρ πD²/4 the same way
(DESIGN.md "Finite elements"; Tuah (1982), eq. 3.1.12) and the attachments' lumped masses.

References
----------
Tuah, H. (1982), Cable dynamics in an ocean environment, PhD thesis, Oregon State University.
"""

from __future__ import annotations

import math

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp

from stochcable.line.fem import FEModel
from stochcable.line.modes import Modes

__all__ = ["modes_by_node", "out_of_plane_modes"]

#: Free nodes up to which the out-of-plane problem is solved densely (above: sparse
#: shift-invert Lanczos, the matrices being tridiagonal). [-]
_DENSE_MAX = 600


def modes_by_node(model: FEModel, modes: Modes) -> np.ndarray:
    """Mode shapes as global (x, y, z) per node.

    Parameters
    ----------
    model : FEModel
        The line model (2-D or 3-D).
    modes : Modes
        Its modes (shapes on the model DOFs, node-major).

    Returns
    -------
    ndarray, shape (n_nodes, 3, count)
        Shapes, zero in the components the model does not have. [kg^-1/2]
    """
    n = model.n_nodes
    shapes = np.asarray(modes.shapes).reshape(n, model.dim, -1)
    out = np.zeros((n, 3, shapes.shape[-1]))
    for j, comp in enumerate(model.components):
        out[:, comp, :] = shapes[:, j, :]
    return out


def out_of_plane_modes(model: FEModel, omega_max: float) -> tuple[np.ndarray, np.ndarray]:
    """Out-of-plane modes of a 2-D line model up to ``omega_max``.

    Parameters
    ----------
    model : FEModel
        A 2-D (x–z) model; the out-of-plane direction is global y.
    omega_max : float
        Highest natural frequency wanted. [rad/s]

    Returns
    -------
    omega : ndarray, shape (count,)
        Natural frequencies, ascending. [rad/s]
    shapes : ndarray, shape (n_nodes, 3, count)
        Shapes along y, normalized φᵀ M_T φ = 1. [kg^-1/2]
    """
    mesh = model.mesh
    n = model.n_nodes
    tension = np.where(model.slack, 0.0, np.maximum(model.tension, 0.0))
    kel = tension / model.length
    m_el = mesh.mass * mesh.l0
    ma_el = mesh.ca_normal * model.rho * math.pi * mesh.diameter**2 / 4.0 * mesh.l0
    mt = m_el + ma_el
    free_nodes = np.unique(np.asarray(model.free) // model.dim)
    top = float(omega_max) ** 2
    if free_nodes.size <= _DENSE_MAX:
        k, m = _tridiagonal(kel, kel, n), _tridiagonal(mt / 3.0, -mt / 6.0, n)
        m[np.diag_indices(n)] += mesh.node_mass + mesh.node_added_mass
        sub = np.ix_(free_nodes, free_nodes)
        mf = m[sub]
        lam, vec = sla.eigh(k[sub], mf, subset_by_value=(-np.inf, top))
    else:
        import scipy.sparse.linalg as spla  # (here: ~10 ms of import most analyses skip)

        i = np.arange(n - 1)
        rows = np.concatenate([i, i + 1, i, i + 1])
        cols = np.concatenate([i, i + 1, i + 1, i])
        ks = sp.csr_array((np.concatenate([kel, kel, -kel, -kel]), (rows, cols)), shape=(n, n))
        ms = sp.csr_array(
            (np.concatenate([mt / 3.0, mt / 3.0, mt / 6.0, mt / 6.0]), (rows, cols)),
            shape=(n, n),
        )
        ms = ms + sp.diags_array(mesh.node_mass + mesh.node_added_mass)
        kf, mf = ks[free_nodes][:, free_nodes], ms[free_nodes][:, free_nodes]
        count = 16
        while True:
            count = min(count, free_nodes.size - 1)
            lam, vec = spla.eigsh(kf.tocsc(), count, mf.tocsc(), sigma=-1e-6 * top, which="LM")
            order = np.argsort(lam)
            lam, vec = lam[order], vec[:, order]
            if lam[-1] > top or count >= free_nodes.size - 1:
                keep = lam <= top
                lam, vec = lam[keep], vec[:, keep]
                break
            count *= 2
    omega = np.sqrt(np.maximum(lam, 0.0))
    shapes = np.zeros((n, 3, omega.size))
    shapes[free_nodes, 1, :] = vec / np.sqrt(np.einsum("im,im->m", vec, mf @ vec))
    return omega, shapes


def _tridiagonal(diag_el: np.ndarray, off_el: np.ndarray, n: int) -> np.ndarray:
    """Dense n × n assembly of the two-node element matrices [[d, −o], [−o, d]] of a
    chain of n nodes."""
    out = np.zeros((n, n))
    idx = np.arange(n - 1)
    out[idx, idx] += diag_el  # each index once per statement: no np.add.at needed
    out[idx + 1, idx + 1] += diag_el
    out[idx, idx + 1] -= off_el
    out[idx + 1, idx] -= off_el
    return out
