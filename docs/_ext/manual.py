"""Sphinx directives of the manual's generated pages.

``.. scene-reference::``, ``.. results-reference::``, ``.. warnings-reference::``,
``.. openapi-reference::`` and ``.. service-settings::`` insert the reStructuredText
the generators of this folder build from the code (the scene models, result documents
of the bundled examples, the warning call sites, the committed OpenAPI document).  A
generator that finds something undocumented logs a Sphinx warning, which
``sphinx-build -W`` turns into an error.
"""

from __future__ import annotations

import json
from pathlib import Path

import openapi_reference
import results_reference
import scene_reference
import warnings_reference
from docutils import nodes
from docutils.statemachine import StringList
from sphinx.directives.other import TocTree
from sphinx.util import logging
from sphinx.util.docutils import SphinxDirective
from sphinx.util.matching import patfilter
from sphinx.util.nodes import nested_parse_with_titles

ROOT = Path(__file__).resolve().parents[2]
logger = logging.getLogger(__name__)


class _Generated(SphinxDirective):
    """A directive whose content is reStructuredText made by :meth:`text`."""

    has_content = False

    def text(self) -> str:
        raise NotImplementedError

    def run(self) -> list[nodes.Node]:
        node = nodes.section()
        node.document = self.state.document
        source = self.get_source_info()[0]
        lines = StringList(self.text().splitlines(), source=source)
        nested_parse_with_titles(self.state, lines, node)
        return node.children


def _scene_schema() -> dict:
    from stochcable.scene.model import scene_json_schema

    return scene_json_schema()


class SceneReference(_Generated):
    def text(self) -> str:
        return scene_reference.scene_reference_rst(_scene_schema())


class ResultsReference(_Generated):
    def text(self) -> str:
        docs = results_reference.example_documents()
        paths = set().union(*(results_reference.document_paths(d) for d in docs.values()))
        for key in results_reference.undocumented_keys(paths):
            logger.warning(
                "result document key %r is not described in docs/_ext/results_reference.py",
                key,
                location=self.get_location(),
            )
        return results_reference.results_reference_rst(paths)


class WarningsReference(_Generated):
    def text(self) -> str:
        sites = warnings_reference.warning_sites(ROOT)
        for site in warnings_reference.undocumented_sites(sites):
            logger.warning(
                "warning raised in %s is not described in docs/_ext/warnings_reference.py",
                site,
                location=self.get_location(),
            )
        return warnings_reference.warnings_reference_rst()


class OpenapiReference(_Generated):
    def text(self) -> str:
        spec = json.loads((ROOT / "openapi" / "openapi.json").read_text(encoding="utf-8"))
        models = set(_scene_schema()["$defs"]) | {"Scene"}
        return openapi_reference.openapi_reference_rst(spec, models)


class ServiceSettings(_Generated):
    def text(self) -> str:
        from service.settings import ENV_PREFIX, Settings

        return openapi_reference.settings_rst(Settings.model_json_schema(), ENV_PREFIX)


class OptionalGlobToctree(TocTree):
    """A glob toctree whose patterns may match nothing yet (pages other work adds,
    such as ``docs/cases.md`` or ``docs/benchmarks/*.md``): patterns without a match
    are dropped instead of warned about; no match at all gives no toctree."""

    def run(self) -> list[nodes.Node]:
        docs = sorted(self.env.found_docs)
        kept = [p for p in self.content if p.strip() and patfilter(docs, p.strip())]
        if not kept:
            return []
        self.content = StringList(kept, source=self.content.source(0))
        self.options["glob"] = True
        return super().run()


def escape_docstring_bars(app, what, name, obj, options, lines) -> None:  # noqa: ANN001
    """Escape the bars of ASCII mathematics in docstrings (``|v|v``, ``(T − 3σ)/|T|``),
    which reStructuredText would read as substitutions; literal blocks, doctests and
    inline literals are left alone."""
    literal_indent = None
    for i, line in enumerate(lines):
        stripped = line.lstrip()
        indent = len(line) - len(stripped)
        if literal_indent is not None:
            if stripped and indent <= literal_indent:
                literal_indent = None
            else:
                continue
        if stripped.startswith((">>>", "...")) or stripped.startswith(("|", "+-", "+=")):
            continue
        lines[i] = scene_reference.escape_bars(line)
        if stripped.endswith("::"):
            literal_indent = indent


def setup(app):  # noqa: ANN001, ANN201 - Sphinx's extension entry point
    app.connect("autodoc-process-docstring", escape_docstring_bars, priority=600)
    app.add_directive("optional-glob-toctree", OptionalGlobToctree)
    app.add_directive("scene-reference", SceneReference)
    app.add_directive("results-reference", ResultsReference)
    app.add_directive("warnings-reference", WarningsReference)
    app.add_directive("openapi-reference", OpenapiReference)
    app.add_directive("service-settings", ServiceSettings)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
