"""Static equilibrium of lines: elastic catenary or finite-element Newton (Tuah (1982), §4.1).

The static shape is the configuration the dynamic analysis linearizes about (Tuah
(1982), ch. 4: "provide a stable starting configuration for a dynamic problem").  Two methods:

- ``"catenary"``: the closed-form elastic catenary (:mod:`stochcable.line.catenary`) for a
  single homogeneous segment between fixed points in a vertical plane, without current
  or attachments, with seabed contact when end_a lies on the seabed;
- ``"fe"``: a finite-element Newton solve over the mesh of 2-node straight elastic bars
  (Tuah (1982), §3.1) with lumped loads, for everything: several segments, clump weights
  and buoys, current drag, seabed contact, 3-D geometry.

``"auto"`` takes the catenary where it applies and the FE otherwise.  Both solve for
the *effective* tension: the weight is the net submerged weight per unit length
(weight in air minus the weight of displaced water), so the hydrostatic pressure field
is folded into the load and the tension reported is the effective tension.

References
----------
Tuah, H. (1982), Cable dynamics in an ocean environment, PhD thesis, Oregon State University.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Literal

import numpy as np

from stochcable.errors import ConvergenceError, InputError
from stochcable.line.chain import initial_guess
from stochcable.line.equilibrium import LocalFrame, StaticsModel, StaticsSolver
from stochcable.line.mesh import LineMesh
from stochcable.scene.model import Environment

__all__ = [
    "Method",
    "LineStatics",
    "solve_line_statics",
    "solve_line_statics_unchecked",
    "check_statics_options",
    "solve_fe",
]

Method = Literal["auto", "fe", "catenary"]


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
            "end_a": {"tension": float(self.tension_a), "force": [float(v) for v in self.force_a]},
            "end_b": {"tension": float(self.tension_b), "force": [float(v) for v in self.force_b]},
            "touchdown": None if self.touchdown is None else float(self.touchdown),
            "nodes": self.positions.tolist(),
            "s": self.mesh.s0.tolist(),
            "tension": self.tension.tolist(),
            "iterations": int(self.iterations),
            "residual": float(self.residual),
            "method": self.method,
        }


# ------------------------------------------------------------------------ public API


def check_statics_options(
    method: Any, tolerance: Any, max_iterations: Any
) -> tuple[Method, float, int]:
    """The checked options of the line statics, once per call of an entry point
    (:func:`solve_line_statics`, :func:`stochcable.statics.solve_statics`,
    :func:`stochcable.bodies.statics.solve_body_statics`).

    Returns
    -------
    method : {"auto", "fe", "catenary"}
    tolerance : float
        In (0, 1). [-]
    max_iterations : int
        >= 1. [-]

    Raises
    ------
    InputError
        An unknown method, a tolerance outside (0, 1), fewer than one iteration.
    """
    if method not in ("auto", "fe", "catenary"):
        raise InputError("method", method, "-", "must be 'auto', 'fe' or 'catenary'")
    tolerance = float(tolerance)
    if not (0.0 < tolerance < 1.0):
        raise InputError("tolerance", tolerance, "-", "must be in (0, 1)")
    if int(max_iterations) < 1:
        raise InputError("max_iterations", max_iterations, "-", "must be >= 1")
    return method, tolerance, int(max_iterations)


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
    The FE model (Tuah (1982), §3.1, DESIGN.md "Cable model") has the interior node
    positions as unknowns; the ends are fixed at their static positions (end motions
    are dynamic only).  Element force from the exact elastic bar,
    T = EA (l/l0 - 1) for l > l0 and T = eps EA (l/l0 - 1), eps = 1e-6, for a slack
    element (E -> eps, Tuah (1982), §6.2); consistent tangent
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
    shooting on (H, V_0), seabed contact from end_a included, see ``chain_guess``),
    which is the FE solution itself for planar lines without current; a parabola when
    it does not apply (vertical span, contact away from end_a).

    Solution (Tuah (1982), §4.1): Newton–Raphson on the residual feedback form
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
    method, tolerance, max_iterations = check_statics_options(method, tolerance, max_iterations)
    if initial is not None:
        initial = np.asarray(initial, dtype=float)
        if initial.shape != (mesh.n_nodes, 3) or not np.isfinite(initial).all():
            raise InputError(
                "initial", initial, "m", f"must be finite with shape ({mesh.n_nodes}, 3)"
            )
    return solve_line_statics_unchecked(
        mesh, environment, method, initial, tolerance, max_iterations
    )


def solve_line_statics_unchecked(
    mesh: LineMesh,
    environment: Environment,
    method: Method,
    initial: np.ndarray | None,
    tolerance: float,
    max_iterations: int,
) -> LineStatics:
    """:func:`solve_line_statics` with its options already checked
    (:func:`check_statics_options`): for the callers that solve many lines or the same
    line many times (the scene statics, the body statics at every trial pose).

    ``method`` one of "auto", "fe", "catenary"; ``initial`` None or finite floats of
    shape (n_nodes, 3) [m]; ``tolerance`` in (0, 1) [-]; ``max_iterations`` >= 1.
    Raises as :func:`solve_line_statics` for an undetermined line, a catenary asked
    for where it does not apply, and a FE solve that does not converge.
    """
    _check_determined(mesh, environment)
    if method != "fe":
        why = _catenary_inapplicable(mesh, environment)
        if why is None:
            out = _solve_catenary(mesh, environment)
            if isinstance(out, LineStatics):
                return out
            why = out
        if method == "catenary":
            raise InputError(
                "method",
                "catenary",
                "-",
                f"does not apply to line {mesh.name!r}: {why}; use 'fe' or 'auto'",
            )
    return solve_fe(mesh, environment, initial, tolerance, max_iterations)


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
    if np.all(mesh.weight == 0.0) and np.all(mesh.node_mass == 0.0) and L > chord * (1.0 + 1e-12):
        raise InputError(
            f"lines[{mesh.name!r}].length",
            L,
            "m",
            f"a weightless line longer than the distance between its ends ({chord:.6g} m) "
            "has an undetermined slack shape; shorten it or give it a weight",
        )
    on_bed = mesh.end_a[2] <= -env.depth * (1.0 - 1e-9)
    if not on_bed or Z < 0.0 or not np.any(mesh.weight > 0.0):
        return
    w, ea = float(mesh.weight[-1]), float(mesh.ea[-1])
    lv = 2.0 * Z / (1.0 + math.sqrt(1.0 + 2.0 * w * Z / ea))
    if L >= X + lv:
        raise InputError(
            f"lines[{mesh.name!r}].length",
            L,
            "m",
            f"the line is longer than its horizontal span plus its vertical hanging length "
            f"({X:.6g} m + {lv:.6g} m = {X + lv:.6g} m) with end_a on the seabed: the "
            "surplus lies slack on the seabed with zero horizontal tension, and without "
            "seabed friction (not modelled) the horizontal position of a fully slack "
            f"grounded line is undetermined; shorten the line below {X + lv:.6g} m or move "
            "the ends apart",
        )


def solve_fe(
    mesh: LineMesh,
    env: Environment,
    initial: np.ndarray | None,
    tol: float,
    budget: int,
    force_3d: bool = False,
    full_load_iterations: int | None = None,
) -> LineStatics:
    """The FE statics of :func:`solve_line_statics` (options already checked).

    ``initial`` None or finite node positions of shape (n_nodes, 3) [m], ``tol`` the
    relative residual [-], ``budget`` the total number of iterations [-];
    ``force_3d`` solves a planar line in 3-D.  With current, the first attempt at full
    drag gets ``full_load_iterations`` of the budget (default a quarter) before the
    drag is load-stepped from the current-free equilibrium; 0 goes straight to the
    load stepping (a test of the stepping that does not rely on the full-load Newton
    failing).  Raises ConvergenceError as :func:`solve_line_statics`.
    """
    frame = LocalFrame(mesh, env, force_3d=force_3d)
    model = StaticsModel(mesh, env, frame)
    if initial is not None:
        X0 = frame.to_local(initial)
    else:
        X0 = initial_guess(mesh, env, frame, model)
    X0[0] = frame.to_local(mesh.end_a[None, :])[0]
    X0[-1] = frame.to_local(mesh.end_b[None, :])[0]
    if model.has_lift and initial is None:
        X0 = _start_in_resultant_plane(model, X0)
    solver = StaticsSolver(model, tol, budget)
    # with current, a first attempt at full load gets a quarter of the budget; the
    # rest goes to load stepping of the drag from the equilibrium without current
    first = budget
    if model.has_drag:
        first = budget // 4 if full_load_iterations is None else int(full_load_iterations)
    ok, X, r = solver.solve(X0, first)
    if not ok and model.has_drag and solver.used < budget:
        X, r, ok = _drag_stepping(solver, model, X0, budget)
    if not ok:
        note = ""
        if model.has_drag and bool(np.any(X[1:-1, frame.dim - 1] < model.zbed)):
            note = (
                "; part of the line lies on the seabed, where no friction is modelled: "
                "drag on a grounded slack part may have no horizontal restoring force"
            )
        raise ConvergenceError(
            "statics Newton",
            solver.used,
            r,
            tol,
            hint=(
                f"line {mesh.name!r}: check that the line can reach its ends and that "
                "the loads are physical, give a better initial shape, raise "
                f"max_iterations or refine the mesh{note}"
            ),
            partial=frame.to_global(X),
        )
    return _fe_result(mesh, env, frame, model, X, solver.used, r)


def _start_in_resultant_plane(model: StaticsModel, X0: np.ndarray) -> np.ndarray:
    """The start turned about its chord into the plane of the resultant of the weight
    and the flow loads (drag and lift) on it: a lift that exceeds the weight puts the
    equilibrium above the chord, where Newton from the hanging start does not get
    (docs/travelling.md).  Unchanged when the line touches the seabed or its chord is
    within 25° of vertical."""
    from scipy.spatial.transform import Rotation  # only lines with lift

    a, b = X0[0], X0[-1]
    chord = (b - a) / np.linalg.norm(b - a)
    down = np.array([0.0, 0.0, -1.0]) - chord[2] * chord
    if np.linalg.norm(down) < math.sin(math.radians(25.0)) or np.any(X0[:, 2] <= model.zbed):
        return X0
    st = model._residual(X0)
    w = np.where(0.5 * (X0[:-1, 2] + X0[1:, 2]) <= 0.0, model.w_sub, model.w_dry)
    res = (st["l"][:, None] * st["g"]).sum(axis=0) - np.array([0.0, 0.0, float(w @ model.l0)])
    res = res - (res @ chord) * chord
    if np.linalg.norm(res) <= 0.0:
        return X0
    down /= np.linalg.norm(down)
    angle = math.atan2(float(np.cross(down, res) @ chord), float(down @ res))
    rot = Rotation.from_rotvec(angle * chord).as_matrix()
    return a + (X0 - a) @ rot.T


def _drag_stepping(
    solver: StaticsSolver, model: StaticsModel, X0: np.ndarray, budget: int
) -> tuple[np.ndarray, float, bool]:
    """Load stepping of the current (Tuah (1982), §4.1, eq. 4.1.2 applied per increment).

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


def _fe_result(
    mesh: LineMesh,
    env: Environment,
    frame: LocalFrame,
    model: StaticsModel,
    X: np.ndarray,
    iterations: int,
    r: float,
) -> LineStatics:
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
        mesh=mesh,
        positions=pos,
        tension=tension,
        node_tension=node_t,
        force_a=fa,
        force_b=fb,
        tension_a=ta,
        tension_b=tb,
        grounded=grounded,
        touchdown=touchdown,
        iterations=iterations,
        residual=r,
        method="fe",
    )


def _touchdown(
    mesh: LineMesh, X: np.ndarray, T: np.ndarray, zi: int, grounded: np.ndarray
) -> float | None:
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
    if mesh.axial_speed != 0.0 and np.any(mesh.cd_axial > 0.0):
        return "it travels with an axial drag"  # docs/travelling.md
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
    from stochcable.line.catenary import catenary_on_mesh

    cl = catenary_on_mesh(mesh, env)
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
        mesh=mesh,
        positions=np.asarray(pos, dtype=float),
        tension=np.asarray(cl.element_tension, dtype=float),
        node_tension=node_t,
        force_a=fa,
        force_b=fb,
        tension_a=float(sol.tension_a),
        tension_b=float(sol.tension_b),
        grounded=grounded,
        touchdown=touchdown,
        iterations=sol.iterations,
        residual=float(sol.residual) / max(mesh.length, float(np.linalg.norm(d))),
        method="catenary",
    )


# Former name of solve_line_statics_unchecked (ARCHITECTURE.md "Conventions"), kept importable.
line_statics = solve_line_statics_unchecked
