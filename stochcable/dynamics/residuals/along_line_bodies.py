"""The residuals in the element tensions of a line on free bodies: the element tensions
per unit node force through the coupled (lines and bodies) group, as
:mod:`.body_residual` gives the end tensions'.

A load F on the line with its ends held gives the element tensions r_e·A⁻¹F_f (the
adjoint of :func:`~stochcable.dynamics.residuals.along_line.element_influence`) and
the support forces G_R F (G_R: e_i on the end nodes, −x_i on the free nodes, x_i =
A⁻¹Z_f,end e_i, :func:`~stochcable.dynamics.residuals.body_residual.end_solves`).
The bodies answer them, S ξ = T_Lᵀ(G_R F)_att (S condensed over the group's lines as
in :class:`~stochcable.dynamics.residuals.body_residual.CoupledInfluence`), and move
the attached ends by u_end = T_L ξ; the line follows with its free nodes at −Σ_i x_i
u_end,i, so element e's tension changes by c_e·u_end, c_e,i = r_e·(the node motion of
a unit end motion i).  Per unit node force the element's coupled influence is then

    g_e = A⁻ᵀr_e + G_Rᵀ y_e,   y_e = E_attᵀ T_L S⁻¹ T_Lᵀ E_att c_e

(:class:`ElementCoupledInfluence`), with the shape and ``on`` of the stations'
influence of :mod:`.along_line`: the residual kinds' captured loads pass through it
unchanged (:func:`~stochcable.dynamics.residuals.along_line.along_line_residual`
``influence_of``): each line's records carry its own residual loads; the other lines'
and the cross terms are the group's part (:mod:`.group_motion`).

Validation: against the assembled coupled system loaded by the same node forces
(tests/dynamics/test_along_line_bodies.py); the coupled end influence in place of
the elements' gives the kinds' end lines of the line on its bodies.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from stochcable.dynamics.residuals.along_line import element_influence, element_rows
from stochcable.dynamics.residuals.along_line_motion import node_influence
from stochcable.dynamics.residuals.body_residual import CoupledInfluence, end_solves

__all__ = [
    "ElementCoupledInfluence",
    "NodeCoupledInfluence",
    "node_station_influence",
    "station_influence",
]


class ElementCoupledInfluence(CoupledInfluence):
    """The tensions of ``elements`` of a line of a coupled group per unit force on
    each node and component of the line (module notes).

    Parameters
    ----------
    base : CoupledInfluence
        The line's coupled end influence (its group: lines, bodies, body drag).
    elements : ndarray of int
        The elements (indices).
    """

    def __init__(self, base: CoupledInfluence, elements: np.ndarray) -> None:
        super().__init__(base.name, base.lines, base.bodies, base.body_drag)
        self.elements = np.asarray(elements, dtype=int)
        self._grids: list[tuple[np.ndarray, np.ndarray]] = []

    def on(self, w: np.ndarray) -> np.ndarray:
        """The influence on ``w``, shape (n_el, n_nodes, d, n_w), kept for later
        requests of any of its frequencies. [N/N]"""
        w = np.asarray(w, dtype=float)
        for om, g in self._grids if w.size else ():
            at = np.clip(np.searchsorted(om, w), 0, om.size - 1)
            near = np.where(np.abs(om[at - 1] - w) < np.abs(om[at] - w), at - 1, at)
            if np.allclose(om[near], w, rtol=1e-12, atol=0.0):
                return g[..., near]
        g = self.compute(w)
        self._grids.append((w.copy(), g))
        return g

    def compute(self, w: np.ndarray) -> np.ndarray:
        """The influence on ``w`` (not kept), shape (n_el, n_nodes, d, n_w). [N/N]"""
        w = np.asarray(w, dtype=float)
        system = self.line.system
        held = self.held(w)
        off, nb = {}, 0
        for b in self.bodies:
            off[b.name] = nb
            nb += b.n_dof
        by_name = {b.name: b for b in self.bodies}
        t, att = self._link(self.line, by_name, off, nb)
        if not att.size:  # no end on a body: the ends-held influence
            return held
        s = self._body_impedance(w, off, nb)
        model = system.model
        d, n = model.dim, model.n_nodes
        x = np.zeros((w.size, n - 2, d, 2 * d), dtype=complex)  # (the line's: set below)
        for ln in self.lines:
            t_l, att_l = self._link(ln, by_name, off, nb)
            if not att_l.size:
                continue
            x_l, r_e = end_solves(ln.system, ln.damping, w)
            if ln.name == self.name:
                x = x_l
            s = s - t_l.T[None] @ r_e[:, att_l[:, None], att_l[None, :]] @ t_l[None]
        # node motion per unit end motion i: e_i on its end node, −x_i on the free nodes
        u = np.zeros((w.size, n, d, 2 * d), dtype=complex)
        u[:, 0, :, :d] = np.eye(d)
        u[:, -1, :, d:] = np.eye(d)
        u[:, 1:-1] = -x
        c = self.per_end_motion(u)  # (n_w, n_out, 2d)
        free = np.array([off[b.name] + i for b in self.bodies for i in b.free_index], int)
        tf = t[:, free]
        xi = np.linalg.solve(
            s[:, free[:, None], free[None, :]], np.broadcast_to(tf.T, (w.size,) + tf.T.shape)
        )  # (n_w, n_free, |att|)
        y = np.zeros((w.size, c.shape[1], 2 * d), dtype=complex)
        y[:, :, att] = self.through_bodies(c[:, :, att], tf, xi, free)
        g = held
        g[:, 0] += np.transpose(y[:, :, :d], (1, 2, 0))
        g[:, -1] += np.transpose(y[:, :, d:], (1, 2, 0))
        g[:, 1:-1] -= np.einsum("wei,wnki->enkw", y, x)
        return g

    def through_bodies(
        self, c: np.ndarray, tf: np.ndarray, xi: np.ndarray, free: np.ndarray
    ) -> np.ndarray:
        """The outputs (n_w, n_out, |att|) per unit support force on the attached ends
        through the bodies: ``c`` (n_w, n_out, |att|) per unit end motion, ``tf`` the
        rigid links on the free body DOFs ``free`` (group-wide indices), ``xi``
        (n_w, n_free, |att|) the free DOFs per unit support force."""
        return c @ tf[None] @ xi

    def held(self, w: np.ndarray) -> np.ndarray:
        """The outputs per unit node force with the ends held, (n_out, n_nodes, d, n_w)."""
        return element_influence(self.line.system, self.line.damping, w, self.elements)

    def per_end_motion(self, u: np.ndarray) -> np.ndarray:
        """The outputs (n_w, n_out, 2d) of the node motions ``u`` (n_w, n_nodes, d, 2d)
        per unit motion of each end component."""
        rows = element_rows(self.line.system.model)[self.elements]
        el = self.elements
        return np.einsum("ed,wedi->wei", rows[:, 0], u[:, el]) + np.einsum(
            "ed,wedi->wei", rows[:, 1], u[:, el + 1]
        )


class NodeCoupledInfluence(ElementCoupledInfluence):
    """The displacements of ``nodes`` (node-major, the model's d components) of a line
    of a coupled group per unit force on each node and component of the line (module
    notes, with the node rows in place of the element tensions'; ``elements`` holds
    the nodes). [m/N]"""

    def held(self, w: np.ndarray) -> np.ndarray:
        """The displacements per unit node force with the ends held,
        (n_out, n_nodes, d, n_w) (:func:`.along_line_motion.node_influence`)."""
        return node_influence(self.line.system, self.line.damping, w, self.elements)

    def per_end_motion(self, u: np.ndarray) -> np.ndarray:
        """The nodes' displacements (n_w, n_out, 2d) per unit end motion."""
        return u[:, self.elements].reshape(u.shape[0], -1, u.shape[3])


def node_station_influence(base: CoupledInfluence) -> Callable[[np.ndarray], Any]:
    """The ``influence_of`` of
    :func:`~stochcable.dynamics.residuals.along_line_motion.motion_residual` for a line
    on free bodies: its station nodes' :class:`NodeCoupledInfluence`."""

    def make(nodes: np.ndarray) -> NodeCoupledInfluence:
        return NodeCoupledInfluence(base, nodes)

    return make


def station_influence(base: CoupledInfluence) -> Callable[[np.ndarray], Any]:
    """The ``influence_of`` of
    :func:`~stochcable.dynamics.residuals.along_line.along_line_residual` for a line on
    free bodies: its stations' :class:`ElementCoupledInfluence` through ``base``'s
    group."""

    def make(elements: np.ndarray) -> ElementCoupledInfluence:
        return ElementCoupledInfluence(base, elements)

    return make
