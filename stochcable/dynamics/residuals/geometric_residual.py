"""The end-tension variance the linear (small-displacement) model drops: the second-order
geometric forces of the linear response, in closed form.

A straight bar element of static length l, tangent t and effective tension T₀ carries
the force T·ℓ̂ on its end b, with ℓ = l·t + Δu (Δu = u_b − u_a) and T = T₀ + EA(|ℓ| −
l)/L₀ (L₀ the unstretched length).  To second order in Δu = a·t + b (a = t·Δu, b ⊥ t),

    T·ℓ̂ = T₀t + [(EA/L₀)·a·t + (T₀/l)·b] + κ·[½|b|²·t + a·b],   κ = (EA/L₀ − T₀/l)/l,

the bracket being the model's linear (elastic and geometric) stiffness (Tuah 1982, §3.1)
and the last term the quadratic force it drops: Green–Lagrange stretching ½|b|²/l under
the axial stiffness and the rotation of the axial force by the transverse motion.  With
the linear response Gaussian, every component of κ[½|b|²·t + a·b] is a Gaussian
quadratic form whose cross-covariances between elements are sums of products of two
linear cross-covariances (Isserlis: Cov(x₁y₁, x₂y₂) = R_{x₁x₂}R_{y₁y₂} +
R_{x₁y₂}R_{y₁x₂}); they are uncorrelated with the linear response (odd moments vanish),
so the response to them adds to the linear variance:
Var(ΔT) = Σ_ij ∫ H_T,i*(ω) G_ij(ω) H_T,j(ω) dω, H_T,i the end tension per unit force
pair of component i (+ on node b, − on node a), through the same linear system — the
second-order (Volterra) term of the response (Roberts and Spanos, "Random Vibration and
Statistical Linearization", §5; the quadratic forms of
:mod:`stochcable.dynamics.residuals.second_order` are its stretching part alone, without the line's
response to them).  It acts at the sum and difference frequencies of the response.

Validation: the chain's line (fairlead surge) against the nonlinear time domain with the
frequency domain's linear drag, i.e. geometric nonlinearity alone
(docs/benchmarks/drag_residual.md).  Scope: at most
:data:`MAX_ELEMENTS` elements (the cost is O(elements² · n_fft log n_fft)); a line on
free bodies through its coupled influence (:mod:`.body_residual`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from stochcable.dynamics.residuals.body_residual import untapped, with_group_lines
from stochcable.dynamics.residuals.drag_residual import CELL_BEND, cell_factor
from stochcable.dynamics.residuals.influence import element_frames, element_lengths
from stochcable.dynamics.residuals.residual_lines import MAX_LINES as RESIDUAL_LINES
from stochcable.dynamics.residuals.residual_lines import (
    EndInfluence,
    PairLines,
    along_each,
    fft_length,
    load_transfer,
    pair_blocks,
    pair_lags,
    residual_record,
    uniform_grid,
)
from stochcable.results.records import ResidualRecord

__all__ = ["MAX_ELEMENTS", "geometric_residual", "quadratic_output_lines"]

#: Its uniform grid: every LINE_STRIDE-th line of the drag residual's (2: 32 lines, a
#: lag grid of 125, against 64 and 256; its end influence a part of the drag's): its
#: share of the corrected σ is small (≤ 0.6 % on the benchmark lines), so its own error
#: matters less than the drag's. [-]
LINE_STRIDE = 2
#: Most lines of its grid (every second of the drag residual's at most 64). [-]
MAX_LINES = RESIDUAL_LINES // LINE_STRIDE
#: Elements whose quadratic force σ times their largest end tension per unit force is
#: below this fraction of the line's largest are left out (:func:`_live_elements`): the
#: chain's 19 grounded elements of 40 (their share of its variance 5e-8), the
#: two-segment line's 23 (4e-11); pairs 820 → 231 and 153. [-]
ELEMENT_FLOOR = 1e-4
#: Most elements the residual is computed for. [-]
MAX_ELEMENTS = 400


def geometric_residual(
    system: Any,
    channels: Any,
    linearization: Any,
    std: dict[str, float],
    influence: EndInfluence | None = None,
) -> ResidualRecord:
    """The end-tension variance of the second-order geometric forces of one line's
    linear response (module notes).

    Parameters
    ----------
    system : LineSystem
        The line alone (ends prescribed).
    channels : tuple of Channel
        Its inputs on the analysis grid.
    linearization : Linearization
        The converged fixed point (its ``response`` and ``damping``).
    std : dict {"end_a", "end_b"} of float
        The linear end-tension σ. [N]
    influence : EndInfluence, optional
        The line's end influence, shared with its other residual.

    Returns
    -------
    ResidualRecord
        The record (``order`` 2: quadratic forces; ``panels``: the elements);
        ``computed`` False above :data:`MAX_ELEMENTS` elements.
    """
    model = system.model
    n_el = model.n_elements
    if n_el > MAX_ELEMENTS:
        return ResidualRecord.not_computed(
            f"{n_el} elements: above {MAX_ELEMENTS} (the cost grows with their square)", std
        )
    resp = linearization.response
    w = np.asarray(resp.omega, dtype=float)
    # a line on bodies: the group's lines' quadratic forces through the bodies as one
    # set of components (their cross terms count), formed once for the group (the
    # lines' components kept there)
    coupled = None if influence is None or isinstance(influence, EndInfluence) else influence
    joint = None if coupled is None else _joint(coupled)
    c = (
        geometric_components(system, channels, linearization)
        if joint is None
        else coupled.shared["components"][("geometric",), system.name]
    )
    proc, comp_terms, unit, w_out, n_fft = c.proc, c.terms, c.unit, c.w_out, c.n_fft
    # (2, n_comp·n_el, n_o)
    h = load_transfer(system, linearization.damping, unit, w_out, influence)
    keep = _live_elements(proc, comp_terms, h)
    cols = (np.arange(len(comp_terms))[:, None] * n_el + keep[None]).ravel()
    proc, h_k, unit_k = [x[:, keep] for x in proc], h[:, cols], unit[:, :, cols]
    # the cells of a resonance narrower than a line integrated, as the drag's (a bend
    # of the log power scales with the line spacing squared: the drag's threshold at
    # its lines; chain: 26 cells at the drag's threshold, none at this one)
    own = quadratic_output_lines(proc, comp_terms, h_k, n_fft)
    cf = cell_factor(system, linearization.damping, unit_k, w_out, h_k, CELL_BEND * LINE_STRIDE**2)
    out = residual_record(own * cf, w_out, w, std, 2, n_el)
    if joint is not None:
        out = with_group_lines(out, w_out, joint[0] * cf, w, std)
    return out


@dataclass(frozen=True, eq=False)
class GeometricComponents:
    """The quadratic force components of one line (:func:`geometric_components`): the
    processes' lines (each (n_ch, n_el, n_j)), the components' terms, the unit node
    loads (n_nodes, d, n_comp·n_el, component-major), the lines ``w_out`` [rad/s] and
    the lag grid ``n_fft``."""

    proc: list[np.ndarray]
    terms: list[list[tuple[float, int, int]]]
    unit: np.ndarray
    w_out: np.ndarray
    n_fft: int


def geometric_components(system: Any, channels: Any, linearization: Any) -> GeometricComponents:
    """The quadratic force components of a line's geometric residual (module notes)."""
    model = system.model
    n_el = model.n_elements
    resp = linearization.response
    w = np.asarray(resp.omega, dtype=float)
    comps = list(model.components)
    d = model.dim
    n_ch = len(channels)
    # the split touchdown element's suspended part's l and L₀ (shared with the
    # element tensions' own stretch, influence.geometric_feedthrough)
    length, l0 = element_lengths(system)
    frames = element_frames(system)  # the split element along its suspended part
    # the motions on the model's components (a planar line's frames have no third)
    u = np.asarray(resp.displacement, dtype=complex).reshape(w.size, model.n_nodes, d, n_ch)
    du = u[:, 1:] - u[:, :-1]  # (n_w, n_el, d, n_ch)
    mesh = model.mesh
    # the element split at the touchdown: its suspended part, as the linear model's
    split = _suspended_part(model, u, du)
    spectra = np.stack([ch.spectrum for ch in channels])
    grid = uniform_grid(w, None, LINE_STRIDE, spectra)
    # a = t·Δu, b_k = n_k·Δu per element: (n_procs, n_el) lines each
    # (both processes placed on the grid at once, each a view of the lines)
    xs = along_each(du, [f[:, comps] for f in frames])
    both = grid.lines(np.concatenate(xs, axis=1), spectra)  # (n_ch·ranks, n_p·n_el, n_j)
    proc = [both[:, k * n_el : (k + 1) * n_el] for k in range(len(xs))]
    kappa = (mesh.ea / l0 - np.asarray(system.statics.tension) / length) / length
    # components per element: ½Σ_k b_k² along t, a·b_k along n_k — as (coef, x, y) terms
    comp_terms = [[(0.5, k, k) for k in range(1, len(frames))]] + [
        [(1.0, 0, k)] for k in range(1, len(frames))
    ]
    # unit pairs κ·f_e: + on node e + 1, − on node e (component-major columns); the
    # split element's − on its condensed touchdown node, i.e. on its nodes by Rᵀ
    unit = np.zeros((model.n_nodes, d, len(comp_terms), n_el))
    el = np.arange(n_el)
    for i, f in enumerate(frames):
        force = kappa[:, None] * f[:, comps]  # (n_el, d)
        unit[el + 1, :, i, el] += force
        unit[el, :, i, el] -= force
        if split is not None:
            k, r_t = split
            unit[k, :, i, k] += force[k] - r_t[:, :d].T @ force[k]
            unit[k + 1, :, i, k] -= r_t[:, d:].T @ force[k]
    unit = unit.reshape(model.n_nodes, d, -1)
    n_o = 2 * (grid.n_j - 1)
    w_out = grid.step * np.arange(1, n_o + 1)
    n_fft = fft_length(4 * (grid.n_j - 1) + 1)  # (products reach line 2·(n_j − 1))
    return GeometricComponents(proc, comp_terms, unit, w_out, n_fft)


def _suspended_part(
    model: Any,
    u: np.ndarray,
    du: np.ndarray,
) -> tuple[int, np.ndarray] | None:
    """The element that the linear model splits at the static touchdown
    (:attr:`stochcable.line.fem.FEModel.bed`) as its suspended part t–b, in place:
    ``du`` (on the model's components) its u_b − u_t (u_t = R·[u_a; u_b] the condensed
    touchdown node's motion),
    (its frames and l, L₀: :func:`~stochcable.dynamics.residuals.influence.element_frames`,
    :func:`~stochcable.dynamics.residuals.influence.element_lengths`).  The
    chord a–b instead picks up the upper node's heave in its axial motion (×7 on a leg
    whose first suspended node is 0.7 ft above the bed: +5 % of σ at 20 elements,
    +0.2 % at 21, docs/accuracy/bodies.md); the grounded part, held by the bed, is left
    out.  Returns (the element, R) or None (no split element)."""
    bed = getattr(model, "bed", None)
    if bed is None or bed.element is None:
        return None
    k, d = bed.element, model.dim
    r_t = np.asarray(bed.transform, dtype=float)[d : 2 * d]  # (d, 2d)
    ab = np.concatenate([u[:, k], u[:, k + 1]], axis=1)  # (n_w, 2d, n_ch)
    du[:, k] = u[:, k + 1] - np.einsum("ij,wjc->wic", r_t, ab)
    return k, r_t


def _joint(coupled: Any) -> Any:
    """The group's part of the geometric residual of a line on bodies: the lines of the
    joint sum over every line's elements less the line's own elements' pairs
    (:meth:`~stochcable.dynamics.residuals.body_residual.CoupledInfluence.joint_lines`)."""

    def components(ln: Any) -> GeometricComponents | None:
        if ln.system.model.n_elements > MAX_ELEMENTS:
            return None
        return geometric_components(ln.system, ln.channels, ln.linearization)

    def transfer(ln: Any, c: GeometricComponents, infl: Any) -> np.ndarray:
        with untapped():
            h = load_transfer(ln.system, ln.damping, c.unit, c.w_out, infl)
        n_el = c.proc[0].shape[1]
        return np.swapaxes(h.reshape(2, len(c.terms), n_el, -1), 1, 2)  # element-major

    def outputs(cs: list[GeometricComponents], t: np.ndarray) -> np.ndarray:
        if any(not np.array_equal(c.w_out, cs[0].w_out) or len(c.terms) != len(cs[0].terms)
               for c in cs):  # fmt: skip
            raise ValueError("the group's lines have different residual grids or forms")
        proc = [np.concatenate([c.proc[k] for c in cs], axis=1) for k in range(len(cs[0].proc))]
        n_tot = proc[0].shape[1]
        flat = np.swapaxes(t, 1, 2).reshape(t.shape[0], -1, t.shape[3])
        with untapped():
            out = quadratic_output_lines(proc, cs[0].terms, flat, cs[0].n_fft)
            at = 0  # (less each target's own elements' pairs: its own lines)
            for i, c in enumerate(cs):
                n_el = c.proc[0].shape[1]
                own_cols = (np.arange(len(c.terms))[:, None] * n_tot + at + np.arange(n_el)).ravel()
                out[2 * i : 2 * i + 2] -= quadratic_output_lines(
                    [p[:, at : at + n_el] for p in proc],
                    c.terms,
                    flat[2 * i : 2 * i + 2][:, own_cols],
                    c.n_fft,
                )
                at += n_el
        return out

    return coupled.joint_lines(("geometric",), components, transfer, outputs)


def _live_elements(
    processes: list[np.ndarray], terms: list[list[tuple[float, int, int]]], h: np.ndarray
) -> np.ndarray:
    """The elements (indices) whose quadratic forces can reach the ends: the largest
    over their components of Σ|coef|·σ_x·σ_y times the largest end tension per unit
    component at least :data:`ELEMENT_FLOOR` of the line's largest."""
    sig = [np.sqrt(np.sum(np.abs(p) ** 2, axis=(0, 2))) for p in processes]
    n_el = sig[0].size
    reach = np.abs(h).max(axis=(0, 2)).reshape(len(terms), n_el)
    score = np.max(
        [sum(abs(c) * sig[x] * sig[y] for c, x, y in t) * reach[i] for i, t in enumerate(terms)],
        axis=0,
    )
    return np.flatnonzero(score >= ELEMENT_FLOOR * np.max(score, initial=0.0))


def quadratic_output_lines(
    processes: list[np.ndarray],
    terms: list[list[tuple[float, int, int]]],
    transfer: np.ndarray,
    n_fft: int,
) -> np.ndarray:
    """Spectral lines of outputs driven by Gaussian quadratic forms of each element.

    Parameters
    ----------
    processes : list of ndarray, complex, each (n_ch, n_el, n_j)
        Zero-mean jointly Gaussian processes per element as lines on a uniform grid
        (:meth:`~stochcable.dynamics.residuals.residual_lines.UniformGrid.lines`).
    terms : list of list of (float, int, int)
        Each force component of an element as Σ coef·x·y of its processes (by index).
    transfer : ndarray, complex, shape (n_out, n_comp · n_el, n_o)
        Outputs per unit of each component of each element (component-major) at ω_j,
        j = 1 … n_o.
    n_fft : int
        Samples of the lag grid, ≥ 4·(n_j − 1) + 1.

    Returns
    -------
    ndarray, shape (n_out, n_o)
        Variance lines of the outputs (Isserlis: Cov(x₁y₁, x₂y₂) = R_{x₁x₂}R_{y₁y₂} +
        R_{x₁y₂}R_{y₁x₂}; the means of the forms, a static shift, left out).
    """
    n_p = len(processes)
    n_el = processes[0].shape[1]
    n_o = transfer.shape[2]
    # Σ_c conj(x_ce)·y_cf per line of every two processes and elements: one product of
    # the processes side by side (per line a (n_p·n_el)² matrix, its blocks views)
    both = np.ascontiguousarray(np.concatenate(processes, axis=1).transpose(2, 0, 1))
    every = np.conj(both).transpose(0, 2, 1) @ both  # (n_j, n_p·n_el, n_p·n_el)
    every[0] *= 2.0  # (irfft halves the zero-frequency line: pair_lags)
    cross = {
        (x, y): every[:, x * n_el : (x + 1) * n_el, y * n_el : (y + 1) * n_el]
        for x in range(n_p)
        for y in range(n_p)
    }
    # the elements f ≥ e (G_fe = conj(G_ef): the pairs f > e count twice), in blocks
    out = PairLines(transfer)
    for e, f in pair_blocks(n_el, n_fft, 2):
        r = {xy: pair_lags(c, e, f, n_fft) for xy, c in cross.items()}  # R·2/n_fft
        # the pairs f > e weighted 2, covariance_lines' 2/n_fft and the lags' (n_fft/2)²
        twice = np.where(f > e, float(n_fft), 0.5 * n_fft)[:, None]  # (4/n_fft)·(n_fft/2)²
        for i, terms_i in enumerate(terms):
            for j, terms_j in enumerate(terms):
                cov = sum(
                    ci * cj * _isserlis(r, x1, y1, x2, y2)
                    for ci, x1, y1 in terms_i
                    for cj, x2, y2 in terms_j
                )
                cov *= twice
                # e's component i, f's j (transfer columns component-major)
                out.add(np.fft.rfft(cov, axis=1)[:, 1 : n_o + 1], i * n_el + e, j * n_el + f)
    return out.outputs()


def _isserlis(r: dict, x1: int, y1: int, x2: int, y2: int) -> np.ndarray:
    """R_{x₁x₂}R_{y₁y₂} + R_{x₁y₂}R_{y₁x₂} of the lag functions ``r`` (by process pair);
    where the two products have the same factors (x₁ = y₁ or x₂ = y₂) one is formed and
    doubled (the same numbers: the products commute and p + p is exact)."""
    first = r[x1, x2] * r[y1, y2]
    if x1 == y1 or x2 == y2:
        first += first
        return first
    return first + r[x1, y2] * r[y1, x2]
