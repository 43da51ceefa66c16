"""Tuah (1982) §6.5 Example 5, the one-leg single-point mooring in feet,
through :func:`stochcable.analysis.analyze` (example ``tuah_1982_single_leg``).

The example scene is lines only: the disc buoy is end_b heaving with the sea (RAO 1),
so the seed's findings about the disc's surge and pitch resonances (its Figs 6.5-7, -9)
have no counterpart here and are not tested.  Tested (quotes from the seed, §6.5):

- SEED_GRID: "The spectrum is discretized by 200 discrete frequencies with an 0.0245
  rad/sec increment. The simulation time length is 256 seconds with a 0.25 second
  increment, equivalent to 1024 discretized time points."
- SEED_DSA: "The solid line in Figure 6.5.6 represents the expected spectrum which can
  be obtained by the Deterministic Spectral Amplitude (DSA) simulation method" with
  "m_0 = 28 ft^2 and ω_p = 0.5 rad/sec".
- SEED_ITERATIONS: "The linearized drag force coefficients are obtained after eight
  iterations with 0.01 convergence tolerance".
- SEED_HEAVE_SHAPE: "The spectral shape for the heave is almost identical with the wave
  surface spectral shape."
- SEED_ELEMENTS: "The surge for the eight-element model of the cable is slightly larger
  than for the three-element model" (deterministic run; here: the fairlead tension σ
  of the random run).
- SEED_SLACK: "The high frequency fluctuation in the heave motion occurs because of the
  sudden release of the disc when the cable slackens."

Unit consistency: the same scene converted to SI gives the same results converted back.
"""

from __future__ import annotations

import copy
import math

import numpy as np
import pytest

from stochcable.analysis import analyze
from stochcable.examples import load_example

# one worker runs the module: its module fixtures run once (--dist loadgroup)
pytestmark = pytest.mark.xdist_group("test_seed_tuah_1982_ex5")

# Tuah 1982, §6.5 (quoted in the module docstring).
TUAH_1982_EX5 = {
    "m0": 28.0,  # [ft²]
    "omega_p": 0.5,  # [rad/s]
    "frequencies": 200,
    "d_omega": 0.0245,  # [rad/s], as printed (2π/256 = 0.02454 rounded)
    "duration": 256.0,  # [s]
    "dt": 0.25,  # [s]
    "time_points": 1024,
    "drag_iterations": 8,
    "drag_tolerance": 0.01,
    "elements": 3,
}

# Exact conversion factors.  The pound-force is derived from the slug and the foot
# (1 lbf = 1 slug·ft/s²), so that the converted scene is the same physical system to
# round-off (the rounded 4.44822 N would differ from 14.5939·0.3048 by 1.6e-7), and g
# is converted (32.174 ft/s² = 9.80664 m/s², not the standard 9.80665, 1.5e-6 apart).
FT = 0.3048  # [m/ft]
SLUG = 14.59390294  # [kg/slug]
LBF = SLUG * FT  # [N/lbf]


@pytest.fixture(scope="module")
def doc() -> dict:
    return load_example("tuah_1982_single_leg").model_dump()


@pytest.fixture(scope="module")
def result(doc):
    return analyze(doc)


def test_imperial_scene_is_the_seed_setup(doc):
    env = doc["environment"]
    assert env["g"] == 32.174  # ft/s² (DESIGN.md)
    assert env["rho"] == pytest.approx(2.0)  # slug/ft³, seed §6.2/6.6 fluid density
    spec = doc["sea"]["spectrum"]
    assert (spec["m0"], spec["omega_p"]) == (TUAH_1982_EX5["m0"], TUAH_1982_EX5["omega_p"])
    grid = doc["analysis"]["omega"]
    # SEED_GRID: 200 frequencies 0.0245 … 4.9 rad/s
    assert grid["count"] == TUAH_1982_EX5["frequencies"]
    w = np.linspace(grid["min"], grid["max"], grid["count"])
    np.testing.assert_allclose(np.diff(w), TUAH_1982_EX5["d_omega"], rtol=1e-12)
    ts = doc["analysis"]["timeseries"]
    assert ts["method"] == "dsa"
    assert round(ts["duration"] / ts["dt"]) == TUAH_1982_EX5["time_points"]
    assert doc["lines"][0]["segments"][0]["elements"] == TUAH_1982_EX5["elements"]
    assert doc["analysis"]["linearization"]["tolerance"] == TUAH_1982_EX5["drag_tolerance"]


def test_runs_in_feet_with_finite_plausible_results(result):
    res = result
    line = res.lines["leg"]
    assert res.converged
    for stats in (line.end_a, line.end_b):
        for v in stats.as_dict().values():
            assert math.isfinite(v)
        assert stats.std > 0.0
    # statics: the example's L = 339 ft balances the seed's 100 lb wind load
    # (horizontal force at the buoy, within the 1 % the example title allows)
    fb = np.asarray(res.statics.lines["leg"].force_b)
    assert abs(fb[0]) == pytest.approx(100.0, rel=0.05)
    # 2-D, 3 elements: 2 free nodes x 2 DOFs = 4 modes, all kept by Foss ("auto")
    assert line.model.dim == 2 and line.modes_omega.size == 4 and line.n_modes == 4
    assert np.all(np.isfinite(line.motion_std)) and np.all(np.isfinite(line.tension_std))
    # the fairlead heaves with the sea (RAO 1): σ = √m0 on the grid (trapezoid of the
    # PM spectrum from 0.0245 to 4.9 rad/s: tails below/above hold < 0.1 % of m0)
    assert line.motion_std[-1, 2] == pytest.approx(math.sqrt(TUAH_1982_EX5["m0"]), rel=1e-3)
    # the anchor does not move; the grounded node hardly heaves (seabed stiffness)
    assert np.all(line.motion_std[0] == 0.0)
    assert line.motion_std[1, 2] < 1e-3 * line.motion_std[-1, 2]


def test_seed_dsa_realization_has_the_expected_spectrum(result):
    """SEED_DSA: every DSA ordinate is the expected spectrum S(ω_m) exactly, so the
    realization's variance is Σ S Δω ≈ m0 = 28 ft²."""
    res = result
    ts = res.timeseries
    n_t = ts.time.size
    assert n_t == TUAH_1982_EX5["time_points"]
    d_omega = ts.omega[1]
    assert d_omega == pytest.approx(TUAH_1982_EX5["d_omega"], rel=2e-3)  # printed 0.0245
    x = np.fft.rfft(ts.elevation)
    a = 2.0 * np.abs(x) / n_t  # cosine amplitudes
    sample = a**2 / (2.0 * d_omega)  # periodogram ordinate of a DSA realization
    spec = res.scene.sea.spectrum
    expected = np.zeros_like(ts.omega)
    expected[1:-1] = spec.spectral_density(ts.omega[1:-1], res.scene.environment.g)
    # FFT round-off
    np.testing.assert_allclose(sample[1:-1], expected[1:-1], rtol=1e-9, atol=1e-12 * expected.max())
    # m0 = 28 ft²: the grid 0.0245 … 63 rad/s misses < 1e-4 of the PM spectrum
    assert np.var(ts.elevation) == pytest.approx(TUAH_1982_EX5["m0"], rel=1e-4)


def test_seed_drag_linearization_converges_within_eight_iterations(result):
    """SEED_ITERATIONS: tolerance 0.01, the seed needed eight (plain) iterations; the
    Anderson-accelerated fixed point needs no more.  The record counts full-grid
    evaluations only: since the coarse-grid start (analysis.linearize, coarse=True)
    supplies the starting σ, one full-grid evaluation may already pass the test."""
    rec = result.lines["leg"].linearization
    assert rec.converged
    assert rec.tolerance == TUAH_1982_EX5["drag_tolerance"]
    assert 1 <= rec.iterations <= TUAH_1982_EX5["drag_iterations"]
    assert rec.relative_change < rec.tolerance


def test_seed_heave_spectrum_has_the_wave_spectrum_shape(result):
    """SEED_HEAVE_SHAPE, for the cable node next to the buoy: its heave spectrum,
    normalized to unit area, is the normalized wave spectrum within 5 % (L1 distance;
    measured 1.7 %), and peaks within one grid step of ωp."""
    line = result.lines["leg"]
    w = line.omega
    s_eta = line.input_spectra[0]
    heave = line.motion_spectrum[-2, 2]
    a = heave / np.trapezoid(heave, w)
    b = s_eta / np.trapezoid(s_eta, w)
    assert np.trapezoid(np.abs(a - b), w) < 0.05
    assert abs(w[np.argmax(heave)] - TUAH_1982_EX5["omega_p"]) <= 1.01 * (w[1] - w[0])
    # ... while the fairlead tension spectrum does NOT have the wave shape (the test
    # discriminates): its L1 distance is 0.4
    t = line.end_tension_spectrum("end_b")
    assert np.trapezoid(np.abs(t / np.trapezoid(t, w) - b), w) > 0.2


def test_seed_slackening_is_predicted(result):
    """SEED_SLACK: the cable slackens.  The linear model's dynamic tension σ exceeds
    the mean at both ends (mean − σ < 0), i.e. slack events are frequent: the
    linearized result is outside its range of validity here, as the seed observed."""
    line = result.lines["leg"]
    for stats in (line.end_a, line.end_b):
        assert stats.mean - stats.std < 0.0


def _with_elements(doc: dict, n: int) -> dict:
    d = copy.deepcopy(doc)
    d["lines"][0]["segments"][0]["elements"] = n
    d["analysis"]["timeseries"] = None
    # direct solve: the mesh effect alone, without modal truncation (the 3-element
    # example keeps all 4 modes, so it is the direct solve too)
    d["analysis"]["solver"] = "direct"
    return d


def test_seed_more_elements_give_larger_response_then_converge(doc, result):
    """SEED_ELEMENTS: eight elements respond more than three (the seed: "slightly";
    here the fairlead tension σ is 35 % larger: the 3-element model's lowest natural
    frequency is 5.0 rad/s, above the grid, while 4 or more elements give ~1 rad/s).
    Beyond 8 elements the σ settles: with the wave loads integrated exactly along each
    element and the suspended span ending at the static touchdown whatever the mesh
    (stochcable.line.seabed), 647 / 598 / 591 lbf at 8 / 16 / 32 elements (601 at 64;
    meshes with a node at the touchdown give 664 / 615 / 604 / 603, the same 7 % step
    from 8 to 16) — 8 -> 16 within 10 % (the 8-element mesh under-resolves the surface
    decay at the buoy, see the analysis' surface-resolution warning, and the leg's
    curvature), 16 -> 32 within 2 %."""
    sigma = {3: result.lines["leg"].end_b.std}
    low = {3: result.lines["leg"].modes_omega[0]}
    for n in (8, 16, 32):
        line = analyze(_with_elements(doc, n)).lines["leg"]
        sigma[n], low[n] = line.end_b.std, line.modes_omega[0]
    assert sigma[8] > sigma[3]
    assert low[3] > 4.0 and low[8] < 1.5
    assert sigma[16] == pytest.approx(sigma[8], rel=0.1)
    assert sigma[32] == pytest.approx(sigma[16], rel=0.02)


# ----------------------------------------------------------------- unit consistency


def to_si(doc: dict) -> dict:
    """The same scene in SI: ft -> m, slug -> kg, lbf -> N, exactly."""
    d = copy.deepcopy(doc)
    env = d["environment"]
    env["depth"] *= FT
    env["rho"] *= SLUG / FT**3  # slug/ft³ -> kg/m³
    env["g"] *= FT  # ft/s² -> m/s²
    env["seabed"]["stiffness"] *= LBF / FT**3  # lbf/ft² per ft -> Pa/m
    env["seabed"]["damping"] *= LBF / FT**3  # lbf·s/ft² per ft -> Pa·s/m
    d["sea"]["spectrum"]["m0"] *= FT**2  # ft² -> m²; omega_p unchanged (rad/s)
    line = d["lines"][0]
    for end in ("end_a", "end_b"):
        line[end]["position"] = [x * FT for x in line[end]["position"]]
    for seg in line["segments"]:
        seg["length"] *= FT
        seg["ea"] *= LBF
        seg["mass"] *= SLUG / FT  # slug/ft -> kg/m
        seg["diameter"] *= FT
        assert seg["weight"] is None  # from mass, rho, g: converted above
    assert not line["attachments"]
    # the heave RAO is m/m = ft/ft; ω in rad/s and times in s are unchanged
    return d


def test_same_scene_in_si_gives_the_same_results(doc, result):
    """Unit consistency: every result of the SI scene converted back to ft/lbf equals
    the imperial one to 1e-6 (measured 1e-14: the two runs are the same arithmetic up
    to the scaling of each quantity, so only round-off separates them)."""
    imp = result
    si = analyze(to_si(doc))
    a, b = imp.lines["leg"], si.lines["leg"]
    rel = 1e-6
    np.testing.assert_allclose(b.modes_omega, a.modes_omega, rtol=rel)
    assert b.linearization.iterations == a.linearization.iterations
    for end in ("end_a", "end_b"):
        sa, sb = getattr(a, end), getattr(b, end)
        assert sb.mean / LBF == pytest.approx(sa.mean, rel=rel)
        assert sb.std / LBF == pytest.approx(sa.std, rel=rel)
        assert sb.tz == pytest.approx(sa.tz, rel=rel)
        assert sb.mpm_3h / LBF == pytest.approx(sa.mpm_3h, rel=rel)
    np.testing.assert_allclose(b.tension_mean / LBF, a.tension_mean, rtol=rel)
    np.testing.assert_allclose(b.tension_std / LBF, a.tension_std, rtol=rel)
    np.testing.assert_allclose(
        b.motion_std / FT, a.motion_std, rtol=rel, atol=rel * a.motion_std.max()
    )
    np.testing.assert_allclose(
        b.positions / FT, a.positions, rtol=0, atol=rel * np.abs(a.positions).max()
    )
    # linearized drag per unit length: N·s/m² -> lbf·s/ft²
    np.testing.assert_allclose(
        b.linearization.b_normal / (LBF / FT**2), a.linearization.b_normal, rtol=rel
    )
    # time series: same realization (ω, seed), tension in N vs lbf, η in m vs ft
    ta, tb = imp.timeseries, si.timeseries
    np.testing.assert_allclose(
        tb.elevation / FT, ta.elevation, rtol=0, atol=rel * np.abs(ta.elevation).max()
    )
    for end in ("end_a", "end_b"):
        xa = ta.end_tension["leg"][end]
        np.testing.assert_allclose(
            tb.end_tension["leg"][end] / LBF, xa, rtol=0, atol=rel * np.abs(xa).max()
        )


def test_standard_gravity_instead_of_the_exact_conversion_is_visible(doc, result):
    """The check is sharp: using g = 9.80665 (1.5e-6 from 32.174 ft/s² in m/s²) moves
    the mean fairlead tension by about that much — more than round-off, less than 1e-5."""
    d = to_si(doc)
    d["environment"]["g"] = 9.80665
    d["analysis"]["timeseries"] = None
    b = analyze(d).lines["leg"]
    change = abs(b.end_b.mean / LBF / result.lines["leg"].end_b.mean - 1.0)
    assert 1e-8 < change < 1e-4
