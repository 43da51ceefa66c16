"""The HTTP reference of the manual, rendered from the committed OpenAPI document
(``openapi/openapi.json``, generated from the FastAPI app; ``tests/service/test_openapi.py``
keeps file and app equal).

Every operation with its parameters, request body, examples and answers, then every
schema of the answers.  The scene models link to the scene reference (they are the same
pydantic models).
"""

from __future__ import annotations

import json
import re
from collections.abc import Mapping
from typing import Any

from scene_reference import field_rows, model_section

__all__ = ["openapi_reference_rst", "settings_rst"]

_METHODS = ("get", "post", "put", "patch", "delete")
# Examples longer than this many lines of JSON are named, not printed.
_EXAMPLE_LINES = 60


def _http_anchor(model: str) -> str:
    return f"http-{model.lower()}"


def _anchors(scene_models: set[str]):
    def anchor(model: str) -> str:
        return f"scene-{model.lower()}" if model in scene_models else _http_anchor(model)

    return anchor


def _paragraphs(text: str) -> list[str]:
    """A description as reStructuredText paragraphs (Markdown single backticks as
    literals)."""
    text = re.sub(r"(?<![`:\w])`([^`]+)`(?!`)", r"``\1``", text.strip())
    return [*text.splitlines(), ""]


def _ref(node: Mapping[str, Any]) -> str | None:
    ref = node.get("$ref")
    return ref.rsplit("/", 1)[-1] if ref else None


def _schema_text(node: Mapping[str, Any], anchor) -> str:
    name = _ref(node)
    if name:
        return f":ref:`{name} <{anchor(name)}>`"
    kind = node.get("type", "")
    if kind == "array" and "items" in node:
        return f"array of {_schema_text(node['items'], anchor)}"
    return kind or "any"


def _operation(path: str, method: str, op: Mapping[str, Any], anchor) -> list[str]:
    title = f"{method.upper()} {path}"
    out = [title, "-" * len(title), "", f"**{op.get('summary', '')}**", ""]
    out += _paragraphs(op.get("description", ""))
    params = op.get("parameters", [])
    if params:
        out += [
            ".. list-table:: Parameters",
            "   :header-rows: 1",
            "   :widths: 15 10 10 15 50",
            "",
            "   * - Name",
            "     - In",
            "     - Required",
            "     - Schema",
            "     - Meaning",
        ]
        for p in params:
            schema = p.get("schema", {})
            kind = (
                "one of " + ", ".join(f"``{v}``" for v in schema["enum"])
                if "enum" in schema
                else schema.get("type", "")
            )
            if "default" in schema:
                kind += f" (default ``{schema['default']}``)"
            out += [
                f"   * - ``{p['name']}``",
                f"     - {p['in']}",
                f"     - {'yes' if p.get('required') else 'no'}",
                f"     - {kind or '—'}",
                f"     - {' '.join(p.get('description', '').split()) or '—'}",
            ]
        out.append("")
    body = op.get("requestBody")
    if body:
        for media, content in body.get("content", {}).items():
            out += [
                f"**Request body** (``{media}``): "
                + _schema_text(content.get("schema", {}), anchor),
                "",
            ]
            for name, example in content.get("examples", {}).items():
                text = json.dumps(example.get("value"), indent=2, ensure_ascii=False)
                label = example.get("summary", name)
                if text.count("\n") < _EXAMPLE_LINES:
                    out += [f"Example *{label}*:", "", ".. code-block:: json", ""]
                    out += ["   " + line for line in text.splitlines()] + [""]
                else:
                    out += [
                        f"Example *{label}*: the bundled example ``{name}`` "
                        f"(``GET /v1/examples/{name}``).",
                        "",
                    ]
    out += [
        ".. list-table:: Answers",
        "   :header-rows: 1",
        "   :widths: 10 50 40",
        "",
        "   * - Status",
        "     - Meaning",
        "     - Body",
    ]
    for status, resp in op.get("responses", {}).items():
        bodies = [
            f"``{media}``: {_schema_text(c.get('schema', {}), anchor)}"
            for media, c in resp.get("content", {}).items()
        ]
        out += [
            f"   * - {status}",
            f"     - {' '.join(resp.get('description', '').split()) or '—'}",
            f"     - {'; '.join(bodies) or '—'}",
        ]
    return out + [""]


def openapi_reference_rst(spec: Mapping[str, Any], scene_models: set[str]) -> str:
    """The reStructuredText of the HTTP reference.

    Parameters
    ----------
    spec : mapping
        The OpenAPI document.
    scene_models : set of str
        Names of the scene's models (documented on the scene reference page).
    """
    anchor = _anchors(scene_models)
    info = spec.get("info", {})
    out = [
        f"OpenAPI {spec.get('openapi', '')}, API version {info.get('version', '')}.",
        "",
    ]
    out += _paragraphs(info.get("description", ""))
    for path, item in spec.get("paths", {}).items():
        for method in _METHODS:
            if method in item:
                out += _operation(path, method, item[method], anchor)
    schemas = spec.get("components", {}).get("schemas", {})
    own = [name for name in schemas if name not in scene_models]
    out += ["Answer and request schemas", "--------------------------", ""]
    defs = {"$defs": schemas}
    for name in own:
        out += model_section(defs, name, anchor, underline="~")
    return "\n".join(out)


def settings_rst(schema: Mapping[str, Any], prefix: str) -> str:
    """The table of the service's settings (the pydantic-settings model's JSON Schema):
    environment variable, default, constraints and meaning."""
    out = [
        ".. list-table::",
        "   :header-rows: 1",
        "   :widths: 30 15 15 40",
        "",
        "   * - Environment variable",
        "     - Default",
        "     - Constraints",
        "     - Meaning",
    ]
    rows = field_rows({"$defs": {"S": schema}}, "S")
    for name, row in zip(schema.get("properties", {}), rows):
        out += [
            f"   * - ``{prefix}{name.upper()}``",
            f"     - {row['default']}",
            f"     - {row['constraints'] or '—'}",
            f"     - {row['meaning'] or '—'}",
        ]
    return "\n".join(out + [""])
