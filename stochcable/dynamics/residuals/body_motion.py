"""The residuals of the linear model in the motions of free bodies: the body DOFs'
variance the lines' residual loads add, through the coupled group.

A load F on a line of the group moves the free body DOFs by ξ = S⁻¹T_Lᵀ(G_R F)_att
(:mod:`.along_line_bodies`, module notes): the rows of the reference-point DOFs are
:class:`BodyCoupledInfluence` (the outputs ξ in place of the element tensions'
c_e·T_L ξ; zero with the ends held).  A line end node attached to a body moves by
T_L ξ, so its residual motion is the body's carried to the attachment point by
rigid-body kinematics (translation + rotation × arm).  Each line's captured residual
loads pass through these rows as through its node stations
(:func:`~stochcable.dynamics.residuals.along_line_motion.motion_lines`, the misfits,
a 3-D line's drag parts), for a group of one line (its loads are the group's); the
body's residual variance is added to the linear variance (uncorrelated with the
linear response).  A line whose node motions carry no residual (not computed,
out of range) lends none, so a body and its lines' end nodes agree.  A group of
several lines: :mod:`.group_motion` (the body DOFs as rows of the joint sums over
every line's loads, their cross terms included).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from stochcable.dynamics.residuals.along_line import CELL_BENDS, misfit_lines, top_line
from stochcable.dynamics.residuals.along_line_3d import vector_parts
from stochcable.dynamics.residuals.along_line_bodies import ElementCoupledInfluence
from stochcable.dynamics.residuals.along_line_motion import motion_cells, motion_lines
from stochcable.dynamics.residuals.body_residual import CoupledInfluence

__all__ = ["BodyCoupledInfluence", "body_motion_parts", "body_rows"]


def body_rows(bodies: Any) -> dict[str, np.ndarray]:
    """The rows (group-wide DOF indices, in the group's body order) of each body."""
    out, nb = {}, 0
    for b in bodies:
        out[b.name] = np.arange(nb, nb + b.n_dof)
        nb += b.n_dof
    return out


class BodyCoupledInfluence(ElementCoupledInfluence):
    """The DOFs of every body of a coupled group (group order, each body's reference
    point DOFs) per unit force on each node and component of one line of it (module
    notes). [m/N, rad/N]

    Parameters
    ----------
    base : CoupledInfluence
        The line's coupled end influence (its group: lines, bodies, body drag).
    """

    def __init__(self, base: CoupledInfluence) -> None:
        nb = sum(b.n_dof for b in base.bodies)
        super().__init__(base, np.arange(nb))

    def held(self, w: np.ndarray) -> np.ndarray:
        """Zero: with the line's ends held the bodies do not move."""
        model = self.line.system.model
        return np.zeros((self.elements.size, model.n_nodes, model.dim, np.size(w)), dtype=complex)

    def per_end_motion(self, u: np.ndarray) -> np.ndarray:
        """Unused (:meth:`through_bodies` gives the DOFs): zeros (n_w, nb, 2d)."""
        return np.zeros((u.shape[0], self.elements.size, u.shape[3]), dtype=complex)

    def through_bodies(
        self, c: np.ndarray, tf: np.ndarray, xi: np.ndarray, free: np.ndarray
    ) -> np.ndarray:
        """The body DOFs (n_w, nb, |att|) per unit support force: ``xi`` on the free
        DOFs, zero on the held ones."""
        out = np.zeros((xi.shape[0], self.elements.size, xi.shape[2]), dtype=complex)
        out[:, free] = xi
        return out


def body_motion_parts(
    system: Any,
    damping: Any,
    applied: Mapping[str, Any],
    taps: Mapping[str, Any],
    influence: BodyCoupledInfluence,
    transfer: np.ndarray,
    spectra: np.ndarray,
) -> list[tuple[np.ndarray, np.ndarray]]:
    """The variance lines of the group's body DOFs driven by one line's ``applied``
    residual records (by kind) from what their ``taps`` collected, as
    :func:`~stochcable.dynamics.residuals.along_line_motion.motion_residual` forms a
    node's: parts (frequencies [rad/s] (n,), variance (nb, n) [m², rad²]).

    ``transfer``: the group's linear body DOF transfer (n_ch, nb, n_w) on the line's
    channels (the misfits' cross term); ``spectra`` (n_ch, n_w) their spectra."""
    eye = np.eye(influence.elements.size)
    parts: list[tuple[np.ndarray, np.ndarray]] = []

    def linear() -> np.ndarray:
        return transfer

    for kind, rec in applied.items():
        tap = taps.get(kind)
        if getattr(tap, "vectors", None) and not tap.unmatched:  # a 3-D line's drag
            parts += list(
                vector_parts(
                    system, damping, tap, influence, eye, top_line(rec), spectra, linear,
                    motion_cells,
                )
            )  # fmt: skip
            continue
        caps = [] if tap is None or tap.unmatched or kind not in CELL_BENDS else tap.captures
        if not caps:
            continue
        w_lines = np.asarray(caps[0].w, dtype=float)
        parts.append((w_lines, motion_lines(system, damping, kind, caps, influence, top_line(rec))))
        for mis in tap.misfits:
            dv = misfit_lines(system, damping, mis, w_lines, influence, transfer, spectra)
            parts.append((mis[2], dv))
    return parts
