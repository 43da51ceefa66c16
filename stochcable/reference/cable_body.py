"""Nonlinear time-domain reference of a line whose end_b is on a free rigid body: the
line of :mod:`stochcable.reference.cable` and a planar body (surge, heave, pitch)
integrated together, the yardstick of the frequency domain's lines on bodies and of
their residuals (:mod:`stochcable.dynamics.residuals.body_residual`).

The body is the frequency domain's (:class:`stochcable.bodies.rigid.RigidBody` at the
static pose of :func:`stochcable.statics.solve_statics`, Tuah (1982), eq. 3.2.c.20):
rigid-body mass and inertia about the reference point, constant added mass and
radiation damping (a frequency-dependent table is refused: no Cummins convolution
here), the hydrostatic stiffness and the extra stiffness and damping, and the wave
excitation table synthesized from the same sea coefficients as the line's waves.  What
is nonlinear besides the line: the body's quadratic drag ½ρ·CdA·|u|u per direction on
the relative velocity u at the drag point (the frequency domain linearizes it), the
finite pitch of the fairlead and drag-point arms (R(θ)r, the frequency domain's
T(r)ξ plus the attachment geometric stiffness to first order) and the inertia of
the end node's share of the line moving with the fairlead.  Linear, as in the
frequency domain: the inertia (no centripetal terms of the CoG offset), the
hydrostatics, and the excitation and wave velocity at the static pose.

Integration: the line's Newmark average acceleration (:mod:`~stochcable.reference.cable_newmark`)
with the body's three DOFs in the same Newton iteration (monolithic): the end node
follows the body, X_b = X_b,s + ξ_t + R(θ)r₀ − r₀, and the body carries the line's
support reaction R_b at the fairlead; the Newton correction solves the line's band
for the residual and for the three unit body motions, then the 3×3 body system
(bordered band).  The body's static balance (buoyancy, weight, wind, line pull) is
the static start: its residual is written about the start, with the line's static
reaction R_b,0 and the static drag (current) subtracted.

Known limit: with the one-sided penalty bed a light slack line whose nodes lift off
and land gains energy in the non-dissipative scheme (the disc buoy's 20-element leg
at m0 = 0.1 ft²: element tensions above 10⁴ lbf on a 10² lbf mean before Newton
fails); ``seabed="linear"`` (the bed frozen at its static contact, the frequency
domain's kind) or axial ``internal_damping`` keeps such records bounded
(docs/accuracy/bodies.md).

References
----------
Tuah, H. (1982), Cable dynamics in an ocean environment, PhD thesis, Oregon State University.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy import linalg as sla

from stochcable import validation as _v
from stochcable.bodies.from_scene import scene_rigid_bodies
from stochcable.bodies.rigid import body_excitation
from stochcable.errors import ConvergenceError, InputError
from stochcable.line.mesh import mesh_line
from stochcable.reference.cable import _select_line, _static_start, _time_step
from stochcable.reference.cable_excitation import (
    band_limited,
    half_cosine,
    realization_grid,
    upsample,
    wave_series,
)
from stochcable.reference.cable_model import axes, statics_guess
from stochcable.scene.model import Scene, load_scene
from stochcable.sea.kinematics import wave_kinematics, wavenumber
from stochcable.statics import solve_statics

__all__ = ["BodyLineHistory", "simulate_line_on_body"]

_BACKTRACK = 12  # largest number of halvings in a Newton line search
_SUBSTEPS = 4  # a failed step is retried in up to 2**_SUBSTEPS substeps


@dataclass(frozen=True, eq=False)
class BodyLineHistory:
    """Nonlinear time-domain response of a line on a free body.

    Attributes
    ----------
    line, body : str
        The line and the body at its end_b.
    t : ndarray, shape (n_t,)
        Time, 0 at the static start. [s]
    tension_a, tension_b : ndarray, shape (n_t,)
        End tensions: the support reactions (as the frequency domain's). [N]
    motion : ndarray, shape (n_t, 3)
        Body motion (surge, heave, pitch) from its static pose. [m, m, rad]
    iterations : ndarray of int, shape (n_t,)
        Newton iterations per step. [-]
    dt, ramp : float
        Step and half-cosine ramp (excluded from the statistics). [s]
    """

    line: str
    body: str
    t: np.ndarray
    tension_a: np.ndarray
    tension_b: np.ndarray
    motion: np.ndarray
    iterations: np.ndarray
    dt: float
    ramp: float
    excitation: tuple = ()

    def linear(self, omega: np.ndarray, transfer: np.ndarray) -> np.ndarray:
        """The linear response of transfer function ``transfer`` (per unit wave
        amplitude on ``omega``, e.g. a frequency-domain result's end tension) to this
        record's sea, ramp and steps: the paired linear record of the same waves.

        Parameters
        ----------
        omega : ndarray, shape (n_w,)
            [rad/s]
        transfer : ndarray, complex, shape (n_w,)
            Interpolated (real and imaginary parts) on the realization's grid, zero
            outside ``omega``. [unit/m]

        Returns
        -------
        ndarray, shape (n_t,)
        """
        w_grid, x_sea, n_samples, k_up, sl, r = self.excitation
        w = np.asarray(omega, dtype=float)
        hh = np.asarray(transfer)
        inside = (w_grid >= w[0]) & (w_grid <= w[-1])
        h_grid = (np.interp(w_grid, w, hh.real) + 1j * np.interp(w_grid, w, hh.imag)) * inside
        return upsample(h_grid * x_sea, n_samples, k_up)[sl] * r

    def std(self, start: float | None = None) -> dict[str, float]:
        """σ of the end tensions and body DOFs after ``start`` (default the ramp). [N, m, rad]"""
        keep = self.t >= (self.ramp if start is None else start)
        out = {
            "end_a": float(np.std(self.tension_a[keep])),
            "end_b": float(np.std(self.tension_b[keep])),
        }
        for i, dof in enumerate(("surge", "heave", "pitch")):
            out[dof] = float(np.std(self.motion[keep, i]))
        return out


def _rot(theta: float, r: np.ndarray) -> np.ndarray:
    """R(θ)r in the x–z plane, pitch about +y (x' = x cos θ + z sin θ)."""
    c, s = math.cos(theta), math.sin(theta)
    return np.array([r[0] * c + r[1] * s, -r[0] * s + r[1] * c])


def _link(r: np.ndarray) -> np.ndarray:
    """(2, 3) map of (surge, heave, pitch) rates to the velocity of arm ``r`` (x, z)."""
    return np.array([[1.0, 0.0, r[1]], [0.0, 1.0, -r[0]]])


def _band_entries(band: np.ndarray, u: int, rows: np.ndarray, cols: np.ndarray) -> np.ndarray:
    """Dense block of a LAPACK band matrix (2u+1, N) at ``rows`` × ``cols``."""
    out = np.zeros((rows.size, cols.size))
    for a, i in enumerate(rows):
        for b, j in enumerate(cols):
            if abs(i - j) <= u:
                out[a, b] = band[u + i - j, j]
    return out


def simulate_line_on_body(
    scene: Scene | dict[str, Any] | str,
    line_name: str | None = None,
    *,
    duration: float,
    seed: int,
    dt: float | None = None,
    ramp: float | None = None,
    band: tuple[float, float] | None = None,
    method: str = "dsa",
    tolerance: float = 1e-7,
    max_iterations: int = 30,
    linear_drag: tuple[Any, Any, Any] | None = None,
    seabed: str = "one_sided",
    internal_damping: float = 0.0,
) -> BodyLineHistory:
    """Nonlinear time-domain response of a line with end_b on a free planar body.

    Parameters
    ----------
    scene : Scene, mapping or JSON
        A planar scene: the line's end_a fixed (no end motion), its end_b attached to
        a free body (the body's only line), a long-crested sea.
    line_name : str, optional
        The line (default the first). [-]
    duration : float
        Length of the sea realization and of the record. [s]
    seed : int
        Seed of the sea realization (:func:`stochcable.sea.realization.simulate_sea`). [-]
    dt : float, optional
        Integration step (default: the period error (ωΔt)²/12 ≤ 0.5 % at the highest
        excitation frequency). [s]
    ramp : float, optional
        Half-cosine ramp of the excitation (default 3 peak periods). [s]
    band : (float, float), optional
        Wave components kept (the frequency domain's ω range reproduces its
        excitation). [rad/s]
    method : {"dsa", "nsa"}
        Spectral amplitude method of the realization. [-]
    tolerance : float
        Newton tolerance on max |residual| relative to the largest static force. [-]
    max_iterations : int
        Newton iterations per step before a ConvergenceError. [-]
    linear_drag : (array_like, array_like, array_like), optional
        A controlled experiment: the line's drag linear with (B_n, B_t) per element
        (:func:`stochcable.reference.cable.simulate_line_timedomain`'s ``drag="linear"``)
        and the body's with the linear coefficient per direction (x, y, z) at the drag
        point (a frequency-domain result's ``linearization.b_normal``, ``b_axial`` and
        the body's ``drag_coefficient``): what is left nonlinear is the geometry and
        the seabed. [N·s/m², N·s/m², N·s/m]
    seabed : {"one_sided", "linear"}
        The one-sided penalty bed, or its tangent at the static start (the frequency
        domain's kind of bed; :meth:`stochcable.reference.cable_model.LineModel.set_variant`). [-]
    internal_damping : float
        Axial internal damping BA of every element, T_d = BA·(dl/dt)/l0
        (:func:`stochcable.reference.cable.simulate_line_timedomain`'s); 0: none. [N·s]

    Returns
    -------
    BodyLineHistory

    Raises
    ------
    InputError
        A scene outside the scope above, or a body with frequency-dependent added mass
        or radiation damping over the band.
    ConvergenceError
        Newton did not converge in a step.
    """
    sc = load_scene(scene)
    line = _select_line(sc, line_name)
    if not sc.is_planar or sc.sea is None or sc.sea.spreading is not None:
        raise InputError("scene", "-", "-", "needs a planar scene with a long-crested sea")
    att = line.end_b.attach
    if att is None or line.end_a.attach is not None or line.end_a.motion is not None:
        raise InputError(
            "line", line.name, "-", "needs end_b on a free body and end_a fixed without motion"
        )
    if any(ln.name != line.name and att.body in (_bodies_of(ln)) for ln in sc.lines):
        raise InputError("body", att.body, "-", "must carry only this line")
    tolerance = _v.positive("tolerance", tolerance, "-")
    env = sc.environment
    statics = solve_statics(sc)
    bst = statics.bodies[att.body]
    if bst.prescribed:
        raise InputError("body", att.body, "-", "must be free (not prescribed)")
    body = dataclasses.replace(
        scene_rigid_bodies(sc)[att.body], position=np.asarray(bst.position, float)
    )
    if not np.any(body.hydrostatic_stiffness):
        raise InputError("body", body.name, "-", "needs a hydrostatic_stiffness matrix")

    # ---- excitation: the line's waves, the body's excitation and drag-point velocity
    grid = realization_grid(sc, None, duration, dt, seed, method)
    ends, seas = band_limited(grid, {}, band)
    _, w_peak, k_up, h = _time_step(grid, seas, ends, dt)
    w_lo = 0.0 if band is None else band[0]
    w_hi = float(grid.omega[-1]) if band is None else band[1]
    inb = (grid.omega >= w_lo) & (grid.omega <= w_hi) & (grid.omega > 0)
    am, bm = body.added_mass_at(grid.omega[inb]), body.radiation_damping_at(grid.omega[inb])
    for nm, a in (("added_mass", am), ("radiation_damping", bm)):
        if np.abs(a - a[0]).max() > 1e-9 * max(np.abs(a).max(), 1e-30):
            raise InputError(
                f"bodies[{body.name}].{nm}", "frequency-dependent", "-",
                "must be constant over the band (no radiation convolution here)",
            )  # fmt: skip
    n_steps = int(round(grid.duration / h))
    t = h * np.arange(n_steps + 1)
    if ramp is None:
        ramp = 3.0 * 2.0 * math.pi / w_peak
    ramp = _v.nonnegative("ramp", ramp, "s")
    r = half_cosine(t, ramp)
    sl = np.arange(n_steps + 1) % (k_up * grid.n_samples)
    mesh = mesh_line(line, env.rho, env.g)
    ax = axes(2)
    x3 = statics_guess(sc, line, mesh, statics)
    internal_damping = _v.nonnegative("internal_damping", internal_damping, "N·s")
    model, xs, u_cur, u_cur_g, tol_abs = _static_start(sc, mesh, x3, 2, tolerance, internal_damping)
    b_lin = None
    if seabed not in ("one_sided", "linear"):
        raise InputError("seabed", seabed, "-", "must be 'one_sided' or 'linear'")
    if linear_drag is not None:
        model.set_variant(drag="linear", linear_drag=linear_drag[:2], seabed=seabed)
        b_lin = np.asarray(linear_drag[2], dtype=float)[[0, 2]]
    else:
        model.set_variant(seabed=seabed)
    ((heading, x_sea),) = seas
    u_wave, u_wave_g, f_in = wave_series(
        model, xs @ ax.T, grid.omega, x_sea, heading, env, ax, grid.n_samples, k_up, sl, r[0]
    )
    k = wavenumber(np.maximum(grid.omega, 1e-9), env.depth, env.g)
    f_exc = body_excitation(body, grid.omega, heading, wavenumber=k)  # (n_w, 3)
    dp3 = body.position + body.drag_point
    dp3[2] = max(dp3[2], -env.depth)
    kin = wave_kinematics(grid.omega, dp3[None], heading, env.depth, env.g)
    v_dp = kin.velocity[0][[0, 2]]  # (2, n_w)
    coeff = np.concatenate([f_exc.T, v_dp], axis=0) * x_sea
    series = np.moveaxis(upsample(coeff, grid.n_samples, k_up)[..., sl] * r[0], -1, 0)
    f_body, v_fluid = series[:, :3], series[:, 3:]
    u_body_cur = np.asarray(env.current_velocity(np.array([min(dp3[2], 0.0)]))[0])[[0, 2]]

    # ---- the body's matrices (perturbation about the static pose)
    m_b = body.mass_matrix() + am[0]
    c_b = bm[0] + body.extra_damping
    k_b = body.hydrostatic_stiffness + body.extra_stiffness
    cda = np.asarray(body.drag_area, float)[[0, 2]]
    half_rho_cda = 0.5 * env.rho * cda
    r0 = xs[-1] - body.position[[0, 2]]  # fairlead arm at the static pose
    p0 = np.asarray(body.drag_point, float)[[0, 2]]
    free_q = np.asarray(body.free_index, dtype=int)

    def body_drag(q: np.ndarray, qd: np.ndarray, vf: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Generalized drag force and its Jacobian on q̇."""
        g = _link(_rot(q[2], p0))
        u = u_body_cur + vf - g @ qd
        if b_lin is not None:
            return g.T @ (b_lin * u), g.T @ np.diag(b_lin) @ g
        f = half_rho_cda * np.abs(u) * u
        return g.T @ f, g.T @ np.diag(2.0 * half_rho_cda * np.abs(u)) @ g

    excitation = (grid.omega, x_sea, grid.n_samples, k_up, sl, r[0])
    return _integrate(
        model, xs, u_cur, u_cur_g, u_wave, u_wave_g, f_in, f_body, v_fluid, body_drag,
        (m_b, c_b, k_b, r0, free_q), t, h, tol_abs, max_iterations, line.name, body.name, ramp,
        excitation,
    )  # fmt: skip


def _bodies_of(ln: Any) -> tuple[str, ...]:
    return tuple(e.attach.body for e in (ln.end_a, ln.end_b) if e.attach is not None)


def _correction(model, st, aux, res, rq, c12, bmat) -> tuple[np.ndarray, np.ndarray]:
    """The Newton correction (line free DOFs, body DOFs) of the coupled step: the line's
    band solved for the residual and the three unit body motions, then the 3×3 body
    system (bordered band; module notes)."""
    c1, c2 = c12
    m_b, c_b, k_b, free_q = bmat
    d, nn, fr, ub = model.dim, model.N, model.free, model.u
    ib = np.arange(nn - d, nn)
    ifr = np.arange(d, nn - d)
    e, ln, tt, ea, c_el, c_nd, kb, cb = st
    rr, g, cdj = aux[6], aux[7], aux[8]
    kel = model.stiffness_blocks(e, ln, tt, ea)
    if c_el is not None:
        kel = kel + c2 * c_el
    c_int = model.damping_blocks(e)
    if c_int is not None:
        kel = kel + c2 * c_int
    c_nd = c2 * c_nd
    c_nd[:, -1, -1] += c2 * cb + kb
    full = model.band_matrix(kel, c_nd) + c1 * model.M_band
    j_fb = _band_entries(full, ub, ifr[-ub:], ib)
    j_bf = _band_entries(full, ub, ib, ifr[-ub:])
    j_bb = _band_entries(full, ub, ib, ib)
    rhs = np.zeros((ifr.size, 4))
    rhs[:, 0] = -res[fr]
    rhs[-ub:, 1:] = -j_fb @ g
    sol = sla.solve_banded((ub, ub), full[:, fr], rhs, check_finite=False)
    y0, yq = sol[:, 0], sol[:, 1:]
    kq = c1 * m_b + c2 * (c_b + cdj) + k_b + g.T @ j_bb @ g
    kq[2, 2] -= float(rr @ res[ib])
    kq = kq + g.T @ j_bf @ yq[-ub:]
    bq = -rq - g.T @ j_bf @ y0[-ub:]
    ddq = np.zeros(3)
    ddq[free_q] = np.linalg.solve(kq[np.ix_(free_q, free_q)], bq[free_q])
    ddu = y0 + yq @ ddq
    return ddu, ddq


def _integrate(
    model, xs, u_cur, u_cur_g, u_wave, u_wave_g, f_in, f_body, v_fluid, body_drag, bmat,
    t, h, tol, max_it, line_name, body_name, ramp, excitation,
) -> BodyLineHistory:  # fmt: skip
    """Newmark average acceleration of the line and the body (module notes); a step
    whose Newton iteration fails is retried as 2, 4, … :data:`_SUBSTEPS` substeps
    with the excitation interpolated linearly (a slack line snapping taut)."""
    m_b, c_b, k_b, r0, free_q = bmat
    d, n, nn = model.dim, model.n, model.N
    fr = model.free
    ib = np.arange(nn - d, nn)
    nt = t.size
    ten_a, ten_b = np.empty(nt), np.empty(nt)
    motion = np.zeros((nt, 3))
    iters = np.zeros(nt, dtype=int)
    xs_flat = xs.reshape(-1)
    fgr = model.f_gravity.reshape(n, d)
    carry_a = fgr[0] if xs[0, -1] <= -model.depth + 1e-9 * max(model.depth, 1.0) else 0.0
    fixed_q = np.setdiff1d(np.arange(3), free_q)

    def line_residual(xf, vf_, af, uf, ug, fi, s_bed):
        xm, vm = xf.reshape(n, d), vf_.reshape(n, d)
        e, ln, tt, ea = model.elements(xm)
        td = model.damping_tension(vm, e)
        if td is not None:
            tt = tt + td  # the element's total axial force
        fd, c_el, c_nd = model.drag(xm, vm, e, uf, ug, jacobian=True)
        fb, kb, cb = model.seabed(xm, vm, s_bed)
        res = model.M_sparse @ af + (
            model.internal_force(xm, e, tt) - model.f_gravity - fd - fb
        ).reshape(-1)
        if fi is not None:
            res = res - fi
        return res, (e, ln, tt, ea, c_el, c_nd, kb, cb)

    x0 = xs_flat.copy()
    zero = np.zeros(nn)
    r_start, _ = line_residual(x0, zero, zero, u_cur, u_cur_g, None, model.contact_blend(xs))
    rb0 = r_start[ib].copy()
    f_static = -_link(r0).T @ rb0  # the line's static pull on the body
    fd0, _ = body_drag(np.zeros(3), np.zeros(3), np.zeros(2))

    def evaluate(du_, dq_, prev, load, c1, c2):
        q, qd, qdd, X, V, A = prev
        uf, ug, fi, f_b, v_f, s_bed = load
        qn = q + dq_
        qdn = c2 * dq_ - qd
        qddn = c1 * dq_ - 2.0 * c2 * qd - qdd
        rr = _rot(qn[2], r0)
        g = _link(rr)
        xn, vn, an = x0.copy(), zero.copy(), zero.copy()
        xn[fr] = X[fr] + du_
        vn[fr] = c2 * du_ - V[fr]
        an[fr] = c1 * du_ - 2.0 * c2 * V[fr] - A[fr]
        xn[ib] = xs_flat[ib] + qn[:2] + rr - r0
        vn[ib] = g @ qdn
        an[ib] = g @ qddn - qdn[2] ** 2 * rr
        res, st = line_residual(xn, vn, an, uf, ug, fi, s_bed)
        fdg, cdj = body_drag(qn, qdn, v_f)
        rq = m_b @ qddn + c_b @ qdn + k_b @ qn - f_b - (fdg - fd0)
        rq = rq + g.T @ res[ib] + f_static
        rq[fixed_q] = 0.0
        norm = max(float(np.abs(res[fr]).max()), float(np.abs(rq).max()))
        return norm, res, rq, st, (qn, qdn, qddn, xn, vn, an, rr, g, cdj)

    def step(prev, load, hh):
        """One Newmark step of length hh: (max residual, iterations, residual, state)."""
        c1, c2 = 4.0 / hh**2, 2.0 / hh
        _, qd, qdd, X, V, A = prev
        du = hh * V[fr] + 0.25 * hh * hh * A[fr]
        dq = hh * qd + 0.25 * hh * hh * qdd
        load = load + (model.contact_blend(X.reshape(n, d)),)
        rn, res, rq, st, aux = evaluate(du, dq, prev, load, c1, c2)
        it = 0
        while rn > tol and it < max_it:
            ddu, ddq = _correction(model, st, aux, res, rq, (c1, c2), (m_b, c_b, k_b, free_q))
            lam = 1.0
            r2 = float(res[fr] @ res[fr] + rq @ rq)
            for _ in range(_BACKTRACK):
                out = evaluate(du + lam * ddu, dq + lam * ddq, prev, load, c1, c2)
                n2 = float(out[1][fr] @ out[1][fr] + out[2] @ out[2])
                if out[0] <= tol or n2 < r2 or lam < 2.0 ** (1 - _BACKTRACK):
                    break
                lam *= 0.5
            du, dq = du + lam * ddu, dq + lam * ddq
            rn, res, rq, st, aux = out
            it += 1
        return rn, it, res, aux

    ten_a[0] = np.linalg.norm(r_start[:d] + carry_a)
    ten_b[0] = np.linalg.norm(rb0)
    state = (np.zeros(3), np.zeros(3), np.zeros(3), x0.copy(), zero.copy(), zero.copy())

    def load_at(k: int) -> tuple:
        return (
            u_cur + u_wave[k], u_cur_g + u_wave_g[k], f_in[k], f_body[k], v_fluid[k]
        )  # fmt: skip

    for kstep in range(1, nt):
        a_load, b_load = load_at(kstep - 1), load_at(kstep)
        for level in range(_SUBSTEPS + 1):
            m = 2**level
            sub, total, ok = state, 0, True
            for j in range(1, m + 1):
                frac = j / m
                ld = tuple((1.0 - frac) * a + frac * b for a, b in zip(a_load, b_load))
                rn, it, res, aux = step(sub, ld, h / m)
                total += it
                if rn > tol:
                    ok = False
                    break
                sub = aux[:6]
            if ok:
                break
        if not ok:
            raise ConvergenceError(
                f"line-on-body time-domain Newton at step {kstep} (t = {t[kstep]:.6g} s)",
                total,
                rn,
                tol,
                hint=f"reduce dt (now {h:.4g} s, {2**_SUBSTEPS} substeps tried)",
                partial={
                    "t": t[:kstep],
                    "motion": motion[:kstep],
                    "tension_a": ten_a[:kstep],
                    "tension_b": ten_b[:kstep],
                },
            )
        state = sub
        iters[kstep] = total
        motion[kstep] = state[0]
        ten_a[kstep] = np.linalg.norm(res[:d] + carry_a)
        ten_b[kstep] = np.linalg.norm(res[ib])
    return BodyLineHistory(
        line_name, body_name, t, ten_a, ten_b, motion, iters, h, ramp, excitation
    )
