"""Tests of stochcable.results.residual_dataset: the residuals of the linear model in
the result Dataset and its NetCDF."""

from __future__ import annotations

import copy
import json
import warnings

import numpy as np
import pytest

from stochcable.analysis import analyze
from stochcable.examples import load_example
from stochcable.results.datasets import dataset_from_document

# one worker runs the module: its module fixture runs once (--dist loadgroup)
pytestmark = pytest.mark.xdist_group("test_residual_dataset")

xr = pytest.importorskip("xarray")
pytest.importorskip("netCDF4")
ENDS = ("end_a", "end_b")


@pytest.fixture(scope="module")
def chain():
    """The bundled chain at the defaults (both residuals on), its document."""
    doc = load_example("chain_catenary").model_dump(mode="json")
    doc["analysis"]["timeseries"] = None
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = analyze(doc)
    return res, json.loads(json.dumps(res.to_document()))


def test_corrected_density_linear_statistics_and_variances_are_the_documents(chain):
    res, doc = chain
    ds = res.to_xarray()
    line = doc["lines"]["leg1"]
    for end in ENDS:
        spec = line["corrected_spectra"][end]
        got = ds["end_tension_corrected_spectrum"].sel(line="leg1", end=end)
        # one line: its grid is the coordinate, every value finite and the document's
        assert np.array_equal(ds["omega_corrected"].values, spec["omega"])
        assert np.array_equal(got.values, spec["tension"])
        # its area is the corrected σ² (corrected_spectrum: to round-off; 1e-9 for
        # the trapezoid's summation order)
        area = np.trapezoid(got.values, ds["omega_corrected"].values)
        std = ds["end_tension_std"].sel(line="leg1", end=end).item()
        assert area == pytest.approx(std**2, rel=1e-9)
        for key in ("mean", "std", "tz", "mpm_3h", "significant", "expected_max"):
            lin = ds[f"linear_end_tension_{key}"].sel(line="leg1", end=end).item()
            assert lin == line["linear"][end]["tension"][key]
        # the corrected σ exceed the linear (the chain: +4 % at the fairlead)
        assert std > ds["linear_end_tension_std"].sel(line="leg1", end=end).item()
        for kind in ("drag_residual", "geometric_residual"):
            v = ds[f"{kind}_variance"].sel(line="leg1", end=end).item()
            assert v == line[kind][end]["variance"]
    assert ds["drag_residual_computed"].sel(line="leg1").item()
    assert ds["end_tension_corrected_spectrum"].attrs["units"] == "N2 s rad-1"
    assert ds["omega_corrected"].attrs["units"] == "rad s-1"


def test_lines_with_other_grids_or_no_residuals_get_nan(chain):
    """Two more lines: one whose corrected grid stops earlier (its own points only,
    NaN beyond), one without residuals (the linear model's numbers: NaN in the
    linear block, 0 variance, not computed)."""
    _, doc = chain
    doc = copy.deepcopy(doc)
    short = copy.deepcopy(doc["lines"]["leg1"])
    for end in ENDS:
        for k in ("omega", "tension"):
            short["corrected_spectra"][end][k] = short["corrected_spectra"][end][k][:-5]
    plain = copy.deepcopy(doc["lines"]["leg1"])
    for key in ("corrected_spectra", "linear"):
        plain.pop(key)
    plain["drag_residual"]["computed"] = False
    for end in ENDS:
        plain["drag_residual"][end]["variance"] = 0.0
    plain.pop("geometric_residual")
    doc["lines"].update(short=short, plain=plain)
    ds = dataset_from_document(doc)
    spec = ds["end_tension_corrected_spectrum"]
    assert np.isnan(spec.sel(line="short").values[:, -5:]).all()
    assert np.array_equal(
        spec.sel(line="short").values[:, :-5], spec.sel(line="leg1").values[:, :-5]
    )
    assert np.isnan(spec.sel(line="plain").values).all()
    assert np.isnan(ds["linear_end_tension_std"].sel(line="plain").values).all()
    assert list(ds["drag_residual_computed"].values) == [True, True, False]
    assert (ds["drag_residual_variance"].sel(line="plain").values == 0.0).all()
    assert np.isnan(ds["geometric_residual_variance"].sel(line="plain").values).all()


def test_netcdf_round_trip_keeps_the_residuals(chain, tmp_path):
    res, _ = chain
    path = res.to_netcdf(tmp_path / "chain.nc")
    with xr.open_dataset(path) as back:
        ds = res.to_xarray()
        for name in ("end_tension_corrected_spectrum", "linear_end_tension_std", "omega_corrected"):
            np.testing.assert_array_equal(back[name].values, ds[name].values)
        assert back["drag_residual_computed"].values.tolist() == [True]


def test_without_residuals_the_dataset_has_none_of_them():
    """Both switches false: the linear model's Dataset, no residual variable."""
    doc = load_example("taut_wire").model_dump(mode="json")
    doc["analysis"]["linearization"].update(drag_residual=False, geometric_residual=False)
    doc["analysis"]["omega"]["count"] = 40
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ds = dataset_from_document(analyze(doc).to_document())
    assert "omega_corrected" not in ds.coords
    assert not [v for v in ds.data_vars if "residual" in v or v.startswith("linear_")]
