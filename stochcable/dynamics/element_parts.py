"""The sea's element kinematics kept compact: the horizontal and vertical parts of the
consistent moments (:class:`MomentParts`) and of the mean square (:class:`SquareParts`)
of the wave velocity along each element, and a channel's full moments seen the same way
(:class:`ArrayMoments`).

Linear waves of heading β move the fluid along b = (cos β, sin β, 0) and ẑ only, so
per element and frequency the moments ∫N_i v dξ are two complex numbers per element
end (h·b + v·ẑ) instead of three, and the mean square ∫Re(v vᴴ)dξ two real numbers
(h·b bᵀ + v·ẑẑᵀ: the horizontal and vertical velocities are in quadrature) instead of
nine.  The loads, the variance sums and the indicators read the parts
(:mod:`stochcable.dynamics.node_inputs`); the 3-vector and 3 × 3 forms of the public
:class:`~stochcable.dynamics.element_kinematics.ElementKinematics` fields are formed
when they are read.  The products are those of the full forms (h·cos β, h·sin β, v):
the same numbers.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

__all__ = ["ArrayMoments", "MomentParts", "SquareParts"]


def _direction(heading: float) -> tuple[float, float]:
    return math.cos(heading), math.sin(heading)


@dataclass(frozen=True, eq=False)
class MomentParts:
    """The consistent moments ∫N_a v dξ, ∫N_b v dξ of the sea's velocity in their
    horizontal and vertical parts, element-major.

    Attributes
    ----------
    parts : ndarray, complex, shape (n_el, 2, 2, n_omega)
        Per element, end (a, b) and part (horizontal along b, vertical), the
        frequencies contiguous. [(m/s)/m]
    heading : float
        β. [rad]
    """

    parts: np.ndarray
    heading: float

    @property
    def nbytes(self) -> int:
        """Bytes of the parts. [B]"""
        return int(self.parts.nbytes)

    def mix(self, comps: Any) -> np.ndarray:
        """The components ``comps`` of x, y, z as combinations of the parts, (d, 2)."""
        cb, sb = _direction(self.heading)
        rows = np.array([[cb, 0.0], [sb, 0.0], [0.0, 1.0]])
        return rows[np.asarray(comps, dtype=int)]

    def block(self, comps: Any, freq: Any = slice(None)) -> np.ndarray:
        """The moments on the components ``comps`` and frequencies ``freq``, (n_el, 2,
        d, n_f), a fresh contiguous array. [(m/s)/m]"""
        cb, sb = _direction(self.heading)
        h, v = self.parts[:, :, 0, freq], self.parts[:, :, 1, freq]
        out = np.empty(h.shape[:2] + (len(comps),) + h.shape[2:], dtype=complex)
        for j, c in enumerate(comps):
            if c == 2:
                out[:, :, j] = v
            else:
                np.multiply(h, cb if c == 0 else sb, out=out[:, :, j])
        return out

    def ends(self, comps: Any) -> tuple[np.ndarray, np.ndarray]:
        """∫N_a v dξ of the first element and ∫N_b v dξ of the last on ``comps``, each
        (d, n_omega). [(m/s)/m]"""
        first = MomentParts(self.parts[:1, :1], self.heading).block(comps)[0, 0]
        last = MomentParts(self.parts[-1:, 1:], self.heading).block(comps)[0, 0]
        return first, last

    def stacked(self, freq: Any) -> np.ndarray:
        """The parts on the frequencies ``freq``, (n_el, 2, 2, n_f), a view."""
        return self.parts[..., freq]

    def full(self) -> np.ndarray:
        """The moments on x, y, z, shape (n_omega, n_el, 2, 3): a frequency-major view
        of fresh element-major storage. [(m/s)/m]"""
        return np.moveaxis(self.block((0, 1, 2)), 3, 0)

    def __getitem__(self, idx: Any) -> MomentParts:
        """The parts on the frequencies ``idx`` (a copy for an index array)."""
        return MomentParts(self.parts[..., idx], self.heading)


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

    def mix(self, comps: Any) -> np.ndarray:
        """The selection of ``comps`` among x, y, z, (d, 3)."""
        return np.eye(3)[np.asarray(comps, dtype=int)]

    def block(self, comps: Any, freq: Any = slice(None)) -> np.ndarray:
        """(n_el, 2, d, n_f), a fresh contiguous array. [(m/s)/m]"""
        el = np.moveaxis(self.array, 0, -1)  # (n_el, 2, 3, n_w)
        return np.ascontiguousarray(el[:, :, list(comps), freq])

    def ends(self, comps: Any) -> tuple[np.ndarray, np.ndarray]:
        """(d, n_omega) each: the first element's end a, the last element's end b."""
        c = list(comps)
        return self.array[:, 0, 0, c].T.copy(), self.array[:, -1, 1, c].T.copy()

    def stacked(self, freq: Any) -> np.ndarray:
        """(n_el, 2, 3, n_f), a view."""
        return np.moveaxis(self.array, 0, -1)[..., freq]

    def full(self) -> np.ndarray:
        """The array itself, (n_omega, n_el, 2, 3)."""
        return self.array

    def __getitem__(self, idx: Any) -> ArrayMoments:
        return ArrayMoments(self.array[idx])


@dataclass(frozen=True, eq=False)
class SquareParts:
    """The element mean square ∫₀¹ Re(v vᴴ) dξ of the sea's kinematics in its two
    parts, S = h·b bᵀ + v·ẑ ẑᵀ with b = (cos β, sin β, 0) the wave direction (the
    horizontal and vertical velocities are in quadrature): two numbers per element and
    frequency instead of the nine of S.

    Attributes
    ----------
    horizontal, vertical : ndarray, shape (n_omega, n_el)
        h = ∫|u_h|² dξ and v = ∫|u_z|² dξ. [(m/s)²/m²]
    heading : float
        β. [rad]
    """

    horizontal: np.ndarray
    vertical: np.ndarray
    heading: float

    @property
    def nbytes(self) -> int:
        """Bytes of the two arrays. [B]"""
        return int(self.horizontal.nbytes + self.vertical.nbytes)

    def _pattern(self) -> tuple[np.ndarray, np.ndarray]:
        cb, sb = _direction(self.heading)
        p = np.array([[cb * cb, cb * sb, 0.0], [cb * sb, sb * sb, 0.0], [0.0, 0.0, 0.0]])
        z = np.zeros((3, 3))
        z[2, 2] = 1.0
        return p, z

    def full(self) -> np.ndarray:
        """S, shape (n_omega, n_el, 3, 3) (a fresh array). [(m/s)²/m²]"""
        cb, sb = _direction(self.heading)
        h = self.horizontal
        sq = np.zeros(h.shape + (3, 3))
        sq[:, :, 0, 0] = h * (cb * cb)
        sq[:, :, 1, 1] = h * (sb * sb)
        sq[:, :, 0, 1] = sq[:, :, 1, 0] = h * (cb * sb)
        sq[:, :, 2, 2] = self.vertical
        return sq

    def __getitem__(self, idx: Any) -> SquareParts:
        """The parts on the frequencies ``idx``."""
        return SquareParts(self.horizontal[idx], self.vertical[idx], self.heading)

    def weighted(self, weights: np.ndarray, comps: Any) -> np.ndarray:
        """Σ_ω weight·S on the components ``comps``, (n_el, d, d). [(m/s)²·…]"""
        p, z = self._pattern()
        c = np.asarray(comps)
        hw, vw = self.horizontal.T @ weights, self.vertical.T @ weights
        return hw[:, None, None] * p[c[:, None], c][None] + vw[:, None, None] * z[c[:, None], c]

    def projected(self, proj: np.ndarray) -> np.ndarray:
        """Σ_ij S_ij P_ij for per-element matrices P (n_el, 3, 3), (n_omega, n_el)."""
        p, z = self._pattern()
        ph = np.einsum("eij,ij->e", proj, p)
        pz = np.einsum("eij,ij->e", proj, z)
        return self.horizontal * ph + self.vertical * pz
