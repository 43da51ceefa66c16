"""``stochcable import FILE -o scene.json``: a MoorDyn input file (v1 or v2) as a scene
document (:func:`stochcable.io.read_moordyn`; docs/manual/moordyn.md).

Examples::

    stochcable import mooring.dat -o scene.json
    stochcable import mooring.dat --sea sea.json --vessel-rao rao.json -o scene.json
"""

from __future__ import annotations

import argparse
from typing import Any

from stochcable.cli._output import write_json
from stochcable.cli._scene_args import add_scene_arguments, scene_from_args
from stochcable.errors import InputError
from stochcable.io import is_moordyn

__all__ = ["register", "run"]


def register(subparsers: Any) -> None:
    """Add the ``import`` sub-command."""
    p = subparsers.add_parser(
        "import",
        help="a MoorDyn input file (v1 or v2) as a scene document",
        description="Read a MoorDyn input file and write the scene document it describes "
        "(lines joined at free points, clump weights and buoys, point bodies, the vessel "
        "as a prescribed body); the options MoorDyn uses for its own time stepping are "
        "listed as ignored on stderr.",
    )
    p.add_argument("file", help="MoorDyn input file")
    p.add_argument("-o", "--output", default=None, help="scene file (default stdout)")
    add_scene_arguments(p)
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Read the file and write its scene document."""
    if not is_moordyn(args.file):
        raise InputError(
            "file", args.file, "-", "is not a MoorDyn input file (no MoorDyn header, no "
            "LINE TYPES or LINE DICTIONARY section)",
        )  # fmt: skip
    args.scene = args.file
    scene = scene_from_args(args)
    write_json(scene.model_dump(mode="json", exclude_none=True), args.output)
    return 0
