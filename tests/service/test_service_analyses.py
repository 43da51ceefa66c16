"""POST /v1/analyses through the app (FastAPI TestClient; the analyses run in the app's
worker processes): the result document equals the core's analyze(scene).to_document()
and the CLI's output, every published OpenAPI example answers 200, the limits answer
413/422 naming the bound, solver failures answer 422 with the reason, and concurrent
analyses keep their own warnings.  The run limit and worker failures:
tests/service/test_service_workers.py and tests/service/."""

from __future__ import annotations

import copy
import json
import threading
import warnings

import numpy as np
import pytest
from _compare import assert_close_documents
from fastapi.testclient import TestClient
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from service.app import create_app
from service.routers.analyses import WARNINGS_HEADER
from service.schemas import AnalysisResponse
from service.settings import Settings
from stochcable.analysis import analyze
from stochcable.cli import main as cli_main
from stochcable.examples import list_examples, load_example

# one worker runs the module: its module fixtures run once (--dist loadgroup)
pytestmark = pytest.mark.xdist_group("test_service_analyses")

CHAIN = "chain_catenary"  # the README / banner example: sea + end motion, time series
SMALL = "tuah_1982_single_leg"  # 3 elements, time series, ~20 ms: for the limit tests


def _doc(name: str) -> dict:
    return load_example(name).model_dump(mode="json")


def _plain(doc: dict) -> dict:
    """The document as JSON gives it back, without the (run-dependent) timing."""
    out = json.loads(json.dumps(doc))
    out.pop("timing")
    return out


def _err(resp, status=422) -> dict:
    assert resp.status_code == status, resp.text
    return resp.json()["detail"][0]


@pytest.fixture(scope="module")
def client() -> TestClient:
    with TestClient(create_app(Settings())) as c:
        yield c


@pytest.fixture(scope="module")
def small() -> TestClient:
    limits = Settings(max_elements=3, max_frequencies=200, max_samples=1024, max_body_bytes=4096)
    with TestClient(create_app(limits)) as c:
        yield c


@pytest.fixture(scope="module")
def chain_answer(client):
    """GET the example, POST it back: the pipeline the start-up message shows."""
    scene = client.get(f"/v1/examples/{CHAIN}").json()
    return client.post("/v1/analyses", json=scene)


# ------------------------------------------------------------------ equality


def test_example_pipeline_equals_the_core_and_the_cli(chain_answer, tmp_path):
    assert chain_answer.status_code == 200, chain_answer.text
    doc = chain_answer.json()
    local = analyze(load_example(CHAIN)).to_document()
    # the same computation on the same input (in a worker thread): equal to
    # round-off, timing aside (tests/_compare.py says why not to the last bit)
    assert_close_documents(_plain(doc), _plain(local))
    assert set(doc["timing"]) == set(local["timing"])
    out = tmp_path / "result.json"
    path = tmp_path / "scene.json"
    path.write_text(json.dumps(_doc(CHAIN)), encoding="utf-8")
    assert cli_main(["analyze", str(path), "--format", "json", "-o", str(out)]) == 0
    assert_close_documents(_plain(doc), _plain(json.loads(out.read_text(encoding="utf-8"))))


@pytest.mark.parametrize("name", [n for n in list_examples() if n != CHAIN])
def test_every_example_equals_the_core(client, name):
    resp = client.post("/v1/analyses", json=_doc(name))
    assert resp.status_code == 200, resp.text
    assert_close_documents(_plain(resp.json()), _plain(analyze(load_example(name)).to_document()))


def test_document_conforms_to_the_response_model(chain_answer):
    doc = chain_answer.json()
    model = AnalysisResponse.model_validate(doc)
    # the v1 contract keys (DESIGN.md "Scene and result documents")
    assert model.lines["leg1"].end_b.tension.std > 0
    assert model.statics.lines["leg1"]["end_b"]["tension"] > 0
    assert set(doc) >= {
        "statics",
        "modes",
        "linearization",
        "lines",
        "timing",
        "warnings",
        "timeseries",
    }


def test_the_default_answer_carries_the_residuals_and_the_linear_model(chain_answer):
    """The chain at the defaults (both residuals on): the response model reads the
    residual records, the linear block and the corrected densities as typed parts,
    whose area is the corrected σ² the end statistics carry (1e-9: the trapezoid's
    summation order), above the linear model's σ."""
    model = AnalysisResponse.model_validate(chain_answer.json())
    line = model.lines["leg1"]
    assert line.drag_residual.computed and line.geometric_residual.computed
    for end in ("end_a", "end_b"):
        spec = line.corrected_spectra[end]
        std = getattr(line, end).tension.std
        assert np.trapezoid(spec.tension, spec.omega) == pytest.approx(std**2, rel=1e-9)
        assert line.linear[end].tension.std < std
        assert getattr(line.drag_residual, end).variance > 0
    schemas = AnalysisResponse.model_json_schema()["$defs"]
    props = schemas["LineDocument"]["properties"]
    assert {"linear", "corrected_spectra", "drag_residual", "geometric_residual"} <= set(props)


@pytest.mark.slow
def test_residuals_of_the_linear_model_through_http(client):
    """The chain example with both residuals asked for: the service answers the core's
    residual records (the closed forms are deterministic: round-off only) and the
    response model accepts them."""
    doc = _doc(CHAIN)
    doc["analysis"].pop("timeseries", None)
    doc["analysis"]["linearization"].update(drag_residual=True, geometric_residual=True)
    resp = client.post("/v1/analyses", json=doc)
    assert resp.status_code == 200, resp.text
    got = resp.json()["lines"]["leg1"]
    AnalysisResponse.model_validate(resp.json())
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        want = analyze(doc).lines["leg1"].to_document()
    for key in ("drag_residual", "geometric_residual"):
        assert got[key]["computed"] is True
        assert_close_documents(got[key], want[key])
        assert got[key]["end_b"]["ratio"] > 1.0


def test_warnings_are_listed_and_counted_in_a_header(chain_answer, client):
    # the seed's slack leg warns of snap loads (and of its coarse mesh)
    loud = client.post("/v1/analyses", json=_doc("tuah_1982_single_leg"))
    doc = loud.json()
    assert any("snap loads likely" in w for w in doc["warnings"])
    assert loud.headers[WARNINGS_HEADER] == str(len(doc["warnings"])) != "0"
    # the chain example runs clean
    assert chain_answer.json()["warnings"] == []
    assert chain_answer.headers[WARNINGS_HEADER] == "0"


def test_large_document_is_gzipped(chain_answer):
    assert chain_answer.headers.get("content-encoding") == "gzip"  # TestClient accepts gzip


@pytest.mark.parametrize("mode", ["full", "none"])
def test_timeseries_query_parameter(small, mode):
    scene = _doc(SMALL)
    doc = small.post(f"/v1/analyses?timeseries={mode}", json=scene).json()
    local = analyze(load_example(SMALL)).to_document(timeseries=mode)
    assert _plain(doc) == _plain(local)
    if mode == "none":
        assert "timeseries" not in doc
    else:  # 256 s at 0.25 s: all 1024 samples (the window would be min(1024, 2048) too)
        assert doc["timeseries"]["window"] == doc["timeseries"]["samples"] == 1024


def test_bad_timeseries_parameter_names_it(small):
    err = _err(small.post("/v1/analyses?timeseries=all", json=_doc(SMALL)))
    assert err["loc"] == ["query", "timeseries"] and err["parameter"] == "timeseries"
    assert "'window', 'full' or 'none'" in err["msg"]


# -------------------------------------------------------------------- limits


def test_element_limit_names_the_bound(small):
    scene = _doc(SMALL)
    assert small.post("/v1/analyses", json=scene).status_code == 200  # 3 = the bound
    scene["lines"][0]["segments"][0]["elements"] = 4
    err = _err(small.post("/v1/analyses", json=scene))
    assert err["type"] == "limit_exceeded" and err["setting"] == "STOCHCABLE_MAX_ELEMENTS"
    assert err["msg"] == "4 finite elements exceeds the limit of 3 (STOCHCABLE_MAX_ELEMENTS)"
    assert err["loc"] == ["body", "lines"]


def test_frequency_limit_names_the_bound(small):
    scene = _doc(SMALL)
    scene["analysis"]["omega"]["count"] = 201
    err = _err(small.post("/v1/analyses", json=scene))
    assert err["msg"] == (
        "analysis.omega.count = 201 frequencies exceeds the limit of 200 "
        "(STOCHCABLE_MAX_FREQUENCIES)"
    )
    assert err["loc"] == ["body", "analysis", "omega", "count"] and err["limit"] == 200


def test_sample_limit_names_the_bound(small):
    scene = _doc(SMALL)
    scene["analysis"]["timeseries"]["duration"] = 512.0  # 2048 samples at 0.25 s
    err = _err(small.post("/v1/analyses", json=scene))
    assert err["msg"] == (
        "analysis.timeseries duration/dt = 2048 samples exceeds the limit "
        "of 1024 (STOCHCABLE_MAX_SAMPLES)"
    )
    assert err["loc"] == ["body", "analysis", "timeseries", "duration"]


def test_body_limit_is_413(small):
    body = json.dumps(_doc(SMALL)) + " " * 4096
    resp = small.post("/v1/analyses", content=body, headers={"Content-Type": "application/json"})
    err = _err(resp, 413)
    assert "exceeds the limit of 4096 bytes (STOCHCABLE_MAX_BODY_BYTES)" in err["msg"]


# ------------------------------------------------------------- solver failures


def test_unconverged_linearization_is_422_with_the_reason(small):
    # CPU-independent by a wide margin: the first iteration's relative change is 0.81
    # (measured), 80 times the example's tolerance 1e-2
    scene = _doc(SMALL)
    scene["analysis"]["linearization"]["max_iterations"] = 1
    err = _err(small.post("/v1/analyses", json=scene))
    assert err["type"] == "convergence_error" and err["iterations"] == 1
    assert err["solver"] == "drag linearization of line 'leg'"
    assert "did not converge" in err["msg"] and "max_iterations" in err["msg"]
    # allow_unconverged: the flagged partial result instead (DESIGN.md)
    scene["analysis"]["linearization"]["allow_unconverged"] = True
    doc = small.post("/v1/analyses", json=scene).json()
    assert doc["linearization"]["converged"] is False
    assert doc["linearization"]["iterations"] == 1


def test_core_input_error_is_422_with_the_path(small):
    scene = _doc(SMALL)
    scene["analysis"]["linearization"]["method"] = "harmonic"
    scene["environment"]["current"] = [{"z": 0.0, "speed": 1.0, "heading": 0.0}]
    err = _err(small.post("/v1/analyses", json=scene))
    assert err["type"] == "input_error"
    assert err["loc"] == ["body", "analysis", "linearization", "method"]
    assert "no current term" in err["msg"]


def test_validation_error_names_the_field_path_and_unit(small):
    # SMALL is in feet (g = 32.174 ft/s²): the unit is given in its system
    scene = _doc(SMALL)
    scene["lines"][0]["segments"][0]["ea"] = -1.0
    err = _err(small.post("/v1/analyses", json=scene))
    assert err["parameter"] == "lines[0].segments[0].ea" and err["unit"] == "lbf"
    assert err["msg"] == "Input should be greater than 0"
    scene = _doc(CHAIN)  # SI
    scene["lines"][0]["segments"][0]["ea"] = -1.0
    err = _err(small.post("/v1/analyses", json=scene))
    assert err["parameter"] == "lines[0].segments[0].ea" and err["unit"] == "N"


def test_anchor_above_the_water_is_422_naming_the_field(small):
    # issue 19: a scene-level check named no field
    for name, unit in ((SMALL, "ft"), (CHAIN, "m")):
        scene = _doc(name)
        scene["lines"][0]["end_a"]["position"][2] = 30.0
        err = _err(small.post("/v1/analyses", json=scene))
        assert err["loc"] == ["body", "lines", 0, "end_a", "position"]
        assert err["parameter"] == "lines[0].end_a.position" and err["unit"] == unit
        assert (
            "z = 30.0 is above the still-water level: the anchor end (end_a) must have "
            in (err["msg"])
        )


# -------------------------------------------------------- run time, concurrency


def test_concurrent_analyses_keep_their_own_warnings(client):
    # analyze() records warnings with warnings.catch_warnings (process-global state):
    # each analysis runs alone in its worker process, so overlapping requests neither
    # swap their warnings nor alter the HTTP process's warning filters
    filters = list(warnings.filters)
    names = ["tuah_1982_suspended_cable", "taut_wire", "tuah_1982_suspended_cable", "taut_wire"]
    out: dict[int, object] = {}

    def post(i: int) -> None:
        out[i] = client.post("/v1/analyses", json=_doc(names[i]))

    threads = [threading.Thread(target=post, args=(i,)) for i in range(len(names))]
    for t in threads:
        t.start()
    for t in threads:
        t.join(30.0)
    for i, name in enumerate(names):
        got = out[i].json()["warnings"]
        if name == "taut_wire":  # the element check's (examples.DOCUMENTED_WARNINGS)
            assert len(got) == 1 and "error of the end-tension σ" in got[0]
        else:
            assert len(got) == 1 and "has no excitation" in got[0]
    assert warnings.filters == filters


def test_every_published_openapi_example_answers_200(client):
    # the "Try it out" examples of POST /v1/analyses in the served OpenAPI document
    doc = client.get("/openapi.json").json()
    body = doc["paths"]["/v1/analyses"]["post"]["requestBody"]["content"]["application/json"]
    examples = body["examples"]
    assert set(examples) == set(list_examples())
    for name, example in examples.items():
        resp = client.post("/v1/analyses?timeseries=none", json=example["value"])
        assert resp.status_code == 200, (name, resp.text)


def test_spectrum_type_is_required_in_the_schema(client):
    # the union of spectra is discriminated by type: a document without it is refused,
    # so the schema says so
    schemas = client.get("/openapi.json").json()["components"]["schemas"]
    for name in ("PiersonMoskowitz", "Jonswap", "TableSpectrum"):
        assert "type" in schemas[name]["required"], name


# ----------------------------------------------- generated scenes never fail 5xx


@st.composite
def _perturbed_scenes(draw):
    """Example scenes with perturbed properties: reach statics and the solver (the
    schemathesis scenes almost never do), all within the small test limits."""
    name = draw(st.sampled_from(["taut_wire", "tuah_1982_single_leg", "inclined_guy"]))
    doc = copy.deepcopy(_doc(name))
    line = doc["lines"][0]
    seg = line["segments"][0]
    factor = st.floats(0.05, 20.0)
    seg["ea"] *= draw(factor)
    seg["mass"] *= draw(factor)
    seg["diameter"] *= draw(factor)
    seg["elements"] = draw(st.integers(1, 30))
    seg["cd_normal"] = draw(st.floats(0.0, 3.0))
    line["end_b"]["position"][1] = draw(st.sampled_from([0.0, 15.0]))
    doc["environment"]["current"] = [
        {"z": 0.0, "speed": draw(st.floats(0.0, 2.0)), "heading": draw(st.floats(-180.0, 180.0))}
    ]
    hs = draw(st.floats(0.1, 15.0))
    doc["sea"] = {
        "spectrum": {"type": "jonswap", "hs": hs, "tp": draw(st.floats(3.0, 20.0))},
        "heading": draw(st.floats(-180.0, 180.0)),
    }
    a = doc["analysis"]
    a["omega"] = {
        "min": draw(st.floats(0.01, 0.5)),
        "max": draw(st.floats(0.6, 6.0)),
        "count": draw(st.integers(2, 120)),
        "spacing": draw(st.sampled_from(["linear", "log"])),
    }
    a["solver"] = draw(st.sampled_from(["foss", "direct"]))
    a["modes"] = draw(st.sampled_from(["auto", 1, 5]))
    a["linearization"]["method"] = draw(st.sampled_from(["seed", "vector"]))
    a["linearization"]["allow_unconverged"] = draw(st.booleans())
    return doc


_GENERATED_APP = create_app(Settings(max_run_seconds=10.0))


@pytest.mark.slow
@settings(
    max_examples=8,
    deadline=None,
    derandomize=True,
    database=None,
    suppress_health_check=list(HealthCheck),
)
@given(scene=_perturbed_scenes())
def test_generated_scenes_answer_a_document_or_a_reason(scene):
    with TestClient(_GENERATED_APP, raise_server_exceptions=False) as c:
        resp = c.post("/v1/analyses", json=scene)
    assert resp.status_code in (200, 422), resp.text
    if resp.status_code == 200:
        AnalysisResponse.model_validate(resp.json())
    else:
        assert resp.json()["detail"][0]["type"] in (
            "input_error",
            "convergence_error",
            "solver_error",
            "value_error",
        )
