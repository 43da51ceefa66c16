"""Scene pieces shared by several test modules."""

from __future__ import annotations

import copy
import math

import numpy as np

from stochcable.examples import load_example
from stochcable.reference.cable import simulate_line_timedomain
from stochcable.scene.model import load_scene

#: ``analysis.linearization`` switches of the linear model alone (the residuals of
#: stochcable.scene.residual_kinds are on by default since issue 31): for tests of the
#: linear model's own properties (two solvers, closed forms, a line on a body against
#: the same line alone, conservation), which the residuals' closed forms do not share.
LINEAR_ONLY = {"drag_residual": False, "geometric_residual": False}


def three_chain_legs(n_el: int, attach: str | None = None) -> list[dict]:
    """Three 330 m chain legs (EA 5e8 N, 100 kg/m, D 0.1 m) at 0/120/240° from anchors
    at radius 300 m on the seabed at 100 m depth to fairleads at radius 5 m, z = −2 m:
    fixed positions, or points of the body ``attach`` (relative to its reference point
    at the origin). The three-leg buoy of benchmarks/bench_bodies.py."""
    lines = []
    for i in range(3):
        a = math.radians(120.0 * i)
        fair = [5.0 * math.cos(a), 5.0 * math.sin(a), -2.0]
        lines.append(
            {
                "name": f"leg{i + 1}",
                "end_a": {"position": [300.0 * math.cos(a), 300.0 * math.sin(a), -100.0]},
                "end_b": (
                    {"position": fair}
                    if attach is None
                    else {"attach": {"body": attach, "point": fair}}
                ),
                "segments": [
                    {"length": 330.0, "ea": 5e8, "mass": 100.0, "diameter": 0.1, "elements": n_el}
                ],
            }
        )
    return lines


def full_circle_excitation(doc: dict, step: float = 15.0) -> None:
    """The disc's excitation table (heading 0 only) over the whole circle: the disc is
    axisymmetric about z through its reference point, so the excitation of heading β
    is that of heading 0 with its force and moment vectors turned by β about z."""
    exc = doc["bodies"][0]["hydrodynamics"]["excitation"]
    f0 = np.asarray(exc["re"], float)[0] + 1j * np.asarray(exc["im"], float)[0]  # (6, n_w)
    heads = np.arange(0.0, 360.0, step)
    out = []
    for b in np.radians(heads):
        c, s = math.cos(b), math.sin(b)
        rot = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
        out.append(np.concatenate([rot @ f0[:3], rot @ f0[3:]]))
    out = np.array(out)
    exc.update(heading=heads.tolist(), re=out.real.tolist(), im=out.imag.tolist())


def vessel_rao_table(headings: list[float] | None = None) -> dict:
    """A vessel's 6-DOF RAO table (the ``prescribed`` document) on 60 frequencies.

    Without ``headings`` one RAO per DOF (no heading dimension).  With ``headings``
    [deg] an (n_heading, n_omega) table per DOF in which surge and pitch scale with
    cos β and sway and roll with sin β (a ship's head-to-beam trend; the 0° row is
    the heading-free table with sway and roll moved into the sin β terms)."""
    w = np.linspace(0.01, 5.0, 60)
    rao = {
        "surge": 0.8 * np.exp(-0.3j * w) / (1 + w**2),
        "sway": 0.3j / (1 + w**2),
        "heave": 1.0 / (1 + (w / 0.9) ** 4) + 0j,
        "roll": 0.01 * w * np.exp(-w) + 0j,
        "pitch": 0.02j * w * np.exp(-w),
    }
    doc: dict = {"omega": w.tolist()}
    if headings is not None:
        b = np.radians(np.asarray(headings, dtype=float))[:, None]
        trend = {"surge": np.cos(b), "sway": np.sin(b), "roll": np.sin(b), "pitch": np.cos(b)}
        rao = {k: trend.get(k, np.ones_like(b)) * v[None] for k, v in rao.items()}
        doc["heading"] = list(headings)
    doc.update({k: {"re": v.real.tolist(), "im": v.imag.tolist()} for k, v in rao.items()})
    return doc


def _vessel(doc: dict, headings: list[float] | None) -> None:
    """A prescribed vessel (:func:`vessel_rao_table`) and a riser from it, beside the
    buoy (ft-slug-lbf, as the example)."""
    doc["bodies"].append(
        {
            "name": "ship",
            "position": [600.0, 0.0, 0.0],
            "mass": 1e6,
            "prescribed": vessel_rao_table(headings),
        }
    )
    doc["lines"].append(
        {
            "name": "riser",
            "end_a": {"position": [800.0, 30.0, -100.0]},
            "end_b": {"attach": {"body": "ship", "point": [10.0, 0.0, -5.0]}},
            "segments": [
                {
                    "length": 265.0,
                    "ea": 1.0e6,
                    "mass": 0.5,
                    "diameter": 0.2,
                    "cd_normal": 1.2,
                    "elements": 8,
                }
            ],
        }
    )


def buoy_with_vessel(
    heading: float = 0.0,
    spreading: dict | None = None,
    *,
    full_circle: bool = False,
    vessel: bool = False,
    drag: bool = True,
    vessel_headings: list[float] | None = None,
) -> dict:
    """The seed §6.7 three-leg disc buoy example at sea ``heading`` [deg] with an
    optional ``spreading``; optionally the disc's excitation over the full circle, a
    vessel with a riser (its RAO table over ``vessel_headings`` when given), the drag
    off."""
    scene = load_example("tuah_1982_disc_buoy_three_legs")
    doc = copy.deepcopy(scene.model_dump(mode="json", exclude_none=True))
    doc["analysis"].pop("timeseries", None)
    if full_circle:
        full_circle_excitation(doc)
    if vessel:
        _vessel(doc, vessel_headings)
    if not drag:  # nothing couples the directions: the response is linear in the sea
        for line in doc["lines"]:
            for seg in line["segments"]:
                seg.update(cd_normal=0.0, cd_axial=0.0)
        doc["bodies"][0]["drag_area"] = [0.0, 0.0, 0.0]
    doc["sea"]["heading"] = heading
    if spreading is not None:
        doc["sea"]["spreading"] = spreading
    return doc


# ------------------------------------------------- the chain's line, fairlead surge

CHAIN_BAND = (0.05, 2.0)
CHAIN_PERIOD = 200.0


def chain_surge_doc(elements: int, residual: bool = True, scale: float = 1.0) -> dict:
    """The chain example's line alone, fairlead surge only (sea and current off; its
    spectrum × scale²), FD on the lines 2πj/P of the band (the TD's), direct solve,
    drag to 1e-8, the drag and geometric residuals asked for when ``residual``."""
    doc = copy.deepcopy(load_example("chain_catenary").model_dump(mode="json"))
    doc["sea"] = None
    doc["environment"]["current"] = []
    doc["analysis"].pop("timeseries", None)
    dw = 2 * math.pi / CHAIN_PERIOD
    k0, k1 = math.ceil(CHAIN_BAND[0] / dw), math.floor(CHAIN_BAND[1] / dw)
    doc["analysis"].update(
        solver="direct",
        omega={"min": k0 * dw, "max": k1 * dw, "count": k1 - k0 + 1},
        linearization={
            "tolerance": 1e-8,
            "max_iterations": 200,
            "drag_residual": residual,
            "geometric_residual": residual,
        },
    )
    surge = doc["lines"][0]["end_b"]["motion"]["surge"]
    surge["density"] = [scale**2 * v for v in surge["density"]]
    doc["lines"][0]["segments"][0]["elements"] = elements
    return doc


def periodic_surge_td(doc: dict, seed: int, scale: float = 1.0, **variant):  # noqa: ANN201
    """The reference TD of ``doc`` (a :func:`chain_surge_doc`) over two periods of a
    periodic DSA fairlead surge on the FD's lines (the input variance exact; phases from
    ``seed``), the motion × ``scale``: its history (``variant``: the TD's options)."""
    scene = load_scene(doc)
    dt = 0.05
    n_t = int(round(2 * CHAIN_PERIOD / dt))
    dw = 2 * math.pi / CHAIN_PERIOD
    w = scene.analysis.omega.values()
    s = scene.lines[0].end_b.motion.surge.spectral_density(w, scene.environment.g)
    phase = np.random.default_rng(seed).uniform(-np.pi, np.pi, w.size)
    c = np.zeros((3, n_t // 2 + 1), dtype=complex)
    c[0, 2 * np.rint(w / dw).astype(int)] = (
        0.5 * n_t * scale * np.sqrt(2 * s * dw) * np.exp(-1j * phase)
    )
    return simulate_line_timedomain(
        scene,
        duration=2 * CHAIN_PERIOD,
        end_realizations={"b": c},
        band=CHAIN_BAND,
        dt=dt,
        **variant,
    )


def td_end_sigma(doc: dict, seed: int, scale: float = 1.0, **variant) -> np.ndarray:
    """TD end σ (fairlead, anchor) over the second period of :func:`periodic_surge_td`
    and the σ divided by ``scale`` (a small scale: the linear limit)."""
    h = periodic_surge_td(doc, seed, scale, **variant)
    keep = (h.t >= CHAIN_PERIOD - 1e-9) & (h.t < 2 * CHAIN_PERIOD - 1e-9)
    return np.array([h.tension_b[keep].std(), h.tension_a[keep].std()]) / scale


#: Sea water density of the buoy groups' drag linearization. [kg/m³]
RHO = 1025.0


def three_leg_buoy_group() -> tuple:
    """Three 3-D chain legs (10 elements) on a 6-DOF buoy (tests/dynamics/
    test_coupled_analysis.py's mooring), the coupled drag fixed point converged:
    (scene, coupled lines, body loads, body, CoupledLinearization)."""
    from stochcable.bodies.rigid import RigidBody
    from stochcable.dynamics.groups import CoupledLine, body_loads, linearize_coupled
    from stochcable.dynamics.loads.channels import line_channels
    from stochcable.dynamics.model.system import build_line_system
    from stochcable.statics import solve_statics

    doc = {
        "environment": {"depth": 100.0},
        "sea": {"spectrum": {"type": "jonswap", "hs": 3.0, "tp": 9.0}, "heading": 30.0},
        "lines": three_chain_legs(10),
        "analysis": {
            "omega": {"min": 0.1, "max": 2.0, "count": 30},
            "solver": "direct",
            "linearization": {"tolerance": 1e-7, "max_iterations": 200},
        },
    }
    body = RigidBody(
        name="buoy",
        position=[0.0, 0.0, 0.0],
        mass=2.0e4,
        inertia=np.diag([5e4, 5e4, 8e4]),
        added_mass=np.diag([1e4, 1e4, 2e4, 2e4, 2e4, 1e3]),
        radiation_damping=np.diag([1e3, 1e3, 5e3, 1e3, 1e3, 1e2]),
        hydrostatic_stiffness=np.diag([0.0, 0.0, 1.26e5, 1e5, 1e5, 0.0]),
        drag_area=[4.0, 4.0, 8.0],
        drag_point=[0.0, 0.0, -1.0],
    )
    scene = load_scene(doc)
    statics = solve_statics(scene, method="fe")
    omega = scene.analysis.omega.values()
    cls = []
    for line in scene.lines:
        s = build_line_system(scene, line, statics.lines[line.name])
        cls.append(CoupledLine(s, line_channels(scene, line, s.positions, omega), end_b="buoy"))
    loads = {"buoy": body_loads(body, cls[0].channels, omega, scene.sea, scene.environment)}
    lin = linearize_coupled(cls, [body], scene.analysis, rho=RHO, loads=loads)
    return scene, cls, loads, body, lin


def two_leg_buoy_doc(heading: float = 0.0, wind: float = 100.0) -> dict:
    """The planar disc buoy (Tuah 1982 §6.5 example) on two legs mirrored about x = 0."""
    doc = load_example("tuah_1982_disc_buoy_single_leg").model_dump(mode="json")
    leg2 = copy.deepcopy(doc["lines"][0])
    leg2["name"] = "leg2"
    leg2["end_a"]["position"] = [300.0, 0.0, -100.0]
    doc["lines"].append(leg2)
    doc["sea"]["heading"] = heading
    doc["bodies"][0]["wind_force"] = [wind, 0.0, 0.0]
    if heading != 0.0:  # (the excitation table has heading 0 only: the Froude–Krylov form)
        doc["bodies"][0].pop("hydrodynamics")
    return doc


def analyzed_group(doc: dict) -> tuple:
    """``doc`` analysed (warnings silenced), with its (first) group's lines, bodies and
    fixed point as the analysis gave them to the results: (result, coupled lines,
    bodies, CoupledLinearization)."""
    import warnings

    import pytest

    from stochcable import analyze
    from stochcable.dynamics.groups import analysis as group_analysis

    seen = {}
    real = group_analysis.coupled_results

    def capture(cls, bodies, clin, settings, **kw):  # noqa: ANN001, ANN202
        seen.setdefault("group", (cls, bodies, clin))
        return real(cls, bodies, clin, settings, **kw)

    mp = pytest.MonkeyPatch()
    mp.setattr(group_analysis, "coupled_results", capture)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            res = analyze(doc)
    finally:
        mp.undo()
    return (res, *seen["group"])


def assembled_group(cls, bodies, clin) -> tuple:  # noqa: ANN001
    """The group's lines and bodies assembled (stochcable.bodies.coupling), at the
    converged line and body drag of ``clin``: (CoupledSystem, the lines' Damping)."""
    from stochcable.bodies.coupling import LineLink, couple
    from stochcable.dynamics.linearization.bodydrag import body_drag_matrix

    damp = {c.name: clin.lines[c.name].damping for c in cls}
    links = [
        LineLink(c.name, c.system.model, end_a=c.end_a, end_b=c.end_b,
                 force_a=c.system.statics.force_a, force_b=c.system.statics.force_b,
                 damping=damp[c.name].matrix)
        for c in cls
    ]  # fmt: skip
    bd = {b.name: body_drag_matrix(b, clin.body_drag[b.name]) for b in bodies
          if b.name in clin.body_drag}  # fmt: skip
    return couple(links, bodies, body_damping=bd), damp


# ------------------------------------------------- the residuals along a line (tests/dynamics)


def guy_3d_doc() -> dict:
    """The inclined guy in its sea turned to 45° (a 3-D model), both residuals."""
    doc = load_example("inclined_guy").model_dump(mode="json")
    doc["analysis"].pop("timeseries", None)
    doc["analysis"]["linearization"].update(drag_residual=True, geometric_residual=True)
    doc["sea"]["heading"] = 45.0
    return doc


def along_line_arguments(doc: dict, line: str | None = None) -> tuple:
    """``doc`` analysed (warnings silenced) with the arguments of each line's along-line
    evaluation kept, ``{system, damping, applied, taps, **keywords}``: (its result, the
    arguments by line name), or with ``line`` (a name; "" the first) that line's
    result and arguments."""
    import warnings

    import pytest

    import stochcable.dynamics.outputs.line_result as line_result_module
    from stochcable import analyze

    seen = {}
    orig = line_result_module.along_line_residual

    def spy(system, damping, applied, taps, *args, **kw):  # noqa: ANN001, ANN202
        seen[system.name] = dict(system=system, damping=damping, applied=applied, taps=taps, **kw)
        return orig(system, damping, applied, taps, *args, **kw)

    mp = pytest.MonkeyPatch()
    mp.setattr(line_result_module, "along_line_residual", spy)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            result = analyze(doc)
    finally:
        mp.undo()
    if line is None:
        return result, seen
    name = line or next(iter(result.lines))
    return result.lines[name], seen[name]


def _dense(blocks, n: int, d: int) -> np.ndarray:  # noqa: ANN001
    """The dense matrix of node blocks (D (n, d, d), O (n − 1, d, d) below the diagonal)."""
    diag, off = blocks
    a = np.zeros((n * d, n * d))
    for k in range(n):
        a[k * d : (k + 1) * d, k * d : (k + 1) * d] = diag[k]
    for k in range(n - 1):
        a[(k + 1) * d : (k + 2) * d, k * d : (k + 1) * d] = off[k]
        a[k * d : (k + 1) * d, (k + 1) * d : (k + 2) * d] = off[k].T
    return a


def forward_dense_motions(system, damping, load: np.ndarray, w: np.ndarray) -> np.ndarray:  # noqa: ANN001
    """The node displacements (n_w, n, d) of a line, ends held, under the node ``load``
    (n, d) at ``w``: its finite-element equations (K − ω²M + iωC) assembled dense from
    the line's blocks and solved by numpy.linalg (no adjoint, no band storage, no LAPACK
    band solver: the influences' independent check)."""
    from stochcable.dynamics.model.blocks import add_blocks, line_prep
    from stochcable.dynamics.solve.line_loads import drag_blocks

    model = system.model
    n, d = model.n_nodes, model.dim
    prep = line_prep(system)
    k, m = _dense(prep.K, n, d), _dense(prep.MT, n, d)
    c = _dense(add_blocks(prep.S, drag_blocks(system, damping)), n, d)
    u = np.zeros((np.size(w), n, d), dtype=complex)
    for j, om in enumerate(np.atleast_1d(w)):
        a = (k - om**2 * m + 1j * om * c)[d:-d, d:-d]
        u[j, 1:-1] = np.linalg.solve(a, load[1:-1].ravel()).reshape(n - 2, d)
    return u


def coupled_leg_motions(group: tuple, f: np.ndarray, w: np.ndarray, leg: int = 0) -> np.ndarray:
    """The displacements (n_w, n, d, n_load) of leg ``leg`` of a
    :func:`three_leg_buoy_group` under its node forces ``f`` (n_dof, n_load) at ``w``:
    the assembled lines–body system (stochcable.bodies.coupling, at the converged line
    and body drag) solved directly and densely (stochcable.reference.bodies)."""
    from stochcable.bodies.coupling import LineLink, couple, coupled_load, expand_line
    from stochcable.dynamics.groups.group import linear_body_drag
    from stochcable.reference.bodies import solve_coupled_direct

    scene, cls, loads, body, lin = group
    damp = {c.name: lin.lines[c.name].damping for c in cls}
    links = [
        LineLink(c.name, c.system.model, end_b="buoy", force_b=c.system.statics.force_b,
                 damping=damp[c.name].matrix)
        for c in cls
    ]  # fmt: skip
    _, cdrag = linear_body_drag(body, RHO, lin.body_sigma["buoy"], loads["buoy"].current, "seed")
    system = couple(links, [body], body_damping={"buoy": cdrag})
    cl = cls[leg]
    fw = np.broadcast_to(f, (w.size,) + f.shape)
    x = solve_coupled_direct(system, coupled_load(system, w, line_loads={cl.name: fw}), w, "dense")
    model = cl.system.model
    return expand_line(system, cl.name, x).reshape(w.size, model.n_nodes, model.dim, -1)
