"""The end-tension variance the statistical drag linearization drops, in closed form.

The statistical linearization (seed 001 eqs. 5.2.2–5.2.5; Borgman 1972) replaces the
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
nodes where it lies (:mod:`stochcable.dynamics.drag_segments`); the orders k ≥ 2 stay
uncorrelated with both linear parts.  Without the split, the inclined guy's 26 m top
element at z = 0 took the residual as one mean velocity spread evenly over its two
nodes, and the correction read +38 % at the fairlead, mostly on the line's 0.7 %-damped
mode at 1.19 rad/s, against +14 % for the quadratic drag in the time domain; a time
domain with the FD's linear drag plus the dropped drag of the fluid velocity reads
+16 % taken pointwise and +32 % taken as element means spread evenly
(docs/benchmarks/drag_residual.md).

Validation: the closed form of the residual's cross-spectrum, and of the split
element's misfit plus residual, against Monte-Carlo Gaussian realizations
(tests/test_drag_residual.py, tests/test_drag_segments.py), and the corrected σ against
the nonlinear time domain (the chain's quadratic-drag shift, the taut wire and the
inclined guy in their seas: docs/benchmarks/drag_residual.md).

Scope: planar lines (the normal velocity a scalar), the seed linearization, normal and
axial drag of the line elements (attachment drag is not included), each element at
its mean relative velocity; lines attached to free bodies are not covered (their
residual would load the coupled system).  Elements (and pieces) are grouped into at
most :data:`MAX_PANELS` panels (the cost is O(panels² · n_fft log n_fft)).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from stochcable.dynamics.drag_segments import (
    Segments,
    panel_groups,
    panel_loads,
    panel_mean,
    segment_velocity,
    segments,
)
from stochcable.dynamics.linearization.variance import current_split
from stochcable.dynamics.model.blocks import trapezoid_weights
from stochcable.dynamics.residual_lines import (
    covariance_lines,
    cross_covariance,
    element_directions,
    load_transfer,
    residual_record,
    uniform_grid,
)
from stochcable.errors import PhysicsWarning, warn
from stochcable.results.records import ResidualRecord

__all__ = [
    "HERMITE_ORDER",
    "MAX_PANELS",
    "RESIDUAL_WARN_RATIO",
    "drag_residual",
    "hermite_coefficients",
    "residual_output_lines",
]

#: Highest Hermite order kept: k = 2 … 5 carry all but 0.7 % of the residual variance
#: of zero-mean drag (k = 3: 4/(3π) = 0.424 of 3 − 8/π = 0.454). [-]
HERMITE_ORDER = 5
#: Most panels (groups of consecutive elements) the residual is evaluated on: the cost
#: grows with their square; 54 panels of the chain's 160 elements give the
#: element-by-element variance within 1 % (tests/test_drag_residual.py). [-]
MAX_PANELS = 64
#: σ ratio (with / without the residual) beyond which (above it, or below its inverse)
#: a PhysicsWarning says the correction is larger than any checked against the nonlinear
#: time domain: +18 % on the taut wire and on the inclined guy, +4 / +7 % on the chain
#: (docs/benchmarks/drag_residual.md). [-]
RESIDUAL_WARN_RATIO = 1.25


def hermite_coefficients(mu: Any, order: int = HERMITE_ORDER) -> np.ndarray:
    """Hermite coefficients a_k(μ) of g(μ + x) = |μ + x|(μ + x), x ~ N(0, 1).

    Parameters
    ----------
    mu : array_like, shape (n,)
        Mean over standard deviation of the relative velocity, U/σ. [-]
    order : int
        Highest order k.

    Returns
    -------
    ndarray, shape (n, order + 1)
        a_k = E[g(μ + x) He_k(x)]/k! (probabilists' Hermite polynomials); a₁ = 2E|μ + x|
        (Stein's lemma: the Borgman coefficient over cσ); exact to round-off for
        |μ| < 12.  The callers clip μ to ±10: beyond, the kink lies more than 10σ out
        (weight e^-50) and g is the polynomial ±(μ + x)², whose residual coefficients
        no longer change (a₂ = ±1, a_k = 0 for k ≥ 3).
    """
    m = np.atleast_1d(np.asarray(mu, dtype=float))
    # g(μ + x) is ±(μ + x)², a polynomial on each side of the kink x = −μ: Gauss–Legendre
    # on each side of it over ±12 (the Gaussian tail beyond is e^-72) is exact to
    # round-off for |μ| < 12
    t, wt = np.polynomial.legendre.leggauss(64)
    lo, hi = -12.0, 12.0
    kink = np.clip(-m, lo, hi)[:, None]
    x = np.concatenate(
        [0.5 * (kink - lo) * t + 0.5 * (kink + lo), 0.5 * (hi - kink) * t + 0.5 * (hi + kink)], 1
    )
    w = np.concatenate([0.5 * (kink - lo) * wt, 0.5 * (hi - kink) * wt], 1)
    w = w * np.exp(-0.5 * x * x) / math.sqrt(2.0 * math.pi)
    y = m[:, None] + x
    g = np.abs(y) * y * w
    out = np.empty((m.size, order + 1))
    for k in range(order + 1):
        he = np.polynomial.hermite_e.hermeval(x, [0.0] * k + [1.0])
        out[:, k] = np.sum(g * he, axis=1) / math.factorial(k)
    return out


def residual_output_lines(
    lines: np.ndarray,
    scale: np.ndarray,
    coeffs: np.ndarray,
    transfer: np.ndarray,
    n_fft: int,
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
        Samples of the lag grid, ≥ 2·K·n_j (no aliasing of the k-fold convolutions).

    Returns
    -------
    ndarray, shape (n_out, n_o)
        The outputs' variance lines at ω_j, j = 1 … n_o (their sum is the variance the
        residual adds). [N²]
    """
    order = coeffs.shape[1] - 1
    sig = np.sqrt(np.einsum("cpj,cpj->p", lines.real, lines.real) + np.einsum(
        "cpj,cpj->p", lines.imag, lines.imag
    ))  # fmt: skip
    live = sig > 0
    force = np.where(live, scale * sig**2, 0.0)  # cσ²L
    inv = np.where(live, 1.0 / np.where(live, sig, 1.0), 0.0)
    n_o = transfer.shape[2]
    out = np.zeros((transfer.shape[0], n_o))
    for e in np.flatnonzero(live):
        rho = cross_covariance(lines[:, e], lines, n_fft) * (inv[e] * inv[:, None])
        rr = np.zeros_like(rho)
        power = rho.copy()
        for k in range(2, order + 1):
            power *= rho
            rr += (math.factorial(k) * coeffs[e, k]) * coeffs[:, k, None] * power
        rr *= force[e] * force[:, None]
        cr = covariance_lines(rr, n_o)  # (n_p, n_o)
        out += np.real(np.conj(transfer[:, e]) * np.einsum("opj,pj->oj", transfer, cr))
    return out


def drag_residual(
    system: Any,
    channels: Any,
    linearization: Any,
    std: dict[str, float],
    order: int = HERMITE_ORDER,
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
    if not live:  # no drag: nothing dropped
        zero = {"end_a": 0.0, "end_b": 0.0}
        return ResidualRecord.from_variances(zero, zero, std, order, 0)
    seg = segments(system, channels, sum(parts[n][0] for n in live), MAX_PANELS)
    groups = panel_groups(seg, MAX_PANELS)
    grid = uniform_grid(w)
    seg_v = segment_velocity(system, channels, resp, seg, {n: parts[n][2] for n in live})
    spectra = np.stack([ch.spectrum for ch in channels])
    n_o = order * (grid.n_j - 1)
    w_out = grid.step * np.arange(1, n_o + 1)
    n_fft = int(2 ** math.ceil(math.log2(2 * order * grid.n_j + 2)))
    h_all = load_transfer(
        system, damping, panel_loads(model, seg, groups, [parts[n][2] for n in live]), w_out
    )
    # the normal and axial residuals of every panel are one set of components: they are
    # functions of jointly Gaussian velocities, so their cross terms count too (where
    # the linear tensions of the two cancel, so do the residuals' in part)
    scales, coeffs, lines, misfit = [], [], [], []
    for name in live:
        c_el, mean_el, _, b_el = parts[name]
        scales.append(
            np.array([float(np.sum(c_el[seg.element[g]] * seg.length[g])) for g in groups])
        )
        mean = panel_mean(mean_el[seg.element], seg, groups)
        pan = panel_mean(seg_v[name], seg, groups)  # (n_ch, n_p, n_w)
        v = grid.lines(pan, spectra)
        sig = np.sqrt(np.sum(np.abs(v) ** 2, axis=(0, 2)))
        mu = np.where(sig > 0, mean / np.where(sig > 0, sig, 1.0), 0.0)
        coeffs.append(hermite_coefficients(np.clip(mu, -10.0, 10.0), order))
        lines.append(v)
        misfit.append((pan, _misfit(seg, groups, c_el, mean_el, b_el, sig)))
    lines_t = residual_output_lines(
        np.concatenate(lines, axis=1),
        np.concatenate(scales),
        np.concatenate(coeffs),
        h_all,
        n_fft,
    )
    linear = _misfit_variance(system, damping, resp, spectra, seg, groups, live, parts, misfit)
    out = residual_record(lines_t, w_out, w, std, order, len(groups), linear)
    _warn_large(system.name, out)
    return out


def _misfit(
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
    for e in np.unique(seg.element[seg.fine]):
        idx = np.flatnonzero(seg.element[first] == e)  # its pieces: one panel each
        s_ = first[idx]
        var = float(np.sum(seg.length[s_] * sig[idx] ** 2) / np.sum(seg.length[s_]))
        if var <= 0.0 or b_el[e] <= 0.0:
            continue
        sig_e = math.sqrt(var)
        mu = np.clip(np.append(mean_el[e] / np.where(sig[idx] > 0, sig[idx], np.inf),
                               mean_el[e] / sig_e), -10.0, 10.0)  # fmt: skip
        a1 = hermite_coefficients(mu, 1)[:, 1]
        out[idx] = b_el[e] * (sig[idx] * a1[:-1] / (sig_e * a1[-1]) - 1.0) * seg.length[s_]
    return out


def _misfit_variance(
    system: Any,
    damping: Any,
    resp: Any,
    spectra: np.ndarray,
    seg: Segments,
    groups: list[np.ndarray],
    live: list[str],
    parts: dict[str, Any],
    misfit: list[tuple[np.ndarray, np.ndarray]],
) -> dict[str, float]:
    """The end-tension variance the linear misfit of the element-constant drag changes:
    its load δB·l·v on the pieces of split elements is linear in the response, so its
    end tension H_c adds to the linear H_L (Σ_c ∫ S_c (|H_L + H_c|² − |H_L|²) dω on the
    analysis grid, the trapezoid of the linear σ; it may be negative). [N²]"""
    w = np.asarray(resp.omega, dtype=float)
    keep = [(k, np.flatnonzero(m)) for k, (_, m) in enumerate(misfit) if np.any(m)]
    if not keep:
        return {"end_a": 0.0, "end_b": 0.0}
    sel = [[groups[i] for i in idx] for _, idx in keep]
    unit = np.concatenate(
        [panel_loads(system.model, seg, g, [parts[live[k]][2]]) for (k, _), g in zip(keep, sel)],
        axis=2,
    )
    h = load_transfer(system, damping, unit, w)  # (2, n_load, n_w)
    load = np.concatenate(
        [misfit[k][1][idx][None, :, None] * misfit[k][0][:, idx] for k, idx in keep], axis=1
    )  # (n_ch, n_load, n_w)
    q = trapezoid_weights(w)[None] * spectra
    out = {}
    for o, end in enumerate(("end_a", "end_b")):
        h_l = np.asarray(resp.end_tension[end])
        h_c = np.einsum("pw,cpw->cw", h[o], load)
        out[end] = float(np.sum(q * (np.abs(h_l + h_c) ** 2 - np.abs(h_l) ** 2)))
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
