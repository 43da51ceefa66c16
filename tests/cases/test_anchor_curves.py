"""The curves the adaptive residual anchors interpolate a heading's corrections with
(stochcable.cases.anchor_transfer, anchor_moments): the residual moments' coordinates
and their inverse, a column borrowing its parents' shape, the law each column chooses,
and the elements' tolerance relative to the line's largest damage."""

from __future__ import annotations

import numpy as np
import pytest

from stochcable.cases import LineFatigue, scatter_from_rows
from stochcable.cases.anchor_layout import check_ratios, correction_rows, element_scale, layout
from stochcable.cases.anchor_moments import MomentCoordinates, damage_slopes, power_rows
from stochcable.cases.anchor_transfer import HeadingCurves
from stochcable.cases.chunk import CaseRow
from stochcable.cases.residual_anchors import (
    first_anchors,
    interpolate_corrections,
    next_anchors,
)

HS = tuple(float(h) for h in range(1, 10))


def _field(std, tz, sigma, tzc, hs=HS, tps=(8.0,), damage=None, rows=None):
    """A synthetic diagram of one line (every Hs at every Tp, or ``rows``): the linear
    σ and Tz ``std(h, t)``, ``tz(h, t)`` and the corrected ``sigma(h, t)``,
    ``tzc(h, t)`` (MPM ratio 1; the end damage ``damage(h, t)`` as (corrected,
    linear), or none)."""
    rows = rows or [{"hs": h, "tp": t, "hours": 1.0} for t in tps for h in hs]
    states = scatter_from_rows(rows).states
    n = len(states)
    lin = np.zeros((n, 2, 4))
    stats = {e: np.zeros((n, 4)) for e in ("end_a", "end_b")}
    d_ends = np.full((n, 2), np.nan)
    for i, s in enumerate(states):
        h, t = s.hs, s.tp
        lin[i, :, 0], lin[i, :, 1], lin[i, :, 2] = std(h, t), tz(h, t), 1.0
        lin[i, :, 3] = np.nan if damage is None else damage(h, t)[1]
        for e in stats:
            stats[e][i] = (0.0, sigma(h, t), tzc(h, t), 1.0)
        if damage is not None:
            d_ends[i] = damage(h, t)[0]
    dam = {} if damage is None else {"l": d_ends}
    rows_ = [CaseRow(i, "ok") for i in range(n)]
    return states, {"l": stats}, dam, {"l": lin}, rows_


def _adapt(states, stats, dam, linear, rows, tolerance=1e-3, slopes=None):
    """The adaptive anchors pass after pass; the cases computed and the largest miss of
    the interpolated σ and Tz from the given ones."""
    exact = first_anchors(states, None)
    while True:
        more = next_anchors(states, None, tolerance, exact, rows, stats, dam, linear, None, slopes)
        if not more.any():
            break
        assert not (more & exact).any()
        exact = exact | more
    got = {"l": {e: v.copy() for e, v in stats["l"].items()}}
    for e, k in (("end_a", 0), ("end_b", 1)):  # (the others linear, as in a set)
        got["l"][e][~exact, 1:3] = linear["l"][~exact, k, :2]
    interpolate_corrections(states, exact, rows, got, dam, linear, "power", None, slopes)
    miss = max(np.max(np.abs(got["l"][e][:, 1:3] / stats["l"][e][:, 1:3] - 1)) for e in got["l"])
    return exact, float(miss)


def test_moment_coordinates_round_trip_and_closed_form():
    """Δm0 = σ² − σ_lin² and Δm2 = (σ/Tz)² − (σ_lin/Tz_lin)² per end, the damage over
    its proxy (σ/σ_lin)^m·Tz_lin/Tz less 1, the other ratios less 1; and back to the
    same ratios at the case (round-off)."""
    states, stats, dam, linear, _ = _field(
        lambda h, t: 10 * h**0.7, lambda h, t: 6.0 + 0.1 * h,
        lambda h, t: np.sqrt(100 * h**1.4 + 3 * h**3), lambda h, t: 5.5 + 0.1 * h,
        damage=lambda h, t: (2e-9 * h**3, 1e-9 * h**2.5),
    )  # fmt: skip
    r, _ = check_ratios(stats, dam, linear)
    mc = MomentCoordinates.of(r, linear, dam, {"l": 3.0})
    for i, s in enumerate(states):
        h = s.hs
        sig, sl, tzc, tzl = (
            np.sqrt(100 * h**1.4 + 3 * h**3),
            10 * h**0.7,
            5.5 + 0.1 * h,
            6 + 0.1 * h,
        )
        assert mc.y[i, 0] == pytest.approx(3 * h**3, rel=1e-12)
        assert mc.y[i, 1] == pytest.approx((sig / tzc) ** 2 - (sl / tzl) ** 2, rel=1e-12)
        proxy = (sig / sl) ** 3 * tzl / tzc
        assert mc.y[i, 3] == pytest.approx(2 * h**0.5 / proxy - 1, rel=1e-12)
        assert mc.y[i, 2] == 0.0
        np.testing.assert_allclose(mc.ratios(mc.y[i], i), r[i], rtol=1e-13)


def test_power_rows_exact_for_a_power_and_linear_in_hs2_across_a_sign_change():
    y = np.array([[2.0, -1.0], [16.0, 3.0]])
    got = power_rows(1.5, np.array([1.0, 2.0]), y)
    assert got[0] == pytest.approx(2 * 1.5**3, rel=1e-14)
    assert got[1] == pytest.approx(-1 + 4 * (2.25 - 1) / 3, rel=1e-14)


def test_a_residual_variance_growing_as_a_power_of_hs_is_met_by_the_moments():
    """The linear σ bent by drag damping (σ_lin ∝ Hs/(1 + Hs/3)) and the residual
    variance a power of Hs (3·Hs³, as the drag residual's): the ratio σ/σ_lin rises and
    falls (1.03 … 1.19 … 1.17), the ratios' law between the first pass's Hs 1, 5 and 9
    misses it by 1 %, the moments' meets it to round-off: the column chooses the
    moments and computes no case more, every σ and Tz within 1e-12."""

    def std(h, t):
        return 10 * h / (1 + h / 3)

    def sigma(h, t):
        return np.sqrt(std(h, t) ** 2 + 3 * h**3)

    def tzc(h, t):  # Δm2 = 0.05·Hs³ on Tz_lin 7 s
        return np.sqrt(sigma(h, t) ** 2 / ((std(h, t) / 7.0) ** 2 + 0.05 * h**3))

    states, stats, dam, linear, rows = _field(std, lambda h, t: 7.0, sigma, tzc)
    r, scale = check_ratios(stats, dam, linear)
    ratios_law = correction_rows(5.0, np.array([1.0, 9.0]), r[[0, 8]])  # (Hs 5 from 1, 9)
    assert abs(ratios_law[0] / r[4, 0] - 1) > 5e-3
    exact, miss = _adapt(states, stats, dam, linear, rows)
    assert exact.sum() == 3 and miss < 1e-12
    ok = exact.copy()
    curves = HeadingCurves(layout(states)[0.0], ok, r, scale, "power",
                           MomentCoordinates.of(r, linear, dam))  # fmt: skip
    assert curves.column_law(0) == "moments"


def test_a_column_borrows_its_parents_shape():
    """Corrections that rise and fall with Hs (1 + 0.1·Hs·e^(−Hs/3)) and change
    linearly with the period: the shortest and longest period interpolate their own
    (their Hs all computed: the bend defeats the power law), every other column takes
    its parents' shape (column_law "transfer") from its first three Hs, met to
    round-off, so the set computes 2 × 9 + 7 × 3 of 81 cases."""

    def ratio(h, t):
        return 1 + 0.1 * h * np.exp(-h / 3) * (1 + 0.02 * t) + 0.001 * t

    tps = tuple(6.0 + k for k in range(9))
    states, stats, dam, linear, rows = _field(
        lambda h, t: 1.0, lambda h, t: 1.0, ratio, lambda h, t: 1.0, tps=tps
    )
    exact, miss = _adapt(states, stats, dam, linear, rows, slopes={})
    r, scale = check_ratios(stats, dam, linear)
    curves = HeadingCurves(layout(states)[0.0], exact, r, scale, "power",
                           MomentCoordinates.of(r, linear, dam))  # fmt: skip
    assert [curves.column_law(j) for j in range(9)][1:-1] == ["transfer"] * 7
    assert curves.parents(4) == (0, 8) and curves.parents(2) == (0, 4)
    assert curves.parents(3) == (2, 4) and curves.parents(0) is None
    assert exact.sum() == 2 * 9 + 7 * 3 and miss < 1e-12


def test_element_damage_tolerance_relative_to_the_lines_largest():
    """An element's damage tolerance is the end damage's (3) times the line's largest
    damage rate of the case over the element's: an element with 1 % of the largest
    gets 100 × the tolerance (its error relative to the largest then within 3 × it);
    one without damage is never checked."""
    d = np.array([[1.0, 0.5, 0.01, 1.0, 0.0], [np.nan, 2.0, 1.0, 4.0, 2.0]])
    got = element_scale(d)
    np.testing.assert_allclose(got[0], [300.0, 3.0, np.inf])
    np.testing.assert_allclose(got[1], [12.0, 3.0, 6.0])


def test_damage_slopes_of_the_curves():
    got = damage_slopes(
        {
            "wire": LineFatigue("dnv-six-strand", nominal_area=1.2e-3),
            "chain": LineFatigue("api-studless", mbs=2e5),
        }
    )
    assert got == {"wire": 4.0, "chain": 3.0}


def test_the_base_is_quadratic_in_the_period_through_the_parents_and_their_parent():
    """Every case computed, ratios quadratic in Tp at each Hs: a column whose parents
    have a parent interval of their own (Tp 8 s: parents 6 and 10 s, 10 s the middle of
    6 … 14 s) gets its ratios back to round-off from theirs; the middle column (parents
    the shortest and longest period) linearly between them, missing by the quadratic's
    term q·(t − 6)(t − 14) exactly."""
    q = 1e-3

    def ratio(h, t):
        return 1 + 0.05 * h + q * (t - 6.0) * (t - 14.0) * (1 + 0.1 * h)

    tps = tuple(6.0 + k for k in range(9))
    states, stats, dam, linear, _ = _field(
        lambda h, t: 1.0, lambda h, t: 1.0, ratio, lambda h, t: 1.0, tps=tps
    )
    r, scale = check_ratios(stats, dam, linear)
    ok = np.ones(len(states), dtype=bool)
    curves = HeadingCurves(layout(states)[0.0], ok, r, scale, "power")
    for h in (1.0, 4.0, 9.0):
        assert curves.base(2, h)[0] == pytest.approx(ratio(h, 8.0), rel=1e-13)
        lin = 1 + 0.05 * h  # (the quadratic term vanishes at 6 and 14 s)
        assert curves.base(4, h)[0] == pytest.approx(lin, rel=1e-13)
        assert abs(curves.base(4, h)[0] - ratio(h, 10.0)) == pytest.approx(
            q * 16 * (1 + 0.1 * h), rel=1e-9
        )


def test_no_base_is_extrapolated_beyond_a_parents_computed_hs():
    """A column borrows its parents' shape only where their computed Hs reach over its
    own (a real diagram's short periods stop at lower Hs): with the shortest period's
    column ending at Hs 5 m, the columns whose parents include it interpolate their
    own ratios (every Hs checked), the others still borrow; every σ within the
    tolerance."""

    def ratio(h, t):
        return 1 + 0.1 * h * np.exp(-h / 3) * (1 + 0.02 * t) + 0.001 * t

    tps = tuple(6.0 + k for k in range(9))
    rows = [{"hs": h, "tp": t, "hours": 1.0} for t in tps for h in HS if t > 6.0 or h <= 5.0]
    states, stats, dam, linear, rws = _field(
        lambda h, t: 1.0, lambda h, t: 1.0, ratio, lambda h, t: 1.0, rows=rows
    )
    exact, miss = _adapt(states, stats, dam, linear, rws, slopes={})
    r, scale = check_ratios(stats, dam, linear)
    curves = HeadingCurves(layout(states)[0.0], exact, r, scale, "power",
                           MomentCoordinates.of(r, linear, dam))  # fmt: skip
    laws = [curves.column_law(j) for j in range(9)]
    assert curves.parents(1) == (0, 2) and laws[1] != "transfer"
    assert curves.parents(6) == (4, 8) and laws[6] == "transfer"
    assert miss < 1e-3
