"""Tests of the analysis pipeline (stochcable.analysis, stochcable.dynamics.*,
stochcable.results.documents)."""

from __future__ import annotations

import copy
import dataclasses
import math
import re
import warnings

import numpy as np
import pytest
from _scenes import LINEAR_ONLY

from stochcable import analysis
from stochcable.dynamics.groups import line_fixed_point as dfixedpoint
from stochcable.dynamics.linearization import coarse_grid as dgrid
from stochcable.dynamics.linearization import variance as dvariance
from stochcable.dynamics.loads.channels import line_channels
from stochcable.dynamics.model import blocks as dblocks
from stochcable.dynamics.model import system as dsystem
from stochcable.dynamics.outputs import indicators as dindicators
from stochcable.dynamics.outputs import line_result as doutputs
from stochcable.dynamics.outputs import resolution as dresolution
from stochcable.dynamics.solve import line_loads as dloads
from stochcable.dynamics.solve import line_solve as dsolve
from stochcable.errors import ConvergenceError, InputError, ResolutionWarning, SolverError
from stochcable.line.modes import natural_modes
from stochcable.scene.model import load_scene
from stochcable.statics import solve_statics

# The fairlead surge spectra below have a PM ω⁻⁵ tail, so the tension spectra are cut by
# the 2 rad/s grids (ResolutionWarning, tested in test_grid_cutting_the_response_warns);
# the tests compare methods on the same grid, so the warning is silenced elsewhere.
pytestmark = [
    pytest.mark.filterwarnings("ignore::stochcable.errors.ResolutionWarning"),
    pytest.mark.xdist_group("test_analysis"),
]

PM_SEA = {"type": "pierson_moskowitz", "hs": 4.0, "tp": 9.0}
PM_SURGE = {"type": "pierson_moskowitz", "hs": 2.0, "tp": 10.0}


def chain_doc(
    *,
    grounded: bool = True,
    sea: bool = True,
    surge: bool = True,
    heading: float = 0.0,
    elements: int = 30,
    omega_count: int = 80,
) -> dict:
    """A studless-chain-like catenary in 100 m (grounded) or 300 m of water."""
    depth = 100.0 if grounded else 300.0
    anchor_z = -100.0 if grounded else -200.0
    length = 450.0 if grounded else 480.0
    end_b: dict = {"position": [0.0, 0.0, -10.0]}
    if surge:
        end_b["motion"] = {"surge": PM_SURGE}
    doc = {
        "environment": {"depth": depth, "seabed": {"stiffness": 3.0e5, "damping": 1.0e3}},
        "lines": [
            {
                "name": "chain",
                "end_a": {"position": [-400.0, 0.0, anchor_z]},
                "end_b": end_b,
                "segments": [
                    {
                        "length": length,
                        "ea": 5.0e8,
                        "mass": 100.0,
                        "diameter": 0.1,
                        "cd_normal": 2.4,
                        "cd_axial": 1.15,
                        "ca_normal": 1.0,
                        "elements": elements,
                    }
                ],
            }
        ],
        "analysis": {"omega": {"min": 0.1, "max": 2.0, "count": omega_count}},
    }
    if sea:
        doc["sea"] = {"spectrum": PM_SEA, "heading": heading}
    return doc


def system_and_channels(doc: dict, *, dim: int | None = None, statics_method: str = "auto"):
    scene = load_scene(doc)
    st = solve_statics(scene, method=statics_method).lines[scene.lines[0].name]
    system = dsystem.build_line_system(scene, scene.lines[0], st, dim=dim)
    chans = line_channels(scene, scene.lines[0], system.positions, scene.analysis.omega.values())
    return scene, system, chans


def with_all_modes(system: dsystem.LineSystem, solver: str) -> dsystem.LineSystem:
    n = int(system.model.free.size)
    return dataclasses.replace(
        system, modes=natural_modes(system.model, n), n_modes=n, solver=solver
    )


# ----------------------------------------------------------------- direct vs Foss


@pytest.mark.parametrize("heading, dim", [(0.0, 2), (30.0, 3)])
def test_foss_with_all_modes_equals_direct(heading, dim):
    doc = chain_doc(heading=heading, elements=16, omega_count=40)
    scene, system, chans = system_and_channels(doc)
    assert system.model.dim == dim  # planar -> 2-D, oblique sea -> 3-D
    lin = dfixedpoint.linearize(system, chans, scene.analysis)
    foss = dsolve.solve(with_all_modes(system, "foss"), chans, lin.damping)
    direct = dsolve.solve(with_all_modes(system, "direct"), chans, lin.damping)
    scale = np.max(np.abs(direct.displacement))
    # round-off of a 2n-dimensional QZ eigen-decomposition vs LU: 1e-8 relative
    assert np.max(np.abs(foss.displacement - direct.displacement)) <= 1e-8 * scale
    for end in ("end_a", "end_b"):
        ref = direct.end_tension[end]
        assert np.max(np.abs(foss.end_tension[end] - ref)) <= 1e-8 * np.max(np.abs(ref))


def test_truncated_foss_converges_to_direct():
    doc = chain_doc(sea=True, surge=True, elements=16, omega_count=40)
    scene, system, chans = system_and_channels(doc)
    lin = dfixedpoint.linearize(system, chans, scene.analysis)
    ref = dsolve.solve(with_all_modes(system, "direct"), chans, lin.damping).end_tension["end_b"]
    errors = []
    for n in (4, 12, 24):
        sysn = dataclasses.replace(with_all_modes(system, "foss"), n_modes=n)
        h = dsolve.solve(sysn, chans, lin.damping).end_tension["end_b"]
        errors.append(np.max(np.abs(h - ref)) / np.max(np.abs(ref)))
    # with the quasi-static split of the end motion and the static correction, 24 of 30
    # modes is within 1e-3; 4 and 12 modes err alike (measured 1.6 % and 1.8 %: the
    # modes between 2.7 and 20 rad/s add drag coupling the static correction ignores)
    assert errors[2] < 0.1 * min(errors[:2])
    assert errors[2] < 1e-3
    # the count dsystem.AUTO_MODE_FACTOR x omega_max (used by "auto" for large models)
    # keeps the end-tension σ within 5 %: truncation is slow for drag-dominated lines
    # (the static correction ignores the drag coupling of the truncated modes)
    n_auto = int(np.count_nonzero(system.modes.omega <= dsystem.AUTO_MODE_FACTOR * 2.0))
    sys_auto = dataclasses.replace(with_all_modes(system, "foss"), n_modes=n_auto)
    h = dsolve.solve(sys_auto, chans, lin.damping).end_tension["end_b"]
    spectra = np.stack([c.spectrum for c in chans])
    w = chans[0].omega

    def sigma(x):
        return math.sqrt(np.trapezoid(np.sum(np.abs(x) ** 2 * spectra, axis=0), w))

    assert sigma(h) == pytest.approx(sigma(ref), rel=5e-2)
    # "auto" on this small model keeps every mode: Foss = direct
    assert system.n_modes == system.model.free.size


def test_undamped_resonance_on_the_grid_is_a_solver_error():
    """Cd = 0, no seabed contact: a grid point on a natural frequency has no finite
    answer; both solvers say so instead of returning inf/NaN."""
    doc = chain_doc(grounded=False, sea=False, elements=8, omega_count=5)
    for seg in doc["lines"][0]["segments"]:
        seg["cd_normal"] = 0.0
        seg["cd_axial"] = 0.0
    scene, system, _ = system_and_channels(doc)
    w = np.array([0.5 * system.modes.omega[0], system.modes.omega[0]])
    chans = line_channels(scene, scene.lines[0], system.positions, w)
    damping = dvariance.drag_coefficients(system, np.zeros(2 * system.model.n_elements), "seed")
    for solver in ("direct", "foss"):
        with pytest.raises(SolverError, match=r"(?i)resonance|singular"):
            dsolve.solve(dataclasses.replace(system, solver=solver), chans, damping)


# --------------------------------------------------------- taut string, closed form


# Weightless taut string (Cd = Ca = 0) between (0, 0, -50) and (SPAN, 0, -50) with a
# heave spectrum at end_b: the closed-form cases below (sin kx / sin kL, damped mode).
STRING_EA, STRING_L0, STRING_SPAN, STRING_M = 1.0e7, 99.0, 100.0, 10.0


def _taut_string_doc(n_el: int, analysis: dict) -> dict:
    return {
        "environment": {"depth": 200.0},
        "lines": [
            {
                "name": "string",
                "end_a": {"position": [0.0, 0.0, -50.0]},
                "end_b": {"position": [STRING_SPAN, 0.0, -50.0], "motion": {"heave": PM_SURGE}},
                "segments": [
                    {
                        "length": STRING_L0,
                        "ea": STRING_EA,
                        "mass": STRING_M,
                        "diameter": 0.05,
                        "cd_normal": 0.0,
                        "cd_axial": 0.0,
                        "ca_normal": 0.0,
                        "weight": 0.0,
                        "elements": n_el,
                    }
                ],
            }
        ],
        "analysis": analysis,
    }


def test_taut_string_end_motion_matches_closed_form():
    """Weightless taut string, Cd = Ca = 0, heave of end_b: u(x) = sin kx / sin kL."""
    ea, l0, span, m = STRING_EA, STRING_L0, STRING_SPAN, STRING_M
    n_el = 200
    doc = _taut_string_doc(
        n_el, {"omega": {"min": 0.5, "max": 2.5, "count": 9}, "solver": "direct"}
    )
    scene, system, chans = system_and_channels(doc)
    tension = ea * (span / l0 - 1.0)
    np.testing.assert_allclose(system.model.tension, tension, rtol=1e-9)
    damping = dvariance.drag_coefficients(system, np.zeros(2 * n_el), "seed")
    assert damping.matrix.nnz == 0 or np.all(damping.matrix.data == 0.0)
    # frequencies between the resonances k L = pi and 2 pi (c = sqrt(T/m') with the
    # mass per stretched length m' = m l0 / span)
    c = math.sqrt(tension / (m * l0 / span))
    w = np.array([0.5, 0.8, 1.4, 1.7]) * math.pi * c / span
    chans = line_channels(scene, scene.lines[0], system.positions, w)
    resp = dsolve.solve(system, chans, damping)
    x = system.positions[:, 0]
    k = w[:, None] / c
    exact = np.sin(k * x) / np.sin(k * span)
    uz = resp.displacement[:, 2 * np.arange(system.model.n_nodes) + 1, 0]
    # consistent-mass linear elements: phase error O((k h)^2/12) ~ 5e-5 at h = 0.5 m
    np.testing.assert_allclose(uz.real, exact, atol=2e-4 * np.max(np.abs(exact)))
    assert np.max(np.abs(uz.imag)) < 1e-12  # undamped: in phase
    ux = resp.displacement[:, 2 * np.arange(system.model.n_nodes), 0]
    assert np.max(np.abs(ux)) < 1e-12  # transverse motion does not stretch at 1st order


def test_undamped_mode_on_coarse_grid_warns():
    doc = chain_doc(grounded=False, sea=False, elements=10, omega_count=5)
    for seg in doc["lines"][0]["segments"]:
        seg["cd_normal"] = 0.0
        seg["cd_axial"] = 0.0
    doc["environment"]["seabed"]["damping"] = 0.0
    with pytest.warns(ResolutionWarning, match=r"does not resolve mode \d+ .*analysis.omega"):
        analysis.analyze(doc)


# ------------------------------------------------------------- DSA time series


def test_dsa_timeseries_variance_equals_spectrum_sum():
    doc = chain_doc(sea=True, surge=False, elements=12, omega_count=40)
    doc["analysis"]["timeseries"] = {"method": "dsa", "duration": 400.0, "dt": 0.5, "seed": 7}
    res = analysis.analyze(doc)
    ts = res.timeseries
    scene = res.scene
    d_omega = ts.omega[1] - ts.omega[0]
    s = np.zeros_like(ts.omega)
    s[1:-1] = scene.sea.spectrum.spectral_density(ts.omega[1:-1], scene.environment.g)
    assert ts.channels["chain"] == ("sea",)
    for end, mean in (
        ("end_a", res.statics.lines["chain"].tension_a),
        ("end_b", res.statics.lines["chain"].tension_b),
    ):
        x = ts.end_tension["chain"][end] - mean
        h = ts.end_tension_transfer["chain"][end][0]
        expected = float(np.sum(np.abs(h) ** 2 * s) * d_omega)
        # DSA: the realization's variance is the grid sum exactly (round-off only)
        assert np.mean(x**2) == pytest.approx(expected, rel=1e-10)
        assert abs(np.mean(x)) < 1e-9 * math.sqrt(expected)
    # the elevation is the stand-alone realization with the same seed
    from stochcable.sea.realization import simulate_sea

    eta = simulate_sea(
        lambda w: np.where(
            w > 0,
            scene.sea.spectrum.spectral_density(np.where(w > 0, w, 1.0), scene.environment.g),
            0.0,
        ),
        400.0,
        0.5,
        "dsa",
        rng=7,
    )
    np.testing.assert_allclose(ts.elevation, eta.elevation, rtol=0, atol=1e-12)


# ------------------------------------------------------------ planar in 3-D = 2-D


def test_planar_scene_in_3d_equals_2d_and_has_no_out_of_plane_motion():
    doc = chain_doc(elements=16, omega_count=40)
    # the linear model: the drag residual is computed on the planar model only
    doc["analysis"]["linearization"] = LINEAR_ONLY
    scene, sys2, chans = system_and_channels(doc, dim=2)
    _, sys3, _ = system_and_channels(doc, dim=3)
    # all modes in both (auto would truncate the 45-DOF 3-D model but not the 2-D one)
    sys2, sys3 = with_all_modes(sys2, "foss"), with_all_modes(sys3, "foss")
    lin2 = dfixedpoint.linearize(sys2, chans, scene.analysis)
    lin3 = dfixedpoint.linearize(sys3, chans, scene.analysis)
    assert lin2.record.iterations == lin3.record.iterations
    r2 = doutputs.line_result(sys2, chans, lin2, scene.analysis)
    r3 = doutputs.line_result(sys3, chans, lin3, scene.analysis)
    # same physics, same iteration path: agreement to round-off amplified by the solves
    np.testing.assert_allclose(r3.tension_std, r2.tension_std, rtol=1e-8)
    np.testing.assert_allclose(r3.motion_std, r2.motion_std, rtol=1e-8, atol=1e-14)
    assert r3.end_b.std == pytest.approx(r2.end_b.std, rel=1e-8)
    # sway: zero up to round-off of the modal basis (which may mix degenerate in- and
    # out-of-plane modes)
    assert np.max(np.abs(r3.motion_transfer[:, :, 1])) <= 1e-12 * np.max(np.abs(r3.motion_transfer))
    assert np.all(r2.motion_std[:, 1] == 0.0)


def test_vector_form_equals_seed_form_for_in_plane_velocity():
    """With the normal-plane velocity along n1 only, E[|v|I + vvᵀ/|v|] gives the seed
    coefficient on n1 (DESIGN.md), so the in-plane answer is the same."""
    doc = chain_doc(elements=12, omega_count=30)
    # tight tolerance: the two iterate different vectors, so they agree to ~tolerance
    doc["analysis"]["linearization"] = {"method": "seed", "tolerance": 1e-8}
    base = analysis.analyze(doc)
    doc_v = copy.deepcopy(doc)
    doc_v["analysis"]["linearization"] = {"method": "vector", "tolerance": 1e-8}
    vec = analysis.analyze(doc_v)
    a, b = base.lines["chain"], vec.lines["chain"]
    # recorded b_normal of the vector form is trace/2 = (B11 + B11/2)/2 here
    np.testing.assert_allclose(
        b.linearization.b_normal,
        0.75 * a.linearization.b_normal,
        rtol=1e-7,
        atol=1e-9 * a.linearization.b_normal.max(),
    )
    np.testing.assert_allclose(b.tension_std, a.tension_std, rtol=1e-7)


# ------------------------------------------------------------ chain end to end


@pytest.fixture(scope="module")
def chain_result():
    doc = chain_doc(elements=30, omega_count=80)
    doc["analysis"]["timeseries"] = {"method": "nsa", "duration": 200.0, "dt": 0.5, "seed": 3}
    return analysis.analyze(doc)


def test_chain_runs_end_to_end_with_finite_statistics(chain_result):
    res = chain_result
    doc = res.to_document()
    assert set(doc) >= {"statics", "modes", "linearization", "lines", "timing", "warnings"}
    assert doc["linearization"]["converged"] is True
    assert 1 <= doc["linearization"]["iterations"] <= 100
    assert doc["linearization"]["relative_change"] <= 1e-4
    line = doc["lines"]["chain"]
    for end in ("end_a", "end_b"):
        t = line[end]["tension"]
        assert set(t) >= {"mean", "std", "tz", "mpm_3h", "significant", "m0", "m2", "m4"}
        assert all(math.isfinite(v) for v in t.values())
        assert t["std"] > 0.0
        # mpm_3h = mean + sigma sqrt(2 ln(10800/Tz)) (DESIGN.md)
        assert t["mpm_3h"] == pytest.approx(
            t["mean"] + t["std"] * math.sqrt(2 * math.log(10800.0 / t["tz"])), rel=1e-12
        )
        assert t["tz"] == pytest.approx(2 * math.pi * math.sqrt(t["m0"] / t["m2"]), rel=1e-12)
    n_el = res.lines["chain"].tension_std.size
    assert len(line["tension"]["s"]) == len(line["tension"]["std"]) == n_el
    assert np.array(line["motion"]["std"]).shape == (n_el + 1, 3)
    assert doc["modes"]["omega"][0] > 0.0
    assert doc["timeseries"]["window"] == 400
    # fairlead motion std is the prescribed surge: Hs/4 = 0.5 m on the analysis band
    lr = res.lines["chain"]
    band = lr.input_spectra[lr.channels.index("end_b.surge")]
    assert lr.motion_std[-1, 0] == pytest.approx(math.sqrt(np.trapezoid(band, lr.omega)), rel=1e-12)


def test_chain_fairlead_tension_sigma_plausible(chain_result):
    """σ_T at the fairlead against the quasi-static estimate dT/dx·σ_x: dynamics (first
    in-plane mode at 0.14 rad/s, drag) change it by a factor of order one, not by
    orders of magnitude (which a unit or 2π error would)."""
    lr = chain_result.lines["chain"]
    scene = chain_result.scene
    system = dsystem.build_line_system(scene, scene.lines[0], chain_result.statics.lines["chain"])
    w0 = np.array([1e-3])
    chans = line_channels(scene, scene.lines[0], system.positions, w0)
    resp = dsolve.solve(
        system,
        chans,
        dvariance.drag_coefficients(system, np.zeros(2 * system.model.n_elements), "seed"),
    )
    k_t = abs(
        resp.end_tension["end_b"][chans.index(next(c for c in chans if c.name == "end_b.surge")), 0]
    )
    sigma_x = lr.motion_std[-1, 0]
    ratio = lr.end_b.std / (k_t * sigma_x)
    assert 0.3 < ratio < 10.0, ratio
    # and the fairlead sigma is a modest fraction of the mean tension
    assert 0.002 < lr.end_b.std / lr.end_b.mean < 0.5


# ------------------------------------------------------- quasi-static stiffness


def _fd_end_tension(doc: dict, method: str, delta: float = 0.01) -> float:
    t = []
    for dx in (-delta, delta):
        d = copy.deepcopy(doc)
        d["lines"][0]["end_b"]["position"][0] += dx
        t.append(solve_statics(load_scene(d), method=method).lines["chain"].tension_b)
    return (t[1] - t[0]) / (2 * delta)


def _low_frequency_transfer(doc: dict, method: str) -> complex:
    scene, system, _ = system_and_channels(doc, statics_method=method)
    chans = line_channels(scene, scene.lines[0], system.positions, np.array([1e-3]))
    damping = dvariance.drag_coefficients(system, np.zeros(2 * system.model.n_elements), "seed")
    return dsolve.solve(system, chans, damping).end_tension["end_b"][0, 0]


def test_quasi_static_fairlead_tension_matches_catenary_stiffness():
    """Suspended chain: H_T(ω→0) for surge -> dT_b/dx of the closed-form elastic
    catenary (independent of the FE model)."""
    doc = chain_doc(grounded=False, sea=False, elements=40)
    h = _low_frequency_transfer(doc, "auto")
    ref = _fd_end_tension(doc, "catenary")
    # FE discretization O(h²) (0.2 % at 20 elements, 0.01 % at 80) + ω² m L inertia
    assert h.real == pytest.approx(ref, rel=1e-3)
    assert abs(h.imag) < 1e-3 * abs(h.real)


def test_quasi_static_fairlead_tension_matches_fe_statics():
    """Suspended chain about its FE equilibrium: the linear model is the tangent of the
    FE statics, so H_T(ω→0) equals the finite difference of the FE statics."""
    doc = chain_doc(grounded=False, sea=False, elements=30)
    h = _low_frequency_transfer(doc, "fe")
    ref = _fd_end_tension(doc, "fe")
    # central difference O(δ²) and ω = 1e-3 rad/s inertia: 1e-4 (measured 1.1e-5)
    assert h.real == pytest.approx(ref, rel=1e-4)


def test_quasi_static_fairlead_tension_with_seabed_matches_catenary_stiffness():
    """Grounded chain on a stiff bed: H_T(ω→0) tends to dT_b/dx of the closed-form
    elastic catenary on a rigid frictionless bed.  The linear model's suspended span
    ends at the static touchdown whatever the mesh (the touchdown element is split
    there, stochcable.line.seabed), not at the last grounded node as the FE statics'
    own tangent does (whose finite difference jumps by 20 % between meshes here)."""
    doc = chain_doc(grounded=True, sea=False, elements=120)
    doc["environment"]["seabed"]["stiffness"] = 3.0e7
    h = _low_frequency_transfer(doc, "fe")
    ref = _fd_end_tension(doc, "catenary")
    # the bed's compliance moves the support √(T/k') ≈ 0.4 m behind the touchdown
    # (1e-3 of the stiffness here; 1.4 % at 3e6 Pa/m, 4.6 % at 3e5) plus the
    # discretization (0.1 % between 120 and 240 elements): measured −0.13 %
    assert h.real == pytest.approx(ref, rel=5e-3)


def test_end_reaction_tends_to_end_element_tension():
    """The support-force magnitude and the end element's δT differ by the inertia and
    drag of half an element: small at low frequency, O(h) at wave frequencies."""
    diffs, lows = [], []
    for n_el in (10, 40):
        doc = chain_doc(grounded=False, sea=False, elements=n_el, omega_count=20)
        scene, system, chans = system_and_channels(doc)
        lin = dfixedpoint.linearize(system, chans, scene.analysis)
        et = doutputs.element_tension_transfer(system, lin.response)
        ref = lin.response.end_tension["end_b"][0]
        diffs.append(np.max(np.abs(et[0, -1] - ref)) / np.max(np.abs(ref)))
        ch0 = line_channels(scene, scene.lines[0], system.positions, np.array([1e-3]))
        r0 = dsolve.solve(system, ch0, lin.damping)
        e0 = doutputs.element_tension_transfer(system, r0)[0, -1, 0]
        t0 = r0.end_tension["end_b"][0, 0]
        lows.append(abs(e0 - t0) / abs(t0))
    # quasi-static: only the rotation of the end node's share of the weight differs,
    # O(h): below 1 % at 40 elements (12 m)
    assert lows[1] < 1e-2
    assert lows[1] < 0.5 * lows[0]
    assert diffs[1] < 0.5 * diffs[0]  # O(h) at wave frequencies: 4x finer, 2x closer


# ------------------------------------------------------------------ bad input


def test_unconverged_linearization_raises():
    # CPU-independent by a wide margin: the first iteration's relative change is 0.70
    # (measured), 7e7 times the tolerance 1e-8
    doc = chain_doc(elements=10, omega_count=20)
    doc["analysis"]["linearization"] = {"max_iterations": 1, "tolerance": 1e-8}
    with pytest.raises(
        ConvergenceError,
        match=r"drag linearization of line 'chain' did not converge.*"
        r"after 1 iterations.*max_iterations",
    ):
        analysis.analyze(doc)


def test_unconverged_linearization_flagged_when_allowed():
    doc = chain_doc(elements=10, omega_count=20)
    doc["analysis"]["linearization"] = {
        "max_iterations": 1,
        "tolerance": 1e-8,
        "allow_unconverged": True,
    }
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = analysis.analyze(doc)
    assert res.converged is False
    d = res.to_document()
    assert d["linearization"]["converged"] is False
    assert d["linearization"]["iterations"] == 1
    assert d["linearization"]["relative_change"] > 1e-8
    assert any("did not converge" in w for w in d["warnings"])


def test_harmonic_form_with_current_is_rejected():
    doc = chain_doc(elements=10, omega_count=20)
    doc["environment"]["current"] = [{"z": 0.0, "speed": 0.5}]
    doc["analysis"]["linearization"] = {"method": "harmonic"}
    with pytest.raises(InputError, match="harmonic.*current"):
        analysis.analyze(doc)


def test_rao_without_sea_is_rejected():
    doc = chain_doc(sea=False, surge=False, elements=10, omega_count=20)
    doc["lines"][0]["end_b"]["motion"] = {
        "rao": {"omega": [0.1, 2.0], "surge": {"re": [1.0, 1.0], "im": [0.0, 0.0]}}
    }
    with pytest.raises(InputError, match="needs a 'sea'"):
        analysis.analyze(doc)


def test_support_forces_balance_quasi_statically():
    """Suspended line, end motion only, ω → 0: no load change on the line, so the
    dynamic forces on the two supports cancel (static equilibrium of the line)."""
    doc = chain_doc(grounded=False, sea=False, elements=20)
    scene, system, _ = system_and_channels(doc)
    chans = line_channels(scene, scene.lines[0], system.positions, np.array([1e-4, 2e-4]))
    damping = dvariance.drag_coefficients(system, np.zeros(2 * system.model.n_elements), "seed")
    lin = dsystem.Linearization(
        damping=damping, record=None, response=dsolve.solve(system, chans, damping)
    )
    res = doutputs.line_result(system, chans, lin, scene.analysis)
    fa = res.end_force_transfer["end_a"][0, :, 0]
    fb = res.end_force_transfer["end_b"][0, :, 0]
    # inertia ω² M_total U_mean at 1e-4 rad/s: ~1e-8 of the force
    assert np.linalg.norm(fa + fb) < 1e-6 * np.linalg.norm(fb)
    assert fb[1] == 0.0 and fa[1] == 0.0  # 2-D model: no y force
    # δ|F_b| is the projection of δF_b on the static force direction
    u = system.statics.force_b / np.linalg.norm(system.statics.force_b)
    assert res.end_tension_transfer["end_b"][0, 0] == pytest.approx(u @ fb, rel=1e-12)


def test_grid_cutting_the_response_warns():
    """Fairlead surge with a PM tail: the inertia-driven tension spectrum decays like
    ω⁻¹, so a grid ending at 2 rad/s cuts it; extending the grid raises σ."""
    doc = chain_doc(sea=False, elements=12, omega_count=60)
    with pytest.warns(
        ResolutionWarning,
        match=r"end_b tension spectrum .* raise "
        r"analysis.omega.max",
    ):
        short = analysis.analyze(doc)
    doc["analysis"]["omega"]["max"] = 6.0
    doc["analysis"]["omega"]["count"] = 180
    long = analysis.analyze(doc)
    assert long.lines["chain"].end_b.std > 1.05 * short.lines["chain"].end_b.std


def test_rao_end_motion_adds_coherently_to_the_wave_loads():
    """An RAO end motion belongs to the sea channel: for a fixed drag, its transfer is
    H_waves + RAO(ω)·H_unit-surge (complex sum, not a sum of variances)."""
    doc = chain_doc(sea=True, surge=True, elements=12, omega_count=20)
    scene, system, chans = system_and_channels(doc)
    lin = dfixedpoint.linearize(system, chans, scene.analysis)
    base = dsolve.solve(system, chans, lin.damping).end_tension["end_b"]  # [sea, surge]
    w = chans[0].omega
    rao_re, rao_im = np.cos(w) * 0.8, -0.3 * w
    doc_r = copy.deepcopy(doc)
    doc_r["lines"][0]["end_b"]["motion"] = {
        "rao": {"omega": w.tolist(), "surge": {"re": rao_re.tolist(), "im": rao_im.tolist()}}
    }
    scene_r = load_scene(doc_r)
    chans_r = line_channels(scene_r, scene_r.lines[0], system.positions, w)
    assert [c.name for c in chans_r] == ["sea"]
    with_rao = dsolve.solve(
        dataclasses.replace(system, line=scene_r.lines[0]), chans_r, lin.damping
    ).end_tension["end_b"][0]
    expected = base[0] + (rao_re + 1j * rao_im) * base[1]
    # linear superposition: round-off only
    np.testing.assert_allclose(with_rao, expected, rtol=1e-9, atol=1e-9 * np.abs(expected).max())


def test_strong_current_drag_tends_to_steady_drag_tangent():
    """U_n ≫ σ: B_n → ρ Cdn D |U_n| with U_n the current's component normal to each
    element (DESIGN.md current form), checked against the geometry computed here."""
    doc = chain_doc(grounded=False, sea=True, surge=False, elements=12, omega_count=20)
    doc["sea"]["spectrum"] = {"type": "pierson_moskowitz", "hs": 0.05, "tp": 9.0}
    doc["environment"]["current"] = [{"z": 0.0, "speed": 1.5, "heading": 0.0}]
    res = analysis.analyze(doc)
    rec = res.lines["chain"].linearization
    pos = res.lines["chain"].positions
    e = np.diff(pos, axis=0)
    e /= np.linalg.norm(e, axis=1)[:, None]
    u = np.array([1.5, 0.0, 0.0])
    u_n = np.linalg.norm(u - (e @ u)[:, None] * e, axis=1)
    ref = 1025.0 * 2.4 * 0.1 * u_n
    # σ_n/U_n < 3 %: E|v| = U(1 + σ²/U² + ...) within 1e-3 relative
    assert np.all(rec.sigma_normal < 0.03 * u_n)
    np.testing.assert_allclose(rec.b_normal, ref, rtol=1e-3)


# --------------------------------------------------- Rayleigh structural damping


def test_rayleigh_damping_equals_independent_linear_solve():
    """Cd = 0, no current, no seabed contact: the transfer functions are the linear
    solve of (K − ω²M_T + iω(αM_T + βK))U = F, built here from the FE matrices and the
    sparse load assembly of stochcable.dynamics.loads.channels (independent of the block solver)."""
    from stochcable.dynamics.loads.channels import prescribed_motion, wave_loads

    doc = chain_doc(grounded=False, sea=True, surge=True, elements=12, omega_count=25)
    for seg in doc["lines"][0]["segments"]:
        seg["cd_normal"] = 0.0
        seg["cd_axial"] = 0.0
    alpha, beta = 0.02, 0.01
    doc["analysis"]["structural_damping"] = {"alpha": alpha, "beta": beta}
    scene, system, chans = system_and_channels(doc)
    model = system.model
    assert not model.grounded.any()
    K = model.K.toarray()
    MT = (model.M + model.Ma).toarray()
    C = alpha * MT + beta * K
    w = chans[0].omega
    n_el = model.n_elements
    F = wave_loads(model, chans, np.zeros(n_el), np.zeros(n_el), g=9.80665)
    ub = prescribed_motion(model, chans, w.size)
    free, fixed = model.free, model.fixed
    Z = K[None] - w[:, None, None] ** 2 * MT[None] + 1j * w[:, None, None] * C[None]
    rhs = F[:, free] - Z[:, free][:, :, fixed] @ ub
    u_ref = np.linalg.solve(Z[:, free][:, :, free], rhs)
    lin = dfixedpoint.linearize(system, chans, scene.analysis)
    assert np.all(lin.damping.b_normal == 0.0) and np.all(lin.damping.b_axial == 0.0)
    for solver in ("direct", "foss"):
        sysx = with_all_modes(system, solver)
        resp = dsolve.solve(sysx, chans, lin.damping)
        # two exact solves of a 22-DOF system (LU vs Foss eigenvectors): round-off
        u = resp.displacement[:, free]
        assert np.max(np.abs(u - u_ref)) <= 1e-9 * np.max(np.abs(u_ref)), solver
        np.testing.assert_array_equal(resp.displacement[:, fixed], ub)
        # support forces: −[Z U − F] on the end rows
        u_all = np.zeros((w.size, model.n_dof, len(chans)), dtype=complex)
        u_all[:, free], u_all[:, fixed] = u_ref, ub
        ref_f = -(Z[:, fixed] @ u_all - F[:, fixed])
        assert np.max(np.abs(resp.support_force - ref_f)) <= 1e-8 * np.max(np.abs(ref_f))
    # analyze() reaches the same system: end tension σ with and without all modes
    res = analysis.analyze(doc)
    assert res.lines["chain"].linearization.converged


def test_rayleigh_damped_taut_string_first_mode_peak():
    """Weightless taut string, Cd = Ca = 0, heave of end_b, evaluated at the first
    natural frequency ω1 = πc/L: the midspan amplitude is the quasi-static 1/2 plus
    the damped modal oscillator at resonance, q = Γ(ω1² − iαω1)/(2iζ1ω1²) with
    Γ = 2/π (participation of the linear shape x/L in sin(πx/L)) and
    2ζ1ω1 = α + βω1² (Rayleigh)."""
    ea, l0, span, m = STRING_EA, STRING_L0, STRING_SPAN, STRING_M
    n_el = 100
    alpha, beta = 0.01, 2.0e-4
    doc = _taut_string_doc(
        n_el,
        {
            "omega": {"min": 0.5, "max": 2.5, "count": 9},
            "solver": "direct",
            "structural_damping": {"alpha": alpha, "beta": beta},
        },
    )
    scene, system, _ = system_and_channels(doc)
    tension = ea * (span / l0 - 1.0)
    c = math.sqrt(tension / (m * l0 / span))
    w1 = math.pi * c / span
    zeta = 0.5 * (alpha / w1 + beta * w1)
    assert 1e-3 < zeta < 1e-2  # light damping: the resonant term dominates
    gamma = 2.0 / math.pi
    q = gamma * (w1**2 - 1j * alpha * w1) / (2j * zeta * w1**2)
    expected = abs(0.5 + q)
    chans = line_channels(scene, scene.lines[0], system.positions, np.array([w1]))
    damping = dvariance.drag_coefficients(system, np.zeros(2 * n_el), "seed")
    for solver in ("direct", "foss"):
        resp = dsolve.solve(dataclasses.replace(system, solver=solver), chans, damping)
        mid = resp.displacement[0, 2 * (n_el // 2) + 1, 0]
        # non-resonant modes 3, 5, … add ~Γ3/8 ≈ 0.03 (4e-4 of |q| ≈ 60), FE frequency
        # error (kh)²/24 ≈ 4e-5 of ω1 moves the peak by 4e-5/ζ ≈ 1 % in phase, < 1e-4
        # in magnitude: 2e-3
        assert abs(mid) == pytest.approx(expected, rel=2e-3), solver
    # and without structural damping the same frequency is an undamped resonance
    undamped = dataclasses.replace(system, structural_damping=(0.0, 0.0))
    with pytest.raises(SolverError, match="singular|resonance"):
        dsolve.solve(
            undamped,
            line_channels(
                scene, scene.lines[0], system.positions, np.array([system.modes.omega[0]])
            ),
            damping,
        )


def test_damping_matrix_is_assembled_lazily_and_equals_drag_matrix():
    import json
    from pathlib import Path

    from stochcable.dynamics.loads.channels import drag_matrix

    path = Path(dsystem.__file__).parents[2] / "examples" / "chain_catenary.json"
    scene = load_scene(json.loads(path.read_text()))
    st = solve_statics(scene)
    line = scene.lines[0]
    system = dsystem.build_line_system(scene, line, st.lines[line.name])
    n_el = system.model.n_elements
    damping = dvariance.drag_coefficients(system, np.linspace(0.1, 0.5, 2 * n_el), "seed")
    assert "matrix" not in damping._cache  # nothing assembled in the iteration
    ref = drag_matrix(system.model, damping.b_normal, damping.b_axial, damping.b_node)
    assert abs(damping.matrix - ref).max() == 0.0  # the same assembly, exactly


# --------------------------------------------- speed pass: same numbers, other route
# (issue 4, docs/BENCHMARKS.md "Response analysis", fifth pass).  Each fast route is
# checked against the computation it replaced.


@pytest.fixture(scope="module")
def chain_parts():
    scene, system, chans = system_and_channels(chain_doc(elements=16, omega_count=100))
    inp = dloads.line_inputs(system, chans)
    x = dvariance.rest_sigmas(system, inp, "seed")
    damping = dvariance.drag_coefficients(system, x, "seed")
    return scene, system, chans, inp, damping


def test_node_block_stash_follows_in_place_changes(chain_parts):
    """_blocks_of reads the node blocks fem stashed on its matrices; a matrix changed in
    place afterwards is read again from its CSR entries."""
    _, system, _, _, _ = chain_parts
    model = system.model
    d = model.dim
    k = model.K.copy()  # a copy carries no stash: the CSR route
    k._node_blocks = model.K._node_blocks
    ref = dblocks.node_blocks(model.K.copy(), d)
    got = dblocks.node_blocks(k, d)
    for g_, r_ in zip(got, ref):
        np.testing.assert_array_equal(g_, r_)
    k.data *= 2.0  # changed in place: the stash no longer matches its entries
    for g_, r_ in zip(dblocks.node_blocks(k, d), ref):
        np.testing.assert_array_equal(g_, 2.0 * r_)


def test_base_load_equals_block_products(chain_parts):
    """_base builds M_T U_p, C_s U_p from the cached products with the unit end
    displacements, and only for the channels that move an end; against the block
    products of the whole U_p (the route it replaced): 1e-13 of the largest load
    (round-off of sums in another order)."""
    _, system, _, inp, _ = chain_parts
    prep = dblocks.line_prep(system)
    u, f0, q = dloads.base_motion(system, prep, inp)
    u_ref = dvariance.quasi_static_motion(system, inp)  # Foss: U_p is the quasi-static following
    np.testing.assert_allclose(u, u_ref, rtol=0, atol=1e-14 * np.abs(u_ref).max())
    f0_ref = inp.inertia_load - dsolve._dynamic(prep, prep.S, inp.omega, u_ref)
    np.testing.assert_allclose(f0, f0_ref, rtol=0, atol=1e-13 * np.abs(f0_ref).max())
    np.testing.assert_array_equal(u[..., 0], 0.0)  # the sea channel moves no end
    np.testing.assert_array_equal(f0[..., 0], inp.inertia_load[..., 0])


def test_free_load_equals_drag_load_plus_damping_of_end_motion(chain_parts):
    """_free_load merges F_d(V) and C_d Q into one element load of combined moments;
    against the two loads of the route it replaced: 1e-13 of the largest; a block of
    frequencies is that block of the whole (the same products, fewer columns)."""
    _, system, _, inp, damping = chain_parts
    prep = dblocks.line_prep(system)
    u, f0, _ = dloads.base_motion(system, prep, inp)
    q = (-1j * inp.omega)[:, None] * u
    ref = (
        dloads._drag_load(system, inp, damping)
        + f0
        + dblocks.block_matvec(dloads.drag_blocks(system, damping), q)
    )
    got = dloads.free_load(system, prep, inp, damping)
    np.testing.assert_allclose(got, ref, rtol=0, atol=1e-13 * np.abs(ref).max())
    block = slice(3, 10)
    got = dloads.free_load(system, prep, inp, damping, block)
    np.testing.assert_allclose(got, ref[:, :, block], rtol=0, atol=1e-13 * np.abs(ref).max())


def test_rest_sigmas_equal_quasi_static_sigmas(chain_parts):
    """The start σ from the cached projections (Foss) are _sigmas of the quasi-static
    motion, to the bit."""
    _, system, _, inp, _ = chain_parts
    ref = dvariance.sigmas_from_nodes(
        system, inp, dvariance.quasi_static_motion(system, inp), "seed"
    )
    np.testing.assert_array_equal(dvariance.rest_sigmas(system, inp, "seed"), ref)


def test_subset_caches_are_the_subset_computation(chain_parts, monkeypatch):
    """The coarse subset slices the full grid's drag-independent arrays; computed on
    the subset directly they are the same (1e-15: products in other batch sizes)."""
    monkeypatch.delenv("STOCHCABLE_WORKING_MEMORY_MB", raising=False)  # (caches kept)
    _, system, chans, inp, _ = chain_parts
    prep = dblocks.line_prep(system)
    dvariance.end_motion_projections(system, inp, "seed")
    dloads.drag_inputs(system, prep, inp)
    dvariance.fluid_terms(system, inp, "seed")
    idx = np.unique(np.r_[np.arange(0, inp.omega.size, 4), inp.omega.size - 1])  # stride 4
    sliced = dgrid.subset_inputs(system, chans, inp, idx)
    fresh = dgrid.subset_inputs(system, chans, dloads.line_inputs(system, chans), idx)
    assert ("following", "foss") in sliced.cache and not fresh.cache

    def close(a, b):
        if callable(a):  # U_p of end_motion_projections, on a slice of the frequencies
            a, b = a(slice(None)), b(slice(None))
        if a is None or b is None:
            assert a is None and b is None
        else:
            scale = float(np.abs(b).max(initial=0.0))
            np.testing.assert_allclose(a, b, rtol=0, atol=1e-15 * scale)

    for fn in (
        lambda i: dloads.base_motion(system, prep, i),
        lambda i: dloads.drag_inputs(system, prep, i),
        lambda i: dvariance.end_motion_projections(system, i, "seed"),
        lambda i: dvariance.fluid_terms(system, i, "seed"),
    ):
        for a, b in zip(fn(sliced), fn(fresh)):
            close(a, b)


def test_reactions_and_tension_transfer_equal_their_direct_formulas(chain_parts):
    """End reactions from real block products (_reactions) against the impedance blocks
    Z = K − ω²M_T + iωC applied to U with the whole-line loads; the element tension
    transfer against the einsum e·(u_b − u_a)·EA/l0: 1e-12 of the largest (the end rows
    sum stiffness terms much larger than their sum)."""
    _, system, chans, inp, damping = chain_parts
    prep = dblocks.line_prep(system)
    u_f, c = dsolve.solve_free(system, inp, damping)
    u = dsolve.total_displacement(system, inp, u_f)
    w = inp.omega
    got = dsolve.reactions(system, prep, c, u, dloads.end_loads(system, inp, damping), w)
    f_all = dloads.fluid_loads(system, inp, damping)
    w2, iw = (w * w)[:, None, None], (1j * w)[:, None, None]

    def z(k, i):
        return prep.K[k][i][None] - w2 * prep.MT[k][i][None] + iw * c[k][i][None]

    ra = (
        np.einsum("wpq,qwc->wpc", z(0, 0), u[0])
        + np.einsum("wqp,qwc->wpc", z(1, 0), u[1])
        - np.moveaxis(f_all[0], 1, 0)
    )
    rb = (
        np.einsum("wpq,qwc->wpc", z(0, -1), u[-1])
        + np.einsum("wpq,qwc->wpc", z(1, -1), u[-2])
        - np.moveaxis(f_all[-1], 1, 0)
    )
    ref = -np.concatenate([ra, rb], axis=1)
    np.testing.assert_allclose(got, ref, rtol=0, atol=1e-12 * np.abs(ref).max())
    resp = dsolve.line_response(system, inp, damping, (u, c))
    model = system.model
    uu = resp.displacement.reshape(w.size, model.n_nodes, model.dim, -1)
    rows = model.tension_rows  # (EA/l0)(−e, e); the split touchdown element its own
    np.testing.assert_allclose(
        np.delete(rows[:, 1], int(np.flatnonzero(model.grounded)[-1]), axis=0),
        np.delete(
            (model.mesh.ea / model.l0)[:, None] * model.tangents,
            int(np.flatnonzero(model.grounded)[-1]),
            axis=0,
        ),
        rtol=1e-14,
    )
    ref_t = np.einsum("wedc,ed->cew", uu[:, :-1], rows[:, 0]) + np.einsum(
        "wedc,ed->cew", uu[:, 1:], rows[:, 1]
    )
    got_t = doutputs.element_tension_transfer(system, resp)
    # 1e-12: the split touchdown element's two rows are large (EA over its suspended
    # part's length) and nearly opposite, so the sums cancel to ~1e-13 of the largest
    np.testing.assert_allclose(got_t, ref_t, rtol=0, atol=1e-12 * np.abs(ref_t).max())


def test_attachment_drag_sigma_is_the_total_relative_velocity_sigma():
    """An attachment with a drag area under a sea: its linearization σ is that of the
    total relative velocity V − iωU at its node (trapezoid over ω, all components, all
    channels), computed here from the response and the channels' nodal velocities
    (the σ used to flatten the components into the frequency axis and failed)."""
    doc = chain_doc(elements=12, omega_count=60)
    doc["lines"][0]["attachments"] = [
        {"at": 300.0, "mass": 500.0, "buoyancy": 2.0e4, "drag_area": 2.0, "added_mass": 300.0}
    ]
    scene, system, chans = system_and_channels(doc)
    node = int(system.drag_nodes[0])
    lin = dfixedpoint.linearize(system, chans, scene.analysis)
    sig = dvariance.relative_velocity_sigmas(system, chans, lin.response, "seed")
    w = chans[0].omega
    u = lin.response.displacement.reshape(w.size, system.model.n_nodes, system.model.dim, -1)
    comps = list(system.model.components)
    var = 0.0
    for i, ch in enumerate(chans):
        v = np.zeros((w.size, system.model.dim), dtype=complex)
        if ch.velocity is not None:
            v = ch.velocity[:, node][:, comps]
        rel = v - 1j * w[:, None] * u[:, node, :, i]
        var += np.trapezoid(ch.spectrum * np.sum(np.abs(rel) ** 2, axis=1), w)
    # the same sums in another order: round-off
    assert sig[-1] == pytest.approx(math.sqrt(var), rel=1e-12)
    res = analysis.analyze(doc)
    assert np.isfinite(res.lines["chain"].end_b.std)


def _scene_without_timeseries(name: str):
    from stochcable.examples import load_example

    scene = load_scene(load_example(name))
    return scene.model_copy(
        update={"analysis": scene.analysis.model_copy(update={"timeseries": None})}
    )


def test_warnings_and_document_use_the_scene_units_in_feet(monkeypatch) -> None:
    """Tuah (1982) single leg is in feet, slugs and pounds-force (g = 32.17 ft/s²): the
    snap, element-resolution and large-motion warnings give its forces in lbf and
    lengths in ft (they said N and m), and the result document names the system."""
    from stochcable.scene.units import FOOT_SLUG_SECOND

    # a zero sag threshold forces the large-motion warning, so all three are checked
    monkeypatch.setattr(dindicators, "MOTION_SAG_FRACTION", 0.0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = analysis.analyze(_scene_without_timeseries("tuah_1982_single_leg"))
    snap = [m for m in res.warnings if "dynamic tension σ" in m]
    surface = [m for m in res.warnings if "wave-velocity σ varies" in m]
    motion = [m for m in res.warnings if "motion σ at node" in m]
    assert len(snap) == len(surface) == len(motion) == 1, res.warnings
    assert re.search(r"\d lbf at end_a\)", snap[0]) and "mean tension (" in snap[0]
    assert re.search(r"\(\d[^)]* lbf\): mean", snap[0])
    assert re.search(r"to -?\d[\d.]* ft; threshold", surface[0])
    assert re.search(r"at most [\d.e+-]+ ft of depth", surface[0])
    assert re.search(r"\(\d[^)]* ft\) is .* sag \(\d[^)]* ft\)", motion[0])
    for m in snap + surface + motion:
        assert not re.search(r"\d (N|m)\b", m), m  # no SI label left
    assert res.to_document()["units"] == FOOT_SLUG_SECOND.as_dict()


def test_result_document_names_si_units() -> None:
    doc = analysis.analyze(_scene_without_timeseries("taut_wire")).to_document()
    assert doc["units"] == {"system": "SI", "length": "m", "mass": "kg", "force": "N", "time": "s"}


def test_nearest_spacing_equals_argmin_and_gradient():
    """The resolution check's nearest grid point and local spacing (searchsorted, pass
    E7) against the dense argmin and np.gradient they replace: the same bits, on a
    non-uniform grid, at the grid ends, on grid points and at exact midpoints (ties
    go to the lower point, as argmin)."""
    rng = np.random.default_rng(7)
    omega = np.cumsum(rng.uniform(0.01, 0.1, 50)) + 0.1
    mids = 0.5 * (omega[1:] + omega[:-1])
    x = np.concatenate([omega[[0, 1, -2, -1]], mids[::7], rng.uniform(omega[0], omega[-1], 200)])
    dist, spacing = dresolution._nearest_spacing(omega, x)
    near = np.argmin(np.abs(omega[None, :] - x[:, None]), axis=1)
    # exact equality: the same subtractions and divisions as np.argmin/np.gradient
    np.testing.assert_array_equal(dist, np.abs(omega[near] - x))
    np.testing.assert_array_equal(spacing, np.gradient(omega)[near])
