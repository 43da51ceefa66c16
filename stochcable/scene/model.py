"""The scene document: one definition of a cable analysis for Python, CLI and service.

A scene is environment + sea + lines + analysis settings (DESIGN.md, "Scene and result
documents", v1 contract).  The models are frozen pydantic models; they validate every
field with its unit and bounds once, at the boundary, and the numerical code below
trusts them.  :func:`load_scene` turns pydantic's validation errors into
:class:`~stochcable.errors.InputError` messages naming the field path, value, unit and
constraint.

Units are consistent units, SI by default (m, kg, s, N, rad/s); the seeds' imperial
examples run unchanged when ``g`` and ``rho`` are given in feet and slugs.  Headings
in the document are in degrees (the document is an edge); the models expose radians
(``heading_rad``) to the core.

The parts of the document are modelled in :mod:`~stochcable.scene.spectra`,
:mod:`~stochcable.scene.environment`, :mod:`~stochcable.scene.lines`,
:mod:`~stochcable.scene.bodies` (with :mod:`~stochcable.scene.tables`, the
hydrodynamic tables) and :mod:`~stochcable.scene.analysis_settings`; this module holds
the :class:`Scene`, :func:`load_scene` and the conversion of validation errors, and
re-exports every model (``from stochcable.scene.model import Line`` and
``from stochcable.scene import Line`` both work).

References
----------
Tuah, H. (1982), Cable dynamics in an ocean environment, PhD thesis, Oregon State University.
"""

from __future__ import annotations

import json
import math
import re
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any, Literal

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, ValidationError, model_validator

from stochcable.errors import InputError
from stochcable.scene.analysis_settings import (
    AnalysisSettings,
    FidelitySettings,
    LinearizationSettings,
    OmegaGrid,
    StructuralDamping,
    TimeSeriesSettings,
)
from stochcable.scene.base import G_STANDARD, RHO_SEAWATER, LocatedValueError, _Doc
from stochcable.scene.bodies import (
    BODY_DOFS,
    PLANAR_BODY_DOFS,
    Body,
    BodyExcitation,
    BodyHydrodynamics,
    BodyHydrodynamicsFile,
)
from stochcable.scene.environment import CurrentPoint, Environment, Sea, Seabed
from stochcable.scene.lines import (
    Attachment,
    BodyAttachment,
    End,
    EndMotion,
    Line,
    Segment,
    SegmentStrumming,
    check_span,
)
from stochcable.scene.raos import ComplexTable, MotionRao, VesselMotion, check_rao_headings
from stochcable.scene.spectra import (
    Bretschneider,
    Issc,
    Jonswap,
    OchiHubble,
    PiersonMoskowitz,
    Spectrum,
    TableSpectrum,
)
from stochcable.scene.units import UnitLabels, labels_of_document

__all__ = [
    "G_STANDARD",
    "RHO_SEAWATER",
    "PiersonMoskowitz",
    "Jonswap",
    "Bretschneider",
    "Issc",
    "OchiHubble",
    "TableSpectrum",
    "Spectrum",
    "CurrentPoint",
    "Seabed",
    "Environment",
    "Sea",
    "ComplexTable",
    "MotionRao",
    "EndMotion",
    "BodyAttachment",
    "End",
    "Segment",
    "SegmentStrumming",
    "Attachment",
    "Line",
    "BodyExcitation",
    "BodyHydrodynamics",
    "BodyHydrodynamicsFile",
    "VesselMotion",
    "Body",
    "BODY_DOFS",
    "PLANAR_BODY_DOFS",
    "OmegaGrid",
    "LinearizationSettings",
    "TimeSeriesSettings",
    "StructuralDamping",
    "FidelitySettings",
    "AnalysisSettings",
    "Scene",
    "load_scene",
    "scene_json_schema",
    "field_path_and_unit",
    "error_location",
]


class Scene(_Doc):
    """A complete analysis: environment, sea, lines and settings (DESIGN.md v1)."""

    model_config = ConfigDict(defer_build=False)  # (:class:`_Doc`)
    title: str = Field(default="", max_length=2000, description="Free text: source and assumptions")
    environment: Environment
    sea: Sea | None = None
    lines: tuple[Line, ...] = Field(min_length=1, max_length=100)
    bodies: tuple[Body, ...] = Field(
        default=(), max_length=100, description="Large rigid bodies the lines attach to"
    )
    analysis: AnalysisSettings = Field(default_factory=AnalysisSettings)

    @model_validator(mode="after")
    def _check_scene(self) -> Scene:
        names = [ln.name for ln in self.lines]
        dup = {n for n in names if names.count(n) > 1}
        if dup:
            raise ValueError(f"line names must be unique; repeated: {sorted(dup)}")
        bnames = [b.name for b in self.bodies]
        dup = {n for n in bnames if bnames.count(n) > 1}
        if dup:
            raise ValueError(f"body names must be unique; repeated: {sorted(dup)}")
        bodies = {b.name: b for b in self.bodies}
        depth = self.environment.depth
        for i, ln in enumerate(self.lines):
            for end in ("end_a", "end_b"):
                e = getattr(ln, end)
                if e.attach is not None:
                    if e.attach.body not in bodies:
                        raise ValueError(
                            f"lines[{i}].{end}.attach.body = {e.attach.body!r}: no body of "
                            f"that name; bodies: {bnames}"
                        )
                    continue
                z = e.position[2]
                if z < -depth * (1 + 1e-9):
                    raise ValueError(
                        f"lines[{i}].{end}.position z = {z} m is below the seabed (depth {depth} m)"
                    )
                if end == "end_a" and z > 0.0:
                    raise LocatedValueError(
                        ("lines", i, end, "position"),
                        list(e.position),
                        f"z = {z} is above the still-water level: the anchor end (end_a) "
                        "must have z <= 0 (end_b may be above the water: the part of a line "
                        "in air has its weight in air, no buoyancy and no wave or current "
                        "load)",
                    )
            if ln.end_a.attach is not None or ln.end_b.attach is not None:
                try:
                    check_span(
                        self.end_position(ln, "end_a"), self.end_position(ln, "end_b"), ln.length
                    )
                except ValueError as exc:
                    raise ValueError(f"lines[{i}]: {exc}") from None
        check_rao_headings(self.sea, self.bodies, self.lines)
        if self.bodies:
            planar = self.is_planar
            for j, b in enumerate(self.bodies):
                if b.planar_data and not planar:
                    raise LocatedValueError(
                        ("bodies", j),
                        b.name,
                        f"bodies[{j}] ({b.name!r}) has 3×3 (surge, heave, pitch) data but "
                        "the scene is not planar (a line, body, sea or current leaves the "
                        "x–z plane; a spread sea does): give 6×6 matrices and a 6-DOF table",
                    )
                if planar:
                    bad = [d for d in b.fixed_dofs if d not in PLANAR_BODY_DOFS]
                    if bad:
                        raise ValueError(
                            f"bodies[{j}].fixed_dofs {bad}: the scene is planar, its bodies "
                            f"have only {list(PLANAR_BODY_DOFS)}"
                        )
        return self

    @property
    def uses_files(self) -> bool:
        """True when a body's hydrodynamics refers to a file (refused by the service)."""
        return any(isinstance(b.hydrodynamics, BodyHydrodynamicsFile) for b in self.bodies)

    def body(self, name: str) -> Body:
        """The body called ``name``."""
        for b in self.bodies:
            if b.name == name:
                return b
        raise InputError(
            "body", name, "-", f"no body of that name; bodies: {[b.name for b in self.bodies]}"
        )

    def end_position(
        self,
        line: Line | str,
        end: Literal["end_a", "end_b"],
        poses: Mapping[str, Any] | None = None,
    ) -> np.ndarray:
        """Position of a line end, shape (3,). [m]

        Parameters
        ----------
        line : Line or str
            The line or its name.
        end : {"end_a", "end_b"}
        poses : mapping of body name to pose, optional
            Body poses: objects with ``position`` (3,) [m] and ``rotation`` (3,)
            rotation vector [rad] (:class:`stochcable.bodies.statics.BodyStatics`), or
            ``(position, rotation)`` pairs.  Default: the bodies' ``position``, no
            rotation.

        Returns
        -------
        ndarray, shape (3,)
            ``end.position``, or for an attached end X + R(θ)·r (Tuah (1982), eq. 3.3.6
            to first order), X, θ the body pose and r ``attach.point``. [m]
        """
        if isinstance(line, str):
            found = [ln for ln in self.lines if ln.name == line]
            if not found:
                raise InputError("line", line, "-", "no line of that name")
            line = found[0]
        e = getattr(line, end)
        if e.attach is None:
            return np.asarray(e.position, dtype=float)
        name = e.attach.body
        r = np.asarray(e.attach.point, dtype=float)
        pose = None if poses is None else poses.get(name)
        if pose is None:
            return np.asarray(self.body(name).position, dtype=float) + r
        if hasattr(pose, "position"):
            x, rot = pose.position, pose.rotation
        else:
            x, rot = pose
        return np.asarray(x, dtype=float) + rotate(np.asarray(rot, dtype=float), r)

    def resolved_line(self, line: Line, poses: Mapping[str, Any] | None = None) -> Line:
        """The line with its attached ends replaced by fixed positions at ``poses``
        (:meth:`end_position`), for the code that needs ``end.position``."""
        upd = {}
        for end in ("end_a", "end_b"):
            if getattr(line, end).attach is not None:
                p = self.end_position(line, end, poses)
                upd[end] = End(position=tuple(float(v) for v in p))
        return line.model_copy(update=upd) if upd else line

    @property
    def is_planar(self) -> bool:
        """True when every line, the sea, current and end motions lie in one vertical
        plane through the x axis (y = 0, headings 0 or 180 deg), so a 2-D model suffices."""
        tol = 1e-9
        for b in self.bodies:
            if b.out_of_plane:
                return False
        for ln in self.lines:
            for end in ("end_a", "end_b"):
                e = getattr(ln, end)
                y = e.position[1] if e.attach is None else e.attach.point[1]
                if abs(y) > tol:
                    return False
            for end in (ln.end_a, ln.end_b):
                m = end.motion
                if m is not None and (
                    m.sway is not None or (m.rao is not None and m.rao.sway is not None)
                ):
                    return False
        if self.sea is not None and (
            abs(math.sin(self.sea.heading_rad)) > tol or self.sea.spreading is not None
        ):
            return False
        for p in self.environment.current:
            if p.speed > 0 and abs(math.sin(p.heading_rad)) > tol:
                return False
        return True


# ---------------------------------------------------------------------- boundary


def field_path_and_unit(model: type[BaseModel] | None, loc: Sequence[Any]) -> tuple[str, str]:
    """Dotted path and declared unit of the field at a pydantic error location.

    Parameters
    ----------
    model : pydantic model class or None
        The model the location is relative to.
    loc : sequence of str and int
        A pydantic error location, e.g. ``("sea", "spectrum", "jonswap", "hs")``.

    Returns
    -------
    path : str
        ``"sea.spectrum.hs"``: discriminator tags (a union member's ``type`` default)
        and pydantic's validator labels are dropped, list indices become ``[i]``.
    unit : str
        The unit in the field's ``json_schema_extra`` (``"m"``), or ``""``.
    """
    from typing import get_args

    unit = ""
    candidates: list[type[BaseModel]] = [model] if model is not None else []
    out = ""
    for part in loc:
        if isinstance(part, int):
            out += f"[{part}]"
            continue
        tagged = [
            c
            for c in candidates
            if "type" in c.model_fields and c.model_fields["type"].default == part
        ]
        if tagged:
            candidates = tagged
            continue
        if isinstance(part, str) and part.startswith("function-"):
            continue
        if (
            part in ("file", "table")
            and any(c in (BodyHydrodynamicsFile, BodyHydrodynamics) for c in candidates)
            and not any(
                part in c.model_fields for c in candidates if c is not BodyHydrodynamicsFile
            )
        ):
            if part == "table":
                candidates = [BodyHydrodynamics]
                continue
            if out.endswith("hydrodynamics"):
                candidates = [BodyHydrodynamicsFile]
                continue
        out += ("." if out else "") + str(part)
        current = next((c for c in candidates if part in c.model_fields), None)
        if current is None:
            candidates, unit = [], ""
            continue
        info = current.model_fields[part]
        extra = info.json_schema_extra
        unit = extra.get("unit", "") if isinstance(extra, dict) else ""
        found: list[type[BaseModel]] = []
        stack: list[Any] = [info.annotation]
        while stack:
            t = stack.pop()
            if isinstance(t, type) and issubclass(t, BaseModel):
                found.append(t)
                continue
            stack.extend(get_args(t))
        candidates = found
    return out, unit


#: A number followed by an SI unit symbol in a validator's message ("-120 m", "5 m²").
_QUOTED_UNIT = re.compile(r"([\d\]] )((?:kg|m|N)(?:[²³]|/m|/s)?)(?![\w/·])")


def error_location(err: Mapping[str, Any]) -> tuple[str | int, ...]:
    """The location of one pydantic error (an item of ``ValidationError.errors()``),
    extended by the field a :class:`~stochcable.scene.base.LocatedValueError` names."""
    loc = tuple(err.get("loc", ()))
    located = (err.get("ctx") or {}).get("error")
    if isinstance(located, LocatedValueError):
        loc += located.loc
    return loc


def input_error_from_validation(
    exc: ValidationError,
    model: type[BaseModel],
    prefix: str = "",
    labels: UnitLabels | None = None,
) -> InputError:
    """Convert the first error of a pydantic ValidationError into an InputError.

    ``labels``: the scene's unit system (:func:`stochcable.scene.units.labels_of_document`);
    the field's SI unit label is given in it (default SI).
    """
    errors = exc.errors(include_url=False)
    locs = [tuple(e.get("loc", ())) for e in errors]
    # pydantic repeats a nested failure at every enclosing tuple ("should have at least
    # 1 item"): keep only errors whose location is not a prefix of another's.
    leaves = [
        e for e, lc in zip(errors, locs) if not any(o != lc and o[: len(lc)] == lc for o in locs)
    ] or errors
    err = leaves[0]
    path, unit = field_path_and_unit(model, error_location(err))
    if labels is not None:
        unit = labels.convert(unit)
    path = path or "scene"
    if prefix:
        path = f"{prefix}.{path}" if path != "scene" else prefix
    msg = str(err.get("msg", "invalid"))
    if msg.startswith("Value error, "):
        msg = msg[len("Value error, ") :]
    if labels is not None and labels.system != "SI":
        # the validators' own messages quote values with SI symbols ("z = -120 m")
        msg = _QUOTED_UNIT.sub(lambda mt: mt.group(1) + labels.convert(mt.group(2)), msg)
    more = len(leaves) - 1
    if more:
        msg += f" (and {more} more error{'s' if more > 1 else ''})"
    value = err.get("input")
    located = (err.get("ctx") or {}).get("error")
    if isinstance(located, LocatedValueError):
        value = located.value
    if isinstance(value, Mapping):
        value = InputError._NO_VALUE
    elif isinstance(value, (list, tuple)) and len(value) > 6:
        value = f"[{len(value)} values]"
    return InputError(path, value, unit, msg)


def rotate(rotation: np.ndarray, r: np.ndarray) -> np.ndarray:
    """R(θ)·r for a rotation vector θ (Rodrigues' formula). [m]"""
    th = float(np.linalg.norm(rotation))
    if th == 0.0:
        return np.array(r, dtype=float)
    k = rotation / th
    return (
        r * math.cos(th) + np.cross(k, r) * math.sin(th) + k * float(k @ r) * (1.0 - math.cos(th))
    )


def load_scene(
    source: Scene | Mapping[str, Any] | str | Path,
    *,
    allow_files: bool = True,
    parameter: str = "scene",
) -> Scene:
    """Validate a scene given as a model, a mapping, a JSON string or a path to a file.

    The one coercion of every public entry point that takes a scene (``analyze``,
    ``build_engine``, ``solve_statics``, ``natural_modes``,
    ``simulate_line_timedomain``, ``run_cases``, the client): a :class:`Scene` is
    returned as it is (validated once, when it was made).

    Parameters
    ----------
    source : Scene, mapping, str or path
        The scene document. A ``str`` that does not start with ``{`` is a file path.
    allow_files : bool, optional
        Accept bodies whose ``hydrodynamics`` is a ``{"file": ...}`` (the HTTP
        service passes False).  Relative paths are made absolute against the scene
        file's folder (a path source) or the working folder; the file must exist.
    parameter : str, optional
        The caller's name of the argument, named by the errors about the source itself
        (its type, an unreadable file, text that is not JSON).

    Returns
    -------
    Scene
        The validated, frozen scene.

    Raises
    ------
    InputError
        Naming the first offending field path, its value, unit and constraint.
    """
    if isinstance(source, Scene):
        return _check_files(source, allow_files)
    if not isinstance(source, (Mapping, str, Path)):
        raise InputError(
            parameter,
            type(source).__name__,
            "-",
            "must be a Scene, a mapping (the scene document), a path or JSON text",
        )
    base = Path.cwd()
    if isinstance(source, (str, Path)):
        text = str(source)
        if isinstance(source, Path) or not text.lstrip().startswith("{"):
            try:
                text = Path(source).read_text(encoding="utf-8")
                base = Path(source).resolve().parent
            except OSError as exc:
                raise InputError(
                    parameter, str(source), "-", f"cannot be read ({exc.strerror})"
                ) from None
        try:
            data = json.loads(text)
        except json.JSONDecodeError as exc:
            raise InputError(
                parameter,
                str(source)[:80],
                "-",
                f"is not valid JSON ({exc.msg} at line {exc.lineno})",
            ) from None
    else:
        data = source
    try:
        scene = Scene.model_validate(data)
    except ValidationError as exc:
        raise input_error_from_validation(exc, Scene, labels=labels_of_document(data)) from None
    return _check_files(scene, allow_files, base)


def _check_files(scene: Scene, allow_files: bool, base: Path | None = None) -> Scene:
    """Refuse or resolve the bodies' hydrodynamics files (see :func:`load_scene`)."""
    if not scene.uses_files:
        return scene
    bodies = list(scene.bodies)
    for i, b in enumerate(bodies):
        h = b.hydrodynamics
        if not isinstance(h, BodyHydrodynamicsFile):
            continue
        where = f"bodies[{i}].hydrodynamics.file"
        if not allow_files:
            raise InputError(
                where,
                h.file,
                "-",
                "files are not accepted here: give the "
                "coefficient table inline (docs/BODIES.md JSON table)",
            )
        p = Path(h.file)
        if not p.is_absolute():
            p = (base if base is not None else Path.cwd()) / p
        if not p.is_file():
            raise InputError(where, h.file, "-", f"file not found (looked for {p})")
        if str(p) != h.file:
            bodies[i] = b.model_copy(update={"hydrodynamics": BodyHydrodynamicsFile(file=str(p))})
    if bodies == list(scene.bodies):
        return scene
    return scene.model_copy(update={"bodies": tuple(bodies)})


def scene_json_schema() -> dict[str, Any]:
    """The JSON Schema of the scene document (committed as openapi/scene.schema.json)."""
    schema = Scene.model_json_schema()
    schema["$schema"] = "https://json-schema.org/draft/2020-12/schema"
    schema["title"] = "stochcable scene (v1)"
    return schema
