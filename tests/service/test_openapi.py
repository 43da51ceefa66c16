"""The committed openapi/openapi.json is the app's document (drift test), with stable
operation ids and a unit on every numeric field."""

from __future__ import annotations

import json

import pytest

from service.openapi import DEFAULT_PATH, REGENERATE_COMMAND, main, openapi_document, render

OPERATIONS = {
    ("get", "/health"): "get_health",
    ("get", "/version"): "get_version",
    ("post", "/v1/spectra"): "compute_spectrum",
    ("post", "/v1/sea/realizations"): "simulate_sea",
    ("get", "/v1/examples"): "list_examples",
    ("get", "/v1/examples/{name}"): "get_example",
    ("post", "/v1/analyses"): "run_analysis",
}


def test_committed_document_matches_the_app():
    assert DEFAULT_PATH.exists(), f"{DEFAULT_PATH} is missing; run: {REGENERATE_COMMAND}"
    committed = json.loads(DEFAULT_PATH.read_text(encoding="utf-8"))
    current = openapi_document()
    assert committed == current, (
        f"{DEFAULT_PATH} differs from the app's OpenAPI document; regenerate it with "
        f"`{REGENERATE_COMMAND}` and commit the result"
    )


@pytest.mark.slow
def test_check_mode_detects_drift(tmp_path, capsys):
    out = tmp_path / "openapi.json"
    out.write_text(render(openapi_document()), encoding="utf-8")
    assert main(["--output", str(out), "--check"]) == 0
    out.write_text("{}\n", encoding="utf-8")
    assert main(["--output", str(out), "--check"]) == 1
    assert REGENERATE_COMMAND in capsys.readouterr().err


def test_operation_ids_are_stable():
    doc = openapi_document()
    found = {
        (m, p): op["operationId"] for p, item in doc["paths"].items() for m, op in item.items()
    }
    for key, op_id in OPERATIONS.items():
        assert found.get(key) == op_id, key


def _numeric(prop: dict) -> bool:
    kinds = [prop.get("type")] + [a.get("type") for a in prop.get("anyOf", [])]
    if prop.get("type") == "array":
        kinds.append(prop.get("items", {}).get("type"))
    return any(k in ("number", "integer") for k in kinds)


def test_every_numeric_field_states_its_unit():
    doc = openapi_document()
    missing = []
    for name, schema in doc["components"]["schemas"].items():
        for field, prop in schema.get("properties", {}).items():
            if _numeric(prop) and "[" not in prop.get("description", ""):
                missing.append(f"{name}.{field}")
    # integer identifiers without a physical unit, error locations, and the scene's
    # ComplexTable whose unit depends on where it is used (stochcable/scene.py)
    allowed = {
        "TimeSeriesSettings.seed",
        "RealizationRequest.seed",
        "AnalysisSettings.modes",
        "TimeSeriesDocument.seed",
        "ErrorItem.loc",
        "ValidationError.loc",
        "ComplexTable.re",
        "ComplexTable.im",
    }
    assert sorted(set(missing) - allowed) == []


def test_error_answers_are_documented():
    doc = openapi_document()
    post = doc["paths"]["/v1/sea/realizations"]["post"]["responses"]
    for code in ("200", "406", "413", "422", "504"):
        assert code in post
    assert post["422"]["content"]["application/json"]["schema"]["$ref"].endswith("ErrorResponse")
    assert "application/x-npy" in post["200"]["content"]


def test_analyses_are_documented_with_the_scene_and_the_result_models():
    doc = openapi_document()
    post = doc["paths"]["/v1/analyses"]["post"]
    body = post["requestBody"]["content"]["application/json"]
    assert body["schema"]["$ref"].endswith("/Scene")  # the core's model, not a copy
    assert "chain_catenary" in body["examples"]  # "Try it out" in /docs runs an example
    ok = post["responses"]["200"]
    assert ok["content"]["application/json"]["schema"]["$ref"].endswith("AnalysisResponse")
    assert "X-Stochcable-Warnings" in ok["headers"]
    for code in ("413", "422", "504"):
        assert post["responses"][code]["content"]["application/json"]["schema"]["$ref"].endswith(
            "ErrorResponse"
        )
    params = {p["name"]: p for p in post["parameters"]}
    assert params["timeseries"]["schema"]["enum"] == ["window", "full", "none"]
    result = doc["components"]["schemas"]["AnalysisResponse"]
    assert set(result["required"]) == {
        "statics",
        "modes",
        "linearization",
        "lines",
        "timing",
        "warnings",
    }
