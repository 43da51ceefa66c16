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
from stochcable.dynamics.residuals.body_residual import CoupledInfluence, untapped
from stochcable.dynamics.residuals.drag_misfit import misfit_loads
from stochcable.dynamics.residuals.drag_residual import CELL_BEND, SUB_SAMPLES
from stochcable.dynamics.residuals.geometric_residual import LINE_STRIDE
from stochcable.dynamics.residuals.residual_lines import load_transfer

__all__ = ["ROW_SCALE", "BodyRows", "GroupBodyInfluence", "body_rows_of", "misfit_parts"]

#: The body rows' largest transfer in a joint sum relative to the end tensions'
#: largest (module notes): the kinds keep a component whose largest output transfer
#: is at least 1e-4 of the largest (PANEL_FLOOR, ELEMENT_FLOOR); rows at 1e-9 of it
#: cannot raise a component there. [-]
ROW_SCALE = 1e-9

#: The cell bend of each joint sum's kind (its key's first item), as the ends'. [-]
_BENDS = {"drag": CELL_BEND, "drag_3d": CELL_BEND, "geometric": CELL_BEND * LINE_STRIDE**2}


class GroupBodyInfluence:
    """The body DOFs of the group (group order; zero on the held ones) per unit force on
    each node and component of one line (as :class:`~.body_motion.BodyCoupledInfluence`)
    from the group's solves on each grid, shared by its lines (``state``: the group's
    body offsets, condensed impedance, links and end solves on a grid, as
    :class:`~.body_residual.CoupledInfluence` keeps them), kept for the grids asked.
    [m/N, rad/N]"""

    def __init__(self, base: CoupledInfluence, state: Callable[[np.ndarray], tuple]) -> None:
        self.base = base
        self.line = base.line
        self.state = state
        self._kept: list[tuple[np.ndarray, np.ndarray]] = []

    def on(self, w: np.ndarray) -> np.ndarray:
        """The influence on ``w``, shape (n_dof, n_nodes, d, n_w)."""
        w = np.asarray(w, dtype=float)
        for om, g in self._kept:
            if om.size == w.size and np.array_equal(om, w):
                return g
        g = self.compute(w)
        self._kept.append((w.copy(), g))
        return g

    def compute(self, w: np.ndarray) -> np.ndarray:
        """ξ = S⁻¹T_Lᵀ(G_R F)_att per unit node force (module notes), not kept."""
        w = np.asarray(w, dtype=float)
        off, s, links, solved = self.state(w)
        model = self.line.system.model
        d, n = model.dim, model.n_nodes
        nb = s.shape[1]
        g = np.zeros((nb, n, d, w.size), dtype=complex)
        t, att = links[self.line.name]
        if not att.size:
            return g
        free = np.array([off[b.name] + i for b in self.base.bodies for i in b.free_index], int)
        tf = t[:, free]
        xi = np.linalg.solve(
            s[:, free[:, None], free[None, :]], np.broadcast_to(tf.T, (w.size,) + tf.T.shape)
        )  # (n_w, n_free, |att|)
        y = np.zeros((w.size, nb, 2 * d), dtype=complex)
        y[:, free[:, None], att[None, :]] = xi
        g[:, 0] = np.transpose(y[:, :, :d], (1, 2, 0))
        g[:, -1] = np.transpose(y[:, :, d:], (1, 2, 0))
        g[:, 1:-1] = -np.einsum("wei,wnki->enkw", y, solved[self.line.name][0])
        return g


class _Rows:
    """Two rows (zero-padded) of a body influence: an influence of two outputs."""

    def __init__(self, body: GroupBodyInfluence, rows: np.ndarray) -> None:
        self.body = body
        self.rows = rows
        self.line = body.line

    def on(self, w: np.ndarray) -> np.ndarray:
        g = self.body.on(w)
        out = np.zeros((2,) + g.shape[1:], dtype=complex)
        out[: self.rows.size] = g[self.rows]
        return out


class BodyRows:
    """The body DOFs of a group as extra output rows of its joint sums (module notes):
    registered as ``shared["extra_rows"]`` of the group's coupled influences
    (:func:`body_rows_of`).

    Parameters
    ----------
    influences : mapping of str to CoupledInfluence
        The group's coupled influences (one per line, one shared state).
    """

    def __init__(self, influences: Mapping[str, CoupledInfluence]) -> None:
        self.influences = dict(influences)
        first = next(iter(self.influences.values()))
        self.n_dof = sum(b.n_dof for b in first.bodies)
        self._body: dict[str, GroupBodyInfluence] = {}
        self._own: dict[str, Any] = {}  # (the grids' solves the end tensions did not ask)
        self._scale: dict[Any, np.ndarray] = {}
        self._parts: dict[Any, tuple[list[tuple[Any, Any]], Callable]] = {}
        #: by joint key: (frequencies [rad/s] (n_o,), variance lines (n_dof, n_o))
        self.lines: dict[Any, tuple[np.ndarray, np.ndarray]] = {}

    def body(self, name: str) -> GroupBodyInfluence:
        """The body influence of line ``name`` (kept: its grids are kept on it)."""
        if name not in self._body:
            self._body[name] = GroupBodyInfluence(self.influences[name], self._state)
        return self._body[name]

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

    def _pairs(self, name: str) -> list[_Rows]:
        b = self.body(name)
        return [_Rows(b, np.arange(k, min(k + 2, self.n_dof))) for k in range(0, self.n_dof, 2)]

    def transfers(
        self,
        key: Any,
        parts: Sequence[tuple[Any, Any]],
        transfer: Callable[[Any, Any, Any], np.ndarray],
        h: np.ndarray,
    ) -> list[np.ndarray]:
        """The body rows' transfers (two rows each, the sources along axis 1 as the
        targets' ``h``), scaled to :data:`ROW_SCALE` of ``h``'s largest."""
        pairs = {src.name: self._pairs(src.name) for src, _ in parts}
        out = [
            np.concatenate([transfer(src, c, pairs[src.name][k]) for src, c in parts], 1)
            for k in range(len(pairs[parts[0][0].name]))
        ]
        top = float(np.abs(h).max(initial=0.0))
        scale = np.ones(2 * len(out))
        for k, t in enumerate(out):
            for r in range(2):
                m = float(np.abs(t[r]).max(initial=0.0))
                if m > 0.0 and top > 0.0:
                    scale[2 * k + r] = ROW_SCALE * top / m
            t *= scale[2 * k : 2 * k + 2].reshape((2,) + (1,) * (t.ndim - 1))
        self._scale[key] = scale
        self._parts[key] = (list(parts), transfer)
        return out

    def keep(self, key: Any, lines: np.ndarray) -> None:
        """The joint sum's lines of the body rows (scaled as :meth:`transfers` gave
        them): unscaled, integrated over the cells, kept by ``key``."""
        v = (lines / self._scale[key][:, None] ** 2)[: self.n_dof]
        parts, transfer = self._parts[key]
        w_out = np.asarray(parts[0][1].w_out, dtype=float)
        v = v * self._cells(parts, transfer, w_out, _BENDS.get(key[0], CELL_BEND))
        self.lines[key] = (w_out, v)

    def _power(self, parts: Sequence[tuple[Any, Any]], transfer: Callable, w: np.ndarray):
        """Σ over every line's components of |body DOFs per unit component|², on
        ``w``: (n_dof, n)."""
        p = np.zeros((self.n_dof, w.size))
        for src, c in parts:
            cw = c if np.array_equal(c.w_out, w) else dataclasses.replace(c, w_out=w)
            for pair in self._pairs(src.name):
                with untapped():
                    t = transfer(src, cw, pair)
                t = np.abs(t.reshape(2, -1, w.size)) ** 2
                p[pair.rows] += t.sum(axis=1)[: pair.rows.size]
        return p

    def _cells(self, parts, transfer, w_out: np.ndarray, bend: float) -> np.ndarray:  # noqa: ANN001
        """The cell factor (n_dof, n_o) of the body rows (module notes; as
        :func:`~.drag_residual.cell_factor`, over every line's components)."""
        power = self._power(parts, transfer, w_out)
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
        p_sub = self._power(parts, transfer, w_sub).reshape(self.n_dof, cells.size, -1)
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


def body_rows_of(influences: Mapping[str, CoupledInfluence]) -> BodyRows | None:
    """The :class:`BodyRows` of a group of several lines on free bodies, registered on
    its influences' shared state (None: a group of one line, or no bodies)."""
    if len(influences) < 2:
        return None
    first = next(iter(influences.values()))
    if not first.bodies or sum(b.n_dof for b in first.bodies) == 0:
        return None
    rows = BodyRows(influences)
    first.shared["extra_rows"] = rows
    return rows


def misfit_parts(
    rows: BodyRows, linear: np.ndarray, spectra: np.ndarray, w: np.ndarray
) -> list[tuple[np.ndarray, np.ndarray]]:
    """The drag residual's linear misfit in the body DOFs: every line's misfit loads δB·v
    (the components the joint sums kept) through its body influence added to the
    bodies' ``linear`` transfer (n_ch, n_dof, n_w) on ``w`` before the variance is
    formed, Σ_c q·S_c(|H_L + H_c|² − |H_L|²): parts (``w``, (n_dof, n_w)) (empty
    without misfit loads). [m², rad²]"""
    w = np.asarray(w, dtype=float)
    kept = next(iter(rows.influences.values())).shared.get("components", {})
    keys = {}  # (one joint key per kind: those of the body lines)
    for key in rows.lines:
        keys.setdefault(key[0], key)
    h_c = np.zeros_like(linear)
    found = False
    for key, name in list(kept):
        c = kept[key, name]
        if c is None or keys.get(key[0]) != key or key[0] not in ("drag", "drag_3d"):
            continue
        line = rows.influences[name].line
        if key[0] == "drag":
            mis = misfit_loads(line.system.model, c.seg, c.groups, c.live, c.parts, c.misfit)
        elif c.db is not None:
            v = np.stack([c.pan["n1"], c.pan["n2"], c.pan["t"]], axis=1)
            load = np.einsum("pab,cbpw->capw", c.db, v)
            mis = (c.unit, load.reshape(load.shape[0], -1, w.size))
        else:
            mis = None
        if mis is None:
            continue
        with untapped():
            h = load_transfer(line.system, line.damping, mis[0], w, rows.body(name))
        h_c += np.einsum("okw,ckw->cow", h, mis[1])
        found = True
    if not found:
        return []
    q = trapezoid_weights(w)[None, None] * spectra[:, None]
    return [(w, np.sum(q * (np.abs(linear + h_c) ** 2 - np.abs(linear) ** 2), axis=0))]
