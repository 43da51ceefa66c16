"""Groups on the realization grid: the transfer functions of the time series (Tuah
1982, §5.1, eq. 5.3.29 and step 14), for lines coupled to bodies and for lines alone (the
groups without bodies) by the same solve.

The time series of :func:`stochcable.dynamics.timeseries.synthesis.simulate_timeseries` are the
synthesis (:func:`stochcable.sea.realization.synthesize`) of transfer functions solved on the
realization
grid ω_m = mΔω inside the analysis band, driven by the same complex amplitudes as η.
For a coupled group (lines attached to free bodies, :mod:`stochcable.dynamics.groups`)
the drag linearization is done once on the analysis grid; with its converged linear
drag (the lines' :class:`~stochcable.dynamics.model.system.Damping`, the bodies' drag σ) the group
is a linear system, solved here again on the realization band by the same substructured
solve (:func:`stochcable.dynamics.groups.group.solve_group`): the channels and the body
loads are evaluated on the band, the lines' support forces give the end tensions
(:func:`stochcable.dynamics.solve.line_solve.end_tension_from_support`) and the body equation the
motion ξ.

Memory
------
Only the end tensions (n_ch × n_w per end) and the body motions (n_ch × d × n_w) are
kept.  The node arrays of the solve (channel kinematics, loads, displacements:
n_nodes × d × n_w × n_ch each) exist one chunk of frequencies at a time; the chunk
holds about :data:`CHUNK_BYTES` of them (:func:`frequency_chunks`).  The solve is
independent per frequency, so the chunked transfer equals the one-piece solve to
round-off.

References
----------
Tuah, H. (1982), Cable dynamics in an ocean environment, PhD thesis, Oregon State University.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass

import numpy as np

from stochcable import validation as v
from stochcable.dynamics.groups.analysis import CoupledGroup
from stochcable.dynamics.groups.group import GroupSystem, body_drag_matrix, solve_group
from stochcable.dynamics.groups.inputs import (
    CoupledLine,
    body_loads,
    group_channels,
    scene_line_channels,
    sea_only_channels,
)
from stochcable.dynamics.groups.vessels import VesselRaos
from stochcable.dynamics.loads.channels import Channel
from stochcable.dynamics.solve.line_solve import end_tension_from_support
from stochcable.line.fem import FEModel
from stochcable.scene.model import Line, Scene

__all__ = [
    "CHUNK_BYTES",
    "GroupTransfer",
    "coupled_group_transfer",
    "frequency_chunks",
    "line_entry_bytes",
    "vessel_raos",
]

#: Target size of the node arrays alive while one chunk of frequencies is solved. [B]
CHUNK_BYTES = 48 * 2**20
# Node arrays of one (node, component, frequency, channel) entry alive at the peak of
# a solve: channel kinematics (velocity, acceleration, element moments and squares),
# inputs (velocity, inertia load, element moments), loads, displacement and the
# unit end-motion columns; a generous count (measured peak in the module tests).
_ARRAYS_PER_ENTRY = 24
# Smallest chunk (per-chunk overhead: the Foss eigenproblem, the band Cholesky).
_MIN_CHUNK = 64


@dataclass(frozen=True, eq=False)
class GroupTransfer:
    """Transfer functions of a coupled group on a frequency grid.

    Attributes
    ----------
    omega : ndarray, shape (n_omega,)
        Frequencies. [rad/s]
    channels : tuple of str
        The group's channels: ``"sea"``, then ``"<line>.<end>.<dof>"`` for the
        end-motion spectra of the lines' unattached ends (``"none"`` for a group
        without excitation).
    kinds : tuple of str
        ``"sea"``, ``"end_motion"`` or ``"none"`` per channel.
    sources : tuple
        Per channel: None for the sea (and ``"none"``), else ``(line, channel)``, the
        line's own channel name (``"end_a.surge"``).
    end_tension : dict of str to dict
        ``{line: {"end_a": H, "end_b": H}}``, H (n_ch, n_omega): δ|F| at each support
        per unit input. [N/unit]
    body_motion : dict of str to ndarray, complex, shape (n_ch, d, n_omega)
        Motion of each free body's reference point per unit input. [m/unit, rad/unit]
    """

    omega: np.ndarray
    channels: tuple[str, ...]
    kinds: tuple[str, ...]
    sources: tuple[tuple[str, str] | None, ...]
    end_tension: dict[str, dict[str, np.ndarray]]
    body_motion: dict[str, np.ndarray]


def frequency_chunks(n_omega: int, entry_bytes: int, budget: int = CHUNK_BYTES) -> Iterator[slice]:
    """Consecutive slices of ``range(n_omega)`` whose node arrays fit ``budget``.

    Parameters
    ----------
    n_omega : int
        Number of frequencies. [-]
    entry_bytes : int
        Bytes of the node arrays per frequency. [B]
    budget : int, optional
        Target bytes per chunk (default :data:`CHUNK_BYTES`). [B]

    Yields
    ------
    slice
        At least ``_MIN_CHUNK`` frequencies each (the last may be shorter).
    """
    size = max(_MIN_CHUNK, int(budget // max(int(entry_bytes), 1)))
    for start in range(0, int(n_omega), size):
        yield slice(start, min(start + size, int(n_omega)))


def vessel_raos(scene: Scene, omega: np.ndarray) -> VesselRaos:
    """The 6-DOF RAOs of every prescribed body (vessel) of the scene on ``omega``, per
    wave heading (zero outside the frequency table). [m/m, rad/m]"""
    return VesselRaos(
        np.asarray(omega, dtype=float),
        {
            b.name: b.prescribed
            for b in (getattr(scene, "bodies", ()) or ())
            if getattr(b, "prescribed", None) is not None
        },
    )


def _scene_line(scene: Scene, name: str) -> Line:
    return next(ln for ln in scene.lines if ln.name == name)


def _group_on(
    scene: Scene, group: CoupledGroup, omega: np.ndarray
) -> tuple[GroupSystem, tuple[str, ...], tuple[tuple[str, str] | None, ...]]:
    """The group's solve data on ``omega``: channels of every line (vessel ends in the
    sea channel), aligned on the group list as the analysis does (a line alone keeps
    its own channels), and body loads."""
    env = scene.environment
    vessel = vessel_raos(scene, omega)
    chans: dict[str, tuple[Channel, ...]] = {}
    for n in group.lines:
        chans[n], _ = scene_line_channels(
            scene, _scene_line(scene, n), group.systems[n], omega, vessel
        )
    if group.lines and not group.bodies:  # a line alone: its own channels
        (n,) = group.lines
        cls = [CoupledLine(group.systems[n], chans[n])]
        channels = chans[n]
        sources = tuple(
            (n, c.name) if c.kind == "end_motion" else ("sea", c.name) if c.kind == "sea" else None
            for c in channels
        )
        return (
            GroupSystem(cls, (), {}, env.rho, channels),
            tuple(c.kind for c in channels),
            sources,
        )
    if group.lines:
        gch = group_channels(group.lines, chans, omega)
        cls = [
            CoupledLine(
                group.systems[n],
                gch[n],
                end_a=group.attach[n].get("end_a"),
                end_b=group.attach[n].get("end_b"),
            )
            for n in group.lines
        ]
        channels = cls[0].channels
    else:  # a free-floating body: the sea alone (analyze_coupled)
        channels = sea_only_channels(scene.sea, omega, env.g)
        cls = []
    own = {
        f"{n}.{c.name}": (n, c.name)
        for n in group.lines
        for c in chans[n]
        if c.kind == "end_motion"
    }
    sources = tuple(
        own.get(c.name) if c.kind == "end_motion" else ("sea", c.name) if c.kind == "sea" else None
        for c in channels
    )
    loads = {b.name: body_loads(b, channels, omega, scene.sea, env) for b in group.bodies}
    return (
        GroupSystem(cls, group.bodies, loads, env.rho, channels),
        tuple(c.kind for c in channels),
        sources,
    )


def line_entry_bytes(model: FEModel, n_columns: int) -> int:
    """Bytes of a line's node arrays per frequency, the unit of the chunk budget.

    Parameters
    ----------
    model : FEModel
        The line model (``n_nodes``, ``dim``).
    n_columns : int
        Right-hand sides solved together: channels plus unit end-motion columns. [-]

    Returns
    -------
    int
        n_nodes · dim · n_columns · 16 B times the count of such complex arrays alive
        at the peak of a solve. [B]
    """
    return int(model.n_nodes * model.dim * max(int(n_columns), 1) * 16 * _ARRAYS_PER_ENTRY)


def _entry_bytes(group: CoupledGroup, scene: Scene) -> int:
    """Bytes of the group's node arrays per frequency (the chunk budget's unit)."""
    ds = None if scene.sea is None else scene.sea.direction_set()
    n_ch = (1 if ds is None else ds.count) + sum(
        3
        for n in group.lines
        for e in ("end_a", "end_b")
        if getattr(getattr(_scene_line(scene, n), e), "motion", None) is not None
    )
    total = sum(
        line_entry_bytes(
            group.systems[n].model, n_ch + group.systems[n].model.dim * len(group.attach[n])
        )
        for n in group.lines
    )
    return max(total, 1)


def coupled_group_transfer(
    scene: Scene,
    group: CoupledGroup,
    omega: np.ndarray,
    *,
    budget: int = CHUNK_BYTES,
    timing: dict[str, float] | None = None,
) -> GroupTransfer:
    """End-tension and body-motion transfer functions of a coupled group on ``omega``.

    Parameters
    ----------
    scene : Scene
        The scene the group belongs to (environment, sea, line end motions, vessels).
    group : CoupledGroup
        The group's converged state
        (:attr:`stochcable.dynamics.groups.analysis.CoupledAnalysis.groups`).
    omega : array_like, shape (n_omega,)
        Frequencies, > 0 (the realization band). [rad/s]
    budget : int, optional
        Bytes of node arrays per chunk of frequencies (module docstring). [B]
    timing : dict, optional
        Accumulates ``solve_s``. [s]

    Returns
    -------
    GroupTransfer

    Raises
    ------
    InputError
        ``omega`` not a 1-D array of positive frequencies, ``budget`` not a positive
        integer.

    Notes
    -----
    The group's linear system at the converged drag: lines' drag ``group.dampings``,
    body drag ``group.body_drag`` (Tuah 1982, eq. 5.2.2 form with the current at the
    drag point, Tᵀ diag(b) T on the body DOFs), the body equation
    (Tuah 1982, eq. 3.2.c.20) with the condensed lines (eqs. 3.3.8–3.3.10) solved exactly
    at every frequency — the same system as the frequency-domain result, so on a common
    frequency the transfer functions agree to round-off.
    """
    w = v.float_array("omega", omega, "rad/s", positive=True, min_size=1)
    budget = v.positive_int("budget", budget)
    n_w = w.size
    end_t: dict[str, dict[str, np.ndarray]] = {}
    motion: dict[str, np.ndarray] = {}
    names: tuple[str, ...] = ()
    kinds: tuple[str, ...] = ()
    sources: tuple[tuple[str, str] | None, ...] = ()
    for sl in frequency_chunks(n_w, _entry_bytes(group, scene), budget):
        g, kinds, sources = _group_on(scene, group, w[sl])
        if not names:
            names = tuple(c.name for c in g.channels)
            end_t = {
                n: {e: np.zeros((g.n_ch, n_w), dtype=complex) for e in ("end_a", "end_b")}
                for n in group.lines
            }
            motion = {b.name: np.zeros((g.n_ch, b.n_dof, n_w), dtype=complex) for b in group.bodies}
        body_c = np.zeros((g.nb, g.nb))
        body_b: dict[str, np.ndarray] = {}
        for b in g.drag:
            # the drag the converged response used, as a damping on the body DOFs:
            # Tᵀ diag(b) T at the drag point
            bb = group.body_drag[b.name]
            s = slice(g.off[b.name], g.off[b.name] + b.n_dof)
            body_c[s, s] += body_drag_matrix(b, bb)
            body_b[b.name] = bb
        sol, xi = solve_group(g, group.dampings, body_c, body_b, timing)
        for n in group.lines:
            et = end_tension_from_support(group.systems[n], sol[n][1])
            for e in ("end_a", "end_b"):
                end_t[n][e][:, sl] = et[e]
        for b in group.bodies:
            s = slice(g.off[b.name], g.off[b.name] + b.n_dof)
            motion[b.name][:, :, sl] = np.transpose(xi[:, s, :], (2, 1, 0))
        del sol, xi, g
    return GroupTransfer(
        omega=w.copy(),
        channels=names,
        kinds=kinds,
        sources=sources,
        end_tension=end_t,
        body_motion=motion,
    )
