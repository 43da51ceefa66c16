"""The sea's element kinematics kept compact: the horizontal and vertical parts of the
consistent moments (:class:`MomentParts`) and of the mean square (:class:`SquareParts`)
of the wave velocity along each element, and a channel's full moments seen the same way
(:class:`ArrayMoments`).

Linear waves of heading β move the fluid along b = (cos β, sin β, 0) and ẑ only, so
per element and frequency the moments ∫N_i v dξ are two complex numbers per element
end (h·b + v·ẑ) instead of three, and the mean square ∫Re(v vᴴ)dξ two real numbers
(h·b bᵀ + v·ẑẑᵀ: the horizontal and vertical velocities are in quadrature) instead of
nine.  The loads, the variance sums and the indicators read the parts
(:mod:`stochcable.dynamics.solve.node_inputs`); the 3-vector and 3 × 3 forms of the public
:class:`~stochcable.dynamics.loads.element_kinematics.ElementKinematics` fields are formed
when they are read.  The products are those of the full forms (h·cos β, h·sin β, v):
the same numbers.
"""

from __future__ import annotations

import math
from collections.abc import Iterator, Sequence
from dataclasses import dataclass, field
from typing import Protocol

import numpy as np

from stochcable.dynamics.loads.freqblocks import FrequencyIndex, frequency_slices

#: Components of x, y, z (indices 0, 1, 2).
Components = Sequence[int] | np.ndarray


class PartsSource(Protocol):
    """What forms the parts of any frequencies when none are kept
    (:class:`~stochcable.dynamics.loads.element_kinematics.KinematicsBlocks`)."""

    @property
    def n_elements(self) -> int: ...

    def moments(self, freq: FrequencyIndex = ...) -> np.ndarray: ...

    def square(self, freq: FrequencyIndex = ...) -> np.ndarray: ...

    def elements(self, sel: slice) -> PartsSource: ...


__all__ = [
    "KINEMATICS_BYTES",
    "ArrayMoments",
    "Components",
    "EndSquare",
    "MomentParts",
    "PartsSource",
    "SquareParts",
    "sub_blocks",
]

#: Bytes of the sea's element kinematics per element and frequency: the moments' two
#: parts at both ends (4 complex numbers) and the mean square's two parts. [B]
KINEMATICS_BYTES = 80
#: Elements × frequencies per sub-block of the NumPy forms of the kinematics
#: (:func:`sub_blocks`; ≈ 30 temporaries of this many entries stay in the cache).
_BLOCK_ENTRIES = 2**14


def sub_blocks(n_w: int, n_el: int) -> list[slice]:
    """Consecutive slices of ``range(n_w)`` of ``_BLOCK_ENTRIES`` // ``n_el``
    frequencies: the NumPy forms' temporaries stay in cache (≈ 2x faster than
    whole-grid passes on 400 elements × 2,000 ω); their quantities are elementwise in
    ω, so the numbers do not depend on the slices."""
    step = max(1, _BLOCK_ENTRIES // max(n_el, 1))
    return [slice(i, min(i + step, n_w)) for i in range(0, n_w, step)]


def _direction(heading: float) -> tuple[float, float]:
    return math.cos(heading), math.sin(heading)


@dataclass(frozen=True, eq=False)
class MomentParts:
    """The consistent moments ∫N_a v dξ, ∫N_b v dξ of the sea's velocity in their
    horizontal and vertical parts, element-major.

    Attributes
    ----------
    parts : ndarray, complex, shape (n_el, 2, 2, n_omega), or None
        Per element, end (a, b) and part (horizontal along b, vertical), the
        frequencies contiguous; None: formed by ``source`` per block when read.
        [(m/s)/m]
    heading : float
        β. [rad]
    source : KinematicsBlocks, optional
        Forms the parts of any frequencies (and their mean square) when ``parts`` is
        None (:class:`~stochcable.dynamics.loads.element_kinematics.KinematicsBlocks`: a
        grid whose parts do not fit the working-memory target keeps none).
    """

    parts: np.ndarray | None
    heading: float
    source: PartsSource | None = None

    @property
    def nbytes(self) -> int:
        """Bytes kept (none for parts formed when read). [B]"""
        return 0 if self.parts is None else int(self.parts.nbytes)

    def stacked(self, freq: FrequencyIndex) -> np.ndarray:
        """The parts on the frequencies ``freq``, (n_el, 2, 2, n_f): a view of the kept
        parts or formed."""
        return self.source.moments(freq) if self.parts is None else self.parts[..., freq]

    def mix(self, comps: Components) -> np.ndarray:
        """The components ``comps`` of x, y, z as combinations of the parts, (d, 2)."""
        cb, sb = _direction(self.heading)
        rows = np.array([[cb, 0.0], [sb, 0.0], [0.0, 1.0]])
        return rows[np.asarray(comps, dtype=int)]

    def block(self, comps: Components, freq: FrequencyIndex = slice(None)) -> np.ndarray:
        """The moments on the components ``comps`` and frequencies ``freq``, (n_el, 2,
        d, n_f), a fresh contiguous array. [(m/s)/m]"""
        cb, sb = _direction(self.heading)
        parts = self.stacked(freq)
        h, v = parts[:, :, 0], parts[:, :, 1]
        out = np.empty(h.shape[:2] + (len(comps),) + h.shape[2:], dtype=complex)
        for j, c in enumerate(comps):
            if c == 2:
                out[:, :, j] = v
            else:
                np.multiply(h, cb if c == 0 else sb, out=out[:, :, j])
        return out

    def ends(self, comps: Components) -> tuple[np.ndarray, np.ndarray]:
        """∫N_a v dξ of the first element and ∫N_b v dξ of the last on ``comps``, each
        (d, n_omega). [(m/s)/m]"""
        if self.parts is None:  # the two elements alone
            n = self.source.n_elements
            a, b = self.source.elements(slice(0, 1)), self.source.elements(slice(n - 1, n))
            parts = (a.moments(slice(None))[:, :1], b.moments(slice(None))[:, 1:])
        else:
            parts = (self.parts[:1, :1], self.parts[-1:, 1:])
        first, last = (MomentParts(x, self.heading).block(comps)[0, 0] for x in parts)
        return first, last

    def full(self) -> np.ndarray:
        """The moments on x, y, z, shape (n_omega, n_el, 2, 3): a frequency-major view
        of fresh element-major storage. [(m/s)/m]"""
        return np.moveaxis(self.block((0, 1, 2)), 3, 0)

    def __getitem__(self, idx: FrequencyIndex) -> MomentParts:
        """The parts on the frequencies ``idx`` (a copy for an index array; formed, or
        formed when read where they do not fit the working-memory target)."""
        if self.parts is not None:
            return MomentParts(self.parts[..., idx], self.heading)
        sub = self.source[idx]
        return sub.parts()[0] if sub.fits() else MomentParts(None, self.heading, sub)


@dataclass(frozen=True, eq=False)
class ArrayMoments:
    """A channel's moments given on x, y, z (hand-built channels, the nodal
    interpolation), with the interface of :class:`MomentParts` (three "parts": the
    components themselves).

    Attributes
    ----------
    array : ndarray, complex, shape (n_omega, n_el, 2, 3)
        ∫N_a v dξ, ∫N_b v dξ. [(m/s)/m]
    """

    array: np.ndarray

    @property
    def nbytes(self) -> int:
        """Bytes of the array. [B]"""
        return int(self.array.nbytes)

    def mix(self, comps: Components) -> np.ndarray:
        """The selection of ``comps`` among x, y, z, (d, 3)."""
        return np.eye(3)[np.asarray(comps, dtype=int)]

    def block(self, comps: Components, freq: FrequencyIndex = slice(None)) -> np.ndarray:
        """(n_el, 2, d, n_f), a fresh contiguous array. [(m/s)/m]"""
        el = np.moveaxis(self.array, 0, -1)  # (n_el, 2, 3, n_w)
        return np.ascontiguousarray(el[:, :, list(comps), freq])

    def ends(self, comps: Components) -> tuple[np.ndarray, np.ndarray]:
        """(d, n_omega) each: the first element's end a, the last element's end b."""
        c = list(comps)
        return self.array[:, 0, 0, c].T.copy(), self.array[:, -1, 1, c].T.copy()

    def stacked(self, freq: FrequencyIndex) -> np.ndarray:
        """(n_el, 2, 3, n_f), a view."""
        return np.moveaxis(self.array, 0, -1)[..., freq]

    def full(self) -> np.ndarray:
        """The array itself, (n_omega, n_el, 2, 3)."""
        return self.array

    def __getitem__(self, idx: FrequencyIndex) -> ArrayMoments:
        return ArrayMoments(self.array[idx])


@dataclass(frozen=True, eq=False)
class SquareParts:
    """The element mean square ∫₀¹ Re(v vᴴ) dξ of the sea's kinematics in its two
    parts, S = h·b bᵀ + v·ẑ ẑᵀ with b = (cos β, sin β, 0) the wave direction (the
    horizontal and vertical velocities are in quadrature): two numbers per element and
    frequency instead of the nine of S.

    Attributes
    ----------
    horizontal, vertical : ndarray, shape (n_omega, n_el), or None
        h = ∫|u_h|² dξ and v = ∫|u_z|² dξ; None: formed by ``source`` per block
        when read. [(m/s)²/m²]
    heading : float
        β. [rad]
    source : KinematicsBlocks, optional
        As :attr:`MomentParts.source`.
    """

    horizontal: np.ndarray | None
    vertical: np.ndarray | None
    heading: float
    source: PartsSource | None = None

    @property
    def nbytes(self) -> int:
        """Bytes kept (none for parts formed when read). [B]"""
        if self.horizontal is None:
            return 0
        return int(self.horizontal.nbytes + self.vertical.nbytes)

    def _blocks(self) -> Iterator[tuple[FrequencyIndex, np.ndarray, np.ndarray]]:
        """(frequencies, h, v) of the whole grid at once, or per block of the
        working-memory target when formed."""
        if self.horizontal is not None:
            yield slice(None), self.horizontal, self.vertical
            return
        src = self.source
        for sl in frequency_slices(src.n_omega, KINEMATICS_BYTES * src.n_elements):
            sq = src.square(sl)
            yield sl, sq[0], sq[1]

    def _pattern(self) -> tuple[np.ndarray, np.ndarray]:
        cb, sb = _direction(self.heading)
        p = np.array([[cb * cb, cb * sb, 0.0], [cb * sb, sb * sb, 0.0], [0.0, 0.0, 0.0]])
        z = np.zeros((3, 3))
        z[2, 2] = 1.0
        return p, z

    def full(self) -> np.ndarray:
        """S, shape (n_omega, n_el, 3, 3) (a fresh array). [(m/s)²/m²]"""
        cb, sb = _direction(self.heading)
        if self.horizontal is None:
            sq = self.source.square(slice(None))
            return SquareParts(sq[0], sq[1], self.heading).full()
        h = self.horizontal
        sq = np.zeros(h.shape + (3, 3))
        sq[:, :, 0, 0] = h * (cb * cb)
        sq[:, :, 1, 1] = h * (sb * sb)
        sq[:, :, 0, 1] = sq[:, :, 1, 0] = h * (cb * sb)
        sq[:, :, 2, 2] = self.vertical
        return sq

    def __getitem__(self, idx: FrequencyIndex) -> SquareParts:
        """The parts on the frequencies ``idx`` (formed, or formed when read, as
        :meth:`MomentParts.__getitem__`)."""
        if self.horizontal is not None:
            return SquareParts(self.horizontal[idx], self.vertical[idx], self.heading)
        sub = self.source[idx]
        return sub.parts()[1] if sub.fits() else SquareParts(None, None, self.heading, sub)

    def weighted(self, weights: np.ndarray, comps: Components) -> np.ndarray:
        """Σ_ω weight·S on the components ``comps``, (n_el, d, d). [(m/s)²·…]"""
        p, z = self._pattern()
        c = np.asarray(comps)
        hw = vw = 0.0
        for sl, h, v in self._blocks():
            hw = hw + h.T @ weights[sl]
            vw = vw + v.T @ weights[sl]
        return hw[:, None, None] * p[c[:, None], c][None] + vw[:, None, None] * z[c[:, None], c]

    def projected_sum(self, proj: np.ndarray, weights: np.ndarray) -> np.ndarray:
        """Σ_ω weight·max(Σ_ij S_ij P_ij, 0) for per-element matrices P (n_el, 3, 3),
        (n_el,), over blocks of frequencies (the negative round-off of a projection
        that vanishes dropped). [(m/s)²/m²·unit of weights]"""
        p, z = self._pattern()
        ph = np.einsum("eij,ij->e", proj, p)
        pz = np.einsum("eij,ij->e", proj, z)
        out = np.zeros(proj.shape[0])
        for sl, h, v in self._blocks():
            out += np.clip(h * ph + v * pz, 0.0, None).T @ weights[sl]
        return out


@dataclass(frozen=True, eq=False)
class EndSquare:
    """|v|² at the two ends of each element's wet part, formed on demand from the
    wavenumbers and the ends' depths (two exponentials per element end and frequency:
    ω²(ch² + sh²) of the kinematics; in deep water 2ω²e^{2kz}).

    Attributes
    ----------
    omega, wavenumber : ndarray, shape (n_omega,)
        [rad/s], [rad/m]
    z_ends : ndarray, shape (n_el, 2)
        Depth of the ends of each element's wet part (≤ 0). [m]
    wet : ndarray of bool, shape (n_el,)
        Elements with a wet part.
    depth, g : float
        [m], [m/s²]
    """

    omega: np.ndarray
    wavenumber: np.ndarray
    z_ends: np.ndarray
    wet: np.ndarray
    depth: float
    g: float
    # (the last weighted sum and its weights' bytes: the line's resolution check and its
    # drag residual's pieces ask for the same one)
    _last: list = field(default_factory=list, init=False, repr=False)

    @property
    def nbytes(self) -> int:
        """Bytes kept (no per-frequency array of the elements). [B]"""
        return int(self.omega.nbytes + self.wavenumber.nbytes + self.z_ends.nbytes)

    def block(self, freq: FrequencyIndex = slice(None)) -> np.ndarray:
        """|v|² on the frequencies ``freq``, (n_f, n_el, 2). [(m/s)²/m²]"""
        w, k, h, z = self.omega[freq], self.wavenumber[freq], self.depth, self.z_ends
        e1 = np.exp(2.0 * np.multiply.outer(k, z))  # (n_f, n_el, 2)
        if math.isinf(h):
            ends = 2.0 * e1 * (w * w)[:, None, None]
        else:
            zero_w = w == 0.0
            den = -np.expm1(-2.0 * k * h)
            with np.errstate(divide="ignore", invalid="ignore"):
                c = np.where(zero_w, 0.0, w / np.where(zero_w, 1.0, den))
            c2 = (c * c)[:, None]
            e2 = np.exp(-2.0 * np.multiply.outer(k, z + 2.0 * h))
            ends = 2.0 * (e1 + e2) * c2[:, :, None]  # ω²(ch² + sh²)
            if zero_w.any():  # long-wave limit: u_h = √(g/h) uniform, u_z = 0
                u0 = math.sqrt(self.g / h)
                ends[zero_w] = u0 * u0
        return np.where(self.wet[None, :, None], ends, 0.0)

    def full(self) -> np.ndarray:
        """|v|², shape (n_omega, n_el, 2). [(m/s)²/m²]"""
        return self.block()

    def weighted(self, weights: np.ndarray) -> np.ndarray:
        """Σ_ω weight·|v|² per element end, (n_el, 2), over blocks of frequencies (the
        last weights' sum kept: asked again with the same weights, a copy of it)."""
        key = np.ascontiguousarray(weights, dtype=float).tobytes()
        if self._last and self._last[0] == key:
            return self._last[1].copy()
        out = np.zeros(self.z_ends.shape)
        for sl in sub_blocks(self.omega.size, self.z_ends.shape[0]):
            out += np.einsum("wes,w->es", self.block(sl), weights[sl])
        self._last[:] = [key, out.copy()]
        return out

    def __getitem__(self, idx: FrequencyIndex) -> EndSquare:
        """On the frequencies ``idx``."""
        return EndSquare(
            self.omega[idx], self.wavenumber[idx], self.z_ends, self.wet, self.depth, self.g
        )
