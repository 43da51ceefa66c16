"""Real FFTs through cached pyfftw plans, with numpy.fft as the fallback.

``rfft`` and ``irfft`` have numpy's signatures and normalization (``irfft`` divides
by ``n``) and agree with :mod:`numpy.fft` to round-off.  With pyfftw installed, one
FFTW plan is built per (input shape, n, axis, direction) with planner effort
``FFTW_ESTIMATE`` (set ``STOCHCABLE_FFTW_EFFORT`` to change it) and kept in a small
LRU cache.  Each plan owns aligned work buffers and a lock, so concurrent calls from
worker threads are safe (calls on the same plan are serialized, different plans run in
parallel).  Plans use ``os.cpu_count()`` threads for transforms of 2^15 points or more.

FFTW wisdom (measured plans, kept on disk): before the first plan, the wisdom file
:func:`wisdom_path` is imported if it exists; plans of any effort then use the measured
plans it holds.  :func:`tune` measures the plans of given sizes and writes the file
(``FFTW_MEASURE`` takes 15–35 s for 2^20 points on a 2-core machine; the 2^20-point
irfft then runs in ~3.4 ms instead of ~4.0 ms, docs/BENCHMARKS.md); with
``STOCHCABLE_FFTW_EFFORT`` set above ``FFTW_ESTIMATE`` every new plan is saved too.  A
measured plan rounds differently from an estimated one (≲ 1e-15 relative), so results
may differ at round-off between machines and wisdom files.
"""

from __future__ import annotations

import os
import sys
import threading
from collections import OrderedDict
from typing import Any

import numpy as np

from stochcable import validation as v
from stochcable.errors import InputError

# pyfftw is imported on first use, not with this module, and without its optional dask
# interface: pyfftw.interfaces imports dask.array (and with it pandas) whenever dask is
# installed, ≈ 0.5 s of the first time series of every command and worker, for an
# interface stochcable does not use.  Its FFTW threads run through OpenMP (libgomp),
# whose wait policy stochcable.runtime.configure() sets.
_UNLOADED: Any = object()
_pyfftw: Any = _UNLOADED  # the module, None without pyfftw (tests patch None in)


def _lib_for(n: int) -> Any:
    """pyfftw for transforms of ``PYFFTW_MIN_SIZE`` points or more, else None (numpy)."""
    return _lib() if n >= PYFFTW_MIN_SIZE else None


def _lib() -> Any:
    """pyfftw, imported on the first call (None when it is not installed); dask.array,
    when nothing has imported it yet, is hidden from pyfftw's import (its
    ``from dask.array.fft import fft_wrap`` then fails and skips the dask interface, as
    without dask)."""
    global _pyfftw
    if _pyfftw is _UNLOADED:
        hide = "dask.array" not in sys.modules
        if hide:
            sys.modules["dask.array"] = None  # type: ignore[assignment]
        try:
            import pyfftw
        except ImportError:  # pragma: no cover
            pyfftw = None
        finally:
            if hide and sys.modules.get("dask.array", 0) is None:
                del sys.modules["dask.array"]
        _pyfftw = pyfftw
    return _pyfftw


__all__ = [
    "rfft",
    "irfft",
    "irfft_input",
    "irfft_overwrite",
    "backend",
    "clear_cache",
    "wisdom_path",
    "tune",
]

_MAX_PLANS = 16
#: Transform length from which pyfftw runs the transforms; shorter ones go to numpy.fft
#: (as fast there, and importing pyfftw costs ≈ 0.2 s of a process's first record: the
#: 2,400 samples of the chain example's record).  The choice depends on the length only,
#: so a given length always rounds the same way.
PYFFTW_MIN_SIZE = 2**15
_THREAD_MIN_SIZE = 2**15
_EFFORT = os.environ.get("STOCHCABLE_FFTW_EFFORT", "FFTW_ESTIMATE")

_WISDOM_ENV = "STOCHCABLE_FFTW_WISDOM"
_wisdom_loaded = False

_cache: OrderedDict[tuple, _Plan] = OrderedDict()
_cache_lock = threading.Lock()


def wisdom_path() -> str | None:
    """Path of the FFTW wisdom file, or ``None`` when wisdom is switched off.

    ``$STOCHCABLE_FFTW_WISDOM`` if set (an empty value switches wisdom off), else
    ``$XDG_CACHE_HOME/stochcable/fftw_wisdom.txt`` (``~/.cache`` without XDG_CACHE_HOME).
    The file holds FFTW's own text format (double precision), read at the first plan.
    """
    path = os.environ.get(_WISDOM_ENV)
    if path is not None:
        return path or None
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return os.path.join(base, "stochcable", "fftw_wisdom.txt")


def _load_wisdom() -> None:
    """Import the wisdom file once per process (caller holds _cache_lock)."""
    global _wisdom_loaded
    if _wisdom_loaded:
        return
    _wisdom_loaded = True
    path = wisdom_path()
    if path is None:
        return
    try:
        with open(path, "rb") as f:
            data = f.read()
    except OSError:
        return
    if data:
        _lib().import_wisdom((data, b"", b""))  # FFTW ignores what it cannot parse


def _save_wisdom() -> str | None:
    """Write the process's double-precision wisdom to wisdom_path() (caller holds the lock)."""
    path = wisdom_path()
    if path is None:
        return None
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    tmp = f"{path}.{os.getpid()}.{threading.get_ident()}.tmp"
    with open(tmp, "wb") as f:
        f.write(_lib().export_wisdom()[0])
    os.replace(tmp, path)  # readers never see a partial file
    return path


def backend(n: int | None = None) -> str:
    """Name of the FFT backend in use: ``"pyfftw"`` or ``"numpy"`` (for transforms of
    ``n`` points when given: numpy below ``PYFFTW_MIN_SIZE``)."""
    lib = _lib() if n is None else _lib_for(n)
    return "numpy" if lib is None else "pyfftw"


def clear_cache() -> None:
    """Drop every cached FFTW plan (frees their work buffers)."""
    with _cache_lock:
        _cache.clear()


class _Plan:
    """One FFTW plan with its aligned input buffer and a lock."""

    __slots__ = ("fftw", "inp", "out_shape", "out_dtype", "lock", "scale")

    def __init__(
        self, in_shape: tuple[int, ...], n: int, inverse: bool, effort: str | None = None
    ) -> None:
        if inverse:
            in_dtype, out_dtype = "complex128", "float64"
            out_shape = in_shape[:-1] + (n,)
        else:
            in_dtype, out_dtype = "float64", "complex128"
            out_shape = in_shape[:-1] + (n // 2 + 1,)
        self.inp = _lib().empty_aligned(in_shape, dtype=in_dtype)
        out = _lib().empty_aligned(out_shape, dtype=out_dtype)
        threads = (os.cpu_count() or 1) if n >= _THREAD_MIN_SIZE else 1
        self.fftw = _lib().FFTW(
            self.inp,
            out,
            axes=(len(in_shape) - 1,),
            direction="FFTW_BACKWARD" if inverse else "FFTW_FORWARD",
            flags=(effort or _EFFORT, "FFTW_DESTROY_INPUT"),
            threads=threads,
        )
        self.out_shape = out_shape
        self.out_dtype = out_dtype
        self.lock = threading.Lock()
        self.scale = 1.0 / n if inverse else 1.0

    def run(self, inp: np.ndarray) -> np.ndarray:
        """Transform a caller-owned aligned input (destroyed) into a new output array."""
        out = _lib().empty_aligned(self.out_shape, dtype=self.out_dtype)
        with self.lock:
            self.fftw.update_arrays(inp, out)
            self.fftw.execute()
        return out

    def __call__(self, x: np.ndarray) -> np.ndarray:
        out = _lib().empty_aligned(self.out_shape, dtype=self.out_dtype)
        with self.lock:
            np.copyto(self.inp, x, casting="unsafe")
            self.fftw.update_arrays(self.inp, out)
            self.fftw.execute()
        if self.scale != 1.0:
            out *= self.scale
        return out


def _plan(in_shape: tuple[int, ...], n: int, inverse: bool) -> _Plan:
    key = (in_shape, n, inverse)
    with _cache_lock:
        plan = _cache.get(key)
        if plan is not None:
            _cache.move_to_end(key)
            return plan
        # FFTW's planner is not thread-safe: build under the cache lock.
        _load_wisdom()
        plan = _Plan(in_shape, n, inverse)
        if _EFFORT != "FFTW_ESTIMATE":
            try:
                _save_wisdom()  # a measured plan: keep it for next time
            except OSError:  # no writable cache: the plan still works
                pass
        _cache[key] = plan
        while len(_cache) > _MAX_PLANS:
            _cache.popitem(last=False)
        return plan


def tune(n_samples: int | list[int], effort: str = "FFTW_MEASURE") -> str | None:
    """Measure the FFTW plans of real transforms of ``n_samples`` points and save them.

    Builds the inverse (the sea synthesis's) and forward 1-D plans of each size with
    planner ``effort``, replaces the cached plans and writes the process's wisdom to
    :func:`wisdom_path`, so later processes start with the measured plans.

    Parameters
    ----------
    n_samples : int or list of int
        Transform lengths N_t (e.g. ``2**20`` for ``simulate_sea`` of 2^20 samples). [-]
    effort : str, default "FFTW_MEASURE"
        FFTW planner flag: ``"FFTW_MEASURE"``, ``"FFTW_PATIENT"`` or ``"FFTW_EXHAUSTIVE"``. [-]

    Returns
    -------
    str or None
        The wisdom file written, ``None`` without pyfftw or with wisdom switched off. [-]
    """
    if isinstance(n_samples, (int, np.integer)) and not isinstance(n_samples, bool):
        n_samples = [n_samples]
    sizes = [v.positive_int("n_samples", n, minimum=2) for n in n_samples]
    if effort not in ("FFTW_MEASURE", "FFTW_PATIENT", "FFTW_EXHAUSTIVE"):
        raise InputError(
            "effort", effort, "-", "must be 'FFTW_MEASURE', 'FFTW_PATIENT' or 'FFTW_EXHAUSTIVE'"
        )
    if _lib() is None:
        return None
    with _cache_lock:
        _load_wisdom()
        for n in sizes:
            for shape, inverse in (((n // 2 + 1,), True), ((n,), False)):
                _cache[(shape, n, inverse)] = _Plan(shape, n, inverse, effort)
                _cache.move_to_end((shape, n, inverse))
        while len(_cache) > _MAX_PLANS:
            _cache.popitem(last=False)
        return _save_wisdom()


def irfft(x: np.ndarray, n: int, axis: int = -1) -> np.ndarray:
    """Inverse of :func:`rfft`: real array of length ``n`` along ``axis``.

    Parameters
    ----------
    x : numpy.ndarray
        Complex half-spectrum, ``n // 2 + 1`` entries along ``axis``. [unit]
    n : int
        Length of the real output along ``axis``. [-]
    axis : int, default -1
        Transform axis. [-]

    Returns
    -------
    numpy.ndarray
        float64 array, ``x[k]`` → ``(1/n) Σ_k X_k e^{2πi k j/n}`` (numpy convention). [unit]
    """
    x = np.asarray(x)
    if _lib_for(n) is None:
        return np.fft.irfft(x, n, axis=axis)
    if x.shape[axis] != n // 2 + 1:
        return np.fft.irfft(x, n, axis=axis)  # padding/truncation: rare, let numpy do it
    xm = np.moveaxis(x, axis, -1)
    out = _plan(xm.shape, int(n), True)(xm)
    return np.moveaxis(out, -1, axis)


def irfft_input(n: int) -> np.ndarray:
    """A new complex work array of ``n // 2 + 1`` entries for :func:`irfft_overwrite`.

    SIMD-aligned as the FFTW plans require (a plain array with the numpy backend).
    """
    if _lib_for(n) is None:
        return np.empty(n // 2 + 1, dtype=np.complex128)
    return _lib().empty_aligned(n // 2 + 1, dtype="complex128")


def irfft_overwrite(x: np.ndarray, n: int) -> np.ndarray:
    """Unnormalized 1-D inverse real FFT ``n · irfft(x, n)`` that may overwrite ``x``.

    Parameters
    ----------
    x : numpy.ndarray
        Complex half-spectrum from :func:`irfft_input` (``n // 2 + 1`` entries); its
        content is destroyed. [unit]
    n : int
        Length of the real output. [-]

    Returns
    -------
    numpy.ndarray
        ``Σ_k X_k e^{2πi k j/n}``, a new array (no 1/n factor: fold it into ``x`` while
        filling it, which saves a pass over the output). [unit]

    Notes
    -----
    The plan runs on ``x`` itself (FFTW's new-array execute): no copy into the plan's
    buffer, so filling ``x`` can be fused with computing it.  An input-preserving plan
    on the caller's array was tried: 1–3 ms slower for 2^20 points than this
    input-destroying plan plus the fused copy.
    """
    if _lib_for(n) is None:
        return np.fft.irfft(x, n, norm="forward")
    return _plan(x.shape, int(n), True).run(x)


def rfft(x: np.ndarray, axis: int = -1) -> np.ndarray:
    """Real-input FFT along ``axis`` (numpy convention, no normalization).

    Parameters
    ----------
    x : numpy.ndarray
        Real samples. [unit]
    axis : int, default -1
        Transform axis. [-]

    Returns
    -------
    numpy.ndarray
        complex128 half-spectrum with ``n // 2 + 1`` entries along ``axis``. [unit]
    """
    x = np.asarray(x)
    if np.iscomplexobj(x) or _lib_for(np.shape(x)[axis]) is None:
        return np.fft.rfft(x, axis=axis)
    xm = np.moveaxis(x, axis, -1)
    out = _plan(xm.shape, xm.shape[-1], False)(xm)
    return np.moveaxis(out, -1, axis)
