"""The inputs of a line on a frequency subset of its grid: the quadrature weights that
stand for the full grid's trapezoid rule (:func:`interpolatory_weights`) and the line's
inputs sliced to the subset (:func:`subset_inputs`), for the coarse start of the drag
fixed point (:mod:`stochcable.dynamics.groups.coarse`).
"""

from __future__ import annotations

import numpy as np

from stochcable.dynamics.loads.channels import Channel
from stochcable.dynamics.model.blocks import trapezoid_weights
from stochcable.dynamics.model.system import LineSystem
from stochcable.dynamics.solve.line_loads import LineInputs
from stochcable.dynamics.solve.node_inputs import weighted_mean_square

__all__ = ["interpolatory_weights", "subset_inputs"]


def interpolatory_weights(omega: np.ndarray, idx: np.ndarray) -> np.ndarray:
    """Quadrature weights on the subset ``omega[idx]`` that stand for the full grid's
    trapezoid rule, (idx.size,). [rad/s]

    W = Pᵀq with q the trapezoid weights of ``omega`` and P (n_omega × n_sub) the local
    4-point Lagrange (cubic) interpolation from the subset (two nodes on each side,
    shifted inward at the ends; exact at the subset points): Σ_a W_a f(ω_a) =
    Σ_j q_j (Pf)(ω_j), the full-grid trapezoid sum of the interpolant of f.  f is
    reproduced wherever it is cubic over a stencil, so the error is O(H⁴) in the
    subset spacing H against O(H²) for the trapezoid rule on the subset (the
    (idx.size < 4) subsets use the highest order they allow)."""
    q = trapezoid_weights(omega)
    ws = omega[idx]
    n_sub = ws.size
    order = min(4, n_sub)
    pos = np.searchsorted(ws, omega)
    lo = np.clip(pos - order // 2, 0, n_sub - order)
    nodes = lo[:, None] + np.arange(order)  # (n_omega, order) stencil of each point
    x = ws[nodes]
    # Lagrange basis, vectorized over the frequencies and the stencil: the ratios
    # r_ab = (ω − x_b)/(x_a − x_b) (r_aa = 1), multiplied in the order b = 0, 1, …
    # (the same products as a loop over a and b)
    with np.errstate(divide="ignore", invalid="ignore"):
        r = (omega[:, None, None] - x[:, None, :]) / (x[:, :, None] - x[:, None, :])
    idx_a = np.arange(order)
    r[:, idx_a, idx_a] = 1.0
    basis = r[:, :, 0].copy()
    for b in range(1, order):
        basis *= r[:, :, b]
    return np.bincount(nodes.ravel(), weights=(q[:, None] * basis).ravel(), minlength=n_sub)


def subset_inputs(
    system: LineSystem,
    channels: tuple[Channel, ...],
    inp: LineInputs,
    idx: np.ndarray,
    keep: np.ndarray | None = None,
    quadrature: np.ndarray | None = None,
) -> LineInputs:
    """The inputs on the frequencies ``inp.omega[idx]``, weighted by
    :func:`interpolatory_weights` (the same layout as :func:`line_inputs`).

    Parameters
    ----------
    system : LineSystem
    channels : tuple of Channel
        The channels of ``inp`` (spectra; mean squares of hand-built channels).
    inp : LineInputs
        The inputs on the full grid.
    idx : ndarray of int
        The subset whose cubic interpolant the weights integrate.
    keep : ndarray of int, optional
        Rows of ``idx`` kept (default all): the weights and the mean squares stay
        those of the interpolant on ``idx``, the arrays are sliced at ``idx[keep]``
        (the frequencies of negligible weight left out).
    quadrature : ndarray, shape (idx.size,), optional
        ``interpolatory_weights(inp.omega, idx)`` when already computed.

    Returns
    -------
    LineInputs
    """
    comps = list(system.model.components)
    spectra = np.stack([c.spectrum for c in channels], axis=1)[idx]
    if quadrature is None:
        quadrature = interpolatory_weights(inp.omega, idx)
    weights = quadrature[:, None] * spectra
    square = None
    for i, ch in enumerate(channels):
        if (
            ch.element_velocity is None
            and ch.element_velocity_parts is None
            and ch.velocity is None
        ):
            continue  # as line_inputs: the mean square goes with the element moments
        sq = weighted_mean_square(ch, weights[:, i], comps, idx)
        square = sq if square is None else square + sq
    if keep is not None:
        idx, weights = idx[keep], weights[keep]

    def take(a: np.ndarray | None, axis: int) -> np.ndarray | None:
        return None if a is None else np.take(a, idx, axis=axis)

    sub = inp.subset(idx, weights, square)
    # The drag-independent, per-frequency arrays the full grid has already computed
    # (:func:`end_following_at`, :func:`base_load`, the attachments' velocity of
    # :func:`drag_inputs`, the kept moments and inertia load, where kept) are the same
    # numbers at the subset's frequencies: sliced, not recomputed.

    for key, val in inp.cache.items():
        name = key if isinstance(key, str) else key[0]
        if name in ("moments", "drag_moments"):
            sub.cache[key] = take(val, 3)
        elif name in ("inertia", "base_load", "attached_velocity", "following"):
            sub.cache[key] = take(val, 2)
    return sub
