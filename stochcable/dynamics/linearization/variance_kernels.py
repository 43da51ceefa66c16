"""The element variances of the drag fixed point as one compiled loop
(:func:`element_variance_terms`): what :func:`stochcable.dynamics.linearization.variance.
_element_variance` forms with NumPy as frequency blocks of projections and products.

Per element e, row r of the projection rows (tangent and normals), and column n (a
frequency and an input channel) it sums, with q_a, q_b = r·(−iω)(U_p + u_f) at the
element's two nodes and m_a, m_b = r·∫N_{a,b} v dξ the projected moments of the fluid
velocity,

    w_n [(|q_a|² + |q_b|² + Re(q̄_a q_b))/3 + 2 Re(m̄_a q_a + m̄_b q_b)],

in one pass over the response without temporaries (the NumPy form builds −iωU on all
nodes, its projections at both ends and their products; measured in
docs/benchmarks/dynamics.md, "Element variances").  The same sums in another order:
equal to round-off.

Imported lazily (numba's import is slow); compiled with ``cache=True``
(:func:`stochcable.compiled.jit_cached`).
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numba import types

from stochcable.compiled import jit_cached

__all__ = ["element_variance_terms"]


def _terms(pr, a, f, omega, wt, mom, mix, fch, n_ch, var):  # noqa: ANN001 - numba kernel
    """var[e, r] += the sums of the module docstring (a, f, mom empty: absent), with
    q = −iω·x: |q|² terms times ω², Re(m̄q) = ω·Im(m̄x); column n is frequency
    n // n_ch and channel n % n_ch, mom[i] the moments (n_el, 2, P, n_w) of channel
    fch[i] in P parts, mix[i] (d, P) the model components as their combinations."""
    n_el, k, d = pr.shape
    n_cols = omega.size
    has_a = a.shape[0] > 0
    n_fc = mom.shape[0]
    n_p = mom.shape[3]
    n_free = f.shape[0]
    xa = np.empty(d, dtype=np.complex128)
    xb = np.empty(d, dtype=np.complex128)
    acc_t = np.empty(k)
    acc_m = np.empty(k)
    for e in range(n_el):
        fa = e >= 1 and e - 1 < n_free  # node e is interior and u_f is given
        fb = e < n_free  # node e + 1 likewise
        acc_t[:] = 0.0
        acc_m[:] = 0.0
        for n in range(n_cols):
            for j in range(d):  # the displacement at the element's two nodes
                va = a[e, j, n] if has_a else 0j
                vb = a[e + 1, j, n] if has_a else 0j
                if fa:
                    va += f[e - 1, j, n]
                if fb:
                    vb += f[e, j, n]
                xa[j] = va
                xb[j] = vb
            w2 = wt[n] * omega[n] * omega[n]
            w1 = wt[n] * omega[n]
            c = n % n_ch
            iw = n // n_ch
            fm = -1  # the fluid channel of this column
            for i in range(n_fc):
                if fch[i] == c:
                    fm = i
            for r in range(k):
                qa = 0j
                qb = 0j
                for j in range(d):
                    qa += pr[e, r, j] * xa[j]
                    qb += pr[e, r, j] * xb[j]
                ar, ai, br, bi = qa.real, qa.imag, qb.real, qb.imag
                acc_t[r] += w2 * ((ar + br) * ar + br * br + (ai + bi) * ai + bi * bi)
                if fm >= 0:
                    ma = 0j
                    mb = 0j
                    for j in range(d):
                        va = 0j
                        vb = 0j
                        for p in range(n_p):
                            va += mix[fm, j, p] * mom[fm, e, 0, p, iw]
                            vb += mix[fm, j, p] * mom[fm, e, 1, p, iw]
                        ma += pr[e, r, j] * va
                        mb += pr[e, r, j] * vb
                    acc_m[r] += w1 * (ma.real * ai - ma.imag * ar + mb.real * bi - mb.imag * br)
        for r in range(k):
            var[e, r] += acc_t[r] / 3.0 + 2.0 * acc_m[r]


_C3 = types.Array(types.complex128, 3, "C", readonly=True)
_SIGNATURE = types.void(
    types.Array(types.float64, 3, "C", readonly=True),
    _C3,
    _C3,
    types.Array(types.float64, 1, "C", readonly=True),
    types.Array(types.float64, 1, "C", readonly=True),
    types.Array(types.complex128, 5, "A", readonly=True),
    types.Array(types.float64, 3, "C", readonly=True),
    types.Array(types.int64, 1, "C", readonly=True),
    types.int64,
    types.Array(types.float64, 2, "C"),
)
"""(rows, U_p, u_f, ω per column, weight per column, moments per fluid channel
(n_fc, n_el, 2, P, n_w), their mixing to the model components (n_fc, d, P), the fluid
channels, n_ch, var)."""

_kernel, _ = jit_cached(_terms, _SIGNATURE, "element variance")

_NONE3 = np.zeros((0, 0, 0), dtype=complex)
_NONE5 = np.zeros((0, 0, 2, 3, 0), dtype=complex)


def element_variance_terms(
    rows: np.ndarray,
    u_nodes: np.ndarray | None,
    u_free: np.ndarray | None,
    omega: np.ndarray,
    weights: np.ndarray,
    moments: Any,
    var: np.ndarray,
) -> None:
    """Add the response terms of the element mean squares to ``var`` (module docstring).

    Parameters
    ----------
    rows : ndarray, shape (n_el, k, d)
        Projection rows per element. [-]
    u_nodes : ndarray, complex, shape (n_nodes, d, n_w, n_ch), or None
        Displacement of every node (the ends' motion followed inside). [m/unit]
    u_free : ndarray, complex, shape (n_nodes − 2, d, n_w, n_ch), or None
        Displacement added on the interior nodes. [m/unit]
    omega : ndarray, shape (n_w,)
        Frequencies. [rad/s]
    weights : ndarray, shape (n_w, n_ch)
        σ² weights (quadrature × spectrum). [unit²·rad/s·s/rad]
    moments : ndarray, tuple or None
        Consistent moments ∫N_{a,b} v dξ of the fluid velocity: an array (n_el, 2, d,
        n_w, n_ch), or ``(views, mix, channels)`` with ``views`` (n_fc, n_el, 2, P,
        n_w) the moments of the channels ``channels`` in P parts in any memory layout
        (the sea's element-major parts, read in place) and ``mix`` (n_fc, d, P) the
        model's components as combinations of them; None: no fluid velocity.
        [m/s/unit]
    var : ndarray, shape (n_el, k)
        Accumulated in place. [m²/s²]
    """
    n_w, n_ch = weights.shape
    n = n_w * n_ch

    def flat(x: np.ndarray | None, empty: np.ndarray) -> np.ndarray:
        if x is None:
            return empty
        return np.ascontiguousarray(x, dtype=complex).reshape(*x.shape[: x.ndim - 2], n)

    if moments is None:
        views, mix, chans = _NONE5, np.zeros((0, 0, 0)), np.zeros(0, dtype=np.int64)
    elif isinstance(moments, tuple):
        views, mix, chans = moments
    else:  # (n_el, 2, d, n_w, n_ch): every channel, the model's components in order
        views = np.moveaxis(moments, 4, 0)
        mix = np.broadcast_to(np.eye(moments.shape[2]), (n_ch,) + (moments.shape[2],) * 2)
        chans = np.arange(n_ch)
    _kernel(
        np.ascontiguousarray(rows, dtype=float),
        flat(u_nodes, _NONE3),
        flat(u_free, _NONE3),
        np.repeat(np.asarray(omega, dtype=float), n_ch),
        np.ascontiguousarray(weights, dtype=float).ravel(),
        views,
        np.ascontiguousarray(mix, dtype=float),
        np.asarray(chans, dtype=np.int64),
        n_ch,
        var,
    )
