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
from _scenes import RHO, three_leg_buoy_group
from _scenes import analyzed_group as _group_of
from _scenes import assembled_group as _assembled
from _scenes import two_leg_buoy_doc as _two_leg_doc

from stochcable import analyze, load_example
from stochcable.bodies.coupling import LineLink, couple, coupled_load, expand_line
from stochcable.dynamics.groups import CoupledLine
from stochcable.dynamics.groups.group import linear_body_drag
from stochcable.dynamics.linearization.formulas import drag_linear_vector
from stochcable.dynamics.residuals.body_motion import BodyCoupledInfluence
from stochcable.dynamics.residuals.body_residual import CoupledInfluence, coupled_influences
from stochcable.dynamics.residuals.drag_residual import hermite_coefficients
from stochcable.dynamics.residuals.drag_residual_3d import (
    vector_hermite_coefficients,
    vector_residual_output_lines,
)
from stochcable.dynamics.residuals.residual_lines import end_influence
from stochcable.dynamics.solve.line_solve import end_tension_from_support
from stochcable.reference.bodies import solve_coupled_direct


@pytest.fixture(scope="module")
def buoy_group():
    """Three 3-D chain legs on a buoy, the drag fixed point converged
    (_scenes.three_leg_buoy_group)."""
    return three_leg_buoy_group()


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


@pytest.fixture(scope="module")
def two_leg_group():
    """The two-leg planar buoy analysed, with its group."""
    return _group_of(_two_leg_doc())


def _end_tensions(system, cl, damp, x, w, f=None):
    """A line's end tensions (2, n_w, n_case) from the assembled solution ``x`` and
    the node forces ``f`` (n_w, n_dof, n_case) on it."""
    m = cl.system.model
    u = expand_line(system, cl.name, x)
    c = m.Cs + damp.matrix
    d = m.dim
    ends = np.r_[np.arange(d), np.arange((m.n_nodes - 1) * d, m.n_nodes * d)]
    r = np.stack(
        [(0.0 if f is None else f[i][ends])
         - ((m.K - wi**2 * (m.M + m.Ma) + 1j * wi * c) @ u[i])[ends]
         for i, wi in enumerate(w)]
    )  # fmt: skip
    ten = end_tension_from_support(cl.system, r)
    return np.stack([ten["end_a"].T, ten["end_b"].T])


def test_misfit_through_the_group_equals_the_assembled_system():
    """The drag residual's misfit part of a side leg of the three-leg buoy (every leg's
    linear misfit loads δB·v through the group, with the target's linear tension):
    against the same loads on all three legs applied to the assembled lines–body
    system solved directly, Σ_c q S_c (|H_L + H_c|² − |H_L|²): to 1e-8 of the part's
    largest line (measured 2e-13; the dense solve's conditioning); the other legs'
    loads move it (the leg's own alone: +1833 / +670 lbf² against −87 / −1300)."""
    from stochcable.dynamics.model.blocks import trapezoid_weights
    from stochcable.dynamics.residuals.drag_residual_3d import drag_components_3d

    doc = load_example("tuah_1982_disc_buoy_three_legs").model_dump(mode="json")
    res, cls, bodies, clin = _group_of(doc)
    system, damp = _assembled(cls, bodies, clin)
    w = np.asarray(cls[0].channels[0].omega)
    loads = {}
    for c in cls:
        comp = drag_components_3d(c.system, c.channels, clin.lines[c.name], 3, True)
        assert comp.db is not None
        v = np.stack([comp.pan["n1"], comp.pan["n2"], comp.pan["t"]], axis=1)
        load = np.einsum("pab,cbpw->capw", comp.db, v).reshape(v.shape[0], -1, w.size)
        n_dof = c.system.model.n_dof
        loads[c.name] = np.einsum("kp,cpw->wkc", comp.unit.reshape(n_dof, -1), load)
    x = solve_coupled_direct(system, coupled_load(system, w, line_loads=loads), w, "dense")
    target = next(c for c in cls if c.name == "leg2")
    h_c = _end_tensions(system, target, damp["leg2"], x, w, loads["leg2"])  # (2, n_w, n_ch)
    spectra = np.stack([ch.spectrum for ch in target.channels])
    q = trapezoid_weights(w)[None] * spectra
    rec = res.lines["leg2"].residuals["drag_residual"]
    got = next(part for om, part in rec.lines if om.size == w.size and np.allclose(om, w))
    own = _end_tensions(system, target, damp["leg2"],
                        solve_coupled_direct(system, coupled_load(system, w, line_loads={
                            "leg2": loads["leg2"]}), w, "dense"), w, loads["leg2"])  # fmt: skip
    for k, end in enumerate(("end_a", "end_b")):
        h_l = np.asarray(clin.lines["leg2"].response.end_tension[end])
        ref = np.sum(q * (np.abs(h_l + h_c[k].T) ** 2 - np.abs(h_l) ** 2), axis=0)
        alone = np.sum(q * (np.abs(h_l + own[k].T) ** 2 - np.abs(h_l) ** 2), axis=0)
        scale = np.abs(ref).max()
        np.testing.assert_allclose(got[end], ref, rtol=0, atol=1e-8 * scale)
        assert abs(alone.sum() - ref.sum()) > 0.1 * np.abs(ref).sum()


def test_other_legs_loads_reach_through_the_body_as_the_assembled_system(two_leg_group):
    """The drag residual's panel loads of one leg reach the other leg's end tensions
    (CoupledInfluence.sources, the influence the residual uses) as in the assembled
    lines–body system solved directly, at the residual's lines up to 3·ω_max: to 1e-9
    (measured ~1e-13; the dense solve's conditioning)."""
    from stochcable.dynamics.residuals.drag_residual import drag_components
    from stochcable.dynamics.residuals.residual_lines import load_transfer

    _, cls, bodies, clin = two_leg_group
    damp = {c.name: clin.lines[c.name].damping for c in cls}
    infl = coupled_influences(cls, bodies, damp, clin.body_drag, clin.lines)
    (src, through), = infl["leg2"].sources()  # fmt: skip
    assert src.name == "leg"
    comp = drag_components(src.system, src.channels, src.linearization, 3, True)
    w = comp.w_out[:: max(1, comp.w_out.size // 40)]
    got = load_transfer(src.system, src.damping, comp.unit, w, through)  # (2, n_comp, n_w)
    system, _ = _assembled(cls, bodies, clin)
    model = src.system.model
    f = np.broadcast_to(
        comp.unit.reshape(model.n_dof, -1), (w.size, model.n_dof, comp.unit.shape[2])
    )
    x = solve_coupled_direct(system, coupled_load(system, w, line_loads={"leg": f}), w, "dense")
    other = next(c for c in cls if c.name == "leg2")
    mo = other.system.model
    u2 = expand_line(system, "leg2", x)
    c2 = mo.Cs + damp["leg2"].matrix
    d = mo.dim
    ends = np.r_[np.arange(d), np.arange((mo.n_nodes - 1) * d, mo.n_nodes * d)]
    r2 = np.stack(
        [-((mo.K - wi**2 * (mo.M + mo.Ma) + 1j * wi * c2) @ u2[i])[ends] for i, wi in enumerate(w)]
    )
    ten = end_tension_from_support(other.system, r2)
    ref = np.stack([ten["end_a"].T, ten["end_b"].T])  # (2, n_w, n_comp)
    ref = np.transpose(ref, (0, 2, 1))
    assert np.abs(ref).max() > 0
    np.testing.assert_allclose(got, ref, rtol=1e-9, atol=1e-9 * np.abs(ref).max())


def test_two_legs_residual_cross_terms_equal_monte_carlo(two_leg_group, monkeypatch):
    """The legs' drag residual forces are correlated (their velocities share the sea and
    the body), so the other leg's contribution is not the sum of each leg's alone: the
    closed form over both legs' panels as one set of components (the largest-σ normal
    panel of each leg, their actual velocity lines and means, orders to 7) through the
    target leg's end tensions against the mean over Gaussian realizations (fixed seed,
    2000) of the sampled residual forces filtered alike: within 4 standard errors plus
    1e-3 (the orders above 7); the cross term itself (measured −10 % / −14 % at
    end_a / end_b of the independent-legs sum) is beyond 4 standard errors of it.  The
    body's surge, heave and pitch as more outputs of the same components (the joint
    sums' body rows, residuals.group_motion) alike (their cross terms of these two
    panels, 1e-3 of surge's, are within the sampling error).  The split top elements'
    pieces equal (CONTINUOUS_PIECES off: the picked panel a fifth of its element; the
    continuous pieces make it 0.13 of it, and its cross term less than 4 errors)."""
    import stochcable.dynamics.residuals.drag_segments as drag_segments
    from stochcable.dynamics.residuals.drag_residual import drag_components
    from stochcable.dynamics.residuals.drag_residual import residual_output_lines as rol
    from stochcable.dynamics.residuals.residual_lines import load_transfer

    monkeypatch.setattr(drag_segments, "CONTINUOUS_PIECES", False)
    _, cls, bodies, clin = two_leg_group
    damp = {c.name: clin.lines[c.name].damping for c in cls}
    infl = coupled_influences(cls, bodies, damp, clin.body_drag, clin.lines)
    order, pick, transfer, lines = 7, [], [], []
    for c in cls:
        comp = drag_components(c.system, c.channels, clin.lines[c.name], order, False)
        sig = np.sqrt(np.sum(np.abs(comp.lines) ** 2, axis=(0, 2)))
        p = int(np.argmax(sig[: len(comp.groups)]))  # (normal panels first)
        through = infl["leg2"] if c.name == "leg2" else infl["leg2"].sources()[0][1]
        h = load_transfer(c.system, damp[c.name], comp.unit[:, :, [p]], comp.w_out, through)
        body = BodyCoupledInfluence(infl[c.name])  # (and the body DOFs: joint sums' rows)
        hb = load_transfer(c.system, damp[c.name], comp.unit[:, :, [p]], comp.w_out, body)
        pick.append((comp.scale[p], comp.coeffs[p], sig[p]))
        transfer.append(np.concatenate([h, hb]))
        lines.append(comp.lines[:, [p]])
        grid_n, n_fft = comp.grid.n_j, comp.n_fft
    lines_all = np.concatenate(lines, axis=1)
    scale = np.array([s for s, _, _ in pick])
    coeffs = np.stack([a for _, a, _ in pick])
    h_all = np.concatenate(transfer, axis=1)  # (2 ends + 3 body DOFs, 2, n_o)
    closed = rol(lines_all, scale, coeffs, h_all, n_fft).sum(axis=1)
    alone = sum(
        rol(lines_all[:, [p]], scale[[p]], coeffs[[p]], h_all[:, [p]], n_fft).sum(axis=1)
        for p in (0, 1)
    )
    # the panels' mean flow: μ from a₀…: recovered as the one whose coefficients match
    mus = np.linspace(-10.0, 10.0, 4001)
    table = hermite_coefficients(mus, order)
    mu = [float(mus[np.argmin(np.abs(table - a).sum(axis=1))]) for a in coeffs]
    assert all(np.allclose(hermite_coefficients([m], order)[0], a, atol=1e-6)
               for m, a in zip(mu, coeffs))  # fmt: skip
    rng = np.random.default_rng(31)
    n_o = h_all.shape[2]
    samples = []
    for _ in range(2000):
        n_ch = lines_all.shape[0]
        amp = rng.standard_normal((n_ch, grid_n)) + 1j * rng.standard_normal((n_ch, grid_n))
        amp /= np.sqrt(2.0)
        spec = np.zeros((2, n_fft // 2 + 1), dtype=complex)
        spec[:, :grid_n] = np.einsum("cj,cpj->pj", np.sqrt(2.0) * amp, lines_all)
        x = np.fft.irfft(spec, n=n_fft, axis=1) * (0.5 * n_fft)  # zero-mean velocity
        r = np.empty_like(x)
        for p, (s, a, sg) in enumerate(pick):
            v = mu[p] * sg + x[p]
            xi = x[p] / sg
            r[p] = s * (np.abs(v) * v - sg**2 * (a[0] + a[1] * xi))
        rf = np.fft.rfft(r, axis=1)[:, 1 : n_o + 1]
        y = np.einsum("epw,pw->ew", h_all, rf)
        samples.append(2.0 * (np.abs(y) ** 2).sum(axis=1) / n_fft**2)
    samples = np.array(samples)
    mc, se = samples.mean(axis=0), samples.std(axis=0, ddof=1) / np.sqrt(len(samples))
    assert np.all(closed > 0)
    np.testing.assert_array_less(np.abs(closed - mc), 4.0 * se + 1e-3 * closed)
    assert np.all(np.abs(closed - alone)[:2] > 4.0 * se[:2])
    assert np.all(closed[2:] > 10.0 * se[2:])  # (the body rows: well resolved)


def test_mirrored_two_leg_buoy_mirrors_the_legs_residuals():
    """The two-leg buoy mirrored (sea from the other side, wind reversed): each leg's
    drag and geometric residuals (its own loads, the other leg's through the buoy and
    their cross terms) is the other leg's in the original, to 1e-10 (measured 2e-15: the mirrored
    solves are the same arithmetic up to order); the other leg's loads change it (by
    more than 1 %)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        mirror = analyze(_two_leg_doc(heading=180.0, wind=-100.0))
        doc = _two_leg_doc()
        doc["bodies"][0].pop("hydrodynamics")
        res = analyze(doc)
    for a, b in (("leg", "leg2"), ("leg2", "leg")):
        for end in ("end_a", "end_b"):
            for kind in ("drag_residual", "geometric_residual"):
                got = mirror.lines[b].residuals[kind].variance[end]
                ref = res.lines[a].residuals[kind].variance[end]
                np.testing.assert_allclose(got, ref, rtol=1e-10)
    from stochcable.dynamics.residuals import body_residual as br

    mp = pytest.MonkeyPatch()
    mp.setattr(br.CoupledInfluence, "sources", lambda self: [])
    mp.setattr(br.CoupledInfluence, "joint_lines", lambda self, *a: None)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            own = analyze(doc)
    finally:
        mp.undo()
    for name in ("leg", "leg2"):
        got = res.lines[name].residuals["drag_residual"].variance["end_b"]
        assert abs(got / own.lines[name].residuals["drag_residual"].variance["end_b"] - 1) > 0.01


def test_three_leg_group_part_equals_the_assembled_system(monkeypatch):
    """The bundled three-leg buoy (3-D): the side legs' residuals mirror (the sea along
    x, the legs at ±120°: to 1e-10, measured ~1e-15); the group part of each leg's
    drag residual (all legs' panels as one sum less its own pairs) against the same
    sum with the end tensions per unit panel force of the assembled lines–body system
    solved directly, line by line relative to the leg's own part (the cells' factor
    common to both): to 1e-7 (passes at 1e-11; the dense solve's conditioning).  (The
    body's own drag residual, one more part after it, is left out here:
    tests/dynamics/test_body_drag_residual.py.)"""
    import stochcable.dynamics.groups.results as group_results
    from stochcable.dynamics.residuals.drag_residual_3d import (
        JOINT_MIN_PANELS,
        drag_components_3d,
    )

    monkeypatch.setattr(group_results, "body_drag_residual", lambda *a, **k: None)

    doc = load_example("tuah_1982_disc_buoy_three_legs").model_dump(mode="json")
    res, cls, bodies, clin = _group_of(doc)
    for kind in ("drag_residual", "geometric_residual"):
        for end in ("end_a", "end_b"):
            np.testing.assert_allclose(
                res.lines["leg2"].residuals[kind].variance[end],
                res.lines["leg3"].residuals[kind].variance[end],
                rtol=1e-10,
            )
    system, damp = _assembled(cls, bodies, clin)
    comps = [
        drag_components_3d(c.system, c.channels, clin.lines[c.name], 3, True, JOINT_MIN_PANELS)
        for c in cls
    ]
    w = comps[0].w_out
    per = []  # (2 ends of every target, n_p of this source, 3, n_o)
    for c, comp in zip(cls, comps):
        n_dof = c.system.model.n_dof
        f = np.broadcast_to(comp.unit.reshape(n_dof, -1), (w.size, n_dof, comp.unit.shape[2]))
        x = solve_coupled_direct(
            system, coupled_load(system, w, line_loads={c.name: f}), w, "dense"
        )
        t = np.concatenate(
            [_end_tensions(system, tc, damp[tc.name], x, w, f if tc is c else None) for tc in cls]
        )  # (2·n_lines, n_w, 3·n_p) direction-major columns
        n_p = comp.z.shape[1]
        per.append(np.transpose(t.reshape(t.shape[0], w.size, 3, n_p), (0, 3, 2, 1)))
    t_all = np.concatenate(per, axis=1)
    z = np.concatenate([c.z for c in comps], axis=1)
    co = np.concatenate([c.coeffs for c in comps])
    joint = vector_residual_output_lines(z, co, t_all, comps[0].n_fft)
    at = 0
    for i, (c, comp) in enumerate(zip(cls, comps)):
        n_p = comp.z.shape[1]
        rows = slice(2 * i, 2 * i + 2)
        own = vector_residual_output_lines(comp.z, comp.coeffs, t_all[rows, at : at + n_p],
                                           comp.n_fft)  # fmt: skip
        at += n_p
        ref = (joint[rows] - own) / np.where(own != 0, own, 1.0)
        rec = res.lines[c.name].residuals["drag_residual"]
        got_own, got_group = rec.lines[0][1], rec.lines[-1][1]
        for k, end in enumerate(("end_a", "end_b")):
            live = np.abs(own[k]) > 1e-9 * np.abs(own[k]).max()
            got = got_group[end][live] / got_own[end][live]
            np.testing.assert_allclose(got, ref[k][live], rtol=1e-7, atol=1e-7)
