"""The end-tension spectral density with the residuals
(stochcable.dynamics.residuals.corrected_spectrum): its area is the corrected σ² the
statistics report, its higher moments theirs within the interpolation's error, and
the spectral fatigue damage of it exceeds the linear one (equal with the switches off)."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

from stochcable import analyze
from stochcable.cases import LineFatigue
from stochcable.cases.fatigue_settings import curve_factor
from stochcable.design import damage_rate, spectral_moments_along
from stochcable.dynamics.residuals.corrected_spectrum import corrected_spectrum
from stochcable.examples import load_example
from stochcable.results.records import ResidualRecord

ENDS = ("end_a", "end_b")


def _chain(on: bool):
    doc = load_example("chain_catenary").model_dump(mode="json")
    doc["analysis"].pop("timeseries", None)
    doc["analysis"]["linearization"].update(drag_residual=on, geometric_residual=on)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return analyze(doc).lines["leg1"]


@pytest.fixture(scope="module")
def chain():
    return _chain(True), _chain(False)


def test_area_is_the_corrected_variance(chain):
    """∫S dω = σ² of the corrected end statistics to round-off (1e-12: the scale of
    the residual lines is solved for it); m2 and m4 within 1 % of the statistics'
    line sums (the interpolation of the lines' densities onto the grid: 0.13 % and
    0.25 % measured); the grid reaches the drag's top line, those above it left out
    within 2e-4 of the ends' linear m0, m2, m4 (:mod:`.line_top`: here 1.94·ω_max of
    the third order's 3·ω_max)."""
    line, _ = chain
    for end in ENDS:
        om, dens = line.end_tension_density(end)
        st = getattr(line, end)
        m = spectral_moments_along(om, dens)
        assert float(m["m0"]) == pytest.approx(st.std**2, rel=1e-12)
        assert float(m["m2"]) == pytest.approx(st.m2, rel=1e-2)
        assert float(m["m4"]) == pytest.approx(st.m4, rel=1e-2)
        top = float(line.drag_residual.lines[0][0][-1])
        assert om[-1] >= top > 1.5 * line.omega[-1] and np.all(np.diff(om) > 0)
        assert np.all(np.isin(line.omega, om)) and np.all(dens >= 0)
        assert abs(line.corrected_spectra[end].scale - 1.0) < 0.01  # (1.0006–1.001)
        assert st.std > line.linear[end].std
        part = line.to_document()["corrected_spectra"][end]
        np.testing.assert_array_equal(part["omega"], om)
        np.testing.assert_array_equal(part["tension"], dens)


def test_exact_parts_of_a_synthetic_record():
    """Lines chosen by hand: the misfit's changes on the analysis grid enter as their
    exact densities v/q, the uniform lines' area is their sum, and the total area is
    the linear σ² plus every line (1e-12)."""
    w = np.linspace(0.2, 2.0, 37)
    lin = np.exp(-((w - 1.0) ** 2) / 0.05)
    step = 0.1
    om = step * np.arange(1, 61)  # up to 3·ω_max
    uni = {e: 1e-3 * np.exp(-((om - 2.0) ** 2)) for e in ENDS}
    mis = {e: -1e-4 * np.ones_like(w) for e in ENDS}
    rec = ResidualRecord.from_variances(
        {e: float(uni[e].sum() + mis[e].sum()) for e in ENDS},
        dict.fromkeys(ENDS, 0.0),
        dict.fromkeys(ENDS, 1.0),
        3,
        1,
        ((om, uni), (w, mis)),
    )
    q = np.gradient(w)  # (interior trapezoid weights of a uniform grid)
    q[[0, -1]] *= 0.5
    target = float(np.sum(q * lin) + uni["end_b"].sum() + mis["end_b"].sum())
    out = corrected_spectrum(w, lin, "end_b", [rec])
    assert np.trapezoid(out.density, out.omega) == pytest.approx(target, rel=1e-12)
    assert out.omega[-1] == pytest.approx(6.0) and out.omega[0] == pytest.approx(0.1)
    none = corrected_spectrum(w, lin, "end_b", [])
    np.testing.assert_array_equal(none.density, lin)
    assert none.scale == 1.0


def test_linear_density_stops_at_the_grid_top():
    """A linear density largest at ω_max (a deep catenary's tension) and residual lines
    up to 3·ω_max: the density above ω_max is the lines' (their variance there within
    the half line that straddles ω_max), the scale is 1 within the interpolation's
    error (it was 0.48 on the accuracy page's deep line when the trapezoid spread the
    linear density's last value over the first residual cell), and the linear density
    is untouched on the grid."""
    w = np.linspace(0.05, 2.0, 200)
    lin = 1e3 * w**2  # rising to the top of the grid
    step = 2.0 / 63.0
    om = step * np.arange(1, 190)  # up to 6 rad/s, as the drag's third order
    uni = {e: 0.2 * np.exp(-(((om - 2.5) / 1.5) ** 2)) for e in ENDS}
    rec = ResidualRecord.from_variances(
        {e: float(uni[e].sum()) for e in ENDS},
        dict.fromkeys(ENDS, 0.0),
        dict.fromkeys(ENDS, 1.0),
        3,
        1,
        ((om, uni),),
    )
    out = corrected_spectrum(w, lin, "end_b", [rec])
    v = uni["end_b"]
    assert out.scale == pytest.approx(1.0, abs=2e-3)  # (interpolation: 1e-3 measured)
    hi = out.omega > w[-1]
    area = np.trapezoid(out.density[hi], out.omega[hi])
    at_top = v[np.isclose(om, 2.0)].sum()  # the line on ω_max: half its cell above
    assert area == pytest.approx(v[om > 2.0].sum() + 0.5 * at_top, rel=2e-3)
    on_grid = np.isin(out.omega, w)
    assert np.all(out.density[on_grid] >= lin)  # (the linear density plus the lines')
    assert out.omega[np.argmax(out.omega > w[-1])] - w[-1] < 1e-6 * (w[1] - w[0]) * 1.01


@pytest.mark.parametrize("method", ["dirlik", "narrow_band"])
def test_fatigue_damage_of_the_corrected_spectrum(chain, method):
    """The damage rate of the corrected density exceeds the linear model's (more
    variance, and the superharmonics add cycles); with the switches off the density
    is the linear spectrum itself and the damage the same bits."""
    line, plain = chain
    curve, factor = curve_factor(LineFatigue("dnv-studless", nominal_diameter=0.076), 9.81, "x")
    for end in ENDS:
        om, dens = line.end_tension_density(end)
        cor = float(damage_rate(om, dens * factor**2, curve, method))
        lin_dens = line.end_tension_spectrum(end) * factor**2
        lin = float(damage_rate(line.omega, lin_dens, curve, method))
        assert cor > lin > 0
        # (the chain's corrected σ is 4–7 % above the linear: damage ∝ σ^m, m = 3)
        assert cor / lin > (getattr(line, end).std / line.linear[end].std) ** 2
        om0, dens0 = plain.end_tension_density(end)
        assert om0 is plain.omega and plain.corrected_spectra is None
        np.testing.assert_array_equal(dens0, plain.end_tension_spectrum(end))
    assert "corrected_spectra" not in plain.to_document()
    assert math.isclose(plain.end_b.std, line.linear["end_b"].std)


def _former_spectrum_with_lines(omega, linear, parts):
    """The former one-response form of spectrum_with_lines (its grid formed per call)."""
    from stochcable.dynamics.model.blocks import trapezoid_weights
    from stochcable.dynamics.residuals.corrected_spectrum import _with_steps

    w = np.asarray(omega, dtype=float)
    q = trapezoid_weights(w)
    base = np.asarray(linear, dtype=float).copy()
    target = float(np.sum(q * base))
    uniform = []
    for om, v in parts:
        om, v = np.asarray(om, dtype=float), np.asarray(v, dtype=float)
        target += float(np.sum(v))
        if om.size == w.size and np.array_equal(om, w):
            base += np.divide(v, q, out=np.zeros_like(v), where=q > 0)
        elif om.size:
            step = float(om[1] - om[0]) if om.size > 1 else float(om[0])
            uniform.append((om, v / step))
    target = max(target, 0.0)
    outside = [om[(om < w[0]) | (om > w[-1])] for om, _ in uniform]
    grid = np.union1d(w, np.concatenate(outside)) if outside else w
    grid = _with_steps(grid, w)
    dens = np.zeros(grid.size)
    dens[np.searchsorted(grid, w)] = np.maximum(base, 0.0)
    res = np.zeros(grid.size)
    for om, d in uniform:
        res += np.interp(grid, om, d, left=d[0], right=0.0)
    qg = trapezoid_weights(grid)
    area = float(np.sum(qg * res))
    scale = (target - float(np.sum(qg * dens))) / area if area > 0 else 1.0
    return grid, np.maximum(dens + scale * res, 0.0), scale


def test_both_ends_on_one_grid_are_the_former_per_end_spectra(chain):
    """corrected_spectra (the extended grid formed once for both ends) gives each
    end's former per-end spectrum bitwise: the chain's records (uniform lines beyond
    the analysis band, the drag misfit on the analysis grid), and synthetic ones with a
    single line, an empty part and a negative misfit below the linear density."""
    from stochcable.dynamics.residuals.corrected_spectrum import corrected_spectra

    on, _ = chain
    w = on.omega
    dens = {e: np.asarray(on.end_tension_spectrum(e), dtype=float) for e in ENDS}
    records = [r for r in on.residuals.values() if r.computed]
    rng = np.random.default_rng(9)
    synthetic = ResidualRecord.from_variances(
        {e: 1.0 for e in ENDS}, {e: 1.0 for e in ENDS}, {e: 1.0 for e in ENDS}, 2, 1,
        (
            (np.array([w[-1] * 1.7]), {e: np.array([3.0]) for e in ENDS}),
            (np.zeros(0), {e: np.zeros(0) for e in ENDS}),
            (w, {e: -50.0 * rng.uniform(size=w.size) * dens[e] for e in ENDS}),
        ),
    )  # fmt: skip
    for recs in (records, records + [synthetic]):
        got = corrected_spectra(w, dens, recs)
        for e in ENDS:
            parts = [(om, lines[e]) for r in recs for om, lines in r.lines]
            grid, density, scale = _former_spectrum_with_lines(w, dens[e], parts)
            assert np.array_equal(got[e].omega, grid) and np.array_equal(got[e].density, density)
            assert got[e].scale == scale
            one = corrected_spectrum(w, dens[e], e, recs)
            assert np.array_equal(one.density, density) and one.scale == scale
