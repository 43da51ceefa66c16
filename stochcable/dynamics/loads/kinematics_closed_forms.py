"""The element wave kinematics in closed form, NumPy: the consistent moments and the
mean square of the wave velocity integrated exactly along straight elements
(:func:`kinematics_block`; the model and its formulas in
:mod:`stochcable.dynamics.loads.element_kinematics`, Tuah (1982), eqs. 5.2.8–5.2.11).

The integrals are sums of exponentials e^{e0 + αξ} with e0, α linear in the element's
geometry: ∫ N_i e^{…} dξ by φ1(x) = (e^x − 1)/x and ψ(x) = ((x − 1)e^x + 1)/x² of an
argument with Re x <= 0 (factored at the endpoint where the exponential is largest: no
overflow), as series near x = 0.  The compiled loop
(:mod:`stochcable.dynamics.loads.kinematics_kernels`) evaluates the same formulas element by
element for large grids; this form is the reference and the path without numba.

References
----------
Tuah, H. (1982), Cable dynamics in an ocean environment, PhD thesis, Oregon State University.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["kinematics_block", "mean_block", "square_block"]

# |x| below which φ1 and ψ are summed as series (full relative precision; above it the
# closed forms lose at most ~1e-16·(1 + |e^x|)/|x| absolutely, harmless as |e^x| <= 1).
_SERIES_RADIUS = 0.5
# 15 terms: the remainder x^15/16! < 2e-18 for |x| < 0.5.
_SERIES_TERMS = 15
_PHI1_COEF = np.array([1.0 / math.factorial(n + 1) for n in range(_SERIES_TERMS)])
_PSI_COEF = np.array([1.0 / (math.factorial(n) * (n + 2)) for n in range(_SERIES_TERMS)])


def _series(x: np.ndarray, coef: np.ndarray) -> np.ndarray:
    out = np.full(x.shape, coef[-1], dtype=x.dtype)
    for c in coef[-2::-1]:
        out *= x
        out += c
    return out


def _phi1_psi(x: np.ndarray, want_psi: bool = True) -> tuple[np.ndarray, np.ndarray | None]:
    """φ1(x) = ∫₀¹ e^{xu} du = (e^x − 1)/x and ψ(x) = ∫₀¹ u e^{xu} du
    = ((x − 1)e^x + 1)/x², elementwise for Re x <= 0 (real or complex).

    Series (Horner, ``_SERIES_TERMS`` terms) for |x| < ``_SERIES_RADIUS``, where the
    closed forms cancel; closed forms (with expm1) elsewhere."""
    small = np.abs(x) < _SERIES_RADIUS
    # closed forms everywhere (no gather/scatter of the large part), then the series
    # over the small entries (where the closed forms cancel, 0/0 at x = 0)
    with np.errstate(divide="ignore", invalid="ignore"):
        if np.iscomplexobj(x):
            # e^x − 1 where the closed forms are kept (|x| >= 0.5, Re x <= 0: |e^x − 1|
            # >= 0.49, so the subtraction costs at most ~3 ulp); numpy's complex expm1
            # is 2.4x slower than its exp (0.27 ms per call on the chain)
            em1 = np.exp(x)
            em1 -= 1.0
        else:
            em1 = np.expm1(x)
        phi = em1 / x
        psi = None
        if want_psi:
            psi = em1 * (x - 1.0)
            psi += x
            psi /= x * x  # ((x − 1)e^x + 1)/x²
    if small.any():
        xs = x[small]
        phi[small] = _series(xs, _PHI1_COEF)
        if want_psi:
            psi[small] = _series(xs, _PSI_COEF)
    return phi, psi


def _moment_argument(alpha: np.ndarray, p: np.ndarray, q: np.ndarray) -> np.ndarray:
    """The argument x of φ1 and ψ in :func:`_exp_moments` (Re x <= 0)."""
    s = np.where(alpha.real >= 0.0, -1.0, 1.0)
    if np.all(p == 0.0) and np.all(q == 1.0):
        return s * alpha
    return s * alpha * (q - p)


def _exp_moments(
    e0: np.ndarray,
    alpha: np.ndarray,
    p: np.ndarray,
    q: np.ndarray,
    phi_psi: tuple[np.ndarray, np.ndarray] | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """∫_p^q (1 − ξ) e^{e0 + αξ} dξ and ∫_p^q ξ e^{e0 + αξ} dξ, elementwise.

    The exponential is factored at the endpoint c where Re(e0 + αξ) is largest (q when
    Re α >= 0, else p), so with t = |ξ − c|, x = −α(q − p) or α(q − p) (Re x <= 0):
    ∫_p^q e^{…} = e^{e0 + αc} L φ1(x) and ∫_p^q ξ e^{…} = e^{e0 + αc}(c L φ1(x) ± L² ψ(x)),
    L = q − p — never an overflow, whatever α·L (the integrand's largest value
    e^{Re(e0 + αc)} is <= 1 for wave kinematics).  L = 0 gives zeros.  ``phi_psi``:
    (φ1(x), ψ(x)) when the caller has them (x of :func:`_moment_argument`)."""
    length = q - p
    grow = alpha.real >= 0.0
    s = np.where(grow, -1.0, 1.0)
    if np.all(p == 0.0) and np.all(q == 1.0):
        # every element wet over its whole length (L = 1, c = 0 or 1): the general
        # expressions below with the factors 1 and 0 dropped — the same numbers
        # (x·1 and 0 + x are exact), a third fewer complex passes
        f1, f2 = _phi1_psi(s * alpha) if phi_psi is None else phi_psi
        ref = np.exp(np.where(grow, e0 + alpha, e0))
        d12 = f1 - f2
        return ref * np.where(grow, f2, d12), ref * np.where(grow, d12, f2)
    c = np.where(grow, q, p)
    f1, f2 = _phi1_psi(s * alpha * length) if phi_psi is None else phi_psi
    ref = np.exp(e0 + alpha * c)
    t1 = length * f1
    t2 = s * (length * length) * f2
    return ref * ((1.0 - c) * t1 - t2), ref * (c * t1 + t2)


def _exp_integral(
    e0: np.ndarray, alpha: np.ndarray, p: np.ndarray, q: np.ndarray, phi: np.ndarray | None = None
) -> np.ndarray:
    """∫_p^q e^{e0 + αξ} dξ for real e0, α (as :func:`_exp_moments`, factored at the
    larger endpoint).  ``phi``: φ1 of the argument −|α|(q − p) when the caller has it
    (the same for α and −α)."""
    length = q - p
    grow = alpha >= 0.0
    c = np.where(grow, q, p)
    if phi is None:
        phi, _ = _phi1_psi(np.where(grow, -alpha, alpha) * length, want_psi=False)
    return np.exp(e0 + alpha * c) * length * phi


def _complex(re: np.ndarray, im: np.ndarray) -> np.ndarray:
    """re + i·im in one pass (no complex temporaries)."""
    out = np.empty(re.shape, dtype=complex)
    out.real = re
    out.imag = im
    return out


def kinematics_block(
    w: np.ndarray,
    k: np.ndarray,
    geo: tuple,
    vel: np.ndarray,
    sq: np.ndarray | None,
) -> None:
    """The element kinematics of the frequencies ``w`` (wavenumbers ``k``) written into
    ``vel`` (the moments' parts, (n_el, 2, 2, n_w):
    :class:`~stochcable.dynamics.loads.element_parts.MomentParts`) and ``sq`` (the mean
    square's h and v, (2, n_w, n_el):
    :class:`~stochcable.dynamics.loads.element_parts.SquareParts`; None: the moments
    alone, the same numbers) on one block; ``geo`` =
    (z_a, z_b, χ, p, q, cos β, sin β, h, g).  Frequency-major (n_w, n_el) arrays
    throughout.  The NumPy form of
    :func:`stochcable.dynamics.loads.kinematics_kernels.kinematics_block`, the compiled loop
    :meth:`~stochcable.dynamics.loads.element_kinematics.KinematicsBlocks.form` calls for
    large grids where numba is available (not with ``STOCHCABLE_NUMBA=0``): the same
    formulas, ≈ 2–3x faster."""
    za, zb, chi, p, q, cb, sb, h, g = geo
    length = q - p
    za, zb, dry = _wet_ends(za, zb, length)
    dz = np.multiply.outer(k, zb - za)
    phase0 = -np.multiply.outer(k, chi[:-1])  # imaginary parts of the exponents
    dphase = -np.multiply.outer(k, chi[1:] - chi[:-1])
    kza = np.multiply.outer(k, za)
    alpha1 = _complex(dz, dphase)
    f12 = _phi1_psi(_moment_argument(alpha1, p, q))
    ma1, mb1 = _exp_moments(_complex(kza, phase0), alpha1, p, q, f12)
    zero_w = w == 0.0
    if math.isinf(h):
        coef = w.astype(complex)[:, None]
        mh = (ma1 * coef, mb1 * coef)
        mz = (ma1 * (1j * w)[:, None], mb1 * (1j * w)[:, None])
    else:
        e2a = -np.multiply.outer(k, za + 2.0 * h)
        # the second exponent's slope −dz + i·dphase: where dz ≠ 0 the sign s of
        # _exp_moments flips with Re α, so its argument is the conjugate of the first
        # one's and so are φ1 and ψ (exp, products, quotients and the series commute
        # with conjugation in IEEE arithmetic); where dz = 0 it is the same argument
        # (up to the sign of a zero real part).  Tested equal to the direct evaluation.
        flip = dz != 0.0
        f12_2 = tuple(np.where(flip, f.conj(), f) for f in f12)
        ma2, mb2 = _exp_moments(_complex(e2a, phase0), _complex(-dz, dphase), p, q, f12_2)
        c = _depth_factor(w, k, h)
        mh = ((ma1 + ma2) * c[:, None], (mb1 + mb2) * c[:, None])
        ic = (1j * c)[:, None]
        mz = ((ma1 - ma2) * ic, (mb1 - mb2) * ic)
        if zero_w.any():  # long-wave limit: u_h = √(g/h) uniform, u_z = 0
            u0 = math.sqrt(g / h)
            side_b = 0.5 * (q * q - p * p)
            mh[0][zero_w, :] = u0 * (length - side_b)
            mh[1][zero_w, :] = u0 * side_b
    for side in range(2):  # (n_el, n_w) each: the transposed block
        vel[:, side, 0] = mh[side].T
        vel[:, side, 1] = mz[side].T
    if sq is not None:  # (None: the moments alone)
        _squares(w, k, za, kza, dz, p, q, h, g, sq)
    if dry.any():  # (zeros, not e^{kz}·0: NaN once kz > 709 high above the water)
        vel[dry] = 0.0
        if sq is not None:
            sq[:, :, dry] = 0.0


def mean_block(w: np.ndarray, k: np.ndarray, geo: tuple) -> np.ndarray:
    """The wave velocity integrated over each element's wet part, ∫_p^q v dξ (the sum
    of :func:`kinematics_block`'s two moments, ∫N_a v + ∫N_b v, in one closed form:
    e^{e0 + αc}·L·φ1(x) of each exponential, no ψ), for the frequencies ``w``
    (wavenumbers ``k``) and ``geo`` as :func:`kinematics_block`'s: shape (n_el, 2,
    n_w), the horizontal (along β) and vertical parts.  [(m/s)/unit]"""
    za, zb, chi, p, q, _, _, h, g = geo
    length = q - p
    za, zb, dry = _wet_ends(za, zb, length)
    dz = np.multiply.outer(k, zb - za)
    phase0 = -np.multiply.outer(k, chi[:-1])
    dphase = -np.multiply.outer(k, chi[1:] - chi[:-1])
    alpha1 = _complex(dz, dphase)
    f1, _ = _phi1_psi(_moment_argument(alpha1, p, q), want_psi=False)
    i1 = _exp_mean(_complex(np.multiply.outer(k, za), phase0), alpha1, p, q, f1)
    if math.isinf(h):
        mh, mz = i1 * w[:, None], i1 * (1j * w)[:, None]
    else:
        e2a = -np.multiply.outer(k, za + 2.0 * h)
        # (the second exponent's φ1: the first one's conjugate where dz ≠ 0, as in
        # kinematics_block)
        f2 = np.where(dz != 0.0, f1.conj(), f1)
        i2 = _exp_mean(_complex(e2a, phase0), _complex(-dz, dphase), p, q, f2)
        c = _depth_factor(w, k, h)
        mh, mz = (i1 + i2) * c[:, None], (i1 - i2) * (1j * c)[:, None]
        zero_w = w == 0.0
        if zero_w.any():  # long-wave limit: u_h = √(g/h) uniform, u_z = 0
            mh[zero_w, :] = math.sqrt(g / h) * length
    out = np.empty((za.size, 2, w.size), dtype=complex)
    out[:, 0], out[:, 1] = mh.T, mz.T
    if dry.any():
        out[dry] = 0.0
    return out


def _exp_mean(
    e0: np.ndarray, alpha: np.ndarray, p: np.ndarray, q: np.ndarray, phi: np.ndarray
) -> np.ndarray:
    """∫_p^q e^{e0 + αξ} dξ, elementwise, factored at the endpoint where the real part
    of the exponent is largest (as :func:`_exp_moments`; ``phi`` φ1 of the argument of
    :func:`_moment_argument`)."""
    grow = alpha.real >= 0.0
    if np.all(p == 0.0) and np.all(q == 1.0):
        return np.exp(np.where(grow, e0 + alpha, e0)) * phi
    c = np.where(grow, q, p)
    return np.exp(e0 + alpha * c) * ((q - p) * phi)


def square_block(w: np.ndarray, k: np.ndarray, geo: tuple, sq: np.ndarray) -> None:
    """The mean square's parts alone (``sq`` of :func:`kinematics_block`, the same
    operations): for the sums that read no moments (a fifth of the work of both).
    [(m/s)²/m²]"""
    za, zb, _, p, q, _, _, h, g = geo
    za, zb, dry = _wet_ends(za, zb, q - p)
    dz = np.multiply.outer(k, zb - za)
    _squares(w, k, za, np.multiply.outer(k, za), dz, p, q, h, g, sq)
    if dry.any():
        sq[:, :, dry] = 0.0


def _wet_ends(
    za: np.ndarray, zb: np.ndarray, length: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The ends' depths with those of the elements without a wet part set to 0 (they
    are computed at z = 0, then set to zero) and those elements."""
    dry = length[0] <= 0.0
    if dry.any():
        za, zb = np.where(dry, 0.0, za), np.where(dry, 0.0, zb)
    return za, zb, dry


def _depth_factor(w: np.ndarray, k: np.ndarray, h: float) -> np.ndarray:
    """ω/D, D = 1 − e^{−2kh} (0 at ω = 0). [rad/s]"""
    zero_w = w == 0.0
    den = -np.expm1(-2.0 * k * h)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(zero_w, 0.0, w / np.where(zero_w, 1.0, den))


def _squares(w, k, za, kza, dz, p, q, h, g, sq) -> None:  # noqa: ANN001
    """∫|u_h|² dξ and ∫|u_z|² dξ into ``sq`` (2, n_w, n_el) from the exponents' parts
    of :func:`kinematics_block` (kza = k z_a, dz = k (z_b − z_a))."""
    length = q - p
    two_dz = 2.0 * dz
    phi_k, _ = _phi1_psi(np.where(two_dz >= 0.0, -two_dz, two_dz) * length, want_psi=False)
    k1 = _exp_integral(2.0 * kza, two_dz, p, q, phi_k)  # ∫ e^{2kz} dξ
    if math.isinf(h):
        sq[0] = sq[1] = k1 * (w * w)[:, None]
        return
    e2a = -np.multiply.outer(k, za + 2.0 * h)
    # ∫ e^{−2k(z+2h)} dξ: its φ1 argument −|2dz|·L is the first one's
    k2 = _exp_integral(2.0 * e2a, -two_dz, p, q, phi_k)
    c2 = (_depth_factor(w, k, h) ** 2)[:, None]
    cross2 = (2.0 * np.exp(-2.0 * k * h))[:, None] * length
    sq[0] = (k1 + k2 + cross2) * c2
    sq[1] = np.clip(k1 + k2 - cross2, 0.0, None) * c2
    zero_w = w == 0.0
    if zero_w.any():  # long-wave limit: u_h = √(g/h) uniform, u_z = 0
        u0 = math.sqrt(g / h)
        sq[0][zero_w, :] = u0 * u0 * length
