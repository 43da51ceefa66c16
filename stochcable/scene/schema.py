"""Write the scene document's JSON Schema (committed as ``openapi/scene.schema.json``).

Run ``python -m stochcable.scene.schema [path]`` after changing the scene models;
``tests/scene/test_scene.py`` fails when the committed file and the models disagree.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

from stochcable.scene.model import scene_json_schema

__all__ = ["DEFAULT_SCHEMA_PATH", "scene_schema_text", "write_scene_schema"]

#: Where the schema is committed, relative to the repository root.
DEFAULT_SCHEMA_PATH = Path("openapi") / "scene.schema.json"


def scene_schema_text() -> str:
    """The scene JSON Schema as the exact text committed (sorted keys, 2-space indent)."""
    return json.dumps(scene_json_schema(), indent=2, sort_keys=True, ensure_ascii=False) + "\n"


def write_scene_schema(path: str | Path = DEFAULT_SCHEMA_PATH) -> Path:
    """Write the scene JSON Schema to ``path`` (UTF-8) and return the path.

    Parameters
    ----------
    path : str or Path, optional
        Output file; its directory is created when missing.

    Returns
    -------
    Path
        The file written.
    """
    out = Path(path)
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(scene_schema_text(), encoding="utf-8")
    return out


def main(argv: list[str] | None = None) -> int:
    """``python -m stochcable.scene.schema [path]``: write the schema, say where."""
    import argparse

    ap = argparse.ArgumentParser(
        prog="python -m stochcable.scene.schema", description=__doc__.splitlines()[0]
    )
    ap.add_argument("path", nargs="?", default=str(DEFAULT_SCHEMA_PATH), help="output file")
    target = write_scene_schema(ap.parse_args(argv).path)
    sys.stdout.write(f"wrote {target}\n")
    return 0


if __name__ == "__main__":  # pragma: no cover - exercised by hand / CI
    raise SystemExit(main())
