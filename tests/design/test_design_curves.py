"""Tests of stochcable.design.curves: catalogue constants, user curves, unit factors."""

from __future__ import annotations

import math

import numpy as np
import pytest

from stochcable.design import (
    FatigueCurve,
    curve_names,
    fatigue_curve,
    fatigue_curve_user,
    tension_to_curve_quantity,
)
from stochcable.errors import InputError

# DNV-OS-E301 (2010) Ch.2 Sec.2 Table D1: (a_D [MPa^m], m), S in MPa
DNV_TABLE = {
    "dnv-studlink": (1.2e11, 3.0),
    "dnv-studless": (6.0e10, 3.0),
    "dnv-six-strand": (3.4e14, 4.0),
    "dnv-spiral-strand": (1.7e17, 4.8),
}
# API RP 2SK 3rd ed. (2005), fatigue T-N curves: N R^M = K
API_CHAIN = {"api-studlink": (1000.0, 3.0), "api-studless": (316.0, 3.0)}
API_ROPE = {"api-six-strand": (3.20, 2.79, 4.09), "api-spiral-strand": (3.25, 3.43, 5.05)}

# conversions are exact up to the rounding of 10**x: a few ulps
RTOL = 1e-12


@pytest.mark.parametrize("name", sorted(DNV_TABLE))
def test_dnv_curves_in_pa_equal_the_mpa_table(name):
    a_d, m = DNV_TABLE[name]
    c = fatigue_curve(name)
    s_mpa = np.array([10.0, 50.0, 200.0])
    n = c.cycles_to_failure(s_mpa * 1e6)  # the curve takes Pa
    np.testing.assert_allclose(n, a_d * s_mpa**-m, rtol=RTOL)
    assert c.quantity == "stress" and c.unit == "Pa"
    assert "DNV-OS-E301" in c.source and "Table D1" in c.source
    assert c.endurance_limit is None and len(c.slopes) == 1


@pytest.mark.parametrize("name", sorted(API_CHAIN))
def test_api_chain_curves(name):
    k, m = API_CHAIN[name]
    c = fatigue_curve(name)
    r = np.array([0.01, 0.05, 0.2])
    np.testing.assert_allclose(c.cycles_to_failure(r), k * r**-m, rtol=RTOL)
    assert c.quantity == "tension_ratio" and c.unit == "-"
    assert "API RP 2SK" in c.source


@pytest.mark.parametrize("name", sorted(API_ROPE))
def test_api_rope_curves_depend_on_mean_load(name):
    a, b, m = API_ROPE[name]
    lm = 0.3
    c = fatigue_curve(name, mean_load_ratio=lm)
    r = np.array([0.02, 0.1])
    np.testing.assert_allclose(c.cycles_to_failure(r), 10 ** (a - b * lm) * r**-m, rtol=RTOL)
    assert f"Lm = {lm:g}" in c.source
    with pytest.raises(InputError, match="mean_load_ratio.*is required"):
        fatigue_curve(name)
    with pytest.raises(InputError, match=r"mean_load_ratio = 1.0: must be < 1"):
        fatigue_curve(name, mean_load_ratio=1.0)


def test_catalogue_names_and_errors():
    assert set(curve_names()) == set(DNV_TABLE) | set(API_CHAIN) | set(API_ROPE)
    assert fatigue_curve(" DNV-Studless ").name == "dnv-studless"
    with pytest.raises(InputError, match="name = 'dnv-x': must be one of"):
        fatigue_curve("dnv-x")
    with pytest.raises(InputError, match="mean_load_ratio.*applies only to the API rope curves"):
        fatigue_curve("dnv-studless", mean_load_ratio=0.2)


def test_cycles_to_failure_edges():
    c = fatigue_curve("dnv-studless")
    n = c.cycles_to_failure([0.0, 1e6])
    assert n[0] == math.inf and math.isfinite(n[1])
    with pytest.raises(InputError, match="ranges.*must be >= 0"):
        c.cycles_to_failure([-1.0])
    with pytest.raises(InputError, match="ranges.*must be finite"):
        c.cycles_to_failure([np.nan])


def test_miner_sum():
    c = fatigue_curve("api-studless")
    r = np.array([0.05, 0.1])
    expected = 2.0 / (316.0 * 0.05**-3) + 0.5 / (316.0 * 0.1**-3)
    assert c.damage(r, [2.0, 0.5]) == pytest.approx(expected, rel=RTOL)
    assert c.damage(r) == pytest.approx(1 / (316.0 * 0.05**-3) + 1 / (316.0 * 0.1**-3), rel=RTOL)
    with pytest.raises(InputError, match="counts.*must have the shape of ranges"):
        c.damage(r, [1.0])


def test_user_two_slope_is_continuous_with_endurance_limit():
    # DNV-RP-C203-like: m1 = 3 to 10^7 cycles, m2 = 5 below, log10 a1 = 12.164 (MPa)
    la1_pa = 12.164 + 6 * 3.0
    c = fatigue_curve_user(
        "c203-like",
        quantity="stress",
        slope=3.0,
        log10_a=la1_pa,
        slope2=5.0,
        transition_cycles=1e7,
        endurance_limit=10e6,
    )
    st = c.transition
    assert st == pytest.approx(10 ** ((la1_pa - 7.0) / 3.0), rel=RTOL)
    # both segments give 10^7 cycles at the transition (continuity)
    n_hi = 10 ** (c.log10_intercepts[0]) * st ** -c.slopes[0]
    n_lo = 10 ** (c.log10_intercepts[1]) * st ** -c.slopes[1]
    assert n_hi == pytest.approx(1e7, rel=1e-10) and n_lo == pytest.approx(1e7, rel=1e-10)
    s = np.array([2.0 * st, 0.5 * st, 9e6, 10e6])
    n = c.cycles_to_failure(s)
    assert n[0] == pytest.approx(1e7 * 2.0**-3, rel=1e-10)
    assert n[1] == pytest.approx(1e7 * 0.5**-5, rel=1e-10)
    assert n[2] == math.inf and n[3] == math.inf  # at or below the endurance limit
    segs = c.segments()
    assert [s.slope for s in segs] == [3.0, 5.0]
    assert segs[0].upper == math.inf and segs[1].lower == 10e6 and segs[0].lower == st


def test_user_curve_errors():
    kw = {"quantity": "stress", "slope": 3.0, "log10_a": 30.0}
    with pytest.raises(InputError, match="quantity = 'force': must be one of"):
        fatigue_curve_user("u", quantity="force", slope=3.0, log10_a=1.0)
    with pytest.raises(InputError, match="slope = 0.0: must be > 0"):
        fatigue_curve_user("u", **{**kw, "slope": 0.0})
    with pytest.raises(InputError, match="transition_cycles.*is required with slope2"):
        fatigue_curve_user("u", **kw, slope2=5.0)
    with pytest.raises(InputError, match="transition_cycles.*needs slope2"):
        fatigue_curve_user("u", **kw, transition_cycles=1e7)
    with pytest.raises(InputError, match=r"endurance_limit = -1.0 \[Pa\]: must be > 0"):
        fatigue_curve_user("u", **kw, endurance_limit=-1.0)
    with pytest.raises(InputError, match="log10_a = inf.*must be finite"):
        fatigue_curve_user("u", **{**kw, "log10_a": math.inf})
    one = fatigue_curve_user("u", **kw)
    assert one.cycles_to_failure([1e7])[0] == pytest.approx(1e30 * 1e7**-3, rel=RTOL)


def test_direct_construction_is_validated():
    with pytest.raises(InputError, match="slopes.*one or two slopes"):
        FatigueCurve("x", "s", "stress", (3.0,), (1.0, 2.0))
    with pytest.raises(InputError, match="transition.*exactly for two-slope"):
        FatigueCurve("x", "s", "stress", (3.0, 5.0), (1.0, 2.0))
    with pytest.raises(InputError, match="unit = 'Pa'.*must be '-'"):
        FatigueCurve("x", "s", "tension_ratio", (3.0,), (1.0,), unit="Pa")


def test_tension_to_curve_quantity():
    d = 0.1
    chain = fatigue_curve("dnv-studless")
    # DNV-OS-E301: the nominal area of chain is the two legs of a link, 2·πd²/4
    assert tension_to_curve_quantity(chain, nominal_diameter=d) == pytest.approx(
        1.0 / (2.0 * math.pi * d * d / 4.0), rel=RTOL
    )
    assert tension_to_curve_quantity(chain, nominal_area=0.01) == pytest.approx(100.0)
    rope = fatigue_curve("dnv-spiral-strand")
    assert tension_to_curve_quantity(rope, nominal_area=0.005) == pytest.approx(200.0)
    api = fatigue_curve("api-studless")
    assert tension_to_curve_quantity(api, mbs=1e7) == pytest.approx(1e-7)
    with pytest.raises(InputError, match="mbs.*is required by api-studless"):
        tension_to_curve_quantity(api, nominal_area=0.01)
    with pytest.raises(InputError, match="nominal_area.*is required by dnv-studless"):
        tension_to_curve_quantity(chain)
    with pytest.raises(InputError, match="nominal_diameter.*give nominal_area for dnv-spiral"):
        tension_to_curve_quantity(rope, nominal_diameter=0.1)
    with pytest.raises(InputError, match="nominal_diameter.*give nominal_area or nominal_diam"):
        tension_to_curve_quantity(chain, nominal_diameter=0.1, nominal_area=0.01)
    with pytest.raises(InputError, match=r"mbs = -1.0 \[N\]: must be > 0"):
        tension_to_curve_quantity(api, mbs=-1.0)
    with pytest.raises(InputError, match="curve = 'str': must be a FatigueCurve"):
        tension_to_curve_quantity("dnv-studless", nominal_diameter=0.1)
