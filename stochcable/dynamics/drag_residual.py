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

Validation: the closed form of the residual's cross-spectrum against Monte-Carlo
Gaussian realizations (tests/test_drag_residual.py), and the corrected σ against the
nonlinear time domain's quadratic-drag shift (docs/benchmarks/drag_residual.md).

Scope: planar lines (the normal velocity a scalar), the seed linearization, normal and
axial drag of the line elements (attachment drag is not included), each element at
its mean relative velocity; lines attached to free bodies are not covered (their
residual would load the coupled system).  Elements are grouped into at most
:data:`MAX_PANELS` panels (the cost is O(panels² · n_fft log n_fft)).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from stochcable.dynamics.residual_lines import (
    UniformGrid,
    covariance_lines,
    cross_covariance,
    element_directions,
    load_transfer,
    residual_record,
    uniform_grid,
)
from stochcable.dynamics.variance import current_split
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
#: σ ratio (with / without the residual) above which a PhysicsWarning says the
#: first-order residual overestimates: +38 % predicted against +19 % in the time domain
#: on the inclined guy, +18 % against +16 ± 3 % on the taut wire
#: (docs/benchmarks/drag_residual.md). [-]
RESIDUAL_WARN_RATIO = 1.2


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
    groups = _panels(model.n_elements)
    grid = uniform_grid(w)
    lines_v, dirs = _panel_lines(system, channels, resp, groups, grid)
    grid_step, n_j = grid.step, grid.n_j
    mesh = model.mesh
    rho = model.rho
    u_t, u_nvec, _ = current_split(system)
    u_n = np.einsum("ij,ij->i", u_nvec, dirs["normal"])
    parts = {
        "normal": (0.5 * rho * mesh.cd_normal * mesh.diameter, u_n),
        "axial": (0.5 * rho * mesh.cd_axial * math.pi * mesh.diameter, u_t),
    }
    n_o = order * (n_j - 1)
    w_out = grid_step * np.arange(1, n_o + 1)
    n_fft = int(2 ** math.ceil(math.log2(2 * order * n_j + 2)))
    live = [name for name, (c_el, _) in parts.items() if np.any(c_el > 0)]
    if not live:  # no drag: nothing dropped
        zero = {"end_a": 0.0, "end_b": 0.0}
        return ResidualRecord.from_variances(zero, zero, std, order, len(groups))
    h_all = load_transfer(
        system, damping, _panel_loads(model, groups, [dirs[n] for n in live]), w_out
    )
    # the normal and axial residuals of every panel are one set of components: they are
    # functions of jointly Gaussian velocities, so their cross terms count too (where
    # the linear tensions of the two cancel, so do the residuals' in part)
    length = np.array([float(np.sum(mesh.l0[g])) for g in groups])
    scales, coeffs, lines = [], [], []
    for name in live:
        c_el, mean_el = parts[name]
        scales.append([float(np.sum(c_el[g] * mesh.l0[g])) for g in groups])
        mean = np.array([float(np.sum(mean_el[g] * mesh.l0[g])) for g in groups]) / length
        v = lines_v[name]
        sig = np.sqrt(np.sum(np.abs(v) ** 2, axis=(0, 2)))
        mu = np.where(sig > 0, mean / np.where(sig > 0, sig, 1.0), 0.0)
        coeffs.append(hermite_coefficients(np.clip(mu, -10.0, 10.0), order))
        lines.append(v)
    lines_t = residual_output_lines(
        np.concatenate(lines, axis=1),
        np.concatenate(scales),
        np.concatenate(coeffs),
        h_all,
        n_fft,
    )
    out = residual_record(lines_t, w_out, w, std, order, len(groups))
    _warn_large(system.name, out)
    return out


def _warn_large(name: str, res: ResidualRecord) -> None:
    """PhysicsWarning where the residual raises an end's σ by more than
    :data:`RESIDUAL_WARN_RATIO`."""
    end = max(("end_a", "end_b"), key=res.ratio)
    if res.ratio(end) > RESIDUAL_WARN_RATIO:
        warn(
            f"line '{name}': the drag residual raises the {end} tension σ by "
            f"{res.ratio(end) - 1:.0%} (above {RESIDUAL_WARN_RATIO - 1:.0%}): the drag "
            "linearization is doubtful here, and this first-order correction overestimates "
            "corrections this large (docs/benchmarks/drag_residual.md); check with a "
            "nonlinear time-domain analysis (stochcable.reference.cable)",
            PhysicsWarning,
            stacklevel=4,
        )


def _panels(n_el: int) -> list[np.ndarray]:
    """Consecutive element groups, at most :data:`MAX_PANELS`."""
    size = max(1, math.ceil(n_el / MAX_PANELS))
    return [np.arange(i, min(i + size, n_el)) for i in range(0, n_el, size)]


def _panel_lines(
    system: Any, channels: Any, resp: Any, groups: list[np.ndarray], grid: UniformGrid
) -> tuple[dict[str, np.ndarray], dict[str, np.ndarray]]:
    """Normal and axial relative-velocity lines of the panels per channel on ``grid``
    (:meth:`UniformGrid.lines`) and the element directions (3-D unit vectors)."""
    model = system.model
    w = np.asarray(resp.omega, dtype=float)
    n_ch = len(channels)
    n_n, d = model.n_nodes, model.dim
    comps = list(model.components)
    u = resp.displacement.reshape(w.size, n_n, d, n_ch)
    vel = np.zeros((w.size, n_n - 1, 3, n_ch), dtype=complex)
    vel[:, :, comps] = -1j * w[:, None, None, None] * 0.5 * (u[:, :-1] + u[:, 1:])
    for c, ch in enumerate(channels):
        fluid = ch.element_velocity
        if fluid is None and ch.element_velocity_parts is not None:  # (the sea's parts)
            fluid = ch.element_velocity_parts.full()
        if fluid is not None:
            vel[..., c] += fluid.sum(axis=2)
        elif ch.kind == "sea" and ch.velocity is not None:
            vel[..., c] += 0.5 * (ch.velocity[:, :-1] + ch.velocity[:, 1:])
    tang, normal = element_directions(system)
    dirs = {"normal": normal, "axial": tang}
    spectra = np.stack([ch.spectrum for ch in channels])
    l0 = model.mesh.l0
    out = {}
    for name, vec in dirs.items():
        comp = np.einsum("wedc,ed->cew", vel, vec)  # (n_ch, n_el, n_w)
        pan = np.stack([(comp[:, g] * l0[g, None]).sum(axis=1) / l0[g].sum() for g in groups], 1)
        out[name] = grid.lines(pan, spectra)
    return out, dirs


def _panel_loads(model: Any, groups: list[np.ndarray], directions: list[np.ndarray]) -> np.ndarray:
    """Unit forces spread uniformly over each panel along each of ``directions`` (n_el,
    3) (consistent linear-element loads, half an element's share on each node): shape
    (n_nodes, d, n_directions · n_panels), direction-major."""
    comps = list(model.components)
    unit = np.zeros((model.n_nodes, model.dim, len(groups) * len(directions)))
    l0 = model.mesh.l0
    for k, direction in enumerate(directions):
        for q, g in enumerate(groups):
            p = k * len(groups) + q
            share = l0[g] / l0[g].sum()
            for e, s_ in zip(g, share):
                unit[e, :, p] += 0.5 * s_ * direction[e, comps]
                unit[e + 1, :, p] += 0.5 * s_ * direction[e, comps]
    return unit
