"""MoorDyn's points and lines mapped to a scene's lines and bodies (the mapping is in
:mod:`stochcable.io.moordyn_read`'s docstring and docs/manual/moordyn.md): lines joined
at free points of two line ends become one multi-segment line with the points' clump
weights and buoys as attachments; free points of one or three and more line ends become
point bodies; Coupled points the fairleads of prescribed bodies with a zero motion RAO.

References
----------
Hall, M. (2024), MoorDyn v2 input file documentation,
https://moordyn.readthedocs.io/en/latest/inputs.html.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from stochcable.io.moordyn_parts import VESSEL, MoorDynLine, MoorDynPoint
from stochcable.scene.model import Body

__all__ = [
    "POINT_BODY_MASS",
    "ZERO_MOTION",
    "line_chains",
    "point_body_names",
    "scene_lines",
    "scene_bodies",
    "is_point_body",
]

#: Mass given to a point body whose MoorDyn point is massless (a body needs a mass). [kg]
POINT_BODY_MASS = 1e-3
#: The motion of a prescribed body read from a file: zero RAO (MoorDyn files carry
#: no motion); replaced by the user's RAO table.
ZERO_MOTION: dict[str, Any] = {
    "omega": [0.0, 100.0],
    "surge": {"re": [0.0, 0.0], "im": [0.0, 0.0]},
}


def line_chains(
    lines: list[MoorDynLine], points: dict[int, MoorDynPoint]
) -> list[list[tuple[MoorDynLine, bool]]]:
    """Lines joined at free points of exactly two line ends: the chains, each a list of
    (line, reversed) from one end to the other."""
    at: dict[int, list[tuple[MoorDynLine, str]]] = {}
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


def point_body_names(points: dict[int, MoorDynPoint]) -> dict[int, str]:
    """The point bodies: free points of 1 or >= 3 line ends, by point ID →
    ``point1``, ``point2``, ... ."""
    return {
        p.pid: f"point{k}"
        for k, p in enumerate(
            (p for p in points.values() if p.kind == "free" and p.degree not in (0, 2)), start=1
        )
    }


def _end_doc(p: MoorDynPoint, pbody: dict[int, str]) -> dict[str, Any]:
    """A scene line end at MoorDyn point ``p``."""
    if p.kind == "fixed":
        return {"position": [float(v) for v in p.position]}
    if p.kind == "coupled":
        return {"attach": {"body": p.body, "point": list(p.point)}}
    return {"attach": {"body": pbody[p.pid], "point": [0.0, 0.0, 0.0]}}


def _chain_ends(
    chain: list[tuple[MoorDynLine, bool]], points: dict[int, MoorDynPoint]
) -> tuple[list[tuple[MoorDynLine, bool]], int, int]:
    """The chain oriented from end a to end b and their point IDs: a fixed end is end
    a; between two ends of one kind, the deeper one."""
    seq = list(chain)
    first, frev = seq[0]
    last, lrev = seq[-1]
    pa = first.b if frev else first.a
    pb = last.a if lrev else last.b
    ka, kb = points[pa].kind, points[pb].kind
    za, zb = float(points[pa].position[2]), float(points[pb].position[2])
    flip = (kb == "fixed" and ka != "fixed") or (
        (ka == "fixed") == (kb == "fixed") and zb < za - 1e-12
    )
    if flip:
        seq = [(ln, not rev) for ln, rev in reversed(seq)]
        pa, pb = pb, pa
    return seq, pa, pb


def scene_lines(
    chains: list[list[tuple[MoorDynLine, bool]]],
    points: dict[int, MoorDynPoint],
    pbody: dict[int, str],
    rho: float,
    g: float,
) -> list[dict[str, Any]]:
    """The scene's lines ``line1``, ``line2``, ... of the chains: a segment per MoorDyn
    line, an attachment per joint point with a mass, volume or CdA (buoyancy ρ·g·V,
    added mass Ca·ρ·V).  ``rho`` [kg/m³], ``g`` [m/s²]."""
    line_docs = []
    for k, chain in enumerate(chains, start=1):
        seq, pa, pb = _chain_ends(chain, points)
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
                "end_a": _end_doc(points[pa], pbody),
                "end_b": _end_doc(points[pb], pbody),
                "segments": segments,
                "attachments": attachments,
            }
        )
    return line_docs


def scene_bodies(
    points: dict[int, MoorDynPoint],
    bodies: dict[int, tuple[str, np.ndarray, np.ndarray, Any]],
    pbody: dict[int, str],
    rho: float,
) -> list[dict[str, Any]]:
    """The scene's bodies: the prescribed ones (``vessel`` at the origin, ``body<k>`` at
    the k-th Coupled MoorDyn body) that hold a line, with a zero motion RAO, then the
    point bodies (mass, buoyancy volume, added mass Ca·ρ·V, drag area CdA, rotations
    held).  ``rho`` [kg/m³]."""
    body_docs = []
    prescribed = sorted({p.body for p in points.values() if p.kind == "coupled" and p.degree})
    coupled_ids = [b for b, v in bodies.items() if v[0] == "coupled"]
    for name in prescribed:
        pos = [0.0, 0.0, 0.0]
        if name != VESSEL:
            pos = [float(v) for v in bodies[coupled_ids[int(name[4:]) - 1]][1]]
        body_docs.append({"name": name, "position": pos, "mass": 1.0, "prescribed": ZERO_MOTION})
    planar = all(abs(float(p.position[1])) < 1e-9 for p in points.values())
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
    return body_docs


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
