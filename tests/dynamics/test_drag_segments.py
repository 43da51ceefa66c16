"""Where the drag residual is evaluated (stochcable.dynamics.residuals.drag_segments) and the
linear part it gains there: the pieces of split elements integrate to their element's
kinematics, their loads to a unit force at their centroid; the decomposition of the
pointwise dropped drag (the linear misfit of the element-constant B, correlated with
the linear response, plus the Hermite residual, uncorrelated with it) against
Monte-Carlo Gaussian realizations of the same model; and the inclined guy's corrected
σ against the nonlinear time domain."""

from __future__ import annotations

import math
import warnings
from types import SimpleNamespace

import numpy as np
import pytest
from scipy import stats

import stochcable.dynamics.residuals.drag_residual as dr
import stochcable.dynamics.residuals.drag_segments as drag_segments
from stochcable import analyze, load_example, load_scene
from stochcable.cases import run_cases, scatter_from_rows
from stochcable.dynamics.loads.channels import line_channels
from stochcable.dynamics.model.system import build_line_system
from stochcable.dynamics.residuals.drag_misfit import misfit_scales
from stochcable.dynamics.residuals.drag_residual import hermite_coefficients, residual_output_lines
from stochcable.dynamics.residuals.drag_segments import (
    MAX_SUB,
    Segments,
    panel_groups,
    panel_loads,
    segment_velocity,
    segments,
)
from stochcable.dynamics.residuals.residual_lines import element_directions
from stochcable.reference.cable import simulate_line_timedomain
from stochcable.statics import solve_statics


def _line(name: str, doc: dict | None = None):
    """The example ``name``'s (or ``doc``'s) first line: system, channels, drag scale."""
    scene = load_scene(doc if doc is not None else load_example(name).model_dump(mode="json"))
    line = scene.lines[0]
    system = build_line_system(scene, line, solve_statics(scene).lines[line.name])
    chans = line_channels(scene, line, system.positions, scene.analysis.omega.values())
    mesh = system.model.mesh
    scale = 0.5 * system.model.rho * mesh.diameter * (mesh.cd_normal + math.pi * mesh.cd_axial)
    return system, chans, scale


def test_pieces_integrate_to_their_elements_kinematics():
    """The inclined guy: its top elements (the surface element's wave-velocity variance
    varies ×2 along it) are split, within the budget (half of MAX_PANELS), the deep
    ones not; the pieces' fluid velocities, length-weighted, are the element means
    the linear model loads with (exact integrals over the pieces: to round-off).  The
    taut wire (10 m below the surface) has nothing to split."""
    system, chans, scale = _line("inclined_guy")
    seg = segments(system, chans, scale, dr.MAX_PANELS)
    parts = np.bincount(seg.element, minlength=system.model.n_elements)
    assert parts[-1] > 1 and parts[0] == 1 and parts.max() <= MAX_SUB
    assert parts[parts > 1].sum() <= dr.MAX_PANELS // 2
    n_w, n_dof = chans[0].omega.size, system.model.n_nodes * system.model.dim
    resp = SimpleNamespace(omega=chans[0].omega, displacement=np.zeros((n_w, n_dof, len(chans))))
    tang, normal = element_directions(system)
    v = segment_velocity(system, chans, resp, seg, {"normal": normal, "axial": tang})
    for name, vec in (("normal", normal), ("axial", tang)):
        moments = chans[0].element_velocity_parts.full()  # (the sea's parts)
        whole = np.einsum("wed,ed->ew", moments.sum(axis=2), vec)
        for e in np.flatnonzero(parts > 1):
            s_ = np.flatnonzero(seg.element == e)
            mean = (seg.length[s_, None] * v[name][0, s_]).sum(axis=0) / seg.length[s_].sum()
            np.testing.assert_allclose(mean, whole[e], rtol=1e-9, atol=1e-12 * abs(whole[e]).max())
    system, chans, scale = _line("taut_wire")
    assert not segments(system, chans, scale, dr.MAX_PANELS).fine.any()


def test_panel_loads_are_unit_forces_at_the_panels_centroids():
    """Every panel's nodal loads add up to the unit force along its direction, and their
    first moment puts it at the length-weighted centroid of its pieces; the pieces of a
    split element are panels of their own, whole elements are grouped (⌈160/32⌉ = 5 at
    a time for 160 elements)."""
    system, chans, scale = _line("inclined_guy")
    model = system.model
    seg = segments(system, chans, scale, dr.MAX_PANELS)
    groups = panel_groups(seg, dr.MAX_PANELS)
    assert len(groups) <= dr.MAX_PANELS + 1
    assert all(g.size == 1 for g in groups if seg.fine[g[0]])
    _, normal = element_directions(system)
    unit = panel_loads(model, seg, groups, [normal])
    comps = list(model.components)
    x = np.asarray(system.positions)[:, comps]
    for q, g in enumerate(groups):
        e = seg.element[g]
        share = seg.length[g] / seg.length[g].sum()
        np.testing.assert_allclose(
            unit[:, :, q].sum(axis=0), share @ normal[e][:, comps], atol=1e-12
        )
        at = x[e] + seg.xi[g, None] * (x[e + 1] - x[e])
        mag = np.linalg.norm(unit[:, :, q], axis=1)
        # (the normals of a group's neighbouring elements differ slightly: a shared node's
        # load magnitude is not quite the sum of its shares, 1e-9 on 5-element groups)
        np.testing.assert_allclose(mag @ x / mag.sum(), share @ at, rtol=1e-8)
    whole = Segments(np.arange(160), np.zeros(160), np.ones(160), np.ones(160), np.zeros(160, bool))
    assert len(panel_groups(whole, dr.MAX_PANELS)) == 32


def _chain_in(tp: float):
    """The chain example's system and channels in a JONSWAP sea, Hs 5 m, Tp ``tp``."""
    doc = load_example("chain_catenary").model_dump(mode="json")
    doc["sea"]["spectrum"] = {"type": "jonswap", "hs": 5.0, "tp": tp}
    return _line("chain_catenary", doc)


def test_the_grouping_is_the_meshs_and_the_pieces_move_continuously():
    """The chain (40 elements) in seas of Tp 8 and 14 s: its whole elements are grouped
    within the same tiles of ⌈40/32⌉ = 2 elements whatever the sea (before: groups of
    2 or 3 by the sea's variance, the fairlead σ's correction stepping by 2.4e-3
    between periods 0.5 s apart); a split element's pieces, but for the last, are
    1/want of it long, so a piece appears at zero length (a sea between two whole
    numbers of pieces: its last piece shorter than the others)."""
    for tp in (8.0, 14.0):
        system, chans, scale = _chain_in(tp)
        seg = segments(system, chans, scale, dr.MAX_PANELS)
        groups = panel_groups(seg, dr.MAX_PANELS)
        for g in groups:
            assert np.unique(seg.element[g] // 2).size == 1
        split = np.flatnonzero(np.bincount(seg.element) > 1)
        assert split.size > 0
        lengths = [(seg.hi - seg.lo)[seg.element == e] for e in split]
        # Tp 8 s: six elements want 2.4–4.3 pieces, the budget (16) caps them at two equal
        # pieces; Tp 14 s: seven, uneven (want not whole)
        assert any(np.ptp(x) > 0.05 for x in lengths) == (tp == 14.0)
    # equal pieces with the evaluation before (CONTINUOUS_PIECES false)
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(drag_segments, "CONTINUOUS_PIECES", False)
        seg = segments(system, chans, scale, dr.MAX_PANELS)
    for e in np.flatnonzero(np.bincount(seg.element) > 1):
        assert np.ptp((seg.hi - seg.lo)[seg.element == e]) < 1e-12


def test_corrections_are_smooth_in_the_period():
    """The chain's fairlead σ correction (corrected over linear σ) at Hs 5 m over Tp
    8–12 s in steps of 0.5 s: neighbours within 6e-4 (measured ≤ 4.3e-4, where an
    element starts to split or a tile is cut; before the fixed tiles 2.4e-3): what
    lets a load-case set interpolate the corrections between few computed periods
    (docs/benchmarks/cases.md)."""
    tps = np.arange(8.0, 12.01, 0.5)
    rows = [{"hs": 5.0, "tp": t, "heading": 0.0, "probability": 1 / tps.size} for t in tps]
    sd = scatter_from_rows(rows)
    doc = load_example("chain_catenary").model_dump(mode="json")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        on = run_cases(doc, sd, residual_tolerance=None).stats["leg1"]["end_b"][:, 1]
        doc["analysis"]["linearization"].update(drag_residual=False, geometric_residual=False)
        off = run_cases(doc, sd).stats["leg1"]["end_b"][:, 1]
    ratio = on / off
    assert np.all(ratio > 1.03)
    assert np.abs(np.diff(ratio)).max() < 6e-4


@pytest.mark.slow
def test_corrected_sigma_holds_under_mesh_refinement():
    """The inclined guy's FD σ with the drag residual on 40 and 160 elements: the linear
    σ falls by 7.5 % (one B per element on the 14 m deep top element), the corrected
    one moves by 3 % (the reference TD by ≈ 1 %); whole elements grouped into panels
    near the surface would bring the even-split overshoot back (160 elements in
    groups of three: +38 %), so the groups there stay single."""
    out = {}
    for n in (40, 160):
        doc = load_example("inclined_guy").model_dump(mode="json")
        doc["lines"][0]["segments"][0]["elements"] = n
        doc["analysis"]["linearization"]["drag_residual"] = True
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            out[n] = analyze(doc).lines["guy"]
    assert out[160].linear_end("end_b").std / out[40].linear_end("end_b").std < 0.94
    for end in ("end_a", "end_b"):
        cor = out[160].drag_residual.std[end] / out[40].drag_residual.std[end]
        assert 1.0 < cor < 1.04
    assert out[160].drag_residual.ratio("end_b") < 1.34


def test_misfit_plus_hermite_equal_monte_carlo_of_the_pointwise_drag():
    """One element split in three pieces whose velocity σ decay 1 : 0.6 : 0.35 (a
    surface element), one whole element, one channel, outputs through
    frequency-dependent filters, and a linear response correlated with the
    velocities: the variance the pointwise drag c|v_s|v_s·l_s adds to the linear model
    with the element-constant B_e (its mean-variance fit) — over Gaussian realizations —
    equals the closed form: the misfit δB_s·l_s·v_s (:func:`drag_misfit.misfit_scales`,
    its cross term with the linear response included) plus the Hermite residual
    (orders 2…9, no cross term).  Tolerance: 4 standard errors of the Monte-Carlo
    mean (paired: the linear part of each realization subtracted)."""
    rng = np.random.default_rng(11)
    n_j, n_fft, order = 40, 1024, 9
    j = np.arange(n_j)
    shape = np.exp(-0.5 * ((j - 12) / 4.0) ** 2) * (j > 0)
    amp = np.array([1.0, 0.6, 0.35, 0.2])
    lines = (amp[:, None] * shape * np.exp(-0.3j * np.arange(4)[:, None] * j))[None]
    seg = Segments(
        element=np.array([0, 0, 0, 1]),
        lo=np.array([0.0, 1 / 3, 2 / 3, 0.0]),
        hi=np.array([1 / 3, 2 / 3, 1.0, 1.0]),
        length=np.array([2.0, 2.0, 2.0, 6.0]),
        fine=np.array([True, True, True, False]),
    )
    groups = [np.array([i]) for i in range(4)]
    c = 1.5
    sig = np.sqrt((np.abs(lines) ** 2).sum(axis=(0, 2)))
    var_e = np.array([np.mean(sig[:3] ** 2), sig[3] ** 2])
    b_el = c * math.sqrt(8.0 / math.pi) * np.sqrt(var_e)  # the FD's B of each element
    misfit = misfit_scales(seg, groups, np.full(2, c), np.zeros(2), b_el, sig)
    assert misfit[3] == 0.0 and misfit[0] > 0 > misfit[2]
    coeffs = hermite_coefficients(np.zeros(4), order)
    n_o = order * (n_j - 1)
    jo = np.arange(1, n_o + 1)
    transfer = np.stack(
        [
            np.stack([np.exp(-0.1j * s * jo) / (1 + 1j * (jo - 15 - s) / 3.0) for s in range(4)]),
            np.stack([(0.5 + 0.1 * s) * np.ones(n_o) for s in range(4)]),
        ]
    ).astype(complex)  # (n_out, n_s, n_o)
    gain = np.stack([0.7 * transfer[:, s, : n_j - 1] for s in range(4)], axis=1)
    h_lin = np.einsum("osj,sj->oj", gain, lines[0, :, 1:])  # linear output lines
    hermite = residual_output_lines(lines, c * seg.length, coeffs, transfer, n_fft).sum(axis=1)
    h_c = np.einsum("osj,s,sj->oj", transfer[:, :, : n_j - 1], misfit, lines[0, :, 1:])
    closed = hermite + (np.abs(h_lin + h_c) ** 2 - np.abs(h_lin) ** 2).sum(axis=1)
    b_s = b_el[seg.element]
    samples = []
    for _ in range(800):
        a = (rng.standard_normal(n_j) + 1j * rng.standard_normal(n_j)) / math.sqrt(2)
        spec = np.zeros((4, n_fft // 2 + 1), dtype=complex)
        spec[:, :n_j] = math.sqrt(2.0) * a * lines[0]
        v = np.fft.irfft(spec, n=n_fft, axis=1) * (0.5 * n_fft)
        load = seg.length[:, None] * (c * np.abs(v) * v - b_s[:, None] * v)
        rf = np.fft.rfft(load, axis=1)[:, 1 : n_o + 1] * (2.0 / n_fft)
        y = np.einsum("osj,sj->oj", transfer, rf) / math.sqrt(2.0)
        lin = h_lin * a[1:]
        y[:, : n_j - 1] += lin
        samples.append((np.abs(y) ** 2).sum(axis=1) - (np.abs(lin) ** 2).sum(axis=1))
    samples = np.array(samples)
    mc, se = samples.mean(axis=0), samples.std(axis=0, ddof=1) / math.sqrt(len(samples))
    assert np.all(np.abs(closed - mc) < 4.0 * se + 1e-4 * np.abs(closed))
    # without the misfit (the residual relative to each piece's own fit) it is off
    assert np.any(np.abs(hermite - mc) > 4.0 * se)


@pytest.mark.slow
def test_inclined_guy_corrected_sigma_within_the_time_domain_interval():
    """The inclined guy in its sea on the example's 40 elements: the FD end σ with the
    drag residual lies within the 95 % interval of the reference TD's mean (seeds 1–5,
    1200 s records without the first 200 s, the analysis band; Student t), where the
    linear FD alone (−16 %) and the residual on whole elements (+16 %, before the
    split) do not.  ≈ 30 s."""
    doc = load_example("inclined_guy").model_dump(mode="json")
    doc["analysis"].pop("timeseries", None)
    doc["analysis"]["linearization"].update(tolerance=1e-8, drag_residual=True)
    scene = load_scene(doc)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        line = analyze(scene).lines["guy"]
        band = (float(line.omega[0]), float(line.omega[-1]))
        td = []
        for seed in range(1, 6):
            h = simulate_line_timedomain(scene, duration=1200.0, seed=seed, band=band)
            keep = h.t >= 200.0
            td.append([h.tension_b[keep].std(), h.tension_a[keep].std()])
    td = np.array(td)
    mean = td.mean(axis=0)
    half = stats.t.ppf(0.975, len(td) - 1) * td.std(axis=0, ddof=1) / math.sqrt(len(td))
    res = line.drag_residual
    for k, end in enumerate(("end_b", "end_a")):
        assert abs(res.std[end] - mean[k]) < half[k]
        assert abs(res.std_linear[end] - mean[k]) > 2 * half[k]


def test_panel_mean_of_complex_values_by_one_real_product():
    """drag_segments.panel_mean of complex (n_a, n_s, n_w) values (the shares times
    the interleaved real view) against the former complex product with the shares
    upcast: to round-off (1e-15 of the largest; equal on the benchmark lines), real
    values and a 1-D array unchanged."""
    dsg = drag_segments

    rng = np.random.default_rng(12)
    lengths = rng.uniform(0.5, 2.0, 9)
    seg = dsg.Segments(
        element=np.arange(9), lo=np.zeros(9), hi=np.ones(9), length=lengths,
        fine=np.zeros(9, dtype=bool), ends=None,
    )  # fmt: skip
    groups = [np.array([0, 1, 2]), np.array([3]), np.array([4, 5, 6, 7, 8])]
    share = dsg.panel_share(seg, groups)
    values = rng.normal(size=(3, 9, 17)) + 1j * rng.normal(size=(3, 9, 17))
    ref = np.moveaxis(np.moveaxis(values, 1, 2) @ share, 2, 1)
    got = dsg.panel_mean(values, seg, groups, share)
    assert got.shape == ref.shape == (3, 3, 17)
    assert np.max(np.abs(got - ref)) <= 1e-15 * np.max(np.abs(ref))
    real = np.moveaxis(np.moveaxis(values.real, 1, 2) @ share, 2, 1)
    assert np.array_equal(dsg.panel_mean(values.real, seg, groups), real)
    assert np.array_equal(dsg.panel_mean(lengths, seg, groups), lengths @ share)
