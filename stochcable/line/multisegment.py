"""A chain of elastic catenary segments with point loads at the junctions (Irvine 1981,
ch. 2; Tuah's (1982) §6.2 buoy), no seabed contact: the reference of the FE statics of
multi-segment lines.

References
----------
Irvine, H. M. (1981), Cable structures, MIT Press, Cambridge, MA.
Tuah, H. (1982), Cable dynamics in an ocean environment, PhD thesis, Oregon State University.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from stochcable import validation as v
from stochcable.errors import ConvergenceError, InputError
from stochcable.line.catenary import catenary_solve_unchecked
from stochcable.line.catenary_kernel import CLOSURE_TOL, MAX_NEWTON, kernel
from stochcable.line.catenary_start import check_reach, newton_start

__all__ = ["MultiSegmentSolution", "catenary_multisegment"]


@dataclass(frozen=True)
class MultiSegmentSolution:
    """Static equilibrium of a chain of elastic catenary segments (no seabed contact).

    Attributes
    ----------
    H : float
        Horizontal tension component. [N]
    V_start, V_end : ndarray, shape (n_segments,)
        Vertical tension component at the start and end of each segment. [N]
    tension_a, tension_b : float
        Effective tension at end_a and end_b. [N]
    junctions : ndarray, shape (n_segments - 1, 2)
        Local (x, z) of the junctions. [m]
    iterations : int
        Newton iterations used.
    lengths, weights, eas : ndarray
        Segment data: L [m], w [N/m], EA [N].
    residual : float
        Largest closure error at the solution. [m]
    """

    H: float
    V_start: np.ndarray
    V_end: np.ndarray
    tension_a: float
    tension_b: float
    junctions: np.ndarray
    iterations: int
    lengths: np.ndarray
    weights: np.ndarray
    eas: np.ndarray
    residual: float = 0.0

    def __post_init__(self) -> None:
        for name in ("H", "tension_a", "tension_b", "residual"):
            object.__setattr__(self, name, float(getattr(self, name)))

    def profile(self, s: ArrayLike) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Local (x, z) and tension at unstretched arc lengths ``s`` from end_a. [m, m, N]

        At a junction itself the tension of the segment ending there is returned.
        """
        s = np.asarray(s, dtype=float)
        edges = np.concatenate([[0.0], np.cumsum(self.lengths)])
        s_c = np.clip(s, 0.0, edges[-1])
        k = np.clip(np.searchsorted(edges, s_c, side="left") - 1, 0, self.lengths.size - 1)
        origin = np.vstack([[0.0, 0.0], self.junctions])
        sl = s_c - edges[k]
        c = np.where(np.isinf(self.eas), 0.0, 1.0 / self.eas)
        x = np.empty_like(s_c)
        z = np.empty_like(s_c)
        for j in range(self.lengths.size):
            m = k == j
            if not m.any():
                continue
            xk, zk, *_ = kernel(self.H, self.V_start[j], float(self.weights[j]), sl[m], c[j])
            x[m] = origin[j, 0] + xk
            z[m] = origin[j, 1] + zk
        t = np.hypot(self.H, self.V_start[k] + self.weights[k] * sl)
        return x, z, t


def catenary_multisegment(
    horizontal_span: float,
    vertical_span: float,
    lengths: ArrayLike,
    weights: ArrayLike,
    eas: ArrayLike,
    junction_loads: ArrayLike | None = None,
) -> MultiSegmentSolution:
    """Chain of elastic catenary segments with point loads at the junctions.

    Parameters
    ----------
    horizontal_span : float
        Horizontal distance from end_a to end_b, > 0. [m]
    vertical_span : float
        Height of end_b above end_a. [m]
    lengths : array_like, shape (n,)
        Unstretched segment lengths from end_a. [m]
    weights : array_like, shape (n,)
        Net submerged weight per unit length of each segment (positive down). [N/m]
    eas : array_like, shape (n,)
        Axial stiffness of each segment. [N]
    junction_loads : array_like, shape (n - 1,), optional
        Net downward point force at each junction (clump weight positive, buoy
        negative). [N]

    Returns
    -------
    MultiSegmentSolution

    Notes
    -----
    The vertical tension component jumps by the junction load across each junction
    (node equilibrium, Tuah (1982), §6.2 buoy of 900 lb); H is constant.  The spans are
    the sums of the segments' closures (Irvine 1981, ch. 2) and the Jacobian the
    sum of theirs; damped Newton on (H, V_a) as in :func:`catenary_solve`, started from
    the single-segment solution with the average weight.  No seabed contact.
    """
    X = v.positive("horizontal_span", horizontal_span, "m")
    Z = v.finite_scalar("vertical_span", vertical_span, "m")
    Ls = v.float_array("lengths", lengths, "m", positive=True)
    n = Ls.size
    ws = v.float_array("weights", weights, "N/m")
    if ws.size != n:
        raise InputError("weights", weights, "N/m", f"must have {n} entries (one per segment)")
    eas_a = np.asarray(eas, dtype=float).reshape(-1)
    if eas_a.size != n or np.isnan(eas_a).any() or (eas_a <= 0).any():
        raise InputError("eas", eas, "N", f"must be {n} values > 0")
    if junction_loads is None:
        P = np.zeros(n - 1)
    else:
        P = v.float_array("junction_loads", junction_loads, "N", min_size=0)
    if P.size != n - 1:
        raise InputError(
            "junction_loads", junction_loads, "N", f"must have {n - 1} entries (one per junction)"
        )
    cs = np.where(np.isinf(eas_a), 0.0, 1.0 / eas_a)
    L = float(Ls.sum())
    chord = math.hypot(X, Z)
    ea_eq = L / float(np.sum(Ls * cs)) if np.sum(Ls * cs) > 0 else math.inf
    check_reach(L, chord, ea_eq)
    # V at the start of each segment = Va + offsets
    offsets = np.concatenate([[0.0], np.cumsum(ws[:-1] * Ls[:-1] + P)])

    def closure(H, Va):
        xs = zs = 0.0
        J = np.zeros((2, 2))
        for j in range(n):
            x, z, a, b, cc, d = kernel(H, Va + offsets[j], float(ws[j]), Ls[j], cs[j])
            xs += float(x)
            zs += float(z)
            J += np.array([[a, b], [cc, d]], dtype=float)
        return np.array([xs - X, zs - Z]), J

    w_avg = (float(np.sum(ws * Ls)) + float(P.sum())) / L
    if abs(w_avg) <= 1e-6 * float(np.max(np.abs(ws), initial=0.0)):
        w_avg = float(np.mean(np.abs(ws))) or 1.0  # a start only
    try:
        s0 = catenary_solve_unchecked(X, Z, L, w_avg, ea_eq, False)
        H, Va = s0.H, s0.V_a
    except (InputError, ConvergenceError):
        H, Va = newton_start(X, Z, L, w_avg if w_avg != 0 else 1.0, 1.0 / ea_eq)
    scale = max(L, chord)
    tol = CLOSURE_TOL * scale
    r, J = closure(H, Va)
    nr = float(np.max(np.abs(r)))
    it = 0
    for it in range(1, MAX_NEWTON + 1):  # noqa: B007 - the count goes into the error
        if nr <= tol:
            break
        d = np.linalg.solve(J, -r)
        t = 1.0
        if H + d[0] <= 0.1 * H:
            t = 0.9 * H / -d[0]
        for _ in range(60):
            rn, Jn = closure(H + t * d[0], Va + t * d[1])
            nrn = float(np.max(np.abs(rn)))
            if np.isfinite(nrn) and nrn < nr:
                break
            t *= 0.5
        else:
            break
        H, Va, r, J, nr = H + t * d[0], Va + t * d[1], rn, Jn, nrn
    if nr > tol:
        raise ConvergenceError("multi-segment catenary Newton", it, nr, tol, partial=(H, Va))
    V_start = Va + offsets
    V_end = V_start + ws * Ls
    junctions = np.zeros((n - 1, 2))
    px = pz = 0.0
    for j in range(n - 1):
        x, z, *_ = kernel(H, V_start[j], float(ws[j]), Ls[j], cs[j])
        px += float(x)
        pz += float(z)
        junctions[j] = (px, pz)
    return MultiSegmentSolution(
        H=H,
        V_start=V_start,
        V_end=V_end,
        tension_a=math.hypot(H, V_start[0]),
        tension_b=math.hypot(H, V_end[-1]),
        junctions=junctions,
        iterations=it,
        lengths=Ls,
        weights=ws,
        eas=eas_a,
        residual=nr,
    )
