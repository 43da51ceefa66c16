"""The closed form of Hu & Jin (2001) for a travelling cable in a cross-flow, and its
correction (stochcable.reference.travelling_cable; docs/travelling.md)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import brentq

from stochcable.errors import InputError
from stochcable.reference.travelling_cable import (
    equilibrium_hu_jin,
    groups_hu_jin,
    residual_hu_jin,
)

FIG6 = {"d": 0.1, "c_f": 0.5, "v_f": 0.1, "d_f": 0.1}  # Hu & Jin (2001), Fig. 6


def test_stated_cases_with_the_correction():
    # Fig. 8: μ = 0.1, λ0 = 20: φ0 ≈ 1.571 ≈ π/2.  The transition is steep there
    # (dφ0/dλ0 ≈ 0.48): 0.02 rad is λ0 within 0.2 %
    assert equilibrium_hu_jin(0.1, 20.0, **FIG6).phi[0] == pytest.approx(np.pi / 2, abs=0.02)
    # Fig. 9(a): μ = 0.3, λ0 = 50 stays near the bottom
    assert equilibrium_hu_jin(0.3, 50.0, **FIG6).phi[0] < 0.05
    # Figs. 5(d), 9(b): μ = 0.3, λ0 = 200: φ → 3.04 (two digits printed)
    assert equilibrium_hu_jin(0.3, 200.0, **FIG6).phi[0] == pytest.approx(3.04, abs=0.005)
    # Fig. 7: μ = 0.1 low at λ0 = 10, at the top at λ0 = 100 and 200
    assert equilibrium_hu_jin(0.1, 10.0, **FIG6).phi[0] < np.pi / 4
    for lam0 in (100.0, 200.0):
        assert equilibrium_hu_jin(0.1, lam0, **FIG6).phi[0] > 3.0


def test_printed_equations_contradict_the_figures():
    """As printed (X = D_f v_f) the μ = 0.1 cable is near the top already at λ0 = 10
    and the μ = 0.3 cable at λ0 = 50: the reason for the correction."""
    assert equilibrium_hu_jin(0.1, 10.0, **FIG6, figure_scaling=False).phi[0] > 2.5
    assert equilibrium_hu_jin(0.3, 50.0, **FIG6, figure_scaling=False).phi[0] > 2.5


@pytest.mark.parametrize("scaling", [True, False])
@pytest.mark.parametrize("mu", [0.1, 0.2, 0.3])
@pytest.mark.parametrize("lam0", [0.0, 3.0, 20.0, 80.0, 150.0, 400.0])
def test_cubic_root_solves_eq39(mu, lam0, scaling):
    """The cubic (40)–(42) against a bracketed root of (39) itself: the one root in
    (0, π); φ02 = φ01 + π also solves it."""
    g = groups_hu_jin(mu, lam0, **FIG6, figure_scaling=scaling)
    eq = equilibrium_hu_jin(mu, lam0, **FIG6, figure_scaling=scaling)
    f = lambda p: float(residual_hu_jin(np.array(p), g))  # noqa: E731
    grid = np.linspace(1e-9, np.pi - 1e-9, 4001)
    vals = np.array([f(p) for p in grid])
    sign = np.flatnonzero(np.sign(vals[:-1]) != np.sign(vals[1:]))
    assert sign.size == 1
    ref = brentq(f, grid[sign[0]], grid[sign[0] + 1], xtol=1e-14)
    assert eq.phi[0] == pytest.approx(ref, abs=1e-9)
    assert abs(f(eq.phi[1])) < 1e-12


def test_not_travelling_reduces_to_eqs_36_37():
    mu, x = 0.2, 0.1 * 0.1 * 0.1
    eq = equilibrium_hu_jin(mu, 0.0, **FIG6)
    a = mu**2 - 0.5 * x
    r = np.hypot(a, x)
    assert eq.phi[0] == pytest.approx(np.arccos(a / r), rel=1e-12)  # eq. (36)
    np.testing.assert_allclose(eq.xi, [8 / np.pi**5 * r, -8 / np.pi**5 * r], rtol=1e-12)


@pytest.mark.parametrize("mu", [0.1, 0.2, 0.3])
def test_left_stable_right_saddle(mu):
    """Eq. (44) against the slope of (39): the restoring coefficient is δ1·dR/dφ."""
    for lam0 in np.geomspace(0.5, 500.0, 25):
        eq = equilibrium_hu_jin(mu, lam0, **FIG6)
        assert eq.kind[0].startswith("stable") and eq.kind[1] == "saddle"
        g = groups_hu_jin(mu, lam0, **FIG6)
        for p, k in zip(eq.phi, eq.stiffness, strict=True):
            h = 1e-6
            slope = (residual_hu_jin(p + h, g) - residual_hu_jin(p - h, g)) / (2 * h)
            # central difference: O(h²) ≈ 1e-12 against coefficients ≥ 1e-4
            assert k == pytest.approx(4 / np.pi * slope, rel=1e-6)


def test_figure6_rises_and_heavier_cables_rise_later():
    lam = np.geomspace(1.0, 1000.0, 200)
    crossing = []
    for mu in (0.1, 0.2, 0.3):
        phi = np.array([equilibrium_hu_jin(mu, x, **FIG6).phi[0] for x in lam])
        assert (np.diff(phi) > -1e-12).all()  # up from the bottom to the top
        crossing.append(lam[np.argmax(phi > np.pi / 2)])
    # the transition φ0 = π/2 near μ²/(c_f d D_f v_f) = 20, 80, 180
    np.testing.assert_allclose(crossing, [20.0, 80.0, 180.0], rtol=0.04)


def test_bad_input_named():
    with pytest.raises(InputError, match="lambda0"):
        equilibrium_hu_jin(0.1, -1.0)
    with pytest.raises(InputError, match="mu"):
        equilibrium_hu_jin(0.0, 1.0)
