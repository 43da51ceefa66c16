"""The drag residual of a 3-D line in its element tensions: the vector drag residual's
force cross-spectral lines (:mod:`.drag_residual_3d`, the bivariate expansion of
c|v|v) contracted with the element tensions per unit panel force instead of the end
tensions'.

:func:`~stochcable.dynamics.residuals.drag_residual_3d.vector_residual_output_lines`
forms the panels' residual force cross-spectra G_ef(ω_j) block by block and contracts
each block with the end tensions per unit force, Var_j = Re Σ_ef conj(T_e) G_ef T_f;
with a tap active (:data:`~stochcable.dynamics.residuals.residual_lines.RESIDUAL_TAP`)
the blocks are kept (:meth:`VectorTapMixin.vector`) and contracted here with any
other outputs' influence (:func:`vector_lines`: the element tensions at the stations
of :mod:`.along_line`, from the same adjoint solve): no second pass of the Hermite
covariances, which are the residual's cost.  The seed form's linear misfit δB·v
(correlated with the linear response) enters with its cross term on the analysis
grid, solved at every frequency as the ends' (:func:`vector_misfit_lines`).  With the
end influence in place of the elements' the same steps give the kind's end lines to
round-off (tests/dynamics/test_along_line_3d.py).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy import sparse

from stochcable.dynamics.model.blocks import trapezoid_weights
from stochcable.dynamics.residuals.drag_residual import cell_factor
from stochcable.dynamics.residuals.influence import ModalRows

__all__ = [
    "VectorCapture",
    "VectorTapMixin",
    "sparse_transfer",
    "vector_lines",
    "vector_misfit_lines",
    "vector_parts",
]


@dataclass
class VectorCapture:
    """One evaluation of the 3-D drag residual's force cross-spectra: its output lines
    ``w`` [rad/s] (n_o,), its panel loads ``unit`` (n_nodes, d, 3·n_p; columns
    direction-major: n₁, n₂, t), the blocks (g, e, f) of
    :func:`~stochcable.dynamics.residuals.drag_residual_3d.vector_residual_output_lines`
    (g (n_o, 3·n_b, 3·n_f) panel-major, pairs weighted; panels e, f as slices) and the
    end ``transfer`` they were contracted with (the evaluation's mark)."""

    w: np.ndarray
    unit: np.ndarray
    blocks: list[tuple[np.ndarray, slice, slice]]
    transfer: np.ndarray


class VectorTapMixin:
    """The 3-D drag residual's part of a residual tap: ``vectors`` collects a
    :class:`VectorCapture` per evaluation, its loads and lines those of the tap's last
    :meth:`loads` whose transfer the blocks' end ``transfer`` is."""

    vectors: list[VectorCapture]
    unmatched: int
    _loads: list[tuple[np.ndarray, np.ndarray, np.ndarray]]

    def vector_block(self, g: np.ndarray, e: slice, f: slice, transfer: np.ndarray) -> None:
        """A block of
        :func:`~stochcable.dynamics.residuals.drag_residual_3d.vector_residual_output_lines`:
        its force cross-spectral lines ``g`` between panels ``e`` and ``f`` and the
        end ``transfer`` (n_out, n_p, 3, n_o) they were contracted with."""
        if not hasattr(self, "vectors"):
            self.vectors = []
        if not self.vectors or self.vectors[-1].transfer is not transfer:
            n_out, n_p, _, n_o = transfer.shape
            for unit, w, h in reversed(self._loads):  # (h: n_out, 3·n_p direction-major, n_o)
                if h.shape == (n_out, 3 * n_p, n_o) and np.array_equal(
                    np.transpose(h.reshape(n_out, 3, n_p, n_o), (0, 2, 1, 3)), transfer
                ):
                    self.vectors.append(VectorCapture(w, unit, [], transfer))
                    break
            else:
                self.unmatched += 1
                return
        self.vectors[-1].blocks.append((g, e, f))


def sparse_transfer(g: np.ndarray, unit: np.ndarray) -> np.ndarray:
    """The outputs per unit load case (n_out, n_load, n_w) from the outputs per unit
    node force ``g`` (n_out, n_nodes, d, n_w) and the load cases ``unit`` (n_nodes,
    d, n_load), through the cases' nonzero entries only (a geometric force pair: two
    nodes of the line; the dense product of
    :func:`~stochcable.dynamics.residuals.residual_lines.load_transfer` costs every
    node per case: the 800-element chain's 1600 cases ×50). [unit/unit]"""
    n_out, n, d, n_w = g.shape
    flat = unit.reshape(n * d, -1)
    rows, cols = np.nonzero(flat)
    u = sparse.csr_matrix((flat[rows, cols], (cols, rows)), shape=(flat.shape[1], n * d))
    if isinstance(g, ModalRows):  # (through the modes: the rows never formed)
        return g.transfer(u)
    gf = np.transpose(g.reshape(n_out, n * d, n_w), (1, 0, 2)).reshape(n * d, n_out * n_w)
    return np.transpose(np.asarray(u @ gf).reshape(flat.shape[1], n_out, n_w), (1, 0, 2))


def vector_lines(
    system: Any,
    damping: Any,
    cap: VectorCapture,
    influence: Any,
    top_line: int | None = None,
    cells: Callable[..., np.ndarray] = cell_factor,
) -> np.ndarray:
    """The variance lines (n_out, n_o) on ``cap.w`` of the outputs of ``influence``
    (an object whose ``on(w)`` gives them per unit node force, (n_out, n_nodes, d,
    n_w)) driven by the vector drag residual of ``cap``; the lines from ``top_line``
    up left out (zero), the resonant cells integrated as the kind's
    (``cells``: :func:`~stochcable.dynamics.residuals.drag_residual.cell_factor`'s
    signature). [N²]"""
    top = cap.w.size if top_line is None else min(top_line, cap.w.size)
    w = cap.w[:top]
    if top == 0:  # no live line (the outputs' count from one frequency)
        return np.zeros((influence.on(cap.w[:1]).shape[0], cap.w.size))
    full = sparse_transfer(influence.on(w), cap.unit)  # (n_out, 3·n_p, top)
    n_out = full.shape[0]
    n_p = cap.unit.shape[2] // 3
    t = np.transpose(full.reshape(n_out, 3, n_p, top), (3, 2, 1, 0))  # (top, n_p, 3, n_out)
    out = np.zeros((n_out, cap.w.size))
    for g, blk, f_all in cap.blocks:
        t_f = t[:, f_all].reshape(top, -1, n_out)
        t_e = np.conj(t[:, blk]).reshape(top, -1, n_out)
        out[:, :top] += np.einsum("jek,jek->kj", t_e, g[:top] @ t_f).real
    out[:, :top] *= cells(system, damping, cap.unit, w, full, influence=influence)
    return out


def vector_misfit_lines(
    system: Any,
    damping: Any,
    misfit: tuple[np.ndarray, np.ndarray, np.ndarray],
    influence: Any,
    linear: np.ndarray,
    spectra: np.ndarray,
) -> np.ndarray:
    """The variance change (n_out, n_w) of the outputs of ``influence`` (their linear
    transfer ``linear`` (n_ch, n_out, n_w)) by the 3-D drag residual's linear misfit
    (its loads ``unit``, their values per unit input (n_ch, n_load, n_w) on the
    analysis grid ``w``), Σ_c q·S_c(|H_L + H_c|² − |H_L|²), the outputs per unit load
    solved at every frequency (as the ends'). [N²]"""
    unit, load, w = misfit
    h = sparse_transfer(influence.on(w), unit)  # (n_out, n_load, n_w)
    h_c = np.einsum("opw,cpw->cow", h, load)
    q = trapezoid_weights(w)[None, None] * spectra[:, None]
    return np.sum(q * (np.abs(linear + h_c) ** 2 - np.abs(linear) ** 2), axis=0)


def vector_parts(
    system: Any,
    damping: Any,
    tap: Any,
    influence: Any,
    weights: np.ndarray,
    top_line: int | None,
    spectra: np.ndarray,
    linear: Callable[[], np.ndarray],
    cells: Callable[..., np.ndarray] = cell_factor,
) -> tuple[tuple[np.ndarray, np.ndarray], ...]:
    """The parts (frequencies [rad/s], variance lines of every element (n_el, n) [N²])
    of a 3-D line's drag residual from what ``tap`` collected: each capture's
    :func:`vector_lines` and each misfit's :func:`vector_misfit_lines` at the stations
    of ``influence``, interpolated to the elements by ``weights`` (n_el, n_st);
    ``linear()`` the stations' linear transfer (n_ch, n_st, n_w); ``cells`` as
    :func:`vector_lines`'."""
    parts = [
        (c.w, weights @ vector_lines(system, damping, c, influence, top_line, cells))
        for c in tap.vectors
    ]
    lin = linear() if tap.misfits else None
    for m in tap.misfits:
        dv = vector_misfit_lines(system, damping, m, influence, lin, spectra)
        parts.append((m[2], weights @ dv))
    return tuple(parts)
