"""Write a scene as a MoorDyn v2 input file.

The inverse of :mod:`stochcable.io.moordyn_read` (read → write → read gives the same
scene): each segment becomes a MoorDyn line, joined to the next at a Free point that
carries the clump weights and buoys attached there; an attachment inside a segment
splits it (its elements shared in proportion).  Fixed ends → Fixed points; ends on a
prescribed body → Coupled points (the body ``vessel``: at the body position plus the
attachment point; another prescribed body: a Coupled MoorDyn body and its Body<k>
points); ends on a point body → its Free point; ends with a prescribed ``motion`` →
Coupled points (the motion itself is not written: MoorDyn takes it from its driver).
The stiffness-proportional structural damping β becomes BA = β·EA per line type.

Not expressible, refused: a segment's ``weight`` override (MoorDyn derives the weight
from Mass/m and Diam) and free bodies that are not point bodies.
"""

from __future__ import annotations

from collections.abc import Collection
from dataclasses import dataclass
from typing import Any

import numpy as np

from stochcable import validation as _v
from stochcable.errors import InputError, warn
from stochcable.io.moordyn_parts import VESSEL
from stochcable.io.moordyn_pieces import line_pieces, static_node_positions
from stochcable.io.moordyn_scene import POINT_BODY_MASS, is_point_body
from stochcable.scene.model import Line, Scene, load_scene

__all__ = ["write_moordyn", "is_point_body"]


def _f(v: float) -> str:
    """A number in its shortest form that reads back exactly."""
    v = float(v)
    return str(int(v)) if v.is_integer() and abs(v) < 1e15 else repr(v)


def write_moordyn(
    scene: Scene | dict | str,
    *,
    dt: float = 1e-3,
    internal_damping: float | None = None,
    coupled_ends: Collection[tuple[str, str]] = (),
    ic_threshold: float = 1e-6,
    ic_tmax: float = 300.0,
    scheme: str = "RK4",
    static_positions: bool = True,
    ic_dynamic: bool = False,
) -> str:
    """The MoorDyn v2 input file of a scene.

    Parameters
    ----------
    scene : Scene, mapping or JSON
        The scene (its sea and analysis settings other than the structural damping
        are not written).
    dt : float, default 1e-3
        MoorDyn's integration step ``dtM``. [s]
    internal_damping : float, optional
        ``BA`` of every line type: >= 0 a coefficient [N·s], < 0 minus a damping ratio
        [-].  Default: β·EA, β the scene's stiffness-proportional structural damping.
    coupled_ends : collection of (line name, "end_a" or "end_b")
        Fixed ends written as Coupled points (a driver moves them).
    ic_threshold : float, default 1e-6
        ``threshIC``: convergence of MoorDyn's initial-condition solve. [-]
    ic_tmax : float, default 300
        ``TmaxIC``: its longest pseudo-time. [s]
    scheme : str, default "RK4"
        ``tScheme`` (see :func:`stochcable.reference.moordyn.moordyn_input_file`).
    static_positions : bool, default True
        Place the free points at stochcable's static solution (else on the straight
        line between the ends); MoorDyn starts its own solve from them.
    ic_dynamic : bool, default False
        ``ICgenDynamic 1``: MoorDyn's initial conditions by dynamic relaxation (drag
        scaled by ``ICDfac``, converged when the fairlead tensions change by less than
        ``threshIC``) instead of its stationary solver (MoorDyn-C 2.x's default, whose
        relaxation of a long grounded chain is slow: docs/manual/moordyn.md).

    Returns
    -------
    str
        The file's text.  Points: the point bodies first, then per line end_a, the
        joints and end_b; MoorDyn lines in the order of the scene's lines and segments.

    Raises
    ------
    InputError
        A segment with a ``weight`` override, or a free body that is not a point body.
    """
    sc = load_scene(scene)
    env = sc.environment
    dt = _v.positive("dt", dt, "s")
    ic_threshold = _v.positive("ic_threshold", ic_threshold, "-")
    ic_tmax = _v.positive("ic_tmax", ic_tmax, "s")
    coupled = set(coupled_ends)
    if sc.analysis.structural_damping.alpha > 0:
        warn("structural_damping.alpha (mass-proportional) has no MoorDyn counterpart: not written")
    positions, poses = static_node_positions(sc) if static_positions else ({}, {})
    types, type_rows = _line_type_rows(sc, internal_damping)
    points = _PointRows()
    body_rows, body_point, md_body = _body_rows(sc, poses, points)
    ends = _Ends(sc, coupled, body_point, md_body, points)
    line_rows = _line_rows(sc, types, positions, ends, points)
    options = [
        f"{_f(dt)} dtM",
        f"{_f(env.seabed.stiffness)} kBot",
        f"{_f(env.seabed.damping)} cBot",
        f"{_f(env.depth)} WtrDpth",
        f"{_f(env.rho)} rho",
        f"{_f(env.g)} g",
        "0 WaveKin",
        "0 Currents",
        f"{scheme} tScheme",
        f"{_f(ic_threshold)} threshIC",
        f"{_f(ic_tmax)} TmaxIC",
        *(["1 ICgenDynamic"] if ic_dynamic else []),
        "0 writeLog",
        "1 disableOutput",
    ]
    text = _file_text(sc.title, type_rows, body_rows, points.rows, line_rows, options)
    if env.current:
        warn("the scene's current is not written (MoorDyn reads currents from its own files)")
    return text


def _type_key(sg: Any) -> tuple[float, ...]:
    """The properties that make a MoorDyn line type."""
    return (sg.diameter, sg.mass, sg.ea, sg.cd_normal, sg.ca_normal, sg.cd_axial)


def _line_type_rows(
    sc: Scene, internal_damping: float | None
) -> tuple[dict[tuple[float, ...], str], list[str]]:
    """LINE TYPES: a type per distinct segment (``type1``, ``type2``, ...) and its rows;
    BA = ``internal_damping``, else β·EA."""
    beta = sc.analysis.structural_damping.beta
    types: dict[tuple[float, ...], str] = {}
    type_rows = []
    for i, ln in enumerate(sc.lines):
        for j, sg in enumerate(ln.segments):
            if sg.weight is not None:
                raise InputError(
                    f"lines[{i}].segments[{j}].weight",
                    sg.weight,
                    "N/m",
                    "cannot be written to MoorDyn (it derives the weight from Mass/m and "
                    "Diam): remove it and give mass and diameter",
                )
            key = _type_key(sg)
            if key not in types:
                name = f"type{len(types) + 1}"
                types[key] = name
                ba = internal_damping if internal_damping is not None else beta * sg.ea
                type_rows.append(
                    f"{name} {_f(sg.diameter)} {_f(sg.mass)} {_f(sg.ea)} {_f(ba)} 0 "
                    f"{_f(sg.cd_normal)} {_f(sg.ca_normal)} {_f(sg.cd_axial)} 0"
                )
    return types, type_rows


class _PointRows:
    """The POINTS section: its rows, a point's ID its place in the list."""

    def __init__(self) -> None:
        self.rows: list[str] = []

    def add(self, kind: str, xyz: Any, *props: float) -> int:
        """Add a point at ``xyz`` [m], ``props`` its mass [kg], volume [m³], CdA [m²]
        and Ca [-] (zero where not given); its ID."""
        pid = len(self.rows) + 1
        numbers = [xyz[0], xyz[1], xyz[2], *props, *[0.0] * (4 - len(props))]
        self.rows.append(f"{pid} {kind} " + " ".join(_f(v) for v in numbers))
        return pid


@dataclass(frozen=True)
class _Ends:
    """The points of the scene lines' ends: a point body's Free point; a Body<k> point
    of a Coupled MoorDyn body; a Coupled point (on ``vessel``, with a prescribed motion
    or listed in ``coupled``); else a Fixed point."""

    sc: Scene
    coupled: set[tuple[str, str]]
    body_point: dict[str, int]
    md_body: dict[str, int]
    points: _PointRows

    def point(self, ln: Line, end: str) -> int:
        """The point ID of ``ln``'s ``end`` ("end_a" or "end_b"), added if new."""
        e = getattr(ln, end)
        if e.attach is not None:
            name = e.attach.body
            if name in self.body_point:
                return self.body_point[name]
            body = self.sc.body(name)
            if name in self.md_body:
                return self.points.add(f"Body{self.md_body[name]}", e.attach.point)
            return self.points.add(
                "Coupled", np.asarray(body.position) + np.asarray(e.attach.point)
            )
        if e.motion is not None or (ln.name, end) in self.coupled:
            return self.points.add("Coupled", e.position)
        return self.points.add("Fixed", e.position)


def _body_rows(
    sc: Scene, poses: dict[str, np.ndarray], points: _PointRows
) -> tuple[list[str], dict[str, int], dict[str, int]]:
    """BODIES (a Coupled body per prescribed body other than ``vessel``) and the point
    bodies' Free points: the rows, point body name → point ID, prescribed body name →
    MoorDyn body ID."""
    env = sc.environment
    body_point: dict[str, int] = {}
    body_rows: list[str] = []
    md_body: dict[str, int] = {}
    for i, b in enumerate(sc.bodies):
        if b.prescribed is not None:
            if b.name != VESSEL:
                k = len(body_rows) + 1
                md_body[b.name] = k
                p = b.position
                body_rows.append(
                    f"{k} Coupled {_f(p[0])} {_f(p[1])} {_f(p[2])} 0 0 0 {_f(b.mass)} 0 0 0 0 0"
                )
            if b.prescribed.model_dump(exclude_none=True) != {
                "omega": (0.0, 100.0),
                "surge": {"re": (0.0, 0.0), "im": (0.0, 0.0)},
            }:
                warn(
                    f"bodies[{i}] ({b.name!r}): its prescribed motion is not written "
                    "(MoorDyn takes the motion of Coupled points from its driver)",
                    stacklevel=3,
                )
            continue
        if not is_point_body(b):
            raise InputError(
                f"bodies[{i}]",
                b.name,
                "-",
                "a free rigid body cannot be written to MoorDyn here (only point "
                "bodies: rotations held fixed, no inertia or hydrodynamic table)",
            )
        vol = b.displaced_volume or 0.0
        a = 0.0 if b.added_mass is None else b.added_mass[0][0]
        ca = a / (env.rho * vol) if vol > 0 else 0.0
        if vol == 0 and a > 0:
            warn(
                f"bodies[{i}] ({b.name!r}): added mass without volume is not written", stacklevel=3
            )
        mass = 0.0 if b.mass <= POINT_BODY_MASS * (1 + 1e-12) else b.mass
        where = poses.get(b.name, b.position)
        body_point[b.name] = points.add("Free", where, mass, vol, b.drag_area[0], ca)
    return body_rows, body_point, md_body


def _line_rows(
    sc: Scene,
    types: dict[tuple[float, ...], str],
    positions: dict[str, tuple[np.ndarray, np.ndarray]],
    ends: _Ends,
    points: _PointRows,
) -> list[str]:
    """LINES: per scene line, a MoorDyn line per piece from end_a through the Free
    joint points (at the static positions, else on the straight line) to end_b."""
    line_rows: list[str] = []
    for ln in sc.lines:
        pieces, joints = line_pieces(ln)
        prev = ends.point(ln, "end_a")
        xa, xb = sc.end_position(ln, "end_a"), sc.end_position(ln, "end_b")
        for k, (seg, length, elements) in enumerate(pieces):
            if k < len(pieces) - 1:
                s, att = joints[k]
                if ln.name in positions:
                    s0, xyz = positions[ln.name]
                    pos = [float(np.interp(s, s0, xyz[:, c])) for c in range(3)]
                else:
                    pos = xa + (xb - xa) * (s / ln.length)
                nxt = _joint_point(sc.environment, ln, pos, att, points)
            else:
                nxt = ends.point(ln, "end_b")
            line_rows.append(
                f"{len(line_rows) + 1} {types[_type_key(seg)]} {prev} {nxt} {_f(length)} "
                f"{elements} -"
            )
            prev = nxt
    return line_rows


def _joint_point(env: Any, ln: Line, pos: Any, att: list, points: _PointRows) -> int:
    """The Free point joining two pieces of line ``ln`` at ``pos``, carrying the
    attachments ``att`` there (volume = buoyancy/(ρ·g), Ca = added mass/(ρ·V))."""
    mass = sum(a.mass for a in att)
    vol = sum(a.buoyancy for a in att) / (env.rho * env.g)
    added = sum(a.added_mass for a in att)
    ca = added / (env.rho * vol) if vol > 0 else 0.0
    if vol == 0 and added > 0:
        warn(
            f"line {ln.name!r}: attachment added mass without buoyancy is not written", stacklevel=4
        )
    cda = sum(a.drag_area for a in att)
    return points.add("Free", pos, mass, vol, cda, ca)


def _file_text(
    title: str,
    type_rows: list[str],
    body_rows: list[str],
    point_rows: list[str],
    line_rows: list[str],
    options: list[str],
) -> str:
    """The file: the sections' headers, names and units rows around their rows."""
    rows = [
        "--------------------- MoorDyn Input File ------------------------------------",
        title.replace("\n", " ").replace("---", "- - -"),
        "---------------------- LINE TYPES -----------------------------------------",
        "TypeName Diam Mass/m EA BA/-zeta EI Cd Ca CdAx CaAx",
        "(name) (m) (kg/m) (N) (N-s/-) (N-m^2) (-) (-) (-) (-)",
        *type_rows,
    ]
    if body_rows:
        rows += [
            "---------------------- BODIES ---------------------------------------------",
            "ID Attachment X0 Y0 Z0 r0 p0 y0 Mass CG* I* Volume CdA* Ca*",
            "(#) (-) (m) (m) (m) (deg) (deg) (deg) (kg) (m) (kg-m^2) (m^3) (m^2) (-)",
            *body_rows,
        ]
    rows += [
        "---------------------- POINTS ---------------------------------------------",
        "ID Attachment X Y Z Mass Volume CdA Ca",
        "(#) (-) (m) (m) (m) (kg) (m^3) (m^2) (-)",
        *point_rows,
        "---------------------- LINES ----------------------------------------------",
        "ID LineType AttachA AttachB UnstrLen NumSegs Outputs",
        "(#) (name) (#) (#) (m) (-) (-)",
        *line_rows,
        "---------------------- OPTIONS --------------------------------------------",
        *options,
        "------------------------- need this line ---------------------------------",
        "",
    ]
    return "\n".join(rows)
