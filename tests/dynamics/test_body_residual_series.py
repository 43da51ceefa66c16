"""A free body's motion series with the residuals
(stochcable.dynamics.timeseries.synthesis, residual_series.residual_motion_density): each
DOF gets an independent Gaussian component with the residuals' density (its corrected
density less its linear one), so the record's σ is the corrected one; the linear series
is the switches-off run's to round-off, and so are the end tensions'."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from stochcable import analyze, load_example
from stochcable.dynamics.timeseries.residual_series import residual_motion_density


def _disc(on: bool):
    doc = load_example("tuah_1982_disc_buoy_single_leg").model_dump(mode="json")
    doc["analysis"]["linearization"].update(drag_residual=on, geometric_residual=on)
    doc["analysis"]["timeseries"] = {"method": "dsa", "duration": 2048.0, "dt": 0.2, "seed": 3}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return analyze(doc)


@pytest.fixture(scope="module")
def runs():
    return _disc(True), _disc(False)


def test_component_carries_the_residual_variance(runs):
    """Surge (where the residuals move σ by −2 %…+50 %): the component's variance is
    the residuals' density's area within 5 % (a DSA record of the density sampled on
    its 2048 s lines, the lines' density varying across a line's cell), and the
    record's σ the corrected one within 5 %."""
    on, _ = runs
    (name, body), = on.bodies.items()  # fmt: skip
    ts = on.timeseries
    comp = ts.body_motion_residual[name]["surge"]
    om, s_r = residual_motion_density(body, "surge")
    assert np.var(comp) == pytest.approx(np.trapezoid(s_r, om), rel=5e-2)
    series = ts.body_motion[name]["surge"]
    assert np.std(series) == pytest.approx(body.motion["surge"].std, rel=5e-2)
    assert body.motion["surge"].std > 1.2 * body.motion_linear["surge"].std


def test_linear_series_and_the_others_are_the_switches_off_runs(runs):
    """The body's linear series (the series less the component) and the end tensions'
    linear series equal the switches-off run's to round-off (1e-12 of their range: the
    component added and taken off again), the sea's bit for bit (the components'
    generators follow every other)."""
    on, off = runs
    (name, _), = on.bodies.items()  # fmt: skip
    for dof, s in off.timeseries.body_motion[name].items():
        np.testing.assert_allclose(
            on.timeseries.body_motion_linear[name][dof], s, rtol=0, atol=1e-12 * np.ptp(s)
        )
    np.testing.assert_array_equal(on.timeseries.elevation, off.timeseries.elevation)
    for line, ends in off.timeseries.end_tension.items():
        for end, s in ends.items():
            np.testing.assert_allclose(
                on.timeseries.end_tension_linear[line][end], s, rtol=0, atol=1e-12 * np.ptp(s)
            )
    assert off.timeseries.body_motion_residual == {}
