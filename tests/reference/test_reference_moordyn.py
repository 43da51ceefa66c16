"""The MoorDyn harness (stochcable.reference.moordyn, moordyn_compare): the periodic DSA
motion, the input-file conventions, MoorDyn's static tensions against the closed-form
catenary, and one short dynamic comparison of the time-domain reference with MoorDyn."""

from __future__ import annotations

import copy
import math

import numpy as np
import pytest
from _paths import ROOT

from stochcable.errors import InputError
from stochcable.examples import load_example
from stochcable.reference.moordyn import (
    comparison_scene,
    internal_damping_coefficient,
    moordyn_input_file,
    periodic_dsa_surge,
    sample_stride,
    simulate_line_moordyn,
)
from stochcable.reference.moordyn_compare import compare_line, student_interval
from stochcable.sea.spectra import spectrum_pierson_moskowitz
from stochcable.statics import solve_statics

# one worker runs the module: its module fixtures run once (--dist loadgroup)
pytestmark = pytest.mark.xdist_group("test_reference_moordyn")


def _pm(w: np.ndarray) -> np.ndarray:
    return spectrum_pierson_moskowitz(w, 2.0, 10.0)


@pytest.fixture(scope="module")
def chain():
    return load_example("chain_catenary")


# ------------------------------------------------------------------ motion


@pytest.mark.parametrize("seed", [1, 7])
def test_periodic_dsa_variance_is_exact_over_a_period(seed):
    motion = periodic_dsa_surge(_pm, 100.0, (0.05, 2.0), seed)
    dw = 2.0 * math.pi / 100.0
    w = dw * np.arange(1, int(2.0 / dw) + 1)
    w = w[w >= 0.05]
    riemann = float(np.sum(_pm(w)) * dw)  # Σ S(ω_j)Δω, the DSA variance (DESIGN.md)
    assert motion.std**2 == pytest.approx(riemann, rel=1e-12)
    # sampled over one whole period (any start, 2000 samples > 2·top harmonic):
    # the sample variance is Σ a²/2 to rounding
    t = 37.0 + 0.05 * np.arange(2000)
    x = motion.displacement(t)
    assert x.var() == pytest.approx(riemann, rel=1e-10)
    # the band-limited PM (0.05–2 rad/s) keeps all but the tail: Hs²/16 = 0.25 m²
    assert 0.24 < riemann < 0.25


def test_motion_coefficients_reproduce_the_cosine_sum():
    motion = periodic_dsa_surge(_pm, 50.0, (0.1, 2.0), np.random.default_rng(3))
    n_t = 4000  # two periods at 0.025 s
    x_fft = np.fft.irfft(motion.coefficients(2, n_t), n_t)
    t = 100.0 / n_t * np.arange(n_t)
    np.testing.assert_allclose(x_fft, motion.displacement(t), atol=1e-12)
    # derivatives: central differences of the closed form
    h = 1e-4
    v_fd = (motion.displacement(t[:50] + h) - motion.displacement(t[:50] - h)) / (2 * h)
    np.testing.assert_allclose(motion.velocity(t[:50]), v_fd, atol=1e-6)
    with pytest.raises(InputError, match="n_samples"):
        motion.coefficients(2, 40)  # top harmonic 2·15 = 30 > 40/2


def test_student_interval_matches_the_t_table():
    m, h = student_interval(np.array([1.0, 2.0, 3.0]))
    # t_{0.975, 2} = 4.302653 (tables), s = 1
    assert m == 2.0
    assert h == pytest.approx(4.302653 / math.sqrt(3.0), rel=1e-6)
    assert student_interval(np.array([5.0]))[1] == math.inf


# ------------------------------------------------------------------ conventions


def test_input_file_maps_the_conventions(chain):
    sc = comparison_scene(chain, elements=12)
    text = moordyn_input_file(sc, internal_damping=-0.5)
    seg = sc.lines[0].segments[0]
    row = next(r for r in text.splitlines() if r.startswith("type1 "))
    vals = [float(v) for v in row.split()[1:]]
    # Diam Mass/m EA BA EI Cd Ca CdAx CaAx: CdAx on π·d as ours -> unchanged
    assert vals == [seg.diameter, seg.mass, seg.ea, -0.5, 0.0, 1.333, 1.0, 0.2034, 0.0]
    opts = {r.split()[1]: float(r.split()[0]) for r in text.splitlines() if r[:1].isdigit()}
    assert opts["kBot"] == 3.0e6 and opts["cBot"] == 3.0e5  # per contact area in both
    assert opts["WtrDpth"] == 200.0 and opts["rho"] == 1025.0 and opts["g"] == 9.80665
    assert "1 type1 1 2 850 12 -" in text  # point 1 = end_a (Fixed), 2 = end_b (Coupled)
    assert "2 Coupled " in text and "1 Fixed " in text
    # no sea, no current, no motions left in the comparison scene
    assert sc.sea is None and not sc.environment.current
    assert sc.lines[0].end_b.motion is None


def test_internal_damping_ratio_is_per_segment(chain):
    sc = comparison_scene(chain, elements=80)
    # MoorDyn-C Line::initialize: BA = ζ·(L/N)·√(EA·m) for BA = −ζ
    expected = 0.7 * 850.0 / 80 * math.sqrt(1.2326e9 * 288.0)
    assert internal_damping_coefficient(sc, -0.7) == pytest.approx(expected, rel=1e-14)
    assert internal_damping_coefficient(sc, 1234.0) == 1234.0


def test_comparison_scene_refuses_what_moordyn_line_types_cannot_hold(chain):
    doc = copy.deepcopy(chain.model_dump(mode="json", exclude_none=True))
    doc["lines"][0]["segments"].append(dict(doc["lines"][0]["segments"][0], length=10.0))
    doc["lines"][0]["end_a"]["position"] = [-805.0, 0.0, -200.0]
    with pytest.raises(InputError, match="segments"):
        comparison_scene(doc)
    with pytest.raises(InputError, match="line_name"):
        comparison_scene(chain, "nope")
    doc = copy.deepcopy(chain.model_dump(mode="json", exclude_none=True))
    doc["lines"][0]["drag_form"] = "hu_jin"  # MoorDyn has only the cross-flow drag
    with pytest.raises(InputError, match=r"drag_form.*cross_flow"):
        comparison_scene(doc)


# ------------------------------------------------------------------ reference options


def _model(chain, **kw):
    from stochcable.line.mesh import mesh_line
    from stochcable.reference.cable_model import LineModel

    sc = comparison_scene(chain, elements=6)
    env = sc.environment
    mesh = mesh_line(sc.lines[0], env.rho, env.g)
    ls = solve_statics(sc).lines[sc.lines[0].name]
    X = np.asarray(ls.positions)[:, [0, 2]]
    return LineModel(mesh, env, X, 2, **kw), X


def test_internal_damping_is_ba_times_the_strain_rate(chain):
    ba = 2.5e6  # [N·s]
    model, X = _model(chain, internal_damping=ba)
    rng = np.random.default_rng(11)
    V = rng.normal(size=X.shape)
    e, l, _, _ = model.elements(X)
    # strain rate by central differences of the element lengths along X + V·τ
    h = 1e-6
    lp = model.elements(X + h * V)[1]
    lm = model.elements(X - h * V)[1]
    rate = (lp - lm) / (2 * h) / model.l0
    np.testing.assert_allclose(model.damping_tension(V, e), ba * rate, rtol=1e-6)
    # its velocity Jacobian (fixed tangents): linear in V, so central differences are
    # exact to rounding
    blocks = model.damping_blocks(e)
    j = 2
    Vj = V.copy()
    dv = np.zeros_like(V)
    dv[j + 1, 0] = 1.0  # node b of element j, x
    td1 = model.damping_tension(Vj + dv, e)[j]
    td0 = model.damping_tension(Vj, e)[j]
    force_b = (td1 - td0) * e[j]  # change of T_d·e on node b (sign of the residual)
    np.testing.assert_allclose(blocks[j][2:, 2], force_b, rtol=1e-9)
    # none by default (the reference's results unchanged)
    plain, _ = _model(chain)
    assert plain.damping_tension(V, e) is None and plain.damping_blocks(e) is None


def test_lumped_mass_keeps_the_total_and_is_diagonal(chain):
    lumped, _ = _model(chain, lumped_mass=True)
    consistent, _ = _model(chain)
    Ml = lumped.M_sparse.toarray()
    Mc = consistent.M_sparse.toarray()
    # every element's mass split half-half: the row sums of the two matrices agree
    # (a rigid translation has the same inertia)
    np.testing.assert_allclose(Ml.sum(axis=1), Mc.sum(axis=1), rtol=1e-12)
    # the structural mass is diagonal (added mass couples x, z of a node only)
    off_node = Ml.copy()
    for i in range(lumped.n):
        off_node[2 * i : 2 * i + 2, 2 * i : 2 * i + 2] = 0.0
    assert np.abs(off_node).max() == 0.0


# ------------------------------------------------------------------ MoorDyn


@pytest.fixture(scope="module")
def moordyn():
    return pytest.importorskip("moordyn")


def test_moordyn_statics_match_the_closed_form_catenary(moordyn, chain):
    n = 40
    sc = comparison_scene(chain, elements=n)
    motion = periodic_dsa_surge(_pm, 60.0, (0.05, 2.0), 1)
    md = simulate_line_moordyn(sc, motion, duration=0.01, ramp=1.0, sample_dt=0.005)
    ls = solve_statics(sc).lines[sc.lines[0].name]
    assert ls.method == "catenary"
    seg = sc.lines[0].segments[0]
    w = seg.submerged_weight(1025.0, 9.80665)
    # MoorDyn lumps the weight on the nodes: its end-segment (chord) tension differs
    # from the continuous catenary's by the order of (w·l/T)² (a chord of l = L/N
    # under a distributed vs a lumped load); half of it bounds the measured 2.8e-4
    # (40 segments) and 1.4e-2 (10 segments) at the anchor, where T is least.
    tol = 0.5 * (w * seg.length / n / ls.tension_a) ** 2
    assert md.static_a == pytest.approx(ls.tension[0], rel=tol)
    assert md.static_b == pytest.approx(ls.tension[-1], rel=tol)
    # and the horizontal component at the grounded anchor is the catenary's H
    assert md.static_a > 0.99 * ls.tension_a
    # the anchor's support reaction (the fixed end node's net force) is the end
    # segment's tension plus the node's own loads, which the seabed carries on the
    # grounded chain: the same to 0.1 % at rest
    assert md.reaction_a[0] == pytest.approx(md.static_a, rel=1e-3)


@pytest.mark.slow
def test_moordyn_reads_both_ends_of_a_two_segment_line(moordyn):
    """Chain on the bed, rope to the fairlead (two MoorDyn lines joined at a free
    point; the accuracy page's ``twoseg``): the anchor tension is read on the first
    line, the fairlead's on the last, and both agree with stochcable's statics (0.01 %
    measured with 46 + 34 segments, 0.5 % with 23 + 17; the joint starts at that static
    solution: from the straight line MoorDyn's initial-condition solve stops with the
    anchor slack).  About 30 s on the loaded 2-core VM (MoorDyn's 300 s
    initial-condition relaxation)."""
    chain_sg = {"ea": 1.2326e9, "mass": 288.0, "diameter": 0.216, "cd_normal": 1.333,
                "cd_axial": 0.2034, "ca_normal": 1.0}  # fmt: skip
    rope_sg = {"ea": 1.5e8, "mass": 25.0, "diameter": 0.16, "cd_normal": 1.2,
               "cd_axial": 0.008, "ca_normal": 1.0}  # fmt: skip
    doc = {
        "environment": {"depth": 200.0, "seabed": {"stiffness": 3e6, "damping": 3e5}},
        "lines": [
            {
                "name": "chain_rope",
                "end_a": {"position": [-700.0, 0.0, -200.0]},
                "end_b": {"position": [0.0, 0.0, -20.0]},
                "segments": [
                    {"length": 420.0, "elements": 46, **chain_sg},
                    {"length": 315.0, "elements": 34, **rope_sg},
                ],
            }
        ],
    }
    motion = periodic_dsa_surge(_pm, 60.0, (0.05, 2.0), 1)
    md = simulate_line_moordyn(doc, motion, duration=0.01, ramp=1.0, sample_dt=0.005)
    ls = solve_statics(doc).lines["chain_rope"]
    # 10× the measured 1e-4 (MoorDyn's lumped weight on 9 m chain segments, its
    # initial-condition residual 1.7e-4 m/s² after TmaxIC = 300 s)
    assert md.static_a == pytest.approx(ls.tension[0], rel=1e-3)
    assert md.static_b == pytest.approx(ls.tension[-1], rel=1e-3)
    assert md.static_b > 1.05 * md.static_a  # the fairlead's: the suspended weight


@pytest.mark.slow
def test_reference_agrees_with_moordyn_on_a_short_chain_record(moordyn, chain):
    """40 elements, a 60 s period (one warm-up, one measured), three seeds (two give a
    Student-t factor of 12.7 and a useless interval)."""
    c = compare_line(chain, elements=40, seeds=(1, 2, 3), period=60.0, ramp=20.0)
    assert c.motion_std == pytest.approx(c.seeds[0].motion_std, rel=1e-9)
    for q in ("a", "b", "reaction_a", "reaction_b"):
        mean, half = c.ratio(q)
        # 0.5 %: the agreement target, which at 40 elements also covers the
        # lumped (MoorDyn) vs consistent (reference) discretization, measured
        # −0.34…+0.31 % over seeds and periods (< 0.1 % at 80 elements,
        # docs/benchmarks/moordyn.md); plus the 95 % Student-t half-width of the paired
        # ratio over the seeds.  Detects e.g. MoorDyn's CdAx taken on d instead of
        # π·d (fairlead +1.7 %) or a 20 % added-mass error (+3 %).
        assert abs(mean) < 5e-3 + half, (q, mean, half)
    # the same phases in both: the σ themselves are of the chain's size (DESIGN.md
    # chain, FD fairlead σ ≈ 120 kN for this motion)
    assert 1.0e5 < c.sigma("moordyn", "b")[0] < 1.4e5


# ------------------------------------------------------------------ the benchmark page


def _load_benchmark():
    import importlib.util
    import sys

    path = ROOT / "benchmarks" / "moordyn_check.py"
    spec = importlib.util.spec_from_file_location("moordyn_check", path)
    mod = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = mod
    spec.loader.exec_module(mod)
    return mod


def test_benchmark_page_reports_the_paired_ratio(moordyn):
    """The page of benchmarks/moordyn_check.py from a synthetic cache in which every
    reference σ is 1 % above MoorDyn's: every paired ratio reads +1.000 ± 0.000 %."""
    bench = _load_benchmark()
    cache = {}
    for run in bench._runs():
        sig = {q: 1e5 * (1.0 + 0.1 * i) for i, q in enumerate(("a", "b", "reaction_b"))}
        # seed-to-seed scatter, the same for both simulators of a pair
        k_md = 1.0 + 0.01 * run["seed"]
        fac = 1.01 if run["sim"] == "reference" else 1.0
        cache[bench.run_key(run)] = {
            **{q: v * k_md * fac for q, v in sig.items()},
            "motion_std": 0.5,
            "motion_exact": 0.5,
            "static_a": 1e6,
            "static_b": 1.5e6,
            "ba_ns": 0.0,
            "wall": 1.0,
        }
    page = bench.write_page(cache)
    table = [r for r in page.splitlines() if r.startswith("| chain |")][0]
    assert table.count("+1.000 ± 0.000 %") == 3  # ratio a, ratio b, ratio reaction b
    assert "| 20 elements" in page and "| deep |" in page


@pytest.mark.slow
def test_lumped_mass_explains_most_of_the_coarse_mesh_difference(moordyn, chain):
    """20 elements: the consistent-mass reference reads 2–4 % below MoorDyn (−3.2 % at
    the fairlead over two 200 s seeds, docs/benchmarks/moordyn.md); MoorDyn's lumped
    mass (``mass_matrix='lumped'``) removes most of it (+1.0 %, the rest being MoorDyn's
    nodal drag and node-tangent added mass)."""
    from stochcable.reference.moordyn_compare import simulate_line_reference, window_std

    sc = comparison_scene(chain, elements=20)
    motion = periodic_dsa_surge(_pm, 60.0, (0.05, 2.0), 1)
    kw = {"duration": 120.0, "ramp": 20.0}
    md, _ = window_std(simulate_line_moordyn(sc, motion, **kw), 60.0, 120.0)
    cons, _ = window_std(simulate_line_reference(sc, motion, **kw), 60.0, 120.0)
    lump, _ = window_std(
        simulate_line_reference(sc, motion, mass_matrix="lumped", **kw), 60.0, 120.0
    )
    for q in ("a", "b"):
        r_cons = cons[q] / md[q] - 1.0
        r_lump = lump[q] / md[q] - 1.0
        # a discretization difference well beyond the 80-element agreement (< 0.3 %)
        assert r_cons < -0.015, (q, r_cons)
        # the mass matrix is most of it
        assert abs(r_lump) < 0.5 * abs(r_cons), (q, r_cons, r_lump)


@pytest.mark.parametrize(
    ("sample_dt", "coupling_dt"), [(0.05, 0.02), (0.01, 0.05), (0.1, 0.0), (-0.1, 0.01)]
)
def test_sample_stride_refuses_a_sampling_that_is_not_a_multiple(sample_dt, coupling_dt):
    # every MoorDyn run of the package (line, vessel, body) samples its record through
    # this check: a record must be sampled at whole coupling steps
    with pytest.raises(InputError, match=r"(sample_dt|coupling_dt) = .* \[s\]"):
        sample_stride(sample_dt, coupling_dt)


def test_sample_stride_counts_coupling_steps_despite_decimal_round_off():
    # 0.1 / 0.01 is 9.999999999999998 in binary floating point: rounded, not truncated
    assert sample_stride(0.1, 0.01) == 10
    assert sample_stride(0.05, 0.025) == 2
    assert sample_stride(0.025, 0.025) == 1
