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
from stochcable.dynamics.residuals.drag_hermite import hermite_coefficients
from stochcable.dynamics.residuals.drag_segments import Segments, panel_loads
from stochcable.dynamics.residuals.residual_lines import (
    RESIDUAL_TAP,
    UniformGrid,
    load_transfer,
)

__all__ = ["misfit_loads", "misfit_scales", "misfit_variance"]


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


def misfit_scales(
    seg: Segments,
    groups: list[np.ndarray],
    c_el: np.ndarray,
    mean_el: np.ndarray,
    b_el: np.ndarray,
    sig: np.ndarray,
) -> np.ndarray:
    """δB·l of every panel (0 but on the pieces of split elements): the pointwise linear
    fit B_s = cσ_s a₁(U/σ_s) of each piece against its element's constant B, scaled so
    that a uniform field gives none (B_e·(B_s/B̂_e − 1), B̂_e the fit of the pieces'
    length-weighted mean variance, the linear model's σ² in the pieces' terms). [N·s/m]"""
    out = np.zeros(len(groups))
    first = np.array([int(g[0]) for g in groups])
    el = seg.element[first]
    # the panels of split elements (one piece each), by element
    split = np.zeros(int(seg.element.max(initial=0)) + 1, dtype=bool)
    split[seg.element[seg.fine]] = True  # (a lookup table: np.isin sorts both)
    pan = np.flatnonzero(split[el])
    if pan.size == 0:
        return out
    els, at = np.unique(el[pan], return_inverse=True)
    length = seg.length[first[pan]]
    var = np.bincount(at, length * sig[pan] ** 2) / np.bincount(at, length)
    ok = (var > 0.0) & (b_el[els] > 0.0)
    use = ok[at]
    pan, at, length = pan[use], at[use], length[use]
    if pan.size == 0:
        return out
    sig_e = np.sqrt(np.where(ok, var, 1.0))
    # a₁ of every piece and of each element's mean variance: one evaluation
    mu = np.concatenate(
        [mean_el[el[pan]] / np.where(sig[pan] > 0, sig[pan], np.inf), mean_el[els[ok]] / sig_e[ok]]
    )
    a1 = hermite_coefficients(np.clip(mu, -10.0, 10.0), 1)[:, 1]
    a_e = np.zeros(els.size)
    a_e[ok] = a1[pan.size :]
    ratio = sig[pan] * a1[: pan.size] / (sig_e[at] * a_e[at])
    out[pan] = b_el[els[at]] * (ratio - 1.0) * length
    return out
