"""The Newmark–Newton step of several lines on one free planar body
(:func:`stochcable.reference.cable_bodies.simulate_lines_on_body`, whose module notes
give the scheme): each line's band solved for its residual and the three unit body
motions, then one 3×3 body system with every line's reactions (the bordered band's
Schur complement summed over the lines).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy import linalg as sla

from stochcable.errors import ConvergenceError

__all__ = ["Leg", "integrate_lines_on_body", "link", "rot"]

_BACKTRACK = 12  # largest number of halvings in a Newton line search
_SUBSTEPS = 4  # a failed step is retried in up to 2**_SUBSTEPS substeps


@dataclass(frozen=True, eq=False)
class Leg:
    """One line's model, static start and excitation series."""

    name: str
    model: Any
    xs: np.ndarray
    u_cur: np.ndarray
    u_cur_g: np.ndarray
    u_wave: np.ndarray
    u_wave_g: np.ndarray
    f_in: np.ndarray
    r0: np.ndarray  # fairlead arm at the static pose (x, z)
    tol: float


def rot(theta: float, r: np.ndarray) -> np.ndarray:
    """R(θ)r in the x–z plane, pitch about +y (x' = x cos θ + z sin θ)."""
    c, s = math.cos(theta), math.sin(theta)
    return np.array([r[0] * c + r[1] * s, -r[0] * s + r[1] * c])


def link(r: np.ndarray) -> np.ndarray:
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


def _correction(legs, sts, auxs, ress, rq, c12, bmat, cdj) -> tuple[list, np.ndarray]:
    """The Newton correction (each line's free DOFs, body DOFs) of the coupled step:
    each line's band solved for its residual and the three unit body motions, then the
    3×3 body system with every line's reactions (module notes)."""
    c1, c2 = c12
    m_b, c_b, k_b, free_q = bmat
    kq = c1 * m_b + c2 * (c_b + cdj) + k_b
    bq = -rq
    parts = []
    for leg, st, aux, res in zip(legs, sts, auxs, ress):
        model = leg.model
        d, nn, fr, ub = model.dim, model.N, model.free, model.u
        ib = np.arange(nn - d, nn)
        ifr = np.arange(d, nn - d)
        e, ln, tt, ea, c_el, c_nd, kb, cb = st
        rr, g = aux
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
        kq = kq + g.T @ j_bb @ g
        kq[2, 2] -= float(rr @ res[ib])
        kq = kq + g.T @ j_bf @ yq[-ub:]
        bq = bq - g.T @ j_bf @ y0[-ub:]
        parts.append((y0, yq))
    ddq = np.zeros(3)
    ddq[free_q] = np.linalg.solve(kq[np.ix_(free_q, free_q)], bq[free_q])
    return [y0 + yq @ ddq for y0, yq in parts], ddq


def _line_residual(model, xf, vf_, af, uf, ug, fi, s_bed) -> tuple[np.ndarray, tuple]:
    """A line's Newmark residual at (x, v, a) and the state its Jacobian needs."""
    n, d = model.n, model.dim
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


def _interpolate(a, b, frac: float):
    """(1 − frac)·a + frac·b through nested tuples and lists of arrays."""
    if isinstance(a, (tuple, list)):
        return type(a)(_interpolate(x, y, frac) for x, y in zip(a, b))
    return (1.0 - frac) * a + frac * b


class _Stepper:
    """The Newmark–Newton step of the lines and the body (module notes)."""

    def __init__(self, legs, body_drag, bmat, max_it) -> None:
        self.legs, self.body_drag, self.bmat, self.max_it = legs, body_drag, bmat, max_it
        self.tol = min(leg.tol for leg in legs)
        self.fixed_q = np.setdiff1d(np.arange(3), bmat[3])
        self.x0 = [leg.xs.reshape(-1).copy() for leg in legs]
        self.ib = [np.arange(leg.model.N - leg.model.dim, leg.model.N) for leg in legs]
        self.r_start, f_static = [], np.zeros(3)
        for leg, x0, ib in zip(legs, self.x0, self.ib):
            zero = np.zeros(leg.model.N)
            r_st, _ = _line_residual(
                leg.model, x0, zero, zero, leg.u_cur, leg.u_cur_g, None,
                leg.model.contact_blend(leg.xs),
            )  # fmt: skip
            self.r_start.append(r_st)
            f_static = f_static - link(leg.r0).T @ r_st[ib]  # the line's static pull
        self.f_static = f_static
        self.fd0, _ = body_drag(np.zeros(3), np.zeros(3), np.zeros(2))

    def evaluate(self, dus, dq_, prev, load, c1, c2):
        """Residual norm, line residuals, body residual, states and kinematics."""
        q, qd, qdd, xx, vv, aa = prev
        legs_load, f_b, v_f = load
        m_b, c_b, k_b, _ = self.bmat
        qn = q + dq_
        qdn = c2 * dq_ - qd
        qddn = c1 * dq_ - 2.0 * c2 * qd - qdd
        fdg, cdj = self.body_drag(qn, qdn, v_f)
        rq = m_b @ qddn + c_b @ qdn + k_b @ qn - f_b - (fdg - self.fd0)
        ress, sts, auxs, kin = [], [], [], ([], [], [])
        norm = 0.0
        for j, leg in enumerate(self.legs):
            fr, ib, x0 = leg.model.free, self.ib[j], self.x0[j]
            uf, ug, fi, s_bed = legs_load[j]
            rr = rot(qn[2], leg.r0)
            g = link(rr)
            xn, vn, an = x0.copy(), np.zeros_like(x0), np.zeros_like(x0)
            xn[fr] = xx[j][fr] + dus[j]
            vn[fr] = c2 * dus[j] - vv[j][fr]
            an[fr] = c1 * dus[j] - 2.0 * c2 * vv[j][fr] - aa[j][fr]
            xn[ib] = leg.xs.reshape(-1)[ib] + qn[:2] + rr - leg.r0
            vn[ib] = g @ qdn
            an[ib] = g @ qddn - qdn[2] ** 2 * rr
            res, st = _line_residual(leg.model, xn, vn, an, uf, ug, fi, s_bed)
            rq = rq + g.T @ res[ib]
            norm = max(norm, float(np.abs(res[fr]).max()))
            ress.append(res)
            sts.append(st)
            auxs.append((rr, g))
            for lst, v in zip(kin, (xn, vn, an)):
                lst.append(v)
        rq = rq + self.f_static
        rq[self.fixed_q] = 0.0
        norm = max(norm, float(np.abs(rq).max()))
        return norm, ress, rq, (sts, auxs, cdj), (qn, qdn, qddn) + kin

    def _sq(self, ress, rq) -> float:
        s = 0.0
        for leg, res in zip(self.legs, ress):
            s += float(res[leg.model.free] @ res[leg.model.free])
        return s + float(rq @ rq)

    def step(self, prev, load, hh):
        """One Newmark step of length hh: (max residual, iterations, residuals, state)."""
        c1, c2 = 4.0 / hh**2, 2.0 / hh
        _, qd, qdd, xx, vv, aa = prev
        dus = [
            hh * v[leg.model.free] + 0.25 * hh * hh * a[leg.model.free]
            for leg, v, a in zip(self.legs, vv, aa)
        ]
        dq = hh * qd + 0.25 * hh * hh * qdd
        legs_load = [
            ld + (leg.model.contact_blend(x.reshape(leg.model.n, leg.model.dim)),)
            for leg, ld, x in zip(self.legs, load[0], xx)
        ]
        load = (legs_load,) + tuple(load[1:])
        rn, ress, rq, jac, state = self.evaluate(dus, dq, prev, load, c1, c2)
        it = 0
        while rn > self.tol and it < self.max_it:
            sts, auxs, cdj = jac
            ddus, ddq = _correction(self.legs, sts, auxs, ress, rq, (c1, c2), self.bmat, cdj)
            lam = 1.0
            r2 = self._sq(ress, rq)
            for _ in range(_BACKTRACK):
                trial = [du + lam * ddu for du, ddu in zip(dus, ddus)]
                out = self.evaluate(trial, dq + lam * ddq, prev, load, c1, c2)
                n2 = self._sq(out[1], out[2])
                if out[0] <= self.tol or n2 < r2 or lam < 2.0 ** (1 - _BACKTRACK):
                    break
                lam *= 0.5
            dus, dq = [du + lam * ddu for du, ddu in zip(dus, ddus)], dq + lam * ddq
            rn, ress, rq, jac, state = out
            it += 1
        return rn, it, ress, state


def integrate_lines_on_body(legs, f_body, v_fluid, body_drag, bmat, t, h, max_it) -> tuple:
    """Newmark average acceleration of the lines and the body (module notes); a step
    whose Newton iteration fails is retried as 2, 4, … :data:`_SUBSTEPS` substeps
    with the excitation interpolated linearly (a slack line snapping taut)."""
    stp = _Stepper(legs, body_drag, bmat, max_it)
    nt, nl = t.size, len(legs)
    ten_a, ten_b = np.empty((nt, nl)), np.empty((nt, nl))
    motion = np.zeros((nt, 3))
    iters = np.zeros(nt, dtype=int)
    carry = []
    for j, leg in enumerate(legs):
        model = leg.model
        fgr = model.f_gravity.reshape(model.n, model.dim)
        on_bed = leg.xs[0, -1] <= -model.depth + 1e-9 * max(model.depth, 1.0)
        carry.append(fgr[0] if on_bed else 0.0)
        ten_a[0, j] = np.linalg.norm(stp.r_start[j][: model.dim] + carry[j])
        ten_b[0, j] = np.linalg.norm(stp.r_start[j][stp.ib[j]])
    state = (np.zeros(3), np.zeros(3), np.zeros(3)) + (
        [x.copy() for x in stp.x0],
        [np.zeros_like(x) for x in stp.x0],
        [np.zeros_like(x) for x in stp.x0],
    )

    def load_at(k: int) -> tuple:
        lines = [
            (leg.u_cur + leg.u_wave[k], leg.u_cur_g + leg.u_wave_g[k], leg.f_in[k]) for leg in legs
        ]
        return (lines, f_body[k], v_fluid[k])

    for kstep in range(1, nt):
        a_load, b_load = load_at(kstep - 1), load_at(kstep)
        for level in range(_SUBSTEPS + 1):
            m = 2**level
            sub, total, ok = state, 0, True
            for j in range(1, m + 1):
                rn, it, ress, out = stp.step(sub, _interpolate(a_load, b_load, j / m), h / m)
                total += it
                if rn > stp.tol:
                    ok = False
                    break
                sub = out
            if ok:
                break
        if not ok:
            raise ConvergenceError(
                f"lines-on-body time-domain Newton at step {kstep} (t = {t[kstep]:.6g} s)",
                total,
                rn,
                stp.tol,
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
        for j, leg in enumerate(legs):
            d = leg.model.dim
            ten_a[kstep, j] = np.linalg.norm(ress[j][:d] + carry[j])
            ten_b[kstep, j] = np.linalg.norm(ress[j][stp.ib[j]])
    return ten_a, ten_b, motion, iters
