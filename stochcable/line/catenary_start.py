"""Input checks, the Newton start and the vertical-line solve of the elastic catenary.

Shared by :func:`stochcable.line.catenary.catenary_solve_unchecked` (whose damped Newton
iteration on (H, V_a) starts here) and the multi-segment solver
(:mod:`stochcable.line.multisegment`): the scalar checks of :func:`catenary_solve
<stochcable.line.catenary.catenary_solve>`, the reach check (a line may stretch at most
:data:`MAX_STRAIN` to meet its span), the Newton start (Peyrot & Goulois 1979 for slack
lines, a parabolic elastic estimate for taut ones) and the bisection of a vertical
line (H = 0) on the closure integrals of :mod:`stochcable.line.catenary_kernel`.
"""

from __future__ import annotations

import math

import numpy as np

from stochcable import validation as v
from stochcable.errors import InputError
from stochcable.line.catenary_kernel import (
    vertical_profile,
)

__all__ = ["MAX_STRAIN", "check_reach", "newton_start"]

#: Largest strain a line may need to reach its span (as the scene's validation). [-]
MAX_STRAIN = 0.1


# ----------------------------------------------------------------------- validation


def _check_common(horizontal_span, vertical_span, length, weight, ea):
    X = v.nonnegative("horizontal_span", horizontal_span, "m")
    Z = v.finite_scalar("vertical_span", vertical_span, "m")
    L = v.positive("length", length, "m")
    w = v.finite_scalar("weight", weight, "N/m")
    try:
        ea_f = float(ea)
    except (TypeError, ValueError):
        raise InputError("ea", ea, "N", "must be a real number") from None
    if math.isnan(ea_f) or ea_f <= 0.0 or ea_f == -math.inf:
        raise InputError("ea", ea, "N", "must be > 0 (math.inf for an inextensible line)")
    return X, Z, L, w, ea_f


def check_reach(L, chord, ea):
    if math.isinf(ea):
        if chord >= L:
            raise InputError(
                "length",
                L,
                "m",
                f"an inextensible line must be longer than the distance between its ends "
                f"({chord:.6g} m)",
            )
    elif chord > L * (1.0 + MAX_STRAIN):
        raise InputError(
            "length",
            L,
            "m",
            f"is shorter than the distance between the ends ({chord:.6g} m): the line "
            f"would have to stretch {chord / L - 1.0:.1%} (> {MAX_STRAIN:.0%})",
        )


# ---------------------------------------------------------------------------- solve


def newton_start(X, Z, L, w, c):
    """Start for Newton: the inextensible catenary estimate of Peyrot & Goulois (1979)
    for slack lines, a parabolic elastic estimate for taut ones."""
    chord = math.hypot(X, Z)
    slack = (L - chord) / chord if chord > 0 else math.inf
    if slack > 0.02 and X > 0.0:
        lam = math.sqrt(3.0 * max((L * L - Z * Z) / (X * X) - 1.0, 1e-12))
        H0 = abs(w) * X / (2.0 * lam)
        Vb0 = 0.5 * w * (Z / math.tanh(lam) + L)
        return max(H0, 1e-12 * abs(w) * L), Vb0 - w * L
    # taut: L (1 + T c) − chord = (w X)² chord / (24 T²), increasing in T
    wx = abs(w) * X

    def f(T):
        return L * (1.0 + T * c) - chord - wx * wx * chord / (24.0 * T * T)

    lo, hi = 1e-300, 1.0
    while f(hi) < 0.0 and hi < 1e300:
        hi *= 10.0
    lo = hi / 10.0
    while f(lo) > 0.0 and lo > 1e-300:
        lo /= 10.0
    for _ in range(200):
        mid = math.sqrt(lo * hi) if lo > 0 else 0.5 * hi
        if f(mid) > 0.0:
            hi = mid
        else:
            lo = mid
        if hi / max(lo, 1e-300) < 1.0 + 1e-6:
            break
    T = hi
    return max(T * X / chord, 1e-12 * T), T * Z / chord - 0.5 * w * L


def _vertical_solve(Z, L, w, c, seabed):
    """H = 0: solve z(L) = Z for V_a (monotone increasing)."""

    def zend(Va):
        return float(vertical_profile(np.array(L), Va, w, c)[1])

    Tsc = abs(w) * L + (1.0 / c if c > 0 else 0.0) * 1e-3 + 1.0
    lo, hi = -abs(w) * L - Tsc, abs(w) * L + Tsc
    while zend(hi) < Z:
        hi = 2.0 * hi + Tsc
    while zend(lo) > Z:
        lo = 2.0 * lo - Tsc
    for it in range(1, 400):  # noqa: B007 - the bisection count is returned
        mid = 0.5 * (lo + hi)
        if zend(mid) < Z:
            lo = mid
        else:
            hi = mid
        if hi - lo <= 4e-16 * max(abs(hi), abs(lo), 1e-300):
            break
    Va = 0.5 * (lo + hi)
    if seabed and Va < 0.0:
        raise InputError(
            "horizontal_span",
            0.0,
            "m",
            "a vertical slack line on the seabed would pile up at end_a; no catenary "
            "equilibrium (give a horizontal span or a shorter line)",
        )
    return Va, it, abs(zend(Va) - Z)
