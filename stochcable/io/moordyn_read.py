"""Read a MoorDyn input file (version 1 or 2) into a scene.

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

import math
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from stochcable.errors import InputError, warn
from stochcable.io.moordyn_file import (
    MoorDynInputError,
    MoorDynTables,
    Row,
    Table,
    split_tables,
)
from stochcable.scene.model import Scene, load_scene

__all__ = ["read_moordyn", "POINT_BODY_MASS", "VESSEL", "ZERO_MOTION"]

#: Mass given to a point body whose MoorDyn point is massless (a body needs a mass). [kg]
POINT_BODY_MASS = 1e-3
#: Name of the prescribed body that carries the Coupled/Vessel points.
VESSEL = "vessel"
#: The motion of a prescribed body read from a file: zero RAO (MoorDyn files carry
#: no motion); replaced by the user's RAO table.
ZERO_MOTION: dict[str, Any] = {
    "omega": [0.0, 100.0],
    "surge": {"re": [0.0, 0.0], "im": [0.0, 0.0]},
}

_USED_OPTIONS = {"wtrdpth", "rho", "wtrdnsty", "g", "gravity", "kbot", "kb", "cbot", "cb"}
_ATTACH = re.compile(r"^([A-Za-z]*)(\d+)([A-Za-z]*)$")
_TYPE_WORD = re.compile(r"^([A-Za-z]+)(\d*)$")


@dataclass
class _Point:
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
class _LineRow:
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


def _line_types(table: Table, ignored: dict[str, list[str]]) -> dict[str, tuple[dict, float, Row]]:
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


def _bodies(tables: MoorDynTables) -> dict[int, tuple[str, np.ndarray, np.ndarray, Row]]:
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


def _points(tables: MoorDynTables, bodies: dict) -> dict[int, _Point]:
    table = tables.get("points")
    assert table is not None  # split_tables checks it
    sec = table.title
    out: dict[int, _Point] = {}
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
        p = _Point(pid, "", xyz, mass, vol, cda, ca, row)
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
        else:
            raise row.error(
                sec,
                1,
                f"unknown point attachment {row.tokens[1]!r}: expected Fixed, Coupled "
                "(Vessel), Free (Connect) or Body<n>",
            )
        out[pid] = p
    return out


def _lines(tables: MoorDynTables, types: dict, points: dict[int, _Point]) -> list[_LineRow]:
    table = tables.get("lines")
    assert table is not None
    sec = table.title
    low = [n.lower() for n in table.names]
    v1 = (len(low) > 2 and ("len" in low[2])) or (
        len(low) > 4 and low[4].startswith("node") and "PROPERTIES" in sec.upper()
    )
    ia, ib, il, ins = (4, 5, 2, 3) if v1 else (2, 3, 4, 5)
    out: list[_LineRow] = []
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
        out.append(_LineRow(lid, seg, ends[0], ends[1], row, beta))
    if not out:
        raise MoorDynInputError(table.line, 1, sec, sec, "no lines are defined")
    return out


def _options(tables: MoorDynTables) -> tuple[dict[str, float], list[str]]:
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


def _chains(lines: list[_LineRow], points: dict[int, _Point]) -> list[list[tuple[_LineRow, bool]]]:
    """Lines joined at free points of exactly two line ends: the chains, each a list of
    (line, reversed) from one end to the other."""
    at: dict[int, list[tuple[_LineRow, str]]] = {}
    for ln in lines:
        at.setdefault(ln.a, []).append((ln, "a"))
        at.setdefault(ln.b, []).append((ln, "b"))

    def merge(pid: int) -> bool:
        p = points[pid]
        return p.kind == "free" and p.degree == 2

    done: set[int] = set()
    chains = []
    for ln in lines:
        if ln.lid in done:
            continue
        # walk to the chain's start from ln's end a
        cur, end = ln, "a"
        seen = {ln.lid}
        while True:
            pid = cur.a if end == "a" else cur.b
            if not merge(pid):
                break
            other = next((o, e) for o, e in at[pid] if o is not cur or e != end)
            nxt, nend = other
            if nxt.lid in seen:
                raise points[pid].row.error(
                    "POINTS",
                    1,
                    "the free points of two lines each close a ring of lines: "
                    "a ring has no end to hold it",
                )
            seen.add(nxt.lid)
            cur, end = nxt, ("b" if nend == "a" else "a")
        # cur's `end` is the chain's start: walk forward
        chain = []
        start_end = end
        while True:
            rev = start_end == "b"
            chain.append((cur, rev))
            done.add(cur.lid)
            far = cur.a if rev else cur.b
            if not merge(far):
                break
            nxt, nend = next(
                (o, e) for o, e in at[far] if o is not cur or e != ("a" if rev else "b")
            )
            cur, start_end = nxt, nend
        chains.append(chain)
    chains.sort(key=lambda c: min(ln.lid for ln, _ in c))
    return chains


def _fmt_ids(ids: list[int]) -> str:
    return ", ".join(str(i) for i in ids)


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
    if isinstance(source, Path) or ("\n" not in str(source) and "\r" not in str(source)):
        try:
            text = Path(source).read_text(encoding="utf-8", errors="replace")
        except OSError as exc:
            raise InputError(
                "moordyn file", str(source), "-", f"cannot be read ({exc.strerror})"
            ) from None
    else:
        text = str(source)
    tables = split_tables(text)
    rods = tables.get("rods")
    if rods is not None and rods.rows:
        raise rods.rows[0].error(
            rods.title, 0, "rods are not supported: a scene holds no rods (rigid cylinders)"
        )
    v1 = "LINE DICTIONARY" in tables.sections["line_types"].title.upper()
    ignored_props: dict[str, list[str]] = {}
    types = _line_types(tables.sections["line_types"], ignored_props)
    bodies = _bodies(tables)
    points = _points(tables, bodies)
    lines = _lines(tables, types, points)
    opts, ignored = _options(tables)
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

    for p in points.values():
        if p.kind == "free" and p.degree == 0:
            warn(f"MoorDyn point {p.pid} (line {p.row.line}) has no line: ignored")

    chains = _chains(lines, points)
    # the point bodies: free points of 1 or >= 3 line ends, by point ID
    pbody = {
        p.pid: f"point{k}"
        for k, p in enumerate(
            (p for p in points.values() if p.kind == "free" and p.degree not in (0, 2)), start=1
        )
    }
    planar = all(abs(float(p.position[1])) < 1e-9 for p in points.values())
    z_of = {pid: float(p.position[2]) for pid, p in points.items()}

    def end_doc(pid: int) -> dict[str, Any]:
        p = points[pid]
        if p.kind == "fixed":
            return {"position": [float(v) for v in p.position]}
        if p.kind == "coupled":
            return {"attach": {"body": p.body, "point": list(p.point)}}
        return {"attach": {"body": pbody[pid], "point": [0.0, 0.0, 0.0]}}

    line_docs = []
    for k, chain in enumerate(chains, start=1):
        seq = [(ln, rev) for ln, rev in chain]
        first, frev = seq[0]
        last, lrev = seq[-1]
        pa = first.b if frev else first.a
        pb = last.a if lrev else last.b
        ka, kb_ = points[pa].kind, points[pb].kind
        flip = (kb_ == "fixed" and ka != "fixed") or (
            (ka == "fixed") == (kb_ == "fixed") and z_of[pb] < z_of[pa] - 1e-12
        )
        if flip:
            seq = [(ln, not rev) for ln, rev in reversed(seq)]
            pa, pb = pb, pa
        segments, attachments = [], []
        s = 0.0
        for j, (ln, rev) in enumerate(seq):
            segments.append(dict(ln.segment))
            s += ln.segment["length"]
            if j < len(seq) - 1:
                p = points[ln.a if rev else ln.b]
                if p.mass > 0 or p.volume > 0 or p.cda > 0:
                    attachments.append(
                        {
                            "at": s,
                            "mass": p.mass,
                            "buoyancy": rho * g * p.volume,
                            "added_mass": p.ca * rho * p.volume,
                            "drag_area": p.cda,
                        }
                    )
        line_docs.append(
            {
                "name": f"line{k}",
                "end_a": end_doc(pa),
                "end_b": end_doc(pb),
                "segments": segments,
                "attachments": attachments,
            }
        )

    body_docs = []
    prescribed = sorted({p.body for p in points.values() if p.kind == "coupled" and p.degree})
    coupled_ids = [b for b, v in bodies.items() if v[0] == "coupled"]
    for name in prescribed:
        pos = [0.0, 0.0, 0.0]
        if name != VESSEL:
            pos = [float(v) for v in bodies[coupled_ids[int(name[4:]) - 1]][1]]
        body_docs.append({"name": name, "position": pos, "mass": 1.0, "prescribed": ZERO_MOTION})
    for pid, name in pbody.items():
        p = points[pid]
        doc: dict[str, Any] = {
            "name": name,
            "position": [float(v) for v in p.position],
            "mass": p.mass if p.mass > 0 else POINT_BODY_MASS,
            "drag_area": [p.cda] * 3,
            "fixed_dofs": ["pitch"] if planar else ["roll", "pitch", "yaw"],
        }
        if p.volume > 0:
            doc["displaced_volume"] = p.volume
            a = p.ca * rho * p.volume
            if a > 0:
                doc["added_mass"] = [
                    [a if (i == j and i < 3) else 0.0 for j in range(6)] for i in range(6)
                ]
        body_docs.append(doc)

    betas = sorted({round(ln.beta, 15) for ln in lines})
    beta = betas[0] if betas else 0.0
    if betas and betas[-1] > betas[0] * (1 + 1e-6) and betas[-1] > 0:
        warn(
            f"MoorDyn's BA/-zeta gives the lines different stiffness-proportional damping "
            f"β = BA/EA from {betas[0]:.4g} s to {betas[-1]:.4g} s; the scene has one β: "
            f"{beta:.4g} s (the smallest) is used"
        )
    for label, names in ignored_props.items():
        warn(
            f"MoorDyn line types {sorted(set(names))}: {label} has no counterpart in "
            "stochcable and is ignored"
        )
    others = [t.title for key, t in tables.sections.items() if key.startswith("other:")]
    failure = tables.get("failure")
    if failure is not None and failure.rows:
        others.append(failure.title)
    if others:
        warn(f"MoorDyn sections ignored: {', '.join(others)}")
    if ignored:
        warn(
            "MoorDyn options ignored (time stepping, initial conditions, waves, outputs; "
            f"used: WtrDpth, rho, g, kBot, cBot): {', '.join(ignored)}"
        )
    doc = {
        "title": tables.description[:2000],
        "environment": {
            "depth": depth,
            "rho": rho,
            "g": g,
            "seabed": {"stiffness": kb, "damping": cb},
        },
        "lines": line_docs,
        "bodies": body_docs,
        "analysis": {"structural_damping": {"beta": beta}},
    }
    try:
        return load_scene(doc)
    except InputError as exc:
        # a check of the scene (a line shorter than its span, an anchor above the
        # water): name the file's row of the line's first MoorDyn line
        m = re.search(r"lines\[(\d+)\]", str(exc))
        lines_table = tables.sections["lines"]
        if m is None or int(m.group(1)) >= len(chains):
            raise MoorDynInputError(lines_table.line, 1, lines_table.title, "-", str(exc)) from None
        row = chains[int(m.group(1))][0][0].row
        ids = ", ".join(str(ln.lid) for ln, _ in chains[int(m.group(1))])
        raise MoorDynInputError(
            row.line, 1, lines_table.title, row.tokens[0], f"MoorDyn line(s) {ids}: {exc}"
        ) from None
