"""The element rules of the fidelity planner applied to a scene: the static geometry
of every segment (:class:`LineGeometry`), the static touchdowns, the segments and
element counts of the rules (:func:`mesh_rules`) and the scene with new segments
(:func:`segments_scene`)."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from stochcable.fidelity.plan import Choice
from stochcable.fidelity.rules import CUTOFF_KH
from stochcable.scene.model import Scene, load_scene
from stochcable.statics import solve_statics

__all__ = [
    "TOUCHDOWN_ELEMENTS",
    "LineGeometry",
    "segment_geometry",
    "static_touchdowns",
    "Segments",
    "mesh_rules",
    "segments_scene",
]

#: Elements of the finite-element statics that locates a touchdown (when the closed
#: form does not apply and the scene's mesh is coarser). [-]
TOUCHDOWN_ELEMENTS = 200


@dataclass(frozen=True, eq=False)
class LineGeometry:
    """Static geometry of one line for the element rules: per segment a dict (length,
    ⟨1/c²⟩, suspended lengths, arc-length interval, touchdown), and the nodes' arc
    length and z (for the wave-load rule). [m]"""

    segments: list[dict[str, Any]]
    s_nodes: np.ndarray
    z_nodes: np.ndarray


def segment_geometry(
    scene: Scene, statics: Any, touchdown: dict[str, float | None] | None = None
) -> dict[str, LineGeometry]:
    """Per line and segment: length, ⟨1/c²⟩ over the suspended part, suspended length,
    arc-length interval, node z (for the wave-load rule) and the static touchdown
    (``touchdown`` overrides the statics' own, e.g. from a finer model)."""
    rho = scene.environment.rho
    out: dict[str, LineGeometry] = {}
    for line in scene.lines:
        st = statics.lines[line.name]
        s_td = (touchdown or {}).get(line.name, st.touchdown)
        mesh = st.mesh
        grounded_el = st.grounded[1:] & st.grounded[:-1]
        susp_line = float(np.sum(mesh.l0[~grounded_el]))
        s_start = 0.0
        segs = []
        for i, seg in enumerate(line.segments):
            sel = mesh.segment == i
            m_t = seg.mass + seg.ca_normal * rho * math.pi * seg.diameter**2 / 4.0
            t = np.asarray(st.tension)[sel]
            free = sel & ~grounded_el
            tf = np.asarray(st.tension)[free]
            l0f = mesh.l0[free]
            if tf.size:
                # tension floor: 1 % of the segment's largest (a slack element has T = 0)
                tf = np.maximum(tf, 1e-2 * max(float(t.max()), 1e-300))
                inv_c2 = float(np.sum(l0f * m_t / tf) / np.sum(l0f))
            else:
                inv_c2 = 0.0
            segs.append(
                {
                    "length": seg.length,
                    "inv_c2": inv_c2,
                    "suspended": float(np.sum(l0f)),
                    "line_suspended": susp_line,
                    "s0": s_start,
                    "s1": s_start + seg.length,
                    "grounded_any": bool(np.any(grounded_el[sel])),
                    "touchdown": s_td,
                }
            )
            s_start += seg.length
        out[line.name] = LineGeometry(segs, np.asarray(mesh.s0), st.positions[:, 2].copy())
    return out


def static_touchdowns(scene: Scene | Any) -> dict[str, float | None]:
    """Static touchdown of every line, for placing a node there.

    Parameters
    ----------
    scene : Scene or document
        The scene.

    Returns
    -------
    dict of str to float or None
        Per line name, the unstretched arc length from end_a where the line leaves the
        seabed (None without seabed contact). [m]

    Notes
    -----
    The closed-form elastic catenary where it applies, else the finite-element statics
    on a mesh of at least :data:`TOUCHDOWN_ELEMENTS` elements (the scene's own mesh may
    be coarse: its 3-element FE statics puts the touchdown of tuah_1982_single_leg at
    157 ft instead of 165.7 ft), whose touchdown is interpolated from the vertical
    tension of the first suspended element (:mod:`stochcable.line.statics`).
    """
    scene = load_scene(scene)
    auto = solve_statics(scene)
    out: dict[str, float | None] = {}
    refine: dict[str, tuple[tuple[int, float, int], ...]] = {}
    for line in scene.lines:
        st = auto.lines[line.name]
        out[line.name] = st.touchdown
        n = sum(seg.elements for seg in line.segments)
        if st.touchdown is not None and st.method == "fe" and n < TOUCHDOWN_ELEMENTS:
            f = TOUCHDOWN_ELEMENTS / n
            refine[line.name] = tuple(
                (i, seg.length, max(1, int(math.ceil(seg.elements * f))))
                for i, seg in enumerate(line.segments)
            )
    if refine:
        fine = solve_statics(segments_scene(scene, refine, {}), method="fe")
        for name in refine:
            out[name] = fine.lines[name].touchdown
    return out


Segments = dict[str, tuple[tuple[int, float, int], ...]]
"""Per line name, the new segments as (source segment index, length [m], elements)."""


@dataclass(frozen=True)
class _LoadRule:
    """The wave-load element rule: off (``k`` None) or h ≤ ``dz`` above ``depth``."""

    k: float | None  # load wavenumber [rad/m]
    depth: float  # depth where e^{kz} < eps_el [m]
    dz: float  # element length above it [m]
    eps_el: float  # element share of the error [-]


def mesh_rules(
    scene: Scene,
    geo: dict[str, LineGeometry],
    w2: float,
    wmax: float,
    eps_el: float,
    k_load: float | None,
    exact: bool,
) -> tuple[Segments, list[Choice], float]:
    """Segments (source, length, elements) per line by the element rules.

    Parameters
    ----------
    scene : Scene
    geo : dict of str to LineGeometry
        Static geometry of every line (:func:`segment_geometry`).
    w2 : float
        Frequency of the string-wave rule (the response's ω₂). [rad/s]
    wmax : float
        Frequency of the cut-off rule (ω_max). [rad/s]
    eps_el : float
        Share of the error given to the elements. [-]
    k_load : float or None
        Wavenumber of the wave-load rule (None: no sea). [rad/m]
    exact : bool
        Whether the wave loads are integrated exactly (no wave-load rule).

    Returns
    -------
    (Segments, list of Choice, float)
        The segments, one choice per source segment, and the largest error estimate.
    """
    choices: list[Choice] = []
    out: Segments = {}
    # the string-wave and the wave-load rules get half of eps_el each
    eps_w = eps_el / 2.0 if (k_load and not exact) else eps_el
    err = 0.0
    load = _LoadRule(
        k=k_load if (k_load and not exact) else None,
        depth=(math.log(1.0 / eps_el) / k_load) if k_load else 0.0,
        dz=math.sqrt(12.0 * eps_el / 2.0) / k_load if k_load else math.inf,
        eps_el=eps_el,
    )
    for line in scene.lines:
        lg = geo[line.name]
        new: list[tuple[int, float, int]] = []
        for i, (_, g) in enumerate(zip(line.segments, lg.segments)):
            path = f"lines[{line.name}].segments[{i}].elements"
            h, n, rule = _wavelength_rules(g, w2, wmax, eps_el, eps_w)
            kh_eff = (h * w2 * math.sqrt(g["inv_c2"])) if g["inv_c2"] > 0 else 0.0
            e_seg = (
                kh_eff**2 / 24.0 + (min(h, load.dz) * k_load) ** 2 / 12.0
                if load.k
                else kh_eff**2 / 24.0
            )
            wet_part = None  # (a, b) arc-length interval of the finely meshed top part
            if load.k:
                h, n, rule, wet_part = _wave_load_rule(g, lg, load, h, n, rule)
            # touchdown rule: a node at the static touchdown.  The linear model's contact
            # state is the static one (grounded nodes on the seabed springs), so a
            # touchdown inside an element puts an O(h) error on the suspended length;
            # measured on tuah_1982_single_leg: fairlead σ −3.3 %, +2.0 %, −0.8 %, +0.5 %
            # at 56, 112, 224, 448 uniform elements, +0.09 %, +0.03 % at 56, 112 with a
            # node at the touchdown (then the √ε rule above bounds it).
            s_td = g.get("touchdown")
            cut_td = (
                s_td is not None
                and g["s0"] + 1e-6 * g["length"] < s_td < g["s1"] - 1e-6 * g["length"]
            )
            err = max(err, e_seg)
            if wet_part is None and not cut_td:
                new.append((i, g["length"], n))
                choices.append(Choice(path, n, rule + f"; h = {g['length'] / n:.3g} m", e_seg))
                continue
            parts = _split_segment(i, g, h, load.dz, wet_part, s_td if cut_td else None)
            new.extend(parts)
            why = []
            if wet_part is not None:
                why.append(
                    f"wave-load depth {load.depth:.3g} m (e^(kz) < {eps_el:.2g}, "
                    f"k = {k_load:.3g} rad/m): the part above it with h ≤ "
                    f"√(12·{eps_el / 2:.2g})/k = {load.dz:.3g} m"
                )
            if cut_td:
                why.append(f"a node at the static touchdown s = {float(s_td):.4g} m")
            choices.append(
                Choice(
                    path,
                    [m for _, _, m in parts],
                    "split at "
                    + " and ".join(why)
                    + f"; elsewhere {rule} (lengths "
                    + ", ".join(f"{L:.4g}" for _, L, _ in parts)
                    + " m)",
                    e_seg,
                )
            )
        out[line.name] = tuple(new)
    return out, choices, err


def _wavelength_rules(
    g: dict[str, Any], w2: float, wmax: float, eps_el: float, eps_w: float
) -> tuple[float, int, str]:
    """Element length, count and reason of a segment by the string-wave, cut-off and
    touchdown-length rules (the smallest h binds)."""
    if g["inv_c2"] > 0:
        sq = math.sqrt(g["inv_c2"])
        h_w2 = math.sqrt(24.0 * eps_w) / (w2 * sq)
        h_cut = CUTOFF_KH / (wmax * sq)
    else:
        h_w2 = h_cut = math.inf
    h_td = g["line_suspended"] * math.sqrt(eps_el) if g["grounded_any"] else math.inf
    h = min(h_w2, h_cut, h_td, g["length"])
    n = max(1, int(math.ceil(g["length"] / h - 1e-9)))
    rule = {
        h_w2: f"string wave at the response's ω₂ = {w2:.3g} rad/s: h ≤ "
        f"√(24·{eps_w:.2g})·c/ω₂ = {h_w2:.3g} m",
        h_cut: f"cut-off at ω_max = {wmax:.3g} rad/s: kh ≤ {CUTOFF_KH:g}, h ≤ {h_cut:.3g} m",
        h_td: f"touchdown: h ≤ √{eps_el:.2g} × suspended length = {h_td:.3g} m",
        g["length"]: "one element (no rule binds)",
    }[h]
    return h, n, rule


def _wave_load_rule(
    g: dict[str, Any], lg: LineGeometry, load: _LoadRule, h: float, n: int, rule: str
) -> tuple[float, int, str, tuple[float, float] | None]:
    """The wave-load rule on one segment: the part above ``load.depth`` gets h ≤
    ``load.dz`` — the whole segment (new h, n, reason) or a top part to split off
    (its arc-length interval)."""
    sel = (lg.s_nodes >= g["s0"] - 1e-9) & (lg.s_nodes <= g["s1"] + 1e-9)
    ss, zz = lg.s_nodes[sel], lg.z_nodes[sel]
    wet = zz > -load.depth
    if np.all(wet):
        if load.dz < h:
            h = load.dz
            n = max(1, int(math.ceil(g["length"] / h - 1e-9)))
            rule = (
                f"wave loads (nodal kinematics e^(kz-ikx)): h ≤ "
                f"√(12·{load.eps_el / 2:.2g})/k = {load.dz:.3g} m, k = {load.k:.3g} "
                "rad/m"
            )
        return h, n, rule, None
    if not (wet[-1] or wet[0]):
        return h, n, rule, None
    top_end = bool(wet[-1] and (not wet[0] or zz[-1] >= zz[0]))
    if top_end:
        j = int(np.flatnonzero(~wet)[-1])
        l_top = g["s1"] - ss[j]
    else:
        j = int(np.flatnonzero(~wet)[0])
        l_top = ss[j] - g["s0"]
    if load.dz < h and 0.0 < l_top < g["length"]:
        return h, n, rule, ((g["s1"] - l_top, g["s1"]) if top_end else (g["s0"], g["s0"] + l_top))
    return h, n, rule, None


def _split_segment(
    i: int,
    g: dict[str, Any],
    h: float,
    dz_load: float,
    wet_part: tuple[float, float] | None,
    s_td: float | None,
) -> list[tuple[int, float, int]]:
    """Segment ``i`` cut at the wet part's ends and the touchdown ``s_td``: (i, length,
    elements) per part, h ≤ ``dz_load`` in the wet part."""
    cuts = sorted(
        {g["s0"], g["s1"]}
        | ({wet_part[0], wet_part[1]} if wet_part else set())
        | ({float(s_td)} if s_td is not None else set())
    )
    parts = []
    for a, b in zip(cuts[:-1], cuts[1:]):
        if b - a <= 1e-9 * g["length"]:
            continue
        in_wet = wet_part is not None and wet_part[0] - 1e-9 <= a and b <= wet_part[1] + 1e-9
        hp = min(h, dz_load) if in_wet else h
        m = max(1, int(math.ceil((b - a) / hp - 1e-9)))
        parts.append((i, float(b - a), m))
    return parts


def segments_scene(scene: Scene, segments: Segments, update: dict[str, Any]) -> Scene:
    """A new, validated scene: the lines of ``segments`` with those segments (same
    properties as their source segment), ``analysis`` updated with ``update``."""
    lines = []
    for line in scene.lines:
        spec = segments.get(line.name)
        if spec is None:
            lines.append(line)
            continue
        segs = tuple(
            line.segments[i].model_copy(update={"length": float(L), "elements": int(n)})
            for i, L, n in spec
        )
        lines.append(line.model_copy(update={"segments": segs}))
    analysis = scene.analysis.model_copy(update=update)
    new = scene.model_copy(update={"lines": tuple(lines), "analysis": analysis})
    return Scene.model_validate(new.model_dump())
