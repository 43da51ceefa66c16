"""Tests of stochcable.design.rainflow_fatigue, and the spectral methods against rainflow
counting of long DSA realizations of the same spectra."""

from __future__ import annotations

import math

import numpy as np
import pytest

from stochcable.design import (
    damage_rainflow,
    damage_rate,
    fatigue_curve,
    fatigue_curve_user,
    rainflow_ranges,
)
from stochcable.errors import InputError
from stochcable.sea.realization import simulate_sea
from stochcable.sea.spectra import spectrum_jonswap

SIGMA = 20e6  # stress std of the wave-frequency part [Pa]


def _narrow(w):
    """Narrow band: JONSWAP γ = 7 (Hs 6 m, Tp 10 s) cut at 1 rad/s, as a stress
    spectrum [Pa²·s/rad]; α2 ≈ 0.95."""
    w = np.asarray(w)
    return spectrum_jonswap(w, 6.0, 10.0, gamma=7.0) * (w < 1.0) * (SIGMA / 1.5) ** 2


def _wide(w):
    """Wide band, two peaks: a JONSWAP sea (γ 3.3, full ω⁻⁵ tail) plus a low-frequency
    component at 0.12 rad/s of the same variance (slow drift of a moored vessel, or a
    low-frequency end motion); α2 ≈ 0.44."""
    w = np.asarray(w)
    sea = spectrum_jonswap(w, 6.0, 10.0) * (SIGMA / 1.5) ** 2
    lf = SIGMA**2 * np.exp(-0.5 * ((w - 0.12) / 0.02) ** 2) / (0.02 * math.sqrt(2 * math.pi))
    return sea + lf


# Scatter of Dirlik and Benasciutti–Tovo about rainflow counting that their authors and
# the comparative studies report for m = 3…5 on uni- and bimodal spectra: within about
# ±10 % (Benasciutti & Tovo 2005, Int. J. Fatigue 27, §5 and their comparison figures;
# Bouyssy, Naboishikov & Rackwitz 1993, Struct. Safety 12; Mršnik, Slavič & Boltežar
# 2013, Int. J. Fatigue 47).
METHOD_TOLERANCE = 0.10


def _case(density, curve, seed):
    # 2^19 samples at 0.5 s (72.8 h): ≈ 5·10⁴ rainflow cycles
    r = simulate_sea(density, 2**19 * 0.5, 0.5, "dsa", rng=seed)
    rf = damage_rainflow(r.elevation, curve, duration=r.duration)
    ranges = rainflow_ranges(r.elevation)
    m = curve.slopes[0]
    # sampling error of the rainflow damage: coefficient of variation of the mean of
    # S^m over the counted cycles (cycles taken as independent)
    cov = float(np.std(ranges**m) / np.mean(ranges**m) / math.sqrt(ranges.size))
    spectral = {
        k: float(damage_rate(r.omega, density(r.omega), curve, k))
        for k in ("narrow_band", "dirlik", "benasciutti_tovo")
    }
    return rf, cov, spectral


@pytest.mark.parametrize(
    ("density", "curve", "seed"),
    [
        (_narrow, "dnv-studless", 1),
        (_wide, "dnv-studless", 2),
        (_wide, "dnv-spiral-strand", 3),
    ],
    ids=["narrow-m3", "wide-m3", "wide-m4.8"],
)
def test_spectral_methods_against_rainflow(density, curve, seed):
    c = fatigue_curve(curve)
    rf, cov, spectral = _case(density, c, seed)
    assert rf > 0.0
    tol = METHOD_TOLERANCE + 3.0 * cov
    for name in ("dirlik", "benasciutti_tovo"):
        assert spectral[name] == pytest.approx(rf, rel=tol), name
    # narrow band is conservative (Rychlik 1993: rainflow ranges <= level-crossing ranges)
    assert spectral["narrow_band"] >= rf * (1.0 - 3.0 * cov)
    if density is _wide:
        assert spectral["narrow_band"] > 1.2 * rf  # and clearly so for a wide band


def test_sine_wave_miner_sum():
    # 100 periods of a sine of amplitude 3 MPa: 100 cycles of range 6 MPa
    t = np.arange(0.0, 1000.0, 0.05)
    y = 3e6 * np.sin(2 * np.pi * t / 10.0)
    c = fatigue_curve("dnv-studless")
    expected = 100.0 / (6.0e10 * 6.0**-3.0)
    k = 4096
    # class mid-levels: the range is off by at most one class width (span/k), so the
    # damage by at most about m/k relative
    assert damage_rainflow(y, c) == pytest.approx(expected, rel=2 * 3.0 / k)
    assert damage_rainflow(y, c, duration=1000.0) == pytest.approx(expected / 1000.0, rel=6 / k)
    assert rainflow_ranges(y).size == 100


def test_endurance_limit_and_no_cycles():
    t = np.arange(0.0, 1000.0, 0.05)
    y = 3e6 * np.sin(2 * np.pi * t / 10.0)
    limited = fatigue_curve_user(
        "u", quantity="stress", slope=3.0, log10_a=math.log10(6e10) + 18, endurance_limit=7e6
    )
    assert damage_rainflow(y, limited) == 0.0  # 6 MPa ranges below the 7 MPa limit
    c = fatigue_curve("dnv-studless")
    assert damage_rainflow(np.linspace(0.0, 1.0, 50), c) == 0.0  # monotonic: no cycle
    assert damage_rainflow(np.ones(50), c) == 0.0  # constant


def test_errors():
    c = fatigue_curve("dnv-studless")
    y = np.sin(np.arange(100.0))
    with pytest.raises(InputError, match="curve = 'str': must be a FatigueCurve"):
        damage_rainflow(y, "dnv-studless")
    with pytest.raises(InputError, match=r"duration = 0.0 \[s\]: must be > 0"):
        damage_rainflow(y, c, duration=0.0)
    with pytest.raises(InputError, match="series.*must have at least 3 entries"):
        damage_rainflow([1.0, 2.0], c)
    with pytest.raises(InputError, match="series.*must be finite"):
        damage_rainflow([1.0, np.nan, 2.0, 0.0], c)
    with pytest.raises(InputError, match="series.*must be a 1-D array"):
        damage_rainflow(np.zeros((3, 3)), c)
    with pytest.raises(InputError, match="n_classes = 1: must be an integer >= 2"):
        rainflow_ranges(y, n_classes=1)
