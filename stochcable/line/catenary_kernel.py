"""The closure integrals of the elastic catenary (Irvine 1981, ch. 2; Bliet (1984), eqs.
(2.5)–(2.6)), shared by the single- and multi-segment solvers.

For a suspended stretch of unstretched length l_s starting with vertical force V_0 under
horizontal force H and weight w per length, the spans

    x = H l_s/EA + ∫ H/T ds,   z = (V_0 l_s + w l_s²/2)/EA + ∫ V/T ds,

and their Jacobian in (H, V_0), evaluated as divided differences (no 1/w cancellation):
exact in the weightless (w → 0) and vertical (H → 0) limits and for taut lines.

References
----------
Bliet, A. (1984), Dynamic analysis of single span cables, PhD thesis, Massachusetts
Institute of Technology.
Irvine, H. M. (1981), Cable structures, MIT Press, Cambridge, MA.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = [
    "CLOSURE_TOL",
    "MAX_NEWTON",
    "asinhc",
    "kernel",
    "kernel_scalar",
    "kernel_spans",
    "closure",
    "vertical_profile",
]

CLOSURE_TOL = 1e-12  # closure tolerance, relative to max(length, chord)
MAX_NEWTON = 200  # Newton iterations of the closure


def asinhc(d: np.ndarray) -> np.ndarray:
    """asinh(d)/d, 1 at d = 0."""
    d = np.asarray(d, dtype=float)
    small = np.abs(d) < 1e-6
    safe = np.where(small, 1.0, d)
    return np.where(small, 1.0 - d * d / 6.0, np.arcsinh(safe) / safe)


def kernel(H, V0, w, ls, c):
    """Suspended stretch of length ``ls`` starting with vertical force ``V0``.

    Returns x, z (spans of the stretch) and the partial derivatives dx/dH, dx/dV0,
    dz/dH, dz/dV0 at fixed ``ls`` (the Jacobian is symmetric: it is the Hessian of the
    complementary energy).  ``c`` = 1/EA (0 for an inextensible line).  H > 0.
    All arguments broadcast.
    """
    H = np.asarray(H, dtype=float)
    V0 = np.asarray(V0, dtype=float)
    ls = np.asarray(ls, dtype=float)
    V1 = V0 + w * ls
    T0 = np.hypot(H, V0)
    T1 = np.hypot(H, V1)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        same = V0 * V1 >= 0.0
        both0 = (V0 == 0.0) & (V1 == 0.0)
        den = V1 * T0 + V0 * T1
        q = np.where(both0, 1.0 / H, (V0 + V1) / np.where(den == 0.0, 1.0, den))
        # same-sign branch (no cancellation: V0, V1 of one sign)
        s1_same = ls * H * q * asinhc(w * ls * q)
        j_same = ls * H * H * q / (T0 * T1)
        # opposite-sign branch (w != 0 there and |w ls| >= |V0|, |V1|: no cancellation)
        wsafe = w if w != 0.0 else 1.0
        s1_opp = (H / wsafe) * (np.arcsinh(V1 / H) - np.arcsinh(V0 / H))
        j_opp = (V1 / T1 - V0 / T0) / wsafe
        S1 = np.where(same, s1_same, s1_opp)  # ∫ H/T ds
        J = np.where(same, j_same, j_opp)  # ∫ H²/T³ ds
    return kernel_spans(H, V0, V1, T0, T1, S1, J, w, ls, c)


def kernel_spans(H, V0, V1, T0, T1, S1, J, w, ls, c) -> tuple:  # noqa: ANN001
    """The branch-free end of :func:`kernel` and :func:`kernel_scalar` (arrays or
    floats alike): spans and Jacobian from S1 = ∫ H/T ds and J = ∫ H²/T³ ds."""
    S2 = ls * (V0 + V1) / (T0 + T1)  # ∫ V/T ds
    K = -H * ls * (V0 + V1) / (T0 * T1 * (T0 + T1))  # ∫ −HV/T³ ds
    x = H * c * ls + S1
    z = c * (V0 * ls + 0.5 * w * ls * ls) + S2
    dxdH = c * ls + S1 / H - J
    dzdV = c * ls + J
    return x, z, dxdH, K, K, dzdV


def kernel_scalar(H: float, V0: float, w: float, ls: float, c: float) -> tuple:
    """:func:`kernel` for Python floats: the same formulas and branches as float
    arithmetic (the closure Newton evaluates it a few times per solve, where numpy's
    per-call overhead on 0-d arrays dominated, ≈ 0.2 ms of every chain statics).
    hypot and asinh stay numpy's (math's may differ in the last bit), so the results
    are the array kernel's to the bit."""
    V1 = V0 + w * ls
    T0 = float(np.hypot(H, V0))
    T1 = float(np.hypot(H, V1))
    if V0 * V1 >= 0.0:  # same-sign branch (no cancellation: V0, V1 of one sign)
        if V0 == 0.0 and V1 == 0.0:
            q = 1.0 / H
        else:
            den = V1 * T0 + V0 * T1
            q = (V0 + V1) / (1.0 if den == 0.0 else den)
        dd = w * ls * q
        asinhc = 1.0 - dd * dd / 6.0 if abs(dd) < 1e-6 else float(np.arcsinh(dd)) / dd
        S1 = ls * H * q * asinhc  # ∫ H/T ds
        J = ls * H * H * q / (T0 * T1)  # ∫ H²/T³ ds
    else:  # opposite signs (w != 0 there and |w ls| >= |V0|, |V1|: no cancellation)
        wsafe = w if w != 0.0 else 1.0
        S1 = (H / wsafe) * (float(np.arcsinh(V1 / H)) - float(np.arcsinh(V0 / H)))
        J = (V1 / T1 - V0 / T0) / wsafe
    return kernel_spans(H, V0, V1, T0, T1, S1, J, w, ls, c)


def closure(H, Va, L, w, c, seabed):
    """Spans (X, Z) and the Jacobian d(X, Z)/d(H, Va) of the whole segment."""
    H, Va, L, w, c = float(H), float(Va), float(L), float(w), float(c)
    if not (math.isfinite(H) and math.isfinite(Va)) or H <= 0.0:
        stretch = kernel  # numpy's inf/nan semantics (the line search rejects them)
    else:
        stretch = kernel_scalar
    if seabed and Va < 0.0:
        lb = -Va / w  # may exceed L inside the iteration: the closure stays smooth
        x, z, a, b, cc, d = stretch(H, 0.0, w, L - lb, c)
        return (
            float(x + lb * (1.0 + H * c)),
            float(z),
            np.array([[a + lb * c, b], [cc, d]], dtype=float),
        )
    x, z, a, b, cc, d = stretch(H, Va, w, L, c)
    return float(x), float(z), np.array([[a, b], [cc, d]], dtype=float)


def vertical_profile(s, Va, w, c):
    """Profile of a vertical line (H = 0), possibly folded where V changes sign."""
    V = Va + w * s
    # ∫ sgn(V)(1 + c|V|) ds' = ∫ (sgn V + c V) ds' ; sgn integral via the root s*.
    if w != 0.0:
        s_star = -Va / w
    else:
        s_star = math.inf
    sg0 = 1.0 if (Va > 0.0 or (Va == 0.0 and w >= 0.0)) else -1.0
    if 0.0 < s_star:
        before = np.minimum(s, s_star)
        after = np.maximum(s - s_star, 0.0)
        sgn_int = sg0 * before - sg0 * after
    else:
        sgn_int = sg0 * s
    z = sgn_int + c * (Va * s + 0.5 * w * s * s)
    x = np.zeros_like(s)
    return x, z, np.abs(V)
