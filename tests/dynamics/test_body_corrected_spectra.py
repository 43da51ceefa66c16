"""A free body's motion spectral densities with the residuals
(stochcable.dynamics.groups.results.body_result through
stochcable.dynamics.residuals.corrected_spectrum.spectrum_with_lines): each DOF's area
is the corrected σ² its statistics report, its m2 and m4 are theirs within the
interpolation's error, the document and the Dataset carry it unchanged, and with the
switches off there is none (the linear statistics bit for bit)."""

from __future__ import annotations

import json
import warnings

import numpy as np
import pytest

from stochcable import analyze, load_example
from stochcable.design import spectral_moments_along
from stochcable.results.datasets import dataset_from_document


def _buoy(name: str, on: bool):
    doc = load_example(name).model_dump(mode="json")
    doc["analysis"].pop("timeseries", None)
    doc["analysis"]["linearization"].update(drag_residual=on, geometric_residual=on)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return analyze(doc)


@pytest.fixture(scope="module")
def three_legs():
    name = "tuah_1982_disc_buoy_three_legs"
    return _buoy(name, True), _buoy(name, False)


@pytest.mark.parametrize("legs", ["single_leg", "three_legs"])
def test_area_is_the_corrected_variance(legs, three_legs):
    """Every DOF: ∫S dω = σ² of its corrected statistics (1e-12: the scale of the
    residual lines is solved for it); m2, m4 within 3 % of the statistics' line sums
    (the lines' interpolation: surge's residual sits in the first difference-frequency
    lines, measured −0.9 %/−0.3 % single leg, −2.1 %/−1.6 % three legs; heave and pitch
    below 0.03 %); the density is ≥ 0, reaches above ω_max (the drag's superharmonics)
    and holds the analysis grid; surge's corrected density exceeds the linear one's
    area (the residual raises surge σ)."""
    res = three_legs[0] if legs == "three_legs" else _buoy("tuah_1982_disc_buoy_single_leg", True)
    (body,) = res.bodies.values()
    assert body.corrected_spectra is not None
    for dof in body.dofs:
        om, dens = body.motion_density(dof)
        st = body.motion[dof]
        assert np.all(dens >= 0) and np.all(np.isin(body.omega, om))
        if st.std == 0.0:  # (sway, roll, yaw of the symmetric buoy: at rest)
            assert np.all(dens == 0)
            continue
        m = spectral_moments_along(om, dens)
        assert float(m["m0"]) == pytest.approx(st.std**2, rel=1e-12)
        assert float(m["m2"]) == pytest.approx(st.m2, rel=3e-2)
        assert float(m["m4"]) == pytest.approx(st.m4, rel=3e-2)
        assert om[-1] > 1.9 * body.omega[-1]
    lin = np.trapezoid(body.motion_spectrum[0], body.omega)
    assert lin == pytest.approx(body.motion_linear["surge"].std ** 2, rel=1e-12)
    assert body.motion["surge"].std ** 2 > 1.5 * lin


def test_switches_off_give_no_corrected_density(three_legs):
    """Switches off: no ``corrected_spectra`` (nor in the document), the density read
    is the linear spectrum on the analysis grid, and the statistics are the linear copy
    of the run with them, bit for bit."""
    on, off = (next(iter(r.bodies.values())) for r in three_legs)
    assert off.corrected_spectra is None and off.motion_linear is None
    for i, dof in enumerate(off.dofs):
        om, dens = off.motion_density(dof)
        assert om is off.omega
        np.testing.assert_array_equal(dens, off.motion_spectrum[i])
        assert off.motion[dof] == on.motion_linear[dof]
    assert "corrected_spectra" not in off.to_document()
    np.testing.assert_array_equal(on.motion_spectrum, off.motion_spectrum)


def test_document_and_dataset_carry_the_densities(three_legs):
    """The document's ``corrected_spectra`` (through JSON) equal the result's arrays
    exactly, and the Dataset's ``body_motion_corrected_spectrum`` over its finite
    values equals them and integrates to ``body_motion_std`` squared (1e-12)."""
    res, off = three_legs
    doc = json.loads(json.dumps(res.to_document(timeseries="none")))
    (name, body) = next(iter(res.bodies.items()))
    part = doc["bodies"][name]["corrected_spectra"]
    ds = dataset_from_document(doc)
    got = ds["body_motion_corrected_spectrum"]
    assert got.attrs["units"] == "(ft2 or rad2) s rad-1"
    for dof in body.dofs:
        om, dens = body.motion_density(dof)
        np.testing.assert_array_equal(part[dof]["omega"], om)
        np.testing.assert_array_equal(part[dof]["motion"], dens)
        sel = got.sel(body=name, dof=dof)
        keep = np.isfinite(sel.values)
        np.testing.assert_array_equal(sel["omega_body_corrected"].values[keep], om)
        np.testing.assert_array_equal(sel.values[keep], dens)
        area = np.trapezoid(sel.values[keep], om)
        std = float(ds["body_motion_std"].sel(body=name, dof=dof))
        assert area == pytest.approx(std**2, rel=1e-12, abs=1e-300)
    plain = dataset_from_document(off.to_document(timeseries="none"))
    assert "body_motion_corrected_spectrum" not in plain


def test_netcdf_round_trip(three_legs, tmp_path):
    """Written as NetCDF-4 and read back: the body densities and their frequency
    coordinate unchanged (NaN where a DOF has no point)."""
    xr = pytest.importorskip("xarray")
    res, _ = three_legs
    ds = res.to_xarray()
    path = res.to_netcdf(tmp_path / "r.nc")
    with xr.open_dataset(path) as back:
        for name in ("body_motion_corrected_spectrum", "omega_body_corrected"):
            np.testing.assert_array_equal(back[name].values, ds[name].values)
