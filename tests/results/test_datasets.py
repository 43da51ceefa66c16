"""Tests of stochcable.results.datasets: the result as an xarray Dataset and NetCDF."""

from __future__ import annotations

import json
import warnings

import numpy as np
import pytest
from _paths import ROOT

from stochcable.analysis import analyze
from stochcable.results.datasets import dataset_from_document, netcdf_bytes
from stochcable.scene.model import load_scene

# one worker runs the module: its module fixtures run once (--dist loadgroup)
pytestmark = pytest.mark.xdist_group("test_datasets")

EXAMPLES = ROOT / "stochcable" / "examples"
xr = pytest.importorskip("xarray")
pytest.importorskip("netCDF4")


@pytest.fixture(scope="module")
def three_legs():
    """A foot-slug-second scene with a body, three lines and (added) a time series."""
    doc = json.loads((EXAMPLES / "tuah_1982_disc_buoy_three_legs.json").read_text())
    doc["analysis"]["timeseries"] = {"method": "dsa", "duration": 64.0, "dt": 0.5, "seed": 2}
    scene = load_scene(doc)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the example's documented warnings
        return analyze(scene)


def test_values_equal_the_result_document(three_legs):
    ds = three_legs.to_xarray()
    doc = json.loads(json.dumps(three_legs.to_document(timeseries="full")))
    assert ds.attrs["unit_system"] == "foot-slug-second"
    assert ds["end_tension_std"].attrs["units"] == "lbf"
    assert ds["motion_std"].attrs["units"] == "ft"
    assert list(ds["line"].values) == list(doc["lines"])
    for name, line in doc["lines"].items():
        for end in ("end_a", "end_b"):
            for key in ("mean", "std", "tz", "mpm_3h", "significant", "expected_max"):
                got = ds[f"end_tension_{key}"].sel(line=name, end=end).item()
                assert got == line[end]["tension"][key]
            spec = ds["end_tension_spectrum"].sel(line=name, end=end).values
            assert np.array_equal(spec, line["spectra"][end]["tension"])
            assert np.array_equal(
                ds["end_force_std"].sel(line=name, end=end).values, line[end]["force_std"]
            )
        n_el = len(line["tension"]["s"])
        sel = ds.sel(line=name)
        assert np.array_equal(sel["tension_std"].values[:n_el], line["tension"]["std"])
        assert np.array_equal(sel["tension_mean"].values[:n_el], line["tension"]["mean"])
        assert np.array_equal(sel["element_arclength"].values[:n_el], line["tension"]["s"])
        n_nd = len(line["motion"]["s"])
        assert np.array_equal(sel["motion_std"].values[:n_nd], line["motion"]["std"])
        assert np.array_equal(
            sel["static_position"].values[:n_nd], doc["statics"]["lines"][name]["nodes"]
        )
        assert sel["touchdown"].item() == doc["statics"]["lines"][name]["touchdown"]
        assert sel["linearization_iterations"].item() == line["linearization"]["iterations"]
        assert np.array_equal(
            ds["end_tension_series"].sel(line=name, end="end_b").values,
            doc["timeseries"]["lines"][name]["end_b"]["tension"],
        )
    assert np.array_equal(ds["omega"].values, doc["lines"]["leg1"]["spectra"]["omega"])
    body = doc["bodies"]["disc"]
    for dof in body["dofs"]:
        assert ds["body_motion_std"].sel(body="disc", dof=dof).item() == body["motion"][dof]["std"]
        assert np.array_equal(
            ds["body_motion_spectrum"].sel(body="disc", dof=dof).values, body["spectra"][dof]
        )
    assert np.array_equal(ds["elevation"].values, doc["timeseries"]["elevation"])


def test_document_read_back_gives_the_same_dataset(three_legs):
    """The JSON document (the CLI's or the service's) gives the Dataset the result gives,
    less the along-line spectra only the Python result carries."""
    ds = three_legs.to_xarray().drop_vars(["tension_spectrum", "motion_spectrum"])
    doc = json.loads(json.dumps(three_legs.to_document(timeseries="full")))
    xr.testing.assert_identical(dataset_from_document(doc), ds)


def test_spectra_along_the_line_integrate_to_the_documented_sigma(three_legs):
    """Second route to σ: ∫S dω (trapezoid on the grid, as the statistics use) of the
    element tension and node motion spectra equals the σ the document carries."""
    ds = three_legs.to_xarray()
    w = ds["omega"].values
    for name in ds["line"].values:
        sel = ds.sel(line=name)
        n_el = int(np.isfinite(sel["tension_std"].values).sum())
        var = np.trapezoid(sel["tension_spectrum"].values[:n_el], w, axis=-1)
        # the same sum in another order: round-off only (the spectra are the linear
        # model's: σ the linear one where the residuals were added along the line)
        lin = sel["tension_std_linear"] if "tension_std_linear" in sel else sel["tension_std"]
        assert np.sqrt(var) == pytest.approx(lin.values[:n_el], rel=1e-9, abs=1e-9)
        n_nd = int(np.isfinite(sel["node_arclength"].values).sum())
        mvar = np.trapezoid(sel["motion_spectrum"].values[:n_nd], w, axis=-1)
        mlin = sel["motion_std_linear"] if "motion_std_linear" in sel else sel["motion_std"]
        assert np.sqrt(mvar) == pytest.approx(mlin.values[:n_nd], rel=1e-9, abs=1e-9)


def test_netcdf_round_trip(three_legs, tmp_path):
    path = three_legs.to_netcdf(tmp_path / "result.nc")
    ds = three_legs.to_xarray()
    with xr.open_dataset(path) as back:
        xr.testing.assert_identical(back.load(), ds)


def test_netcdf_bytes_of_a_document_read_back(three_legs, tmp_path):
    doc = json.loads(json.dumps(three_legs.to_document()))
    ds = dataset_from_document(doc)
    data = netcdf_bytes(ds)
    assert data[:4] == b"\x89HDF"  # NetCDF-4 is an HDF5 file
    path = tmp_path / "answer.nc"
    path.write_bytes(data)
    with xr.open_dataset(path) as back:
        xr.testing.assert_identical(back.load(), ds)


def test_linear_series_beside_when_asked(three_legs):
    """timeseries_linear: ``end_tension_series_linear`` holds the linear model's end
    tensions (the document's ``tension_linear``); not asked for, it is absent."""
    assert "end_tension_series_linear" not in three_legs.to_xarray()
    ds = three_legs.to_xarray(timeseries_linear=True)
    ts = three_legs.timeseries
    assert ts.end_tension_residual  # (the legs carry the residuals' component)
    for name in three_legs.lines:
        for end in ("end_a", "end_b"):
            np.testing.assert_allclose(
                ds["end_tension_series_linear"].sel(line=name, end=end).values,
                ts.end_tension_linear[name][end],
                rtol=1e-12,
            )
