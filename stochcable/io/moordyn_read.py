"""Read a MoorDyn input file (version 1 or 2) into a scene.

The steps: :mod:`~stochcable.io.moordyn_file` splits the file into sections and rows,
:mod:`~stochcable.io.moordyn_parts` reads the line types, bodies, points, lines and
options, :mod:`~stochcable.io.moordyn_scene` maps points and lines to the scene's lines
and bodies; this module reads the environment and damping and checks the scene.

How MoorDyn's parts become a scene (docs/manual/moordyn.md):

- LINE TYPES → the segments' ``diameter``, ``mass``, ``ea``, ``cd_normal`` (Cd/Cdn),
  ``ca_normal`` (Ca/Can), ``cd_axial`` (CdAx/Cdt, on π·d in both); CaAx, EI and the
  VIV lift coefficient have no counterpart (a warning names them when non-zero); a
  non-linear or visco-elastic EA (a table file or ``a|b``) is refused.
- BA/−ζ → the scene's stiffness-proportional structural damping β = BA/EA (a
  negative entry is MoorDyn's ratio ζ: BA = ζ·(L/N)·√(EA·m), per segment of the line);
  lines with different β: the smallest, with a warning.
- Fixed (Anchor) points → fixed line ends.  Coupled (Vessel, Fairlead) points → the
  fairleads of one prescribed body ``vessel`` at the origin (MoorDyn moves them with
  the platform); a Coupled body's points → the fairleads of a prescribed body
  ``body<k>``; a Fixed body's points → fixed ends.  The prescribed bodies get a zero
  motion RAO (``--vessel-rao`` of the CLI, or the scene, gives the real one).
- Free (Connect) points joining exactly two line ends → one multi-segment line; their
  mass and volume → a clump weight / buoy ``attachments`` entry at that arc length.
  Free points joining one or three and more ends (bridles, crowfoots, a buoy at a
  line's end) → point bodies ``point<k>``: a body of the point's mass (1e-3 kg when
  massless), buoyancy ρ·g·V, added mass Ca·ρ·V and Cd·A, rotations held fixed.
- OPTIONS: WtrDpth, rho/WtrDnsty, g/gravity, kBot/kb, cBot/cb (MoorDyn's defaults
  where absent: the deepest point, 1025 kg/m³, 9.80665 m/s² (v1: 9.8), 3e6 Pa/m,
  3e5 Pa·s/m); every other option is listed as ignored in one warning.
- Rods, free bodies, point forces and 3-D seabeds are refused in one line that names
  the file's line and column.

References
----------
Hall, M. (2024), MoorDyn v2 input file documentation,
https://moordyn.readthedocs.io/en/latest/inputs.html.
Hall, M. and Goupee, A. (2015), Validation of a lumped-mass mooring line model with
DeepCwind semisubmersible model test data, Ocean Engineering 104, eq. 1–10.
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

from stochcable.errors import InputError, warn
from stochcable.io.moordyn_file import MoorDynInputError, MoorDynTables, split_tables
from stochcable.io.moordyn_parts import (
    VESSEL,
    MoorDynLine,
    MoorDynPoint,
    parse_bodies,
    parse_line_types,
    parse_lines,
    parse_options,
    parse_points,
)
from stochcable.io.moordyn_scene import (
    POINT_BODY_MASS,
    ZERO_MOTION,
    line_chains,
    point_body_names,
    scene_bodies,
    scene_lines,
)
from stochcable.scene.model import Scene, load_scene

__all__ = ["read_moordyn", "POINT_BODY_MASS", "VESSEL", "ZERO_MOTION"]


def read_moordyn(source: str | Path) -> Scene:
    """Read a MoorDyn input file (v1 or v2) as a scene.

    Parameters
    ----------
    source : str or path
        A path to the file, or the file's text (a ``str`` holding a line break).

    Returns
    -------
    Scene
        The validated scene: no sea (give one to analyse it); prescribed bodies with a
        zero motion RAO.  The mapping is in the module docstring; the lines are named
        ``line1``, ``line2``, ... in the order of their first MoorDyn line.

    Raises
    ------
    InputError
        :class:`~stochcable.io.moordyn_file.MoorDynInputError`, naming the file's
        line and column: a missing section or units row, a wrong column count, an
        unknown attachment or line type, text after END, a part the scene cannot hold
        (rods, free bodies, point forces, a non-linear EA).

    Warns
    -----
    PhysicsWarning
        The options ignored, and EI, CaAx, Cl or differing BA that have no counterpart.
    """
    tables = split_tables(_file_text(source))
    rods = tables.get("rods")
    if rods is not None and rods.rows:
        raise rods.rows[0].error(
            rods.title, 0, "rods are not supported: a scene holds no rods (rigid cylinders)"
        )
    v1 = "LINE DICTIONARY" in tables.sections["line_types"].title.upper()
    ignored_props: dict[str, list[str]] = {}
    types = parse_line_types(tables.sections["line_types"], ignored_props)
    bodies = parse_bodies(tables)
    points = parse_points(tables, bodies)
    lines = parse_lines(tables, types, points)
    opts, ignored = parse_options(tables)
    environment = _environment(tables, opts, points, v1)

    for p in points.values():
        if p.kind == "free" and p.degree == 0:
            warn(f"MoorDyn point {p.pid} (line {p.row.line}) has no line: ignored")

    chains = line_chains(lines, points)
    pbody = point_body_names(points)
    rho, g = environment["rho"], environment["g"]
    line_docs = scene_lines(chains, points, pbody, rho, g)
    body_docs = scene_bodies(points, bodies, pbody, rho)
    beta = _structural_beta(lines)
    _warn_ignored(tables, ignored_props, ignored)
    doc = {
        "title": tables.description[:2000],
        "environment": environment,
        "lines": line_docs,
        "bodies": body_docs,
        "analysis": {"structural_damping": {"beta": beta}},
    }
    try:
        return load_scene(doc)
    except InputError as exc:
        raise _scene_error(exc, tables, chains) from None


def _file_text(source: str | Path) -> str:
    """The file's text: ``source`` itself when it holds a line break, else the file at
    that path."""
    if isinstance(source, Path) or ("\n" not in str(source) and "\r" not in str(source)):
        try:
            return Path(source).read_text(encoding="utf-8", errors="replace")
        except OSError as exc:
            raise InputError(
                "moordyn file", str(source), "-", f"cannot be read ({exc.strerror})"
            ) from None
    return str(source)


def _environment(
    tables: MoorDynTables, opts: dict[str, float], points: dict[int, MoorDynPoint], v1: bool
) -> dict[str, Any]:
    """The scene's environment from the OPTIONS, MoorDyn's defaults where absent: the
    depth WtrDpth or the deepest point's [m], rho 1025 kg/m³, g 9.80665 m/s² (v1: 9.8),
    the seabed's kBot 3e6 Pa/m and cBot 3e5 Pa·s/m."""
    depth = opts.get("wtrdpth", 0.0)
    deepest = max(-float(p.position[2]) for p in points.values())
    depth = max(depth, deepest)
    if depth <= 0:
        raise MoorDynInputError(
            tables.n_lines, 1, "OPTIONS", depth, "no WtrDpth and no point below z = 0"
        )
    rho = opts.get("rho", opts.get("wtrdnsty", 1025.0))
    g = opts.get("g", opts.get("gravity", 9.8 if v1 else 9.80665))
    kb = opts.get("kbot", opts.get("kb", 3.0e6))
    cb = opts.get("cbot", opts.get("cb", 3.0e5))
    return {
        "depth": depth,
        "rho": rho,
        "g": g,
        "seabed": {"stiffness": kb, "damping": cb},
    }


def _structural_beta(lines: list[MoorDynLine]) -> float:
    """The scene's one stiffness-proportional damping β [s]: the smallest of the
    lines', with a warning when they differ."""
    betas = sorted({round(ln.beta, 15) for ln in lines})
    beta = betas[0] if betas else 0.0
    if betas and betas[-1] > betas[0] * (1 + 1e-6) and betas[-1] > 0:
        warn(
            f"MoorDyn's BA/-zeta gives the lines different stiffness-proportional damping "
            f"β = BA/EA from {betas[0]:.4g} s to {betas[-1]:.4g} s; the scene has one β: "
            f"{beta:.4g} s (the smallest) is used",
            stacklevel=3,
        )
    return beta


def _warn_ignored(
    tables: MoorDynTables, ignored_props: dict[str, list[str]], ignored_options: list[str]
) -> None:
    """One warning each for the line-type properties, sections and options the scene
    does not hold."""
    for label, names in ignored_props.items():
        warn(
            f"MoorDyn line types {sorted(set(names))}: {label} has no counterpart in "
            "stochcable and is ignored",
            stacklevel=3,
        )
    others = [t.title for key, t in tables.sections.items() if key.startswith("other:")]
    failure = tables.get("failure")
    if failure is not None and failure.rows:
        others.append(failure.title)
    if others:
        warn(f"MoorDyn sections ignored: {', '.join(others)}", stacklevel=3)
    if ignored_options:
        warn(
            "MoorDyn options ignored (time stepping, initial conditions, waves, outputs; "
            f"used: WtrDpth, rho, g, kBot, cBot): {', '.join(ignored_options)}",
            stacklevel=3,
        )


def _scene_error(
    exc: InputError, tables: MoorDynTables, chains: list[list[tuple[MoorDynLine, bool]]]
) -> MoorDynInputError:
    """A failed check of the scene (a line shorter than its span, an anchor above the
    water) as an error naming the file's row of the line's first MoorDyn line."""
    m = re.search(r"lines\[(\d+)\]", str(exc))
    lines_table = tables.sections["lines"]
    if m is None or int(m.group(1)) >= len(chains):
        return MoorDynInputError(lines_table.line, 1, lines_table.title, "-", str(exc))
    row = chains[int(m.group(1))][0][0].row
    ids = ", ".join(str(ln.lid) for ln, _ in chains[int(m.group(1))])
    return MoorDynInputError(
        row.line, 1, lines_table.title, row.tokens[0], f"MoorDyn line(s) {ids}: {exc}"
    )
