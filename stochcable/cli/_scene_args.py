"""Scene arguments shared by ``analyze``, ``cases``, ``statics`` and ``import``: the scene
file (a scene document or a MoorDyn input file, :func:`stochcable.io.load_scene`), and
what a MoorDyn file lacks: the sea (``--sea``) and the vessel's motion (``--vessel-rao``,
or motion spectra of its fairleads, ``--fairlead-spectra``).
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import Any

from pydantic import ValidationError

from stochcable.errors import InputError
from stochcable.io import load_scene
from stochcable.scene.model import EndMotion, Scene, Sea, VesselMotion

__all__ = ["add_scene_arguments", "scene_from_args"]


def add_scene_arguments(parser: argparse.ArgumentParser, sea: bool = True) -> None:
    """Add ``--vessel-rao`` (and ``--sea``) to ``parser``."""
    parser.add_argument(
        "--vessel-rao",
        metavar="RAO.json",
        default=None,
        help="motion of the scene's prescribed body (a MoorDyn file's Coupled/Vessel "
        "points): a JSON RAO table {omega, heading?, surge, sway, heave, roll, pitch, "
        "yaw: {re, im}} per unit wave amplitude (docs/manual/moordyn.md)",
    )
    parser.add_argument(
        "--fairlead-spectra",
        metavar="SPECTRA.json",
        default=None,
        help="instead of --vessel-rao: motion spectra of the vessel's fairleads, "
        "{surge?, sway?, heave?: spectrum document} in metres, the same at every "
        "fairlead; each becomes a fixed end with that motion (lines.<n>.end_b.motion): "
        "every line's statistics hold, the motions of two fairleads are taken as "
        "uncorrelated and the vessel's rotations are left out",
    )
    parser.add_argument(
        "--vessel",
        default=None,
        help="name of the prescribed body --vessel-rao moves (default: the only one)",
    )
    if sea:
        parser.add_argument(
            "--sea",
            metavar="SEA.json",
            default=None,
            help="the sea: a JSON sea document {spectrum, heading, spreading?} "
            "(replaces the scene's; a MoorDyn file has none)",
        )


def _read_json(path: str, flag: str) -> Any:
    try:
        return json.loads(Path(path).read_text(encoding="utf-8"))
    except OSError as exc:
        raise InputError(flag, path, "-", f"cannot be read ({exc.strerror})") from None
    except json.JSONDecodeError as exc:
        raise InputError(
            flag, path, "-", f"is not valid JSON ({exc.msg} at line {exc.lineno})"
        ) from None


def _model(cls: type, data: Any, flag: str, path: str) -> Any:
    try:
        return cls.model_validate(data)
    except ValidationError as exc:
        err = exc.errors(include_url=False)[0]
        where = ".".join(str(p) for p in err.get("loc", ()))
        raise InputError(
            f"{flag} {path}", where or "document", "-", err.get("msg", "invalid")
        ) from None


def scene_from_args(args: argparse.Namespace) -> Scene:
    """The scene of ``args.scene`` with ``--sea``, and ``--vessel-rao`` or
    ``--fairlead-spectra``, applied."""
    scene = load_scene(Path(args.scene))
    doc = None
    sea_path = getattr(args, "sea", None)
    if sea_path is not None:
        sea = _model(Sea, _read_json(sea_path, "--sea"), "--sea", sea_path)
        doc = scene.model_dump(mode="json", exclude_none=True)
        doc["sea"] = sea.model_dump(mode="json", exclude_none=True)
    rao_path = getattr(args, "vessel_rao", None)
    spectra_path = getattr(args, "fairlead_spectra", None)
    if rao_path is not None and spectra_path is not None:
        raise InputError(
            "--fairlead-spectra", spectra_path, "-", "give --vessel-rao or it, not both"
        )
    if rao_path is None and spectra_path is None:
        return scene if doc is None else load_scene(doc)
    doc = doc or scene.model_dump(mode="json", exclude_none=True)
    name = _vessel_name(doc, args.vessel)
    if rao_path is not None:
        rao = _model(VesselMotion, _read_json(rao_path, "--vessel-rao"), "--vessel-rao", rao_path)
        for b in doc["bodies"]:
            if b["name"] == name:
                b["prescribed"] = rao.model_dump(mode="json", exclude_none=True)
        return load_scene(doc)
    motion = _model(
        EndMotion, _read_json(spectra_path, "--fairlead-spectra"), "--fairlead-spectra",
        spectra_path,
    )  # fmt: skip
    if motion.rao is not None:
        raise InputError(
            "--fairlead-spectra", spectra_path, "-", "give spectra; an RAO goes in --vessel-rao"
        )
    for i, ln in enumerate(doc["lines"]):
        for end in ("end_a", "end_b"):
            e = ln[end]
            if e.get("attach", {}).get("body") == name:
                where = scene.end_position(scene.lines[i], end)
                ln[end] = {
                    "position": [float(v) for v in where],
                    "motion": motion.model_dump(mode="json", exclude_none=True),
                }
    doc["bodies"] = [b for b in doc["bodies"] if b["name"] != name]
    return load_scene(doc)


def _vessel_name(doc: dict[str, Any], name: str | None) -> str:
    names = [b["name"] for b in doc.get("bodies", []) if b.get("prescribed") is not None]
    if name is None:
        if len(names) != 1:
            raise InputError(
                "--vessel", None, "-",
                f"the scene has {len(names)} prescribed bodies {names}: name one",
            )  # fmt: skip
        return names[0]
    if name not in names:
        raise InputError("--vessel", name, "-", f"no prescribed body of that name: {names}")
    return name
