"""The compiled element variances (stochcable.dynamics.linearization.variance_kernels) against the
formula they sum, written out with NumPy, and the analysis with and without them."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("numba")

from stochcable.analysis import analyze  # noqa: E402
from stochcable.dynamics.linearization.variance_kernels import element_variance_terms  # noqa: E402
from stochcable.examples import load_example  # noqa: E402


def _reference(rows, u_nodes, u_free, omega, weights, moments):
    """Σ w [(|q_a|² + |q_b|² + Re(q̄_a q_b))/3 + 2 Re(m̄_a q_a + m̄_b q_b)], q = −iωU."""
    n_el, k, d = rows.shape
    n_w, n_ch = weights.shape
    u = np.zeros((n_el + 1, d, n_w, n_ch), dtype=complex)
    if u_nodes is not None:
        u += u_nodes
    if u_free is not None:
        u[1:-1] += u_free
    q = -1j * omega[:, None] * u
    qa = np.einsum("ekj,ejwc->ekwc", rows, q[:-1])
    qb = np.einsum("ekj,ejwc->ekwc", rows, q[1:])
    terms = (abs(qa) ** 2 + abs(qb) ** 2 + (qa.conj() * qb).real) / 3.0
    if moments is not None:
        ma = np.einsum("ekj,ejwc->ekwc", rows, moments[:, 0])
        mb = np.einsum("ekj,ejwc->ekwc", rows, moments[:, 1])
        terms = terms + 2.0 * (ma.conj() * qa + mb.conj() * qb).real
    return np.einsum("ekwc,wc->ek", terms, weights)


@pytest.mark.parametrize("d,k", [(2, 2), (3, 4)])
@pytest.mark.parametrize("nodes,free,fluid", [(1, 1, 1), (0, 1, 1), (1, 0, 0), (0, 1, 0)])
def test_compiled_terms_equal_the_formula(d, k, nodes, free, fluid):
    rng = np.random.default_rng(7)
    n_el, n_w, n_ch = 6, 9, 2

    def c(*shape):
        return rng.standard_normal(shape) + 1j * rng.standard_normal(shape)

    rows = rng.standard_normal((n_el, k, d))
    u_nodes = c(n_el + 1, d, n_w, n_ch) if nodes else None
    u_free = c(n_el - 1, d, n_w, n_ch) if free else None
    moments = c(n_el, 2, d, n_w, n_ch) if fluid else None
    omega = np.linspace(0.1, 2.0, n_w)
    weights = rng.random((n_w, n_ch))
    var = np.full((n_el, k), 0.5)
    element_variance_terms(rows, u_nodes, u_free, omega, weights, moments, var)
    ref = 0.5 + _reference(rows, u_nodes, u_free, omega, weights, moments)
    np.testing.assert_allclose(var, ref, rtol=1e-12, atol=1e-12 * np.abs(ref).max())


def test_analysis_with_and_without_the_compiled_terms(monkeypatch):
    scene = load_example("chain_catenary")
    compiled = analyze(scene).lines["leg1"]
    monkeypatch.setenv("STOCHCABLE_NUMBA", "0")
    plain = analyze(scene).lines["leg1"]
    np.testing.assert_allclose(compiled.tension_std, plain.tension_std, rtol=1e-10)
    assert compiled.end_b.std == pytest.approx(plain.end_b.std, rel=1e-10)
