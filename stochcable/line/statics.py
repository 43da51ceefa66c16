"""Static equilibrium of lines: elastic catenary or finite-element Newton (seed 001 §4.1).

The static shape is the configuration the dynamic analysis linearizes about (seed 001
ch. 4: "provide a stable starting configuration for a dynamic problem").  Two methods:

- ``"catenary"``: the closed-form elastic catenary (:mod:`stochcable.line.catenary`) for a
  single homogeneous segment between fixed points in a vertical plane, without current
  or attachments, with seabed contact when end_a lies on the seabed;
- ``"fe"``: a finite-element Newton solve over the mesh of 2-node straight elastic bars
  (seed 001 §3.1) with lumped loads, for everything: several segments, clump weights
  and buoys, current drag, seabed contact, 3-D geometry.

``"auto"`` takes the catenary where it applies and the FE otherwise.  Both solve for
the *effective* tension: the weight is the net submerged weight per unit length
(weight in air minus the weight of displaced water), so the hydrostatic pressure field
is folded into the load and the tension reported is the effective tension.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np
from scipy.linalg import LinAlgError, get_lapack_funcs

from stochcable.errors import ConvergenceError, InputError
from stochcable.line.mesh import LineMesh, mesh_line
from stochcable.scene.model import Environment, Scene

__all__ = ["LineStatics", "StaticsResult", "solve_statics", "solve_line_statics"]

Method = Literal["auto", "fe", "catenary"]

#: Axial stiffness factor of a slack (compressed) element: E -> eps E (seed 001 §6.2).
SLACK_FACTOR = 1e-6

_EPS = np.finfo(float).eps


# --------------------------------------------------------------------------- results


@dataclass(frozen=True, eq=False)
class LineStatics:
    """Static equilibrium of one line.

    Attributes
    ----------
    mesh : LineMesh
        The discretization the nodes belong to.
    positions : ndarray, shape (n_nodes, 3)
        Node positions, global frame, z up. [m]
    tension : ndarray, shape (n_el,)
        Effective tension of each element, EA (l/l0 - 1), zero for slack elements. [N]
    node_tension : ndarray, shape (n_nodes,)
        Effective tension at the nodes: the end-force magnitude at the two ends, the
        mean of the two adjacent elements inside. [N]
    force_a, force_b : ndarray, shape (3,)
        Force the line exerts on its end supports (element force plus the loads lumped
        at the end node), global frame. [N]
    tension_a, tension_b : float
        Magnitudes of ``force_a`` and ``force_b``: the end tensions. [N]
    grounded : ndarray of bool, shape (n_nodes,)
        Nodes in contact with the seabed.
    touchdown : float or None
        Unstretched arc length from end_a where the line leaves the seabed (toward
        end_b), interpolated between nodes; None without seabed contact. [m]
    iterations : int
        Newton / relaxation iterations used (0 for the closed form).
    residual : float
        Final max |nodal residual force| divided by the reference force (total weight
        magnitude plus largest element tension plus total drag). [-]
    method : str
        ``"catenary"`` or ``"fe"``.
    """

    mesh: LineMesh
    positions: np.ndarray
    tension: np.ndarray
    node_tension: np.ndarray
    force_a: np.ndarray
    force_b: np.ndarray
    tension_a: float
    tension_b: float
    grounded: np.ndarray
    touchdown: float | None
    iterations: int
    residual: float
    method: str

    def to_document(self) -> dict[str, Any]:
        """The line's entry of the result document's ``statics`` (DESIGN.md v1)."""
        return {
            "end_a": {"tension": float(self.tension_a),
                      "force": [float(v) for v in self.force_a]},
            "end_b": {"tension": float(self.tension_b),
                      "force": [float(v) for v in self.force_b]},
            "touchdown": None if self.touchdown is None else float(self.touchdown),
            "nodes": self.positions.tolist(),
            "s": self.mesh.s0.tolist(),
            "tension": self.tension.tolist(),
            "iterations": int(self.iterations),
            "residual": float(self.residual),
            "method": self.method,
        }


@dataclass(frozen=True)
class StaticsResult:
    """Static equilibrium of every line of a scene, by line name, and of its bodies
    (:class:`stochcable.bodies.statics.BodyStatics`, by body name; empty without bodies)."""

    lines: dict[str, LineStatics] = field(default_factory=dict)
    bodies: dict[str, Any] = field(default_factory=dict)

    def to_document(self) -> dict[str, Any]:
        """The ``statics`` part of the result document (DESIGN.md v1); ``"bodies"``
        only when the scene has bodies."""
        doc: dict[str, Any] = {"lines": {name: ls.to_document()
                                         for name, ls in self.lines.items()}}
        if self.bodies:
            doc["bodies"] = {name: b.to_document() for name, b in self.bodies.items()}
        return doc


# ------------------------------------------------------------------------ public API


def solve_statics(scene: Scene, method: Method = "auto", *, tolerance: float = 1e-10,
                  max_iterations: int = 500) -> StaticsResult:
    """Static equilibrium of every line of a scene.

    Parameters
    ----------
    scene : Scene
        The validated scene (see :func:`stochcable.scene.model.load_scene`).
    method : {"auto", "fe", "catenary"}, optional
        Solution method, see :func:`solve_line_statics`.
    tolerance : float, optional
        Relative residual force at convergence (FE). [-]
    max_iterations : int, optional
        Iteration budget per line (FE). [-]

    Returns
    -------
    StaticsResult
        One :class:`LineStatics` per line, by name; with bodies, one
        :class:`~stochcable.bodies.statics.BodyStatics` per body and the lines solved with
        their attached ends at the body poses
        (:func:`stochcable.bodies.statics.solve_body_statics`).
    """
    env = scene.environment
    if scene.bodies:
        from stochcable.bodies.statics import solve_body_statics

        lines, bodies = solve_body_statics(scene, method, tolerance=tolerance,
                                           max_iterations=max_iterations)
        return StaticsResult(lines=lines, bodies=bodies)
    out = {}
    for line in scene.lines:
        mesh = mesh_line(line, env.rho, env.g)
        out[line.name] = solve_line_statics(mesh, env, method=method, tolerance=tolerance,
                                            max_iterations=max_iterations)
    return StaticsResult(lines=out)


def solve_line_statics(
    mesh: LineMesh,
    environment: Environment,
    method: Method = "auto",
    initial: np.ndarray | None = None,
    *,
    tolerance: float = 1e-10,
    max_iterations: int = 500,
) -> LineStatics:
    """Static equilibrium of one meshed line with fixed ends.

    Parameters
    ----------
    mesh : LineMesh
        The line's elements and nodes (:func:`stochcable.line.mesh.mesh_line`).
    environment : Environment
        Depth, fluid, gravity, current and seabed.
    method : {"auto", "fe", "catenary"}, optional
        ``"catenary"``: closed-form elastic catenary (one homogeneous segment between
        fixed points, no current, no attachments, submerged; seabed contact when end_a
        lies on the seabed), positions reported at the mesh nodes.  ``"fe"``: the
        finite-element Newton solve.  ``"auto"`` (default): the catenary where it
        applies, the FE otherwise.
    initial : ndarray, shape (n_nodes, 3), optional
        Initial node positions for the FE (the end rows are replaced by the ends). [m]
    tolerance : float, optional
        Convergence threshold of the max nodal residual force relative to the
        reference force (total weight + largest tension + total drag). [-]
    max_iterations : int, optional
        Total iteration budget of the FE solve (Newton, relaxation and load steps). [-]

    Returns
    -------
    LineStatics
        Positions, effective tensions, end forces and seabed contact.

    Raises
    ------
    InputError
        For an unknown method, an ``initial`` of the wrong shape, ``"catenary"``
        asked for a line it does not apply to, or a line whose static shape is
        undetermined (see Notes).
    ConvergenceError
        When the FE solve does not reach ``tolerance`` within ``max_iterations``; the
        message carries the residual reached.

    Notes
    -----
    The FE model (seed 001 §3.1, DESIGN.md "Cable model") has the interior node
    positions as unknowns; the ends are fixed at their static positions (end motions
    are dynamic only).  Element force from the exact elastic bar,
    T = EA (l/l0 - 1) for l > l0 and T = eps EA (l/l0 - 1), eps = 1e-6, for a slack
    element (E -> eps, seed 001 §6.2); consistent tangent
    K_e = [(EA/l0) e eᵀ + (T/l)(I - e eᵀ)] ⊗ [[1, -1], [-1, 1]].

    Loads, lumped half to each node of an element:

    - weight: net submerged weight per unstretched length w·l0 (effective tension);
      the part of an element above z = 0 carries the dry weight mass·g instead, by the
      fraction of the element below the surface (tangent included);
    - attachments: mass·g down, buoyancy up, at their nodes;
    - steady current U(z) at the element midpoint: normal drag ½ρ Cdn D |u_n| u_n and
      axial drag ½ρ Cdt πD |u_t| u_t per unit stretched length (a follower load whose
      exact tangent with respect to the element direction and length is included;
      the variation of U with depth is left out of the tangent, which makes the
      iteration linearly rather than quadratically convergent for sheared currents);
      attachment drag ½ρ (Cd·A) |U| U at the node;
    - seabed (z < -depth): a one-sided linear spring, stiffness·D per unit length over
      the node's tributary unstretched length, pushing up only.  The penetration of a
      line lying on the bed is w/(stiffness·D).  Seabed friction is not modelled.

    Start: the exact equilibrium of the lumped chain without drag (a two-unknown
    shooting on (H, V_0), seabed contact from end_a included, see ``_chain_guess``),
    which is the FE solution itself for planar lines without current; a parabola when
    it does not apply (vertical span, contact away from end_a).

    Solution (seed 001 §4.1): Newton–Raphson on the residual feedback form
    (eq. 4.1.2) with a backtracking line search that accepts a decrease of the residual
    norm or of the potential energy with the drag frozen at the current iterate (the
    exact energy without current); when no step is accepted, the viscous relaxation
    method (eqs. 4.1.5-4.1.8): artificial nodal damping proportional to the stiffness
    diagonal, [K + C/Δt] ΔU = R, with 1/Δt relaxed toward zero as full steps succeed,
    which ends as plain Newton.  With current, the full-load attempt gets a quarter of
    the budget and then the drag is load-stepped from the current-free equilibrium.
    The tangent of a line is block tridiagonal and is solved banded (O(n) per
    iteration).

    Undetermined shapes are refused up front (InputError): without current, a line
    with end_a on the frictionless seabed longer than its horizontal span plus its
    vertical hanging length (the slack lies on the bed with zero horizontal tension and
    can slide), and a weightless slack line.  Otherwise the iteration count is bounded
    by ``max_iterations`` and a ConvergenceError names the line.

    The reachable residual is bounded below by round-off in l - l0: about
    8·eps·max(EA/l0)·max|x| relative to the reference force; ``tolerance`` is raised
    to that floor when it is larger (nearly inextensible, finely meshed lines).
    """
    if method not in ("auto", "fe", "catenary"):
        raise InputError("method", method, "-", "must be 'auto', 'fe' or 'catenary'")
    tolerance = float(tolerance)
    if not (0.0 < tolerance < 1.0):
        raise InputError("tolerance", tolerance, "-", "must be in (0, 1)")
    if int(max_iterations) < 1:
        raise InputError("max_iterations", max_iterations, "-", "must be >= 1")
    if initial is not None:
        initial = np.asarray(initial, dtype=float)
        if initial.shape != (mesh.n_nodes, 3) or not np.isfinite(initial).all():
            raise InputError("initial", initial, "m",
                             f"must be finite with shape ({mesh.n_nodes}, 3)")

    _check_determined(mesh, environment)
    if method != "fe":
        why = _catenary_inapplicable(mesh, environment)
        if why is None:
            out = _solve_catenary(mesh, environment)
            if isinstance(out, LineStatics):
                return out
            why = out
        if method == "catenary":
            raise InputError("method", "catenary", "-",
                             f"does not apply to line {mesh.name!r}: {why}; use 'fe' or 'auto'")
    return _solve_fe(mesh, environment, initial, tolerance, int(max_iterations))


def _check_determined(mesh: LineMesh, env: Environment) -> None:
    """Raise InputError for a line whose static shape is undetermined.

    Without current and with the loads all downward:

    - a weightless line longer than the distance between its ends (no load fixes the
      slack shape);
    - a line with end_a on the frictionless seabed that is longer than its horizontal
      span X plus the shortest hanging length l_v that reaches end_b's height Z
      (l_v = 2Z / (1 + sqrt(1 + 2 w Z / EA)), the elastic vertical line of the segment
      at end_b, w its net weight): the surplus would lie slack on the bed with zero
      horizontal tension, and with no seabed friction (not modelled) its horizontal
      position is undetermined.  Both ends on the bed is the case Z = 0.
    """
    if any(p.speed > 0.0 for p in env.current):
        return
    if np.any(mesh.weight < 0.0) or np.any(mesh.node_buoyancy - mesh.node_mass * env.g > 0.0):
        return
    L = mesh.length
    d = mesh.end_b - mesh.end_a
    X = math.hypot(d[0], d[1])
    Z = float(d[2])
    chord = math.hypot(X, Z)
    if (np.all(mesh.weight == 0.0) and np.all(mesh.node_mass == 0.0)
            and L > chord * (1.0 + 1e-12)):
        raise InputError(
            f"lines[{mesh.name!r}].length", L, "m",
            f"a weightless line longer than the distance between its ends ({chord:.6g} m) "
            "has an undetermined slack shape; shorten it or give it a weight")
    on_bed = mesh.end_a[2] <= -env.depth * (1.0 - 1e-9)
    if not on_bed or Z < 0.0 or not np.any(mesh.weight > 0.0):
        return
    w, ea = float(mesh.weight[-1]), float(mesh.ea[-1])
    lv = 2.0 * Z / (1.0 + math.sqrt(1.0 + 2.0 * w * Z / ea))
    if L >= X + lv:
        raise InputError(
            f"lines[{mesh.name!r}].length", L, "m",
            f"the line is longer than its horizontal span plus its vertical hanging length "
            f"({X:.6g} m + {lv:.6g} m = {X + lv:.6g} m) with end_a on the seabed: the "
            "surplus lies slack on the seabed with zero horizontal tension, and without "
            "seabed friction (not modelled) the horizontal position of a fully slack "
            f"grounded line is undetermined; shorten the line below {X + lv:.6g} m or move "
            "the ends apart")


# ---------------------------------------------------------------------- local frame


class _Frame:
    """Local frame: x' along the horizontal projection of end_a -> end_b, z up.

    A planar problem (every load in the vertical plane through the ends) is solved with
    two DOFs per node (x', z); otherwise with three (x', y', z).
    """

    def __init__(self, mesh: LineMesh, env: Environment, force_3d: bool = False) -> None:
        a, b = mesh.end_a, mesh.end_b
        h = b[:2] - a[:2]
        hn = math.hypot(*h)
        cur = [(p.speed * math.cos(p.heading_rad), p.speed * math.sin(p.heading_rad))
               for p in env.current if p.speed > 0.0]
        if hn > 1e-12 * max(1.0, mesh.length):
            ux = h / hn
        elif cur:
            c = np.sum(np.asarray(cur), axis=0)
            cn = math.hypot(*c)
            ux = c / cn if cn > 0 else np.array([1.0, 0.0])
        else:
            ux = np.array([1.0, 0.0])
        self.Q = np.array([[ux[0], ux[1], 0.0], [-ux[1], ux[0], 0.0], [0.0, 0.0, 1.0]])
        self.origin = np.array([a[0], a[1], 0.0])
        out_of_plane = any(abs(-ux[1] * cx + ux[0] * cy) > 1e-12 * math.hypot(cx, cy)
                           for cx, cy in cur)
        self.dim = 3 if (force_3d or out_of_plane) else 2
        self.cols = [0, 1, 2] if self.dim == 3 else [0, 2]

    def to_local(self, X: np.ndarray) -> np.ndarray:
        return ((X - self.origin) @ self.Q.T)[:, self.cols]

    def to_global(self, Xl: np.ndarray) -> np.ndarray:
        full = np.zeros((Xl.shape[0], 3))
        full[:, self.cols] = Xl
        return full @ self.Q + self.origin

    def vec_to_global(self, v: np.ndarray) -> np.ndarray:
        full = np.zeros(3)
        full[self.cols] = v
        return full @ self.Q


# -------------------------------------------------------------------------- FE model


class _Model:
    """Residual and banded tangent of the FE statics of one line (local frame)."""

    def __init__(self, mesh: LineMesh, env: Environment, frame: _Frame) -> None:
        self.n = mesh.n_nodes
        self.dim = dim = frame.dim
        self.zi = dim - 1
        self.l0 = mesh.l0
        self.ea = mesh.ea
        self.w_sub = mesh.weight
        self.w_dry = mesh.mass * env.g
        self.node_fz = mesh.node_buoyancy - mesh.node_mass * env.g
        self.zbed = -env.depth
        trib_kd = 0.5 * mesh.l0 * mesh.diameter * env.seabed.stiffness
        kb = np.zeros(self.n)
        kb[:-1] += trib_kd
        kb[1:] += trib_kd
        self.kb = kb
        # current profile in the local frame
        pts = sorted((p for p in env.current), key=lambda p: p.z)
        self.has_current = any(p.speed > 0 for p in pts)
        if self.has_current:
            self.cz = np.array([p.z for p in pts])
            uv = np.array([[p.speed * math.cos(p.heading_rad),
                            p.speed * math.sin(p.heading_rad), 0.0] for p in pts])
            loc = uv @ frame.Q.T
            self.cu = loc[:, frame.cols]  # (n_pts, dim)
        self.c_n = 0.5 * env.rho * mesh.cd_normal * mesh.diameter
        self.c_t = 0.5 * env.rho * mesh.cd_axial * math.pi * mesh.diameter
        self.c_node = 0.5 * env.rho * mesh.node_drag_area
        self.has_drag = self.has_current and (
            bool(np.any(self.c_n > 0)) or bool(np.any(self.c_t > 0))
            or bool(np.any(self.c_node > 0)))
        # load-stepping factor of the drag (1 = full current)
        self.beta = 1.0
        self._band_index()

    # ---- loads that do not depend on position, for the reference force
    def weight_scale(self) -> float:
        """Σ max(|w_sub|, |w_dry|)·l0 + Σ |node loads| (position-independent: computed
        once per model; the Newton asks for it at every residual test). [N]"""
        ws = self.__dict__.get("_weight_scale")
        if ws is None:
            w = np.maximum(np.abs(self.w_sub), np.abs(self.w_dry))
            ws = self._weight_scale = float(np.sum(w * self.l0)
                                            + np.sum(np.abs(self.node_fz)))
        return ws

    def energy(self, X: np.ndarray) -> float:
        """Potential energy of the conservative loads (all but drag); -grad = R - drag."""
        zi, l0 = self.zi, self.l0
        d = X[1:] - X[:-1]
        l = np.sqrt(np.einsum("ij,ij->i", d, d))
        strain = l / l0 - 1.0
        eae = np.where(strain > 0.0, self.ea, self.ea * SLACK_FACTOR)
        z = X[:, zi]
        za, zb = z[:-1], z[1:]
        wet = (za <= 0.0) & (zb <= 0.0)
        W = l0 * np.where(wet, self.w_sub, self.w_dry)
        pen = np.maximum(self.zbed - z, 0.0)
        return float(0.5 * np.sum(eae * l0 * strain**2) + np.sum(W * 0.5 * (za + zb))
                     - np.sum(self.node_fz * z) + 0.5 * np.sum(self.kb * pen**2))

    def current(self, z: np.ndarray) -> np.ndarray:
        u = np.empty(z.shape + (self.dim,))
        for k in range(self.dim):
            u[:, k] = np.interp(z, self.cz, self.cu[:, k])
        u[z > 0.0] = 0.0
        return u

    def _band_index(self) -> None:
        dim, nf = self.dim, self.n - 2
        bw = 2 * dim - 1
        self.bw = bw
        self.band_rows, self.band_cols = _block_band_indices(nf, dim)

    _memo: dict | None = None

    def forces(self, X: np.ndarray, tangent: bool = True) -> tuple:
        """Nodal residual forces R (n, dim) (force on each node, zero at equilibrium),
        element tensions, drag magnitude, and the tangent blocks -dR/dX.

        The residual of the last position is remembered: the Newton iteration asks for
        it twice at every accepted point (line search, then with the tangent) and the
        result once more; a repeated call (same X and drag factor) reuses it and only
        adds the tangent (the same numbers, ≈ 0.4 ms of the reference chain's
        statics)."""
        memo = self._memo
        if (memo is not None and memo["beta"] == self.beta and memo["X"].shape == X.shape
                and np.array_equal(memo["X"], X)):
            if self.has_drag:
                self.drag_nodes = memo["drag_nodes"].copy()
            R = memo["R"].copy()
        else:
            memo = self._residual(X)
            self._memo = memo
            R = memo["R"].copy()
        if not tangent:
            return R, memo["T"], memo["drag"], None
        return R, memo["T"], memo["drag"], self._tangent(memo)

    def _residual(self, X: np.ndarray) -> dict:
        """The residual part of :meth:`forces` and the intermediates of the tangent."""
        zi, l0 = self.zi, self.l0
        beta = self.beta
        d = X[1:] - X[:-1]
        l = np.sqrt(np.einsum("ij,ij->i", d, d))
        e = d / l[:, None]
        strain = l / l0 - 1.0
        taut = strain > 0.0
        eae = np.where(taut, self.ea, self.ea * SLACK_FACTOR)
        T = eae * strain
        Fe = T[:, None] * e
        R = np.zeros_like(X)
        R[:-1] += Fe
        R[1:] -= Fe
        # weight, wet fraction of each element
        z = X[:, zi]
        za, zb = z[:-1], z[1:]
        w_sub, w_dry = self.w_sub, self.w_dry
        mixed = (np.minimum(za, zb) < 0.0) & (np.maximum(za, zb) > 0.0)
        if mixed.any():
            dz = np.where(mixed, zb - za, 1.0)
            f = np.where(za <= 0.0, 1.0, 0.0) * np.where(zb <= 0.0, 1.0, 0.0)
            f = np.where(mixed, -np.minimum(za, zb) / np.abs(dz), f)
            W = l0 * (w_dry + f * (w_sub - w_dry))
            # derivatives of the wet fraction, mixed elements only
            dfa = np.where(mixed, np.where(za < zb, -zb, zb) / dz**2, 0.0)
            dfb = np.where(mixed, np.where(za < zb, za, -za) / dz**2, 0.0)
        else:
            wet = (za <= 0.0) & (zb <= 0.0)
            W = l0 * np.where(wet, w_sub, w_dry)
        R[:-1, zi] -= 0.5 * W
        R[1:, zi] -= 0.5 * W
        R[:, zi] += self.node_fz
        drag = 0.0
        if self.has_drag:
            u = self.current(0.5 * (za + zb))
            ua = np.einsum("ij,ij->i", u, e)
            un = u - ua[:, None] * e
            unn = np.sqrt(np.einsum("ij,ij->i", un, un))
            g = ((self.c_n * unn)[:, None] * un
                 + (self.c_t * np.abs(ua) * ua)[:, None] * e)
            Fd = beta * l[:, None] * g
            R[:-1] += 0.5 * Fd
            R[1:] += 0.5 * Fd
            un_node = self.current(z)
            Fn = beta * (self.c_node * np.sqrt(np.einsum("ij,ij->i", un_node, un_node)))[:, None] * un_node
            R += Fn
            self.drag_nodes = np.zeros_like(X)
            self.drag_nodes[:-1] += 0.5 * Fd
            self.drag_nodes[1:] += 0.5 * Fd
            self.drag_nodes += Fn
            drag = float(np.sum(np.sqrt(np.einsum("ij,ij->i", Fd, Fd)))
                         + np.sum(np.abs(Fn)))
        pen = self.zbed - z
        contact = pen > 0.0
        R[:, zi] += np.where(contact, self.kb * pen, 0.0)
        st = {"X": X.copy(), "beta": beta, "R": R, "T": T, "drag": drag, "e": e, "l": l,
              "eae": eae, "mixed": mixed, "pen": pen}
        if mixed.any():
            st["dfa"], st["dfb"] = dfa, dfb
        if self.has_drag:
            st.update(u=u, ua=ua, un=un, unn=unn, g=g, drag_nodes=self.drag_nodes.copy())
        return st

    def _tangent(self, st: dict) -> tuple:
        """Tangent blocks (Kd, Ku, Kl) = −dR/dX from the intermediates of
        :meth:`_residual`."""
        dim, zi, l0 = self.dim, self.zi, self.l0
        beta = st["beta"]
        e, l, eae, T, mixed, pen = (st[k] for k in ("e", "l", "eae", "T", "mixed", "pen"))
        w_sub, w_dry = self.w_sub, self.w_dry
        if self.has_drag:
            u, ua, un, unn, g = (st[k] for k in ("u", "ua", "un", "unn", "g"))
        if mixed.any():
            dfa, dfb = st["dfa"], st["dfb"]
        I = np.eye(dim)
        ee = e[:, :, None] * e[:, None, :]
        k = (eae / l0)[:, None, None] * ee + (T / l)[:, None, None] * (I - ee)
        Kd = np.zeros((self.n, dim, dim))
        Kd[:-1] += k
        Kd[1:] += k
        Ku = -k
        Kl = -k.copy()
        if self.has_drag:
            # D = dF/dd = g eᵀ + (dg/de)(I - e eᵀ)
            safe = np.where(unn > 0.0, unn, 1.0)
            A = (unn[:, None, None] * I
                 + np.where(unn > 0.0, 1.0 / safe, 0.0)[:, None, None]
                 * un[:, :, None] * un[:, None, :])
            B = e[:, :, None] * u[:, None, :] + ua[:, None, None] * I
            dg = (-self.c_n[:, None, None] * (A @ B)
                  + (self.c_t * np.abs(ua))[:, None, None]
                  * (2.0 * e[:, :, None] * u[:, None, :] + ua[:, None, None] * I))
            D = beta * (g[:, :, None] * e[:, None, :] + dg @ (I - ee))
            Kd[:-1] += 0.5 * D
            Kd[1:] -= 0.5 * D
            Ku = Ku - 0.5 * D
            Kl = Kl + 0.5 * D
        if mixed.any():
            dWa = 0.5 * l0 * (w_sub - w_dry) * dfa
            dWb = 0.5 * l0 * (w_sub - w_dry) * dfb
            Kd[:-1, zi, zi] += dWa
            Kd[1:, zi, zi] += dWb
            Ku[:, zi, zi] += dWb
            Kl[:, zi, zi] += dWa
        # nodes resting exactly on the bed get the contact stiffness too
        Kd[:, zi, zi] += np.where(pen >= 0.0, self.kb, 0.0)
        return Kd, Ku, Kl

    def band(self, K: tuple, lam: float) -> np.ndarray:
        """The free–free tangent (+ the relaxation λ) in the layout of
        :func:`_banded_solve`: rows ``bw:`` the general banded storage
        (``A[i, j] -> ab[2·bw + i − j, j]``), rows ``:bw`` zeros (LAPACK's room for
        the fill-in of the pivoting)."""
        Kd, Ku, Kl = K
        nf = self.n - 2
        N = nf * self.dim
        bw = self.bw
        ab = np.zeros((3 * bw + 1, N), order="F")
        vals = np.concatenate([Kd[1:-1].ravel(), Ku[1:-1].ravel(), Kl[1:-1].ravel()])
        ab[self.band_rows + bw, self.band_cols] = vals
        if lam > 0.0:
            diag = np.abs(ab[2 * bw])
            ab[2 * bw] += lam * (diag + 1e-3 * float(np.mean(diag)))
        return ab


#: LAPACK dgbsv (general banded LU with partial pivoting and solve).
_GBSV = get_lapack_funcs(("gbsv",), (np.zeros(1),))[0]


def _banded_solve(ab: np.ndarray, b: np.ndarray, bw: int) -> np.ndarray:
    """x of A x = b, A banded with ``bw`` sub- and super-diagonals, given as ``ab`` of
    shape (3·bw + 1, N): rows ``bw:`` its general banded storage
    (``A[i, j] -> ab[2·bw + i − j, j]``), rows ``:bw`` zeros; ``ab`` is overwritten.

    LAPACK gbsv directly: the call ``scipy.linalg.solve_banded((bw, bw), ab[bw:], b)``
    makes after its validation and copy into that layout (bw >= 2), so the same
    numbers, without ≈ 30 µs of wrapper per solve (≈ 40 solves per body statics).
    N >= 2.  Raises LinAlgError when A is singular."""
    _, _, x, info = _GBSV(bw, bw, ab, b, overwrite_ab=True, overwrite_b=False)
    if info > 0:
        raise LinAlgError("singular matrix")
    if info < 0:
        raise ValueError(f"illegal value in {-info}-th argument of internal gbsv")
    return x


@functools.lru_cache(maxsize=64)
def _block_band_indices(nf: int, dim: int) -> tuple[np.ndarray, np.ndarray]:
    """Rows and columns in LAPACK general banded storage (l = u = 2·dim − 1) of the
    entries of a block-tridiagonal matrix of nf × nf blocks dim × dim, in the order:
    the diagonal blocks, the upper blocks (q, q + 1), the lower blocks (q + 1, q), each
    block row-major (``A[i, j] -> ab[bw + i − j, j]``).  Cached (read-only arrays)."""
    bw = 2 * dim - 1
    p = np.arange(nf)[:, None, None]
    a = np.arange(dim)[None, :, None]
    b = np.arange(dim)[None, None, :]
    rd = np.broadcast_to(bw + a - b, (nf, dim, dim))
    cd = np.broadcast_to(p * dim + b, (nf, dim, dim))
    q = np.arange(max(nf - 1, 0))[:, None, None]
    ru = np.broadcast_to(bw + a - b - dim, (q.shape[0], dim, dim))
    cu = np.broadcast_to((q + 1) * dim + b, (q.shape[0], dim, dim))
    rl = np.broadcast_to(bw + dim + a - b, (q.shape[0], dim, dim))
    cl = np.broadcast_to(q * dim + b, (q.shape[0], dim, dim))
    rows = np.concatenate([rd.ravel(), ru.ravel(), rl.ravel()])
    cols = np.concatenate([cd.ravel(), cu.ravel(), cl.ravel()])
    rows.flags.writeable = False
    cols.flags.writeable = False
    return rows, cols


def _reference_force(model: _Model, T: np.ndarray, drag: float) -> float:
    return model.weight_scale() + float(np.max(np.abs(T))) + drag


class _Solver:
    """Newton with line search, then viscous relaxation (seed 001 eqs. 4.1.5-4.1.8)."""

    def __init__(self, model: _Model, tol: float, budget: int) -> None:
        self.m = model
        self.tol = tol
        self.budget = budget
        self.used = 0
        scale = float(np.max(model.ea / model.l0))
        self._floor_k = 8.0 * _EPS * scale

    def status(self, X: np.ndarray, tangent: bool = True
               ) -> tuple[float, float, np.ndarray, tuple | None]:
        """Relative residual, tolerance (raised to the round-off floor), nodal
        residual and, with ``tangent``, the tangent blocks (else None: a converged
        point needs no tangent; ``m.forces(X)`` adds it later from the memo)."""
        R, T, drag, K = self.m.forces(X, tangent=tangent)
        ref = _reference_force(self.m, T, drag)
        r = float(np.max(np.abs(R[1:-1]))) / ref if self.m.n > 2 else 0.0
        floor = self._floor_k * float(np.max(np.abs(X))) / ref
        return r, max(self.tol, floor), R, K

    def _step(self, R: np.ndarray, K: tuple, lam: float) -> np.ndarray | None:
        ab = self.m.band(K, lam)
        try:
            dx = _banded_solve(ab, R[1:-1].ravel(), self.m.bw)
        except (LinAlgError, ValueError):
            return None
        if not np.all(np.isfinite(dx)):
            return None
        return dx.reshape(-1, self.m.dim)

    def solve(self, X: np.ndarray, limit: int) -> tuple[bool, np.ndarray, float]:
        """Iterate from X; returns (converged, X, relative residual)."""
        m = self.m
        if m.n <= 2:
            return True, X, 0.0
        X = X.copy()
        r, tol, R, K = self.status(X, tangent=False)
        if r <= tol:
            return True, X, r
        span = float(np.sum(m.l0))
        cap = 0.25 * span
        lam = 0.0
        phi = float(np.sum(R[1:-1] ** 2))
        # the energy at X only matters when a trial step fails the residual test: on
        # demand (Newton from the chain start takes full steps, 0.1 ms of energies)
        energy: float | None = None
        fd = m.drag_nodes.copy() if m.has_drag else None
        best = (r, X.copy())
        for _ in range(limit):
            if self.used >= self.budget:
                break
            self.used += 1
            if K is None:
                # the tangent at X, from the residual memo of the status at X (the
                # same numbers as computing it with the status)
                K = m.forces(X)[3]
            dx = self._step(R, K, lam)
            if dx is None:
                lam = max(10.0 * lam, 1e-3)
                continue
            big = float(np.max(np.sqrt(np.sum(dx * dx, axis=1))))
            t = min(1.0, cap / big) if big > 0 else 1.0
            slope = float(np.sum(R[1:-1] * dx))  # -dPi/dt along dx
            accepted = False
            # backtracking line search: accept a decrease of the total potential energy
            # (Armijo, when the loads are conservative) or of the residual norm
            for _ls in range(10):
                Xt = X.copy()
                Xt[1:-1] += t * dx
                Rt = m.forces(Xt, tangent=False)[0]
                phit = float(np.sum(Rt[1:-1] ** 2))
                if not np.isfinite(phit):
                    t *= 0.5
                    continue
                if phit <= (1.0 - 1e-4 * t) * phi:
                    accepted = True
                elif slope > 0.0:
                    # energy with the drag frozen at X (its work t·Fd·dx): exact for
                    # conservative loads, a local merit of the follower drag
                    et = m.energy(Xt)
                    if fd is not None:
                        et -= t * float(np.sum(fd[1:-1] * dx))
                    if energy is None:
                        energy = m.energy(X)
                    accepted = et <= energy - 1e-4 * t * slope
                if accepted:
                    break
                t *= 0.5
            if not accepted:
                # Newton stalls: viscous relaxation, artificial damping C ∝ diag(K)
                # (seed 001 eqs. 4.1.5-4.1.8), stiffened until a step is taken
                lam = max(4.0 * lam, 1e-2)
                continue
            X = Xt
            r, tol, R, K = self.status(X, tangent=False)
            phi = float(np.sum(R[1:-1] ** 2))
            energy = None
            if fd is not None:
                fd = m.drag_nodes.copy()
            if r < best[0]:
                best = (r, X.copy())
            if r <= tol:
                return True, X, r
            if lam > 0.0 and _ls == 0:
                # relax the damping toward zero (pure Newton) while full steps succeed
                lam *= 0.3
                if lam < 1e-6:
                    lam = 0.0
        return False, best[1], best[0]


def _straight(a: np.ndarray, b: np.ndarray, frac: np.ndarray) -> np.ndarray:
    return a + frac[:, None] * (b - a)


def _initial_guess(mesh: LineMesh, env: Environment, frame: _Frame,
                   model: _Model) -> np.ndarray:
    """A hanging (parabolic) or straight initial shape in the local frame, (n, dim)."""
    a = frame.to_local(mesh.end_a[None, :])[0]
    b = frame.to_local(mesh.end_b[None, :])[0]
    frac = mesh.s0 / mesh.length
    chord = float(np.linalg.norm(b - a))
    L = mesh.length
    if L <= chord * (1.0 + 1e-9):
        return _straight(a, b, frac)
    guess = _chain_guess(mesh, env, frame, model, a, b)
    if guess is not None:
        return guess
    zi = frame.dim - 1
    sign = 1.0 if float(np.sum(mesh.weight * mesh.l0)) >= 0.0 else -1.0
    xi = np.linspace(0.0, 1.0, 401)
    base = _straight(a, b, xi)
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


def _chain_shots(mesh: LineMesh, model: _Model, a: np.ndarray, zi: int, on_bed: bool,
                 kb: np.ndarray) -> tuple[Any, Any]:
    """The shots of :func:`_chain_guess`: ``shoot(H, V0, P) -> (x, z)`` the node
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
        z[1:k_star + 1] = zbed - pen[1:k_star + 1]
        if k_star < V.size:
            z[k_star + 1:] = z[k_star] + np.cumsum(dz[k_star:])
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


def _chain_guess(mesh: LineMesh, env: Environment, frame: _Frame, model: _Model,
                 a: np.ndarray, b: np.ndarray) -> np.ndarray | None:
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
    continuous catenary of the mean weight (:func:`stochcable.line.catenary.catenary_solve`),
    or, when the kinks of the closure stall it, by nested bracketing
    (:func:`_chain_closure`).  The weights follow the wet fraction of each element at
    the shape found (re-solved up to three times).  Drag is ignored (a start only).

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
    on_bed = (a[zi] <= zbed * (1.0 - 1e-9) and Z > 0.0 and env.seabed.stiffness > 0.0)
    l0, ea = mesh.l0, mesh.ea
    kb = np.where(model.kb > 0.0, model.kb, np.inf)

    def loads(W: np.ndarray) -> np.ndarray:
        P = -model.node_fz.copy()
        P[:-1] += 0.5 * W
        P[1:] += 0.5 * W
        return P

    shoot, shoot_ends = _chain_shots(mesh, model, a, zi, on_bed, kb)

    W = l0 * model.w_sub
    P = loads(W)
    scale = max(L, 1.0)
    for _pass in range(3):
        HV = _chain_newton(shoot, P, float(b[0]), float(b[zi]), X, Z, L, l0, ea,
                           on_bed, scale, shoot_ends)
        if HV is None:
            HV = _chain_closure(shoot, P, float(b[0]), float(b[zi]), scale)
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
    if float(np.min(z[1:-1], initial=0.0)) < zbed - 10.0 * float(np.max(
            np.abs(P) / kb, initial=0.0)) - 1e-9 * max(env.depth, 1.0):
        return None  # passes through the seabed away from end_a
    Xg[0], Xg[-1] = a, b
    return Xg


def _chain_newton(shoot, P: np.ndarray, xb: float, zb: float, X: float, Z: float,
                  L: float, l0: np.ndarray, ea: np.ndarray, on_bed: bool,
                  scale: float, shoot_ends: Any = None) -> tuple[float, float] | None:
    """(H, V_0) of the lumped chain by damped Newton on the end closure, started from
    the continuous catenary of the mean weight; None when it fails (kinks where an
    element lifts off the bed can stall it; :func:`_chain_closure` then brackets).
    ``shoot_ends(H, V0, P)``: the end nodes of several shots at once (the four shots
    of the central-difference Jacobian in one call, the same numbers)."""
    from stochcable.line.catenary import catenary_solve

    w_mean = float(np.sum(P)) / L
    try:
        sol = catenary_solve(X, Z, L, w_mean, L / float(np.sum(l0 / ea)),
                             seabed=on_bed and w_mean > 0.0)
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
            ends = shoot_ends(np.array([math.exp(p[0]) for p in pts]),
                              np.array([p[1] for p in pts]), P)
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


def _chain_closure(shoot, P: np.ndarray, xb: float, zb: float,
                   scale: float) -> tuple[float, float] | None:
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
        return brentq(lambda v: shoot(H, v, P)[1][-1] - zb, lo, hi, xtol=1e-15 * load,
                      rtol=4 * _EPS, maxiter=200)

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


def _solve_fe(mesh: LineMesh, env: Environment, initial: np.ndarray | None,
              tol: float, budget: int, force_3d: bool = False) -> LineStatics:
    frame = _Frame(mesh, env, force_3d=force_3d)
    model = _Model(mesh, env, frame)
    if initial is not None:
        X0 = frame.to_local(initial)
    else:
        X0 = _initial_guess(mesh, env, frame, model)
    X0[0] = frame.to_local(mesh.end_a[None, :])[0]
    X0[-1] = frame.to_local(mesh.end_b[None, :])[0]
    solver = _Solver(model, tol, budget)
    # with current, a first attempt at full load gets a quarter of the budget; the
    # rest goes to load stepping of the drag from the equilibrium without current
    ok, X, r = solver.solve(X0, budget // 4 if model.has_drag else budget)
    if not ok and model.has_drag and solver.used < budget:
        X, r, ok = _drag_stepping(solver, model, X0, budget)
    if not ok:
        note = ""
        if model.has_drag and bool(np.any(X[1:-1, frame.dim - 1] < model.zbed)):
            note = ("; part of the line lies on the seabed, where no friction is modelled: "
                    "drag on a grounded slack part may have no horizontal restoring force")
        raise ConvergenceError(
            "statics Newton", solver.used, r, tol,
            hint=(f"line {mesh.name!r}: check that the line can reach its ends and that "
                  "the loads are physical, give a better initial shape, raise "
                  f"max_iterations or refine the mesh{note}"),
            partial=frame.to_global(X),
        )
    return _fe_result(mesh, env, frame, model, X, solver.used, r)


def _drag_stepping(solver: "_Solver", model: _Model, X0: np.ndarray,
                   budget: int) -> tuple[np.ndarray, float, bool]:
    """Load stepping of the current (seed 001 §4.1, eq. 4.1.2 applied per increment).

    The drag is scaled by a factor beta (model.beta) raised from 0 (the equilibrium
    without current, whose start is the exact lumped chain) to 1; each increment is
    solved by Newton from the previous equilibrium, the step doubled after a success
    (up to 0.5) and halved after a failure (down to 1/256).  Returns the last state,
    its residual and whether beta = 1 was reached.
    """
    beta_ok = 0.0
    model.beta = 0.0
    ok, X_ok, r = solver.solve(X0, budget)
    step = 0.25
    while ok and beta_ok < 1.0 and solver.used < budget and step >= 1.0 / 256:
        model.beta = min(1.0, beta_ok + step)
        ok_s, X_s, r = solver.solve(X_ok, 50)
        if ok_s:
            beta_ok, X_ok = model.beta, X_s
            step = min(2.0 * step, 0.5)
        else:
            step *= 0.5
    model.beta = 1.0
    r = solver.status(X_ok)[0]
    return X_ok, r, bool(ok and beta_ok >= 1.0)


def _fe_result(mesh: LineMesh, env: Environment, frame: _Frame, model: _Model,
               X: np.ndarray, iterations: int, r: float) -> LineStatics:
    R, T, _, _ = model.forces(X, tangent=False)
    zi = frame.dim - 1
    z = X[:, zi]
    zbed = -env.depth
    ztol = 1e-9 * max(env.depth, 1.0)
    grounded = z <= zbed + ztol
    # An end node resting on the seabed: the bed, not the support, carries the weight
    # lumped on that node, so the end force is the line's own (continuous) end force.
    Ra, Rb = R[0].copy(), R[-1].copy()
    if grounded[0]:
        Ra[zi] += 0.5 * mesh.l0[0] * mesh.weight[0] - model.node_fz[0]
    if grounded[-1]:
        Rb[zi] += 0.5 * mesh.l0[-1] * mesh.weight[-1] - model.node_fz[-1]
    fa = frame.vec_to_global(Ra)
    fb = frame.vec_to_global(Rb)
    tension = np.where(T > 0.0, T, 0.0)
    ta, tb = float(np.linalg.norm(fa)), float(np.linalg.norm(fb))
    node_t = np.empty(mesh.n_nodes)
    node_t[1:-1] = 0.5 * (tension[:-1] + tension[1:])
    node_t[0], node_t[-1] = ta, tb
    touchdown = _touchdown(mesh, X, T, zi, grounded)
    pos = frame.to_global(X)
    pos[0], pos[-1] = mesh.end_a, mesh.end_b
    return LineStatics(
        mesh=mesh, positions=pos, tension=tension, node_tension=node_t,
        force_a=fa, force_b=fb, tension_a=ta, tension_b=tb, grounded=grounded,
        touchdown=touchdown, iterations=iterations, residual=r, method="fe",
    )


def _touchdown(mesh: LineMesh, X: np.ndarray, T: np.ndarray, zi: int,
               grounded: np.ndarray) -> float | None:
    """Arc length where the line leaves the seabed toward end_b.

    Interpolated from the vertical tension component of the first suspended element k:
    along a catenary V(s) = w (s - s_td), and the element tension of a lumped chain is
    the continuous tension at the element midpoint, so s_td = s_mid,k - V_k / w_k.
    """
    inner = np.flatnonzero(grounded[1:-1]) + 1
    if inner.size == 0:
        return None
    g = int(inner[-1])
    if g >= mesh.n_nodes - 1 or grounded[g + 1]:
        return float(mesh.s0[g])
    k = g  # element from node g to g + 1
    d = X[k + 1] - X[k]
    vz = T[k] * d[zi] / float(np.linalg.norm(d))
    w = mesh.weight[k]
    s_mid = 0.5 * (mesh.s0[k] + mesh.s0[k + 1])
    s = s_mid - vz / w if w > 0 else mesh.s0[g]
    lo = mesh.s0[g - 1] if g >= 1 else mesh.s0[0]
    return float(min(max(s, lo), mesh.s0[g + 1]))


# ---------------------------------------------------------------------- catenary path


def _catenary_inapplicable(mesh: LineMesh, env: Environment) -> str | None:
    """None when the closed-form catenary applies to the line, else the reason."""
    if np.unique(mesh.segment).size > 1:
        return "it has more than one segment"
    if np.any(mesh.node_mass != 0.0) or np.any(mesh.node_buoyancy != 0.0):
        return "it has attachments"
    if any(p.speed > 0.0 for p in env.current):
        return "there is a current"
    if not (float(mesh.weight[0]) > 0.0):
        return "its net submerged weight is not positive"
    if max(mesh.end_a[2], mesh.end_b[2]) > 0.0:
        return "an end is above the still-water level"
    if math.hypot(*(mesh.end_b[:2] - mesh.end_a[:2])) <= 1e-9 * mesh.length:
        return "its ends are vertically aligned"
    return None


def _solve_catenary(mesh: LineMesh, env: Environment) -> LineStatics | str:
    """Closed-form elastic catenary at the mesh nodes; a reason string when the free
    catenary would pass below the seabed (contact away from end_a needs the FE)."""
    from stochcable.line.catenary import catenary_line

    cl = catenary_line(mesh, env)
    sol = cl.solution
    pos = cl.positions
    depth = env.depth
    ztol = 1e-9 * max(depth, 1.0)
    if sol.touchdown <= 0.0 and float(np.min(pos[:, 2])) < -depth - ztol:
        return "the free catenary passes below the seabed"
    d = mesh.end_b - mesh.end_a
    e_h = np.array([d[0], d[1], 0.0]) / math.hypot(d[0], d[1])
    ez = np.array([0.0, 0.0, 1.0])
    fa = sol.H * e_h + sol.V_a * ez
    fb = -sol.H * e_h - sol.V_b * ez
    touchdown = float(sol.touchdown) if sol.touchdown > 0.0 else None
    grounded = pos[:, 2] <= -depth + ztol
    if touchdown is not None:
        grounded = grounded | (mesh.s0 <= touchdown)
    node_t = np.asarray(cl.node_tension, dtype=float).copy()
    node_t[0], node_t[-1] = sol.tension_a, sol.tension_b
    return LineStatics(
        mesh=mesh, positions=np.asarray(pos, dtype=float),
        tension=np.asarray(cl.element_tension, dtype=float), node_tension=node_t,
        force_a=fa, force_b=fb, tension_a=float(sol.tension_a),
        tension_b=float(sol.tension_b), grounded=grounded, touchdown=touchdown,
        iterations=sol.iterations,
        residual=float(sol.residual) / max(mesh.length, float(np.linalg.norm(d))),
        method="catenary",
    )
