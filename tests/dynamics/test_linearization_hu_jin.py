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
