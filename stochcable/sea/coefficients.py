"""The coefficient kernel of a sea realization: random draws, amplitudes, phasors and
the FFT input, on the caller's thread and a helper.

Private to :mod:`stochcable.sea`: :func:`~stochcable.sea.realization.simulate_sea`
sets up the grid, the seed and the spectrum, hands the work to :class:`_Synthesis`,
then runs the FFT.  Here: the phasor table and chunk size shared with the compiled
kernel (:mod:`stochcable.sea.kernels`), the NumPy kernel :func:`_phasor_chunk`, the
per-thread scratch and the reused work arrays of one call.  The operations and their
order are the realization's bit-exact contract (tests/sea/test_sea.py pins the bits).
"""

from __future__ import annotations

import itertools
import math
import threading
from collections.abc import Callable

import numpy as np

from stochcable.sea import fft as _fft

_TABLE_BITS = 13
_TABLE_SIZE = 1 << _TABLE_BITS
_TABLE = -np.exp(2j * np.pi * np.arange(_TABLE_SIZE) / _TABLE_SIZE)  # −e^{2πij/2^13}
_CHUNK = 32768

_scratch = threading.local()
_WORK_POOL_BYTES = 64 * 2**20
_work_pool: list[tuple[tuple[int, str], tuple[np.ndarray, np.ndarray, np.ndarray]]] = []
_work_lock = threading.Lock()


def _work_arrays(n_t: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Work arrays of one call: draws u (N−1), S on the grid (N+1), FFT input (N+1).

    None of them is part of a result (the FFT destroys its input), so :func:`_give_back`
    keeps them for the next call of the same size: 2^20 samples would otherwise
    page-fault 16 MiB of fresh memory in, call after call.  A call owns its set until
    it gives it back; concurrent calls get different sets.
    """
    key = (n_t, _fft.backend(n_t))  # the FFT input must suit the backend's alignment
    with _work_lock:
        for i in range(len(_work_pool) - 1, -1, -1):
            if _work_pool[i][0] == key:
                return _work_pool.pop(i)[1]
    n = n_t // 2
    return np.empty(n - 1), np.empty(n + 1), _fft.irfft_input(n_t)


def _give_back(n_t: int, arrays: tuple[np.ndarray, np.ndarray, np.ndarray]) -> None:
    """Keep a call's work arrays for reuse (the 8 most recent sets, ≤ 64 MiB in all)."""
    with _work_lock:
        _work_pool.append(((n_t, _fft.backend(n_t)), arrays))
        while (
            len(_work_pool) > 8
            or sum(a.nbytes for _, arrs in _work_pool for a in arrs) > _WORK_POOL_BYTES
        ):
            _work_pool.pop(0)


def _buffers(size: int) -> list[np.ndarray]:
    """Per-thread scratch arrays of the coefficient kernel (kept between calls)."""
    bufs = getattr(_scratch, "bufs", None)
    if bufs is None or bufs[0].shape[0] < size:
        bufs = (
            [np.empty(size) for _ in range(5)]
            + [np.empty(size, dtype=np.intp)]
            + [np.empty(size, dtype=np.complex128) for _ in range(2)]
        )
        _scratch.bufs = bufs
    return bufs


def _phasor_chunk(
    u: np.ndarray,
    s: np.ndarray,
    c2: float,
    out: np.ndarray,
    gain: np.ndarray | None,
    fft_in: np.ndarray,
    scale: float,
) -> None:
    """out = a·e^{−iθ}, a = √(c2·S) (× gain), θ = π − 2πu, without calling cos/sin;
    fft_in = out·scale (the FFT's work array, filled while the chunk is in cache).

    −e^{2πiu} = T[j] · e^{iδ}, T[j] = −e^{2πij/8192}, j = ⌊8192u⌋,
    δ = 2π(8192u − j)/8192 ∈ [0, 7.7e-4): a table times cos δ ≈ 1 − δ²/2 + δ⁴/24,
    sin δ ≈ δ(1 − δ²/6) (truncation δ⁶/720 < 3e-22, δ⁵/120 < 3e-18); |error| ≲ 3e-16
    relative per entry.  The amplitude multiplies e^{iδ} before the one complex product
    with the table.  One cache-sized chunk (≤ _CHUNK entries) on the calling thread.
    :func:`stochcable.sea.kernels.phasor_chunk` is the compiled equivalent (same operations).
    """
    m = u.shape[0]
    x_, w_, d2_, c_, amp, j_, e, t = (b[:m] for b in _buffers(_CHUNK))
    np.multiply(u, float(_TABLE_SIZE), out=x_)
    np.floor(x_, out=w_)
    np.copyto(j_, w_, casting="unsafe")
    np.subtract(x_, w_, out=x_)
    x_ *= 2.0 * math.pi / _TABLE_SIZE  # δ
    np.multiply(x_, x_, out=d2_)  # δ²
    np.multiply(s, c2, out=amp)
    np.sqrt(amp, out=amp)
    if gain is not None:
        amp *= gain
    ev = e.view(np.float64)
    np.multiply(d2_, 1.0 / 24.0, out=c_)  # cos δ = 1 + δ²(−1/2 + δ²/24)
    c_ -= 0.5
    c_ *= d2_
    c_ += 1.0
    np.multiply(c_, amp, out=ev[0::2])
    np.multiply(d2_, -1.0 / 6.0, out=c_)  # sin δ = δ(1 − δ²/6)
    c_ += 1.0
    c_ *= x_
    np.multiply(c_, amp, out=ev[1::2])
    np.take(_TABLE, j_, out=t, mode="wrap")  # 0 <= j < 8192: no wrap; "wrap" skips the checks
    np.multiply(t, e, out=out)
    np.multiply(out.view(np.float64), scale, out=fft_in.view(np.float64))


class _Synthesis:
    """Draws, spectrum, coefficients and FFT input of one realization, on two threads.

    A pool thread makes the random draws (in the documented order) while the caller's
    thread evaluates the spectrum on pieces of the grid; once the helper has drawn, it
    takes the remaining pieces too.  Then both take chunks of the coefficient kernel
    (amplitudes, phasors, FFT input) from a shared counter.  The helper waits (without
    holding the GIL) rather than starting on the kernel early: many short kernel calls
    would make the caller's large spectrum operations queue for the GIL.  Chunk
    boundaries are fixed multiples of _CHUNK and every entry gets the same operations
    whichever thread computes it, so the result does not depend on the split; the
    density is a pointwise function of ω, so its pieces give the values of one call
    (a density that does not return one value per ω of a piece, or raises, is called
    again on the whole grid by the caller, which then reports the error).

    With the compiled kernel (``kernel``, GIL released) and a known amplitude factor
    ``c2`` the work is pipelined instead: whichever thread evaluates a piece of S runs
    the kernel on that piece's lines at once (still in cache) if the draws are done, else
    queues the piece for later (:meth:`drain`).  The one barrier before the FFT is then
    the end of the kernel work, and the caller validates S while the helper finishes.
    """

    def __init__(
        self,
        gen: np.random.Generator | int,
        lines: int,
        nsa: bool,
        coeff: np.ndarray,
        fft_in: np.ndarray,
        scale: float,
        density: Callable | None = None,
        omega: np.ndarray | None = None,
        pieces: int = 1,
        u: np.ndarray | None = None,
        s_grid: np.ndarray | None = None,
        kernel: Callable | None = None,
        c2: float = 0.0,
    ) -> None:
        self.gen, self.lines, self.nsa = gen, lines, nsa
        self.kernel = kernel  # compiled kernel, or None for NumPy's
        # pipelined: S piece -> kernel on its lines, same thread (compiled kernel only)
        self.pipelined = kernel is not None and density is not None and omega is not None
        self.drawn = threading.Event()  # set once every draw is made
        self._deferred: list[tuple[int, int]] = []  # line ranges waiting for the draws
        self.coeff, self.fft_in, self.scale = coeff, fft_in, scale
        self.u = np.empty(lines) if u is None else u
        self.gain: np.ndarray | None = None  # NSA: √(α² + β²) (NumPy kernel)
        self.alpha = self.beta = np.empty(0)  # NSA: α, β (compiled kernel: fused hypot)
        self.s: np.ndarray | None = None  # S(ω_m), m = 1 … N−1
        self.c2 = c2  # a_m N_t/2 = √(c2 S(ω_m))
        self.edges = list(range(0, lines, _CHUNK)) + [lines]
        self._next = itertools.count()
        self._draw_lock = threading.Lock()
        self._drawn = False
        # an int seed: the generator is built by draw() (on the helper thread, off the
        # caller's set-up; seeding costs 0.05–0.2 ms with cold caches) and is private
        self._state = gen.bit_generator.state if isinstance(gen, np.random.Generator) else None
        self.cancelled = False
        self.ready = threading.Event()  # set once s and c2 are final
        # S(ω) on the whole grid, evaluated piece by piece (see spectrum())
        self.density, self.omega = density, omega
        size = 0 if density is None or omega is None else omega.shape[0]
        self.s_grid = np.empty(size) if s_grid is None or s_grid.shape[0] != size else s_grid
        self.piece_edges = [size * k // pieces for k in range(pieces + 1)] if size else [0]
        self._next_piece = itertools.count()
        self._pieces_done = 0
        self.piece_failed = False
        self.piece_min = math.inf  # min over the pieces (NaN if one has a NaN)
        self.s_ready = threading.Event()  # set once every piece is done
        self._piece_lock = threading.Lock()
        self.errstate = np.geterr()  # the caller's floating-point error modes

    def spectrum(self) -> None:
        """Evaluate S on grid pieces from a shared counter until none is left.

        Each piece is written into ``s_grid``; a failure (an exception, a wrong shape)
        only sets ``piece_failed``: the caller then evaluates S on the whole grid itself.
        """
        edges = self.piece_edges
        last = len(edges) - 1
        with np.errstate(**self.errstate):
            while True:
                i = next(self._next_piece)
                if i >= last:
                    return
                try:
                    if not (self.piece_failed or self.cancelled):
                        a, b = edges[i], edges[i + 1]
                        si = np.asarray(self.density(self.omega[a:b]), dtype=float)
                        if si.shape == (b - a,):
                            self.s_grid[a:b] = si
                            lo = float(si.min()) if b > a else math.inf
                            with self._piece_lock:  # NaN wins (fails every check)
                                if not (math.isnan(self.piece_min) or lo >= self.piece_min):
                                    self.piece_min = lo
                        else:
                            self.piece_failed = True
                except Exception:  # noqa: BLE001 - reported by the caller's full call
                    self.piece_failed = True
                finally:
                    with self._piece_lock:
                        self._pieces_done += 1
                        if self._pieces_done == last:
                            self.s_ready.set()
                if self.pipelined and not (self.piece_failed or self.cancelled):
                    # lines m = 1 … N−1 of grid points [a, b): line index m − 1
                    la, lb = max(a, 1) - 1, min(b, self.lines + 1) - 1
                    if lb > la:
                        if self.drawn.is_set():
                            self._kernel_lines(la, lb)
                        else:
                            # queued chunk by chunk: the two threads then finish
                            # the kernel within one chunk (≈ 0.15 ms) of each other
                            with self._piece_lock:
                                self._deferred.extend(
                                    (c, min(c + _CHUNK, lb)) for c in range(la, lb, _CHUNK)
                                )

    def _kernel_lines(self, a: int, b: int) -> None:
        """Compiled kernel on lines [a, b) with S from ``s_grid``, in _CHUNK sub-chunks."""
        kernel, u, s, c2 = self.kernel, self.u, self.s_grid, self.c2
        alpha, beta, coeff, fft_in = self.alpha, self.beta, self.coeff, self.fft_in
        nsa = alpha.shape[0] > 0
        jbuf = _buffers(_CHUNK)[0]
        for c in range(a, b, _CHUNK):
            d = min(c + _CHUNK, b)
            kernel(
                u[c:d],
                s[c + 1 : d + 1],
                c2,
                alpha[c:d] if nsa else alpha,
                beta[c:d] if nsa else beta,
                _TABLE,
                coeff[c:d],
                fft_in[c:d],
                self.scale,
                jbuf,
            )

    def drain(self) -> None:
        """Run the kernel on the queued pieces (the draws must be done)."""
        while not (self.cancelled or self.piece_failed):
            with self._piece_lock:
                if not self._deferred:
                    return
                a, b = self._deferred.pop()
            self._kernel_lines(a, b)

    def draw(self) -> None:
        """All random draws, once, by whichever thread gets here first."""
        with self._draw_lock:
            if self._drawn:
                return
            self._drawn = True
            if not isinstance(self.gen, np.random.Generator):
                self.gen = np.random.default_rng(self.gen)
            self.gen.random(out=self.u)
            if self.nsa:
                alpha = self.gen.standard_normal(self.lines)
                beta = self.gen.standard_normal(self.lines)
                if self.kernel is None:
                    self.gain = np.hypot(alpha, beta, out=alpha)
                else:
                    self.alpha, self.beta = alpha, beta
            self.drawn.set()

    def cancel(self) -> None:
        """Stop the work and leave the caller's generator where it was."""
        with self._draw_lock:
            self.cancelled = True
            if self._drawn and self._state is not None:
                self.gen.bit_generator.state = self._state
            self._drawn = True
        self.ready.set()

    def start(self, s: np.ndarray, c2: float) -> None:
        """Hand over the spectrum lines and the amplitude factor; the kernel may start."""
        self.s, self.c2 = s, c2
        self.ready.set()

    def work(self) -> None:
        """Draw (if nobody has), help with S, wait for it, then take chunks until none is left.

        Pipelined: draw, take S pieces (each followed by its kernel), then queued pieces.
        """
        self.draw()
        self.spectrum()
        if self.pipelined:
            self.drain()
            return
        self.ready.wait()
        edges, coeff, u, s, c2 = self.edges, self.coeff, self.u, self.s, self.c2
        gain, fft_in, scale = self.gain, self.fft_in, self.scale
        last = len(edges) - 1
        if self.kernel is not None:
            # compiled, GIL released: √ of a negative S (discarded) gives NaN silently
            kernel, alpha, beta, jbuf = self.kernel, self.alpha, self.beta, _buffers(_CHUNK)[0]
            nsa = alpha.shape[0] > 0
            while not self.cancelled:
                i = next(self._next)
                if i >= last:
                    return
                a, b = edges[i], edges[i + 1]
                kernel(
                    u[a:b],
                    s[a:b],
                    c2,
                    alpha[a:b] if nsa else alpha,
                    beta[a:b] if nsa else beta,
                    _TABLE,
                    coeff[a:b],
                    fft_in[a:b],
                    scale,
                    jbuf,
                )
            return
        # the caller's thread validates S while a helper may already run the kernel:
        # on invalid S (discarded, then rejected) √ of a negative must stay silent
        with np.errstate(invalid="ignore"):
            while not self.cancelled:
                i = next(self._next)
                if i >= last:
                    return
                a, b = edges[i], edges[i + 1]
                _phasor_chunk(
                    u[a:b],
                    s[a:b],
                    c2,
                    coeff[a:b],
                    None if gain is None else gain[a:b],
                    fft_in[a:b],
                    scale,
                )
