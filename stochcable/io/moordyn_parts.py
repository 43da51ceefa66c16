"""The parts of a MoorDyn input file as records, checked row by row: the line types
(→ segment properties and BA/−ζ), bodies, points, lines (→ their ends and segment) and
options.  :mod:`stochcable.io.moordyn_scene` maps them to a scene's lines and bodies;
:func:`stochcable.io.moordyn_read.read_moordyn` runs the steps.

References
----------
Hall, M. (2024), MoorDyn v2 input file documentation,
https://moordyn.readthedocs.io/en/latest/inputs.html.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from typing import Any

import numpy as np

from stochcable.errors import warn
from stochcable.io.moordyn_file import MoorDynInputError, MoorDynTables, Row, Table

__all__ = [
    "VESSEL",
    "MoorDynPoint",
    "MoorDynLine",
    "parse_line_types",
    "parse_bodies",
    "parse_points",
    "parse_lines",
    "parse_options",
]

#: Name of the prescribed body that carries the Coupled/Vessel points.
VESSEL = "vessel"

_USED_OPTIONS = {"wtrdpth", "rho", "wtrdnsty", "g", "gravity", "kbot", "kb", "cbot", "cb"}
_ATTACH = re.compile(r"^([A-Za-z]*)(\d+)([A-Za-z]*)$")
_TYPE_WORD = re.compile(r"^([A-Za-z]+)(\d*)$")


@dataclass
class MoorDynPoint:
    """A MoorDyn point: its kind (fixed, coupled, free), static global position, the
    mass, volume, CdA and Ca it carries, and (filled in by :func:`parse_lines`) the
    number of line ends it joins."""

    pid: int
    kind: str  # fixed | coupled | free
    position: np.ndarray  # global, static pose
    mass: float
    volume: float
    cda: float
    ca: float
    row: Row
    body: str = ""  # coupled: the prescribed body's name
    point: tuple[float, float, float] = (0.0, 0.0, 0.0)  # coupled: relative to body
    degree: int = 0


@dataclass
class MoorDynLine:
    """A MoorDyn line: its ID, the scene segment it becomes, its end points ``a``, ``b``
    (point IDs) and its stiffness-proportional damping β. [s]"""

    lid: int
    segment: dict[str, Any]
    a: int
    b: int
    row: Row
    beta: float


def _type_columns(table: Table) -> dict[str, int]:
    """Column index of each line-type quantity.  MoorDyn reads the columns by position
    (MoorDyn-C 2.7 ``readLineProps``), whatever the names row says, and so does this:
    v2 (LINE TYPES) Name Diam Mass/m EA BA/-zeta EI Cd Ca CdAx CaAx [Cl [dF cF]];
    v1 (LINE DICTIONARY) LineType Diam MassDenInAir EA BA/-zeta [EI] Can Cat Cdn Cdt.
    A v2 table whose names row gives v1's order (Can Cat Cdn Cdt) gets a warning."""
    low = [x.lower() for x in table.names]
    if len(low) == 9:  # v1 without EI, also under MoorDyn-F 1.x's "LINE TYPES" header
        return {"d": 1, "mass": 2, "ea": 3, "ba": 4, "can": 5, "cat": 6, "cdn": 7, "cdt": 8}
    if "DICTIONARY" in table.title.upper():
        if "ei" in low or len(low) >= 10:
            return {
                "d": 1,
                "mass": 2,
                "ea": 3,
                "ba": 4,
                "ei": 5,
                "can": 6,
                "cat": 7,
                "cdn": 8,
                "cdt": 9,
            }
        return {"d": 1, "mass": 2, "ea": 3, "ba": 4, "can": 5, "cat": 6, "cdn": 7, "cdt": 8}
    if len(low) >= 10 and low[6] == "can" and low[8] == "cdn":
        warn(
            f"MoorDyn file line {table.line + 1}: the LINE TYPES names row gives v1's order "
            f"({' '.join(table.names[6:10])}); MoorDyn reads these columns by position as "
            "Cd Ca CdAx CaAx, and so does stochcable"
        )
    cols = {"d": 1, "mass": 2, "ea": 3, "ba": 4, "ei": 5, "cdn": 6, "can": 7, "cdt": 8, "cat": 9}
    if len(low) >= 11:
        cols["cl"] = 10
    return cols


def _check_columns(row: Row, table: Table, minimum: int) -> None:
    need = max(minimum, len(table.names))
    if len(row.tokens) < need:
        raise row.error(
            table.title,
            len(row.tokens),
            f"{len(row.tokens)} columns, but the section has {need} "
            f"({' '.join(table.names) or 'see the MoorDyn manual'})",
        )


def parse_line_types(
    table: Table, ignored: dict[str, list[str]]
) -> dict[str, tuple[dict, float, Row]]:
    """LINE TYPES (LINE DICTIONARY): name → (segment properties, BA/−ζ, row).  The
    properties without counterpart that are non-zero go to ``ignored`` (label → type
    names)."""
    cols = _type_columns(table)
    out: dict[str, tuple[dict, float, Row]] = {}
    sec = table.title
    for row in table.rows:
        _check_columns(row, table, max(cols.values()) + 1)
        name = row.tokens[0]
        if name in out:
            raise row.error(sec, 0, f"line type {name!r} is defined twice")
        ea_tok = row.tokens[cols["ea"]]
        if "|" in ea_tok or not _is_number(ea_tok):
            raise row.error(
                sec,
                cols["ea"],
                "a non-linear or visco-elastic EA (a table file or 'a|b' values) is not "
                "supported: give the EA at the static tension as one number",
            )
        ba_tok = row.tokens[cols["ba"]]
        if "|" in ba_tok:
            raise row.error(sec, cols["ba"], "a visco-elastic BA ('a|b') is not supported")
        vals = {k: row.number(sec, i, k) for k, i in cols.items()}
        for k, label in (("d", "Diam"), ("mass", "Mass/m"), ("ea", "EA")):
            if vals[k] <= 0:
                raise row.error(sec, cols[k], f"{label} must be > 0")
        for k, label in (("cdn", "Cd"), ("can", "Ca"), ("cdt", "CdAx")):
            if vals[k] < 0:
                raise row.error(sec, cols[k], f"{label} must be >= 0")
        for k, label in (
            ("ei", "EI (bending stiffness)"),
            ("cat", "CaAx (axial added mass)"),
            ("cl", "Cl (VIV lift)"),
        ):
            if vals.get(k, 0.0) != 0.0:
                ignored.setdefault(label, []).append(name)
        seg = {
            "diameter": vals["d"],
            "mass": vals["mass"],
            "ea": vals["ea"],
            "cd_normal": vals["cdn"],
            "ca_normal": vals["can"],
            "cd_axial": vals["cdt"],
        }
        out[name] = (seg, vals["ba"], row)
    if not out:
        raise MoorDynInputError(table.line, 1, sec, sec, "no line types are defined")
    return out


def _is_number(tok: str) -> bool:
    try:
        float(tok)
    except ValueError:
        return False
    return True


def _rotation(r: float, p: float, y: float) -> np.ndarray:
    """MoorDyn's body orientation (roll, pitch, yaw in degrees): R = Rz(y)·Ry(p)·Rx(r)."""
    r, p, y = (math.radians(v) for v in (r, p, y))
    cr, sr, cp, sp, cy, sy = (
        math.cos(r),
        math.sin(r),
        math.cos(p),
        math.sin(p),
        math.cos(y),
        math.sin(y),
    )
    rx = np.array([[1, 0, 0], [0, cr, -sr], [0, sr, cr]])
    ry = np.array([[cp, 0, sp], [0, 1, 0], [-sp, 0, cp]])
    rz = np.array([[cy, -sy, 0], [sy, cy, 0], [0, 0, 1]])
    return rz @ ry @ rx


def parse_bodies(tables: MoorDynTables) -> dict[int, tuple[str, np.ndarray, np.ndarray, Row]]:
    """MoorDyn bodies: id → (kind fixed|coupled, position, rotation matrix, row)."""
    table = tables.get("bodies")
    out: dict[int, tuple[str, np.ndarray, np.ndarray, Row]] = {}
    if table is None:
        return out
    sec = table.title
    for k, row in enumerate(table.rows, start=1):
        _check_columns(row, table, 8)
        bid = row.integer(sec, 0, "ID")
        if bid != k:
            raise row.error(sec, 0, f"body IDs must be 1, 2, 3, ... in order (expected {k})")
        word = row.tokens[1].upper()
        if word in ("FIXED", "FIX", "ANCHOR"):
            kind = "fixed"
        elif word in ("COUPLED", "VESSEL", "VES", "CPLD"):
            kind = "coupled"
        else:
            raise row.error(
                sec,
                1,
                f"a {row.tokens[1]} body is not supported: a scene holds fixed and coupled "
                "(prescribed) MoorDyn bodies only",
            )
        pos = np.array(
            [row.number(sec, i, "X0 Y0 Z0"[3 * (i - 2) : 3 * (i - 2) + 2]) for i in (2, 3, 4)]
        )
        rot = _rotation(*(row.number(sec, i, "r0/p0/y0") for i in (5, 6, 7)))
        out[bid] = (kind, pos, rot, row)
    return out


def parse_points(tables: MoorDynTables, bodies: dict) -> dict[int, MoorDynPoint]:
    """POINTS (CONNECTION PROPERTIES): ID → point; a body's points placed by its pose."""
    table = tables.get("points")
    assert table is not None  # split_tables checks it
    sec = table.title
    out: dict[int, MoorDynPoint] = {}
    coupled_bodies = [b for b, v in bodies.items() if v[0] == "coupled"]
    for k, row in enumerate(table.rows, start=1):
        _check_columns(row, table, 9)
        pid = row.integer(sec, 0, "ID")
        if pid != k:
            raise row.error(sec, 0, f"point IDs must be 1, 2, 3, ... in order (expected {k})")
        xyz = np.array([row.number(sec, i, "XYZ"[i - 2]) for i in (2, 3, 4)])
        mass = row.number(sec, 5, "Mass")
        vol = row.number(sec, 6, "Volume")
        if len(row.tokens) >= 12 and len(table.names) != 9:
            force = [row.number(sec, i, "F" + "XYZ"[i - 7]) for i in (7, 8, 9)]
            cda, ca, ica = row.number(sec, 10, "CdA"), row.number(sec, 11, "Ca"), 10
        else:
            force = [0.0, 0.0, 0.0]
            cda, ca, ica = row.number(sec, 7, "CdA"), row.number(sec, 8, "Ca"), 7
        for v, i, label in (
            (mass, 5, "Mass"),
            (vol, 6, "Volume"),
            (cda, ica, "CdA"),
            (ca, ica + 1, "Ca"),
        ):
            if v < 0:
                raise row.error(sec, i, f"{label} must be >= 0")
        m = _TYPE_WORD.match(row.tokens[1])
        word = m.group(1).upper() if m else row.tokens[1].upper()
        num = m.group(2) if m else ""
        p = MoorDynPoint(pid, "", xyz, mass, vol, cda, ca, row)
        if word in ("FIXED", "FIX", "ANCHOR"):
            p.kind = "fixed"
        elif word in ("VESSEL", "VES", "COUPLED", "CPLD", "FAIRLEAD"):
            p.kind, p.body, p.point = "coupled", VESSEL, tuple(float(v) for v in xyz)
        elif word in ("CONNECT", "CON", "FREE", "POINT"):
            p.kind = "free"
            if any(f != 0.0 for f in force):
                raise row.error(
                    sec, 7, "a free point with an external force FX/FY/FZ is not supported"
                )
        elif word == "BODY":
            bid = int(num) if num else 0
            if bid not in bodies:
                raise row.error(
                    sec, 1, f"attachment {row.tokens[1]!r}: there is no body {num or '(no number)'}"
                )
            kind, bpos, rot, _ = bodies[bid]
            rel = rot @ xyz
            p.position = bpos + rel
            if kind == "fixed":
                p.kind = "fixed"
            else:
                p.kind = "coupled"
                p.body = f"body{coupled_bodies.index(bid) + 1}"
                p.point = tuple(float(v) for v in rel)
        elif word == "TURBINE":
            raise row.error(
                sec,
                1,
                "Turbine<n> points (FAST.Farm farm-level mooring) are not supported: "
                "their X, Y, Z are relative to turbine n, placed by the FAST.Farm input",
            )
        else:
            raise row.error(
                sec,
                1,
                f"unknown point attachment {row.tokens[1]!r}: expected Fixed, Coupled "
                "(Vessel), Free (Connect) or Body<n>",
            )
        out[pid] = p
    return out


def parse_lines(
    tables: MoorDynTables, types: dict, points: dict[int, MoorDynPoint]
) -> list[MoorDynLine]:
    """LINES (LINE PROPERTIES), v1 or v2 column order; counts each point's line ends."""
    table = tables.get("lines")
    assert table is not None
    sec = table.title
    low = [n.lower() for n in table.names]
    v1 = (len(low) > 2 and ("len" in low[2])) or (
        len(low) > 4 and low[4].startswith("node") and "PROPERTIES" in sec.upper()
    )
    ia, ib, il, ins = (4, 5, 2, 3) if v1 else (2, 3, 4, 5)
    out: list[MoorDynLine] = []
    rods = tables.get("rods")
    for k, row in enumerate(table.rows, start=1):
        _check_columns(row, table, 6)
        lid = row.integer(sec, 0, "ID")
        if lid != k:
            raise row.error(sec, 0, f"line IDs must be 1, 2, 3, ... in order (expected {k})")
        tname = row.tokens[1]
        if tname not in types:
            raise row.error(sec, 1, f"unknown line type; the LINE TYPES are {sorted(types)}")
        ends = []
        for i in (ia, ib):
            tok = row.tokens[i]
            m = _ATTACH.match(tok)
            if m is None:
                raise row.error(
                    sec, i, "unknown attachment: expected a point number, P<n> or R<n>A/B"
                )
            let, num, suffix = m.group(1).upper(), int(m.group(2)), m.group(3).upper()
            if let in ("R", "ROD"):
                if rods is None or num < 1 or num > len(rods.rows):
                    raise row.error(sec, i, f"unknown attachment: there is no rod {num}")
                raise row.error(
                    sec,
                    i,
                    "a line attached to a rod end is not supported: a scene holds no rods "
                    f"(rod {num}{suffix})",
                )
            if let not in ("", "C", "CON", "P", "POINT") or suffix:
                raise row.error(
                    sec, i, "unknown attachment: expected a point number, P<n> or R<n>A/B"
                )
            if num not in points:
                raise row.error(sec, i, f"unknown attachment: there is no point {num}")
            ends.append(num)
        length = row.number(sec, il, "UnstrLen")
        nseg = row.integer(sec, ins, "NumSegs")
        if length <= 0:
            raise row.error(sec, il, "UnstrLen must be > 0")
        if nseg < 1:
            raise row.error(sec, ins, "NumSegs must be >= 1")
        if ends[0] == ends[1]:
            raise row.error(sec, ib, "the line's two ends are at the same point")
        seg_props, ba, _ = types[tname]
        seg = {**seg_props, "length": length, "elements": nseg}
        if ba >= 0:
            beta = ba / seg["ea"]
        else:
            beta = -ba * (length / nseg) * math.sqrt(seg["mass"] / seg["ea"])
        for e in ends:
            points[e].degree += 1
        out.append(MoorDynLine(lid, seg, ends[0], ends[1], row, beta))
    if not out:
        raise MoorDynInputError(table.line, 1, sec, sec, "no lines are defined")
    return out


def parse_options(tables: MoorDynTables) -> tuple[dict[str, float], list[str]]:
    """OPTIONS: the ones used (lower-case name → value) and the names of the others."""
    table = tables.get("options")
    used: dict[str, float] = {}
    ignored: list[str] = []
    if table is None:
        return used, ignored
    for row in table.rows:
        if len(row.tokens) < 2:
            raise row.error(table.title, len(row.tokens), "an option row is 'value name'")
        name = row.tokens[1].lower()
        if name in _USED_OPTIONS:
            used[name] = row.number(table.title, 0, row.tokens[1])
        else:
            ignored.append(row.tokens[1])
    return used, ignored
