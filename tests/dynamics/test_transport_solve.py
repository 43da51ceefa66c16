"""The frequency-domain response of a travelling line (stochcable.dynamics.model.transport).

The engine's direct solve with the transport terms (G in the band, K_c in K, the end
motion's gyroscopic load and reaction rows) against an independent second method: the
complex-modal receptance with left eigenvectors (stochcable.line.transport.modes) and
the full sparse impedance.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from stochcable.dynamics.loads.channels import Channel
from stochcable.dynamics.model.system import Damping, build_line_system
from stochcable.dynamics.solve.line_solve import solve
from stochcable.line.fem import build_fe_model
from stochcable.line.transport.matrices import transport_matrices
from stochcable.line.transport.modes import complex_modes, receptance_modal
from stochcable.scene.model import load_scene
from stochcable.statics import solve_statics

SAGGED = {
    "environment": {"depth": 200.0, "rho": 1025.0},
    "lines": [
        {
            "name": "cable",
            "end_a": {"position": [0.0, 0.0, -150.0]},
            "end_b": {"position": [150.0, 0.0, -20.0]},
            "segments": [
                {"length": 220.0, "ea": 2.0e8, "mass": 20.0, "diameter": 0.06,
                 "weight": 150.0, "cd_axial": 0.02, "elements": 16}
            ],
            "axial_speed": 3.0,
        }
    ],
}  # fmt: skip


def _system(speed: float, dim: int = 2):
    doc = json.loads(json.dumps(SAGGED))
    doc["lines"][0]["axial_speed"] = speed
    scene = load_scene(doc)
    statics = solve_statics(scene, method="fe")
    line = scene.lines[0]
    return scene, build_line_system(scene, line, statics.lines[line.name], dim=dim)


def _damping(system, rng) -> Damping:
    n_el = system.model.l0.size
    return Damping(
        method="seed",
        sigma=np.zeros(2 * n_el),
        b_normal=rng.uniform(20.0, 60.0, n_el),
        b_axial=rng.uniform(1.0, 5.0, n_el),
        b_node=np.zeros(system.model.n_nodes),
        model=system.model,
    )


@pytest.mark.parametrize("speed", [3.0, -5.0])
def test_direct_solve_equals_complex_modal_receptance(speed):
    """A unit heave and surge of end_b in still water: the engine's free-node response
    and support forces equal −H(ω) Z_fe u_b with H the complex-modal receptance (left
    eigenvectors) and Z the full sparse impedance, to 1e-9 (round-off of the QZ)."""
    from stochcable.errors import PhysicsWarning

    with pytest.warns(PhysicsWarning, match="modes at rest"):
        scene, system = _system(speed)
    assert system.solver == "direct" and system.gyro is not None
    rng = np.random.default_rng(34)
    damping = _damping(system, rng)
    w = np.array([0.05, 0.4, 1.3, 3.0])
    unit = np.zeros((w.size, 3), complex)
    chans = []
    for k, name in ((2, "end_b.heave"), (0, "end_b.surge")):
        mb = unit.copy()
        mb[:, k] = 1.0
        chans.append(Channel(name=name, kind="end_motion", omega=w, spectrum=np.ones_like(w),
                             density=lambda x: np.ones_like(x), motion_b=mb))  # fmt: skip
    resp = solve(system, tuple(chans), damping)

    # the second method, from the line's model at rest (complex_modes adds G, K_c)
    rest = build_fe_model(system.statics, scene.environment, dim=2)
    tr = transport_matrices(rest, speed)
    np.testing.assert_array_equal(system.model.K.toarray(), tr.K.toarray())
    K = tr.K.toarray()
    M = (rest.M + rest.Ma).toarray()
    C = damping.matrix.toarray() + rest.Cs.toarray()
    G = tr.G.toarray()
    fr, fx = rest.free, rest.fixed
    modes = complex_modes(rest, speed, added_mass=True, damping=C[np.ix_(fr, fr)])
    H = receptance_modal(modes, w, fr)
    d = rest.dim
    for j, k in enumerate((2, 0)):
        ub = np.zeros(rest.K.shape[0])
        ub[fx[d:]] = np.eye(3)[k][list(rest.components)]  # end_b's DOFs
        U = np.zeros((w.size, ub.size), complex)
        for i, x in enumerate(w):
            Z = K - x * x * M + 1j * x * (C + G)
            U[i, fr] = -H[i] @ (Z[np.ix_(fr, fx)] @ ub[fx])
            U[i, fx] = ub[fx]
            reac = -(Z @ U[i])[fx]
            # the reaction is a difference of terms of size |Z_end| |U|: its round-off
            # is 1e-9 of that (EA/l ≈ 1.5e7 N/m against reactions of 1e2 N)
            scale = np.abs(Z[fx]).max() * np.abs(U[i]).max()
            np.testing.assert_allclose(resp.support_force[i, :, j], reac, rtol=0,
                                       atol=1e-9 * scale)  # fmt: skip
        got = resp.displacement[:, :, j]
        np.testing.assert_allclose(got, U, rtol=0, atol=1e-9 * np.abs(U).max())


@pytest.mark.slow  # two analyses and a 300 s time-domain simulation: ≈ 5 s
def test_laying_example_frequency_domain_equals_time_domain_with_transport():
    """The bundled laying example in its linear limit (Hs 0.2 m; strakes: the TD has
    no vortex shedding), 300 s: the analysis' synthesized end tensions against the
    nonlinear time-domain reference with transport on the same realization.  The
    allowance is the drag nonlinearity σ_vr/U_n (σ of the relative normal velocity
    against the 0.5 m/s cross-current, ≈ 7 %) plus the Newmark period error, as in
    tests/reference/test_cable_timedomain.py's linear-limit tests (measured: 2.8 % and 2.0 %).
    The transport is resolved: the time domain with transport is further than that from
    the frequency domain at rest (end_b: 11 %)."""
    from stochcable.analysis import analyze
    from stochcable.examples import load_example
    from stochcable.reference.cable import newmark_period_error, simulate_line_timedomain

    doc = load_example("cable_laying").model_dump(mode="json")
    doc["sea"]["spectrum"]["hs"] = 0.2
    doc["analysis"]["timeseries"]["duration"] = 300.0
    doc["lines"][0]["segments"][0]["strumming"] = {"suppression": "strakes"}
    assert doc["lines"][0]["axial_speed"] == -1.0
    with pytest.warns(Warning):  # the modes at rest of a travelling line
        res = analyze(doc)
    lr = res.lines["cable"]
    at_rest = json.loads(json.dumps(doc))
    at_rest["lines"][0]["axial_speed"] = 0.0
    ts0 = analyze(at_rest).timeseries
    hist = simulate_line_timedomain(doc, band=(0.2, 2.5))
    u_n = 0.5  # the cross-current, normal to the whole line [m/s]
    tol = float(np.max(lr.linearization.sigma_normal)) / u_n
    tol += newmark_period_error(hist._meta["omega_max"], hist.dt)
    assert tol < 0.08
    ts = res.timeseries
    k = round(0.25 / hist.dt)
    sel = ts.time >= hist.ramp
    for end in ("a", "b"):
        fd = np.asarray(ts.end_tension["cable"][f"end_{end}"])[sel]
        td = (hist.tension_a if end == "a" else hist.tension_b)[::k][: ts.time.size][sel]
        a, b = td - td.mean(), fd - fd.mean()
        assert (a - b).std() <= tol * b.std()
        assert a.std() == pytest.approx(getattr(lr, f"end_{end}").std, rel=tol)
    fd0 = np.asarray(ts0.end_tension["cable"]["end_b"])[sel]
    assert (a - (fd0 - fd0.mean())).std() > tol * b.std()


def test_end_influence_of_a_travelling_line_by_the_adjoint():
    """The residuals' end influence (end tension per unit node force, by the adjoint:
    Aᵀ with C − G) equals the forward solve with the full impedance, to 1e-9."""
    from stochcable.dynamics.residuals.residual_lines import end_influence
    from stochcable.dynamics.solve.line_solve import end_tension_from_support

    with pytest.warns(Warning):
        scene, system = _system(-5.0)
    damping = _damping(system, np.random.default_rng(7))
    w = np.array([0.3, 1.7])
    got = end_influence(system, damping, w)  # (2, n_nodes, d, n_w)
    rest = build_fe_model(system.statics, scene.environment, dim=2)
    tr = transport_matrices(rest, -5.0)
    K, M = tr.K.toarray(), (rest.M + rest.Ma).toarray()
    C = damping.matrix.toarray() + rest.Cs.toarray() + tr.G.toarray()
    fr, fx, d = rest.free, rest.fixed, rest.dim
    e_hat = end_tension_from_support(system, np.eye(2 * d)[None].astype(complex))
    for i, x in enumerate(w):
        Z = K - x * x * M + 1j * x * C
        for dof in fr[[0, 5, -1]]:
            f = np.zeros(K.shape[0])
            f[dof] = 1.0
            u = np.zeros(K.shape[0], complex)
            u[fr] = np.linalg.solve(Z[np.ix_(fr, fr)], f[fr])
            support = -(Z @ u - f)[fx]
            for k, end in enumerate(("end_a", "end_b")):
                t = np.real(e_hat[end][:, 0]) @ support
                g = got[k, dof // d, dof % d, i]
                assert abs(g - t) <= 1e-9 * max(abs(t), 1e-12), (end, dof, g, t)


# -------------------------------------------------------------- a travelling line on a body


def _leg_doc(speed: float, motion=None) -> dict:
    """A 215 m leg from the seabed to a point 5 m deep, travelling at ``speed``."""
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
                    {"length": 215.0, "ea": 1e9, "mass": 80.0, "diameter": 0.09,
                     "cd_axial": 0.02, "elements": 12}
                ],
                "axial_speed": speed,
            }
        ],
        "analysis": {
            "omega": {"min": 0.2, "max": 2.5, "count": 50},
            "solver": "direct",
            "linearization": {"tolerance": 1e-11, "max_iterations": 200,
                              "drag_residual": False, "geometric_residual": False},
        },
    }  # fmt: skip


@pytest.mark.filterwarnings("ignore::stochcable.errors.ResolutionWarning")
@pytest.mark.filterwarnings("ignore::stochcable.errors.PhysicsWarning")
@pytest.mark.parametrize("speed", [2.0, -3.0])
def test_travelling_line_on_a_body_equals_the_line_with_that_end_motion(speed):
    """A planar body of mass 1e15 kg driven by F = −ω²M ξ moves with ξ; the travelling
    line on it, solved in the coupled group (its unit end motions, the gyroscopic end
    load and reaction rows), equals the independent analysis of the travelling line
    whose end moves with T(r)ξ (the free line's direct solve, checked above against
    the complex-modal receptance), to 1e-6 (both fixed points converged to 1e-11, the
    body lags ξ by 1e-7 relative; measured 2e-11); the travel changes the end_b σ by
    1–5 %, so the transport is resolved."""
    from stochcable.bodies.rigid import ExcitationTable, RigidBody
    from stochcable.dynamics.groups import (
        CoupledLine,
        body_loads,
        coupled_results,
        linearize_coupled,
    )
    from stochcable.dynamics.groups.line_fixed_point import linearize
    from stochcable.dynamics.loads.channels import line_channels
    from stochcable.dynamics.outputs.line_result import line_result

    def analysed(doc_speed, motion=None):
        scene = load_scene(_leg_doc(doc_speed, motion))
        statics = solve_statics(scene, method="fe")
        line = scene.lines[0]
        s = build_line_system(scene, line, statics.lines["leg"])
        return scene, s, line_channels(scene, line, s.positions, scene.analysis.omega.values())

    scene, s, ch = analysed(speed)
    assert s.gyro is not None
    w = scene.analysis.omega.values()
    xi = np.stack([0.6 * np.exp(0.7j * w), 0.9 + 0.1j * w, 0.02j * np.ones_like(w)])
    big, pos = 1e15, np.array([0.0, 0.0, -4.0])  # fairlead r = (0, 0, -1)
    body = RigidBody(
        "heavy",
        pos,
        big,
        inertia=np.diag([big, big, big]),
        planar=True,
        excitation=ExcitationTable(w, [0.0], (-(w**2)[None, :] * (big * xi))[None]),
        excitation_point=[-pos[0], -pos[1]],
    )
    cl = CoupledLine(s, ch, end_b="heavy")
    loads = {"heavy": body_loads(body, ch, w, scene.sea, scene.environment)}
    lin = linearize_coupled([cl], [body], scene.analysis, rho=1025.0, loads=loads)
    np.testing.assert_allclose(lin.body_motion["heavy"][:, :, 0], xi.T, rtol=1e-7)
    got = coupled_results([cl], [body], lin, scene.analysis)[0]["leg"]
    u = xi[0] + (-1.0) * xi[2], xi[1]  # T(r) ξ, r = (0, 0, -1)
    rao = {
        "omega": w.tolist(),
        "surge": {"re": u[0].real.tolist(), "im": u[0].imag.tolist()},
        "heave": {"re": u[1].real.tolist(), "im": u[1].imag.tolist()},
    }
    ref_scene, rs, rch = analysed(speed, rao)
    ref = line_result(rs, rch, linearize(rs, rch, ref_scene.analysis), ref_scene.analysis)
    for end in ("end_a", "end_b"):
        assert getattr(got, end).std == pytest.approx(getattr(ref, end).std, rel=1e-6)
    np.testing.assert_allclose(got.tension_std, ref.tension_std, rtol=1e-6)
    np.testing.assert_allclose(got.motion_transfer, ref.motion_transfer, rtol=1e-6, atol=1e-9)
    rest_scene, rest, rest_ch = analysed(0.0, rao)
    at_rest = line_result(
        rest, rest_ch, linearize(rest, rest_ch, rest_scene.analysis), rest_scene.analysis
    )
    assert abs(got.end_b.std / at_rest.end_b.std - 1.0) > 0.005


@pytest.mark.filterwarnings("ignore::stochcable.errors.ResolutionWarning")
def test_engine_solves_a_travelling_line_on_a_body():
    """The scene path: a travelling leg on the disc buoy of Tuah (1982) is solved (no
    longer refused), with the coupled-modes warning; at c = 0 the result is the
    example's."""
    from stochcable.analysis import analyze
    from stochcable.errors import PhysicsWarning
    from stochcable.examples import load_example

    doc = load_example("tuah_1982_disc_buoy_single_leg").model_dump(mode="json")
    rest = analyze(doc)
    doc["lines"][0]["axial_speed"] = 1.0
    with pytest.warns(PhysicsWarning, match="coupled modes of its group leave out"):
        moving = analyze(doc)
    # the linear model's σ: the residuals are not computed for a travelling line on a
    # body (its coupled influence leaves out the transport terms), and say so
    a = rest.lines["leg"].linear_end("end_b").std
    b = moving.lines["leg"].linear_end("end_b").std
    assert a != b and b == pytest.approx(a, rel=0.01)  # a light line (0.07 kg/m)
    skipped = moving.lines["leg"].drag_residual
    assert not skipped.computed and "on free bodies is not covered" in skipped.reason
