"""Rigid bodies and their rigid-link coupling to lines (stochcable.bodies.rigid).

Independent checks: closed-form transfer functions of bodies on springs (matrices
written out by hand); the rigid link against finite rotations (scipy Rotation); the
rigid-body mass matrix against the kinetic energy of a cloud of point masses; the
infinite-mass limit against the line with a prescribed end; symmetry and reciprocity
of the coupled matrices; the attachment geometric stiffness against central finite
differences of the line statics (stochcable.line.statics) at rotated and displaced body
poses; the Schur direct solve against the dense one.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from fem_cases import taut_string, uniform_mesh
from scipy.spatial.transform import Rotation

from stochcable.bodies.coupling import (
    LineLink,
    constant_matrices,
    couple,
    coupled_load,
    expand_line,
)
from stochcable.bodies.rigid import (
    ExcitationTable,
    FrequencyTable,
    RigidBody,
    attachment_geometric_stiffness,
    body_excitation,
    rigid_body_mass_matrix,
    rigid_link_matrix,
)
from stochcable.errors import InputError, SolverError
from stochcable.line.fem import assemble, build_fe_model
from stochcable.line.mesh import mesh_line
from stochcable.line.statics import solve_line_statics
from stochcable.reference.bodies import body_drag_damping, solve_coupled_direct
from stochcable.scene.model import Environment, Line

RHO = 1025.0


# ----------------------------------------------------------------------- helpers


def _string_model(start, end, n_el, tension, mass, ea, dim=3):
    """Taut string FEModel from ``start`` to ``end`` (both ends prescribed)."""
    start, end = np.asarray(start, float), np.asarray(end, float)
    length = float(np.linalg.norm(end - start))
    mesh, pos, ten = taut_string(n_el, length, tension, mass, ea, direction=end - start)
    return assemble(mesh, pos + start, ten, RHO, dim=dim)


def _diag_body(planar=False, **kw):
    n = 3 if planar else 6
    base = dict(
        name="b",
        position=[0.0, 0.0, 0.0],
        mass=2.0e3,
        inertia=np.diag([3.0e3, 4.0e3, 5.0e3]),
        hydrostatic_stiffness=np.diag(np.linspace(1.0e4, 6.0e4, n)),
        planar=planar,
    )
    base.update(kw)
    return RigidBody(**base)


# ------------------------------------------------------------ bodies on springs


def test_heave_one_dof_closed_form_with_tables():
    """Heave of a body on its hydrostatic spring with A(ω), B(ω) tables:
    H = 1/(K33 − ω²(m + A33(ω)) + iω B33(ω)), A and B linear between table points."""
    tw = np.array([0.2, 0.8, 1.4, 2.0])
    a33 = np.array([900.0, 700.0, 650.0, 600.0])
    b33 = np.array([10.0, 400.0, 250.0, 100.0])
    A = np.zeros((4, 6, 6))
    A[:, 2, 2] = a33
    B = np.zeros((4, 6, 6))
    B[:, 2, 2] = b33
    for i in (0, 1, 3, 4, 5):  # the other DOFs: constant, irrelevant to heave
        A[:, i, i] = 100.0
        B[:, i, i] = 50.0
    m, k33 = 1500.0, 3.0e4
    hs = np.diag([1e3, 1e3, k33, 1e4, 1e4, 1e3])
    body = RigidBody(
        "buoy",
        [0, 0, 0],
        m,
        inertia=np.eye(3) * 800.0,
        added_mass=FrequencyTable(tw, A),
        radiation_damping=FrequencyTable(tw, B),
        hydrostatic_stiffness=hs,
    )
    system = couple([], [body])
    w = np.array([0.2, 0.5, 1.1, 1.7, 2.0])
    F = np.zeros((w.size, 6), complex)
    F[:, 2] = 1.0
    x = solve_coupled_direct(system, F, w)
    a = np.interp(w, tw, a33)
    b = np.interp(w, tw, b33)
    expected = 1.0 / (k33 - w**2 * (m + a) + 1j * w * b)
    # round-off of a 6×6 solve
    np.testing.assert_allclose(x[:, 2], expected, rtol=1e-12)
    np.testing.assert_allclose(np.delete(x, 2, axis=1), 0.0, atol=1e-15)


def test_six_dof_diagonal_closed_form():
    """A body with diagonal M, A, B, K responds DOF by DOF: H_ii = 1/Z_ii."""
    md = np.array([2.0e3, 2.0e3, 2.0e3, 3.0e3, 4.0e3, 5.0e3])
    A = np.diag([100.0, 200.0, 300.0, 400.0, 500.0, 600.0])
    B = np.diag([10.0, 20.0, 30.0, 40.0, 50.0, 60.0])
    K = np.diag([1e3, 2e3, 3e4, 4e4, 5e4, 6e3])
    body = _diag_body(added_mass=A, radiation_damping=B, hydrostatic_stiffness=K)
    system = couple([], [body])
    w = np.linspace(0.1, 3.0, 7)
    F = np.broadcast_to(np.eye(6, dtype=complex), (w.size, 6, 6)).copy()
    x = solve_coupled_direct(system, F, w)
    z = np.diag(K)[None] - w[:, None] ** 2 * (md + np.diag(A))[None] + 1j * w[:, None] * np.diag(B)
    for i in range(6):
        # round-off of a 6×6 solve
        np.testing.assert_allclose(x[:, i, i], 1.0 / z[:, i], rtol=1e-12)
    off = x - np.einsum("wii->wi", x)[:, :, None] * np.eye(6)
    assert np.abs(off).max() == 0.0


def test_planar_three_dof_with_spring_line_closed_form():
    """Planar body (surge, heave, pitch), CoG offset, coupled added mass, and a
    horizontal taut string (EA, T) attached at (r_x, 0, h): the full 3×3 transfer
    matrix against matrices written out by hand (pitch about +y)."""
    m, iyy, cx, cz = 5.0e3, 2.0e4, 0.3, -0.8
    rx, h, L, T, EA = 1.5, 2.0, 40.0, 2.0e4, 4.0e6
    k33, k55 = 8.0e4, 3.0e5
    A = np.array([[800.0, 0.0, 150.0], [0.0, 1200.0, 0.0], [150.0, 0.0, 3000.0]])
    B = np.array([[60.0, 0.0, 5.0], [0.0, 90.0, 0.0], [5.0, 0.0, 200.0]])
    P = np.array([10.0, 0.0, -3.0])
    body = RigidBody(
        "disc",
        P,
        m,
        inertia=np.diag([0.0, iyy, 0.0]),
        cog=[cx, 0.0, cz],
        added_mass=A,
        radiation_damping=B,
        hydrostatic_stiffness=np.diag([0.0, k33, k55]),
        planar=True,
    )
    att = P + [rx, 0.0, h]
    mesh = uniform_mesh(1, L, EA, 0.0)
    model = assemble(mesh, np.array([att - [L, 0.0, 0.0], att]), np.array([T]), RHO, dim=2)
    system = couple([LineLink("spring", model, end_b="disc")], [body])
    ka, kt = EA / L, T / L
    M_hand = (
        np.array(
            [[m, 0.0, m * cz], [0.0, m, -m * cx], [m * cz, -m * cx, iyy + m * (cx**2 + cz**2)]]
        )
        + A
    )
    K_hand = np.array(
        [
            [ka, 0.0, ka * h],
            [0.0, k33 + kt, -kt * rx],
            [ka * h, -kt * rx, k55 + ka * h**2 + kt * rx**2 - T * rx],
        ]
    )
    w = np.linspace(0.2, 4.0, 9)
    Z = K_hand[None] - w[:, None, None] ** 2 * M_hand[None] + 1j * w[:, None, None] * B[None]
    H_hand = np.linalg.inv(Z)
    F = np.broadcast_to(np.eye(3, dtype=complex), (w.size, 3, 3)).copy()
    H = solve_coupled_direct(system, F, w)
    # round-off of 3×3 solves of matrices with entries up to ~1e7
    np.testing.assert_allclose(H, H_hand, rtol=1e-10, atol=1e-12 * np.abs(H_hand).max())
    np.testing.assert_allclose(system.K.toarray(), K_hand, rtol=1e-12, atol=1e-9)


# --------------------------------------------------------------- rigid link, mass


@pytest.mark.parametrize("axis", [(1, 0, 0), (0, 1, 0), (0, 0, 1), (0.3, -0.5, 0.8)])
def test_rigid_link_first_order_in_finite_rotation(axis):
    """R(θ)r − r = T(r)[0; θ] + O(|θ|²|r|): the error is below ½|θ|²|r| and falls as θ²."""
    r = np.array([1.2, -0.7, 2.5])
    a = np.asarray(axis, float) / np.linalg.norm(axis)
    t = rigid_link_matrix(r)
    u = np.array([0.1, -0.2, 0.3])
    errs = []
    for eps in (1e-2, 1e-3):
        q = np.concatenate([u, eps * a])
        exact = u + Rotation.from_rotvec(eps * a).apply(r) - r
        err = np.linalg.norm(t @ q - exact)
        # |R r − r − θ×r| <= ½|θ|²|r| (Taylor remainder of the rotation)
        assert err <= 0.5 * eps**2 * np.linalg.norm(r) * (1 + 1e-9)
        errs.append(err)
    # second order: ten times smaller angle -> ~100 times smaller error (70 leaves room
    # for the third-order term)
    assert errs[0] / errs[1] > 70.0


def test_rigid_link_planar_signs():
    """Planar map is the 3-D one restricted to (x, z) rows and (surge, heave, pitch)
    columns; positive pitch (about +y) moves a point ahead (+x) down and a point above
    (+z) forward."""
    r = np.array([2.0, 0.0, 0.5])
    t3 = rigid_link_matrix(r)
    t2 = rigid_link_matrix(r, planar=True)
    np.testing.assert_array_equal(t2, t3[np.ix_([0, 2], [0, 2, 4])])
    np.testing.assert_array_equal(rigid_link_matrix([2.0, 0.5], planar=True), t2)
    assert rigid_link_matrix([1.0, 0.0, 0.0], planar=True) @ [0, 0, 0.01] @ [0, 1] < 0
    assert rigid_link_matrix([0.0, 0.0, 1.0], planar=True) @ [0, 0, 0.01] @ [1, 0] > 0
    # Rotation about +y by a small angle agrees in sign
    d = Rotation.from_rotvec([0, 1e-4, 0]).apply([1.0, 0, 0]) - [1.0, 0, 0]
    assert d[2] < 0


def test_mass_matrix_equals_point_mass_cloud():
    """M about the reference = Σ m_i T(r_i)ᵀ T(r_i) for a cloud of point masses."""
    rng = np.random.default_rng(3)
    pts = rng.normal(size=(7, 3)) + [0.5, -0.2, 1.0]
    ms = rng.uniform(1.0, 5.0, 7)
    M_ref = sum(mi * rigid_link_matrix(p).T @ rigid_link_matrix(p) for mi, p in zip(ms, pts))
    m = ms.sum()
    c = (ms[:, None] * pts).sum(0) / m
    d = pts - c
    I_G = sum(mi * (di @ di * np.eye(3) - np.outer(di, di)) for mi, di in zip(ms, d))
    # round-off
    np.testing.assert_allclose(rigid_body_mass_matrix(m, I_G, c), M_ref, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(
        rigid_body_mass_matrix(m, I_G, c, planar=True),
        M_ref[np.ix_([0, 2, 4], [0, 2, 4])],
        rtol=1e-12,
        atol=1e-12,
    )


# ----------------------------------------------------------- coupling: the limits


def _body_on_string(mass, r=(0.5, 0.3, -0.4)):
    L = 10.0
    r = np.asarray(r)
    model = _string_model([0, 0, 0], [L, 0, 0], 8, 1000.0, 1.0, 1.0e6)
    body = RigidBody("heavy", np.array([L, 0, 0]) - r, mass, inertia=np.eye(3) * mass)
    return model, body, r


def _prescribed_end_solve(model, ub, w):
    """Line alone with end b moving by ub (n_w, 3): free rows of Z u = 0."""
    u = np.zeros((w.size, model.n_dof), complex)
    u[:, -3:] = ub
    out = []
    for k, wk in enumerate(w):
        Z = (model.K - wk**2 * (model.M + model.Ma)).toarray()
        Zff = Z[np.ix_(model.free, model.free)]
        Zfp = Z[np.ix_(model.free, model.fixed)]
        uf = np.linalg.solve(Zff, -Zfp @ u[k, model.fixed])
        uk = u[k].copy()
        uk[model.free] = uf
        out.append(uk)
    return np.array(out)


def test_infinite_body_mass_gives_prescribed_end_motion():
    """Body mass → ∞ driven by F = −ω² M_B q0: the body moves by q0 and the line
    responds as the line with its end prescribed to T(r) q0; the error falls like 1/m."""
    w = np.array([1.0, 5.0, 15.0])  # away from the string's fixed-end resonances 9.93, 19.9
    q0 = np.array([0.01, 0.02 - 0.01j, 0.005j, 0.003, -0.002, 0.004 + 0.001j])
    errs = []
    k_line = 1.0e5  # axial stiffness EA/L of the string, the stiffest path to the body [N/m]
    for mass in (1.0e9, 1.0e11):
        model, body, r = _body_on_string(mass)
        system = couple([LineLink("s", model, end_b="heavy")], [body])
        F = coupled_load(
            system, w, body_loads={"heavy": -(w**2)[:, None] * (body.mass_matrix() @ q0)[None]}
        )
        x = solve_coupled_direct(system, F, w)
        u = expand_line(system, "s", x)
        ref = _prescribed_end_solve(model, (rigid_link_matrix(r) @ q0)[None].repeat(w.size, 0), w)
        errs.append(np.abs(u - ref).max() / np.abs(ref).max())
        # the line's reaction perturbs the body by ~ k_line/(ω² m) relative, ω >= 1 rad/s
        np.testing.assert_allclose(
            x[:, system.body_dofs["heavy"]], q0[None].repeat(3, 0), rtol=10.0 * k_line / mass
        )
    # 1/m convergence: 100 times the mass, ~100 times smaller error
    assert errs[1] < 10.0 * k_line / 1.0e11
    assert errs[0] / errs[1] > 50.0


def test_stiff_body_and_moving_anchor_equal_line_with_prescribed_ends():
    """A body held by huge springs does not move; a moving anchor (line_motions) then
    gives the line's prescribed-end response, and L/P expansion restores the ends."""
    model, body, r = _body_on_string(10.0)
    body = dataclasses.replace(body, hydrostatic_stiffness=np.eye(6) * 1e16)
    system = couple([LineLink("s", model, end_b="heavy")], [body])
    w = np.array([2.0, 7.0])
    ua = np.array([0.01, 0.02j, -0.005])
    motion = np.zeros((w.size, model.n_dof), complex)
    motion[:, :3] = ua
    F = coupled_load(system, w, line_motions={"s": motion})
    x = solve_coupled_direct(system, F, w)
    p = np.zeros((w.size, system.n_prescribed), complex)
    p[:, system.prescribed_dofs["s"]] = ua
    u = expand_line(system, "s", x, p)
    ref = np.zeros_like(u)
    for k, wk in enumerate(w):
        Z = (model.K - wk**2 * (model.M + model.Ma)).toarray()
        up = np.concatenate([ua, np.zeros(3)])
        ref[k, model.fixed] = up
        ref[k, model.free] = np.linalg.solve(
            Z[np.ix_(model.free, model.free)], -Z[np.ix_(model.free, model.fixed)] @ up
        )
    # body compliance 1e-16 m/N times line end forces ~1e3 N/m·m: relative ~1e-10
    np.testing.assert_allclose(u, ref, atol=1e-9 * np.abs(ref).max())


def test_end_node_load_goes_to_body_through_transpose():
    """A force f on the attached end node gives the same response as Tᵀ f on the body."""
    model, body, r = _body_on_string(50.0)
    system = couple([LineLink("s", model, end_b="heavy")], [body])
    w = np.array([0.7, 3.0])
    f = np.array([10.0, -5.0 + 2j, 3.0])
    fl = np.zeros((w.size, model.n_dof), complex)
    fl[:, -3:] = f
    x1 = solve_coupled_direct(system, coupled_load(system, w, line_loads={"s": fl}), w)
    fb = (rigid_link_matrix(r).T @ f)[None].repeat(w.size, 0)
    x2 = solve_coupled_direct(system, coupled_load(system, w, body_loads={"heavy": fb}), w)
    np.testing.assert_allclose(x1, x2, rtol=1e-12, atol=1e-15)  # same linear system


# ----------------------------------------------------- symmetry and reciprocity


def _two_line_system(symmetric=True, tables=False):
    z = 0.7
    body_kw = {}
    if tables:
        tw = np.array([0.1, 1.0, 3.0])
        A = np.array(
            [np.diag([500.0, 500.0, 800.0, 300.0, 300.0, 100.0]) * s for s in (1.2, 1.0, 0.8)]
        )
        A[:, 0, 4] = A[:, 4, 0] = 40.0
        Bt = np.array([np.diag([5.0, 5.0, 80.0, 3.0, 3.0, 1.0]) * s for s in (0.1, 1.0, 0.3)])
        body_kw = dict(added_mass=FrequencyTable(tw, A), radiation_damping=FrequencyTable(tw, Bt))
    body = RigidBody(
        "buoy",
        [0.0, 0.0, 0.0],
        800.0,
        inertia=np.diag([300.0, 300.0, 200.0]),
        cog=[0.0, 0.0, -0.3],
        hydrostatic_stiffness=np.diag([0, 0, 2e4, 5e3, 5e3, 0]),
        **body_kw,
    )
    m1 = _string_model([-30.0, 0, z], [-1.0, 0, z], 6, 5.0e3, 2.0, 1.0e7)
    links = [LineLink("left", m1, end_b="buoy", damping=0.05 * (m1.M + m1.Ma) + 1e-3 * m1.K)]
    if symmetric:
        m2 = _string_model([30.0, 0, z], [1.0, 0, z], 6, 5.0e3, 2.0, 1.0e7)
        links.append(LineLink("right", m2, end_b="buoy", damping=0.05 * (m2.M + m2.Ma)))
    return couple(links, [body])


def _two_line_system_fixed(fixed=(), penalty=0.0):
    """The symmetric two-line system of _two_line_system(tables=True) with body DOFs
    held by ``fixed_dofs`` or by a ``penalty`` spring on those DOFs instead."""
    import dataclasses

    s = _two_line_system(tables=True)
    body = s.bodies[0]
    names = list(body.dof_names)
    extra = np.zeros((6, 6))
    for d in fixed:
        extra[names.index(d), names.index(d)] = penalty
    new = dataclasses.replace(
        body, fixed_dofs=() if penalty else tuple(fixed), extra_stiffness=extra
    )
    links = [LineLink(ln.name, ln.model, end_b="buoy", damping=ln.damping) for ln in s.lines]
    return couple(links, [new])


@pytest.mark.parametrize("method", ["schur", "dense"])
def test_fixed_dofs_are_constraints_in_the_monolithic_solve(method):
    """Body heave and pitch held by fixed_dofs: exactly zero motion, and the other DOFs
    and the lines equal the limit of a stiff spring on those DOFs (an independent
    method). A spring k_p leaves a motion O(F/k_p): with k_p = 1e12 N/m against
    line/body stiffnesses ≤ 1e7, the difference is ≤ 1e-5 of the response."""
    fixed = ("heave", "pitch")
    s = _two_line_system_fixed(fixed)
    p = _two_line_system_fixed(fixed, penalty=1e12)
    w = np.array([0.3, 1.3, 2.6])
    rng = np.random.default_rng(5)
    F = rng.standard_normal((w.size, s.n_dof)) + 1j * rng.standard_normal((w.size, s.n_dof))
    x = solve_coupled_direct(s, F, w, method=method)
    xp = solve_coupled_direct(p, F, w, method=method)
    rows = [int(s.body_dofs["buoy"][list(s.bodies[0].dof_names).index(d)]) for d in fixed]
    assert np.all(x[:, rows] == 0.0)
    np.testing.assert_allclose(x, xp, atol=1e-5 * np.abs(x).max())
    # and the constraint changed the answer (the test can fail)
    free = solve_coupled_direct(_two_line_system(tables=True), F, w, method=method)
    assert np.abs(free - x).max() > 1e-2 * np.abs(x).max()


def test_coupled_matrices_symmetric_when_moments_balance():
    """Symmetric two-line mooring (Σ r × F = 0): K, M, C symmetric; one line alone
    leaves the moment r × F unbalanced and K is not symmetric (the check can fail)."""
    s = _two_line_system()
    for a in (s.K, s.M, s.C):
        # round-off
        assert abs(a - a.T).max() <= 1e-12 * abs(a).max()
    assert s.asymmetry() < 1e-14
    one = _two_line_system(symmetric=False)
    assert one.asymmetry() > 1e-6


def test_reciprocity_and_schur_equals_dense():
    """Maxwell–Betti: H(ω) = Z(ω)⁻¹ symmetric for a symmetric system, with A(ω), B(ω)
    tables; the Schur and dense solves agree."""
    s = _two_line_system(tables=True)
    w = np.array([0.3, 1.3, 2.6])
    n = s.n_dof
    F = np.broadcast_to(np.eye(n, dtype=complex), (w.size, n, n)).copy()
    h1 = solve_coupled_direct(s, F, w, method="schur")
    h2 = solve_coupled_direct(s, F, w, method="dense")
    scale = np.abs(h2).max()
    # two factorizations of the same well-conditioned matrices: round-off
    np.testing.assert_allclose(h1, h2, atol=1e-9 * scale)
    np.testing.assert_allclose(h2, np.swapaxes(h2, 1, 2), atol=1e-9 * scale)
    # the tables entered: frozen at ω_ref, the constant matrices reproduce ω_ref only
    K, MT, CT = constant_matrices(s, 1.3)
    Z = (K - 1.3**2 * MT + 1.3j * CT).toarray()
    np.testing.assert_allclose(np.linalg.inv(Z), h2[1], atol=1e-9 * scale)
    Z0 = (K - 0.3**2 * MT + 0.3j * CT).toarray()
    assert np.abs(np.linalg.inv(Z0) - h2[0]).max() > 1e-3 * np.abs(h2[0]).max()


# --------------------------------------- geometric stiffness by finite differences


def _hanging_line(att, planar):
    env = Environment(depth=500.0)
    line = Line(
        name="leg",
        end_a={"position": [-60.0, 0.0, -80.0]},
        end_b={"position": list(att)},
        segments=[{"length": 110.0, "ea": 5.0e7, "mass": 40.0, "diameter": 0.08, "elements": 12}],
    )
    mesh = mesh_line(line, env.rho, env.g)
    return env, mesh


def _end_force(env, mesh, xb):
    ls = solve_line_statics(
        dataclasses.replace(mesh, end_b=np.asarray(xb, float)), env, method="fe", tolerance=1e-13
    )
    return ls.force_b


@pytest.mark.parametrize("planar", [False, True])
def test_geometric_stiffness_matches_statics_finite_differences(planar):
    """Body held by a hanging line at a point r not parallel to the end force: the
    body stiffness condensed from the coupled K (Schur complement over the line DOFs)
    equals −dQ/dq, Q = [F; (R r) × F], by central differences of the line statics at
    displaced and rotated body poses.  Without the −[F]×[r]× term it does not."""
    X = np.array([5.0, 0.0, -4.0])
    r = np.array([1.5, 0.0, -2.5]) if planar else np.array([1.5, 0.8, -2.5])
    env, mesh = _hanging_line(X + r, planar)
    ls = solve_line_statics(mesh, env, method="fe", tolerance=1e-13)
    model = build_fe_model(ls, env, dim=2 if planar else 3)
    body = RigidBody("b", X, 1.0, planar=planar)
    idx = [0, 2, 4] if planar else list(range(6))

    def condensed(geo):
        s = couple(
            [LineLink("leg", model, end_b="b", force_b=ls.force_b)], [body], geometric_stiffness=geo
        )
        K = s.K.toarray()
        f, b = s.line_dofs["leg"], s.body_dofs["b"]
        return K[np.ix_(b, b)] - K[np.ix_(b, f)] @ np.linalg.solve(K[np.ix_(f, f)], K[np.ix_(f, b)])

    def Q(q6):
        arm = Rotation.from_rotvec(q6[3:]).apply(r)
        F = _end_force(env, mesh, X + q6[:3] + arm)
        return np.concatenate([F, np.cross(arm, F)])

    h = np.array([1e-3, 1e-3, 1e-3, 1e-4, 1e-4, 1e-4])
    K_fd = np.zeros((6, 6))
    for j in idx:
        e = np.zeros(6)
        e[j] = h[j]
        K_fd[:, j] = -(Q(e) - Q(-e)) / (2 * h[j])
    K_fd = K_fd[np.ix_(idx, idx)]
    K_c = condensed(True)
    scale = np.abs(K_fd).max()
    # statics solved to 1e-13 of the reference force; central-difference steps give
    # truncation (h/line length)² ~ 1e-10 and noise ~1e-13·F/h ≈ 1e-8·scale
    np.testing.assert_allclose(K_c, K_fd, atol=1e-5 * scale)
    geo = attachment_geometric_stiffness(ls.force_b, r, planar)
    assert np.abs(geo).max() > 1e-2 * scale  # the term matters here
    assert np.abs(condensed(False) - K_fd).max() > 100 * 1e-5 * scale


def test_geometric_stiffness_formula():
    """−[F]×[r]× = (F·r)I − r Fᵀ; planar entry F_x r_x + F_z r_z; pendulum stable."""
    F = np.array([3.0, -1.0, 2.0])
    r = np.array([0.5, 2.0, -1.0])
    k = attachment_geometric_stiffness(F, r)
    sF = np.array([[0, -F[2], F[1]], [F[2], 0, -F[0]], [-F[1], F[0], 0]])
    sr = np.array([[0, -r[2], r[1]], [r[2], 0, -r[0]], [-r[1], r[0], 0]])
    np.testing.assert_allclose(k[3:, 3:], -sF @ sr, rtol=1e-15)
    assert np.abs(k[:3]).max() == 0 and np.abs(k[:, :3]).max() == 0
    kp = attachment_geometric_stiffness(F, r, planar=True)
    assert kp[2, 2] == pytest.approx(F[0] * r[0] + F[2] * r[2], rel=1e-15)
    # a body hanging from a line above its reference: F up, r up -> restoring pitch
    assert attachment_geometric_stiffness([0, 0, 100.0], [0, 0, 2.0], planar=True)[2, 2] == 200.0


# --------------------------------------------------------- excitation, drag


def test_excitation_interpolation_heading_wrap_and_phase():
    w = np.array([0.5, 1.0, 2.0])
    hd = np.radians([0.0, 90.0, 180.0, 270.0])
    vals = np.zeros((4, 6, 3), complex)
    for i in range(4):
        vals[i, 2] = (i + 1) * np.array([1.0, 2.0, 4.0]) * (1 + 1j)
    body = _diag_body(excitation=ExcitationTable(w, hd, vals), position=[30.0, 10.0, 0.0])
    f = body_excitation(body, [0.75, 1.5], math.radians(45.0))
    # halfway in heading (1 and 2 -> 1.5), linear in ω (1.5 and 3)
    np.testing.assert_allclose(f[:, 2], 1.5 * np.array([1.5, 3.0]) * (1 + 1j), rtol=1e-14)
    # wrap-around between 270 and 360 deg: halfway between 4 and 1
    f = body_excitation(body, [1.0], math.radians(315.0))
    assert f[0, 2] == pytest.approx(2.5 * 2.0 * (1 + 1j), rel=1e-14)
    # global phase at the reference point: P = exp(−ik(x cos β + y sin β))
    k = np.array([0.1, 0.4])
    f0 = body_excitation(body, [0.75, 1.5], 0.0)
    f1 = body_excitation(body, [0.75, 1.5], 0.0, wavenumber=k)
    np.testing.assert_allclose(f1, f0 * np.exp(-1j * k * 30.0)[:, None], rtol=1e-14)


def test_excitation_and_table_errors():
    w = np.array([0.5, 1.0])
    table = ExcitationTable(w, np.radians([0.0, 30.0]), np.ones((2, 6, 2)))
    with pytest.raises(InputError, match=r"heading = 90.* outside the excitation table"):
        table.at(w, math.radians(90.0))
    with pytest.raises(InputError, match=r"omega = 2.*outside the table \[0.5, 1\]"):
        table.at([2.0], 0.0)
    held = FrequencyTable(w, np.ones((2, 6, 6)), extrapolation="hold")
    np.testing.assert_array_equal(held.at([3.0])[0], np.ones((6, 6)))
    with pytest.raises(InputError, match=r"values .* must have shape \(2, d, d\)"):
        FrequencyTable(w, np.ones((3, 6, 6)))
    with pytest.raises(InputError, match=r"inertia .* must be symmetric"):
        RigidBody("b", [0, 0, 0], 1.0, inertia=[[1, 2, 0], [0, 1, 0], [0, 0, 1]])
    with pytest.raises(InputError, match=r"added_mass .* must be a \(3, 3\) or \(6, 6\)"):
        RigidBody("b", [0, 0, 0], 1.0, added_mass=np.eye(4), planar=True)


def test_body_drag_damping_seed_form_and_arm():
    """Zero-mean: b = √(8/π)·½ρ CdA σ per direction (seed eq. 5.2.2), carried to the
    reference point by the arm of the drag point."""
    body = _diag_body(drag_area=[2.0, 0.0, 1.0], drag_point=[0.0, 0.0, -3.0], planar=True)
    sig = np.array([0.4, 0.0, 0.2])
    c = body_drag_damping(body, RHO, sig)
    bx = math.sqrt(8 / math.pi) * 0.5 * RHO * 2.0 * 0.4
    bz = math.sqrt(8 / math.pi) * 0.5 * RHO * 1.0 * 0.2
    expected = np.array([[bx, 0.0, -3.0 * bx], [0.0, bz, 0.0], [-3.0 * bx, 0.0, 9.0 * bx]])
    np.testing.assert_allclose(c, expected, rtol=1e-14)


# ----------------------------------------------------------------- error paths


def test_couple_errors():
    model = _string_model([0, 0, 0], [10, 0, 0], 3, 100.0, 1.0, 1e5)
    body = _diag_body()
    with pytest.raises(InputError, match=r"lines\[s\]\.end_b = 'nobody'.*is not a body"):
        couple([LineLink("s", model, end_b="nobody")], [body])
    with pytest.raises(InputError, match="body names must be unique"):
        couple([], [body, body])
    with pytest.raises(InputError, match="a 3-D line model needs a 6-DOF body"):
        couple([LineLink("s", model, end_b="b")], [_diag_body(planar=True)])
    free_end = assemble(model.mesh, model.positions, model.tension, RHO, fixed_nodes=(0,))
    with pytest.raises(InputError, match="the end node is free in the model"):
        couple([LineLink("s", free_end, end_b="b")], [body])


def test_undamped_resonance_raises():
    body = _diag_body(
        planar=True, mass=1.0, inertia=np.eye(3), hydrostatic_stiffness=np.diag([4.0, 4.0, 4.0])
    )
    s = couple([], [body])
    with pytest.raises(SolverError, match="omega = 2 rad/s"):
        solve_coupled_direct(s, np.ones((1, 3)), [2.0])


def test_end_force_from_model_matches_statics():
    """Without current, the end force couple() derives from the model (end element
    tension + weight lumped on the end node) is the statics' force_b."""
    X = np.array([5.0, 0.0, -4.0])
    r = np.array([1.5, 0.8, -2.5])
    env, mesh = _hanging_line(X + r, False)
    ls = solve_line_statics(mesh, env, method="fe", tolerance=1e-13)
    model = build_fe_model(ls, env, dim=3)
    body = RigidBody("b", X, 1.0)
    given = couple([LineLink("leg", model, end_b="b", force_b=ls.force_b)], [body])
    derived = couple([LineLink("leg", model, end_b="b")], [body], g=env.g)
    # statics converged to 1e-13 of the reference force
    np.testing.assert_allclose(
        derived.geometric["b"], given.geometric["b"], atol=1e-9 * np.abs(given.geometric["b"]).max()
    )
