"""Steady loads of the relative flow on a travelling line, and its static shape in them.

A line whose material travels at speed c along its tangent t through a uniform flow U
sees the relative velocity V_r = U − c t.  Hu & Jin (2001, eq. 6) load each element
with a drag along the relative velocity's cross-chord component and a lift across the
flow, both on the magnitude |V_r| (b = |V_r|/V_f = √(1 + λ₀²) at the mid-span):

    f_D = ½ ρ C_D D |V_r| (V_r · ŷ) ŷ,      f_L = ½ ρ C_L D |V_r|² ẑ,

with ŷ the flow direction and ẑ up.  The cross-chord velocity V_f − c v′ (v′ = t · ŷ)
is what makes the drag of an inclined element change with the travel (the factor
1 − λ₀ v′ of eq. 6), and |V_r| = b V_f (1 − k̄ v′ + …) its factor 1 − k̄ v′.

:func:`static_shape_in_flow` solves the static equilibrium of a line with both ends
fixed under its weight and these loads, by Newton iterations on the node positions
(the exact elastic tangent of :mod:`stochcable.line.elements` plus the loads'
Jacobian by coloured finite differences), with continuation in the load.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from stochcable.errors import ConvergenceError, InputError
from stochcable.line.elements import STIFFNESS_PATTERN, expand_blocks, stiffness_blocks
from stochcable.validation import finite_scalar, float_array, nonnegative, positive

__all__ = [
    "FlowShape",
    "hu_jin_flow_force",
    "steady_lift_force",
    "lift_velocity_jacobian",
    "static_shape_in_flow",
]

_Y = np.array([0.0, 1.0, 0.0])
_Z = np.array([0.0, 0.0, 1.0])


def hu_jin_flow_force(
    tangents: np.ndarray,
    speed: float,
    flow_speed: float,
    rho: float,
    diameter: float,
    cd: float,
    cl: float,
) -> np.ndarray:
    """Steady drag and lift per unit length of the relative flow (Hu & Jin 2001, eq. 6).

    Parameters
    ----------
    tangents : array_like, shape (n_el, 3)
        Unit tangents of the elements, pointing the way the material travels for
        ``speed`` > 0. [-]
    speed : float
        Axial (transport) speed c. [m/s]
    flow_speed : float
        Speed V_f of the uniform flow along +y. [m/s]
    rho : float
        Fluid density. [kg/m³]
    diameter : float
        Hydrodynamic diameter. [m]
    cd, cl : float
        Drag and lift coefficients (lift along +z for V_f ≠ 0 and C_L > 0). [-]

    Returns
    -------
    ndarray, shape (n_el, 3)
        Force per unit current length. [N/m]

    Notes
    -----
    V_r = V_f ŷ − c t; f = ½ρD[C_D |V_r| (V_r·ŷ) ŷ + C_L |V_r|² ẑ] (module docstring).
    On a chord along x with small slopes v′ = t·ŷ, this is eq. (6) without motion:
    f_y = ½ρ b D C_D V_f² (1 − λ₀v′)(1 − k̄v′) and the lift ½ρ b² D C_L V_f² (1 − k̄v′)²
    to first order in v′.
    """
    t = float_array("tangents", tangents, "-", ndim=2)
    if t.shape[1] != 3:
        raise InputError("tangents", t.shape, "-", "must have 3 columns (x, y, z)")
    c = finite_scalar("speed", speed, "m/s")
    vf = finite_scalar("flow_speed", flow_speed, "m/s")
    rho = positive("rho", rho, "kg/m³")
    dia = positive("diameter", diameter, "m")
    cd = nonnegative("cd", cd, "-")
    cl = finite_scalar("cl", cl, "-")
    vr = vf * _Y[None, :] - c * t
    mag = np.linalg.norm(vr, axis=1)
    q = 0.5 * rho * dia
    return (
        q * (cd * mag * vr[:, 1])[:, None] * _Y[None, :]
        + q * (cl * mag * mag)[:, None] * _Z[None, :]
    )


def steady_lift_force(
    tangents: np.ndarray, current: np.ndarray, speed: np.ndarray | float, coef: np.ndarray
) -> np.ndarray:
    """Steady lift per unit length of the relative flow on a line's elements, as the
    scene statics apply it (docs/travelling.md).

    Parameters
    ----------
    tangents : array_like, shape (n_el, 3)
        Unit tangents e of the elements, end_a → end_b; z up. [-]
    current : array_like, shape (n_el, 3)
        Current U at the elements. [m/s]
    speed : float or array_like, shape (n_el,)
        Axial speed c of the material along e (0 on dry elements). [m/s]
    coef : array_like, shape (n_el,)
        ½ ρ C_L D of each element. [kg/m²]

    Returns
    -------
    ndarray, shape (n_el, 3)
        Force per unit current length; 0 where the current has no component normal
        to the element (no cross-flow: no lift direction). [N/m]

    Notes
    -----
    f_L = ½ρC_L D |V_r|² (ẑ·m̂) m̂, with V_r = U − c e the relative flow and
    m̂ = e × U_n/|U_n| the unit normal to the element and the cross-flow
    U_n = U − (U·e) e: the lift of Hu & Jin (2001, eq. 6), ½ρC_L D |V_r|², across the
    flow and the element, on its upward side.  On their chord along x̂ in a flow V_f ŷ
    it is ½ρC_L D (V_f² − 2cV_f v′ + c²) ẑ (1 + O(w′²)): eq. (6)'s b²(1 − k̄v′)² to
    first order in the slopes.  The factor ẑ·m̂ keeps it continuous where m̂ turns
    horizontal (a vertical element: no up side, no lift); a planar problem (current in
    the vertical plane of the line) has m̂ horizontal and normal to it: no lift.
    """
    e = np.asarray(tangents, dtype=float)
    u = np.asarray(current, dtype=float)
    ua = np.einsum("ij,ij->i", u, e)
    un = u - ua[:, None] * e
    un2 = np.einsum("ij,ij->i", un, un)
    m = np.cross(e, un)
    rel = ua - speed
    vr2 = un2 + rel * rel
    scale = np.divide(coef * vr2 * m[:, 2], un2, out=np.zeros_like(un2), where=un2 > 0.0)
    return scale[:, None] * m


def lift_velocity_jacobian(
    tangents: np.ndarray, current: np.ndarray, speed: np.ndarray | float, coef: np.ndarray
) -> np.ndarray:
    """∂f_L/∂U of :func:`steady_lift_force`: the linearized lift of a change of the
    relative flow (the fluid's velocity minus the line's), at fixed tangents.

    Parameters
    ----------
    tangents, current, speed, coef
        As :func:`steady_lift_force`.

    Returns
    -------
    ndarray, shape (n_el, 3, 3)
        A with δf_L = A δV per unit length [N·s/m²]; zero where the mean flow has no
        normal component (no lift direction to linearize about).

    Notes
    -----
    Central differences with a step 1e-6 of the normal flow speed (f_L is smooth
    where U_n ≠ 0; the truncation error is of order 1e-12 relative).  A check: f_L
    is homogeneous of degree 2 in (U, c), so A U + c ∂f_L/∂c = 2 f_L.
    """
    e = np.asarray(tangents, dtype=float)
    u = np.asarray(current, dtype=float)
    coef = np.asarray(coef, dtype=float)
    un = u - np.einsum("ij,ij->i", u, e)[:, None] * e
    unorm = np.linalg.norm(un, axis=1)
    h = 1e-6 * np.where(unorm > 0.0, unorm, 1.0)
    jac = np.zeros(e.shape + (3,))
    for k in range(3):
        du = np.zeros_like(u)
        du[:, k] = h
        fp = steady_lift_force(e, u + du, speed, coef)
        fm = steady_lift_force(e, u - du, speed, coef)
        jac[:, :, k] = (fp - fm) / (2.0 * h)[:, None]
    jac[unorm <= 0.0] = 0.0
    return jac


@dataclass(frozen=True, eq=False)
class FlowShape:
    """Static shape of a line in a relative flow.

    Attributes
    ----------
    positions : ndarray, shape (n_nodes, 3)
        Node positions. [m]
    tension : ndarray, shape (n_el,)
        Element tension EA (l − l0)/l0. [N]
    iterations : int
        Newton iterations of the last load step.
    residual : float
        Largest nodal force residual at the end. [N]
    """

    positions: np.ndarray
    tension: np.ndarray
    iterations: int
    residual: float

    def midspan_angle(self) -> float:
        """Rotation φ of the mid-span node about the chord, from hanging straight down
        (0) towards +y (π/2) and the top (π), as Hu & Jin's φ. [rad]"""
        p = self.positions
        a, b = p[0], p[-1]
        mid = p[p.shape[0] // 2]
        chord = (b - a) / np.linalg.norm(b - a)
        r = mid - a
        r = r - (r @ chord) * chord
        return float(np.arctan2(r @ _Y, -(r @ _Z)) % (2.0 * np.pi))


def _forces(x, l0, ea, w, load):
    """Nodal residual (internal + external) of positions x (n_nodes, 3)."""
    d = x[1:] - x[:-1]
    l = np.linalg.norm(d, axis=1)
    e = d / l[:, None]
    t = ea * (l - l0) / l0
    f = np.zeros_like(x)
    f[:-1] += t[:, None] * e
    f[1:] -= t[:, None] * e
    ext = load(e) * l[:, None] - (w * l0)[:, None] * _Z[None, :]
    f[:-1] += 0.5 * ext
    f[1:] += 0.5 * ext
    return f, e, l, t


def static_shape_in_flow(
    start: np.ndarray,
    l0: np.ndarray,
    ea: float,
    weight: float,
    load,
    steps: int = 10,
    tol: float = 1e-7,
    max_iter: int = 50,
) -> FlowShape:
    """Static equilibrium of a line with fixed ends under weight and a tangent-dependent
    flow load.

    Parameters
    ----------
    start : array_like, shape (n_nodes, 3)
        Starting node positions; the first and last are the fixed ends. [m]
    l0 : array_like, shape (n_el,)
        Unstretched element lengths. [m]
    ea : float
        Axial stiffness. [N]
    weight : float
        Weight per unit unstretched length, along −z. [N/m]
    load : callable
        ``load(tangents (n_el, 3)) -> (n_el, 3)`` force per unit current length [N/m],
        e.g. a closure over :func:`hu_jin_flow_force`.
    steps : int
        Load steps of the continuation (the flow load scaled by k/steps).
    tol : float
        Convergence: largest nodal residual below ``tol`` times the total weight. [-]
    max_iter : int
        Newton iterations per step.

    Returns
    -------
    FlowShape

    Raises
    ------
    ConvergenceError
        A load step that does not converge (with its residual).
    """
    x = float_array("start", start, "m", ndim=2).copy()
    l0 = float_array("l0", l0, "m", positive=True)
    ea = positive("ea", ea, "N")
    w = nonnegative("weight", weight, "N/m") * np.ones_like(l0)
    n = x.shape[0]
    if x.shape != (n, 3) or l0.shape != (n - 1,):
        raise InputError("start", x.shape, "m", "must be (n_el + 1, 3) for l0 of n_el")
    scale = max(float(w.sum() * l0.mean()), 1e-12) if w.any() else 1.0
    free = np.arange(3, 3 * (n - 1))
    res = np.inf
    it = 0
    for step in range(1, steps + 1):
        frac = step / steps

        def scaled(e, frac=frac):
            return frac * load(e)

        for it in range(1, max_iter + 1):  # noqa: B007
            f, e, l, t = _forces(x, l0, ea, w, scaled)
            res = float(np.abs(f[1:-1]).max())
            if res <= tol * scale:
                break
            jac = _jacobian(x, l0, ea, w, scaled, e, l, t)
            dx = np.linalg.solve(jac, f.reshape(-1)[free])
            # a step no longer than a tenth of the mean element length (the shape
            # rotates a lot between load steps near a transition)
            big = float(np.abs(dx).max())
            lim = 0.1 * float(l0.mean())
            x.reshape(-1)[free] += dx * min(1.0, lim / big if big > 0 else 1.0)
            if big <= 1e-12 * float(l0.sum()):
                break  # at the round-off of the stiff elastic forces (EA·ε_machine)
        else:
            raise ConvergenceError(
                f"static shape in the flow (load step {step}/{steps})",
                max_iter,
                res / scale,
                tol,
                hint="more load steps, or a start nearer the equilibrium",
            )
    f, e, l, t = _forces(x, l0, ea, w, load)
    return FlowShape(positions=x, tension=t, iterations=it, residual=res)


def _jacobian(x, l0, ea, w, load, e, l, t):
    """−∂f/∂x on the free DOFs: the elastic tangent plus the loads' by differences
    (nodes coloured mod 3: a node's load touches only its two elements)."""
    n = x.shape[0]
    k = expand_blocks(stiffness_blocks(e, l, l0, ea * np.ones_like(l0), t), STIFFNESS_PATTERN)
    jac = np.zeros((3 * n, 3 * n))
    for j in range(n - 1):
        s = slice(3 * j, 3 * j + 6)
        jac[s, s] += k[j]
    f0, *_ = _forces(x, l0, ea, w, load)
    elastic_only = _forces(x, l0, ea, w, lambda e_: np.zeros_like(e_))[0]
    ext0 = f0 - elastic_only
    h = 1e-7 * float(l0.mean())
    for colour in range(3):
        nodes = np.arange(colour, n, 3)
        for c in range(3):
            xp = x.copy()
            xp[nodes, c] += h
            fp, *_ = _forces(xp, l0, ea, w, load)
            ep = _forces(xp, l0, ea, w, lambda e_: np.zeros_like(e_))[0]
            dext = ((fp - ep) - ext0) / h  # (n, 3): rows touched by these nodes
            for i in nodes:
                rows = slice(max(0, i - 1) * 3, min(n, i + 2) * 3)
                jac[rows, 3 * i + c] -= dext[max(0, i - 1) : min(n, i + 2)].reshape(-1)
    free = np.arange(3, 3 * (n - 1))
    return jac[np.ix_(free, free)]
