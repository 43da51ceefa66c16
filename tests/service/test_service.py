"""The HTTP service in-process (FastAPI TestClient): answers equal the core's, errors
carry the field path, unit and constraint, encodings agree with each other."""

from __future__ import annotations

import csv
import gzip
import io
import json
import math
import warnings

import numpy as np
import pytest
from fastapi.testclient import TestClient

import stochcable
from service.app import create_app
from service.schemas import default_omega
from service.settings import Settings
from stochcable.errors import ConvergenceError, SolverError
from stochcable.scene.model import PiersonMoskowitz, Spectrum
from stochcable.sea.kinematics import kinematics_timeseries
from stochcable.sea.realization import simulate_sea
from stochcable.sea.spectra import spectrum_statistics

# one worker runs the module: its module fixtures run once (--dist loadgroup)
pytestmark = pytest.mark.xdist_group("test_service")

PM = {"type": "pierson_moskowitz", "hs": 6.0, "tp": 10.0}
SPECTRA = [
    PM,
    {"type": "pierson_moskowitz", "m0": 28.0, "omega_p": 0.5},  # Tuah 1982, §6.5 example
    {"type": "pierson_moskowitz", "wind_speed": 15.0},
    {"type": "jonswap", "hs": 4.0, "tp": 8.0, "gamma": 3.3},
    {"type": "bretschneider", "hs": 3.0, "tp": 9.0},
    {"type": "issc", "hs": 5.0, "t1": 8.0},
    {
        "type": "ochi_hubble",
        "hs1": 2.0,
        "tp1": 14.0,
        "lambda1": 3.0,
        "hs2": 3.0,
        "tp2": 7.0,
        "lambda2": 1.5,
    },
    {"type": "table", "omega": [0.2, 0.5, 0.8, 1.5], "density": [0.0, 2.0, 1.0, 0.0]},
]


@pytest.fixture(scope="module")
def client() -> TestClient:
    with TestClient(create_app(Settings(max_samples=2**16))) as c:
        yield c


def _spectrum_model(doc):
    from pydantic import TypeAdapter

    return TypeAdapter(Spectrum).validate_python(doc)


def _only_error(resp, status=422) -> dict:
    assert resp.status_code == status, resp.text
    detail = resp.json()["detail"]
    assert isinstance(detail, list) and detail
    return detail[0]


# ------------------------------------------------------------------ health/version


def test_health_and_version(client):
    resp = client.get("/health")
    assert resp.json() == {"status": "ok"}
    # the service's own time, for clients telling it from transfer time
    assert resp.headers["server-timing"].startswith("app;dur=")
    assert float(resp.headers["server-timing"].split("dur=")[1]) >= 0.0
    assert client.get("/version").json() == {"stochcable": stochcable.__version__, "api": "v1"}


def test_unknown_route_and_method_use_the_error_shape(client):
    err = _only_error(client.get("/v1/nothing"), 404)
    assert err["type"] == "not_found"
    resp = client.get("/v1/spectra")
    err = _only_error(resp, 405)
    assert err["type"] == "http_error" and "POST" in resp.headers["allow"]


# ------------------------------------------------------------------------- spectra


@pytest.mark.parametrize("doc", SPECTRA, ids=[d["type"] + str(i) for i, d in enumerate(SPECTRA)])
def test_spectrum_equals_the_core(client, doc):
    resp = client.post("/v1/spectra", json={"spectrum": doc})
    assert resp.status_code == 200, resp.text
    data = resp.json()
    model = _spectrum_model(doc)
    omega = default_omega(model)
    density = model.spectral_density(omega)
    # JSON carries float64 by repr, which round-trips exactly: equality, not closeness
    assert data["omega"] == omega.tolist()
    assert data["density"] == density.tolist()
    expected = {
        k: (None if math.isinf(v) else v)
        for k, v in spectrum_statistics(omega, density).as_dict().items()
    }
    assert data["stats"] == expected


def test_pm_default_grid_recovers_hs(client):
    # independent check: Hs = 4 sqrt(m0) of the PM document; the default grid stops at
    # 6 wp and starts at wp/33, losing ~0.05 % of m0 to the tails -> 0.1 % tolerance
    stats = client.post("/v1/spectra", json={"spectrum": PM}).json()["stats"]
    assert stats["hs"] == pytest.approx(6.0, rel=1e-3)
    assert stats["tp"] == pytest.approx(10.0, rel=0.02)  # grid step 0.019 rad/s at wp=0.63


def test_spectrum_on_a_given_grid(client):
    body = {"spectrum": PM, "omega": {"min": 0.1, "max": 3.0, "count": 50}, "g": 9.81}
    data = client.post("/v1/spectra", json=body).json()
    omega = np.linspace(0.1, 3.0, 50)
    assert data["omega"] == omega.tolist()
    assert data["density"] == PiersonMoskowitz(hs=6.0, tp=10.0).spectral_density(omega).tolist()


def test_spectrum_npy_and_csv_equal_json(client):
    body = {"spectrum": SPECTRA[3]}
    js = client.post("/v1/spectra", json=body).json()
    resp = client.post("/v1/spectra", json=body, headers={"Accept": "application/x-npy"})
    assert resp.headers["content-type"] == "application/x-npy"
    rec = np.load(io.BytesIO(resp.content), allow_pickle=False)
    assert rec.dtype.names == ("omega", "density")
    assert rec["density"].tolist() == js["density"]
    assert json.loads(resp.headers["x-stochcable-stats"]) == js["stats"]
    resp = client.post("/v1/spectra", json=body, headers={"Accept": "text/csv"})
    assert resp.headers["content-type"].startswith("text/csv")
    rows = list(csv.reader(io.StringIO(resp.text)))
    assert rows[0] == ["omega", "density"]
    assert [float(r[1]) for r in rows[1:]] == js["density"]  # %.17g round-trips


def test_unsupported_accept_is_406(client):
    err = _only_error(
        client.post("/v1/spectra", json={"spectrum": PM}, headers={"Accept": "image/png"}), 406
    )
    assert "application/x-npy" in err["msg"]


def test_accept_quality_values_pick_the_best(client):
    resp = client.post(
        "/v1/spectra",
        json={"spectrum": PM},
        headers={"Accept": "application/json;q=0.5, text/csv;q=0.9"},
    )
    assert resp.headers["content-type"].startswith("text/csv")


# ---------------------------------------------------------------- validation errors


@pytest.mark.parametrize(
    ("spectrum", "type_", "parameter", "unit"),
    [
        (
            {"type": "pierson_moskowitz", "hs": -6.0, "tp": 10.0},
            "greater_than_equal",
            "spectrum.hs",
            "m",
        ),
        ({"type": "jonswap", "hs": 6.0}, "missing", "spectrum.tp", "s"),
        ({"type": "jonswap", "hs": "big", "tp": 10.0}, "float_parsing", "spectrum.hs", "m"),
        (
            {"type": "jonswap", "hs": 6.0, "tp": 10.0, "gamma": 30},
            "less_than_equal",
            "spectrum.gamma",
            "-",
        ),
        (
            {"type": "bretschneider", "hs": 1.0, "tp": 5.0, "colour": "blue"},
            "extra_forbidden",
            "spectrum.colour",
            None,
        ),
        ({"type": "nope", "hs": 1.0}, "union_tag_invalid", "spectrum", None),
    ],
)
def test_validation_errors_name_path_and_unit(client, spectrum, type_, parameter, unit):
    err = _only_error(client.post("/v1/spectra", json={"spectrum": spectrum}))
    assert err["type"] == type_
    assert err["loc"][0] == "body"
    assert err["parameter"] == parameter
    assert err.get("unit") == unit


def test_nan_is_rejected_with_the_field_path(client):
    body = b'{"spectrum": {"type": "pierson_moskowitz", "hs": NaN, "tp": 10}}'
    err = _only_error(
        client.post("/v1/spectra", content=body, headers={"Content-Type": "application/json"})
    )
    assert err["type"] == "finite_number"
    assert err["parameter"] == "spectrum.hs" and err["unit"] == "m"
    assert "input" not in err  # NaN is not echoed (it is not valid JSON)


def test_malformed_json_is_422(client):
    err = _only_error(
        client.post(
            "/v1/spectra", content=b'{"spectrum": ', headers={"Content-Type": "application/json"}
        )
    )
    assert err["type"] == "json_invalid" and err["loc"][0] == "body"


@pytest.mark.parametrize("path", ["/v1/spectra", "/v1/analyses"])
def test_undecodable_body_is_422_naming_the_body(client, path):
    # issue 19: FastAPI answered an undocumented 400 without a parameter
    json_type = {"Content-Type": "application/json"}
    not_utf8 = b'{"spectrum": {"type": "pierson_moskowitz", "hs": 6, "tp": 10, "x": "\xff"}}'
    err = _only_error(client.post(path, content=not_utf8, headers=json_type))
    assert err == {
        "loc": ["body"],
        "msg": f"the request body is not UTF-8 JSON: byte 0xff at offset {not_utf8.index(0xFF)} "
        "cannot be decoded (invalid start byte); send the JSON document encoded as UTF-8",
        "type": "json_invalid",
        "parameter": "body",
    }
    for deep in (b"[" * 10_000 + b"]" * 10_000, b'{"a":' * 10_000 + b"1" + b"}" * 10_000):
        err = _only_error(client.post(path, content=deep, headers=json_type))
        assert err["type"] == "json_invalid" and err["parameter"] == "body"
        assert err["loc"] == ["body"]
        assert err["msg"].startswith("the request body is JSON nested too deeply to decode")
    # the server is fine afterwards
    assert client.get("/health").status_code == 200


def test_spectrum_out_of_double_precision_names_the_parameter(client):
    # issue 19: these answered 422 numerical_error with loc ["body"] and no parameter
    def post(spectrum, omega=None):
        body = {"spectrum": spectrum} if omega is None else {"spectrum": spectrum, "omega": omega}
        return _only_error(client.post("/v1/spectra", json=body))

    # the JONSWAP peak shape overflowed for a tiny width: refused by its bound
    err = post({"type": "jonswap", "hs": 6.0, "tp": 10.0, "sigma_a": 1e-300})
    assert err["parameter"] == "spectrum.sigma_a" and err["type"] == "greater_than_equal"
    assert err["ctx"] == {"ge": 0.001}
    # a grid far below the peak (omega_p = 4849 rad/s): m0·m4 underflows, 0/0
    err = post({"type": "issc", "hs": 1e4, "t1": 1e-3}, {"min": 1e-3, "max": 1e3, "count": 100})
    assert err["type"] == "input_error" and err["parameter"] == "omega"
    assert err["loc"] == ["body", "omega"] and err["unit"] == "rad/s"
    assert err["msg"].startswith(
        "omega = [0.001, 1000.0] [rad/s]: the spectrum sampled on this grid (min, max; 100 "
        "frequencies) has moments m0…m4 outside double precision (ZeroDivisionError: "
    )
    assert "omega_p = 4849.18 rad/s" in err["msg"] and "omit omega" in err["msg"]
    # a grid far above it: ω⁴·S overflows
    err = post({"type": "pierson_moskowitz", "hs": 6.0, "tp": 10.0}, {"min": 1e-3, "max": 1e300})
    assert err["parameter"] == "omega" and "omega_p = 0.628319 rad/s" in err["msg"]
    # a table density too large for its moments
    err = post({"type": "table", "omega": [0.0, 1.0, 2.0], "density": [1e308] * 3})
    assert err["parameter"] == "spectrum.density" and err["input"] == 1e308
    assert err["loc"] == ["body", "spectrum", "density"]
    assert "overflow double precision" in err["msg"] and "smaller unit" in err["msg"]


def test_pydantic_model_validator_message_is_kept(client):
    err = _only_error(
        client.post("/v1/spectra", json={"spectrum": {"type": "pierson_moskowitz", "hs": 6.0}})
    )
    assert "hs and tp must be given together" in err["msg"]


def test_core_input_error_is_422_with_parameter_and_unit(client):
    body = {"spectrum": {"type": "table", "omega": [0.0, 1.0], "density": [0.0, 0.0]}}
    err = _only_error(client.post("/v1/spectra", json=body))
    assert err["type"] == "input_error"
    assert err["parameter"] == "density" and err["unit"] == "unit²·s/rad"
    assert "must not be zero everywhere" in err["msg"]


def test_solver_errors_map_to_422_with_the_reason():
    app = create_app(Settings())

    @app.get("/converge")
    def converge():
        raise ConvergenceError("drag linearization", 100, 3e-2, 1e-4, hint="raise max_iterations")

    @app.get("/solve")
    def solve():
        raise SolverError("singular stiffness: line end_b is free")

    with TestClient(app) as c:
        err = _only_error(c.get("/converge"))
        assert err["type"] == "convergence_error"
        assert err["solver"] == "drag linearization" and err["iterations"] == 100
        assert "did not converge" in err["msg"] and "raise max_iterations" in err["msg"]
        err = _only_error(c.get("/solve"))
        assert err == {
            "loc": ["body"],
            "msg": "singular stiffness: line end_b is free",
            "type": "solver_error",
        }


# ------------------------------------------------------------------------------ sea


def _realization_body(**kw):
    body = {"spectrum": PM, "duration": 256.0, "dt": 0.5, "method": "dsa", "seed": 7}
    body.update(kw)
    return body


def _local(body):
    spec = _spectrum_model(body["spectrum"])
    return simulate_sea(
        lambda w: spec.spectral_density(w),
        body["duration"],
        body["dt"],
        method=body.get("method", "dsa"),
        rng=body["seed"],
    )


@pytest.mark.parametrize("method", ["dsa", "nsa"])
def test_realization_equals_the_core(client, method):
    body = _realization_body(method=method)
    data = client.post("/v1/sea/realizations", json=body).json()
    sea = _local(body)
    assert data["time"] == sea.time.tolist()
    assert data["elevation"] == sea.elevation.tolist()
    # mean square of the record = sum a_m^2/2 (Parseval), to rounding of 512 terms
    assert data["stats"]["variance"] == pytest.approx(sea.variance_grid, rel=1e-12)
    assert "kinematics" not in data or data["kinematics"] is None


def test_dsa_variance_equals_the_target_m0(client):
    # DSA: sum a_m^2/2 = sum S(w_m) dw exactly (DESIGN.md); rounding of 256 terms only
    stats = client.post("/v1/sea/realizations", json=_realization_body()).json()["stats"]
    assert stats["variance"] == pytest.approx(stats["m0"], rel=1e-12)
    # and the elevation's own mean square (independent of the core's bookkeeping)
    data = client.post("/v1/sea/realizations", json=_realization_body()).json()
    assert np.mean(np.square(data["elevation"])) == pytest.approx(stats["m0"], rel=1e-12)


def test_single_column_npy_is_the_elevation(client):
    body = _realization_body(method="nsa")
    resp = client.post("/v1/sea/realizations", json=body, headers={"Accept": "application/x-npy"})
    rec = np.load(io.BytesIO(resp.content), allow_pickle=False)
    sea = _local(body)
    assert rec.dtype.names == ("elevation",) and np.array_equal(rec["elevation"], sea.elevation)
    # m0 is the Riemann sum of S over the simulated lines m = 1 … N-1 (independent
    # evaluation here; the service reuses the simulation's own S values)
    spec = _spectrum_model(PM)
    m0 = spec.spectral_density(sea.omega[1:-1]).sum() * sea.d_omega
    assert json.loads(resp.headers["x-stochcable-stats"])["m0"] == pytest.approx(m0, rel=1e-15)


def test_realization_kinematics_equal_the_core(client):
    points = [[0.0, 0.0, -5.0], [10.0, 3.0, -20.0], [0.0, 0.0, 1.0]]
    body = _realization_body(points=points, heading=30.0, depth=50.0, g=9.81)
    data = client.post("/v1/sea/realizations", json=body).json()
    spec = _spectrum_model(PM)
    sea = simulate_sea(lambda w: spec.spectral_density(w, 9.81), 256.0, 0.5, rng=7)
    vel, acc = kinematics_timeseries(sea, np.array(points), math.radians(30.0), 50.0, 9.81)
    assert np.array_equal(np.asarray(data["kinematics"]["velocity"]), vel)
    assert np.array_equal(np.asarray(data["kinematics"]["acceleration"]), acc)
    # a point above the still-water level has zero kinematics (DESIGN.md)
    assert not np.asarray(data["kinematics"]["velocity"])[2].any()


def test_realization_npy_and_csv_layouts(client):
    body = _realization_body(points=[[0.0, 0.0, -5.0], [5.0, 0.0, -10.0]])
    js = client.post("/v1/sea/realizations", json=body).json()
    resp = client.post("/v1/sea/realizations", json=body, headers={"Accept": "application/x-npy"})
    rec = np.load(io.BytesIO(resp.content), allow_pickle=False)
    names = ["elevation"] + [
        f"{q}_{p}_{a}" for q in ("velocity", "acceleration") for p in range(2) for a in "xyz"
    ]
    assert list(rec.dtype.names) == names  # NPY: no time column, t_n = n·dt
    assert (np.arange(rec.size) * body["dt"]).tolist() == js["time"]
    assert rec["elevation"].tolist() == js["elevation"]
    assert rec["acceleration_1_z"].tolist() == js["kinematics"]["acceleration"][1][2]
    assert json.loads(resp.headers["x-stochcable-stats"]) == js["stats"]
    resp = client.post("/v1/sea/realizations", json=body, headers={"Accept": "text/csv"})
    rows = list(csv.reader(io.StringIO(resp.text)))
    assert rows[0] == ["time", *names] and len(rows) == 1 + 512
    assert [float(r[3]) for r in rows[1:]] == js["kinematics"]["velocity"][0][1]


def test_odd_sample_count_is_an_input_error(client):
    err = _only_error(client.post("/v1/sea/realizations", json=_realization_body(duration=100.5)))
    assert err["type"] == "input_error" and err["parameter"] == "duration"
    assert "even integer" in err["msg"] and err["unit"] == "s"


def test_realization_request_bounds(client):
    err = _only_error(client.post("/v1/sea/realizations", json=_realization_body(method="x")))
    assert err["parameter"] == "method"
    err = _only_error(
        client.post("/v1/sea/realizations", json=_realization_body(points=[[0.0, 0.0]]))
    )
    assert err["parameter"].startswith("points[0]")
    err = _only_error(client.post("/v1/sea/realizations", json=_realization_body(depth=-1)))
    assert err["parameter"] == "depth" and err["unit"] == "m"


def test_large_json_is_gzipped_but_npy_is_not(client):
    body = _realization_body(duration=4096.0)
    resp = client.post("/v1/sea/realizations", json=body, headers={"Accept-Encoding": "gzip"})
    assert resp.headers.get("content-encoding") == "gzip"
    assert len(resp.json()["elevation"]) == 8192  # httpx decoded it
    resp = client.post(
        "/v1/sea/realizations",
        json=body,
        headers={"Accept-Encoding": "gzip", "Accept": "application/x-npy"},
    )
    assert "content-encoding" not in resp.headers
    # sanity of the fixture: gzip really is what the header says
    assert gzip.decompress(gzip.compress(b"x")) == b"x"


# ------------------------------------------------------------------------- examples


def _examples_module():
    examples = pytest.importorskip("stochcable.examples")
    if not hasattr(examples, "list_examples"):
        pytest.skip("stochcable.examples.list_examples not written yet")
    return examples


def test_examples_list_and_documents(client):
    examples = _examples_module()
    listed = client.get("/v1/examples").json()
    assert [e["name"] for e in listed] == examples.list_examples()
    for entry in listed:
        doc = client.get(f"/v1/examples/{entry['name']}").json()
        scene = examples.load_example(entry["name"])
        assert doc == scene.model_dump(mode="json")
        assert entry["title"] == scene.title


def test_unknown_example_is_404_listing_the_names(client):
    examples = _examples_module()
    err = _only_error(client.get("/v1/examples/no-such-scene"), 404)
    assert err["type"] == "not_found" and err["loc"] == ["path", "name"]
    for name in examples.list_examples():
        assert name in err["msg"]


def test_mean_square_matches_the_direct_sum():
    # the realization's "variance" stat: chunked sum of squares (no BLAS, no temporary)
    # against np.mean(x²), over several chunks and a partial last one; both sum the same
    # squares in different orders -> round-off only (1e-13 relative)
    from service.routers.sea import _SQUARE_CHUNK, _mean_square

    x = np.random.default_rng(3).standard_normal(2 * _SQUARE_CHUNK + 123)
    assert _mean_square(x) == pytest.approx(np.mean(x * x), rel=1e-13)
    assert math.isnan(_mean_square(np.array([1.0, np.nan])))


def test_columns_response_checks_the_columns_not_declared_finite():
    from service.encoding import NPY, columns_response
    from service.errors import NumericalError

    good, bad = np.ones(4), np.array([0.0, np.inf, 1.0, 2.0])
    with pytest.raises(NumericalError, match="non-finite"):
        columns_response({"elevation": good, "velocity_0_x": bad}, NPY)
    # declaring one column finite skips only that column's check
    with pytest.raises(NumericalError, match="non-finite"):
        columns_response({"elevation": good, "velocity_0_x": bad}, NPY, finite=("elevation",))
    resp = columns_response({"elevation": good}, NPY, finite=("elevation",))
    assert int(resp.headers["content-length"]) > 4 * 8


@pytest.mark.parametrize("bad", [math.nan, math.inf, -math.inf])
@pytest.mark.parametrize("where", ["scalar", "list", "nested", "mixed"])
def test_dumps_refuses_non_finite_anywhere_in_a_document(bad, where):
    """orjson would write NaN/inf as null: the service's encoder refuses them instead,
    wherever they sit (a scalar, a float list, a list of lists, a list with None)."""
    from service.encoding import dumps
    from service.errors import NumericalError

    docs = {
        "scalar": {"a": {"b": bad}},
        "list": {"a": [1.0, 2.0, bad]},
        "nested": {"a": [[1.0, 2.0], [3.0, bad]]},
        "mixed": {"a": [None, "x", 1, bad]},
    }
    with pytest.raises(NumericalError, match="non-finite"):
        dumps(docs[where])


def test_dumps_equals_the_standard_encoder_after_parsing():
    """orjson text parses to the same document as json.dumps' (shortest round-trip
    floats both): the result document of the chain example, time series included; and
    finite sums that overflow (1e308 + 1e308) take the element-wise path, not an error."""
    import json

    from service.encoding import dumps
    from stochcable.analysis import analyze
    from stochcable.examples import load_example

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        doc = analyze(load_example("chain_catenary")).to_document(timeseries="window")
    assert json.loads(dumps(doc)) == json.loads(json.dumps(doc, allow_nan=False))
    assert json.loads(dumps({"x": [1e308, 1e308]})) == {"x": [1e308, 1e308]}


def test_realization_of_a_vanishing_spectrum_names_the_spectrum(client):
    # JONSWAP with Tp = 1 ms: S underflows to 0 on every frequency of the record's grid
    body = {"spectrum": {"type": "jonswap", "hs": 1.0, "tp": 1e-3}, "duration": 64, "dt": 0.25}
    err = _only_error(client.post("/v1/sea/realizations", json=body))
    assert err["type"] == "input_error" and err["parameter"] == "spectrum"
    assert err["loc"] == ["body", "spectrum"] and "is zero at every grid frequency" in err["msg"]


def test_a_bug_answers_json_500():
    app = create_app(Settings())

    @app.get("/bug")
    def bug() -> dict:
        raise KeyError("a programming error")

    with TestClient(app, raise_server_exceptions=False) as c:
        resp = c.get("/bug")
    assert resp.status_code == 500 and resp.headers["content-type"] == "application/json"
    err = resp.json()["detail"][0]
    assert err["type"] == "internal_error" and "KeyError" in err["msg"]
