"""The compiled ends' contraction of a kind's dense pair lines
(stochcable.dynamics.residuals.pair_form_kernels) against NumPy's
(residual_lines.dense_pair_outputs: the square G cast to double, one matrix product per
line): the same sums over the upper triangle in another order, so equal to round-off;
and PairLines' outputs the same with and without numba (STOCHCABLE_NUMBA=0)."""

from __future__ import annotations

import numpy as np
import pytest

from stochcable.dynamics.residuals.residual_lines import PairLines, dense_pair_outputs

kernels = pytest.importorskip("stochcable.dynamics.residuals.pair_form_kernels")


def _upper(rng: np.random.Generator, n_o: int, n: int) -> np.ndarray:
    """Random complex64 lines G (n_o, n·n), zero below the diagonal."""
    e, f = np.triu_indices(n)
    g = np.zeros((n_o, n * n), dtype=np.complex64)
    g[:, e * n + f] = rng.normal(size=(n_o, e.size)) + 1j * rng.normal(size=(n_o, e.size))
    return g


@pytest.mark.parametrize("n_o, n, n_out", [(1, 1, 1), (5, 3, 2), (189, 51, 2), (40, 17, 7)])
def test_upper_forms_match_dense(n_o: int, n: int, n_out: int) -> None:
    rng = np.random.default_rng(31)
    g = _upper(rng, n_o, n)
    t = rng.normal(size=(n_out, n, n_o)) + 1j * rng.normal(size=(n_out, n, n_o))
    ref = dense_pair_outputs(g, t)
    got = kernels.upper_forms(g, t)
    # round-off of sums of ~n²/2 products of order 1 in double (another order)
    assert np.max(np.abs(got - ref)) <= 1e-13 * np.max(np.abs(ref))


def test_pair_lines_with_and_without_numba(monkeypatch: pytest.MonkeyPatch) -> None:
    rng = np.random.default_rng(7)
    n, n_o, n_out = 40, 120, 2  # (above KERNEL_MIN_ENTRIES: the kernel's path)
    t = rng.normal(size=(n_out, n, n_o)) + 1j * rng.normal(size=(n_out, n, n_o))
    e, f = np.triu_indices(n)
    g = rng.normal(size=(e.size, n_o)) + 1j * rng.normal(size=(e.size, n_o))

    def outputs() -> np.ndarray:
        lines = PairLines(t)
        for s in range(0, e.size, 300):  # (in blocks, as the residuals add them)
            lines.add(g[s : s + 300], e[s : s + 300], f[s : s + 300])
        return lines.outputs()

    compiled = outputs()
    monkeypatch.setenv("STOCHCABLE_NUMBA", "0")
    plain = outputs()
    assert np.max(np.abs(compiled - plain)) <= 1e-13 * np.max(np.abs(plain))


def test_upper_forms_by_blocks() -> None:
    """G upper triangular by blocks (the geometric residual's two components of the
    element pairs f ≥ e): the same as the dense contraction."""
    rng = np.random.default_rng(3)
    n_el, n_comp, n_o, n_out = 9, 2, 30, 2
    n = n_el * n_comp
    e, f = np.triu_indices(n_el)
    g = np.zeros((n_o, n * n), dtype=np.complex64)
    for i in range(n_comp):
        for j in range(n_comp):
            cols = (i * n_el + e) * n + j * n_el + f
            g[:, cols] = rng.normal(size=(n_o, e.size)) + 1j * rng.normal(size=(n_o, e.size))
    t = rng.normal(size=(n_out, n, n_o)) + 1j * rng.normal(size=(n_out, n, n_o))
    ref = dense_pair_outputs(g, t)
    got = kernels.upper_forms(g, t, n_el)
    assert np.max(np.abs(got - ref)) <= 1e-13 * np.max(np.abs(ref))
