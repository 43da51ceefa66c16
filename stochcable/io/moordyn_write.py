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
from typing import Any

import numpy as np

from stochcable import validation as _v
from stochcable.errors import InputError, StochcableError, warn
from stochcable.io.moordyn_read import POINT_BODY_MASS, VESSEL
from stochcable.scene.model import Body, Line, Scene, load_scene

__all__ = ["write_moordyn", "is_point_body", "moordyn_lines"]


def is_point_body(body: Body) -> bool:
    """True for a point body: free, rotations held, no inertia or hydrodynamic table
    (what :func:`~stochcable.io.moordyn_read.read_moordyn` makes of a MoorDyn free point
    joining one or three and more line ends)."""
    rot = {"roll", "pitch", "yaw"}
    return (
        body.prescribed is None
        and body.hydrodynamics is None
        and body.inertia is None
        and (rot <= set(body.fixed_dofs) or set(body.fixed_dofs) == {"pitch"})
        and body.hydrostatic_stiffness is None
    )


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
    beta = sc.analysis.structural_damping.beta
    if sc.analysis.structural_damping.alpha > 0:
        warn("structural_damping.alpha (mass-proportional) has no MoorDyn counterpart: not written")
    positions, poses = _static_positions(sc) if static_positions else ({}, {})

    # ---- line types
    types: dict[tuple, str] = {}
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
            key = (sg.diameter, sg.mass, sg.ea, sg.cd_normal, sg.ca_normal, sg.cd_axial)
            if key not in types:
                name = f"type{len(types) + 1}"
                types[key] = name
                ba = internal_damping if internal_damping is not None else beta * sg.ea
                type_rows.append(
                    f"{name} {_f(sg.diameter)} {_f(sg.mass)} {_f(sg.ea)} {_f(ba)} 0 "
                    f"{_f(sg.cd_normal)} {_f(sg.ca_normal)} {_f(sg.cd_axial)} 0"
                )

    # ---- bodies and their points
    point_rows: list[str] = []

    def add_point(kind: str, xyz: Any, mass=0.0, vol=0.0, cda=0.0, ca=0.0) -> int:
        pid = len(point_rows) + 1
        point_rows.append(
            f"{pid} {kind} {_f(xyz[0])} {_f(xyz[1])} {_f(xyz[2])} {_f(mass)} {_f(vol)} "
            f"{_f(cda)} {_f(ca)}"
        )
        return pid

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
                    "(MoorDyn takes the motion of Coupled points from its driver)"
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
            warn(f"bodies[{i}] ({b.name!r}): added mass without volume is not written")
        mass = 0.0 if b.mass <= POINT_BODY_MASS * (1 + 1e-12) else b.mass
        where = poses.get(b.name, b.position)
        body_point[b.name] = add_point("Free", where, mass, vol, b.drag_area[0], ca)

    # ---- lines
    line_rows: list[str] = []
    for ln in sc.lines:
        pieces, joints = _pieces(ln)
        pa = _end_point(sc, ln, "end_a", coupled, body_point, md_body, add_point)
        prev = pa
        total = ln.length
        xa, xb = sc.end_position(ln, "end_a"), sc.end_position(ln, "end_b")
        for k, (seg, length, elements) in enumerate(pieces):
            if k < len(pieces) - 1:
                s, att = joints[k]
                if ln.name in positions:
                    s0, xyz = positions[ln.name]
                    pos = [float(np.interp(s, s0, xyz[:, c])) for c in range(3)]
                else:
                    pos = xa + (xb - xa) * (s / total)
                mass = sum(a.mass for a in att)
                vol = sum(a.buoyancy for a in att) / (env.rho * env.g)
                added = sum(a.added_mass for a in att)
                ca = added / (env.rho * vol) if vol > 0 else 0.0
                if vol == 0 and added > 0:
                    warn(f"line {ln.name!r}: attachment added mass without buoyancy is not written")
                cda = sum(a.drag_area for a in att)
                nxt = add_point("Free", pos, mass, vol, cda, ca)
            else:
                nxt = _end_point(sc, ln, "end_b", coupled, body_point, md_body, add_point)
            key = (seg.diameter, seg.mass, seg.ea, seg.cd_normal, seg.ca_normal, seg.cd_axial)
            line_rows.append(
                f"{len(line_rows) + 1} {types[key]} {prev} {nxt} {_f(length)} {elements} -"
            )
            prev = nxt

    rows = [
        "--------------------- MoorDyn Input File ------------------------------------",
        sc.title.replace("\n", " ").replace("---", "- - -"),
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
        "0 writeLog",
        "1 disableOutput",
        "------------------------- need this line ---------------------------------",
        "",
    ]
    if env.current:
        warn("the scene's current is not written (MoorDyn reads currents from its own files)")
    return "\n".join(rows)


def moordyn_lines(scene: Scene) -> list[tuple[str, int, int]]:
    """The MoorDyn lines :func:`write_moordyn` writes for ``scene``, in file order: (scene
    line name, index of its first element in the scene line, element count).  The
    indices are the scene mesh's when the attachments sit at segment boundaries (every
    scene read from a MoorDyn file); an attachment inside a segment splits it."""
    out = []
    for ln in scene.lines:
        e0 = 0
        for _, _, n in _pieces(ln)[0]:
            out.append((ln.name, e0, n))
            e0 += n
    return out


def _pieces(ln: Line) -> tuple[list[tuple[Any, float, int]], list[tuple[float, list]]]:
    """The MoorDyn lines of a scene line: (segment, length, elements) pieces and the
    joints between them (arc length, attachments there)."""
    total = ln.length
    tol = 1e-9 * total
    bounds = np.cumsum([0.0] + [s.length for s in ln.segments])
    cuts = sorted({float(b) for b in bounds[1:-1]})
    for i, a in enumerate(ln.attachments):
        if a.at <= tol or a.at >= total - tol:
            warn(
                f"line {ln.name!r}: attachments[{i}] at an end (at = {a.at} m) is not "
                "written (MoorDyn lumps it with the end point)"
            )
            continue
        if all(abs(a.at - c) > tol for c in cuts):
            cuts.append(float(a.at))
    cuts.sort()
    edges = [0.0, *cuts, total]
    pieces, joints = [], []
    for k in range(len(edges) - 1):
        s0, s1 = edges[k], edges[k + 1]
        j = int(np.searchsorted(bounds, 0.5 * (s0 + s1)) - 1)
        seg = ln.segments[j]
        frac = (s1 - s0) / seg.length
        if frac > 1 - 1e-9:  # the whole segment: its own numbers, exactly
            pieces.append((seg, seg.length, seg.elements))
        else:
            pieces.append((seg, s1 - s0, max(1, int(round(seg.elements * frac)))))
        if k < len(edges) - 2:
            att = [a for a in ln.attachments if abs(a.at - s1) <= tol]
            joints.append((s1, att))
    return pieces, joints


def _end_point(sc, ln, end, coupled, body_point, md_body, add_point) -> int:
    e = getattr(ln, end)
    if e.attach is not None:
        name = e.attach.body
        if name in body_point:
            return body_point[name]
        body = sc.body(name)
        if name in md_body:
            r = e.attach.point
            return add_point(f"Body{md_body[name]}", r)
        return add_point("Coupled", np.asarray(body.position) + np.asarray(e.attach.point))
    if e.motion is not None or (ln.name, end) in coupled:
        return add_point("Coupled", e.position)
    return add_point("Fixed", e.position)


def _static_positions(
    sc: Scene,
) -> tuple[dict[str, tuple[np.ndarray, np.ndarray]], dict[str, np.ndarray]]:
    """Line name → (unstretched arc lengths, static node positions) and free body name
    → static position, or ({}, {}) when the statics do not solve (the free points then
    go on the straight line, the point bodies at their ``position``)."""
    from stochcable.statics import solve_statics

    try:
        st = solve_statics(sc)
    except (StochcableError, ArithmeticError, ValueError):
        return {}, {}
    lines = {
        name: (np.asarray(ls.mesh.s0, float), np.asarray(ls.positions, float))
        for name, ls in st.lines.items()
    }
    return lines, {name: np.asarray(b.position, float) for name, b in st.bodies.items()}
