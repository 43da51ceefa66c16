"""Second-order stretching tension (stochcable.dynamics.residuals.second_order): the Gaussian
quadratic form against Monte Carlo, a quasi-static taut line against its closed form,
Irvine's λ*² and the indicator in the result."""

from __future__ import annotations

import copy
import json
import math
import warnings

import numpy as np
import pytest

import stochcable
from stochcable.dynamics.residuals import second_order as so
from stochcable.errors import PhysicsWarning
from stochcable.examples import load_example
from stochcable.scene.model import load_scene


def test_quadratic_form_moments_match_monte_carlo():
    # x = Re(B a), a = ξ + iη with ξ, η ~ N(0, 1): covariance Br Brᵀ + Bi Biᵀ, the
    # spectral representation's.  200,000 draws: the sample mean of xᵀx has standard
    # error σ/√N and the sample σ about σ·√((κ−1)/4N) (κ the kurtosis, ≤ 15 for a
    # quadratic form of Gaussians); 5 standard errors leave a false alarm below 1e-6.
    rng = np.random.default_rng(20261124)
    b = rng.normal(size=(6, 9)) + 1j * rng.normal(size=(6, 9))
    b[:, :3] *= 3.0  # unequal eigenvalues
    mean, std = so.quadratic_form_moments(b)
    n = 200_000
    a = rng.normal(size=(9, n)) + 1j * rng.normal(size=(9, n))
    x = (b @ a).real
    q = np.sum(x * x, axis=0)
    assert abs(q.mean() - mean) < 5 * std / math.sqrt(n)
    assert abs(q.std() - std) < 5 * std * math.sqrt(14.0 / (4 * n))


def test_quadratic_form_moments_either_gram_side():
    # tr and ‖Σ‖_F do not depend on which Gram matrix is formed (tall or wide B)
    rng = np.random.default_rng(7)
    b = rng.normal(size=(4, 30)) + 1j * rng.normal(size=(4, 30))
    c = np.concatenate([b.real, b.imag], axis=1)
    sigma = c @ c.T
    mean, std = so.quadratic_form_moments(b)
    assert mean == pytest.approx(np.trace(sigma), rel=1e-12)
    assert std == pytest.approx(math.sqrt(2 * np.sum(sigma * sigma)), rel=1e-12)
    mean_t, std_t = so.quadratic_form_moments(np.ascontiguousarray(b.T))
    ct = np.concatenate([b.T.real, b.T.imag], axis=1)
    assert mean_t == pytest.approx(np.sum(ct * ct), rel=1e-12)
    assert std_t == pytest.approx(math.sqrt(2 * np.sum((ct.T @ ct) ** 2)), rel=1e-12)


def _taut_wire_with_sway(omega_band: tuple[float, float], sigma_y: float) -> dict:
    doc = json.loads(json.dumps(load_example("taut_wire").model_dump(mode="json")))
    doc.pop("sea", None)
    w0, w1 = omega_band
    dens = sigma_y**2 / (w1 - w0)
    doc["lines"][0]["end_b"]["motion"] = {
        "sway": {"type": "table", "omega": [w0, w1], "density": [dens, dens]}
    }
    doc["analysis"]["omega"] = {"min": w0, "max": w1, "count": 201}
    return doc


def test_quasi_static_sway_of_a_taut_wire_matches_the_closed_form():
    # A slow sideways motion Y of the top of a taut wire (0.01–0.05 rad/s, the first
    # transverse mode is near 9 rad/s) turns it rigidly about the anchor: u⊥(s) = Y·s/L,
    # ½∫(u⊥')² ds = Y²/2L, so E[T₂] = EA·σ_Y²/(2L²(1 + λ*²/12)) and T₂ is a scaled χ²₁:
    # σ(T₂) = √2·E[T₂].  Dynamic and drag effects are O((ω/ω₁)²) ≈ 3e-5 and the static
    # strain (0.5 %) enters only through λ*²: 1e-3 is a safe bound.
    sigma_y = 2.0
    scene = load_scene(_taut_wire_with_sway((0.01, 0.05), sigma_y))
    r = stochcable.analyze(scene)
    lr = r.lines["wire"]
    got = lr.indicators.second_order
    seg = scene.lines[0].segments[0]
    expect = seg.ea * sigma_y**2 / (2 * seg.length**2 * (1 + got.lambda2 / 12))
    assert got.mean == pytest.approx(expect, rel=1e-3)
    assert got.std == pytest.approx(math.sqrt(2) * expect, rel=1e-3)
    assert got.lambda2 < 0.1  # a taut line: the stretching is not relieved by the sag
    doc = r.to_document()["lines"]["wire"]["indicators"]["second_order"]
    assert doc["mean"] == pytest.approx(got.mean, rel=1e-15)


def test_large_sway_flags_and_warns():
    # σ_Y = 2 m gives T₂ ≈ 5e4 N against a linear tension σ of nearly nothing (sway is
    # transverse, the linear stretching is second order): far above the 20 % threshold.
    scene = load_scene(_taut_wire_with_sway((0.01, 0.05), 2.0))
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        r = stochcable.analyze(scene)
    ind = r.lines["wire"].indicators
    assert ind.second_order.ratio > so.SECOND_ORDER_WARN_RATIO
    assert "second_order" in ind.flags
    msgs = [str(w.message) for w in caught if issubclass(w.category, PhysicsWarning)]
    assert any("second-order stretching tension" in m and "threshold 20%" in m for m in msgs)


@pytest.mark.parametrize("name", ["chain_catenary", "taut_wire", "inclined_guy"])
def test_bundled_examples_are_not_flagged(name):
    # On the bundled lines the stretching term is below 0.2 % of the linear σ (a wave-
    # loaded taut wire moves too little sideways; a catenary's sag takes the
    # lengthening up): no flag, and the moments are finite and >= 0.
    r = stochcable.analyze(load_example(name))
    for lr in r.lines.values():
        s = lr.indicators.second_order
        assert "second_order" not in lr.indicators.flags
        assert 0.0 <= s.ratio < so.SECOND_ORDER_WARN_RATIO
        assert s.mean >= 0.0 and s.std >= 0.0


def test_irvine_lambda2_of_a_shallow_horizontal_cable():
    # λ² = (wL/H)²·EA/H for a horizontal chord (Bliet 1984, eq. 3.79's parameter)
    n = 10
    x = np.linspace(0.0, 100.0, n + 1)
    pos = np.stack([x, np.zeros_like(x), np.zeros_like(x)], axis=1)
    l0 = np.full(n, 10.0)
    lam2 = so.irvine_lambda2(pos, l0, np.full(n, 2e8), np.full(n, 50.0), np.full(n, 1e5))
    assert lam2 == pytest.approx((50.0 * 100.0 / 1e5) ** 2 * 2e8 / 1e5, rel=1e-12)
    # a vertical chord: cos φ = 0; slack (no positive tension): inf
    vert = pos[:, [1, 2, 0]]
    assert so.irvine_lambda2(vert, l0, np.full(n, 2e8), np.full(n, 50.0), np.full(n, 1e5)) == 0
    assert math.isinf(so.irvine_lambda2(pos, l0, np.full(n, 2e8), np.full(n, 50.0), np.zeros(n)))


def test_deep_copy_of_indicators_keeps_second_order():
    r = stochcable.analyze(load_example("taut_wire"))
    ind = copy.deepcopy(r.lines["wire"].indicators)
    assert ind.second_order == r.lines["wire"].indicators.second_order


@pytest.mark.slow
def test_stretching_tension_against_the_nonlinear_time_domain():
    # The nonlinear time-domain reference (stochcable.reference) of the taut wire swayed
    # sideways at its top (0.2–0.5 rad/s, σ_Y = 2 m; first transverse mode ≈ 9 rad/s):
    # the linear tension is zero, the whole tension variation is the stretching term.
    # Its series must follow T₂(t) = κ·Y(t)²/2L of the realized top motion (the
    # indicator's quadratic form for this shape), and its mean shift κ·⟨Y²⟩/2L.
    # Tolerance 2 %: quasi-static error (ω/ω₁)² ≤ 0.3 %, the static strain (0.5 %) the
    # formula's unstretched lengths ignore, and the end node's inertia and drag.
    from stochcable.reference.cable import simulate_line_timedomain

    scene = load_scene(_taut_wire_with_sway((0.2, 0.5), 2.0))
    got = stochcable.analyze(scene).lines["wire"].indicators.second_order
    seg = scene.lines[0].segments[0]
    kappa = seg.ea / (seg.length * (1 + got.lambda2 / 12))
    hist = simulate_line_timedomain(scene, duration=600.0, seed=3, dim=3)
    sel = hist.t >= hist.ramp
    y = hist.positions[sel, -1, 1]
    t2 = hist.tension_b[sel] - hist.tension_b[0]
    pred = kappa * y**2 / (2 * seg.length)
    assert (t2 - pred).std() < 0.02 * pred.std()
    assert t2.mean() == pytest.approx(pred.mean(), rel=0.02)
    # and the indicator's mean is that of the spectrum's σ_Y² (4 m²) exactly
    assert got.mean == pytest.approx(kappa * 4.0 / (2 * seg.length), rel=1e-3)
