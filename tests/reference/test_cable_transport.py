"""Transport terms of the time-domain reference (stochcable.reference.cable_transport).

References: Wickert & Mote (1990), "Classical vibration analysis of axially moving
continua", J. Appl. Mech. 57, eq. 22: ω_n = nπ(c_w² − c²)/(L c_w), c_w² = T/m.
"""

from __future__ import annotations

import numpy as np
import pytest

from stochcable.errors import InputError
from stochcable.line.mesh import mesh_line
from stochcable.reference.cable_model import LineModel
from stochcable.reference.cable_newmark import integrate
from stochcable.scene.model import load_scene

L0, SPAN, EA, M0 = 399.6, 400.0, 1.0e9, 50.0


def _string_scene(speed: float, n_el: int = 40) -> dict:
    """A weightless taut string with no added mass and no drag (only m travels)."""
    seg = {"length": L0, "ea": EA, "mass": M0, "diameter": 0.1, "weight": 0.0}
    seg.update({"ca_normal": 0.0, "cd_normal": 0.0, "cd_axial": 0.0, "elements": n_el})
    return {
        "environment": {"depth": 500.0, "rho": 1025.0},
        "lines": [
            {
                "name": "string",
                "end_a": {"position": [0.0, 0.0, -300.0]},
                "end_b": {"position": [SPAN, 0.0, -300.0]},
                "segments": [seg],
                "axial_speed": speed,
            }
        ],
    }


def _wave_speed() -> float:
    return float(np.sqrt(EA * (SPAN / L0 - 1.0) / (M0 * L0 / SPAN)))


def _free_decay(speed: float, duration: float, h: float, n_el: int = 40):
    """The string plucked by a short smooth transverse pulse of end_b, then free."""
    scene = load_scene(_string_scene(speed, n_el))
    env, line = scene.environment, scene.lines[0]
    mesh = mesh_line(line, env.rho, env.g)
    xs = np.stack([np.linspace(0.0, SPAN, mesh.n_nodes), np.full(mesh.n_nodes, -300.0)], 1)
    model = LineModel(mesh, env, xs, 2)
    t = h * np.arange(int(round(duration / h)) + 1)
    tau = 2.0  # pulse length [s]
    ph = np.clip(t / tau, 0.0, 1.0)
    z = 0.05 * np.sin(np.pi * ph) ** 2  # C1 bump of 5 cm
    dz = np.where(t < tau, 0.05 * np.pi / tau * np.sin(2 * np.pi * ph), 0.0)
    ddz = np.where(t < tau, 0.05 * 2 * np.pi**2 / tau**2 * np.cos(2 * np.pi * ph), 0.0)
    zero = np.zeros_like(t)
    end = tuple(np.stack([zero, q], 1) for q in (z, dz, ddz))
    zeros = np.zeros_like(xs)
    zg = np.zeros((mesh.n_elements, 3, 2))
    pos, *_ = integrate(
        model, xs, zeros, zg, None, None, None, {mesh.n_nodes - 1: end}, t, h, 1e-3, 20, 10**6
    )
    return t, pos, model


@pytest.mark.slow  # 6000 Newmark steps: 3–5 s each
@pytest.mark.parametrize("ratio", [0.0, 0.3, 0.6])
def test_free_decay_of_travelling_string_wickert_mote(ratio):
    """FFT peaks of a free decay at ω_n = nπ(c_w² − c²)/(L c_w), n = 1, 2, within the
    record's resolution Δω = 2π/T (plus the Newmark period elongation (ωΔt)²/12 <
    0.1 % and the 40-element dispersion (nπ/40)²/24 < 0.3 %, both far below Δω/ω)."""
    cw = _wave_speed()
    c = ratio * cw
    h, duration = 0.1, 600.0
    t, pos, _ = _free_decay(c, duration, h)
    keep = t > 2.5  # after the pulse: free vibration
    y = pos[keep, pos.shape[1] // 3, 1]  # node at L/3: modes 1 and 2 both move it
    y = (y - y.mean()) * np.hanning(y.size)
    spec = np.abs(np.fft.rfft(y, 8 * y.size))  # zero-padded: the peak's position
    w = 2 * np.pi * np.fft.rfftfreq(8 * y.size, h)
    dw = 2 * np.pi / (t[keep][-1] - t[keep][0])
    for n in (1, 2):
        exact = n * np.pi * (cw**2 - c**2) / (SPAN * cw)
        gap = 0.4 * np.pi * (cw**2 - c**2) / (SPAN * cw)  # 0.4 of the mode spacing
        band = (w > exact - gap) & (w < exact + gap)
        peak = w[band][np.argmax(spec[band])]
        assert abs(peak - exact) < dw, (n, peak, exact, dw)
    # the transport matters: at 0.6 c_w the first mode is 36 % below the string at rest
    if ratio == 0.6:
        assert abs(peak - 2 * np.pi * cw / SPAN) > 10 * dw


def test_transport_matrices_skew_and_centripetal():
    """G is skew (no work: the gyroscopic force is conservative), K_c annihilates a
    rigid translation and carries −m c² on the second difference."""
    cw = _wave_speed()
    scene = load_scene(_string_scene(0.5 * cw, 10))
    env, line = scene.environment, scene.lines[0]
    mesh = mesh_line(line, env.rho, env.g)
    xs = np.stack([np.linspace(0.0, SPAN, mesh.n_nodes), np.full(mesh.n_nodes, -300.0)], 1)
    tr = LineModel(mesh, env, xs, 2).transport
    G, Kc = tr.G.toarray(), tr.Kc.toarray()
    np.testing.assert_allclose(G, -G.T, atol=0.0)
    np.testing.assert_allclose(Kc, Kc.T, atol=0.0)
    np.testing.assert_allclose(Kc @ np.tile([1.0, 2.0], mesh.n_nodes), 0.0, atol=1e-6)
    assert np.allclose(np.abs(G).max(), tr.mass_per_length[0] * 0.5 * cw)


def test_speed_at_critical_refused():
    cw = _wave_speed()
    with pytest.raises(InputError, match="critical speed"):
        _free_decay(1.01 * cw, 1.0, 0.1, 8)


def test_normal_drag_has_no_slope_term():
    """The Morison normal drag of the material moving at c e along the *deformed*
    tangent e: P(e)(U − u̇ − c e) = P(e)(U − u̇), so the normal drag of a deformed,
    moving travelling line does not depend on c at all (docs/travelling.md, "Limits":
    the slope term −c δe of a projection on the static normal is cancelled by the
    rotation of the projection, δP(−c e₀) = +c δe).  Without axial drag the time-domain
    drag forces at c = 0, 2 and −3 m/s are equal to round-off."""
    doc = _string_scene(0.0, 10)
    doc["lines"][0]["segments"][0].update({"cd_normal": 1.2, "cd_axial": 0.0})
    scene = load_scene(doc)
    env, line = scene.environment, scene.lines[0]
    mesh = mesh_line(line, env.rho, env.g)
    rng = np.random.default_rng(34)
    xs = np.stack(
        [
            np.linspace(0.0, SPAN, mesh.n_nodes),
            np.zeros(mesh.n_nodes),
            np.full(mesh.n_nodes, -300.0),
        ],
        1,
    )
    model = LineModel(mesh, env, xs, 3)
    X = xs + rng.normal(0.0, 5.0, xs.shape) * np.array([0.2, 1.0, 1.0])
    X[0], X[-1] = xs[0], xs[-1]
    V = rng.normal(0.0, 0.3, xs.shape)
    d = np.diff(X, axis=0)
    e = d / np.linalg.norm(d, axis=1)[:, None]
    u_gauss = np.broadcast_to([0.0, 0.5, 0.0], (mesh.n_elements, model.gauss_N.shape[0], 3))
    forces = []
    for c in (0.0, 2.0, -3.0):
        model.speed = c
        forces.append(model.drag(X, V, e, np.zeros_like(X), np.array(u_gauss), False)[0])
    scale = np.abs(forces[0]).max()
    assert scale > 1.0  # the drag is there
    for f in forces[1:]:
        np.testing.assert_allclose(f, forces[0], atol=1e-12 * scale)
