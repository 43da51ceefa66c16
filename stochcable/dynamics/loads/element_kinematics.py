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
  (:func:`stochcable.dynamics.loads.channels.wave_loads`; B constant per element);
- the element mean square ∫ Re(v vᴴ) dξ, from which the drag linearization takes the
  σ of the relative velocity as an element mean (:mod:`stochcable.dynamics.linearization.variance`).

The moments are the exact consistent load for both mass-matrix options: for a uniform
field they equal the lumped ½·l0 weights, so the Froude–Krylov balance above holds
either way.  Channels without these element data (built by hand) fall back on the
linear interpolation of their nodal kinematics with the model's mass pattern.

References
----------
Tuah, H. (1982), Cable dynamics in an ocean environment, PhD thesis, Oregon State University.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from stochcable import validation as v
from stochcable.compiled import optional_kernel
from stochcable.dynamics.loads.element_parts import (
    KINEMATICS_BYTES,
    EndSquare,
    MomentParts,
    SquareParts,
    sub_blocks,
)
from stochcable.dynamics.loads.freqblocks import FrequencyIndex, working_memory_bytes
from stochcable.dynamics.loads.kinematics_closed_forms import (
    kinematics_block,
    mean_block,
    square_block,
)
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
    "element_mean_velocity",
    "element_wave_velocity",
]


#: Elements × frequencies from which a block is formed by the compiled loop
#: (:mod:`stochcable.dynamics.loads.kinematics_kernels`, ≈ 2–3x faster; loading it costs
#: ≈ 0.3 s once per process, more than NumPy spends on the bundled examples' grids).
KERNEL_MIN_ENTRIES = 2**16


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
    omega: ArrayLike,
    positions: ArrayLike,
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
    Kinematics of Tuah (1982), eqs. 5.2.8–5.2.11 in the DESIGN.md convention
    (:func:`stochcable.sea.kinematics.wave_kinematics`): with χ = x cos β + y sin β,
    E₁ = k z − i k χ, E₂ = −k(z + 2h) − i k χ and D = 1 − e^{−2kh},

        u_h = ω (e^{E₁} + e^{E₂})/D (along β),   u_z = iω (e^{E₁} − e^{E₂})/D,

    (deep water: D = 1 and no E₂ term).  Along the element r(ξ) = r_a + ξ(r_b − r_a)
    each E is linear in ξ, so the moments ∫ N_i e^{E(ξ)} dξ over the wet part
    ξ ∈ [p, q] (z(ξ) <= 0; the element is split at the waterline) are closed forms
    (:mod:`~stochcable.dynamics.loads.kinematics_closed_forms`, series near α·L = 0, no
    overflow for large |α|·L).  The mean square uses
    |u_h|² = ω² (e^{2E₁ᵣ} + 2e^{−2kh} + e^{2E₂ᵣ})/D² and
    |u_z|² = ω² (e^{2E₁ᵣ} − 2e^{−2kh} + e^{2E₂ᵣ})/D² (E_ᵣ the real parts; the phases
    of the two terms coincide): its absolute error is ~1e-16 of the largest |v|² on the
    element (the vertical part in very shallow water, kh < 1e-4, carries a relative
    error ~1e-16/(kh)²).  At ω = 0 the finite-depth horizontal velocity takes its limit
    √(g/h), as in :func:`~stochcable.sea.kinematics.wave_kinematics`.
    """
    return _element_kinematics(*_checked(omega, positions, heading, depth, g))


def _checked(
    omega: ArrayLike, positions: ArrayLike, heading: float, depth: float, g: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray, float, float, float]:
    """:func:`element_wave_kinematics`' arguments checked: (ω, k, positions, β, h, g)."""
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
    return w, k, pts, beta, h, g


def element_wave_velocity(
    omega: ArrayLike,
    positions: ArrayLike,
    heading: float = 0.0,
    depth: float = np.inf,
    g: float = G_STANDARD,
) -> np.ndarray:
    """:attr:`ElementKinematics.velocity` of :func:`element_wave_kinematics` (the same
    arguments, checks and numbers) alone: the moments without the mean square and the
    wet ends' squares, shape (n_omega, n_el, 2, 3). [(m/s)/m]"""
    w, k, pts, beta, h, g = _checked(omega, positions, heading, depth, g)
    src = _source(w, k, pts, beta, h, g)[0]
    return MomentParts(src.moments(), beta).full()


def element_mean_velocity(
    omega: ArrayLike,
    positions: ArrayLike,
    heading: float = 0.0,
    depth: float = np.inf,
    g: float = G_STANDARD,
) -> np.ndarray:
    """The wave velocity integrated along each element's wet part, ∫ v dξ (the sum of
    :func:`element_wave_velocity`'s two moments: the same arguments and checks, the
    sum in one closed form), in its horizontal part (along the heading) and vertical
    part: shape (n_el, 2, n_omega). [(m/s)/m]"""
    w, k, pts, beta, h, g = _checked(omega, positions, heading, depth, g)
    geo = _source(w, k, pts, beta, h, g)[0].geometry
    out = np.empty((pts.shape[0] - 1, 2, w.size), dtype=complex)
    for sl in sub_blocks(w.size, out.shape[0]):  # (blocks of frequencies, as the moments')
        out[..., sl] = mean_block(w[sl], k[sl], geo)
    return out


def _element_kinematics(
    w: np.ndarray, k: np.ndarray, pts: np.ndarray, beta: float, h: float, g: float
) -> ElementKinematics:
    """:func:`element_wave_kinematics` without validation."""
    src, za, zb, p, q = _source(w, k, pts, beta, h, g)
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


def _source(
    w: np.ndarray, k: np.ndarray, pts: np.ndarray, beta: float, h: float, g: float
) -> tuple[KinematicsBlocks, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The kinematics source of the elements of ``pts`` and their ends' depths and wet
    parts ξ ∈ [p, q] (p, q of shape (1, n_el))."""
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
    return KinematicsBlocks(w, k, (za, zb, chi, p, q, cb, sb, h, g), beta), za, zb, p, q


@dataclass(frozen=True, eq=False)
class KinematicsBlocks:
    """The sea's element kinematics of a line formed for any frequencies: every
    quantity is elementwise in ω, so a block of frequencies formed alone holds the
    numbers of the whole grid formed at once (the same operations on the same inputs).

    A grid whose kinematics (:data:`~stochcable.dynamics.loads.element_parts.
    KINEMATICS_BYTES` per element and frequency) fit a quarter of the working-memory
    target (:func:`~stochcable.dynamics.loads.freqblocks.working_memory_bytes`) keeps them
    (:meth:`parts`); a larger one keeps only this source, and the loads, the variance
    sums and the outputs form the block of frequencies they read (memory independent
    of the number of frequencies; each read costs a formation of that block).

    Attributes
    ----------
    omega, wavenumber : ndarray, shape (n_omega,)
        [rad/s], [rad/m]
    geometry : tuple
        (z_a, z_b, χ, p, q, cos β, sin β, h, g) of
        :func:`~stochcable.dynamics.loads.kinematics_closed_forms.kinematics_block`.
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

    def form(
        self, freq: FrequencyIndex = slice(None), square: bool = True
    ) -> tuple[np.ndarray, np.ndarray | None]:
        """The moments' parts (n_el, 2, 2, n_f) and the mean square's (2, n_f, n_el)
        on the frequencies ``freq`` (``square`` False: None for the squares where the
        NumPy form skips them, a fifth of its work). [(m/s)/m, (m/s)²/m²]"""
        w, k = self.omega[freq], self.wavenumber[freq]
        n_w, n_el = w.size, self.n_elements
        # the moments' horizontal and vertical parts stored element-major: the loads
        # read a block of frequencies per element end and part as one contiguous run
        parts = np.empty((n_el, 2, 2, n_w), dtype=complex)
        sq = np.empty((2, n_w, n_el))  # ∫|u_h|², ∫|u_z|²
        kern = None
        if n_w * n_el >= KERNEL_MIN_ENTRIES:
            kern = optional_kernel(
                "stochcable.dynamics.loads.kinematics_kernels", "kinematics_block"
            )
        if kern is not None:  # the compiled loop, in one call (it chunks its own work)
            kern(w, k, *self.geometry, parts, sq)
            return parts, sq
        for sl in sub_blocks(n_w, n_el):
            block = sq[:, sl] if square else None
            kinematics_block(w[sl], k[sl], self.geometry, parts[..., sl], block)
        return parts, sq if square else None

    def moments(self, freq: FrequencyIndex = slice(None)) -> np.ndarray:
        """The moments' parts on ``freq``, (n_el, 2, 2, n_f). [(m/s)/m]"""
        return self.form(freq, square=False)[0]

    def square(self, freq: FrequencyIndex = slice(None)) -> np.ndarray:
        """The mean square's parts on ``freq``, (2, n_f, n_el), alone (NumPy,
        :func:`~stochcable.dynamics.loads.kinematics_closed_forms.square_block`: ≈ 17 ns per
        element and frequency against the compiled moments and squares' ≈ 42; the
        indicators' and the inputs' sums read no moments). [(m/s)²/m²]"""
        w, k = self.omega[freq], self.wavenumber[freq]
        sq = np.empty((2, w.size, self.n_elements))
        for sl in sub_blocks(w.size, self.n_elements):
            square_block(w[sl], k[sl], self.geometry, sq[:, sl])
        return sq

    def parts(self) -> tuple[MomentParts, SquareParts]:
        """The whole grid's parts: formed and kept where they fit a quarter of the
        working-memory target (:meth:`fits`), else formed per block when read."""
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

    def __getitem__(self, idx: FrequencyIndex) -> KinematicsBlocks:
        """The source on the frequencies ``idx``."""
        return KinematicsBlocks(self.omega[idx], self.wavenumber[idx], self.geometry, self.heading)


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
