"""The drag residual's linear misfit of the element-constant drag (a planar line) through
the line's, or on a shared body the group's, end tensions: its loads δB·l·v on the
pieces of split elements are linear in the response, so their end tension adds to the
linear one before the variance is formed (:mod:`.drag_residual`, module notes; on
bodies the other lines' misfit loads through their coupled influence,
:mod:`.body_residual`).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from stochcable.dynamics.model.blocks import trapezoid_weights
from stochcable.dynamics.residuals.body_residual import untapped
from stochcable.dynamics.residuals.drag_segments import Segments, panel_loads
from stochcable.dynamics.residuals.residual_lines import (
    RESIDUAL_TAP,
    UniformGrid,
    load_transfer,
)

__all__ = ["misfit_loads", "misfit_variance"]


def misfit_variance(
    system: Any,
    damping: Any,
    resp: Any,
    spectra: np.ndarray,
    seg: Segments,
    groups: list[np.ndarray],
    live: list[str],
    parts: dict[str, Any],
    misfit: list[tuple[np.ndarray, np.ndarray]],
    lines: tuple[UniformGrid, np.ndarray, Any, np.ndarray],
    coupled: Any = None,
    others: list[tuple[Any, Any]] | None = None,
    exact: bool = False,
    unit_all: np.ndarray | None = None,
) -> dict[str, np.ndarray]:
    """The end-tension variance the linear misfit of the element-constant drag changes,
    as lines on the analysis grid (empty without split elements): its load δB·l·v on
    the pieces of split elements is linear in the response, so its end tension H_c
    adds to the linear H_L (Σ_c S_c (|H_L + H_c|² − |H_L|²) times the trapezoid
    weights of the linear σ; it may be negative). [N²]

    ``lines`` (grid, w_out, influence, bent): the end tensions per unit load are taken
    at the residual's line nearest each analysis frequency (no solve of their own:
    chain 0.2 % of the misfit's variance, itself 0.04 % of the residual's), and solved
    at the frequency itself where the line's cell is ``bent`` (a resonance narrower than
    a line; on the inclined guy 253 of its 300 frequencies; all of them with
    ``exact``),
    through ``coupled`` (a line on bodies: its coupled influence) where given.
    ``others`` (a line on bodies): the group's other lines' components with their
    influence on this line's end tensions (:mod:`.drag_residual`); their misfit loads
    add to H_c (taken at the analysis frequencies) before the variance is formed.
    ``unit_all``: the components' unit loads (:func:`misfit_loads`)."""
    w = np.asarray(resp.omega, dtype=float)
    h_c = np.zeros((2, spectra.shape[0], w.size), dtype=complex)
    mis = misfit_loads(system.model, seg, groups, live, parts, misfit, unit_all)
    if mis is not None:
        unit, load = mis
        grid, w_out, influence, bent = lines
        at = np.clip(grid.index - 1, 0, w_out.size - 1)  # (line j is w_out[j − 1])
        h = load_transfer(system, damping, unit, w_out[: at.max() + 1], influence)[:, :, at]
        solved = np.arange(w.size) if exact else np.flatnonzero(bent[at])
        if solved.size:
            h[:, :, solved] = load_transfer(system, damping, unit, w[solved], coupled)
        if (tap := RESIDUAL_TAP.get()) is not None:  # (the element tensions': .along_line)
            tap.misfit(unit, load, w)
        h_c += _outputs(h, load)
    for c, infl in others or ():  # (through the bodies: H_c of this line's ends)
        mis = misfit_loads(
            infl.line.system.model, c.seg, c.groups, c.live, c.parts, c.misfit, c.unit
        )
        if mis is not None:
            with untapped():
                h = load_transfer(infl.line.system, infl.line.damping, mis[0], w, infl)
            h_c += _outputs(h, mis[1])
    if not np.any(h_c):
        return {}
    q = trapezoid_weights(w)[None] * spectra
    out = {}
    for o, end in enumerate(("end_a", "end_b")):
        h_l = np.asarray(resp.end_tension[end])
        out[end] = np.sum(q * (np.abs(h_l + h_c[o]) ** 2 - np.abs(h_l) ** 2), axis=0)
    return out


def _outputs(h: np.ndarray, load: np.ndarray) -> np.ndarray:
    """Σ_p h[o, p, w]·load[c, p, w], shape (n_out, n_ch, n_w) (``np.einsum("opw,cpw->ocw")``
    as one batched product over the frequencies)."""
    return np.transpose(np.transpose(h, (2, 0, 1)) @ np.transpose(load, (2, 1, 0)), (1, 2, 0))


def misfit_loads(
    model: Any,
    seg: Segments,
    groups: list[np.ndarray],
    live: list[str],
    parts: dict[str, Any],
    misfit: list[tuple[np.ndarray, np.ndarray]],
    unit_all: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray] | None:
    """The misfit's unit node loads (n_nodes, d, n_load) and its loads per channel
    (n_ch, n_load, n_w) on the panels with a δB (None: none); ``unit_all``: every
    panel's unit loads along every direction of ``live`` (direction-major, the drag
    components' :func:`~.drag_segments.panel_loads`), whose columns they are (a panel's
    loads are its pieces' alone: the same numbers formed with any set of panels)."""
    keep = [(k, np.flatnonzero(m)) for k, (_, m) in enumerate(misfit) if np.any(m)]
    if not keep:
        return None
    if unit_all is not None:
        cols = np.concatenate([k * len(groups) + idx for k, idx in keep])
        unit = unit_all[:, :, cols]
    else:
        sel = [[groups[i] for i in idx] for _, idx in keep]
        unit = np.concatenate(
            [panel_loads(model, seg, g, [parts[live[k]][2]]) for (k, _), g in zip(keep, sel)],
            axis=2,
        )
    load = np.concatenate(
        [misfit[k][1][idx][None, :, None] * misfit[k][0][:, idx] for k, idx in keep], axis=1
    )  # (n_ch, n_load, n_w)
    return unit, load
