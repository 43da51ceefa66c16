"""Wave kinematics integrated exactly along the elements of a line (the sea channel's
element data, :func:`element_wave_kinematics`).

Wave loads integrated exactly along the elements
------------------------------------------------
The wave kinematics decay like e^{kz} with depth and turn like e^{−ikx} along the wave:
over an element much longer than 1/k (near the surface at high frequency) their linear
interpolation between the nodes is far off (the inclined guy of docs/ACCURACY.md: its
26 m top element at z = 0 against 1/k = 0.6 m at 4 rad/s overestimated the fairlead
tension σ by 77 %).  Along a straight element from node a to node b, ξ = s/l ∈ [0, 1],
the kinematics per unit amplitude are sums of exponentials e^{E(ξ)} with E linear in
ξ (deep water: E = k z(ξ) − i k χ(ξ), χ = x cos β + y sin β; finite depth: cosh and
sinh as two exponentials).  :func:`element_wave_kinematics` integrates them in closed
form over the wet part of each element (split at z = 0; the dry part gets no load):

- the consistent (work-equivalent) moments ∫ N_a v dξ, ∫ N_b v dξ with N_a = 1 − ξ,
  N_b = ξ, so the element's Morison load on node i is
  l0·[ρ(πD²/4)(1 + Can)(I − eeᵀ)·iω + B_n(I − eeᵀ) + B_t eeᵀ]·∫ N_i v dξ
  (:func:`stochcable.dynamics.loads.wave_loads`; B constant per element);
- the element mean square ∫ Re(v vᴴ) dξ, from which the drag linearization takes the
  σ of the relative velocity as an element mean (:mod:`stochcable.dynamics.variance`).

The moments are the exact consistent load for both mass-matrix options: for a uniform
field they equal the lumped ½·l0 weights, so the Froude–Krylov balance above holds
either way.  Channels without these element data (built by hand) fall back on the
linear interpolation of their nodal kinematics with the model's mass pattern.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from stochcable import validation as v
from stochcable.compiled import optional_kernel
from stochcable.dynamics.element_parts import (
    KINEMATICS_BYTES,
    EndSquare,
    MomentParts,
    SquareParts,
)
from stochcable.dynamics.freqblocks import working_memory_bytes
from stochcable.errors import InputError
from stochcable.sea.kinematics import G_STANDARD, wavenumber

__all__ = [
    "ElementKinematics",
    "EndSquare",
    "KinematicsBlocks",
    "MomentParts",
    "SquareParts",
    "element_frames",
    "element_wave_kinematics",
]


# |x| below which φ1 and ψ are summed as series (full relative precision; above it the
# closed forms lose at most ~1e-16·(1 + |e^x|)/|x| absolutely, harmless as |e^x| <= 1).
_SERIES_RADIUS = 0.5
# 15 terms: the remainder x^15/16! < 2e-18 for |x| < 0.5.
_SERIES_TERMS = 15
_PHI1_COEF = np.array([1.0 / math.factorial(n + 1) for n in range(_SERIES_TERMS)])
_PSI_COEF = np.array([1.0 / (math.factorial(n) * (n + 2)) for n in range(_SERIES_TERMS)])
#: Elements × frequencies from which a block is formed by the compiled loop
#: (:mod:`stochcable.dynamics.kinematics_kernels`, ≈ 2–3x faster; loading it costs
#: ≈ 0.3 s once per process, more than NumPy spends on the bundled examples' grids).
KERNEL_MIN_ENTRIES = 2**16
# Elements × frequencies per block of :func:`_element_kinematics` (its temporaries,
# ≈ 30 arrays of this many entries, stay in the cache).
_BLOCK_ENTRIES = 2**14


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


@dataclass(frozen=True, eq=False)
class ElementKinematics:
    """Linear wave kinematics integrated along straight elements, per unit amplitude.

    Attributes
    ----------
    omega : ndarray, shape (n_omega,)
        [rad/s]
    wavenumber : ndarray, shape (n_omega,)
        [rad/m]
    positions : ndarray, shape (n_nodes, 3)
        Node positions; element j joins nodes j and j + 1. [m]
    heading : float
        [rad]
    depth : float
        [m]
    wet_fraction : ndarray, shape (n_el,)
        Fraction of each element below z = 0 (only that part is loaded). [-]
    moments : MomentParts
        ∫₀¹ N_a v dξ and ∫₀¹ N_b v dξ (N_a = 1 − ξ, N_b = ξ, ξ = s/l), v = 0 above
        z = 0, in their horizontal and vertical parts (:attr:`velocity` forms them on
        x, y, z). [(m/s)/m]
    square : SquareParts
        ∫₀¹ Re(v vᴴ) dξ, the element mean of the velocity's second moment, in its
        horizontal and vertical parts (:attr:`velocity_square` forms it). [(m/s)²/m²]
    ends : EndSquare
        |v|² at the two ends of each element's wet part (the lower-ξ end first; the
        waterline point for an element crossing it; 0 for a dry element), formed on
        demand (:attr:`end_square`). [(m/s)²/m²]
    """

    omega: np.ndarray
    wavenumber: np.ndarray
    positions: np.ndarray
    heading: float
    depth: float
    wet_fraction: np.ndarray
    moments: MomentParts
    square: SquareParts
    ends: EndSquare

    @property
    def end_square(self) -> np.ndarray:
        """|v|² at the ends of the wet parts, shape (n_omega, n_el, 2) (formed on
        access). [(m/s)²/m²]"""
        return self.ends.full()

    @property
    def velocity(self) -> np.ndarray:
        """∫₀¹ N_i v dξ on x, y, z, shape (n_omega, n_el, 2, 3) (formed on access).
        [(m/s)/m]"""
        return self.moments.full()

    @property
    def velocity_square(self) -> np.ndarray:
        """∫₀¹ Re(v vᴴ) dξ, shape (n_omega, n_el, 3, 3) (formed on access). [(m/s)²/m²]"""
        return self.square.full()

    @property
    def acceleration(self) -> np.ndarray:
        """∫ N_i a dξ = iω ∫ N_i v dξ, shape (n_omega, n_el, 2, 3). [(m/s²)/m]"""
        return self.velocity * (1j * self.omega)[:, None, None, None]


def element_wave_kinematics(
    omega: Any,
    positions: Any,
    heading: float = 0.0,
    depth: float = np.inf,
    g: float = G_STANDARD,
) -> ElementKinematics:
    """Linear wave kinematics integrated exactly along the straight elements of a line.

    Parameters
    ----------
    omega : array_like
        Angular frequencies, >= 0, 1-D. [rad/s]
    positions : array_like
        Node positions (x, y, z), shape (n_nodes, 3), n_nodes >= 2; element j joins
        nodes j and j + 1; z >= −depth. [m]
    heading : float, default 0.0
        Wave heading β from +x toward +y. [rad]
    depth : float, default inf
        Water depth h. [m]
    g : float, default 9.80665
        Acceleration of gravity. [m/s²]

    Returns
    -------
    ElementKinematics
        Consistent moments and element mean square of the fluid velocity.

    Raises
    ------
    InputError
        Invalid frequencies, positions (shape, below the seabed), heading, depth or g.

    Notes
    -----
    Kinematics of seed 001 eqs. 5.2.8–5.2.11 in the DESIGN.md convention
    (:func:`stochcable.sea.kinematics.wave_kinematics`): with χ = x cos β + y sin β,
    E₁ = k z − i k χ, E₂ = −k(z + 2h) − i k χ and D = 1 − e^{−2kh},

        u_h = ω (e^{E₁} + e^{E₂})/D (along β),   u_z = iω (e^{E₁} − e^{E₂})/D,

    (deep water: D = 1 and no E₂ term).  Along the element r(ξ) = r_a + ξ(r_b − r_a)
    each E is linear in ξ, so the moments ∫ N_i e^{E(ξ)} dξ over the wet part
    ξ ∈ [p, q] (z(ξ) <= 0; the element is split at the waterline) are closed forms
    (:func:`_exp_moments`, series near α·L = 0, no overflow for large |α|·L).  The
    mean square uses |u_h|² = ω² (e^{2E₁ᵣ} + 2e^{−2kh} + e^{2E₂ᵣ})/D² and
    |u_z|² = ω² (e^{2E₁ᵣ} − 2e^{−2kh} + e^{2E₂ᵣ})/D² (E_ᵣ the real parts; the phases of
    the two terms coincide): its absolute error is ~1e-16 of the largest |v|² on the
    element (the vertical part in very shallow water, kh < 1e-4, carries a relative
    error ~1e-16/(kh)²).  At ω = 0 the finite-depth horizontal velocity takes its limit
    √(g/h), as in :func:`~stochcable.sea.kinematics.wave_kinematics`.
    """
    w = v.float_array("omega", omega, "rad/s", nonnegative=True)
    pts = np.asarray(positions, dtype=float)
    if pts.ndim != 2 or pts.shape[1] != 3 or pts.shape[0] < 2:
        raise InputError("positions", positions, "m", "must have shape (n_nodes >= 2, 3)")
    pts = v.float_array("positions", pts, "m", ndim=2)
    beta = v.finite_scalar("heading", heading, "rad")
    # depth and g validated by wavenumber (sea.kinematics' messages, in this order)
    k = wavenumber(w, depth, g)
    h, g = float(depth), float(g)
    z = pts[:, 2]
    if not math.isinf(h) and (z < -h).any():
        i = int(np.flatnonzero(z < -h)[0])
        raise InputError(
            "positions", positions, "m", f"z must be >= -depth = {-h:g} (node {i} has z = {z[i]:g})"
        )
    return _element_kinematics(w, k, pts, beta, h, g)


def _complex(re: np.ndarray, im: np.ndarray) -> np.ndarray:
    """re + i·im in one pass (no complex temporaries)."""
    out = np.empty(re.shape, dtype=complex)
    out.real = re
    out.imag = im
    return out


def _element_kinematics(
    w: np.ndarray, k: np.ndarray, pts: np.ndarray, beta: float, h: float, g: float
) -> ElementKinematics:
    """:func:`element_wave_kinematics` without validation."""
    cb, sb = math.cos(beta), math.sin(beta)
    za, zb = pts[:-1, 2], pts[1:, 2]
    chi = pts[:, 0] * cb + pts[:, 1] * sb
    # wet part ξ ∈ [p, q] of each element (z <= 0 wet, as the nodal kinematics)
    with np.errstate(divide="ignore", invalid="ignore"):
        cross = np.where(za != zb, za / (za - zb), 0.0)
    wet_a, wet_b = za <= 0.0, zb <= 0.0
    p = np.where(wet_a, 0.0, np.where(wet_b, cross, 0.0))
    q = np.where(wet_b, 1.0, np.where(wet_a, cross, 0.0))
    p, q = np.clip(p, 0.0, 1.0)[None, :], np.clip(q, 0.0, 1.0)[None, :]
    for a in (w, k, pts):
        a.setflags(write=False)
    src = KinematicsBlocks(w, k, (za, zb, chi, p, q, cb, sb, h, g), beta)
    moments, square = src.parts()
    wet = (q - p)[0]
    z_ends = za[:, None] + (zb - za)[:, None] * np.hstack([p.T, q.T])  # (n_el, 2)
    z_ends = np.minimum(z_ends, 0.0)
    for a in (wet, z_ends):
        a.setflags(write=False)
    return ElementKinematics(
        omega=w,
        wavenumber=k,
        positions=pts,
        heading=beta,
        depth=h,
        wet_fraction=wet,
        moments=moments,
        square=square,
        ends=EndSquare(w, k, z_ends, wet > 0.0, h, g),
    )


@dataclass(frozen=True, eq=False)
class KinematicsBlocks:
    """The sea's element kinematics of a line formed for any frequencies: every
    quantity is elementwise in ω, so a block of frequencies formed alone holds the
    numbers of the whole grid formed at once (the same operations on the same inputs).

    A grid whose kinematics (:data:`~stochcable.dynamics.element_parts.
    KINEMATICS_BYTES` per element and frequency) fit a quarter of the working-memory
    target (:func:`~stochcable.dynamics.freqblocks.working_memory_bytes`) keeps them
    (:meth:`parts`); a larger one keeps only this source, and the loads, the variance
    sums and the outputs form the block of frequencies they read (memory independent
    of the number of frequencies; each read costs a formation of that block).

    Attributes
    ----------
    omega, wavenumber : ndarray, shape (n_omega,)
        [rad/s], [rad/m]
    geometry : tuple
        (z_a, z_b, χ, p, q, cos β, sin β, h, g) of :func:`_kinematics_block`.
    heading : float
        β. [rad]
    """

    omega: np.ndarray
    wavenumber: np.ndarray
    geometry: tuple
    heading: float

    @property
    def n_omega(self) -> int:
        """Number of frequencies. [-]"""
        return int(self.omega.size)

    @property
    def n_elements(self) -> int:
        """Number of elements. [-]"""
        return int(self.geometry[0].size)

    def fits(self) -> bool:
        """Whether the whole grid's kinematics fit a quarter of the working-memory
        target (as the other drag-independent arrays kept between evaluations)."""
        need = KINEMATICS_BYTES * self.n_elements * self.n_omega
        return need <= working_memory_bytes() // 4

    def form(self, freq: Any = slice(None)) -> tuple[np.ndarray, np.ndarray]:
        """The moments' parts (n_el, 2, 2, n_f) and the mean square's (2, n_f, n_el)
        on the frequencies ``freq``. [(m/s)/m, (m/s)²/m²]"""
        w, k = self.omega[freq], self.wavenumber[freq]
        n_w, n_el = w.size, self.n_elements
        # the moments' horizontal and vertical parts stored element-major: the loads
        # read a block of frequencies per element end and part as one contiguous run
        parts = np.empty((n_el, 2, 2, n_w), dtype=complex)
        sq = np.empty((2, n_w, n_el))  # ∫|u_h|², ∫|u_z|²
        kern = None
        if n_w * n_el >= KERNEL_MIN_ENTRIES:
            kern = optional_kernel("stochcable.dynamics.kinematics_kernels", "kinematics_block")
        if kern is not None:  # the compiled loop, in one call (it chunks its own work)
            kern(w, k, *self.geometry, parts, sq)
            return parts, sq
        # NumPy: sub-blocks whose temporaries stay in cache (≈ 2x faster than
        # whole-grid passes on 400 elements × 2,000 ω); elementwise in ω: the same
        # numbers
        step = max(1, _BLOCK_ENTRIES // max(n_el, 1))
        for i in range(0, n_w, step):
            sl = slice(i, min(i + step, n_w))
            _kinematics_block(w[sl], k[sl], self.geometry, parts[..., sl], sq[:, sl])
        return parts, sq

    def moments(self, freq: Any = slice(None)) -> np.ndarray:
        """The moments' parts on ``freq``, (n_el, 2, 2, n_f). [(m/s)/m]"""
        return self.form(freq)[0]

    def square(self, freq: Any = slice(None)) -> np.ndarray:
        """The mean square's parts on ``freq``, (2, n_f, n_el). [(m/s)²/m²]"""
        return self.form(freq)[1]

    def parts(self) -> tuple[MomentParts, SquareParts]:
        """The whole grid's parts: formed and kept where they fit the working-memory
        target, else formed per block when read."""
        if not self.fits():
            return MomentParts(None, self.heading, self), SquareParts(
                None, None, self.heading, self
            )
        parts, sq = self.form()
        for a in (parts, sq):
            a.setflags(write=False)
        return MomentParts(parts, self.heading), SquareParts(sq[0], sq[1], self.heading)

    def elements(self, sel: slice) -> KinematicsBlocks:
        """The source of the elements ``sel`` (a slice with step 1)."""
        za, zb, chi, p, q, *rest = self.geometry
        start, stop, _ = sel.indices(za.size)
        geo = (za[sel], zb[sel], chi[start : stop + 1], p[:, sel], q[:, sel], *rest)
        return KinematicsBlocks(self.omega, self.wavenumber, geo, self.heading)

    def __getitem__(self, idx: Any) -> KinematicsBlocks:
        """The source on the frequencies ``idx``."""
        return KinematicsBlocks(self.omega[idx], self.wavenumber[idx], self.geometry, self.heading)


def _kinematics_block(
    w: np.ndarray,
    k: np.ndarray,
    geo: tuple,
    vel: np.ndarray,
    sq: np.ndarray,
) -> None:
    """The element kinematics of the frequencies ``w`` (wavenumbers ``k``) written into
    ``vel`` (the parts of :class:`MomentParts`, (n_el, 2, 2, n_w)), ``sq`` (h and v of
    :class:`SquareParts`): the body of
    :func:`_element_kinematics` on one block; ``geo`` = (z_a, z_b, χ, p, q, cos β,
    sin β, h, g).  Frequency-major (n_w, n_el) arrays throughout.  The NumPy form of
    :func:`stochcable.dynamics.kinematics_kernels.kinematics_block`, the compiled loop
    :meth:`KinematicsBlocks.form` calls where numba is available (not with
    ``STOCHCABLE_NUMBA=0``): the same formulas, ≈ 2–3x faster."""
    za, zb, chi, p, q, cb, sb, h, g = geo
    length = q - p
    dry = length[0] <= 0.0  # no wet part: computed at z = 0, then set to zero
    if dry.any():
        za, zb = np.where(dry, 0.0, za), np.where(dry, 0.0, zb)
    dz = np.multiply.outer(k, zb - za)
    phase0 = -np.multiply.outer(k, chi[:-1])  # imaginary parts of the exponents
    dphase = -np.multiply.outer(k, chi[1:] - chi[:-1])
    kza = np.multiply.outer(k, za)
    alpha1 = _complex(dz, dphase)
    f12 = _phi1_psi(_moment_argument(alpha1, p, q))
    ma1, mb1 = _exp_moments(_complex(kza, phase0), alpha1, p, q, f12)
    two_dz = 2.0 * dz
    phi_k, _ = _phi1_psi(np.where(two_dz >= 0.0, -two_dz, two_dz) * length, want_psi=False)
    k1 = _exp_integral(2.0 * kza, two_dz, p, q, phi_k)  # ∫ e^{2kz} dξ
    zero_w = w == 0.0
    if math.isinf(h):
        coef = w.astype(complex)[:, None]
        mh = (ma1 * coef, mb1 * coef)
        mz = (ma1 * (1j * w)[:, None], mb1 * (1j * w)[:, None])
        ch2 = sh2 = k1 * (w * w)[:, None]
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
        # ∫ e^{−2k(z+2h)} dξ: its φ1 argument −|2dz|·L is the first one's
        k2 = _exp_integral(2.0 * e2a, -two_dz, p, q, phi_k)
        den = -np.expm1(-2.0 * k * h)
        with np.errstate(divide="ignore", invalid="ignore"):
            c = np.where(zero_w, 0.0, w / np.where(zero_w, 1.0, den))
            cross2 = (2.0 * np.exp(-2.0 * k * h))[:, None] * length
            c2 = (c * c)[:, None]
            ch2 = (k1 + k2 + cross2) * c2
            sh2 = np.clip(k1 + k2 - cross2, 0.0, None) * c2
        mh = ((ma1 + ma2) * c[:, None], (mb1 + mb2) * c[:, None])
        ic = (1j * c)[:, None]
        mz = ((ma1 - ma2) * ic, (mb1 - mb2) * ic)
        if zero_w.any():  # long-wave limit: u_h = √(g/h) uniform, u_z = 0
            u0 = math.sqrt(g / h)
            side_b = 0.5 * (q * q - p * p)
            mh[0][zero_w, :] = u0 * (length - side_b)
            mh[1][zero_w, :] = u0 * side_b
            ch2[zero_w, :] = u0 * u0 * length
    for side in range(2):  # (n_el, n_w) each: the transposed block
        vel[:, side, 0] = mh[side].T
        vel[:, side, 1] = mz[side].T
    sq[0] = ch2
    sq[1] = sh2
    if dry.any():  # (zeros, not e^{kz}·0: NaN once kz > 709 high above the water)
        vel[dry] = 0.0
        sq[:, :, dry] = 0.0


# ------------------------------------------------------------------ element geometry


def element_frames(positions: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Unit tangent and two unit normals of every element, global frame.

    Parameters
    ----------
    positions : ndarray, shape (n_nodes, 3)
        Static node positions. [m]

    Returns
    -------
    e, n1, n2 : ndarray, shape (n_el, 3)
        Tangent (node j to j+1); n2 the horizontal normal e × ẑ normalized (ŷ for a
        vertical element), out of the plane for a line in a vertical plane; n1 = n2 × e,
        the normal in the element's vertical plane. [-]
    """
    d = np.diff(positions, axis=0)
    e = d / np.linalg.norm(d, axis=1)[:, None]
    n2 = _cross(e, np.array([0.0, 0.0, 1.0]))
    nn = np.linalg.norm(n2, axis=1)
    vertical = nn < 1e-12
    n2 = np.where(
        vertical[:, None], np.array([0.0, 1.0, 0.0]), n2 / np.where(vertical, 1.0, nn)[:, None]
    )
    n1 = _cross(n2, e)
    return e, n1, n2


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Row-wise a × b of 3-vectors: np.cross's products and differences in its order
    (the same numbers), without its generic axis handling (≈ 20 µs a call)."""
    a0, a1, a2 = a[..., 0], a[..., 1], a[..., 2]
    b0, b1, b2 = b[..., 0], b[..., 1], b[..., 2]
    out = np.empty(np.broadcast_shapes(a.shape, b.shape))
    out[..., 0] = a1 * b2 - a2 * b1
    out[..., 1] = a2 * b0 - a0 * b2
    out[..., 2] = a0 * b1 - a1 * b0
    return out
