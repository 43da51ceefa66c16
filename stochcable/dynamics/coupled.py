"""Coupled dynamics of lines and large rigid bodies (seed 001 §3.2.c, §3.3, ch. 5).

Lines attached to a freely moving body are solved together with it: one drag
linearization loop over every attached line and body, the response at every frequency
by substructuring, the outputs of each line as :func:`stochcable.dynamics.line.line_result`
gives them and the body motions as :class:`stochcable.results.documents.BodyResult`.

Substructuring (exact at every frequency)
-----------------------------------------
Each attached line keeps its own finite-element model with both end nodes
prescribed (:func:`stochcable.dynamics.line.build_line_system`).  Its response is linear in
the motion u_e of its attached end nodes:

    U = U_0 + G u_e,        F_end = R_0 + R_e u_e,

with U_0, R_0 the response and the dynamic end forces of the line with the attached
ends held (sea, moving unattached ends), and G, R_e those of unit end motions (d extra
right-hand sides of the same solve: the "unit channels").  The rigid link u_e = T(r) ξ
(seed 001 eqs. 3.3.6–3.3.7, :func:`stochcable.bodies.rigid.rigid_link_matrix`) and the
transformed body equation (seed 001 eq. 3.2.c.20 with eqs. 3.3.8–3.3.10) give, per
frequency,

    [K_B − ω²(M_B + A(ω)) + iω(B(ω) + C_B) − Σ Tᵀ R_e T] ξ
        = F_exc + Tdᵀ diag(b) v + Σ Tᵀ R_0,

a dense (n_b × n_b) solve (Td, b, v: the drag point's rigid link, linear drag and
fluid velocity); then U follows.  This is the Schur complement of the
coupled system of :func:`stochcable.bodies.rigid.couple` on the body DOFs (tested equal to
:func:`stochcable.bodies.rigid.solve_coupled_direct`), with the line interiors solved by the
line machinery: banded direct solve (``solver="direct"``) or Foss modal superposition
with the static correction of the truncated modes (``solver="foss"``, seed 001 §5.3;
the unit end motions use the quasi-static split of :func:`stochcable.dynamics.line.solve`;
their constant split U_p makes their loads ω²·M_T U_p − iω·C U_p, so their modal
loads and static correction are closed-form columns, :func:`_foss_unit_split`).
A Foss line stays in the coordinates of its Foss (state) modes until the body solve
(:class:`_FossLine`): R_0 and R_e need the end nodes and their neighbours only, and
the one combined response P_0 + P_e u_e is reconstructed on the nodes afterwards —
the same linear system, reassociated (tested equal to the node-level path to
round-off, tests/test_coupled_reduction.py).  The lines' Foss decompositions of one
evaluation (:func:`_foss_state`) may run on a thread pool, opt-in with
``STOCHCABLE_THREADS`` (:mod:`stochcable.runtime`; the same bits as serially).

Fixed body DOFs
---------------
``RigidBody.fixed_dofs`` are constraints: the body equation above is solved on the
free DOFs only (rows and columns of the fixed ones dropped) and ξ_j ≡ 0 for a fixed
j, under both solvers; :func:`coupled_modes` lists the modes of the constrained
system.

Frequency-dependent added mass and radiation damping
----------------------------------------------------
Because the body DOFs are always condensed exactly at every ω, the body's A(ω), B(ω)
are exact under both solvers; "foss" only approximates the line interiors (exact
when all modes are kept).  No constant-matrix freezing is needed for the response.
The coupled *modes* (:func:`coupled_modes`) do need constant matrices: K and
M + A(ω_ref) of :func:`stochcable.bodies.rigid.constant_matrices`, ω_ref the peak of the sea
spectrum (documented on :class:`CoupledModes`).

Drag linearization
------------------
The fixed-point variable is the concatenation of every attached line's σ vector
(:func:`stochcable.dynamics.line.drag_coefficients` layout) and, per body with a drag area,
the σ of the relative velocity (fluid − body) at its drag point along x, y, z
(:func:`stochcable.bodies.rigid.body_drag_damping`: b = ρ·CdA·E|v|, seed 001 eq. 5.2.2 form
with the current).  The iteration mirrors :func:`stochcable.dynamics.line.linearize`: the
start is the fluid velocity relative to lines and bodies at rest (lines following
their moving unattached ends quasi-statically), the first response starts the
Anderson-accelerated iteration unmixed.  The record is one for the whole group.

Coarse start
------------
On a grid of at least ``COARSE_MIN_FREQUENCIES`` points the iteration first runs on
a frequency subset G (every ``COARSE_STRIDE``-th frequency and the last) to
``COARSE_TOLERANCE_FACTOR`` times the tolerance.  The σ integrals on the subset are
the full grid's trapezoid rule on the cubic interpolant of the integrand
(:func:`stochcable.dynamics.line._interpolatory_weights`, as the single-line coarse start
of :mod:`stochcable.dynamics.line`); subset frequencies whose σ weight is at most
``COARSE_NEGLIGIBLE`` (1e-12) of the largest in every channel (the spectrum's empty
tail) are then left out (their σ contributions are below round-off).  A Foss line
solves its modal equations per frequency there (:class:`_ModalLine`: the same modal
system, no Foss eigenproblem).  Then, at the coarse map's last input x, one full-grid
evaluation F(x); while its relative change exceeds the tolerance, a defect
correction: the coarse map scaled by the ratio r = F(x)/G(x) (per component, clipped
to [0.1, 10]) reproduces F at x, and its fixed point is the next full-grid point.  Each
round first takes one step of the corrected map from the Anderson extrapolation
(:func:`_warm_step`) of the last ``_WARM_MEMORY`` coarse secant pairs; when that
step's change is within a tenth of the full-grid change it is the next full-grid
point, else the corrected map is iterated from it (coarse evaluations) to 0.5 % of
the full-grid change.  At most ``COARSE_CORRECTIONS`` rounds, a round that does not
contract the full-grid change by 0.3 hands over to the plain full-grid iteration.
The usual convergence test on the full grid ends the iteration, so the
answer is the full-grid fixed point (tested equal within the tolerance to
``coarse=False``); the coarse model only moves the start.  On the three-leg
benchmark (narrow, lightly damped line resonances that a stride-4 subset does not
resolve: its σ are 0.7 % off at the same drag) the full grid needs 2 evaluations
instead of 7 (6 + 1 coarse ones on 45 of 200 frequencies; docs/BENCHMARKS.md,
"Bodies", passes E5, E5c).  The record's ``iterations`` and ``history`` list every
evaluation in order, coarse and full.  Used by default under both solvers when the
tolerance is at least ``COARSE_MIN_TOLERANCE`` (tighter: the coarse stage's 1e-6
floor and slower rounds make it cost more than it saves).

Vessel-driven ends
------------------
An end attached to a *prescribed* body (a vessel with a motion RAO ξ_RAO) moves with
the RAO u = T(r)·ξ_RAO (three translations; the rotations move it through the arm r)
coherently with the sea: it is the sea channel's end motion of an otherwise
independent line (:func:`fairlead_motion`), no coupling back.
"""

from __future__ import annotations

import dataclasses
import math
import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import scipy.linalg as sla

from stochcable.dynamics.blocks import (
    add_blocks as _add,
    block_matvec as _matvec,
    line_prep as _prep,
    real_gemm as _real_gemm,
    to_freq as _to_freq,
    trapezoid_weights as _trapezoid_weights,
)
from stochcable.dynamics.fixedpoint import (
    ANDERSON_MIXING,
    interpolatory_weights as _interpolatory_weights,
    linearization_record,
    subset_inputs as _subset_inputs,
)
from stochcable.dynamics.line_loads import (
    base_motion as _base,
    drag_blocks as _drag_blocks,
    end_loads as _end_loads,
    free_load as _free_load,
    line_inputs as _inputs,
)
from stochcable.dynamics.outputs import line_result
from stochcable.dynamics.solve import (
    end_tension_from_support as _end_tension,
    reactions as _reactions,
    solve_free as _solve_free,
    total_displacement as _total,
)
from stochcable.dynamics.system import (
    Damping,
    Linearization,
    LineSystem,
    noop_progress as _noop,
    Progress,
    Response,
)
from stochcable.dynamics.variance import (
    drag_coefficients,
    quasi_static_motion as _quasi_static,
    sigmas_from_nodes as _sigmas,
)
from stochcable.bodies.rigid import (
    PLANAR_INDEX,
    LineLink,
    RigidBody,
    attachment_geometric_stiffness,
    constant_matrices,
    couple,
    rigid_link_matrix,
)
from stochcable.errors import ConvergenceError, InputError, PhysicsWarning, SolverError, warn
from stochcable.dynamics.loads import Channel
from stochcable.dynamics.iteration import fixed_point, FixedPointResult
from stochcable.dynamics.linearization import drag_linear_current, drag_linear_harmonic
from stochcable.runtime import line_map
from stochcable.results.documents import BodyResult, LineResult, stats_from_spectrum
from stochcable.dynamics.modal_solvers import (
    foss_modes as _foss_decomposition,
    foss_transfer_modal as _foss_transfer_modal,
    FossModes,
)

__all__ = [
    "CoupledLine",
    "BodyLoads",
    "CoupledModes",
    "CoupledLinearization",
    "fairlead_motion",
    "body_loads",
    "body_gravity_stiffness",
    "linearize_coupled",
    "coupled_modes",
    "coupled_results",
    "body_result",
    "analyze_coupled",
]

#: Modes listed: those up to this factor times the top of the grid, at least
#: ``MIN_LISTED_MODES`` (as the line listing of :mod:`stochcable.dynamics.line`).
LISTED_MODE_FACTOR = 2.5
MIN_LISTED_MODES = 10
# Coupled DOFs up to which the modes are a dense generalized eigenproblem.
_DENSE_MODES = 1500
# Dense eigenproblems up to this size are solved whole (LAPACK divide and conquer)
# and the listed modes kept; larger ones by the subset driver (``_listed_eigh``).
_ALL_EIGH_MAX = 256


# ------------------------------------------------------------------------ inputs


@dataclass(frozen=True, eq=False)
class CoupledLine:
    """A line of a coupled group: its system, channels and body attachments.

    Parameters
    ----------
    system : LineSystem
        The line about its static shape, both end nodes prescribed
        (:func:`stochcable.dynamics.line.build_line_system`).
    channels : tuple of Channel
        The group's input channels in the group order, sampled on the analysis grid,
        as seen by this line: fluid kinematics and the motion of its *unattached*
        ends (channels that do not concern the line carry only the spectrum).
    end_a, end_b : str, optional
        Name of the (free) body the end is attached to; None: the end stays
        prescribed (fixed or moving with its channels).
    """

    system: LineSystem
    channels: tuple[Channel, ...]
    end_a: str | None = None
    end_b: str | None = None

    @property
    def name(self) -> str:
        return self.system.name

    def attached(self) -> list[tuple[int, str]]:
        """(end index 0/1, body name) of the attached ends."""
        return [(k, b) for k, b in enumerate((self.end_a, self.end_b)) if b is not None]


@dataclass(frozen=True, eq=False)
class BodyLoads:
    """Wave inputs of one body per channel.

    Parameters
    ----------
    force : ndarray, complex, shape (n_omega, d, n_ch)
        Wave excitation per unit input (:func:`stochcable.bodies.rigid.body_excitation`).
        [N/m, N·m/m]
    velocity : ndarray, complex, shape (n_omega, 3, n_ch)
        Fluid velocity at the drag point per unit input. [(m/s)/m]
    current : ndarray, shape (3,)
        Current at the drag point (the mean relative velocity). [m/s]
    """

    force: np.ndarray
    velocity: np.ndarray
    current: np.ndarray


def fairlead_motion(rao: Any, r: Any) -> np.ndarray:
    """Motion of a point of a prescribed (vessel) body from its 6-DOF RAO.

    Parameters
    ----------
    rao : array_like, complex, shape (n_omega, 6)
        Vessel motion per unit wave amplitude (surge, sway, heave [m/m], roll, pitch,
        yaw [rad/m]) about its reference point, global axes.
    r : array_like, shape (3,)
        The point relative to the reference point at the static pose. [m]

    Returns
    -------
    ndarray, complex, shape (n_omega, 3)
        u = T(r)·ξ = ξ_t + θ × r (seed 001 eqs. 3.3.6–3.3.7). [m/m]
    """
    a = np.asarray(rao, dtype=complex)
    if a.ndim != 2 or a.shape[1] != 6:
        raise InputError("rao", a.shape, "m/m", "must have shape (n_omega, 6)")
    t = rigid_link_matrix(r)
    return a @ t.T


def body_loads(body: RigidBody, channels: Sequence[Channel], omega: np.ndarray,
               sea: Any, environment: Any) -> BodyLoads:
    """Excitation force and drag-point fluid velocity of a body per channel.

    Parameters
    ----------
    body : RigidBody
    channels : sequence of Channel
        The group's channels (only ``kind == "sea"`` loads the body).
    omega : ndarray, shape (n_omega,)
        [rad/s]
    sea : Sea or None
        The scene's sea (heading).
    environment : Environment
        depth, g, current.

    Returns
    -------
    BodyLoads
        The sea channel: ``body_excitation(body, ω, β, k)`` (phase moved to the global
        wave phase) and the linear wave velocity at the drag point
        (:func:`stochcable.sea.kinematics.wave_kinematics`, zero above z = 0).
    """
    from stochcable.bodies.rigid import body_excitation
    from stochcable.sea.kinematics import wave_kinematics, wavenumber

    w = np.asarray(omega, dtype=float)
    n_ch = len(channels)
    d = body.n_dof
    force = np.zeros((w.size, d, n_ch), dtype=complex)
    vel = np.zeros((w.size, 3, n_ch), dtype=complex)
    point = body.position + body.drag_point
    for i, ch in enumerate(channels):
        if ch.kind != "sea" or sea is None:
            continue
        beta = sea.heading_rad
        k = wavenumber(w, environment.depth, environment.g)
        force[:, :, i] = body_excitation(body, w, beta, wavenumber=k)
        if np.any(body.drag_area > 0):
            p = point.copy()
            p[2] = max(p[2], -environment.depth)
            kin = wave_kinematics(w, p, beta, environment.depth, environment.g)
            vel[:, :, i] = kin.velocity[0].T
    cur = np.asarray(environment.current_velocity(np.array([min(point[2], 0.0)]))[0],
                     dtype=float)
    return BodyLoads(force=force, velocity=vel, current=cur)


def body_gravity_stiffness(body: RigidBody, displaced_volume: float,
                           centre_of_buoyancy: Any, rho: float, g: float) -> np.ndarray:
    """Restoring of the weight and the buoyancy of a body when it rotates.

    Parameters
    ----------
    body : RigidBody
        Mass and centre of gravity ``cog`` (relative to the reference point).
    displaced_volume : float
        Displaced volume ∇. [m³]
    centre_of_buoyancy : array_like, shape (3,)
        Centre of buoyancy relative to the reference point. [m]
    rho, g : float
        Water density [kg/m³] and gravity [m/s²].

    Returns
    -------
    ndarray, shape (d, d)
        Σ −[F]×[r]× over the weight F = (0, 0, −m g) at the CoG and the buoyancy
        (0, 0, ρ g ∇) at the CoB (:func:`stochcable.bodies.rigid.attachment_geometric_stiffness`):
        roll and pitch restoring ρ g ∇ z_B − m g z_G (the metacentric terms of a
        fully submerged body, option (a) of docs/BODIES.md "Symmetry"). [N·m/rad]

    Notes
    -----
    No waterplane terms: a surface-piercing body needs its ``hydrostatic_stiffness``
    (which already contains these gravity terms, WAMIT convention).
    """
    w = np.array([0.0, 0.0, -body.mass * g])
    b = np.array([0.0, 0.0, rho * g * float(displaced_volume)])
    cob = np.asarray(centre_of_buoyancy, dtype=float)
    return (attachment_geometric_stiffness(w, body.cog, body.planar)
            + attachment_geometric_stiffness(b, cob, body.planar))


# ------------------------------------------------------------------- linearization


@dataclass(frozen=True, eq=False)
class CoupledLinearization:
    """Outcome of :func:`linearize_coupled`.

    Attributes
    ----------
    lines : dict of str to Linearization
        Per line: its drag, its record (the group's iteration history with the
        line's σ and B) and the coupled response (attached ends moving with the
        bodies) per physical channel.
    body_motion : dict of str to ndarray, complex, shape (n_omega, d, n_ch)
        Body response per unit input. [m/unit, rad/unit]
    body_sigma : dict of str to ndarray, shape (3,)
        σ of the relative velocity at the drag point along x, y, z. [m/s]
    body_drag : dict of str to ndarray, shape (3,)
        Linear drag coefficient per direction at the drag point. [N·s/m]
    converged, iterations, relative_change, history, tolerance
        The group's fixed-point record.
    """

    lines: dict[str, Linearization]
    body_motion: dict[str, np.ndarray]
    body_sigma: dict[str, np.ndarray]
    body_drag: dict[str, np.ndarray]
    converged: bool
    iterations: int
    relative_change: float
    history: tuple[float, ...]
    tolerance: float


def _zero_density(w: np.ndarray) -> np.ndarray:
    return np.zeros_like(np.asarray(w, dtype=float))


def _unit_channels(cl: CoupledLine) -> tuple[Channel, ...]:
    """d unit end-motion channels per attached end (zero spectrum)."""
    model = cl.system.model
    comps = list(model.components)
    w = cl.channels[0].omega
    out = []
    for k, _ in cl.attached():
        for j, c in enumerate(comps):
            m = np.zeros((w.size, 3), dtype=complex)
            m[:, c] = 1.0
            out.append(Channel(name=f"unit.{k}.{j}", kind="end_motion", omega=w,
                               spectrum=np.zeros(w.size), density=_zero_density,
                               motion_a=m if k == 0 else None,
                               motion_b=m if k == 1 else None))
    return tuple(out)


class _LazyInputs(dict):
    """Line name -> inputs of its channels plus its unit end-motion channels, built
    on first access."""

    def __init__(self, lines: Sequence[CoupledLine]) -> None:
        super().__init__()
        self._lines = {cl.name: cl for cl in lines}

    def __missing__(self, name: str) -> Any:
        cl = self._lines[name]
        value = _inputs(cl.system, tuple(cl.channels) + _unit_channels(cl))
        self[name] = value
        return value


class _Group:
    """Frequency-independent data of a coupled group."""

    def __init__(self, lines: Sequence[CoupledLine], bodies: Sequence[RigidBody],
                 loads: Mapping[str, BodyLoads], rho: float,
                 channels: Sequence[Channel],
                 inp_phys: Mapping[str, Any] | None = None,
                 weights: np.ndarray | None = None) -> None:
        self.lines = tuple(lines)
        # the coarse stage's group (:func:`_coarse_group`): Foss lines solve their
        # modal equations per frequency (:class:`_ModalLine`), no Foss eigenproblem
        self.modal_direct = False
        # per line: the drag-independent arrays of :class:`_ModalLine`
        self.modal_cache: dict[str, dict[str, Any]] = {}
        # per line: the drag-independent arrays of :class:`_FossLine` (full grid)
        self.foss_cache: dict[str, dict[str, Any]] = {}
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
        self.body_free = np.array([off[b.name] + i for b in bodies for i in b.free_index],
                                  dtype=int)
        self.channels = tuple(channels)
        self.n_ch = len(channels)
        self.omega = channels[0].omega
        self.weights = (_trapezoid_weights(self.omega)[:, None]
                        * np.stack([c.spectrum for c in channels], axis=1)
                        if weights is None else weights)
        self.sizes: dict[str, int] = {}
        # per line: augmented inputs (built on first use: only the node-level paths
        # need them), link matrix T_l (d·n_att, nb), attached rows
        self.inp: dict[str, Any] = _LazyInputs(self.lines)
        self.inp_phys, self.tmat, self.rows = {}, {}, {}
        geo = {b.name: np.zeros((b.n_dof, b.n_dof)) for b in bodies}
        for cl in self.lines:
            if [c.name for c in cl.channels] != [c.name for c in channels]:
                raise InputError(f"lines[{cl.name}].channels", [c.name for c in cl.channels],
                                 "-", "every line of a group needs the group's channels")
            model = cl.system.model
            d = model.dim
            att = cl.attached()
            t = np.zeros((d * len(att), self.nb))
            rows = []
            for i, (k, bname) in enumerate(att):
                if bname not in self.by_name:
                    raise InputError(f"lines[{cl.name}].{('end_a', 'end_b')[k]}", bname, "-",
                                     f"is not a body; bodies: {names}")
                body = self.by_name[bname]
                if (d == 2) != body.planar:
                    raise InputError(f"lines[{cl.name}]", bname, "-",
                                     f"a {d}-D line model needs a "
                                     f"{'planar' if d == 2 else '6-DOF'} body")
                node = 0 if k == 0 else model.n_nodes - 1
                r = model.positions[node] - body.position
                tl = rigid_link_matrix(r, planar=body.planar)
                t[i * d:(i + 1) * d, off[bname]:off[bname] + body.n_dof] = tl
                st = cl.system.statics
                f = np.asarray(st.force_a if k == 0 else st.force_b, dtype=float)
                geo[bname] += attachment_geometric_stiffness(f, r, body.planar)
                rows.extend(range(k * d, (k + 1) * d))
            self.tmat[cl.name] = t
            self.rows[cl.name] = np.asarray(rows, dtype=int)
        # the physical channels alone, for the σ (the unit channels weigh zero)
        self.inp_phys = ({cl.name: _inputs(cl.system, tuple(cl.channels))
                          for cl in self.lines} if inp_phys is None else dict(inp_phys))
        self.geometric = geo
        nb = self.nb
        self.kb = np.zeros((nb, nb))
        self.mb = np.zeros((nb, nb))
        self.cb = np.zeros((nb, nb))
        for b in bodies:
            s = slice(off[b.name], off[b.name] + b.n_dof)
            self.kb[s, s] = b.hydrostatic_stiffness + b.extra_stiffness + geo[b.name]
            self.mb[s, s] = b.mass_matrix()
            self.cb[s, s] = b.extra_damping
        w = self.omega
        a = np.zeros((w.size, nb, nb))
        bb = np.zeros((w.size, nb, nb))
        for b in bodies:
            s = slice(off[b.name], off[b.name] + b.n_dof)
            a[:, s, s] = b.added_mass_at(w)
            bb[:, s, s] = b.radiation_damping_at(w)
        w2 = (w * w)[:, None, None]
        iw = (1j * w)[:, None, None]
        self.z_body = self.kb[None] - w2 * (self.mb[None] + a) + iw * (self.cb[None] + bb)
        # body loads (n_w, nb, n_ch), drag-point maps
        self.f_body = np.zeros((w.size, nb, self.n_ch), dtype=complex)
        self.drag = [b for b in bodies if np.any(b.drag_area > 0)]
        self.loads = dict(loads)
        for b in bodies:
            ld = loads.get(b.name)
            if ld is not None:
                s = slice(off[b.name], off[b.name] + b.n_dof)
                self.f_body[:, s, :] = ld.force
        self.emb = {}   # (6, d) embedding of a body's DOFs among the six
        for b in bodies:
            e = np.eye(6)
            self.emb[b.name] = e[:, list(PLANAR_INDEX)] if b.planar else e

    # ------------------------------------------------------------------ σ layout
    def split(self, x: np.ndarray) -> tuple[dict[str, np.ndarray], dict[str, np.ndarray]]:
        out, k = {}, 0
        for cl in self.lines:
            n = self.sizes[cl.name]
            out[cl.name] = x[k:k + n]
            k += n
        body = {}
        for b in self.drag:
            body[b.name] = x[k:k + 3]
            k += 3
        return out, body


def _body_drag(body: RigidBody, rho: float, sigma: np.ndarray, mean: np.ndarray,
               method: str) -> tuple[np.ndarray, np.ndarray]:
    """Linear drag per direction b (3,) and the damping Tᵀdiag(b)T on the body DOFs."""
    if method == "harmonic":
        b = np.asarray(drag_linear_harmonic(rho, body.drag_area, 1.0, math.sqrt(2.0) * sigma),
                       dtype=float)
    else:
        b = np.asarray(drag_linear_current(rho, body.drag_area, 1.0, sigma, mean), dtype=float)
    t = rigid_link_matrix(body.drag_point)
    c = t.T @ (b[:, None] * t)
    if body.planar:
        c = c[np.ix_(PLANAR_INDEX, PLANAR_INDEX)]
    return np.broadcast_to(b, (3,)).copy(), c


def _body_sigma(g: _Group, body: RigidBody, xi: np.ndarray | None) -> np.ndarray:
    """σ of the relative velocity at the drag point, (3,), ξ (n_w, nb, n_ch) or None."""
    v = g.loads[body.name].velocity if body.name in g.loads else np.zeros(
        (g.omega.size, 3, g.n_ch), dtype=complex)
    if xi is not None:
        s = slice(g.off[body.name], g.off[body.name] + body.n_dof)
        t = rigid_link_matrix(body.drag_point) @ g.emb[body.name]  # (3, d)
        v = v - (1j * g.omega)[:, None, None] * np.einsum("ij,wjc->wic", t, xi[:, s, :])
    var = np.einsum("wic,wc->i", np.abs(v) ** 2, g.weights)
    return np.sqrt(np.clip(var, 0.0, None))


def _solve_group(g: _Group, line_damping: Mapping[str, Damping],
                 body_c: np.ndarray, body_b: Mapping[str, np.ndarray],
                 timing: dict[str, float] | None
                 ) -> tuple[dict[str, tuple[np.ndarray, np.ndarray]], np.ndarray]:
    """One coupled solve for given drag: per line the combined node displacements
    (n_nodes, d, n_w, n_ch) and support forces (n_w, 2d, n_ch); the body motion
    (n_w, nb, n_ch)."""
    t0 = time.perf_counter()
    w = g.omega
    n_ch = g.n_ch
    iw = (1j * w)[:, None, None]
    s = g.z_body + iw * body_c[None]
    rhs = g.f_body.copy()
    for b in g.drag:
        bb = body_b[b.name]
        t = rigid_link_matrix(b.drag_point)
        gen = g.emb[b.name].T @ (t.T * bb[None, :])     # (d, 3)
        sl = slice(g.off[b.name], g.off[b.name] + b.n_dof)
        rhs[:, sl, :] += np.einsum("ij,wjc->wic", gen, g.loads[b.name].velocity)
    # the lines are independent until the body solve: their Foss decompositions (the
    # LAPACK eigenproblems, GIL released) may run on the thread pool (opt-in,
    # stochcable.runtime), the rest serially (many small NumPy steps that hold the
    # GIL: pooled they cost more CPU than they overlap, docs/BENCHMARKS.md pass E4);
    # summed in line order, the same bits with or without the pool
    modal = [cl for cl in g.lines
             if cl.system.solver != "direct" and _MODAL_FOSS and not g.modal_direct]
    states = dict(zip([cl.name for cl in modal], line_map(
        lambda cl: _foss_state(cl.system, line_damping[cl.name]), modal)))
    done = [_line_part(g, cl, line_damping[cl.name], states.get(cl.name))
            for cl in g.lines]
    parts: dict[str, Any] = {}
    for cl, (part, r0, re) in zip(g.lines, done):
        t = g.tmat[cl.name]
        s = s - t.T[None] @ re @ t[None]
        rhs = rhs + t.T[None] @ r0
        parts[cl.name] = part
    free = g.body_free
    if free.size == g.nb:
        xi = _solve_body(s, rhs, w) if g.nb else np.zeros((w.size, 0, n_ch), dtype=complex)
    else:
        # fixed DOFs: the constraint ξ_j ≡ 0, the free rows and columns solved
        xi = np.zeros((w.size, g.nb, n_ch), dtype=complex)
        if free.size:
            xi[:, free, :] = _solve_body(s[:, free[:, None], free[None, :]],
                                         rhs[:, free, :], w)
    out = {}
    for cl in g.lines:
        t = g.tmat[cl.name]
        ue = t[None] @ xi                                     # (n_w, d·n_att, n_ch)
        part = parts[cl.name]
        if isinstance(part, (_FossLine, _ModalLine)):
            out[cl.name] = part.combine(ue)
            continue
        u, sup = part
        uc = u[..., :n_ch] + np.einsum("ndwj,wjc->ndwc", u[..., n_ch:], ue)
        sc = sup[:, :, :n_ch] + sup[:, :, n_ch:] @ ue
        out[cl.name] = (uc, sc)
    if timing is not None:
        timing["solve_s"] = timing.get("solve_s", 0.0) + time.perf_counter() - t0
    return out, xi


def _line_part(g: _Group, cl: CoupledLine, damping: Damping, state: Any = None
               ) -> tuple[Any, np.ndarray, np.ndarray]:
    """One line of :func:`_solve_group` before the body solve: its part (a
    :class:`_FossLine`, or the node-level (u, support) with the unit columns) and its
    end reactions R_0 (n_w, |rows|, n_ch), R_e (n_w, |rows|, n_e) on the attached rows;
    ``state``: the line's :func:`_foss_state` when already computed."""
    system = cl.system
    rows = g.rows[cl.name]
    n_ch = g.n_ch
    if system.solver != "direct" and g.modal_direct:
        part = _ModalLine(system, g.inp_phys[cl.name], damping,
                          tuple(k for k, _ in cl.attached()),
                          g.modal_cache.setdefault(cl.name, {}))
        r0, re = part.reactions(rows)
        return part, r0, re
    if system.solver != "direct" and _MODAL_FOSS:
        try:
            part = _FossLine(system, g.inp_phys[cl.name], damping,
                             tuple(k for k, _ in cl.attached()), state,
                             g.foss_cache.setdefault(cl.name, {}))
        except SolverError:   # defective pencil: the plain solve's fallback
            pass
        else:
            r0, re = part.reactions(rows)
            return part, r0, re
    inp = g.inp[cl.name]
    solved = None
    if system.solver != "direct":
        solved = _foss_unit_split(system, g.inp_phys[cl.name], inp, damping)
    u_f, c = _solve_free(system, inp, damping) if solved is None else solved
    u = _total(system, inp, u_f)
    sup = _reactions(system, _prep(system), c, u, _end_loads(system, inp, damping), g.omega)
    return (u, sup), sup[:, rows, :n_ch], sup[:, rows, n_ch:]


def _foss_unit_split(system: LineSystem, inp_phys: Any, inp: Any, damping: Damping
                     ) -> tuple[np.ndarray, Any] | None:
    """:func:`stochcable.dynamics.line._solve_free` (Foss) of the physical channels plus the
    unit end-motion channels, the unit columns in closed form.

    A unit end motion e_j moves the line by the constant U_p,j (the end and its exact
    static following, :func:`stochcable.dynamics.line._base`), so its free-row load is
    ω²·[M_T U_p,j]_f − iω·[C U_p,j]_f: its modal load, its static correction and the
    drag load need no per-frequency products over the nodes; one Foss decomposition
    serves both.  The same linear system as the plain call to round-off; None (use the
    plain call) when the pencil is defective (its fallback and warning).
    """
    prep = _prep(system)
    w = inp.omega
    n_ch = inp_phys.weights.shape[1]
    n_e = inp.weights.shape[1] - n_ch
    _, c, foss = _foss_state(system, damping)
    if foss is None:
        return None
    phi, _, _ = prep.modal(system)
    m, nf = phi.shape[1], phi.shape[0]
    n_w = w.size
    # physical channels: the free-row load of _solve_free
    rhs = _free_load(system, prep, inp_phys, damping)
    flat = np.ascontiguousarray(prep._free_rows(rhs)).reshape(nf, n_w * n_ch)
    u_p = _real_gemm(phi, np.ascontiguousarray(
        _foss_transfer_modal(foss, _real_gemm(phi.T, flat), w, n_ch)))
    # unit channels: U_p,j constant (node vectors (n, d, n_e))
    key = ("unit_up", n_ch)
    if key not in inp.cache:
        up = np.ascontiguousarray(_base(system, prep, inp)[0][:, :, 0, n_ch:].real)
        inp.cache[key] = (up, prep._free_rows(_matvec(prep.MT, up)))
    up, a = inp.cache[key]
    b = prep._free_rows(_matvec(c, up))
    ah, bh = phi.T @ a, phi.T @ b                              # (m, n_e)
    fe = ((w * w)[None, :, None] * ah[:, None, :]
          - (1j * w)[None, :, None] * bh[:, None, :])          # (m, n_w, n_e)
    u_e = _real_gemm(phi, np.ascontiguousarray(
        _foss_transfer_modal(foss, fe.reshape(m, n_w * n_e), w, n_e)))
    u_e = u_e.reshape(nf, n_w, n_e)
    if m < nf:
        u_p += prep.residual(system, flat)
        st = prep.residual(system, np.concatenate([a, b], axis=1).astype(complex))
        u_e += ((w * w)[None, :, None] * st[:, None, :n_e]
                - (1j * w)[None, :, None] * st[:, None, n_e:])
    u = np.concatenate([u_p.reshape(nf, n_w, n_ch), u_e], axis=2)
    return u.reshape(prep.n - 2, prep.d, n_w, n_ch + n_e), c


def _foss_state(system: LineSystem, damping: Damping) -> tuple[Any, Any, FossModes | None]:
    """The drag blocks C_d, the damping C = S + C_d and the Foss decomposition of a
    line's kept modes (None when the pencil is defective): the frequency-independent
    start of :class:`_FossLine`, the part :func:`_solve_group` runs on the thread
    pool (NumPy's LAPACK ``geev`` in :func:`stochcable.dynamics.solvers._foss_decomposition`
    releases the GIL)."""
    prep = _prep(system)
    cd = _drag_blocks(system, damping)
    c = _add(prep.S, cd)
    phi, mh, kh = prep.modal(system)
    ch = phi.T @ prep._free_rows(_matvec(c, prep._nodes(phi)))
    try:
        foss = _foss_decomposition(mh, 0.5 * (ch + ch.T), kh)
    except SolverError:
        foss = None
    return cd, c, foss


def _unit_follow(system: LineSystem, inp: Any, ends: tuple[int, ...]
                 ) -> tuple[np.ndarray, np.ndarray, np.ndarray | None]:
    """The unit end motions of the attached ends ``ends`` of a Foss line: their
    constant static following U_p (n_nodes, d, n_e), the modal mass load
    âh = Φᵀ[M_T U_p]_f (m, n_e) and its static correction (None with all modes kept),
    cached on the inputs ``inp``."""
    key = ("unit_follow", ends)
    if key not in inp.cache:
        prep = _prep(system)
        d, n = prep.d, prep.n
        phi, _, _ = prep.modal(system)
        m, nf = phi.shape[1], phi.shape[0]
        n_e = d * len(ends)
        ub = np.zeros((2 * d, n_e))
        for i, k in enumerate(ends):
            ub[k * d:(k + 1) * d, i * d:(i + 1) * d] = np.eye(d)
        up = np.zeros((n, d, n_e))
        up[0], up[-1] = ub[:d], ub[d:]
        up[1:-1] = (prep.follower() @ ub).reshape(n - 2, d, n_e)
        a = prep._free_rows(_matvec(prep.MT, up))
        st_a = prep.residual(system, a.astype(complex)).real if m < nf else None
        inp.cache[key] = (up, phi.T @ a, st_a)
    return inp.cache[key]


#: Foss lines of a group kept in modal coordinates until the body solve
#: (:class:`_FossLine`); False: the node-level path of :func:`_foss_unit_split` (the
#: reference of the tests, the same linear system).
_MODAL_FOSS = True


class _FossLine:
    """A Foss line of a group in the coordinates of its Foss (state) modes.

    The same linear system as :func:`_foss_unit_split` + :func:`stochcable.dynamics.line.
    _reactions`, reordered: the physical channels' state-modal response P_0 (2m, n_w,
    n_ch) and the unit end motions' P_e (2m, n_w, n_e) are kept (the latter in closed
    form, ``(ω²·W âh − iω·W b̂h)/(iω − λ)``, W the Foss weights); the end reactions
    need the displacement of the end nodes and their neighbours only (two rows of
    Φχ); after the body solve, :meth:`combine` forms P_0 + P_e u_e and reconstructs
    the one combined response on all nodes (σ, support forces).  Raises SolverError
    when the Foss pencil is defective (the caller falls back to the plain solve).
    ``cache`` (a dict per line of the group, :attr:`_Group.foss_cache`) keeps the
    drag-independent arrays (end-node rows of Φ, of the base response and of the
    static following, ω²·[static correction of âh] at those rows) from the first
    evaluation for the next ones: the same arrays, not recomputed (docs/BENCHMARKS.md
    pass E8).
    """

    def __init__(self, system: LineSystem, inp: Any, damping: Damping,
                 ends: tuple[int, ...], state: Any = None,
                 cache: dict[str, Any] | None = None) -> None:
        prep = _prep(system)
        w = inp.omega
        n_w, n_ch = inp.weights.shape
        d = prep.d
        _, c, foss = _foss_state(system, damping) if state is None else state
        if foss is None:
            raise SolverError("Foss eigenproblem is (nearly) defective")
        phi, _, _ = prep.modal(system)
        m, nf = phi.shape[1], phi.shape[0]
        lam = foss.lambdas
        den = 1j * w[None, :] - lam[:, None]                      # (2m, n_w)
        bad = np.abs(den) <= 1e-12 * np.maximum(np.abs(lam)[:, None], w[None, :])
        if bad.any():   # the message of solvers._foss_transfer_modal
            _foss_transfer_modal(foss, np.zeros((m, n_w), dtype=complex), w, 1)
        w2, iw = w * w, 1j * w
        if not cache:
            # the drag-independent arrays; kept in ``cache`` (one per line of the
            # group) for the later evaluations
            cache = {} if cache is None else cache
            cache["u_p"] = u_p = _base(system, prep, inp)[0]
            up, _, st_a = cache["follow"] = _unit_follow(system, inp, ends)
            n_e = up.shape[2]
            # end nodes and their neighbours: nodes 0, 1, n-2, n-1
            cache["adj"] = adj = np.r_[np.arange(d), np.arange(nf - d, nf)]
            cache["pa"] = phi[adj]
            cache["u4"] = u_p[[0, 1, -2, -1]]
            up4 = np.empty((4, d, n_w, n_e), dtype=complex)
            up4[...] = up[[0, 1, -2, -1]][:, :, None, :]
            cache["up4"] = up4
            cache["w2sa"] = (None if st_a is None
                             else w2[None, None] * st_a[adj][:, :, None])  # (2d, n_e, n_w)
            cache["zero_e"] = np.zeros((2, d, n_w, n_e), complex)     # read only
        u_p = cache["u_p"]
        up, ah, st_a = cache["follow"]
        adj = cache["adj"]
        # physical channels: the free-row load of _solve_free
        rhs = _free_load(system, prep, inp, damping)
        flat = np.ascontiguousarray(prep._free_rows(rhs)).reshape(nf, n_w * n_ch)
        p0 = (foss.weights @ _real_gemm(phi.T, flat)).reshape(2 * m, n_w, n_ch)
        p0 /= den[:, :, None]
        # unit end motions: the constant static following U_p,j of each attached end DOF
        b = prep._free_rows(_matvec(c, up))
        n_e = up.shape[2]
        # W âh and W b̂h as the two blocks of one (2m, 2 n_e) product: each column of a
        # product is that of the separate one (the same sums, tested to the bit)
        wab = foss.weights @ np.concatenate([ah, phi.T @ b], axis=1)  # (2m, 2 n_e)
        rden = 1.0 / den
        self.res0 = self.st = None
        if m < nf:
            self.res0 = prep.residual(system, flat).reshape(nf, n_w, n_ch)
            st_b = prep.residual(system, b.astype(complex)).real
            self.st = np.ascontiguousarray(np.hstack([st_a, st_b]))   # (nf, 2 n_e)
        y_adj = cache["pa"] @ foss.chi                               # (2d, 2m)
        u4 = cache["u4"].copy()
        v = (y_adj @ p0.reshape(2 * m, -1)).reshape(2, d, n_w, n_ch)
        if self.res0 is not None:
            v += self.res0[adj].reshape(2, d, n_w, n_ch)
        u4[1:3] += v
        u4e = cache["up4"].copy()
        # the unit columns' P_e = (ω² W âh − iω W b̂h)/(iω − λ) seen through y_adj, the
        # âh and b̂h rows stacked in one product with 1/(iω − λ) (rows as the separate
        # products', tested to the bit)
        y2 = (y_adj[None, :, None, :] * wab.T.reshape(2, 1, n_e, 2 * m)
              ).reshape(2 * 2 * d * n_e, 2 * m) @ rden
        ya, yb = y2[:2 * d * n_e], y2[2 * d * n_e:]
        ve = (w2 * ya - iw * yb).reshape(2, d, n_e, n_w)
        if self.st is not None:
            sb = st_b[adj]                                           # (2d, n_e)
            ve += (cache["w2sa"] - iw[None, None] * sb[:, :, None]).reshape(2, d, n_e, n_w)
        u4e[1:3] += ve.transpose(0, 1, 3, 2)
        f_end = _end_loads(system, inp, damping)
        self.sup0 = _reactions(system, prep, c, u4, f_end, w)       # (n_w, 2d, n_ch)
        self.supe = _reactions(system, prep, c, u4e, cache["zero_e"], w)
        self.inp, self.phi, self.chi, self.rden = inp, phi, foss.chi, rden
        self.p0, self.wab, self.up, self.u_p = p0, wab, up, u_p
        self.w2, self.iw = (w2)[None, :, None], iw[None, :, None]

    def reactions(self, rows: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """R_0 (n_w, |rows|, n_ch) and R_e (n_w, |rows|, n_e) on the attached rows."""
        return self.sup0[:, rows, :], self.supe[:, rows, :]

    def combine(self, ue: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Node displacements (n_nodes, d, n_w, n_ch) and support forces (n_w, 2d,
        n_ch) of the line whose attached ends move by ``ue`` (n_w, n_e, n_ch)."""
        m2, n_w, n_ch = self.p0.shape
        n_e = self.up.shape[2]
        uet = np.ascontiguousarray(np.transpose(ue, (1, 0, 2)))       # (n_e, n_w, n_ch)
        flat_e = uet.reshape(n_e, n_w * n_ch)
        # W âh u_e and W b̂h u_e: the row blocks of one product (tested to the bit)
        gab = (self.wab.reshape(m2, 2, n_e).transpose(1, 0, 2).reshape(2 * m2, n_e)
               @ flat_e)
        ga = gab[:m2].reshape(m2, n_w, n_ch)
        gb = gab[m2:].reshape(m2, n_w, n_ch)
        # p0 + (ω² ga − iω gb)/(iω − λ) in place (the sum commutes exactly)
        pc = self.w2 * ga
        pc -= self.iw * gb
        pc *= self.rden[:, :, None]
        pc += self.p0
        uf = _real_gemm(self.phi, np.ascontiguousarray(self.chi @ pc.reshape(m2, -1)))
        return _assemble_line(self, uf, ue, uet)


class _ModalLine:
    """A Foss line of the coarse stage's group: the modal equations of its kept modes
    (K̂ − ω²M̂ + iωĈ) z = Φᵀf solved per frequency (one batched dense LU for the
    physical channels and the unit end motions), no Foss eigenproblem.

    The same modal system as :class:`_FossLine` (Foss diagonalizes it exactly), so
    the same response to round-off, with the interface of :class:`_FossLine`
    (:meth:`reactions`, :meth:`combine`): on a few dozen frequencies the batched
    m × m solves cost less than the line's 2m × 2m eigenproblem
    (docs/BENCHMARKS.md, "Bodies", pass E5).  The physical channels' modal response
    z_0 (n_w, m, n_ch), the unit end motions' z_e (n_w, m, n_e) (loads
    ω²âh − iωb̂h, :func:`_foss_unit_split`); after the body solve z_0 + z_e u_e is
    reconstructed on the nodes with the static correction of the truncated modes.
    ``cache`` (a dict per line of the coarse group, :attr:`_Group.modal_cache`) keeps
    the drag-independent arrays (static following, unit-motion mass loads, K̂ − ω²M̂,
    end-node rows) from the first coarse evaluation for the next ones: the same
    arrays, not recomputed (docs/BENCHMARKS.md pass E5c).
    """

    def __init__(self, system: LineSystem, inp: Any, damping: Damping,
                 ends: tuple[int, ...], cache: dict[str, Any] | None = None) -> None:
        prep = _prep(system)
        w = inp.omega
        n_w, n_ch = inp.weights.shape
        d = prep.d
        c = _add(prep.S, _drag_blocks(system, damping))
        phi, mh, kh = prep.modal(system)
        m, nf = phi.shape[1], phi.shape[0]
        w2, iw = w * w, 1j * w
        if not cache:
            # the drag-independent arrays; kept in ``cache`` (one per line of the
            # coarse group) for the later coarse evaluations
            cache = {} if cache is None else cache
            cache["u_p"] = _base(system, prep, inp)[0]
            up, ah, st_a = cache["follow"] = _unit_follow(system, inp, ends)
            cache["w2ah"] = w2[:, None, None] * ah[None]
            cache["adj"] = adj = np.r_[np.arange(d), np.arange(nf - d, nf)]
            cache["pa"] = phi[adj]
            cache["u4"] = cache["u_p"][[0, 1, -2, -1]]
            cache["up4"] = up[[0, 1, -2, -1]][:, :, None, :]
            cache["w2sa"] = (None if st_a is None
                             else w2[None, :, None] * st_a[adj][:, None, :])
            key = ("stiff_mass", m, w.tobytes())  # K̂ − ω²M̂, as analysis._foss_free
            if key not in prep._modal:
                prep._modal[key] = kh - (w2[:, None, None]) * mh
            cache["kmm"] = prep._modal[key]
        u_p = cache["u_p"]
        up, ah, st_a = cache["follow"]
        ch = phi.T @ prep._free_rows(_matvec(c, prep._nodes(phi)))
        rhs = _free_load(system, prep, inp, damping)
        flat = np.ascontiguousarray(prep._free_rows(rhs)).reshape(nf, n_w * n_ch)
        b = prep._free_rows(_matvec(c, up))
        bh = phi.T @ b
        n_e = up.shape[2]
        f = np.empty((n_w, m, n_ch + n_e), dtype=complex)
        f[:, :, :n_ch] = _real_gemm(phi.T, flat).reshape(m, n_w, n_ch).transpose(1, 0, 2)
        f[:, :, n_ch:] = cache["w2ah"] - iw[:, None, None] * bh[None]
        # symmetric matrices passed as their transposes (LAPACK's column-major layout,
        # as analysis._foss_free)
        # (K̂ − ω²M̂) + iωĈ written as its real and imaginary parts (the product iω·Ĉ
        # has the real part ±0): the bits of the complex sum, no complex temporary
        a = np.empty((n_w, m, m), dtype=complex)
        a.real[...] = cache["kmm"]
        np.multiply(w[:, None, None], 0.5 * (ch + ch.T), out=a.imag)
        z = np.linalg.solve(a.transpose(0, 2, 1), f)
        # non-finite entries make the sum non-finite (one reduction, no mask)
        if not np.isfinite(z.sum()):
            raise SolverError("coarse stage: singular modal impedance")
        z0, ze = z[:, :, :n_ch], z[:, :, n_ch:]
        self.res0 = self.st = None
        if m < nf:
            self.res0 = prep.residual(system, flat).reshape(nf, n_w, n_ch)
            st_b = prep.residual(system, b.astype(complex)).real
            self.st = np.ascontiguousarray(np.hstack([st_a, st_b]))   # (nf, 2 n_e)
        adj, pa = cache["adj"], cache["pa"]                            # (2d,), (2d, m)
        u4 = cache["u4"].copy()
        v = np.transpose(pa @ z0, (1, 0, 2)).reshape(2, d, n_w, n_ch)
        if self.res0 is not None:
            v += self.res0[adj].reshape(2, d, n_w, n_ch)
        u4[1:3] += v
        u4e = np.empty((4, d, n_w, n_e), dtype=complex)
        u4e[...] = cache["up4"]
        ve = np.transpose(pa @ ze, (1, 0, 2)).reshape(2, d, n_w, n_e)
        if self.st is not None:
            sb = st_b[adj]                                             # (2d, n_e)
            ve += (cache["w2sa"] - iw[None, :, None] * sb[:, None, :]
                   ).reshape(2, d, n_w, n_e)
        u4e[1:3] += ve
        f_end = _end_loads(system, inp, damping)
        self.sup0 = _reactions(system, prep, c, u4, f_end, w)
        self.supe = _reactions(system, prep, c, u4e, np.zeros((2, d, n_w, n_e), complex), w)
        self.inp, self.phi, self.z0, self.ze, self.up, self.u_p = inp, phi, z0, ze, up, u_p

    def reactions(self, rows: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """R_0 (n_w, |rows|, n_ch) and R_e (n_w, |rows|, n_e) on the attached rows."""
        return self.sup0[:, rows, :], self.supe[:, rows, :]

    def combine(self, ue: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """As :meth:`_FossLine.combine`."""
        n_w, m, n_ch = self.z0.shape
        z = self.z0 + self.ze @ ue                                      # (n_w, m, n_ch)
        zf = np.ascontiguousarray(np.transpose(z, (1, 0, 2))).reshape(m, n_w * n_ch)
        uf = _real_gemm(self.phi, zf)
        uet = np.ascontiguousarray(np.transpose(ue, (1, 0, 2)))       # (n_e, n_w, n_ch)
        return _assemble_line(self, uf, ue, uet)


def _assemble_line(part: Any, uf: np.ndarray, ue: np.ndarray, uet: np.ndarray
                   ) -> tuple[np.ndarray, np.ndarray]:
    """The tail of :meth:`_FossLine.combine` and :meth:`_ModalLine.combine`: the free
    rows' modal displacement ``uf`` (nf, n_w·n_ch) plus the truncated modes' static
    correction (physical and unit channels), the static following of the end motions
    ``ue`` (n_w, n_e, n_ch; ``uet`` its (n_e, n_w, n_ch) copy) and the base response:
    node displacements (n_nodes, d, n_w, n_ch) and support forces (n_w, 2d, n_ch)."""
    n, d, n_e = part.up.shape
    n_w, n_ch = ue.shape[0], ue.shape[2]
    flat_e = uet.reshape(n_e, n_w * n_ch)
    if part.res0 is not None:
        w = part.inp.omega
        w2 = (w * w)[None, :, None]
        iw = (1j * w)[None, :, None]
        x = np.concatenate([w2 * uet, -iw * uet], axis=0).reshape(2 * n_e, -1)
        uf += part.res0.reshape(uf.shape[0], -1) + _real_gemm(part.st, x)
    uc = part.u_p.copy()
    uc[1:-1] += uf.reshape(n - 2, d, n_w, n_ch)
    uc += _real_gemm(part.up.reshape(n * d, n_e), flat_e).reshape(n, d, n_w, n_ch)
    sc = part.sup0 + part.supe @ ue
    return uc, sc


def _solve_body(s: np.ndarray, g: np.ndarray, w: np.ndarray) -> np.ndarray:
    try:
        x = np.linalg.solve(s, g)
    except np.linalg.LinAlgError:
        x = None
    if x is None or not np.all(np.isfinite(x)):
        raise SolverError("coupled body solve: the body impedance (with the condensed "
                          "lines) is singular at some frequency (an undamped body "
                          "resonance or a DOF without restoring); add damping or "
                          "stiffness to the body")
    return x


#: Coarse start: every COARSE_STRIDE-th frequency and the last, used when the grid
#: has at least COARSE_MIN_FREQUENCIES points; the coarse iteration stops at
#: COARSE_TOLERANCE_FACTOR times the linearization tolerance (at least 1e-6).
COARSE_STRIDE = 4
COARSE_MIN_FREQUENCIES = 64
COARSE_TOLERANCE_FACTOR = 0.25
#: Default coarse start for linearization tolerances at least this (tighter ones: the
#: coarse iterations stall at their 1e-6 floor and the rounds contract less; on the
#: test mooring 1e-7 needed 6 full + 15 coarse evaluations against 8 full).
COARSE_MIN_TOLERANCE = 1e-6
#: Defect-correction rounds of the coarse start (coarse fixed point of the corrected
#: map, then one full-grid evaluation) before the plain full-grid iteration.
COARSE_CORRECTIONS = 3
#: Coarse frequencies whose σ weight (quadrature weight × spectrum) is at most this
#: fraction of the largest in every channel are left out of the coarse evaluations
#: (their σ contributions are below the coarse stage's round-off).
COARSE_NEGLIGIBLE = 1e-12


def _coarse_subset(g: _Group) -> np.ndarray | None:
    """Indices of the coarse-start grid (None: the grid is too small)."""
    n = g.omega.size
    if n < COARSE_MIN_FREQUENCIES:
        return None
    keep = np.zeros(n, dtype=bool)
    keep[::COARSE_STRIDE] = True
    keep[-1] = True
    idx = np.flatnonzero(keep)
    return idx if idx.size < 0.75 * n else None


#: Defect-correction rounds start with the warm step (:func:`_warm_step`) over the
#: last _WARM_MEMORY coarse evaluations (3: on the benchmark 1 coarse evaluation per
#: round instead of 3; 4 was worse there, docs/BENCHMARKS.md pass E5).
_WARM_ROUNDS = True
_WARM_MEMORY = 3


def _relative_change(new: np.ndarray, x: np.ndarray) -> float:
    """The convergence measure of :func:`stochcable.dynamics.linearization.fixed_point`:
    max |new − x| / max(|new|, 1e-6·max|new|)."""
    den = np.maximum(np.abs(new), 1e-6 * max(float(np.max(np.abs(new), initial=0.0)),
                                             1e-300))
    return float(np.max(np.abs(new - x) / den, initial=0.0))


def _warm_step(pairs: Sequence[tuple[np.ndarray, np.ndarray]], ratio: np.ndarray
               ) -> np.ndarray:
    """Anderson step (type II, unmixed) of the corrected coarse map y -> r·G(y) from
    its secant pairs: the coarse evaluations (x_j, G(x_j)), the last at the current
    full-grid point. [m/s]"""
    x = np.array([p[0] for p in pairs]).T
    res = np.array([ratio * p[1] - p[0] for p in pairs]).T
    f = res[:, -1]
    step = x[:, -1] + f
    if x.shape[1] > 1:
        dx, dr = np.diff(x, axis=1), np.diff(res, axis=1)
        gamma, *_ = np.linalg.lstsq(dr, f, rcond=1e-12)
        step = step - (dx + dr) @ gamma
    return np.maximum(step, 0.0)


def _coarse_group(g: _Group, idx: np.ndarray) -> _Group:
    """The group on the frequencies ``g.omega[idx]``: σ integrals by the full grid's
    trapezoid rule on the subset's cubic interpolant
    (:func:`stochcable.dynamics.line._interpolatory_weights`), the lines' inputs sliced
    from the full grid's (:func:`stochcable.dynamics.line._subset_inputs`), Foss lines
    solved per frequency in modal coordinates (:class:`_ModalLine`); the frequencies
    of negligible σ weight (``COARSE_NEGLIGIBLE``) left out after the weights are
    formed."""
    spectra = np.stack([c.spectrum for c in g.channels], axis=1)[idx]
    weights = _interpolatory_weights(g.omega, idx)[:, None] * spectra
    inp = {cl.name: _subset_inputs(cl.system, tuple(cl.channels), g.inp_phys[cl.name], idx)
           for cl in g.lines}
    # frequencies whose σ weight is negligible in every channel (the spectrum's empty
    # tail) are dropped after the weights are formed: the other weights, the mean
    # squares and the inputs stay those of the interpolant on ``idx``
    ref = np.max(np.abs(weights), axis=0, initial=0.0)
    keep = np.flatnonzero(np.any(np.abs(weights) > COARSE_NEGLIGIBLE * ref, axis=1))
    if 4 <= keep.size < idx.size:
        for cl in g.lines:
            sub = inp[cl.name]
            rows = _subset_inputs(cl.system, _sliced_line(cl, idx).channels, sub, keep)
            inp[cl.name] = dataclasses.replace(rows, weights=sub.weights[keep],
                                               square=sub.square)
        idx, weights = idx[keep], weights[keep]
    gc = _Group([_sliced_line(cl, idx) for cl in g.lines], g.bodies,
                {k: _sliced_loads(v, idx) for k, v in g.loads.items()}, g.rho,
                [_sliced_channel(c, idx) for c in g.channels], inp_phys=inp,
                weights=weights)
    gc.sizes = g.sizes
    gc.modal_direct = True
    return gc


_CHANNEL_ARRAYS = ("velocity", "acceleration", "motion_a", "motion_b", "element_velocity",
                   "element_velocity_square", "element_end_square")
_NODAL_ARRAYS = ("velocity", "acceleration")


def _sliced_channel(c: Channel, idx: np.ndarray) -> Channel:
    """The channel on the frequencies ``omega[idx]`` (every array's first axis).

    Nodal kinematics computed on first use (a channel with ``nodal``, the sea
    channel of :func:`stochcable.dynamics.loads.line_channels`) stay lazy: the sliced
    channel's ``nodal`` slices the full channel's on first access (the coarse stage
    never reads them; slicing them eagerly computed them on the full grid, ≈ 0.4 ms
    per line, docs/BENCHMARKS.md pass E5c)."""
    lazy = c.nodal is not None
    kw: dict[str, Any] = {k: getattr(c, k)[idx] for k in _CHANNEL_ARRAYS
                          if not (lazy and k in _NODAL_ARRAYS) and getattr(c, k) is not None}
    if lazy:
        def nodal() -> tuple[Any, Any]:
            v, a = c.velocity, c.acceleration
            return (None if v is None else v[idx], None if a is None else a[idx])

        kw.update(velocity=None, acceleration=None, nodal=nodal)
    return dataclasses.replace(c, omega=c.omega[idx], spectrum=c.spectrum[idx], **kw)


def _sliced_line(cl: CoupledLine, idx: np.ndarray) -> CoupledLine:
    return dataclasses.replace(cl, channels=tuple(_sliced_channel(c, idx)
                                                  for c in cl.channels))


def _sliced_loads(ld: BodyLoads, idx: np.ndarray) -> BodyLoads:
    return BodyLoads(force=ld.force[idx], velocity=ld.velocity[idx], current=ld.current)


def _make_update(g: _Group, method: str, rho: float, state: dict[str, Any],
                 cache: dict[str, Any], progress: Progress, names: str,
                 timing: dict[str, float] | None) -> Any:
    """The fixed-point map σ -> σ(response to the drag of σ) of a group; ``state``
    holds the evaluation count and the last relative change, ``cache`` the last
    drag, solution and σ."""
    state.setdefault("it", 0)

    def update(x: np.ndarray) -> np.ndarray:
        ls, bs = g.split(x)
        damp = {cl.name: drag_coefficients(cl.system, ls[cl.name], method) for cl in g.lines}
        body_c = np.zeros((g.nb, g.nb))
        body_b = {}
        for b in g.drag:
            bb, c = _body_drag(b, rho, bs[b.name], g.loads[b.name].current
                               if b.name in g.loads else np.zeros(3), method)
            sl = slice(g.off[b.name], g.off[b.name] + b.n_dof)
            body_c[sl, sl] += c
            body_b[b.name] = bb
        sol, xi = _solve_group(g, damp, body_c, body_b, timing)
        new = []
        for cl in g.lines:
            new.append(_sigmas(cl.system, g.inp_phys[cl.name], sol[cl.name][0], method))
        for b in g.drag:
            new.append(_body_sigma(g, b, xi))
        new = np.concatenate(new) if new else np.zeros(0)
        state["it"] += 1
        change = _relative_change(new, x)
        state["change"] = change
        progress("linearization", {"group": names, "iteration": state["it"],
                                   "change": change})
        cache.update(damping=damp, sol=sol, xi=xi, sigma=new, body_b=body_b)
        return new

    update.state = state  # type: ignore[attr-defined]
    return update


def linearize_coupled(
    lines: Sequence[CoupledLine],
    bodies: Sequence[RigidBody],
    settings: Any,
    *,
    rho: float,
    loads: Mapping[str, BodyLoads] | None = None,
    channels: Sequence[Channel] | None = None,
    progress: Progress | None = None,
    timing: dict[str, float] | None = None,
    coarse: bool | None = None,
) -> CoupledLinearization:
    """Drag linearization and response of lines coupled through rigid bodies.

    Parameters
    ----------
    lines : sequence of CoupledLine
        The lines of the group (at least one; all with the same channels).
    bodies : sequence of RigidBody
        The free bodies of the group (static pose as ``position``).
    settings : AnalysisSettings
        ``linearization`` (method, tolerance, max_iterations, relaxation,
        acceleration, allow_unconverged).
    rho : float
        Water density for the body drag. [kg/m³]
    loads : mapping of body name to BodyLoads, optional
        Wave inputs of the bodies (default none).
    channels : sequence of Channel, optional
        The group's channels (names, spectra, grid); default those of the first
        line; required for bodies without lines (a body on springs).
    progress : callable, optional
        ``progress("linearization", {"group", "iteration", "change"})``.
    timing : dict, optional
        Accumulates ``solve_s``. [s]
    coarse : bool, optional
        Start the full-grid iteration from the fixed point of a frequency subset and
        correct it by the full/coarse defect (module docstring, "Coarse start");
        False iterates on the full grid only.  Default: when the tolerance is at
        least ``COARSE_MIN_TOLERANCE`` (1e-6), under both solvers; skipped on grids
        below ``COARSE_MIN_FREQUENCIES``.

    Returns
    -------
    CoupledLinearization

    Raises
    ------
    ConvergenceError
        When the σ do not settle (unless ``allow_unconverged``).
    SolverError
        A singular body impedance (undamped resonance).

    Notes
    -----
    Module docstring: substructuring, fixed point (seed 001 §5.3 steps 5–13 over all
    lines and bodies).
    """
    lin = settings.linearization
    method = lin.method
    progress = _noop if progress is None else progress
    if channels is None:
        if not lines:
            raise InputError("channels", None, "-",
                             "a group without lines needs its channels")
        channels = lines[0].channels
    if not lines and not bodies:
        raise InputError("lines", 0, "-", "a coupled group needs a line or a body")
    g = _Group(lines, bodies, loads or {}, rho, channels)
    names = ", ".join(cl.name for cl in g.lines)
    gname = f"coupled drag linearization of lines {names} and bodies " \
            f"{', '.join(b.name for b in g.bodies)}"
    # start: lines at rest (quasi-static on their moving ends), bodies at rest
    parts = [_sigmas(cl.system, g.inp_phys[cl.name],
                     _quasi_static(cl.system, g.inp_phys[cl.name]), method)
             for cl in g.lines]
    g.sizes = {cl.name: p.size for cl, p in zip(g.lines, parts)}
    for b in g.drag:
        parts.append(_body_sigma(g, b, None))
    x_rest = np.concatenate(parts) if parts else np.zeros(0)
    state: dict[str, Any] = {"it": 0}
    cache: dict[str, Any] = {}
    hint = ("increase analysis.linearization.max_iterations, lower relaxation, or set "
            "allow_unconverged to get a flagged result")
    fixed = dict(relaxation=lin.relaxation,
                 method="anderson" if lin.acceleration == "anderson" else "relaxed",
                 mixing=ANDERSON_MIXING)
    # coarse stage (module docstring "Coarse start"): the fixed point of a frequency
    # subset supplies the start of the full-grid iteration; its history is kept
    coarse_hist: tuple[float, ...] = ()
    if coarse is None:
        coarse = lin.tolerance >= COARSE_MIN_TOLERANCE
    idx = _coarse_subset(g) if coarse and x_rest.size else None
    # the coarse model is only good to its defect: no tighter than 1e-6 (round-off
    # noise of the σ stalls tighter coarse iterations; the full grid finishes)
    tol_c = max(lin.tolerance * COARSE_TOLERANCE_FACTOR, 1e-6)
    last: dict[str, np.ndarray] = {}
    pairs: list[tuple[np.ndarray, np.ndarray]] = []
    use_coarse = False
    if idx is not None:
        gc = _coarse_group(g, idx)
        raw_c = _make_update(gc, method, rho, state, {}, progress, names, None)

        def upd_c(y: np.ndarray) -> np.ndarray:
            """The coarse map, remembering its inputs and outputs."""
            out = raw_c(y)
            last["x"], last["g"] = np.array(y, dtype=float), out
            pairs.append((last["x"], out))
            return out

        try:
            xc = upd_c(x_rest)
            hc: tuple[float, ...] = (raw_c.state["change"],)
            if np.all(np.isfinite(xc)) and hc[0] > tol_c:
                fc = fixed_point(upd_c, xc, tol=tol_c, max_iterations=lin.max_iterations,
                                 allow_unconverged=True, name=gname + " (coarse start)",
                                 **fixed)
                hc = hc + tuple(fc.history)
            use_coarse = bool(np.all(np.isfinite(last["g"])))
        except (SolverError, ConvergenceError, np.linalg.LinAlgError):
            # a singular or non-finite coarse model: the full grid alone (its checks)
            use_coarse = False
        if use_coarse:
            # the full grid starts at the coarse map's last input, whose coarse
            # response is known (the defect correction below needs both)
            x_rest, coarse_hist = last["x"], hc
    update = _make_update(g, method, rho, state, cache, progress, names, timing)
    x_full = last.get("x") if use_coarse else None
    x0 = update(x_rest)
    change0 = state["change"]
    # defect correction (module docstring "Coarse start"): the coarse map scaled by
    # the full/coarse ratio at the last full-grid point has that point's full-grid
    # response; its fixed point (coarse evaluations) is the next full-grid point
    rounds = 0
    while (use_coarse and rounds < COARSE_CORRECTIONS and np.all(np.isfinite(x0))
           and change0 > lin.tolerance and rounds + 2 < lin.max_iterations):
        try:
            if x_full is not last["x"]:
                # the coarse response at the last full-grid point (warm rounds)
                upd_c(x_full)
                coarse_hist = coarse_hist + (raw_c.state["change"],)
                last["x"] = x_full
            g_in = last["g"]
            ratio = np.clip(np.divide(x0, g_in, out=np.ones_like(x0), where=g_in > 0),
                            0.1, 10.0)
            tol_r = max(tol_c, 0.005 * change0)
            hist: tuple[float, ...] = ()
            start = x0
            if _WARM_ROUNDS and len(pairs) > 1:
                # one step of the corrected map from the Anderson extrapolation of the
                # last coarse secant pairs (its Jacobian is the coarse one, scaled);
                # accepted when it moved the corrected map 10x closer than the
                # full-grid change, else its result starts the corrected iteration
                y0 = _warm_step(pairs[-_WARM_MEMORY:], ratio)
                h = ratio * upd_c(y0)
                hist = (_relative_change(h, y0),)
                start = h
            if hist and hist[0] <= max(tol_r, 0.1 * change0):
                x_next = h
            else:
                fc = fixed_point(lambda y, r=ratio: r * upd_c(y), start, tol=tol_r,
                                 max_iterations=lin.max_iterations, allow_unconverged=True,
                                 name=gname + " (coarse correction)", **fixed)
                hist, x_next = hist + fc.history, last["x"]
        except (SolverError, ConvergenceError, np.linalg.LinAlgError):
            break
        if not (np.all(np.isfinite(last["g"])) and np.all(np.isfinite(x_next))):
            break
        coarse_hist = coarse_hist + (change0,) + hist
        rounds += 1
        x_full = x_next
        x0 = update(x_full)
        prev, change0 = change0, state["change"]
        if change0 > 0.3 * prev:   # not contracting: the plain full-grid iteration
            break
    n_c = len(coarse_hist)
    if not np.all(np.isfinite(x0)):
        raise ConvergenceError(gname, n_c + 1, float("nan"), lin.tolerance,
                               hint="the first response gave non-finite σ")
    if change0 <= lin.tolerance or lin.max_iterations == 1 or x0.size == 0:
        fp = FixedPointResult(x0, 1, change0, change0 <= lin.tolerance or x0.size == 0,
                              (change0,))
        if not fp.converged and not lin.allow_unconverged:
            raise ConvergenceError(gname, n_c + 1, change0, lin.tolerance, hint=hint,
                                   partial=fp)
    else:
        try:
            fp = fixed_point(
                update, x0, tol=lin.tolerance,
                max_iterations=lin.max_iterations - 1 - rounds,
                allow_unconverged=lin.allow_unconverged, name=gname, **fixed,
            )
        except ConvergenceError as exc:
            raise ConvergenceError(gname, n_c + exc.iterations + 1, exc.residual,
                                   exc.tolerance, hint=hint, partial=exc.partial) from None
        fp = FixedPointResult(fp.x, fp.iterations + 1, fp.relative_change, fp.converged,
                              (change0,) + fp.history)
    fp = FixedPointResult(fp.x, n_c + fp.iterations, fp.relative_change, fp.converged,
                          coarse_hist + fp.history)
    if not fp.converged:
        warn(f"{gname} did not converge: relative change {fp.relative_change:.3e} after "
             f"{fp.iterations} iterations (tolerance {lin.tolerance:.1e}); the result is "
             "flagged unconverged (increase analysis.linearization.max_iterations)",
             PhysicsWarning, stacklevel=2)
    ls, bs = g.split(cache["sigma"])
    out = {}
    for cl in g.lines:
        system = cl.system
        damping = cache["damping"][cl.name]
        uc, sc = cache["sol"][cl.name]
        resp = Response(omega=g.omega, displacement=_to_freq(uc), support_force=sc,
                        end_tension=_end_tension(system, sc))
        record = linearization_record(system, ls[cl.name], damping, fp, lin.tolerance,
                                      method)
        out[cl.name] = Linearization(damping=damping, record=record, response=resp)
    xi = cache["xi"]
    motion = {b.name: xi[:, g.off[b.name]:g.off[b.name] + b.n_dof, :].copy()
              for b in g.bodies}
    return CoupledLinearization(
        lines=out, body_motion=motion,
        body_sigma={b.name: bs[b.name].copy() for b in g.drag},
        body_drag={k: v.copy() for k, v in cache["body_b"].items()},
        converged=fp.converged, iterations=fp.iterations,
        relative_change=fp.relative_change, history=fp.history, tolerance=lin.tolerance)


# ------------------------------------------------------------------------ modes


@dataclass(frozen=True, eq=False)
class CoupledModes:
    """Natural modes of a coupled group (undamped, constant matrices).

    Attributes
    ----------
    omega : ndarray, shape (n,)
        Natural frequencies, lowest first. [rad/s]
    body_fraction : ndarray, shape (n,)
        Share of each mass-normalized mode's kinetic energy in the body DOFs,
        φ_Jᵀ(Mφ)_J. [-]
    body_shapes : dict of str to ndarray, shape (d, n)
        Body part of each mode shape (mass-normalized). [m·kg^-1/2, rad·kg^-1/2]
    omega_ref : float
        Frequency at which the bodies' added mass was frozen. [rad/s]
    asymmetry : float
        max|K − Kᵀ|/max|K| of the coupled stiffness (its symmetric part is used). [-]
    """

    omega: np.ndarray
    body_fraction: np.ndarray
    body_shapes: dict[str, np.ndarray]
    omega_ref: float
    asymmetry: float

    def as_dict(self) -> dict[str, Any]:
        return {"omega": self.omega.tolist(), "body_fraction": self.body_fraction.tolist(),
                "omega_ref": float(self.omega_ref), "asymmetry": float(self.asymmetry)}


def coupled_modes(lines: Sequence[CoupledLine], bodies: Sequence[RigidBody],
                  omega_ref: float, omega_top: float, *,
                  method: str = "auto") -> CoupledModes:
    """Natural modes of lines and bodies coupled by rigid links.

    Parameters
    ----------
    lines : sequence of CoupledLine
    bodies : sequence of RigidBody
        Their ``fixed_dofs`` are constraints (ξ_j ≡ 0): the modes are those of the
        constrained system, the fixed rows of ``body_shapes`` are zero.
    omega_ref : float
        Frequency of the added mass A(ω_ref) (spectral peak). [rad/s]
    omega_top : float
        Top of the analysis grid: modes up to 2.5·omega_top are listed, at least 10.
        [rad/s]
    method : {"auto", "full", "reduced"}
        "full": the assembled system; "reduced": the Craig–Bampton reduction;
        "auto": reduced when every line's highest fixed-end mode is at least
        ``_CB_MIN_RATIO`` times the listing top, else full.

    Returns
    -------
    CoupledModes

    Notes
    -----
    K φ = ω²(M + A(ω_ref)) φ on the assembled system of
    :func:`stochcable.bodies.rigid.couple` (:func:`~stochcable.bodies.rigid.constant_matrices`),
    the symmetric part of K (the attachment geometric stiffness is antisymmetric by
    ½[Σ r × F]× when the static moments on a body are not balanced by the model's own
    terms; :attr:`CoupledModes.asymmetry`).  Full: dense LAPACK up to 1500 DOFs, else
    shift-invert Lanczos.  Reduced (Craig–Bampton): each line's free DOFs are
    x_f = Φ q + G T ξ, Φ its fixed-end modes (all computed), G = −K_ff⁻¹K_fe its
    static following of the attached ends, T the rigid links; the eigenproblem of
    Lᵀ K L, Lᵀ M L over (q of every line, ξ) is a Rayleigh–Ritz projection of the
    full one (upper bounds; on the three-leg benchmark the listed frequencies agree
    within 1e-4 relative, tests/test_coupled_analysis.py).
    """
    if method not in ("auto", "full", "reduced"):
        raise InputError("method", method, "-", "must be 'auto', 'full' or 'reduced'")
    top = (LISTED_MODE_FACTOR * omega_top) ** 2
    if method == "auto":
        ok = bool(lines) and all(
            cl.system.modes is not None and cl.system.modes.count
            and float(np.max(cl.system.modes.omega)) >= _CB_MIN_RATIO * math.sqrt(top)
            and cl.system.model.free.size == (cl.system.model.n_nodes - 2)
            * cl.system.model.dim for cl in lines)
        method = "reduced" if ok else "full"
    if method == "reduced":
        return _coupled_modes_reduced(lines, bodies, omega_ref, top)
    return _coupled_modes_full(lines, bodies, omega_ref, top)


#: Craig–Bampton coupled modes ("auto") when every line's highest fixed-end mode is at
#: least this factor above the top listed frequency.
_CB_MIN_RATIO = 1.5


def _fixed_body_rows(bodies: Sequence[RigidBody], body_dofs: Mapping[str, np.ndarray]
                     ) -> np.ndarray:
    """Coupled indices of the fixed body DOFs."""
    out = [body_dofs[b.name][i] for b in bodies
           for i, n in enumerate(b.dof_names) if n in b.fixed_dofs]
    return np.asarray(out, dtype=int)


def _listed_eigh(kd: np.ndarray, md: np.ndarray, top: float
                 ) -> tuple[np.ndarray, np.ndarray]:
    n = kd.shape[0]
    if n == 0:
        return np.zeros(0), np.zeros((0, 0))
    if n <= _ALL_EIGH_MAX:
        # every eigenpair by divide and conquer, then the listed ones: on the
        # benchmark's 126-DOF reduction 1.2 ms against 2.5 ms for the subset driver
        # (the same eigenvalues to 3e-13; docs/BENCHMARKS.md "Bodies", pass E5b)
        lam, phi = sla.eigh(kd, md, driver="gvd")
        k = max(int(np.searchsorted(lam, top, side="right")), min(MIN_LISTED_MODES, n))
        return lam[:k], phi[:, :k]
    lam, phi = sla.eigh(kd, md, subset_by_value=(-np.inf, top), driver="gvx")
    if lam.size < min(MIN_LISTED_MODES, n):
        lam, phi = sla.eigh(kd, md, subset_by_index=(0, min(MIN_LISTED_MODES, n) - 1))
    return lam, phi


def _coupled_modes_full(lines: Sequence[CoupledLine], bodies: Sequence[RigidBody],
                        omega_ref: float, top: float) -> CoupledModes:
    """:func:`coupled_modes` on the assembled system (the reference)."""
    links = [LineLink(cl.name, cl.system.model, end_a=cl.end_a, end_b=cl.end_b,
                      force_a=cl.system.statics.force_a if cl.end_a else None,
                      force_b=cl.system.statics.force_b if cl.end_b else None)
             for cl in lines]
    system = couple(links, bodies)
    K, M, _ = constant_matrices(system, omega_ref)
    asym = system.asymmetry()
    ks = 0.5 * (K + K.T)
    n = system.n_dof
    keep = np.setdiff1d(np.arange(n), _fixed_body_rows(bodies, system.body_dofs))
    ks, M = ks[keep][:, keep], M[keep][:, keep]
    nk = keep.size
    if nk <= _DENSE_MODES:
        kd, md = ks.toarray(), M.toarray()
        md = 0.5 * (md + md.T)
        lam, phi = _listed_eigh(kd, md, top)
    else:
        from scipy.sparse.linalg import eigsh

        k = min(max(MIN_LISTED_MODES, 20), nk - 2)
        lam, phi = eigsh(ks.tocsc(), k=k, M=M.tocsc(), sigma=0.0, which="LM")
        order = np.argsort(lam)
        lam, phi = lam[order], phi[:, order]
    mphi = M @ phi
    full = np.zeros((n, lam.size))
    full[keep] = phi
    mfull = np.zeros((n, lam.size))
    mfull[keep] = mphi
    J = system.body_index
    frac = np.einsum("jn,jn->n", full[J], mfull[J]) if J.size else np.zeros(lam.size)
    shapes = {b.name: full[system.body_dofs[b.name]].copy() for b in bodies}
    return CoupledModes(omega=np.sqrt(np.clip(lam, 0.0, None)),
                        body_fraction=np.clip(frac, 0.0, 1.0), body_shapes=shapes,
                        omega_ref=float(omega_ref), asymmetry=asym)


def _coupled_modes_reduced(lines: Sequence[CoupledLine], bodies: Sequence[RigidBody],
                           omega_ref: float, top: float) -> CoupledModes:
    """:func:`coupled_modes` by the Craig–Bampton reduction (its Notes)."""
    by_name = {b.name: b for b in bodies}
    off, nb = {}, 0
    for b in bodies:
        off[b.name] = nb
        nb += b.n_dof
    kb, mb = np.zeros((nb, nb)), np.zeros((nb, nb))
    for b in bodies:
        sl = slice(off[b.name], off[b.name] + b.n_dof)
        kb[sl, sl] = b.hydrostatic_stiffness + b.extra_stiffness
        mb[sl, sl] = b.mass_matrix() + b.added_mass_at(np.array([omega_ref]))[0]
    parts = []          # per line: (L (n_dof, m + nb), K, M, end rows, T rows)
    top_k = 0.0
    kb_lines = np.zeros((nb, nb))
    m_tot = 0
    for cl in lines:
        model = cl.system.model
        d, nn = model.dim, model.n_nodes
        phi = np.asarray(cl.system.modes.shapes)[model.free]
        m = phi.shape[1]
        t = np.zeros((2 * d, nb))
        for k, bname in cl.attached():
            body = by_name[bname]
            node = 0 if k == 0 else nn - 1
            r = model.positions[node] - body.position
            t[k * d:(k + 1) * d, off[bname]:off[bname] + body.n_dof] = rigid_link_matrix(
                r, planar=body.planar)
            st = cl.system.statics
            f = np.asarray(st.force_a if k == 0 else st.force_b, dtype=float)
            sl = slice(off[bname], off[bname] + body.n_dof)
            kb[sl, sl] += attachment_geometric_stiffness(f, r, body.planar)
        ends = np.r_[np.arange(d), np.arange((nn - 1) * d, nn * d)]
        kd_ = model.K.toarray()
        md_ = model.M.toarray() + model.Ma.toarray()
        # the assembled (physical) coupling Lᵀ K L, L = [free selection, ends → T],
        # for the asymmetry measure of the full K: its free rows K[free] L and body
        # block Tᵀ K_ends T (the selection rows of Lᵀ taken by indexing)
        lp = np.zeros((model.n_dof, model.free.size + nb))
        lp[model.free, np.arange(model.free.size)] = 1.0
        lp[ends, model.free.size:] = t
        top_k = max(top_k, float(np.abs(kd_[model.free] @ lp).max(initial=0.0)))
        kb_lines += t.T @ kd_[np.ix_(ends, ends)] @ t
        ell = np.zeros((model.n_dof, m + nb))
        ell[model.free, :m] = phi
        ell[model.free, m:] = _prep(cl.system).follower() @ t
        ell[ends, m:] = t
        parts.append((ell, kd_, md_, ends, t, m_tot, m))
        m_tot += m
    kfull_b = kb_lines + kb
    top_k = max(top_k, float(np.abs(kfull_b).max(initial=0.0)))
    asym = float(np.abs(kfull_b - kfull_b.T).max(initial=0.0) / top_k) if top_k > 0 else 0.0
    n = m_tot + nb
    kr, mr = np.zeros((n, n)), np.zeros((n, n))
    for ell, kd_, md_, _, _, o, m in parts:
        idx = np.r_[np.arange(o, o + m), np.arange(m_tot, n)]
        kr[np.ix_(idx, idx)] += ell.T @ kd_ @ ell
        mr[np.ix_(idx, idx)] += ell.T @ md_ @ ell
    kr[m_tot:, m_tot:] += kb
    mr[m_tot:, m_tot:] += mb
    fixed = m_tot + _fixed_body_rows(bodies, {b.name: np.arange(off[b.name], off[b.name]
                                                                 + b.n_dof) for b in bodies})
    keep = np.setdiff1d(np.arange(n), fixed)
    ks = 0.5 * (kr + kr.T)[np.ix_(keep, keep)]
    ms = 0.5 * (mr + mr.T)[np.ix_(keep, keep)]
    lam, z = _listed_eigh(ks, ms, top)
    zf = np.zeros((n, lam.size))
    zf[keep] = z
    xi = zf[m_tot:]
    # (M φ) on the body DOFs of the full system: Σ Tᵀ (M_line u)_ends + M_B ξ
    mxi = mb @ xi
    for ell, _, md_, ends, t, o, m in parts:
        u = ell @ np.r_[zf[o:o + m], xi]
        mxi += t.T @ (md_[ends] @ u)
    frac = np.einsum("jn,jn->n", xi, mxi) if nb else np.zeros(lam.size)
    shapes = {b.name: xi[off[b.name]:off[b.name] + b.n_dof].copy() for b in bodies}
    return CoupledModes(omega=np.sqrt(np.clip(lam, 0.0, None)),
                        body_fraction=np.clip(frac, 0.0, 1.0), body_shapes=shapes,
                        omega_ref=float(omega_ref), asymmetry=asym)


# --------------------------------------------------------------------- results


def coupled_results(
    lines: Sequence[CoupledLine],
    bodies: Sequence[RigidBody],
    linearization: CoupledLinearization,
    settings: Any,
    *,
    static_pose: Mapping[str, np.ndarray] | None = None,
    modes: CoupledModes | None = None,
    channels: Sequence[Channel] | None = None,
) -> tuple[dict[str, LineResult], dict[str, BodyResult]]:
    """Line and body results of a coupled group.

    Parameters
    ----------
    lines : sequence of CoupledLine
    bodies : sequence of RigidBody
    linearization : CoupledLinearization
    settings : AnalysisSettings
        ``duration`` for the maxima.
    static_pose : mapping of body name to ndarray (d,), optional
        Static value of each body DOF (position and rotation components), the
        statistics' mean (default: the body position, zero rotation). [m, rad]
    modes : CoupledModes, optional
        Listed on every body result.
    channels : sequence of Channel, optional
        The group's channels (default those of the first line).

    Returns
    -------
    (lines, bodies) : dict of LineResult, dict of BodyResult
    """
    out_lines = {}
    for cl in lines:
        out_lines[cl.name] = line_result(cl.system, cl.channels,
                                         linearization.lines[cl.name], settings)
    ch = tuple(lines[0].channels if channels is None else channels)
    spectra = np.stack([c.spectrum for c in ch])
    w = ch[0].omega
    out_bodies = {}
    for b in bodies:
        h = np.transpose(linearization.body_motion[b.name], (2, 1, 0))  # (n_ch, d, n_w)
        if static_pose is not None and b.name in static_pose:
            mean = np.asarray(static_pose[b.name], dtype=float)
        else:
            full = np.concatenate([b.position, np.zeros(3)])
            mean = full[list(PLANAR_INDEX)] if b.planar else full
        out_bodies[b.name] = body_result(b.name, b.dof_names, w, tuple(c.name for c in ch),
                                         spectra, h, mean, settings.duration,
                                         sigma=linearization.body_sigma.get(b.name),
                                         drag=linearization.body_drag.get(b.name),
                                         modes=modes, prescribed=False)
    return out_lines, out_bodies


def body_result(name: str, dofs: Sequence[str], omega: np.ndarray,
                channels: tuple[str, ...], spectra: np.ndarray, transfer: np.ndarray,
                mean: np.ndarray, duration: float, *, sigma: Any = None, drag: Any = None,
                modes: CoupledModes | None = None, prescribed: bool = False) -> BodyResult:
    """Statistics of a body's motion from its transfer functions (see BodyResult)."""
    dens = np.einsum("cdw,cw->dw", np.abs(transfer) ** 2, spectra)
    stats = {dof: stats_from_spectrum(omega, dens[i], float(mean[i]), duration)
             for i, dof in enumerate(dofs)}
    return BodyResult(name=name, dofs=tuple(dofs), omega=np.asarray(omega).copy(),
                      channels=tuple(channels), input_spectra=np.asarray(spectra).copy(),
                      motion_transfer=transfer, motion=stats, prescribed=prescribed,
                      drag_sigma=None if sigma is None else np.asarray(sigma).copy(),
                      drag_coefficient=None if drag is None else np.asarray(drag).copy(),
                      modes=modes)


# ------------------------------------------------------------------------ scene


#: Static body rotation above which the body's data (given at its input orientation)
#: are flagged: the rigid-body matrices, hydrodynamic coefficients, hydrostatics,
#: excitation and drag point are used unrotated, only the line attachment arms follow
#: the static rotation. 5° moves a body-fixed direction by sin 5° ≈ 9 % of its length.
STATIC_ROTATION_LIMIT = math.radians(5.0)


def _static_rotation_check(name: str, rotation: np.ndarray) -> None:
    """PhysicsWarning when a body's static rotation exceeds STATIC_ROTATION_LIMIT."""
    angle = float(np.linalg.norm(rotation))
    if angle > STATIC_ROTATION_LIMIT:
        warn(f"body '{name}': its static rotation is {math.degrees(angle):.3g}° "
             f"(rotation vector {np.round(np.degrees(rotation), 3).tolist()} deg), above "
             f"{math.degrees(STATIC_ROTATION_LIMIT):g}°: the dynamics use its mass, inertia, "
             "added mass, damping, hydrostatic stiffness, excitation and drag point at the "
             "input orientation (only the line attachment arms follow the rotation), so "
             "they are off by about the sine of that angle; give the body's data at its "
             "static orientation (rotate them and the attachment points) and re-run",
             PhysicsWarning, stacklevel=3)


def analyze_coupled(scene: Any, statics: Any, settings: Any,
                    progress: Progress | None = None,
                    timing: dict[str, float] | None = None, *,
                    rigid_bodies: Mapping[str, RigidBody] | None = None
                    ) -> CoupledAnalysis:
    """Frequency-domain analysis of a scene with bodies (the ``analyze`` branch).

    Parameters
    ----------
    scene : Scene
        A validated scene with ``bodies``.
    statics : StaticsResult
        Its static equilibrium (lines with attached ends at the body poses, and
        ``statics.bodies``).
    settings : AnalysisSettings
    progress : callable, optional
    timing : dict, optional
        Accumulates ``model_s``, ``linearization_s``, ``solve_s``, ``outputs_s``. [s]
    rigid_bodies : mapping of str to RigidBody, optional
        The bodies as RigidBody (default
        :func:`stochcable.bodies.from_scene.scene_rigid_bodies`); their ``position`` is
        replaced by the static pose of ``statics.bodies`` when present.

    Returns
    -------
    CoupledAnalysis
        Unpacks as ``lines, bodies, systems, dampings``:  every line's LineResult in
        scene order; every body's BodyResult (prescribed ones with their RAO motion);
        the LineSystem and converged Damping of the lines NOT coupled to a free body.
        ``groups`` holds the converged state of each coupled group (and of each
        free-floating body without lines) for the time series
        (:func:`stochcable.dynamics.coupled_timeseries.coupled_group_transfer`).

    Notes
    -----
    Lines attached to no free body: the independent path of
    :mod:`stochcable.dynamics.line` (linearize, line_result), an end on a prescribed
    body moving with :func:`fairlead_motion` in the sea channel.  Each connected
    component of free bodies and their lines is one coupled group
    (:func:`linearize_coupled`, :func:`coupled_modes`, :func:`coupled_results`).
    """
    from stochcable.dynamics.fixedpoint import linearize
    from stochcable.dynamics.line_loads import silent_channel as _silent_channel
    from stochcable.dynamics.system import build_line_system

    progress = _noop if progress is None else progress
    timing = {} if timing is None else timing
    for key in ("model_s", "linearization_s", "solve_s", "outputs_s"):
        timing.setdefault(key, 0.0)
    omega = settings.omega.values()
    env = scene.environment
    t0 = time.perf_counter()
    if rigid_bodies is None:
        from stochcable.bodies.from_scene import scene_rigid_bodies

        rigid_bodies = scene_rigid_bodies(scene)
    rigid = dict(rigid_bodies)
    body_docs = {b.name: b for b in scene.bodies}
    prescribed = {n for n, b in body_docs.items() if getattr(b, "prescribed", None) is not None}
    bstat = getattr(statics, "bodies", {}) or {}
    free: dict[str, RigidBody] = {}
    pose: dict[str, np.ndarray] = {}
    for name in body_docs:
        if name in prescribed:
            continue
        if name not in rigid:
            raise InputError("rigid_bodies", name, "-", "a free body has no RigidBody")
        body = rigid[name]
        if name in bstat:
            pos = np.asarray(bstat[name].position, dtype=float)
            rot = np.asarray(bstat[name].rotation, dtype=float)
        else:
            pos, rot = np.asarray(body.position, dtype=float), np.zeros(3)
        _static_rotation_check(name, rot)
        full = np.concatenate([pos, rot])
        pose[name] = full[list(PLANAR_INDEX)] if body.planar else full
        extra = body.extra_stiffness
        if not np.any(body.hydrostatic_stiffness):
            # no hydrostatic matrix: the statics apply the weight at the CoG and the
            # buoyancy (if a displaced volume is given) at the CoB exactly
            # (stochcable.bodies.statics), so their rotation restoring belongs to the
            # linearization (body_gravity_stiffness); a hydrostatic matrix already
            # holds these gravity terms (WAMIT convention)
            vol = getattr(body_docs[name], "displaced_volume", None) or 0.0
            cob = getattr(body_docs[name], "centre_of_buoyancy", None)
            extra = extra + body_gravity_stiffness(
                body, vol, np.zeros(3) if cob is None else cob, env.rho, env.g)
        free[name] = dataclasses.replace(body, position=pos, extra_stiffness=extra)
    # vessel RAOs on the grid
    vessel_rao = {n: _vessel_rao(body_docs[n].prescribed, omega) for n in prescribed}
    systems: dict[str, LineSystem] = {}
    chans: dict[str, tuple[Channel, ...]] = {}
    attach: dict[str, dict[str, str]] = {}
    for line in scene.lines:
        system = build_line_system(scene, line, statics.lines[line.name], settings=settings)
        ch, att = _scene_line_channels(scene, line, system, omega, vessel_rao)
        systems[line.name] = system
        chans[line.name] = ch
        attach[line.name] = att
    timing["model_s"] += time.perf_counter() - t0
    # connected groups of free bodies
    parent = {n: n for n in free}

    def root(n: str) -> str:
        while parent[n] != n:
            n = parent[n]
        return n

    for line in scene.lines:
        bs = list(attach[line.name].values())
        for b in bs[1:]:
            parent[root(b)] = root(bs[0])
    lines_out: dict[str, LineResult] = {}
    bodies_out: dict[str, BodyResult] = {}
    ind_systems: dict[str, LineSystem] = {}
    dampings: dict[str, Damping] = {}
    groups: dict[str, list[str]] = {}
    states: list[CoupledGroup] = []
    for line in scene.lines:
        if attach[line.name]:
            groups.setdefault(root(next(iter(attach[line.name].values()))), []).append(line.name)
    for line in scene.lines:
        if attach[line.name]:
            continue
        system, ch = systems[line.name], chans[line.name]
        if not ch:
            warn(f"line '{line.name}' has no excitation (no sea and no end motion): its "
                 "dynamic response is zero; add a 'sea' or an end 'motion'",
                 PhysicsWarning, stacklevel=2)
            ch = _silent_channel(omega)
        t1 = time.perf_counter()
        lin = linearize(system, ch, settings, progress=progress, timing=timing)
        timing["linearization_s"] += time.perf_counter() - t1
        t1 = time.perf_counter()
        lines_out[line.name] = line_result(system, ch, lin, settings)
        timing["outputs_s"] += time.perf_counter() - t1
        ind_systems[line.name] = system
        dampings[line.name] = lin.damping
    for rootname, lnames in groups.items():
        gbodies = [free[n] for n in free if root(n) == rootname]
        group_ch = _group_channels(lnames, chans, omega)
        cls = [CoupledLine(systems[n], group_ch[n], end_a=attach[n].get("end_a"),
                           end_b=attach[n].get("end_b")) for n in lnames]
        first = cls[0].channels
        loads = {b.name: body_loads(b, first, omega, scene.sea, env) for b in gbodies}
        t1 = time.perf_counter()
        clin = linearize_coupled(cls, gbodies, settings, rho=env.rho, loads=loads,
                                 progress=progress, timing=timing)
        timing["linearization_s"] += time.perf_counter() - t1
        t1 = time.perf_counter()
        w_ref = _reference_omega(first, omega)
        modes = coupled_modes(cls, gbodies, w_ref, float(omega[-1]))
        lo, bo = coupled_results(cls, gbodies, clin, settings, static_pose=pose, modes=modes)
        timing["outputs_s"] += time.perf_counter() - t1
        lines_out.update(lo)
        bodies_out.update(bo)
        states.append(_group_state(lnames, systems, attach, gbodies, pose, clin))
    for n in free:  # free-floating bodies without lines: the body alone
        if n in bodies_out:
            continue
        if scene.sea is None:
            warn(f"body '{n}' has no lines and there is no sea: its motion is zero",
                 PhysicsWarning, stacklevel=2)
            continue
        from stochcable.dynamics.loads import spectrum_callable as _spectrum_callable

        dens = _spectrum_callable(scene.sea.spectrum, env.g)
        sea_ch = (Channel(name="sea", kind="sea", omega=omega, spectrum=dens(omega),
                          density=dens),)
        b = free[n]
        t1 = time.perf_counter()
        clin = linearize_coupled([], [b], settings, rho=env.rho, channels=sea_ch,
                                 loads={n: body_loads(b, sea_ch, omega, scene.sea, env)},
                                 progress=progress, timing=timing)
        timing["linearization_s"] += time.perf_counter() - t1
        _, bo = coupled_results([], [b], clin, settings, static_pose=pose, channels=sea_ch)
        bodies_out.update(bo)
        states.append(_group_state([], systems, attach, [b], pose, clin))
    for n in prescribed:
        if scene.sea is None:
            continue
        h = vessel_rao[n].T[None]   # (1, 6, n_w)
        sea = np.atleast_2d(scene.sea.spectrum.spectral_density(omega, env.g))
        dofs = ("surge", "sway", "heave", "roll", "pitch", "yaw")
        mean = np.concatenate([np.asarray(body_docs[n].position, float), np.zeros(3)])
        bodies_out[n] = body_result(n, dofs, omega, ("sea",), sea, h, mean,
                                    settings.duration, prescribed=True)
    ordered = {line.name: lines_out[line.name] for line in scene.lines}
    ordered_b = {b.name: bodies_out[b.name] for b in scene.bodies if b.name in bodies_out}
    return CoupledAnalysis(ordered, ordered_b, ind_systems, dampings, tuple(states))


def _reference_omega(channels: Sequence[Channel], omega: np.ndarray) -> float:
    """Peak of the sea spectrum on the grid (else of the first channel, else the grid
    middle): where frequency-dependent added mass is frozen for the modes."""
    for c in channels:
        if c.kind == "sea" and np.any(c.spectrum > 0):
            return float(omega[int(np.argmax(c.spectrum))])
    for c in channels:
        if np.any(c.spectrum > 0):
            return float(omega[int(np.argmax(c.spectrum))])
    return float(omega[omega.size // 2])


def _group_channels(lnames: Sequence[str], chans: Mapping[str, tuple[Channel, ...]],
                    omega: np.ndarray) -> dict[str, tuple[Channel, ...]]:
    """Align the lines' channels on the group list: "sea" then "<line>.<end>.<dof>"."""
    order: list[tuple[str, str, Channel]] = []
    sea = None
    for n in lnames:
        for c in chans[n]:
            if c.kind == "sea":
                sea = c
            else:
                order.append((n, f"{n}.{c.name}", c))
    out = {}
    for n in lnames:
        own = {c.name: c for c in chans[n]}
        lst = []
        if sea is not None:
            lst.append(own.get("sea", dataclasses.replace(
                sea, velocity=None, acceleration=None, motion_a=None, motion_b=None,
                element_velocity=None, element_velocity_square=None,
                element_end_square=None)))
        for owner, full, c in order:
            if owner == n:
                lst.append(dataclasses.replace(c, name=full))
            else:
                lst.append(Channel(name=full, kind="end_motion", omega=c.omega,
                                   spectrum=c.spectrum, density=c.density))
        if not lst:
            lst = [Channel(name="none", kind="none", omega=omega,
                           spectrum=np.zeros(omega.size), density=_zero_density)]
        out[n] = tuple(lst)
    return out


def _vessel_rao(motion: Any, omega: np.ndarray) -> np.ndarray:
    """6-DOF vessel RAO (n_omega, 6) on the grid from a scene VesselMotion (zero
    outside its table, as end-motion RAOs)."""
    if hasattr(motion, "transfer"):  # (6, n_omega), as MotionRao.transfer's (3, n)
        return np.asarray(motion.transfer(omega), dtype=complex).T
    out = np.zeros((omega.size, 6), dtype=complex)
    w = np.asarray(motion.omega, dtype=float)
    for i, k in enumerate(("surge", "sway", "heave", "roll", "pitch", "yaw")):
        tab = getattr(motion, k, None)
        if tab is None:
            continue
        v = tab.values()
        out[:, i] = (np.interp(omega, w, v.real, 0.0, 0.0)
                     + 1j * np.interp(omega, w, v.imag, 0.0, 0.0))
    return out


def _scene_line_channels(scene: Any, line: Any, system: LineSystem, omega: np.ndarray,
                         vessel_rao: Mapping[str, np.ndarray]
                         ) -> tuple[tuple[Channel, ...], dict[str, str]]:
    """A scene line's input channels on ``omega`` and its ends on free bodies.

    Channels as :func:`stochcable.dynamics.loads.line_channels`, with each end attached to
    a prescribed body (a key of ``vessel_rao``: its 6-DOF RAO on ``omega``) moving with
    :func:`fairlead_motion` inside the sea channel; returns also ``{end: body}`` for
    the ends attached to free bodies (they are solved with the body)."""
    from stochcable.dynamics.loads import line_channels

    body_docs = {b.name: b for b in getattr(scene, "bodies", ()) or ()}
    ch = line_channels(scene, line, system.positions, omega)
    att: dict[str, str] = {}
    for k, end in enumerate(("end_a", "end_b")):
        a = getattr(getattr(line, end), "attach", None)
        if a is None:
            continue
        if a.body not in vessel_rao:
            att[end] = a.body
            continue
        if scene.sea is None:
            raise InputError(f"bodies[{a.body}].prescribed", "RAO table", "-",
                             "a vessel motion RAO is relative to the sea: the scene "
                             "needs a 'sea'")
        node = 0 if k == 0 else system.model.n_nodes - 1
        r = system.positions[node] - np.asarray(body_docs[a.body].position, float)
        mot = fairlead_motion(vessel_rao[a.body], r)
        ch = tuple(dataclasses.replace(c, **{f"motion_{end[-1]}": mot})
                   if c.kind == "sea" else c for c in ch)
    return ch, att


@dataclass(frozen=True, eq=False)
class CoupledGroup:
    """Converged state of one coupled group: what re-solving it on another frequency
    grid needs (the time series, :mod:`stochcable.dynamics.coupled_timeseries`).

    Attributes
    ----------
    lines : tuple of str
        The group's lines in scene order (empty for a free-floating body).
    systems : dict of str to LineSystem
        Their systems (both end nodes prescribed).
    attach : dict of str to dict
        Per line ``{end: body}`` of its ends on the group's free bodies.
    bodies : tuple of RigidBody
        The free bodies at their static pose (``position``), with the gravity
        restoring of :func:`body_gravity_stiffness` in ``extra_stiffness``.
    pose : dict of str to ndarray, shape (d,)
        Static value of each body DOF (position and rotation). [m, rad]
    dampings : dict of str to Damping
        The converged linear drag of each line.
    body_drag : dict of str to ndarray, shape (3,)
        Linear drag per direction at the drag point of each body with a drag area,
        the one the converged response was solved with
        (:attr:`CoupledLinearization.body_drag`). [N·s/m]
    """

    lines: tuple[str, ...]
    systems: dict[str, LineSystem]
    attach: dict[str, dict[str, str]]
    bodies: tuple[RigidBody, ...]
    pose: dict[str, np.ndarray]
    dampings: dict[str, Damping]
    body_drag: dict[str, np.ndarray]


@dataclass(frozen=True, eq=False)
class CoupledAnalysis:
    """Outcome of :func:`analyze_coupled`; unpacks as the 4-tuple
    ``lines, bodies, systems, dampings``.

    Attributes
    ----------
    lines : dict of str to LineResult
        Every line of the scene, in scene order.
    bodies : dict of str to BodyResult
        Every body (prescribed ones with their RAO motion).
    systems : dict of str to LineSystem
        The lines NOT coupled to a free body (independent path).
    dampings : dict of str to Damping
        Their converged drag.
    groups : tuple of CoupledGroup
        Each coupled group, then each free-floating body without lines.
    """

    lines: dict[str, LineResult]
    bodies: dict[str, BodyResult]
    systems: dict[str, LineSystem]
    dampings: dict[str, Damping]
    groups: tuple[CoupledGroup, ...] = ()

    def __iter__(self) -> Any:
        return iter((self.lines, self.bodies, self.systems, self.dampings))


def _group_state(lnames: Sequence[str], systems: Mapping[str, LineSystem],
                 attach: Mapping[str, Mapping[str, str]], bodies: Sequence[RigidBody],
                 pose: Mapping[str, np.ndarray], clin: CoupledLinearization
                 ) -> CoupledGroup:
    return CoupledGroup(
        lines=tuple(lnames), systems={n: systems[n] for n in lnames},
        attach={n: dict(attach[n]) for n in lnames}, bodies=tuple(bodies),
        pose={b.name: np.asarray(pose[b.name], dtype=float).copy() for b in bodies},
        dampings={n: clin.lines[n].damping for n in lnames},
        body_drag={k: np.asarray(v, dtype=float).copy() for k, v in clin.body_drag.items()})
