"""MoorDyn as an independent check of the time-domain reference: the same line, the
same prescribed fairlead motion and the same coefficients run in MoorDyn-C (the
``moordyn`` Python package, the ``test``/``benchmark`` extras) and in
:func:`stochcable.reference.cable.simulate_line_timedomain`.

Conventions (stochcable scene → MoorDyn v2 input file), checked against the MoorDyn-C
2.7 source (``Line.cpp``, ``Point.cpp``, ``MoorDyn2.cpp``):

============================  =================================================
stochcable (``Segment``)       MoorDyn line type
============================  =================================================
``diameter`` D                 ``Diam`` d (volume-equivalent: A = πd²/4 in both)
``mass`` (in air) [kg/m]       ``Mass/m`` (weight (m − ρA)g in both)
``ea`` [N]                     ``EA`` (compression: MoorDyn T = 0, ours ε·EA)
internal damping (option)      ``BA`` [N·s]: T_d = BA·(dl/dt)/l0 per segment;
                               a negative ``BA`` is MoorDyn's damping *ratio*
                               ζ → BA = ζ·(L/N)·√(EA·m) (per segment, so it
                               depends on the segment count); ours: 0 unless
                               ``internal_damping`` is given (then the same
                               N·s law in the reference, per element)
(none)                         ``EI`` = 0
``cd_normal``                  ``Cd``: ½ρ Cd d |v_n| v_n per length (both)
``ca_normal``                  ``Ca``: Ca ρA (I − qqᵀ) per length (both)
``cd_axial``                   ``CdAx``: ½ρ CdAx **π d** |v_t| v_t per length
                               (MoorDyn-C v2 ``Dq = … Cdt·π·shared_part``; ours
                               ½ρ Cdt πD — the same convention, so the number
                               is passed unchanged; a CdAx on the frontal area d
                               would be π times smaller)
(none: no axial added mass)    ``CaAx`` = 0
============================  =================================================

- Environment: ``depth`` → ``WtrDpth`` (MoorDyn's seabed is z = −WtrDpth), ``rho`` →
  ``rho``, ``g`` → ``g``; no waves, no current (``WaveKin 0``, ``Currents 0``).
- Seabed: ``seabed.stiffness`` [Pa/m] → ``kBot``, ``seabed.damping`` [Pa·s/m] →
  ``cBot``.  Both are per unit contact area: MoorDyn's node force is
  (kBot·p − cBot·ż)·d·l_node (``Line.cpp``), ours k·D and c·D per unit length lumped on
  the node's tributary length (:class:`~stochcable.reference.cable_model.LineModel`) —
  the same numbers.  Differences left: ours blends the contact in over the static
  penetration p₀ = w/(kD) (a C¹ law, resting depth 1.5 p₀ instead of p₀) and engages
  the dashpot one step late; MoorDyn's friction is off (``FrictionCoefficient`` 0),
  as ours (none).
- Ends: end_a → a ``Fixed`` point, end_b → a ``Coupled`` point moved by
  ``moordyn.Step(x, v, t, dt)``: MoorDyn moves it linearly, r = x + v·(τ − t), over
  the coupling step, so the harness passes the exact position at the step start and
  the secant velocity (x(t + Δt) − x(t))/Δt: the path is the exact one at every
  coupling instant and piecewise linear between (error ≤ Δt²·max|ẍ|/8).
- Masses: MoorDyn lumps mass, added mass, weight and drag on the nodes (node tangent =
  the mean of the adjacent segments'), ours uses consistent mass and Gauss quadrature
  on the elements; with the same element count the two converge to the same continuum.
  ``simulate_line_timedomain(..., mass_matrix="lumped")`` takes MoorDyn's lumped mass
  (most of the difference on coarse meshes: docs/benchmarks/moordyn.md).
- Time integration: MoorDyn's RK2 needs internal damping (see :func:`moordyn_input_file`),
  so the harness runs RK4 with BA = 0 to match the undamped reference; to compare with
  MoorDyn as commonly run (BA = −1, RK2) give the reference the same BA in N·s
  (:func:`internal_damping_coefficient`).
- Tensions compared: the **end-segment tension** (MoorDyn ``GetLineFairTen`` = |T_N−1
  + T_d|, ``GetLineNodeTen(line, 0)`` at the anchor; ours ``element_tension`` of the
  first and last element), a like-for-like quantity.  The support reaction (ours
  ``tension_a``/``tension_b``) differs from it by the loads of the half element lumped
  on the end node (inertia and weight of l/2): O(1/N), reported separately.
- Statics: MoorDyn computes its initial state with its stationary solver
  (``threshIC``, ``TmaxIC``); ours from :func:`stochcable.statics.solve_statics` and a
  Newton re-solve of the same model.

Motion: a periodic DSA surge (:func:`periodic_dsa_surge`), so the sample variance of
the fairlead motion over one whole period is exactly Σ a_j²/2; the records are one
warm-up period (a half-cosine ramp inside it) and one measured period.
"""

from __future__ import annotations

import contextlib
import math
import os
import sys
import tempfile
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from stochcable import validation as _v
from stochcable.errors import InputError, SolverError
from stochcable.io import write_moordyn
from stochcable.reference.cable import _select_line
from stochcable.reference.cable_excitation import half_cosine
from stochcable.reference.periodic_motion import SurgeMotion, periodic_dsa_surge
from stochcable.scene.model import Scene, load_scene

__all__ = [
    "SurgeMotion",
    "EndTensionHistory",
    "periodic_dsa_surge",
    "comparison_scene",
    "moordyn_input_file",
    "simulate_line_moordyn",
    "import_moordyn",
    "moordyn_system",
    "quiet_moordyn",
    "sample_stride",
    "internal_damping_coefficient",
]

_EXTRA_HINT = (
    "MoorDyn is needed for this check: install the 'moordyn' package "
    "(pip install moordyn, or the stochcable 'test'/'benchmark' extra)"
)


def import_moordyn() -> Any:
    """The ``moordyn`` module, imported lazily.

    Raises
    ------
    ImportError
        When it is not installed; the message names the extra that brings it.
    """
    try:
        import moordyn  # noqa: PLC0415 (optional dependency, imported on use)
    except ImportError as exc:  # pragma: no cover - exercised only without moordyn
        raise ImportError(_EXTRA_HINT) from exc
    return moordyn


# --------------------------------------------------------------------------- scenes


def comparison_scene(
    scene: Scene | dict | str, line_name: str | None = None, elements: int | None = None
) -> Scene:
    """The one-line scene both simulators run: the line alone, no sea, no current, no
    end motions, no time-series settings; ``elements`` elements when given.

    Raises
    ------
    InputError
        When the line has more than one segment, attachments, a weight override or an
        end attached to a body (MoorDyn's line type is one homogeneous segment here).
    """
    sc = load_scene(scene)
    line = _select_line(sc, line_name)
    name = f"lines[{line.name}]"
    if len(line.segments) != 1:
        raise InputError(
            f"{name}.segments", len(line.segments), "-", "must be one homogeneous segment"
        )
    if line.attachments:
        raise InputError(f"{name}.attachments", len(line.attachments), "-", "must be empty")
    if getattr(line, "drag_form", "cross_flow") != "cross_flow":
        raise InputError(
            f"{name}.drag_form",
            line.drag_form,
            "-",
            "must be 'cross_flow' (MoorDyn has only the cross-flow drag ½ρC_dD|V_n|V_n)",
        )
    if line.segments[0].weight is not None:
        raise InputError(
            f"{name}.segments[0].weight",
            line.segments[0].weight,
            "N/m",
            "must be absent (MoorDyn derives the weight from mass and diameter)",
        )
    if line.end_a.position is None or line.end_b.position is None:
        raise InputError(f"{name}.end_a/end_b", "attach", "-", "must be fixed positions")
    doc = sc.model_dump(mode="json", exclude_none=True)
    ln = next(x for x in doc["lines"] if x["name"] == line.name)
    for end in ("end_a", "end_b"):
        ln[end].pop("motion", None)
    if elements is not None:
        ln["segments"][0]["elements"] = _v.positive_int("elements", elements)
    doc["lines"] = [ln]
    doc.pop("sea", None)
    doc.pop("bodies", None)
    doc["environment"]["current"] = []
    doc["analysis"].pop("timeseries", None)
    doc["analysis"].pop("fidelity", None)
    return load_scene(doc)


def moordyn_input_file(
    scene: Scene | dict | str,
    *,
    dt: float = 1e-3,
    internal_damping: float = 0.0,
    ic_threshold: float = 1e-7,
    ic_tmax: float = 300.0,
    scheme: str = "RK4",
) -> str:
    """The MoorDyn v2 input file of the first line of a :func:`comparison_scene`.

    Parameters
    ----------
    scene : Scene, mapping or JSON
        A one-line comparison scene; its segment's ``elements`` is MoorDyn's NumSegs.
    dt : float, default 1e-3
        MoorDyn's integration step ``dtM``. [s]
    internal_damping : float, default 0
        MoorDyn's ``BA``: >= 0 the axial damping coefficient [N·s], < 0 minus a damping
        ratio [-] (see the module docstring).
    ic_threshold : float, default 1e-7
        ``threshIC``: relative convergence of the stationary initial-condition solve. [-]
    ic_tmax : float, default 300
        ``TmaxIC``: its longest pseudo-time. [s]
    scheme : str, default "RK4"
        ``tScheme``.  MoorDyn's default RK2 amplifies an undamped oscillation of
        frequency ω by √(1 + (ωΔt)⁴/4) per step: without internal damping (BA = 0) the
        segments' axial modes (ω ≈ 2√(EA/m)/l_seg, ωΔt ≈ 0.4 for 80 segments of the
        chain example at 1 ms) grow without bound; RK4 is stable there (its amplification
        1 − (ωΔt)⁶/144 + …) and nearly free of numerical damping.

    Returns
    -------
    str
        The file's text (point 1 = end_a, fixed; point 2 = end_b, coupled).
    """
    sc = load_scene(scene)
    ba = _v.finite_scalar("internal_damping", internal_damping, "N·s")
    return write_moordyn(
        sc,
        dt=dt,
        internal_damping=ba,
        coupled_ends=[(sc.lines[0].name, "end_b")],
        ic_threshold=ic_threshold,
        ic_tmax=ic_tmax,
        scheme=scheme,
        # joints of several segments start at stochcable's static solution: from the
        # straight line MoorDyn's initial-condition solve stops unconverged (a chain on
        # the bed below a rope: residual 3.6 m/s² after 13 s, the anchor slack)
        static_positions=len(sc.lines[0].segments) > 1,
    )


def internal_damping_coefficient(scene: Scene | dict | str, ba: float) -> float:
    """MoorDyn's ``BA`` input as a coefficient in N·s.

    Parameters
    ----------
    scene : Scene, mapping or JSON
        A one-line comparison scene (its segment count is MoorDyn's NumSegs).
    ba : float
        ``BA``: >= 0 a coefficient [N·s], < 0 minus a damping ratio ζ [-].

    Returns
    -------
    float
        BA itself when >= 0, else ζ·(L/N)·√(EA·m) (MoorDyn-C ``Line::initialize``: the
        critical damping of one segment's axial mode times ζ). [N·s]
    """
    ba = _v.finite_scalar("ba", ba, "N·s")
    if ba >= 0.0:
        return ba
    sg = load_scene(scene).lines[0].segments[0]
    return -ba * sg.length / sg.elements * math.sqrt(sg.ea * sg.mass)


# --------------------------------------------------------------------------- run


@dataclass(frozen=True, eq=False)
class EndTensionHistory:
    """End tensions of one simulation, sampled every ``dt``.

    Attributes
    ----------
    t : ndarray, shape (n_t,)
        Sample times, t = 0 at the static start. [s]
    tension_a, tension_b : ndarray, shape (n_t,)
        End-segment tension at end_a (anchor) and end_b (fairlead). [N]
    reaction_b : ndarray, shape (n_t,)
        Support reaction at end_b (the end segment's force plus the loads lumped on the
        end node, its inertia included). [N]
    static_a, static_b : float
        End-segment tensions of the initial (static) state. [N]
    motion : ndarray, shape (n_t,)
        The surge applied at end_b (ramped). [m]
    simulator : str
        ``"moordyn"`` or ``"reference"``.
    reaction_a : ndarray, shape (n_t,), optional
        Support reaction at end_a (the fixed anchor: the end segment's force plus the
        loads lumped on the end node, seabed contact included; what the frequency
        domain's ``end_a`` tension is). [N]
    """

    t: np.ndarray
    tension_a: np.ndarray
    tension_b: np.ndarray
    reaction_b: np.ndarray
    static_a: float
    static_b: float
    motion: np.ndarray
    simulator: str
    reaction_a: np.ndarray | None = None

    def window(self, start: float, stop: float) -> np.ndarray:
        """Mask of the samples with start <= t < stop (a whole period: exact σ)."""
        eps = 1e-6 * float(self.t[1] - self.t[0])
        return (self.t >= start - eps) & (self.t < stop - eps)


@contextlib.contextmanager
def quiet_moordyn() -> Iterator[None]:
    """Silence MoorDyn's console log (written by C++ to file descriptor 1)."""
    try:
        fd = sys.stdout.fileno()
    except (AttributeError, OSError, ValueError):  # pragma: no cover - no real stdout
        yield
        return
    sys.stdout.flush()
    saved = os.dup(fd)
    try:
        with open(os.devnull, "w") as null:
            os.dup2(null.fileno(), fd)
            yield
    finally:
        os.dup2(saved, fd)
        os.close(saved)


@contextlib.contextmanager
def moordyn_system(text: str, name: str) -> Iterator[Any]:
    """MoorDyn's system of the input file ``text`` (written as ``name`` in a temporary
    directory), created and closed with its console log silenced; yields the system
    handle of the ``moordyn`` module."""
    md = import_moordyn()
    with tempfile.TemporaryDirectory(prefix="stochcable_moordyn_") as tmp:
        path = Path(tmp) / name
        path.write_text(text)
        with quiet_moordyn():
            system = md.Create(str(path))
        try:
            yield system
        finally:
            with quiet_moordyn():
                md.Close(system)


def sample_stride(sample_dt: float, coupling_dt: float) -> int:
    """Coupling steps per sample of a record: ``sample_dt`` must be a positive multiple
    of ``coupling_dt`` (within 1e-9 of it, the round-off of a decimal step). [-]"""
    coupling_dt = _v.positive("coupling_dt", coupling_dt, "s")
    every = int(round(_v.positive("sample_dt", sample_dt, "s") / coupling_dt))
    if every < 1 or abs(every * coupling_dt - sample_dt) > 1e-9 * sample_dt:
        raise InputError(
            "sample_dt", sample_dt, "s", f"must be a multiple of coupling_dt = {coupling_dt} s"
        )
    return every


def simulate_line_moordyn(
    scene: Scene | dict | str,
    motion: SurgeMotion,
    *,
    duration: float,
    ramp: float,
    sample_dt: float = 0.05,
    coupling_dt: float = 5e-3,
    dt: float = 1e-3,
    internal_damping: float = 0.0,
    ic_threshold: float = 1e-7,
    scheme: str = "RK4",
) -> EndTensionHistory:
    """Run the line of a :func:`comparison_scene` in MoorDyn with end_b surging.

    Parameters
    ----------
    scene : Scene, mapping or JSON
        One-line comparison scene, or a one-line scene of several segments (each a
        MoorDyn line, joined at free points; the first holds end_a, the last end_b).
    motion : SurgeMotion
        Surge of end_b (x direction), applied as r(t)·x(t) with the half-cosine ramp r.
    duration : float
        Simulated time. [s]
    ramp : float
        Ramp length. [s]
    sample_dt : float, default 0.05
        Sampling interval of the record, a multiple of ``coupling_dt``. [s]
    coupling_dt : float, default 5e-3
        Interval of the calls to ``moordyn.Step`` (the coupled point moves linearly
        between them). [s]
    dt : float, default 1e-3
        MoorDyn's ``dtM``. [s]
    internal_damping : float, default 0
        MoorDyn's ``BA`` (see :func:`moordyn_input_file`). [N·s]
    ic_threshold : float, default 1e-7
        MoorDyn's ``threshIC``. [-]
    scheme : str, default "RK4"
        MoorDyn's ``tScheme`` (see :func:`moordyn_input_file`). [-]

    Returns
    -------
    EndTensionHistory
    """
    md = import_moordyn()
    sc = load_scene(scene)
    duration = _v.positive("duration", duration, "s")
    ramp = _v.nonnegative("ramp", ramp, "s")
    coupling_dt = _v.positive("coupling_dt", coupling_dt, "s")
    every = sample_stride(sample_dt, coupling_dt)
    n_steps = int(round(duration / coupling_dt))
    tc = coupling_dt * np.arange(n_steps + 1)
    r, r1, r2 = half_cosine(tc, ramp)
    xs = r * motion.displacement(tc)
    p0 = np.asarray(sc.lines[0].end_b.position, float)
    text = moordyn_input_file(
        sc, dt=dt, internal_damping=internal_damping, ic_threshold=ic_threshold, scheme=scheme
    )
    n_s = n_steps // every + 1
    ta, tb, rb, ra = np.empty(n_s), np.empty(n_s), np.empty(n_s), np.empty(n_s)
    a_ramped = (
        r * motion.acceleration(tc) + 2.0 * r1 * motion.velocity(tc) + r2 * motion.displacement(tc)
    )
    with moordyn_system(text, "line.txt") as system:
        with quiet_moordyn():
            err = md.Init(system, list(p0), [0.0, 0.0, 0.0])
        if err:
            raise InputError("scene", "MoorDyn Init", "-", f"failed with error code {err}")
        # a segment per MoorDyn line, in order from end_a: the first line holds
        # end_a, the last end_b
        line = md.GetLine(system, 1)
        last = md.GetLine(system, md.GetNumberLines(system))
        n_node = md.GetLineNumberNodes(last) - 1
        static_a = float(np.linalg.norm(md.GetLineNodeTen(line, 0)))
        static_b = float(md.GetLineFairTen(last))
        for k in range(n_steps + 1):
            if k % every == 0:
                j = k // every
                ta[j] = np.linalg.norm(md.GetLineNodeTen(line, 0))
                tb[j] = md.GetLineFairTen(last)
                f_end = np.asarray(md.GetLineNodeForce(last, n_node))
                m_end = np.asarray(md.GetLineNodeM(last, n_node))
                rb[j] = np.linalg.norm(m_end[:, 0] * a_ramped[k] - f_end)
                # the anchor node does not move: its reaction is its net force
                ra[j] = np.linalg.norm(md.GetLineNodeForce(line, 0))
            if k == n_steps:
                break
            x = p0 + np.array([xs[k], 0.0, 0.0])
            v = np.array([(xs[k + 1] - xs[k]) / coupling_dt, 0.0, 0.0])
            md.Step(system, list(x), list(v), float(tc[k]), coupling_dt)
    if not (np.all(np.isfinite(ta)) and np.all(np.isfinite(tb))):
        raise SolverError(
            f"MoorDyn's end tensions are not finite (dtM {dt} s, tScheme {scheme}, BA "
            f"{internal_damping}): reduce dt, or use RK4 or internal damping"
        )
    ts = tc[::every]
    return EndTensionHistory(
        ts, ta, tb, rb, static_a, static_b, xs[::every], "moordyn", reaction_a=ra
    )
