"""The statistical linearization of the Hu & Jin drag ½ρC_dD|V|V_n
(stochcable.dynamics.linearization.hu_jin)."""

from __future__ import annotations

import numpy as np
import pytest

from stochcable.dynamics.linearization.formulas import drag_linear_current
from stochcable.dynamics.linearization.hu_jin import drag_linear_hu_jin

RHO, CD, DIA = 1025.0, 1.2, 0.1


@pytest.mark.parametrize("mean", [0.0, 0.3, 1.5])
def test_no_axial_flow_is_the_cross_flow_coefficient(mean):
    """W = 0: ½ρC_dD E[2|v|] = ρC_dD E|v|, the closed form, to the quadrature's 1e-6."""
    sig = np.array([0.05, 0.4, 2.0])
    got = drag_linear_hu_jin(RHO, CD, DIA, sig, mean, 0.0)
    ref = drag_linear_current(RHO, CD, DIA, sig, mean)
    np.testing.assert_allclose(got, ref, rtol=1e-6)


@pytest.mark.parametrize(("sigma", "mean", "axial"), [(0.5, 0.0, 1.0), (0.3, 0.6, -2.0)])
def test_against_monte_carlo_of_the_nonlinear_force(sigma, mean, axial):
    """B = E[f v′]/σ² for the fluctuation v′ = v − U (Gaussian integration by parts:
    E[f(v)(v − U)] = σ² E[f′(v)]), from 400 000 samples of the nonlinear force, seed
    fixed; tolerance 5 standard errors of the sample mean (about 1 %)."""
    rng = np.random.default_rng(34)
    v = mean + sigma * rng.standard_normal(400_000)
    f = 0.5 * RHO * CD * DIA * np.sqrt(v * v + axial * axial) * v
    samples = f * (v - mean) / sigma**2
    b_mc = samples.mean()
    se = samples.std() / np.sqrt(samples.size)
    b = float(drag_linear_hu_jin(RHO, CD, DIA, sigma, mean, axial))
    assert abs(b - b_mc) < 5.0 * se
    # the transport raises the coefficient above the cross-flow one
    assert b > float(drag_linear_current(RHO, CD, DIA, sigma, mean))


def test_limits():
    """σ = 0: the steady tangent ½ρC_dD(2U² + W²)/√(U² + W²); |W| ≫ σ, U = 0: ½ρC_dD|W|
    (to (σ/W)² = 1e-4)."""
    q = 0.5 * RHO * CD * DIA
    assert float(drag_linear_hu_jin(RHO, CD, DIA, 0.0, 0.6, 0.8)) == pytest.approx(
        q * (2 * 0.36 + 0.64) / 1.0, rel=1e-14
    )
    assert float(drag_linear_hu_jin(RHO, CD, DIA, 0.02, 0.0, 2.0)) == pytest.approx(
        q * 2.0, rel=2e-4
    )


def test_vector_form_against_monte_carlo_and_the_cross_flow_form():
    """The 2×2 normal-plane form B = ½ρC_dD E[|V| I + v vᵀ/|V|], |V| = √(|v|² + W²)
    (drag_linear_vector with ``axial``): W = 0 is the cross-flow matrix to the
    quadrature's 1e-7; with W it matches B = E[f (v − μ)ᵀ] Σ⁻¹ (Stein's lemma) from
    400 000 samples of the nonlinear force, seed fixed, within 5 standard errors."""
    from stochcable.dynamics.linearization.formulas import drag_linear_vector

    cov = np.array([[0.25, 0.06], [0.06, 0.09]])
    mean = np.array([0.4, -0.1])
    b0 = drag_linear_vector(RHO, CD, DIA, cov, mean)
    np.testing.assert_allclose(drag_linear_vector(RHO, CD, DIA, cov, mean, 0.0), b0, rtol=1e-7)
    w = 1.3
    b = drag_linear_vector(RHO, CD, DIA, cov, mean, w)
    rng = np.random.default_rng(340)
    v = mean + rng.standard_normal((400_000, 2)) @ np.linalg.cholesky(cov).T
    f = 0.5 * RHO * CD * DIA * np.sqrt((v * v).sum(axis=1) + w * w)[:, None] * v
    samples = np.einsum("ki,kj->kij", f, (v - mean) @ np.linalg.inv(cov))
    b_mc = samples.mean(axis=0)
    se = samples.std(axis=0) / np.sqrt(samples.shape[0])
    assert np.all(np.abs(b - b_mc) < 5.0 * se)
    assert np.all(np.linalg.eigvalsh(b - b0) > 0.0)  # the axial flow adds damping
