"""The residual of a free body's own drag (stochcable.dynamics.residuals.body_drag_residual).

Independent checks: the components' σ and the Hermite a₁ against the group's drag
fixed point (its σ and its b = ρ·C_dA·E|v|); the drag point's outputs per unit force
against the assembled lines–body system loaded at the drag point and solved directly;
the closed form (the body's component with a panel of each leg, cross terms
included) against Monte Carlo realizations of the sampled drag c|v|v less the
linearization's fit, filtered by the same outputs; switches off: nothing added."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from _scenes import analyzed_group as _group_of
from _scenes import assembled_group as _assembled
from _scenes import two_leg_buoy_doc as _two_leg_doc

import stochcable.dynamics.groups.results as group_results
from stochcable import analyze, load_example
from stochcable.bodies.coupling import coupled_load, expand_line
from stochcable.dynamics.groups.inputs import body_loads
from stochcable.dynamics.residuals.body_drag_residual import (
    body_drag_components,
    body_drag_residual,
    drag_point_link,
    drag_point_transfer,
)
from stochcable.dynamics.residuals.body_motion import BodyCoupledInfluence
from stochcable.dynamics.residuals.body_residual import coupled_influences
from stochcable.dynamics.residuals.drag_residual import (
    drag_components,
    hermite_coefficients,
    residual_output_lines,
)
from stochcable.dynamics.residuals.residual_lines import load_transfer
from stochcable.dynamics.solve.line_solve import end_tension_from_support
from stochcable.reference.bodies import solve_coupled_direct


def _velocities(rng: np.random.Generator, lines: np.ndarray, n_fft: int) -> np.ndarray:
    """One Gaussian realization (n_p, n_fft) of zero-mean velocities whose amplitude
    lines are ``lines`` (n_ch, n_p, n_j) (complex Gaussian amplitudes per channel)."""
    n_ch, n_p, n_j = lines.shape
    amp = rng.standard_normal((n_ch, n_j)) + 1j * rng.standard_normal((n_ch, n_j))
    amp /= np.sqrt(2.0)
    spec = np.zeros((n_p, n_fft // 2 + 1), dtype=complex)
    spec[:, :n_j] = np.einsum("cj,cpj->pj", np.sqrt(2.0) * amp, lines)
    return np.fft.irfft(spec, n=n_fft, axis=1) * (0.5 * n_fft)


def _body_growth(h: np.ndarray, r: np.ndarray, n_fft: int) -> np.ndarray:
    """The outputs' variance (n_out,) of one realization of the forces ``r`` (n_p,
    n_fft) through ``h`` (n_out, n_p, n_o), less that without the first (the body's)."""
    n_o = h.shape[2]
    rf = np.fft.rfft(r, axis=1)[:, 1 : n_o + 1]
    y_all = np.einsum("epw,pw->ew", h, rf)
    y_pan = np.einsum("epw,pw->ew", h[:, 1:], rf[1:])
    return 2.0 * (np.abs(y_all) ** 2 - np.abs(y_pan) ** 2).sum(axis=1) / n_fft**2


def _agree(closed: np.ndarray, samples: np.ndarray, n_ends: int) -> np.ndarray:
    """Assert the closed form within 4 standard errors of the samples' mean plus 1e-3
    of the largest of the end tensions (the first ``n_ends`` rows) and of the DOFs
    (the orders above 7); the standard errors."""
    mc = samples.mean(axis=0)
    se = samples.std(axis=0, ddof=1) / np.sqrt(len(samples))
    for rows in (slice(0, n_ends), slice(n_ends, None)):
        top = np.abs(closed[rows]).max()
        np.testing.assert_array_less(np.abs(closed[rows] - mc[rows]), 4.0 * se[rows] + 1e-3 * top)
    return se


@pytest.fixture(scope="module")
def two_leg():
    """The planar two-leg buoy analysed: its group, the bodies' loads and influences."""
    doc = _two_leg_doc()
    res, cls, bodies, clin = _group_of(doc)
    w = np.asarray(cls[0].channels[0].omega)
    scene = res.scene
    loads = {b.name: body_loads(b, cls[0].channels, w, scene.sea, scene.environment)
             for b in bodies}  # fmt: skip
    damp = {c.name: clin.lines[c.name].damping for c in cls}
    infl = coupled_influences(cls, bodies, damp, clin.body_drag, clin.lines)
    spectra = np.stack([ch.spectrum for ch in cls[0].channels])
    return res, cls, bodies, clin, loads, infl, w, spectra


def test_components_are_the_linearizations(two_leg):
    """The body's drag components: σ of the relative velocity on the residual's uniform
    grid equals the fixed point's body σ (1e-9: the same trapezoid sum regrouped onto
    lines), and c·σ·a₁(U/σ) its linear drag b (1e-3: b is the linearization of the
    last iterate's σ, within the fixed point's tolerance); planar: x only (y has no
    velocity, z no drag area)."""
    res, cls, bodies, clin, loads, infl, w, spectra = two_leg
    (body,) = bodies
    comp = body_drag_components(bodies, 2.0, loads, clin.body_motion, w, spectra)
    sig = np.sqrt(np.sum(np.abs(comp.lines) ** 2, axis=(0, 2)))
    live = [k for k, s in enumerate(sig) if s > 0]
    assert [comp.where[k] for k in live] == [(body.name, 0)]
    for k in live:
        i = comp.where[k][1]
        assert sig[k] == pytest.approx(clin.body_sigma[body.name][i], rel=1e-9)
        b = comp.scale[k] * sig[k] * comp.coeffs[k, 1]
        assert b == pytest.approx(clin.body_drag[body.name][i], rel=1e-3)


def test_drag_point_transfer_equals_the_assembled_system(two_leg):
    """A unit force at the drag point along x and z (frequencies to 3·ω_max): the body
    DOFs and both legs' end tensions of the group's solves equal the assembled
    lines–body system's, loaded by the force's generalized force Tᵀe_i and solved
    directly, to 1e-9 of the largest (measured ~1e-13; the dense solve's
    conditioning)."""
    res, cls, bodies, clin, loads, infl, w, spectra = two_leg
    (body,) = bodies
    wt = np.linspace(0.05, 3.0 * w[-1], 23)
    where = ((body.name, 0), (body.name, 2))
    got = drag_point_transfer(infl, where, wt)  # (2·2 + 3, 2, n_w)
    system, damp = _assembled(cls, bodies, clin)
    f = np.stack([drag_point_link(body)[i] for _, i in where], axis=1)  # (d, 2)
    x = solve_coupled_direct(
        system, coupled_load(system, wt, body_loads={body.name: np.broadcast_to(
            f, (wt.size,) + f.shape)}), wt, "dense")  # fmt: skip
    ref = []
    for c in cls:
        m = c.system.model
        u = expand_line(system, c.name, x)
        cm = m.Cs + damp[c.name].matrix
        ends = np.r_[np.arange(m.dim), np.arange((m.n_nodes - 1) * m.dim, m.n_nodes * m.dim)]
        r = np.stack([-((m.K - wi**2 * (m.M + m.Ma) + 1j * wi * cm) @ u[i])[ends]
                      for i, wi in enumerate(wt)])  # fmt: skip
        ten = end_tension_from_support(c.system, r)
        ref.append(np.stack([ten["end_a"], ten["end_b"]]))  # (2, 2 cases, n_w)
    ref.append(np.transpose(x[:, system.body_dofs[body.name]], (1, 2, 0)))
    ref = np.concatenate(ref)
    assert np.abs(ref[:4]).max() > 0 and np.abs(ref[4:]).max() > 0
    for rows in (slice(0, 4), slice(4, None)):  # (tensions, motions: their own scales)
        np.testing.assert_allclose(
            got[rows], ref[rows], rtol=0, atol=1e-9 * np.abs(ref[rows]).max()
        )


def test_body_drag_residual_with_leg_panels_equals_monte_carlo(two_leg):
    """The body's x drag component and the largest-σ normal panel of each leg as one set
    of jointly Gaussian components (their actual velocity lines, c, means; orders to 7)
    through both legs' end tensions and the body's DOFs: the closed form's body part
    (the sum over the three less the sum over the two panels) against the mean over
    Gaussian realizations (fixed seed, 2000) of the sampled forces — the body's
    c|U + v|(U + v) less its linearization (c·E|v|v + b·v, b the fixed point's), the
    panels' residuals likewise — filtered by the same outputs, the variance with the
    body's less without: within 4 standard errors plus 1e-3 of the largest (the
    orders above 7); its cross terms with the panels (the body part less the body's
    own sum) are beyond 4 standard errors at the body's surge."""
    res, cls, bodies, clin, loads, infl, w, spectra = two_leg
    (body,) = bodies
    order = 7
    bc = body_drag_components(bodies, 2.0, loads, clin.body_motion, w, spectra, order)
    bc_sig = np.sqrt(np.sum(np.abs(bc.lines) ** 2, axis=(0, 2)))
    kb = int(np.argmax(bc_sig))
    names = [c.name for c in cls]
    t_body = drag_point_transfer(infl, [bc.where[kb]], bc.w_out)
    pick, transfer, lines = [], [t_body], [bc.lines[:, [kb]]]
    for c in cls:
        comp = drag_components(c.system, c.channels, clin.lines[c.name], order, False)
        assert np.array_equal(comp.w_out, bc.w_out)
        sig = np.sqrt(np.sum(np.abs(comp.lines) ** 2, axis=(0, 2)))
        p = int(np.argmax(sig[: len(comp.groups)]))
        h = [load_transfer(c.system, clin.lines[c.name].damping, comp.unit[:, :, [p]],
                           comp.w_out, infl[c.name] if t == c.name else dict(
                               (s.name, i) for s, i in infl[t].sources())[c.name])
             for t in names]  # fmt: skip
        h.append(load_transfer(c.system, clin.lines[c.name].damping, comp.unit[:, :, [p]],
                               comp.w_out, BodyCoupledInfluence(infl[c.name])))  # fmt: skip
        pick.append((comp.scale[p], comp.coeffs[p], sig[p]))
        transfer.append(np.concatenate(h))
        lines.append(comp.lines[:, [p]])
    lines_all = np.concatenate(lines, axis=1)
    h_all = np.concatenate(transfer, axis=1)  # (4 ends + 3 DOFs, 3 components, n_o)
    scale = np.array([bc.scale[kb]] + [s for s, _, _ in pick])
    coeffs = np.stack([bc.coeffs[kb]] + [a for _, a, _ in pick])
    n_fft = bc.n_fft
    closed = (residual_output_lines(lines_all, scale, coeffs, h_all, n_fft)
              - residual_output_lines(lines_all[:, 1:], scale[1:], coeffs[1:], h_all[:, 1:],
                                      n_fft)).sum(axis=1)  # fmt: skip
    own = residual_output_lines(lines_all[:, :1], scale[:1], coeffs[:1], h_all[:, :1], n_fft)
    own = own.sum(axis=1)
    # the means U = μσ: the body's its current, the panels' recovered from a_k
    mus = np.linspace(-10.0, 10.0, 4001)
    table = hermite_coefficients(mus, order)
    mu = [float(np.asarray(loads[body.name].current)[0]) / bc_sig[kb]] + [
        float(mus[np.argmin(np.abs(table - a).sum(axis=1))]) for _, a, _ in pick
    ]
    sigs = [bc_sig[kb]] + [s for _, _, s in pick]
    b_lin = clin.body_drag[body.name][0]
    rng = np.random.default_rng(18)
    samples = []
    for _ in range(2000):
        x = _velocities(rng, lines_all, n_fft)
        r = np.empty_like(x)
        for p in range(3):
            sg, s = sigs[p], scale[p]
            v = mu[p] * sg + x[p]
            a = hermite_coefficients([mu[p]], 1)[0]
            fit = s * sg**2 * a[0] + (b_lin if p == 0 else s * sg * a[1]) * x[p]
            r[p] = s * np.abs(v) * v - fit
        samples.append(_body_growth(h_all, r, n_fft))
    se = _agree(closed, np.array(samples), 4)
    assert abs(closed[4] - own[4]) > 4.0 * se[4]  # (surge: the cross terms count)


def _quiet(doc):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return analyze(doc)


def _single_leg(residuals: bool) -> dict:
    doc = load_example("tuah_1982_disc_buoy_single_leg").model_dump(mode="json")
    doc["analysis"]["linearization"].update(drag_residual=residuals, geometric_residual=residuals)
    doc["analysis"].pop("timeseries", None)
    return doc


def test_the_analysis_adds_the_body_drag_residual(monkeypatch):
    """The single-leg buoy: with the body's drag residual the body's surge variance and
    the leg's end tensions' drag residual lines gain the function's lines (exactly:
    they are one more part), its corrected spectra keep their area = σ², its end
    element and fairlead node move alike; without it (the function answering None)
    the analysis of before; switches off: none."""
    seen = []
    real = group_results.body_drag_residual

    def spy(*a, **k):  # noqa: ANN002, ANN003, ANN202
        out = real(*a, **k)
        seen.append(out)
        return out

    monkeypatch.setattr(group_results, "body_drag_residual", spy)
    on = _quiet(_single_leg(True))
    (own,) = seen
    monkeypatch.setattr(group_results, "body_drag_residual", lambda *a, **k: None)
    before = _quiet(_single_leg(True))
    (b1,), (b0,) = on.bodies.values(), before.bodies.values()
    added = float(own.body[0].sum())
    assert b1.motion["surge"].std ** 2 == pytest.approx(b0.motion["surge"].std ** 2 + added)
    # heave hardly moves (measured −9e-7 relative): the residual's load is the drag
    # point's, whose heave share the stiff, radiation-damped heave takes up
    assert b1.motion["heave"].std == pytest.approx(b0.motion["heave"].std, rel=1e-5)
    leg1, leg0 = on.lines["leg"], before.lines["leg"]
    for k, end in enumerate(("end_a", "end_b")):
        v1 = leg1.residuals["drag_residual"].variance[end]
        v0 = leg0.residuals["drag_residual"].variance[end]
        assert v1 == pytest.approx(v0 + float(own.ends["leg"][k].sum()), rel=1e-12)
        om, dens = leg1.end_tension_density(end)
        assert np.trapezoid(dens, om) == pytest.approx(getattr(leg1, end).std ** 2, rel=1e-12)
    # the stations take it too: the end elements' tension variance and the fairlead
    # node's x variance move with the end tensions' and the body's surge (within 3 %:
    # the half element between support and element, the arm's pitch part)
    d_end = leg1.end_a.std**2 - leg0.end_a.std**2
    d_el = leg1.tension_std[0] ** 2 - leg0.tension_std[0] ** 2
    assert d_el == pytest.approx(d_end, rel=3e-2) and abs(d_end) > 100.0
    d_x = leg1.motion_std[-1][0] ** 2 - leg0.motion_std[-1][0] ** 2
    d_surge = b1.motion["surge"].std ** 2 - b0.motion["surge"].std ** 2
    assert d_x == pytest.approx(d_surge, rel=3e-2)
    monkeypatch.setattr(group_results, "body_drag_residual", real)
    off = next(iter(_quiet(_single_leg(False)).bodies.values()))
    assert off.motion_linear is None


def test_without_cross_terms_is_the_bodys_own_sum(two_leg):
    """``cross_terms=False``: the body's components alone (no panel joined)."""
    res, cls, bodies, clin, loads, infl, w, spectra = two_leg
    alone = body_drag_residual(infl, 2.0, loads, clin.body_motion, w, spectra, cross_terms=False)
    comp = alone.components
    t = drag_point_transfer(infl, comp.where, comp.w_out)
    ref = residual_output_lines(comp.lines, comp.scale, comp.coeffs, t, comp.n_fft)
    assert alone.panels == 0
    np.testing.assert_allclose(alone.body, ref[4:], rtol=1e-12, atol=0)


def test_three_leg_vector_form_equals_monte_carlo(monkeypatch):
    """The three-leg buoy (3-D legs): the body's x drag component joined as a panel of
    the vector form (its velocity the third variable, its drag the third direction)
    with the front leg's largest-σ panel (normal 2-vector and tangent; orders to 7,
    as the group's kept panel set), through the three legs' end tensions and the six
    body DOFs: the function's lines against the mean over Gaussian realizations (fixed
    seed, 2000) of the sampled forces — the body's c|v|v less b·v (b the fixed
    point's), the panel's c_n|v_n|v_n less its vector fit B·v_n (vector Borgman) and
    c_t|v_t|v_t less its fit — filtered alike, the variance with the body's less
    without: within 4 standard errors plus 1e-3 of the largest of the tensions'
    and of the DOFs' (the orders above 7)."""
    import stochcable.dynamics.residuals.body_drag_residual as bdr
    from stochcable.dynamics.linearization.formulas import drag_linear_vector
    from stochcable.dynamics.residuals.drag_residual_3d import (
        drag_components_3d,
        vector_hermite_coefficients,
    )
    from stochcable.dynamics.residuals.residual_lines import uniform_grid

    doc = load_example("tuah_1982_disc_buoy_three_legs").model_dump(mode="json")
    res, cls, bodies, clin = _group_of(doc)
    (body,) = bodies
    w = np.asarray(cls[0].channels[0].omega)
    scene = res.scene
    loads = {body.name: body_loads(body, cls[0].channels, w, scene.sea, scene.environment)}
    damp = {c.name: clin.lines[c.name].damping for c in cls}
    infl = coupled_influences(cls, bodies, damp, clin.body_drag, clin.lines)
    spectra = np.stack([ch.spectrum for ch in cls[0].channels])
    order, front = 7, cls[0]
    comp = drag_components_3d(front.system, front.channels, clin.lines[front.name], order, False)
    n_p = comp.z.shape[1]
    sig_n = np.sqrt(np.sum(np.abs(comp.z[:, :, :2]) ** 2, axis=(0, 3)))
    grid = uniform_grid(w)
    raw = {k: grid.lines(v, spectra) for k, v in comp.pan.items()}  # (n_ch', n_p, n_j)
    var_n = sum(np.sum(np.abs(raw[k]) ** 2, axis=(0, 2)) for k in ("n1", "n2"))
    p = int(np.argmax(var_n))
    assert sig_n[p].max() > 0  # (the front leg moves in the sea's plane: n2 at rest)
    cols = [p, n_p + p, 2 * n_p + p]
    one = bdr.dataclasses.replace(
        comp, z=comp.z[:, [p]], coeffs=comp.coeffs[[p]], unit=comp.unit[:, :, cols]
    )
    monkeypatch.setattr(bdr, "_panel_sets", lambda _: (("drag_3d",), [(front.name, one)]))
    got = body_drag_residual(infl, 2.0, loads, clin.body_motion, w, spectra, order=order)
    assert got.panels == 1
    closed = np.concatenate([np.concatenate(list(got.ends.values())), got.body]).sum(axis=1)
    # the same forces sampled: the body's x and the panel's (n1, n2, t) velocities
    bc = got.components
    kb = [k for k, wh in enumerate(bc.where) if wh[1] == 0][0]
    lines = np.concatenate(
        [bc.lines[:, [kb]], raw["n1"][:, [p]], raw["n2"][:, [p]], raw["t"][:, [p]]], axis=1
    )
    sig = np.sqrt(np.sum(np.abs(lines) ** 2, axis=(0, 2)))
    vn = lines[:, 1:3]
    cov = np.einsum("caj,cbj->ab", vn.conj(), vn).real
    a_unit = vector_hermite_coefficients(np.zeros((1, 2)), cov[None], order, False)[0][0]
    big = np.unravel_index(np.argmax(np.abs(a_unit)), a_unit.shape)
    scale_n = float(one.coeffs[0, :2, :, :, 0][big] / a_unit[big])
    np.testing.assert_allclose(
        one.coeffs[0, :2, :, :, 0], scale_n * a_unit, rtol=0, atol=1e-9 * abs(scale_n)
    )
    a_t = hermite_coefficients([0.0], order)[0]
    scale_t = one.coeffs[0, 2, 0, 0, 1] / (sig[3] ** 2 * a_t[1])
    b_n = drag_linear_vector(1.0, 1.0, 2.0, cov, np.zeros(2))
    b_x = clin.body_drag[body.name][0]
    c_x = bc.scale[kb]
    t_body = drag_point_transfer(infl, [bc.where[kb]], bc.w_out)  # (12, 1, n_o)
    names = [c.name for c in cls]
    h = [load_transfer(front.system, damp[front.name], one.unit, bc.w_out, infl[t]
                       if t == front.name else dict((s.name, i) for s, i in
                                                    infl[t].sources())[front.name])
         for t in names]  # fmt: skip
    h.append(load_transfer(front.system, damp[front.name], one.unit, bc.w_out,
                           BodyCoupledInfluence(infl[front.name])))  # fmt: skip
    h_all = np.concatenate([t_body, np.concatenate(h)], axis=1)  # (12, 4, n_o)
    n_fft = bc.n_fft
    rng = np.random.default_rng(181)
    samples = []
    for _ in range(2000):
        v = _velocities(rng, lines, n_fft)
        r = np.empty_like(v)
        r[0] = c_x * np.abs(v[0]) * v[0] - b_x * v[0]
        r[1:3] = scale_n * (np.linalg.norm(v[1:3], axis=0) * v[1:3] - b_n @ v[1:3])
        r[3] = scale_t * (np.abs(v[3]) * v[3] - sig[3] ** 2 * a_t[1] * v[3] / sig[3])
        samples.append(_body_growth(h_all, r, n_fft))
    _agree(closed, np.array(samples), 6)


def test_first_pairs_are_the_growth_of_the_vector_sum():
    """``vector_residual_output_lines(..., first=k)`` (the pairs whose first panel is
    one of the first k) equals the full sum less the sum over the other panels, to
    round-off (1e-10 of the largest line), on random jointly Gaussian panels."""
    from stochcable.dynamics.residuals.drag_residual_3d import vector_residual_output_lines

    rng = np.random.default_rng(7)
    n_ch, n_p, n_j, k1, n_fft = 3, 5, 12, 4, 96
    z = rng.standard_normal((n_ch, n_p, 3, n_j)) + 1j * rng.standard_normal((n_ch, n_p, 3, n_j))
    z /= np.sqrt(np.sum(np.abs(z) ** 2, axis=(0, 3)))[None, :, :, None]
    coeffs = rng.standard_normal((n_p, 3) + (k1,) * 3)
    coeffs[..., :2, :2, :2] = 0.0  # (orders ≥ 2 only, as the residual's)
    t = rng.standard_normal((4, n_p, 3, 30)) + 1j * rng.standard_normal((4, n_p, 3, 30))
    full = vector_residual_output_lines(z, coeffs, t, n_fft)
    rest = vector_residual_output_lines(z[:, 2:], coeffs[2:], t[:, 2:], n_fft)
    got = vector_residual_output_lines(z, coeffs, t, n_fft, first=2)
    np.testing.assert_allclose(got, full - rest, rtol=0, atol=1e-10 * np.abs(full).max())
