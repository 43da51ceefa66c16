"""Lines on a free 6-DOF body in MoorDyn, driven by a random sea: the independent 3-D
check of the frequency domain's lines on a free body (benchmarks/moordyn_body.py,
docs/accuracy/bodies.md "MoorDyn: a free buoy on three legs").

The scene's one free body becomes a MoorDyn ``Free`` body, its lines' ends on it
``Body1`` points (:func:`stochcable.io.write_moordyn` writes the scene with the body
as a Coupled body; the row is then made Free).  Same physics on both sides:

- mass, inertia (diagonal, about the reference point = the centre of gravity:
  ``cog`` must be zero), constant translational added mass (MoorDyn ``Ca`` times
  ρ·Volume; no rotational added mass), no radiation damping, no hydrodynamic table;
- buoyancy ρ·g·∇ at the reference point (MoorDyn applies weight and buoyancy at the
  CG; ``centre_of_buoyancy`` must be zero), no hydrostatic matrix: a submerged body;
- body drag per direction ½ρ·CdA_i·|u_i|·u_i at the reference point (``drag_point``
  zero).  MoorDyn's own body drag uses the vector norm (½ρ·CdA_i·u_i·|u|, MoorDyn-C
  2.7 ``Body::doRHS``), so the body's CdA is 0 and the drag is carried by three short
  Rods fixed to the body (``Body1``) along x, y and z, centred on the reference
  point, with no transverse drag (Cd = 0): the two end drags of the rod along i,
  ½ρ·CdEnd·(πd²/4)·|u_i|·u_i each, give CdA_i = 2·CdEnd_i·πd²/4 — the per-direction
  law at any heading.  Their diameter is tiny (their volume, Froude–Krylov and
  added-mass terms of ``Rod::doRHS`` ∝ d², negligible: ``ROD_DIAMETER``), Ca = CaEnd = 0.
- waves: MoorDyn's externally driven kinematics (``WaveKin 1``), set every coupling
  step to the linear (Airy) kinematics of the same DSA sea components as the frequency
  domain (:func:`stochcable.sea.kinematics.wave_kinematics`), evaluated at the
  points' *static* positions (the frequency domain's assumption: no Wheeler
  stretching, no kinematics following the moving nodes) at the middle of the step.

The realization is periodic (Δω = 2π/T): the record is one warm-up period (a
half-cosine ramp of the sea over its first half) and one measured period.  Records:
the end-segment tensions' support reactions at the fairleads (the last segment's force
plus the fairlead node's lumped loads less its inertia, the node's acceleration by
central differences of its sampled position) and anchors (the anchor node's net
force), and the body's surge, heave and pitch.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

import numpy as np

from stochcable import validation as _v
from stochcable.errors import InputError, PhysicsWarning, SolverError
from stochcable.io import moordyn_lines, write_moordyn
from stochcable.reference.cable_excitation import half_cosine
from stochcable.reference.moordyn import (
    import_moordyn,
    moordyn_system,
    quiet_moordyn,
    sample_stride,
)
from stochcable.scene.model import Scene, load_scene
from stochcable.sea.kinematics import wave_kinematics
from stochcable.statics import solve_statics

__all__ = [
    "ROD_DIAMETER",
    "BodyRecord",
    "moordyn_body_input_file",
    "simulate_body_moordyn",
    "three_leg_buoy_scene",
]

#: Diameter of the drag rods: its volume π/4·d²·l (3 N of buoyancy per metre at 0.02 m)
#: and its Froude–Krylov load ρ·V·a are negligible against the lines' tensions. [m]
ROD_DIAMETER = 0.02
#: Length of the drag rods, centred on the body reference point. [m]
ROD_LENGTH = 1.0
_NO_MOTION = {"omega": [0.0, 100.0], "surge": {"re": [0.0, 0.0], "im": [0.0, 0.0]}}


@dataclass(frozen=True, eq=False)
class BodyRecord:
    """A MoorDyn run of a free body and its lines over the measured period.

    Attributes
    ----------
    lines : tuple of str
        The scene lines (one MoorDyn line each).
    t : ndarray, shape (n_t,)
        Sample times of the measured period. [s]
    fairlead, anchor : ndarray, shape (n_t, n_lines)
        Support reactions at end_b (on the body) and end_a. [N]
    fairlead_segment : ndarray, shape (n_t, n_lines)
        Tension of the last segment (MoorDyn ``GetLineFairTen``). [N]
    motion : ndarray, shape (n_t, 6)
        Body position and MoorDyn's orientation angles (roll, pitch, yaw) less their
        static values. [m, rad]
    static_fairlead, static_anchor : ndarray, shape (n_lines,)
        The end reactions at t = 0, after MoorDyn's initial-condition solve. [N]
    static_pose : ndarray, shape (6,)
        The body position and angles at t = 0.  The stationary solve stops at TmaxIC
        with the buoy of :func:`three_leg_buoy_scene` 0.05 m below its equilibrium (it
        then rings in heave without a sea): MoorDyn's statics are a calm run's means.
        [m, rad]
    """

    lines: tuple[str, ...]
    t: np.ndarray
    fairlead: np.ndarray
    anchor: np.ndarray
    fairlead_segment: np.ndarray
    motion: np.ndarray
    static_fairlead: np.ndarray
    static_anchor: np.ndarray
    static_pose: np.ndarray


def _free_body(sc: Scene) -> tuple[int, object]:
    """The scene's one free body, checked against what the MoorDyn model represents."""
    free = [(i, b) for i, b in enumerate(sc.bodies) if b.prescribed is None]
    if len(free) != 1 or len(sc.bodies) != 1:
        raise InputError("bodies", len(sc.bodies), "-", "must be exactly one free body")
    i, b = free[0]
    name = f"bodies[{i}]"
    for field in ("cog", "centre_of_buoyancy", "drag_point"):
        if np.any(np.asarray(getattr(b, field), float) != 0.0):
            raise InputError(f"{name}.{field}", getattr(b, field), "m", "must be zero")
    for field in ("radiation_damping", "hydrostatic_stiffness", "hydrodynamics"):
        if getattr(b, field) is not None and np.any(np.asarray(getattr(b, field)) != 0):
            raise InputError(f"{name}.{field}", "given", "-", "must be absent")
    if not b.displaced_volume:
        raise InputError(f"{name}.displaced_volume", b.displaced_volume, "m³", "must be > 0")
    return i, b


def moordyn_body_input_file(
    scene: Scene | dict | str,
    *,
    dt: float = 2.5e-3,
    waves: bool = True,
    position: np.ndarray | None = None,
) -> str:
    """The MoorDyn v2 input file of a scene with one free body (see the module).

    Parameters
    ----------
    scene : Scene, mapping or JSON
        The scene: single-segment lines, end_b of some on the free body.
    dt : float, default 2.5e-3
        ``dtM``. [s]
    waves : bool, default True
        ``WaveKin 1`` (externally driven kinematics), else ``WaveKin 0``.
    position : array_like, shape (3,), optional
        The body's starting position, the lines' shapes stochcable's static ones with
        the body held there.  Default: stochcable's static pose. [m]

    Returns
    -------
    str
        The file's text: body 1 Free, rods 1–3 its drag rods along x, y, z.
    """
    sc = load_scene(scene)
    i, b = _free_body(sc)
    env = sc.environment
    doc = sc.model_dump(mode="json", exclude_none=True)
    doc["bodies"][i]["prescribed"] = _NO_MOTION
    if position is None:
        # MoorDyn's initial-condition solve starts from stochcable's static pose and
        # line shapes (from the scene's guess its free body ends 5 m off after TmaxIC)
        pose = solve_statics(sc).bodies[b.name]
        if np.max(np.abs(pose.rotation)) > 1e-6:
            raise InputError(f"bodies[{i}]", b.name, "rad", "must have no static rotation")
        position = pose.position
    p = np.asarray(position, float)
    doc["bodies"][i]["position"] = p.tolist()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PhysicsWarning)
        text = write_moordyn(load_scene(doc), dt=dt, ic_threshold=1e-7, ic_tmax=300.0)
    inertia = np.zeros(3) if b.inertia is None else np.diag(np.asarray(b.inertia, float))
    # the rods' own volume (buoyant in MoorDyn: 3·πd²/4·l) taken from the body's
    vol = float(b.displaced_volume) - 3.0 * 0.25 * math.pi * ROD_DIAMETER**2 * ROD_LENGTH
    am = np.zeros((6, 6)) if b.added_mass is None else np.asarray(b.added_mass, float)
    ca = np.diag(am)[:3] / (env.rho * vol)
    row = (
        f"1 Free {p[0]:.10g} {p[1]:.10g} {p[2]:.10g} 0 0 0 {b.mass:.10g} 0 "
        f"{'|'.join(f'{x:.10g}' for x in inertia)} {vol:.10g} 0 "
        f"{'|'.join(f'{x:.10g}' for x in ca)}"
    )
    head = next(r for r in text.splitlines() if r.startswith("1 Coupled "))
    area = 0.25 * math.pi * ROD_DIAMETER**2
    h = 0.5 * ROD_LENGTH
    rods = [
        "---------------------- ROD TYPES ------------------------------------------",
        "TypeName Diam Mass/m Cd Ca CdEnd CaEnd",
        "(name) (m) (kg/m) (-) (-) (-) (-)",
    ]
    rows = []
    for i, axis in enumerate("xyz"):  # the rod along axis i: its end drags carry CdA_i
        rods.append(f"drag{axis} {ROD_DIAMETER:.10g} 0 0 0 {b.drag_area[i] / (2.0 * area):.10g} 0")
        end = np.eye(3)[i] * h
        rows.append(
            f"{i + 1} drag{axis} Body1 {-end[0]:.10g} {-end[1]:.10g} {-end[2]:.10g} "
            f"{end[0]:.10g} {end[1]:.10g} {end[2]:.10g} 2 -"
        )
    rods += [
        "---------------------- RODS -----------------------------------------------",
        "ID RodType Attachment Xa Ya Za Xb Yb Zb NumSegs RodOutputs",
        "(#) (name) (word/ID) (m) (m) (m) (m) (m) (m) (-) (-)",
        *rows,
    ]
    points = "---------------------- POINTS"
    text = text.replace(head, row)
    k = text.index(points)
    text = text[:k] + "\n".join(rods) + "\n" + text[k:]
    return text.replace("0 WaveKin", "1 WaveKin" if waves else "0 WaveKin")


def _sea_components(
    sc: Scene, period: float, rng: np.random.Generator | int
) -> tuple[np.ndarray, np.ndarray]:
    """Frequencies on the analysis band at Δω = 2π/T and complex amplitudes
    a_j·e^{−iθ_j}, a_j = √(2 S(ω_j) Δω) (η(0, t) = Re Σ A_j e^{iω_j t}). [rad/s, m]"""
    if sc.sea is None:
        return np.zeros(0), np.zeros(0, complex)
    if sc.sea.spreading is not None:
        raise InputError("sea.spreading", "given", "-", "must be absent (long-crested)")
    om = sc.analysis.omega.values()
    dw = 2.0 * math.pi / period
    j = np.arange(max(1, math.ceil(om.min() / dw)), math.floor(om.max() / dw) + 1)
    w = j * dw
    a = np.sqrt(2.0 * sc.sea.spectrum.spectral_density(w, sc.environment.g) * dw)
    theta = np.random.default_rng(rng).uniform(-math.pi, math.pi, w.size)
    return w, a * np.exp(-1j * theta)


def simulate_body_moordyn(
    scene: Scene | dict | str,
    *,
    period: float,
    rng: np.random.Generator | int,
    dt: float = 2.5e-3,
    coupling_dt: float = 0.025,
    sample_dt: float = 0.05,
) -> BodyRecord:
    """Run the scene's free body and its lines in MoorDyn in the scene's sea.

    Parameters
    ----------
    scene : Scene, mapping or JSON
        One free body (see the module), single-segment lines, a long-crested sea (or
        none: the run stays at rest).
    period : float
        Period T of the sea realization (Δω = 2π/T on the analysis band); the record
        is 2T. [s]
    rng : Generator or int
        Source of the phases. [-]
    dt, coupling_dt, sample_dt : float
        MoorDyn's ``dtM``, the interval of the kinematics updates (each set to the
        value at the middle of its interval), the sampling (a multiple of it). [s]

    Returns
    -------
    BodyRecord
    """
    md = import_moordyn()
    sc = load_scene(scene)
    period = _v.positive("period", period, "s")
    coupling_dt = _v.positive("coupling_dt", coupling_dt, "s")
    every = sample_stride(sample_dt, coupling_dt)
    if any(len(ln.segments) != 1 for ln in sc.lines):
        raise InputError("lines", "segments", "-", "each line must be one segment")
    w, amp = _sea_components(sc, period, rng)
    env = sc.environment
    heading = sc.sea.heading_rad if sc.sea is not None else 0.0
    n_steps = int(round(2.0 * period / coupling_dt))
    names = tuple(p[0] for p in moordyn_lines(sc))
    text = moordyn_body_input_file(sc, dt=dt, waves=w.size > 0)
    with moordyn_system(text, "body.txt") as system:
        with quiet_moordyn():
            err = md.Init(system, [], [])
        if err:
            raise InputError("scene", "MoorDyn Init", "-", f"failed with error code {err}")
        kin = None
        if w.size:
            md.ExternalWaveKinInit(system)
            pts = np.asarray(md.ExternalWaveKinGetCoordinates(system), float)
            pts[:, 2] = np.maximum(pts[:, 2], -env.depth)  # nodes sunk into the bed
            wk = wave_kinematics(w, pts, heading, env.depth, env.g)
            kin = (wk.velocity * amp, wk.acceleration * amp)  # (n_p, 3, n_w)
        body = md.GetBody(system, 1)
        handles = [md.GetLine(system, k + 1) for k in range(len(names))]
        last = [md.GetLineNumberNodes(h) - 1 for h in handles]
        n_s = n_steps // every + 1
        f_end = np.empty((n_s, len(names), 3))
        m_end = np.empty((n_s, len(names), 3, 3))
        x_end = np.empty((n_s, len(names), 3))
        anchor = np.empty((n_s, len(names)))
        segment = np.empty((n_s, len(names)))
        pose = np.empty((n_s, 6))
        for k in range(n_steps + 1):
            if k % every == 0:
                s = k // every
                pose[s] = np.asarray(md.GetBodyState(body)[0], float)
                for i, (h, n) in enumerate(zip(handles, last)):
                    f_end[s, i] = md.GetLineNodeForce(h, n)
                    m_end[s, i] = md.GetLineNodeM(h, n)
                    x_end[s, i] = md.GetLineNodePos(h, n)
                    anchor[s, i] = np.linalg.norm(md.GetLineNodeForce(h, 0))
                    segment[s, i] = md.GetLineFairTen(h)
            if k == n_steps:
                break
            t = coupling_dt * k
            if kin is not None:
                tm = t + 0.5 * coupling_dt
                r = float(half_cosine(np.array([tm]), 0.5 * period)[0][0])
                e = r * np.exp(1j * w * tm)
                u = (kin[0] @ e).real
                a = (kin[1] @ e).real  # the ramp's derivative left out: O(1/T)
                md.ExternalWaveKinSet(system, u.tolist(), a.tolist(), t)
            md.Step(system, [], [], t, coupling_dt)
    if not (np.all(np.isfinite(f_end)) and np.all(np.isfinite(pose))):
        raise SolverError(f"MoorDyn's body run is not finite (dtM {dt} s)")
    ts = sample_dt * np.arange(n_s)
    acc = np.zeros_like(x_end)
    acc[1:-1] = (x_end[2:] - 2.0 * x_end[1:-1] + x_end[:-2]) / sample_dt**2
    fair = np.linalg.norm(np.einsum("tlij,tlj->tli", m_end, acc) - f_end, axis=2)
    keep = ts >= period - 1e-9 * period
    keep[-1] = False  # one whole period: [T, 2T)
    return BodyRecord(
        names,
        ts[keep],
        fair[keep],
        anchor[keep],
        segment[keep],
        pose[keep] - pose[0],
        fair[0],
        anchor[0],
        pose[0],
    )


def three_leg_buoy_scene(
    *, elements: int = 20, hs: float = 3.0, volume: float = 60.0, count: int = 200
) -> dict:
    """The mooring of benchmarks/bench_bodies.py made MoorDyn-representable: a buoy
    (2·10⁴ kg, inertia 5/5/8·10⁴ kg·m², translational added mass 1/1/2·10⁴ kg, drag
    area 4/4/8 m²) submerged at z = −5 m with ``volume`` of displacement (no
    hydrostatic matrix, no radiation damping), on three chains (330 m, EA 5·10⁸ N,
    100 kg/m, D 0.1 m) from anchors 300 m away at 0/120/240° in 100 m of water to
    fairleads 5 m out and 2 m below its centre; JONSWAP ``hs``, Tp 9 s, head seas.

    Parameters
    ----------
    elements : int, default 20
        Elements per leg. [-]
    hs : float, default 3
        Significant wave height. [m]
    volume : float, default 60
        Displaced volume of the buoy. [m³]
    count : int, default 200
        Frequencies on [0.1, 2] rad/s. [-]

    Returns
    -------
    dict
        The scene document.
    """
    lines = []
    for i in range(3):
        c, s = math.cos(2.0 * math.pi * i / 3.0), math.sin(2.0 * math.pi * i / 3.0)
        lines.append(
            {
                "name": f"leg{i + 1}",
                "end_a": {"position": [300.0 * c, 300.0 * s, -100.0]},
                "end_b": {"attach": {"body": "buoy", "point": [5.0 * c, 5.0 * s, -2.0]}},
                "segments": [
                    {"length": 330.0, "ea": 5e8, "mass": 100.0, "diameter": 0.1,
                     "elements": elements}
                ],
            }
        )  # fmt: skip
    am = [[0.0] * 6 for _ in range(6)]
    for k, v in enumerate((1e4, 1e4, 2e4)):
        am[k][k] = v
    body = {
        "name": "buoy",
        "position": [0.0, 0.0, -5.0],
        "mass": 2.0e4,
        "inertia": [[5e4, 0, 0], [0, 5e4, 0], [0, 0, 8e4]],
        "added_mass": am,
        "displaced_volume": volume,
        "drag_area": [4.0, 4.0, 8.0],
    }
    return {
        "environment": {"depth": 100.0},
        "sea": {"spectrum": {"type": "jonswap", "hs": hs, "tp": 9.0}, "heading": 0.0},
        "bodies": [body],
        "lines": lines,
        "analysis": {"omega": {"min": 0.1, "max": 2.0, "count": count}},
    }
