"""POST /v1/analyses with rigid bodies (issue 6): the service answers the same document
as the core for a buoy on three legs, refuses a coefficient file (it would be read
from the server's file system) with 422 naming the field, and carries the time series
of a coupled line and of its body (timeseries.bodies)."""

from __future__ import annotations

import json
import warnings

import numpy as np
import pytest
from _compare import assert_close_documents
from fastapi.testclient import TestClient

from service.app import create_app
from service.settings import Settings
from stochcable.analysis import analyze
from stochcable.examples import load_example

# one worker runs the module: its module fixtures run once (--dist loadgroup)
pytestmark = pytest.mark.xdist_group("test_service_bodies")

THREE_LEGS = "tuah_1982_disc_buoy_three_legs"


@pytest.fixture(scope="module")
def client():
    with TestClient(create_app(Settings())) as c:
        yield c


def _plain(doc: dict) -> dict:
    out = json.loads(json.dumps(doc))
    out.pop("timing")
    return out


def test_three_leg_buoy_document_equals_core(client):
    scene = load_example(THREE_LEGS)
    r = client.post("/v1/analyses", json=scene.model_dump(mode="json"))
    assert r.status_code == 200, r.text
    got = _plain(r.json())
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        want = _plain(analyze(scene).to_document())
    assert set(got["bodies"]) == {"disc"}
    # the body's motion densities with the residuals (the default) are in the answer
    spec = got["bodies"]["disc"]["corrected_spectra"]["surge"]
    area = np.trapezoid(spec["motion"], spec["omega"])
    assert area == pytest.approx(got["bodies"]["disc"]["motion"]["surge"]["std"] ** 2, rel=1e-12)
    # the service thread may run BLAS with other threads than the caller: round-off only
    assert_close_documents(got, want)


def test_coefficient_file_refused_with_422(client, tmp_path):
    doc = load_example(THREE_LEGS).model_dump(mode="json")
    doc["bodies"][0]["hydrodynamics"] = {"file": "/etc/passwd.nc"}
    r = client.post("/v1/analyses", json=doc)
    assert r.status_code == 422, r.text
    text = r.text
    assert "bodies[0].hydrodynamics.file" in text
    assert "files are not accepted here" in text


def test_bodies_scene_with_timeseries_document_carries_body_series(client):
    """The disc buoy on one leg with analysis.timeseries: the service document has the
    coupled leg's tensions and the body's motion series (timeseries.bodies.<name>.motion
    per DOF), equal to the core's."""
    doc = load_example("tuah_1982_disc_buoy_single_leg").model_dump(mode="json")
    doc["analysis"]["timeseries"] = {"method": "dsa", "duration": 128.0, "dt": 0.5, "seed": 4}
    r = client.post("/v1/analyses", json=doc)
    assert r.status_code == 200, r.text
    got = _plain(r.json())
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = analyze(doc)
    want = _plain(res.to_document())
    ts = got["timeseries"]
    assert set(ts["lines"]) == {"leg"} and set(ts["bodies"]) == {"disc"}
    motion = ts["bodies"]["disc"]["motion"]
    assert list(motion) == ["surge", "heave", "pitch"]
    assert all(len(v) == ts["window"] == 256 for v in motion.values())
    # the series move about the static pose (not a constant)
    assert np.std(motion["heave"]) > 0.0 and np.std(ts["lines"]["leg"]["end_b"]["tension"]) > 0
    assert not any("time series are not simulated" in m for m in got["warnings"])
    # BLAS threads may differ between the service thread and the caller: round-off
    assert_close_documents(got, want)
