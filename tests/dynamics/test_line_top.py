"""The residual lines an output needs (stochcable.dynamics.residuals.line_top): the
bound of a variance line from the components' own lines, and the drag residual's
lines cut above the top its budget allows.

Independent checks: the bound against the full quadratic form T^H G T of random
positive semi-definite cross-spectra (Cauchy–Schwarz: it must hold line by line);
the cut evaluation against the full one (every line), on the lines kept to
round-off, the left-out tail within the budget."""

from __future__ import annotations

import numpy as np
import pytest

import stochcable.dynamics.residuals.residual_lines as rl
from stochcable.dynamics.residuals.drag_hermite import lumped_coefficients
from stochcable.dynamics.residuals.drag_residual import residual_output_lines
from stochcable.dynamics.residuals.line_top import line_bound, line_top, spectral_moments
from stochcable.dynamics.residuals.residual_lines import fft_length


def test_bound_holds_for_positive_semidefinite_cross_spectra():
    """B_j ≥ T^H G T at every line and output for random Hermitian G ⪰ 0 (rank-
    deficient ones too: the bound is tight for rank one with aligned phases)."""
    rng = np.random.default_rng(3)
    n, n_o, n_out = 9, 40, 3
    g = np.zeros((n_o, n, n), dtype=complex)
    for j in range(n_o):
        a = rng.standard_normal((n, 1 + j % 4)) + 1j * rng.standard_normal((n, 1 + j % 4))
        g[j] = a @ a.conj().T
    t = rng.standard_normal((n_out, n, n_o)) + 1j * rng.standard_normal((n_out, n, n_o))
    exact = np.einsum("oej,jef,ofj->oj", t.conj(), g, t).real
    bound = line_bound(np.einsum("jee->ej", g), t)
    assert np.all(exact >= 0.0)
    assert np.all(bound >= exact * (1.0 - 1e-12))
    # rank one, T_e with the phase of a_e: equality
    a = rng.standard_normal(n) + 1j * rng.standard_normal(n)
    g1 = np.outer(a, a.conj())[None]
    t1 = (np.exp(1j * np.angle(a)) * rng.uniform(0.5, 2.0, n))[None, :, None]
    exact1 = np.einsum("oej,jef,ofj->oj", t1.conj(), g1, t1).real
    assert line_bound(np.diagonal(g1, axis1=1, axis2=2).T, t1) == pytest.approx(exact1, rel=1e-12)


def test_line_top_keeps_the_fewest_lines_within_the_budget():
    """The tail Σ_{j ≥ J} at every output within its budget, J the smallest such (at
    least ``floor``); no budget left: every line with a non-zero bound."""
    bound = np.array([[5.0, 4.0, 3.0, 2.0, 1.0], [0.0, 0.0, 1.0, 0.5, 0.0]])
    assert line_top(bound, np.array([3.0, 10.0])) == 3  # tail from 3: 3 ≤ 3, from 2: 6
    assert line_top(bound, np.array([3.0, 0.4])) == 4  # the second output: tail 0.5
    assert line_top(bound, np.array([100.0, 100.0])) == 0
    assert line_top(bound, np.array([100.0, 100.0]), floor=2) == 2
    assert line_top(bound, np.zeros(2)) == 5
    assert line_top(bound, np.zeros(2), floor=9) == 5


def _panels(seed: int, n_p: int = 6, n_j: int = 24) -> tuple:
    rng = np.random.default_rng(seed)
    w = np.arange(n_j)
    shape = np.exp(-0.5 * ((w - 8) / 3.0) ** 2) * (w > 0)
    lines = (rng.standard_normal((2, n_p, n_j)) + 1j * rng.standard_normal((2, n_p, n_j))) * shape
    sig = np.sqrt((np.abs(lines) ** 2).sum(axis=(0, 2)))
    coeffs = lumped_coefficients(np.linspace(-0.6, 0.9, n_p), 3)
    scale = rng.uniform(0.5, 2.0, n_p) / sig**2
    n_o = 3 * (n_j - 1)
    jo = np.arange(1, n_o + 1)
    # outputs that pass the band and fall above it (a line's ends: low-pass)
    transfer = rng.standard_normal((2, n_p, 1)) / (1.0 + (jo / 12.0) ** 4) + 0j
    transfer = transfer * np.exp(1j * rng.uniform(0, 6, (2, n_p, n_o)))
    return lines, scale, coeffs, transfer, fft_length(2 * 3 * (n_j - 1) + 1), n_j


@pytest.mark.parametrize("seed", [1, 2, 5])
def test_cut_lines_equal_the_full_evaluation_and_the_tail_fits(monkeypatch, seed):
    """The lines up to the top equal every line's evaluation to round-off (pair lines
    in double here: their single-precision storage alone moves them 1e-7), on a lag
    grid shortened to the top (no alias below it), and the left-out lines' variance
    is within the budget; the cut leaves lines out (the test can fail)."""
    monkeypatch.setattr(rl, "PAIR_DTYPE", complex)
    lines, scale, coeffs, transfer, n_fft, n_j = _panels(seed)
    full = residual_output_lines(lines, scale, coeffs, transfer, n_fft)
    budget = 1e-3 * full.sum(axis=1)
    cut = residual_output_lines(lines, scale, coeffs, transfer, n_fft, budget, None, n_j)
    top = cut.shape[1]
    assert n_j <= top < full.shape[1]
    np.testing.assert_allclose(cut, full[:, :top], rtol=1e-10, atol=1e-12 * full.max())
    assert np.all(full[:, top:].sum(axis=1) <= budget)
    # the cells' factors weight the bound: a factor of 0 above line 30 cuts there
    weight = np.ones_like(full)
    weight[:, 30:] = 0.0
    cut0 = residual_output_lines(lines, scale, coeffs, transfer, n_fft, np.zeros(2), weight, n_j)
    assert cut0.shape[1] == 30


def test_moment_budget_bounds_the_left_out_moments(monkeypatch):
    """With a budget on m0, m2 and m4 (the lines' ω^0, ω², ω⁴), the left-out lines'
    moments are each within theirs, and the top is at least the variance's alone (the
    superharmonics weigh more in m4)."""
    monkeypatch.setattr(rl, "PAIR_DTYPE", complex)
    lines, scale, coeffs, transfer, n_fft, n_j = _panels(2)
    full = residual_output_lines(lines, scale, coeffs, transfer, n_fft)
    w = np.arange(1, full.shape[1] + 1) * 0.1
    powers = w[None] ** np.array([0.0, 2.0, 4.0])[:, None]
    budget = 1e-3 * full @ powers.T  # (n_out, 3)
    cut = residual_output_lines(lines, scale, coeffs, transfer, n_fft, budget, None, n_j, powers)
    top = cut.shape[1]
    assert np.all(full[:, top:] @ powers[:, top:].T <= budget)
    alone = residual_output_lines(lines, scale, coeffs, transfer, n_fft, budget[:, 0], None, n_j)
    assert alone.shape[1] <= top < full.shape[1]


def test_spectral_moments_are_the_trapezoid_rule_of_the_linear_spectrum():
    """m_k of the ends against numpy's trapezoid rule of ω^k Σ_c |H_c|² S_c."""

    class _Resp:
        omega = np.linspace(0.1, 2.0, 57) ** 1.3
        end_tension = {
            "end_a": np.vstack([np.exp(1j * omega), 2.0 / (1.0 + omega)]),
            "end_b": np.vstack([omega + 0j, 1j * np.ones_like(omega)]),
        }

    spectra = np.vstack([np.exp(-_Resp.omega), 0.5 * np.ones_like(_Resp.omega)])
    got = spectral_moments(_Resp, spectra, np.array([0.0, 2.0, 4.0]))
    for i, end in enumerate(("end_a", "end_b")):
        dens = np.sum(np.abs(_Resp.end_tension[end]) ** 2 * spectra, axis=0)
        for j, k in enumerate((0, 2, 4)):
            ref = np.trapezoid(dens * _Resp.omega**k, _Resp.omega)
            assert got[i, j] == pytest.approx(ref, rel=1e-12)
