"""Directional spreading (stochcable.sea.spreading): normalization and closed-form
moments against independent quadrature, the O(Δθ²) error of the discrete directions,
the long-crested limit, the kinematics variance of a short-crested sea against the
closed-form directional integral, and the directional estimate of a realization
against its input within the sampling error of several seeds."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import integrate

from stochcable.errors import InputError
from stochcable.sea import spreading as sp
from stochcable.sea.kinematics import wave_kinematics
from stochcable.sea.spectra import spectrum_jonswap


@pytest.mark.parametrize("s", [0.5, 1.0, 4.0, 15.0, 80.0])
def test_cos2s_is_normalized_and_has_its_closed_form_moments(s):
    mean = 0.4
    f = lambda t: sp.spreading_cos2s(t, mean, s)  # noqa: E731
    # adaptive quadrature to 1e-12: independent of the closed forms
    kw = {"epsabs": 1e-13, "epsrel": 1e-12, "limit": 200, "points": [mean]}
    total = integrate.quad(lambda t: float(f(t)), mean - math.pi, mean + math.pi, **kw)[0]
    assert total == pytest.approx(1.0, abs=1e-10)
    ref = sp.moments_cos2s(s)
    for key, g in (("a1", math.cos), ("a2", lambda x: math.cos(2 * x))):
        got = integrate.quad(
            lambda t, g=g: float(f(t)) * g(t - mean), mean - math.pi, mean + math.pi, **kw
        )[0]
        assert got == pytest.approx(ref[key], abs=1e-10)


@pytest.mark.parametrize("n", [1.0, 2.0, 4.0, 10.0, 50.0])
def test_cosn_is_normalized_and_has_its_closed_form_moments(n):
    f = lambda t: sp.spreading_cosn(t, 0.0, n)  # noqa: E731
    kw = {"epsabs": 1e-13, "epsrel": 1e-12, "limit": 200}
    assert integrate.quad(lambda t: float(f(t)), -math.pi / 2, math.pi / 2, **kw)[
        0
    ] == pytest.approx(1.0, abs=1e-10)
    assert float(f(0.6 * math.pi)) == 0.0  # no energy against the mean direction
    ref = sp.moments_cosn(n)
    for key, g in (("a1", math.cos), ("a2", lambda x: math.cos(2 * x))):
        got = integrate.quad(lambda t, g=g: float(f(t)) * g(t), -math.pi / 2, math.pi / 2, **kw)[0]
        assert got == pytest.approx(ref[key], abs=1e-10)


@pytest.mark.parametrize(
    ("make", "param", "closed", "span"),
    [
        (sp.directions_cos2s, 5.0, sp.moments_cos2s, 2 * math.pi),
        (sp.directions_cos2s, 30.0, sp.moments_cos2s, 2 * math.pi),
        (sp.directions_cosn, 2.0, sp.moments_cosn, math.pi),
        (sp.directions_cosn, 8.0, sp.moments_cosn, math.pi),
    ],
)
@pytest.mark.parametrize("count", [9, 16, 64])
def test_discrete_directions_err_by_the_centroid_rule_bound(make, param, closed, span, count):
    """Weights are exact bin integrals and headings bin centroids, so Σ w f(θ_k) −
    ∫ D f errs by at most max|f''|·Δθ²/8 (f = cos nΔθ: |f''| ≤ n²)."""
    mean = -0.7
    ds = make(mean, param, count)
    assert ds.weight.sum() == pytest.approx(1.0, abs=1e-14)
    assert np.all(ds.weight >= 0) and np.all(np.diff(ds.heading) > 0)
    dth = span / count
    got, ref = ds.moments(mean), closed(param)
    for key, order in (("a1", 1), ("a2", 2)):
        assert abs(got[key] - ref[key]) <= order**2 * dth**2 / 8
    # symmetric about the mean: the odd moments vanish to round-off
    assert abs(got["b1"]) < 1e-14 and abs(got["b2"]) < 1e-14
    if count == 9:  # the weights (incomplete beta) against quadrature of D on each bin
        d = sp.spreading_cos2s if make is sp.directions_cos2s else sp.spreading_cosn
        edges = mean + np.linspace(-span / 2, span / 2, count + 1)
        quad = [
            integrate.quad(lambda t: float(d(t, mean, param)), a, b, epsabs=1e-14)[0]
            for a, b in zip(edges[:-1], edges[1:])
        ]
        full = np.zeros(count)  # (bins of zero weight are left out of the set)
        full[np.searchsorted(edges, ds.heading) - 1] = ds.weight
        np.testing.assert_allclose(full, quad, rtol=0, atol=1e-11)


def test_narrow_spreading_is_the_long_crested_sea():
    """s → ∞ (its largest value, 1e6): all the weight in the bin on the mean, at the mean
    heading."""
    mean = math.radians(25.0)
    ds = sp.directions_cos2s(mean, 1e6, 15)
    k = int(np.argmax(ds.weight))
    assert ds.heading[k] == pytest.approx(mean, abs=1e-12)
    # the weight outside the central bin ≈ ∫ beyond its half-width π/15: < 1e-30 here,
    # and the empty bins are left out: one direction, the long-crested sea
    assert ds.weight[k] == pytest.approx(1.0, abs=1e-12)
    assert ds.count == 1


@pytest.mark.parametrize("depth", [math.inf, 30.0])
def test_kinematics_variance_is_the_directional_integral(depth):
    """σ² of the horizontal velocity components at a point: the direction sum of the
    long-crested variances equals ∫S|H_h|²dω × ∫D cos²θ (resp. sin²θ) dθ =
    ½(1 ± a2 cos 2θ̄) for a symmetric D, within the directions' O(Δθ²) bound."""
    w = np.linspace(0.05, 3.0, 400)
    s_w = spectrum_jonswap(w, 4.0, 9.0)
    dw = np.full_like(w, w[1] - w[0])
    point = [3.0, -2.0, -5.0]
    mean, s = math.radians(30.0), 6.0
    ds = sp.directions_cos2s(mean, s, 36)
    var = np.zeros(3)
    for beta, wk in zip(ds.heading, ds.weight):
        u = wave_kinematics(w, point, float(beta), depth).velocity[0].T  # (n_w, 3)
        var += wk * np.sum(np.abs(u) ** 2 * (s_w * dw)[:, None], axis=0)
    along = wave_kinematics(w, point, 0.0, depth).velocity[0].T
    m_h = float(np.sum(np.abs(along[:, 0]) ** 2 * s_w * dw))  # |H_h|² (heading 0: all on x)
    m_v = float(np.sum(np.abs(along[:, 2]) ** 2 * s_w * dw))
    a2 = sp.moments_cos2s(s)["a2"]
    bound = 4 * (2 * math.pi / 36) ** 2 / 8  # f = cos 2θ, |f''| ≤ 4
    assert var[0] / m_h == pytest.approx(0.5 * (1 + a2 * math.cos(2 * mean)), abs=0.5 * bound)
    assert var[1] / m_h == pytest.approx(0.5 * (1 - a2 * math.cos(2 * mean)), abs=0.5 * bound)
    assert var[0] + var[1] == pytest.approx(m_h, rel=1e-12)  # the horizontal total: any D
    assert var[2] == pytest.approx(m_v, rel=1e-12)  # vertical: independent of direction


@pytest.mark.parametrize("method", ["dsa", "nsa"])
def test_realization_reproduces_its_directional_moments(method):
    """From the velocity (u, v) of one realization: a2 = (σ_u² − σ_v²)/(σ_u² + σ_v²),
    b2 = 2 cov(u, v)/(σ_u² + σ_v²) about +x (Longuet-Higgins et al. 1963) against the
    input's Σ w cos 2θ, Σ w sin 2θ — the expectation of the estimate, exact for a
    frequency-independent D.  Eight seeds: their mean within 4 standard errors (the
    seeds' own scatter), each within 6 standard deviations."""
    ds = sp.directions_cos2s(math.radians(30.0), 4.0, 17)
    density = lambda w: spectrum_jonswap(w, 3.0, 8.0)  # noqa: E731
    expected = ds.moments(0.0)
    est = []
    for seed in range(8):
        reals = sp.simulate_sea_directional(density, ds, 2048.0, 0.5, method, rng=seed)
        u = sp.velocity_timeseries_directional(reals, ds, [0.0, 0.0, -1.0])[0]
        cu = np.cov(u[:2])
        tot = cu[0, 0] + cu[1, 1]
        est.append(((cu[0, 0] - cu[1, 1]) / tot, 2 * cu[0, 1] / tot))
    est = np.array(est)
    mean, sd = est.mean(axis=0), est.std(axis=0, ddof=1)
    for j, key in enumerate(("a2", "b2")):
        assert abs(mean[j] - expected[key]) <= 4 * sd[j] / math.sqrt(len(est)) + 1e-12, key
        assert np.all(np.abs(est[:, j] - expected[key]) <= 6 * sd[j] + 1e-12), key
        assert sd[j] < 0.1  # the estimate is informative at this record length


def test_realization_elevation_spectrum_is_the_point_spectrum():
    """DSA: the directions' amplitudes are √(2 w_k S Δω), so Σ_k a_k²/2 = S Δω per line."""
    ds = sp.directions_cosn(0.0, 4.0, 9)
    density = lambda w: spectrum_jonswap(w, 2.0, 7.0)  # noqa: E731
    reals = sp.simulate_sea_directional(density, ds, 512.0, 0.5, "dsa", rng=3)
    line_var = sum(0.5 * r.amplitudes**2 for r in reals)
    w = reals[0].omega
    ref = density(w) * reals[0].d_omega
    inner = slice(1, -1)
    np.testing.assert_allclose(line_var[inner], ref[inner], rtol=1e-12, atol=1e-18)


@pytest.mark.parametrize(
    ("call", "parameter"),
    [
        (lambda: sp.spreading_cos2s([0.0], 0.0, 0.0), "s"),
        (lambda: sp.spreading_cos2s([0.0], 0.0, -2.0), "s"),
        (lambda: sp.spreading_cosn([0.0], 0.0, -1.0), "n"),
        (lambda: sp.directions_cos2s(0.0, 2.0, 0), "count"),
        (lambda: sp.directions_cosn(math.nan, 2.0, 5), "mean"),
        (lambda: sp.directions_table([0.0, 0.5], [0.0, 0.0]), "weight"),
        (lambda: sp.directions_table([0.0, 0.5], [1.0, -0.2]), "weight"),
        (lambda: sp.directions_table([0.0, 0.5], [1.0]), "weight"),
        (lambda: sp.directions_table([0.0, 0.0], [1.0, 1.0]), "heading"),
        (lambda: sp.directions_table([0.0, math.inf], [1.0, 1.0]), "heading"),
    ],
)
def test_bad_parameters_name_themselves(call, parameter):
    with pytest.raises(InputError) as info:
        call()
    assert info.value.parameter == parameter


def test_table_is_normalized_and_sorted():
    ds = sp.directions_table([0.5, -0.5, 0.0], [1.0, 1.0, 2.0])
    np.testing.assert_array_equal(ds.heading, [-0.5, 0.0, 0.5])
    np.testing.assert_allclose(ds.weight, [0.25, 0.5, 0.25], rtol=0, atol=1e-16)
