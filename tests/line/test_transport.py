"""Transport terms of a travelling line (stochcable.line.transport.matrices).

References: Wickert & Mote (1990), "Classical vibration analysis of axially moving
continua", J. Appl. Mech. 57, 738–744 (the travelling string's frequencies and mode
shapes, eqs. 22 and 26).
"""

from __future__ import annotations

import dataclasses
import json

import numpy as np
import pytest
from fem_cases import shallow_parabola, taut_string

from stochcable.errors import InputError
from stochcable.line.fem import assemble
from stochcable.line.transport.matrices import check_axial_speed, critical_speed, transport_matrices
from stochcable.line.transport.modes import (
    complex_modes,
    divergence_speed,
    receptance_direct,
    receptance_modal,
    stability_transport,
)

L, T, M_STRING, EA = 10.0, 1000.0, 1.0, 1.0e9  # EA/T = 1e6: the stretch is negligible
CW = np.sqrt(T / M_STRING)


def _string(n_el: int):
    mesh, pos, ten = taut_string(n_el, L, T, M_STRING, EA)
    return assemble(mesh, pos, ten, rho=1025.0, dim=2)


def _wickert_mote(n: np.ndarray, c: float) -> np.ndarray:
    """ω_n = nπ(c_w² − c²)/(L c_w) (Wickert & Mote 1990, eq. 22). [rad/s]"""
    return n * np.pi * (CW**2 - c**2) / (L * CW)


def test_matrices_skew_and_centripetal():
    model = _string(10)
    tr = transport_matrices(model, 7.0)
    g = tr.G.toarray()
    # assembled on prescribed ends and a uniform line: G is skew-symmetric
    assert np.abs(g + g.T).max() == 0.0
    # K_c = −m c² (1/l) pattern: on the free DOFs, −c²/c_w² times the transverse
    # geometric stiffness of the taut string (T/l pattern)
    ff = model.free
    kz = model.K.toarray()[np.ix_(ff[1::2], ff[1::2])]
    kcz = tr.Kc.toarray()[np.ix_(ff[1::2], ff[1::2])]
    np.testing.assert_allclose(kcz, -(7.0**2) / CW**2 * kz, rtol=1e-12)


@pytest.mark.parametrize("ratio", [0.0, 0.3, 0.6, 0.9])
def test_travelling_string_frequencies(ratio):
    """Wickert & Mote within 0.5 % for n = 1…3, converged in the element count."""
    c = ratio * CW
    n = np.arange(1, 4)
    exact = _wickert_mote(n, c)
    errs = []
    for n_el in (60, 120):
        modes = complex_modes(_string(n_el), c, count=3, added_mass=False)
        # conservative gyroscopic system: imaginary eigenvalues (QZ round-off ~1e-12)
        assert np.abs(modes.growth).max() < 1e-8 * modes.omega.max()
        errs.append(modes.omega / exact - 1.0)
    # 0.5 %: the tolerance; linear elements are O(h²): 120 elements give
    # ≤ 0.17 % at c/c_w = 0.9, n = 3
    assert np.abs(errs[1]).max() < 5e-3
    # converged: halving the element length divides the error by ≈ 4 (O(h²))
    np.testing.assert_allclose(errs[0] / errs[1], 4.0, rtol=0.02)


def test_travelling_string_in_water_only_the_line_travels():
    """With added mass m_a (not convected): (m + m_a)ü + 2mcu̇′ − (T − mc²)u″ = 0 has
    ω_n = k_n P/√((m + m_a)P + m²c²), P = T − mc², k_n = nπ/L (the travelling string's
    solution sin(k s) e^{iβs}, β = mcω/P, with the inertia split)."""
    ma = 0.8  # [kg/m]
    mesh, pos, ten = taut_string(100, L, T, M_STRING, EA)
    dia = np.sqrt(4.0 * ma / (1025.0 * np.pi))  # Ca = 1: m_a = ρπD²/4
    mesh = dataclasses.replace(mesh, diameter=np.full(100, dia), ca_normal=np.ones(100))
    model = assemble(mesh, pos, ten, rho=1025.0, dim=2)
    c = 0.6 * CW
    p = T - M_STRING * c**2
    k = np.arange(1, 4) * np.pi / L
    exact = k * p / np.sqrt((M_STRING + ma) * p + (M_STRING * c) ** 2)
    modes = complex_modes(model, c, count=3, added_mass=True)
    # 100 elements, O(h²): ≤ 0.3 % at n = 3 (the in-air case gives 0.25 % at 100)
    np.testing.assert_allclose(modes.omega, exact, rtol=3e-3)
    # and not the frequencies of a line whose added mass travelled too
    mt = M_STRING + ma
    wrong = k * (T - mt * c**2) / np.sqrt(mt * T)  # Wickert & Mote with m + m_a
    assert np.abs(modes.omega[0] / wrong[0] - 1) > 0.02


def test_travelling_string_mode_phase_follows_travel():
    """The mode's phase e^{iβs}, β = cω/(c_w² − c²), sign set by the travel direction
    (Wickert & Mote 1990, eq. 26: φ = sin(nπs/L) e^{iβs} for u = Re φ e^{iωt})."""
    model = _string(60)
    for c in (0.5 * CW, -0.5 * CW):
        modes = complex_modes(model, c, count=1, added_mass=False)
        w = modes.omega[0]
        phi = modes.right[1::2, 0]  # z components along the string
        s = model.positions[:, 0]
        beta = c * w / (CW**2 - c**2)
        inner = slice(5, -5)
        ref = np.sin(np.pi * s / L) * np.exp(1j * beta * s)
        ratio = phi[inner] / ref[inner]
        # one complex constant (the normalization): its phase is the same along s
        # O(h²) phase error of 60 elements: a few 1e-3 rad, against βL ≈ 2 rad
        np.testing.assert_allclose(np.angle(ratio / ratio[len(ratio) // 2]), 0.0, atol=1e-2)


def test_modal_receptance_equals_direct_solve():
    """Left/right normalization ψᵀ(2λM + D)φ = 1 gives the exact receptance."""
    model = _string(12)
    rng = np.random.default_rng(34)
    n_free = model.free.size
    c = np.diag(rng.uniform(0.0, 2.0, n_free))  # a damping on top of G
    omega = np.array([0.0, 3.0, 17.5, 60.0])
    modes = complex_modes(model, 0.7 * CW, damping=c, added_mass=False)
    h_modal = receptance_modal(modes, omega, model.free)
    h_direct = receptance_direct(model, 0.7 * CW, omega, added_mass=False, damping=c)
    # the two agree to round-off of the QZ and of the inverse
    np.testing.assert_allclose(h_modal, h_direct, rtol=0, atol=1e-9 * np.abs(h_direct).max())


def test_critical_speed_refusal_names_speed():
    model = _string(10)
    crit = critical_speed(model)
    assert crit.speed == pytest.approx(CW, rel=1e-12)
    assert check_axial_speed(model, -0.99 * CW) == -0.99 * CW
    for c in (CW, -1.2 * CW):
        with pytest.raises(InputError) as err:
            check_axial_speed(model, c, "lines[0].axial_speed")
        msg = str(err.value)
        assert "lines[0].axial_speed" in msg and f"{CW:.4g} m/s" in msg
        assert "\n" not in msg


def test_string_diverges_at_wave_speed():
    """The taut string: stable below c_w, an eigenvalue through zero at c_w, a real
    positive eigenvalue (divergence) above."""
    model = _string(20)
    assert divergence_speed(model) == pytest.approx(CW, rel=1e-9)
    below = stability_transport(model, 0.95 * CW, added_mass=False)
    assert below.stable and below.negative_stiffness == 0
    above = stability_transport(model, 1.05 * CW, added_mass=False)
    assert above.kind == "divergence"
    assert above.eigenvalue.real > 0 and above.negative_stiffness % 2 == 1


def test_sagged_cable_divergence_between_tension_bounds():
    """A sagged cable (tension varying along it): the divergence speed of the symmetric
    problem K φ = c² K₁ φ lies between √(T_min/m) and √(T_max/m), and the complex
    eigenvalues of the gyroscopic system agree: stable 1 % below it, divergent 1 %
    above."""
    g, span, sag, h = 9.81, 100.0, 0.1, 2.0e4
    w = 8.0 * h * sag * span / span**2
    mesh, pos, ten = shallow_parabola(40, span, sag, h, w / g, g, 1.0e9)
    model = assemble(mesh, pos, ten, rho=1025.0, dim=2)
    m = w / g
    cd = divergence_speed(model)
    assert np.sqrt(ten.min() / m) <= cd <= np.sqrt(ten.max() / m)
    assert critical_speed(model).speed <= cd
    assert stability_transport(model, 0.99 * cd, added_mass=False).stable
    above = stability_transport(model, 1.01 * cd, added_mass=False)
    # the nearly uniform tension (T/H ≤ 1.08) softens many modes at once: the index
    # is large, but any negative stiffness under a gyroscopic term alone diverges here
    assert above.kind == "divergence" and above.negative_stiffness >= 1


# ---------------------------------------------------------------- the scene field


def _taut_scene(speed: float) -> dict:
    """The weightless taut line of test_modes (T = EA(span/l0 − 1) ≈ 1.0 MN), travelling."""
    from test_modes import TAUT_SCENE

    doc = json.loads(json.dumps(TAUT_SCENE))
    doc["lines"][0]["axial_speed"] = speed
    return doc


def _taut_scene_wave_speed() -> float:
    """c_w = √(T/m) of the taut scene, m per current length. [m/s]"""
    l0, span, ea, m0 = 399.6, 400.0, 1.0e9, 50.0
    return float(np.sqrt(ea * (span / l0 - 1.0) / (m0 * l0 / span)))


def test_scene_axial_speed_field():
    from stochcable.scene.model import load_scene

    assert load_scene(_taut_scene(0.0)).lines[0].axial_speed == 0.0
    assert load_scene(_taut_scene(-3.0)).lines[0].axial_speed == -3.0  # end_b to end_a
    doc = _taut_scene(2.0)
    doc["lines"][0]["attachments"] = [{"at": 100.0, "mass": 10.0}]
    with pytest.raises(InputError, match=r"lines\[0\].axial_speed.*attachments"):
        load_scene(doc)


def test_cli_modes_travelling_line(tmp_path):
    """`stochcable modes` on a travelling taut line (in air, in-plane): Wickert & Mote."""
    from stochcable.cli import main

    cw = _taut_scene_wave_speed()
    path = tmp_path / "scene.json"
    path.write_text(json.dumps(_taut_scene(0.5 * cw)))
    out = tmp_path / "modes.json"
    assert main(["modes", str(path), "--count", "3", "--dim", "2", "--in-air", "-o", str(out)]) == 0
    line = json.loads(out.read_text())["modes"]["lines"]["taut"]
    assert line["stability"] == "stable" and line["axial_speed"] == 0.5 * cw
    assert line["critical_speed"] == pytest.approx(cw, rel=1e-9)
    c, span = 0.5 * cw, 400.0
    exact = np.arange(1, 4) * np.pi * (cw**2 - c**2) / (span * cw)
    # 100 elements, effective wavenumbers up to 1.5·3π/L: O(h²) error ≤ 0.2 %
    np.testing.assert_allclose(line["omega"], exact, rtol=2e-3)


@pytest.mark.parametrize("command", ["modes", "analyze"])
def test_cli_refuses_critical_speed_in_one_line(tmp_path, capsys, command):
    from stochcable.cli import main

    cw = _taut_scene_wave_speed()
    path = tmp_path / "scene.json"
    path.write_text(json.dumps(_taut_scene(-1.01 * cw)))
    assert main([command, str(path)]) == 2
    err = capsys.readouterr().err.strip()
    assert "lines[0].axial_speed" in err and f"√(T/m) = {cw:.4g} m/s" in err
    assert "\n" not in err


def test_harmonic_linearization_refused_for_a_travelling_line():
    from stochcable.dynamics.engine import build_engine

    doc = _taut_scene(1.0)
    doc["analysis"] = {"linearization": {"method": "harmonic"}}
    with pytest.raises(InputError, match=r"line 'taut' travels.*use 'seed' or 'vector'"):
        build_engine(doc)


def test_flutter_reported_not_solved():
    """A negative damping −εM (a stand-in for a non-conservative fluid load) makes the
    string's oscillating modes grow: complex pairs with Re λ > 0 are a flutter (at rest
    Re λ = ε/2 exactly, the damping being proportional); +εM damps them (stable)."""
    model = _string(12)
    m_free = model.partition("M")[0].toarray()
    eps = 0.4  # [1/s]
    rest = stability_transport(model, 0.0, added_mass=False, damping=-eps * m_free)
    # QZ round-off ~1e-10 of the largest |λ| (the axial modes, ~4e5 rad/s): 1e-4 abs
    assert rest.kind == "flutter" and rest.eigenvalue.real == pytest.approx(eps / 2, abs=1e-4)
    grows = stability_transport(model, 0.5 * CW, added_mass=False, damping=-eps * m_free)
    assert grows.kind == "flutter" and not grows.stable and grows.eigenvalue.real > 0.1
    assert grows.negative_stiffness == 0  # not a divergence: K + K_c stays positive
    damped = stability_transport(model, 0.5 * CW, added_mass=False, damping=eps * m_free)
    assert damped.stable


def test_service_answers_422_naming_the_critical_speed():
    """The HTTP service: the same one-line error, a 422 with parameter and unit."""
    pytest.importorskip("fastapi")
    from fastapi.testclient import TestClient

    from service.app import create_app
    from service.settings import Settings

    cw = _taut_scene_wave_speed()
    # one forked analysis worker, as test_fidelity_limits (the default spawns several)
    with TestClient(create_app(Settings(analysis_workers=1, worker_start_method="fork"))) as client:
        resp = client.post("/v1/analyses", json=_taut_scene(1.5 * cw))
    assert resp.status_code == 422, resp.text
    err = resp.json()["detail"][0]
    assert err["parameter"] == "lines[0].axial_speed" and err["unit"] == "m/s"
    assert f"√(T/m) = {cw:.4g} m/s" in err["msg"]


@pytest.mark.parametrize("speed", [0.0, 10.0, 25.0])
def test_sparse_modes_equal_dense(speed):
    """Shift-invert Arnoldi (long lines) against the dense QZ on a 3-D sagged cable
    (degenerate in-/out-of-plane clusters at rest): the same eigenvalues, and left and
    right shapes bi-orthonormal, ψ_iᵀ((λ_i + λ_j)M + G)φ_j = δ_ij."""
    mesh, pos, ten = shallow_parabola(60, 100.0, 0.1, 2.0e4, 16.3, 9.81, 1.0e9)
    model = assemble(mesh, pos, ten, rho=1025.0, dim=3)
    dense = complex_modes(model, speed, count=8, method="dense")
    sparse = complex_modes(model, speed, count=8, method="sparse")
    # both solvers to ~1e-10 relative (QZ and ARPACK at tol 1e-12)
    np.testing.assert_allclose(sparse.eigenvalues, dense.eigenvalues, rtol=1e-8)
    m = model._mass_total.toarray()
    g = transport_matrices(model, speed).G.toarray()
    lam = sparse.eigenvalues
    n = (sparse.left.T @ m @ sparse.right) * (lam[:, None] + lam[None, :])
    n += sparse.left.T @ g @ sparse.right
    np.testing.assert_allclose(n, np.eye(8), atol=1e-8)


def test_statics_axial_drag_on_the_relative_axial_velocity():
    """A vertical line hauled up (c > 0, end_a at the bottom) or paid out down (c < 0):
    its axial drag ½ρC_t πD |u_t − c|(u_t − c) adds ∓C c² per unit length to the
    tension gradient, C = ½ρ C_t πD; the difference of the end elements' tensions
    changes by C c² times the stretched length between their midpoints."""
    from stochcable.scene.model import load_scene
    from stochcable.statics import solve_statics

    def riser(c: float):
        doc = {
            "environment": {"depth": 200.0, "rho": 1025.0},
            "lines": [
                {
                    "name": "riser",
                    "end_a": {"position": [0.0, 0.0, -150.0]},
                    "end_b": {"position": [0.0, 0.0, -10.0]},
                    "axial_speed": c,
                    "segments": [
                        {
                            "length": 139.9,
                            "ea": 1e8,
                            "mass": 20.0,
                            "diameter": 0.05,
                            "cd_axial": 0.01,
                            "elements": 40,
                        }
                    ],
                }
            ],
        }
        return solve_statics(load_scene(doc)).lines["riser"]

    rest = riser(0.0)
    span = rest.tension[-1] - rest.tension[0]
    coef = 0.5 * 1025.0 * 0.01 * np.pi * 0.05
    for c in (2.0, -2.0):
        line = riser(c)
        l = np.linalg.norm(np.diff(line.positions, axis=0), axis=1)
        between = l.sum() - 0.5 * (l[0] + l[-1])
        change = (line.tension[-1] - line.tension[0]) - span
        # the solver's tolerance on the tensions (~1e-9 of 8e4 N) against 440 N
        assert change == pytest.approx(np.sign(c) * coef * c * c * between, rel=1e-6)


def test_real_modes_of_a_travelling_line_warn():
    from stochcable.errors import PhysicsWarning
    from stochcable.statics import modes_of_scene

    with pytest.warns(PhysicsWarning, match="travels: these are its modes at rest"):
        modes_of_scene(_taut_scene(1.0), count=2)


def test_statics_of_a_travelling_line_with_axial_drag_is_the_fe():
    """The closed-form catenary has no axial drag: a travelling line with one is
    solved by the FE ("auto" = "fe"), not silently as at rest."""
    from stochcable.scene.model import load_scene
    from stochcable.statics import solve_statics

    doc = {
        "environment": {"depth": 100.0, "rho": 1025.0},
        "lines": [
            {
                "name": "lay",
                "end_a": {"position": [0.0, 0.0, -90.0]},
                "end_b": {"position": [60.0, 0.0, -5.0]},
                "axial_speed": -3.0,
                "segments": [
                    {
                        "length": 110.0,
                        "ea": 1e8,
                        "mass": 20.0,
                        "diameter": 0.05,
                        "cd_axial": 0.05,
                        "elements": 30,
                    }
                ],
            }
        ],
    }
    auto = solve_statics(load_scene(doc)).lines["lay"]
    fe = solve_statics(load_scene(doc), method="fe").lines["lay"]
    np.testing.assert_allclose(auto.tension, fe.tension, rtol=1e-9)
    doc["lines"][0]["axial_speed"] = 0.0
    rest = solve_statics(load_scene(doc), method="fe").lines["lay"]
    # paid out downwards: the drag pulls the line up, the top tension drops
    assert fe.tension[-1] < rest.tension[-1] - 1.0
