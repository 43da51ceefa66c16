"""POST /v1/analyses answers NetCDF on ``Accept: application/x-netcdf``: the Dataset of
the same analysis, the numbers of the JSON answer."""

from __future__ import annotations

import numpy as np
import pytest
from fastapi.testclient import TestClient

from service.app import create_app
from service.settings import Settings
from stochcable.examples import load_example
from stochcable.results.datasets import dataset_from_document

# one worker runs the module: its module fixtures run once (--dist loadgroup)
pytestmark = pytest.mark.xdist_group("test_service_netcdf")


@pytest.fixture(scope="module")
def client():
    with TestClient(create_app(Settings(analysis_workers=1))) as c:
        yield c


def test_netcdf_answer_carries_the_json_numbers(client, tmp_path):
    import xarray as xr

    doc = load_example("chain_catenary").model_dump(mode="json", exclude_unset=True)
    as_json = client.post("/v1/analyses", json=doc)
    as_nc = client.post("/v1/analyses", json=doc, headers={"Accept": "application/x-netcdf"})
    assert as_nc.status_code == 200, as_nc.text
    assert as_nc.headers["content-type"] == "application/x-netcdf"
    assert as_nc.headers["x-stochcable-warnings"] == as_json.headers["x-stochcable-warnings"]
    path = tmp_path / "result.nc"
    path.write_bytes(as_nc.content)
    ds = xr.load_dataset(path)
    ref = dataset_from_document(as_json.json())
    compared = 0
    for name in ref.data_vars:
        # the document's time series is its 2048-sample window, the file's all of it
        if (
            name in ds
            and np.issubdtype(ref[name].dtype, np.floating)
            and "time" not in ref[name].dims
        ):
            # the same analysis in two worker runs: equal to round-off of the solves
            np.testing.assert_allclose(ds[name].values, ref[name].values, rtol=1e-10)
            compared += 1
    assert compared >= 10, sorted(ref.data_vars)
    # the default answer's residuals: the corrected densities on their own grid, the
    # linear model's statistics, each residual's variance
    residuals = {
        "end_tension_corrected_spectrum",
        "linear_end_tension_std",
        "drag_residual_variance",
    }
    assert residuals <= set(ds.data_vars) and "omega_corrected" in ds.coords


def test_unsupported_accept_is_406(client):
    doc = load_example("taut_wire").model_dump(mode="json", exclude_unset=True)
    resp = client.post("/v1/analyses", json=doc, headers={"Accept": "text/csv"})
    assert resp.status_code == 406
    assert "application/x-netcdf" in resp.text
