"""Time integration of the time-domain reference (:mod:`stochcable.reference.cable`):
Newmark average acceleration (β = 1/4, γ = 1/2; Tuah (1982), eqs. 4.2.7–4.2.11) with full
Newton iterations per step, a backtracking line search on the residual and banded
LAPACK solves; the end tensions are the support reactions.

References
----------
Tuah, H. (1982), Cable dynamics in an ocean environment, PhD thesis, Oregon State University.
"""

from __future__ import annotations

import math

import numpy as np
from scipy import linalg as sla

from stochcable.errors import ConvergenceError
from stochcable.reference.cable_model import LineModel
from stochcable.reference.cable_transport import check_transport_speed

__all__ = ["newmark_period_error", "newmark_step_for", "integrate"]

_BACKTRACK = 12  # largest number of step halvings in a Newton line search


def newmark_period_error(omega: float | np.ndarray, dt: float) -> float | np.ndarray:
    """Relative period elongation of Newmark average acceleration.

    Parameters
    ----------
    omega : float or array
        Angular frequency. [rad/s]
    dt : float
        Time step. [s]

    Returns
    -------
    float or array
        ΔT/T = ωΔt / (2 arctan(ωΔt/2)) − 1 ≈ (ωΔt)²/12. [-]

    Notes
    -----
    The trapezoidal rule maps s = iω to i(2/Δt) tan(ωΔt/2): a linear undamped mode of
    frequency ω oscillates at (2/Δt) arctan(ωΔt/2) with no amplitude error.
    """
    x = np.asarray(omega, dtype=float) * dt
    with np.errstate(invalid="ignore", divide="ignore"):
        r = np.where(x > 0, x / (2.0 * np.arctan(0.5 * np.where(x > 0, x, 1.0))) - 1.0, 0.0)
    return float(r) if r.ndim == 0 else r


def newmark_step_for(omega: float, tolerance: float) -> float:
    """The largest step with the period error (ωΔt)²/12 of :func:`newmark_period_error`
    at most ``tolerance`` at ``omega`` [rad/s]: Δt = 2√(3·tolerance)/ω. [s]"""
    return 2.0 * math.sqrt(3.0 * tolerance) / max(float(omega), 1e-12)


def integrate(
    model: LineModel,
    xs: np.ndarray,
    u_cur: np.ndarray,
    u_cur_g: np.ndarray,
    u_wave,
    u_wave_g,
    f_in,
    end_disp: dict,
    t: np.ndarray,
    h: float,
    tol: float,
    max_it: int,
    every: int,
):
    """Newmark average acceleration with Newton iterations (Tuah (1982), eqs. 4.2.7–4.2.11).

    Parameters
    ----------
    model : LineModel
    xs : ndarray, shape (n, d)
        Static start (an equilibrium of ``model``). [m]
    u_cur, u_cur_g : ndarray
        Current velocity at the nodes (n, d) and the drag points (ne, ng, d). [m/s]
    u_wave, u_wave_g, f_in : ndarray or None
        Wave velocity at the nodes and the drag points, wave-inertia nodal load, per
        step (:func:`~stochcable.reference.cable_excitation.wave_series`; None without
        a sea).
    end_disp : dict
        Prescribed end motion per end node
        (:func:`~stochcable.reference.cable_excitation.end_series`).
    t : ndarray
        Step times. [s]
    h : float
        Step. [s]
    tol : float
        Newton tolerance on max |residual|. [N]
    max_it : int
        Newton iterations per step before a ConvergenceError.
    every : int
        Element tensions are stored every this many steps.

    Returns
    -------
    positions (n_t, n, d), (tension_a, tension_b, element tensions), Newton iterations
    per step, largest final residual.
    """
    d, n, N = model.dim, model.n, model.N
    fr = model.free
    nt = t.size
    pos = np.empty((nt, n, d))
    ten_a = np.empty(nt)
    ten_b = np.empty(nt)
    ten_el = np.empty(((nt - 1) // every + 1, model.ne))
    iters = np.zeros(nt, dtype=int)
    X = xs.copy()
    V = np.zeros_like(X)
    A = np.zeros_like(X)
    pos[0] = X
    e, _, T, _ = model.elements(X)
    fd0, _, _ = model.drag(X, V, e, u_cur, u_cur_g, jacobian=False)
    fb0, _, _ = model.seabed(X, V)
    R0 = (model.internal_force(X, e, T) - model.f_gravity - fd0 - fb0).reshape(-1)
    # An end node resting on the seabed: the bed carries the load lumped on it, so the
    # end tension is the line's own end force, as in the statics (stochcable.line.statics).
    fgr = model.f_gravity.reshape(n, d)
    zbed_tol = 1e-9 * max(model.depth, 1.0)
    carry_a = fgr[0] if xs[0, -1] <= -model.depth + zbed_tol else np.zeros(d)
    carry_b = fgr[-1] if xs[-1, -1] <= -model.depth + zbed_tol else np.zeros(d)
    ten_a[0] = np.linalg.norm(R0[:d] + carry_a)
    ten_b[0] = np.linalg.norm(R0[N - d :] + carry_b)
    ten_el[0] = T
    c1, c2 = 4.0 / h**2, 2.0 / h
    M_band_f = model.M_band[:, fr]
    if model.transport is not None:  # G u̇ + K_c (x − x_s) (reference.cable_transport):
        # its constant Jacobian c2·G + K_c rides in the mass band, c1·(M + J/c1) = c1 M + J
        check_transport_speed(model.transport, T, model.mesh.name)
        M_band_f = M_band_f + model.transport.jacobian_band(c2, fr) / c1
    maxres = 0.0
    xs_flat = xs.reshape(-1)
    # initial acceleration: static start with zero excitation at t = 0 -> A = 0, except a
    # prescribed end acceleration (zero with the half-cosine ramp); keep A = 0.
    for k in range(1, nt):
        Xp, Vp, Ap = X.reshape(-1).copy(), V.reshape(-1).copy(), A.reshape(-1).copy()
        # prescribed ends at t_k
        Xn = xs_flat.copy()
        Vn = np.zeros(N)
        An = np.zeros(N)
        for node, (xe, ve, ae) in end_disp.items():
            sl = slice(node * d, node * d + d)
            Xn[sl] += xe[k]
            Vn[sl] = ve[k]
            An[sl] = ae[k]
        step = _Step(
            model,
            c1,
            c2,
            (Xp, Vp, Ap),
            (Xn, Vn, An),
            u_cur if u_wave is None else u_cur + u_wave[k],
            u_cur_g if u_wave_g is None else u_cur_g + u_wave_g[k],
            None if f_in is None else f_in[k],
            model.contact_blend(X),
        )
        # predictor (constant acceleration) for the free DOFs
        du = h * Vp[fr] + 0.25 * h * h * Ap[fr]
        rn, R, T, res_hist = _newton(step, du, M_band_f, tol, max_it)
        it = len(res_hist) - 1
        if rn > tol:
            raise ConvergenceError(
                f"time-domain Newton at step {k} (t = {t[k]:.6g} s)",
                it,
                rn,
                tol,
                hint=f"reduce dt (now {h:.4g} s) or check the excitation amplitude",
                partial={
                    "t": t[:k],
                    "positions": pos[:k],
                    "residuals": res_hist,
                    "worst_dof": int(np.argmax(np.abs(R[fr]))) + d,
                },
            )
        maxres = max(maxres, rn)
        iters[k] = it
        X, V, A = Xn.reshape(n, d).copy(), Vn.reshape(n, d).copy(), An.reshape(n, d).copy()
        pos[k] = X
        # support reactions: the residual rows of the prescribed end nodes
        ten_a[k] = np.linalg.norm(R[:d] + carry_a)
        ten_b[k] = np.linalg.norm(R[N - d :] + carry_b)
        if k % every == 0:
            ten_el[k // every] = T
    return pos, (ten_a, ten_b, ten_el), iters, maxres


class _Step:
    """One Newmark step from the previous state (Xp, Vp, Ap), flat: the prescribed end
    DOFs of (X, V, A) are set at t_k, the free ones from the increment ``du`` by
    :meth:`residual` (eqs. 4.2.7a,b), so (X, V, A) hold the last state evaluated."""

    def __init__(
        self,
        model: LineModel,
        c1: float,
        c2: float,
        previous: tuple[np.ndarray, np.ndarray, np.ndarray],
        state: tuple[np.ndarray, np.ndarray, np.ndarray],
        uf: np.ndarray,
        ug: np.ndarray,
        fi: np.ndarray | None,
        s_bed: np.ndarray,
    ) -> None:
        self.model, self.c1, self.c2 = model, c1, c2
        self.Xp, self.Vp, self.Ap = previous
        self.X, self.V, self.A = state
        self.uf, self.ug, self.fi, self.s_bed = uf, ug, fi, s_bed

    def residual(self, du: np.ndarray, jac: bool):
        """Residual of the step for the free increment ``du``: (max |R_free|, R, element
        tensions, (e, l, ea, drag element/node Jacobians, seabed stiffness, damping))."""
        model, c1, c2 = self.model, self.c1, self.c2
        Xn, Vn, An, Xp, Vp, Ap = self.X, self.V, self.A, self.Xp, self.Vp, self.Ap
        d, n, fr = model.dim, model.n, model.free
        Xn[fr] = Xp[fr] + du
        Vn[fr] = c2 * du - Vp[fr]
        An[fr] = c1 * du - 2.0 * c2 * Vp[fr] - Ap[fr]
        Xm = Xn.reshape(n, d)
        Vm = Vn.reshape(n, d)
        e, l, T, ea = model.elements(Xm)
        td = model.damping_tension(Vm, e)
        if td is not None:
            T = T + td  # the element's total axial force (as MoorDyn's T + T_d)
        fd, c_el, c_nd = model.drag(Xm, Vm, e, self.uf, self.ug, jacobian=jac)
        fb, kb, cb = model.seabed(Xm, Vm, self.s_bed)
        R = (model.M_sparse @ An) + (
            model.internal_force(Xm, e, T) - model.f_gravity - fd - fb
        ).reshape(-1)
        if self.fi is not None:
            R -= self.fi
        if model.transport is not None:
            R += model.transport.force(Xn, Vn, model.x_static.reshape(-1))
        rn = float(np.abs(R[fr]).max()) if model.N - 2 * d else 0.0
        return rn, R, T, (e, l, ea, c_el, c_nd, kb, cb)


def _newton(
    step: _Step, du: np.ndarray, M_band_f: np.ndarray, tol: float, max_it: int
) -> tuple[float, np.ndarray, np.ndarray, list[float]]:
    """Newton iterations on the step from the predictor ``du`` with a backtracking line
    search, at most ``max_it``.  Returns the final max |R_free| (above ``tol``: not
    converged), R, the element tensions and the max |R_free| of every iterate."""
    model, c1, c2 = step.model, step.c1, step.c2
    fr, u_b = model.free, model.u

    def norm2(R: np.ndarray) -> float:
        return float(np.dot(R[fr], R[fr]))

    rn, R, T, st = step.residual(du, True)
    res_hist = [rn]
    it = 0
    while rn > tol and it < max_it:
        e, l, ea, c_el, c_nd, kb, cb = st
        kel = model.stiffness_blocks(e, l, T, ea)
        if c_el is not None:
            kel = kel + c2 * c_el
        c_int = model.damping_blocks(e)
        if c_int is not None:
            kel = kel + c2 * c_int
        c_nd[:, -1, -1] += c2 * cb + kb
        ab = model.band_matrix(kel, c_nd)[:, fr] + c1 * M_band_f
        ddu = sla.solve_banded((u_b, u_b), ab, -R[fr], check_finite=False)
        # backtracking: the one-sided seabed and slack elements make the residual
        # nonsmooth; halve the correction until the residual decreases
        lam = 1.0
        r2 = norm2(R)
        for _ in range(_BACKTRACK):
            rn_new, R_new, T_new, st_new = step.residual(du + lam * ddu, True)
            if rn_new <= tol or norm2(R_new) < r2 or lam < 2.0 ** (1 - _BACKTRACK):
                break
            lam *= 0.5
        du = du + lam * ddu
        rn, R, T, st = rn_new, R_new, T_new, st_new
        res_hist.append(rn)
        it += 1
    return rn, R, T, res_hist
