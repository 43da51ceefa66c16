"""The modal sums of the influence rows (stochcable.dynamics.residuals.modal_rows)."""

from __future__ import annotations

import numpy as np

from stochcable.dynamics.model.modal_solvers import foss_modes
from stochcable.dynamics.residuals.modal_rows import modal_sums


def _modes(rng: np.random.Generator, n: int, overdamped: bool):
    a = rng.standard_normal((n, n))
    k = a @ a.T + n * np.eye(n)
    m = np.eye(n) + 0.1 * np.diag(rng.uniform(size=n))
    c = 0.05 * k if not overdamped else 0.05 * k + np.diag(np.r_[60.0, np.zeros(n - 1)])
    return m, c, k


def test_modal_sums_equal_the_complex_sum_over_every_mode():
    """Σ_j χ_j p_j/(iω − λ_j) by conjugate pairs in real arithmetic against the plain
    complex sum: underdamped modes (all paired), an overdamped one (two real λ without a
    partner) and a complex right-hand side (no conjugate terms: every mode alone), to
    round-off (1e-13 of the largest)."""
    rng = np.random.default_rng(3)
    w = np.linspace(0.05, 6.0, 37)
    for overdamped in (False, True):
        m, c, k = _modes(rng, 8, overdamped)
        foss = foss_modes(m, c, k)
        for rhs in (rng.standard_normal((8, 5)), rng.standard_normal((8, 5)) * (1 + 0.3j)):
            p = foss.weights @ rhs.astype(complex)
            got = modal_sums(foss.chi, p, foss.lambdas, w)
            ref = np.einsum(
                "ij,jk,jw->ikw", foss.chi, p, 1.0 / (1j * w[None] - foss.lambdas[:, None])
            )
            assert np.max(np.abs(got - ref)) <= 1e-13 * np.max(np.abs(ref))
    assert np.any(np.abs(foss.lambdas.imag) == 0.0)  # (the overdamped case has real modes)


def test_row_marks_follow_the_rows_sliced():
    """ModalRows keeps which of its rows carry the static correction's ω terms and ê
    (the end rows) and slices them with the rows: on any slice they equal the marks
    computed from the slice's own static rows and ê (the former per-call test of
    ``rc[1:] != 0``), and a slice without end rows has none."""
    from stochcable.dynamics.residuals.modal_rows import ModalRows

    rng = np.random.default_rng(5)
    m, k, n_w, n, d = 4, 6, 9, 5, 2
    phi = rng.normal(size=((n - 2) * d, m))
    z = rng.normal(size=(k, m, n_w)) + 1j * rng.normal(size=(k, m, n_w))  # (rows first)
    rc = np.zeros((3, (n - 2) * d, k), dtype=complex)
    rc[0] = rng.normal(size=rc.shape[1:])
    rc[1:, :, :2] = rng.normal(size=(2, rc.shape[1], 2))  # (ω terms on the end rows only)
    ends = np.zeros((2, k, d))
    ends[0, 0], ends[1, 1] = rng.normal(size=d), rng.normal(size=d)
    rows = ModalRows(phi, z, np.linspace(0.1, 2.0, n_w), rc, ends, n)
    for g in (rows, rows[:2], rows[1:4], rows[2:], rows[1:4][..., 2:7], rows[np.array([0, 3, 5])]):
        again = ModalRows(g.phi, g.z, g.w, g.rc, g.ends, n)  # (marks from its own rows)
        for a, b in zip(g.marks, again.marks, strict=True):
            assert np.array_equal(a, b)
    assert not rows[2:].marks[0].any() and not rows[2:].marks[1].any()
    assert np.array_equal(rows.marks[0], [True, True, False, False, False, False])


def test_pairs_by_their_factors_are_the_pairs_by_their_terms():
    """_conjugate_pairs with the terms' factors (χ, p: the bound on their products'
    conjugacy, the terms compared only where it does not settle it) pairs the same
    modes as comparing every term: partners perturbed from exact conjugates by 0 …
    100 × PAIR_TOL (in χ, in p, in λ), a mode without a partner."""
    from stochcable.dynamics.residuals.modal_rows import PAIR_TOL, _conjugate_pairs

    rng = np.random.default_rng(11)
    m, k = 6, 4
    half = rng.normal(size=m) * 0.3 - 0.1 + 1j * (1.0 + rng.random(m) * 5)
    lam = np.empty(2 * m, dtype=complex)
    lam[0::2], lam[1::2] = half, np.conj(half)
    chi = rng.normal(size=(m, 2 * m)) + 1j * rng.normal(size=(m, 2 * m))
    chi[:, 1::2] = np.conj(chi[:, 0::2])
    p = rng.normal(size=(2 * m, k)) + 1j * rng.normal(size=(2 * m, k))
    p[1::2] = np.conj(p[0::2])
    lam[-2] = -0.7  # (an overdamped mode: real, no partner)
    seen = set()
    for scale in (0.0, 0.2, 0.45, 0.6, 1.0, 3.0, 100.0):
        for what in ("chi", "p", "lam"):
            c, q, la = chi.copy(), p.copy(), lam.copy()
            kick = scale * PAIR_TOL * (1.0 + 1j)
            if what == "chi":
                c[:, 3] += kick * np.abs(c[:, 2]).max()
            elif what == "p":
                q[5] += kick * np.abs(q[4]).max()
            else:
                la[7] += kick * np.abs(la[6])
            terms = (c[:, None, :] * q.T[None]).reshape(m * k, -1)
            a = _conjugate_pairs(terms, la)
            b = _conjugate_pairs(terms, la, (c, q))
            assert all(np.array_equal(x, y) for x, y in zip(a, b, strict=True))
            seen.add(a[0].size)
    assert len(seen) > 1  # (some kicks broke a pair: the tolerance was crossed)


def test_static_rows_in_the_product_are_the_rows_formed():
    """ModalRows.transfer with the static correction as coordinates 1, −ω², iω in the
    modes' product (real static rows: one real product; complex ones: a complex
    product; r₀ alone: one static row) equals the formed rows (np.asarray: Φz plus
    r₀ − ω²r₁ + iωr₂ added) contracted with the loads, dense and sparse, sliced; z
    without static coordinates gets them, and too few for rc's terms is refused."""
    import pytest
    from scipy import sparse

    from stochcable.dynamics.residuals.modal_rows import STATIC_ROWS, ModalRows

    rng = np.random.default_rng(8)
    m, k, n_w, n, d = 5, 4, 11, 6, 2
    w = np.linspace(0.1, 3.0, n_w)
    phi = rng.normal(size=((n - 2) * d, m))
    z = rng.normal(size=(k, m, n_w)) + 1j * rng.normal(size=(k, m, n_w))
    ends = np.zeros((2, k, d))
    ends[0, 0], ends[1, 1] = rng.normal(size=d), rng.normal(size=d)
    unit = rng.normal(size=(n, d, 7))
    flat = sparse.csr_matrix(unit.reshape(n * d, -1).T)
    for real in (True, False):
        rc = rng.normal(size=(3, (n - 2) * d, k)) + (0.0 if real else 1j) * rng.normal(
            size=(3, (n - 2) * d, k)
        )
        rc[1:, :, 2:] = 0.0  # (ω terms on the end rows only)
        rows = ModalRows(phi, z, w, rc, ends, n)
        assert rows.z.shape[1] == m + STATIC_ROWS
        for g in (rows, rows[1:3], rows[..., 2:9:3], rows[2:][..., np.arange(1, 8)]):
            ref = np.einsum("onkw,nkl->olw", np.asarray(g), unit)
            scale = np.abs(ref).max()
            assert np.abs(g.transfer(unit) - ref).max() < 1e-13 * scale
            assert np.abs(g.transfer(flat) - ref).max() < 1e-13 * scale
        # (the rows without ω terms with r₀'s coordinate alone)
        one = ModalRows(phi, rows.z[2:, : m + 1], w, rc[:, :, 2:], ends[:, 2:], n)
        ref = np.einsum("onkw,nkl->olw", np.asarray(rows[2:]), unit)
        assert np.abs(one.transfer(unit) - ref).max() < 1e-13 * np.abs(ref).max()
    with pytest.raises(ValueError, match="static coordinate rows"):
        ModalRows(phi, rows.z[:, : m + 1], w, rc, ends, n)
