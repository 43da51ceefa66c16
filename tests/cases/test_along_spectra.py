"""The element tensions' corrected densities of a set's computed case, all elements at
once (stochcable.cases.along_spectra): each element's the density of
AlongLineResidual.density (corrected_spectrum) to round-off, and its area the
element's corrected variance."""

from __future__ import annotations

import warnings

import numpy as np

from stochcable.cases import scatter_from_rows
from stochcable.cases.along_spectra import element_densities
from stochcable.cases.chunk import case_sea, engine_template, set_engine
from stochcable.dynamics.model.blocks import trapezoid_weights
from stochcable.examples import load_example
from stochcable.scene.model import load_scene


def test_element_densities_are_each_elements_corrected_spectrum():
    doc = load_example("taut_wire").model_dump(mode="json", exclude_none=True)
    doc["analysis"].pop("timeseries", None)
    scene = load_scene(doc)
    sd = scatter_from_rows([{"hs": 3.0, "tp": 10.0, "hours": 1.0}])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        engine = set_engine(engine_template(scene, sd.states, "jonswap"))
        lr = engine.solve(case_sea(scene, sd.states[0], "jonswap")).lines["wire"]
    assert lr.along_line is not None and lr.along_line.computed
    grid, dens = element_densities(lr.along_line, lr.omega, lr.tension_spectrum)
    for e in range(dens.shape[0]):
        one = lr.along_line.density(e, lr.omega, lr.tension_spectrum[e])
        np.testing.assert_array_equal(one.omega, grid)
        # (the same sums in another order: round-off, measured 3e-16 of the peak)
        np.testing.assert_allclose(dens[e], one.density, rtol=0, atol=1e-12 * one.density.max())
    # the area of every element's density is its corrected variance (σ with the residuals)
    area = dens @ trapezoid_weights(grid)
    np.testing.assert_allclose(np.sqrt(area), lr.tension_std, rtol=1e-9)
    assert np.max(lr.tension_std / lr.tension_std_linear - 1) > 0.05  # (corrected here)
