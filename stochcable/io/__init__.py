"""Scene files in other formats: MoorDyn input files (v1 and v2), read and written.

:func:`read_moordyn` builds a scene from a MoorDyn file, :func:`write_moordyn` writes a
scene as one, and :func:`load_scene` is :func:`stochcable.scene.model.load_scene`
that also accepts a MoorDyn file (recognised from its header).  User page:
docs/manual/moordyn.md.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

from stochcable.io.moordyn_file import MoorDynInputError, is_moordyn_text
from stochcable.io.moordyn_pieces import moordyn_lines
from stochcable.io.moordyn_read import read_moordyn
from stochcable.io.moordyn_write import write_moordyn
from stochcable.scene.model import Scene
from stochcable.scene.model import load_scene as _load_json_scene

__all__ = [
    "read_moordyn",
    "write_moordyn",
    "moordyn_lines",
    "load_scene",
    "is_moordyn",
    "MoorDynInputError",
]


def is_moordyn(source: str | Path) -> bool:
    """True when ``source`` (a path, or a file's text holding a line break) is a
    MoorDyn input file, recognised from its header (:func:`moordyn_file.is_moordyn_text`)."""
    text = str(source)
    if isinstance(source, Path) or ("\n" not in text and not text.lstrip().startswith("{")):
        try:
            with open(source, encoding="utf-8", errors="replace") as fh:
                text = fh.read(20_000)
        except OSError:
            return False
    return is_moordyn_text(text)


def load_scene(
    source: Scene | Mapping[str, Any] | str | Path, *, allow_files: bool = True
) -> Scene:
    """:func:`stochcable.scene.model.load_scene`, also accepting a MoorDyn input file.

    Parameters
    ----------
    source : Scene, mapping, str or path
        A scene (model, mapping, JSON text or path to a JSON file), or a MoorDyn input
        file (its path or text), recognised from its header.
    allow_files : bool, optional
        As :func:`stochcable.scene.model.load_scene`.

    Returns
    -------
    Scene
    """
    if isinstance(source, (str, Path)) and is_moordyn(source):
        return read_moordyn(source)
    return _load_json_scene(source, allow_files=allow_files)
