"""The end-tension variance the drag linearization of a 3-D line drops, in closed form:
the residual of the vector drag c|v_n|v_n of a bivariate Gaussian normal velocity.

In 3-D the normal relative velocity of a panel is a vector v = (v₁, v₂) along the
element normals n₁, n₂, Gaussian with mean m (the current's normal part) and
covariance Σ.  With Σ = Q diag(s²) Qᵀ and x = diag(s)⁻¹Qᵀ(v − m) standard normal, the
drag of each normal component o has the bivariate Hermite (Wiener chaos) expansion

    c|v|v_o = c Σ_α a^o_α He_α₁(x₁) He_α₂(x₂),   a^o_α = E[|v|v_o He_α(x)]/α!,

(:func:`vector_hermite_coefficients`, by quadrature graded toward the kink v = 0).
Order 0 is the mean drag (the statics'), order 1 is E[∇(|v|v)]·(v − m) — the exact
Gaussian linearization (Borgman 1972; the ``vector`` method's B,
:func:`stochcable.dynamics.linearization.formulas.drag_linear_vector`).  The axial
drag is the scalar expansion of :mod:`stochcable.dynamics.residuals.drag_residual`
(x₃ = v_t/σ_t).  For standardized vectors x (of one panel) and y (of another, or of
the same at another time) with cross-covariance C_ij(τ) = E[x_i(t) y_j(t + τ)]
(the diagram formula; Mehler's formula in several variables),

    E[He_α(x) He_β(y)] = Σ_N α! β! Π_ij C_ij^N_ij / N_ij!,

the sum over the integer matrices N with row sums α and column sums β: the residual's
cross-covariance functions are polynomials of the nine velocity cross-covariances of
two panels, ρ^k of the scalar case generalized (:func:`vector_residual_covariance`).
Orders ≥ 2 are uncorrelated with the linear response; their end-tension variance
lines follow as in 2-D (:func:`vector_residual_output_lines`).  The orders kept are
2 and 3, each output's top order of each parity carrying the variance of the higher
ones of its parity (as :func:`~stochcable.dynamics.residuals.drag_residual.lumped_coefficients`;
across normal components and panels they keep the top order's lag shape: within 3 %
of Monte Carlo, where orders to 9 are within 0.1 %).

The linear model of a 3-D line differs from the exact fit where the ``seed`` method
is used: it damps the normal plane isotropically with B = ρC_dD·E|w|, w ~ N(|m|,
tr Σ) (Tuah 1982, eq. 5.2.2 with σ_n² = σ_n₁² + σ_n₂²), while the Gaussian fit is
c·E[|v|I + vvᵀ/|v|] (isotropic velocity: 18 % less; in-line only: half across).
That order-1 misfit δB·(v − m) is linear in the response, so its end tension H_c
enters with its cross term, Σ_c S_c(|H_L + H_c|² − |H_L|²) (and may lower σ), as the
misfit of split elements does in 2-D (with which it is formed here: the pieces of a
split element against their element's mean covariance).  The ``vector`` method has
no form misfit.

Validation: Monte Carlo of correlated Gaussian velocities with a mean
(tests/dynamics/test_drag_residual_3d.py), the 2-D residual from a 3-D planar line, and
the nonlinear time domain (figures in docs/benchmarks/drag_residual.md).

Scope: 3-D lines, ``seed`` and ``vector`` methods (not ``harmonic``), the line
elements' drag (not attachments'), at most
:data:`~stochcable.dynamics.residuals.drag_residual.MAX_PANELS` panels.

References
----------
Borgman, L. E. (1972), Statistical models for ocean waves and wave forces, Advances in
Hydroscience 8, 139–181.
Roberts, J. B. and Spanos, P. D. (1990), Random Vibration and Statistical
Linearization, Wiley, §5.
"""

from __future__ import annotations

import functools
import itertools
import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from stochcable.dynamics.linearization.variance import current_split
from stochcable.dynamics.residuals.body_residual import untapped, with_group_lines
from stochcable.dynamics.residuals.drag_misfit_3d import misfit_3d, misfit_variance_3d, panel_sum
from stochcable.dynamics.residuals.drag_residual import (
    LUMPED_ORDER,
    MAX_PANELS,
    _warn_large,
    cell_factor,
    hermite_coefficients,
    lumped_coefficients,
)
from stochcable.dynamics.residuals.drag_segments import (
    panel_groups,
    panel_loads,
    panel_mean,
    segment_velocity,
    segments,
)
from stochcable.dynamics.residuals.residual_lines import (
    RESIDUAL_TAP,
    EndInfluence,
    element_directions,
    fft_length,
    load_transfer,
    residual_record,
    uniform_grid,
)
from stochcable.results.records import ResidualRecord

__all__ = [
    "drag_residual_3d",
    "vector_hermite_coefficients",
    "vector_residual_covariance",
    "vector_residual_output_lines",
]

#: Memory of the covariance functions held at a time (a block of panel pairs). [bytes]
_BLOCK_BYTES = 48 * 2**20
#: Quadrature of the bivariate coefficients, per axis: composite Gauss–Legendre of
#: ``_GL`` points on unit steps over ±``_RADIUS`` standard deviations, graded toward
#: the kink and its mirror (for the even part) by ``_RATIO``^k, k < ``_LEVELS``
#: (the Gaussian weight beyond 10 is e^-50; tested against the scalar closed sums).
_RADIUS, _GL, _RATIO, _LEVELS = 10.0, 4, 0.2, 6
#: Panels whose quadrature grids are formed at a time. [-]
_CHUNK = 8


# ------------------------------------------------------------------ coefficients


def _graded_points(kink: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Points and weights (n, m) of E[f(x)], x ~ N(0, 1), for f smooth but near the
    ``kink`` (n,) and its mirror (module constants)."""
    n = kink.shape[0]
    c = np.clip(np.where(np.isfinite(kink), kink, 2 * _RADIUS), -2 * _RADIUS, 2 * _RADIUS)
    off = _RATIO ** np.arange(_LEVELS)
    near = np.concatenate([c[:, None] + off, c[:, None] - off, c[:, None]], axis=1)
    base = np.arange(-_RADIUS, _RADIUS + 0.5)
    pts = np.concatenate([np.broadcast_to(base, (n, base.size)), near, -near], axis=1)
    pts = np.sort(np.clip(pts, -_RADIUS, _RADIUS), axis=1)
    t, wt = np.polynomial.legendre.leggauss(_GL)
    lo, hi = pts[:, :-1, None], pts[:, 1:, None]
    x = (0.5 * (hi - lo) * t + 0.5 * (hi + lo)).reshape(n, -1)
    w = (0.5 * (hi - lo) * wt).reshape(n, -1)
    return x, w * np.exp(-0.5 * x * x) / math.sqrt(2.0 * math.pi)


def _hermite_table(x: np.ndarray, order: int) -> np.ndarray:
    """He_k(x), k = 0 … order, stacked last (three-term recurrence)."""
    out = np.empty(x.shape + (order + 1,))
    out[..., 0] = 1.0
    if order >= 1:
        out[..., 1] = x
    for k in range(1, order):
        out[..., k + 1] = x * out[..., k] - k * out[..., k - 1]
    return out


def vector_hermite_coefficients(
    mean: Any, cov: Any, order: int = LUMPED_ORDER, lumped: bool = True
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Bivariate Hermite coefficients of the vector drag |v|v, v ~ N(m, Σ) in a plane.

    Parameters
    ----------
    mean : array_like, shape (n, 2)
        Mean velocity m (the current's normal part). [m/s]
    cov : array_like, shape (n, 2, 2)
        Covariance Σ of the velocity (symmetric, positive semi-definite). [m²/s²]
    order : int
        Highest total order |α|.
    lumped : bool
        Each component's top odd and top even order carry the variance of all higher
        orders of their parity (the tensor of the order scaled; its sign pattern kept).

    Returns
    -------
    coeffs : ndarray, shape (n, 2, order + 1, order + 1)
        a^o_ij = E[|v|v_o He_i(x₁) He_j(x₂)]/(i! j!) for i + j ≤ order (zero above),
        o the component in the basis of ``mean`` and ``cov``. [m²/s²]
    basis : ndarray, shape (n, 2, 2)
        Columns q₁, q₂: the principal directions of Σ (major first). [-]
    scale : ndarray, shape (n, 2)
        s₁ ≥ s₂, the standard deviations along them: x_i = q_i·(v − m)/s_i (0 where
        s_i = 0). [m/s]

    Notes
    -----
    Checks: order 1 is E[∇(|v|v)]·diag(s)Q (Stein's lemma, the vector linearization);
    Parseval Σ_α α!·(a^o_α)² = Var(|v|v_o); a planar velocity gives the scalar
    coefficients (tests).
    """
    m = np.asarray(mean, dtype=float).reshape(-1, 2)
    c = np.asarray(cov, dtype=float).reshape(-1, 2, 2)
    lam, q = np.linalg.eigh(0.5 * (c + np.swapaxes(c, 1, 2)))
    lam, q = lam[:, ::-1], q[:, :, ::-1]
    s = np.sqrt(np.clip(lam, 0.0, None))
    s[s <= 1e-12 * np.maximum(s[:, :1], 1e-300)] = 0.0
    mp = np.einsum("nji,nj->ni", q, m)
    with np.errstate(divide="ignore", invalid="ignore"):
        kink = np.where(s > 0, -mp / np.where(s > 0, s, 1.0), np.inf)
    x1, w1 = _graded_points(kink[:, 0])
    x2, w2 = _graded_points(kink[:, 1])
    h1 = _hermite_table(x1, order) * w1[..., None]  # (n, k1, K + 1)
    h2 = _hermite_table(x2, order) * w2[..., None]
    fact = np.array([math.factorial(k) for k in range(order + 1)], dtype=float)
    out = np.zeros((m.shape[0], 2, order + 1, order + 1))
    var = np.zeros((m.shape[0], 2, 2))  # per component: E[f²], E[f(m + Lx) f(m − Lx)]
    for lo in range(0, m.shape[0], _CHUNK):  # (a chunk of panels' grids at a time)
        sl = slice(lo, min(lo + _CHUNK, m.shape[0]))
        f = [_drag_grid(mp[sl], s[sl], q[sl], x1[sl], x2[sl], sign) for sign in (1.0, -1.0)]
        a1, a2 = w1[sl, None, :], w2[sl, :, None]
        for o in range(2):
            out[sl, o] = np.swapaxes(h1[sl], 1, 2) @ f[0][o] @ h2[sl]
            var[sl, o, 0] = (a1 @ (f[0][o] * f[0][o]) @ a2)[:, 0, 0]
            var[sl, o, 1] = (a1 @ (f[0][o] * f[1][o]) @ a2)[:, 0, 0]
    out /= fact[None, None, :, None] * fact[None, None, None, :]
    deg = np.add.outer(np.arange(order + 1), np.arange(order + 1))
    out[:, :, deg > order] = 0.0
    if lumped:
        _lump(out, var, deg, fact)
    return out, q, s


def _drag_grid(
    mp: np.ndarray, s: np.ndarray, q: np.ndarray, x1: np.ndarray, x2: np.ndarray, sign: float
) -> list[np.ndarray]:
    """|v|v_o, o = 1, 2 (the input basis), on the tensor grid of v = m ± (s₁x₁q₁ +
    s₂x₂q₂): two arrays (n, k1, k2)."""
    v1 = mp[:, 0, None, None] + sign * s[:, 0, None, None] * x1[:, :, None]
    v2 = mp[:, 1, None, None] + sign * s[:, 1, None, None] * x2[:, None, :]
    r = np.hypot(v1, v2)
    return [r * (q[:, o, 0, None, None] * v1 + q[:, o, 1, None, None] * v2) for o in range(2)]


def _lump(out: np.ndarray, var: np.ndarray, deg: np.ndarray, fact: np.ndarray) -> None:
    """Scale each component's top odd and top even order to carry the variance of the
    higher orders of its parity (in place; the closed total E[f²] and its even part
    (E[f(m + Lx)²] + E[f(m + Lx) f(m − Lx)])/2 from the quadrature)."""
    order = out.shape[2] - 1
    weight = np.outer(fact, fact)
    by_order = [
        np.einsum("noij,ij->no", out**2, weight * (deg == k)) for k in range(order + 1)
    ]  # (n, 2) each: the variance of each order
    total, even = var[..., 0], 0.5 * (var[..., 0] + var[..., 1])
    tails = {0: even - by_order[0], 1: total - even - by_order[1]}
    for k in (order, order - 1):
        if k < 2:
            continue
        below = sum(by_order[j] for j in range(k % 2 + 2, k, 2))
        tail = np.maximum(tails[k % 2] - below, 0.0)
        have = by_order[k]
        f = np.where(have > 0, np.sqrt(tail / np.where(have > 0, have, 1.0)), 1.0)
        out[:, :, deg == k] *= f[:, :, None]


# ------------------------------------------------------------------ covariances


@functools.lru_cache(maxsize=8)
def _monomials(order: int) -> tuple[tuple[Any, ...], ...]:
    """The index matrices N of the diagram formula for orders 2 … ``order`` between the
    three variables of two panels (x₁, x₂ normal, x₃ axial), as (cells, exponents,
    row multi-index, column multi-index, α!β!/N!, row outputs, column outputs): only
    those whose rows lie in the normal pair or in the axial variable, and likewise
    their columns (the supports of the coefficients)."""
    groups = (((0, 1), slice(0, 2)), ((2,), slice(2, 3)))
    out = []
    for k in range(2, order + 1):
        for (rows, ro), (cols, co) in itertools.product(groups, groups):
            cells = [(i, j) for i in rows for j in cols]
            for combo in itertools.combinations_with_replacement(range(len(cells)), k):
                n = np.zeros((3, 3), dtype=int)
                for idx in combo:
                    n[cells[idx]] += 1
                r, c = n.sum(axis=1), n.sum(axis=0)
                w = math.prod(math.factorial(int(a)) for a in (*r, *c)) / math.prod(
                    math.factorial(int(a)) for a in n.ravel()
                )
                nz = tuple((int(i), int(j), int(n[i, j])) for i, j in zip(*np.nonzero(n)))
                out.append((nz, tuple(int(a) for a in r), tuple(int(a) for a in c), w, ro, co))
    return tuple(out)


def _cross(z: np.ndarray, blk: slice, f_all: slice, n_fft: int) -> np.ndarray:
    """C_ij(τ) = E[z_{e,i}(t) z_{f,j}(t + τ)] of the panels e of ``blk`` and f of
    ``f_all`` on the lag grid: shape (3, 3, n_b, n_f, n_fft)."""
    n_j = z.shape[3]
    zz = np.einsum("cevj,cfuj->vuefj", np.conj(z[:, blk]), z[:, f_all])
    cross = np.zeros(zz.shape[:4] + (n_fft // 2 + 1,), dtype=complex)
    cross[..., :n_j] = zz
    cross[..., 0] *= 2.0  # (irfft halves the zero-frequency line)
    return np.fft.irfft(cross, n=n_fft, axis=-1) * (0.5 * n_fft)


def _block_covariance(
    z: np.ndarray, coeffs: np.ndarray, blk: slice, f_all: slice, n_fft: int, order: int
) -> np.ndarray:
    """Residual force cross-covariance functions of the panels of ``blk`` with those of
    ``f_all``: shape (3, 3, n_b, n_f, n_fft) (output, output, panel, panel, lag)."""
    cc = _cross(z, blk, f_all, n_fft)
    n_b, n_f = cc.shape[2], cc.shape[3]
    # per output pair, the monomials' sum Σ_N w_N·a_r(N)[e]·a_c(N)[f]·Π C^N
    cov = np.zeros((3, 3, n_b, n_f, n_fft))
    mono = np.empty((n_b, n_f, n_fft))
    tmp = np.empty((n_b, n_f, n_fft))
    for nz, r, c, w, ro, co in _monomials(order):
        a_r = coeffs[blk, ro][..., r[0], r[1], r[2]]  # (n_b, |ro|)
        a_c = coeffs[f_all, co][..., c[0], c[1], c[2]]  # (n_f, |co|)
        if not (np.any(a_r) and np.any(a_c)):
            continue
        i, j, p = nz[0]
        np.power(cc[i, j], p, out=mono) if p > 1 else np.copyto(mono, cc[i, j])
        for i, j, p in nz[1:]:
            mono *= cc[i, j] if p == 1 else cc[i, j] ** p
        for oi, o in enumerate(range(ro.start, ro.stop)):
            for ui, u in enumerate(range(co.start, co.stop)):
                coef = w * np.outer(a_r[:, oi], a_c[:, ui])
                np.multiply(mono, coef[..., None], out=tmp)
                cov[o, u] += tmp
    return cov


def vector_residual_covariance(z: np.ndarray, coeffs: np.ndarray, n_fft: int) -> np.ndarray:
    """Cross-covariance functions of the residual forces of every panel pair.

    Parameters
    ----------
    z : ndarray, complex, shape (n_ch, n_p, 3, n_j)
        Lines of each panel's standardized variables (x₁, x₂ the whitened normal
        velocity, x₃ the axial over its σ; zero lines for a variable without
        variance) on the uniform grid ω_j = jΔ, with E[x(t)y(t + τ)] =
        Σ_j Re(Σ_c x̄_{c,j} y_{c,j} e^{iω_jτ}). [-]
    coeffs : ndarray, shape (n_p, 3, K + 1, K + 1, K + 1)
        Force of each output (n₁, n₂, axial) per Hermite polynomial He_α(x) of the
        three variables (the normal outputs' α₃ = 0, the axial's α₁ = α₂ = 0; orders
        below 2 are not used). [N]
    n_fft : int
        Samples of the lag grid, ≥ 2·K·(n_j − 1) + 1.

    Returns
    -------
    ndarray, shape (n_p, 3, n_p, 3, n_fft)
        E[r_{e,o}(t) r_{f,u}(t + τ_m)] on the lag grid τ_m = 2πm/(n_fft·Δ). [N²]
    """
    n_p = z.shape[1]
    order = coeffs.shape[2] - 1
    cov = _block_covariance(z, coeffs, slice(0, n_p), slice(0, n_p), n_fft, order)
    return np.transpose(cov, (2, 0, 3, 1, 4))


def vector_residual_output_lines(
    z: np.ndarray, coeffs: np.ndarray, transfer: np.ndarray, n_fft: int, first: int | None = None
) -> np.ndarray:
    """Spectral lines of outputs driven by the vector drag residual of jointly Gaussian
    panels (module notes).

    Parameters
    ----------
    z, coeffs, n_fft
        As :func:`vector_residual_covariance`.
    transfer : ndarray, complex, shape (n_out, n_p, 3, n_o)
        Outputs per unit force on each panel along each output direction at ω_j,
        j = 1 … n_o. [N/N]
    first : int, optional
        Only the pairs (e ≤ f) whose first panel e is one of the ``first`` panels: what
        they add to the sum over the others (a body's drag components ahead of the
        lines' panels, :mod:`.body_drag_residual`); default every pair.

    Returns
    -------
    ndarray, shape (n_out, n_o)
        The outputs' variance lines at ω_j, j = 1 … n_o. [N²]
    """
    n_p = z.shape[1]
    order = coeffs.shape[2] - 1
    n_out, n_o = transfer.shape[0], transfer.shape[3]
    out = np.zeros((n_out, n_o))
    size = max(1, int(_BLOCK_BYTES // (8 * 30 * n_fft * max(n_p, 1))))
    stop = n_p if first is None else min(int(first), n_p)
    for start in range(0, stop, size):
        blk = slice(start, min(start + size, stop))
        f_all = slice(start, n_p)
        cov = _block_covariance(z, coeffs, blk, f_all, n_fft, order)  # (3, 3, n_b, n_f, ·)
        cr = (2.0 / n_fft) * np.fft.rfft(cov, axis=-1)[..., 1 : n_o + 1]
        e_idx = np.arange(blk.start, blk.stop)[:, None]
        f_idx = np.arange(f_all.start, f_all.stop)[None, :]
        pair = np.where(f_idx > e_idx, 2.0, np.where(f_idx == e_idx, 1.0, 0.0))
        cr *= pair[None, None, :, :, None]
        n_b, n_f = cr.shape[2], cr.shape[3]
        # (n_o, n_b·3, n_f·3), panel-major
        g = np.transpose(cr, (4, 2, 0, 3, 1)).reshape(n_o, n_b * 3, n_f * 3)
        if (tap := RESIDUAL_TAP.get()) is not None:  # (other outputs': .along_line_3d)
            tap.vector_block(g, blk, f_all, transfer)
        t_f = np.transpose(transfer[:, f_all].reshape(n_out, n_f * 3, n_o), (2, 1, 0))
        t_e = np.transpose(np.conj(transfer[:, blk]).reshape(n_out, n_b * 3, n_o), (2, 1, 0))
        out += np.einsum("jek,jek->kj", t_e, g @ t_f).real
    return out


# ------------------------------------------------------------------ the line


def drag_residual_3d(
    system: Any,
    channels: Any,
    linearization: Any,
    std: dict[str, float],
    order: int = LUMPED_ORDER,
    lumped: bool = True,
    influence: Any = None,
) -> ResidualRecord:
    """The end-tension variance the drag linearization of one 3-D line drops (module
    notes).

    Parameters
    ----------
    system : LineSystem
        The line (a 3-D model).
    channels : tuple of Channel
        Its inputs on the analysis grid.
    linearization : Linearization
        The converged fixed point (its ``response`` and ``damping``).
    std : dict {"end_a", "end_b"} of float
        The linear end-tension σ. [N]
    order : int
        Highest Hermite order.
    lumped : bool
        The two highest orders carry the variance of all higher ones of their parity.
    influence : EndInfluence or CoupledInfluence, optional
        The line's end influence (shared with its other residual; a line on free
        bodies: :class:`stochcable.dynamics.residuals.body_residual.CoupledInfluence`).

    Returns
    -------
    ResidualRecord
        ``computed`` False with the reason where the scope (module notes) excludes the line.
    """
    model = system.model
    damping = linearization.damping
    if model.dim != 3:
        return ResidualRecord.not_computed("a 2-D line: see drag_residual", std)
    if damping.method not in ("seed", "vector"):
        return ResidualRecord.not_computed(
            f"linearization method {damping.method!r}: only 'seed' and 'vector' are covered", std
        )
    coupled = None if influence is None or isinstance(influence, EndInfluence) else influence
    # a line on bodies: the group's lines' panels through the bodies as one set of
    # components (body_residual; formed once for the group at JOINT_PANELS per line),
    # the lines' components at full resolution kept on the group for the misfits
    joint = None if coupled is None else _joint(coupled, order, lumped)
    full = {} if coupled is None else coupled.shared.setdefault(("drag_3d_full", order, lumped), {})

    def full_of(name: str, ln: Any) -> DragComponents3D | None:
        if name not in full:
            full[name] = drag_components_3d(ln.system, ln.channels, ln.linearization, order,
                                            lumped)  # fmt: skip
        return full[name]

    comp = full_of(system.name, _Line(system, channels, linearization))
    if comp is None:  # no drag: nothing dropped
        zero = {"end_a": 0.0, "end_b": 0.0}
        return ResidualRecord.from_variances(zero, zero, std, order, 0)
    resp = linearization.response
    w = np.asarray(resp.omega, dtype=float)
    n_p, n_o = comp.z.shape[1], comp.w_out.size
    h = load_transfer(system, damping, comp.unit, comp.w_out, influence)  # (2, 3·n_p, n_o)
    transfer = np.transpose(h.reshape(2, 3, n_p, n_o), (0, 2, 1, 3))
    cf = cell_factor(system, damping, comp.unit, comp.w_out, h, influence=coupled)
    own = vector_residual_output_lines(comp.z, comp.coeffs, transfer, comp.n_fft)
    others = [] if joint is None else joint[1]
    mis = [(system, damping, comp, coupled)] + [
        (s_.system, s_.damping, full_of(s_.name, s_), i) for s_, _, i in others
    ]
    linear = misfit_variance_3d(
        resp, comp.spectra, [m for m in mis if m[2] is not None and m[2].db is not None]
    )
    out = residual_record(own * cf, comp.w_out, w, std, order, n_p, linear)
    if joint is not None:  # (the own lines first: the along-line residuals' loads)
        out = with_group_lines(out, comp.w_out, joint[0] * cf, w, std)
    _warn_large(system.name, out)
    return out


@dataclass(frozen=True)
class _Line:
    """A line's inputs as a group line gives them."""

    system: Any
    channels: Any
    linearization: Any


#: Panels per line of a group's joint sum (the cross terms between its lines and the
#: other lines' own): MAX_PANELS shared among the group's lines, at least this many.
#: On benchmarks/bench_bodies.py's three-leg chain mooring (31 panels per leg) the
#: group part at 16 panels per leg is within 0.6 % / 3.5 % (front / side leg) of its
#: value at 31, the end σ within 0.07 % (at 10: 6 %, 0.14 %); the joint sum 0.8 →
#: ~0.3 s. [-]
JOINT_MIN_PANELS = 16


def _joint(coupled: Any, order: int, lumped: bool) -> Any:
    """The group's part of the drag residual of a line on bodies: the lines of the
    joint sum over its group's 3-D lines' panels less the line's own panels' pairs
    (:meth:`~stochcable.dynamics.residuals.body_residual.CoupledInfluence.joint_lines`),
    at :data:`JOINT_MIN_PANELS` or MAX_PANELS / lines per line."""
    n = sum(1 for ln in coupled.lines if ln.attached and ln.channels and ln.linearization)
    cap = max(JOINT_MIN_PANELS, MAX_PANELS // max(n, 1))

    def components(ln: Any) -> DragComponents3D | None:
        if ln.system.model.dim != 3 or ln.linearization.damping.method not in ("seed", "vector"):
            return None
        return drag_components_3d(ln.system, ln.channels, ln.linearization, order, lumped, cap)

    def transfer(ln: Any, c: DragComponents3D, infl: Any) -> np.ndarray:
        with untapped():
            h = load_transfer(ln.system, ln.damping, c.unit, c.w_out, infl)
        return np.transpose(h.reshape(2, 3, c.z.shape[1], c.w_out.size), (0, 2, 1, 3))

    def outputs(cs: list[DragComponents3D], t: np.ndarray) -> np.ndarray:
        if any(not np.array_equal(c.w_out, cs[0].w_out) for c in cs):
            raise ValueError("the group's lines have different residual grids")
        z = np.concatenate([c.z for c in cs], axis=1)
        co = np.concatenate([c.coeffs for c in cs])
        with untapped():
            out = vector_residual_output_lines(z, co, t, cs[0].n_fft)
            at = 0
            for i, c in enumerate(cs):  # (less each target's own panels' pairs)
                n_p = c.z.shape[1]
                out[2 * i : 2 * i + 2] -= vector_residual_output_lines(
                    c.z, c.coeffs, t[2 * i : 2 * i + 2, at : at + n_p], c.n_fft
                )
                at += n_p
        return out

    return coupled.joint_lines(("drag_3d", order, lumped, cap), components, transfer, outputs)


@dataclass(frozen=True, eq=False)
class DragComponents3D:
    """The drag residual's panel components of one 3-D line (:func:`drag_components_3d`):
    the whitened velocity lines ``z`` (n_ch, n_p, 3, n_j), the coefficients (n_p, 3,
    K + 1, K + 1, K + 1), the unit node loads (n_nodes, 3, 3·n_p), the residual's lines
    ``w_out`` [rad/s] and lag grid ``n_fft``, the spectra, the panels' velocities ``pan``
    and their misfit ``db`` (None: none)."""

    z: np.ndarray
    coeffs: np.ndarray
    unit: np.ndarray
    w_out: np.ndarray
    n_fft: int
    spectra: np.ndarray
    pan: dict[str, np.ndarray]
    db: np.ndarray | None


def drag_components_3d(
    system: Any,
    channels: Any,
    linearization: Any,
    order: int,
    lumped: bool,
    max_panels: int = MAX_PANELS,
) -> DragComponents3D | None:
    """The panel components of a 3-D line's drag residual on at most ``max_panels``
    panels (None: no drag)."""
    model = system.model
    damping = linearization.damping
    resp = linearization.response
    w = np.asarray(resp.omega, dtype=float)
    mesh = model.mesh
    tang, n1, n2 = element_directions(system)
    u_t, u_nvec, _ = current_split(system)
    c_n = 0.5 * model.rho * mesh.cd_normal * mesh.diameter
    c_t = 0.5 * model.rho * mesh.cd_axial * math.pi * mesh.diameter
    if not (np.any(c_n > 0) or np.any(c_t > 0)):
        return None
    seg = segments(system, channels, c_n + c_t, max_panels)
    groups = panel_groups(seg, max_panels)
    n_p = len(groups)
    grid = uniform_grid(w)
    dirs = {"n1": n1, "n2": n2, "t": tang}
    seg_v = segment_velocity(system, channels, resp, seg, dirs)
    pan = {k: panel_mean(v, seg, groups) for k, v in seg_v.items()}  # (n_ch, n_p, n_w)
    spectra = np.stack([ch.spectrum for ch in channels])
    lines = {k: grid.lines(v, spectra) for k, v in pan.items()}  # (n_ch', n_p, n_j)
    vn = np.stack([lines["n1"], lines["n2"]], axis=2)  # (n_ch', n_p, 2, n_j)
    cov = np.einsum("cpaj,cpbj->pab", vn.conj(), vn).real
    mean_el = np.column_stack([np.einsum("ij,ij->i", u_nvec, n) for n in (n1, n2)])
    mean = np.column_stack([panel_mean(mean_el[seg.element, k], seg, groups) for k in (0, 1)])
    scale_n = panel_sum(c_n, seg, groups)
    scale_t = panel_sum(c_t, seg, groups)
    a_n, basis, s = vector_hermite_coefficients(mean, cov, order, lumped)
    sig_t = np.sqrt(np.sum(np.abs(lines["t"]) ** 2, axis=(0, 2)))
    mean_t = panel_mean(u_t[seg.element], seg, groups)
    mu_t = np.where(sig_t > 0, mean_t / np.where(sig_t > 0, sig_t, 1.0), 0.0)
    a_t = (lumped_coefficients if lumped else hermite_coefficients)(
        np.clip(mu_t, -10.0, 10.0), order
    )
    coeffs = np.zeros((n_p, 3) + (order + 1,) * 3)
    coeffs[:, :2, :, :, 0] = scale_n[:, None, None, None] * a_n
    coeffs[:, 2, 0, 0, :] = (scale_t * sig_t**2)[:, None] * a_t
    # the whitened variables' lines: x_i = q_i·(v − m)/s_i, x₃ = v_t/σ_t
    inv = np.where(s > 0, 1.0 / np.where(s > 0, s, 1.0), 0.0)
    z = np.empty(vn.shape[:2] + (3, vn.shape[3]), dtype=complex)
    z[:, :, :2] = np.einsum("pai,cpaj->cpij", basis, vn) * inv[None, :, :, None]
    z[:, :, 2] = (
        lines["t"] * np.where(sig_t > 0, 1.0 / np.where(sig_t > 0, sig_t, 1.0), 0.0)[None, :, None]
    )
    n_o = order * (grid.n_j - 1)
    w_out = grid.step * np.arange(1, n_o + 1)
    n_fft = fft_length(2 * order * (grid.n_j - 1) + 1)
    unit = panel_loads(model, seg, groups, [n1, n2, tang])  # columns direction-major
    db = misfit_3d(damping, seg, groups, c_n, c_t, cov, mean, sig_t, mean_t, scale_n, scale_t)
    return DragComponents3D(z, coeffs, unit, w_out, n_fft, spectra, pan, db)
