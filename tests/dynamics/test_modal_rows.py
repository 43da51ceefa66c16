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
    z = rng.normal(size=(m, k, n_w)) + 1j * rng.normal(size=(m, k, n_w))
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
