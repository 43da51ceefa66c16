"""How :func:`~stochcable.io.moordyn_write.write_moordyn` cuts a scene's lines into
MoorDyn lines: a piece per segment, split where an attachment sits inside one (its
elements shared in proportion), the joints between the pieces carrying the
attachments; and the static positions at which it places the Free points.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from stochcable.errors import StochcableError, warn
from stochcable.scene.model import Line, Scene

__all__ = ["moordyn_lines", "line_pieces", "static_node_positions"]


def moordyn_lines(scene: Scene) -> list[tuple[str, int, int]]:
    """The MoorDyn lines :func:`write_moordyn` writes for ``scene``, in file order: (scene
    line name, index of its first element in the scene line, element count).  The
    indices are the scene mesh's when the attachments sit at segment boundaries (every
    scene read from a MoorDyn file); an attachment inside a segment splits it."""
    out = []
    for ln in scene.lines:
        e0 = 0
        for _, _, n in line_pieces(ln)[0]:
            out.append((ln.name, e0, n))
            e0 += n
    return out


def line_pieces(ln: Line) -> tuple[list[tuple[Any, float, int]], list[tuple[float, list]]]:
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


def static_node_positions(
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
