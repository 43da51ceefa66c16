"""Fast paths of the coupled dynamics (stochcable.dynamics.groups, issue 6 speed).

Each fast path is the same linear system as a reference kept reachable:
- Foss lines in modal coordinates (``FossLine``, ``lineparts._MODAL_FOSS``) against the node-level
  path (:func:`stochcable.dynamics.groups.lineparts.foss_unit_split` + reactions), at a given
  drag and through the whole drag fixed point;
- coupled modes by Craig–Bampton reduction (``coupled_modes(method="reduced")``)
  against the assembled system (``method="full"``): a Rayleigh–Ritz projection, exact
  when every line mode is kept, otherwise upper bounds within a stated tolerance.
"""

from __future__ import annotations

import dataclasses
import math
import sys
from pathlib import Path

import numpy as np
import pytest

import stochcable.dynamics.groups.coarse as cc
import stochcable.dynamics.groups.group as cg
import stochcable.dynamics.groups.lineparts as cp
import stochcable.dynamics.groups.modes as cm
from stochcable.bodies.rigid import RigidBody
from stochcable.dynamics.groups import (
    CoupledLine,
    body_loads,
    coupled_modes,
    linearize_coupled,
)
from stochcable.dynamics.groups.fixed_point_state import EvaluationCount
from stochcable.dynamics.groups.group import GroupSystem, solve_group
from stochcable.dynamics.linearization.variance import (
    drag_coefficients,
    quasi_static_motion,
    sigmas_from_nodes,
)
from stochcable.dynamics.loads.channels import line_channels
from stochcable.dynamics.model.system import build_line_system, noop_progress
from stochcable.scene.model import load_scene
from stochcable.statics import solve_statics

# one worker runs the module: its module fixtures run once (--dist loadgroup)
pytestmark = pytest.mark.xdist_group("test_coupled_reduction")

sys.path.insert(0, str(Path(__file__).parent))
from test_coupled_analysis import RHO, _buoy, _group, _mooring_doc  # noqa: E402


@pytest.fixture
def node_level(monkeypatch):
    """Switch the Foss lines to the node-level reference path."""

    def use(flag: bool) -> None:
        monkeypatch.setattr(cp, "_MODAL_FOSS", flag)

    return use


def _solve_both(g, node_level, sigma=0.3, body_b=(2e3, 2e3, 4e3)):
    damp = {
        cl.name: drag_coefficients(
            cl.system, np.full(2 * cl.system.model.n_elements, sigma), "seed"
        )
        for cl in g.lines
    }
    bb = {b.name: np.asarray(body_b, float) for b in g.drag}
    bc = np.zeros((g.nb, g.nb))
    for cl in g.lines:  # the modal path runs (no silent fallback to the reference)
        cp.FossLine(
            cl.system, g.inp_phys[cl.name], damp[cl.name], tuple(k for k, _ in cl.attached())
        )
    out = []
    for flag in (False, True):
        node_level(flag)
        out.append(solve_group(g, damp, bc, bb, None))
    return out


def _assert_same(ref, got):
    (sol_r, xi_r), (sol_g, xi_g) = ref, got
    # the same linear system, products reassociated: round-off (1e-10 of the largest)
    np.testing.assert_allclose(xi_g, xi_r, rtol=0, atol=1e-10 * np.abs(xi_r).max())
    for name, (u, s) in sol_r.items():
        ug, sg = sol_g[name]
        assert ug.shape == u.shape and sg.shape == s.shape
        np.testing.assert_allclose(ug, u, rtol=0, atol=1e-10 * np.abs(u).max())
        np.testing.assert_allclose(sg, s, rtol=0, atol=1e-10 * np.abs(s).max())


@pytest.mark.parametrize("modes", [8, "auto", 27])
def test_modal_foss_lines_equal_node_level_path(node_level, modes):
    """Three legs on a 6-DOF buoy, truncated (8 of 27 modes: static correction on) or
    all modes: the modal-coordinate line solve gives the node-level one's
    displacements, support forces and body motion."""
    body = _buoy()
    scene, cls, loads = _group(_mooring_doc(solver="foss", modes=modes), body)
    assert cls[0].system.solver == "foss"
    g = GroupSystem(cls, [body], loads, RHO, cls[0].channels)
    ref, got = _solve_both(g, node_level)
    _assert_same(ref, got)


def _planar_two_body_group():
    """A planar leg between two planar bodies (both ends attached) and a tether from
    body A whose other end moves with its own heave spectrum: exercises the
    attached-end pair (0, 1), truncated modes (6), two channels and a moving
    unattached end."""
    doc = {
        "environment": {"depth": 50.0},
        "sea": {"spectrum": {"type": "jonswap", "hs": 2.0, "tp": 7.0}},
        "lines": [
            {
                "name": "link",
                "end_a": {"position": [-60.0, 0.0, -20.0]},
                "end_b": {"position": [0.0, 0.0, -5.0]},
                "segments": [
                    {"length": 66.0, "ea": 1e9, "mass": 80.0, "diameter": 0.09, "elements": 12}
                ],
            },
            {
                "name": "tether",
                "end_a": {"position": [20.0, 0.0, -45.0]},
                "end_b": {
                    "position": [0.0, 0.0, -5.0],
                    "motion": {"heave": {"type": "jonswap", "hs": 0.5, "tp": 8.0}},
                },
                "segments": [
                    {"length": 45.0, "ea": 1e9, "mass": 50.0, "diameter": 0.05, "elements": 8}
                ],
            },
        ],
        "analysis": {"omega": {"min": 0.2, "max": 2.5, "count": 30}, "solver": "foss", "modes": 6},
    }
    scene = load_scene(doc)
    st = solve_statics(scene, method="fe")
    w = scene.analysis.omega.values()
    a = RigidBody(
        "A",
        [-60.0, 0.0, -19.0],
        3e3,
        inertia=np.diag([0.0, 2e3, 0.0]),
        extra_stiffness=np.diag([1e4, 2e4, 3e4]),
        planar=True,
        radiation_damping=np.diag([50.0, 50.0, 50.0]),
        drag_area=[1.0, 0.0, 2.0],
    )
    b = RigidBody(
        "B",
        [1.0, 0.0, -4.0],
        2e3,
        inertia=np.diag([0.0, 1e3, 0.0]),
        extra_stiffness=np.diag([2e4, 2e4, 1e4]),
        planar=True,
        radiation_damping=np.diag([40.0, 40.0, 40.0]),
    )
    link = scene.lines[0]
    s = build_line_system(scene, link, st.lines["link"])
    tether = scene.lines[1]
    s2 = build_line_system(scene, tether, st.lines["tether"])
    ch2 = line_channels(scene, tether, s2.positions, w)
    ch1 = line_channels(scene, link, s.positions, w)
    # the group's channels: the sea and the tether's end motion (silent for the link)
    from stochcable.dynamics.loads.channels import Channel

    names = [c.name for c in ch2]
    ch1 = tuple(
        list(ch1)
        + [
            Channel(
                name=c.name,
                kind="end_motion",
                omega=c.omega,
                spectrum=c.spectrum,
                density=c.density,
            )
            for c in ch2
            if c.kind != "sea"
        ]
    )
    assert [c.name for c in ch1] == names
    cls = [CoupledLine(s, ch1, end_a="A", end_b="B"), CoupledLine(s2, ch2, end_a="A")]
    loads = {x.name: body_loads(x, ch1, w, scene.sea, scene.environment) for x in (a, b)}
    return cls, [a, b], loads


def test_modal_foss_equal_node_level_planar_two_bodies(node_level):
    cls, bodies, loads = _planar_two_body_group()
    assert all(cl.system.solver == "foss" and cl.system.model.dim == 2 for cl in cls)
    assert cls[1].system.n_modes < cls[1].system.model.free.size
    g = GroupSystem(cls, bodies, loads, RHO, cls[0].channels)
    # the sea and the tether's independent end motion: two channels, U_p of the
    # second not zero
    assert g.n_ch == 2 and cls[1].channels[1].motion_b is not None
    ref, got = _solve_both(g, node_level)
    _assert_same(ref, got)


def test_modal_foss_fixed_point_equals_node_level(node_level):
    """Through the whole drag fixed point (tolerance 1e-4): the same iterates up to
    round-off, so the same iteration count and σ, body motion to ~1e-10."""
    body = _buoy()
    scene, cls, loads = _group(_mooring_doc(solver="foss", tol=1e-4), body)
    out = []
    for flag in (False, True):
        node_level(flag)
        out.append(linearize_coupled(cls, [body], scene.analysis, rho=RHO, loads=loads))
    ref, got = out
    assert got.iterations == ref.iterations
    # round-off carried through ~5 iterations of a contraction
    np.testing.assert_allclose(
        got.body_motion["buoy"],
        ref.body_motion["buoy"],
        rtol=0,
        atol=1e-9 * np.abs(ref.body_motion["buoy"]).max(),
    )
    # σ of near-still elements (≈ 1e-8 m/s against ≈ 0.3 m/s on the line) carry the
    # round-off of the whole line's sums: compared to 1e-9 of the line's largest σ too
    # (a 1e-9 relative miss on the 1e-8 entry was seen on one CPU)
    for n, lin in ref.lines.items():
        np.testing.assert_allclose(
            got.lines[n].damping.sigma,
            lin.damping.sigma,
            rtol=1e-9,
            atol=1e-9 * lin.damping.sigma.max(),
        )


@pytest.fixture(scope="module")
def benchmark_legs():
    """The benchmark's legs (40 elements, 40 computed modes up to ~10.5 rad/s)."""
    body = _buoy()
    scene, cls, _ = _group(_mooring_doc(n_el=40, count=20, solver="foss"), body)
    return cls, body


def test_reduced_modes_within_tolerance_of_full(benchmark_legs):
    """Craig–Bampton with the 40 computed line modes (top ≈ 10.5 rad/s) against the
    assembled 363-DOF problem, listing to 2.5·2 = 5 rad/s: the same count, every
    frequency an upper bound within 1e-3 relative (measured 3.3e-4, the highest
    modes), body energy fractions within 3e-3 (measured 1e-3), same asymmetry."""
    cls, body = benchmark_legs
    assert float(cls[0].system.modes.omega.max()) < 11.0
    full = coupled_modes(cls, [body], 0.7, 2.0, method="full")
    red = coupled_modes(cls, [body], 0.7, 2.0, method="reduced")
    assert red.omega.size == full.omega.size >= 10
    np.testing.assert_allclose(red.omega, full.omega, rtol=1e-3)
    assert np.all(red.omega >= full.omega * (1 - 1e-9))  # Rayleigh–Ritz: from above
    np.testing.assert_allclose(red.body_fraction, full.body_fraction, atol=3e-3)
    assert red.asymmetry == pytest.approx(full.asymmetry, rel=1e-6, abs=1e-14)
    # the body shapes span the same motions: |⟨φ_r, φ_f⟩_body| close to the norms for
    # the lowest (well separated, body-dominated) mode
    for k in (2,):
        a, b = red.body_shapes["buoy"][:, k], full.body_shapes["buoy"][:, k]
        assert abs(a @ b) == pytest.approx(math.sqrt((a @ a) * (b @ b)), rel=1e-3)


def test_auto_uses_the_reduction_only_below_its_cutoff(benchmark_legs):
    """ "auto": reduced when every line's highest computed mode is ≥ 1.5× the listing
    top (10.5 ≥ 1.5·5), the full problem otherwise (top 2.5·6 = 15 rad/s)."""
    cls, body = benchmark_legs
    auto = coupled_modes(cls, [body], 0.7, 2.0)
    red = coupled_modes(cls, [body], 0.7, 2.0, method="reduced")
    np.testing.assert_array_equal(auto.omega, red.omega)
    auto_hi = coupled_modes(cls, [body], 0.7, 6.0)
    full_hi = coupled_modes(cls, [body], 0.7, 6.0, method="full")
    np.testing.assert_array_equal(auto_hi.omega, full_hi.omega)
    with pytest.raises(Exception, match="method"):
        coupled_modes(cls, [body], 0.7, 2.0, method="exact")


@pytest.mark.parametrize("solver", ["foss", "direct"])
def test_threaded_lines_give_the_same_bits_as_serial(monkeypatch, solver):
    """The lines' Foss decompositions on the thread pool (stochcable.runtime; Foss
    lines only, direct lines have none) against ``STOCHCABLE_THREADS=1``: the same
    computation per line, summed in line order, so the same bits (not a
    tolerance)."""
    import stochcable.runtime as par
    from stochcable.runtime import single_blas_thread

    body = _buoy()
    scene, cls, loads = _group(_mooring_doc(solver=solver, tol=1e-4), body)
    used = []
    real = par._executor

    def spy(n):
        used.append(n)
        return real(n)

    monkeypatch.setattr(par, "_executor", spy)
    out = []
    for threads in ("1", "2"):
        monkeypatch.setenv("STOCHCABLE_THREADS", threads)
        with single_blas_thread():
            out.append(linearize_coupled(cls, [body], scene.analysis, rho=RHO, loads=loads))
        # the pool ran only when allowed, and only for Foss lines
        assert bool(used) == (threads == "2" and solver == "foss")
    ref, got = out
    assert got.iterations == ref.iterations
    np.testing.assert_array_equal(got.body_motion["buoy"], ref.body_motion["buoy"])
    for n, lin in ref.lines.items():
        np.testing.assert_array_equal(got.lines[n].damping.sigma, lin.damping.sigma)
        np.testing.assert_array_equal(got.lines[n].response.displacement, lin.response.displacement)


def test_foss_decomposition_of_a_line_with_drag_solves_the_quadratic_eigenproblem():
    """``solvers._foss_decomposition`` (NumPy's geev, which releases the GIL for the
    thread pool) on a line's kept modes with drag: every pair satisfies
    (λ²M̂ + λĈ + K̂)χ = 0 to 1e-10 of the terms' size (round-off of a 78×78 geev with
    condition ≈ the printed one), and the pairs come in complex conjugates."""
    from stochcable.dynamics.model.blocks import add_blocks, block_matvec, line_prep
    from stochcable.dynamics.model.modal_solvers import foss_modes
    from stochcable.dynamics.solve.line_loads import drag_blocks

    body = _buoy()
    _, cls, _ = _group(_mooring_doc(solver="foss", tol=1e-4), body)
    system = cls[0].system
    prep = line_prep(system)
    damping = drag_coefficients(system, np.full(2 * system.model.n_elements, 0.3), "seed")
    c = add_blocks(prep.S, drag_blocks(system, damping))
    phi, mh, kh = prep.modal(system)
    ch = phi.T @ prep.free_rows(block_matvec(c, prep.nodes(phi)))
    ch = 0.5 * (ch + ch.T)
    got = foss_modes(mh, ch, kh)
    lam, chi = got.lambdas, got.chi
    res = lam**2 * (mh @ chi) + lam * (ch @ chi) + kh @ chi
    # normwise backward error of each pair (element-wise would divide round-off by
    # the ~0 entries of localized modes)
    norm = np.linalg.norm
    scale = (np.abs(lam) ** 2 * norm(mh, 2) + np.abs(lam) * norm(ch, 2) + norm(kh, 2)) * norm(
        chi, axis=0
    )
    assert np.max(norm(res, axis=0) / scale) < 1e-10
    np.testing.assert_allclose(np.sort_complex(lam), np.sort_complex(lam.conj()), rtol=1e-10)


# ------------------------------------------------------- coarse stage (pass E5)


def _solve_modal_direct(g, sigma=0.3, body_b=(2e3, 2e3, 4e3)):
    """The group solve with Foss lines by their Foss decomposition (:class:`_FossLine`)
    and by the per-frequency modal solve of the coarse stage (:class:`_ModalLine`)."""
    damp = {
        cl.name: drag_coefficients(
            cl.system, np.full(2 * cl.system.model.n_elements, sigma), "seed"
        )
        for cl in g.lines
    }
    bb = {b.name: np.asarray(body_b, float) for b in g.drag}
    bc = np.zeros((g.nb, g.nb))
    out = []
    for flag in (False, True):
        g.modal_direct = flag
        out.append(solve_group(g, damp, bc, bb, None))
    g.modal_direct = False
    return out


@pytest.mark.parametrize("modes", [8, "auto"])
def test_modal_direct_lines_equal_foss_lines(modes):
    """The coarse stage's line solve (modal equations per frequency, batched LU) is the
    same modal system as Foss's diagonalization: equal displacements, support forces
    and body motion to round-off (1e-10 of the largest), truncated (static
    correction on) and all modes."""
    body = _buoy()
    scene, cls, loads = _group(_mooring_doc(solver="foss", modes=modes), body)
    g = GroupSystem(cls, [body], loads, RHO, cls[0].channels)
    ref, got = _solve_modal_direct(g)
    _assert_same(ref, got)


def test_modal_direct_equal_foss_planar_two_bodies():
    """As above on the planar two-body group (both ends attached, a second channel
    with a moving unattached end, truncated modes)."""
    cls, bodies, loads = _planar_two_body_group()
    g = GroupSystem(cls, bodies, loads, RHO, cls[0].channels)
    ref, got = _solve_modal_direct(g)
    _assert_same(ref, got)


# ------------------------------------------------- coarse evaluation cost (pass E5c)


def _coarse_update(g, idx, x=None):
    """The coarse group of ``g`` on ``idx`` and its map evaluated at ``x`` (default
    the rest σ scaled up, so the drag is not tiny)."""
    gc = cc.coarse_group(g, idx)
    rest = [
        sigmas_from_nodes(
            cl.system,
            g.inp_phys[cl.name],
            quasi_static_motion(cl.system, g.inp_phys[cl.name]),
            "seed",
        )
        for cl in g.lines
    ]
    gc.sizes = {cl.name: p.size for cl, p in zip(g.lines, rest)}
    rest += [cg.body_sigma(g, b, None) for b in g.drag]
    x = 3.0 * np.concatenate(rest) if x is None else x
    upd = cg.SigmaMap(gc, "seed", RHO, EvaluationCount(), noop_progress, "g", None)
    return gc, upd, x


@pytest.mark.parametrize("modes", [8, "auto"])
@pytest.mark.parametrize("stage", ["coarse", "full"])
def test_line_part_cache_gives_the_same_bits(stage, modes):
    """The drag-independent arrays kept per line across the evaluations
    (``GroupSystem.modal_cache`` of the coarse stage's :class:`ModalLine`,
    ``GroupSystem.foss_cache`` of the full grid's :class:`FossLine`): a solve at a second
    drag with the cache filled by a first one is bit-identical to the same solve on a
    fresh group (the cache holds nothing that depends on the drag)."""
    body = _buoy()
    _, cls, loads = _group(_mooring_doc(solver="foss", modes=modes), body)
    damp = [
        {
            cl.name: drag_coefficients(
                cl.system, np.full(2 * cl.system.model.n_elements, s), "seed"
            )
            for cl in cls
        }
        for s in (0.05, 0.4)
    ]
    bb = {body.name: np.array([2e3, 2e3, 4e3])}
    bc = np.zeros((6, 6))
    g1 = GroupSystem(cls, [body], loads, RHO, cls[0].channels)
    g2 = GroupSystem(cls, [body], loads, RHO, cls[0].channels)
    g1.modal_direct = g2.modal_direct = stage == "coarse"
    used, other = (
        ("modal_cache", "foss_cache") if stage == "coarse" else ("foss_cache", "modal_cache")
    )
    sol0, _ = solve_group(g1, damp[0], bc, bb, None)
    assert all(getattr(g1, used)[cl.name] for cl in cls)
    assert not getattr(g1, other)
    sol1, xi1 = solve_group(g1, damp[1], bc, bb, None)
    assert not getattr(g2, used)
    sol2, xi2 = solve_group(g2, damp[1], bc, bb, None)
    np.testing.assert_array_equal(xi1, xi2)
    for name, (u, s) in sol2.items():
        np.testing.assert_array_equal(sol1[name][0], u)
        np.testing.assert_array_equal(sol1[name][1], s)
        # the drag matters (the bit test above compares two different answers)
        assert not np.array_equal(sol0[name][0], u)


def test_coarse_group_leaves_out_negligible_weights(monkeypatch):
    """The coarse group leaves out the subset frequencies whose σ weight is at most
    ``COARSE_NEGLIGIBLE`` of the largest (the JONSWAP's empty low-frequency tail: 3
    of 25 on the test mooring), keeping the other weights to the bit, and its map
    gives the σ of the whole subset: the dropped terms weigh ≤ 1e-12 of the largest
    (with |H|² at those frequencies not above 1e2 × the weighted mean: 1e-10)."""
    body = _buoy(drag_area=[4.0, 4.0, 8.0])
    _, cls, loads = _group(_mooring_doc(count=96, solver="foss"), body)
    g = GroupSystem(cls, [body], loads, RHO, cls[0].channels)
    idx = cc.coarse_subset(g)
    gc, upd, x = _coarse_update(g, idx)
    monkeypatch.setattr(cc, "COARSE_NEGLIGIBLE", -1.0)  # keep every frequency
    gall, upd_all, _ = _coarse_update(g, idx)
    assert gall.omega.size == idx.size and gc.omega.size == idx.size - 3
    kept = np.isin(gall.omega, gc.omega)
    np.testing.assert_array_equal(gc.weights, gall.weights[kept])
    assert np.all(np.abs(gall.weights[~kept]) <= 1e-12 * np.abs(gall.weights).max())
    for cl in cls:
        np.testing.assert_array_equal(
            gc.inp_phys[cl.name].weights, gall.inp_phys[cl.name].weights[kept]
        )
        np.testing.assert_array_equal(gc.inp_phys[cl.name].square, gall.inp_phys[cl.name].square)
    np.testing.assert_allclose(upd(x), upd_all(x), rtol=1e-10)


def test_sliced_channel_keeps_nodal_kinematics_lazy(monkeypatch):
    """A channel whose nodal kinematics are computed on first use (``nodal``) is sliced
    without computing them; the sliced channel's velocity and acceleration, on first
    access, are the full channel's at the subset (bit-identical)."""
    monkeypatch.delenv("STOCHCABLE_WORKING_MEMORY_MB", raising=False)  # (kept kinematics)
    body = _buoy()
    _, cls, _ = _group(_mooring_doc(count=40, solver="foss"), body)
    sea = cls[0].channels[0]
    calls = []

    def nodal():
        calls.append(1)
        return sea.nodal()

    lazy = dataclasses.replace(sea, velocity=None, acceleration=None, nodal=nodal)
    idx = np.arange(0, 40, 3)
    sub = cc._sliced_channel(lazy, idx)
    assert not calls
    np.testing.assert_array_equal(sub.velocity, sea.velocity[idx])
    np.testing.assert_array_equal(sub.acceleration, sea.acceleration[idx])
    assert len(calls) == 1
    np.testing.assert_array_equal(
        sub.element_velocity_parts.parts, sea.element_velocity_parts.parts[..., idx]
    )
    np.testing.assert_array_equal(sub.element_square.horizontal, sea.element_square.horizontal[idx])


@pytest.mark.parametrize("top", [0.5, 40.0, 1e9])
def test_listed_eigh_whole_driver_equals_subset_driver(top):
    """``_listed_eigh`` below ``_ALL_EIGH_MAX`` (every eigenpair by ``gvd``, then the
    listed ones) against the subset driver ``gvx`` on a random SPD pencil (n = 60,
    eigenvalues 0.047–167; 5 below 0.5, 38 below 40, none within 1 % of a top): the same
    listed count, the
    eigenvalues to 1e-10 relative (round-off of two LAPACK drivers), M-orthonormal
    vectors; below 10 listed, the lowest 10 (top 0.5)."""
    import scipy.linalg as sla

    rng = np.random.default_rng(7)
    n = 60
    a = rng.standard_normal((n, n))
    md = a @ a.T / n + np.eye(n)
    b = rng.standard_normal((n, n))
    kd = b @ b.T + 0.1 * np.eye(n)
    assert n <= cm._ALL_EIGH_MAX
    lam, phi = cm._listed_eigh(kd, md, top)
    ref = sla.eigh(kd, md, subset_by_value=(-np.inf, top), driver="gvx", eigvals_only=True)
    if ref.size < cm.MIN_LISTED_MODES:
        ref = sla.eigh(kd, md, eigvals_only=True)[: cm.MIN_LISTED_MODES]
    assert lam.size == ref.size
    np.testing.assert_allclose(lam, ref, rtol=1e-10)
    # mass-normalized eigenvectors: round-off of an n = 60 factorization
    np.testing.assert_allclose(phi.T @ md @ phi, np.eye(lam.size), atol=1e-10)
    np.testing.assert_allclose(kd @ phi, md @ phi * lam, atol=1e-8 * np.abs(kd).max())
