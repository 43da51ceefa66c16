"""Write the committed OpenAPI document: ``python -m service.openapi``.

Writes ``openapi/openapi.json`` at the repository root (or ``--output PATH``); with
``--check`` it writes nothing and exits 1 when the file differs from the app's
document.  ``tests/service/test_openapi.py`` fails when code and file disagree.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path
from typing import Any

__all__ = ["DEFAULT_PATH", "REGENERATE_COMMAND", "openapi_document", "render", "main"]

DEFAULT_PATH = Path(__file__).resolve().parents[1] / "openapi" / "openapi.json"
REGENERATE_COMMAND = "python -m service.openapi"


def openapi_document() -> dict[str, Any]:
    """The OpenAPI document of an application built with default settings.

    Limits do not appear in the document, so the environment does not change it.
    """
    from .app import create_app
    from .settings import Settings

    return create_app(Settings()).openapi()


def render(document: dict[str, Any]) -> str:
    """The document as committed: 2-space indented JSON, UTF-8, final newline."""
    return json.dumps(document, indent=2, ensure_ascii=False) + "\n"


def main(argv: list[str] | None = None) -> int:
    """Command-line entry point; returns the exit code."""
    parser = argparse.ArgumentParser(prog="python -m service.openapi", description=__doc__)
    parser.add_argument(
        "--output", type=Path, default=DEFAULT_PATH, help=f"file to write (default {DEFAULT_PATH})"
    )
    parser.add_argument(
        "--check", action="store_true", help="compare instead of writing; exit 1 when they differ"
    )
    args = parser.parse_args(argv)
    text = render(openapi_document())
    if args.check:
        current = args.output.read_text(encoding="utf-8") if args.output.exists() else ""
        if current != text:
            sys.stderr.write(f"{args.output} is out of date; run: {REGENERATE_COMMAND}\n")
            return 1
        return 0
    args.output.parent.mkdir(parents=True, exist_ok=True)
    args.output.write_text(text, encoding="utf-8")
    sys.stderr.write(f"wrote {args.output}\n")
    return 0


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
