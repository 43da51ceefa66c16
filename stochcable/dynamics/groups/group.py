"""A coupled group and its solve at every frequency for given linear drag (Tuah
1982, §3.2.c, §3.3, §5.3).

Substructuring (exact at every frequency)
-----------------------------------------
Each attached line's response is linear in the motion u_e of its attached end nodes,
U = U_0 + G u_e, F_end = R_0 + R_e u_e (:mod:`stochcable.dynamics.groups.lineparts`).
The rigid link u_e = T(r) ξ (Tuah 1982, eqs. 3.3.6–3.3.7,
:func:`stochcable.bodies.rigid.rigid_link_matrix`) and the transformed body equation
(Tuah 1982, eq. 3.2.c.20 with eqs. 3.3.8–3.3.10) give, per frequency,

    [K_B − ω²(M_B + A(ω)) + iω(B(ω) + C_B) − Σ Tᵀ R_e T] ξ
        = F_exc + Tdᵀ diag(b) v + Σ Tᵀ R_0,

a dense (n_b × n_b) solve (Td, b, v: the drag point's rigid link, linear drag and
fluid velocity); then U follows.  This is the Schur complement of the coupled system
of :func:`stochcable.bodies.coupling.couple` on the body DOFs (tested equal to
:func:`stochcable.reference.bodies.solve_coupled_direct`), with the line interiors solved
by the line machinery: banded direct solve (``solver="direct"``) or Foss modal
superposition with the static correction of the truncated modes (``solver="foss"``,
Tuah (1982), §5.3).

Fixed body DOFs
---------------
``RigidBody.fixed_dofs`` are constraints: the body equation above is solved on the
free DOFs only (rows and columns of the fixed ones dropped) and ξ_j ≡ 0 for a fixed
j, under both solvers.

Frequency-dependent added mass and radiation damping
----------------------------------------------------
Because the body DOFs are always condensed exactly at every ω, the body's A(ω), B(ω)
are exact under both solvers; "foss" only approximates the line interiors (exact
when all modes are kept).

References
----------
Tuah, H. (1982), Cable dynamics in an ocean environment, PhD thesis, Oregon State University.
"""

from __future__ import annotations

import time
from collections.abc import Mapping, Sequence

import numpy as np

from stochcable.bodies.rigid import (
    PLANAR_INDEX,
    RigidBody,
    attachment_geometric_stiffness,
    rigid_link_matrix,
)
from stochcable.dynamics.groups.fixed_point_state import Evaluation, EvaluationCount, LineSolution
from stochcable.dynamics.groups.freeline import FreeLine
from stochcable.dynamics.groups.inputs import BodyLoads, CoupledLine, unit_channels
from stochcable.dynamics.groups.lineparts import LinePart, line_parts
from stochcable.dynamics.groups.modal_parts import FossLine, ModalLine, PartCache
from stochcable.dynamics.linearization.bodydrag import body_drag_matrix, linear_body_drag
from stochcable.dynamics.linearization.iteration import relative_change
from stochcable.dynamics.linearization.variance import drag_coefficients, sigmas_from_nodes
from stochcable.dynamics.loads.channels import Channel
from stochcable.dynamics.model.blocks import trapezoid_weights
from stochcable.dynamics.model.system import Damping, Progress
from stochcable.dynamics.solve.line_loads import line_inputs
from stochcable.dynamics.solve.node_inputs import LineInputs
from stochcable.errors import InputError, SolverError

__all__ = [
    "GroupSystem",
    "body_drag_matrix",
    "body_sigma",
    "linear_body_drag",
    "SigmaMap",
    "solve_group",
]


class _LazyInputs(dict):
    """Line name -> inputs of its channels plus its unit end-motion channels, built
    on first access."""

    def __init__(self, lines: Sequence[CoupledLine], phys: Mapping[str, LineInputs]) -> None:
        super().__init__()
        self._lines = {cl.name: cl for cl in lines}
        self._phys = phys

    def __missing__(self, name: str) -> LineInputs:
        cl = self._lines[name]
        units = unit_channels(cl)
        # a line without attached ends has no unit channels: its physical inputs
        value = line_inputs(cl.system, tuple(cl.channels) + units) if units else self._phys[name]
        self[name] = value
        return value


class GroupSystem:
    """A coupled group on a frequency grid: its lines, bodies, links and inputs.

    Parameters
    ----------
    lines : sequence of CoupledLine
        The group's lines (all with the group's channels).
    bodies : sequence of RigidBody
        The free bodies (static pose as ``position``; unique names).
    loads : mapping of str to BodyLoads
        Wave inputs of the bodies (missing: none).
    rho : float
        Water density for the body drag. [kg/m³]
    channels : sequence of Channel
        The group's channels on the grid (names, spectra).
    inp_phys : mapping of str to inputs, optional
        The lines' inputs of the physical channels (default built from the lines).
    weights : ndarray, shape (n_omega, n_ch), optional
        σ quadrature weights × spectra (default the trapezoid rule on the grid).

    Attributes
    ----------
    off : dict of str to int
        Offset of each body's DOFs in the group's body vector (size ``nb``).
    body_free : ndarray of int
        Body DOFs not held by ``RigidBody.fixed_dofs``.
    tmat : dict of str to ndarray, shape (d·n_att, nb)
        Per line the rigid links T of its attached ends.
    rows : dict of str to ndarray of int
        Per line its attached end rows among the support forces (2d).
    geometric : dict of str to ndarray, shape (d, d)
        Attachment geometric stiffness of the lines' static tensions on each body.
    kb, mb, cb : ndarray, shape (nb, nb)
        Body stiffness (hydrostatic + extra + geometric), mass, extra damping.
    z_body : ndarray, complex, shape (n_omega, nb, nb)
        K_B − ω²(M_B + A(ω)) + iω(C_B + B(ω)). [N/m, …]
    f_body : ndarray, complex, shape (n_omega, nb, n_ch)
        Wave excitation per channel. [N/unit, N·m/unit]
    drag : list of RigidBody
        The bodies with a drag area.
    sizes : dict of str to int
        Per line the size of its σ vector (set by the fixed point).
    start_drag : (ndarray, dict of str to Damping) or None
        The start σ of the fixed point and its drag per line, when already computed
        (reused by the evaluation at that very σ).
    modal_direct : bool
        The coarse stage's group: Foss lines as :class:`ModalLine`.
    modal_cache, foss_cache : dict of str to dict
        Per line the drag-independent arrays of :class:`ModalLine`/:class:`FossLine`
        (filled on the first evaluation).
    """

    def __init__(
        self,
        lines: Sequence[CoupledLine],
        bodies: Sequence[RigidBody],
        loads: Mapping[str, BodyLoads],
        rho: float,
        channels: Sequence[Channel],
        inp_phys: Mapping[str, LineInputs] | None = None,
        weights: np.ndarray | None = None,
    ) -> None:
        self.lines = tuple(lines)
        # the coarse stage's group (coarse.coarse_group): Foss lines solve their
        # modal equations per frequency (ModalLine), no Foss eigenproblem
        self.modal_direct = False
        # per line: the drag-independent arrays of ModalLine
        self.modal_cache: dict[str, PartCache] = {}
        # per line: the drag-independent arrays of FossLine (full grid)
        self.foss_cache: dict[str, PartCache] = {}
        self.bodies = tuple(bodies)
        self.rho = rho
        names = [b.name for b in bodies]
        if len(set(names)) != len(names):
            raise InputError("bodies", names, "-", "body names must be unique")
        self.by_name = {b.name: b for b in bodies}
        off, k = {}, 0
        for b in bodies:
            off[b.name] = k
            k += b.n_dof
        self.off = off
        self.nb = k
        # body DOFs not held by ``RigidBody.fixed_dofs`` (the fixed ones are ξ ≡ 0)
        self.body_free = np.array(
            [off[b.name] + i for b in bodies for i in b.free_index], dtype=int
        )
        self.channels = tuple(channels)
        self.n_ch = len(channels)
        self.omega = channels[0].omega
        self.weights = (
            trapezoid_weights(self.omega)[:, None]
            * np.stack([c.spectrum for c in channels], axis=1)
            if weights is None
            else weights
        )
        self.sizes: dict[str, int] = {}
        # (x, drag per line) of the fixed point's start when already computed (the
        # coarse subset's narrow-feature test): its first evaluation reuses them
        self.start_drag: tuple[np.ndarray, dict[str, Damping]] | None = None
        # per line: augmented inputs (built on first use: only the node-level paths
        # need them), link matrix T_l (d·n_att, nb), attached rows
        self.tmat, self.rows = {}, {}
        self.geometric = self._link_lines(names)
        # the physical channels alone, for the σ (the unit channels weigh zero)
        self.inp_phys = (
            {cl.name: line_inputs(cl.system, tuple(cl.channels)) for cl in self.lines}
            if inp_phys is None
            else dict(inp_phys)
        )
        self.inp: dict[str, LineInputs] = _LazyInputs(self.lines, self.inp_phys)
        self._body_matrices()
        # body loads (n_w, nb, n_ch), drag-point maps
        w = self.omega
        self.f_body = np.zeros((w.size, self.nb, self.n_ch), dtype=complex)
        self.drag = [b for b in bodies if np.any(b.drag_area > 0)]
        self.loads = dict(loads)
        for b in bodies:
            ld = loads.get(b.name)
            if ld is not None:
                s = slice(off[b.name], off[b.name] + b.n_dof)
                self.f_body[:, s, :] = ld.force
        self.emb = {}  # (6, d) embedding of a body's DOFs among the six
        for b in bodies:
            e = np.eye(6)
            self.emb[b.name] = e[:, list(PLANAR_INDEX)] if b.planar else e

    def _link_lines(self, names: list[str]) -> dict[str, np.ndarray]:
        """Check the lines, set their links ``tmat`` and attached ``rows``; return the
        attachment geometric stiffness per body."""
        geo = {b.name: np.zeros((b.n_dof, b.n_dof)) for b in self.bodies}
        for cl in self.lines:
            if [c.name for c in cl.channels] != [c.name for c in self.channels]:
                raise InputError(
                    f"lines[{cl.name}].channels",
                    [c.name for c in cl.channels],
                    "-",
                    "every line of a group needs the group's channels",
                )
            model = cl.system.model
            d = model.dim
            att = cl.attached()
            t = np.zeros((d * len(att), self.nb))
            rows = []
            for i, (k, bname) in enumerate(att):
                if bname not in self.by_name:
                    raise InputError(
                        f"lines[{cl.name}].{('end_a', 'end_b')[k]}",
                        bname,
                        "-",
                        f"is not a body; bodies: {names}",
                    )
                body = self.by_name[bname]
                if (d == 2) != body.planar:
                    raise InputError(
                        f"lines[{cl.name}]",
                        bname,
                        "-",
                        f"a {d}-D line model needs a {'planar' if d == 2 else '6-DOF'} body",
                    )
                node = 0 if k == 0 else model.n_nodes - 1
                r = model.positions[node] - body.position
                tl = rigid_link_matrix(r, planar=body.planar)
                o = self.off[bname]
                t[i * d : (i + 1) * d, o : o + body.n_dof] = tl
                st = cl.system.statics
                f = np.asarray(st.force_a if k == 0 else st.force_b, dtype=float)
                geo[bname] += attachment_geometric_stiffness(f, r, body.planar)
                rows.extend(range(k * d, (k + 1) * d))
            self.tmat[cl.name] = t
            self.rows[cl.name] = np.asarray(rows, dtype=int)
        return geo

    def _body_matrices(self) -> None:
        """K_B, M_B, C_B and the body impedance ``z_body`` on the grid."""
        nb, off, geo = self.nb, self.off, self.geometric
        if not nb:  # no bodies: empty matrices
            self.kb = self.mb = self.cb = np.zeros((0, 0))
            self.z_body = np.zeros((self.omega.size, 0, 0), dtype=complex)
            return
        self.kb = np.zeros((nb, nb))
        self.mb = np.zeros((nb, nb))
        self.cb = np.zeros((nb, nb))
        for b in self.bodies:
            s = slice(off[b.name], off[b.name] + b.n_dof)
            self.kb[s, s] = b.hydrostatic_stiffness + b.extra_stiffness + geo[b.name]
            self.mb[s, s] = b.mass_matrix()
            self.cb[s, s] = b.extra_damping
        w = self.omega
        a = np.zeros((w.size, nb, nb))
        bb = np.zeros((w.size, nb, nb))
        for b in self.bodies:
            s = slice(off[b.name], off[b.name] + b.n_dof)
            a[:, s, s] = b.added_mass_at(w)
            bb[:, s, s] = b.radiation_damping_at(w)
        w2 = (w * w)[:, None, None]
        iw = (1j * w)[:, None, None]
        self.z_body = self.kb[None] - w2 * (self.mb[None] + a) + iw * (self.cb[None] + bb)

    # ------------------------------------------------------------------ σ layout
    def split(self, x: np.ndarray) -> tuple[dict[str, np.ndarray], dict[str, np.ndarray]]:
        """The fixed-point vector as (per line σ, per drag body σ (3,)). [m/s]"""
        out, k = {}, 0
        for cl in self.lines:
            n = self.sizes[cl.name]
            out[cl.name] = x[k : k + n]
            k += n
        body = {}
        for b in self.drag:
            body[b.name] = x[k : k + 3]
            k += 3
        return out, body


def body_sigma(g: GroupSystem, body: RigidBody, xi: np.ndarray | None) -> np.ndarray:
    """σ of the relative velocity at a body's drag point.

    Parameters
    ----------
    g : GroupSystem
    body : RigidBody
        A body of ``g`` with a drag area.
    xi : ndarray, complex, shape (n_omega, nb, n_ch), or None
        The group's body motion per unit input; None: the body at rest.

    Returns
    -------
    ndarray, shape (3,)
        σ along x, y, z of fluid minus body velocity, over ``g.weights``. [m/s]
    """
    v = (
        g.loads[body.name].velocity
        if body.name in g.loads
        else np.zeros((g.omega.size, 3, g.n_ch), dtype=complex)
    )
    if xi is not None:
        s = slice(g.off[body.name], g.off[body.name] + body.n_dof)
        t = rigid_link_matrix(body.drag_point) @ g.emb[body.name]  # (3, d)
        v = v - (1j * g.omega)[:, None, None] * np.einsum("ij,wjc->wic", t, xi[:, s, :])
    var = np.einsum("wic,wc->i", np.abs(v) ** 2, g.weights)
    return np.sqrt(np.clip(var, 0.0, None))


def solve_group(
    g: GroupSystem,
    line_damping: Mapping[str, Damping],
    body_c: np.ndarray,
    body_b: Mapping[str, np.ndarray],
    timing: dict[str, float] | None,
    *,
    lazy: bool = False,
) -> tuple[dict[str, LineSolution], np.ndarray]:
    """One coupled solve of a group for given linear drag (module docstring).

    Parameters
    ----------
    g : GroupSystem
    line_damping : mapping of str to Damping
        Each line's linear drag.
    body_c : ndarray, shape (nb, nb)
        The bodies' drag damping on the body DOFs (:func:`body_drag_matrix`). [N·s/m, …]
    body_b : mapping of str to ndarray, shape (3,)
        Linear drag per direction of each drag body (the fluid-velocity load). [N·s/m]
    timing : dict, optional
        Accumulates ``solve_s``. [s]
    lazy : bool, optional
        A line without attached ends is returned as its
        :class:`~stochcable.dynamics.groups.freeline.FreeLine` (σ from the free
        nodes; node displacements and support forces formed on demand) instead of
        the pair (the drag fixed point).

    Returns
    -------
    lines : dict of str to (u, support)
        Per line the node displacements (n_nodes, d, n_w, n_ch) [m/unit] and support
        forces (n_w, 2d, n_ch) [N/unit] with its attached ends moving with the bodies
        (``lazy``: a FreeLine for a line without attached ends).
    xi : ndarray, complex, shape (n_w, nb, n_ch)
        Body motion per unit input. [m/unit, rad/unit]

    Raises
    ------
    SolverError
        A singular body impedance at some frequency.
    """
    t0 = time.perf_counter()
    if not g.nb:  # no bodies (a line alone): nothing to condense or solve for
        xi = np.zeros((g.omega.size, 0, g.n_ch), dtype=complex)
        parts = {cl.name: p for cl, (p, _, _) in zip(g.lines, line_parts(g, line_damping))}
        out = {
            n: p if lazy and isinstance(p, FreeLine) else _combine(g, p, xi)
            for n, p in parts.items()
        }
        _add_time(timing, t0)
        return out, xi
    s, rhs = _body_equation(g, body_c, body_b)
    parts = {}
    for cl, (part, r0, re) in zip(g.lines, line_parts(g, line_damping)):
        # the condensed line (summed in line order: the same bits with or without
        # the thread pool)
        t = g.tmat[cl.name]
        s = s - t.T[None] @ re @ t[None]
        rhs = rhs + t.T[None] @ r0
        parts[cl.name] = part
    xi = _solve_free_dofs(g, s, rhs)
    out = {
        cl.name: parts[cl.name]
        if lazy and isinstance(parts[cl.name], FreeLine)
        else _combine(g, parts[cl.name], g.tmat[cl.name][None] @ xi)
        for cl in g.lines
    }
    _add_time(timing, t0)
    return out, xi


def _add_time(timing: dict[str, float] | None, t0: float) -> None:
    """Add the time since ``t0`` to ``timing["solve_s"]`` (when timing is kept)."""
    if timing is not None:
        timing["solve_s"] = timing.get("solve_s", 0.0) + time.perf_counter() - t0


def _body_equation(
    g: GroupSystem, body_c: np.ndarray, body_b: Mapping[str, np.ndarray]
) -> tuple[np.ndarray, np.ndarray]:
    """The body impedance with the drag damping and the body loads with the drag
    loads Tdᵀ diag(b) v, before the lines are condensed."""
    iw = (1j * g.omega)[:, None, None]
    s = g.z_body + iw * body_c[None]
    rhs = g.f_body.copy()
    for b in g.drag:
        bb = body_b[b.name]
        t = rigid_link_matrix(b.drag_point)
        gen = g.emb[b.name].T @ (t.T * bb[None, :])  # (d, 3)
        sl = slice(g.off[b.name], g.off[b.name] + b.n_dof)
        rhs[:, sl, :] += np.einsum("ij,wjc->wic", gen, g.loads[b.name].velocity)
    return s, rhs


def _solve_free_dofs(g: GroupSystem, s: np.ndarray, rhs: np.ndarray) -> np.ndarray:
    """ξ (n_w, nb, n_ch) of the condensed body equation, the fixed DOFs ξ_j ≡ 0."""
    w, n_ch = g.omega, g.n_ch
    free = g.body_free
    if free.size == g.nb:
        return _solve_body(s, rhs) if g.nb else np.zeros((w.size, 0, n_ch), dtype=complex)
    # fixed DOFs: the constraint ξ_j ≡ 0, the free rows and columns solved
    xi = np.zeros((w.size, g.nb, n_ch), dtype=complex)
    if free.size:
        xi[:, free, :] = _solve_body(s[:, free[:, None], free[None, :]], rhs[:, free, :])
    return xi


def _combine(g: GroupSystem, part: LinePart, ue: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """A line's response with its attached ends moving by ``ue`` (n_w, d·n_att, n_ch)."""
    if isinstance(part, (FossLine, ModalLine, FreeLine)):
        return part.combine(ue)
    n_ch = g.n_ch
    u, sup = part
    uc = u[..., :n_ch] + np.einsum("ndwj,wjc->ndwc", u[..., n_ch:], ue)
    sc = sup[:, :, :n_ch] + sup[:, :, n_ch:] @ ue
    return uc, sc


def _solve_body(s: np.ndarray, g: np.ndarray) -> np.ndarray:
    try:
        x = np.linalg.solve(s, g)
    except np.linalg.LinAlgError:
        x = None
    if x is None or not np.all(np.isfinite(x)):
        raise SolverError(
            "coupled body solve: the body impedance (with the condensed "
            "lines) is singular at some frequency (an undamped body "
            "resonance or a DOF without restoring); add damping or "
            "stiffness to the body"
        )
    return x


# ------------------------------------------------------------ the σ map of a group


class SigmaMap:
    """The fixed-point map σ → σ(response to the drag of σ) of a group.

    Parameters
    ----------
    g : GroupSystem
        Its ``sizes`` set (the σ layout of :meth:`GroupSystem.split`).
    method : str
        Drag linearization method
        (:func:`stochcable.dynamics.linearization.variance.drag_coefficients`).
    rho : float
        Water density. [kg/m³]
    count : EvaluationCount
        Shared record: the evaluation count and the last :func:`relative_change`.
    progress : callable
        ``progress("linearization", {"group", "iteration", "change"})``.
    names : str
        The group's line names (progress).
    timing : dict, optional
        Accumulates ``solve_s``. [s]
    keep_last : bool, optional
        Keep the last evaluation as :attr:`last` (the full grid's, whose outcome is
        the fixed point's); False: keep nothing (the coarse map reads its σ only).

    Attributes
    ----------
    last : Evaluation or None
        The last evaluation (released when the next one starts).
    """

    def __init__(
        self,
        g: GroupSystem,
        method: str,
        rho: float,
        count: EvaluationCount,
        progress: Progress,
        names: str,
        timing: dict[str, float] | None,
        *,
        keep_last: bool = True,
    ) -> None:
        self.g, self.method, self.rho, self.count = g, method, rho, count
        self.progress, self.names, self.timing = progress, names, timing
        self.keep_last = keep_last
        self.last: Evaluation | None = None

    def __call__(self, x: np.ndarray) -> np.ndarray:
        """x (lines' σ then bodies' σ, [m/s]) → the σ of the response to the drag of
        x. [m/s]"""
        g, method = self.g, self.method
        # the last evaluation's response is released before this one is solved (the
        # outcome reads the last evaluation only)
        self.last = None
        ls, bs = g.split(x)
        if g.start_drag is not None and x is g.start_drag[0]:  # the start's drag, known
            damp = dict(g.start_drag[1])
        else:
            damp = {cl.name: drag_coefficients(cl.system, ls[cl.name], method) for cl in g.lines}
        body_c = np.zeros((g.nb, g.nb))
        body_b = {}
        for b in g.drag:
            bb, c = linear_body_drag(
                b,
                self.rho,
                bs[b.name],
                g.loads[b.name].current if b.name in g.loads else np.zeros(3),
                method,
            )
            sl = slice(g.off[b.name], g.off[b.name] + b.n_dof)
            body_c[sl, sl] += c
            body_b[b.name] = bb
        sol, xi = solve_group(g, damp, body_c, body_b, self.timing, lazy=True)
        new = []
        for cl in g.lines:
            part = sol[cl.name]
            if isinstance(part, FreeLine):  # a line alone: σ from its free nodes
                new.append(part.sigmas(method))
            else:
                new.append(sigmas_from_nodes(cl.system, g.inp_phys[cl.name], part[0], method))
        for b in g.drag:
            new.append(body_sigma(g, b, xi))
        new = np.concatenate(new) if new else np.zeros(0)
        self.count.iterations += 1
        change = relative_change(new, x)
        self.count.change = change
        info = {"group": self.names, "iteration": self.count.iterations, "change": change}
        if len(g.lines) == 1 and not g.bodies:  # one line without bodies: named as a line
            info["line"] = self.names
        self.progress("linearization", info)
        if self.keep_last:
            self.last = Evaluation(damping=damp, sol=sol, xi=xi, sigma=new, body_b=body_b)
        return new
