"""MoorDyn's static solution of a whole scene: the scene written as a MoorDyn file
(:func:`stochcable.io.write_moordyn`), MoorDyn-C's initial-condition solve run with the
coupled points and bodies held at their static positions, and the end-segment
tensions of every MoorDyn line read back, next to the element of the scene line they
belong to.  The check of :func:`stochcable.statics.solve_statics` on MoorDyn files
(tests/io/test_io_moordyn_statics.py, docs/manual/moordyn.md).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from stochcable.errors import InputError
from stochcable.io import moordyn_lines, write_moordyn
from stochcable.reference.moordyn import import_moordyn, moordyn_system, quiet_moordyn
from stochcable.scene.model import Scene, load_scene

__all__ = ["MoorDynSegmentTension", "moordyn_static_tensions"]


@dataclass(frozen=True)
class MoorDynSegmentTension:
    """The static end-segment tensions of one MoorDyn line.

    Attributes
    ----------
    line : str
        The scene line it is part of.
    element_a, element_b : int
        Index of its first and last segment among the scene line's elements.
    tension_a, tension_b : float
        Tension of its first and last segment (MoorDyn ``GetLineNodeTen(line, 0)``
        and ``GetLineFairTen``). [N]
    """

    line: str
    element_a: int
    element_b: int
    tension_a: float
    tension_b: float


def moordyn_static_tensions(
    scene: Scene | dict | str,
    *,
    ic_threshold: float = 1e-6,
    ic_tmax: float = 300.0,
    dt: float = 1e-3,
    ic_dynamic: bool = False,
) -> list[MoorDynSegmentTension]:
    """Run MoorDyn's initial-condition solve of ``scene`` and read its segment tensions.

    Parameters
    ----------
    scene : Scene, mapping or JSON
        The scene (its point bodies are MoorDyn Free points, its prescribed bodies
        Coupled points or bodies held at their static pose).
    ic_threshold : float, default 1e-6
        ``threshIC``. [-]
    ic_tmax : float, default 300
        ``TmaxIC``. [s]
    dt : float, default 1e-3
        ``dtM``. [s]
    ic_dynamic : bool, default False
        MoorDyn's dynamic relaxation (``ICgenDynamic 1``) instead of its stationary
        solver (:func:`stochcable.io.write_moordyn`).

    Returns
    -------
    list of MoorDynSegmentTension
        One per MoorDyn line, in file order.
    """
    md = import_moordyn()
    sc = load_scene(scene)
    text = write_moordyn(
        sc, dt=dt, ic_threshold=ic_threshold, ic_tmax=ic_tmax, ic_dynamic=ic_dynamic
    )
    pieces = moordyn_lines(sc)
    out = []
    with moordyn_system(text, "scene.txt") as system:
        x: list[float] = []
        for i in range(md.GetNumberBodies(system)):
            b = md.GetBody(system, i + 1)
            if md.GetBodyType(b) == md.BODY_TYPE_COUPLED:
                x += list(md.GetBodyPos(b)) + [0.0, 0.0, 0.0]
        for i in range(md.GetNumberPoints(system)):
            p = md.GetPoint(system, i + 1)
            if md.GetPointType(p) == md.POINT_TYPE_COUPLED:
                x += list(md.GetPointPos(p))
        with quiet_moordyn():
            err = md.Init(system, x, [0.0] * len(x))
        if err:
            raise InputError("scene", "MoorDyn Init", "-", f"failed with error code {err}")
        for k, (name, e0, n) in enumerate(pieces, start=1):
            line = md.GetLine(system, k)
            ta = float(np.linalg.norm(md.GetLineNodeTen(line, 0)))
            tb = float(md.GetLineFairTen(line))
            out.append(MoorDynSegmentTension(name, e0, e0 + n - 1, ta, tb))
    return out
