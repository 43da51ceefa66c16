"""The 3-D drag residual's linear misfit (:mod:`.drag_residual_3d`, module notes): the
Gaussian fit of each panel's own velocity statistics against the model's form at its
element's, and the end-tension variance its loads δB·v change through the line's, or on
a shared body the group's, end tensions (the other lines' misfit loads through their
coupled influence, :mod:`.body_residual`).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from stochcable.dynamics.linearization.formulas import drag_linear_vector, mean_abs_gaussian
from stochcable.dynamics.model.blocks import trapezoid_weights
from stochcable.dynamics.residuals.body_residual import untapped
from stochcable.dynamics.residuals.residual_lines import RESIDUAL_TAP, load_transfer

__all__ = ["misfit_3d", "misfit_variance_3d", "panel_sum"]


def panel_sum(c_el: np.ndarray, seg: Any, groups: list[np.ndarray]) -> np.ndarray:
    """Σ c·l over each panel's pieces (the drag constant times length). [N·s²/m²]"""
    return np.array([float(np.sum(c_el[seg.element[g]] * seg.length[g])) for g in groups])


def _reference(values: np.ndarray, seg: Any, groups: list[np.ndarray]) -> np.ndarray:
    """Per panel: its own ``values`` (n_p, …), or for the pieces of a split element
    their element's length-weighted mean (the statistics its constant B was formed
    from)."""
    out = values.copy()
    first = np.array([int(g[0]) for g in groups])
    for e in np.unique(seg.element[seg.fine]):
        idx = np.flatnonzero(seg.element[first] == e)
        share = seg.length[first[idx]] / seg.length[first[idx]].sum()
        out[idx] = np.tensordot(share, values[idx], axes=1)
    return out


def misfit_3d(
    damping: Any,
    seg: Any,
    groups: list[np.ndarray],
    c_n: np.ndarray,
    c_t: np.ndarray,
    cov: np.ndarray,
    mean: np.ndarray,
    sig_t: np.ndarray,
    mean_t: np.ndarray,
    scale_n: np.ndarray,
    scale_t: np.ndarray,
) -> np.ndarray | None:
    """δB·l of every panel, (n_p, 3, 3) in (n₁, n₂, t) (None where it vanishes): the
    Gaussian fit of the panel's own statistics, c·E[|v|I + vvᵀ/|v|] (normal) and
    2c·E|v_t| (axial), minus the model's form at its element's statistics (the
    panel's, or the mean over a split element's pieces), scaled so that the model's
    form gives its actual B (a uniform field under the ``vector`` method gives
    none). [N·s/m]"""
    n_p = len(groups)
    length = np.array([float(seg.length[g].sum()) for g in groups])
    ref_cov, ref_mean = _reference(cov, seg, groups), _reference(mean, seg, groups)
    ref_var_t = _reference(sig_t**2, seg, groups)
    has_mean = bool(np.any(mean != 0.0))
    e_true = drag_linear_vector(1.0, 1.0, 2.0, cov, mean if has_mean else None)
    if damping.method == "vector":
        e_model = drag_linear_vector(1.0, 1.0, 2.0, ref_cov, ref_mean if has_mean else None)
    else:  # the seed form: isotropic, from the total normal variance and |m|
        tr = np.sqrt(np.clip(np.trace(ref_cov, axis1=1, axis2=2), 0.0, None))
        e_abs = 2.0 * mean_abs_gaussian(tr, np.linalg.norm(ref_mean, axis=1))
        e_model = e_abs[:, None, None] * np.eye(2)[None]
    b_n = np.asarray(damping.b_normal, dtype=float)
    b_n = 0.5 * np.trace(b_n, axis1=1, axis2=2) if b_n.ndim == 3 else b_n
    b_bar = panel_sum(b_n, seg, groups) / length
    c_bar = scale_n / length
    half_tr = 0.5 * np.trace(e_model, axis1=1, axis2=2)
    live = (c_bar * half_tr) > 0
    k = np.where(live, b_bar / np.where(live, c_bar * half_tr, 1.0), 0.0)
    out = np.zeros((n_p, 3, 3))
    out[:, :2, :2] = (scale_n * k)[:, None, None] * (e_true - e_model)
    # axial: the scalar fit of the piece against its element's (0 on whole elements)
    e_t = 2.0 * mean_abs_gaussian(sig_t, mean_t)
    e_t_ref = 2.0 * mean_abs_gaussian(np.sqrt(ref_var_t), mean_t)
    b_t = panel_sum(np.asarray(damping.b_axial, dtype=float), seg, groups) / length
    ct_bar = scale_t / length
    live_t = (ct_bar * e_t_ref) > 0
    k_t = np.where(live_t, b_t / np.where(live_t, ct_bar * e_t_ref, 1.0), 0.0)
    out[:, 2, 2] = scale_t * k_t * (e_t - e_t_ref)
    size = np.abs(out).max(initial=0.0)
    ref = max(float(np.max(np.abs(b_bar * length), initial=0.0)), 1e-300)
    return None if size <= 1e-12 * ref else out


def misfit_variance_3d(
    resp: Any, spectra: np.ndarray, sources: list[tuple[Any, Any, Any, Any]]
) -> dict[str, np.ndarray]:
    """The end-tension variance change of the linear misfit loads δB·v of every panel
    (Σ_c S_c(|H_L + H_c|² − |H_L|²) times the trapezoid weights), as lines on the
    analysis grid; ``sources`` (system, damping, components, influence) the line's own
    (influence None: ends held, or its coupled influence) and, on bodies, the group's
    other lines with their influence on its end tensions: their H_c add. [N²]"""
    if not sources:
        return {}
    w = np.asarray(resp.omega, dtype=float)
    h_c = 0.0
    for k, (system, damping, c, infl) in enumerate(sources):
        v = np.stack([c.pan["n1"], c.pan["n2"], c.pan["t"]], axis=1)  # (n_ch, 3, n_p, n_w)
        load = np.einsum("pab,cbpw->capw", c.db, v)  # along n₁, n₂, t
        if k == 0:
            h = load_transfer(system, damping, c.unit, w, infl)  # (2, 3·n_p, n_w)
            if (tap := RESIDUAL_TAP.get()) is not None:  # (the element tensions': .along_line_3d)
                tap.misfit(c.unit, load.reshape(load.shape[0], -1, w.size), w)
        else:
            with untapped():
                h = load_transfer(system, damping, c.unit, w, infl)
        h_c = h_c + np.einsum("okw,ckw->ocw", h, load.reshape(load.shape[0], -1, w.size))
    q = trapezoid_weights(w)[None] * spectra
    out = {}
    for o, end in enumerate(("end_a", "end_b")):
        h_l = np.asarray(resp.end_tension[end])
        out[end] = np.sum(q * (np.abs(h_l + h_c[o]) ** 2 - np.abs(h_l) ** 2), axis=0)
    return out
