"""The compiled stacked banded LU (stochcable.dynamics.model.band_lu_kernels, through
stochcable.dynamics.model.band_lu) against LAPACK's ``gbsv`` on the stack
(solvers.solve_band_stacked): the same partially pivoted elimination (``zgbtf2``'s
pivot choice), the divisions by the pivots as products with their reciprocals, so equal
to round-off; a system that needs its row interchanges; an exactly singular one."""

from __future__ import annotations

import numpy as np
import pytest

from stochcable.dynamics.model.solvers import solve_band_stacked
from stochcable.errors import SolverError

kernels = pytest.importorskip("stochcable.dynamics.model.band_lu_kernels")
from stochcable.dynamics.model.band_lu import band_factors  # noqa: E402


def _band(rng: np.random.Generator, n: int, kl: int, ku: int) -> np.ndarray:
    """A random matrix in LAPACK band storage b[ku + i − j, j] (the corners outside the
    matrix zero, as ``solvers._band`` leaves them: the stacked gbsv reads them as
    couplings between frequencies)."""
    b = rng.normal(size=(kl + ku + 1, n))
    q, j = np.arange(kl + ku + 1)[:, None], np.arange(n)[None]
    i = j + q - ku
    b[(i < 0) | (i >= n)] = 0.0
    return b


def _reference(bk, bm, bc, terms, w, kl, ku):
    """gbsv on the stack of b(ω) = T₀ − ω²T₁ + iωT₂, as (r, n, n_w)."""
    rhs = terms[0][None] - (w * w)[:, None, None] * terms[1][None]
    rhs = rhs + (1j * w)[:, None, None] * terms[2][None]
    x = solve_band_stacked(bk, bm, bc, rhs, w, kl, ku)
    return np.transpose(x, (2, 1, 0))


@pytest.mark.parametrize(
    "n, kl, ku, r", [(1, 0, 0, 1), (2, 1, 1, 3), (7, 2, 1, 4), (38, 3, 3, 23), (60, 5, 5, 9)]
)
def test_band_lu_equals_gbsv(n, kl, ku, r):
    # random band matrices with complex damping over frequencies across their
    # resonances (Z indefinite): pivoting at work; random complex right-hand sides
    # with all three terms
    rng = np.random.default_rng(1000 * n + 10 * kl + ku)
    bk, bm = _band(rng, n, kl, ku), _band(rng, n, kl, ku)
    bc = _band(rng, n, kl, ku) + 1j * _band(rng, n, kl, ku)
    w = np.linspace(0.1, 4.0, 37)
    terms = rng.normal(size=(3, n, r)) + 1j * rng.normal(size=(3, n, r))
    ref = _reference(bk, bm, bc, terms, w, kl, ku)
    fac = band_factors(bk, bm, bc, w, kl, ku)
    got = fac.solve_into(terms, np.full((r, n + 3, w.size), np.nan + 0j), offset=1)
    assert np.all(np.isnan(got[:, 0])) and np.all(np.isnan(got[:, n + 1 :]))  # (untouched)
    # the same operations in another order: round-off of the solution's scale (the
    # random systems; measured ≤ 1e-14 relative, with 31–1,687 row interchanges)
    scale = np.abs(ref).max(axis=(1, 2), keepdims=True)
    np.testing.assert_allclose(got[:, 1 : n + 1], ref, rtol=0, atol=1e-11 * scale.max())
    # a subset of the factored frequencies, in any order
    at = np.array([5, 0, 36, 5])
    sub = fac.solve_into(terms, np.empty((r, n, at.size), dtype=complex), at)
    np.testing.assert_allclose(sub, ref[..., at], rtol=0, atol=1e-11 * scale.max())


def test_band_lu_needs_its_pivoting():
    """K with a zero diagonal: Z = K − ω²I has the small diagonal −ω² beside off-diagonal
    entries 1 and 2 (at ω → 0 elimination without row interchanges divides by ~0); the
    pivoted LU takes the row below, as gbsv does (its interchanges are used)."""
    n, kl, ku = 9, 1, 1
    bk = np.zeros((3, n))
    bk[0, 1:] = 1.0  # super-diagonal
    bk[2, :-1] = 2.0  # sub-diagonal
    bm = np.zeros((3, n))
    bm[1] = 1.0  # M = I: the diagonal of Z is −ω²
    w = np.array([0.5, 1.0])
    rng = np.random.default_rng(7)
    terms = np.zeros((3, n, 2), dtype=complex)
    terms[0] = rng.normal(size=(n, 2)) + 1j * rng.normal(size=(n, 2))
    ref = _reference(bk, bm, None, terms, w, kl, ku)
    fac = band_factors(bk, bm, None, w, kl, ku)
    lu, inv, piv = fac.factors
    assert np.any(piv != np.arange(n)[None])  # (rows were interchanged)
    got = fac.solve_into(terms, np.empty((2, n, w.size), dtype=complex))
    np.testing.assert_allclose(got, ref, rtol=0, atol=1e-13 * np.abs(ref).max())
    # and against the dense solve, independently of LAPACK's band code
    z = np.diag(np.full(n - 1, 1.0), 1) + np.diag(np.full(n - 1, 2.0), -1) - 0.25 * np.eye(n)
    np.testing.assert_allclose(got[:, :, 0].T, np.linalg.solve(z, terms[0]), rtol=1e-12)


def test_band_lu_singular_names_the_frequency():
    """An exactly singular Z(ω) (a zero column at the second frequency): the kernel's
    info points at it (k·n + j + 1) and band_factors raises the SolverError of gbsv's
    path (solvers.singular_error), naming ω."""
    n, kl, ku = 5, 1, 1
    bk = np.zeros((3, n))
    bk[1] = [1.0, 1.0, 4.0, 1.0, 1.0]  # K = diag, M = I at column 2: K − ω²M = 0 at ω = 2
    bm = np.zeros((3, n))
    bm[1, 2] = 1.0
    w = np.array([1.0, 2.0, 3.0])
    _, info = kernels.band_lu_factor(bk, bm, None, w, kl, ku)
    assert info == 1 * n + 2 + 1
    with pytest.raises(SolverError, match=r"singular at omega = 2 rad/s"):
        band_factors(bk, bm, None, w, kl, ku)
    with pytest.raises(SolverError, match=r"singular at omega = 2 rad/s"):  # (gbsv's own)
        solve_band_stacked(bk, bm, None, np.ones((3, n, 1), dtype=complex), w, kl, ku)


@pytest.mark.parametrize("n, kl, ku, r", [(1, 0, 0, 1), (7, 2, 1, 4), (38, 3, 3, 3)])
def test_band_solve_of_a_right_hand_side_per_frequency_equals_gbsv(n, kl, ku, r):
    """band_lu.band_solve (a load-case set's drag fixed point, a different right-hand
    side at each frequency: band_lu_solve_each) against gbsv on the stack: round-off of
    the solution's scale, as the substitutions of the terms above; an exactly singular
    frequency raises as gbsv's."""
    from stochcable.dynamics.model.band_lu import band_solve

    rng = np.random.default_rng(7 * n + kl)
    bk, bm = _band(rng, n, kl, ku), _band(rng, n, kl, ku)
    bc = _band(rng, n, kl, ku) + 1j * _band(rng, n, kl, ku)
    w = np.linspace(0.1, 4.0, 41)
    f = rng.normal(size=(w.size, n, r)) + 1j * rng.normal(size=(w.size, n, r))
    ref = solve_band_stacked(bk, bm, bc, f, w, kl, ku)
    got = band_solve(bk, bm, bc, f, w, kl, ku)
    assert got.shape == ref.shape
    np.testing.assert_allclose(got, ref, rtol=0, atol=1e-11 * np.abs(ref).max())
    zero = np.zeros_like(bk)
    with pytest.raises(SolverError):
        band_solve(zero, zero, None, f, w, kl, ku)
