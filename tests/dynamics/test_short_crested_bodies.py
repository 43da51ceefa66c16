"""Short-crested seas with bodies and vessels (``sea.spreading``, issue 20): each
direction channel drives the bodies' wave excitation at its own heading and the
vessel's fairleads with the vessel RAO (a table without headings: the same in every
direction; tables over heading: tests/dynamics/test_vessels.py), and the drag linearization
stays one fixed point over all directions.

Independent checks: a spreading that narrows to zero width is the long-crested
analysis; with the drag off (nothing couples the directions) the spread response
spectrum is the sum of long-crested analyses at the directions' headings θ_k with the
spectra w_k S; a spreading mirrored about the scene's symmetry plane mirrors the
response; an excitation table without a direction's heading names it."""

from __future__ import annotations

import math

import numpy as np
import pytest
from _scenes import buoy_with_vessel as _buoy

from stochcable.analysis import analyze
from stochcable.errors import InputError
from stochcable.examples import load_example
from stochcable.scene.model import load_scene

DOFS = ("surge", "sway", "heave", "roll", "pitch", "yaw")


def _body_std(result, name: str = "disc") -> np.ndarray:
    return np.array([result.bodies[name].motion[k].std for k in result.bodies[name].dofs])


def _body_spectrum(result, name: str = "disc") -> np.ndarray:
    """Σ_c |H_c|² S_c of every DOF, shape (d, n_w)."""
    b = result.bodies[name]
    return np.einsum("cdw,cw->dw", np.abs(b.motion_transfer) ** 2, b.input_spectra)


def _tension_spectrum(result, line: str) -> np.ndarray:
    """End tension spectra Σ_c |H_c|² S_c, shape (2, n_w) (end_a, end_b)."""
    r = result.lines[line]
    return np.stack(
        [
            np.einsum("cw,cw->w", np.abs(r.end_tension_transfer[e]) ** 2, r.input_spectra)
            for e in ("end_a", "end_b")
        ]
    )


# ----------------------------------------------------------------- zero width


@pytest.mark.parametrize(
    "spreading",
    [
        {"type": "table", "offset": [0.0], "weight": [1.0]},
        # the side bins carry < 1e-30 and are left out; the centre bin's centroid is
        # the mean heading to round-off
        {"type": "cos2s", "s": 1e6, "directions": 15},
    ],
)
def test_zero_width_spreading_is_the_long_crested_sea_with_bodies(spreading):
    """The seed §6.7 three-leg buoy example (excitation at heading 0 only) with a
    vessel and its riser: one direction at the mean heading gives the long-crested
    analysis — the body's and the vessel's motion σ and every end tension σ — to
    round-off (1e-10: the same numbers, the channel renamed "sea@0")."""
    ref = analyze(_buoy(0.0, vessel=True))
    got = analyze(_buoy(0.0, spreading, vessel=True))
    assert got.bodies["disc"].channels[0] == "sea@0"
    assert got.bodies["ship"].channels == ("sea@0",)
    for name in ("disc", "ship"):
        a, b = _body_std(got, name), _body_std(ref, name)
        np.testing.assert_allclose(a, b, rtol=1e-10, atol=1e-10 * np.max(b))
    for line in ref.lines:
        for end in ("end_a", "end_b"):
            assert getattr(got.lines[line], end).std == pytest.approx(
                getattr(ref.lines[line], end).std, rel=1e-10
            )
        np.testing.assert_allclose(
            got.lines[line].tension_std, ref.lines[line].tension_std, rtol=1e-10
        )


# -------------------------------------------------------------- superposition


@pytest.mark.slow
def test_spread_response_is_the_sum_of_long_crested_responses_without_drag():
    """Drag off (lines and the disc): the system does not depend on the response, so
    the directions are independent inputs of one linear system and the spread
    response spectrum of a body DOF and of an end tension is Σ_k of the long-crested
    analyses at heading θ_k with the spectrum w_k S (θ_k, w_k from
    ``Sea.direction_set()``: cos-2s, s = 3, 16 directions over the whole circle,
    about 30°).  The long-crested analyses are scaled by w_k afterwards (the response
    spectrum is linear in the sea spectrum).  Round-off: the directions are solved as
    16 right-hand sides of one factorization instead of one each (measured ≤ 1e-15
    relative to each spectrum's peak; 1e-12 allowed)."""
    spread = {"type": "cos2s", "s": 3.0, "directions": 16}
    doc = _buoy(30.0, spread, full_circle=True, vessel=True, drag=False)
    got = analyze(doc)
    ds = load_scene(doc).sea.direction_set()
    assert ds.count == 16 and np.all(ds.weight > 1e-6)
    body = np.zeros_like(_body_spectrum(got))
    ship = np.zeros_like(_body_spectrum(got, "ship"))
    tension = {n: np.zeros((2, got.lines[n].omega.size)) for n in got.lines}
    for theta, wk in zip(ds.heading, ds.weight):
        one = analyze(_buoy(math.degrees(theta), full_circle=True, vessel=True, drag=False))
        body += wk * _body_spectrum(one)
        ship += wk * _body_spectrum(one, "ship")
        for n in tension:
            tension[n] += wk * _tension_spectrum(one, n)
    s_body = _body_spectrum(got)
    for i, dof in enumerate(DOFS):
        np.testing.assert_allclose(
            s_body[i], body[i], rtol=0, atol=1e-12 * np.max(body[i]), err_msg=dof
        )
    np.testing.assert_allclose(_body_spectrum(got, "ship"), ship, rtol=1e-12)
    for n in tension:
        np.testing.assert_allclose(
            _tension_spectrum(got, n), tension[n], rtol=0, atol=1e-12 * np.max(tension[n])
        )
    # and the spreading matters: the mean heading alone differs (the linear sway of the
    # spectra above, 2.87 against 2.23; σ with the geometric residual, 5.18 against
    # 5.37, is mostly the residual's on this undamped buoy)
    lc = analyze(_buoy(30.0, full_circle=True, vessel=True, drag=False))
    sway = [
        np.sqrt(
            np.sum(_body_spectrum(r)[1]) * (r.bodies["disc"].omega[1] - r.bodies["disc"].omega[0])
        )
        for r in (got, lc)
    ]
    assert abs(sway[0] / sway[1] - 1) > 0.05, sway


def test_vessel_rao_applies_to_every_direction():
    """The vessel RAO table has no heading dimension: every direction channel carries
    it, so the vessel's motion spectrum is |RAO|² Σ_k w_k S = |RAO|² S, the
    long-crested one, whatever the spreading (Σ w_k = 1 to round-off)."""
    spread = {"type": "cosn", "n": 2.0, "directions": 9}
    got = analyze(_buoy(30.0, spread, full_circle=True, vessel=True))
    ref = analyze(_buoy(30.0, full_circle=True, vessel=True))
    ship = got.bodies["ship"]
    assert len(ship.channels) == 9 and ship.prescribed
    np.testing.assert_allclose(_body_spectrum(got, "ship"), _body_spectrum(ref, "ship"), rtol=1e-12)
    # the riser feels the spreading through its own wave loads
    assert got.lines["riser"].end_a.std != pytest.approx(ref.lines["riser"].end_a.std, rel=1e-3)


@pytest.mark.slow  # the three-leg buoy's group residuals at the stations: 4.9 s of CPU
def test_engine_solves_spread_sea_states_as_analyze():
    """An engine built for the long-crested scene (3-D models) solves spread sea
    states as ``analyze`` of the scene with each: the same numbers (1e-11: round-off).
    The second sea state of the spreading reuses the grouped legs' kinematics of the
    first (one entry per directions kept) with its own spectra."""
    from stochcable.dynamics.engine import build_engine

    spread = {"type": "cosn", "n": 4.0, "directions": 7}
    engine = build_engine(_buoy(30.0, full_circle=True, vessel=True))
    engine.solve()  # the long-crested sea of the scene
    engine.solve({"spectrum": {"type": "jonswap", "hs": 8.0, "tp": 9.0}, "heading": 30.0,
                  "spreading": spread})  # fmt: skip
    sea = {"spectrum": {"type": "jonswap", "hs": 12.0, "tp": 11.0}, "heading": 30.0}
    got = engine.solve({**sea, "spreading": spread})
    assert len(engine.systems["leg1"]._cache["group_channels"]) == 2
    ref = analyze(
        {**_buoy(30.0, spread, full_circle=True, vessel=True), "sea": {**sea, "spreading": spread}}
    )
    for name in ("disc", "ship"):
        np.testing.assert_allclose(_body_std(got, name), _body_std(ref, name), rtol=1e-11)
    for line in ref.lines:
        np.testing.assert_allclose(
            got.lines[line].tension_std, ref.lines[line].tension_std, rtol=1e-11
        )
    assert got.bodies["disc"].channels[:7] == ref.bodies["disc"].channels[:7]


# --------------------------------------------------------------- time series

_SERIES = {"method": "dsa", "duration": 200.0, "dt": 0.5, "seed": 3}


def test_zero_width_time_series_with_bodies_are_the_long_crested_ones():
    """One direction: the long-crested realization drives the disc, the vessel and
    the lines; their series equal the long-crested analysis' to round-off."""
    ref_doc = _buoy(0.0, vessel=True)
    got_doc = _buoy(0.0, {"type": "cos2s", "s": 1e6, "directions": 15}, vessel=True)
    for d in (ref_doc, got_doc):
        d["analysis"]["timeseries"] = dict(_SERIES)
    ref, got = analyze(ref_doc).timeseries, analyze(got_doc).timeseries
    np.testing.assert_array_equal(got.elevation, ref.elevation)
    for body in ("disc", "ship"):
        # (sway, roll, yaw are zero in a head sea: the body's largest motion scales)
        scale = max(np.ptp(ref.body_motion[body][dof]) for dof in DOFS)
        for dof in DOFS:
            a, b = got.body_motion[body][dof], ref.body_motion[body][dof]
            np.testing.assert_allclose(a, b, rtol=0, atol=1e-10 * scale, err_msg=(body, dof))
    assert set(got.end_tension) == set(ref.end_tension) == {"leg1", "leg2", "leg3", "riser"}
    for line in ref.end_tension:
        for end in ("end_a", "end_b"):
            # (round-off of the residuals' sums over 15 channels against 1, against the
            # series' range as for the bodies: pointwise it reaches 2.1e-9 relative on a
            # 0.31 N sample of a 190–340 N record, 2e-12 of its range)
            a, b = got.end_tension[line][end], ref.end_tension[line][end]
            np.testing.assert_allclose(a, b, rtol=0, atol=1e-10 * np.ptp(b), err_msg=line)


def test_time_series_drive_each_direction_with_its_own_realization():
    """A spread sea: the disc and the vessel have one channel per direction (the
    analysis' names), and the vessel's motion is Σ_k of its RAO driven by direction
    k's realization (:func:`stochcable.sea.spreading.simulate_sea_directional` with the
    scene's seed), not by one shared realization."""
    from stochcable.dynamics.loads.sea_channels import spectrum_callable
    from stochcable.dynamics.timeseries.group_transfer import vessel_raos
    from stochcable.sea.realization import synthesize
    from stochcable.sea.spreading import simulate_sea_directional

    doc = _buoy(20.0, {"type": "cos2s", "s": 2.0, "directions": 6}, full_circle=True, vessel=True)
    doc["analysis"]["timeseries"] = dict(_SERIES)
    res = analyze(doc)
    ts, scene = res.timeseries, res.scene
    assert ts.body_channels["disc"][:6] == res.bodies["disc"].channels[:6]
    assert ts.body_channels["ship"] == res.bodies["ship"].channels
    reals = simulate_sea_directional(
        spectrum_callable(scene.sea.spectrum, scene.environment.g),
        scene.sea.direction_set(),
        _SERIES["duration"],
        _SERIES["dt"],
        "dsa",
        _SERIES["seed"],
    )
    np.testing.assert_allclose(ts.elevation, np.sum([r.elevation for r in reals], axis=0))
    w = ts.omega
    grid = scene.analysis.omega
    band = (w >= grid.min) & (w <= grid.max) & (w > 0)
    rao = np.zeros((6, w.size), dtype=complex)
    rao[:, band] = vessel_raos(scene, w[band]).at("ship", scene.sea.heading_rad).T
    surge = sum(synthesize(r, rao[0]) for r in reals)
    scale = np.max(np.abs(surge))
    np.testing.assert_allclose(ts.body_motion["ship"]["surge"] - 600.0, surge, atol=1e-10 * scale)
    shared = len(reals) * synthesize(reals[0], rao[0])
    assert np.max(np.abs(shared - surge)) > 0.1 * scale


# -------------------------------------------------------------------- mirror


def test_mirrored_spreading_mirrors_the_body_response():
    """The three-leg buoy is symmetric about the x–z plane (leg1 on −x, leg2 and leg3
    mirrored in y) and so is its full-circle excitation table; a spreading mirrored
    about heading 0 (offsets negated) mirrors the response: leg2 and leg3 swap, the
    disc's surge, heave and pitch transfer functions are those of the mirrored
    direction, its sway, roll and yaw change sign.  Drag on (the coupled fixed point
    over all directions): round-off of the same sums in another order (1e-8)."""
    table = {"type": "table", "offset": [-40.0, -10.0, 25.0, 70.0], "weight": [0.2, 0.4, 0.3, 0.1]}
    mirror = {**table, "offset": [-x for x in table["offset"]]}
    a = analyze(_buoy(0.0, table, full_circle=True))
    b = analyze(_buoy(0.0, mirror, full_circle=True))
    ta = {n: a.lines[n].tension_std for n in a.lines}
    tb = {n: b.lines[n].tension_std for n in b.lines}
    np.testing.assert_allclose(ta["leg1"], tb["leg1"], rtol=1e-8)
    np.testing.assert_allclose(ta["leg2"], tb["leg3"], rtol=1e-8)
    np.testing.assert_allclose(ta["leg3"], tb["leg2"], rtol=1e-8)
    assert abs(ta["leg2"][0] / ta["leg3"][0] - 1) > 1e-3  # the response is not symmetric
    ha, hb = a.bodies["disc"].motion_transfer, b.bodies["disc"].motion_transfer
    assert ha.shape[0] == 4
    sign = np.array([1, -1, 1, -1, 1, -1])[:, None]
    scale = np.max(np.abs(ha), axis=(0, 2))[:, None]
    for k in range(4):  # headings increase: direction k mirrors direction 3 − k
        np.testing.assert_allclose(
            ha[k] / (scale + 1e-300), sign * hb[3 - k] / (scale + 1e-300), rtol=0, atol=1e-8
        )
    assert np.max(np.abs(ha[:, 1])) > 1e-2 * np.max(np.abs(ha[:, 0]))  # sway is excited
    np.testing.assert_allclose(_body_std(a), _body_std(b), rtol=1e-8, atol=1e-12)


# ---------------------------------------------------------------- bad input


def test_excitation_without_a_direction_names_heading_and_the_direction():
    """The example's excitation is given at heading 0 only: a spread sea needs it at
    every direction; the error names ``heading``, the direction and its channel."""
    with pytest.raises(InputError) as info:
        analyze(_buoy(0.0, {"type": "cosn", "n": 4.0, "directions": 5}))
    err = info.value
    assert err.parameter == "heading"
    assert "sea.spreading" in str(err) and "direction 1 of 5" in str(err)
    assert "channel 'sea@" in str(err) and "disc" in str(err)


def test_planar_body_data_with_a_spread_sea_is_refused():
    """3×3 (surge, heave, pitch) body data need a planar scene; a spread sea is not
    (its directions leave the x–z plane): refused naming the body."""
    doc = load_example("tuah_1982_disc_buoy_single_leg").model_dump(mode="json", exclude_none=True)
    doc["sea"]["spreading"] = {"type": "cos2s", "s": 3.0}
    with pytest.raises(InputError) as info:
        load_scene(doc)
    assert "bodies" in info.value.parameter
    assert "spread sea" in str(info.value)
