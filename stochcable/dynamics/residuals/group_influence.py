"""The influences of a group's outputs per unit node force on any of its lines, from the
group's solves (:mod:`.group_motion`): the free bodies' DOFs (:class:`GroupBodyInfluence`)
and the element tensions and node motions at the stations of one line driven by forces
on another or itself (:class:`StationInfluence`).

A load F on line S moves the bodies by ξ = S⁻¹T_Sᵀ(G_R,S F)_att; line L's attached
ends follow by T_L ξ and its free nodes by −Σ_i x_i (T_L ξ)_i, so an output of L with
rows c per unit end motion changes by c_att·T_L ξ; with S = L the output's
ends-held influence adds (:mod:`.along_line_bodies` gives the same, L = S, in the
form G_Rᵀy).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from stochcable.dynamics.residuals.along_line_bodies import ElementCoupledInfluence
from stochcable.dynamics.residuals.body_residual import CoupledInfluence

__all__ = ["Fresh", "GroupBodyInfluence", "Rows", "StationInfluence", "station_body_rows"]


class _Kept:
    """An influence kept for the grids asked (``compute`` per new grid)."""

    def __init__(self) -> None:
        self._kept: list[tuple[np.ndarray, np.ndarray]] = []

    def on(self, w: np.ndarray) -> np.ndarray:
        """The influence on ``w``, shape (n_out, n_nodes, d, n_w)."""
        w = np.asarray(w, dtype=float)
        for om, g in self._kept:
            if om.size == w.size and np.array_equal(om, w):
                return g
        g = self.compute(w)
        self._kept.append((w.copy(), g))
        return g

    def compute(self, w: np.ndarray) -> np.ndarray:  # pragma: no cover (abstract)
        raise NotImplementedError

    def release(self) -> None:
        """Forget the kept grids (their arrays: n_out × n_nodes × d × n_w each)."""
        self._kept.clear()


class Fresh:
    """An influence's ``compute`` as its ``on``: nothing kept (a grid asked once)."""

    def __init__(self, of: _Kept) -> None:
        self.of = of
        self.line = of.line

    def on(self, w: np.ndarray) -> np.ndarray:
        """The influence on ``w``, not kept."""
        return self.of.compute(w)


class GroupBodyInfluence(_Kept):
    """The body DOFs of the group (group order; zero on the held ones) per unit force on
    each node and component of one line (as :class:`~.body_motion.BodyCoupledInfluence`)
    from the group's solves on each grid, shared by its lines (``state``: the group's
    body offsets, condensed impedance, links and end solves on a grid, as
    :class:`~.body_residual.CoupledInfluence` keeps them), kept for the grids asked.
    [m/N, rad/N]"""

    def __init__(self, base: CoupledInfluence, state: Callable[[np.ndarray], tuple]) -> None:
        super().__init__()
        self.base = base
        self.line = base.line
        self.state = state

    def compute(self, w: np.ndarray) -> np.ndarray:
        """ξ = S⁻¹T_Lᵀ(G_R F)_att per unit node force (module notes), not kept."""
        w = np.asarray(w, dtype=float)
        off, s, links, solved = self.state(w)
        model = self.line.system.model
        d, n = model.dim, model.n_nodes
        nb = s.shape[1]
        g = np.zeros((nb, n, d, w.size), dtype=complex)
        t, att = links[self.line.name]
        if not att.size:
            return g
        free = np.array([off[b.name] + i for b in self.base.bodies for i in b.free_index], int)
        tf = t[:, free]
        xi = np.linalg.solve(
            s[:, free[:, None], free[None, :]], np.broadcast_to(tf.T, (w.size,) + tf.T.shape)
        )  # (n_w, n_free, |att|)
        y = np.zeros((w.size, nb, 2 * d), dtype=complex)
        y[:, free[:, None], att[None, :]] = xi
        g[:, 0] = np.transpose(y[:, :, :d], (1, 2, 0))
        g[:, -1] = np.transpose(y[:, :, d:], (1, 2, 0))
        g[:, 1:-1] = -np.einsum("wei,wnki->enkw", y, solved[self.line.name][0])
        return g


class StationInfluence(_Kept):
    """The outputs of ``target`` (the element tensions or node motions at the stations
    of line L, an :class:`~.along_line_bodies.ElementCoupledInfluence` or
    :class:`~.along_line_bodies.NodeCoupledInfluence`: its ``held`` and
    ``per_end_motion``) per unit force on each node and component of line S, whose
    body influence is ``body``, from the group's solves ``state`` (module notes).
    [N/N, m/N]"""

    def __init__(
        self,
        target: ElementCoupledInfluence,
        body: GroupBodyInfluence,
        state: Callable[[np.ndarray], tuple],
    ) -> None:
        super().__init__()
        self.target = target
        self.body = body
        self.line = body.line
        self.state = state

    def compute(self, w: np.ndarray) -> np.ndarray:
        """c_att·T_L ξ per unit force on S (and L's ends-held rows where S = L)."""
        w = np.asarray(w, dtype=float)
        off, s, links, solved = self.state(w)
        tl = self.target.line
        d = tl.system.model.dim
        ms = self.line.system.model
        own = tl.name == self.line.name
        n_out = self.target.elements.size
        g = (
            self.target.held(w)
            if own
            else np.zeros((n_out * (d if _nodes(self.target) else 1), ms.n_nodes, ms.dim, w.size),
                          dtype=complex)
        )  # fmt: skip
        c = station_body_rows(self.target, (links, solved), w)  # (n_w, n_out, nb)
        if c is None:
            return g
        b = self.body.on(w)  # (nb, n_S, d, n_w)
        b_w = np.ascontiguousarray(np.moveaxis(b.reshape(b.shape[0], -1, w.size), 2, 0))
        cross = np.moveaxis(c @ b_w, 0, 2)  # (n_out, n_S·d, n_w)
        return g + cross.reshape(g.shape)


def station_body_rows(
    target: ElementCoupledInfluence, solves: tuple[dict, dict], w: np.ndarray
) -> np.ndarray | None:
    """The outputs of ``target`` (stations of line L) per unit motion of the group's
    body DOFs, c_att·T_L (module notes), from the group's ``solves`` on ``w`` (its
    links and end solves): shape (n_w, n_out, nb); None where L has no end on a
    body. [N/m, m/m]"""
    links, solved = solves
    tl = target.line
    model = tl.system.model
    d, n = model.dim, model.n_nodes
    t_l, att = links[tl.name]
    if not att.size:
        return None
    u = np.zeros((np.size(w), n, d, 2 * d), dtype=complex)
    u[:, 0, :, :d] = np.eye(d)
    u[:, -1, :, d:] = np.eye(d)
    u[:, 1:-1] = -solved[tl.name][0]
    return target.per_end_motion(u)[:, :, att] @ t_l[None]


def _nodes(target: ElementCoupledInfluence) -> bool:
    """Whether ``target`` gives node motions (d rows a node) rather than tensions."""
    return type(target).__name__ == "NodeCoupledInfluence"


class Rows:
    """Rows ``rows`` of an influence (zero-padded to two): an influence of two outputs,
    as the kinds' joint transfers take it."""

    def __init__(self, of: _Kept, rows: np.ndarray) -> None:
        self.of = of
        self.rows = rows
        self.line = of.line

    def on(self, w: np.ndarray) -> np.ndarray:
        """The two rows on ``w``, shape (2, n_nodes, d, n_w)."""
        g = self.of.on(w)
        out = np.zeros((2,) + g.shape[1:], dtype=complex)
        out[: self.rows.size] = g[self.rows]
        return out
