"""Compiled (numba) start grid of :func:`stochcable.line.strumming.balance.lock_in_balance`.

Imported lazily, by the first lock-in balance a process runs (importing numba costs
~0.2 s; ``import stochcable``, the CLI and the service start do not import it).  The
kernel evaluates the scale-free modal residual |Z A − L|/(|Z A| + |L|) of the balance
on the (amplitude × frequency) start grid, every element's wake by the same closed form
as :func:`~stochcable.line.strumming.balance.wake_response` (the largest root of the
cubic x|a0 + a1 x|² = |rhs|², Cardano or the trigonometric form, two Newton steps).
The coefficients a0, a1 and the cubic's normalized x², x¹ coefficients depend on the
frequency and the element only, so they are formed once per grid column; NumPy's
version formed them for every grid point and element, with a dozen temporaries of
that size — 4 ms of the 5 ms a mode's screening took.  The grid only chooses where
least squares starts, so round-off differences from the NumPy form change no root.

Most grid points are far from a root, and a bound proves it without a root: with
α = ωω_sḠC_L0² and β = ωω_sḠ(1 + 3r²)/4 (Im a0 = −α, Im a1 = β), Im(a0 + a1x) ≥ βx/2 for
x ≥ 2α/β, so |c| = √x ≤ √(2α/β) + (4|rhs|²/β²)^(1/6); and |c| ≤ |rhs|/m with m the
distance from 0 to the ray a0 + a1x, x ≥ 0.  Summed over the elements (|rhs| ∝ A),
|L| ≤ min(S₁ + S₂A^(1/3), S_lin A) per frequency; where that is at most |Z A|/3 the
residual is at least 0.5, above the start threshold of
:func:`~stochcable.line.strumming.balance.lock_in_balance`, and the point holds 1.0
(no start, and no local minimum beside it changes).  On the chain example every point
of its three candidate modes is proven so (no lock-in: no cube root at all).

Compiled with ``cache=True`` (the machine code is kept in ``__pycache__`` next to this
file, in numba's user cache directory or in ``$NUMBA_CACHE_DIR``; without a writable
one, in memory in each process, with a warning: :func:`stochcable.compiled.jit_cached`).
"""

from __future__ import annotations

import math

import numpy as np
from numba import types

from stochcable.compiled import jit_cached
from stochcable.line.strumming.bound import LockInGrid

__all__ = ["balance_grid"]


def _balance_grid(
    amps, omegas, omega_n, zeta, psi, q, diameter, omega_s, lift0sq, g, big_h, f, out
):
    """out[i, j] = the relative modal residual at amplitude amps[i], frequency omegas[j]."""
    n = psi.size
    a0r = np.empty(n)
    a0i = np.empty(n)
    a1r = np.empty(n)
    a1i = np.empty(n)
    p2 = np.empty(n)
    p1 = np.empty(n)
    big_p = np.empty(n)
    q_base = np.empty(n)
    inv_c3 = np.empty(n)
    rhs_unit = np.empty(n)
    for j in range(omegas.size):
        w = omegas[j]
        zr = omega_n * omega_n - w * w
        zi = 2.0 * zeta * omega_n * w
        z_abs = math.hypot(zr, zi)
        s1 = 0.0
        s2 = 0.0
        s_lin = 0.0
        for e in range(n):
            ws = omega_s[e]
            r2 = (w / ws) ** 2
            a0r[e] = ws * ws - w * w + ws * ws * big_h * lift0sq[e]
            a0i[e] = -w * ws * g * lift0sq[e]
            a1r[e] = -ws * ws * big_h * (3.0 + r2) / 4.0
            a1i[e] = w * ws * g * (1.0 + 3.0 * r2) / 4.0
            cc3 = a1r[e] * a1r[e] + a1i[e] * a1i[e]
            cc2 = 2.0 * (a0r[e] * a1r[e] + a0i[e] * a1i[e])
            cc1 = a0r[e] * a0r[e] + a0i[e] * a0i[e]
            inv_c3[e] = 1.0 / cc3
            p2[e] = cc2 / cc3
            p1[e] = cc1 / cc3
            big_p[e] = p1[e] - p2[e] * p2[e] / 3.0
            q_base[e] = 2.0 * p2[e] ** 3 / 27.0 - p2[e] * p1[e] / 3.0
            # |rhs|² per unit amplitude²: rhs = ω_s F̄ · iωAψ/D
            rhs_unit[e] = ws * f * w * psi[e] / diameter[e]
            # the bound |c| <= sqrt(2α/β) + (4/β²)^(1/6) |rhs|^(1/3) (module notes)
            alpha = w * ws * g * lift0sq[e]
            beta = a1i[e]
            weight = abs(q[e] * psi[e])
            s1 += weight * math.sqrt(2.0 * alpha / beta)
            s2 += weight * (4.0 / (beta * beta)) ** (1.0 / 6.0) * abs(rhs_unit[e]) ** (1.0 / 3.0)
            # and |c| <= |rhs|/m, m = min over x >= 0 of |a0 + a1 x|
            dot = a0r[e] * a1r[e] + a0i[e] * a1i[e]
            if dot >= 0.0:
                dist = math.hypot(a0r[e], a0i[e])
            else:
                dist = abs(a0r[e] * a1i[e] - a0i[e] * a1r[e]) * math.sqrt(inv_c3[e])
            s_lin += weight * abs(rhs_unit[e]) / dist if dist > 0.0 else math.inf
        for i in range(amps.size):
            a = amps[i]
            if min(s1 + s2 * a ** (1.0 / 3.0), s_lin * a) <= z_abs * a / 3.0:
                out[i, j] = 1.0  # |L| >= 3|R| proves the residual is at least 0.5
                continue
            right_r = 0.0
            right_i = 0.0
            for e in range(n):
                # c = rhs/(a0 + a1 x), rhs = i ω_s F̄ ω A ψ/D (purely imaginary)
                rhs_i = rhs_unit[e] * a
                k2 = rhs_i * rhs_i
                if k2 <= 0.0:
                    continue
                p0 = -k2 * inv_c3[e]
                bq = q_base[e] + p0
                disc = (bq / 2.0) ** 2 + (big_p[e] / 3.0) ** 3
                if disc >= 0.0:
                    sq = math.sqrt(disc)
                    # Cardano, cbrt(u) + cbrt(v) with cbrt(u)·cbrt(v) = −P/3: one cube
                    # root, of the term without cancellation
                    u = np.cbrt(-bq / 2.0 + sq) if bq < 0.0 else np.cbrt(-bq / 2.0 - sq)
                    t = u - big_p[e] / (3.0 * u) if u != 0.0 else 0.0
                else:
                    m = math.sqrt(max(-big_p[e] / 3.0, 0.0))
                    arg = min(max(-bq / (2.0 * m**3), -1.0), 1.0)
                    t = 2.0 * m * math.cos(math.acos(arg) / 3.0)
                x = t - p2[e] / 3.0
                for _ in range(2):
                    fx = ((x + p2[e]) * x + p1[e]) * x + p0
                    dfx = (3.0 * x + 2.0 * p2[e]) * x + p1[e]
                    if dfx != 0.0:
                        x = x - fx / dfx
                x = max(x, 0.0)
                dr = a0r[e] + a1r[e] * x
                di = a0i[e] + a1i[e] * x
                scale = rhs_i / (dr * dr + di * di)
                cr = scale * di
                ci = scale * dr
                right_r += q[e] * psi[e] * cr
                right_i += q[e] * psi[e] * ci
            left_r = zr * a
            left_i = zi * a
            num = math.hypot(left_r - right_r, left_i - right_i)
            out[i, j] = num / (math.hypot(left_r, left_i) + math.hypot(right_r, right_i))


_F1 = types.Array(types.float64, 1, "C", readonly=True)
_SIGNATURE = types.void(
    _F1,
    _F1,
    types.float64,
    types.float64,
    _F1,
    _F1,
    _F1,
    _F1,
    _F1,
    types.float64,
    types.float64,
    types.float64,
    types.Array(types.float64, 2, "C"),
)
"""(amps, omegas, ω_n, ξ, ψ, q, D, ω_s, C_L0², Ḡ, H̄, F̄, out)."""

_kernel, _ = jit_cached(_balance_grid, _SIGNATURE, "strumming lock-in start grid")


def balance_grid(grid: LockInGrid) -> np.ndarray:
    """Relative residual of the modal lock-in balance on a grid.

    Parameters
    ----------
    grid : LockInGrid
        The start grid and the mode's shedding elements.

    Returns
    -------
    ndarray, shape (n_a, n_w)
        |Z A − L|/(|Z A| + |L|), or 1.0 where a bound proves it is at least 0.5. [-]
    """
    as_f = np.ascontiguousarray
    amps, omegas = as_f(grid.amps, float), as_f(grid.omegas, float)
    out = np.empty((amps.size, omegas.size))
    _kernel(
        amps,
        omegas,
        float(grid.omega_n),
        float(grid.damping_ratio),
        as_f(grid.psi, float),
        as_f(grid.q, float),
        as_f(grid.diameter, float),
        as_f(grid.omega_s, float),
        as_f(np.asarray(grid.lift0, float) ** 2),
        float(grid.g),
        float(grid.big_h),
        float(grid.f),
        out,
    )
    return out
