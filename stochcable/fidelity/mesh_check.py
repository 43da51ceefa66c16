"""Default element counts and the check of explicit ones: the fidelity planner's
element rule (:mod:`stochcable.fidelity.rules`) applied to an analysis already made.

A segment without ``elements`` is analyzed first at the scene model's default count
(a pilot) and then, when the rule asks for more, at the count whose estimated
discretization error of the end-tension σ is at most :data:`MESH_ERROR_LIMIT`
(:func:`default_counts`).  A segment with an explicit count whose estimate exceeds the
limit gets a ResolutionWarning naming the count that brings it below
(:func:`mesh_warnings`).

Estimate
--------
Per segment, the larger of the string-wave rule and the touchdown-length rule of
:func:`stochcable.fidelity.meshing.mesh_rules`: linear elements with consistent mass
put the relative error (kh)²/24 on the frequency of a transverse string wave (Tuah
(1982), eq. 3.1.12), with k = ω₂√⟨1/c²⟩, ω₂ = √(m₂/m₀) of the end-tension spectra
(the larger end) and ⟨1/c²⟩ over the suspended length; a grounded segment adds
(h/suspended length)² (a touchdown inside an element errs on the suspended length),
and a segment wholly in the wave zone (every node above the depth where e^{kz} < the
limit, k the sea's wavenumber at its ω₂) (kh)²/12 (nodal wave kinematics interpolated
linearly); a segment partly in it is left to ``analysis.fidelity``, which splits it.
Checked by mesh convergence against 160 elements (tests/fidelity/test_mesh_check.py):
a bound at 20 elements, 1.9× the measured error on the chain example (1.84 % vs
0.97 %) and on the accuracy page's deep catenary (11.8 % vs 6.1 %), 7× on the taut
wire (wave-load rule, 1.41 % vs 0.20 %); more conservative on finer meshes (deep
catenary at 40: 3.1 % vs 0.15 %).

References
----------
Tuah, H. (1982), Cable dynamics in an ocean environment, PhD thesis, Oregon State
University, eq. 3.1.12.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from stochcable.fidelity.limits import elements_limit
from stochcable.fidelity.meshing import segment_geometry
from stochcable.fidelity.pilot import sea_omega2
from stochcable.scene.model import Scene
from stochcable.sea.kinematics import wavenumber

__all__ = [
    "MESH_ERROR_LIMIT",
    "MeshEstimate",
    "mesh_estimates",
    "omitted_counts",
    "default_counts",
    "mesh_warnings",
]

#: Largest estimated discretization error of end-tension σ a mesh may leave: the
#: default count meets it, an explicit count above it warns. [-]
MESH_ERROR_LIMIT = 0.01


@dataclass(frozen=True)
class MeshEstimate:
    """The element rule on one segment: its count, estimated σ error [-] and the
    count that brings the estimate to :data:`MESH_ERROR_LIMIT` (capped by the scene
    model's limit)."""

    line: str
    segment: int
    elements: int
    error: float
    needed: int


def _segment_error(g: dict[str, Any], n: int, w2: float, k_load: float) -> float:
    """Estimated relative σ error of a segment of ``n`` elements. [-]"""
    h = g["length"] / n
    e_wave = (h * w2) ** 2 * g["inv_c2"] / 24.0
    e_td = (h / g["line_suspended"]) ** 2 if g["grounded_any"] else 0.0
    return max(e_wave, e_td, (h * k_load) ** 2 / 12.0)


def _needed(g: dict[str, Any], w2: float, k_load: float, limit: float) -> int:
    """Smallest count whose estimate is at most ``limit``."""
    h = g["length"]
    if g["inv_c2"] > 0.0 and w2 > 0.0:
        h = min(h, math.sqrt(24.0 * limit / g["inv_c2"]) / w2)
    if g["grounded_any"]:
        h = min(h, g["line_suspended"] * math.sqrt(limit))
    if k_load > 0.0:
        h = min(h, math.sqrt(12.0 * limit) / k_load)
    return max(1, int(math.ceil(g["length"] / h - 1e-9)))


def _load_wavenumber(lg: Any, g: dict[str, Any], sea: _SeaWave, limit: float) -> float:
    """The wave-load rule's wavenumber for a segment wholly in the wave zone (every
    node above the depth where e^{kz} < ``limit``), else 0. [rad/m]"""
    sel = (lg.s_nodes >= g["s0"] - 1e-9) & (lg.s_nodes <= g["s1"] + 1e-9)
    depth = math.log(1.0 / limit)
    z_min = float(np.min(lg.z_nodes[sel], initial=np.inf))
    # k ≥ ω²/g (ω² = gk·tanh kd): a node below depth·g/ω² is below depth/k too, and
    # the wavenumber need not be solved
    if not sea.omega2 or z_min <= -depth * sea.gravity / sea.omega2**2:
        return 0.0
    k = sea.k()
    return float(k) if z_min > -depth / k else 0.0


class _SeaWave:
    """The sea's ω₂ and, solved on first use, its wavenumber."""

    def __init__(self, scene: Scene) -> None:
        self.scene = scene
        self.gravity = scene.environment.g
        self.omega2 = sea_omega2(scene)
        self._k: float | None = None

    def k(self) -> float:
        if self._k is None:
            env = self.scene.environment
            self._k = float(wavenumber(self.omega2, env.depth, env.g))
        return self._k


def mesh_estimates(
    result: Any, limit: float = MESH_ERROR_LIMIT, geometry: dict[str, Any] | None = None
) -> list[MeshEstimate]:
    """The element rule on every segment of an analysis.

    Parameters
    ----------
    result : Result
        An analysis (:func:`stochcable.analyze`): its scene, statics and end-tension
        statistics.
    limit : float
        Relative σ error the needed count is for. [-]
    geometry : dict, optional
        :func:`stochcable.fidelity.meshing.segment_geometry` of the result's scene and
        statics, when already formed (an engine's, the same for every sea state).

    Returns
    -------
    list of MeshEstimate
        One per segment, in scene order.
    """
    geo = segment_geometry(result.scene, result.statics) if geometry is None else geometry
    sea = _SeaWave(result.scene)
    cap = elements_limit()
    out = []
    for line in result.scene.lines:
        lr = result.lines.get(line.name)
        if lr is None:
            continue
        w2 = 0.0
        for end in ("end_a", "end_b"):
            st = lr.linear_end(end)
            if st.m0 > 0.0:
                w2 = max(w2, math.sqrt(st.m2 / st.m0))
        lg = geo[line.name]
        for i, (seg, g) in enumerate(zip(line.segments, lg.segments)):
            k = _load_wavenumber(lg, g, sea, limit)
            out.append(
                MeshEstimate(
                    line.name,
                    i,
                    seg.elements,
                    _segment_error(g, seg.elements, w2, k),
                    min(cap, _needed(g, w2, k, limit)),
                )
            )
    return out


def omitted_counts(scene: Scene) -> set[tuple[str, int]]:
    """(line, segment index) of every segment whose ``elements`` the document left out."""
    return {
        (line.name, i)
        for line in scene.lines
        for i, seg in enumerate(line.segments)
        if "elements" not in seg.model_fields_set
    }


def default_counts(
    scene: Scene, estimates: list[MeshEstimate], omitted: set[tuple[str, int]]
) -> Scene | None:
    """The scene with every omitted count raised to its needed count, or None when
    none needs more (the pilot's mesh meets the limit)."""
    raise_to = {
        (e.line, e.segment): e.needed
        for e in estimates
        if (e.line, e.segment) in omitted and e.needed > e.elements
    }
    if not raise_to:
        return None
    lines = []
    for line in scene.lines:
        segs = tuple(
            seg.model_copy(update={"elements": raise_to[(line.name, i)]})
            if (line.name, i) in raise_to
            else seg
            for i, seg in enumerate(line.segments)
        )
        lines.append(line.model_copy(update={"segments": segs}))
    return scene.model_copy(update={"lines": tuple(lines)})


def mesh_warnings(
    estimates: list[MeshEstimate],
    omitted: set[tuple[str, int]] | frozenset[tuple[str, int]],
    limit: float = MESH_ERROR_LIMIT,
    *,
    other_sea: bool = False,
) -> list[str]:
    """One message per segment whose estimate exceeds ``limit``: an explicit count
    (with the count that fixes it), or a default count clipped by the scene model's
    limit — or, with ``other_sea`` (a sea other than the one the default counts were
    chosen for), a default count this sea needs more than."""
    out = []
    cap = elements_limit()
    for e in estimates:
        default = (e.line, e.segment) in omitted
        # a default count was chosen from the pilot's ω₂: for the pilot's sea it warns
        # only when clipped (the finer mesh's own ω₂ moves its estimate a little)
        if e.error <= limit or (default and e.needed < cap and not other_sea):
            continue
        if default and other_sea and e.needed <= e.elements:
            continue
        where = f"lines[{e.line}].segments[{e.segment}].elements = {e.elements}"
        if default and e.needed >= cap:
            fix = "the default count is clipped to the scene model's limit"
        elif default:
            fix = (
                f"the default count was chosen for the engine's pilot sea; this sea "
                f"needs elements = {e.needed} (build the engine with it)"
            )
        else:
            fix = f"use elements = {e.needed} (or omit the field: the default meets it)"
        out.append(
            f"{where}: the estimated discretization error of the end-tension σ is "
            f"{100 * e.error:.3g} %, above {100 * limit:g} % (string-wave, "
            f"touchdown and wave-load element rules of the fidelity planner); {fix}"
        )
    return out
