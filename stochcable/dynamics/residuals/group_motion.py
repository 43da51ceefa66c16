"""The residuals of the linear model in the motions of the free bodies of a group of
several lines: the body DOFs as output rows of the group's joint sums.

The end tensions of the lines on a shared body take every line's residual loads as one
set of jointly Gaussian components (Mehler's formula for the drag, Isserlis' for the
geometric residual; :meth:`~.body_residual.CoupledInfluence.joint_lines`): the cross
terms between panels of different lines count, their velocities being correlated
through the common sea and the common body motion.  The body DOFs are more outputs of
the same components: a load F on line ℓ moves them by ξ = S⁻¹T_ℓᵀ(G_R,ℓ F)_att
(:class:`GroupBodyInfluence`, from the group's solves the end tensions' influences
hold).  :class:`BodyRows`, registered on the
group's shared state, gives the joint sums these rows, two at a time as the kinds'
transfers take an influence of two outputs (end_a, end_b), and keeps their lines:
the full sum over every line's components, cross terms included (a body row has no
"own" part to leave out).  The kinds' own selection of live components reads the end
tensions only: the body rows enter it scaled to :data:`ROW_SCALE` of the end
tensions' largest transfer (and unscaled after; the variance is quadratic in the
transfer, so exactly), so the end tensions' sums are unchanged by them.

Each kind's body lines are integrated over the cells of a resonance narrower than a
line as the end tensions' (:func:`~.drag_residual.cell_factor`, its sub-samples
through every line's body influence).  The drag residual's linear misfit loads of
every line (δB·v) add to the bodies' linear transfer before the variance is formed
(:func:`misfit_parts`), as at the ends (:mod:`.drag_misfit`, :mod:`.drag_misfit_3d`).

A group of one line keeps :func:`~.body_motion.body_motion_parts` (its own loads are
the group's).

Validation: the rows against the assembled coupled system loaded by every leg's unit
loads; the joint body variance against Monte Carlo on the two-leg buoy; a mirrored
buoy's sway and heave (tests/dynamics/test_body_residual.py).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Mapping, Sequence
from typing import Any

import numpy as np

from stochcable.dynamics.model.blocks import trapezoid_weights
from stochcable.dynamics.residuals.along_line_bodies import (
    ElementCoupledInfluence,
    NodeCoupledInfluence,
)
from stochcable.dynamics.residuals.body_residual import CoupledInfluence, untapped
from stochcable.dynamics.residuals.drag_misfit import misfit_loads
from stochcable.dynamics.residuals.drag_residual import CELL_BEND, SUB_SAMPLES
from stochcable.dynamics.residuals.geometric_residual import LINE_STRIDE
from stochcable.dynamics.residuals.group_influence import (
    Fresh,
    GroupBodyInfluence,
    Rows,
    StationInfluence,
)
from stochcable.dynamics.residuals.influence import geometric_feedthrough
from stochcable.dynamics.residuals.residual_lines import DENSE_PAIR_BYTES, load_transfer

__all__ = [
    "MISFIT_CHUNK",
    "ROUND_OFF",
    "ROW_SCALE",
    "STATION_CELL_NODES",
    "STATION_KINDS",
    "BodyRows",
    "body_rows_of",
    "misfit_loads_of",
    "misfit_parts",
    "station_misfit",
]

#: The body rows' largest transfer in a joint sum relative to the end tensions'
#: largest (module notes): the kinds keep a component whose largest output transfer
#: is at least 1e-4 of the largest (PANEL_FLOOR, ELEMENT_FLOOR); rows at 1e-9 of it
#: cannot raise a component there. [-]
ROW_SCALE = 1e-9

#: A body DOF's residual variance at most this share of the body's largest is
#: round-off (:meth:`BodyRows.body_parts`). [-]
ROUND_OFF = 1e-12

#: The joint sums (their key's first item) that give the lines' stations the group's
#: part: the drag residuals'; the geometric residual's only where its pair lines form
#: one dense matrix (DENSE_PAIR_BYTES: the bundled three-leg buoy's 3 elements a leg).
#: Beyond, its joint sum over every line's elements runs block by block at a cost
#: proportional to its outputs: on benchmarks/bench_bodies.py's mooring (3 × 40
#: elements) the stations' 132 rows took 6.5 s against an analysis of 7 s; its group
#: part at the ends is +0.3 % of σ (docs/accuracy/bodies.md).
STATION_KINDS = ("drag", "drag_3d")

#: The stations' group parts are integrated over the cells of a resonance narrower
#: than a line (as the body rows' and the lines' own parts) in groups of at most this
#: many nodes over their lines; above, taken on the lines.  The integration's
#: sub-samples pass through every line's station rows: the three-leg disc buoy (12
#: nodes) +0.03 s, its fairlead nodes' surge-direction σ 2.96 / 2.87 ft (front / side
#: legs, which move alike with the buoy) → 2.92 / 2.92; benchmarks/bench_bodies.py's
#: mooring (123 nodes) +5 s on an analysis of 7 s, for at most 2e-4 of σ. [-]
STATION_CELL_NODES = 60

#: Frequencies per block of the misfits' transfers on the analysis grid (each block's
#: station influence n_out × n_nodes × d of them: the three-leg buoy at 100 elements
#: and 600 frequencies kept 96 MB a line pair at once). [-]
MISFIT_CHUNK = 64

#: The cell bend of each joint sum's kind (its key's first item), as the ends'. [-]
_BENDS = {"drag": CELL_BEND, "drag_3d": CELL_BEND, "geometric": CELL_BEND * LINE_STRIDE**2}


class BodyRows:
    """The body DOFs of a group, and the stations of its lines, as extra output rows of
    its joint sums (module notes): registered as ``shared["extra_rows"]`` of the
    group's coupled influences (:func:`body_rows_of`).

    Parameters
    ----------
    influences : mapping of str to CoupledInfluence
        The group's coupled influences (one per line, one shared state).
    stations : mapping of str to (ndarray, ndarray), optional
        Per line its element stations and its node stations (indices): their tensions
        and motions (the model's d components a node, node-major) are rows too, and
        the group's part of their lines (the sum over every line's components less the
        line's own pairs) kept (:meth:`station_parts`).
    """

    def __init__(
        self,
        influences: Mapping[str, CoupledInfluence],
        stations: Mapping[str, tuple[np.ndarray, np.ndarray]] | None = None,
    ) -> None:
        self.influences = dict(influences)
        first = next(iter(self.influences.values()))
        self.n_dof = sum(b.n_dof for b in first.bodies)
        self._body: dict[str, GroupBodyInfluence] = {}
        self._own: dict[str, Any] = {}  # (the grids' solves the end tensions did not ask)
        self._made: list[Any] = []  # (the station influences)
        self.n_nodes = sum(i.line.system.model.n_nodes for i in self.influences.values())
        # the row sets: (set, target line or None, rows, influence of a source's forces)
        self.sets: list[tuple[str, str | None, int, Callable[[str], Any]]] = []
        if self.n_dof:
            self.sets.append(("body", None, self.n_dof, self.body))
        for name, (el, nodes) in (stations or {}).items():
            base = self.influences[name]
            d = base.line.system.model.dim
            for kind, target, n in (
                ("elements", ElementCoupledInfluence(base, el), el.size),
                ("nodes", NodeCoupledInfluence(base, nodes), nodes.size * d),
            ):
                self.sets.append((kind, name, n, self._station(target)))
        self._kept: dict[Any, dict] = {}
        #: by joint key: (frequencies [rad/s] (n_o,), body variance lines (n_dof, n_o))
        self.lines: dict[Any, tuple[np.ndarray, np.ndarray]] = {}
        #: by joint key and (set, line): the group's part of the stations' lines
        self.stations: dict[Any, dict[tuple[str, str], np.ndarray]] = {}

    def body(self, name: str) -> GroupBodyInfluence:
        """The body influence of line ``name`` (kept: its grids are kept on it)."""
        if name not in self._body:
            self._body[name] = GroupBodyInfluence(self.influences[name], self._state)
        return self._body[name]

    def _station(self, target: Any) -> Callable[[str], StationInfluence]:
        made: dict[str, StationInfluence] = {}

        def of(name: str) -> StationInfluence:
            if name not in made:
                made[name] = StationInfluence(target, self.body(name), self._state)
                self._made.append(made[name])
            return made[name]

        return of

    def _state(self, w: np.ndarray) -> tuple:
        """The group's solves on ``w``: the end tensions' where they hold the grid,
        else kept here (:meth:`~.body_residual.CoupledInfluence._state`)."""
        base = next(iter(self.influences.values()))
        held = base.shared.get("state", {}).get(np.asarray(w, dtype=float).tobytes())
        if held is not None:
            return held
        probe = CoupledInfluence(
            base.name, base.lines, base.bodies, base.body_drag, None, self._own
        )
        return probe._state(np.asarray(w, dtype=float))

    def transfers(
        self,
        key: Any,
        parts: Sequence[tuple[Any, Any]],
        transfer: Callable[[Any, Any, Any], np.ndarray],
        h: np.ndarray,
    ) -> list[np.ndarray]:
        """The extra rows' transfers (two rows each, the sources along axis 1 as the
        targets' ``h``), scaled to :data:`ROW_SCALE` of ``h``'s largest."""
        names = [src.name for src, _ in parts]
        n = int(np.prod(h.shape[1:-1]))  # (the sums' components)
        dense = 16 * n * n * h.shape[-1] <= DENSE_PAIR_BYTES
        lines = key[0] in STATION_KINDS or (key[0] == "geometric" and dense)
        sets = [st for st in self.sets if st[1] is None or (st[1] in names and lines)]
        out, layout = [], []
        for kind, line, n, of in sets:
            for k in range(0, n, 2):
                rows = np.arange(k, min(k + 2, n))
                per = [transfer(src, c, Rows(of(src.name), rows)) for src, c in parts]
                if key[0] == "geometric" and kind == "elements":
                    i = names.index(line)
                    per[i] = per[i] + _feedthrough(parts[i], of(line).target.elements[rows])
                out.append(np.concatenate(per, 1))
                layout.append((kind, line, rows))
        widths = np.cumsum([0] + [t.shape[1] for t in per]) if out else np.zeros(1, int)
        top = float(np.abs(h).max(initial=0.0))
        scale = np.ones(2 * len(out))
        for k, t in enumerate(out):
            for r in range(2):
                m = float(np.abs(t[r]).max(initial=0.0))
                if m > 0.0 and top > 0.0:
                    scale[2 * k + r] = ROW_SCALE * top / m
            t *= scale[2 * k : 2 * k + 2].reshape((2,) + (1,) * (t.ndim - 1))
        self._kept[key] = {
            "parts": list(parts), "transfer": transfer, "h": h, "scale": scale,
            "layout": layout, "t": out, "widths": widths,
        }  # fmt: skip
        return out

    def keep(self, key: Any, lines: np.ndarray, outputs: Callable) -> None:
        """The joint sum's lines of the extra rows (scaled as :meth:`transfers` gave
        them): unscaled; the stations' less their line's own pairs (``outputs``: the
        kind's, over the line's components alone); integrated over the cells; kept by
        ``key``."""
        kept = self._kept.pop(key)
        parts, transfer, scale = kept["parts"], kept["transfer"], kept["scale"]
        v = lines / scale[:, None] ** 2
        w_out = np.asarray(parts[0][1].w_out, dtype=float)
        bend = _BENDS.get(key[0], CELL_BEND)
        names = [src.name for src, _ in parts]
        by_set: dict[tuple[str, str | None], list[int]] = {}
        for k, (kind, line, _) in enumerate(kept["layout"]):
            by_set.setdefault((kind, line), []).append(k)
        for (kind, line), pairs in by_set.items():
            _, _, n, of = next(st for st in self.sets if st[0] == kind and st[1] == line)
            rows = (2 * np.asarray(pairs)[:, None] + np.arange(2)).ravel()  # (real rows first)
            lines_set = v[rows]
            if kind != "body":  # less the line's own pairs (its along-line record's)
                i = names.index(line)
                cols = slice(int(kept["widths"][i]), int(kept["widths"][i + 1]))
                t_own = np.concatenate(
                    [kept["h"][2 * i : 2 * i + 2][:, cols]] + [kept["t"][k][:, cols] for k in pairs]
                )
                with untapped():
                    own = outputs([parts[i][1]], t_own)[2:]
                lines_set = lines_set - own / scale[rows, None] ** 2
            lines_set = lines_set[:n]
            if kind == "body" or self.n_nodes <= STATION_CELL_NODES:
                lines_set = lines_set * self._cells(parts, transfer, w_out, bend, of, n)
            if kind == "body":
                self.lines[key] = (w_out, lines_set)
            else:
                self.stations.setdefault(key, {})[kind, line] = (w_out, lines_set)
        for infl in self._made:  # (their grids are this sum's: not asked again)
            infl.release()

    def _power(self, parts, transfer, w: np.ndarray, of, n: int) -> np.ndarray:  # noqa: ANN001
        """Σ over every line's components of |rows per unit component|², on ``w``:
        (n, n_w)."""
        p = np.zeros((n, w.size))
        for src, c in parts:
            cw = c if np.array_equal(c.w_out, w) else dataclasses.replace(c, w_out=w)
            for k in range(0, n, 2):
                rows = np.arange(k, min(k + 2, n))
                with untapped():
                    t = transfer(src, cw, Rows(of(src.name), rows))
                p[rows] += (np.abs(t.reshape(2, -1, w.size)) ** 2).sum(axis=1)[: rows.size]
        return p

    def _cells(self, parts, transfer, w_out: np.ndarray, bend: float, of, n: int) -> np.ndarray:  # noqa: ANN001
        """The cell factor (n, n_o) of a row set (module notes; as
        :func:`~.drag_residual.cell_factor`, over every line's components)."""
        power = self._power(parts, transfer, w_out, of, n)
        out = np.ones_like(power)
        logp = np.log(np.maximum(power, np.max(power, initial=0.0) * 1e-300 + 1e-300))
        bent = np.zeros(power.shape[1], dtype=bool)
        bent[1:-1] = np.any(np.abs(logp[:, 2:] - 2.0 * logp[:, 1:-1] + logp[:, :-2]) > bend, 0)
        cells = np.flatnonzero(bent | np.roll(bent, 1) | np.roll(bent, -1))
        if cells.size == 0:
            return out
        step = float(w_out[1] - w_out[0]) if w_out.size > 1 else float(w_out[0])
        sub = step * ((np.arange(SUB_SAMPLES) + 0.5) / SUB_SAMPLES - 0.5)
        w_sub = (w_out[cells, None] + sub[None]).ravel()
        p_sub = self._power(parts, transfer, w_sub, of, n).reshape(n, cells.size, -1)
        at = power[:, cells]
        out[:, cells] = np.where(at > 0, p_sub.mean(axis=2) / np.where(at > 0, at, 1.0), 1.0)
        return out

    def parts(self) -> list[tuple[np.ndarray, np.ndarray]]:
        """The kept kinds' body lines, one joint key per kind."""
        seen, out = set(), []
        for key, part in self.lines.items():
            if key[0] not in seen:
                seen.add(key[0])
                out.append(part)
        return out

    def body_parts(
        self, linear: np.ndarray, spectra: np.ndarray, w: np.ndarray
    ) -> list[tuple[np.ndarray, np.ndarray]]:
        """The body DOFs' residual lines: the kinds' (:meth:`parts`) and the misfit's
        (:func:`misfit_parts`, the bodies' ``linear`` transfer (n_ch, n_dof, n_w) on
        ``w`` with the inputs' ``spectra``); a DOF whose total is round-off, at most
        :data:`ROUND_OFF` of the largest DOF's (a symmetric mooring's sway and roll,
        ~1e-17 against ~1: the legs' parts cancel), gets none."""
        out = self.parts()
        if not out:
            return []
        out += misfit_parts(self, linear, spectra, w)
        total = np.abs(sum(v.sum(axis=1) for _, v in out))
        noise = total <= ROUND_OFF * np.max(total, initial=0.0)
        return [(om, np.where(noise[:, None], 0.0, v)) for om, v in out]


def _feedthrough(part: tuple[Any, Any], elements: np.ndarray) -> np.ndarray:
    """The geometric residual's own stretch of ``elements`` per unit of their line's
    components (:func:`~.influence.geometric_feedthrough`), in the layout of the
    kind's joint transfers (2, n_el, n_terms, 1; the second row zero where one
    element): the element tensions' direct term, as the line's own record takes it
    (:func:`~.along_line.element_lines`)."""
    ln, c = part
    n_terms, n_el = len(c.terms), c.proc[0].shape[1]
    ft = geometric_feedthrough(ln.system, n_terms * n_el)[elements]  # (r, n_terms·n_el)
    out = np.zeros((2, n_el, n_terms, 1))
    out[: elements.size] = np.swapaxes(ft.reshape(-1, n_terms, n_el), 1, 2)[..., None]
    return out


def body_rows_of(
    influences: Mapping[str, CoupledInfluence],
    stations: Mapping[str, tuple[np.ndarray, np.ndarray]] | None = None,
) -> BodyRows | None:
    """The :class:`BodyRows` of a group of several lines on free bodies (with the lines'
    ``stations``, as :class:`BodyRows` takes them), registered on its influences'
    shared state (None: a group of one line, or no bodies)."""
    if len(influences) < 2:
        return None
    first = next(iter(influences.values()))
    if not first.bodies or sum(b.n_dof for b in first.bodies) == 0:
        return None
    rows = BodyRows(influences, stations)
    first.shared["extra_rows"] = rows
    return rows


def misfit_loads_of(rows: BodyRows, w: np.ndarray) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """Every line's drag residual misfit loads δB·v (the components the body lines'
    joint sums kept, one key per kind): per line its unit loads (n_nodes, d, n_load)
    and their values per unit input (n_ch, n_load, n_w) on the analysis grid ``w``."""
    kept = next(iter(rows.influences.values())).shared.get("components", {})
    keys: dict[str, Any] = {}
    for key in list(rows.lines) + list(rows.stations):
        keys.setdefault(key[0], key)
    out = {}
    for key, name in list(kept):
        c = kept[key, name]
        if c is None or keys.get(key[0]) != key or key[0] not in ("drag", "drag_3d"):
            continue
        if key[0] == "drag":
            model = rows.influences[name].line.system.model
            mis = misfit_loads(model, c.seg, c.groups, c.live, c.parts, c.misfit)
        elif c.db is not None:
            v = np.stack([c.pan["n1"], c.pan["n2"], c.pan["t"]], axis=1)
            load = np.einsum("pab,cbpw->capw", c.db, v)
            mis = (c.unit, load.reshape(load.shape[0], -1, np.size(w)))
        else:
            mis = None
        if mis is not None:
            out[name] = mis
    return out


def _through(rows: BodyRows, loads: Mapping[str, tuple], w: np.ndarray, of: Callable) -> Any:
    """Σ over the lines' misfit ``loads`` of their outputs through ``of(line)``,
    (n_ch, n_out, n_w) (0 without loads)."""
    h_c: Any = 0.0
    for name, (unit, load) in loads.items():
        line = rows.influences[name].line
        for start in range(0, w.size, MISFIT_CHUNK):  # (not kept: asked once)
            sl = slice(start, start + MISFIT_CHUNK)
            with untapped():
                h = load_transfer(line.system, line.damping, unit, w[sl], Fresh(of(name)))
            part = np.einsum("okw,ckw->cow", h, load[..., sl])
            if np.ndim(h_c) == 0:
                h_c = np.zeros(part.shape[:2] + (w.size,), dtype=complex)
            h_c[..., sl] += part
    return h_c


def _change(base: np.ndarray, more: Any, spectra: np.ndarray, w: np.ndarray) -> np.ndarray:
    """Σ_c q·S_c(|H + H_c|² − |H|²) of transfers ``base`` (n_ch, n_out, n_w) and their
    change ``more``: (n_out, n_w)."""
    q = trapezoid_weights(w)[None, None] * spectra[:, None]
    return np.sum(q * (np.abs(base + more) ** 2 - np.abs(base) ** 2), axis=0)


def misfit_parts(
    rows: BodyRows, linear: np.ndarray, spectra: np.ndarray, w: np.ndarray
) -> list[tuple[np.ndarray, np.ndarray]]:
    """The drag residual's linear misfit in the body DOFs: every line's misfit loads δB·v
    (:func:`misfit_loads_of`) through its body influence added to the bodies' ``linear``
    transfer (n_ch, n_dof, n_w) on ``w`` before the variance is formed,
    Σ_c q·S_c(|H_L + H_c|² − |H_L|²): parts (``w``, (n_dof, n_w)) (empty without misfit
    loads). [m², rad²]"""
    w = np.asarray(w, dtype=float)
    loads = misfit_loads_of(rows, w)
    if not loads:
        return []
    return [(w, _change(linear, _through(rows, loads, w, rows.body), spectra, w))]


def station_misfit(
    rows: BodyRows, name: str, kind: str, linear: np.ndarray, spectra: np.ndarray, w: np.ndarray
) -> np.ndarray | None:
    """The group's part of the drag residual's misfit at line ``name``'s stations
    (``kind`` "elements" or "nodes", their linear transfer ``linear`` (n_ch, n_out,
    n_w) on ``w``): the other lines' misfit loads added to the line's own before the
    variance is formed, Σ_c q·S_c(|H_L + H_own + H_oth|² − |H_L + H_own|²), (n_out,
    n_w) (None: no other line's loads). [N², m²]"""
    w = np.asarray(w, dtype=float)
    loads = misfit_loads_of(rows, w)
    of = next((st[3] for st in rows.sets if st[0] == kind and st[1] == name), None)
    others = {k: v for k, v in loads.items() if k != name}
    if of is None or not others:
        return None
    own = _through(rows, {k: v for k, v in loads.items() if k == name}, w, of)
    return _change(linear + own, _through(rows, others, w, of), spectra, w)
