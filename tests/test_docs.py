"""The manual's generated references cover what the code has.

The generators live in ``docs/_ext`` and run when the manual is built (``.ci/run``:
``sphinx-build -W``); these tests check their coverage without Sphinx: every field of
every scene model in the scene reference with its unit and default, every key of the
result document described, every warning call site described, every HTTP operation
and settings variable rendered.
"""

from __future__ import annotations

import json
import re
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "docs" / "_ext"))

import openapi_reference
import results_reference
import scene_reference
import warnings_reference

from stochcable.scene.model import scene_json_schema


@pytest.fixture(scope="module")
def schema():
    return scene_json_schema()


def _section(text: str, model: str) -> str:
    """The part of the generated reference that documents ``model``."""
    start = text.index(f".. _scene-{model.lower()}:")
    end = text.find("\n.. _scene-", start + 1)
    return text[start : end if end > 0 else len(text)]


def test_scene_reference_has_every_model_and_field(schema):
    text = scene_reference.scene_reference_rst(schema)
    models = {"Scene": schema, **schema["$defs"]}
    assert set(scene_reference.model_order(schema)) == set(models)
    for model, spec in models.items():
        part = _section(text, model)
        for name, node in spec.get("properties", {}).items():
            row = re.search(rf"   \* - ``{re.escape(name)}``\n((?:     - .*\n)+)", part)
            assert row, f"{model}.{name} has no row in the scene reference"
            cells = [c[len("     - ") :] for c in row.group(1).splitlines()]
            _, unit, unit_fss, default, _, meaning = cells[:6]
            if "unit" in node:
                assert unit == node["unit"], f"{model}.{name}: unit {unit!r}"
                assert unit_fss == scene_reference.foot_slug_second(node["unit"])
            if name in spec.get("required", ()):
                assert default == "required"
            elif "default" in node:
                assert json.dumps(node["default"], ensure_ascii=False) in default
            if node.get("description"):
                assert meaning != "—", f"{model}.{name} lost its description"


def test_scene_reference_constraints_are_the_schema_s(schema):
    rows = scene_reference.field_rows(schema, "Jonswap")
    gamma = next(r for r in rows if r["field"] == "``gamma``")
    node = schema["$defs"]["Jonswap"]["properties"]["gamma"]
    assert f"≥ {node['minimum']}" in gamma["constraints"]
    assert f"≤ {node['maximum']}" in gamma["constraints"]
    # the trailing "[unit]" of the description is moved to the unit column
    assert not gamma["meaning"].endswith("[-]")


def test_foot_slug_second_labels():
    f = scene_reference.foot_slug_second
    assert f("kg/m³") == "slug/ft³"
    assert f("N·m/rad") == "lbf·ft/rad"
    assert f("Pa·s/m") == "lbf·s/ft³"
    assert f("m/s²") == "ft/s²"
    assert f("rad/s") == "rad/s"
    assert f("deg") == "deg"


def test_escape_bars_leaves_literals_and_roles():
    text = "|v|v and ``|a|`` and :math:`|H|^2`"
    assert scene_reference.escape_bars(text) == "\\|v\\|v and ``|a|`` and :math:`|H|^2`"


def test_every_result_key_is_described():
    docs = results_reference.example_documents()
    paths = set().union(*(results_reference.document_paths(d) for d in docs.values()))
    assert results_reference.undocumented_keys(paths) == []
    # the examples hold a line with end motion and time series, a body and a plan
    for part in ("timeseries.lines.<line>.<end>.tension", "bodies.<body>.motion", "fidelity"):
        assert part in paths


def test_an_undescribed_result_key_is_reported():
    paths = results_reference.document_paths({"lines": {"leg": {"new_key": 1.0}}})
    assert results_reference.undocumented_keys(paths) == ["lines.<line>.new_key"]


def test_every_warning_is_described():
    sites = warnings_reference.warning_sites(ROOT)
    assert len(sites) >= 10  # the search finds the library's warnings at all
    assert warnings_reference.undocumented_sites(sites) == []
    described = {s for w in warnings_reference.WARNINGS for s in w.sites}
    assert described <= sites, "entries describe warnings the code no longer raises"


def test_warning_thresholds_are_read_from_the_code():
    from stochcable.dynamics.outputs import indicators, resolution

    text = warnings_reference.warnings_reference_rst()
    assert f"``TAIL_FRACTION`` = {resolution.TAIL_FRACTION:g}" in text
    assert f"``RESONANCE_PEAK_ERROR`` = {resolution.RESONANCE_PEAK_ERROR:g}" in text
    assert f"``SNAP_SIGMAS`` = {indicators.SNAP_SIGMAS:g}" in text


def test_http_reference_has_every_operation_and_setting():
    spec = json.loads((ROOT / "openapi" / "openapi.json").read_text(encoding="utf-8"))
    models = set(scene_json_schema()["$defs"]) | {"Scene"}
    text = openapi_reference.openapi_reference_rst(spec, models)
    for path, item in spec["paths"].items():
        for method in item:
            assert f"\n{method.upper()} {path}\n" in text
    from service.settings import ENV_PREFIX, Settings

    table = openapi_reference.settings_rst(Settings.model_json_schema(), ENV_PREFIX)
    for name in Settings.model_fields:
        assert f"``{ENV_PREFIX}{name.upper()}``" in table


GETTING_STARTED = (ROOT / "docs" / "manual" / "getting_started.md").read_text(encoding="utf-8")
BLOCKS = re.findall(r"```python\n(.*?)```", GETTING_STARTED, re.S)


def test_getting_started_python_blocks_run(monkeypatch):
    """The manual's first examples run as written, one after the other (the service's
    block, which needs a running server, aside)."""
    import warnings

    monkeypatch.chdir(ROOT)
    namespace: dict = {}
    ran = 0
    for block in BLOCKS:
        if "Client(" in block:
            continue
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            exec(compile(block, "getting_started.md", "exec"), namespace)
        ran += 1
    assert ran >= 3
    assert namespace["r"].lines["wire"].end_b.std > 0.0
