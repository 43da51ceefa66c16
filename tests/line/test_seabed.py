"""The linearized seabed contact (stochcable.line.seabed): the touchdown element split at
the static touchdown and condensed, its continuity in the touchdown's position, and the
element convergence and time-domain check of the bundled chain's end tensions."""

from __future__ import annotations

import math

import numpy as np
import pytest
from _scenes import LINEAR_ONLY
from fem_cases import uniform_mesh

from stochcable import analyze, load_example, load_scene
from stochcable.line.fem import assemble
from stochcable.line.seabed import TOUCHDOWN_SNAP, touchdown_element
from stochcable.scene.model import Seabed

# one worker runs the module: its module fixtures run once (--dist loadgroup)
pytestmark = pytest.mark.xdist_group("test_seabed")

# ------------------------------------------------------------------ touchdown element


def test_touchdown_element_cuts_the_contact_run_at_the_touchdown():
    s0 = np.arange(6) * 10.0
    # the penalty-bed statics marks node 3 grounded; the touchdown is at 24 m
    gr, k, xi = touchdown_element(s0, np.array([1, 1, 1, 1, 0, 0], bool), 24.0)
    np.testing.assert_array_equal(gr, [1, 1, 1, 0, 0, 0])
    assert k == 2 and xi == pytest.approx(0.4, rel=1e-12)
    # within TOUCHDOWN_SNAP of a node: at the node (no split), either side
    _, k, xi = touchdown_element(s0, np.array([1, 1, 1, 0, 0, 0], bool), 20.0 + 1e-6)
    assert (k, xi) == (2, 0.0)
    gr, k, xi = touchdown_element(s0, np.array([1, 1, 1, 0, 0, 0], bool), 30.0 - 1e-6)
    assert (k, xi) == (3, 0.0) and gr[3]
    # no touchdown, or grounded up to end_b: the static contact unchanged
    g0 = np.array([1, 1, 1, 0, 0, 0], bool)
    gr, k, _ = touchdown_element(s0, g0, None)
    np.testing.assert_array_equal(gr, g0)
    assert k is None
    gr, k, _ = touchdown_element(s0, np.ones(6, bool), 40.0)
    assert k is None and gr.all()


def _bed_line(xi: float, n_el: int = 3, l0: float = 10.0, with_node: bool = True):
    """A 3-element line: nodes 0, 1 on the bed (z = 0), 2 and 3 rising; its touchdown
    inside element 1 at fraction ξ, and the same line with a node at the touchdown."""
    ea, ten, kappa = 1.0e8, 1.0e5, 2.0e-3  # curvature w/H of the suspended part
    seabed = Seabed(stiffness=3.0e6, damping=3.0e5)
    mesh = uniform_mesh(n_el, l0, ea, 100.0, diameter=0.2, ca_normal=1.0, weight=200.0)
    s_td = l0 * (1.0 + xi)
    stretch = 1.0 + ten / ea

    def z_of(s):  # tangent to the bed at the touchdown
        return np.where(s > s_td, 0.5 * kappa * (stretch * (s - s_td)) ** 2, 0.0)

    s = mesh.s0
    pos = np.column_stack([stretch * s, np.zeros_like(s), z_of(s)])
    a = assemble(
        mesh,
        pos,
        np.full(n_el, ten),
        1025.0,
        dim=3,
        grounded=s <= s_td,
        seabed=seabed,
        touchdown=s_td,
    )
    if not with_node:
        return a, None
    # the same line with a node t at the touchdown (on the bed): the split element
    lengths = np.array([l0, xi * l0, (1.0 - xi) * l0] + [l0] * (n_el - 2))
    mesh5 = uniform_mesh(n_el + 1, lengths, ea, 100.0, diameter=0.2, ca_normal=1.0, weight=200.0)
    s5 = mesh5.s0
    pos5 = np.column_stack([stretch * s5, np.zeros_like(s5), z_of(s5)])
    pos5[3:, 0] = pos[2:, 0]  # nodes b… where they are on the 3-element line
    b = assemble(
        mesh5,
        pos5,
        np.full(n_el + 1, ten),
        1025.0,
        dim=3,
        grounded=s5 <= s_td + 1e-9,
        seabed=seabed,
        touchdown=s_td,
    )
    return a, b


@pytest.mark.parametrize("xi", [0.05, 0.37, 0.9])
def test_condensed_touchdown_element_is_the_mesh_with_a_node_at_the_touchdown(xi):
    """Guyan condensation, by a second route: assemble the line with a node t at the
    touchdown (line.fem.assemble, nodal contact) and condense t out of its K by the
    Schur complement; K, the bed damping and the mass reduced with the same map
    equal the split model's."""
    a, b = _bed_line(xi)
    assert a.grounded.tolist() == [True, True, False, False]
    t = np.arange(6, 9)  # node 2 of the 4-element line
    o = np.r_[0:6, 9:15]
    kb = b.dense("K")
    r = -np.linalg.solve(kb[np.ix_(t, t)], kb[np.ix_(t, o)])
    k_red = kb[np.ix_(o, o)] + kb[np.ix_(o, t)] @ r
    scale = np.abs(k_red).max()
    np.testing.assert_allclose(a.dense("K"), k_red, rtol=0, atol=1e-9 * scale)
    tmap = np.zeros((15, 12))
    tmap[o, np.arange(12)] = 1.0
    tmap[t] = r
    # the split element's dynamic tension is its suspended part's, t–b, with u_t = R u
    row_t = b.tension_rows[2, 0] @ tmap[t] + b.tension_rows[2, 1] @ tmap[9:12]
    row_a = np.zeros(12)
    row_a[3:9] = a.tension_rows[1].ravel()
    np.testing.assert_allclose(row_a, row_t, rtol=0, atol=1e-12 * np.abs(row_t).max())
    for name in ("Cs", "M", "Ma"):
        red = tmap.T @ b.dense(name) @ tmap
        np.testing.assert_allclose(
            a.dense(name), red, rtol=0, atol=1e-10 * max(np.abs(red).max(), 1.0)
        )


def _end_stiffness(model, omega: float) -> np.ndarray:
    """The line's dynamic stiffness at its prescribed ends at ω (no damping),
    Z_ee − Z_ef Z_ff⁻¹ Z_fe with Z = K − ω² M_T."""
    z, f, e = model.dense("K") - omega**2 * model.dense("MT"), model.free, model.fixed
    return z[np.ix_(e, e)] - z[np.ix_(e, f)] @ np.linalg.solve(z[np.ix_(f, f)], z[np.ix_(f, e)])


@pytest.mark.parametrize("omega", [0.0, 0.5, 2.0])
def test_split_model_is_continuous_in_the_touchdown_position(omega):
    """As the touchdown approaches a node the split model tends to the nodal contact
    with the touchdown at that node: the line's dynamic stiffness at its ends (what
    the end tensions feel) changes by about the fraction moved times the span ratio
    (measured 6e-5 to 7e-5 for 2e-3 of an element, both sides).  The matrices
    themselves differ more at the touchdown node's vertical DOF (as ξ → 1 the bed
    spring k_t of the split node acts through the short suspended part, T/l_s in
    series, and the grounded part's mass hardly moves vertically), which the string
    does not feel: that node is pinned either way (k_t ≫ T/l0)."""
    for xi, node_xi in ((2.0 * TOUCHDOWN_SNAP, 0.0), (1.0 - 2.0 * TOUCHDOWN_SNAP, 1.0)):
        near, _ = _bed_line(xi, with_node=False)
        at, _ = _bed_line(node_xi if node_xi < 1.0 else 1.0 - 0.5 * TOUCHDOWN_SNAP, with_node=False)
        x, y = _end_stiffness(near, omega), _end_stiffness(at, omega)
        assert np.abs(x - y).max() <= 0.2 * TOUCHDOWN_SNAP * np.abs(y).max()


# ------------------------------------------------------- the bundled chain: convergence


def _chain(elements: int, **analysis) -> dict:
    """The bundled chain's line alone: fairlead surge only (sea and current off)."""
    doc = load_example("chain_catenary").model_dump(mode="json")
    doc["sea"] = None
    doc["environment"]["current"] = []
    doc["analysis"].pop("timeseries", None)
    doc["analysis"].update(analysis)
    doc["lines"][0]["segments"][0]["elements"] = elements
    return doc


def _end_stds(doc: dict) -> tuple[float, float]:
    line = analyze(doc).lines["leg1"]
    return line.end_b.std, line.end_a.std


def test_chain_end_tension_converges_with_the_elements():
    """Fairlead and anchor tension σ of the grounded chain, 20 → 320 elements: with the
    touchdown element split at the static touchdown the ladder is monotone and moves by
    less than 0.5 % from 40 elements on (the nodal contact gave 76.4 / 70.9 / 73.0 /
    71.8 / 72.3 kN at the fairlead); and it converges to the answer of the other
    discretization, a mesh with a node at the touchdown."""
    ns = (20, 40, 80, 160, 320)
    # the linear model's touchdown mesh (the residuals' own convergence: theirs)
    lin = {"linearization": LINEAR_ONLY}
    sig = np.array([_end_stds(_chain(n, **lin)) for n in ns])  # (n, [fairlead, anchor])
    for j, end in enumerate(("fairlead", "anchor")):
        steps = np.diff(sig[:, j])
        assert (np.sign(steps) == np.sign(steps[0])).all(), (end, sig[:, j])
        from40 = sig[1:, j]
        assert from40.max() / from40.min() - 1.0 <= 0.005, (end, sig[:, j])
    # the same line meshed with a node at the static touchdown (two segments): its own
    # ladder moves by 0.1 % between 160 and 320 elements, so 0.3 % bounds the two
    # discretizations' difference at 320
    doc = _chain(320, **lin)
    st = analyze(_chain(320, **lin)).statics.lines["leg1"]
    seg = doc["lines"][0]["segments"][0]
    n1 = round(320 * st.touchdown / seg["length"])
    doc["lines"][0]["segments"] = [
        dict(seg, length=st.touchdown, elements=n1),
        dict(seg, length=seg["length"] - st.touchdown, elements=320 - n1),
    ]
    split = _end_stds(doc)
    np.testing.assert_allclose(sig[-1], split, rtol=3e-3)


# ------------------------------------------- the bundled chain: nonlinear time domain

#: Period of the periodic DSA fairlead motion [s]: the TD statistics are taken over the
#: second period, so the input variance over the window is the DSA sum exactly; the
#: first period (ramp and transient) is discarded.
TD_PERIOD = 300.0
TD_SEEDS = (1, 2, 3)
TD_ELEMENTS = 80


def _periodic_surge(scene, omega_lines: np.ndarray, seed: int, n_t: int) -> np.ndarray:
    """End-motion coefficients (3, n_t/2 + 1) on the 2-period grid of the TD: DSA
    amplitudes √(2SΔω) of the surge spectrum on the lines 2π j/P, uniform phases."""
    spec = scene.lines[0].end_b.motion.surge
    dw = 2.0 * math.pi / TD_PERIOD
    s = spec.spectral_density(omega_lines, scene.environment.g)
    amp = np.sqrt(2.0 * s * dw)
    phase = np.random.default_rng(seed).uniform(-np.pi, np.pi, omega_lines.size)
    c = np.zeros((3, n_t // 2 + 1), dtype=complex)
    j = np.rint(omega_lines / dw).astype(int)
    c[0, 2 * j] = 0.5 * n_t * amp * np.exp(-1j * phase)
    return c


@pytest.fixture(scope="module")
def chain_td():
    """The chain's FD answer on the TD's frequency lines (converged mesh, direct) and
    the nonlinear TD end tensions over one whole period of a periodic DSA motion."""
    from stochcable.reference.cable import simulate_line_timedomain

    dw = 2.0 * math.pi / TD_PERIOD
    k0, k1 = math.ceil(0.05 / dw), math.floor(2.0 / dw)
    omega = {"min": k0 * dw, "max": k1 * dw, "count": k1 - k0 + 1}
    lin = {"tolerance": 1e-8, "max_iterations": 200}
    # the FD grid is the TD's lines (S = 0 at both ends: trapezoid = the DSA sum)
    residuals = {"drag_residual": True, "geometric_residual": True}
    line = analyze(
        _chain(320, solver="direct", omega=omega, linearization={**lin, **residuals})
    ).lines["leg1"]
    fd = (line.linear_end("end_b").std, line.linear_end("end_a").std)
    # with the residuals of the linear model (uncorrelated: their variances add)
    corrected = (line.end_b.std, line.end_a.std)
    scene = load_scene(_chain(TD_ELEMENTS))
    lines = dw * np.arange(k0, k1 + 1)
    n_t = int(round(2 * TD_PERIOD / 0.25))
    out = {"fd": fd, "fd_corrected": corrected, "td": [], "input": []}
    for seed in TD_SEEDS:
        c = _periodic_surge(scene, lines, seed, n_t)
        h = simulate_line_timedomain(
            scene, duration=2 * TD_PERIOD, end_realizations={"b": c}, band=(0.05, 2.0)
        )
        keep = (h.t >= TD_PERIOD - 1e-9) & (h.t < 2 * TD_PERIOD - 1e-9)
        x = h.positions[keep, -1, 0] - h.static_positions[-1, 0]
        dsa = float(np.sum(np.abs(c[0]) ** 2) * 2.0 / n_t**2)
        out["input"].append((float(x.var()), dsa))
        out["td"].append((float(h.tension_b[keep].std()), float(h.tension_a[keep].std())))
    out["td"] = np.array(out["td"])
    return out


@pytest.mark.slow
def test_td_window_has_the_exact_input_variance(chain_td):
    """Over one whole period of the periodic DSA motion the fairlead surge variance is
    the DSA sum Σa²/2 (to rounding): the TD σ scatter between seeds is the response's
    nonlinearity, not the input's sampling."""
    for var, dsa in chain_td["input"]:
        assert var == pytest.approx(dsa, rel=1e-9)


@pytest.mark.slow
@pytest.mark.xfail(
    strict=True,
    reason="the linear FD tension σ of this chain is below the nonlinear TD's by 5.2 % "
    "(fairlead) and 8.0 % (anchor) (TD 160 elements, 8 seeds, 95 % CI ±1.0 % / ±1.2 %). "
    "Budget, one term at a time (docs/benchmarks/fd_budget.md, benchmarks/fd_budget.py): "
    "the TD made linear reproduces the FD to 0.1 % (no linear model mismatch); quadratic "
    "drag against the Borgman linearization +4.0 / +6.4 % (about 2.5 / 3.2 % in band, "
    "still 1.8 / 2.5 % at a tenth of the motion: the drag is the only damping, so the "
    "linearization's relative error does not shrink with it), geometric nonlinearity "
    "+0.9 / +1.5 % (off band), the one-sided bed +0.3 / +0.45 %, the instantaneous "
    "tangent 0.  The closed-form residuals of the linear model (drag and geometric, "
    "docs/benchmarks/drag_residual.md) predict those terms and the default σ carries them "
    "(this test reads the `linear` block): "
    "test_chain_fd_with_residuals_within_target_of_nonlinear_td",
)
def test_chain_fd_within_target_of_nonlinear_td(chain_td):
    """The converged linear FD tension σ (the ``linear`` block) within 1 % (fairlead)
    and 2 % (anchor) of the nonlinear TD's mean over seeds, beyond its 95 % confidence
    interval."""
    _assert_within_target(chain_td["fd"], chain_td["td"])


def _assert_within_target(fd, td: np.ndarray) -> None:
    """FD σ (fairlead, anchor) within 1 % / 2 % of the TD's mean over seeds (rows of
    ``td``), beyond its 95 % Student-t half-width."""
    from scipy import stats

    n = td.shape[0]
    mean = td.mean(axis=0)
    half = stats.t.ppf(0.975, n - 1) * td.std(axis=0, ddof=1) / math.sqrt(n)
    for j, tol in ((0, 0.01), (1, 0.02)):
        ratio = fd[j] / mean[j]
        assert abs(ratio - 1.0) <= tol + half[j] / mean[j], (j, ratio, half[j] / mean[j])


@pytest.mark.slow
def test_chain_fd_with_residuals_within_target_of_nonlinear_td(chain_td):
    """The converged FD tension σ with the closed-form residuals of the linear model (the
    drag the linearization drops and the second-order geometric forces,
    docs/benchmarks/drag_residual.md) within 1 % (fairlead) and 2 % (anchor) of the
    nonlinear TD's mean over seeds, beyond its 95 % confidence interval (measured on
    160-element TDs and 5 seeds: +0.40 ± 1.92 % / +0.17 ± 2.62 %)."""
    assert all(c > f for c, f in zip(chain_td["fd_corrected"], chain_td["fd"]))
    _assert_within_target(chain_td["fd_corrected"], chain_td["td"])


def test_periodic_surge_coefficients_are_the_dsa_amplitudes():
    """The TD's input: on the 2-period grid only the even lines carry energy, their
    variance is Σ S Δω (DSA), and the record repeats after one period."""
    scene = load_scene(_chain(TD_ELEMENTS))
    dw = 2.0 * math.pi / TD_PERIOD
    lines = dw * np.arange(2, 96)
    n_t = int(round(2 * TD_PERIOD / 0.25))
    c = _periodic_surge(scene, lines, 7, n_t)
    x = np.fft.irfft(c[0], n_t)
    half = n_t // 2
    np.testing.assert_allclose(x[:half], x[half:], atol=1e-12 * np.abs(x).max())
    s = scene.lines[0].end_b.motion.surge.spectral_density(lines, scene.environment.g)
    assert x.var() == pytest.approx(float(np.sum(s) * dw), rel=1e-10)
    assert not np.any(c[0, 1::2])
