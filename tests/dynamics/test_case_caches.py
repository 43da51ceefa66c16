"""What a load-case set's every case forms once instead of at each sea state (the
ω₂ quadrature steps of the element check, the excitation-end probe grid, a line's
normal projectors): each cached form gives the bits of the form it replaces, and its
numbers agree with an independent closed form."""

from __future__ import annotations

import json
import math
import warnings
from types import SimpleNamespace

import numpy as np
import pytest
from _paths import ROOT

from stochcable.dynamics.groups.line_fixed_point import linearize
from stochcable.dynamics.loads.channels import line_channels
from stochcable.dynamics.model.system import build_line_system
from stochcable.dynamics.outputs import indicators, resolution
from stochcable.fidelity import pilot
from stochcable.scene.model import Sea, load_scene
from stochcable.statics import solve_statics


def _scene(hs: float, tp: float, family: str) -> SimpleNamespace:
    spec = Sea(spectrum={"type": family, "hs": hs, "tp": tp})
    return SimpleNamespace(sea=spec, environment=SimpleNamespace(g=9.80665))


@pytest.mark.parametrize("family", ["pierson_moskowitz", "jonswap"])
@pytest.mark.parametrize(("hs", "tp"), [(1.0, 6.0), (4.5, 9.0), (10.0, 15.0)])
def test_sea_omega2_is_numpys_trapezoid_to_the_bit(family, hs, tp):
    scene = _scene(hs, tp, family)
    s = np.asarray(scene.sea.spectrum.spectral_density(pilot._WIDE, 9.80665), dtype=float)
    s = np.where(np.isfinite(s), s, 0.0)
    ref = math.sqrt(np.trapezoid(pilot._WIDE**2 * s, pilot._WIDE) / np.trapezoid(s, pilot._WIDE))
    assert pilot.sea_omega2(scene) == ref  # (bitwise: the cut must not move a number)


def test_sea_omega2_of_pierson_moskowitz_is_its_closed_form():
    # m_n = (Hs²/64) ωpⁿ (5/4)^(n/4) Γ(1 − n/4): ω₂ = ωp (5/4)^(1/4) √Γ(1/2); the
    # trapezoid over 16001 geometric points of 8 decades errs by ≈ (Δ ln ω)² ≈ 1e-6
    tp = 9.0
    wp = 2.0 * math.pi / tp
    exact = wp * 1.25**0.25 * math.sqrt(math.gamma(0.5))
    assert pilot.sea_omega2(_scene(3.0, tp, "pierson_moskowitz")) == pytest.approx(exact, rel=1e-5)


def _band_channel(cut: float, w: np.ndarray) -> SimpleNamespace:
    def density(x: np.ndarray) -> np.ndarray:
        return np.where(np.asarray(x) < cut, 1.0, 0.0)

    return SimpleNamespace(spectrum=density(w), density=density)


def test_excitation_end_probe_is_the_geometric_grid_and_finds_the_cut():
    assert np.array_equal(resolution._PROBE, np.geomspace(1.0 + 1e-9, 1e3, 400))
    w = np.linspace(0.1, 3.0, 60)
    for cut in (4.2, 37.0):  # beyond the grid: found on the probe and bisected
        assert resolution.excitation_end((_band_channel(cut, w),), w) == pytest.approx(
            cut, rel=2e-9
        )
    # an input still on at 1000 ω_max: no end
    analytic = SimpleNamespace(spectrum=np.ones_like(w), density=lambda x: np.ones(np.shape(x)))
    assert resolution.excitation_end((analytic,), w) == math.inf


def _chain_parts():
    doc = json.loads((ROOT / "stochcable" / "examples" / "chain_catenary.json").read_text())
    doc["analysis"].pop("timeseries", None)
    scene = load_scene(doc)
    st = solve_statics(scene)
    line = scene.lines[0]
    system = build_line_system(scene, line, st.lines[line.name])
    chans = line_channels(scene, line, system.positions, scene.analysis.omega.values())
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        lin = linearize(system, chans, scene.analysis)
    return system, chans, lin


def test_normal_projector_kept_per_line_gives_the_same_sigma():
    system, chans, lin = _chain_parts()
    w = lin.response.omega
    system._cache.pop("normal_projector", None)
    first = indicators._normal_acceleration_sigma(system, chans, w)
    kept = system._cache["normal_projector"].reshape(-1, 3, 3)
    e = system.frames[0]
    # the projector on the element's normal plane: P e = 0, P² = P, trace 2
    np.testing.assert_allclose(np.einsum("eij,ej->ei", kept, e), 0.0, atol=1e-15)
    np.testing.assert_allclose(kept @ kept, kept, atol=1e-15)
    np.testing.assert_allclose(np.trace(kept, axis1=1, axis2=2), 2.0, rtol=1e-15)
    again = indicators._normal_acceleration_sigma(system, chans, w)  # (from the cache)
    system._cache.pop("normal_projector")
    fresh = indicators._normal_acceleration_sigma(system, chans, w)
    assert np.array_equal(first, again) and np.array_equal(first, fresh)
    assert first.max() > 0.0  # (the elements near the surface: the waves reach them)
