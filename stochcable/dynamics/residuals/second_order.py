"""Second-order (stretching) tension of a line from its linear response: the indicator
of when linear tension is not enough.

A transverse displacement u⊥ of a cable lengthens it to second order by ½∫(∂u⊥/∂s)² ds
(the quadratic part of the Green strain), which the linear model drops.  With the axial
response quasi-static (axial waves much faster than the excitation) the line takes up
that lengthening as a uniform tension increment, reduced by the sag's flexibility::

    T₂ = κ · ½ Σ_e |Δu⊥_e|² / l_e,    κ = 1 / (Σ_e l_e/EA_e · (1 + λ*²/12))

(Irvine 1981, *Cable Structures*, §2.4 and §3.3: the chord stiffness of a shallow
elastic cable; λ*² = (w₀L/H*)²·(EA/H*)·cos²φ_a for an inclined cable, Bliet 1984, eq. 4.3).
For a taut, near-straight line λ*² ≪ 1 and T₂ is the full stretching term; for a
catenary (λ*² ≫ 1, a grounded length) the sag absorbs the lengthening and T₂ vanishes.

The linear response x = (Δu⊥_e) is zero-mean Gaussian, so T₂ = xᵀAx is a Gaussian
quadratic form with closed-form moments (Mathai & Provost 1992, *Quadratic Forms in
Random Variables*, Thm 3.2b.2): E[T₂] = tr(AΣ), Var[T₂] = 2 tr((AΣ)²), and T₂ is
uncorrelated with the linear tension (odd moments of x vanish), so the σ of
linear + second-order tension is √(σ_lin² + Var T₂).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from stochcable.dynamics.loads.freqblocks import working_memory_bytes
from stochcable.errors import PhysicsWarning, warn

__all__ = [
    "SecondOrderTension",
    "second_order_tension",
    "irvine_lambda2",
    "quadratic_form_moments",
    "SECOND_ORDER_WARN_RATIO",
    "with_second_order",
]

#: σ(T₂)/σ_lin above which a warning is raised: the linear tension σ is then
#: underestimated by more than 2 % (√(1 + 0.2²) = 1.020). [-]
SECOND_ORDER_WARN_RATIO = 0.2


@dataclass(frozen=True)
class SecondOrderTension:
    """Moments of the second-order stretching tension of one line.

    Attributes
    ----------
    mean : float
        Mean tension increment E[T₂] (a shift of the mean tension). [N]
    std : float
        σ of T₂. [N]
    ratio : float
        std / the largest linear element tension σ of the line (0 without response, inf
        where only the second-order tension varies). [-]
    lambda2 : float
        Irvine's λ*² of the line's static shape (inf with a grounded length). [-]
    std_factor : float
        √(1 + ratio²): σ of linear + second-order tension over the linear σ. [-]
    """

    mean: float
    std: float
    ratio: float
    lambda2: float
    std_factor: float

    def as_dict(self) -> dict[str, Any]:
        """JSON-ready dict (non-finite λ*² as None)."""
        return {
            "mean": self.mean,
            "std": self.std,
            "ratio": _finite(self.ratio),
            "lambda2": _finite(self.lambda2),
            "std_factor": _finite(self.std_factor),
        }


def _finite(x: float) -> float | None:
    return x if math.isfinite(x) else None


def irvine_lambda2(
    positions: np.ndarray, l0: np.ndarray, ea: np.ndarray, weight: np.ndarray, tension: np.ndarray
) -> float:
    """Irvine's λ*² of a line's static shape (Bliet 1984, eq. 4.3). [-]

    Parameters
    ----------
    positions : ndarray, shape (n_nodes, 3)
        Static node positions. [m]
    l0, ea, weight, tension : ndarray, shape (n_el,)
        Element lengths [m], axial stiffness [N], submerged weight per length [N/m]
        and static effective tension [N].

    Returns
    -------
    float
        (w₀L/H*)²·(EA/H*)·cos²φ_a with L the length, w₀ and EA length-weighted means,
        H* the mean tension and φ_a the chord's angle to the horizontal; inf where the
        mean tension is not positive. [-]
    """
    length = float(np.sum(l0))
    h = float(np.sum(tension * l0) / length)
    if h <= 0.0:
        return math.inf
    w0 = float(np.sum(np.abs(weight) * l0) / length)
    ea_m = length / float(np.sum(l0 / ea))
    chord = positions[-1] - positions[0]
    cos_phi = math.hypot(chord[0], chord[1]) / max(float(np.linalg.norm(chord)), 1e-300)
    return (w0 * length / h) ** 2 * (ea_m / h) * cos_phi**2


def quadratic_form_moments(b: np.ndarray) -> tuple[float, float]:
    """Mean and σ of xᵀx for the real Gaussian vector x = Re(B·a) of the spectral
    representation (a complex unit amplitudes, columns of B the weighted components).

    Parameters
    ----------
    b : ndarray, complex, shape (n_x, n_components)
        √A·H·√(S dω): each column one frequency and input channel. [unit]

    Returns
    -------
    (float, float)
        tr Σ and √(2·‖Σ‖_F²) with Σ = Re(B Bᴴ) the covariance of x. [unit²]
    """
    return _real_form_moments(np.concatenate([b.real, b.imag], axis=1))


def _real_form_moments(c: np.ndarray) -> tuple[float, float]:
    """:func:`quadratic_form_moments` of B from the real columns of B (its real and
    imaginary parts, in any order): tr Σ and √(2·‖Σ‖_F²), Σ = C Cᵀ."""
    mean = float(np.sum(c * c))
    g = c @ c.T if c.shape[0] <= c.shape[1] else c.T @ c  # same Frobenius norm
    return mean, math.sqrt(2.0 * float(np.sum(g * g)))


def second_order_tension(
    motion_transfer: np.ndarray | Callable[[slice], np.ndarray],
    input_spectra: np.ndarray,
    weights: np.ndarray,
    positions: np.ndarray,
    mesh: Any,
    tension_mean: np.ndarray,
    tension_std: np.ndarray,
    components: tuple[int, ...] = (0, 1, 2),
) -> SecondOrderTension:
    """The second-order stretching tension of one line (module docstring).

    Parameters
    ----------
    motion_transfer : ndarray, complex, shape (n_ch, n_nodes, 3, n_omega), or callable
        Node displacement per unit input, or a callable giving it on a slice of the
        frequencies (read block by block). [m/unit]
    input_spectra : ndarray, shape (n_ch, n_omega)
        Input spectra. [unit²·s/rad]
    weights : ndarray, shape (n_omega,)
        Trapezoid weights of the frequency grid. [rad/s]
    positions : ndarray, shape (n_nodes, 3)
        Static node positions. [m]
    mesh : LineMesh
        ``l0``, ``ea``, ``weight`` per element.
    tension_mean, tension_std : ndarray, shape (n_el,)
        Static tension and linear tension σ per element. [N]
    components : tuple of int, optional
        The components the motion can have (a 2-D model's: its plane): the normals
        with no part on them give rows of B that are zero, left out of its Gram
        matrix (a line in a vertical plane: half the rows, a quarter of the work).

    Returns
    -------
    SecondOrderTension
    """
    d = positions[1:] - positions[:-1]
    t = d / np.linalg.norm(d, axis=1)[:, None]
    # two unit normals of every element: Δu⊥ in that basis, 2 components, not 3
    ref = np.where(np.abs(t[:, 2:3]) < 0.9, [[0.0, 0.0, 1.0]], [[1.0, 0.0, 0.0]])
    n1 = np.cross(t, ref)
    n1 /= np.linalg.norm(n1, axis=1)[:, None]
    normals = np.stack([n1, np.cross(t, n1)], axis=1)  # (n_el, 2, 3)
    lam2 = irvine_lambda2(positions, mesh.l0, mesh.ea, mesh.weight, tension_mean)
    kappa = 1.0 / (float(np.sum(mesh.l0 / mesh.ea)) * (1.0 + lam2 / 12.0))
    normals = normals * np.sqrt(0.5 * kappa / mesh.l0)[:, None, None]  # T₂ = Σ_e a_e|Δu⊥_e|²
    amp = np.sqrt(np.clip(input_spectra, 0.0, None) * weights)  # (n_ch, n_w)
    keep = np.any(normals[:, :, list(components)] != 0.0, axis=2).ravel()  # (2·n_el,)
    mean, std = _moments(motion_transfer, amp, normals, keep) if math.isfinite(lam2) else (0.0, 0.0)
    sig = float(np.max(tension_std)) if tension_std.size else 0.0
    ratio = std / sig if sig > 0 else (math.inf if std > 0 else 0.0)
    return SecondOrderTension(mean, std, ratio, lam2, math.sqrt(1.0 + ratio * ratio))


def _moments(
    motion_transfer: np.ndarray | Callable[[slice], np.ndarray],
    amp: np.ndarray,
    normals: np.ndarray,
    keep: np.ndarray | None = None,
) -> tuple[float, float]:
    """:func:`_real_form_moments` of the rows B = normals·Δu·amp (two per element; one
    column per channel and frequency, real and imaginary parts side by side), over
    blocks: of frequencies when there are fewer rows than columns (the rows' Gram
    matrix summed block by block), else of elements (the columns' Gram matrix), each
    block's Δu and B within the working-memory target (the whole B of 400 elements ×
    2,000 ω × 2 channels was 51 MB and its Δu 77 MB).  A callable ``motion_transfer``
    is read by frequency blocks (formed whole for the elements' blocks).  ``keep``: the
    rows (two per element) that can be nonzero (default all)."""
    n_ch, n_w = amp.shape
    n_nodes = normals.shape[0] + 1
    keep = np.ones(2 * (n_nodes - 1), dtype=bool) if keep is None else keep
    n_rows, n_cols = int(np.count_nonzero(keep)), 2 * n_ch * n_w
    if callable(motion_transfer) and n_rows > n_cols:
        motion_transfer = motion_transfer(slice(None))

    def rows(el: slice, fr: slice) -> np.ndarray:
        # Δu·amp per element, component, channel and frequency, then its normal
        # components as one stacked real product on the interleaved (re, im) view
        if callable(motion_transfer):  # this block of frequencies, all elements
            mt, fm = motion_transfer(fr).transpose(1, 2, 0, 3), slice(None)
        else:
            mt, fm = motion_transfer.transpose(1, 2, 0, 3), fr
        a, b = mt[el.start + 1 : el.stop + 1, :, :, fm], mt[el, :, :, fm]
        du = np.empty(a.shape, dtype=complex)
        np.subtract(a, b, out=du)
        du *= amp[:, fr]
        c = normals[el] @ du.view(float).reshape(du.shape[0], 3, -1)
        c = c.reshape(2 * du.shape[0], -1)
        rows_kept = keep[2 * el.start : 2 * el.stop]
        return c if rows_kept.all() else c[rows_kept]

    # a block's Δu, B and copies: ≈ 200 bytes per element, channel and frequency
    per = 200.0 * n_ch
    mean, gram = 0.0, None
    if n_rows <= n_cols:
        step = max(1, int(working_memory_bytes() // (per * (n_nodes - 1))))
        for i in range(0, n_w, step):
            c = rows(slice(0, n_nodes - 1), slice(i, min(i + step, n_w)))
            mean += float(np.sum(c * c))
            gram = c @ c.T if gram is None else gram + c @ c.T
    else:
        step = max(1, int(working_memory_bytes() // (per * n_w)))
        for i in range(0, n_nodes - 1, step):
            c = rows(slice(i, min(i + step, n_nodes - 1)), slice(0, n_w))
            mean += float(np.sum(c * c))
            gram = c.T @ c if gram is None else gram + c.T @ c
    return mean, math.sqrt(2.0 * float(np.sum(gram * gram)))


def with_second_order(line: str, indicators: Any, second_order: SecondOrderTension) -> Any:
    """``indicators`` (a LineIndicators) carrying ``second_order``, flagged and warned
    about when its σ ratio exceeds :data:`SECOND_ORDER_WARN_RATIO`."""
    flags = indicators.flags
    if second_order.ratio > SECOND_ORDER_WARN_RATIO:
        flags = (*flags, "second_order")
        warn(
            f"line {line!r}: the second-order stretching tension has σ = "
            f"{second_order.std:.4g} N and mean {second_order.mean:.4g} N, "
            f"{second_order.ratio:.0%} of the linear tension σ (threshold "
            f"{SECOND_ORDER_WARN_RATIO:.0%}): the linear tension σ is low by a factor "
            f"{second_order.std_factor:.3f}; the result's indicators carry the corrected "
            "moments — check against a nonlinear time-domain analysis "
            "(stochcable.reference) for a design value",
            PhysicsWarning,
        )
    return dataclasses.replace(indicators, second_order=second_order, flags=flags)
