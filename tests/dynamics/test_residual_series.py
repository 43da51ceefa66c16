"""stochcable.dynamics.timeseries.residual_series: the end-tension time series carry the
residuals' Gaussian component, so a long record's σ and spectrum are the corrected ones;
with the residual switches off the series are the linear model's, bit for bit."""

from __future__ import annotations

import numpy as np
import pytest

from stochcable import ResolutionWarning, analyze
from stochcable.dynamics.timeseries.residual_series import residual_density
from stochcable.examples import load_example

DT = 0.25
#: 2^16 samples (4.5 h): about 7,000 realization lines over the taut wire's band
SAMPLES = 2**16


def _doc(residuals: bool = True) -> dict:
    doc = load_example("taut_wire").model_dump(mode="json", exclude_unset=True)
    doc["analysis"]["timeseries"] = {"duration": SAMPLES * DT, "dt": DT, "seed": 3}
    if not residuals:
        doc["analysis"].setdefault("linearization", {}).update(
            drag_residual=False, geometric_residual=False
        )
    return doc


@pytest.fixture(scope="module")
def runs():
    with pytest.warns(Warning):  # (the example's mesh: a ResolutionWarning)
        on = analyze(_doc())
    with pytest.warns(Warning):
        off = analyze(_doc(residuals=False))
    return on, off


def _power(x: np.ndarray, lo: float, hi: float) -> float:
    """Variance of the record ``x`` in the band [lo, hi) (its periodogram's sum). [N²]"""
    c = np.fft.rfft(x - x.mean()) / x.size
    w = 2 * np.pi * np.fft.rfftfreq(x.size, DT)
    band = (w >= lo) & (w < hi)
    return float(2.0 * np.sum(np.abs(c[band]) ** 2))


def _cross_std(line, end: str, lo: float, hi: float) -> float:
    """Standard deviation of a DSA record's band variance in [lo, hi) about its
    expectation: the taut wire has one input channel (the sea), so the linear series
    is one random-phase component and the residuals' another, and their cross term
    over the record, Σ_m a_m b_m cos(θ_m − φ_m) (a_m² = 2 S_lin Δω, b_m² = 2 S_r Δω),
    is the record's only sampling error: its variance is Σ_m 2 S_lin S_r Δω². [N²]"""
    d_omega = 2 * np.pi / (SAMPLES * DT)
    w = d_omega * np.arange(1, SAMPLES // 2)
    w = w[(w >= lo) & (w < hi)]
    s_lin = np.interp(w, line.omega, line.end_tension_spectrum(end), left=0.0, right=0.0)
    omega, s_r = residual_density(line, end)
    s_r = np.interp(w, omega, s_r, left=0.0, right=0.0)
    return float(np.sqrt(2.0 * np.sum(s_lin * s_r)) * d_omega)


@pytest.mark.parametrize("end", ["end_a", "end_b"])
def test_record_has_the_corrected_sigma_and_spectrum(runs, end):
    on, _ = runs
    line = on.lines["wire"]
    x = on.timeseries.end_tension["wire"][end]
    omega, dens = line.end_tension_density(end)
    corrected, linear = getattr(line, end).std ** 2, line.linear[end].std ** 2
    assert corrected > linear
    # σ²: within 4 sampling standard deviations, plus 0.5 % for the densities on the
    # realization lines against the trapezoid on the analysis grid (the switches-off
    # record: 1e-5)
    tol = 4.0 * _cross_std(line, end, 0.0, np.inf) + 0.005 * corrected
    if end == "end_b":  # the residuals' share of the variance, 29 %: the check sees them
        assert tol < 0.5 * (corrected - linear)
    assert abs(np.var(x) - corrected) < tol
    # the spectrum, band by band: the analysis band's two halves and the residuals'
    # superharmonics above it (only the residual component there: no sampling error)
    w_top = float(line.omega[-1])
    for lo, hi in ((0.0, 1.0), (1.0, w_top), (w_top, np.inf)):
        inside = (omega >= lo) & (omega < hi)
        want = float(np.trapezoid(dens[inside], omega[inside]))
        band_tol = 4.0 * _cross_std(line, end, lo, hi) + 0.02 * want
        assert abs(_power(x, lo, hi) - want) < band_tol, (lo, hi)
    assert _power(x, w_top, np.inf) > 0.0  # (the linear series stop at ω_max)


def test_residual_component_is_uncorrelated_with_the_linear_series(runs):
    on, _ = runs
    ts = on.timeseries
    for end in ("end_a", "end_b"):
        r = ts.end_tension_residual["wire"][end]
        lin = ts.end_tension_linear["wire"][end]
        rho = np.corrcoef(r, lin)[0, 1]
        omega, dens = residual_density(on.lines["wire"], end)
        # (the cross term's standard deviation over the two variances' geometric mean)
        cross = _cross_std(on.lines["wire"], end, 0.0, np.inf)
        assert abs(rho) < 4.0 * cross / np.sqrt(np.var(r) * np.var(lin))
        assert np.var(r) == pytest.approx(np.trapezoid(dens, omega), rel=0.01)


def test_switches_off_give_the_linear_series(runs):
    on, off = runs
    assert off.timeseries.end_tension_residual == {}
    np.testing.assert_array_equal(on.timeseries.elevation, off.timeseries.elevation)
    for end in ("end_a", "end_b"):
        base = off.timeseries.end_tension["wire"][end]
        # the linear part of the corrected record: (linear + component) − component
        np.testing.assert_allclose(
            on.timeseries.end_tension_linear["wire"][end], base, rtol=0, atol=1e-9 * np.std(base)
        )
        np.testing.assert_array_equal(off.timeseries.end_tension_linear["wire"][end], base)


def test_document_gives_the_linear_series_when_asked(runs):
    on, off = runs
    plain = on.to_document()["timeseries"]["lines"]["wire"]["end_b"]
    assert set(plain) == {"tension"}
    both = on.to_document(timeseries_linear=True)["timeseries"]["lines"]["wire"]["end_b"]
    lin = on.timeseries.end_tension_linear["wire"]["end_b"][: len(both["tension"])]
    np.testing.assert_allclose(both["tension_linear"], lin, rtol=1e-12)
    # without the residuals there is nothing beside the tension
    assert set(off.to_document(timeseries_linear=True)["timeseries"]["lines"]["wire"]["end_b"]) == {
        "tension"
    }


def test_residuals_above_the_nyquist_frequency_are_said():
    """dt = 1.5 s: π/dt = 2.1 rad/s, below the top of the taut wire's residual spectrum
    (in band to 3 rad/s, its superharmonics beyond): a ResolutionWarning in the
    residuals' terms gives the dt, and the residuals-off analysis has no such warning."""
    doc = _doc()
    doc["analysis"]["timeseries"] = {"duration": 2**10 * 1.5, "dt": 1.5, "seed": 3}
    with pytest.warns(ResolutionWarning, match="residuals' variance .* above the time series"):
        res = analyze(doc)
    assert any("use analysis.timeseries.dt ≤" in w for w in res.warnings)
    doc["analysis"].setdefault("linearization", {}).update(
        drag_residual=False, geometric_residual=False
    )
    with pytest.warns(Warning):
        off = analyze(doc)
    assert not any("residuals' variance" in w for w in off.warnings)
