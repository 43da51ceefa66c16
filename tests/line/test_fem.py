"""Finite-element model (stochcable.line.fem): element matrices, assembly, partition.

Independent checks: the element stiffness against a central finite difference of the
element end force T(l)·e with T = EA(l − l0)/l0 (its exact derivative, Tuah 1982
eqs. 3.1.8–3.1.11); the consistent mass against the integral of the linear shape
functions (Tuah 1982, eq. 3.1.12) and conservation of total mass; rigid-body modes;
the 2-D model against the in-plane part of the 3-D one.
"""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest
import scipy.sparse as sp
from fem_cases import hanging_chain, shallow_parabola, taut_string, uniform_mesh

from stochcable.errors import InputError
from stochcable.line.fem import (
    SLACK_EA_RATIO,
    FEModel,
    assemble,
    build_fe_model,
    element_added_mass,
    element_mass,
    element_stiffness,
)
from stochcable.line.modes import natural_modes
from stochcable.scene.model import Environment, Seabed

RHO = 1025.0
G = 9.80665


def _end_force(xa, xb, l0, ea):
    """Force the element exerts on node b when stretched: −T(l) e (T = EA(l−l0)/l0)."""
    d = xb - xa
    l = np.linalg.norm(d)
    return -ea * (l - l0) / l0 * d / l


@pytest.mark.parametrize("dim", [2, 3])
def test_element_stiffness_is_the_exact_tangent(dim):
    rng = np.random.default_rng(3)
    xa = rng.normal(size=dim)
    xb = xa + rng.normal(size=dim) * 5.0
    l = np.linalg.norm(xb - xa)
    l0, ea = 0.99 * l, 2.0e6
    t = ea * (l - l0) / l0
    k = element_stiffness(xa[None], xb[None], [l0], [ea], [t])[0]
    # −∂f_b/∂x: central differences, step 1e-6 of the length (truncation O(h²) ~1e-12,
    # round-off ~1e-16·EA/h ~1e-9 relative): 1e-6 relative tolerance
    h = 1e-6 * l
    num = np.zeros((2 * dim, 2 * dim))
    for j in range(2 * dim):
        dx = np.zeros(2 * dim)
        dx[j] = h
        fp = _end_force(xa + dx[:dim], xb + dx[dim:], l0, ea)
        fm = _end_force(xa - dx[:dim], xb - dx[dim:], l0, ea)
        col = -(fp - fm) / (2 * h)
        num[dim:, j] = col
        num[:dim, j] = -col  # node a takes the opposite force
    np.testing.assert_allclose(k, num, rtol=1e-6, atol=1e-6 * np.abs(k).max())


def test_element_stiffness_slack_element():
    k = element_stiffness([[0.0, 0.0]], [[2.0, 0.0]], [2.0], [1.0e6], [-5.0])[0]
    # slack: no geometric stiffness, EA -> SLACK_EA_RATIO·EA along the element
    expected = SLACK_EA_RATIO * 1.0e6 / 2.0 * np.kron([[1, -1], [-1, 1]], [[1, 0], [0, 0]])
    np.testing.assert_allclose(k, expected, rtol=1e-14, atol=0)


def test_element_mass_matches_shape_function_integral():
    # ∫ N_i N_j ds over an element with linear N: l0·[[1/3, 1/6], [1/6, 1/3]]
    l0, mass = 3.0, 7.0
    xi = np.linspace(0.0, 1.0, 20001)
    n = np.stack([1 - xi, xi])
    integral = np.trapezoid(n[:, None, :] * n[None, :, :], xi, axis=2) * l0 * mass
    m = element_mass([l0], [mass], dim=3)[0]
    # trapezoid rule on 20001 points: error ~ h²/12 ~ 2e-10
    np.testing.assert_allclose(m[0::3, 0::3], integral, rtol=1e-8)
    np.testing.assert_allclose(m[0::3, 1::3], 0.0)
    lumped = element_mass([l0], [mass], dim=2, lumped=True)[0]
    np.testing.assert_allclose(lumped, np.eye(4) * l0 * mass / 2)


def test_element_added_mass_is_normal_only():
    e = np.array([[0.6, 0.0, 0.8]])
    ma = element_added_mass(e, [2.0], [1.5], [0.1], RHO)[0]
    per_length = 1.5 * RHO * np.pi * 0.1**2 / 4
    u_axial = np.concatenate([e[0], e[0]])
    assert np.abs(ma @ u_axial).max() < 1e-12 * per_length  # no tangential added mass
    u_normal = np.array([0.0, 1.0, 0.0, 0.0, 1.0, 0.0])
    assert u_normal @ ma @ u_normal == pytest.approx(per_length * 2.0, rel=1e-14)


def _planar_sag_model(dim, **kw):
    mesh, pos, ten = shallow_parabola(30, 100.0, 0.05, 1.0e4, 5.0, G, 1.0e7)
    return assemble(mesh, pos, ten, RHO, dim=dim, **kw)


@pytest.mark.parametrize("dim", [2, 3])
def test_matrices_symmetric_and_mass_positive_definite(dim):
    model = _planar_sag_model(dim)
    for name in ("K", "M", "Ma"):
        a = model.dense(name)
        np.testing.assert_allclose(a, a.T, rtol=0, atol=1e-12 * np.abs(a).max())
    np.linalg.cholesky(model.dense("M"))  # raises if not positive definite
    assert np.linalg.eigvalsh(model.dense("K")).min() > -1e-9 * np.abs(model.dense("K")).max()


def test_total_mass_is_conserved():
    mesh, pos, ten = taut_string(17, 50.0, 1e4, 3.0, 1e8)
    model = assemble(mesh, pos, ten, RHO, dim=3)
    ones = np.zeros(model.n_dof)
    ones[model.dof(0, "x") :: 3] = 1.0  # rigid unit translation in x
    assert ones @ (model.M @ ones) == pytest.approx(3.0 * 50.0, rel=1e-13)


def test_two_d_equals_in_plane_part_of_three_d():
    m2, m3 = _planar_sag_model(2), _planar_sag_model(3)
    xz = np.sort(np.concatenate([np.arange(0, m3.n_dof, 3), np.arange(2, m3.n_dof, 3)]))
    for name in ("K", "M", "Ma"):
        np.testing.assert_array_equal(m3.dense(name)[np.ix_(xz, xz)], m2.dense(name))
    d2 = natural_modes(m2, count=6)
    d3 = natural_modes(m3, count=12)
    # same matrices, separate eigensolver calls: equal to round-off (ε·λ_max/λ ~ 1e-11)
    np.testing.assert_allclose(d3.omega[d3.plane == "in-plane"][:6], d2.omega, rtol=1e-9)


def test_free_free_bar_rigid_modes():
    mesh, pos, ten = taut_string(20, 40.0, 0.0, 2.0, 1.0e6)
    # T -> 0+ (1e-6 N; T = 0 itself would be slack): in 2-D the rigid axial translation
    # and one near-zero mode per node for the unstressed transverse DOFs (ω <= 2√(T/(m
    # l²)) ~ 4e-4 rad/s); the rest are free-free axial bar modes √(EA/m) nπ/L
    model = assemble(mesh, pos, np.full(20, 1e-6), RHO, dim=2, fixed_nodes=())
    m = natural_modes(model, added_mass=False)
    zero = m.omega < 1e-4 * m.omega.max()
    assert zero.sum() == 21 + 1
    axial = m.omega[~zero][:3]
    c, h = np.sqrt(1.0e6 / 2.0), 2.0
    kh = np.arange(1, 4) * np.pi / 40.0 * h
    ref = np.arange(1, 4) * np.pi / 40.0 * c
    np.testing.assert_allclose(axial, ref, rtol=1e-2)  # 20 elements: (kh)²/24 <= 9.3e-3
    # the discrete spectrum of linear elements with consistent mass is known exactly
    # (modes cos(k x_j), k = nπ/L): ω_h² = 6c²(1 − cos kh)/(h²(2 + cos kh))
    exact_fe = c * np.sqrt(6 * (1 - np.cos(kh)) / (h**2 * (2 + np.cos(kh))))
    np.testing.assert_allclose(axial, exact_fe, rtol=1e-9)  # round-off only
    # T > 0, free-free: exactly dim rigid translations have zero frequency
    model = assemble(mesh, pos, np.full(20, 1.0e3), RHO, dim=3, fixed_nodes=())
    m = natural_modes(model, count=6, added_mass=False)
    # a zero eigenvalue comes out as round-off, |λ| ~ n·eps·max|K|/min(M) ≈ 1e-11 λ_3
    # here, so ω = √|λ| ~ 3e-6 ω_3 (divide-and-conquer sygvd); 1e-4 is far below the
    # first elastic mode and far above that round-off
    assert (m.omega[:3] < 1e-4 * m.omega[3]).all() and m.omega[3] > 0
    for j in range(3):
        u = m.shapes[:, j].reshape(-1, 3)
        np.testing.assert_allclose(u, np.broadcast_to(u[0], u.shape), atol=1e-8 * np.abs(u).max())


def test_seabed_springs_and_damping_vertical_only():
    mesh, pos, ten = taut_string(10, 20.0, 1e4, 3.0, 1e8)
    mesh = uniform_mesh(10, 2.0, 1e8, 3.0, diameter=0.2)
    grounded = np.zeros(11, dtype=bool)
    grounded[:4] = True
    bed = Seabed(stiffness=3.0e6, damping=2.0e5)
    with_bed = assemble(mesh, pos, ten, RHO, dim=3, grounded=grounded, seabed=bed)
    without = assemble(mesh, pos, ten, RHO, dim=3)
    dk = (with_bed.K - without.K).toarray()
    trib = np.array([1.0, 2.0, 2.0, 2.0])  # half of each 2 m neighbour element
    expected = np.zeros(33)
    expected[[2, 5, 8, 11]] = 3.0e6 * 0.2 * trib
    np.testing.assert_allclose(dk, np.diag(expected), rtol=1e-14, atol=1e-6)
    np.testing.assert_allclose(with_bed.Cs.toarray(), np.diag(expected / 3.0e6 * 2.0e5), rtol=1e-14)
    assert without.Cs.nnz == 0


def test_attachment_masses_lumped_on_nodes():
    mesh = uniform_mesh(4, 1.0, 1e6, 1.0)
    nm = mesh.node_mass.copy()
    nm[2] = 50.0
    na = mesh.node_added_mass.copy()
    na[2] = 7.0
    mesh = type(mesh)(**{**mesh.__dict__, "node_mass": nm, "node_added_mass": na})
    pos = np.column_stack([np.arange(5.0), np.zeros(5), np.zeros(5)])
    model = assemble(mesh, pos, np.full(4, 10.0), RHO, dim=3)
    base = assemble(uniform_mesh(4, 1.0, 1e6, 1.0), pos, np.full(4, 10.0), RHO, dim=3)
    np.testing.assert_allclose(
        (model.M - base.M).toarray(), np.diag(np.r_[np.zeros(6), [50.0] * 3, np.zeros(6)])
    )
    np.testing.assert_allclose(
        (model.Ma - base.Ma).toarray(), np.diag(np.r_[np.zeros(6), [7.0] * 3, np.zeros(6)])
    )


def test_partition_dof_and_banded_storage():
    mesh, pos, ten = hanging_chain(8, 16.0, 2.0, G, 1e9)
    model = assemble(mesh, pos, ten, RHO, dim=3, fixed_nodes=(0,))
    assert isinstance(model, FEModel)
    np.testing.assert_array_equal(model.fixed, [0, 1, 2])
    assert model.free.size == 24 and model.bandwidth == 5
    assert model.dof(-1, "z") == 26 and model.dof(2, 1) == 7
    kff, kfp = model.partition("K")
    assert sp.issparse(kff) and kff.shape == (24, 24) and kfp.shape == (24, 3)
    dff, dfp = model.partition(model.dense("K"))
    np.testing.assert_array_equal(kff.toarray(), dff)
    np.testing.assert_array_equal(kfp.toarray(), dfp)
    ab = model.banded("MT")
    full = model.partition("MT")[0].toarray()
    u = model.bandwidth
    rebuilt = np.zeros_like(full)
    for i in range(24):
        for j in range(i, min(24, i + u + 1)):
            rebuilt[i, j] = rebuilt[j, i] = ab[u + i - j, j]
    np.testing.assert_array_equal(rebuilt, full)
    # nothing outside the band
    assert np.abs(np.triu(full, u + 1)).max() == 0.0


def test_build_fe_model_from_line_statics():
    mesh, pos, ten = shallow_parabola(10, 50.0, 0.02, 1e4, 3.0, G, 1e8)
    grounded = np.zeros(11, dtype=bool)
    ls = SimpleNamespace(mesh=mesh, positions=pos, tension=ten, grounded=grounded)
    env = Environment(depth=100.0, seabed=Seabed(stiffness=1e6, damping=0.0))
    model = build_fe_model(ls, env)
    assert model.dim == 2  # in the x–z plane
    assert build_fe_model(ls, env, dim=3).dim == 3
    shifted = SimpleNamespace(
        mesh=mesh, positions=pos + [0, 5.0, 0], tension=ten, grounded=grounded
    )
    assert build_fe_model(shifted, env).dim == 3


def test_build_fe_model_with_solved_statics():
    statics = pytest.importorskip("stochcable.statics")
    from stochcable.scene.model import load_scene

    scene = load_scene(
        {
            "environment": {"depth": 200.0},
            "lines": [
                {
                    "name": "leg",
                    "end_a": {"position": [-800.0, 0.0, -200.0]},
                    "end_b": {"position": [0.0, 0.0, -20.0]},
                    "segments": [
                        {
                            "length": 850.0,
                            "ea": 1.2326e9,
                            "mass": 288.0,
                            "diameter": 0.216,
                            "elements": 40,
                        }
                    ],
                }
            ],
        }
    )
    ls = statics.solve_statics(scene).lines["leg"]
    model = build_fe_model(ls, scene.environment, dim=3)
    # contact nodes: those before the static touchdown
    np.testing.assert_array_equal(model.grounded, ls.mesh.s0 <= ls.touchdown)
    assert model.grounded.sum() > 0
    # seabed springs only on the grounded nodes' z DOFs, and the touchdown element's
    # node b, which the condensed split element supports at the touchdown
    kz = (
        model.K.diagonal()[2::3]
        - assemble(ls.mesh, ls.positions, ls.tension, 1025.0).K.diagonal()[2::3]
    )
    b = int(np.flatnonzero(model.grounded)[-1]) + 1
    assert (kz[model.grounded] > 0).all() and kz[b] > 0
    assert (kz[~model.grounded][1:] == 0).all()


def test_assemble_error_paths():
    mesh, pos, ten = taut_string(4, 10.0, 1e3, 1.0, 1e6, direction=(1.0, 1.0, 0.0))
    with pytest.raises(InputError, match=r"dim = 2: needs a line in the x–z plane"):
        assemble(mesh, pos, ten, RHO, dim=2)
    with pytest.raises(InputError, match=r"dim = 4: must be 2 \(in-plane x–z\) or 3"):
        assemble(mesh, pos, ten, RHO, dim=4)
    with pytest.raises(
        InputError, match=r"tension = \(3,\) \[N\]: must have one value per element \(4\)"
    ):
        assemble(mesh, pos, ten[:3], RHO)
    with pytest.raises(InputError, match=r"fixed_nodes = 9: must be node indices in 0…4"):
        assemble(mesh, pos, ten, RHO, fixed_nodes=(0, 9))
    bad = pos.copy()
    bad[2] = bad[1]
    with pytest.raises(InputError, match="element 1 has zero length"):
        assemble(mesh, bad, ten, RHO)
    with pytest.raises(InputError, match=r"rho = -1.0 \[kg/m³\]: must be > 0"):
        assemble(mesh, pos, ten, -1.0)
    with pytest.raises(InputError, match="mass_matrix = 'diagonal'"):
        assemble(mesh, pos, ten, RHO, mass_matrix="diagonal")
    model = assemble(mesh, pos, ten, RHO)
    with pytest.raises(InputError, match=r"component = 'w': must be one of the model axes"):
        model.dof(0, "w")
    with pytest.raises(InputError, match="positions_b .* must have the shape of positions_a"):
        element_stiffness(np.zeros((2, 3)), np.ones((3, 3)), [1, 1], [1, 1], [1, 1])


# ------------------------------------------------------------- direct CSR assembly


@pytest.mark.parametrize("dim", [2, 3])
def test_chain_csr_equals_the_coo_assembly(dim):
    """fem.chain_csr (node blocks straight into CSR, the speed pass of issue 4) against
    the COO assembly it replaced (fem._assemble_sparse): the same pattern (explicit
    zeros kept) and the same entries; the diagonal blocks sum two element blocks and a
    nodal diagonal in another order, so 1e-15 relative (a few ulp)."""
    from stochcable.line.fem import _assemble_sparse, _element_dofs, chain_csr

    rng = np.random.default_rng(7)
    n_el = 6
    blocks = rng.normal(size=(n_el, 2 * dim, 2 * dim))
    blocks[:, 0, dim] = 0.0  # explicit zeros stay in the pattern
    diag = np.where(rng.random(dim * (n_el + 1)) < 0.5, rng.normal(size=dim * (n_el + 1)), 0.0)
    for node_diag in (None, diag):
        a = chain_csr(blocks, n_el + 1, dim, node_diag)
        b = _assemble_sparse(blocks, _element_dofs(n_el, dim), dim * (n_el + 1), node_diag)
        assert a.has_canonical_format
        np.testing.assert_array_equal(a.indptr, b.indptr)
        np.testing.assert_array_equal(a.indices, b.indices)
        np.testing.assert_allclose(a.data, b.data, rtol=1e-15, atol=1e-15)


def test_free_free_block_and_total_mass_match_partition():
    """The sliced free–free block (FEModel._free_free) and the cached M + Ma
    (FEModel._mass_total) are partition("K")[0] and partition("MT")[0] exactly."""
    mesh, pos, ten = taut_string(6, 12.0, 1.0e4, 2.0, 1.0e7, direction=(0.6, 0.0, -0.8))
    for dim in (2, 3):
        model = assemble(mesh, pos, ten, RHO, dim=dim)
        for name, mat in (("K", model.K), ("MT", model._mass_total)):
            ff = model._free_free(mat)
            ref = model.partition(name)[0]
            assert sp.issparse(ff)
            np.testing.assert_array_equal(ff.toarray(), ref.toarray())
        np.testing.assert_array_equal(model._mass_total.toarray(), (model.M + model.Ma).toarray())
        # "MT" by name stays a fresh matrix: changing it does not touch the cache
        mt = model._matrix("MT")
        mt.data[:] = 0.0
        assert abs(model._mass_total).max() > 0.0
