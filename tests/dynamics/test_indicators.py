"""Linearization quality indicators (GitHub issue 7 item 3): Borgman variance ratio,
drag/inertia size, snap, near-undamped resonance and large-motion flags."""

from __future__ import annotations

import copy
import dataclasses
import json
import math
import warnings

import numpy as np
import pytest
from _paths import ROOT
from scipy import integrate

from stochcable.analysis import analyze
from stochcable.dynamics.groups.line_fixed_point import linearize
from stochcable.dynamics.linearization.formulas import borgman_variance_ratio, drag_inertia_ratio
from stochcable.dynamics.loads.channels import line_channels
from stochcable.dynamics.model.system import build_line_system
from stochcable.dynamics.outputs.indicators import AT_REST_FRACTION, at_rest_zeroed, line_indicators
from stochcable.errors import InputError, PhysicsWarning
from stochcable.scene.model import load_scene
from stochcable.statics import solve_statics

EXAMPLES = ROOT / "stochcable" / "examples"
# Zero-mean Gaussian: Var(Bv)/Var(c v|v|) = (8/pi) c² σ⁴ / (3 c² σ⁴) (Borgman 1972)
BORGMAN_ZERO_MEAN = 8.0 / (3.0 * math.pi)


def _doc(name: str) -> dict:
    d = json.loads((EXAMPLES / f"{name}.json").read_text())
    d["analysis"].pop("timeseries", None)
    return d


def _analyze_quiet(doc: dict):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return analyze(doc)


# ------------------------------------------------------------------ Borgman ratio


def test_borgman_ratio_zero_mean_is_8_over_3pi():
    sig = np.array([1e-3, 0.2, 1.0, 7.0])
    # exact closed form, any σ: only round-off
    np.testing.assert_allclose(borgman_variance_ratio(sig), BORGMAN_ZERO_MEAN, rtol=1e-14)


def _moments_by_quadrature(mu: float) -> float:
    """Var(Bv)/Var(v|v|) for v ~ N(mu, 1) by adaptive quadrature split at the kink."""
    pdf = lambda v: math.exp(-0.5 * (v - mu) ** 2) / math.sqrt(2 * math.pi)  # noqa: E731

    def e(f):
        lo, hi = mu - 12.0, mu + 12.0
        pts = [0.0] if lo < 0.0 < hi else None
        return integrate.quad(
            lambda v: f(v) * pdf(v), lo, hi, points=pts, epsabs=0, epsrel=1e-13, limit=200
        )[0]

    e_abs = e(abs)
    e_vv = e(lambda v: v * abs(v))
    e_v4 = e(lambda v: v**4)
    return 4.0 * e_abs**2 / (e_v4 - e_vv**2)


@pytest.mark.parametrize("mu", [0.3, 0.76, 1.5, 4.0, 8.0, 9.0, 20.0])
def test_borgman_ratio_with_current_matches_quadrature(mu):
    got = borgman_variance_ratio(0.5, 0.5 * mu)  # only U/σ matters
    # quadrature to ~1e-12; the closed form's erf/exp to round-off
    assert got == pytest.approx(_moments_by_quadrature(mu), rel=1e-9)
    assert got == pytest.approx(borgman_variance_ratio(0.5, -0.5 * mu), rel=1e-14)


def test_borgman_ratio_with_current_matches_monte_carlo():
    rng = np.random.default_rng(20240607)
    sigma, u = 0.4, 0.3
    n = 2_000_000
    v = u + sigma * rng.standard_normal(n)
    c = 0.5 * 1025.0 * 1.2 * 0.1
    b = 2.0 * c * np.mean(np.abs(v))  # B = ρ Cd D E|v| = 2c E|v|
    ratio_mc = np.var(b * v) / np.var(c * v * np.abs(v))
    # relative sampling error of a variance ~ sqrt(Var(x²)/n)/Var(x); the v|v| tail
    # (kurtosis ~ 10) gives ~ 2e-3 at n = 2e6: 5 standard errors
    assert borgman_variance_ratio(sigma, u) == pytest.approx(ratio_mc, rel=1e-2)


def test_borgman_ratio_limits_and_range():
    # σ → 0 with a current: a small fluctuation about U is linear (ratio 1);
    # σ = U = 0: the zero-mean value by scale invariance
    assert borgman_variance_ratio(0.0, 0.5) == 1.0
    assert borgman_variance_ratio(0.0, 0.0) == pytest.approx(BORGMAN_ZERO_MEAN, rel=1e-14)
    # continuity across the switch to the large-|U|/σ form (8.5): smooth to 1e-10
    lo, hi = borgman_variance_ratio(1.0, [8.5 - 1e-9, 8.5 + 1e-9])
    assert hi == pytest.approx(lo, rel=1e-9)
    mu = np.linspace(0.0, 30.0, 3001)
    r = borgman_variance_ratio(np.ones_like(mu), mu)
    assert r.min() == pytest.approx(0.8222, abs=1e-4) and r.max() < 1.0
    with pytest.raises(InputError, match="sigma.*m/s"):
        borgman_variance_ratio(-1.0)


# ------------------------------------------------------------ drag / inertia


def test_elements_at_rest_take_the_limits():
    """Grounded chain barely moves (σ falls by ~100 per element away from the
    touchdown, to round-off): σ and current below 1e-6 of the line's largest are zero
    for the indicators, so the Borgman ratio takes its σ → 0 limits (1 with a normal
    current, 8/(3π) without) and the drag/inertia ratio 0, the same on every machine;
    the moving part keeps its values."""
    s, u = at_rest_zeroed(np.array([1.0, 2e-7, 5e-13, 0.5]), np.array([0.3, 0.2, 1e-15, 0.0]))
    np.testing.assert_array_equal(s, [1.0, 0.0, 0.0, 0.5])
    np.testing.assert_array_equal(u, [0.3, 0.2, 0.0, 0.0])
    assert borgman_variance_ratio(s, u)[1] == 1.0
    assert borgman_variance_ratio(s, u)[2] == pytest.approx(8.0 / (3.0 * math.pi), rel=1e-14)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = analyze(load_scene(EXAMPLES / "chain_catenary.json"))
    ind = res.lines["leg1"].indicators
    # grounded elements lie flat on the bed and slide along it (x): the normal
    # motion is y and z; both nodes moving less than 1e-7 m normally bound the
    # element's normal velocity σ by ω_max·1e-7 m = 2e-7 m/s, under 1e-6 of the
    # line's largest (0.73 m/s)
    node = res.lines["leg1"].motion_std[:, 1:].max(axis=1)
    grounded = np.maximum(node[:-1], node[1:]) < AT_REST_FRACTION * 0.1
    assert grounded.sum() >= 10
    limits = np.isclose(ind.borgman_ratio, 8.0 / (3.0 * math.pi), rtol=1e-14) | (
        ind.borgman_ratio == 1.0
    )
    assert np.all(limits[grounded])
    assert np.all(ind.drag_inertia_ratio[grounded] == 0.0)
    assert ind.borgman_ratio[-5:].min() > 0.0 and ind.drag_inertia_ratio[-5:].min() > 0.0


def test_drag_inertia_ratio_closed_form_and_thin_vs_thick_cylinder():
    # deep-water narrow-band wave of ω = 0.6 rad/s, σ_v = 1 m/s: σ_a = ω σ_v
    rho, cd, cm, w, sv = 1025.0, 1.2, 2.0, 0.6, 1.0
    sa = w * sv
    for d in (0.05, 0.5, 2.0, 10.0):
        kc = sv * (2 * math.pi / w) / d
        expected = math.sqrt(8 / math.pi) / math.pi**2 * cd / cm * kc
        assert drag_inertia_ratio(rho, cd, cm, d, sv, sa) == pytest.approx(expected, rel=1e-13)
    thin = drag_inertia_ratio(rho, cd, cm, 0.05, sv, sa)
    thick = drag_inertia_ratio(rho, cd, cm, 10.0, sv, sa)
    # KC_σ 209 vs 1.05: drag-dominated (20.3) vs inertia-dominated (0.10), ratio ∝ 1/D
    assert thin > 10.0 and thick < 0.15
    assert thin / thick == pytest.approx(200.0, rel=1e-13)
    # no fluid acceleration: inertia force zero
    assert drag_inertia_ratio(rho, cd, cm, 0.1, 1.0, 0.0) == math.inf
    assert drag_inertia_ratio(rho, cd, cm, 0.1, 0.0, 0.0) == 0.0


def test_drag_inertia_in_analysis_scales_like_sigma_squared_over_diameter():
    # the same taut wire, diameter x 4 and mass raised to keep the net weight (so the
    # static shape, hence σ_a of the fluid, is the same: near the seabed the vertical
    # kinematics grow linearly with height): B_n ∝ D σ_n and the inertia force
    # ∝ D² σ_a, so ratio·D/σ_n² is unchanged
    doc = _doc("taut_wire")
    thick = copy.deepcopy(doc)
    seg = thick["lines"][0]["segments"][0]
    d1 = seg["diameter"]
    seg["diameter"] = 4.0 * d1
    seg["mass"] += doc["environment"]["rho"] * math.pi / 4.0 * (seg["diameter"] ** 2 - d1**2)
    l1 = _analyze_quiet(doc).lines["wire"]
    l4 = _analyze_quiet(thick).lines["wire"]
    q1 = l1.indicators.drag_inertia_ratio / l1.linearization.sigma_normal**2
    q4 = 4.0 * l4.indicators.drag_inertia_ratio / l4.linearization.sigma_normal**2
    np.testing.assert_allclose(l4.positions, l1.positions, atol=1e-6)
    # same σ_a; b_n and σ_n of the record differ by the linearization tolerance 1e-4
    np.testing.assert_allclose(q4, q1, rtol=3e-4)
    # and the thin wire is the more drag-dominated one
    assert np.all(l1.indicators.drag_inertia_ratio > 3.0 * l4.indicators.drag_inertia_ratio)


# ------------------------------------------------------------------------ flags


def test_tuah_6_5_sigma_exceeds_mean_tension_gives_snap_warning():
    doc = _doc("tuah_1982_single_leg")
    with pytest.warns(
        PhysicsWarning,
        match=r"snap loads likely; the linear model is out "
        r"of its depth \(threshold mean − 3σ >= 0\)",
    ):
        res = analyze(doc)
    line = next(iter(res.lines.values()))
    assert line.end_a.std > line.end_a.mean  # the seed's case σ_T > T_mean
    ind = line.indicators
    assert ind.snap_risk and "snap" in ind.flags and ind.snap_margin < 0
    doc_ind = res.to_document()["lines"][line.name]["indicators"]
    assert doc_ind["snap"]["risk"] is True and "snap" in doc_ind["flags"]


def test_chain_has_no_snap_resonance_or_motion_flag():
    res = _analyze_quiet(_doc("chain_catenary"))
    ind = res.lines["leg1"].indicators
    assert ind.flags == () and not ind.snap_risk and ind.snap_margin > 0.5
    assert not any("snap" in w or "excitation band" in w for w in res.warnings)
    # current on the line: per-element ratios between the zero-mean value and 1
    assert ind.borgman_ratio.min() >= 0.8221 and ind.borgman_ratio.max() <= 1.0
    json.dumps(res.to_document())  # JSON-ready (inf -> None)


def test_near_undamped_resonance_flag_fires_and_is_cured_by_damping():
    doc = _doc("inclined_guy")
    with pytest.warns(
        PhysicsWarning,
        match=r"mode 2 \(1\.193 rad/s\) lies in the "
        r"excitation band with modal damping ratio"
        r".*threshold 1%",
    ):
        res = analyze(doc)
    ind = res.lines["guy"].indicators
    assert "resonance" in ind.flags
    r = ind.resonances[0]
    assert r["mode"] == 2 and r["damping_ratio"] < 0.01
    # Rayleigh alpha adds ζ = alpha/(2ω) = 2.1 % at 1.19 rad/s: no flag any more
    damped = copy.deepcopy(doc)
    damped["analysis"]["structural_damping"] = {"alpha": 0.05, "beta": 0.0}
    res2 = _analyze_quiet(damped)
    assert "resonance" not in res2.lines["guy"].indicators.flags
    assert not any("excitation band" in w for w in res2.warnings)


def _chain_parts():
    scene = load_scene(_doc("chain_catenary"))
    st = solve_statics(scene)
    line = scene.lines[0]
    system = build_line_system(scene, line, st.lines[line.name])
    chans = line_channels(scene, line, system.positions, scene.analysis.omega.values())
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        lin = linearize(system, chans, scene.analysis)
    return system, chans, lin


def test_large_motion_flag_threshold_against_sag():
    system, chans, lin = _chain_parts()
    res = _analyze_quiet(_doc("chain_catenary")).lines["leg1"]
    stats = {"end_a": res.end_a, "end_b": res.end_b}
    sag = res.indicators.sag
    # the chain spans 800 m x 180 m with 850 m of chain: sag of order 100 m
    assert 50.0 < sag < 200.0
    n = system.model.n_nodes
    for frac, fires in ((0.12, True), (0.08, False)):
        mot = np.zeros((n, 3))
        mot[n // 2, 0] = frac * sag
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            ind = line_indicators(system, chans, lin, res.tension_std, mot, stats)
        msgs = [str(w.message) for w in caught if issubclass(w.category, PhysicsWarning)]
        assert ind.motion_to_sag == pytest.approx(frac, rel=1e-12)
        assert ("large_motion" in ind.flags) is fires
        assert any("of the line's sag" in m and "threshold 0.1" in m for m in msgs) is fires


def test_snap_flag_fires_at_an_element_and_not_below_threshold():
    system, chans, lin = _chain_parts()
    res = _analyze_quiet(_doc("chain_catenary")).lines["leg1"]
    t = np.asarray(res.tension_mean)
    k = t.size // 2
    for factor, fires in ((0.34, True), (0.32, False)):
        std = np.zeros_like(t)
        std[k] = factor * t[k]  # 3σ = 1.02 T or 0.96 T
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            ind = line_indicators(
                system,
                chans,
                lin,
                std,
                np.zeros((t.size + 1, 3)),
                {
                    "end_a": dataclasses.replace(res.end_a, std=0.0),
                    "end_b": dataclasses.replace(res.end_b, std=0.0),
                },
            )
        msgs = [str(w.message) for w in caught]
        assert ind.snap_risk is fires
        assert any(f"element {k + 1}" in m and "snap loads likely" in m for m in msgs) is fires
        assert ind.snap_margin == pytest.approx(1.0 - 3.0 * factor, rel=1e-12)


# ------------------------------------------- lines on bodies: the coupled modes


def _line_modes_of(monkeypatch, factor: float):
    """The disc buoy's leg analysed with the buoy's mass and inertia scaled by
    ``factor`` (same statics): the coupled modes that count for the leg
    (:func:`stochcable.dynamics.groups.results.line_modes`), the leg's system and its
    converged drag."""
    from stochcable.bodies.from_scene import scene_rigid_bodies
    from stochcable.dynamics.groups import analyze_coupled
    from stochcable.dynamics.groups import results as cresults

    scene = load_scene(_doc("tuah_1982_disc_buoy_single_leg"))
    statics = solve_statics(scene, method="fe")
    scaled = {
        n: dataclasses.replace(
            b,
            mass=b.mass * factor,
            inertia=None if b.inertia is None else np.asarray(b.inertia) * factor,
        )
        for n, b in scene_rigid_bodies(scene).items()
    }
    captured: dict = {}
    line_modes = cresults.line_modes

    def spy(*args):
        captured.update(line_modes(*args))
        return captured

    monkeypatch.setattr(cresults, "line_modes", spy)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        out = analyze_coupled(scene, statics, scene.analysis, rigid_bodies=scaled)
    (group,) = out.groups
    return captured["leg"], group.systems["leg"], group.dampings["leg"], out


def _fixed_end(system, damping, top: float):
    from stochcable.dynamics.outputs.resolution import modal_bandwidths

    wn = np.asarray(system.modes.omega)
    keep = wn <= top
    return wn[keep], modal_bandwidths(system, damping)[keep]


def test_heavy_body_gives_the_fixed_end_modes(monkeypatch):
    """A body 10^6 times heavier barely moves in the leg's modes: the coupled modes
    that count for the leg (share >= LINE_MODE_SHARE) are its fixed-end modes, with
    their frequencies and bandwidths, and the body modes do not count."""
    modes, system, damping, out = _line_modes_of(monkeypatch, 1e6)
    top = float(modes.omega.max())
    wn, band = _fixed_end(system, damping, top * (1 + 1e-6))
    assert modes.omega.size == wn.size >= 3
    np.testing.assert_allclose(modes.omega, wn, rtol=1e-4)
    np.testing.assert_allclose(modes.bandwidth, band, rtol=1e-3)
    # the leg's indicator lists the same resonances as its fixed-end modes would
    for r in out.lines["leg"].indicators.resonances:
        assert np.min(np.abs(wn / r["omega"] - 1)) < 1e-4


def test_light_body_changes_the_line_modes(monkeypatch):
    """With the buoy's own mass the leg's end moves in its modes: the coupled modes
    that count for the leg are not its fixed-end modes (other frequencies and
    bandwidths: the body's motion, radiation and drag damp them too)."""
    modes, system, damping, _ = _line_modes_of(monkeypatch, 1.0)
    wn, band = _fixed_end(system, damping, float(modes.omega.max()) * (1 + 1e-3))
    assert modes.omega.size == wn.size >= 3
    # measured: the first mode 5.66 against 5.59 rad/s, its bandwidth 7.24 against
    # 7.50 rad/s (the same converged drag); the heavy body gives both to 1e-4
    assert np.max(np.abs(modes.omega / wn - 1)) > 5e-3
    assert np.max(np.abs(modes.bandwidth / band - 1)) > 2e-2


def test_large_motion_only_where_the_sag_governs_the_stiffness():
    """A taut synthetic rope (Irvine λ² = 0.05) whose fairlead surges 0.5 m on a sag of
    1.05 m is not flagged — its stiffness is elastic, and the linear model is within
    0.02 % of the time domain (docs/accuracy/lines.md) — while the same motion ratio on
    the chain (λ² ≈ 3000) is (test_large_motion_flag_threshold_against_sag)."""
    rope = {"length": 454.0, "ea": 1.5e8, "mass": 25.0, "diameter": 0.16, "cd_normal": 1.2,
            "cd_axial": 0.008, "ca_normal": 1.0, "elements": 20}  # fmt: skip
    surge = {"type": "pierson_moskowitz", "hs": 2.0, "tp": 10.0}
    doc = {
        "environment": {"depth": 200.0},
        "lines": [
            {
                "name": "taut_rope",
                "end_a": {"position": [-420.0, 0.0, -200.0]},
                "end_b": {"position": [0.0, 0.0, -20.0], "motion": {"surge": surge}},
                "segments": [rope],
            }
        ],
        "analysis": {"omega": {"min": 0.05, "max": 2.0, "count": 200}},
    }
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        ind = analyze(doc).lines["taut_rope"].indicators
    assert ind.motion_to_sag > 0.4 and ind.second_order.lambda2 < 0.1
    assert "large_motion" not in ind.flags
    assert not any("of the line's sag" in str(w.message) for w in caught)


def test_normal_projector_kept_per_line_gives_the_same_sigma():
    # the normal-plane projectors of the line's static frames are kept on the line
    # (formed once for every sea state of a set): P e = 0, P² = P, trace 2, and the
    # normal-acceleration σ the same bits from the kept and from fresh projectors
    from stochcable.dynamics.outputs import indicators

    system, chans, lin = _chain_parts()
    w = lin.response.omega
    system._cache.pop("normal_projector", None)
    first = indicators._normal_acceleration_sigma(system, chans, w)
    kept = system._cache["normal_projector"].reshape(-1, 3, 3)
    e = system.frames[0]
    np.testing.assert_allclose(np.einsum("eij,ej->ei", kept, e), 0.0, atol=1e-15)
    np.testing.assert_allclose(kept @ kept, kept, atol=1e-15)
    np.testing.assert_allclose(np.trace(kept, axis1=1, axis2=2), 2.0, rtol=1e-15)
    again = indicators._normal_acceleration_sigma(system, chans, w)  # (from the cache)
    system._cache.pop("normal_projector")
    fresh = indicators._normal_acceleration_sigma(system, chans, w)
    assert np.array_equal(first, again) and np.array_equal(first, fresh)
    assert first.max() > 0.0  # (the elements near the surface: the waves reach them)
