"""The ends' contraction of a kind's dense pair lines, compiled: Re Σ_{e ≤ f}
conj(T_e) G_ef T_f per line and output, G upper triangular in single precision (each
pair once: :class:`~stochcable.dynamics.residuals.residual_lines.PairLines`), summed
in double (:func:`upper_forms`).

G may also be upper triangular by blocks (the geometric residual's components of the
element pairs f ≥ e: :func:`upper_forms`' ``block``).  The NumPy path
(:func:`~stochcable.dynamics.residuals.residual_lines.dense_pair_outputs`) casts G to
double a cache-sized run of lines at a time and takes one matrix product per line over
the whole square, its zeros included; here each line's row of G is read once, in
place, over its nonzero part only (the chain's drag ends: 1.2 → 0.6 ms).  The same
sums in another order: equal to round-off (tests/dynamics/test_pair_form_kernels.py).

Used only in a process that has loaded numba already (a banded line's LU, the
taut and deep wires): importing numba and the kernel costs the chain's first
analysis ≈ 0.5 s against ≈ 1 ms per analysis.  Imported lazily; compiled with
``cache=True`` (:func:`stochcable.compiled.jit_cached`).
"""

from __future__ import annotations

import numpy as np
from numba import types

from stochcable.compiled import jit_cached

__all__ = ["upper_forms"]


def _forms(g, t, block, out):  # noqa: ANN001 - numba kernel
    """out[o, j] = Re Σ_e conj(t[j, o, e]) Σ_f g[j, e, f] t[j, o, f] over the f whose
    place in their block of ``block`` columns is at least e's in its block, g (n_o,
    2·n·n) float32 (interleaved complex), t (n_o, n_out, 2·n) float64 (interleaved
    complex)."""
    n_o = g.shape[0]
    n_out = t.shape[1]
    n = t.shape[2] // 2
    for j in range(n_o):
        for o in range(n_out):
            total = 0.0
            for e in range(n):
                sr = 0.0
                si = 0.0
                row = 2 * e * n
                for start in range(e % block, n, block):
                    for f in range(start, start + block - e % block):
                        gr = np.float64(g[j, row + 2 * f])
                        gi = np.float64(g[j, row + 2 * f + 1])
                        tr = t[j, o, 2 * f]
                        ti = t[j, o, 2 * f + 1]
                        sr += gr * tr - gi * ti
                        si += gr * ti + gi * tr
                total += t[j, o, 2 * e] * sr + t[j, o, 2 * e + 1] * si
            out[o, j] = total


_SIGNATURE = types.void(
    types.Array(types.float32, 2, "C", readonly=True),
    types.Array(types.float64, 3, "C", readonly=True),
    types.int64,
    types.Array(types.float64, 2, "C"),
)
"""(G's lines as float32 pairs, the transfer as float64 pairs, the block, the
outputs)."""

_kernel, _ = jit_cached(_forms, _SIGNATURE, "pair lines' end contraction")


def upper_forms(g_all: np.ndarray, transfer: np.ndarray, block: int | None = None) -> np.ndarray:
    """Re Σ_ef conj(T_e) G_ef T_f of outputs with transfer ``transfer`` (n_out, n, n_o)
    from the dense lines ``g_all`` (n_o, n·n), complex64, G_ef in column e·n + f, over
    the f whose place in their block of ``block`` columns (n by default: G upper
    triangular) is at least e's in its own (the geometric residual's components of
    the element pairs f ≥ e): G is zero at the others. Shape (n_out, n_o), summed in
    double."""
    n_out, n, n_o = transfer.shape
    g = np.ascontiguousarray(g_all, dtype=np.complex64).view(np.float32)
    t = np.ascontiguousarray(np.transpose(transfer, (2, 0, 1)), dtype=complex)
    out = np.empty((n_out, n_o))
    _kernel(g, t.view(float).reshape(n_o, n_out, 2 * n), int(block or n), out)
    return out
