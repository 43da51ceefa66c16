"""The scene reference of the manual, generated from the scene's JSON Schema.

The schema is :func:`stochcable.scene.model.scene_json_schema` (the pydantic models of
``stochcable.scene``, committed as ``openapi/scene.schema.json``): every field of every
model with its meaning, unit (the ``unit`` each field carries), default and
constraints.  Nothing here is written by hand but the table layout.
"""

from __future__ import annotations

import json
import re
from collections.abc import Callable, Iterator, Mapping
from typing import Any

__all__ = [
    "escape_bars",
    "foot_slug_second",
    "model_order",
    "field_rows",
    "model_section",
    "scene_reference_rst",
]

# JSON Schema keywords shown as constraints, with how they read.
_CONSTRAINTS = (
    ("minimum", "≥ {}"),
    ("exclusiveMinimum", "> {}"),
    ("maximum", "≤ {}"),
    ("exclusiveMaximum", "< {}"),
    ("minItems", "at least {} item(s)"),
    ("maxItems", "at most {} item(s)"),
    ("minLength", "at least {} character(s)"),
    ("maxLength", "at most {} characters"),
    ("pattern", "matches ``{}``"),
)


# Inline literals and interpreted text (roles such as :math:`|H|`), left as they are.
_LITERAL = re.compile(r"(``.+?``|`[^`]+`)")


def escape_bars(text: str) -> str:
    """``text`` with the vertical bars of ASCII mathematics (``|v|``, ``|K − Kᵀ|``)
    escaped outside inline literals and roles, so that reStructuredText does not read
    them as substitutions."""
    parts = _LITERAL.split(text)
    return "".join(p if p.startswith("`") else p.replace("|", "\\|") for p in parts)


# SI unit labels and their foot–slug–second counterparts (a scene in consistent units:
# environment.g in ft/s² makes every length ft, mass slug, force lbf).
_FSS = tuple(
    (re.compile(rf"(?<![A-Za-z]){re.escape(si)}(?![A-Za-z])"), fss)
    for si, fss in (
        ("Pa·s/m", "N·s/m³"),
        ("Pa/m", "N/m³"),
        ("Pa", "N/m²"),
        ("kg", "slug"),
        ("N", "lbf"),
        ("m", "ft"),
    )
)


def foot_slug_second(unit: str) -> str:
    """The foot–slug–second label of an SI unit label (``"kg/m³"`` → ``"slug/ft³"``)."""
    for pattern, replacement in _FSS:
        unit = pattern.sub(replacement, unit)
    return unit


def _ref_name(ref: str) -> str:
    return ref.rsplit("/", 1)[-1]


def _anchor(model: str) -> str:
    return f"scene-{model.lower()}"


# How a model's name becomes the label of its section (the OpenAPI page links the
# scene's models to this page and its own models to itself).
Anchor = Callable[[str], str]


def _refs(node: Any) -> Iterator[str]:
    """Every model a schema node refers to, in document order."""
    if isinstance(node, Mapping):
        if "$ref" in node:
            yield _ref_name(node["$ref"])
        for key, value in node.items():
            if key != "discriminator":
                yield from _refs(value)
    elif isinstance(node, list):
        for value in node:
            yield from _refs(value)


def model_order(schema: Mapping[str, Any]) -> list[str]:
    """The models in the order a reader meets them: the scene first, then each model
    after the first model that refers to it (breadth first); every model of ``$defs``
    appears once."""
    defs = schema["$defs"]
    order = ["Scene"]
    queue = [schema]
    while queue:
        node = queue.pop(0)
        for name in _refs(node.get("properties", {})):
            if name not in order:
                order.append(name)
                queue.append(defs[name])
    order += sorted(set(defs) - set(order))
    return order


def _type_text(node: Mapping[str, Any], anchor: Anchor = _anchor) -> str:
    """The field's type in words, with links to the models it holds."""
    if "$ref" in node:
        name = _ref_name(node["$ref"])
        return f":ref:`{name} <{anchor(name)}>`"
    if "oneOf" in node:
        alts = " | ".join(_type_text(x, anchor) for x in node["oneOf"])
        disc = node.get("discriminator", {}).get("propertyName")
        return f"one of {alts}" + (f" (chosen by ``{disc}``)" if disc else "")
    if "anyOf" in node:
        alts = [x for x in node["anyOf"] if x.get("type") != "null"]
        text = " | ".join(_type_text(x, anchor) for x in alts)
        return text + (" or null" if len(alts) < len(node["anyOf"]) else "")
    if "const" in node:
        return f"``{json.dumps(node['const'])}``"
    if "enum" in node:
        return "one of " + ", ".join(f"``{json.dumps(v)}``" for v in node["enum"])
    kind = node.get("type")
    if kind == "array":
        if "prefixItems" in node:
            return f"array of {len(node['prefixItems'])} numbers"
        if "items" in node:
            return f"array of {_type_text(node['items'], anchor)}"
        return "array"
    if kind == "object":
        extra = node.get("additionalProperties")
        if isinstance(extra, Mapping):
            return f"object of {_type_text(extra, anchor)}"
        return "object"
    return {"number": "number", "integer": "integer", "string": "string", "boolean": "boolean"}.get(
        kind, "any"
    )


def _constraints(node: Mapping[str, Any]) -> str:
    parts = []
    for alt in [node, *node.get("anyOf", [])]:
        for key, fmt in _CONSTRAINTS:
            if key in alt:
                parts.append(fmt.format(alt[key]))
    return "; ".join(dict.fromkeys(parts))


def _description(node: Mapping[str, Any], unit: str | None, defs: Mapping[str, Any]) -> str:
    """The field's description without its trailing ``[unit]``; a field without one
    is described by the model it holds."""
    text = node.get("description", "")
    if unit and text.endswith(f"[{unit}]"):
        text = text[: -len(unit) - 2].rstrip()
    if not text:
        names = [n for n in _refs(node) if n in defs]
        if len(names) == 1:
            text = defs[names[0]].get("description", "").split("\n\n")[0]
    return escape_bars(" ".join(text.split()))


def field_rows(
    schema: Mapping[str, Any], model: str, anchor: Anchor = _anchor
) -> list[dict[str, str]]:
    """One row per field of ``model``: name, type, unit, default, constraints, meaning."""
    defs = schema["$defs"]
    spec = schema if model == "Scene" else defs[model]
    required = set(spec.get("required", ()))
    rows = []
    for name, node in spec.get("properties", {}).items():
        unit = node.get("unit")
        if name in required:
            default = "required"
        elif "default" in node:
            default = f"``{json.dumps(node['default'], ensure_ascii=False)}``"
        elif "$ref" in node:
            default = "its fields' defaults"
        else:
            default = "optional"
        rows.append(
            {
                "field": f"``{name}``",
                "type": _type_text(node, anchor),
                "unit": unit or "",
                "unit_fss": foot_slug_second(unit) if unit else "",
                "default": default,
                "constraints": _constraints(node),
                "meaning": _description(node, unit, defs),
            }
        )
    return rows


def _cell(text: str) -> str:
    return text if text else "—"


def model_section(
    schema: Mapping[str, Any], model: str, anchor: Anchor = _anchor, underline: str = "-"
) -> list[str]:
    """The section of one model: its description and the table of its fields."""
    defs = schema["$defs"]
    spec = schema if model == "Scene" else defs[model]
    title = "Scene (the document)" if model == "Scene" else model
    out = [f".. _{anchor(model)}:", "", title, underline * len(title), ""]
    doc = spec.get("description", "")
    for paragraph in re.split(r"\n\s*\n", doc):
        if paragraph.strip():
            out += [escape_bars(" ".join(paragraph.split())), ""]
    rows = field_rows(schema, model, anchor)
    if not rows:
        return out + ["No fields.", ""]
    out += [
        ".. list-table::",
        "   :header-rows: 1",
        "   :widths: 13 20 8 8 11 13 27",
        "",
        "   * - Field",
        "     - Type",
        "     - Unit (SI)",
        "     - Unit (ft–slug–s)",
        "     - Default",
        "     - Constraints",
        "     - Meaning",
    ]
    for row in rows:
        keys = ("field", "type", "unit", "unit_fss", "default", "constraints", "meaning")
        cells = [row[k] for k in keys]
        out.append(f"   * - {_cell(cells[0])}")
        out += [f"     - {_cell(c)}" for c in cells[1:]]
    return out + [""]


def scene_reference_rst(schema: Mapping[str, Any]) -> str:
    """The reStructuredText of the scene reference: one section per model."""
    lines: list[str] = []
    for model in model_order(schema):
        lines += model_section(schema, model)
    return "\n".join(lines)
