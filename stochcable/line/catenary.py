"""Closed-form elastic catenary (Irvine 1981) with optional frictionless seabed contact.

One homogeneous, linearly elastic segment hangs between two fixed points in a vertical
plane.  Local coordinates: ``end_a`` at (0, 0), ``end_b`` at (X, Z), x horizontal from
end_a toward end_b, z up.  Unstretched arc length s runs from end_a (s = 0) to end_b
(s = L).  The tension vector at s has the horizontal component H (constant) and the
vertical component V(s) = V_a + w s, w the net submerged weight per unit length
(positive downward).  The tension is T(s) = sqrt(H² + V(s)²) (effective tension).

Closure: Bliet (1984), eqs. (2.5)–(2.6), the 2-D static equations without
current, integrated in closed form as in Irvine (1981), *Cable Structures*, ch. 2::

    x(s) = H s / EA + ∫₀ˢ H / T ds'   = H s/EA + (H/w)[asinh(V(s)/H) − asinh(V_a/H)]
    z(s) = (V_a s + w s²/2) / EA + ∫₀ˢ V / T ds' = (V_a s + w s²/2)/EA + (T(s) − T_a)/w

With seabed contact (end_a on the seabed, frictionless), a grounded length L_B lies flat
from end_a with constant tension H and zero vertical force; the suspended part above the
touchdown point starts with V = 0.  Writing L_B = −V_a/w for a (virtual) V_a < 0 makes the
closure continuous and continuously differentiable across first contact, so one Newton
iteration on (H, V_a) covers both regimes.

The integrals are evaluated as divided differences (no 1/w cancellation), so the
weightless limit w → 0, the vertical limit H → 0 and taut lines (EA/T up to 1e6 and
more) are all accurate to round-off.

References
----------
Bliet, A. (1984), Dynamic analysis of single span cables, PhD thesis, Massachusetts
Institute of Technology.
Irvine, H. M. (1981), Cable structures, MIT Press, Cambridge, MA.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike

from stochcable import validation as v
from stochcable.errors import ConvergenceError, InputError
from stochcable.line.catenary_kernel import (
    CLOSURE_TOL,
    MAX_NEWTON,
    closure,
    kernel,
    vertical_profile,
)
from stochcable.line.catenary_start import (
    MAX_STRAIN,
    _check_common,
    _vertical_solve,
    check_reach,
    newton_start,
)

if TYPE_CHECKING:  # pragma: no cover
    from stochcable.line.mesh import LineMesh
    from stochcable.scene.model import Environment, Line

__all__ = [
    "MAX_STRAIN",
    "CatenarySolution",
    "CatenaryLine",
    "catenary_solve",
    "catenary_solve_unchecked",
    "catenary_from_top_tension",
    "catenary_line",
    "catenary_on_mesh",
    "check_reach",
    "newton_start",
]


# --------------------------------------------------------------------------- results


@dataclass(frozen=True)
class CatenarySolution:
    """Static equilibrium of one elastic catenary segment.

    Attributes
    ----------
    H : float
        Horizontal tension component, constant along the line. [N]
    V_a : float
        Vertical tension component at end_a, positive when the line pulls end_a
        upward (zero when the line lies on the seabed at end_a). [N]
    V_b : float
        Vertical tension component at end_b, positive when the line pulls end_b
        downward. [N]
    tension_a, tension_b : float
        Effective tension at end_a and end_b. [N]
    grounded_length : float
        Horizontal (stretched) length of line lying on the seabed, 0 without
        contact. [m]
    touchdown : float
        Unstretched arc length from end_a of the touchdown point, 0 without
        contact. [m]
    iterations : int
        Newton iterations used.
    horizontal_span, vertical_span, length, weight, ea : float
        The inputs: X [m], Z [m], L [m], w [N/m], EA [N].
    seabed : bool
        Whether contact with the seabed z = 0 (local) was allowed.
    residual : float
        Largest closure error at the solution. [m]
    """

    H: float
    V_a: float
    V_b: float
    tension_a: float
    tension_b: float
    grounded_length: float
    touchdown: float
    iterations: int
    horizontal_span: float
    vertical_span: float
    length: float
    weight: float
    ea: float
    seabed: bool = False
    residual: float = 0.0

    def __post_init__(self) -> None:
        for name in (
            "H",
            "V_a",
            "V_b",
            "tension_a",
            "tension_b",
            "grounded_length",
            "touchdown",
            "horizontal_span",
            "vertical_span",
            "length",
            "weight",
            "ea",
            "residual",
        ):
            object.__setattr__(self, name, float(getattr(self, name)))
        object.__setattr__(self, "iterations", int(self.iterations))
        object.__setattr__(self, "seabed", bool(self.seabed))

    @property
    def grounded(self) -> bool:
        """True when part of the line lies on the seabed."""
        return self.touchdown > 0.0

    @property
    def angle_a(self) -> float:
        """Angle of the line at end_a above the horizontal. [rad]"""
        return math.atan2(self.V_a, self.H)

    @property
    def angle_b(self) -> float:
        """Angle of the line at end_b above the horizontal. [rad]"""
        return math.atan2(self.V_b, self.H)

    def profile(self, s: ArrayLike) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Position and tension at unstretched arc lengths ``s`` from end_a.

        Parameters
        ----------
        s : array_like
            Unstretched arc lengths, 0 <= s <= length. [m]

        Returns
        -------
        x, z : ndarray
            Local coordinates (end_a at the origin, z up). [m]
        tension : ndarray
            Effective tension. [N]
        """
        s_arr = np.asarray(s, dtype=float)
        s_c = np.clip(s_arr, 0.0, self.length)
        c = 0.0 if math.isinf(self.ea) else 1.0 / self.ea
        H, w = self.H, self.weight
        if H == 0.0:
            return vertical_profile(s_c, self.V_a, w, c)
        lb = self.touchdown
        if lb > 0.0:
            sig = np.maximum(s_c - lb, 0.0)
            xk, zk, *_ = kernel(H, 0.0, w, sig, c)
            on = s_c <= lb
            x = np.where(on, s_c * (1.0 + H * c), lb * (1.0 + H * c) + xk)
            z = np.where(on, 0.0, zk)
            t = np.where(on, H, np.hypot(H, w * sig))
            return x, z, t
        xk, zk, *_ = kernel(H, self.V_a, w, s_c, c)
        return xk, zk, np.hypot(H, self.V_a + w * s_c)


# ---------------------------------------------------------------------------- solve


def _newton(H, Va, X, Z, L, w, c, seabed, scale):
    """Damped Newton on the closure equations; returns (H, Va, iterations, residual)."""
    tol = CLOSURE_TOL * scale

    def resid(H_, Va_):
        x, z, J = closure(H_, Va_, L, w, c, seabed)
        return np.array([x - X, z - Z]), J

    r, J = resid(H, Va)
    nr = float(np.max(np.abs(r)))
    it = 0
    for it in range(1, MAX_NEWTON + 1):
        if nr <= tol:
            return H, Va, it - 1, nr
        try:
            d = np.linalg.solve(J, -r)
        except np.linalg.LinAlgError:
            d = -r * (np.abs(w) * L + H) / scale
        t = 1.0
        if H + d[0] <= 0.1 * H:  # keep H > 0: at most a factor 10 decrease per step
            t = 0.9 * H / -d[0]
        best = None
        for _ in range(60):
            Hn, Vn = H + t * d[0], Va + t * d[1]
            rn, Jn = resid(Hn, Vn)
            nrn = float(np.max(np.abs(rn)))
            if np.isfinite(nrn) and (nrn < nr or nrn <= tol):
                best = (Hn, Vn, rn, Jn, nrn)
                break
            t *= 0.5
        if best is None:
            break
        H, Va, r, J, nr = best
    if nr <= tol:
        return H, Va, it, nr
    raise ConvergenceError(
        "elastic catenary Newton",
        it,
        nr,
        tol,
        hint="check that the line length, weight and EA are consistent with the spans",
        partial=(H, Va),
    )


def catenary_solve(
    horizontal_span: float,
    vertical_span: float,
    length: float,
    weight: float,
    ea: float,
    seabed: bool = False,
) -> CatenarySolution:
    """Elastic catenary of one homogeneous segment between two fixed points.

    Parameters
    ----------
    horizontal_span : float
        Horizontal distance X from end_a to end_b, >= 0. [m]
    vertical_span : float
        Height Z of end_b above end_a (negative when end_b is lower). [m]
    length : float
        Unstretched length L. [m]
    weight : float
        Net submerged weight per unit length w, positive downward; negative for a
        buoyant line, 0 for a weightless (straight, taut) line. [N/m]
    ea : float
        Axial stiffness EA; ``math.inf`` for an inextensible line. [N]
    seabed : bool, optional
        Allow frictionless contact with the seabed through end_a (the plane z = 0 of
        the local frame): the line lies on it from end_a to the touchdown point where
        the vertical force vanishes.  Only for w > 0; needs vertical_span > 0.

    Returns
    -------
    CatenarySolution
        Tensions, touchdown and a vectorized ``profile(s)``.

    Raises
    ------
    InputError
        Invalid input; a line that would stretch more than 10 % (``MAX_STRAIN``) to
        reach its span; a weightless slack line; a slack line on the seabed with too
        small a horizontal span (it would pile up).
    ConvergenceError
        Newton did not reach the closure tolerance (1e-12 of the length).

    Notes
    -----
    Closure equations of the elastic catenary (Irvine 1981, ch. 2; Bliet (1984), eqs.
    (2.5)–(2.6) integrated with T = H/cos φ, eq. (3.28)) with the seabed extension of
    the grounded length L_B = L − V_b/w carrying the constant tension H.  Solved by
    Newton on (H, V_a) with
    an analytic, symmetric Jacobian, a backtracking line search and H kept positive.
    The start is the inextensible estimate of Peyrot & Goulois (1979) (λ from
    (L² − Z²)/X² = 1 + λ²/3) for slack lines and a parabolic elastic estimate for taut
    ones.  The closure integrals ∫H/T ds and ∫V/T ds are evaluated as divided
    differences, exact in the weightless (w → 0) and vertical (H → 0) limits.
    A horizontal span of exactly 0 gives H = 0 (vertical, possibly folded line).
    """
    X, Z, L, w, ea = _check_common(horizontal_span, vertical_span, length, weight, ea)
    return catenary_solve_unchecked(X, Z, L, w, ea, bool(seabed))


def catenary_solve_unchecked(
    X: float, Z: float, L: float, w: float, ea: float, seabed: bool
) -> CatenarySolution:
    """:func:`catenary_solve` for inputs already checked: floats, X >= 0 and Z, w
    finite, L > 0, EA > 0 (``math.inf`` inextensible) [m, m, m, N/m, N].  For the inner
    loops (the lumped-chain start of the FE statics, the line statics at every body
    pose, the multi-segment start).  Raises as :func:`catenary_solve` when the line
    cannot hang between the ends (too short, coincident ends, a weightless slack line,
    a slack line piling up on the seabed) and when Newton does not converge."""
    c = 0.0 if math.isinf(ea) else 1.0 / ea
    chord = math.hypot(X, Z)
    if chord == 0.0:
        raise InputError(
            "horizontal_span",
            X,
            "m",
            "end_a and end_b coincide (horizontal and vertical span are 0)",
        )
    check_reach(L, chord, ea)
    seabed = bool(seabed)
    if seabed and w <= 0.0:
        seabed = False  # a weightless or buoyant line does not rest on the seabed
    if seabed and Z <= 0.0:
        raise InputError(
            "vertical_span", Z, "m", "must be > 0 with seabed contact (end_b above the seabed)"
        )
    if w == 0.0:
        if chord <= L:
            raise InputError(
                "weight",
                w,
                "N/m",
                "a weightless line must be taut (length < distance between "
                "the ends); its slack shape is undetermined",
            )
        T = (chord / L - 1.0) / c
        H, Va = T * X / chord, T * Z / chord
        return CatenarySolution(H, Va, Va, T, T, 0.0, 0.0, 0, X, Z, L, w, ea, seabed, 0.0)
    if seabed:
        # H → 0 limit: vertical suspended part of length Ls with Z = Ls + c w Ls²/2.
        ls_min = 2.0 * Z / (1.0 + math.sqrt(1.0 + 2.0 * c * w * Z))
        if ls_min < L and X <= L - ls_min:
            raise InputError(
                "horizontal_span",
                X,
                "m",
                f"must be > {L - ls_min:.6g} m: with seabed contact a line this slack "
                "would pile up on the seabed (frictionless catenary has no solution)",
            )
    if X == 0.0:
        Va, it, res = _vertical_solve(Z, L, w, c, seabed)
        Vb = Va + w * L
        return CatenarySolution(
            0.0, Va, Vb, abs(Va), abs(Vb), 0.0, 0.0, it, X, Z, L, w, ea, seabed, res
        )
    H0, Va0 = newton_start(X, Z, L, w, c)
    scale = max(L, chord)
    H, Va, it, res = _newton(H0, Va0, X, Z, L, w, c, seabed, scale)
    Vb = Va + w * L
    if seabed and Va < 0.0:
        lb = min(-Va / w, L)
        return CatenarySolution(
            H,
            0.0,
            Vb,
            H,
            math.hypot(H, Vb),
            lb * (1.0 + H * c),
            lb,
            it,
            X,
            Z,
            L,
            w,
            ea,
            seabed,
            res,
        )
    return CatenarySolution(
        H, Va, Vb, math.hypot(H, Va), math.hypot(H, Vb), 0.0, 0.0, it, X, Z, L, w, ea, seabed, res
    )


def catenary_from_top_tension(
    vertical_span: float,
    length: float,
    weight: float,
    ea: float,
    tension_b: float,
    seabed: bool = False,
) -> CatenarySolution:
    """Elastic catenary whose tension at end_b is prescribed; the horizontal span follows.

    Parameters
    ----------
    vertical_span : float
        Height of end_b above end_a, > 0. [m]
    length : float
        Unstretched length. [m]
    weight : float
        Net submerged weight per unit length, > 0. [N/m]
    ea : float
        Axial stiffness (``math.inf`` for inextensible). [N]
    tension_b : float
        Effective tension at end_b. [N]
    seabed : bool, optional
        Allow seabed contact at end_a (see :func:`catenary_solve`).

    Returns
    -------
    CatenarySolution
        The solution, with ``horizontal_span`` the span found.

    Raises
    ------
    InputError
        When no horizontal span gives ``tension_b`` (too small to lift the line).

    Notes
    -----
    With T_b given, V_b = sqrt(T_b² − H²), and the vertical closure z(L; H) = Z is one
    equation in H on (0, T_b) solved by bisection refined with Brent's method; the
    horizontal closure then gives the span, which :func:`catenary_solve` re-solves for a
    consistent result.
    """
    from scipy.optimize import brentq

    Z = v.positive("vertical_span", vertical_span, "m")
    L = v.positive("length", length, "m")
    w = v.positive("weight", weight, "N/m")
    Tb = v.positive("tension_b", tension_b, "N")
    _, _, _, _, ea = _check_common(0.0, Z, L, w, ea)
    c = 0.0 if math.isinf(ea) else 1.0 / ea

    def spans(H):
        Vb = math.sqrt(max(Tb * Tb - H * H, 0.0))
        Va = Vb - w * L
        x, z, _ = closure(H, Va, L, w, c, seabed)
        return x, z

    lo, hi = Tb * 1e-9, Tb * (1.0 - 1e-12)
    flo, fhi = spans(lo)[1] - Z, spans(hi)[1] - Z
    if flo * fhi > 0.0:
        raise InputError(
            "tension_b",
            Tb,
            "N",
            f"no horizontal span gives this end_b tension for a vertical span "
            f"of {Z:g} m (the line is too heavy or too long for it)",
        )
    H = brentq(lambda h: spans(h)[1] - Z, lo, hi, xtol=1e-14 * Tb, rtol=1e-15, maxiter=500)
    X = spans(H)[0]
    return catenary_solve_unchecked(X, Z, L, w, ea, bool(seabed))


# ------------------------------------------------------------------------------ 3-D


@dataclass(frozen=True, eq=False)
class CatenaryLine:
    """A catenary solution placed in 3-D along a mesh.

    Attributes
    ----------
    solution : CatenarySolution
        The 2-D solution in the vertical plane through both ends.
    positions : ndarray, shape (n_nodes, 3)
        Node positions at the mesh's unstretched arc lengths ``s0``. [m]
    element_tension : ndarray, shape (n_elements,)
        Effective tension at each element's mid arc length. [N]
    node_tension : ndarray, shape (n_nodes,)
        Effective tension at the nodes. [N]
    """

    solution: CatenarySolution
    positions: np.ndarray
    element_tension: np.ndarray
    node_tension: np.ndarray


def catenary_line(mesh_or_line: LineMesh | Line, environment: Environment) -> CatenaryLine:
    """Closed-form statics of a one-segment line without attachments, in 3-D.

    Parameters
    ----------
    mesh_or_line : LineMesh or Line
        The line (meshed with ``environment``'s rho and g when a Line is given).
    environment : Environment
        Depth, rho, g; seabed contact is used when end_a lies on the seabed.

    Returns
    -------
    CatenaryLine
        Node positions at the mesh's ``s0`` and element tensions at mid arc length.

    Raises
    ------
    InputError
        For lines with more than one segment or with attachments carrying load.
    """
    from stochcable.line.mesh import LineMesh, mesh_line

    if isinstance(mesh_or_line, LineMesh):
        mesh = mesh_or_line
    else:
        mesh = mesh_line(mesh_or_line, environment.rho, environment.g)
    if np.unique(mesh.segment).size != 1:
        raise InputError(
            f"line {mesh.name!r}.segments",
            int(np.unique(mesh.segment).size),
            "-",
            "the closed-form catenary needs exactly one segment",
        )
    if np.any(mesh.node_mass != 0.0) or np.any(mesh.node_buoyancy != 0.0):
        raise InputError(
            f"line {mesh.name!r}.attachments",
            "mass/buoyancy",
            "-",
            "the closed-form catenary needs a line without loaded attachments",
        )
    return catenary_on_mesh(mesh, environment)


def catenary_on_mesh(mesh: LineMesh, environment: Environment) -> CatenaryLine:
    """:func:`catenary_line` of a mesh already known to have one segment and no loaded
    attachment (the line statics checks that before it takes the closed form)."""
    a, b = mesh.end_a, mesh.end_b
    d = b - a
    X = float(math.hypot(d[0], d[1]))
    Z = float(d[2])
    e_h = np.array([d[0], d[1], 0.0]) / X if X > 0.0 else np.array([1.0, 0.0, 0.0])
    depth = environment.depth
    on_seabed = abs(a[2] + depth) <= 1e-9 * depth
    sol = catenary_solve_unchecked(
        X, Z, float(mesh.length), float(mesh.weight[0]), float(mesh.ea[0]), bool(on_seabed)
    )
    x, z, t = sol.profile(mesh.s0)
    pos = a[None, :] + x[:, None] * e_h[None, :] + z[:, None] * np.array([0.0, 0.0, 1.0])
    mid = 0.5 * (mesh.s0[1:] + mesh.s0[:-1])
    _, _, t_mid = sol.profile(mid)
    return CatenaryLine(solution=sol, positions=pos, element_tension=t_mid, node_tension=t)


# Former name of catenary_solve_unchecked (ARCHITECTURE.md "Conventions"), kept importable.
elastic_catenary = catenary_solve_unchecked
