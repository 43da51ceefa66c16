"""The linearized steady lift in the frequency-domain engine (stochcable.dynamics.model.lift).

The engine's direct solve with the lift's non-symmetric damping C_L (its band, the end
motion's load and the reaction rows) against a second method: the full impedance
assembled densely from the element matrices l0·A ⊗ P and solved directly.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from stochcable.dynamics.loads.channels import Channel
from stochcable.dynamics.model.lift import lift_pattern
from stochcable.dynamics.model.system import Damping, build_line_system
from stochcable.dynamics.solve.line_solve import solve
from stochcable.line.transport.relative_flow import lift_velocity_jacobian, steady_lift_force
from stochcable.scene.model import load_scene
from stochcable.statics import solve_statics

CABLE = {
    "environment": {"depth": 200.0, "rho": 1025.0,
                    "current": [{"z": 0.0, "speed": 0.6, "heading": 90.0}]},
    "lines": [
        {
            "name": "cable",
            "end_a": {"position": [0.0, 0.0, -150.0]},
            "end_b": {"position": [150.0, 0.0, -20.0]},
            "segments": [
                {"length": 220.0, "ea": 2.0e8, "mass": 20.0, "diameter": 0.06,
                 "weight": 150.0, "cd_axial": 0.02, "cl_steady": 0.6, "elements": 16}
            ],
            "axial_speed": 3.0,
        }
    ],
}  # fmt: skip


#: The linear answer (the tests of the linearized lift itself).
LINEAR = {"drag_residual": False, "geometric_residual": False}


def test_lift_jacobian_is_the_derivative_of_a_degree_two_form():
    """f_L is homogeneous of degree 2 in (U, c): A U + c ∂f_L/∂c = 2 f_L (Euler), for
    random tangents, flows and speeds (the differences' truncation: 1e-9 relative)."""
    rng = np.random.default_rng(34)
    e = rng.normal(size=(20, 3))
    e /= np.linalg.norm(e, axis=1)[:, None]
    u, c, coef = rng.normal(size=(20, 3)), rng.normal(size=20), rng.uniform(1.0, 2.0, 20)
    a = lift_velocity_jacobian(e, u, c, coef)
    h = 1e-6
    dfc = (steady_lift_force(e, u, c + h, coef) - steady_lift_force(e, u, c - h, coef)) / (2 * h)
    f = steady_lift_force(e, u, c, coef)
    lhs = np.einsum("eij,ej->ei", a, u) + c[:, None] * dfc
    np.testing.assert_allclose(lhs, 2.0 * f, rtol=0, atol=1e-8 * np.abs(f).max())
    # no mean normal flow: no lift direction, nothing to linearize about
    assert not lift_velocity_jacobian(e[:1], 2.0 * e[:1], 1.0, coef[:1]).any()


def _system(speed: float, cl: float = 0.6):
    doc = json.loads(json.dumps(CABLE))
    doc["lines"][0]["axial_speed"] = speed
    doc["lines"][0]["segments"][0]["cl_steady"] = cl
    scene = load_scene(doc)
    statics = solve_statics(scene, method="fe")
    line = scene.lines[0]
    return scene, build_line_system(scene, line, statics.lines[line.name], dim=3)


def _dense_lift_and_gyro(system) -> tuple[np.ndarray, np.ndarray]:
    """C_L and G assembled densely from the element blocks l0·A ⊗ P and m c."""
    model = system.model
    n, d, pat = model.n_nodes, model.dim, lift_pattern(model)
    cl = np.zeros((n * d, n * d))
    g = np.zeros((n * d, n * d))
    for j in range(model.l0.size):
        for a in range(2):
            for b in range(2):
                r, c = slice((j + a) * d, (j + a + 1) * d), slice((j + b) * d, (j + b + 1) * d)
                cl[r, c] += pat[a, b] * system.lift[j]
                if system.gyro is not None:
                    g[r, c] += system.gyro[j] * [[0.0, 1.0], [-1.0, 0.0]][a][b] * np.eye(d)
    return cl, g


def _random_damping(model, rng) -> Damping:
    n_el = model.l0.size
    return Damping(
        method="seed",
        sigma=np.zeros(2 * n_el),
        b_normal=rng.uniform(20.0, 60.0, n_el),
        b_axial=rng.uniform(1.0, 5.0, n_el),
        b_node=np.zeros(model.n_nodes),
        model=model,
    )


@pytest.mark.filterwarnings("ignore::stochcable.errors.PhysicsWarning")
@pytest.mark.parametrize("speed", [0.0, 3.0])
def test_end_influence_with_lift_by_the_adjoint(speed):
    """The residuals' end influence (end tension per unit node force, by the adjoint
    solve with Aᵀ: C_Lᵀ and −G) equals the forward solve with the full non-symmetric
    impedance, to 1e-9 (round-off), on the first, a middle and the last free DOF."""
    from stochcable.dynamics.residuals.residual_lines import end_influence
    from stochcable.dynamics.solve.line_solve import end_tension_from_support

    scene, system = _system(speed)
    model = system.model
    damping = _random_damping(model, np.random.default_rng(35))
    w = np.array([0.3, 1.7])
    got = end_influence(system, damping, w)  # (2, n_nodes, d, n_w)
    cl, g = _dense_lift_and_gyro(system)
    K, M = model.K.toarray(), (model.M + model.Ma).toarray()
    C = damping.matrix.toarray() + model.Cs.toarray() + g + cl
    fr, fx, d = model.free, model.fixed, model.dim
    e_hat = end_tension_from_support(system, np.eye(2 * d)[None].astype(complex))
    for i, x in enumerate(w):
        Z = K - x * x * M + 1j * x * C
        for dof in fr[[0, 1, fr.size // 2, -2, -1]]:
            f = np.zeros(K.shape[0])
            f[dof] = 1.0
            u = np.zeros(K.shape[0], complex)
            u[fr] = np.linalg.solve(Z[np.ix_(fr, fr)], f[fr])
            support = -(Z @ u - f)[fx]
            for k, end in enumerate(("end_a", "end_b")):
                t = np.real(e_hat[end][:, 0]) @ support
                assert abs(got[k, dof // d, dof % d, i] - t) <= 1e-9 * max(abs(t), 1e-12)


@pytest.mark.filterwarnings("ignore::stochcable.errors.PhysicsWarning")
@pytest.mark.parametrize("speed", [0.0, 3.0])
def test_direct_solve_with_lift_equals_the_assembled_impedance(speed):
    """Unit end_b motions in three directions: the engine's displacement and support
    forces equal the dense solve of Z = K − ω²M_T + iω(C_s + C_d + G + C_L) with C_L
    assembled from l0·A ⊗ P, to 1e-9 (round-off); the lift is there (C_L ≠ 0) and
    changes the response."""
    scene, system = _system(speed)
    assert system.solver == "direct" and system.lift is not None
    model = system.model
    d = model.dim
    damping = _random_damping(model, np.random.default_rng(34))
    w = np.array([0.05, 0.4, 1.3, 3.0])
    chans = []
    for k, name in ((2, "end_b.heave"), (0, "end_b.surge"), (1, "end_b.sway")):
        mb = np.zeros((w.size, 3), complex)
        mb[:, k] = 1.0
        chans.append(Channel(name=name, kind="end_motion", omega=w, spectrum=np.ones_like(w),
                             density=lambda x: np.ones_like(x), motion_b=mb))  # fmt: skip
    resp = solve(system, tuple(chans), damping)

    n = model.n_nodes
    cl, g = _dense_lift_and_gyro(system)
    assert np.abs(cl).max() > 0.0 and not np.allclose(cl, cl.T)
    K = model.K.toarray()
    M = (model.M + model.Ma).toarray()
    C = damping.matrix.toarray() + model.Cs.toarray() + g + cl
    fr, fx = model.free, model.fixed
    for j, k in enumerate((2, 0, 1)):
        ub = np.zeros(n * d)
        ub[fx[d:]] = np.eye(3)[k][list(model.components)]  # end_b's DOFs
        for i, x in enumerate(w):
            z = K - x * x * M + 1j * x * C
            u = np.zeros(n * d, complex)
            u[fr] = np.linalg.solve(z[np.ix_(fr, fr)], -z[np.ix_(fr, fx)] @ ub[fx])
            u[fx] = ub[fx]
            reac = -(z @ u)[fx]
            scale = np.abs(z[fx]).max() * np.abs(u).max()
            np.testing.assert_allclose(resp.support_force[i, :, j], reac, rtol=0,
                                       atol=1e-9 * scale)  # fmt: skip
            got = resp.displacement[i, :, j]
            np.testing.assert_allclose(got, u, rtol=0, atol=1e-9 * np.abs(u).max())
    # without C_L the same solve differs by more than the tolerance: the lift counts
    z = K - 0.16 * M + 0.4j * (C - cl)
    u0 = np.linalg.solve(z[np.ix_(fr, fr)], -z[np.ix_(fr, fx)] @ np.eye(n * d)[fx][:, -2])
    assert np.abs(u0 - resp.displacement[1, fr, 0]).max() > 1e-6 * np.abs(u0).max()


def test_no_lift_in_a_planar_model_or_without_coefficient():
    """In the vertical plane of the line (a 2-D model) the lift of an in-plane flow has
    no in-plane part, and cl_steady = 0 adds nothing: no lift blocks, the solver as
    set."""
    _, flat = _system(0.0, 0.0)
    assert flat.lift is None
    doc = json.loads(json.dumps(CABLE))
    doc["environment"]["current"][0]["heading"] = 0.0
    scene = load_scene(doc)
    st = solve_statics(scene, method="fe")
    system = build_line_system(scene, scene.lines[0], st.lines["cable"], dim=2)
    assert system.lift is None


@pytest.mark.slow  # two analyses and a 300 s time-domain simulation: ≈ 1 min
def test_laying_example_with_lift_frequency_domain_equals_time_domain(monkeypatch):
    """The bundled laying example (paid out at 1 m/s in a 0.5 m/s cross-current) with
    C_L = 0.6, in its linear limit (Hs 0.05 m; strakes: the time domain has no vortex
    shedding), 300 s: the analysis' synthesized end tensions against the nonlinear
    time-domain reference with transport and the lift of the instantaneous relative
    flow (stochcable.reference.cable_transport.lift_nodal_forces), on the same
    realization.  The allowance is the drag nonlinearity σ_vr/U_n plus the Newmark
    period error (≈ 3.6 %; measured 2.8 % and 2.6 %).  The dynamic lift is resolved:
    without it (its static part kept) the frequency domain is 60 % of σ away; with it
    the end σ is 2.8× that without (the lift across the flow turns with the normal
    flow's angle: its gain ½ρC_L D|V|²/|U_n| exceeds the drag's)."""
    from stochcable.analysis import analyze
    from stochcable.examples import load_example
    from stochcable.reference.cable import newmark_period_error, simulate_line_timedomain

    doc = load_example("cable_laying").model_dump(mode="json")
    doc["sea"]["spectrum"]["hs"] = 0.05
    doc["analysis"]["timeseries"]["duration"] = 300.0
    seg = doc["lines"][0]["segments"][0]
    seg["strumming"] = {"suppression": "strakes"}
    seg["cl_steady"] = 0.6
    doc["analysis"]["linearization"].update(LINEAR)
    assert doc["lines"][0]["axial_speed"] == -1.0
    with pytest.warns(Warning):  # the modes at rest of a travelling line
        res = analyze(doc)
    with monkeypatch.context() as m:
        m.setattr("stochcable.dynamics.model.system.lift_blocks", lambda *a: None)
        with pytest.warns(Warning):
            res0 = analyze(doc)
    lr = res.lines["cable"]
    hist = simulate_line_timedomain(doc, band=(0.2, 2.5))
    u_n = 0.5  # the cross-current, normal to the whole line [m/s]
    tol = float(np.max(lr.linearization.sigma_normal)) / u_n
    tol += newmark_period_error(hist._meta["omega_max"], hist.dt)
    assert tol < 0.05
    ts, ts0 = res.timeseries, res0.timeseries
    k = round(0.25 / hist.dt)
    sel = ts.time >= hist.ramp
    for end in ("a", "b"):
        fd = np.asarray(ts.end_tension["cable"][f"end_{end}"])[sel]
        fd0 = np.asarray(ts0.end_tension["cable"][f"end_{end}"])[sel]
        td = (hist.tension_a if end == "a" else hist.tension_b)[::k][: ts.time.size][sel]
        a, b, b0 = td - td.mean(), fd - fd.mean(), fd0 - fd0.mean()
        assert (a - b).std() <= tol * b.std()
        assert a.std() == pytest.approx(getattr(lr, f"end_{end}").std, rel=tol)
        assert (a - b0).std() > 0.5 * b.std()
        assert b.std() > 2.0 * b0.std()


@pytest.mark.filterwarnings("ignore::Warning")
def test_residuals_of_a_line_with_lift_are_computed(monkeypatch):
    """The residuals' adjoint has the lift's Aᵀ (test above): a line with lift in a
    current gets both residuals by default; their variance is finite and positive and
    the corrected σ² is the linear σ² plus their variances (to round-off).  (This
    light cable's residual variance is 2.3× its linear one at end_a, above the range
    the residuals are applied in, RESIDUAL_VARIANCE_LIMIT, tested in test_hard_cases:
    lifted here, the subject being the lift's path through the residuals.)"""
    from stochcable.analysis import analyze
    from stochcable.dynamics.residuals import corrected

    monkeypatch.setattr(corrected, "RESIDUAL_VARIANCE_LIMIT", float("inf"))
    doc = json.loads(json.dumps(CABLE))
    doc["sea"] = {"spectrum": {"type": "jonswap", "hs": 0.5, "tp": 8.0}}
    line = analyze(doc).lines[doc["lines"][0]["name"]]
    added = 0.0
    for kind in ("drag_residual", "geometric_residual"):
        rec = getattr(line, kind)
        assert rec.computed, rec.reason
        added += rec.variance["end_b"]
    assert np.isfinite(added) and added > 0.0
    lin = line.linear_end("end_b").std
    assert line.end_b.std == pytest.approx(np.sqrt(lin**2 + added), rel=1e-9)


@pytest.mark.filterwarnings("ignore::Warning")
def test_galloping_line_is_refused_not_solved():
    """A lift coefficient large against a small drag (C_D 0.05, C_L 2 at 3 m/s) makes
    the linearized line flutter with its converged drag damping: refused, naming the
    coefficient and the growth rate (the time-domain reference diverges on it within
    25 s); C_D 0.1 and C_L 1 is stable and solved."""
    from stochcable.analysis import analyze
    from stochcable.errors import InputError

    def doc(cd, cl):
        d = json.loads(json.dumps(CABLE))
        d["sea"] = {"spectrum": {"type": "jonswap", "hs": 1.0, "tp": 8.0}}
        d["analysis"] = {"linearization": dict(LINEAR)}
        seg = d["lines"][0]["segments"][0]
        seg["cl_steady"], seg["cd_normal"] = cl, cd
        return d

    assert analyze(doc(0.1, 1.0)).lines["cable"].end_b.std > 0.0
    with pytest.raises(InputError, match=r"segments\[0\]\.cl_steady = 2.*flutter: growth"):
        analyze(doc(0.05, 2.0))
