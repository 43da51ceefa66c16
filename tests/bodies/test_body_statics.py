"""Tests of stochcable.bodies.statics: static equilibrium of bodies and their lines.

Checked against: the closed form of a buoy on a vertical elastic tether; central
finite differences of the statics for the reported stiffness; the independent
re-evaluation of the generalized force at the solution; the symmetry of a 120° spread;
the linear stiffness estimate of a small wind offset (with its quadratic error).
"""

from __future__ import annotations

import copy
import dataclasses
import json
import math

import numpy as np
import pytest
from _scenes import three_chain_legs
from scipy.spatial.transform import Rotation

from stochcable.bodies.from_scene import scene_rigid_bodies
from stochcable.bodies.statics import BodyStatics, body_static_load, solve_body_statics
from stochcable.errors import ConvergenceError, InputError
from stochcable.examples import load_example
from stochcable.line.fem import build_fe_model
from stochcable.line.mesh import mesh_line
from stochcable.line.statics import solve_line_statics
from stochcable.scene.model import load_scene
from stochcable.statics import solve_statics

RHO, G = 1025.0, 9.80665


def _tether_doc(planar: bool = True, **body) -> dict:
    """Submerged buoy (∇ = 3 m³, 1000 kg) on a vertical 79 m tether from z = -100 m."""
    b = {
        "name": "buoy",
        "position": [0.0, 0.0, -19.9],
        "mass": 1000.0,
        "displaced_volume": 3.0,
        "cog": [0.0, 0.0, -0.5],
        **body,
    }
    return {
        "environment": {"depth": 100.0, "rho": RHO, "g": G},
        "bodies": [b],
        "lines": [
            {
                "name": "tether",
                "end_a": {"position": [0.0, 0.0, -100.0]},
                "end_b": {"attach": {"body": "buoy", "point": [0.0, 0.0, -1.0]}},
                "segments": [
                    {"length": 79.0, "ea": 1.0e7, "mass": 5.0, "diameter": 0.05, "elements": 10}
                ],
            }
        ],
    }


def test_vertical_tether_closed_form():
    """Tension = ρ g ∇ − m g; the stretch of a vertical bar with linearly varying
    tension: ΔL = (T_top L − w L²/2)/EA (the lumped FE is exact for linear T)."""
    scene = load_scene(_tether_doc())
    st = solve_statics(scene)
    b = st.bodies["buoy"]
    t_top = RHO * G * 3.0 - 1000.0 * G
    w = (5.0 - RHO * math.pi * 0.05**2 / 4) * G
    L, ea = 79.0, 1.0e7
    z_attach = -100.0 + L + (t_top * L - w * L**2 / 2) / ea
    # line statics to 1e-10 of the reference force and body Newton to 1e-8
    np.testing.assert_allclose(
        b.line_forces["tether"], [0.0, 0.0, -t_top], rtol=1e-8, atol=1e-8 * t_top
    )
    np.testing.assert_allclose(b.position, [0.0, 0.0, z_attach + 1.0], atol=1e-8)
    np.testing.assert_allclose(b.rotation, 0.0, atol=1e-12)
    assert st.lines["tether"].tension_b == pytest.approx(t_top, rel=1e-8)
    np.testing.assert_allclose(st.lines["tether"].positions[-1], [0.0, 0.0, z_attach], atol=1e-8)
    # pitch stiffness: weight below the reference (m g 0.5) plus the tension acting
    # 1 m below it (T·1, the geometric term) plus the tether's lateral stiffness × arm²
    k = b.stiffness
    assert b.dofs == ("surge", "heave", "pitch")
    assert k[2, 2] == pytest.approx(1000.0 * G * 0.5 + t_top * 1.0 + k[0, 0], rel=1e-6)
    doc = st.to_document()
    assert doc["bodies"]["buoy"]["position"][2] == pytest.approx(z_attach + 1.0)


def test_vertical_tether_3d_yaw_undetermined_then_fixed():
    """In 3-D a buoy on one line at its axis has no yaw restoring: InputError naming
    the DOF; with fixed_dofs=["yaw"] the closed form holds as in 2-D."""
    doc = _tether_doc()
    doc["lines"][0]["end_b"]["attach"]["point"] = [0.0, 0.0, -1.0]
    doc["bodies"][0]["wind_force"] = [0.0, 0.0, 0.0]
    doc["environment"]["current"] = [{"z": 0.0, "speed": 0.0, "heading": 45.0}]
    doc["bodies"][0]["cog"] = [0.0, 1e-3, -0.5]  # leaves the x–z plane: 6 DOF
    scene = load_scene(doc)
    assert not scene.is_planar
    with pytest.raises(
        InputError,
        match=r"bodies\[buoy\]\.yaw .*no restoring force.*"
        r"fixed_dofs",
    ):
        solve_statics(scene)
    doc["bodies"][0]["fixed_dofs"] = ["yaw"]
    st = solve_statics(load_scene(doc))
    t_top = RHO * G * 3.0 - 1000.0 * G
    assert st.bodies["buoy"].stiffness.shape == (6, 6)
    assert st.lines["tether"].tension_b == pytest.approx(t_top, rel=1e-8)


# ------------------------------------------------------- stiffness vs differences


def _generalized_force(scene, name, pose6, tol=1e-11):
    """Q(q) from independent pieces: every attached line re-solved (FE) with its end
    at X + R(θ) r, plus body_static_load."""
    env = scene.environment
    rb = scene_rigid_bodies(scene)[name]
    poses = {name: (pose6[:3], pose6[3:])}
    q, _ = body_static_load(scene, name, pose6, rb)
    q = q.copy()
    for ln in scene.lines:
        for end in ("end_a", "end_b"):
            a = getattr(ln, end).attach
            if a is None or a.body != name:
                continue
            mesh = mesh_line(scene.resolved_line(ln, poses), env.rho, env.g)
            ls = solve_line_statics(mesh, env, method="fe", tolerance=tol)
            f = ls.force_a if end == "end_a" else ls.force_b
            arm = Rotation.from_rotvec(pose6[3:]).apply(np.asarray(a.point, float))
            q[:3] += f
            q[3:] += np.cross(arm, f)
    return q


@pytest.mark.parametrize(
    "example", ["tuah_1982_disc_buoy_single_leg", "tuah_1982_disc_buoy_three_legs"]
)
def test_stiffness_matches_finite_differences(example):
    """BodyStatics.stiffness = −dQ/dq by central differences of the statics.

    The stiffness is in small global rotations about the static pose; central
    differences in the rotation vector agree with it exactly in 2-D and, in 3-D, to
    O(|θ₀|) (here θ₀ = 0: the three-leg spread without wind)."""
    scene = load_example(example) if "single" in example else _spread()
    st = solve_statics(scene, method="fe", tolerance=1e-11)
    b = st.bodies["disc"]
    idx = [0, 2, 4] if scene.is_planar else list(range(6))
    q0 = np.concatenate([b.position, b.rotation])
    h = np.array([1e-3, 1e-3, 1e-3, 1e-5, 1e-5, 1e-5])
    kfd = np.zeros((6, 6))
    for j in idx:
        e = np.zeros(6)
        e[j] = h[j]
        kfd[:, j] = -(
            _generalized_force(scene, "disc", q0 + e) - _generalized_force(scene, "disc", q0 - e)
        ) / (2 * h[j])
    kfd = kfd[np.ix_(idx, idx)]
    # entries compared on the scale sqrt(K_ii K_jj) (surge ~0.5 lbf/ft next to heave
    # ~5000 lbf/ft): statics noise 1e-11·F/h ~ 2e-6 lbf/ft, truncation (h/300 ft)²
    # ~ 1e-11; the attachment geometric terms are ~2 % of the pitch entry
    dg = np.sqrt(np.abs(np.diag(kfd)))
    err = np.abs(b.stiffness - kfd) / np.outer(dg, dg)
    assert err.max() < 1e-4, err


def test_equilibrium_residual_independent():
    """Q at the reported pose, re-evaluated from independent line solves, is zero to
    the solver tolerance (relative to the 100 lb wind and the line tensions)."""
    scene = load_example("tuah_1982_disc_buoy_three_legs")
    st = solve_statics(scene, method="fe", tolerance=1e-11)
    b = st.bodies["disc"]
    q = _generalized_force(scene, "disc", np.concatenate([b.position, b.rotation]))
    fref = max(st.lines[n].tension_b for n in st.lines)
    # body tolerance 1e-8 on forces / fref and moments / (fref · 5.6 ft)
    assert np.abs(q[:3]).max() < 1e-8 * fref
    assert np.abs(q[3:]).max() < 1e-8 * fref * 5.6
    assert b.residual < 1e-8
    # the lines in the result are those at the pose (force on the body at the rim)
    for name, f in b.line_forces.items():
        np.testing.assert_allclose(f, st.lines[name].force_b, rtol=0, atol=0)


# ---------------------------------------------------------------- 3-leg spread


def _spread(wind=(0.0, 0.0, 0.0)):
    doc = load_example("tuah_1982_disc_buoy_three_legs").model_dump(mode="json", exclude_none=True)
    doc["bodies"][0]["wind_force"] = list(wind)
    return load_scene(doc)


def test_three_leg_symmetric_spread():
    """Without wind the 120° spread holds the disc at zero horizontal offset and zero
    roll/pitch/yaw with three equal tensions."""
    st = solve_statics(_spread())
    b = st.bodies["disc"]
    tens = [st.lines[n].tension_b for n in ("leg1", "leg2", "leg3")]
    # Newton to 1e-8 of ~200 lbf over stiffnesses ~1 lbf/ft: offsets below 1e-6 ft
    np.testing.assert_allclose(b.position[:2], 0.0, atol=1e-6)
    np.testing.assert_allclose(b.rotation, 0.0, atol=1e-8)
    np.testing.assert_allclose(tens, tens[0], rtol=1e-8)
    # the stiffness is isotropic in the horizontal plane (3-fold symmetry)
    k = b.stiffness
    assert k[0, 0] == pytest.approx(k[1, 1], rel=1e-6)
    assert abs(k[0, 1]) < 1e-6 * k[0, 0]


@pytest.mark.parametrize("direction", [0.0, 75.0])
def test_three_leg_small_wind_offset_matches_linear_stiffness(direction):
    """Offset under a small wind F: Δq ≈ K⁻¹ F with K the stiffness at zero wind; the
    error is quadratic in F (halving F quarters the absolute error, within 30 %)."""
    k = solve_statics(_spread()).bodies["disc"].stiffness
    q0 = solve_statics(_spread()).bodies["disc"]
    c, s = math.cos(math.radians(direction)), math.sin(math.radians(direction))
    errs = []
    for f in (2.0, 1.0):
        fvec = np.array([f * c, f * s, 0.0])
        b = solve_statics(_spread(fvec)).bodies["disc"]
        dq = np.concatenate([b.position - q0.position, b.rotation - q0.rotation])
        lin = np.linalg.solve(k, np.concatenate([fvec, np.zeros(3)]))
        # a few lbf against ~200 lbf tensions: the linear estimate within 1 %
        np.testing.assert_allclose(dq[:2], lin[:2], rtol=1e-2, atol=1e-2 * np.abs(lin).max())
        errs.append(np.abs(dq - lin).max())
    assert 0.25 * 0.7 < errs[1] / errs[0] < 0.25 * 1.3


# ----------------------------------------------------------- prescribed and errors


def test_prescribed_body_holds_its_lines():
    """A vessel (prescribed) body: its lines end at position + point, not solved."""
    doc = _tether_doc()
    doc["bodies"][0]["prescribed"] = {
        "omega": [0.1, 2.0],
        "heave": {"re": [1.0, 1.0], "im": [0.0, 0.0]},
    }
    doc["bodies"][0]["position"] = [0.0, 0.0, -19.5]
    st = solve_statics(load_scene(doc))
    b = st.bodies["buoy"]
    assert b.prescribed and b.iterations == 0
    np.testing.assert_array_equal(b.position, [0.0, 0.0, -19.5])
    np.testing.assert_allclose(st.lines["tether"].positions[-1], [0.0, 0.0, -20.5])
    np.testing.assert_allclose(b.line_forces["tether"], st.lines["tether"].force_b)


def test_statics_without_bodies_has_no_bodies_entry():
    st = solve_statics(load_example("taut_wire"))
    assert st.bodies == {} and "bodies" not in st.to_document()


def test_scene_errors_messages():
    doc = _tether_doc()
    bad = copy.deepcopy(doc)
    bad["lines"][0]["end_b"]["attach"]["body"] = "nope"
    with pytest.raises(
        InputError,
        match=r"lines\[0\]\.end_b\.attach\.body = 'nope': no "
        r"body of that name; bodies: \['buoy'\]",
    ):
        load_scene(bad)
    bad = copy.deepcopy(doc)
    bad["lines"][0]["end_b"]["position"] = [0.0, 0.0, -21.0]
    with pytest.raises(
        InputError,
        match=r"lines\[0\]\.end_b: give position or attach, "
        r"not both",
    ):
        load_scene(bad)
    bad = copy.deepcopy(doc)
    bad["bodies"][0]["hydrodynamics"] = {"file": "disc.nc"}
    with pytest.raises(
        InputError,
        match=r"bodies\[0\]\.hydrodynamics\.file = 'disc\.nc': "
        r"files are not accepted here",
    ):
        load_scene(bad, allow_files=False)
    # non-planar body (y ≠ 0) with planar (3×3) data
    bad = copy.deepcopy(doc)
    bad["bodies"][0]["position"] = [0.0, 2.0, -19.9]
    bad["bodies"][0]["extra_stiffness"] = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
    with pytest.raises(
        InputError,
        match=r"bodies\[0\] \('buoy'\) has 3×3 \(surge, heave, "
        r"pitch\) data but the scene is not planar",
    ):
        load_scene(bad)


def test_undetermined_pose_names_the_dof():
    """A body whose only line is slack-free but gives no pitch restoring: CoG, CoB and
    the attachment at the reference point, no hydrostatics → pitch undetermined."""
    doc = _tether_doc(cog=[0.0, 0.0, 0.0])
    doc["lines"][0]["end_b"]["attach"]["point"] = [0.0, 0.0, 0.0]
    doc["bodies"][0]["position"] = [0.0, 0.0, -20.9]
    with pytest.raises(
        InputError,
        match=r"bodies\[buoy\]\.pitch = .*has no restoring "
        r"force.*fixed_dofs",
    ):
        solve_statics(load_scene(doc))
    doc["bodies"][0]["fixed_dofs"] = ["pitch"]
    b = solve_statics(load_scene(doc)).bodies["buoy"]
    assert b.rotation[1] == 0.0


def test_hydrodynamics_file_relative_to_scene(tmp_path):
    """A relative hydrodynamics file is resolved against the scene file's folder."""
    scene = load_example("tuah_1982_disc_buoy_single_leg")
    doc = scene.model_dump(mode="json", exclude_none=True)
    table = doc["bodies"][0].pop("hydrodynamics")
    (tmp_path / "sub").mkdir()
    (tmp_path / "sub" / "disc.json").write_text(json.dumps(table))
    doc["bodies"][0]["hydrodynamics"] = {"file": "sub/disc.json"}
    (tmp_path / "scene.json").write_text(json.dumps(doc))
    loaded = load_scene(tmp_path / "scene.json")
    assert loaded.uses_files
    assert loaded.bodies[0].hydrodynamics.file == str(tmp_path / "sub" / "disc.json")
    a = scene_rigid_bodies(loaded)["disc"]
    b = scene_rigid_bodies(scene)["disc"]
    np.testing.assert_array_equal(a.excitation.values, b.excitation.values)
    with pytest.raises(
        InputError,
        match=r"bodies\[0\]\.hydrodynamics\.file = "
        r"'sub/disc\.json': file not found",
    ):
        load_scene(json.dumps(doc))  # relative to the working folder: not there


def test_body_statics_document():
    st = solve_statics(load_example("tuah_1982_disc_buoy_single_leg"))
    d = st.to_document()["bodies"]["disc"]
    assert set(d) == {
        "position",
        "rotation",
        "line_forces",
        "iterations",
        "residual",
        "dofs",
        "stiffness",
        "prescribed",
    }
    assert d["dofs"] == ["surge", "heave", "pitch"] and len(d["stiffness"]) == 3
    assert isinstance(st.bodies["disc"], BodyStatics)
    # the 100 lb wind is carried by the line's horizontal pull (body residual 1e-8 of
    # the ~12 000 lbf weight: 1.2e-4 lbf)
    assert st.bodies["disc"].line_forces["leg"][0] == pytest.approx(-100.0, abs=2e-4)
    lines, bodies = solve_body_statics(load_example("tuah_1982_disc_buoy_single_leg"))
    assert list(lines) == ["leg"] and list(bodies) == ["disc"]


def test_slack_start_and_unheld_body_errors():
    """A tether slack at the initial position: the statics start again from the
    straight-bar model's pose (stochcable.bodies.start) and find the equilibrium of a
    start near it; a one-leg buoy without wind (line slack on the frictionless bed,
    no horizontal restoring): ConvergenceError with the residual."""
    near = solve_statics(load_scene(_tether_doc())).bodies["buoy"].position
    doc = _tether_doc()
    doc["bodies"][0]["position"] = [0.0, 0.0, -20.5]
    slack = solve_statics(load_scene(doc)).bodies["buoy"].position
    # both converged to the body tolerance 1e-8 of the ~20 kN loads: ~1e-9 m here
    np.testing.assert_allclose(slack, near, rtol=0, atol=1e-7)
    from stochcable.errors import ConvergenceError

    d = load_example("tuah_1982_disc_buoy_single_leg").model_dump(mode="json", exclude_none=True)
    d["bodies"][0]["wind_force"] = [0.0, 0.0, 0.0]
    with pytest.raises(
        ConvergenceError,
        match=r"body statics Newton did not converge: "
        r"residual .*undetermined position",
    ):
        solve_statics(load_scene(d))


# ------------------------------------------------- Newton and the condensed tangent


def _buoy_spread_doc(n_el: int = 40, position=(10.0, 5.0, 0.0)) -> dict:
    """The benchmark scene of benchmarks/bench_bodies.py: a 2e4 kg buoy (K_h heave
    1.26e5 N/m) on three 330 m chain legs at 0/120/240°, anchors 300 m out on the
    seabed at 100 m depth, started off its equilibrium."""
    lines = three_chain_legs(n_el, attach="buoy")
    kh = [[0.0] * 6 for _ in range(6)]
    for i, v in enumerate([0.0, 0.0, 1.26e5, 1e5, 1e5, 0.0]):
        kh[i][i] = v
    body = {
        "name": "buoy",
        "position": list(position),
        "mass": 2.0e4,
        "inertia": [[5e4, 0, 0], [0, 5e4, 0], [0, 0, 8e4]],
        "hydrostatic_stiffness": kh,
    }
    return {"environment": {"depth": 100.0}, "bodies": [body], "lines": lines}


def test_body_newton_converges_quadratically():
    """The Jacobian (condensed FE end stiffness + attachment geometric terms + K_h) is
    the exact derivative of the generalized force, so the residual sequence of Newton
    satisfies r_{k+1} <= C r_k² (measured C ≈ 1.5 here; an inexact Jacobian converges
    linearly, r_{k+1} ≈ ρ r_k, and fails the bound once r_k < ρ/C)."""
    scene = load_scene(_buoy_spread_doc())
    res = []
    for k in range(1, 7):
        try:
            solve_body_statics(scene, "fe", max_body_iterations=k, body_tolerance=1e-14)
        except ConvergenceError as exc:
            res.append(exc.residual)
        else:
            break
    # pairs above the round-off floor of the line statics (tolerance 1e-10 of the line
    # reference force, ~1e-11 relative to the body reference force)
    pairs = [(a, b) for a, b in zip(res, res[1:]) if b > 1e-10]
    assert len(pairs) >= 3, res
    for a, b in pairs:
        # C ≈ 1.5 measured; 10 leaves room for platform round-off
        assert b <= 10.0 * a * a, res
    assert res[-1] < 1e-10


def _dense_end_stiffness(ls, env, ends, planar):
    """K_bb − K_bf K_ff⁻¹ K_fb of build_fe_model's sparse K, dense (second method).

    The statics tangent has the bed at the grounded nodes: without the dynamic
    model's split of the touchdown element (stochcable.line.seabed)."""
    model = build_fe_model(dataclasses.replace(ls, touchdown=None), env, dim=2 if planar else 3)
    k = model.K.toarray()
    c = model.dim
    n = ls.mesh.n_nodes
    b = np.concatenate([np.arange(c) + (0 if e == "end_a" else (n - 1) * c) for e in ends])
    f = np.arange(c, (n - 1) * c)
    return k[np.ix_(b, b)] - k[np.ix_(b, f)] @ np.linalg.solve(k[np.ix_(f, f)], k[np.ix_(f, b)])


@pytest.mark.parametrize("planar", [False, True])
@pytest.mark.parametrize("ends", [["end_b"], ["end_a", "end_b"]])
def test_end_condensation_matches_dense_schur(planar, ends):
    """The banded condensation of the line tangent equals the dense Schur complement
    of stochcable.line.fem's assembled K (grounded nodes and seabed springs included), and
    its interior map predicts the re-solved shape to second order in the end motion."""
    from stochcable.bodies.mooring import end_condensation

    # buoy at its symmetric pose: leg1 in the x–z plane (planar model), leg2 at 120°
    # (3-D); the end motions below keep the seabed contact set (a node lifting off is
    # a kink of the one-sided contact, where the predictor is only first order)
    scene = load_scene(_buoy_spread_doc(n_el=20, position=(0.0, 0.0, 0.0)))
    env = scene.environment
    ln = scene.lines[0 if planar else 1]
    mesh = mesh_line(scene.resolved_line(ln), env.rho, env.g)
    ls = solve_line_statics(mesh, env, method="fe", tolerance=1e-12)
    assert ls.grounded.sum() >= 3  # the seabed springs enter the condensation
    ke, smap = end_condensation(scene, ln, ls, ends, planar, "fe", 1e-10)
    ref = _dense_end_stiffness(ls, env, ends, planar)
    # two factorizations of the same ~1e7 N/m matrix: round-off level
    np.testing.assert_allclose(ke, ref, rtol=0, atol=1e-9 * np.abs(ref).max())
    comps = [0, 2] if planar else [0, 1, 2]
    c = len(comps)
    direction = np.array([0.6, 0.0 if planar else -0.3, 0.74])
    errs = []
    for h in (0.4, 0.2):
        dx = h * direction
        moved = {e: getattr(mesh, e) + (dx if e in ends else 0.0) for e in ("end_a", "end_b")}
        mesh2 = dataclasses.replace(mesh, **moved)
        ls2 = solve_line_statics(mesh2, env, method="fe", tolerance=1e-12)
        dxb = np.concatenate([dx[comps] for _ in ends])
        pred = ls.positions[1:-1, comps] - (smap @ dxb).reshape(-1, c)
        errs.append(np.abs(pred - ls2.positions[1:-1, comps]).max())
    # first-order predictor: the error quarters when the end motion halves (±30 %)
    assert 0.25 * 0.7 < errs[1] / errs[0] < 0.25 * 1.3, errs


def test_cross3_is_numpy_cross_to_the_bit():
    """The body Newton's moment arm × force (_cross3, issue 6 pass E6) is np.cross's
    products and differences: the same bits, signed zeros included."""
    from stochcable.bodies.statics import _cross3

    rng = np.random.default_rng(17)
    for _ in range(200):
        a, b = rng.standard_normal(3) * 10.0 ** rng.uniform(-3, 3), rng.standard_normal(3)
        a[rng.integers(3)] = 0.0
        got, want = _cross3(a, b), np.cross(a, b)
        assert np.array_equal(got, want)
        assert np.array_equal(np.signbit(got), np.signbit(want))


def test_reported_stiffness_is_the_public_mooring_stiffness_at_the_pose():
    """The statics' memoized end positions (issue 6 pass E6) are those of
    Scene.end_position: the reported body stiffness at a rotated, offset pose is the
    body's own stiffness plus mooring_stiffness (which asks the scene) to the bit."""
    from stochcable.bodies.mooring import mooring_stiffness

    scene = _spread(wind=(40.0, 25.0, 0.0))
    st = solve_statics(scene, method="fe")
    b = st.bodies["disc"]
    assert np.abs(b.rotation).max() > 0.0 and np.abs(b.position[:2]).max() > 1e-3
    pose = np.concatenate([b.position, b.rotation])
    rigid = scene_rigid_bodies(scene)["disc"]
    _, own = body_static_load(scene, "disc", pose, rigid)
    k = np.zeros((6, 6))
    k += own
    k += np.asarray(rigid.extra_stiffness, float)
    k += mooring_stiffness(scene, st.lines, {"disc": pose}, ["disc"], False, "fe")
    np.testing.assert_array_equal(b.stiffness, k)
