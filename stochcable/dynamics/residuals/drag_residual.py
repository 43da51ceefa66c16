"""The end-tension variance the statistical drag linearization drops, in closed form.

The statistical linearization (Tuah 1982, eqs. 5.2.2–5.2.5; Borgman 1972) replaces the
Morison drag c|v|v of a Gaussian relative velocity v ~ N(U, σ²) by its best linear
fit a₀ + B·(v − U).  The rest, the drag residual r, is a known function of the
linear response: with x = (v − U)/σ and the Hermite expansion of
g(μ + x) = |μ + x|(μ + x), μ = U/σ,

    c|v|v = cσ² Σ_k a_k(μ) He_k(x),   a_k = E[g(μ + x) He_k(x)]/k!,

the linearization keeps k = 0, 1 (B = cσa₁ = 2cE|v|, the Borgman / Gaussian form)
and drops r = cσ² Σ_{k≥2} a_k He_k(x).  For jointly Gaussian velocities of two
elements with normalized cross-correlation ρ_ef(τ) (Mehler's formula,
E[He_j(x)He_k(y)] = δ_jk k! ρ^k),

    E[r_e(t) r_f(t + τ)] = c_e c_f σ_e² σ_f² Σ_{k≥2} k! a_k^e a_k^f ρ_ef(τ)^k,

and the residual is uncorrelated with every linear functional of the Gaussian field
at every lag (Hermite orthogonality), so its response adds to the linear response's
variance without a cross term: Var(ΔT) = Σ_ef ∫ H_T,e*(ω) G_r,ef(ω) H_T,f(ω) dω,
H_T,e the end tension per unit force on element e.  This is the second term of the
Wiener–Hermite expansion of the response about the equivalent linear system (first
order in the residual; Spanos and Donley 1991, Roberts and Spanos "Random Vibration
and Statistical Linearization" §5).  ρ^k is a k-fold convolution of the velocity
spectra: the residual loads the line in band (difference frequencies) and at the
superharmonics (sums), up to k·ω_max.

The drag is pointwise, c|v(ξ)|v(ξ) along an element, but the linear model takes one B_e
per element (σ_e² the element mean of the pointwise variance).  Where the kinematics
vary along an element (near the surface) the dropped drag has a linear part as well,
(B(ξ) − B_e)·v(ξ) with B(ξ) = cσ(ξ)a₁ the pointwise fit (Hermite order 1 about B_e
instead of 0): it is correlated with the linear response, so its end tension H_c
enters with its cross term, Σ_c ∫ S_c (|H_L + H_c|² − |H_L|²) dω, and may lower σ.
Such elements are split into pieces evaluated one by one, each loading its element's
nodes where it lies (:mod:`stochcable.dynamics.residuals.drag_segments`); the orders k ≥ 2 stay
uncorrelated with both linear parts.  Without the split, the inclined guy's 26 m top
element at z = 0 took the residual as one mean velocity spread evenly over its two
nodes, and the correction read +38 % at the fairlead, mostly on the line's 0.7 %-damped
mode at 1.19 rad/s, against +14 % for the quadratic drag in the time domain; a time
domain with the FD's linear drag plus the dropped drag of the fluid velocity reads
+16 % taken pointwise and +32 % taken as element means spread evenly
(docs/benchmarks/drag_residual.md).

Validation: the closed form of the residual's cross-spectrum, and of the split
element's misfit plus residual, against Monte-Carlo Gaussian realizations
(tests/dynamics/test_drag_residual.py, tests/dynamics/test_drag_segments.py), and the
corrected σ against the nonlinear time domain (the chain's quadratic-drag shift, the
taut wire and the inclined guy in their seas: docs/benchmarks/drag_residual.md).

Scope: planar lines (the normal velocity a scalar), the seed linearization, normal and
axial drag of the line elements (attachment drag is not included), each element at
its mean relative velocity; 3-D lines: :mod:`.drag_residual_3d`; a line on free bodies
through its coupled influence, with the panels of the group's other lines as components
of one sum (cross terms included) and their misfit loads (:mod:`.body_residual`).
Elements (and pieces) are grouped into at most :data:`MAX_PANELS` panels (the cost is
O(panels² · n_fft log n_fft)).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from stochcable.dynamics.linearization.variance import current_split
from stochcable.dynamics.residuals.body_residual import untapped, with_group_lines
from stochcable.dynamics.residuals.drag_hermite import (
    HERMITE_ORDER,
    LUMPED_ORDER,
    hermite_coefficients,
    lumped_coefficients,
)
from stochcable.dynamics.residuals.drag_misfit import misfit_scales, misfit_variance
from stochcable.dynamics.residuals.drag_segments import (
    Segments,
    panel_groups,
    panel_loads,
    panel_mean,
    panel_share,
    segment_velocity,
    segments,
)
from stochcable.dynamics.residuals.line_top import line_bound, line_top, spectral_moments
from stochcable.dynamics.residuals.residual_lines import (
    EndInfluence,
    PairLines,
    UniformGrid,
    element_directions,
    fft_length,
    load_transfer,
    pair_blocks,
    pair_lags,
    residual_record,
    uniform_grid,
)
from stochcable.errors import PhysicsWarning, warn
from stochcable.results.records import ResidualRecord

__all__ = [
    "HERMITE_ORDER",
    "MAX_PANELS",
    "RESIDUAL_WARN_RATIO",
    "bent_lines",
    "drag_residual",
    "hermite_coefficients",
    "lumped_coefficients",
    "residual_output_lines",
]

#: Most panels (groups of consecutive elements) the residual is evaluated on: the cost
#: grows with their square; 54 panels of the chain's 160 elements give the
#: element-by-element variance within 1 % (tests/dynamics/test_drag_residual.py). [-]
MAX_PANELS = 32
#: σ ratio (with / without the residual) beyond which (above it, or below its inverse)
#: a PhysicsWarning says the correction is larger than any checked against the nonlinear
#: time domain: +18 % on the taut wire and on the inclined guy, +4 / +7 % on the chain
#: (docs/benchmarks/drag_residual.md). [-]
RESIDUAL_WARN_RATIO = 1.25
#: The misfit's end tensions per unit load solved at every analysis frequency (the
#: evaluation before issue 31), not taken at the residual's nearest line
#: (:func:`~stochcable.dynamics.residuals.drag_misfit.misfit_variance`). [-]
MISFIT_EXACT = False
#: Panel components whose residual force times their largest end tension per unit force
#: is below this fraction of the line's largest are left out (:func:`_live_panels`).
#: Corrected σ against 1e-4 (ends, elements, nodes): chain ≤ 5e-6, deep ≤ 7e-7,
#: two-segment ends 2.8e-4 / nodes 5.2e-4, the inclined guy 5.3e-4, taut unchanged
#: (docs/benchmarks/residual_cost.md). [-]
PANEL_FLOOR = 1e-3
#: Share of each end's linear spectral moments m0, m2, m4 the residual lines left out
#: above those the ends need may carry at most (a bound: :mod:`.line_top`; σ within
#: half of it); 0: every line. [-]
LINE_TOL = 2e-4
#: Points across a line's cell where the transfer functions of the residual loads are
#: taken where the lines do not resolve them (:func:`cell_factor`). [-]
SUB_SAMPLES = 5
#: Bend of the log power between neighbouring lines (|Δ² ln P|) above which a cell's
#: transfer functions are sub-sampled (:func:`cell_factor`). [-]
CELL_BEND = 0.1


def residual_output_lines(
    lines: np.ndarray,
    scale: np.ndarray,
    coeffs: np.ndarray,
    transfer: np.ndarray,
    n_fft: int,
    budget: np.ndarray | None = None,
    weight: np.ndarray | None = None,
    floor: int = 0,
    powers: np.ndarray | None = None,
) -> np.ndarray:
    """Spectral lines of outputs driven by the drag residual of jointly Gaussian panels.

    Parameters
    ----------
    lines : ndarray, complex, shape (n_ch, n_p, n_j)
        Velocity fluctuation of each panel per independent channel on the uniform grid
        ω_j = jΔ, j = 0 … n_j − 1, as amplitudes h with E[v_e(t)v_f(t + τ)] =
        Σ_j Re(Σ_c h̄_{c,e,j} h_{c,f,j} e^{iω_jτ}). [m/s]
    scale : ndarray, shape (n_p,)
        c_p·L_p, the panel's drag constant times its length (½ρC_dD·L). [N·s²/m²]
    coeffs : ndarray, shape (n_p, K + 1)
        :func:`hermite_coefficients` of each panel (k < 2 are not used).
    transfer : ndarray, complex, shape (n_out, n_p, n_o)
        Outputs per unit force on each panel at ω_j, j = 1 … n_o. [N/N]
    n_fft : int
        Samples of the lag grid, ≥ 2·K·(n_j − 1) + 1 (no aliasing of the k-fold
        convolutions, whose lines reach K·(n_j − 1)).
    budget : ndarray, shape (n_out,) or (n_out, n_mom), optional
        Variance (or spectral moments, with ``powers`` (n_mom, n_o): the lines' ω^k)
        each output may leave out above its lines' top (:func:`.line_top`, a bound
        from the panels' own lines, times ``weight`` (n_out, n_o) where given: the
        cells' factors); the first ``floor`` lines always kept.  None: every line.
        [N²·(rad/s)^k]

    Returns
    -------
    ndarray, shape (n_out, n_top)
        The outputs' variance lines at ω_j, j = 1 … n_top (n_o without ``budget``;
        their sum is the variance the residual adds). [N²]
    """
    order = coeffs.shape[1] - 1
    n_p = lines.shape[1]
    sig = np.sqrt(np.sum(lines.real**2 + lines.imag**2, axis=(0, 2)))
    live = sig > 0
    force = np.where(live, scale * sig**2, 0.0)  # cσ²L
    inv = np.where(live, 1.0 / np.where(live, sig, 1.0), 0.0)
    z = lines * inv[None, :, None]  # unit-variance lines: their covariance is ρ
    # k!·a_k^e·a_k^f·F_e·F_f = b_k^e·b_k^f, b_k = √k!·a_k·F
    b = np.sqrt([float(math.factorial(k)) for k in range(order + 1)]) * coeffs * force[:, None]
    n_o = transfer.shape[2]
    ks = [k for k in range(2, order + 1) if np.any(b[:, k] != 0.0)]  # (zero mean: no evens)
    if not ks:
        return np.zeros((transfer.shape[0], n_o))
    # the pairs f ≥ e (G_fe = conj(G_ef)) in blocks: ρ_ef, Σ_k b_k^e b_k^f ρ^k by
    # Horner's rule, its lines
    zz = np.conj(z).transpose(2, 1, 0) @ z.transpose(2, 0, 1)  # (n_j, n_p, n_p)
    zz[0] *= 2.0  # (irfft halves the zero-frequency line: pair_lags)
    lo, hi = ks[0], ks[-1]
    # the lags' n_fft/2 (pair_lags) as (n_fft/2)^k on the orders' coefficients
    span = np.arange(lo, hi + 1, dtype=float)

    def pair_lines(e: np.ndarray, f: np.ndarray, n_fft: int, top: int) -> np.ndarray:
        rho = pair_lags(zz, e, f, n_fft)  # ρ·2/n_fft
        # b_k^e·b_k^f·(n_fft/2)^k with the pairs f > e weighted 2 and covariance_lines'
        # 2/n_fft in
        c = b[e, lo : hi + 1] * b[f, lo : hi + 1]
        c *= np.where(f > e, 4.0 / n_fft, 2.0 / n_fft)[:, None] * (0.5 * n_fft) ** span
        rr = c[:, -1:] * rho
        for i in range(hi - lo - 1, -1, -1):
            rr += c[:, i : i + 1]
            rr *= rho
        for _ in range(lo - 1):
            rr *= rho
        return np.fft.rfft(rr, axis=1)[:, 1 : top + 1]  # (covariance_lines)

    if budget is None:  # the pairs f ≥ e (G_fe = conj(G_ef)) in blocks
        out = PairLines(transfer)  # (the element tensions read its dense lines: .along_line)
        for e, f in pair_blocks(n_p, n_fft):
            out.add(pair_lines(e, f, n_fft, n_o), e, f)
        return out.outputs()
    # the panels' own lines first: the lines the outputs need (line_top), the pairs
    # e < f on those only, their lag grid free of aliases up to the top line alone
    diag = np.arange(n_p)
    g_diag = pair_lines(diag, diag, n_fft, n_o)
    bound = line_bound(g_diag, transfer) * (1.0 if weight is None else weight)
    if powers is not None:  # (a bound of each moment: the lines' ω^k)
        bound = (bound[:, None, :] * powers[None]).reshape(-1, n_o)
    top = line_top(bound, np.ravel(budget), floor)
    reach = hi * (lines.shape[2] - 1)  # (the top order's highest line)
    n_top = min(n_fft, fft_length(max(top + reach, 2 * top) + 1))
    out = PairLines(np.ascontiguousarray(transfer[:, :, :top]))
    out.add(g_diag[:, :top], diag, diag)
    for e, f in pair_blocks(n_p, n_top, first=1):
        out.add(pair_lines(e, f, n_top, top), e, f)
    return out.outputs()


def drag_residual(
    system: Any,
    channels: Any,
    linearization: Any,
    std: dict[str, float],
    order: int = LUMPED_ORDER,
    lumped: bool = True,
    influence: EndInfluence | None = None,
) -> ResidualRecord:
    """The end-tension variance the drag linearization of one line drops (module notes).

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
    order : int
        Highest Hermite order.
    lumped : bool
        The two highest orders carry the variance of all higher ones of their parity
        (:func:`lumped_coefficients`); False: the orders above ``order`` dropped (the
        evaluation before issue 31, with ``order`` :data:`HERMITE_ORDER`).
    influence : EndInfluence, optional
        The line's end influence, shared with its other residual.

    Returns
    -------
    ResidualRecord
        ``computed`` False with the reason where the scope (module notes) excludes the line.
    """
    model = system.model
    damping = linearization.damping
    why = None
    if model.dim != 2:
        why = "3-D lines are not covered (the normal relative velocity is a vector)"
    elif damping.method != "seed":
        why = f"linearization method {damping.method!r}: only 'seed' is covered"
    if why is not None:
        return ResidualRecord.not_computed(why, std)
    # a line on bodies: its coupled influence on every grid (body_residual), and the
    # group's lines' panels through the bodies as one set of components (their cross
    # terms count: the lines' velocities share the sea and the bodies), formed once for
    # the group (its components kept there) and kept apart from the line's own lines
    # (those of its element tensions)
    coupled = None if influence is None or isinstance(influence, EndInfluence) else influence
    joint = None if coupled is None else _joint(coupled, order, lumped)
    others = [] if joint is None else joint[1]
    comp = (
        None if joint is None else coupled.shared["components"][_KEY + (order, lumped), system.name]
    )
    if comp is None:
        comp = drag_components(system, channels, linearization, order, lumped)
    if comp is None:  # no drag: nothing dropped
        zero = {"end_a": 0.0, "end_b": 0.0}
        return ResidualRecord.from_variances(zero, zero, std, order, 0)
    resp = linearization.response
    w = np.asarray(resp.omega, dtype=float)
    influence = EndInfluence(system, damping) if influence is None else influence
    # the components whose force is nothing against the largest (the grounded panels')
    # left out before their transfer (their score could not reach PANEL_FLOOR)
    sig2 = comp.sig2
    alive = _loaded_panels(sig2, comp.scale, comp.coeffs)
    unit = comp.unit if alive is None else comp.unit[:, :, alive]
    h_all = load_transfer(system, damping, unit, comp.w_out, influence)
    lines, scale, coeffs = (
        (comp.lines, comp.scale, comp.coeffs)
        if alive is None
        else (comp.lines[:, alive], comp.scale[alive], comp.coeffs[alive])
    )
    mag = np.abs(h_all)  # (the panels' reach and the cells' power: formed once)
    keep = _live_panels(lines, scale, coeffs, mag, sig2 if alive is None else sig2[alive])
    power = np.sum(mag**2, axis=1)
    bent = bent_lines(h_all, power=power)  # (the cells: the residual's and the misfit's)
    cf = cell_factor(
        system, damping, unit, comp.w_out, h_all, influence=coupled, cells=bent, power=power
    )
    # the lines above those the ends need left out: within LINE_TOL of the linear
    # spectrum's m0, m2 and m4 at each end (σ, Tz and the bandwidth)
    orders = np.array([0.0, 2.0, 4.0])
    budget = LINE_TOL * spectral_moments(resp, comp.spectra, orders)
    own = residual_output_lines(
        lines[:, keep], scale[keep], coeffs[keep], h_all[:, keep], comp.n_fft,
        budget if coupled is None and LINE_TOL > 0 else None, cf, comp.grid.n_j,
        comp.w_out[None] ** orders[:, None],
    )  # fmt: skip
    top = own.shape[1]
    linear = misfit_variance(
        system,
        damping,
        resp,
        comp.spectra,
        comp.seg,
        comp.groups,
        comp.live,
        comp.parts,
        comp.misfit,
        (comp.grid, comp.w_out, influence, bent),
        coupled,
        [(c, src) for _, c, src in others],
        MISFIT_EXACT,
        comp.unit,
    )
    out = residual_record(
        own * cf[:, :top], comp.w_out[:top], w, std, order, len(comp.groups), linear
    )
    if joint is not None:
        out = with_group_lines(out, comp.w_out, joint[0] * cf, w, std)
    _warn_large(system.name, out)
    return out


@dataclass(frozen=True, eq=False)
class DragComponents:
    """The drag residual's panel components of one planar line (:func:`drag_components`):
    its pieces and panels, drag directions ``live`` and their ``parts`` (½ρC_dD per
    length, mean flow, element directions, B), the spectra, the uniform grid and the
    residual's lines ``w_out`` [rad/s] with their lag grid, the node loads per unit
    component (n_nodes, d, n_comp), the components' velocity lines (n_ch, n_comp, n_j)
    and their variances Σ|lines|², c·L and Hermite coefficients, and per direction the
    panels' velocities and δB·l."""

    seg: Segments
    groups: list[np.ndarray]
    live: list[str]
    parts: dict[str, Any]
    spectra: np.ndarray
    grid: UniformGrid
    w_out: np.ndarray
    n_fft: int
    unit: np.ndarray
    lines: np.ndarray
    sig2: np.ndarray
    scale: np.ndarray
    coeffs: np.ndarray
    misfit: list[tuple[np.ndarray, np.ndarray]]


def drag_components(
    system: Any, channels: Any, linearization: Any, order: int, lumped: bool
) -> DragComponents | None:
    """The panel components of a planar line's drag residual (None: no drag)."""
    model = system.model
    damping = linearization.damping
    resp = linearization.response
    w = np.asarray(resp.omega, dtype=float)
    mesh = model.mesh
    rho = model.rho
    tang, normal = element_directions(system)
    u_t, u_nvec, _ = current_split(system)
    u_n = np.einsum("ij,ij->i", u_nvec, normal)
    c_n = 0.5 * rho * mesh.cd_normal * mesh.diameter
    c_t = 0.5 * rho * mesh.cd_axial * math.pi * mesh.diameter
    # per direction: c (½ρC_dD per length), mean flow, element directions, the FD's B
    parts = {
        "normal": (c_n, u_n, normal, damping.b_normal),
        "axial": (c_t, u_t, tang, damping.b_axial),
    }
    live = [name for name, p in parts.items() if np.any(p[0] > 0)]
    if not live:
        return None
    seg = segments(system, channels, sum(parts[n][0] for n in live), MAX_PANELS)
    groups = panel_groups(seg, MAX_PANELS)
    seg_v = segment_velocity(system, channels, resp, seg, {n: parts[n][2] for n in live})
    spectra = np.stack([ch.spectrum for ch in channels])
    grid = uniform_grid(w, spectra=spectra)
    n_o = order * (grid.n_j - 1)
    w_out = grid.step * np.arange(1, n_o + 1)
    # (ρ^K reaches line K·(n_j − 1): a lag grid of 2·K·(n_j − 1) + 1 samples resolves it)
    n_fft = fft_length(2 * order * (grid.n_j - 1) + 1)
    unit = panel_loads(model, seg, groups, [parts[n][2] for n in live])
    # the normal and axial residuals of every panel are one set of components: they are
    # functions of jointly Gaussian velocities, so their cross terms count too (where
    # the linear tensions of the two cancel, so do the residuals' in part)
    scales, coeffs, misfit = [], [], []
    share = panel_share(seg, groups)
    piece = np.concatenate(groups)  # (each piece's panel: the panels' c·L by one sum)
    panel = np.repeat(np.arange(len(groups)), [g.size for g in groups])
    n_p = len(groups)
    pans = [panel_mean(seg_v[name], seg, groups, share) for name in live]  # (n_ch, n_p, n_w)
    # every direction's panels placed on the grid at once: the components' lines
    lines = grid.lines(np.concatenate(pans, axis=1), spectra)  # (n_ch·ranks, n_comp, n_j)
    sig2 = np.sum(lines.real**2 + lines.imag**2, axis=(0, 2))  # (the panels' choice too)
    sigs = np.sqrt(sig2)
    coef = lumped_coefficients if lumped else hermite_coefficients
    for k, name in enumerate(live):
        c_el, mean_el, _, b_el = parts[name]
        scales.append(np.bincount(panel, (c_el[seg.element] * seg.length)[piece], n_p))
        mean = panel_mean(mean_el[seg.element], seg, groups, share)
        sig = sigs[k * n_p : (k + 1) * n_p]
        mu = np.where(sig > 0, mean / np.where(sig > 0, sig, 1.0), 0.0)
        coeffs.append(coef(np.clip(mu, -10.0, 10.0), order))
        misfit.append((pans[k], misfit_scales(seg, groups, c_el, mean_el, b_el, sig)))
    return DragComponents(seg, groups, live, parts, spectra, grid, w_out, n_fft, unit, lines,
                          sig2, np.concatenate(scales), np.concatenate(coeffs),
                          misfit)  # fmt: skip


#: The key of the joint group computation (body_residual.CoupledInfluence.joint_lines).
_KEY = ("drag",)


def _joint(coupled: Any, order: int, lumped: bool) -> Any:
    """The group's part of the drag residual of a line on bodies: the lines of the joint
    sum over its group's planar lines' panels less the line's own panels' pairs
    (:meth:`~stochcable.dynamics.residuals.body_residual.CoupledInfluence.joint_lines`;
    the panel components below :data:`PANEL_FLOOR` of every output left out)."""

    def components(ln: Any) -> DragComponents | None:
        if ln.system.model.dim != 2 or ln.linearization.damping.method != "seed":
            return None
        return drag_components(ln.system, ln.channels, ln.linearization, order, lumped)

    def transfer(ln: Any, c: DragComponents, infl: Any) -> np.ndarray:
        with untapped():
            return load_transfer(ln.system, ln.damping, c.unit, c.w_out, infl)

    def outputs(cs: list[DragComponents], t: np.ndarray) -> np.ndarray:
        if any(not np.array_equal(c.w_out, cs[0].w_out) for c in cs):
            raise ValueError("the group's lines have different residual grids")
        lines = np.concatenate([c.lines for c in cs], axis=1)
        scale = np.concatenate([c.scale for c in cs])
        coeffs = np.concatenate([c.coeffs for c in cs])
        keep = _live_panels(lines, scale, coeffs, t)
        with untapped():
            out = residual_output_lines(
                lines[:, keep], scale[keep], coeffs[keep], t[:, keep], cs[0].n_fft
            )
            at = 0
            for i, c in enumerate(cs):  # (less each target's own panels' pairs)
                own = keep[(keep >= at) & (keep < at + c.scale.size)]
                rows = slice(2 * i, 2 * i + 2)
                out[rows] -= residual_output_lines(
                    lines[:, own], scale[own], coeffs[own], t[rows][:, own], c.n_fft
                )
                at += c.scale.size
        return out

    return coupled.joint_lines(_KEY + (order, lumped), components, transfer, outputs)


def cell_factor(
    system: Any,
    damping: Any,
    unit: np.ndarray,
    w_out: np.ndarray,
    h: np.ndarray,
    bend: float = CELL_BEND,
    influence: Any = None,
    cells: np.ndarray | None = None,
    power: np.ndarray | None = None,
) -> np.ndarray:
    """Mean over each line's cell [ω_j − Δ/2, ω_j + Δ/2] of the outputs' power per unit
    panel force over its value at ω_j, where the lines do not resolve it: shape
    (n_out, n_o).

    Near a lightly damped mode every panel's transfer function is the mode's resonance
    times its shape, T_e(ω) ≈ φ_e·R(ω): the cell mean of every product conj(T_e)·T_f is
    then the line's times this one factor, and the residual's variance line is
    integrated over the cell, not sampled (the inclined guy's 0.7 %-damped mode, half-
    power width 0.016 rad/s, on lines 0.03 rad/s apart: its corrected σ moved ±2 % with
    the line count, within 0.2 % with the factor).  The cells are those where the log
    power (``h``'s, summed over the panels) bends by more than :data:`CELL_BEND`
    between neighbours, and theirs (``cells``: those lines, (n_o,) bool, where the caller
    has them; ``power``: Σ_e |h_e|² (n_out, n_o), where the caller has it); elsewhere
    the factor is 1 (no solve)."""
    if cells is not None and not np.any(cells):  # (no cell: no power needed)
        return np.ones((h.shape[0], h.shape[2]))
    power = np.sum(np.abs(h) ** 2, axis=1) if power is None else power  # (n_out, n_o)
    out = np.ones_like(power)
    cells = np.flatnonzero(bent_lines(h, bend, power) if cells is None else cells)
    if cells.size == 0:
        return out
    step = float(w_out[1] - w_out[0]) if w_out.size > 1 else float(w_out[0])
    sub = step * ((np.arange(SUB_SAMPLES) + 0.5) / SUB_SAMPLES - 0.5)
    w_sub = (w_out[cells, None] + sub[None]).ravel()
    h_sub = load_transfer(system, damping, unit, w_sub, influence)
    p_sub = np.sum(np.abs(h_sub) ** 2, axis=1).reshape(power.shape[0], cells.size, -1)
    at = power[:, cells]
    out[:, cells] = np.where(at > 0, p_sub.mean(axis=2) / np.where(at > 0, at, 1.0), 1.0)
    return out


#: Panel components whose residual force (largest |a_k|, k ≥ 2, times cσ²L) is below
#: this fraction of the line's largest are left out before their end transfer: the
#: grounded panels of a chain (the bundled chain's 8 of 66: 2e-14 and less of its
#: largest, the next 2e-12).  Their score (:func:`_live_panels`) would need an end
#: tension per unit force 10⁹ times the largest panel's to reach :data:`PANEL_FLOOR`. [-]
DEAD_FORCE = 1e-12


def _loaded_panels(sig2: np.ndarray, scale: np.ndarray, coeffs: np.ndarray) -> np.ndarray | None:
    """The panel components (indices) whose residual force is at least
    :data:`DEAD_FORCE` of the line's largest (``sig2``: their variances Σ|lines|²);
    None where that is all of them (or :data:`PANEL_FLOOR` is 0: every panel kept)."""
    force = np.abs(coeffs[:, 2:]).max(axis=1) * scale * sig2
    alive = force >= DEAD_FORCE * np.max(force, initial=0.0)
    return None if alive.all() or PANEL_FLOOR <= 0 else np.flatnonzero(alive)


def _live_panels(
    lines: np.ndarray,
    scale: np.ndarray,
    coeffs: np.ndarray,
    h: np.ndarray,
    sig2: np.ndarray | None = None,
) -> np.ndarray:
    """The panel components (indices) whose residual force can reach the ends: the
    largest |a_k| (k ≥ 2) times cσ²L times the largest end tension per unit force at
    least :data:`PANEL_FLOOR` of the line's largest.  ``h``: the end tensions per unit
    force, or their magnitudes (real); ``sig2``: the components' variances Σ|lines|²
    where the caller has them."""
    if sig2 is None:
        sig2 = np.sum(lines.real**2 + lines.imag**2, axis=(0, 2))
    reach = (np.abs(h) if np.iscomplexobj(h) else h).max(axis=(0, 2))
    score = np.abs(coeffs[:, 2:]).max(axis=1) * scale * sig2 * reach
    return np.flatnonzero(score >= PANEL_FLOOR * np.max(score, initial=0.0))


def bent_lines(
    h: np.ndarray, bend: float = CELL_BEND, power: np.ndarray | None = None
) -> np.ndarray:
    """The lines (n_o,) where the log power of ``h`` (n_out, n_p, n_o), summed over the
    panels (``power``, where the caller has it), bends by more than ``bend`` between
    neighbours, and theirs."""
    power = np.sum(np.abs(h) ** 2, axis=1) if power is None else power
    logp = np.log(np.maximum(power, np.max(power, initial=0.0) * 1e-300 + 1e-300))
    n = power.shape[1]
    mid = np.zeros(n, dtype=bool)
    if n > 2:
        mid[1:-1] = np.any(np.abs(logp[:, 2:] - 2.0 * logp[:, 1:-1] + logp[:, :-2]) > bend, 0)
    # the lines and their neighbours (the first and last lines never bend themselves)
    out = mid.copy()
    out[1:] |= mid[:-1]
    out[:-1] |= mid[1:]
    return out


def _warn_large(name: str, res: ResidualRecord) -> None:
    """PhysicsWarning where the residual changes an end's σ by more than
    :data:`RESIDUAL_WARN_RATIO` (up or down)."""
    end = max(("end_a", "end_b"), key=lambda e: abs(math.log(max(res.ratio(e), 1e-300))))
    ratio = res.ratio(end)
    if max(ratio, 1.0 / max(ratio, 1e-300)) > RESIDUAL_WARN_RATIO:
        warn(
            f"line '{name}': the drag residual changes the {end} tension σ by "
            f"{ratio - 1:+.0%} (beyond ×{RESIDUAL_WARN_RATIO:g}): the drag linearization "
            "is doubtful here, and this first-order correction is larger than those "
            "checked against the time domain (up to +18 %, "
            "docs/benchmarks/drag_residual.md); check with a nonlinear time-domain "
            "analysis (stochcable.reference.cable)",
            PhysicsWarning,
            stacklevel=4,
        )
