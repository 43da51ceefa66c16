"""Tests of stochcable.dynamics.linearization.formulas: drag linearization formulas and the fixed
point."""

from __future__ import annotations

import math

import numpy as np
import pytest

from stochcable.dynamics.linearization.formulas import (
    _erf,
    borgman_variance_ratio,
    drag_linear_current,
    drag_linear_harmonic,
    drag_linear_seed,
    drag_linear_vector,
    mean_drag_gaussian,
)
from stochcable.dynamics.linearization.iteration import fixed_point
from stochcable.dynamics.model.solvers import solve_direct
from stochcable.errors import ConvergenceError, InputError

RHO, CD, DIAM = 1025.0, 1.2, 0.1
KAPPA = 0.5 * RHO * CD * DIAM  # 1/2 rho Cd D [N s^2/m^3]

# Tuah 1982, eq. (5.2.2.a): B = (2/pi)^(1/2) Cd rho D sigma (printed form).
TUAH_1982_EQ_5_2_2_A = math.sqrt(2.0 / math.pi)
# Tuah 1982, eq. (5.2.2.b): B = (2 pi)^(1/2) Ct rho D sigma (printed form).
TUAH_1982_EQ_5_2_2_B = math.sqrt(2.0 * math.pi)


def _mc_mean_abs(mean, sigma, n, rng):
    v = mean + sigma * rng.standard_normal(n)
    return np.abs(v), v


# ------------------------------------------------------------------ scalar forms


def test_seed_form_matches_printed_equations():
    sigma = np.array([0.0, 0.3, 1.7])
    b = drag_linear_seed(RHO, CD, DIAM, sigma)
    # eq. 5.2.2.a as printed; identical algebra -> round-off only
    np.testing.assert_allclose(b, TUAH_1982_EQ_5_2_2_A * CD * RHO * DIAM * sigma, rtol=1e-14)
    # eq. 5.2.2.b: axial drag with "diameter" = pi D reproduces (2 pi)^(1/2) Ct rho D sigma
    ct = 0.02
    bt = drag_linear_seed(RHO, ct, math.pi * DIAM, sigma)
    np.testing.assert_allclose(bt, TUAH_1982_EQ_5_2_2_B * ct * RHO * DIAM * sigma, rtol=1e-14)


def test_current_form_limits():
    sigma = np.array([1e-9, 0.5, 1.0, 2.0])
    # U = 0: the seed form exactly (same closed form, round-off)
    np.testing.assert_allclose(
        drag_linear_current(RHO, CD, DIAM, sigma, 0.0),
        drag_linear_seed(RHO, CD, DIAM, sigma),
        rtol=1e-14,
    )
    # sigma -> 0: rho Cd D |U|, exactly at sigma = 0, and within O(sigma^2 / U^2) near 0
    u = np.array([-2.0, -0.3, 0.4, 1.5])
    np.testing.assert_allclose(
        drag_linear_current(RHO, CD, DIAM, 0.0, u), RHO * CD * DIAM * np.abs(u), rtol=1e-15
    )
    near = drag_linear_current(RHO, CD, DIAM, 1e-4, u)
    # E|v| = |U| (1 + O(e^{-U^2/2 s^2})) -> relative error far below 1e-12 for U/s >= 3000
    np.testing.assert_allclose(near, RHO * CD * DIAM * np.abs(u), rtol=1e-12)
    # sigma = U = 0 together: zero, no NaN (RuntimeWarnings are errors in this suite)
    assert drag_linear_current(RHO, CD, DIAM, 0.0, 0.0) == 0.0
    assert mean_drag_gaussian(RHO, CD, DIAM, 0.0, 0.0) == 0.0


def test_erf_equals_scipy_erf():
    """The formulas' erf (the C library's, without importing scipy.special) against
    scipy.special.erf over the arguments the drag formulas meet (U/(σ√2) of any size,
    signed zeros, tiny and saturated values, infinities, NaN)."""
    special = pytest.importorskip("scipy.special")
    rng = np.random.default_rng(20261128)
    x = np.concatenate(
        [
            rng.normal(0.0, 3.0, 100_000),
            rng.uniform(-1e-3, 1e-3, 10_000),
            np.linspace(-7.0, 7.0, 10_001),
            [0.0, -0.0, 1e-300, -5e-324, 5.9, 6.0, 27.0, np.inf, -np.inf],
        ]
    ).reshape(-1, 10)
    new, old = _erf(x), special.erf(x)
    assert new.shape == x.shape and new.dtype == np.float64
    # two implementations of a correctly rounded-to-1-ulp function: 2 ulp = 4.4e-16
    np.testing.assert_allclose(new, old, rtol=1e-15, atol=0.0)
    assert np.array_equal(np.signbit(new), np.signbit(old))  # erf(-0) = -0
    assert np.isnan(_erf(np.array([np.nan]))).all()
    assert _erf(np.float64(0.5)).shape == ()


def test_current_forms_equal_the_scipy_erf_forms():
    """drag_linear_current, mean_drag_gaussian and borgman_variance_ratio equal their
    closed forms evaluated with scipy.special.erf (the formulas' erf before it was the C
    library's)."""
    special = pytest.importorskip("scipy.special")
    rng = np.random.default_rng(7)
    sigma = rng.uniform(0.01, 2.0, 2000)
    u = rng.normal(0.0, 1.5, 2000)
    r = u / sigma
    c = math.sqrt(2.0 / math.pi)
    e_abs = sigma * c * np.exp(-0.5 * r**2) + u * special.erf(r / math.sqrt(2.0))
    e_vv = (u**2 + sigma**2) * special.erf(r / math.sqrt(2.0)) + u * sigma * c * np.exp(-0.5 * r**2)
    # both terms of E|v| and of E[v|v|] have the sign of U: no cancellation, the 2 ulp
    # of erf stay a few ulp
    np.testing.assert_allclose(
        drag_linear_current(RHO, CD, DIAM, sigma, u), RHO * CD * DIAM * e_abs, rtol=2e-15
    )
    np.testing.assert_allclose(
        mean_drag_gaussian(RHO, CD, DIAM, sigma, u), KAPPA * e_vv, rtol=2e-15
    )
    m = np.abs(r)
    m = m[m <= 8.5]  # below the large-|μ| asymptote of borgman_variance_ratio
    erf = special.erf(m / math.sqrt(2.0))
    ex = c * np.exp(-0.5 * m**2)
    mvv = (m**2 + 1.0) * erf + m * ex
    ratio = 4.0 * (m * erf + ex) ** 2 / (m**4 + 6.0 * m**2 + 3.0 - mvv**2)
    # Var(v|v|) = μ⁴ + 6μ² + 3 - E[v|v|]² cancels down to ≈ 4μ² + 2: the erf's ulp
    # grow by up to (μ⁴ + 6μ² + 3)/(4μ² + 2) ≈ 19 at μ = 8.5, hence 1e-14
    np.testing.assert_allclose(borgman_variance_ratio(1.0, m), ratio, rtol=1e-14)


def test_current_form_and_mean_force_monte_carlo():
    rng = np.random.default_rng(20240521)
    n = 2_000_000
    for mean, sigma in [(0.0, 1.0), (0.4, 1.0), (-1.5, 0.7), (3.0, 0.5)]:
        a, v = _mc_mean_abs(mean, sigma, n, rng)
        b = drag_linear_current(RHO, CD, DIAM, sigma, mean)
        f = mean_drag_gaussian(RHO, CD, DIAM, sigma, mean)
        # 5 standard errors of the sample means of |v| and |v| v
        tol_b = 5.0 * a.std() / math.sqrt(n)
        tol_f = 5.0 * (a * v).std() / math.sqrt(n)
        assert abs(b / (RHO * CD * DIAM) - a.mean()) < tol_b
        assert abs(f / KAPPA - (a * v).mean()) < tol_f


def test_current_form_is_least_squares_fit():
    # Borgman: B minimizes E[(f(v) - E f - B (v - U))^2]; the normal equation gives
    # B = E[f(v) (v - U)] / sigma^2, integrated here with adaptive quadrature split at
    # the kink v = 0 (independent of the closed form and of Stein's lemma).
    from scipy import integrate, stats

    for mean, sigma in [(0.7, 1.3), (-0.2, 0.4)]:
        pdf = stats.norm(mean, sigma).pdf

        def g(v, mean=mean, pdf=pdf):
            return KAPPA * abs(v) * v * (v - mean) * pdf(v)

        num = integrate.quad(g, -np.inf, 0.0, epsabs=0, epsrel=1e-12)[0]
        num += integrate.quad(g, 0.0, np.inf, epsabs=0, epsrel=1e-12)[0]
        b = drag_linear_current(RHO, CD, DIAM, sigma, mean)
        # adaptive quadrature to ~1e-12; allow 1e-9 for the infinite-interval mapping
        assert num / sigma**2 == pytest.approx(b, rel=1e-9)


def test_harmonic_form_equal_dissipation():
    # Lorentz: (8/3pi) k |v| equals the cycle-average of k |v| v * v over v^2 (equal work)
    amp = 1.7
    th = np.linspace(0.0, 2.0 * math.pi, 20001)[:-1]
    v = amp * np.cos(th)
    b_work = np.mean(KAPPA * np.abs(v) * v * v) / np.mean(v * v)
    # periodic trapezoid of a C^2 periodic integrand: error << 1e-9
    assert drag_linear_harmonic(RHO, CD, DIAM, amp) == pytest.approx(b_work, rel=1e-9)


def test_input_errors_name_the_parameter():
    with pytest.raises(InputError, match=r"sigma = .*m/s.*>= 0"):
        drag_linear_seed(RHO, CD, DIAM, -1.0)
    with pytest.raises(InputError, match=r"rho .*kg/m\^3"):
        drag_linear_current(-1.0, CD, DIAM, 1.0, 0.0)
    with pytest.raises(InputError, match=r"cov.*shape \(\.\.\., 2, 2\)"):
        drag_linear_vector(RHO, CD, DIAM, np.eye(3))
    with pytest.raises(InputError, match=r"cov.*positive semi-definite"):
        drag_linear_vector(RHO, CD, DIAM, np.array([[1.0, 0.0], [0.0, -1.0]]))


# ------------------------------------------------------------------ vector form


def test_vector_form_one_direction_equals_seed_form_and_half():
    # velocity only along e = (cos a, sin a): B = seed form along e, half of it across
    sigma = 0.8
    for ang in (0.0, 0.3, 1.2):
        e = np.array([math.cos(ang), math.sin(ang)])
        n_perp = np.array([-e[1], e[0]])
        cov = sigma**2 * np.outer(e, e)
        b = drag_linear_vector(RHO, CD, DIAM, cov)
        seed = drag_linear_seed(RHO, CD, DIAM, sigma)
        # closed form (elliptic integrals at m = 1): round-off only
        assert e @ b @ e == pytest.approx(seed, rel=1e-12)
        assert n_perp @ b @ n_perp == pytest.approx(0.5 * seed, rel=1e-12)
        assert e @ b @ n_perp == pytest.approx(0.0, abs=1e-12 * seed)
        # with a mean along the same line: the scalar current form (and half across);
        # graded quadrature, relative accuracy ~5e-8
        for mean in (0.3, -1.1):
            bm = drag_linear_vector(RHO, CD, DIAM, cov, mean * e)
            cur = drag_linear_current(RHO, CD, DIAM, sigma, mean)
            assert e @ bm @ e == pytest.approx(cur, rel=1e-7)
            assert n_perp @ bm @ n_perp == pytest.approx(0.5 * cur, rel=1e-7)


def test_vector_form_isotropic_closed_form():
    # isotropic: E|v| = sigma sqrt(pi/2) (Rayleigh mean) and E[v v^T/|v|] = E|v|/2 I
    sigma = 1.3
    b = drag_linear_vector(RHO, CD, DIAM, sigma**2 * np.eye(2))
    expected = KAPPA * 1.5 * sigma * math.sqrt(math.pi / 2.0)
    np.testing.assert_allclose(b, expected * np.eye(2), rtol=1e-13)


def test_vector_quadrature_agrees_with_closed_form_at_zero_mean():
    # mean = 0 passed explicitly uses the graded quadrature; mean=None the elliptic form
    covs = np.array(
        [
            [[1.0, 0.3], [0.3, 0.5]],
            [[2.0, 0.0], [0.0, 2.0]],
            [[1.0, 0.999], [0.999, 1.0]],  # nearly one-directional (ratio of std 0.02)
            [[1e-12, 0.0], [0.0, 1.0]],
        ]
    )
    b_closed = drag_linear_vector(RHO, CD, DIAM, covs)
    b_quad = drag_linear_vector(RHO, CD, DIAM, covs, np.zeros((4, 2)))
    scale = np.abs(b_closed).max(axis=(1, 2))[:, None, None]
    # quadrature accuracy ~5e-8 relative (8.5-sigma truncation, graded Gauss-Legendre)
    assert np.all(np.abs(b_quad - b_closed) <= 1e-7 * scale)


def test_vector_form_monte_carlo_with_mean_and_correlation():
    rng = np.random.default_rng(7)
    cov = np.array([[0.9, 0.35], [0.35, 0.4]])
    mean = np.array([0.25, -0.6])
    n = 1_000_000
    v = rng.multivariate_normal(mean, cov, size=n)
    r = np.linalg.norm(v, axis=1)
    samples = np.empty((n, 2, 2))
    samples[:] = np.eye(2)
    samples *= r[:, None, None]
    samples += v[:, :, None] * (v / r[:, None])[:, None, :]
    est = samples.mean(axis=0)
    se = samples.std(axis=0) / math.sqrt(n)
    b = drag_linear_vector(RHO, CD, DIAM, cov, mean) / KAPPA
    # 5 standard errors of the Monte Carlo mean, entrywise
    assert np.all(np.abs(b - est) < 5.0 * se)
    # differs from applying the scalar current form per principal component (the
    # DESIGN point of the option): more than 20 sampling errors away
    lam, q = np.linalg.eigh(cov)
    mp = q.T @ mean
    scalar = q @ np.diag(drag_linear_current(RHO, CD, DIAM, np.sqrt(lam), mp)) @ q.T / KAPPA
    assert np.abs(scalar - b).max() > 20.0 * se.max()


def test_vector_form_broadcasts_over_elements():
    covs = np.stack([np.eye(2) * s for s in (0.1, 0.5, 2.0)])
    b = drag_linear_vector(np.array([1000.0, 1025.0, 1030.0]), CD, DIAM, covs)
    for i, s in enumerate((0.1, 0.5, 2.0)):
        single = drag_linear_vector([1000.0, 1025.0, 1030.0][i], CD, DIAM, np.eye(2) * s)
        np.testing.assert_allclose(b[i], single, rtol=1e-14)
    assert drag_linear_vector(RHO, CD, DIAM, np.zeros((2, 2))).max() == 0.0


# ------------------------------------------------------------------ fixed point

W_GRID = np.linspace(0.01, 6.0, 1500)


def _pm_velocity(w, sigma_v=1.0, wp=0.8):
    """PM-shaped one-sided velocity spectrum with variance ~sigma_v^2 (closed form)."""
    return (5.0 / 16.0) * (4 * sigma_v) ** 2 * wp**4 * w**-5 * np.exp(-1.25 * (wp / w) ** 4)


def _sdof_update(kappa=0.15, m=1.0, k=1.0):
    s_v = _pm_velocity(W_GRID)

    def update(sig):
        b = math.sqrt(8.0 / math.pi) * kappa * sig[0]
        hr = (k - m * W_GRID**2) / (k - m * W_GRID**2 + 1j * W_GRID * b)
        return np.array([math.sqrt(np.trapezoid(np.abs(hr) ** 2 * s_v, W_GRID))])

    return update


def _chain_update(n=8, kappa=0.3):
    """Chain of n masses (springs to ground and between), drag on the relative velocity
    to a flow v_j = v(t - x_j/c) (phase lag); sigma_r per mass via solve_direct."""
    m, k = 1.0, 2.0
    K = np.diag(np.full(n, 2 * k + 0.5)) - k * np.eye(n, k=1) - k * np.eye(n, k=-1)
    K[-1, -1] -= k
    M = np.eye(n) * m
    s_v = _pm_velocity(W_GRID)
    lag = np.exp(-1j * np.outer(W_GRID, np.arange(n)) * 0.7)  # (n_omega, n)

    def update(sig):
        b = drag_linear_seed(1.0, 1.0, 2.0 * kappa, sig)  # sqrt(8/pi) kappa sigma
        C = np.diag(b)
        u = solve_direct(K, M, C, lag * b, W_GRID)
        vr = lag - 1j * W_GRID[:, None] * u
        return np.sqrt(np.trapezoid(np.abs(vr) ** 2 * s_v[:, None], W_GRID, axis=0))

    return update


@pytest.mark.parametrize("problem", ["sdof", "chain"])
def test_anderson_needs_fewer_iterations(problem):
    update = _sdof_update() if problem == "sdof" else _chain_update()
    x0 = np.ones(1 if problem == "sdof" else 8)
    anderson = fixed_point(update, x0, tol=1e-8, relaxation=0.5, method="anderson")
    assert anderson.converged
    for beta in (0.5, 1.0):  # under-relaxed and plain Picard iteration
        picard = fixed_point(update, x0, tol=1e-8, relaxation=beta, method="relaxed")
        assert picard.converged
        assert anderson.iterations < picard.iterations
    relaxed = picard
    # both are fixed points of the same map to the tolerance (1e-8 relative, x ~ 1)
    np.testing.assert_allclose(anderson.x, relaxed.x, rtol=1e-7)
    np.testing.assert_allclose(update(anderson.x), anderson.x, rtol=1e-7)
    assert anderson.history[-1] == anderson.relative_change <= 1e-8


def test_sdof_quadratic_damping_white_noise_closed_form():
    # m x'' + k x + kappa |x'| x' = F(t), F white with one-sided density S0.
    # Linearized: B = sqrt(8/pi) kappa sigma_v and sigma_v^2 = pi S0 / (2 m B) (one-sided
    # white-noise integral), so the fixed point is sigma_v^3 = pi S0 / (2 m sqrt(8/pi) kappa).
    m, k, kappa, s0 = 2.0, 3.0, 0.4, 0.05
    w = np.concatenate([np.linspace(0.0, 4.0, 8001)[1:], np.linspace(4.0, 200.0, 20001)[1:]])
    one = np.ones((w.size, 1))

    def update(sig):
        b = drag_linear_seed(1.0, 1.0, 2.0 * kappa, sig)
        h = solve_direct([[k]], [[m]], [[b[0]]], one, w)[:, 0]
        return np.array([math.sqrt(np.trapezoid(w**2 * np.abs(h) ** 2 * s0, w))])

    res = fixed_point(update, [1.0], tol=1e-10)
    exact = (math.pi * s0 / (2.0 * m * math.sqrt(8.0 / math.pi) * kappa)) ** (1.0 / 3.0)
    # truncation at 200 rad/s drops ~S0/(m^2 * 200) of sigma^2 (relative 2B/(pi m 200)
    # ~ 2e-4), i.e. ~1e-4 on sigma after the cube root; grid error is far smaller
    assert res.x[0] == pytest.approx(exact, rel=3e-4)
    assert res.x[0] < exact  # the truncated tail can only lower sigma


def test_non_convergence_raises_with_partial_or_returns_flagged():
    update = _sdof_update()
    with pytest.raises(ConvergenceError, match=r"drag linearization did not converge.*2 iter"):
        fixed_point(update, [1.0], tol=1e-12, max_iterations=2, method="relaxed")
    try:
        fixed_point(update, [1.0], tol=1e-12, max_iterations=2, method="relaxed")
    except ConvergenceError as exc:
        assert exc.partial is not None and not exc.partial.converged
        assert exc.partial.iterations == 2
    res = fixed_point(update, [1.0], tol=1e-12, max_iterations=2, allow_unconverged=True)
    assert not res.converged and res.relative_change > 1e-12
    assert res.as_dict()["converged"] is False


def test_fixed_point_keeps_nonnegative_and_handles_zero_components():
    # a component whose fixed point is 0 (element above water): must not block convergence
    def update(x):
        return np.array([0.5 * x[0] + 1.0, 0.0, 0.3 * x[2]])

    res = fixed_point(update, [0.0, 1.0, 2.0], tol=1e-9)
    assert res.converged
    np.testing.assert_allclose(res.x, [2.0, 0.0, 0.0], atol=1e-8)
    assert np.all(res.x >= 0)
    with pytest.raises(InputError, match="relaxation"):
        fixed_point(update, [1.0, 1.0, 1.0], relaxation=1.5)
    with pytest.raises(InputError, match="x0"):
        fixed_point(update, [-1.0, 1.0, 1.0])


def test_fixed_point_anderson_mixing_parameter():
    # linear contraction x = A x + b (spectral radius 0.6): same fixed point with any
    # mixing; mixing=None is the old behaviour (mixing = relaxation)
    rng = np.random.default_rng(11)
    q, _ = np.linalg.qr(rng.standard_normal((6, 6)))
    a = q @ np.diag([0.6, -0.5, 0.3, 0.2, -0.1, 0.05]) @ q.T
    b = rng.uniform(1.0, 2.0, 6)
    exact = np.linalg.solve(np.eye(6) - a, b)
    runs = {}
    for mix in (None, 0.5, 1.0):
        r = fixed_point(lambda x: a @ x + b, np.abs(b), tol=1e-10, relaxation=0.5, mixing=mix)
        np.testing.assert_allclose(r.x, exact, rtol=1e-8)  # tol 1e-10 on the change
        runs[mix] = r
    assert runs[None].history == runs[0.5].history
    with pytest.raises(InputError, match="mixing"):
        fixed_point(lambda x: x, [1.0], mixing=0.0)


@pytest.mark.parametrize("problem", ["sdof", "chain"])
def test_fixed_point_started_after_an_evaluation_takes_it_into_anderson_memory(problem):
    # fixed_point(before=(x_prev, update(x_prev))) from x0 = update(x_prev): the earlier
    # evaluation opens the Anderson memory, so the first step is a secant step: the
    # same fixed point (both to tol 1e-8 relative on x ~ 1), its second evaluation at
    # least 2x closer than after the relaxed first step from the same x0 (measured:
    # 100x on the sdof, 2.5x on the chain), in no more evaluations
    update = _sdof_update() if problem == "sdof" else _chain_update()
    x_prev = np.ones(1 if problem == "sdof" else 8)
    x0 = update(x_prev)
    plain = fixed_point(update, x0, tol=1e-8, relaxation=0.5)
    seeded = fixed_point(update, x0, tol=1e-8, relaxation=0.5, before=(x_prev, x0))
    assert plain.converged and seeded.converged
    assert seeded.history[0] == plain.history[0]  # (the same first evaluation)
    assert seeded.history[1] < 0.5 * plain.history[1]
    assert seeded.iterations <= plain.iterations
    np.testing.assert_allclose(seeded.x, plain.x, rtol=1e-7)
    np.testing.assert_allclose(update(seeded.x), seeded.x, rtol=1e-7)
    # the relaxed iteration ignores it (no memory); a pair of the wrong size is dropped
    relaxed = fixed_point(update, x0, tol=1e-8, method="relaxed")
    assert fixed_point(update, x0, tol=1e-8, method="relaxed", before=(x_prev, x0)).history == (
        relaxed.history
    )
    wrong = (np.ones(x0.size + 1), np.ones(x0.size + 1))
    assert fixed_point(update, x0, tol=1e-8, before=wrong).history == plain.history


def test_current_form_without_current_is_the_seed_form_to_the_bit():
    """E|v| = σ√(2/π) for a zero-mean Gaussian: drag_linear_current with no current
    (its shortcut) against drag_linear_seed, and σ = 0 gives no drag."""
    rng = np.random.default_rng(3)
    sigma = np.r_[0.0, rng.uniform(0.0, 3.0, 200), 1e-300]
    got = drag_linear_current(1025.0, 1.2, 0.1, sigma, np.zeros_like(sigma))
    # the general expression's value: σ·√(2/π)·e⁰ + 0·erf(0)
    expected = 1025.0 * 1.2 * 0.1 * np.where(sigma > 0, sigma * math.sqrt(2.0 / math.pi), 0.0)
    np.testing.assert_array_equal(got, expected)
    np.testing.assert_allclose(
        got, drag_linear_seed(1025.0, 1.2, 0.1, sigma), rtol=4e-16
    )  # √(8/π)·½ against √(2/π): one rounding
    assert got[0] == 0.0
