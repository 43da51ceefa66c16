"""Compiled (numba) coefficient kernel of :func:`stochcable.sea.realization.simulate_sea`.

Imported lazily by :mod:`stochcable.sea.realization` only when a realization of ≥ 2^16 lines runs
(importing numba costs ~0.2 s); ``import stochcable``, the CLI and the service start do
not import it.  The kernel performs exactly the floating-point operations of the NumPy
kernel ``coefficients._phasor_chunk``, in the same order, without fast-math and without FMA
contraction except for the complex product T·e, which is written with explicit fused
multiply-adds in the form NumPy's SIMD complex multiply uses on x86-64 with FMA3
(re = fma(T_r, e_r, −T_i e_i), im = fma(T_r, e_i, T_i e_r); checked against exact
rational arithmetic in tests/sea/test_sea.py).  There both kernels give the same bits;
where numpy's loop is not fused they differ by ≲ 1 ulp of |X|.  The compiled
kernel's bits do not depend on the CPU (``llvm.fma`` is correctly rounded everywhere).

Compiled at import for one explicit signature, with ``nogil=True`` (the two threads of
``simulate_sea`` run it in parallel; no numba threading layer is used) and ``cache=True``
(the machine code is stored in ``__pycache__`` next to this file, or in numba's user
cache directory, or in ``$NUMBA_CACHE_DIR``; where none is writable the kernel is
compiled in memory in each process, with a UserWarning).
"""

from __future__ import annotations

import math

import numpy as np
from llvmlite import ir
from numba import types
from numba.extending import intrinsic

from stochcable.compiled import jit_cached

__all__ = ["phasor_chunk", "CACHED"]

_TABLE_SIZE = 8192.0  # = sea._TABLE_SIZE (2^13 entries)
_DELTA = 2.0 * math.pi / 8192  # the same constant as coefficients._phasor_chunk's
_COS4 = 1.0 / 24.0
_SIN3 = -1.0 / 6.0


@intrinsic
def _fma(typingctx, x, y, z):  # noqa: ANN001, ARG001 - numba intrinsic protocol
    """x·y + z with one rounding (LLVM ``llvm.fma.f64``)."""
    sig = types.float64(types.float64, types.float64, types.float64)

    def codegen(context, builder, signature, args):  # noqa: ANN001, ARG001
        d = ir.DoubleType()
        fn = builder.module.declare_intrinsic("llvm.fma", [d], ir.FunctionType(d, [d, d, d]))
        return builder.call(fn, args)

    return sig, codegen


def _phasor_chunk(u, s, c2, alpha, beta, table, out, fft_in, scale, jbuf):  # noqa: ANN001
    """out = a·e^{−iθ}, fft_in = out·scale; a = √(c2·S) (× √(α²+β²) when α is given).

    Same operations as ``coefficients._phasor_chunk`` (see there for the table and series);
    ``alpha``/``beta`` of size 0 select DSA, else NSA with the gain √(α²+β²) computed
    here (``np.hypot``, as NumPy's).  Two passes over the chunk: the first (vectorized
    by LLVM) writes amp·e^{iδ} into ``out`` and the table index j into ``jbuf``; the
    second (scalar: the table gather does not vectorize) forms T[j]·(amp·e^{iδ}).
    """
    n = u.shape[0]
    if (
        jbuf.shape[0] < n
        or s.shape[0] != n
        or out.shape[0] != n
        or fft_in.shape[0] != n
        or (alpha.shape[0] != 0 and (alpha.shape[0] != n or beta.shape[0] != n))
    ):
        raise ValueError("phasor_chunk: inconsistent array sizes")  # no bounds checks below
    if alpha.shape[0] == 0:
        for i in range(n):
            x = u[i] * _TABLE_SIZE
            w = math.floor(x)
            jbuf[i] = w
            x = (x - w) * _DELTA
            d2 = x * x
            amp = math.sqrt(s[i] * c2)
            out[i] = complex(((d2 * _COS4 - 0.5) * d2 + 1.0) * amp, ((d2 * _SIN3 + 1.0) * x) * amp)
    else:
        for i in range(n):
            x = u[i] * _TABLE_SIZE
            w = math.floor(x)
            jbuf[i] = w
            x = (x - w) * _DELTA
            d2 = x * x
            amp = math.sqrt(s[i] * c2) * np.hypot(alpha[i], beta[i])
            out[i] = complex(((d2 * _COS4 - 0.5) * d2 + 1.0) * amp, ((d2 * _SIN3 + 1.0) * x) * amp)
    for i in range(n):
        t = table[int(jbuf[i])]
        e = out[i]
        re = _fma(t.real, e.real, -(t.imag * e.imag))
        im = _fma(t.real, e.imag, t.imag * e.real)
        out[i] = complex(re, im)
        fft_in[i] = complex(re * scale, im * scale)


_RO = types.Array(types.float64, 1, "C", readonly=True)  # accepts writable arrays too
_RW = types.Array(types.float64, 1, "C")
_TAB = types.Array(types.complex128, 1, "C", readonly=True)
_OUT = types.Array(types.complex128, 1, "C")
_SIGNATURE = types.void(_RO, _RO, types.float64, _RO, _RO, _TAB, _OUT, _OUT, types.float64, _RW)
"""(u, S, c2, α, β, table, out, fft_in, scale, jbuf): compiled once, at import (a
read-only S, e.g. a density's cached array, then needs no second compilation)."""


phasor_chunk, CACHED = jit_cached(_phasor_chunk, _SIGNATURE, "sea")
