"""Nonlinear time-domain reference: Newmark average acceleration with Newton iterations.

Tuah (1982), §4.2: the single-step implicit Newmark operator with beta = 1/4, gamma = 1/2
(constant average acceleration, unconditionally stable for linear systems, eqs.
4.2.7.a,b), with the nonlinear stiffness and the velocity-dependent drag iterated
to equilibrium at every step (incremental-iterative Newton, eqs. 4.2.5, 4.2.8).

The system is anything that implements :class:`NonlinearSystem`:

    M a + f_int(u) = f_ext(t, u, v)

with constant mass ``M`` (structural + added mass), internal (elastic) force
``f_int`` and its tangent ``K_t``, and an external force that may depend on the
displacement and the velocity (drag on the relative velocity).

References
----------
Tuah, H. (1982), Cable dynamics in an ocean environment, PhD thesis, Oregon State University.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Protocol, runtime_checkable

import numpy as np

from stochcable import validation as _v
from stochcable.errors import ConvergenceError, InputError

__all__ = ["NonlinearSystem", "LinearSystem", "TimeHistory", "newmark"]


@runtime_checkable
class NonlinearSystem(Protocol):
    """Protocol of a system integrated by :func:`newmark`.

    Required methods: ``mass() -> (n, n)`` [kg], ``internal_force(u) -> (n,)`` [N],
    ``tangent_stiffness(u) -> (n, n)`` [N/m], ``external_force(t, u, v) -> (n,)`` [N].
    Optional: ``external_force_jacobian_v(t, u, v) -> (n, n)`` [N·s/m] and
    ``external_force_jacobian_u(t, u, v) -> (n, n)`` [N/m], the derivatives of the
    external force used in the Newton tangent (without them Newton converges
    linearly for velocity-dependent loads).
    """

    def mass(self) -> np.ndarray: ...

    def internal_force(self, u: np.ndarray) -> np.ndarray: ...

    def tangent_stiffness(self, u: np.ndarray) -> np.ndarray: ...

    def external_force(self, t: float, u: np.ndarray, v: np.ndarray) -> np.ndarray: ...


@dataclass(frozen=True, eq=False)
class LinearSystem:
    """Linear system ``M a + C v + K u = f(t)`` as a :class:`NonlinearSystem`.

    Attributes
    ----------
    M, C, K : ndarray, shape (n, n)
        Mass [kg], damping [N·s/m], stiffness [N/m].
    force : callable, optional
        ``force(t) -> (n,)`` external load; ``None`` for free vibration. [N]
    """

    M: np.ndarray
    C: np.ndarray
    K: np.ndarray
    force: Callable[[float], np.ndarray] | None = None

    def mass(self) -> np.ndarray:
        return np.asarray(self.M, dtype=float)

    def internal_force(self, u: np.ndarray) -> np.ndarray:
        return np.asarray(self.K, dtype=float) @ u

    def tangent_stiffness(self, u: np.ndarray) -> np.ndarray:
        return np.asarray(self.K, dtype=float)

    def external_force(self, t: float, u: np.ndarray, v: np.ndarray) -> np.ndarray:
        f = -np.asarray(self.C, dtype=float) @ v
        if self.force is not None:
            f = f + np.asarray(self.force(t), dtype=float)
        return f

    def external_force_jacobian_v(self, t: float, u: np.ndarray, v: np.ndarray) -> np.ndarray:
        return -np.asarray(self.C, dtype=float)


@dataclass(frozen=True, eq=False)
class TimeHistory:
    """Result of :func:`newmark`.

    Attributes
    ----------
    t : ndarray, shape (n_t,)
        Time instants. [s]
    u, v, a : ndarray, shape (n_t, n)
        Displacement [m], velocity [m/s] and acceleration [m/s²].
    iterations : ndarray of int, shape (n_t - 1,)
        Newton iterations (linear solves) of each step. [-]
    max_residual : float
        Largest relative force residual at convergence over all steps. [-]
    """

    t: np.ndarray
    u: np.ndarray
    v: np.ndarray
    a: np.ndarray
    iterations: np.ndarray
    max_residual: float


def newmark(
    system: NonlinearSystem,
    u0: np.ndarray,
    v0: np.ndarray,
    t: np.ndarray,
    tol: float = 1e-10,
    max_iterations: int = 25,
) -> TimeHistory:
    r"""Integrate ``M a + f_int(u) = f_ext(t, u, v)`` by Newmark average acceleration + Newton.

    Parameters
    ----------
    system : NonlinearSystem
        The system (see the protocol).
    u0, v0 : array_like, shape (n,)
        Initial displacement [m] and velocity [m/s].
    t : array_like, shape (n_t,)
        Strictly increasing time instants (the step may vary). [s]
    tol : float, optional
        Newton tolerance on the force residual, relative to the largest term in it
        (``|4 M du / h^2|``, ``|M a_n|``, ``|f_int|``, ``|f_ext|``, infinity norms).  A
        step whose Newton correction is below ``tol |du|`` (or round-off) is also
        accepted when its residual is below ``1000 tol``. [-]
    max_iterations : int, optional
        Newton iterations allowed per step. [-]

    Returns
    -------
    TimeHistory

    Raises
    ------
    ConvergenceError
        If Newton fails at a step (the message gives the time); ``partial``
        holds the history up to the last converged step.

    Notes
    -----
    Tuah (1982), eqs. (4.2.7.a,b): with ``du = u_{n+1} - u_n`` and step ``h``,
    ``v_{n+1} = 2 du / h - v_n`` and ``a_{n+1} = 4 du / h^2 - 4 v_n / h - a_n``.
    The residual ``R = M a_{n+1} + f_int(u_{n+1}) - f_ext(t_{n+1}, u_{n+1}, v_{n+1})``
    is driven to zero with the tangent
    ``4 M / h^2 + K_t - df_ext/du - (2/h) df_ext/dv`` (eq. 4.2.8).  For a linear
    system one Newton step is exact; the scheme is the trapezoidal rule for
    ``(u, v)``: no amplitude decay, energy conserved, period elongated
    (``omega h -> 2 arctan(omega h / 2)``).
    """
    tt = _v.float_array("t", t, "s", increasing=True, min_size=2)
    u = _v.float_array("u0", u0, "m").copy()
    v = _v.float_array("v0", v0, "m/s").copy()
    if v.shape != u.shape:
        raise InputError("v0", v0, "m/s", f"must have the shape of u0 {u.shape}")
    tol_ = _v.positive("tol", tol, "-")
    max_it = _v.positive_int("max_iterations", max_iterations)
    M = np.asarray(system.mass(), dtype=float)
    n = u.size
    if M.shape != (n, n):
        raise InputError("system.mass()", M, "kg", f"must have shape ({n}, {n})")
    jac_v = getattr(system, "external_force_jacobian_v", None)
    jac_u = getattr(system, "external_force_jacobian_u", None)

    nt = tt.size
    U = np.empty((nt, n))
    V = np.empty((nt, n))
    A = np.empty((nt, n))
    iters = np.zeros(nt - 1, dtype=int)
    f_ext = np.asarray(system.external_force(tt[0], u, v), dtype=float)
    a = np.linalg.solve(M, f_ext - np.asarray(system.internal_force(u), dtype=float))
    U[0], V[0], A[0] = u, v, a
    max_res = 0.0
    for k in range(nt - 1):
        h = tt[k + 1] - tt[k]
        tk = tt[k + 1]
        un, vn, an = U[k], V[k], A[k]
        u_new = un + h * vn + 0.25 * h * h * an  # predictor (constant acceleration)
        converged = False
        small_step = False
        res_rel = np.inf
        n_solves = 0
        while True:
            du = u_new - un
            v_new = 2.0 * du / h - vn
            a_new = 4.0 * du / (h * h) - 4.0 * vn / h - an
            f_int = np.asarray(system.internal_force(u_new), dtype=float)
            f_ext = np.asarray(system.external_force(tk, u_new, v_new), dtype=float)
            inertia = M @ a_new
            r = inertia + f_int - f_ext
            # scale: the largest term summed (round-off of a_new is relative to 4 du/h^2)
            scale = max(
                np.abs(M @ (4.0 * du / (h * h))).max(),
                np.abs(M @ an).max(),
                np.abs(inertia).max(),
                np.abs(f_int).max(),
                np.abs(f_ext).max(),
                np.finfo(float).tiny,
            )
            res_rel = float(np.abs(r).max() / scale)
            if res_rel <= tol_ or (small_step and res_rel <= 1e3 * tol_):
                # (a negligible correction with a residual at round-off level is accepted)
                converged = True
                break
            if n_solves == max_it:
                break
            kt = 4.0 / (h * h) * M + np.asarray(system.tangent_stiffness(u_new), dtype=float)
            if jac_v is not None:
                kt = kt - (2.0 / h) * np.asarray(jac_v(tk, u_new, v_new), dtype=float)
            if jac_u is not None:
                kt = kt - np.asarray(jac_u(tk, u_new, v_new), dtype=float)
            delta = np.linalg.solve(kt, -r)
            n_solves += 1
            u_new = u_new + delta
            step = tol_ * np.abs(u_new - un).max() + 8 * np.finfo(float).eps * np.abs(u_new).max()
            small_step = bool(np.abs(delta).max() <= step)
        if not converged:
            partial = TimeHistory(
                tt[: k + 1], U[: k + 1], V[: k + 1], A[: k + 1], iters[:k], max_res
            )
            raise ConvergenceError(
                f"Newmark Newton (step {k + 1}, t = {tk:.6g} s)",
                max_it,
                res_rel,
                tol_,
                hint="reduce the time step or provide external_force_jacobian_v",
                partial=partial,
            )
        U[k + 1], V[k + 1], A[k + 1] = u_new, v_new, a_new
        iters[k] = n_solves
        max_res = max(max_res, res_rel)
    return TimeHistory(tt, U, V, A, iters, max_res)
