"""Coupled lines–bodies dynamics (stochcable.dynamics.groups).

Independent checks: a body on springs against its transfer function written out by
hand (and its drag fixed point against the seed's linearized-drag formula); the
infinite-mass limit against the independent line analysis with the equivalent
prescribed end motion (stochcable.dynamics.solve.line_solve); the substructured solve against the
assembled coupled system of stochcable.bodies.rigid (couple + solve_coupled_direct); Foss
with all modes against direct; the 120° symmetry of a three-leg mooring; the vessel
fairlead motion against finite rotations.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from _paths import ROOT
from _scenes import LINEAR_ONLY, three_chain_legs
from scipy.spatial.transform import Rotation

from stochcable.bodies.coupling import LineLink, couple, coupled_load, expand_line
from stochcable.bodies.rigid import ExcitationTable, RigidBody
from stochcable.dynamics.groups import (
    BodyLoads,
    CoupledLine,
    body_loads,
    coupled_modes,
    coupled_results,
    fairlead_motion,
    linearize_coupled,
)
from stochcable.dynamics.groups.line_fixed_point import linearize
from stochcable.dynamics.loads.channels import Channel, line_channels
from stochcable.dynamics.model.blocks import to_freq
from stochcable.dynamics.model.system import build_line_system
from stochcable.dynamics.outputs.line_result import line_result
from stochcable.dynamics.solve.line_loads import fluid_loads, line_inputs
from stochcable.errors import InputError
from stochcable.reference.bodies import solve_coupled_direct
from stochcable.scene.model import load_scene
from stochcable.statics import solve_statics

# one worker runs the module: its module fixtures run once (--dist loadgroup)
pytestmark = pytest.mark.xdist_group("test_coupled_analysis")

RHO = 1025.0


# ----------------------------------------------------------------------- helpers


def _settings():
    """Analysis settings with the fixed point converged to 1e-10."""
    return load_scene(_mooring_doc()).analysis


def _mooring_doc(heading=0.0, n_el=10, count=40, solver="direct", modes="auto", tol=1e-10):
    """Three chain legs at 0/120/240 deg from anchors at radius 300 m to fairleads at
    radius 5 m, z = -2 m, around a buoy at the origin; 100 m depth."""
    lines = three_chain_legs(n_el)
    return {
        "environment": {"depth": 100.0},
        "sea": {"spectrum": {"type": "jonswap", "hs": 3.0, "tp": 9.0}, "heading": heading},
        "lines": lines,
        "analysis": {
            "omega": {"min": 0.1, "max": 2.0, "count": count},
            "solver": solver,
            "modes": modes,
            # the linear model: lines on free bodies carry no residual, the same lines
            # alone (the references here) would
            "linearization": {"tolerance": tol, "max_iterations": 200, **LINEAR_ONLY},
        },
    }


def _buoy(**kw):
    base = dict(
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
    base.update(kw)
    return RigidBody(**base)


def _group(doc, body):
    scene = load_scene(doc)
    statics = solve_statics(scene, method="fe")
    omega = scene.analysis.omega.values()
    cls = []
    for line in scene.lines:
        s = build_line_system(scene, line, statics.lines[line.name])
        cls.append(CoupledLine(s, line_channels(scene, line, s.positions, omega), end_b=body.name))
    loads = {body.name: body_loads(body, cls[0].channels, omega, scene.sea, scene.environment)}
    return scene, cls, loads


@pytest.fixture(scope="module")
def mooring_direct():
    body = _buoy()
    # tolerance 1e-7: the buoy's sway σ is zero by symmetry (heading 0) and carries
    # round-off (~1e-15 m/s) of the mirrored legs; against the convergence floor
    # (1e-6 × the largest σ) that is a relative-change noise of ~1e-9–1e-8, which
    # stalls a 1e-10 iteration (the comparisons below use rtol ≥ 1e-7 / 1e-5)
    scene, cls, loads = _group(_mooring_doc(tol=1e-7), body)
    lin = linearize_coupled(cls, [body], scene.analysis, rho=RHO, loads=loads)
    return scene, cls, loads, body, lin


def _sea_channel(w, spectrum):
    def dens(x):
        return np.interp(x, w, spectrum)

    return Channel(name="sea", kind="sea", omega=w, spectrum=spectrum, density=dens)


# ------------------------------------------------------------ body on springs


def test_planar_body_on_springs_closed_form():
    """Planar body (surge, heave, pitch) with CoG offset, coupled added mass and
    damping on springs, excited by a tabulated force: H = Z⁻¹F with Z written out by
    hand (pitch about +y, Tuah 1982, eq. 3.2.c.20)."""
    m, iyy, cx, cz = 5.0e3, 2.0e4, 0.3, -0.8
    A = np.array([[800.0, 0.0, 150.0], [0.0, 1200.0, 0.0], [150.0, 0.0, 3000.0]])
    B = np.array([[60.0, 0.0, 5.0], [0.0, 90.0, 0.0], [5.0, 0.0, 200.0]])
    Ks = np.array([[2e4, 0.0, 1e3], [0.0, 8e4, 0.0], [1e3, 0.0, 3e5]])
    w = np.linspace(0.2, 3.0, 30)
    f = np.stack([1e4 * np.exp(0.3j * w), 2e4 + 0j * w, 5e3j * w])  # (3, n_w)
    body = RigidBody(
        "disc",
        [0.0, 0.0, -2.0],
        m,
        inertia=np.diag([0.0, iyy, 0.0]),
        cog=[cx, 0.0, cz],
        added_mass=A,
        radiation_damping=B,
        extra_stiffness=Ks,
        planar=True,
        excitation=ExcitationTable(w, [0.0], f[None]),
    )
    spec = np.exp(-((w - 1.0) ** 2))
    ch = (_sea_channel(w, spec),)
    ld = BodyLoads(
        force=f.T[:, :, None].astype(complex),
        velocity=np.zeros((w.size, 3, 1), complex),
        current=np.zeros(3),
    )
    lin = linearize_coupled([], [body], _settings(), rho=RHO, loads={"disc": ld}, channels=ch)
    M_hand = (
        np.array(
            [[m, 0.0, m * cz], [0.0, m, -m * cx], [m * cz, -m * cx, iyy + m * (cx**2 + cz**2)]]
        )
        + A
    )
    z = Ks[None] - w[:, None, None] ** 2 * M_hand[None] + 1j * w[:, None, None] * B[None]
    expected = np.linalg.solve(z, f.T[:, :, None])
    # round-off of a 3×3 solve
    np.testing.assert_allclose(lin.body_motion["disc"], expected, rtol=1e-12, atol=1e-18)
    _, bo = coupled_results([], [body], lin, _settings(), channels=ch)
    dens = np.abs(expected[:, 1, 0]) ** 2 * spec
    # trapezoid of the same density
    assert bo["disc"].motion["heave"].std == pytest.approx(
        math.sqrt(np.trapezoid(dens, w)), rel=1e-12
    )
    assert bo["disc"].motion["heave"].mean == pytest.approx(-2.0)


def test_body_drag_fixed_point_seed_form():
    """Heave of a body with quadratic drag in a wave velocity field: at the fixed
    point b = ρ·CdA·σ·√(2/π) (Tuah 1982, eq. 5.2.2 form, E|v| of a Gaussian) with σ the
    σ of the relative velocity, and H = (F + b v)/(K − ω²(m + A) + iω(B + b))."""
    w = np.linspace(0.2, 2.0, 60)
    m, a33, b33, k33, cda = 1.0e4, 5e3, 2e3, 1.2e5, 10.0
    body = RigidBody(
        "b",
        [0, 0, -5.0],
        m,
        inertia=np.eye(3) * 1e4,
        added_mass=np.diag([1e3, 1e3, a33, 1e3, 1e3, 1e3]),
        radiation_damping=np.diag([0, 0, b33, 0, 0, 0]),
        extra_stiffness=np.diag([1e4, 1e4, k33, 1e5, 1e5, 1e5]),
        drag_area=[0.0, 0.0, cda],
    )
    fz = 3e4 * np.exp(-0.5j * w)
    vz = 0.8j * w
    force = np.zeros((w.size, 6, 1), complex)
    force[:, 2, 0] = fz
    vel = np.zeros((w.size, 3, 1), complex)
    vel[:, 2, 0] = vz
    spec = 2.0 * np.exp(-(((w - 0.9) / 0.2) ** 2))
    ch = (_sea_channel(w, spec),)
    lin = linearize_coupled(
        [],
        [body],
        _settings(),
        rho=RHO,
        channels=ch,
        loads={"b": BodyLoads(force, vel, np.zeros(3))},
    )
    b = lin.body_drag["b"][2]
    h = lin.body_motion["b"][:, 2, 0]
    expected = (fz + b * vz) / (k33 - w**2 * (m + a33) + 1j * w * (b33 + b))
    # the converged linear system, round-off
    np.testing.assert_allclose(h, expected, rtol=1e-10)
    q = np.zeros_like(w)
    q[:-1] += 0.5 * np.diff(w)
    q[1:] += 0.5 * np.diff(w)
    sigma = math.sqrt(np.sum(q * spec * np.abs(vz - 1j * w * h) ** 2))
    # fixed point converged to 1e-10 relative
    assert lin.body_sigma["b"][2] == pytest.approx(sigma, rel=1e-8)
    assert b == pytest.approx(RHO * cda * sigma * math.sqrt(2.0 / math.pi), rel=1e-8)
    assert lin.converged


# ------------------------------------------------------- infinite body mass


def _single_leg_doc(motion=None):
    end_b = {"position": [0.0, 0.0, -5.0]}
    if motion is not None:
        end_b["motion"] = {"rao": motion}
    return {
        "environment": {"depth": 50.0},
        "sea": {"spectrum": {"type": "jonswap", "hs": 2.0, "tp": 7.0}},
        "lines": [
            {
                "name": "leg",
                "end_a": {"position": [-200.0, 0.0, -50.0]},
                "end_b": end_b,
                "segments": [
                    {"length": 215.0, "ea": 1e9, "mass": 80.0, "diameter": 0.09, "elements": 12}
                ],
            }
        ],
        "analysis": {
            "omega": {"min": 0.2, "max": 2.5, "count": 50},
            "solver": "direct",
            # the linear model: the line on the body carries no residual, the line alone
            # (the reference) would
            "linearization": {"tolerance": 1e-11, "max_iterations": 200, **LINEAR_ONLY},
        },
    }


def test_infinite_body_mass_equals_line_with_moving_end():
    """A planar body of mass 1e15 kg excited by F = −ω²M ξ moves with ξ; its line
    must equal the independent analysis of the line whose end moves with the RAO
    T(r)ξ (stochcable.dynamics.solve.line_solve, the moving-end path)."""
    scene = load_scene(_single_leg_doc())
    w = scene.analysis.omega.values()
    xi = np.stack([0.6 * np.exp(0.7j * w), 0.9 + 0.1j * w, 0.02j * np.ones_like(w)])
    big = 1e15
    pos = np.array([0.0, 0.0, -4.0])  # fairlead r = (0, 0, -1)
    M = np.diag([big, big, big])
    F = -(w**2)[None, :] * (M @ xi)
    body = RigidBody(
        "heavy",
        pos,
        big,
        inertia=np.diag([big, big, big]),
        planar=True,
        excitation=ExcitationTable(w, [0.0], F[None]),
        excitation_point=[-pos[0], -pos[1]],
    )
    statics = solve_statics(scene, method="fe")
    line = scene.lines[0]
    s = build_line_system(scene, line, statics.lines["leg"])
    assert s.model.dim == 2
    cl = CoupledLine(s, line_channels(scene, line, s.positions, w), end_b="heavy")
    loads = {"heavy": body_loads(body, cl.channels, w, scene.sea, scene.environment)}
    lin = linearize_coupled([cl], [body], scene.analysis, rho=RHO, loads=loads)
    # body follows ξ to |line reaction| / (ω² m) < 1e6 / (0.04·1e15)
    np.testing.assert_allclose(lin.body_motion["heavy"][:, :, 0], xi.T, rtol=1e-7)
    lo, _ = coupled_results([cl], [body], lin, scene.analysis)
    u = xi[0] + (-1.0) * xi[2], xi[1]  # T(r) ξ, r = (0, 0, -1): u_x = ξ1 + r_z θ
    rao = {
        "omega": w.tolist(),
        "surge": {"re": u[0].real.tolist(), "im": u[0].imag.tolist()},
        "heave": {"re": u[1].real.tolist(), "im": u[1].imag.tolist()},
    }
    ref_scene = load_scene(_single_leg_doc(rao))
    rs = build_line_system(ref_scene, ref_scene.lines[0], statics.lines["leg"])
    ch = line_channels(ref_scene, ref_scene.lines[0], rs.positions, w)
    ref = line_result(rs, ch, linearize(rs, ch, ref_scene.analysis), ref_scene.analysis)
    got = lo["leg"]
    # both fixed points converged to 1e-11; the body lag is 1e-7 relative
    for end in ("end_a", "end_b"):
        assert getattr(got, end).std == pytest.approx(getattr(ref, end).std, rel=1e-6)
    np.testing.assert_allclose(got.tension_std, ref.tension_std, rtol=1e-6)
    np.testing.assert_allclose(got.motion_transfer, ref.motion_transfer, rtol=1e-6, atol=1e-9)


# ------------------------------------------------ second method: assembled system


def test_substructure_equals_assembled_coupled_system(mooring_direct):
    """The substructured response at the converged drag equals the assembled system
    of stochcable.bodies.rigid (couple + coupled_load + solve_coupled_direct, dense)."""
    scene, cls, loads, body, lin = mooring_direct
    w = scene.analysis.omega.values()
    links, line_loads = [], {}
    for cl in cls:
        damp = lin.lines[cl.name].damping
        links.append(
            LineLink(
                cl.name,
                cl.system.model,
                end_b="buoy",
                force_b=cl.system.statics.force_b,
                damping=damp.matrix,
            )
        )
        inp = line_inputs(cl.system, cl.channels)
        line_loads[cl.name] = to_freq(fluid_loads(cl.system, inp, damp))
    from stochcable.dynamics.groups.group import linear_body_drag

    bb, cdrag = linear_body_drag(body, RHO, lin.body_sigma["buoy"], loads["buoy"].current, "seed")
    system = couple(links, [body], body_damping={"buoy": cdrag})
    from stochcable.bodies.rigid import rigid_link_matrix

    t = rigid_link_matrix(body.drag_point)
    fb = loads["buoy"].force + np.einsum("ij,wjc->wic", t.T * bb[None], loads["buoy"].velocity)
    F = coupled_load(system, w, line_loads=line_loads, body_loads={"buoy": fb})
    x = solve_coupled_direct(system, F, w, method="dense")
    xb = x[:, system.body_dofs["buoy"]]
    # two exact solves of the same linear system: round-off of dense LU (cond ~1e8)
    np.testing.assert_allclose(lin.body_motion["buoy"], xb, rtol=1e-7, atol=1e-9 * np.abs(xb).max())
    for cl in cls:
        u = expand_line(system, cl.name, x)
        got = lin.lines[cl.name].response.displacement
        np.testing.assert_allclose(got, u, rtol=1e-7, atol=1e-9 * np.abs(u).max())


def test_foss_all_modes_equals_direct_and_truncated_close(mooring_direct):
    """solver="foss" with every line mode kept is the direct solve (the body DOFs
    are condensed exactly in both); 15 of 27 modes (up to 11·ω_max) keep the
    statistics within 0.5 % (measured 0.15 %; 10 modes, 1.4·ω_max: 1 %)."""
    scene, cls, loads, body, lin = mooring_direct
    n_free = cls[0].system.model.free.size
    lo_d, bo_d = coupled_results(cls, [body], lin, scene.analysis)
    ref = np.array(
        [lo_d[n].end_b.std for n in lo_d]
        + [lo_d[n].end_a.std for n in lo_d]
        + list(bo_d["buoy"].motion_std[[0, 2, 4]])
    )
    for modes, rtol in ((n_free, 1e-5), (15, 5e-3)):
        # all modes: the same linear system; the Foss eigenvectors' round-off stalls the
        # fixed point near 1e-8, so it is converged to 1e-7 here
        sc_f, cls_f, loads_f = _group(_mooring_doc(solver="foss", modes=modes, tol=1e-7), body)
        assert cls_f[0].system.solver == "foss"
        lin_f = linearize_coupled(cls_f, [body], sc_f.analysis, rho=RHO, loads=loads_f)
        lo_f, bo_f = coupled_results(cls_f, [body], lin_f, scene.analysis)
        got = np.array(
            [lo_f[n].end_b.std for n in lo_f]
            + [lo_f[n].end_a.std for n in lo_f]
            + list(bo_f["buoy"].motion_std[[0, 2, 4]])
        )
        np.testing.assert_allclose(got, ref, rtol=rtol)
        if modes == n_free:
            np.testing.assert_allclose(
                lin_f.body_motion["buoy"],
                lin.body_motion["buoy"],
                rtol=1e-5,
                atol=1e-6 * np.abs(lin.body_motion["buoy"]).max(),
            )


def test_frequency_dependent_tables_exact_in_both_solvers(mooring_direct):
    """With A(ω), B(ω) tables both solvers stay exact on the body: the direct and the
    all-modes Foss analysis agree (no frozen matrices)."""
    from stochcable.bodies.rigid import FrequencyTable

    scene, cls, loads, body0, lin_const = mooring_direct
    tw = np.array([0.05, 1.0, 2.5])
    A = np.stack([body0.added_mass * s for s in (1.5, 1.0, 0.7)])
    B = np.stack([body0.radiation_damping * s for s in (0.2, 1.0, 0.4)])
    body = dataclasses.replace(
        body0, added_mass=FrequencyTable(tw, A), radiation_damping=FrequencyTable(tw, B)
    )
    out = []
    for solver, modes in (("direct", "auto"), ("foss", cls[0].system.model.free.size)):
        sc, c, ld = _group(_mooring_doc(solver=solver, modes=modes, tol=1e-7), body)
        out.append(linearize_coupled(c, [body], sc.analysis, rho=RHO, loads=ld))
    # all modes kept: the same linear system, fixed points to 1e-7 (see above)
    np.testing.assert_allclose(
        out[1].body_motion["buoy"],
        out[0].body_motion["buoy"],
        rtol=1e-5,
        atol=1e-6 * np.abs(out[0].body_motion["buoy"]).max(),
    )
    # and the tables do matter: constant matrices give another answer
    assert not np.allclose(out[0].body_motion["buoy"], lin_const.body_motion["buoy"], rtol=1e-3)


# ------------------------------------------------------------------ symmetry


@pytest.fixture(scope="module")
def headings():
    # drag only in heave: Cd·A per global axis (RigidBody.drag_area) is not invariant
    # under rotations about z, so horizontal body drag would break the 120° symmetry
    body = _buoy(drag_area=[0.0, 0.0, 8.0])
    out = {}
    for h in (0.0, 60.0, 120.0):
        # 1e-8: the σ of the grounded elements stall near 1e-8 in round-off at 60 deg
        scene, cls, loads = _group(_mooring_doc(heading=h, tol=1e-8), body)
        lin = linearize_coupled(cls, [body], scene.analysis, rho=RHO, loads=loads)
        out[h] = coupled_results(cls, [body], lin, scene.analysis)
    return out


def _leg_stats(lo, name):
    r = lo[name]
    return np.array([r.end_a.std, r.end_b.std, *r.tension_std])


def test_three_leg_symmetry(headings):
    """120°-symmetric spread: heading 0 is a mirror about x (leg2 = leg3, no sway,
    roll, yaw), 60 a mirror about the 60° axis (leg1 = leg2), 120 the rotation of 0
    (leg2@120 = leg1@0, leg3@120 = leg2@0), the horizontal motion turns with the
    waves."""
    lo0, bo0 = headings[0.0]
    lo60, bo60 = headings[60.0]
    lo120, bo120 = headings[120.0]
    # symmetric statics and equivariant fixed point: round-off and the 1e-8 tolerance
    rt = 1e-6
    np.testing.assert_allclose(_leg_stats(lo0, "leg2"), _leg_stats(lo0, "leg3"), rtol=rt)
    np.testing.assert_allclose(_leg_stats(lo60, "leg1"), _leg_stats(lo60, "leg2"), rtol=rt)
    np.testing.assert_allclose(_leg_stats(lo120, "leg2"), _leg_stats(lo0, "leg1"), rtol=rt)
    np.testing.assert_allclose(_leg_stats(lo120, "leg3"), _leg_stats(lo0, "leg2"), rtol=rt)
    s0 = bo0["buoy"].motion_std
    assert max(s0[1], s0[3], s0[5]) < 1e-8 * s0[0]
    for h, bo in ((60.0, bo60), (120.0, bo120)):
        s = bo["buoy"].motion_std
        b = math.radians(h)
        # on a mirror axis the horizontal motion is along the heading: surge:sway =
        # cos:sin, no yaw
        assert s[1] / s[0] == pytest.approx(abs(math.tan(b)), rel=rt)
        assert s[5] < 1e-6 * s0[0]
    s = bo120["buoy"].motion_std
    # 120 is the rotation of 0: same amplitudes (60 is another case, like 180)
    assert math.hypot(s[0], s[1]) == pytest.approx(s0[0], rel=rt)
    assert s[2] == pytest.approx(s0[2], rel=rt)
    assert math.hypot(s[3], s[4]) == pytest.approx(s0[4], rel=rt)
    s60 = bo60["buoy"].motion_std
    assert abs(math.hypot(s60[0], s60[1]) - s0[0]) > 1e-3 * s0[0]
    # the leg facing the waves differs from the others (the test can fail)
    assert abs(lo0["leg1"].end_b.std - lo0["leg2"].end_b.std) > 1e-2 * lo0["leg1"].end_b.std


def test_coupled_modes_symmetric_pairs(mooring_direct):
    """Modes of the 120°-symmetric spread: the horizontal body modes come in equal
    pairs (surge/sway) and the lowest mode carries body energy."""
    scene, cls, loads, body, _ = mooring_direct
    m = coupled_modes(cls, [body], 0.7, 2.0)
    assert m.omega.size >= 10
    assert np.all(np.diff(m.omega) >= -1e-9)
    # degenerate pair from the 3-fold symmetry, eigen-solver round-off
    assert m.omega[1] == pytest.approx(m.omega[0], rel=1e-8)
    assert m.body_fraction.max() > 0.05


# ------------------------------------------------------------------ vessels


def test_fairlead_motion_first_order_finite_rotation():
    """T(r)ξ against the finite rotation of r (scipy Rotation) for a small ξ."""
    r = np.array([3.0, -2.0, -4.0])
    xi = np.array([0.1, 0.2, -0.3, 0.01, -0.02, 0.015])
    eps = 1e-6
    exact = eps * xi[:3] + Rotation.from_rotvec(eps * xi[3:]).apply(r) - r
    got = fairlead_motion((eps * xi)[None].astype(complex), r)[0]
    # second order in the rotation: |θ|²|r| ~ 1e-15 against 1e-6
    np.testing.assert_allclose(got.real, exact, rtol=1e-7, atol=1e-14)
    with pytest.raises(InputError, match="rao"):
        fairlead_motion(np.zeros((3, 5)), r)


# ------------------------------------------------------------------- errors


def test_errors(mooring_direct):
    scene, cls, loads, body, _ = mooring_direct
    bad = [dataclasses.replace(cls[0], end_b="nobody")]
    with pytest.raises(InputError, match="is not a body"):
        linearize_coupled(bad, [body], scene.analysis, rho=RHO)
    planar = _buoy(planar=True)
    with pytest.raises(InputError, match="6-DOF"):
        linearize_coupled(cls[:1], [planar], scene.analysis, rho=RHO)
    with pytest.raises(InputError, match="needs its channels"):
        linearize_coupled([], [body], scene.analysis, rho=RHO)


# ------------------------------------------------- scene level (analyze_coupled)
#
# The scene fields (Scene.bodies, End.attach, VesselMotion) come from helper A1; until
# they land these tests wrap a v1 scene in stand-ins with the attributes of the
# contract (docs/BODIES.md, notes/bodies_spec.md).

from types import SimpleNamespace  # noqa: E402

from stochcable.dynamics.groups import analyze_coupled  # noqa: E402
from stochcable.results.documents import Result  # noqa: E402


def _attached_scene(scene, attach, bodies):
    """Stand-in scene: ``attach`` maps line name -> (end, body, point)."""
    lines = []
    for ln in scene.lines:
        if ln.name not in attach:
            lines.append(ln)
            continue
        end, body, point = attach[ln.name]
        ends = {e: getattr(ln, e) for e in ("end_a", "end_b")}
        ends[end] = SimpleNamespace(
            position=ends[end].position, motion=None, attach=SimpleNamespace(body=body, point=point)
        )
        lines.append(
            SimpleNamespace(
                name=ln.name,
                segments=ln.segments,
                attachments=ln.attachments,
                elements=ln.elements,
                length=ln.length,
                axial_speed=ln.axial_speed,
                **ends,
            )
        )
    return SimpleNamespace(
        environment=scene.environment,
        sea=scene.sea,
        analysis=scene.analysis,
        is_planar=scene.is_planar,
        lines=tuple(lines),
        bodies=tuple(bodies),
    )


class _Vessel:
    """A VesselMotion stand-in: transfer(omega, heading) -> (6, n_omega) per unit
    amplitude, the same for every heading."""

    def __init__(self, rao):
        self.rao = rao

    def transfer(self, omega, heading=None):
        return np.stack([f(np.asarray(omega)) for f in self.rao])


def test_analyze_coupled_scene_equals_group_and_document(mooring_direct):
    """analyze_coupled on a scene with a buoy on three legs returns the group's
    results (linearize_coupled), a body document with rad and deg, and a Result."""
    scene, cls, loads, body, lin = mooring_direct
    statics = solve_statics(scene, method="fe")
    fake = _attached_scene(
        scene,
        {f"leg{i}": ("end_b", "buoy", None) for i in (1, 2, 3)},
        [SimpleNamespace(name="buoy", position=(0.0, 0.0, 0.0), prescribed=None)],
    )
    timing = {}
    lines, bodies, systems, damp = analyze_coupled(
        fake, statics, scene.analysis, timing=timing, rigid_bodies={"buoy": body}
    )
    assert list(lines) == ["leg1", "leg2", "leg3"] and systems == {} and damp == {}
    # the same computation
    np.testing.assert_allclose(
        bodies["buoy"].motion_transfer, np.transpose(lin.body_motion["buoy"], (2, 1, 0)), rtol=1e-12
    )
    doc = bodies["buoy"].to_document()
    assert doc["motion"]["pitch"]["std_deg"] == pytest.approx(
        math.degrees(doc["motion"]["pitch"]["std"])
    )
    assert doc["modes"]["omega"][0] > 0 and not doc["prescribed"]
    res = Result(
        scene=scene, statics=statics, lines=lines, timeseries=None, timing=timing, bodies=bodies
    )
    full = res.to_document(timeseries="none")
    assert set(full["bodies"]) == {"buoy"} and "lines" in full
    assert "bodies" not in dataclasses.replace(res, bodies={}).to_document("none")


def test_vessel_fairlead_equals_end_motion_rao():
    """A line whose end_b is attached to a prescribed vessel (6-DOF RAO, arm r) equals
    the independent analysis of the line with the end-motion RAO ξ_t + θ × r
    (written out here with np.cross), and the vessel reports its RAO motion."""
    r = np.array([-3.0, 1.0, -4.0])
    vpos = np.array([2.0, -1.0, -1.0])
    fair = vpos + r
    rao = [
        lambda w: 0.5 * np.exp(0.4j * w) + 0 * w,
        lambda w: 0.2j + 0 * w,
        lambda w: 0.9 + 0.1j * w,
        lambda w: 0.01 + 0 * w,
        lambda w: 0.02j * w,
        lambda w: -0.005 + 0 * w,
    ]
    doc = {
        "environment": {"depth": 60.0},
        "sea": {"spectrum": {"type": "jonswap", "hs": 2.0, "tp": 7.0}, "heading": 30.0},
        "lines": [
            {
                "name": "riser",
                "end_a": {"position": [-150.0, 40.0, -60.0]},
                "end_b": {"position": fair.tolist()},
                "segments": [
                    {"length": 175.0, "ea": 8e8, "mass": 90.0, "diameter": 0.1, "elements": 12}
                ],
            }
        ],
        "analysis": {"omega": {"min": 0.2, "max": 2.0, "count": 40}, "solver": "direct"},
    }
    scene = load_scene(doc)
    w = scene.analysis.omega.values()
    statics = solve_statics(scene, method="fe")
    vessel = SimpleNamespace(name="ship", position=tuple(vpos), prescribed=_Vessel(rao))
    fake = _attached_scene(scene, {"riser": ("end_b", "ship", tuple(r))}, [vessel])
    lines, bodies, systems, damp = analyze_coupled(fake, statics, scene.analysis, rigid_bodies={})
    xi = np.stack([f(w) for f in rao])  # (6, n_w)
    u = xi[:3] + np.cross(xi[3:].T, r).T  # θ × r
    mot = {
        "omega": w.tolist(),
        **{
            k: {"re": u[i].real.tolist(), "im": u[i].imag.tolist()}
            for i, k in enumerate(("surge", "sway", "heave"))
        },
    }
    doc["lines"][0]["end_b"]["motion"] = {"rao": mot}
    ref_scene = load_scene(doc)
    rs = build_line_system(ref_scene, ref_scene.lines[0], statics.lines["riser"])
    ch = line_channels(ref_scene, ref_scene.lines[0], rs.positions, w)
    ref = line_result(rs, ch, linearize(rs, ch, ref_scene.analysis), ref_scene.analysis)
    got = lines["riser"]
    # the same path with the same end motion up to round-off of the cross product
    assert got.end_b.std == pytest.approx(ref.end_b.std, rel=1e-10)
    np.testing.assert_allclose(got.motion_transfer, ref.motion_transfer, rtol=1e-10, atol=1e-14)
    assert "riser" in systems and "riser" in damp  # the independent path
    v = bodies["ship"]
    assert v.prescribed and v.dofs[3] == "roll"
    np.testing.assert_allclose(v.motion_transfer[0], xi, rtol=1e-14)
    # a vessel RAO without a sea is refused
    nosea = SimpleNamespace(**{**vars(fake), "sea": None})
    with pytest.raises(InputError, match="needs a 'sea'"):
        analyze_coupled(nosea, statics, scene.analysis, rigid_bodies={})


def test_free_floating_body_without_lines_closed_form():
    """A body with no lines in a scene: heave H = F/(K − ω²(m + A) + iωB), its
    statistics from the sea spectrum; a line-less scene part needs no line."""
    doc = _single_leg_doc()
    scene = load_scene(doc)
    w = scene.analysis.omega.values()
    k33, m, a33, b33 = 2e5, 1e4, 6e3, 4e3
    f = np.zeros((1, 6, w.size), complex)
    f[0, 2] = k33 * (1.0 - 0.1 * w**2)
    body = RigidBody(
        "float",
        [100.0, 0.0, 0.0],
        m,
        inertia=np.eye(3) * 1e4,
        added_mass=np.diag([1e3, 1e3, a33, 1e3, 1e3, 1e3]),
        radiation_damping=np.diag([1e2, 1e2, b33, 1e2, 1e2, 1e2]),
        hydrostatic_stiffness=np.diag([0.0, 0.0, k33, 1e5, 1e5, 0.0]),
        excitation=ExcitationTable(w, [0.0], f),
    )
    fake = _attached_scene(
        scene, {}, [SimpleNamespace(name="float", position=(100.0, 0, 0), prescribed=None)]
    )
    statics = solve_statics(scene, method="fe")
    lines, bodies, _, _ = analyze_coupled(
        fake, statics, scene.analysis, rigid_bodies={"float": body}
    )
    from stochcable.sea.kinematics import wavenumber

    k = wavenumber(w, scene.environment.depth)
    expected = f[0, 2] * np.exp(-1j * k * 100.0) / (k33 - w**2 * (m + a33) + 1j * w * b33)
    # round-off of a 6×6 solve
    np.testing.assert_allclose(bodies["float"].motion_transfer[0, 2], expected, rtol=1e-12)
    assert list(lines) == ["leg"]


def test_body_gravity_stiffness_metacentric_terms():
    """Weight at the CoG and buoyancy at the CoB give roll/pitch restoring
    ρg∇z_B − m g z_G (hand formula), nothing on translations or yaw."""
    from stochcable.dynamics.groups import body_gravity_stiffness

    m, zg, zb, vol, g = 3e4, -1.5, -0.4, 40.0, 9.81
    body = RigidBody("s", [0, 0, -10.0], m, cog=[0.0, 0.0, zg])
    k = body_gravity_stiffness(body, vol, [0.0, 0.0, zb], RHO, g)
    expected = np.zeros((6, 6))
    expected[3, 3] = expected[4, 4] = RHO * g * vol * zb - m * g * zg
    # exact arithmetic of the same products
    np.testing.assert_allclose(k, expected, rtol=1e-14, atol=1e-9)
    kp = body_gravity_stiffness(dataclasses.replace(body, planar=True), vol, [0.0, 0.0, zb], RHO, g)
    assert kp.shape == (3, 3) and kp[2, 2] == pytest.approx(expected[4, 4], rel=1e-14)


# ------------------------------------------------------ with the scene of issue 6


def test_scene_vessel_fairlead_equals_end_motion_rao():
    """Scene document with a prescribed vessel (VesselMotion) and a line attached to
    it: the statics put the end at position + point, the dynamics equal the line with
    the end-motion RAO ξ_t + θ × r (np.cross), as the stand-in test above."""
    r = np.array([-3.0, 1.0, -4.0])
    vpos = np.array([2.0, -1.0, -1.0])
    w_t = np.linspace(0.1, 3.0, 30)
    xi = np.stack(
        [
            0.5 * np.exp(0.4j * w_t),
            0.2j + 0 * w_t,
            0.9 + 0.1j * w_t,
            0.01 + 0 * w_t,
            0.02j * w_t,
            -0.005 + 0 * w_t,
        ]
    )
    tab = {
        k: {"re": xi[i].real.tolist(), "im": xi[i].imag.tolist()}
        for i, k in enumerate(("surge", "sway", "heave", "roll", "pitch", "yaw"))
    }
    doc = {
        "environment": {"depth": 60.0},
        "sea": {"spectrum": {"type": "jonswap", "hs": 2.0, "tp": 7.0}, "heading": 30.0},
        "bodies": [
            {
                "name": "ship",
                "position": vpos.tolist(),
                "mass": 1e7,
                "prescribed": {"omega": w_t.tolist(), **tab},
            }
        ],
        "lines": [
            {
                "name": "riser",
                "end_a": {"position": [-150.0, 40.0, -60.0]},
                "end_b": {"attach": {"body": "ship", "point": r.tolist()}},
                "segments": [
                    {"length": 175.0, "ea": 8e8, "mass": 90.0, "diameter": 0.1, "elements": 12}
                ],
            }
        ],
        "analysis": {"omega": {"min": 0.2, "max": 2.0, "count": 40}, "solver": "direct"},
    }
    scene = load_scene(doc)
    statics = solve_statics(scene, method="fe")
    np.testing.assert_allclose(statics.lines["riser"].positions[-1], vpos + r, atol=1e-9)
    lines, bodies, systems, _ = analyze_coupled(scene, statics, scene.analysis)
    w = scene.analysis.omega.values()
    x = scene.bodies[0].prescribed.transfer(w)
    u = x[:3] + np.cross(x[3:].T, r).T
    ref_doc = {**doc, "bodies": []}
    ref_doc["lines"] = [
        {
            **doc["lines"][0],
            "end_b": {
                "position": (vpos + r).tolist(),
                "motion": {
                    "rao": {
                        "omega": w.tolist(),
                        **{
                            k: {"re": u[i].real.tolist(), "im": u[i].imag.tolist()}
                            for i, k in enumerate(("surge", "sway", "heave"))
                        },
                    }
                },
            },
        }
    ]
    ref_scene = load_scene(ref_doc)
    rs = build_line_system(ref_scene, ref_scene.lines[0], statics.lines["riser"])
    ch = line_channels(ref_scene, ref_scene.lines[0], rs.positions, w)
    ref = line_result(rs, ch, linearize(rs, ch, ref_scene.analysis), ref_scene.analysis)
    # same path, same end motion up to the round-off of the cross product and of the
    # RAO interpolation on the grid
    assert lines["riser"].end_b.std == pytest.approx(ref.end_b.std, rel=1e-10)
    assert bodies["ship"].prescribed and "riser" in systems


def test_scene_three_leg_example_mirror_symmetry():
    """The seed §6.7 disc on three legs (stochcable/examples, helper A1's statics):
    heading 0 is a mirror about x, so leg2 = leg3 and the buoy has no sway, roll or
    yaw; the statics pose is the statistics' mean."""
    path = ROOT / "stochcable" / "examples" / "tuah_1982_disc_buoy_three_legs.json"
    scene = load_scene(path)
    if scene.sea is None or abs(scene.sea.heading) > 0:
        pytest.skip("the example is not at heading 0")
    statics = solve_statics(scene, method="fe")
    lines, bodies, _, _ = analyze_coupled(scene, statics, scene.analysis)
    ((name, b),) = bodies.items()
    s = b.motion_std
    # mirror symmetry: round-off against the surge σ
    assert max(s[1], s[3], s[5]) < 1e-8 * s[0]
    # mirrored legs: statics symmetric to its 1e-10 tolerance, fixed point 1e-4
    assert lines["leg2"].end_b.std == pytest.approx(lines["leg3"].end_b.std, rel=1e-5)
    assert b.motion["heave"].mean == pytest.approx(statics.bodies[name].position[2])


# ------------------------------------------------------------------ coarse start


def _count_full_evaluations(monkeypatch, n_omega):
    """Count the group solves on the full grid of ``n_omega`` frequencies."""
    import stochcable.dynamics.groups.group as cg

    count = [0]
    solve = cg.solve_group

    def counted(g, *args, **kw):
        count[0] += g.omega.size == n_omega
        return solve(g, *args, **kw)

    monkeypatch.setattr(cg, "solve_group", counted)
    return count


@pytest.mark.parametrize("solver", ["direct", "foss"])
def test_coarse_start_gives_the_full_grid_fixed_point(solver, monkeypatch):
    """The coarse-subset stage only supplies the start: with and without it the
    iteration ends at the same full-grid fixed point.  Both stop at a relative σ
    change below tol = 1e-8 with a contraction ≈ 0.1, so each is within ~tol of the
    fixed point: σ and the outputs agree to 1e-6 (100·tol, margin for the transfer
    functions' amplification of the σ error)."""
    from stochcable.dynamics.groups.coarse import coarse_subset
    from stochcable.dynamics.groups.group import GroupSystem

    body = _buoy()
    scene, cls, loads = _group(_mooring_doc(count=96, solver=solver, tol=1e-8), body)
    g = GroupSystem(cls, [body], loads, RHO, cls[0].channels)
    idx = coarse_subset(g)
    np.testing.assert_array_equal(idx, np.r_[np.arange(0, 96, 4), 95])
    full = linearize_coupled(cls, [body], scene.analysis, rho=RHO, loads=loads, coarse=False)
    fast = linearize_coupled(cls, [body], scene.analysis, rho=RHO, loads=loads, coarse=True)
    assert full.converged and fast.converged
    assert fast.history[-1] <= 1e-8 and len(fast.history) == fast.iterations
    # the coarse stage ran (its evaluations head the history); not the default at a
    # tolerance below COARSE_MIN_TOLERANCE
    assert fast.iterations > 2 and fast.history[:2] != full.history[:2]
    auto = linearize_coupled(cls, [body], scene.analysis, rho=RHO, loads=loads)
    assert auto.history == full.history
    for n in ("leg1", "leg2"):
        sig = full.lines[n].damping.sigma
        np.testing.assert_allclose(
            fast.lines[n].damping.sigma, sig, rtol=1e-6, atol=1e-9 * sig.max()
        )
        np.testing.assert_allclose(
            fast.lines[n].response.support_force,
            full.lines[n].response.support_force,
            rtol=1e-6,
            atol=1e-6 * np.abs(full.lines[n].response.support_force).max(),
        )
    # the sway σ is round-off (heading 0): absolute tolerance at 1e-9 of the largest
    np.testing.assert_allclose(
        fast.body_sigma["buoy"],
        full.body_sigma["buoy"],
        rtol=1e-6,
        atol=1e-9 * full.body_sigma["buoy"].max(),
    )
    np.testing.assert_allclose(
        fast.body_motion["buoy"],
        full.body_motion["buoy"],
        rtol=1e-6,
        atol=1e-6 * np.abs(full.body_motion["buoy"]).max(),
    )


@pytest.mark.parametrize("solver,warm", [("direct", True), ("foss", True), ("foss", False)])
def test_coarse_start_saves_full_grid_evaluations(solver, warm, monkeypatch):
    """At the default tolerance 1e-4 the coarse start with its defect correction needs
    fewer full-grid evaluations than the plain iteration (measured 3 against 6 on this
    mooring: the stride-4 subset's σ are ~4 % off, the corrected rounds gain ~30x
    each), with or without the rounds' warm step, and the answer is the full-grid
    fixed point within the tolerance."""
    import stochcable.dynamics.groups.coarse as cc

    monkeypatch.setattr(cc, "_WARM_ROUNDS", warm)
    body = _buoy()
    scene, cls, loads = _group(_mooring_doc(count=96, solver=solver, tol=1e-4), body)
    full = linearize_coupled(cls, [body], scene.analysis, rho=RHO, loads=loads, coarse=False)
    n_full = _count_full_evaluations(monkeypatch, 96)
    fast = linearize_coupled(cls, [body], scene.analysis, rho=RHO, loads=loads)
    assert fast.converged and fast.history[-1] <= 1e-4
    assert 1 <= n_full[0] <= full.iterations - 2
    # both within ~tol of the fixed point (contraction ≈ 0.1): 1e-3 = 10·tol
    for n in ("leg1", "leg2"):
        np.testing.assert_allclose(
            fast.lines[n].damping.sigma,
            full.lines[n].damping.sigma,
            rtol=1e-3,
            atol=1e-6 * full.lines[n].damping.sigma.max(),
        )
    np.testing.assert_allclose(
        fast.body_sigma["buoy"],
        full.body_sigma["buoy"],
        rtol=1e-3,
        atol=1e-6 * full.body_sigma["buoy"].max(),
    )


def test_coarse_subset_skipped_on_small_grids(mooring_direct):
    """40 frequencies (< COARSE_MIN_FREQUENCIES): no coarse stage."""
    from stochcable.dynamics.groups.coarse import COARSE_MIN_FREQUENCIES, coarse_subset
    from stochcable.dynamics.groups.group import GroupSystem

    scene, cls, loads, body, lin = mooring_direct
    assert cls[0].channels[0].omega.size < COARSE_MIN_FREQUENCIES
    assert coarse_subset(GroupSystem(cls, [body], loads, RHO, cls[0].channels)) is None


def test_sliced_channel_inputs_equal_the_subset_of_the_full_inputs(mooring_direct):
    """A channel restricted to a frequency subset gives the full channel's loads at
    those frequencies (every array sliced along its frequency axis)."""
    from stochcable.dynamics.groups.coarse import _sliced_channel

    scene, cls, loads, body, lin = mooring_direct
    s = cls[0].system
    idx = np.array([0, 3, 7, 20, 39])
    full = line_inputs(s, cls[0].channels)
    sub = line_inputs(s, tuple(_sliced_channel(c, idx) for c in cls[0].channels))
    np.testing.assert_array_equal(sub.omega, full.omega[idx])
    np.testing.assert_allclose(sub.inertia_load, full.inertia_load[:, :, idx], rtol=1e-13)
    np.testing.assert_allclose(sub.moments, full.moments[..., idx, :], rtol=1e-13)


@pytest.mark.parametrize("modes", [8, "auto"])
def test_foss_unit_columns_in_closed_form_equal_the_plain_solve(modes):
    """The Foss line solve of the coupled group with the unit end-motion columns in
    closed form (ω²·M_T U_p − iω·C U_p loads, their static correction as two columns)
    is the plain analysis._solve_free of the augmented channels: the same linear
    system, so equal to round-off (1e-10 of the largest entry), truncated (8 of 27
    modes, static correction on) or not."""
    from stochcable.dynamics.groups.group import GroupSystem
    from stochcable.dynamics.groups.lineparts import foss_unit_split
    from stochcable.dynamics.linearization.variance import drag_coefficients
    from stochcable.dynamics.solve.line_solve import solve_free

    body = _buoy()
    scene, cls, loads = _group(_mooring_doc(solver="foss", modes=modes), body)
    g = GroupSystem(cls, [body], loads, RHO, cls[0].channels)
    cl = cls[0]
    s = cl.system
    assert s.solver == "foss"
    assert (s.n_modes < s.model.free.size) == (modes == 8)
    # a drag of a plausible size: σ = 0.3 m/s on every element
    damp = drag_coefficients(s, np.full(2 * s.model.n_elements, 0.3), "seed")
    got, _ = foss_unit_split(s, g.inp_phys[cl.name], g.inp[cl.name], damp)
    ref, _ = solve_free(s, g.inp[cl.name], damp)
    assert got.shape == ref.shape and got.shape[-1] == 4  # sea + 3 unit columns
    np.testing.assert_allclose(got, ref, rtol=0, atol=1e-10 * np.abs(ref).max())


# ------------------------------------------------------------- fixed body DOFs


def test_all_dofs_fixed_equals_lines_with_fixed_fairleads():
    """A buoy with all six DOFs in ``fixed_dofs`` holds its fairleads: each leg is the
    independent analysis (stochcable.dynamics.groups.line_fixed_point.linearize) of the leg with its
    fairlead fixed at the same static point; the body does not move."""
    body = _buoy(fixed_dofs=("surge", "sway", "heave", "roll", "pitch", "yaw"))
    scene, cls, loads = _group(_mooring_doc(), body)
    lin = linearize_coupled(cls, [body], scene.analysis, rho=RHO, loads=loads)
    assert np.all(lin.body_motion["buoy"] == 0.0)  # a constraint, exactly zero
    lo, _ = coupled_results(cls, [body], lin, scene.analysis)
    for cl in cls:
        ref = line_result(
            cl.system,
            cl.channels,
            linearize(cl.system, cl.channels, scene.analysis),
            scene.analysis,
        )
        got = lo[cl.name]
        # both fixed points converged to 1e-10 relative (the group's jointly)
        for end in ("end_a", "end_b"):
            assert getattr(got, end).std == pytest.approx(getattr(ref, end).std, rel=1e-8)
        np.testing.assert_allclose(got.tension_std, ref.tension_std, rtol=1e-8)
        np.testing.assert_allclose(
            got.motion_transfer,
            ref.motion_transfer,
            rtol=1e-8,
            atol=1e-10 * np.abs(ref.motion_transfer).max(),
        )


def test_fixed_heave_on_springs_closed_form():
    """6-DOF body on coupled springs with heave fixed: ξ_heave ≡ 0 and the other five
    DOFs solve the 5×5 system of Z = K − ω²(M + A) + iωB without the heave row and
    column (written out here), not the 6×6 one."""
    w = np.linspace(0.2, 3.0, 25)
    rng = np.random.default_rng(7)
    a = rng.normal(size=(6, 6))
    ks = np.diag([2e4, 3e4, 8e4, 2e5, 3e5, 1e5]) + 2e3 * (a + a.T)
    A = np.diag([800.0, 900.0, 1200.0, 3e3, 3e3, 1e3])
    A[0, 2] = A[2, 0] = 150.0  # heave couples to surge: fixing heave matters
    B = np.diag([60.0, 60.0, 90.0, 200.0, 200.0, 50.0])
    f = (1e4 * np.exp(0.3j * w)[None] * np.arange(1, 7)[:, None]).astype(complex)
    body = RigidBody(
        "b",
        [0.0, 0.0, -3.0],
        5e3,
        inertia=np.diag([2e4, 2e4, 3e4]),
        cog=[0.2, 0.1, -0.5],
        added_mass=A,
        radiation_damping=B,
        extra_stiffness=ks,
        fixed_dofs=["heave"],
        excitation=ExcitationTable(w, [0.0], f[None]),
    )
    spec = np.exp(-((w - 1.0) ** 2))
    ch = (_sea_channel(w, spec),)
    ld = BodyLoads(
        force=f.T[:, :, None], velocity=np.zeros((w.size, 3, 1), complex), current=np.zeros(3)
    )
    lin = linearize_coupled([], [body], _settings(), rho=RHO, loads={"b": ld}, channels=ch)
    keep = [0, 1, 3, 4, 5]
    M = body.mass_matrix() + A
    z = ks[None] - w[:, None, None] ** 2 * M[None] + 1j * w[:, None, None] * B[None]
    expected = np.zeros((w.size, 6), complex)
    expected[:, keep] = np.linalg.solve(z[:, keep][:, :, keep], f.T[:, keep, None])[..., 0]
    xi = lin.body_motion["b"][:, :, 0]
    assert np.all(xi[:, 2] == 0.0)
    # round-off of a 5×5 solve
    np.testing.assert_allclose(xi, expected, rtol=1e-11, atol=1e-14 * np.abs(expected).max())
    # and it is not the unconstrained answer (the test can fail)
    free = np.linalg.solve(z, f.T[:, :, None])[..., 0]
    assert np.max(np.abs(free[:, 0] - expected[:, 0])) > 1e-3 * np.abs(expected[:, 0]).max()
    _, bo = coupled_results([], [body], lin, _settings(), channels=ch)
    assert bo["b"].motion["heave"].std == 0.0


def test_fixed_dofs_direct_equals_foss_all_modes():
    """Yaw and roll fixed: the direct and the all-modes Foss coupled analyses solve the
    same constrained system (fixed point converged to 1e-7, the Foss round-off
    floor of test_foss_all_modes_equals_direct_and_truncated_close)."""
    body = _buoy(fixed_dofs=("roll", "yaw"))
    out = {}
    for solver, modes in (("direct", "auto"), ("foss", 27)):
        sc, c, ld = _group(_mooring_doc(solver=solver, modes=modes, tol=1e-7), body)
        assert c[0].system.solver == solver
        lin = linearize_coupled(c, [body], sc.analysis, rho=RHO, loads=ld)
        out[solver] = lin.body_motion["buoy"]
    for x in out.values():
        assert np.all(x[:, [3, 5]] == 0.0)
    np.testing.assert_allclose(
        out["foss"], out["direct"], rtol=1e-5, atol=1e-6 * np.abs(out["direct"]).max()
    )


@pytest.mark.parametrize("method", ["full", "reduced"])
def test_fixed_dofs_modes_are_the_constrained_eigenproblem(mooring_direct, method):
    """Coupled modes with heave and yaw fixed: the frequencies of the dense constrained
    eigenproblem (the assembled K, M of stochcable.bodies.coupling.couple without the fixed
    rows and columns); the fixed DOFs are zero in the shapes."""
    import scipy.linalg as sla

    from stochcable.bodies.coupling import constant_matrices

    scene, cls, _, body0, _ = mooring_direct
    body = dataclasses.replace(body0, fixed_dofs=("heave", "yaw"))
    links = [
        LineLink(cl.name, cl.system.model, end_b="buoy", force_b=cl.system.statics.force_b)
        for cl in cls
    ]
    system = couple(links, [body])
    K, M, _ = constant_matrices(system, 0.7)
    keep = np.setdiff1d(np.arange(system.n_dof), system.body_dofs["buoy"][[2, 5]])
    k = 0.5 * (K + K.T).toarray()[np.ix_(keep, keep)]
    m = M.toarray()[np.ix_(keep, keep)]
    ref = np.sqrt(sla.eigh(k, m, eigvals_only=True))
    got = coupled_modes(cls, [body], 0.7, 2.0, method=method)
    n = got.omega.size
    assert n >= 10
    # full: the same dense eigenproblem; reduced: Craig–Bampton with all 27 modes of
    # each 10-element leg, an exact change of basis: both round-off of eigh (the
    # truncated reduction is tested in tests/dynamics/test_coupled_reduction.py)
    tol = 1e-9
    np.testing.assert_allclose(got.omega, ref[:n], rtol=tol)
    assert np.all(got.omega >= ref[:n] * (1 - 1e-9))
    assert np.all(got.body_shapes["buoy"][[2, 5]] == 0.0)
    unconstrained = coupled_modes(cls, [body0], 0.7, 2.0, method="full")
    assert not np.allclose(unconstrained.omega[:n], got.omega, rtol=1e-3)


def test_fixed_dofs_validation_and_scene():
    """RigidBody.fixed_dofs: names of the body's DOFs, no repeats; the scene's
    Body.fixed_dofs reach the RigidBody (body_scene)."""
    with pytest.raises(InputError, match="fixed_dofs.*unknown"):
        _buoy(fixed_dofs=("heave", "twist"))
    with pytest.raises(InputError, match="fixed_dofs.*repeat"):
        _buoy(fixed_dofs=("heave", "heave"))
    with pytest.raises(InputError, match="fixed_dofs.*unknown"):
        _buoy(
            planar=True,
            added_mass=None,
            radiation_damping=None,
            hydrostatic_stiffness=None,
            fixed_dofs=("yaw",),
        )
    assert _buoy(fixed_dofs="yaw").fixed_dofs == ("yaw",)
    np.testing.assert_array_equal(_buoy(fixed_dofs=("sway", "yaw")).free_index, [0, 2, 3, 4])
    from stochcable.bodies.from_scene import scene_rigid_bodies

    doc = _mooring_doc()
    doc["bodies"] = [
        {"name": "buoy", "position": [0.0, 0.0, 0.0], "mass": 2.0e4, "fixed_dofs": ["yaw", "roll"]}
    ]
    rb = scene_rigid_bodies(load_scene(doc))["buoy"]
    assert rb.fixed_dofs == ("yaw", "roll")
    # end to end: the fairleads on the buoy, an oblique sea; roll and yaw stay zero
    doc = _mooring_doc(heading=30.0, tol=1e-4)
    for ln in doc["lines"]:
        p = ln["end_b"].pop("position")
        ln["end_b"]["attach"] = {"body": "buoy", "point": p}
    doc["bodies"] = [
        {
            "name": "buoy",
            "position": [0.0, 0.0, 0.0],
            "mass": 2.0e4,
            "inertia": [[5e4, 0, 0], [0, 5e4, 0], [0, 0, 8e4]],
            "added_mass": np.diag([1e4, 1e4, 2e4, 2e4, 2e4, 1e3]).tolist(),
            "radiation_damping": np.diag([1e3, 1e3, 5e3, 1e3, 1e3, 1e2]).tolist(),
            "hydrostatic_stiffness": np.diag([0, 0, 1.26e5, 1e5, 1e5, 0]).tolist(),
            "fixed_dofs": ["roll", "yaw"],
        }
    ]
    sc = load_scene(doc)
    _, bodies, _, _ = analyze_coupled(sc, solve_statics(sc, method="fe"), sc.analysis)
    std = bodies["buoy"].motion_std
    assert std[3] == 0.0 and std[5] == 0.0 and np.all(std[[0, 1, 2, 4]] > 0)


def test_coarse_start_falls_back_to_the_full_grid(monkeypatch):
    """A coarse model that fails (a singular modal impedance) is skipped: the full-grid
    iteration alone runs, the same evaluations as ``coarse=False``."""
    import stochcable.dynamics.groups.lineparts as cp

    body = _buoy()
    scene, cls, loads = _group(_mooring_doc(count=96, solver="foss", tol=1e-4), body)
    full = linearize_coupled(cls, [body], scene.analysis, rho=RHO, loads=loads, coarse=False)

    def fail(*args, **kwargs):
        raise np.linalg.LinAlgError("Singular matrix")

    monkeypatch.setattr(cp, "ModalLine", fail)
    fast = linearize_coupled(cls, [body], scene.analysis, rho=RHO, loads=loads)
    assert fast.history == full.history
    np.testing.assert_array_equal(fast.body_sigma["buoy"], full.body_sigma["buoy"])


def test_warm_step_is_the_fixed_point_of_an_affine_map():
    """The warm step of the coarse start's rounds is an Anderson (type II, unmixed)
    step over secant pairs: for an affine map y -> r·(A y + b) in n dimensions, n + 1
    affinely independent pairs give its fixed point exactly (closed form
    (I − diag(r) A)⁻¹ diag(r) b; tolerance: round-off of a 3×3 solve)."""
    from stochcable.dynamics.groups.coarse import _warm_step

    rng = np.random.default_rng(3)
    a = 0.3 * rng.standard_normal((3, 3))
    b = rng.uniform(1.0, 2.0, 3)
    r = np.array([1.1, 0.9, 1.0])
    xs = rng.uniform(0.5, 1.5, (4, 3))
    pairs = [(x, a @ x + b) for x in xs]
    exact = np.linalg.solve(np.eye(3) - r[:, None] * a, r * b)
    assert np.all(exact > 0)  # the step clips at zero (σ ≥ 0)
    np.testing.assert_allclose(_warm_step(pairs, r), exact, rtol=1e-10)
    # one pair: the plain step r·G(x)
    np.testing.assert_allclose(_warm_step(pairs[:1], r), r * (a @ xs[0] + b), rtol=1e-14)


def test_large_static_body_rotation_is_flagged():
    """The body data are used at the input orientation: a static heel above
    STATIC_ROTATION_LIMIT gets a PhysicsWarning with the angle and the fix; the
    examples (0.45° and 0.12°) get none."""
    import warnings

    from stochcable.analysis import analyze
    from stochcable.dynamics.groups.model import STATIC_ROTATION_LIMIT
    from stochcable.errors import PhysicsWarning
    from stochcable.examples import load_example
    from stochcable.scene.model import load_scene

    doc = load_example("tuah_1982_disc_buoy_single_leg").model_dump(mode="json", exclude_none=True)
    with warnings.catch_warnings(record=True) as rec:
        warnings.simplefilter("always")
        small = analyze(load_scene(doc))
    assert not [w for w in rec if "static rotation" in str(w.message)]
    assert float(abs(small.statics.bodies["disc"].rotation[1])) < STATIC_ROTATION_LIMIT
    # a pitch moment of ≈ 0.13 rad × the pitch stiffness 31,399 lbf·ft/rad heels it ≈ 7.6°
    doc["bodies"][0]["wind_moment"] = [0.0, 4000.0, 0.0]
    with pytest.warns(
        PhysicsWarning,
        match=r"body 'disc': its static rotation is 7\.6\d°.*"
        r"above 5°.*give the body's data at its static "
        r"orientation",
    ) as rec:
        big = analyze(load_scene(doc))
    heel = float(big.statics.bodies["disc"].rotation[1])
    assert heel > STATIC_ROTATION_LIMIT
    assert f"{math.degrees(heel):.3g}°" in str(
        next(w.message for w in rec if "static rotation" in str(w.message))
    )


# ------------------------------------------------------------ build once, solve many


def _assert_same_results(got, ref, rtol, path="result", seen=None):
    """Every public number of two result objects (dataclasses, mappings, sequences,
    arrays) agrees to ``rtol`` of the array's largest entry (``rtol=0``: equal);
    private attributes (caches) are not compared."""
    import dataclasses as dc

    import scipy.sparse as sp

    seen = set() if seen is None else seen
    if got is ref or (id(got), id(ref)) in seen:
        return
    seen.add((id(got), id(ref)))
    if (
        isinstance(ref, (np.ndarray, sp.sparray, sp.spmatrix))
        or np.isscalar(ref)
        and (isinstance(ref, (int, float, complex, np.number)) and not isinstance(ref, bool))
    ):
        a = np.asarray(got.toarray() if sp.issparse(got) else got)
        b = np.asarray(ref.toarray() if sp.issparse(ref) else ref)
        assert a.shape == b.shape, path
        if rtol == 0 or b.dtype.kind not in "fc":
            np.testing.assert_array_equal(a, b, err_msg=path)
        else:
            scale = float(np.max(np.abs(b), initial=0.0))
            np.testing.assert_allclose(a, b, rtol=rtol, atol=rtol * scale, err_msg=path)
    elif dc.is_dataclass(ref):
        assert type(got) is type(ref), path
        for f in dc.fields(ref):
            if not f.name.startswith("_"):
                _assert_same_results(
                    getattr(got, f.name), getattr(ref, f.name), rtol, f"{path}.{f.name}", seen
                )
    elif isinstance(ref, dict):
        assert list(got) == list(ref), path
        for k in ref:
            _assert_same_results(got[k], ref[k], rtol, f"{path}[{k!r}]", seen)
    elif isinstance(ref, (list, tuple)):
        assert len(got) == len(ref), path
        for i, (a, b) in enumerate(zip(got, ref)):
            _assert_same_results(a, b, rtol, f"{path}[{i}]", seen)
    elif hasattr(ref, "__dict__") and not callable(ref):
        for k, v in vars(ref).items():
            if not k.startswith("_"):
                _assert_same_results(getattr(got, k), v, rtol, f"{path}.{k}", seen)
    elif not callable(ref):
        assert got == ref, path


def _frequency_dependent(bodies, scale=0.3):
    """The bodies with their added mass tabulated over ω (A·(1 + scale·ω/5), held
    outside [0, 5] rad/s): coupled modes that depend on the sea's ω_ref."""
    from stochcable.bodies.rigid import FrequencyTable

    w = np.array([0.0, 2.5, 5.0])
    out = {}
    for n, b in bodies.items():
        a = np.asarray(b.added_mass, dtype=float)
        out[n] = dataclasses.replace(
            b,
            added_mass=FrequencyTable(
                w, np.stack([a * (1.0 + scale * x / 5.0) for x in w]), extrapolation="hold"
            ),
        )
    return out


@pytest.mark.parametrize(
    "name,table",
    [
        ("tuah_1982_disc_buoy_single_leg", False),
        # the three legs' group residuals at the stations: 5 s of CPU for five solves
        pytest.param("tuah_1982_disc_buoy_three_legs", False, marks=pytest.mark.slow),
        ("tuah_1982_disc_buoy_single_leg", True),
    ],
)
def test_one_model_solved_for_two_seas_equals_two_fresh_analyses(name, table):
    """build_coupled once, solve_coupled for two sea states (another spectrum; the
    examples' excitation tables have one heading): each result equals a fresh analyze_coupled of
    the scene with that sea (1e-12 of each array's largest entry: the same
    operations), and a second solve for the first sea is identical to the first (a
    solve changes nothing in the model).  With a constant added mass the model holds
    the coupled modes (their ω_ref set per sea); tabulated over ω (``table``), each
    solve computes them at its sea's spectral peak."""
    from stochcable.bodies.from_scene import scene_rigid_bodies
    from stochcable.dynamics.groups import build_coupled, solve_coupled
    from stochcable.examples import load_example

    scene = load_scene(load_example(name).model_dump(mode="json", exclude_none=True))
    statics = solve_statics(scene, method="fe")
    rigid = scene_rigid_bodies(scene)
    if table:
        rigid = _frequency_dependent(rigid)
    spec = scene.sea.spectrum.model_copy(update={"m0": 12.0, "omega_p": 0.8})
    seas = [scene.sea, scene.sea.model_copy(update={"spectrum": spec})]
    model = build_coupled(scene, statics, scene.analysis, rigid_bodies=rigid)
    assert all((g.modes is None) == table for g in model.groups)
    got = [solve_coupled(model, sea) for sea in seas]
    for sea, res in zip(seas, got):
        fresh = analyze_coupled(
            scene.model_copy(update={"sea": sea}), statics, scene.analysis, rigid_bodies=rigid
        )
        _assert_same_results(res, fresh, 1e-12)
    w_refs = [res.bodies["disc"].modes.omega_ref for res in got]
    assert w_refs[0] != w_refs[1]
    again = solve_coupled(model, scene)  # a Scene: its sea
    _assert_same_results(again, got[0], 0.0)
    assert got[1].lines[scene.lines[0].name].tension_std.max() != pytest.approx(
        got[0].lines[scene.lines[0].name].tension_std.max(), rel=1e-3
    )


def test_solve_coupled_needs_the_model_grid():
    """Settings on another grid than the model's are refused."""
    from stochcable.dynamics.groups import build_coupled, solve_coupled
    from stochcable.examples import load_example

    scene = load_scene(
        load_example("tuah_1982_disc_buoy_single_leg").model_dump(mode="json", exclude_none=True)
    )
    model = build_coupled(scene, solve_statics(scene, method="fe"), scene.analysis)
    other = scene.analysis.model_copy(
        update={"omega": scene.analysis.omega.model_copy(update={"count": 50})}
    )
    with pytest.raises(InputError, match="grid the model was built on"):
        solve_coupled(model, None, other)


# ------------------------------------------------ modal damping of the coupled modes


@pytest.mark.parametrize("method", ["full", "reduced"])
def test_coupled_mode_line_shares_complete_the_mass_normalization(mooring_direct, method):
    """The line parts of the mass-normalized coupled modes (``line_shapes``, on all
    nodes, attached ends moving with the body): Σ_l u_lᵀ(M + M_a)_l u_l +
    ξᵀ(M_B + A(ω_ref))ξ = 1 for every mode (round-off of the eigen-solve), under both
    the assembled and the reduced eigenproblem; the ends not on the body are at rest."""
    from stochcable.dynamics.groups.modes import line_mode_shares

    scene, cls, loads, body, _ = mooring_direct
    m = coupled_modes(cls, [body], 0.7, 2.0, method=method)
    shares = line_mode_shares(m, cls)
    xi = m.body_shapes["buoy"]
    mb = body.mass_matrix() + body.added_mass_at(np.array([0.7]))[0]
    total = sum(shares.values()) + np.einsum("jk,jk->k", xi, mb @ xi)
    np.testing.assert_allclose(total, 1.0, rtol=1e-9)
    for cl in cls:
        np.testing.assert_array_equal(m.line_shapes[cl.name][0], 0.0)  # anchor
        assert np.abs(m.line_shapes[cl.name][-1]).max() > 0  # fairlead


def test_coupled_bandwidths_tend_to_the_fixed_end_ones_under_a_heavy_body():
    """One leg on a body 10⁶ times heavier (its end all but held): the line-dominated
    coupled modes are the leg's fixed-end modes and their modal damping φᵀCφ
    (:func:`coupled_modal_bandwidths`) the fixed-end one of
    :func:`stochcable.dynamics.outputs.resolution.modal_bandwidths` (1e-4; measured ≤ 8e-6 with
    body energy fractions ≤ 1e-5 in those modes)."""
    from stochcable.dynamics.groups.modes import coupled_modal_bandwidths
    from stochcable.dynamics.linearization.variance import drag_coefficients
    from stochcable.dynamics.outputs.resolution import modal_bandwidths

    heavy = _buoy(
        mass=2.0e10,
        inertia=np.diag([5e10, 5e10, 8e10]),
        hydrostatic_stiffness=np.diag([1e9, 1e9, 1.26e11, 1e11, 1e11, 1e9]),
    )
    scene, cls, _ = _group(_mooring_doc(), heavy)
    cl = cls[0]
    damp = drag_coefficients(cl.system, np.full(2 * cl.system.model.n_elements, 0.3), "seed")
    m = coupled_modes([cl], [heavy], 0.7, 2.0, method="full")
    band = coupled_modal_bandwidths(m, [cl], [heavy], {cl.name: damp})
    fixed_w = np.asarray(cl.system.modes.omega)
    fixed_b = modal_bandwidths(cl.system, damp)
    checked = 0
    for k, w in enumerate(m.omega):
        j = int(np.argmin(np.abs(fixed_w - w)))
        if abs(fixed_w[j] - w) <= 1e-5 * w and m.body_fraction[k] < 1e-3:
            assert band[k] == pytest.approx(fixed_b[j], rel=1e-4)
            checked += 1
    assert checked >= 12
