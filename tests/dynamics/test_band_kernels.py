"""The compiled banded Cholesky solve (stochcable.dynamics.model.band_kernels) against SciPy's
``cho_solve_banded`` on the same factor: the same substitutions in another order, so
equal to round-off."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg as sla

band_kernels = pytest.importorskip("stochcable.dynamics.model.band_kernels")


@pytest.mark.parametrize("n, u, k", [(1, 0, 3), (7, 2, 1), (60, 5, 40), (200, 11, 9)])
@pytest.mark.parametrize("complex_rhs", [False, True])
def test_cholesky_band_solve_equals_scipy(n, u, k, complex_rhs):
    # a random SPD banded matrix (diagonally dominant: well conditioned, so the two
    # orders of the same operations agree to a few ulps of the solution's scale)
    rng = np.random.default_rng(n * 100 + u)
    ab = rng.normal(size=(u + 1, n))
    ab[u] = np.abs(ab[u]) + 2.0 * (u + 1)
    factor = sla.cholesky_banded(ab, lower=False)
    rhs = rng.normal(size=(n, k))
    if complex_rhs:
        rhs = rhs + 1j * rng.normal(size=(n, k))
    before = rhs.copy()
    ref = sla.cho_solve_banded((factor, False), rhs)
    got = band_kernels.cholesky_band_solve(factor, rhs)
    assert got.shape == rhs.shape and got.dtype == rhs.dtype
    np.testing.assert_allclose(got, ref, rtol=0, atol=1e-13 * np.abs(ref).max())
    np.testing.assert_array_equal(rhs, before)  # the input is left alone (a fresh result)
