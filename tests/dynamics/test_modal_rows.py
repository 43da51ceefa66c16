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
