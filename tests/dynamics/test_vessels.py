"""Vessel and end-motion RAO tables over wave heading (issue 20, "vessel RAOs
interpolated over heading"): :mod:`stochcable.scene.raos` and
:mod:`stochcable.dynamics.groups.vessels`.

Independent checks: a sea heading on a table row gives the analysis of the
heading-free table holding that row; a heading between two rows gives that of the
table holding their linear interpolation (written out here, not by the library); in a
spread sea the vessel's motion spectrum is the closed-form directional sum
Σ_k w_k |RAO(θ_k)|² S; with the drag off the spread response of the riser is the sum
of long-crested analyses at the directions' headings; an engine built once answers
sea states of different headings as ``analyze`` does; a sea direction outside a table
that does not cover the full circle is a 422 naming the table's heading field."""

from __future__ import annotations

import math

import numpy as np
import pytest
from _scenes import LINEAR_ONLY, vessel_rao_table
from _scenes import buoy_with_vessel as _buoy
from fastapi.testclient import TestClient

from service.app import create_app
from service.settings import Settings
from stochcable.analysis import analyze
from stochcable.errors import InputError
from stochcable.scene.model import load_scene
from stochcable.scene.raos import MotionRao, VesselMotion

#: the vessel table's headings [deg]: the full circle every 30°
CIRCLE = [float(h) for h in range(0, 360, 30)]
DOFS = ("surge", "sway", "heave", "roll", "pitch", "yaw")


def _row_table(headings: list[float], weights: list[float]) -> dict:
    """The heading-free table Σ_i weights[i]·(row of headings[i]) of the test vessel,
    formed here from the rows of :func:`vessel_rao_table` (not by interpolation code)."""
    full = vessel_rao_table(CIRCLE)
    out = {"omega": full["omega"]}
    for k in ("surge", "sway", "heave", "roll", "pitch"):
        v = sum(
            wt
            * (
                np.asarray(full[k]["re"][CIRCLE.index(h)])
                + 1j * np.asarray(full[k]["im"][CIRCLE.index(h)])
            )
            for h, wt in zip(headings, weights)
        )
        out[k] = {"re": v.real.tolist(), "im": v.imag.tolist()}
    return out


def _with_vessel_table(doc: dict, table: dict) -> dict:
    doc["bodies"][1]["prescribed"] = table
    return doc


def _ship_spectrum(result) -> np.ndarray:
    b = result.bodies["ship"]
    return np.einsum("cdw,cw->dw", np.abs(b.motion_transfer) ** 2, b.input_spectra)


def _assert_same(got, ref, rtol: float) -> None:
    np.testing.assert_allclose(_ship_spectrum(got), _ship_spectrum(ref), rtol=rtol, atol=1e-300)
    for line in ref.lines:
        np.testing.assert_allclose(
            got.lines[line].tension_std, ref.lines[line].tension_std, rtol=rtol
        )


# ------------------------------------------------------------------- the scene


def test_table_validates_shapes_and_headings():
    """Each DOF of a table with headings is (n_heading, n_omega); headings strictly
    increasing and spanning < 360°; the message names the DOF and both shapes."""
    good = vessel_rao_table([0.0, 90.0])
    VesselMotion.model_validate(good)
    bad = {**good, "heave": {"re": [[0.0] * 60], "im": [[0.0] * 60]}}
    with pytest.raises(
        ValueError, match=r"heave has shape \(1, 60\) but \(heading, omega\) gives \(2, 60\)"
    ):
        VesselMotion.model_validate(bad)
    with pytest.raises(ValueError, match="strictly increasing and span less than 360"):
        VesselMotion.model_validate({**good, "heading": [90.0, 0.0]})
    with pytest.raises(ValueError, match="strictly increasing and span less than 360"):
        VesselMotion.model_validate(vessel_rao_table([0.0, 360.0]))
    flat = vessel_rao_table()
    with pytest.raises(ValueError, match=r"surge has shape \(60,\) but \(heading, omega\)"):
        VesselMotion.model_validate({**flat, "heading": [0.0]})
    with pytest.raises(ValueError, match="regular"):
        MotionRao.model_validate(
            {
                "omega": [0.1, 0.2],
                "heading": [0, 90],
                "heave": {"re": [[1, 1], [1]], "im": [[0, 0], [0]]},
            }
        )


def test_transfer_interpolates_and_wraps_around():
    """Linear in re and im between neighbouring headings; a full-circle table wraps
    from its last heading (330°) to its first (0° = 360°); a row heading gives the row."""
    table = VesselMotion.model_validate(vessel_rao_table(CIRCLE))
    w = np.asarray(table.omega)
    rows = {h: table.transfer(w, math.radians(h)) for h in (0.0, 30.0, 330.0)}
    surge0 = np.asarray(table.surge.re[0]) + 1j * np.asarray(table.surge.im[0])
    np.testing.assert_array_equal(rows[0.0][0], surge0)
    np.testing.assert_allclose(
        table.transfer(w, math.radians(15.0)),
        0.5 * (rows[0.0] + rows[30.0]),
        rtol=1e-14,
        atol=1e-16,
    )
    np.testing.assert_allclose(
        table.transfer(w, math.radians(345.0)),
        0.5 * (rows[330.0] + rows[0.0]),
        rtol=1e-14,
        atol=1e-16,
    )
    np.testing.assert_allclose(
        table.transfer(w, math.radians(-15.0)),
        table.transfer(w, math.radians(345.0)),
        rtol=1e-14,
        atol=1e-16,
    )
    # a heading-free table ignores the heading
    flat = VesselMotion.model_validate(vessel_rao_table())
    np.testing.assert_array_equal(flat.transfer(w, 1.0), flat.transfer(w))
    with pytest.raises(ValueError, match="give the wave heading"):
        table.transfer(w)


def test_sea_outside_a_partial_table_names_the_heading_field():
    """A table over 0–90° and a sea toward 180°: the scene names the table's heading
    field, the direction and the table's range; in a spread sea the first direction
    outside; the service answers 422 with the same message."""
    doc = _buoy(180.0, vessel=True, vessel_headings=[0.0, 45.0, 90.0])
    with pytest.raises(InputError) as info:
        load_scene(doc)
    err = info.value
    assert err.parameter == "bodies[1].prescribed.heading"
    assert err.value == [0.0, 45.0, 90.0]
    assert "the sea direction 180 deg" in err.constraint
    assert "outside the RAO table's headings [0, 90] deg" in err.constraint
    spread = {"type": "table", "offset": [-20.0, 0.0, 20.0], "weight": [1.0, 2.0, 1.0]}
    with pytest.raises(InputError, match="the sea direction 100 deg"):
        load_scene(_buoy(80.0, spread, vessel=True, vessel_headings=[0.0, 45.0, 90.0]))
    load_scene(_buoy(70.0, spread, vessel=True, vessel_headings=[0.0, 45.0, 90.0]))
    with TestClient(create_app(Settings())) as client:
        r = client.post("/v1/analyses", json=doc)
    assert r.status_code == 422, r.text
    assert "bodies[1].prescribed.heading" in r.text and "180 deg" in r.text


# ------------------------------------------------------------------ long-crested


@pytest.mark.parametrize(
    ("heading", "rows", "weights"),
    [
        (60.0, [60.0], [1.0]),
        (45.0, [30.0, 60.0], [0.5, 0.5]),
        (350.0, [330.0, 0.0], [1 / 3, 2 / 3]),
    ],
)
def test_sea_heading_selects_and_interpolates_the_rao(heading, rows, weights):
    """Long-crested sea toward ``heading``: the analysis with the table over the full
    circle equals the analysis with the heading-free table of the row (or of the
    rows' linear interpolation, 350° = 2/3 of 0° and 1/3 of 330°) — the vessel's
    motion spectrum and every line's tension σ, drag on (1e-10: the same numbers; the
    interpolation weights round differently).  The linear model: the table's heading,
    not the residuals (on: 2.7–2.9 s of CPU each, the three legs' group residuals)."""

    def buoy(**kw) -> dict:
        doc = _buoy(heading, full_circle=True, vessel=True, **kw)
        doc["analysis"].setdefault("linearization", {}).update(LINEAR_ONLY)
        return doc

    got = analyze(buoy(vessel_headings=CIRCLE))
    ref = analyze(_with_vessel_table(buoy(), _row_table(rows, weights)))
    _assert_same(got, ref, 1e-10)
    # and the heading matters: the 0° row (no sway) moves the ship otherwise
    other = analyze(_with_vessel_table(buoy(), _row_table([0.0], [1.0])))
    sway = _ship_spectrum(got)[1].sum()
    assert abs(_ship_spectrum(other)[1].sum() - sway) > 0.1 * sway


def test_line_end_rao_over_heading():
    """A line end moving with an RAO table over heading (MotionRao with ``heading``):
    the sea toward 45° gives the analysis of the heading-free table interpolated
    between 30° and 60°, written out here (the linear model: the end's table, not the
    residuals)."""
    table = vessel_rao_table(CIRCLE)
    end = {k: table[k] for k in ("omega", "heading", "surge", "sway", "heave")}
    half = _row_table([30.0, 60.0], [0.5, 0.5])
    flat = {k: half[k] for k in ("omega", "surge", "sway", "heave")}

    def doc(rao):
        d = _buoy(45.0, full_circle=True, vessel=True)
        d["lines"][3]["end_b"] = {"position": [610.0, 0.0, -5.0], "motion": {"rao": rao}}
        d["bodies"].pop(1)
        d["analysis"].setdefault("linearization", {}).update(LINEAR_ONLY)
        return d

    got, ref = analyze(doc(end)), analyze(doc(flat))
    for line in ref.lines:
        np.testing.assert_allclose(
            got.lines[line].tension_std, ref.lines[line].tension_std, rtol=1e-10
        )


# ----------------------------------------------------------------- short-crested


def test_spread_vessel_motion_is_the_directional_sum():
    """A cos-2s sea (s = 2, 9 directions about 40°): the vessel's motion spectrum is
    Σ_k w_k |RAO(θ_k)|² S(ω), with RAO(θ_k) interpolated here between the table's rows
    and w_k S from the analysis' sea channels (round-off only: 1e-12).  The sway of the
    spread sea differs from the mean heading's by more than 5 %."""
    spread = {"type": "cos2s", "s": 2.0, "directions": 9}
    # the linear model: the vessel's motion, not the lines' residuals
    doc = _buoy(40.0, spread, full_circle=True, vessel=True, vessel_headings=CIRCLE)
    doc["analysis"].setdefault("linearization", {}).update(LINEAR_ONLY)
    res = analyze(doc)
    ds = load_scene(doc).sea.direction_set()
    ship = res.bodies["ship"]
    table = vessel_rao_table(CIRCLE)
    w_tab = np.asarray(table["omega"])
    want = np.zeros((6, ship.omega.size))
    for k, theta in enumerate(ds.heading):
        deg = math.degrees(theta) % 360.0
        i = int(deg // 30.0)
        t = (deg - 30.0 * i) / 30.0
        for d, dof in enumerate(DOFS):
            if dof not in table:
                continue
            re, im = np.asarray(table[dof]["re"]), np.asarray(table[dof]["im"])
            rows = re + 1j * im  # (12, n_w), 0°, 30°, ..., 330°
            v = (1 - t) * rows[i % 12] + t * rows[(i + 1) % 12]
            h = np.interp(ship.omega, w_tab, v.real, 0, 0) + 1j * np.interp(
                ship.omega, w_tab, v.imag, 0, 0
            )
            want[d] += np.abs(h) ** 2 * ship.input_spectra[k]
    np.testing.assert_allclose(_ship_spectrum(res), want, rtol=1e-12, atol=1e-300)
    # the spreading matters: the mean heading's RAO on the whole spectrum differs
    mean_doc = _buoy(40.0, full_circle=True, vessel=True, vessel_headings=CIRCLE)
    mean_doc["analysis"].setdefault("linearization", {}).update(LINEAR_ONLY)
    mean = analyze(mean_doc)
    sway = (_ship_spectrum(res)[1].sum(), _ship_spectrum(mean)[1].sum())
    assert abs(sway[0] / sway[1] - 1) > 0.05


def test_spread_riser_is_the_sum_of_long_crested_responses_without_drag():
    """Drag off: three directions (a table spreading, 20° apart about 50°) are
    independent inputs of one linear system, so the riser's tension spectra are
    Σ_k w_k of the long-crested analyses at θ_k — each with the vessel RAO of its own
    heading (round-off: 1e-12 of each spectrum's peak)."""
    spread = {"type": "table", "offset": [-20.0, 0.0, 20.0], "weight": [0.25, 0.5, 0.25]}
    got = analyze(
        _buoy(50.0, spread, full_circle=True, vessel=True, drag=False, vessel_headings=CIRCLE)
    )
    r = got.lines["riser"]
    have = np.stack(
        [
            np.einsum("cw,cw->w", np.abs(r.end_tension_transfer[e]) ** 2, r.input_spectra)
            for e in ("end_a", "end_b")
        ]
    )
    want = np.zeros_like(have)
    for off, wk in zip((-20.0, 0.0, 20.0), (0.25, 0.5, 0.25)):
        one = analyze(
            _buoy(50.0 + off, full_circle=True, vessel=True, drag=False, vessel_headings=CIRCLE)
        ).lines["riser"]
        want += wk * np.stack(
            [
                np.einsum("cw,cw->w", np.abs(one.end_tension_transfer[e]) ** 2, one.input_spectra)
                for e in ("end_a", "end_b")
            ]
        )
    for i in range(2):
        np.testing.assert_allclose(have[i], want[i], rtol=0, atol=1e-12 * want[i].max())


# ----------------------------------------------------------------------- engine


# 3.6 s of CPU with the residuals in the element tensions and node motions: over
# the fast tier's budget
@pytest.mark.slow
def test_engine_answers_each_heading_as_analyze():
    """One engine (model, modes, factorizations built once) solving sea states toward
    0°, 90° and 0° again: each equals ``analyze`` of the scene with that sea (1e-11:
    round-off), so the per-heading RAO and the kinematics kept per heading are not
    mixed up between sea states."""
    from stochcable.dynamics.engine import build_engine

    engine = build_engine(_buoy(0.0, full_circle=True, vessel=True, vessel_headings=CIRCLE))
    for heading, hs in ((0.0, 8.0), (90.0, 10.0), (0.0, 12.0)):
        sea = {"spectrum": {"type": "jonswap", "hs": hs, "tp": 10.0}, "heading": heading}
        got = engine.solve(sea)
        ref_doc = _buoy(heading, full_circle=True, vessel=True, vessel_headings=CIRCLE)
        ref = analyze({**ref_doc, "sea": sea})
        _assert_same(got, ref, 1e-11)


def test_load_case_set_over_headings_moves_the_vessel_per_case():
    """A load-case set over headings 0° and 90° (a scatter table): each case's riser
    tension statistics equal ``analyze`` of the scene with that case's sea (both 3-D,
    the vessel sways: the same model, so round-off only, 1e-9), and the two headings
    differ (the 90° case sways the ship)."""
    from stochcable.cases import run_cases, scatter_from_rows
    from stochcable.scene.model import Sea
    from stochcable.scene.spectra import Jonswap

    doc = _buoy(0.0, full_circle=True, vessel=True, vessel_headings=CIRCLE)
    # the vessel's motion per case, not the residuals (tests/cases): the linear model,
    # 3.8 s of CPU with the three legs' group residuals
    doc["analysis"].setdefault("linearization", {}).update(LINEAR_ONLY)
    scene = load_scene(doc)
    rows = [
        {"hs": 8.0, "tp": 10.0, "gamma": 2.0, "heading": h, "probability": 0.5} for h in (0, 90)
    ]
    res = run_cases(scene, scatter_from_rows(rows))
    # (flagged: the three-leg buoy example's large-motion indicator, as in analyze)
    assert [r.status for r in res.rows] == ["flagged", "flagged"]
    for i, r in enumerate(rows):
        sea = Sea(spectrum=Jonswap(hs=r["hs"], tp=r["tp"], gamma=r["gamma"]), heading=r["heading"])
        one = analyze(scene.model_copy(update={"sea": sea})).lines["riser"]
        for end in ("end_a", "end_b"):
            st = getattr(one, end)
            got = res.stats["riser"][end][i]
            np.testing.assert_allclose(got, [st.mean, st.std, st.tz, st.mpm_3h], rtol=1e-9)
    assert res.stats["riser"]["end_b"][0][1] != pytest.approx(
        res.stats["riser"]["end_b"][1][1], rel=1e-3
    )
