"""The fixed-point iteration of the drag linearization (Tuah 1982, §5.3, steps 5-13):
plain relaxed steps or Anderson acceleration, with the relative-change convergence
test (:func:`fixed_point`, :class:`FixedPointResult`).

References
----------
Tuah, H. (1982), Cable dynamics in an ocean environment, PhD thesis, Oregon State University.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, Literal

import numpy as np

from stochcable import validation as _v
from stochcable.errors import ConvergenceError, InputError

__all__ = ["ANDERSON_MIXING", "FixedPointResult", "fixed_point", "relative_change"]

#: Mixing of the Anderson-accelerated steps of the drag fixed point (the plain steps use
#: analysis.linearization.relaxation): undamped Anderson saves one iteration on the
#: chain, the taut wire, the guy and a 3-D chain (docs/BENCHMARKS.md "Response analysis").
ANDERSON_MIXING = 1.0


def relative_change(new: np.ndarray, x: np.ndarray) -> float:
    """The convergence measure of :func:`fixed_point`.

    Parameters
    ----------
    new, x : ndarray
        The map's output and input.

    Returns
    -------
    float
        max_i |new_i − x_i| / max(|new_i|, 1e-6·max|new|). [-]
    """
    den = np.maximum(np.abs(new), 1e-6 * max(float(np.max(np.abs(new), initial=0.0)), 1e-300))
    return float(np.max(np.abs(new - x) / den, initial=0.0))


@dataclass(frozen=True, eq=False)
class FixedPointResult:
    """Outcome of :func:`fixed_point`.

    Attributes
    ----------
    x : ndarray
        Last iterate (the last output of ``update``). [unit of x]
    iterations : int
        Number of ``update`` evaluations. [-]
    relative_change : float
        ``max_i |update(x)_i - x_i| / max(|update(x)_i|, floor)`` at the last
        evaluation. [-]
    converged : bool
        Whether ``relative_change <= tol``.
    history : tuple of float
        ``relative_change`` after each evaluation. [-]
    """

    x: np.ndarray
    iterations: int
    relative_change: float
    converged: bool
    history: tuple[float, ...]

    def as_dict(self) -> dict[str, Any]:
        """JSON-friendly summary (the "linearization record")."""
        return {
            "converged": bool(self.converged),
            "iterations": int(self.iterations),
            "relative_change": float(self.relative_change),
            "history": [float(h) for h in self.history],
        }


def fixed_point(
    update: Callable[[np.ndarray], np.ndarray],
    x0: np.ndarray,
    tol: float = 1e-4,
    max_iterations: int = 100,
    relaxation: float = 0.5,
    method: Literal["relaxed", "anderson"] = "anderson",
    memory: int = 5,
    floor: float | None = None,
    mixing: float | None = None,
    allow_unconverged: bool = False,
    name: str = "drag linearization",
    before: tuple[np.ndarray, np.ndarray] | None = None,
) -> FixedPointResult:
    r"""Solve ``x = update(x)`` for a non-negative vector (the drag linearization loop).

    Parameters
    ----------
    update : callable
        ``update(x) -> x_new``; maps the vector of velocity standard deviations
        used to build the linear drag to the ones of the resulting response
        (Tuah 1982, §5.3 steps 6-12). [unit of x]
    x0 : array_like
        Starting point, e.g. the standard deviations of the fluid velocity alone
        (cable at rest, Tuah (1982), §5.3 step 5).  Must be >= 0. [unit of x]
    tol : float, optional
        Tolerance on the relative change of every component. [-]
    max_iterations : int, optional
        Maximum number of ``update`` evaluations. [-]
    relaxation : float, optional
        Relaxation (mixing) factor ``beta`` in (0, 1]: the relaxed step is
        ``x + beta (update(x) - x)``; also Anderson's mixing parameter unless
        ``mixing`` is given. [-]
    method : {"anderson", "relaxed"}, optional
        ``"relaxed"``: under-relaxed Picard iteration.  ``"anderson"``: Anderson
        acceleration (type II, Walker & Ni 2011) with ``memory`` previous steps,
        safeguarded: when an accelerated step raised the residual norm the memory
        is cleared and a relaxed step is taken.
    memory : int, optional
        Anderson memory (number of previous differences). [-]
    mixing : float, optional
        Mixing parameter of the Anderson-accelerated steps, in (0, 1]; default
        ``relaxation``.  The plain steps (the first one and those after a safeguard
        restart) always use ``relaxation``.  Undamped Anderson (``mixing=1``, the
        usual choice, Walker & Ni 2011) saves one iteration on the drag fixed points
        of benchmarks/bench_analysis.py. [-]
    floor : float, optional
        Absolute floor of the denominator of the relative change; default
        ``1e-6 * max|update(x)|`` (so components that are ~0, e.g. elements
        above water, do not block convergence). [unit of x]
    allow_unconverged : bool, optional
        Return an unconverged result (``converged=False``) instead of raising.
    name : str, optional
        Solver name used in the error message.
    before : (ndarray, ndarray), optional
        An evaluation made before ``x0``, ``(x_prev, update(x_prev))`` (typically
        ``x0 = update(x_prev)``): with ``"anderson"`` it opens the memory, so the
        first step is already a secant step instead of a relaxed one. [unit of x]

    Returns
    -------
    FixedPointResult

    Raises
    ------
    ConvergenceError
        If ``max_iterations`` is reached without meeting ``tol`` (and
        ``allow_unconverged`` is false); ``partial`` holds the result.

    Notes
    -----
    Iterates are kept non-negative (standard deviations).  The convergence
    measure is the relative change of the map, ``max_i |g_i - x_i| / max(|g_i|,
    floor)`` with ``g = update(x)``, independent of the relaxation factor.
    """
    tol_ = _v.positive("tol", tol, "-")
    max_it = _v.positive_int("max_iterations", max_iterations)
    beta = _v.in_range("relaxation", relaxation, "-", 0.0, 1.0, lo_open=True)
    mem = _v.positive_int("memory", memory)
    if method not in ("relaxed", "anderson"):
        raise InputError("method", method, "-", "must be 'relaxed' or 'anderson'")
    floor_ = None if floor is None else _v.positive("floor", floor, "unit of x")
    mix = beta if mixing is None else _v.in_range("mixing", mixing, "-", 0.0, 1.0, lo_open=True)
    x = _v.float_array("x0", x0, "unit of x", ndim=None, nonnegative=True).copy()
    shape = x.shape
    x = x.ravel()

    def rel_change(g: np.ndarray, f: np.ndarray) -> float:
        fl = floor_ if floor_ is not None else 1e-6 * float(np.max(np.abs(g), initial=0.0))
        den = np.maximum(np.abs(g), fl)
        num = np.abs(f)
        ratio = np.divide(num, den, out=np.where(num > 0, np.inf, 0.0), where=den > 0)
        return float(np.max(ratio, initial=0.0))

    history: list[float] = []
    xs: list[np.ndarray] = []
    fs: list[np.ndarray] = []
    prev_norm = np.inf
    if before is not None and method == "anderson":
        x_prev = np.asarray(before[0], dtype=float).ravel()
        f_prev = np.asarray(before[1], dtype=float).ravel() - x_prev
        if x_prev.shape == x.shape and f_prev.shape == x.shape and np.all(np.isfinite(f_prev)):
            xs, fs = [x_prev.copy()], [f_prev]
            prev_norm = float(np.linalg.norm(f_prev))
    g = x
    change = np.inf
    for it in range(1, max_it + 1):
        g = np.asarray(update(x.reshape(shape)), dtype=float).ravel()
        if g.shape != x.shape or not np.all(np.isfinite(g)):
            raise ConvergenceError(
                name,
                it,
                float("nan"),
                tol_,
                hint="update(x) returned a non-finite value or a wrong shape",
            )
        f = g - x
        change = rel_change(g, f)
        history.append(change)
        if change <= tol_:
            res = FixedPointResult(g.reshape(shape).copy(), it, change, True, tuple(history))
            return res
        norm = float(np.linalg.norm(f))
        if method == "anderson":
            if norm > prev_norm and len(xs) > 1:
                # safeguard: the accelerated step did not reduce the residual
                xs, fs = [], []
            xs.append(x.copy())
            fs.append(f.copy())
            if len(xs) > mem + 1:
                xs.pop(0)
                fs.pop(0)
            if len(xs) > 1:
                dx = np.diff(np.array(xs), axis=0).T
                df = np.diff(np.array(fs), axis=0).T
                gamma, *_ = np.linalg.lstsq(df, f, rcond=1e-12)
                x_new = x + mix * f - (dx + mix * df) @ gamma
            else:
                x_new = x + beta * f
        else:
            x_new = x + beta * f
        prev_norm = norm
        x = np.maximum(x_new, 0.0)

    result = FixedPointResult(g.reshape(shape).copy(), max_it, change, False, tuple(history))
    if allow_unconverged:
        return result
    raise ConvergenceError(
        name,
        max_it,
        change,
        tol_,
        hint="increase max_iterations, lower the relaxation or try method='anderson'",
        partial=result,
    )
