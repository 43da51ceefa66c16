"""The element wave kinematics of a block of frequencies as one compiled loop
(:func:`kinematics_block`): what :func:`stochcable.dynamics.loads.kinematics_closed_forms.
kinematics_block` forms with NumPy.

Per element (wet part ξ ∈ [p, q], L = q − p) and frequency it evaluates the closed
forms of :mod:`~stochcable.dynamics.loads.kinematics_closed_forms` for the kinematics of
Tuah (1982), eqs. 5.2.8–5.2.11 (:func:`~stochcable.dynamics.loads.element_kinematics.
element_wave_kinematics`): with E₁ = k z − i k χ, E₂ = −k(z + 2h) − i k χ (linear in ξ
along the element, slopes α₁ = k dz − i k dχ and α₂ = −k dz − i k dχ) and
D = 1 − e^{−2kh},

- the consistent moments ∫_p^q N_i e^{E(ξ)} dξ, N_a = 1 − ξ, N_b = ξ, factored at the
  end c of the wet part where Re E is largest (no overflow whatever |α|·L) as
  e^{E(c)}(L φ1(x), c L φ1(x) ± L² ψ(x)), x = ∓α L with Re x <= 0,
  φ1(x) = (e^x − 1)/x and ψ(x) = ((x − 1)e^x + 1)/x² (a 15-term Horner series for
  |x| < 0.5, the same coefficients), the second exponent's φ1, ψ the conjugates of the
  first's where dz ≠ 0; then u_h = ω(m₁ + m₂)/D and u_z = iω(m₁ − m₂)/D (deep water:
  D = 1, no E₂);
- the mean squares ∫|u_h|² dξ = ω²(K₁ + K₂ + 2e^{−2kh}L)/D² and ∫|u_z|² dξ =
  ω² max(K₁ + K₂ − 2e^{−2kh}L, 0)/D², K_j = ∫ e^{2 Re E_j} dξ (deep water: both ω²K₁);
- at ω = 0 in finite depth the long-wave limit u_h = √(g/h), u_z = 0.

The NumPy form makes ≈ 30 passes over (frequency × element) temporaries, evaluating the
series and the closed forms everywhere, with three complex exponentials per element and
frequency (libm's cos and sin).  Here, per chunk of ≈ 512 elements ×
frequencies, vectorized passes form the phases (the same angles, rounded the same way),
their cos and sin (in line: Cody–Waite reduction on π/2 and Taylor series, within an ulp
or two of libm's; libm beyond |θ| = 1e6) and the series of φ1 and ψ on every entry; then
a scalar loop takes each (element, frequency) once: the exponentials e^{Re E} at the two
factoring ends and the two e^{2 Re E} of the mean squares (deep water: the square of
e^{Re E}; in finite depth their own, as in the NumPy form, so that K₁ + K₂ − 2e^{−2kh}L
cancels the same way, to exactly 0 on the seabed), the closed forms where |x| >= 0.5
(x⁻¹ = x̄/|x|² once) and the combinations.  The factors of a frequency (D, e^{−2kh})
are formed once per call: half the time of the NumPy form (measured in
docs/benchmarks/dynamics.md, "Element wave kinematics").

The same formulas: equal to the NumPy form to a few ulps of each element's largest
value (libm's exponential against NumPy's vectorized one, e^{2a} as (e^a)² in deep
water, the in-line cos and sin, x⁻¹ formed once), except where the NumPy form cancels:
the vertical mean square in shallow water and near the seabed (≈ 1e-16 of the
horizontal one, documented in :func:`~stochcable.dynamics.loads.element_kinematics.
element_wave_kinematics`).  A wholly dry element gets exact zeros (the NumPy form
multiplies e^{2kz} at its dry end by L = 0: NaN once 2kz > 709, 97 m above the water at
6 rad/s).

Imported lazily (numba's import is slow); compiled with ``cache=True``
(:func:`stochcable.compiled.jit_cached`).  Single-threaded (one thread per worker).

References
----------
Tuah, H. (1982), Cable dynamics in an ocean environment, PhD thesis, Oregon State University.
"""

from __future__ import annotations

import math

import numba
import numpy as np
from numba import types

from stochcable.compiled import jit_cached
from stochcable.dynamics.loads.kinematics_closed_forms import (
    _PHI1_COEF,
    _PSI_COEF,
    _SERIES_RADIUS,
)

__all__ = ["kinematics_block"]

# cos and sin of the phases, in a loop the compiler vectorizes (libm's cos and sin, ≈ 10 ns
# each, cost more than the rest of the kernel): θ = nπ/2 + r, |r| <= π/4, r by Cody–Waite
# reduction on π/2 = _PIO2_1 + _PIO2_2 + _PIO2_3 (fdlibm's pio2_1, pio2_2, pio2_2t; the
# first two of 33 significant bits, so n·_PIO2_1 and n·_PIO2_2 are exact for |n| < 2^20),
# then the Taylor series of sin r to r¹⁷ and cos r to r¹⁸ (remainders below 1e-19 and
# 4e-21 on |r| <= π/4): within an ulp or two of libm's.
_PIO2_1 = float.fromhex("0x1.921fb54400000p+0")
_PIO2_2 = float.fromhex("0x1.0b4611a600000p-34")
_PIO2_3 = float.fromhex("0x1.3198a2e037073p-69")
_TWO_OVER_PI = 2.0 / math.pi
# (x + 1.5·2⁵²) − 1.5·2⁵²: x rounded to an integer, |x| < 2⁵¹ (adds only: vectorized)
_ROUND = 1.5 * 2.0**52
# |θ| from which libm's cos and sin are used instead (n·_PIO2_1 no longer exact)
_PHASE_LIMIT = 1.0e6
_SIN = tuple((-1.0) ** i / math.factorial(2 * i + 1) for i in range(1, 9))  # r³ … r¹⁷
_COS = tuple((-1.0) ** i / math.factorial(2 * i) for i in range(2, 10))  # r⁴ … r¹⁸
# elements × frequencies per chunk of the vectorized passes (their scratch in L1/L2)
_CHUNK = 512
# rows of the scratch array, per entry of a chunk: the three phases (e^{E₁} at c₁, the
# argument x, e^{E₂} at c₂), their cos and sin, x (real, imaginary), the series of φ1(x)
# and ψ(x) (real, imaginary), x_k and the series of φ1(x_k)
_THETA, _COS_T, _SIN_T, _X, _SER, _XK, _PHIK, _ROWS = 0, 3, 6, 9, 11, 15, 16, 17


_inline = numba.njit(nogil=True, inline="always")  # steps of the kernel, inlined


@_inline
def _sincos(sc, row, m):  # noqa: ANN001
    """cos θ and sin θ of the phases of row ``row``, entries [0, m) of the scratch (no
    calls, selects only: the compiler vectorizes the loop; libm beyond _PHASE_LIMIT)."""
    theta = sc[_THETA + row]
    cos_t = sc[_COS_T + row]
    sin_t = sc[_SIN_T + row]
    for j in range(m):
        t = theta[j]
        n = (t * _TWO_OVER_PI + _ROUND) - _ROUND  # nearest integer
        r = ((t - n * _PIO2_1) - n * _PIO2_2) - n * _PIO2_3
        r2 = r * r
        ps = _SIN[7]
        ps = ps * r2 + _SIN[6]
        ps = ps * r2 + _SIN[5]
        ps = ps * r2 + _SIN[4]
        ps = ps * r2 + _SIN[3]
        ps = ps * r2 + _SIN[2]
        ps = ps * r2 + _SIN[1]
        ps = ps * r2 + _SIN[0]
        sr = r + r * r2 * ps
        pc = _COS[7]
        pc = pc * r2 + _COS[6]
        pc = pc * r2 + _COS[5]
        pc = pc * r2 + _COS[4]
        pc = pc * r2 + _COS[3]
        pc = pc * r2 + _COS[2]
        pc = pc * r2 + _COS[1]
        pc = pc * r2 + _COS[0]
        hz = 0.5 * r2
        wc = 1.0 - hz
        cr = wc + (((1.0 - wc) - hz) + r2 * r2 * pc)  # 1 − r²/2 + …, compensated
        quad = n - 4.0 * ((0.25 * n + _ROUND) - _ROUND)  # n mod 4 in −2 … 2
        aq = abs(quad)
        odd = aq == 1.0
        c0 = sr if odd else cr
        s0 = cr if odd else sr
        cos_t[j] = -c0 if (quad == 1.0) | (aq == 2.0) else c0
        sin_t[j] = -s0 if (quad == -1.0) | (aq == 2.0) else s0
    for j in range(m):
        if abs(theta[j]) >= _PHASE_LIMIT:
            cos_t[j] = math.cos(theta[j])
            sin_t[j] = math.sin(theta[j])


@_inline
def _passes(k, za, zb, chi, p, q, c_phi, c_psi, e0, e1, n_rows, sc):  # noqa: ANN001
    """The vectorized passes over elements [e0, e1) × frequencies, into the scratch rows
    ``sc`` (_THETA …): the phases as the exponents of :func:`_element`, their cos and
    sin, x and x_k, and the series of φ1(x), ψ(x) and φ1(x_k) (Horner; where |x| >= 0.5
    they are not used)."""
    n_f = k.size
    n_c = c_phi.size
    m = (e1 - e0) * n_f
    for e in range(e0, e1):
        pe = p[e]
        qe = q[e]
        length = qe - pe
        dz_e = zb[e] - za[e]
        chi_e = chi[e]
        dchi_e = chi[e + 1] - chi_e
        o = (e - e0) * n_f
        for j in range(n_f):
            kj = k[j]
            dz = kj * dz_e
            phase0 = -(kj * chi_e)
            dphase = -(kj * dchi_e)
            grow = dz >= 0.0
            s = -1.0 if grow else 1.0
            sc[_THETA, o + j] = phase0 + dphase * (qe if grow else pe)
            sc[_THETA + 1, o + j] = s * dphase * length
            sc[_THETA + 2, o + j] = phase0 + dphase * (qe if -dz >= 0.0 else pe)
            sc[_X, o + j] = s * dz * length
            sc[_X + 1, o + j] = s * dphase * length
            two_dz = 2.0 * dz
            sc[_XK, o + j] = (-two_dz if two_dz >= 0.0 else two_dz) * length
    xs = sc[_X : _X + 2]
    ser = sc[_SER : _SER + 4]
    xk_s = sc[_XK]
    phik_s = sc[_PHIK]
    for j in range(m):  # Horner, the coefficients in the outer loop
        ser[0, j] = c_phi[n_c - 1]
        ser[1, j] = 0.0
        ser[2, j] = c_psi[n_c - 1]
        ser[3, j] = 0.0
        phik_s[j] = c_phi[n_c - 1]
    for i in range(n_c - 2, -1, -1):
        a = c_phi[i]
        b = c_psi[i]
        for j in range(m):
            xr = xs[0, j]
            xi = xs[1, j]
            fr = ser[0, j]
            fi = ser[1, j]
            ser[0, j] = (fr * xr - fi * xi) + a
            ser[1, j] = fr * xi + fi * xr
            fr = ser[2, j]
            fi = ser[3, j]
            ser[2, j] = (fr * xr - fi * xi) + b
            ser[3, j] = fr * xi + fi * xr
            phik_s[j] = phik_s[j] * xk_s[j] + a
    for row in range(n_rows):
        _sincos(sc, row, m)


@_inline
def _moments(r, f1, f2, full, grow, c, length):  # noqa: ANN001
    """∫_p^q (1 − ξ) e^{E} dξ and ∫_p^q ξ e^{E} dξ = r·(…) with r = e^{E(c)}, c the end
    where Re E is largest (c = q where ``grow``), from φ1 and ψ of x
    (kinematics_closed_forms._exp_moments; ``full``: p = 0, q = 1, its shorter form)."""
    if full:
        d12 = f1 - f2
        if grow:
            return r * f2, r * d12
        return r * d12, r * f2
    t1 = length * f1
    t2 = ((-1.0 if grow else 1.0) * (length * length)) * f2
    return r * ((1.0 - c) * t1 - t2), r * (c * t1 + t2)


@_inline
def _element(e, o, w, k, za, zb, chi, p, q, h, u0, radius, fw, sc, vel, sq):  # noqa: ANN001
    """vel[e] and sq[:, :, e] of element e (its entries from ``o`` in the scratch rows
    ``sc`` of :func:`_passes`; ``fw`` = (c, 2e^{−2kh}) per frequency, (2, n_f))."""
    deep = math.isinf(h)
    radius2 = radius * radius
    pe = p[e]
    qe = q[e]
    length = qe - pe
    full = pe == 0.0 and qe == 1.0  # wet over its whole length (c = 0 or 1)
    za_e = za[e]
    dz_e = zb[e] - za_e
    dchi_e = chi[e + 1] - chi[e]
    z2_e = za_e + 2.0 * h
    side_b = 0.5 * (qe * qe - pe * pe)
    for j in range(k.size):
        kj = k[j]
        dz = kj * dz_e
        dphase = -(kj * dchi_e)
        kza = kj * za_e
        # φ1, ψ of x = sα₁L, s = −1 for Re α₁ >= 0 (Re x <= 0)
        grow = dz >= 0.0
        s = -1.0 if grow else 1.0
        x = complex(s * dz * length, s * dphase * length)
        if x.real * x.real + x.imag * x.imag < radius2:  # |x| < radius: the series
            f1 = complex(sc[_SER, o + j], sc[_SER + 1, o + j])
            f2 = complex(sc[_SER + 2, o + j], sc[_SER + 3, o + j])
        else:
            ex = math.exp(x.real)
            em1 = complex(ex * sc[_COS_T + 1, o + j] - 1.0, ex * sc[_SIN_T + 1, o + j])
            inv = x.conjugate() / (x.real * x.real + x.imag * x.imag)
            f1 = em1 * inv
            f2 = (em1 * (x - 1.0) + x) * (inv * inv)
        # moments of e^{E₁}, factored at c₁
        c = qe if grow else pe
        ex1 = math.exp(kza + dz * c)
        r = complex(ex1 * sc[_COS_T, o + j], ex1 * sc[_SIN_T, o + j])
        ma1, mb1 = _moments(r, f1, f2, full, grow, c, length)
        # ∫ e^{2kz} dξ = e^{2 Re E₁(c₁)} L φ1(−|2dz|·L)
        xk = sc[_XK, o + j]
        phik = sc[_PHIK, o + j] if abs(xk) < radius else math.expm1(xk) / xk
        if deep:  # e^{2a} as (e^a)² (no cancellation follows)
            k1 = (ex1 * ex1) * length * phik
            wj = w[j]
            vel[e, 0, 0, j] = ma1 * wj
            vel[e, 1, 0, j] = mb1 * wj
            vel[e, 0, 1, j] = complex(-ma1.imag * wj, ma1.real * wj)
            vel[e, 1, 1, j] = complex(-mb1.imag * wj, mb1.real * wj)
            sq[0, j, e] = k1 * (wj * wj)
            sq[1, j, e] = k1 * (wj * wj)
            continue
        if w[j] == 0.0:  # long-wave limit: u_h = √(g/h) uniform, u_z = 0
            vel[e, 0, 0, j] = complex(u0 * (length - side_b), 0.0)
            vel[e, 1, 0, j] = complex(u0 * side_b, 0.0)
            vel[e, 0, 1, j] = 0j
            vel[e, 1, 1, j] = 0j
            sq[0, j, e] = u0 * u0 * length
            sq[1, j, e] = 0.0
            continue
        # moments of e^{E₂} (slope −dz − i k dχ) factored at c₂, φ1 and ψ conjugated
        # where dz ≠ 0 (x₂ = x̄; the same x where dz = 0)
        e2a = -(kj * z2_e)
        if dz != 0.0:
            f1 = f1.conjugate()
            f2 = f2.conjugate()
        grow2 = -dz >= 0.0
        c = qe if grow2 else pe
        ex2 = math.exp(e2a + -dz * c)
        r = complex(ex2 * sc[_COS_T + 2, o + j], ex2 * sc[_SIN_T + 2, o + j])
        ma2, mb2 = _moments(r, f1, f2, full, grow2, c, length)
        # ∫ e^{−2k(z+2h)} dξ (the same φ1)
        # ∫ e^{2kz} dξ and ∫ e^{−2k(z+2h)} dξ (the same φ1) with their own exponentials,
        # as the NumPy form: K₁ + K₂ − 2e^{−2kh}L cancels (exactly at the seabed)
        k1 = math.exp(2.0 * kza + (2.0 * dz) * (qe if grow else pe)) * length * phik
        k2 = math.exp(2.0 * e2a + -(2.0 * dz) * c) * length * phik
        cj = fw[0, j]
        da = ma1 - ma2
        db = mb1 - mb2
        vel[e, 0, 0, j] = (ma1 + ma2) * cj
        vel[e, 1, 0, j] = (mb1 + mb2) * cj
        vel[e, 0, 1, j] = complex(-da.imag * cj, da.real * cj)
        vel[e, 1, 1, j] = complex(-db.imag * cj, db.real * cj)
        cross2 = fw[1, j] * length
        c2 = cj * cj
        sq[0, j, e] = (k1 + k2 + cross2) * c2
        d = k1 + k2 - cross2
        sq[1, j, e] = (d if d > 0.0 else 0.0) * c2


def _block(w, k, za, zb, chi, p, q, h, g, c_phi, c_psi, radius, vel, sq):  # noqa: ANN001
    """vel[e, end, part, j] and sq[part, j, e] of the module docstring, frequency j of
    ``w`` (wavenumbers ``k``); c_phi, c_psi the series coefficients of φ1 and ψ."""
    n_el = za.size
    n_f = w.size
    deep = math.isinf(h)
    # per frequency: c = ω/D (0 at ω = 0; deep water ω) and 2e^{−2kh}
    fw = np.zeros((2, n_f))
    for j in range(n_f):
        if deep:
            fw[0, j] = w[j]
        else:
            fw[0, j] = 0.0 if w[j] == 0.0 else w[j] / (-math.expm1(-2.0 * k[j] * h))
            fw[1, j] = 2.0 * math.exp(-2.0 * k[j] * h)
    u0 = 0.0 if deep else math.sqrt(g / h)
    # chunks of about _CHUNK elements × frequencies: the vectorized passes over the
    # chunk, then its elements one by one
    per = max(1, _CHUNK // max(n_f, 1))
    m_cap = per * n_f
    sc = np.empty((_ROWS, m_cap))
    for e0 in range(0, n_el, per):
        e1 = min(n_el, e0 + per)
        _passes(k, za, zb, chi, p, q, c_phi, c_psi, e0, e1, 2 if deep else 3, sc)
        for e in range(e0, e1):
            if q[e] - p[e] == 0.0:  # dry: no load
                for j in range(n_f):
                    for end in range(2):
                        vel[e, end, 0, j] = 0j
                        vel[e, end, 1, j] = 0j
                    sq[0, j, e] = 0.0
                    sq[1, j, e] = 0.0
                continue
            o = (e - e0) * n_f
            _element(e, o, w, k, za, zb, chi, p, q, h, u0, radius, fw, sc, vel, sq)


_F1 = types.Array(types.float64, 1, "C", readonly=True)
_SIGNATURE = types.void(
    _F1,
    _F1,
    _F1,
    _F1,
    _F1,
    _F1,
    _F1,
    types.float64,
    types.float64,
    _F1,
    _F1,
    types.float64,
    types.Array(types.complex128, 4, "A"),
    types.Array(types.float64, 3, "A"),
)
"""(ω, k, z_a, z_b, χ, p, q, h, g, φ1 and ψ series coefficients, series radius, vel,
sq); vel and sq may be strided views (a block of frequencies of the whole arrays)."""

_kernel, _ = jit_cached(_block, _SIGNATURE, "element wave kinematics")


def kinematics_block(
    w: np.ndarray,
    k: np.ndarray,
    za: np.ndarray,
    zb: np.ndarray,
    chi: np.ndarray,
    p: np.ndarray,
    q: np.ndarray,
    cb: float,
    sb: float,
    h: float,
    g: float,
    vel: np.ndarray,
    sq: np.ndarray,
) -> None:
    """The element kinematics of the frequencies ``w`` written into ``vel`` and ``sq``
    (module docstring; the arguments of
    :func:`stochcable.dynamics.loads.kinematics_closed_forms.kinematics_block`, ``geo`` spread).

    Parameters
    ----------
    w, k : ndarray, shape (n_f,)
        Frequencies and their wavenumbers. [rad/s], [rad/m]
    za, zb : ndarray, shape (n_el,)
        Depth of each element's nodes a and b. [m]
    chi : ndarray, shape (n_el + 1,)
        Node positions along the heading, x cos β + y sin β. [m]
    p, q : ndarray, shape (n_el,) or (1, n_el)
        Wet part ξ ∈ [p, q] of each element (p = q: dry). [-]
    cb, sb : float
        cos β, sin β (not used: the parts are along the heading). [-]
    h : float
        Water depth, ``inf`` for deep water. [m]
    g : float
        Acceleration of gravity. [m/s²]
    vel : ndarray, complex, shape (n_el, 2, 2, n_f)
        Written: ∫N_i u dξ per element, end (a, b) and part (horizontal along β,
        vertical); any strides. [(m/s)/m]
    sq : ndarray, shape (2, n_f, n_el)
        Written: ∫|u_h|² dξ and ∫|u_z|² dξ; any strides. [(m/s)²/m²]
    """

    def flat(a: np.ndarray) -> np.ndarray:
        return np.ascontiguousarray(a, dtype=float).reshape(-1)

    _kernel(
        flat(w),
        flat(k),
        flat(za),
        flat(zb),
        flat(chi),
        flat(p),
        flat(q),
        float(h),
        float(g),
        _PHI1_COEF,
        _PSI_COEF,
        float(_SERIES_RADIUS),
        vel,
        sq,
    )
