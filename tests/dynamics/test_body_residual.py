"""The residuals of lines on free bodies (stochcable.dynamics.residuals.body_residual):
the end influence through the coupled group.

Independent checks: the coupled end tensions per unit node force against the
assembled coupled system (couple + coupled_load + solve_coupled_direct, dense) loaded
by the same forces; the closed-form residual through the buoy against Monte Carlo
realizations of the residual forces filtered by the assembled system; a line without
attached ends gives the ends-held influence; the buoy examples' residuals now
computed, through the bodies (different from the line with its ends held)."""

from __future__ import annotations

import copy
import warnings

import numpy as np
import pytest
from _scenes import three_chain_legs

from stochcable import analyze, load_example
from stochcable.bodies.coupling import LineLink, couple, coupled_load, expand_line
from stochcable.bodies.rigid import RigidBody
from stochcable.dynamics.groups import CoupledLine, body_loads, linearize_coupled
from stochcable.dynamics.groups.group import linear_body_drag
from stochcable.dynamics.linearization.formulas import drag_linear_vector
from stochcable.dynamics.loads.channels import line_channels
from stochcable.dynamics.model.system import build_line_system
from stochcable.dynamics.residuals.body_residual import CoupledInfluence, coupled_influences
from stochcable.dynamics.residuals.drag_residual import hermite_coefficients
from stochcable.dynamics.residuals.drag_residual_3d import (
    vector_hermite_coefficients,
    vector_residual_output_lines,
)
from stochcable.dynamics.residuals.residual_lines import end_influence
from stochcable.dynamics.solve.line_solve import end_tension_from_support
from stochcable.reference.bodies import solve_coupled_direct
from stochcable.scene.model import load_scene
from stochcable.statics import solve_statics

RHO = 1025.0


@pytest.fixture(scope="module")
def buoy_group():
    """Three 3-D chain legs on a buoy (tests/dynamics/test_coupled_analysis.py's
    mooring), the drag fixed point converged."""
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


def test_coupled_influence_equals_the_assembled_system(buoy_group):
    """Random node forces on one leg (three load cases, at frequencies up to 3·ω_max as
    the residual's lines reach): the end tensions of the coupled influence equal those
    of the assembled lines–body system solved directly (its support forces −[Z u − F]
    at the end rows, ê·R), to round-off (measured 7e-13; bound 1e-9 for the dense
    solve's conditioning, ~1e8); the body's motion changes them (the ends-held
    influence differs by more than 1e-3); another leg's end tensions under the same
    loads (the ``target`` influence, through the buoy only) likewise."""
    scene, cls, loads, body, lin = buoy_group
    w = np.linspace(0.1, 6.0, 25)
    damp = {cl.name: lin.lines[cl.name].damping for cl in cls}
    infl = coupled_influences(cls, [body], damp, lin.body_drag)
    cl = cls[0]
    model = cl.system.model
    rng = np.random.default_rng(2)
    f = rng.standard_normal((model.n_dof, 3)) + 1j * rng.standard_normal((model.n_dof, 3))
    g = infl[cl.name].on(w)  # (2, n_nodes, d, n_w)
    got = np.einsum("enkw,nkc->ewc", g, f.reshape(model.n_nodes, model.dim, 3))
    links = [
        LineLink(c.name, c.system.model, end_b="buoy", force_b=c.system.statics.force_b,
                 damping=damp[c.name].matrix)
        for c in cls
    ]  # fmt: skip
    _, cdrag = linear_body_drag(body, RHO, lin.body_sigma["buoy"], loads["buoy"].current, "seed")
    system = couple(links, [body], body_damping={"buoy": cdrag})
    fw = np.broadcast_to(f, (w.size,) + f.shape)
    x = solve_coupled_direct(system, coupled_load(system, w, line_loads={cl.name: fw}), w, "dense")
    u = expand_line(system, cl.name, x)  # (n_w, n_dof, 3)
    k, m = model.K, (model.M + model.Ma)
    c = model.Cs + damp[cl.name].matrix
    d, n = model.dim, model.n_nodes
    ends = np.r_[np.arange(d), np.arange((n - 1) * d, n * d)]
    ref_r = np.stack(
        [fw[i][ends] - ((k - w[i] ** 2 * m + 1j * w[i] * c) @ u[i])[ends] for i in range(w.size)]
    )  # (n_w, 2d, 3)
    ten = end_tension_from_support(cl.system, ref_r)
    ref = np.stack([ten["end_a"].T, ten["end_b"].T])  # (2, n_w, 3)
    np.testing.assert_allclose(got, ref, rtol=1e-9, atol=1e-9 * np.abs(ref).max())
    held = np.einsum("enkw,nkc->ewc", end_influence(cl.system, damp[cl.name], w),
                     f.reshape(n, d, 3))  # fmt: skip
    assert np.abs(held - ref).max() > 1e-3 * np.abs(ref).max()
    # another leg's end tensions under the same loads: through the buoy only
    other = cls[1]
    cross = CoupledInfluence(cl.name, infl[cl.name].lines, [body], lin.body_drag, other.name)
    got = np.einsum("enkw,nkc->ewc", cross.on(w), f.reshape(n, d, 3))
    mo = other.system.model
    u2 = expand_line(system, other.name, x)
    c2 = mo.Cs + damp[other.name].matrix
    ends2 = np.r_[np.arange(d), np.arange((mo.n_nodes - 1) * d, mo.n_nodes * d)]
    r2 = np.stack(
        [-((mo.K - w[i] ** 2 * (mo.M + mo.Ma) + 1j * w[i] * c2) @ u2[i])[ends2]
         for i in range(w.size)]
    )  # fmt: skip
    ten2 = end_tension_from_support(other.system, r2)
    ref2 = np.stack([ten2["end_a"].T, ten2["end_b"].T])
    assert np.abs(ref2).max() > 1e-3 * np.abs(ref).max()
    np.testing.assert_allclose(got, ref2, rtol=1e-9, atol=1e-9 * np.abs(ref2).max())


def test_a_line_without_attached_ends_keeps_the_held_influence(buoy_group):
    """The same line with no end on a body: the coupled influence is the ends-held
    end influence (to round-off)."""
    scene, cls, loads, body, lin = buoy_group
    cl = cls[1]
    alone = CoupledLine(cl.system, cl.channels)
    damp = {cl.name: lin.lines[cl.name].damping}
    w = np.linspace(0.2, 4.0, 7)
    got = coupled_influences([alone], [body], damp, {})[cl.name].on(w)
    ref = end_influence(cl.system, damp[cl.name], w)
    np.testing.assert_allclose(got, ref, rtol=1e-10, atol=1e-12 * np.abs(ref).max())


def test_buoy_example_residuals_through_the_body():
    """The disc buoy's single leg (a planar body): both residuals computed, through
    the coupled group (drag +11 %, geometric +3 % on the top tension σ); the same leg
    with the buoy fixed in every DOF (its top end held) gives different ones (drag
    −4 %, geometric +0.005 %)."""
    doc = load_example("tuah_1982_disc_buoy_single_leg").model_dump(mode="json")
    doc["analysis"]["linearization"].update(drag_residual=True, geometric_residual=True)
    doc["analysis"].pop("timeseries", None)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        leg = next(iter(analyze(doc).lines.values()))
        fixed = copy.deepcopy(doc)
        fixed["bodies"][0]["fixed_dofs"] = ["surge", "heave", "pitch"]
        held = next(iter(analyze(fixed).lines.values()))
    for kind in ("drag_residual", "geometric_residual"):
        rec, ref = getattr(leg, kind), getattr(held, kind)
        assert rec.computed and ref.computed, (rec.reason, ref.reason)
        assert rec.variance["end_b"] > 0
    assert leg.drag_residual.variance["end_b"] != pytest.approx(
        held.drag_residual.variance["end_b"], rel=1e-3
    )


def test_residual_through_the_buoy_equals_monte_carlo_through_the_assembled_system(buoy_group):
    """Two panels on a leg of the three-leg buoy, each a point force along two normals
    and the tangent, loaded by the drag residual of correlated Gaussian velocities with
    a current (the bivariate expansion to order 7): the closed form through the
    coupled influence against the mean over Gaussian realizations (fixed seed, 300)
    of the sampled residual forces filtered by the end tensions of the assembled
    lines–body system solved directly: within 4 standard errors plus 1e-3 (the orders
    above 7)."""
    scene, cls, loads, body, lin = buoy_group
    rng = np.random.default_rng(9)
    cl = cls[0]
    model = cl.system.model
    d, n = model.dim, model.n_nodes
    n_j, step, order, n_fft = 12, 0.1, 7, 256
    n_o = order * (n_j - 1)
    w_out = step * np.arange(1, n_o + 1)
    # the panels: nodes 3 and 7, directions (n1, n2, t) of the element below each
    t_el, n1, n2 = cl.system.frames
    nodes = (3, 7)
    unit = np.zeros((n, d, 2, 3))
    for p, k in enumerate(nodes):
        for o, vec in enumerate((n1[k], n2[k], t_el[k])):
            unit[k, :, p, o] = vec[list(model.components)]
    damp = {c.name: lin.lines[c.name].damping for c in cls}
    g = coupled_influences(cls, [body], damp, lin.body_drag)[cl.name].on(w_out)
    closed_t = np.einsum("enkw,nkpo->epow", g, unit)
    # the same unit loads through the assembled system
    links = [
        LineLink(c.name, c.system.model, end_b="buoy", force_b=c.system.statics.force_b,
                 damping=damp[c.name].matrix)
        for c in cls
    ]  # fmt: skip
    _, cdrag = linear_body_drag(body, RHO, lin.body_sigma["buoy"], loads["buoy"].current, "seed")
    system = couple(links, [body], body_damping={"buoy": cdrag})
    f = np.broadcast_to(unit.reshape(n * d, 6), (w_out.size, n * d, 6))
    x = solve_coupled_direct(system, coupled_load(system, w_out, line_loads={cl.name: f}), w_out)
    u = expand_line(system, cl.name, x)
    c = model.Cs + damp[cl.name].matrix
    ends = np.r_[np.arange(d), np.arange((n - 1) * d, n * d)]
    m = model.M + model.Ma
    r_end = np.stack(
        [f[i][ends] - ((model.K - w ** 2 * m + 1j * w * c) @ u[i])[ends]
         for i, w in enumerate(w_out)]
    )  # fmt: skip
    ten = end_tension_from_support(cl.system, r_end)
    direct_t = np.stack([ten["end_a"], ten["end_b"]]).reshape(2, 2, 3, n_o)
    # the velocities: (n_ch, panel, (v_n1, v_n2, v_t), line), a current on panel 2
    j = np.arange(n_j)
    shape = np.exp(-0.5 * ((j - 5) / 2.0) ** 2) * (j > 0)
    mix = rng.standard_normal((2, 2, 3)) + 0.5j * rng.standard_normal((2, 2, 3))
    lines = mix[..., None] * shape * np.exp(-0.4j * j)[None, None, None]
    mean = np.array([[0.0, 0.0, 0.0], [0.5, -0.3, 0.2]])
    scale = np.array([300.0, 500.0])  # c·l of each panel [N·s²/m²]
    coeffs = np.zeros((2, 3) + (order + 1,) * 3)
    z = np.zeros((2, 2, 3, n_j), dtype=complex)
    fits = []
    for p in range(2):
        vn = lines[:, p, :2]
        cov = np.einsum("caj,cbj->ab", vn.conj(), vn).real
        a, q, s = vector_hermite_coefficients([mean[p, :2]], [cov], order, False)
        coeffs[p, :2, :, :, 0] = scale[p] * a[0]
        z[:, p, :2] = np.einsum("ai,caj->cij", q[0], vn) / s[0][None, :, None]
        sig_t = float(np.sqrt(np.sum(np.abs(lines[:, p, 2]) ** 2)))
        at = hermite_coefficients([mean[p, 2] / sig_t], order)[0]
        coeffs[p, 2, 0, 0, :] = scale[p] * sig_t**2 * at
        z[:, p, 2] = lines[:, p, 2] / sig_t
        fits.append((cov, a[0, :, 0, 0], sig_t, at))
    closed = vector_residual_output_lines(z, coeffs, closed_t, n_fft).sum(axis=1)
    samples = []
    for _ in range(300):
        amp = (rng.standard_normal((2, n_j)) + 1j * rng.standard_normal((2, n_j))) / np.sqrt(2)
        spec = np.zeros((2, 3, n_fft // 2 + 1), dtype=complex)
        spec[..., :n_j] = np.einsum("cj,cpvj->pvj", np.sqrt(2.0) * amp, lines)
        v = mean[:, :, None] + np.fft.irfft(spec, n=n_fft, axis=2) * (0.5 * n_fft)
        r = np.empty_like(v)
        for p, (cov, a00, sig_t, at) in enumerate(fits):
            vn, mp = v[p, :2], mean[p, :2, None]
            b = drag_linear_vector(1.0, 1.0, 2.0, cov, mean[p, :2])
            r[p, :2] = scale[p] * (np.linalg.norm(vn, axis=0) * vn - a00[:, None] - b @ (vn - mp))
            xt = (v[p, 2] - mean[p, 2]) / sig_t
            r[p, 2] = scale[p] * (np.abs(v[p, 2]) * v[p, 2] - sig_t**2 * (at[0] + at[1] * xt))
        rf = np.fft.rfft(r, axis=2)[..., 1 : n_o + 1]
        y = np.einsum("epow,pow->ew", direct_t, rf)
        samples.append(2.0 * (np.abs(y) ** 2).sum(axis=1) / n_fft**2)
    samples = np.array(samples)
    mc, se = samples.mean(axis=0), samples.std(axis=0, ddof=1) / np.sqrt(len(samples))
    assert np.all(closed > 0)
    np.testing.assert_array_less(np.abs(closed - mc), 4.0 * se + 1e-3 * closed)
