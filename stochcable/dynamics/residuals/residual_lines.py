"""Shared steps of the closed-form residuals of the linear model (:mod:`.drag_residual`,
:mod:`.geometric_residual`):
linear response quantities as spectral lines on a uniform grid, their cross-covariance
functions by FFT, covariance functions back to variance lines, and the end tensions per
unit load on the line.

The residuals are nonlinear functions of the jointly Gaussian linear response; their
cross-covariances are polynomials of the linear cross-covariances R(τ) (Mehler's formula,
Isserlis' theorem), i.e. sums of convolutions of the linear spectra.  On the periodic
lag grid of ``n_fft`` samples the convolutions are exact when ``n_fft`` exceeds twice
the highest line they reach.
"""

from __future__ import annotations

from collections.abc import Iterator
from contextvars import ContextVar
from typing import Any

import numpy as np

from stochcable.dynamics.model.blocks import trapezoid_weights
from stochcable.dynamics.residuals import influence as _influence
from stochcable.dynamics.residuals.influence import (
    BAND_STACK_BYTES,
    MODAL_SHARE,
    MODAL_SPAN,
    EndInfluence,
    ModalRows,
    SharedRows,
    band_stack,
    element_directions,
    end_influence,
    modal_influence,
    shared_rows,
)
from stochcable.results.records import ResidualRecord

__all__ = [
    "BAND_STACK_BYTES",
    "LIVE_SHARE",
    "MAX_LINES",
    "MODAL_SHARE",
    "MODAL_SPAN",
    "PAIR_BLOCK_BYTES",
    "RESIDUAL_TAP",
    "UniformGrid",
    "DENSE_PAIR_BYTES",
    "PairLines",
    "SharedRows",
    "along",
    "along_each",
    "band_stack",
    "covariance_lines",
    "dense_outputs",
    "dense_pair_outputs",
    "line_pair_outputs",
    "line_runs",
    "cross_covariance",
    "element_directions",
    "fft_length",
    "EndInfluence",
    "end_influence",
    "fill_lines",
    "ALONG_STRIDE",
    "STRIDE_TOL",
    "line_stride",
    "line_subset",
    "load_transfer",
    "modal_influence",
    "pair_blocks",
    "pair_lags",
    "pair_outputs",
    "residual_record",
    "shared_rows",
    "uniform_grid",
]

#: Most lines of the uniform grid the linear quantities are placed on (its step is the
#: analysis grid's smallest spacing, or ω_max/MAX_LINES if that is finer). [-]
MAX_LINES = 63
#: Memory of one block of pairs' lag functions: the block's transforms and products
#: stay in a core's cache (1 MB of L2 on the development host: blocks of 2 MB and more
#: ran 2–3× slower). [bytes]
PAIR_BLOCK_BYTES = 2**19
#: An observer of the residual loads (:mod:`.along_line`): None, or an object whose
#: ``loads(unit, w, h)`` :func:`load_transfer` and ``lines(g, transfer, e, f)``
#: :func:`pair_outputs` call with what they are given and return.
RESIDUAL_TAP: ContextVar[Any] = ContextVar("residual_tap", default=None)
#: Share of each channel's variance in the upper tail of the analysis grid left off the
#: uniform grid, whose lines then span the frequencies that carry the inputs (a log
#: grid to 100 rad/s put a sea's band on two lines: the chain's drag residual read 43 %
#: low; now within 5 % of a fine linear grid).  The lower tail stays (a small input
#: there moves the line far: the cable-laying line's geometric residual lost 6 % with
#: 1e-3 of both tails off), and 1e-5 already moved the inclined guy's σ by −0.8 %
#: (its lightly damped mode). [-]
LIVE_SHARE = 1e-6


class UniformGrid:
    """Lines ω_j = j·step, j = 0 … n_j − 1, that hold an analysis grid ``w`` (each
    frequency moved to its nearest line, its trapezoid weight kept).

    Frequencies sharing a line (a grid finer than the step) add their cross-spectra,
    not their amplitudes: each one of a line becomes its own channel (``ranks``).
    ``stride``: every stride-th line of that grid (a coarser grid whose lines are among
    its lines).  With the input ``spectra`` (n_ch, n_w), the frequencies in the tails
    of every channel (:data:`LIVE_SHARE`) are left off (``live`` False): the lines
    span the others only."""

    def __init__(
        self,
        w: np.ndarray,
        max_lines: int | None = None,
        stride: int = 1,
        spectra: np.ndarray | None = None,
    ) -> None:
        w = np.asarray(w, dtype=float)
        self.omega = w
        self.live = np.ones(w.size, dtype=bool)
        if spectra is not None and w.size > 1:
            energy = np.asarray(spectra, dtype=float) * trapezoid_weights(w)[None]
            total = energy.sum(axis=1, keepdims=True)
            share = energy / np.where(total > 0, total, np.inf)
            # each channel's upper tail of at most LIVE_SHARE of its variance left off
            # (not the lower one: a small input there can move the line far)
            from_above = np.cumsum(share[:, ::-1], axis=1)[:, ::-1]
            live = np.any(from_above >= LIVE_SHARE, axis=0)
            if live.any():
                self.live = live
        wl = w[self.live]
        steps = np.diff(w)
        top = MAX_LINES if max_lines is None else max_lines
        base = max(float(steps.min()) if steps.size else float(w[0]), float(wl[-1]) / top)
        self.step = stride * base
        self.n_j = int(np.rint(wl[-1] / self.step)) + 1
        self.index = np.clip(np.rint(w / self.step).astype(int), 0, self.n_j - 1)
        # each live frequency's place in its run of consecutive live ones on one line
        rank = np.zeros(w.size, dtype=int)
        live_at = np.flatnonzero(self.live)
        on = self.index[live_at]
        first = np.flatnonzero(np.append(True, on[1:] != on[:-1]))
        rank[live_at] = np.arange(on.size) - np.repeat(first, np.diff(np.append(first, on.size)))
        self.rank = rank
        self.ranks = int(rank.max()) + 1

    def lines(self, values: np.ndarray, spectra: np.ndarray) -> np.ndarray:
        """Amplitude lines of ``values`` (n_ch, n_x, n_w) per unit input of channels with
        ``spectra`` (n_ch, n_w): shape (n_ch · ranks, n_x, n_j), with
        E[x(t) y(t + τ)] = Σ_j Re(Σ_c x̄_{c,j} y_{c,j} e^{iω_j τ}) (:func:`cross_covariance`)."""
        n_ch, n_x, _ = values.shape
        amp = np.sqrt(np.asarray(spectra, dtype=float) * trapezoid_weights(self.omega)[None])
        live = self.live
        # each live frequency's (rank, line) as one index of a (rank·line, n_ch, n_x)
        # scratch (one leading advanced index: a plain row scatter), then transposed
        at = self.rank[live] * self.n_j + self.index[live]
        out = np.zeros((self.ranks * self.n_j, n_ch, n_x), dtype=complex)
        out[at] = np.moveaxis((values * amp[:, None, :])[:, :, live], 2, 0)
        out = out.reshape(self.ranks, self.n_j, n_ch, n_x).transpose(2, 0, 3, 1)
        return np.ascontiguousarray(out).reshape(n_ch * self.ranks, n_x, self.n_j)


def uniform_grid(
    w: Any, max_lines: int | None = None, stride: int = 1, spectra: Any = None
) -> UniformGrid:
    """The :class:`UniformGrid` of the analysis frequencies ``w`` [rad/s], of at most
    ``max_lines`` lines (:data:`MAX_LINES` by default), or every ``stride``-th of them;
    over the frequencies that carry the input ``spectra`` (n_ch, n_w) where given."""
    return UniformGrid(np.asarray(w, dtype=float), max_lines, stride, spectra)


def cross_covariance(x: np.ndarray, y: np.ndarray, n_fft: int) -> np.ndarray:
    """E[x(t) y_k(t + τ)] on the lag grid τ_m = 2πm/(n_fft·step), for one quantity's
    lines ``x`` (n_ch, n_j) and many ``y`` (n_ch, n_k, n_j): shape (n_k, n_fft)."""
    cross = np.zeros((y.shape[1], n_fft // 2 + 1), dtype=complex)
    # Σ_c x̄_c·y_ck per line: one matrix product per line
    cross[:, : y.shape[2]] = (np.conj(x).T[:, None, :] @ y.transpose(2, 0, 1))[:, 0].T
    cross[:, 0] *= 2.0  # (irfft halves the zero-frequency line)
    return np.fft.irfft(cross, n=n_fft, axis=1) * (0.5 * n_fft)


def pair_blocks(
    n: int, n_fft: int, per_pair: int = 1, first: int = 0
) -> Iterator[tuple[np.ndarray, np.ndarray]]:
    """The pairs e ≤ f of ``n`` items (f ≥ e + ``first``: 1, the pairs e < f), (e, f)
    index arrays in blocks of at most :data:`PAIR_BLOCK_BYTES` of ``per_pair`` lag
    functions of ``n_fft`` samples each."""
    e, f = np.triu_indices(n, first)
    size = max(1, PAIR_BLOCK_BYTES // (8 * n_fft * per_pair))
    for start in range(0, e.size, size):
        yield e[start : start + size], f[start : start + size]


def pair_lags(cross: np.ndarray, e: np.ndarray, f: np.ndarray, n_fft: int) -> np.ndarray:
    """E[x_e(t) y_f(t + τ)] on the lag grid (as :func:`cross_covariance`) of the pairs
    (e, f) times 2/n_fft (the callers fold n_fft/2 into their coefficients: no pass
    over the lags), from the cross-spectral lines ``cross`` (n_j, n_x, n_y), Σ_c
    x̄_{c,e} y_{c,f} per line (``np.conj(x).transpose(2, 1, 0) @ y.transpose(2, 0, 1)``
    for lines x, y (n_ch, n, n_j)) with the zero-frequency line doubled (irfft halves
    it): shape (n_pairs, n_fft)."""
    half = np.zeros((e.size, n_fft // 2 + 1), dtype=complex)
    half[:, : cross.shape[0]] = cross[:, e, f].T
    return np.fft.irfft(half, n=n_fft, axis=1)


def pair_outputs(g: np.ndarray, transfer: np.ndarray, e: np.ndarray, f: np.ndarray) -> np.ndarray:
    """Variance lines Re Σ_p conj(T_{e_p}) g_p T_{f_p} of outputs driven by the pairs
    (e, f) of components with cross-spectral lines ``g`` (n_pairs, n_o); ``transfer``
    (n_out, n, n_o) the outputs per unit component: shape (n_out, n_o).  A block of
    pairs at a time (no (n, n, n_o) array of every pair: the drag's chain 6.4 MB); the
    callers give one of (c, d) and (d, c) only, weighted 2 where they differ (G_dc =
    conj(G_cd): the two terms' real parts are equal)."""
    if (tap := RESIDUAL_TAP.get()) is not None:
        tap.lines(g, transfer, e, f)
    tt = np.conj(transfer[:, e])
    tt *= transfer[:, f]
    tt *= g  # (in place: one temporary)
    return tt.real.sum(axis=1)


def dense_pair_outputs(g_all: np.ndarray, transfer: np.ndarray, dtype: Any = complex) -> np.ndarray:
    """Re Σ_ef conj(T_e) G_ef T_f of outputs with transfer ``transfer`` (n_out, n, n_o)
    from the dense lines ``g_all`` (n_o, n·n) (G_ef in column e·n + f) as one matrix
    product per line (BLAS; the per-pair form costs n_pairs × n_out elementwise
    products), in ``dtype`` (``np.complex64``: single precision, summed in double):
    shape (n_out, n_o)."""
    n_out, n, n_o = transfer.shape
    t = np.ascontiguousarray(np.transpose(transfer, (2, 1, 0)), dtype=dtype)  # (n_o, n, n_out)
    g = g_all.reshape(n_o, n, n)
    # Re(conj(t)·gt): the parts' products as one pass on the interleaved views (the
    # same products and sums as on .real and .imag, without their strided temporaries)
    part = np.float32 if t.dtype == np.complex64 else float
    if g.dtype == t.dtype:
        prod = (t.view(part) * (g @ t).view(part)).reshape(n_o, n, n_out, 2)
        return (prod[..., 0] + prod[..., 1]).sum(axis=1, dtype=float).T
    # G in single precision, contracted in double a cache-sized run of lines at a time,
    # each run's products summed before the next run's cast (the cast after the complex
    # product alone ran 3–4× slower on the development host: OpenBLAS's zgemm returns
    # with the vector registers' upper halves in use, which slows numpy's SSE-encoded
    # cast loops until an AVX loop, here the real products, clears them)
    out = np.empty((n_o, n_out))
    step = max(1, PAIR_BLOCK_BYTES // (16 * n * n))
    for i in range(0, n_o, step):
        tc = t[i : i + step]
        prod = (tc.view(part) * (g[i : i + step].astype(t.dtype) @ tc).view(part)).reshape(
            -1, n, n_out, 2
        )
        out[i : i + step] = (prod[..., 0] + prod[..., 1]).sum(axis=1)
    return out.T


def line_pair_outputs(g_all: np.ndarray, transfer: np.ndarray, sel: Any, dtype: Any) -> np.ndarray:
    """:func:`dense_pair_outputs` of the dense lines ``g_all``'s rows ``sel`` (an index
    or slice; ``transfer`` on them), the rows read as views run by evenly spaced run
    (:func:`line_subset`'s first and last lines apart), not gathered into a copy (the
    chain's node motions: 2.3 MB a kind, first touched in every analysis)."""
    idx = np.arange(g_all.shape[0])[sel]
    parts, at = [], 0
    for run in line_runs(idx):
        lines = g_all[run] if isinstance(run, slice) else g_all[run : run + 1]
        n_run = lines.shape[0]
        parts.append(dense_pair_outputs(lines, transfer[:, :, at : at + n_run], dtype))
        at += n_run
    if not parts:  # (no line)
        return np.zeros((transfer.shape[0], 0))
    return parts[0] if len(parts) == 1 else np.concatenate(parts, axis=1)


def line_runs(idx: np.ndarray) -> list[slice | int]:
    """``idx`` (increasing) as evenly spaced runs: a slice for each run of at least
    three lines (or two at the end), the index of a line alone."""
    out: list[slice | int] = []
    i = 0
    while i < idx.size:
        if i + 1 == idx.size:
            out.append(int(idx[i]))
            break
        step = int(idx[i + 1] - idx[i])
        j = i + 1
        while j + 1 < idx.size and idx[j + 1] - idx[j] == step:
            j += 1
        if j - i + 1 >= 3 or i + 2 >= idx.size:
            out.append(slice(int(idx[i]), int(idx[j]) + 1, step))
            i = j + 1
        else:  # (a pair that breaks a run: the first alone)
            out.append(int(idx[i]))
            i += 1
    return out


def dense_outputs(
    blocks: list[tuple[np.ndarray, np.ndarray, np.ndarray]],
    transfer: np.ndarray,
    sel: Any = None,
) -> np.ndarray:
    """:func:`~stochcable.dynamics.residuals.residual_lines.pair_outputs` summed over a
    capture's ``blocks``, for many outputs: the
    pairs' lines put into one (n_o, n, n) matrix G (G_ef = g_p), then Re Σ_ef conj(T_e)
    G_ef T_f as one matrix product per line — the per-pair form costs n_pairs × n_out
    per line (the 7 stations: 3.5× the ends'), this one n² × n_out in BLAS.
    ``transfer`` (n_out, n, n_o) on the lines ``sel`` (the first n_o by default);
    shape (n_out, n_o)."""
    n_out, n, n_o = transfer.shape
    g_all = np.zeros((n_o, n * n), dtype=complex)
    for g, e, f in blocks:  # each pair once (pair_outputs' callers: f ≥ e, or (i, j) blocks)
        g_all[:, e * n + f] += g[:, slice(0, n_o) if sel is None else sel].T
    return dense_pair_outputs(g_all, transfer)


#: Largest dense matrix of one contraction's pair lines (:class:`PairLines`, n² × n_o
#: of :data:`PAIR_DTYPE`; the chain's drag 3.2 MB): beyond it the outputs are summed
#: block by block (:func:`pair_outputs`). [bytes]
DENSE_PAIR_BYTES = 24 * 2**20
#: The dense pair lines held in single precision (contracted in double, a cache-sized
#: run of lines at a time: :func:`dense_pair_outputs`), the along-line contractions'
#: precision (:data:`~stochcable.dynamics.residuals.along_line.ALONG_DTYPE`): half the
#: memory and no second copy for them (the chain's 6.4 + 3.2 MB were 9.6 MB held and
#: first touched in every analysis); end σ within 3e-9 of double on the five lines. [-]
PAIR_DTYPE = np.complex64


class PairLines:
    """The outputs of one contraction of pair lines (:func:`pair_outputs` summed over
    its blocks): the blocks' lines gathered into one dense matrix G (n_o, n·n), G_ef in
    column e·n + f, and contracted once (:func:`dense_pair_outputs`), or block by block
    where G would exceed :data:`DENSE_PAIR_BYTES`.  The blocks are shown to
    :data:`RESIDUAL_TAP` as :func:`pair_outputs` shows them, and G with them (the
    element tensions' contraction then reads it: :mod:`.along_line`)."""

    def __init__(self, transfer: np.ndarray) -> None:
        self.transfer = transfer
        n_out, n, n_o = transfer.shape
        dense = np.dtype(PAIR_DTYPE).itemsize * n * n * n_o <= DENSE_PAIR_BYTES
        self._g = np.zeros((n_o, n * n), dtype=PAIR_DTYPE) if dense else None
        self._out = None if dense else np.zeros((n_out, n_o))

    def add(self, g: np.ndarray, e: np.ndarray, f: np.ndarray) -> None:
        """A block of pairs (e, f) and their lines ``g`` (n_pairs, n_o) (one of (c, d)
        and (d, c) only, weighted 2 where they differ, as :func:`pair_outputs`; each
        pair in one block only: its column is set, not summed)."""
        if self._g is None:
            self._out += pair_outputs(g, self.transfer, e, f)
            return
        if (tap := RESIDUAL_TAP.get()) is not None:
            tap.lines(g, self.transfer, e, f, keep=False)  # (the tap reads G: outputs)
        n = self.transfer.shape[1]
        self._g[:, np.asarray(e) * n + np.asarray(f)] = g.T

    def outputs(self) -> np.ndarray:
        """The variance lines (n_out, n_o) of the outputs."""
        if self._g is None:
            return self._out
        if (tap := RESIDUAL_TAP.get()) is not None and hasattr(tap, "dense"):
            tap.dense(self._g, self.transfer)
        return dense_pair_outputs(self._g, self.transfer)


#: The element tensions' and node motions' residual lines are formed on every
#: ALONG_STRIDE-th line of the kind's (and its last), the others interpolated
#: (:func:`line_subset`, :func:`fill_lines`) where the ends' lines allow it
#: (:func:`line_stride`): their rows' transfer and contraction cost in proportion. [-]
ALONG_STRIDE = 2
#: :func:`line_stride`'s tolerance on the ends' residual variance summed on the
#: strided lines (its σ share: half of it). [-]
STRIDE_TOL = 2e-3


def line_subset(top: int, stride: int = 1) -> np.ndarray:
    """The lines (indices) of the first ``top`` the along-line outputs are formed on:
    the first, every ``stride``-th from line ``stride − 1`` and the last
    (:func:`fill_lines` the others).  With the kinds' grids (the lines j·Δ, j ≥ 1;
    the geometric residual's every second of them) every second line is then a
    multiple of 2Δ: the geometric residual's lines are among the drag residual's,
    their rows solved once on a short line (the deep wire's banded solve of 7 rows
    on 64 more frequencies)."""
    if stride == 1:
        return np.arange(top)
    sel = np.arange(stride - 1, top, stride)
    sel = np.append(0, sel) if top else sel
    return sel if top == 0 or sel[-1] == top - 1 else np.append(sel, top - 1)


def fill_lines(part: np.ndarray, sel: np.ndarray, top: int) -> np.ndarray:
    """The variance lines (n_out, top) from those on the lines ``sel``
    (:func:`line_subset`) ``part`` (n_out, n_sel), the others interpolated linearly
    between their neighbours. [unit²]"""
    if sel.size == top:
        return part
    out = np.empty((part.shape[0], top))
    for k, row in enumerate(part):
        out[k] = np.interp(np.arange(top), sel, row)
    return out


def line_stride(record: Any, top: int | None, tol: float = STRIDE_TOL) -> int:
    """:data:`ALONG_STRIDE` where the record's end variance lines (their first part, up
    to ``top``) summed on every stride-th line (:func:`fill_lines`' weights) are within
    ``tol`` of their sum on all lines at both ends (the along-line outputs share their
    loads and resonances: the inclined guy's 0.7 %-damped mode fails it), else 1."""
    if ALONG_STRIDE == 1 or not record.lines:
        return 1
    _, part = record.lines[0]
    v = np.stack([np.asarray(x, dtype=float) for x in part.values()])[:, :top]
    if v.shape[1] < 4 * ALONG_STRIDE:
        return 1
    sel = line_subset(v.shape[1], ALONG_STRIDE)
    dec = fill_lines(v[:, sel], sel, v.shape[1]).sum(axis=1)
    full = v.sum(axis=1)
    return ALONG_STRIDE if np.all(np.abs(dec - full) <= tol * np.abs(full)) else 1


def along(x: np.ndarray, vec: np.ndarray) -> np.ndarray:
    """Σ_d x[w, e, d, c]·vec[e, d] of per-element vectors ``x`` (n_w, n_e, k, n_ch) along
    ``vec`` (n_e, k): shape (n_ch, n_e, n_w), as ``np.einsum("wedc,ed->cew", x, vec)``
    by one batched product per element (4× faster on the chain's pieces)."""
    return along_each(x, [vec])[0]


def along_each(x: np.ndarray, vecs: list[np.ndarray]) -> list[np.ndarray]:
    """:func:`along` of ``x`` along each of ``vecs`` (the per-element layout of ``x``
    formed once for them all): a list of (n_ch, n_e, n_w)."""
    x_t = np.ascontiguousarray(np.transpose(x, (1, 3, 0, 2)))  # (n_e, n_ch, n_w, k)
    out = []
    for vec in vecs:
        v = np.asarray(vec)[:, None, :, None].astype(x_t.dtype)
        out.append(np.transpose(x_t @ v, (1, 0, 2, 3))[..., 0])
    return out


def fft_length(n: int) -> int:
    """The shortest lag grid of at least ``n`` ≥ 1 samples whose real FFT is fast: the
    least 5-smooth number ≥ n (763 → 768, 769 → 800), as ``scipy.fft.next_fast_len(n,
    real=True)`` gives it (equal for every n, tests/dynamics/test_drag_residual.py),
    without importing ``scipy.fft`` and the ``scipy.special`` it loads (~35 ms)."""
    n = int(n)
    best = 1 << (n - 1).bit_length()  # the least power of two ≥ n
    p5 = 1
    while p5 < best:
        p35 = p5
        while p35 < best:  # p35 = 3^b 5^c: the least p35·2^a ≥ n
            best = min(best, p35 << max(0, -(-n // p35) - 1).bit_length())
            p35 *= 3
        p5 *= 5
    return best


def covariance_lines(cov: np.ndarray, n_o: int) -> np.ndarray:
    """Lines c_j, j = 1 … n_o, of covariance functions ``cov`` (n_k, n_fft) on the lag
    grid, cov(τ) = Σ_j Re(c_j e^{iω_jτ}) (the zero-frequency line, a random constant,
    left out): shape (n_k, n_o)."""
    n_fft = cov.shape[1]
    return (2.0 / n_fft) * np.fft.rfft(cov, axis=1)[:, 1 : n_o + 1]


def load_transfer(
    system: Any,
    damping: Any,
    unit: np.ndarray,
    w: np.ndarray,
    influence: EndInfluence | None = None,
) -> np.ndarray:
    """End tensions (end_a, end_b) per unit of each load case ``unit`` (n_nodes, d,
    n_load) (node forces on the model's components), ends prescribed, the line's
    linear system with ``damping``, on ``w``: the load cases contracted with the end
    tensions' influence (:func:`modal_influence` where it applies, else
    :func:`end_influence`; from ``influence`` where given, shared
    by the residuals of one line), shape (2, n_load, n_w) (n_out rows for an
    ``influence`` of other outputs). [N/unit]"""
    if influence is None:
        g = modal_influence(system, damping, w) if _influence.MODAL_INFLUENCE else None
        g = end_influence(system, damping, w) if g is None else g
    else:
        g = influence.on(w)
    if isinstance(g, ModalRows):  # (through the modes: the rows never formed)
        h = g.transfer(unit)
        if (tap := RESIDUAL_TAP.get()) is not None:
            tap.loads(unit, w, h)
        return h
    n = g.shape[1] * g.shape[2]
    # the real loads times the complex influence as one real product per output on the
    # interleaved view (a complex product would upcast the loads: 4× the work)
    g = np.ascontiguousarray(g).reshape(g.shape[0], n, w.size)
    u_t = np.ascontiguousarray(unit.reshape(n, -1).T, dtype=float)  # (n_load, n_nodes·d)
    h = (u_t @ g.view(float)).view(complex)  # (n_out, n_load, n_w)
    if (tap := RESIDUAL_TAP.get()) is not None:
        tap.loads(unit, w, h)
    return h


def residual_record(
    lines: np.ndarray,
    w_out: np.ndarray,
    w: np.ndarray,
    std: dict[str, float],
    order: int,
    panels: int,
    linear: dict[str, np.ndarray] | None = None,
) -> ResidualRecord:
    """The record of the end tensions' variance lines ``lines`` (end_a, end_b) at
    ``w_out``: their sums, and the sums over the analysis band [w[0], w[-1]]; plus
    ``linear`` (variance-change lines on the analysis grid ``w`` itself, e.g. of a load
    correlated with the linear response; they may be negative), the lines kept in the
    record. [N²]"""
    keep = (w_out >= w[0] * (1 - 1e-9)) & (w_out <= w[-1] * (1 + 1e-9))
    ends = ("end_a", "end_b")
    extra = {e: float(np.sum(v)) for e, v in (linear or {}).items()}
    variance = {end: float(lines[k].sum()) + extra.get(end, 0.0) for k, end in enumerate(ends)}
    in_band = {end: float(lines[k][keep].sum()) + extra.get(end, 0.0) for k, end in enumerate(ends)}
    parts = [(np.asarray(w_out, dtype=float), {end: lines[k] for k, end in enumerate(ends)})]
    if linear:
        parts.append((np.asarray(w, dtype=float), {e: np.asarray(v) for e, v in linear.items()}))
    return ResidualRecord.from_variances(variance, in_band, std, order, panels, tuple(parts))
