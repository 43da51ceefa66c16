"""The residuals' adjoint rows of a line by the banded solve: the end tensions per unit
node force (:func:`end_influence`) and any other output rows (:func:`adjoint_rows`),
through :class:`LineAdjoint`, which keeps the factors of Aᵀ at each frequency grid it
solved (compiled: :mod:`stochcable.dynamics.model.band_lu`) so that the element
tensions' and node motions' rows on the same lines are substitutions only
(:class:`~stochcable.dynamics.residuals.influence.EndInfluence`).  Without numba (or
``STOCHCABLE_NUMBA=0``, or a job below
:data:`~stochcable.compiled.KERNEL_MIN_ENTRIES`): LAPACK's stacked ``gbsv`` in stacks
of :func:`band_stack` frequencies, each set of rows refactored."""

from __future__ import annotations

from typing import Any

import numpy as np

from stochcable.dynamics.model.band_lu import BandFactors, band_factors, compiled_band_lu
from stochcable.dynamics.model.blocks import add_blocks, free_band, line_prep
from stochcable.dynamics.model.lift import lift_band, lift_pattern
from stochcable.dynamics.model.solvers import solve_band_stacked
from stochcable.dynamics.model.transport import gyro_band
from stochcable.dynamics.solve.line_loads import drag_blocks
from stochcable.dynamics.solve.line_solve import end_tension_from_support

__all__ = [
    "BAND_STACK_BYTES",
    "KEPT_FACTOR_BYTES",
    "LineAdjoint",
    "adjoint_rows",
    "band_stack",
    "end_coupling",
    "end_directions",
    "end_influence",
    "grid_indices",
]

#: Memory of one stack of frequencies of the banded solves by LAPACK (:func:`band_stack`):
#: a stack of many frequencies and right-hand sides outgrows the cache (the deep wire's
#: 2 + 23 rows on 189 lines: 5.9 ms in stacks of 16–32, 11 ms in stacks of 128; its 2
#: end rows alone: 1.6 ms in stacks of 64–128, 1.8 in 16). [bytes]
BAND_STACK_BYTES = 640 * 2**10


#: Memory of the LU factors :class:`LineAdjoint` keeps per frequency grid (the deep
#: wire's 189 lines: 1.2 MB); a grid whose factors need more (a long line solved
#: directly) is factored and solved in stacks within it, nothing kept (its other rows
#: then each solved on their own). [bytes]
KEPT_FACTOR_BYTES = 32 * 2**20


def band_stack(n_dof: int, d: int, r: int) -> int:
    """Frequencies per stacked banded solve of ``n_dof`` unknowns (blocks of ``d``) and
    ``r`` right-hand sides: its band storage and right-hand sides within
    :data:`BAND_STACK_BYTES` (at least 4)."""
    per = 16 * n_dof * (3 * (2 * d - 1) + 1 + r)
    return max(4, int(BAND_STACK_BYTES // per))


def grid_indices(om: np.ndarray, w: np.ndarray) -> np.ndarray | None:
    """The index of each of ``w`` in the sorted grid ``om`` (to 1e-12 relative), None
    where one is not in it."""
    if om.size == 0:
        return None if w.size else np.zeros(0, dtype=np.int64)
    at = np.clip(np.searchsorted(om, w), 0, om.size - 1)
    near = np.where(np.abs(om[at - 1] - w) < np.abs(om[at] - w), at - 1, at)
    return near if np.all(np.abs(om[near] - w) <= 1e-12 * np.abs(w)) else None  # (allclose's)


class LineAdjoint:
    """The adjoint system Aᵀ of a line with ``damping``, ends held (Aᵀ has C − G for a
    travelling line, C_Lᵀ with a steady lift), and the end rows' coupling: the rows of
    :func:`end_influence` and :func:`adjoint_rows` (:meth:`rows`), the factors of each
    compiled solve kept (:meth:`kept_rows`: other rows on the same frequencies by
    substitution only). ``entries``: the job's right-hand-side entries expected
    (n_w · n_free_dof · rows), which decides the compiled path
    (:func:`~stochcable.dynamics.model.band_lu.compiled_band_lu`)."""

    def __init__(self, system: Any, damping: Any, entries: int = 0) -> None:
        model = system.model
        self.system = system
        self.prep = prep = line_prep(system)
        self.d, self.n = model.dim, model.n_nodes
        self.cd = drag_blocks(system, damping)
        b_c = prep.bS + free_band(self.cd)
        if system.gyro is not None:  # a travelling line: Aᵀ has C − G (dynamics.model.transport)
            b_c = b_c - gyro_band(system.gyro, self.d)
        self.lift_t = None if system.lift is None else np.transpose(system.lift, (0, 2, 1))
        if self.lift_t is not None:  # a steady lift: Aᵀ has C_Lᵀ (dynamics.model.lift)
            b_c = b_c + lift_band(self.lift_t, lift_pattern(model))
        self.b_c = b_c
        self.entries = entries
        self._coupling: np.ndarray | None = None
        self._e_hat: tuple[np.ndarray, np.ndarray] | None = None
        self._factors: list[BandFactors] = []

    @property
    def e_hat(self) -> tuple[np.ndarray, np.ndarray]:
        """ê of each end (:func:`end_directions`), computed once."""
        if self._e_hat is None:
            self._e_hat = end_directions(self.system)
        return self._e_hat

    def coupling(self) -> np.ndarray:
        """The end rows' right-hand sides (:func:`end_coupling`), (3, n_f·d, 2)."""
        if self._coupling is None:
            c = add_blocks(self.prep.S, self.cd)
            self._coupling = end_coupling(self.system, self.prep, c, self.e_hat, self.lift_t)
        return self._coupling

    def _rhs(self, ws: np.ndarray, extra: np.ndarray | None, ends: bool) -> np.ndarray:
        """The right-hand sides on ``ws``: the end rows' −g (if ``ends``), then ``extra``."""
        k_x = 0 if extra is None else extra.shape[1]
        k_e = 2 if ends else 0
        rhs = np.empty((ws.size, (self.n - 2) * self.d, k_e + k_x), dtype=complex)
        if k_x:
            rhs[:, :, k_e:] = extra
        if ends:  # (signs: T = ê·F_end − (A⁻¹g)ᵀF_f)
            g = self.coupling()
            rhs[:, :, :2] = (
                (ws * ws)[:, None, None] * g[1][None] - g[0][None] - (1j * ws)[:, None, None] * g[2]
            )
        return rhs

    def _rows(self, x: np.ndarray, sl: Any, out: np.ndarray) -> None:
        """``x`` (n_w, n_f·d, k) into ``out`` (k, n, d, ·)[…, sl] on the free nodes."""
        n_w, _, k = x.shape
        out[:, 1:-1, :, sl] = np.transpose(x.reshape(n_w, self.n - 2, self.d, k), (3, 1, 2, 0))

    def _output(self, w: np.ndarray, extra: np.ndarray | None, ends: bool) -> np.ndarray:
        """The rows' array (2 + k or k, n, d, n_w), the end nodes' set (ê of the end
        rows, zero), the free nodes' left to the solve."""
        k_x = 0 if extra is None else extra.shape[1]
        out = np.empty(((2 if ends else 0) + k_x, self.n, self.d, w.size), dtype=complex)
        out[:, 0] = 0.0
        out[:, -1] = 0.0
        if ends:
            e_a, e_b = self.e_hat
            out[0, 0] = e_a[:, None]
            out[1, -1] = e_b[:, None]
        return out

    def _terms(self, extra: np.ndarray | None, ends: bool) -> np.ndarray:
        """The right-hand sides as T₀ − ω²T₁ + iωT₂, (3, n_f·d, 2 + k or k): the end
        rows' −g (if ``ends``), then ``extra`` (T₀ only)."""
        k_x = 0 if extra is None else extra.shape[1]
        k_e = 2 if ends else 0
        terms = np.zeros((3, (self.n - 2) * self.d, k_e + k_x), dtype=complex)
        if ends:  # (signs: T = ê·F_end − (A⁻¹g)ᵀF_f)
            terms[:, :, :2] = -self.coupling()
        if k_x:
            terms[0, :, k_e:] = extra
        return terms

    def rows(
        self, w: np.ndarray, extra: np.ndarray | None = None, ends: bool = True, kept: Any = None
    ) -> np.ndarray:
        """The end rows (if ``ends``) and the rows of ``extra`` ((n − 2)·d, k) on ``w``,
        shape (2 + k or k, n_nodes, d, n_w) (:func:`end_influence`); ``kept``: the
        factors holding ``w`` and its indices there, if known (:meth:`_kept`). [N/N]"""
        w = np.asarray(w, dtype=float)
        out = self._output(w, extra, ends)
        nf = (self.n - 2) * self.d
        if compiled_band_lu(max(self.entries, w.size * nf * out.shape[0])):
            kept = self._kept(w) if kept is None else kept
            step = max(1, KEPT_FACTOR_BYTES // (16 * nf * (3 * (2 * self.d - 1) + 1)))
            if kept is None and w.size > step:  # (a long line: in stacks, nothing kept)
                for sl in (slice(i, min(i + step, w.size)) for i in range(0, w.size, step)):
                    x = self._factor(w[sl]).solve_into(
                        self._terms(extra, ends),
                        np.empty((out.shape[0], nf, sl.stop - sl.start), dtype=complex),
                    )
                    out[:, 1:-1, :, sl] = x.reshape(out.shape[0], self.n - 2, self.d, -1)
                return out
            if kept is None:
                kept = (self._factor(w), None)
                self._factors.append(kept[0])
            flat = out.reshape(out.shape[0], self.n * self.d, w.size)  # (a view)
            kept[0].solve_into(self._terms(extra, ends), flat, kept[1], offset=self.d)
            return out
        step = band_stack(nf, self.d, max(out.shape[0], 1))
        for sl in (slice(i, min(i + step, w.size)) for i in range(0, w.size, step)):
            ws = w[sl]
            x = solve_band_stacked(
                self.prep.bK, self.prep.bM, self.b_c, self._rhs(ws, extra, ends), ws,
                2 * self.d - 1, 2 * self.d - 1, (self.system.model.K, self.system.model.M),
            )  # fmt: skip
            self._rows(x, sl, out)
        return out

    def _factor(self, w: np.ndarray) -> BandFactors:
        """Aᵀ factored on ``w`` by the compiled LU."""
        lo = 2 * self.d - 1
        mats = (self.system.model.K, self.system.model.M)
        return band_factors(self.prep.bK, self.prep.bM, self.b_c, w, lo, lo, mats)

    def _kept(self, w: np.ndarray) -> tuple[BandFactors, np.ndarray] | None:
        """The kept factors holding every frequency of ``w`` and their indices there."""
        for fac in self._factors:
            at = grid_indices(fac.omega, w)
            if at is not None:
                return fac, at
        return None

    def kept_rows(self, w: np.ndarray, extra: np.ndarray) -> np.ndarray | None:
        """The rows of ``extra`` on ``w`` by substitution in factors kept, shape (k,
        n_nodes, d, n_w); None where none hold ``w`` (no factorization here). [N/N]"""
        w = np.asarray(w, dtype=float)
        kept = self._kept(w)
        return None if kept is None else self.rows(w, extra, ends=False, kept=kept)

    def kept_transfer(
        self, w: np.ndarray, extra: np.ndarray, unit: np.ndarray
    ) -> np.ndarray | None:
        """The rows of ``extra`` on ``w`` per unit load case ``unit`` (n_nodes, d,
        n_load) (real node forces), shape (k, n_load, n_w), by substitution in factors
        kept, the rows contracted with the loads' nonzero entries as they are solved
        (never formed: as :func:`~.along_line_3d.sparse_transfer` of :meth:`kept_rows`,
        to round-off); None where none hold ``w``. [unit/unit]"""
        w = np.asarray(w, dtype=float)
        kept = self._kept(w)
        if kept is None or not compiled_band_lu(self.entries):
            return None
        d = self.d
        free = np.asarray(unit).reshape(self.n * d, -1)[d:-d]  # (the end nodes' rows: 0)
        out = np.empty((extra.shape[1], free.shape[1], w.size), dtype=complex)
        terms = self._terms(extra, ends=False)
        return kept[0].solve_into(terms, out, kept[1], loads=free.T)


def end_influence(
    system: Any, damping: Any, w: np.ndarray, extra: np.ndarray | None = None
) -> np.ndarray:
    """End tensions (end_a, end_b) per unit force on each node and component, ends
    prescribed, the line's linear system with ``damping``: shape (2, n_nodes, d, n_w).
    [N/N]

    ``extra`` ((n_nodes − 2)·d, k), optional: more adjoint right-hand sides r (constant
    in ω, on the free nodes), solved in the same factorization: rows 2 … 2 + k − 1 of
    the result are (A⁻ᵀr)ᵀ on the free nodes and zero on the end nodes (the outputs r·u
    per unit node force: the element tensions of :mod:`.along_line`).

    By the adjoint: with the ends held, T = ê·F_end − ê·Z_end,f u_f and u_f = A⁻¹F_f,
    A = Z_ff = K − ω²M + iωC the free–free impedance; A is symmetric (not Hermitian),
    so T = ê·F_end − (A⁻¹g)ᵀF_f, g = Z_f,end ê: two solves per frequency (one
    factorization) whatever the number of load cases.  A travelling line's A has the
    skew G (:mod:`stochcable.dynamics.model.transport`), a line with a steady lift the
    non-symmetric C_L (:mod:`stochcable.dynamics.model.lift`): then Aᵀ (C − G + C_Lᵀ) is
    solved, with g = Z_end,fᵀ ê (:class:`LineAdjoint`)."""
    return LineAdjoint(system, damping).rows(np.asarray(w, dtype=float), extra)


def adjoint_rows(system: Any, damping: Any, rhs: np.ndarray, w: np.ndarray) -> np.ndarray:
    """The adjoint system's solution for the right-hand sides ``rhs`` ((n − 2)·d, r) on
    ``w``, ends held, shape (r, n_nodes, d, n_w): each output row's answer per unit
    force on every node (Aᵀ as :func:`end_influence`'s, :class:`LineAdjoint`). [unit/N]"""
    return LineAdjoint(system, damping).rows(np.asarray(w, dtype=float), rhs, ends=False)


def end_directions(system: Any) -> tuple[np.ndarray, np.ndarray]:
    """ê of each end (d,): the end tension of a unit support force along each component."""
    d = system.model.dim
    eye = np.eye(2 * d)[None].astype(complex)
    ten = end_tension_from_support(system, eye)
    e_hat = [np.real(ten[end][:, 0]) for end in ("end_a", "end_b")]  # (2d,) each
    return e_hat[0][:d], e_hat[1][d:]


def end_coupling(
    system: Any, prep: Any, c: Any, e_hat: tuple[np.ndarray, np.ndarray], lift_t: Any
) -> np.ndarray:
    """The adjoint right-hand sides of the end rows, g = Z_end,fᵀ ê = g_K − ω²g_M + iωg_C,
    as (g_K, g_M, g_C) on the free DOFs: shape (3, (n_nodes − 2)·d, 2) (g_C complex
    where the transport or lift terms enter)."""
    model = system.model
    d, n = model.dim, model.n_nodes
    out = np.zeros((3, (n - 2) * d, 2), dtype=complex)
    o_first = [blk[1][0] for blk in (prep.K, prep.MT, c)]
    o_last = [blk[1][-1] for blk in (prep.K, prep.MT, c)]
    last = slice((n - 3) * d, None)
    for k, (o, vec, rows, tr) in enumerate(
        ((o_first, e_hat[0], slice(0, d), False), (o_last, e_hat[1], last, True))
    ):
        blocks = [b.T if tr else b for b in o]
        for j, b in enumerate(blocks):  # (d,) of K, M, C
            out[j, rows, k] = b @ vec
        if system.gyro is not None:  # Z_end,fᵀ ê: G[0, 1]ᵀ = g_0 I, G[n−1, n−2]ᵀ = −g I
            gy = system.gyro[-1 if tr else 0] * (-1.0 if tr else 1.0)
            out[2, rows, k] += gy * vec
        if lift_t is not None:  # C_L[0, 1]ᵀ ê_a, C_L[n−1, n−2]ᵀ ê_b
            cl = lift_pattern(model)[1, 0] * lift_t[-1 if tr else 0] @ vec
            out[2, rows, k] += cl
    return out
