"""The start of the FE statics: the exact equilibrium of the lumped chain without drag.

A two-unknown shooting on (H, V_0) (:func:`chain_guess`), with seabed contact from
end_a, solved by damped Newton from the continuous elastic catenary
(:func:`stochcable.line.catenary.catenary_solve_unchecked`) or by nested bracketing; a
parabola (:func:`initial_guess`) where it does not apply.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from stochcable.errors import ConvergenceError, InputError
from stochcable.line.catenary import catenary_solve_unchecked
from stochcable.line.equilibrium import LocalFrame, StaticsModel
from stochcable.line.mesh import LineMesh
from stochcable.scene.model import Environment

__all__ = ["initial_guess", "chain_guess", "chain_shots", "chain_newton", "chain_closure"]

_EPS = np.finfo(float).eps


def straight(a: np.ndarray, b: np.ndarray, frac: np.ndarray) -> np.ndarray:
    return a + frac[:, None] * (b - a)


def initial_guess(
    mesh: LineMesh, env: Environment, frame: LocalFrame, model: StaticsModel
) -> np.ndarray:
    """A hanging (parabolic) or straight initial shape in the local frame, (n, dim)."""
    a = frame.to_local(mesh.end_a[None, :])[0]
    b = frame.to_local(mesh.end_b[None, :])[0]
    frac = mesh.s0 / mesh.length
    chord = float(np.linalg.norm(b - a))
    L = mesh.length
    if L <= chord * (1.0 + 1e-9):
        return straight(a, b, frac)
    guess = chain_guess(mesh, env, frame, model, a, b)
    if guess is not None:
        return guess
    zi = frame.dim - 1
    sign = 1.0 if float(np.sum(mesh.weight * mesh.l0)) >= 0.0 else -1.0
    xi = np.linspace(0.0, 1.0, 401)
    base = straight(a, b, xi)
    horizontal = abs(b[0] - a[0]) > 1e-3 * chord
    bulge_axis = zi if horizontal else 0

    def shape(delta: float) -> np.ndarray:
        P = base.copy()
        P[:, bulge_axis] -= (sign if horizontal else -1.0) * 4.0 * delta * xi * (1 - xi)
        return P

    def arclen(P: np.ndarray) -> float:
        return float(np.sum(np.linalg.norm(np.diff(P, axis=0), axis=1)))

    lo, hi = 0.0, L
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        if arclen(shape(mid)) < L:
            lo = mid
        else:
            hi = mid
    P = shape(0.5 * (lo + hi))
    cum = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(P, axis=0), axis=1))])
    cum *= L / cum[-1]
    X = np.column_stack([np.interp(mesh.s0, cum, P[:, k]) for k in range(frame.dim)])
    X[:, zi] = np.maximum(X[:, zi], -env.depth)
    X[0], X[-1] = a, b
    return X


def chain_shots(
    mesh: LineMesh, model: StaticsModel, a: np.ndarray, zi: int, on_bed: bool, kb: np.ndarray
) -> tuple[Any, Any]:
    """The shots of :func:`chain_guess`: ``shoot(H, V0, P) -> (x, z)`` the node
    coordinates of the lumped chain from end ``a`` with horizontal force H, first
    element vertical force V0 and node loads P; ``shoot_ends(H, V0, P)`` the end node
    (x[-1], z[-1]) of several shots at once, (n, 2), the same numbers."""
    l0, ea = mesh.l0, mesh.ea
    zbed = model.zbed
    memo: dict[str, Any] = {"P": None}
    element_index = np.arange(mesh.n_elements)

    def shoot(H: float, V0: float, P: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        if memo["P"] is not P:  # the load sums of P, once per P (same numbers)
            memo["P"], memo["cum"] = P, np.concatenate([[0.0], np.cumsum(P[1:-1])])
        V = V0 + memo["cum"]  # element k
        if on_bed:
            pos = np.flatnonzero(V > 0.0)
            k_star = int(pos[0]) if pos.size else V.size
            Ve = np.where(element_index < k_star, 0.0, V)
            # contact force of the grounded nodes 1..k_star (the last one carries the
            # part of its load not taken by the first suspended element)
            contact = P.copy()
            if k_star < V.size:
                contact[k_star] = P[k_star] - V[k_star]
            pen = np.maximum(contact, 0.0) / kb
        else:
            k_star, Ve, pen = 0, V, np.zeros(mesh.n_nodes)
        T = np.sqrt(H * H + Ve * Ve)
        c = l0 * (1.0 + T / ea)
        x = a[0] + np.concatenate([[0.0], np.cumsum(c * H / T)])
        dz = c * Ve / T
        z = np.empty(mesh.n_nodes)
        z[0] = a[zi]
        z[1 : k_star + 1] = zbed - pen[1 : k_star + 1]
        if k_star < V.size:
            z[k_star + 1 :] = z[k_star] + np.cumsum(dz[k_star:])
        return x, z

    def shoot_ends(H: np.ndarray, V0: np.ndarray, P: np.ndarray) -> np.ndarray:
        """The end node (x[-1], z[-1]) of :func:`shoot` for several (H, V0) at once,
        (n, 2): the same operations row by row (real +, ×, /, √ and running sums, exact
        whatever the batch), so the same bits as ``shoot``'s last node."""
        if memo["P"] is not P:
            memo["P"], memo["cum"] = P, np.concatenate([[0.0], np.cumsum(P[1:-1])])
        V = V0[:, None] + memo["cum"]  # (n, n_el)
        n_el = V.shape[1]
        zlast = np.full(V0.size, a[zi])
        if on_bed:
            lifted = V > 0.0
            k_star = np.where(lifted.any(axis=1), np.argmax(lifted, axis=1), n_el)
            Ve = np.where(element_index[None, :] < k_star[:, None], 0.0, V)
            for i, k in enumerate(k_star.tolist()):
                if k > 0:  # the node where the suspended part starts, on the bed
                    contact = P[k] - V[i, k] if k < n_el else P[k]
                    zlast[i] = zbed - max(contact, 0.0) / kb[k]
        else:
            k_star, Ve = np.zeros(V0.size, dtype=int), V
        Hc = H[:, None]
        T = np.sqrt(Hc * Hc + Ve * Ve)
        c = l0 * (1.0 + T / ea)
        out = np.empty((V0.size, 2))
        out[:, 0] = a[0] + np.cumsum(c * Hc / T, axis=1)[:, -1]
        # z: the running sum from the first suspended element (zeros before it add
        # nothing: 0 + 0 + … + dz_k = dz_k exactly)
        dz = np.where(element_index[None, :] >= k_star[:, None], c * Ve / T, 0.0)
        out[:, 1] = zlast + np.cumsum(dz, axis=1)[:, -1]
        # all elements on the bed: no suspended sum (the end node is on the bed)
        out[k_star >= n_el, 1] = zlast[k_star >= n_el]
        return out

    return shoot, shoot_ends


def chain_guess(
    mesh: LineMesh,
    env: Environment,
    frame: LocalFrame,
    model: StaticsModel,
    a: np.ndarray,
    b: np.ndarray,
) -> np.ndarray | None:
    """Exact equilibrium of the lumped chain without drag: a two-unknown shooting.

    With the loads lumped at the nodes and no current, the element forces of the FE
    model satisfy F_k = F_{k-1} + P_k (node equilibrium), so every element carries the
    same horizontal component H and a vertical component V_k = V_0 + sum_{i<=k} P_i,
    P_i the net downward node load (half the weight of the two adjacent elements,
    attachment mass·g minus buoyancy).  Each element then has the direction (H, V_k)/T_k
    and the stretched length l0 (1 + T_k/EA): the discrete (lumped) elastic catenary.
    With end_a on the seabed the elements before the first one with V_k > 0 lie on the
    bed (V_k -> 0, the virtual-V_a form of :mod:`stochcable.line.catenary`, continuous at
    first contact), each grounded node at its contact penetration (load / (k·D·l)).
    (H, V_0) are found by damped Newton on the closure at end_b, started from the
    continuous catenary of the mean weight
    (:func:`stochcable.line.catenary.catenary_solve_unchecked`), or, when the kinks of
    the closure stall it, by nested bracketing (:func:`chain_closure`).  The weights
    follow the wet fraction of each element at the shape found (re-solved up to three
    times).  Drag is ignored (a start only).

    Unlike the continuous catenary sampled at the nodes, whose chords are shorter than
    its arcs by l0³κ²/24 (strains of -5e-3 near a sharp touchdown, i.e. slack elements
    with no transverse stiffness), this start has the right element lengths and is the
    FE solution itself for planar lines without current (up to the penetration tilt),
    so Newton ends in a few quadratic steps.

    Returns None for a vertical span, a line that would pass below the seabed away from
    end_a, or when the closure Newton fails; the caller falls back to a parabola.
    """
    zi = frame.dim - 1
    X = float(b[0] - a[0])
    Z = float(b[zi] - a[zi])
    L = mesh.length
    if X <= 1e-6 * L:
        return None
    zbed = model.zbed
    on_bed = a[zi] <= zbed * (1.0 - 1e-9) and Z > 0.0 and env.seabed.stiffness > 0.0
    l0, ea = mesh.l0, mesh.ea
    kb = np.where(model.kb > 0.0, model.kb, np.inf)

    def loads(W: np.ndarray) -> np.ndarray:
        P = -model.node_fz.copy()
        P[:-1] += 0.5 * W
        P[1:] += 0.5 * W
        return P

    shoot, shoot_ends = chain_shots(mesh, model, a, zi, on_bed, kb)

    W = l0 * model.w_sub
    P = loads(W)
    scale = max(L, 1.0)
    for _pass in range(3):
        HV = chain_newton(
            shoot, P, float(b[0]), float(b[zi]), X, Z, L, l0, ea, on_bed, scale, shoot_ends
        )
        if HV is None:
            HV = chain_closure(shoot, P, float(b[0]), float(b[zi]), scale)
        if HV is None:
            return None
        x, z = shoot(HV[0], HV[1], P)
        # weight of the elements by their wet fraction at this shape, then re-solve
        za, zb = z[:-1], z[1:]
        span_z = np.where(za != zb, zb - za, 1.0)
        f = np.where((za <= 0.0) & (zb <= 0.0), 1.0, 0.0)
        mixed = (np.minimum(za, zb) < 0.0) & (np.maximum(za, zb) > 0.0)
        f = np.where(mixed, -np.minimum(za, zb) / np.abs(span_z), f)
        W_new = l0 * (model.w_dry + f * (model.w_sub - model.w_dry))
        if np.allclose(W_new, W, rtol=1e-12, atol=0.0):
            break
        W = W_new
        P = loads(W)
    Xg = np.zeros((mesh.n_nodes, frame.dim))
    Xg[:, 0] = x
    Xg[:, zi] = z
    if not np.all(np.isfinite(Xg)):
        return None
    if float(np.min(z[1:-1], initial=0.0)) < zbed - 10.0 * float(
        np.max(np.abs(P) / kb, initial=0.0)
    ) - 1e-9 * max(env.depth, 1.0):
        return None  # passes through the seabed away from end_a
    Xg[0], Xg[-1] = a, b
    return Xg


def chain_newton(
    shoot,
    P: np.ndarray,
    xb: float,
    zb: float,
    X: float,
    Z: float,
    L: float,
    l0: np.ndarray,
    ea: np.ndarray,
    on_bed: bool,
    scale: float,
    shoot_ends: Any = None,
) -> tuple[float, float] | None:
    """(H, V_0) of the lumped chain by damped Newton on the end closure, started from
    the continuous catenary of the mean weight; None when it fails (kinks where an
    element lifts off the bed can stall it; :func:`chain_closure` then brackets).
    ``shoot_ends(H, V0, P)``: the end nodes of several shots at once (the four shots
    of the central-difference Jacobian in one call, the same numbers)."""
    w_mean = float(np.sum(P)) / L
    try:
        sol = catenary_solve_unchecked(
            X, Z, float(L), w_mean, L / float(np.sum(l0 / ea)), bool(on_bed and w_mean > 0.0)
        )
    except (InputError, ConvergenceError, ValueError):
        return None
    fscale = max(abs(w_mean) * L, sol.H, 1.0)
    H = max(sol.H, 1e-9 * fscale)
    V0 = (sol.V_a if sol.touchdown <= 0.0 else -w_mean * sol.touchdown) + 0.5 * P[0]
    u = np.array([math.log(H), V0])

    def resid(uu: np.ndarray) -> np.ndarray:
        x, z = shoot(math.exp(uu[0]), uu[1], P)
        return np.array([x[-1] - xb, z[-1] - zb])

    r = resid(u)
    nr = float(np.max(np.abs(r)))
    for _it in range(30):
        if nr <= 1e-12 * scale:
            return math.exp(u[0]), float(u[1])
        J = np.empty((2, 2))
        steps = (1e-7, 1e-7 * fscale)
        if shoot_ends is not None:
            pts = []
            for j, hstep in enumerate(steps):
                du = np.zeros(2)
                du[j] = hstep
                pts += [u + du, u - du]
            ends = shoot_ends(
                np.array([math.exp(p[0]) for p in pts]), np.array([p[1] for p in pts]), P
            )
            ends -= np.array([xb, zb])
            for j, hstep in enumerate(steps):
                J[:, j] = (ends[2 * j] - ends[2 * j + 1]) / (2.0 * hstep)
        else:
            for j, hstep in enumerate(steps):
                du = np.zeros(2)
                du[j] = hstep
                J[:, j] = (resid(u + du) - resid(u - du)) / (2.0 * hstep)
        try:
            d = np.linalg.solve(J, -r)
        except np.linalg.LinAlgError:
            return None
        d[0] = float(np.clip(d[0], -2.0, 2.0))
        t = 1.0
        for _ls in range(20):
            rn = resid(u + t * d)
            nrn = float(np.max(np.abs(rn)))
            if np.isfinite(nrn) and nrn < nr:
                break
            t *= 0.5
        else:
            return None
        u, r, nr = u + t * d, rn, nrn
    return None


def chain_closure(
    shoot, P: np.ndarray, xb: float, zb: float, scale: float
) -> tuple[float, float] | None:
    """(H, V_0) of the lumped chain reaching (xb, zb): nested monotone root finding.

    For fixed H the end elevation increases monotonically with V_0 (every element
    turns upward); with the elevation closed, the end abscissa increases with H.  Both
    closures are continuous but only piecewise smooth (an element lifts off the bed at
    a kink), so bracketing (Brent) is used instead of Newton.  None when no bracket.
    """
    from scipy.optimize import brentq

    load = float(np.sum(np.abs(P))) + 1.0

    def v0_of(H: float) -> float | None:
        lo, hi = -2.0 * load - H, 2.0 * load + H
        flo = shoot(H, lo, P)[1][-1] - zb
        fhi = shoot(H, hi, P)[1][-1] - zb
        k = 0
        while flo > 0.0 and k < 30:
            lo, k = 4.0 * lo, k + 1
            flo = shoot(H, lo, P)[1][-1] - zb
        while fhi < 0.0 and k < 60:
            hi, k = 4.0 * hi, k + 1
            fhi = shoot(H, hi, P)[1][-1] - zb
        if not (flo <= 0.0 <= fhi):
            return None
        return brentq(
            lambda v: shoot(H, v, P)[1][-1] - zb,
            lo,
            hi,
            xtol=1e-15 * load,
            rtol=4 * _EPS,
            maxiter=200,
        )

    def gx(logh: float) -> float:
        H = math.exp(logh)
        v0 = v0_of(H)
        if v0 is None:
            raise ValueError("no bracket")
        return shoot(H, v0, P)[0][-1] - xb

    try:
        lo, hi = math.log(1e-6 * load), math.log(load)
        glo, ghi = gx(lo), gx(hi)
        k = 0
        while ghi < 0.0 and k < 40:
            hi, k = hi + 2.0, k + 1
            ghi = gx(hi)
        while glo > 0.0 and k < 60:
            lo, k = lo - 4.0, k + 1
            glo = gx(lo)
        if not (glo <= 0.0 <= ghi):
            return None
        logh = brentq(gx, lo, hi, xtol=1e-14, rtol=4 * _EPS, maxiter=200)
        H = math.exp(logh)
        v0 = v0_of(H)
    except (ValueError, ZeroDivisionError, OverflowError, RuntimeError):
        return None
    if v0 is None:
        return None
    x, z = shoot(H, v0, P)
    if not (abs(x[-1] - xb) <= 1e-8 * scale and abs(z[-1] - zb) <= 1e-8 * scale):
        return None
    return H, v0
