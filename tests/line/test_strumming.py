"""Strumming in the frequency domain (docs/strumming.md): the wake-oscillator harmonic
balance against time integration, Tuah 1982, §6.6 Example 6 (Ramberg et al. 1980) and
the hook-up (scene settings, drag amplification, warning, result document)."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
from _scenes import LINEAR_ONLY
from scipy.integrate import solve_ivp

from stochcable.design.curves import FatigueCurve
from stochcable.dynamics.engine import build_engine
from stochcable.dynamics.model.strumming import strumming_inputs
from stochcable.dynamics.model.system import build_line_system
from stochcable.errors import InputError, ResolutionWarning
from stochcable.examples import load_example
from stochcable.line.fem import build_fe_model
from stochcable.line.modes import natural_modes
from stochcable.line.strumming.balance import lock_in_balance, wake_parameters, wake_response
from stochcable.line.strumming.modes import out_of_plane_modes
from stochcable.line.strumming.screen import (
    StrummingInput,
    amplitude_griffin,
    drag_amplification_vandiver,
    element_flow,
    hydrodynamic_damping_ratio,
    reduced_damping,
    reduced_velocity,
    shedding_frequency,
    strouhal_roshko,
    strumming_screen,
)
from stochcable.reference.wake_oscillator import simulate_wake_oscillator
from stochcable.scene.model import load_scene
from stochcable.statics import solve_statics

# one worker runs the module: its module fixtures run once (--dist loadgroup)
pytestmark = pytest.mark.xdist_group("test_strumming")

FT = 0.3048
EXAMPLE = "tuah_1982_strumming_string"
#: Tuah 1982, §6.6: Strouhal frequency, fundamental, maximum transverse displacement
SEED_OMEGA_S = 15.73  # [rad/s]
SEED_OMEGA_1 = 14.6  # [rad/s]
SEED_AMPLITUDE = 0.016 * FT  # [m] (seed and the experiment of Ramberg et al. 1980)


# ------------------------------------------------------------------ closed forms


def test_shedding_band_damping_and_drag_closed_forms():
    # ω_s = 2π St U/D (Tuah 1982, eq. 3.2.b.4)
    assert shedding_frequency(1.0, 0.1, 0.2) == pytest.approx(2 * math.pi * 2.0, rel=1e-15)
    # V_R = 2πU/(ω_n D): at ω_n = ω_s it is 1/St
    ws = shedding_frequency(0.7, 0.05, 0.18)
    assert reduced_velocity(0.7, ws, 0.05) == pytest.approx(1 / 0.18, rel=1e-14)
    # the seed's two forms of k_s (eq. 3.2.b.6 with eq. 3.2.b.8): 4πmξ/(ρD²) with the
    # viscous ξ is 48 √(ν/ω)/D exactly (the seed rounds 48 to 45); S_G = 2π St² k_s
    rho, d, m, nu, w = 1025.0, 0.02, 0.9, 1.19e-6, 12.0
    xi = hydrodynamic_damping_ratio(rho, d, m, nu, w)
    ks = 4 * math.pi * m * xi / (rho * d**2)
    assert ks == pytest.approx(48 * math.sqrt(nu / w) / d, rel=1e-14)
    assert reduced_damping(m, xi, rho, d, 0.2) == pytest.approx(2 * math.pi * 0.04 * ks, rel=1e-14)
    # Vandiver (1983): 1 + 1.043 (2 Y_rms/D)^0.65; 2 Y_rms = D gives 2.043
    assert drag_amplification_vandiver(0.5) == pytest.approx(2.043, rel=1e-15)
    assert drag_amplification_vandiver(0.0) == 1.0


def test_bad_parameters_name_parameter_value_unit_constraint():
    with pytest.raises(InputError, match=r"strouhal = 0.0: must be finite and > 0"):
        shedding_frequency(1.0, 0.1, 0.0)
    with pytest.raises(InputError, match=r"y_rms_over_d .*>= 0"):
        drag_amplification_vandiver(-0.1)
    doc = load_example(EXAMPLE).model_dump(exclude_none=True)
    seg = doc["lines"][0]["segments"][0]
    for key, value, where in (
        ("strouhal", 0.0, "strouhal"),
        ("strouhal", -0.2, "strouhal"),
        ("lift_coefficient", -0.1, "lift_coefficient"),
        ("suppression", "bubbles", "suppression"),
    ):
        bad = {**seg, "strumming": {**seg["strumming"], key: value}}
        scene = {**doc, "lines": [{**doc["lines"][0], "segments": [bad]}]}
        with pytest.raises(InputError, match=rf"lines\[0\]\.segments\[0\]\.strumming\.{where}"):
            load_scene(scene)
    with pytest.raises(InputError, match=r"environment\.viscosity"):
        load_scene({**doc, "environment": {**doc["environment"], "viscosity": 0.0}})


# ------------------------------------------------------------------ the balance


@pytest.mark.parametrize(("ratio", "velocity"), [(1.0, 0.1), (1.0, 2.0), (0.95, 2.0), (1.05, 2.0)])
def test_wake_balance_matches_the_forced_wake_in_time(ratio, velocity):
    """A wake driven by a prescribed Ẏ/D = v cos ωt: the first harmonic of its
    steady (entrained) time history equals :func:`wake_response`."""
    params = wake_parameters(0.15, 0.02)
    ws, c0, w = 1.0, 0.2, ratio

    def rhs(t, y):
        c, cd = y
        b = c0**2 - c**2 - (cd / ws) ** 2
        forcing = ws * params.f * velocity * math.cos(w * t)
        return [cd, -(ws**2) * c + b * (ws * params.g * cd - ws**2 * params.big_h * c) + forcing]

    t_end = 2000.0
    t = np.linspace(t_end - 40 * 2 * math.pi / w, t_end, 8001)
    sol = solve_ivp(rhs, (0.0, t_end), [c0, 0.0], method="DOP853", t_eval=t, rtol=1e-10, atol=1e-12)
    c1 = 2.0 * np.mean(sol.y[0] * np.exp(-1j * w * t))  # 40 whole periods: exact projection
    hb = wake_response(np.array([velocity + 0j]), w, np.array([ws]), np.array([c0]), params)[0]
    # 0.5 %: the third harmonic the first-harmonic balance drops is ~1e-3 of C here
    assert abs(hb - c1) < 5e-3 * abs(c1)


def _string_mode(n_el=8, mstar=3.0, st=0.18):
    """A pinned uniform string in uniform flow, D = ρ = U = 1: ψ, q, D, ω_s."""
    length = 20.0
    x = (np.arange(n_el) + 0.5) / n_el * length
    psi = math.sqrt(2.0 / (mstar * length)) * np.sin(math.pi * x / length)
    q = np.full(n_el, 0.5 * length / n_el)
    return psi, q, np.ones(n_el), np.full(n_el, 2 * math.pi * st), mstar, st


@pytest.mark.slow
@pytest.mark.parametrize(("ratio", "xi"), [(1.0, 0.02), (1.0, 0.2), (0.95, 0.05)])
def test_lock_in_balance_matches_the_time_domain_oscillator(ratio, xi):
    """The frequency-domain lock-in amplitude against the wake oscillators and the mode
    integrated in time (stochcable.reference.wake_oscillator) from rest, across the
    reduced damping S_G = 0.15 … 1.5 and 5 % detuning."""
    psi, q, d, ws, mstar, st = _string_mode()
    lift0 = np.full(psi.size, 0.2)
    sg = reduced_damping(mstar, xi, 1.0, 1.0, st)
    params = wake_parameters(sg, xi)
    wn = ratio * ws[0]
    fd = lock_in_balance(wn, xi, psi, q, d, ws, lift0, params)
    assert fd.locked
    hist = simulate_wake_oscillator(wn, xi, psi, q, d, ws, lift0, params, 300 * 2 * math.pi / ws[0])
    td = hist.amplitude(0.8 * hist.t[-1])
    # 7 %: the first-harmonic truncation; measured -6.4 % at S_G = 0.15, -5.3 % at 0.23,
    # -2 % at 0.38, -0.5 % at 0.77, -3 % at 1.5 (the balance is below the integration)
    assert fd.amplitude == pytest.approx(td, rel=0.07)
    assert fd.amplitude <= 1.005 * td


@pytest.mark.parametrize("xi", [0.02, 0.2])
def test_compiled_start_grid_equals_the_wake_closed_form(xi):
    """The compiled start grid of lock_in_balance (one cube root per wake, coefficients
    per frequency) against the modal residual formed from wake_response (NumPy, both
    Cardano roots) at every grid point: the same closed form, round-off apart (1e-9: the
    residual is a ratio of sums of ~40 terms; any wrong coefficient moves it by O(1));
    where the kernel's bound skips a point (marked 1.0), the residual is at least 0.5."""
    from stochcable.line.strumming.bound import LockInGrid
    from stochcable.line.strumming.kernels import balance_grid

    psi, q, d, ws, mstar, st = _string_mode()  # a mode that locks in (test above)
    rng = np.random.default_rng(7)  # and wakes that differ element by element
    ws = ws * rng.uniform(0.98, 1.02, ws.size)
    lift0 = rng.uniform(0.18, 0.22, ws.size)
    wn = float(np.mean(ws))
    params = wake_parameters(reduced_damping(mstar, xi, 1.0, 1.0, st), xi)
    amps = np.geomspace(1e-3, 3.0, 20) / np.max(np.abs(psi) / d)
    omegas = np.linspace(0.65, 1.35, 29) * wn
    grid = balance_grid(
        LockInGrid(amps, omegas, wn, xi, psi, q, d, ws, lift0, params.g, params.big_h, params.f)
    )
    a_, w_ = np.meshgrid(amps, omegas, indexing="ij")
    a_, w_ = a_.reshape(-1, 1), w_.reshape(-1, 1)
    c = wake_response(1j * w_ * a_ * psi / d, w_, ws, lift0, params)
    left = (wn**2 - w_[:, 0] ** 2 + 2j * xi * wn * w_[:, 0]) * a_[:, 0]
    right = c @ (q * psi)
    ref = (np.abs(left - right) / (np.abs(left) + np.abs(right))).reshape(grid.shape)
    proven = grid == 1.0  # the kernel's bound |Z A| >= 3 |L|: residual >= 0.5, skipped
    assert np.all(ref[proven] >= 0.5)
    np.testing.assert_allclose(grid[~proven], ref[~proven], rtol=0, atol=1e-9)
    assert proven.any() and (~proven).sum() > 10  # both paths taken
    assert ref.min() < 0.15 < 0.5 < ref.max()  # near a root and far from one


@pytest.mark.parametrize("xi, amp_scale", [(0.02, 1.0), (0.2, 1.0), (5.0, 1.0), (0.2, 1e-6)])
def test_numpy_bound_proves_what_the_kernel_proves(xi, amp_scale):
    """grid_is_proven (NumPy, checked before numba is imported) is True exactly when the
    compiled grid is proven at every point (all 1.0): the locking mode of the test above
    (not proven), a heavily damped one and tiny amplitudes (proven)."""
    from stochcable.line.strumming.bound import LockInGrid, grid_is_proven
    from stochcable.line.strumming.kernels import balance_grid

    psi, q, d, ws, mstar, st = _string_mode()
    rng = np.random.default_rng(7)
    ws = ws * rng.uniform(0.98, 1.02, ws.size)
    lift0 = rng.uniform(0.18, 0.22, ws.size)
    wn = float(np.mean(ws))
    params = wake_parameters(reduced_damping(mstar, xi, 1.0, 1.0, st), xi)
    amps = amp_scale * np.geomspace(1e-3, 3.0, 20) / np.max(np.abs(psi) / d)
    args = (amps, np.linspace(0.65, 1.35, 29) * wn, wn, xi, psi, q, d, ws, lift0)
    start = LockInGrid(*args, params.g, params.big_h, params.f)
    assert grid_is_proven(start) == bool(np.all(balance_grid(start) == 1.0))


# ------------------------------------------------------------------ Example 6


@pytest.fixture(scope="module")
def example6():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        engine = build_engine(load_example(EXAMPLE))
    scene, system = engine.scene, engine.systems["string"]
    inp, omega, shapes = strumming_inputs(scene, system)
    return engine, engine.strumming["string"], inp, omega, shapes


def test_example6_frequencies(example6):
    _, table, *_ = example6
    cross = table.modes[0]  # the candidate nearest ω_s: the first vertical mode
    # 0.1 %: St = 0.18 is the seed's 15.73 rad/s back-computed to two digits
    # (2π·0.18·0.695/0.05 = 15.7205 rad/s, 0.06 % below the printed value)
    assert cross.omega_s == pytest.approx(SEED_OMEGA_S, rel=1e-3)
    # 5 %: the seed's 14.6 rad/s is its 4-element consistent-mass string without added
    # mass at the initial stress (14.63 rad/s); here C_a = 1 (-11 % on ω) and the
    # equilibrium under weight and drag (+5.6 % tension, sag stiffening in the vertical
    # plane) bring it to 14.13 rad/s (-3.3 %); the seed does not say which it used
    assert cross.omega_n == pytest.approx(SEED_OMEGA_1, rel=0.05)
    assert cross.reduced_velocity == pytest.approx(6.18, abs=0.01)  # in DNV's 3…16


def test_example6_amplitude_against_seed_experiment_and_time_domain(example6):
    engine, table, inp, omega, shapes = example6
    cross = table.modes[0]
    # the string does not lock in: ω_s/ω_n = 1.11 is outside the wake's entrainment
    assert not cross.locked and not table.locked
    fd = cross.amplitude_over_d * inp.diameter[0]  # the beat bound 2·A_f
    # 30 %: A_f ∝ 1/|ω_n² − ω_s²|, and the 3.3 % between this model's fundamental and
    # the seed's moves it by 40 % (next assertion); measured -26 %
    assert fd == pytest.approx(SEED_AMPLITUDE, rel=0.30)
    # with the seed's own fundamental (14.6 rad/s, the modes scaled to it) the bound
    # is within 10 % of the seed and the experiment (measured +4 %)
    seed_table = strumming_screen(inp, omega * SEED_OMEGA_1 / cross.omega_n, shapes)
    seed_fd = seed_table.modes[0].amplitude_over_d * inp.diameter[0]
    assert seed_fd == pytest.approx(SEED_AMPLITUDE, rel=0.10)
    # the seed's time integration (its start: at rest, C_L = C_L0 everywhere): the
    # first beat peaks near t = 2.0 s as in the seed's Fig. 6.6-2, below the bound,
    # and the unlocked wakes drift apart so the response decays
    flow = element_flow(inp)
    psi = flow.along_lift(shapes[:, :, cross.index])
    params = wake_parameters(cross.reduced_damping, cross.damping_ratio)
    hist = simulate_wake_oscillator(
        cross.omega_n,
        cross.damping_ratio,
        psi,
        flow.q,
        inp.diameter,
        flow.omega_s,
        inp.lift,
        params,
        50.0,
    )
    y = np.abs(hist.z) * np.max(np.abs(psi))
    first = hist.t < 5.0
    t_peak = hist.t[first][np.argmax(y[first])]
    assert 1.5 < t_peak < 2.5
    assert y[first].max() <= fd
    assert y[first].max() == pytest.approx(SEED_AMPLITUDE, rel=0.45)  # measured -39 %
    assert y[hist.t > 40.0].max() < 0.6 * y[first].max()
    # no lock-in: the drag is not amplified and no warning
    assert np.array_equal(table.cd_normal, inp.cd_normal)
    assert not any("lock-in" in w for w in engine.warnings)


def _locked_scene(**strumming):
    doc = load_example(EXAMPLE).model_dump(exclude_none=True)
    doc["environment"]["current"][0]["speed"] = 0.18  # ω_s = 13.36 rad/s near ω_1
    seg = doc["lines"][0]["segments"][0]
    seg["strumming"] = {**seg["strumming"], **strumming}
    doc["sea"] = {"spectrum": {"type": "jonswap", "hs": 0.05, "tp": 0.5}, "heading": 90.0}
    return doc


def test_locked_in_string_amplifies_drag_warns_and_reports():
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        engine = build_engine(_locked_scene())
    table = engine.strumming["string"]
    mode = table.modes[table.governing]
    assert mode.locked and mode.index == 1
    # the frequency-domain amplitude against the time integration from rest
    inp, omega, shapes = strumming_inputs(engine.scene, engine.systems["string"])
    flow = element_flow(inp)
    psi = flow.along_lift(shapes[:, :, mode.index])
    params = wake_parameters(mode.reduced_damping, mode.damping_ratio)
    hist = simulate_wake_oscillator(
        mode.omega_n,
        mode.damping_ratio,
        psi,
        flow.q,
        inp.diameter,
        flow.omega_s,
        inp.lift,
        params,
        50.0,
    )
    td = hist.amplitude(40.0) * np.max(np.abs(psi) / inp.diameter)
    assert mode.amplitude_over_d == pytest.approx(td, rel=0.01)  # measured 0.02 %
    # Vandiver's amplification with Y_rms = A|ψ_e|/√2 of the mode, in the model
    y_rms = np.abs(flow.along_lift(mode.displacement)) / math.sqrt(2.0) / inp.diameter
    # (inp is read from the engine's system, whose drag is the amplified one already)
    expected = 1.2 * drag_amplification_vandiver(y_rms)
    assert np.allclose(table.cd_normal, expected, rtol=1e-14)
    assert np.all(table.cd_normal > 1.2)
    assert np.array_equal(engine.systems["string"].model.mesh.cd_normal, table.cd_normal)
    text = [str(w.message) for w in caught if "lock-in" in str(w.message)]
    assert len(text) == 1
    assert "mode 1" in text[0] and "band 3-16 of DNV-RP-C205" in text[0]
    assert "strakes or fairings" in text[0]
    assert any("lock-in" in w for w in engine.warnings)
    # the table in the result document, the tension range and cycle rate for fatigue
    doc = engine.solve().to_document()["lines"]["string"]["strumming"]
    assert doc["governing"] == table.governing
    row = doc["modes"][table.governing]
    assert row["locked"] and row["cycle_rate"] == pytest.approx(mode.omega / (2 * math.pi))
    assert len(row["tension_range"]) == 4 and max(row["tension_range"]) > 0
    # the narrow-band fatigue component: ν (ΔT/A)^m / a of a one-slope curve
    curve = FatigueCurve("test", "one slope", "stress", (3.0,), (12.0 + 18.0,))
    area = math.pi * 0.01524**2 / 4
    rate = mode.damage_rate(curve, 1.0 / area)
    expected = mode.cycle_rate * (mode.tension_range / area) ** 3 / 10.0**30
    assert np.allclose(rate, expected, rtol=1e-12)


def test_suppression_turns_strumming_off():
    stds = {}
    for kind in ("strakes", "fairings", "none"):
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            engine = build_engine(_locked_scene(suppression=kind))
            stds[kind] = engine.solve().lines["string"].tension_std
        if kind == "none":
            continue
        assert engine.strumming["string"] is None
        assert engine.systems["string"].model.mesh.cd_normal[0] == 1.2
        assert not any("lock-in" in str(w.message) for w in caught)
    # the amplified drag reaches the wave response (the drag linearization with the
    # current: damping and drag excitation both grow; measured +14 % tension σ)
    assert np.array_equal(stds["strakes"], stds["fairings"])
    assert np.all(stds["none"] > 1.05 * stds["strakes"])


def test_no_current_no_screening():
    doc = _locked_scene()
    doc["environment"]["current"] = []
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        engine = build_engine(doc)
    assert engine.strumming["string"] is None
    assert "strumming" not in engine.solve().to_document()["lines"]["string"]


def test_chain_example_is_screened_without_lock_in():
    """The chain in 0.5 m/s (a planar scene, 2-D model): its out-of-plane modes are
    screened, none locks in, so its drag and results are unchanged."""
    engine = build_engine(load_example("chain_catenary"))
    table = engine.strumming["leg1"]
    assert table is not None and len(table.modes) > 0
    assert not table.locked
    assert np.array_equal(engine.systems["leg1"].model.mesh.cd_normal, np.full(40, 1.333))


def test_out_of_plane_modes_of_a_2d_model_match_the_3d_model():
    scene = load_example("chain_catenary")
    statics = solve_statics(scene, method="fe")
    line = scene.lines[0]
    system2 = build_line_system(scene, line, statics.lines[line.name])
    assert system2.model.dim == 2
    w2, s2 = out_of_plane_modes(system2.model, 3.0)
    model3 = build_fe_model(statics.lines[line.name], scene.environment, dim=3)
    modes3 = natural_modes(model3, 60)
    w3 = modes3.omega[(modes3.plane == "out-of-plane") & (modes3.omega <= 3.0)]
    assert w2.size == w3.size > 5
    # 2e-6: the same geometric stiffness and mass, but the 3-D model condenses the
    # element that contains the touchdown (stochcable.line.seabed); measured 5e-7
    assert np.allclose(w2, w3, rtol=2e-6)
    # mass normalization: φᵀ M_T φ = 1 on the y DOFs of the 3-D model
    mt = model3.dense("MT")
    v = s2[:, :, 0].reshape(-1)  # node-major x, y, z: the 3-D model's DOF order
    assert float(v @ (mt @ v)) == pytest.approx(1.0, rel=1e-9)


def test_out_of_plane_modes_sparse_path_matches_dense(monkeypatch):
    import stochcable.line.strumming.modes as sm

    scene = load_example("chain_catenary")
    statics = solve_statics(scene, method="fe")
    model = build_line_system(scene, scene.lines[0], statics.lines["leg1"]).model
    w_dense, s_dense = out_of_plane_modes(model, 3.0)
    monkeypatch.setattr(sm, "_DENSE_MAX", 0)
    w_sparse, s_sparse = out_of_plane_modes(model, 3.0)
    # 1e-9: shift-invert Lanczos to its default tolerance, the same matrices
    assert np.allclose(w_sparse, w_dense, rtol=1e-9)
    # shapes up to sign
    dots = np.einsum("nm,nm->m", s_sparse[:, 1], s_dense[:, 1])
    norms = np.linalg.norm(s_sparse[:, 1], axis=0) * np.linalg.norm(s_dense[:, 1], axis=0)
    assert np.allclose(np.abs(dots) / norms, 1.0, atol=1e-8)


def test_strumming_input_checks():
    base = dict(
        positions=np.array([[0.0, 0, 0], [1.0, 0, 0]]),
        current=np.array([[0.0, 0.2, 0]]),
        diameter=np.array([0.02]),
        cd_normal=np.array([1.2]),
        mass=np.array([1.0]),
        ca_normal=np.array([1.0]),
        ea=np.array([1e5]),
        l0=np.array([1.0]),
        strouhal=np.array([0.2]),
        lift=np.array([0.2]),
        rho=1025.0,
        viscosity=1.19e-6,
    )
    StrummingInput(**base)
    with pytest.raises(InputError, match="lift_coefficient.*C_L0 must be >= 0"):
        StrummingInput(**{**base, "lift": np.array([-0.2])})
    with pytest.raises(InputError, match="strouhal"):
        StrummingInput(**{**base, "strouhal": np.array([0.0])})
    with pytest.raises(InputError, match="viscosity"):
        StrummingInput(**{**base, "viscosity": -1.0})
    with pytest.raises(InputError, match="damping_ratio"):
        StrummingInput(**{**base, "structural_damping": 1.5})


def test_screening_that_stops_below_the_lock_in_range_warns(monkeypatch):
    import stochcable.dynamics.model.strumming as ds

    doc = load_example(EXAMPLE).model_dump(exclude_none=True)
    doc["analysis"]["modes"] = 2  # the system keeps 2 modes (14.1 rad/s at most)
    monkeypatch.setattr(ds, "MAX_MODES", 2)
    with pytest.warns(ResolutionWarning, match=r"stops at mode 2 .* below 29.11 rad/s"):
        build_engine(doc)
    monkeypatch.setattr(ds, "MAX_MODES", 512)  # computed further up: no warning
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        engine = build_engine(doc)
    assert not any("stops at mode" in str(w.message) for w in caught)
    assert engine.strumming["string"].modes[0].index == 1


def _uniform_string(ratio, zeta=0.005, n_el=40, mstar=6.0, st=0.18):
    """A pinned uniform string along x in a uniform flow along y (D = ρ = U = 1), its
    first two vertical modes (sine shapes) at ratio·ω_s and 2·ratio·ω_s."""
    length = 20.0
    pos = np.zeros((n_el + 1, 3))
    pos[:, 0] = np.linspace(0.0, length, n_el + 1)
    inp = StrummingInput(
        positions=pos,
        current=np.tile([0.0, 1.0, 0.0], (n_el, 1)),
        diameter=np.ones(n_el),
        cd_normal=np.full(n_el, 1.2),
        mass=np.full(n_el, mstar),
        ca_normal=np.zeros(n_el),
        ea=np.full(n_el, 1e6),
        l0=np.full(n_el, length / n_el),
        strouhal=np.full(n_el, st),
        lift=np.full(n_el, 0.2),
        rho=1.0,
        viscosity=1e-7,
        structural_damping=np.full(n_el, zeta),
    )
    ws = 2 * math.pi * st
    shapes = np.zeros((n_el + 1, 3, 2))
    for j in range(2):
        shapes[:, 2, j] = math.sqrt(2 / (mstar * length)) * np.sin(
            (j + 1) * math.pi * pos[:, 0] / length
        )
    return inp, np.array([ratio * ws, 2 * ratio * ws]), shapes


def test_griffin_response_formula():
    # Y/D = 1.29 γ/(1 + 0.43 S_G)^3.35 (Griffin, Skop & Ramberg 1975)
    assert amplitude_griffin(0.0, 1.0) == 1.29
    assert amplitude_griffin(1.0, 2.0) == pytest.approx(2 * 1.29 / 1.43**3.35, rel=1e-15)
    with pytest.raises(InputError, match="reduced_damping"):
        amplitude_griffin(-0.1)


@pytest.mark.slow
def test_resonant_unlocked_mode_is_capped_and_conservative():
    """Low reduced damping (S_G = 0.08), ω_s in the half-power band: the first-harmonic
    balance has no entrained root, the free wakes drive the mode at resonance; the
    screening reports the Griffin amplitude, above what the time integration from rest
    settles at."""
    inp, omega, shapes = _uniform_string(1.0)
    table = strumming_screen(inp, omega, shapes)
    mode = table.modes[table.governing]
    assert not mode.locked and mode.resonant
    gamma = math.sqrt(4.0 / 3.0)  # a sine's shape factor
    # 0.5 %: the sine sampled at 40 element midpoints
    assert mode.amplitude_over_d == pytest.approx(
        amplitude_griffin(mode.reduced_damping, gamma), rel=5e-3
    )
    flow = element_flow(inp)
    psi = flow.along_lift(shapes[:, :, 0])
    params = wake_parameters(mode.reduced_damping, mode.damping_ratio)
    hist = simulate_wake_oscillator(
        mode.omega_n,
        mode.damping_ratio,
        psi,
        flow.q,
        inp.diameter,
        flow.omega_s,
        inp.lift,
        params,
        200 * 2 * math.pi / flow.omega_s[0],
    )
    td = hist.amplitude(0.8 * hist.t[-1]) * np.max(np.abs(psi))
    # conservative: measured 1.33 D against 0.94 D (+41 %; 1.20 D at ω_n/ω_s = 0.99)
    assert td < mode.amplitude_over_d < 1.6 * td
    assert np.all(table.cd_normal > 1.2)
    # detuned by 5 % (outside the half-power band 2ξ = 1.3 %): the balance locks in
    detuned = strumming_screen(inp, *_uniform_string(1.05)[1:])
    assert detuned.modes[0].locked and not detuned.modes[0].resonant


def test_strouhal_from_reynolds():
    # Roshko (1954): F = 0.212 Re − 4.5 (stable range), − 2.7 (irregular range)
    assert strouhal_roshko(100.0) == pytest.approx(0.212 - 4.5 / 100, rel=1e-15)
    assert strouhal_roshko(1000.0) == pytest.approx(0.212 - 2.7 / 1000, rel=1e-15)
    assert strouhal_roshko(1e4) == 0.2 and strouhal_roshko(30.0) == 0.0
    with pytest.raises(InputError, match="reynolds"):
        strouhal_roshko(-1.0)
    # the example with St from Re: Re = U D/ν = 3075, so St = 0.2
    doc = load_example(EXAMPLE).model_dump(exclude_none=True)
    doc["lines"][0]["segments"][0]["strumming"]["strouhal"] = "reynolds"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        engine = build_engine(doc)
    u, d = 0.695 * FT, 0.05 * FT
    assert u * d / doc["environment"]["viscosity"] == pytest.approx(3075, rel=1e-3)
    table = engine.strumming["string"]
    assert np.allclose(table.omega_s, 2 * math.pi * 0.2 * u / d, rtol=1e-5)


def test_load_case_set_adds_the_strumming_damage_to_every_sea_state():
    """A strumming line's load-case set: every case's damage rate is its wave damage
    (the spectral method on that sea state's tension spectra) plus the locked-in mode's
    constant-amplitude damage f·(S/MBS)^m/a (closed form of a single-slope curve), and
    each row says so."""
    from stochcable.cases import LineFatigue, run_cases, scatter_from_rows
    from stochcable.design import damage_rate, fatigue_curve_user
    from stochcable.scene.model import Sea

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        # the linear model: the set's along-line damage of a case whose residuals are
        # computed comes from the elements' corrected spectra (8e-9 above the linear
        # tension spectrum here), the strumming's addition is the subject
        doc = _locked_scene()
        doc["analysis"].setdefault("linearization", {}).update(LINEAR_ONLY)
        scene = load_scene(doc)
        engine = build_engine(scene)
        m, log10_a, mbs = 3.0, 3.0, 50.0  # N = 10³ (S/MBS)^-3 [S in N]
        curve = fatigue_curve_user("t", quantity="tension_ratio", slope=m, log10_a=log10_a)
        rows = [{"hs": hs, "tp": 0.5, "heading": 90.0, "probability": 0.5} for hs in (0.03, 0.06)]
        fat = LineFatigue(curve=curve, mbs=mbs, method="narrow_band")
        res = run_cases(scene, scatter_from_rows(rows), fatigue=fat, engine=engine)
        mode = engine.strumming["string"].modes[engine.strumming["string"].governing]
        strum = mode.cycle_rate * (mode.tension_range / mbs) ** m / 10.0**log10_a
        assert strum.max() > 0
        for i, state in enumerate(res.scatter.states):
            lr = engine.solve(Sea(spectrum=state.spectrum("jonswap"), heading=90.0)).lines["string"]
            wave = damage_rate(lr.omega, lr.tension_spectrum / mbs**2, curve, "narrow_band")
            np.testing.assert_allclose(res.damage_rate_along["string"][i], wave + strum, rtol=1e-9)
            assert any("strumming of mode 1" in w for w in res.rows[i].warnings)
