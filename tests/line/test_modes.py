"""Natural modes (stochcable.line.modes) against closed forms and an independent ODE solution.

References
----------
- Bliet (1984) eq. 3.5: taut string, ω_n = nπ/L √(T/m); axial √(EA/m) nπ/L.
- Bliet 1984 eq. 3.9: hanging chain with a free lower end, J0(2ω√(L/g)) = 0.
- Bliet 1984 eqs. 3.78–3.79 (Irvine & Caughey 1974): horizontal shallow-sag elastic
  cable, antisymmetric kL/2 = nπ, symmetric tan(kL/2) = kL/2 − (4/λ²)(kL/2)³.
- Bliet 1984 §7.3, Table 7-II: the inclined guy, checked against a shooting solution of
  the linear cable equations about the elastic catenary computed here.
"""

from __future__ import annotations

import numpy as np
import pytest
from fem_cases import hanging_chain, shallow_parabola, taut_string, uniform_mesh
from scipy.integrate import solve_ivp
from scipy.optimize import brentq, fsolve
from scipy.special import jn_zeros

from stochcable.errors import InputError
from stochcable.line.fem import assemble
from stochcable.line.modes import Modes, natural_modes

# one worker runs the module: its module fixtures run once (--dist loadgroup)
pytestmark = pytest.mark.xdist_group("test_modes")

# Bliet 1984, §7.2 string (T = 1.0e6 N, m = 48.7 kg/m, L = 1036.32 m), eq. 3.5 values
# (the thesis prints 0.434, 0.861: 0.861 is a misprint of nπ/L√(T/m) = 0.8688).
BLIET_1984_EQ_3_5 = (0.4344, 0.8688, 1.3032)
BLIET_1984_STRING = {"tension": 1.0e6, "mass": 48.7, "length": 1036.32}
# Bliet 1984 eq. 3.9 table (Hildebrand 1949): ω√(L/g) of the hanging chain.
BLIET_1984_EQ_3_9 = (1.204, 2.760, 4.327, 5.896, 7.465)
# Bliet 1984 §7.3 guy data and static results (Fig. 7-7).  The printed net weight
# 494.98 N/m is a misprint: T_top − T_bot = w·depth (to 1e-5) and the printed static
# angles and Δx are reproduced with w = 414.98 N/m (checked in test_guy_statics).
BLIET_1984_GUY = {
    "t_top": 1.332e6,
    "t_bot": 1155096.0,
    "ea": 1.30e9,
    "length": 1036.32,
    "depth": 426.70,
    "mass": 48.7,
    "added_mass": 6.3,
    "weight": 414.98,
    "diameter": 0.0889,
}
BLIET_1984_GUY_STATICS = {"phi_top_deg": 33.056, "phi_bot_deg": 14.874, "dx": 940.68}
# Bliet 1984 Table 7-II: in-plane eigenfrequencies of the guy [rad/s] and shapes.
BLIET_1984_TABLE_7_II = (0.9011, 1.1949, 1.6086, 1.8228, 2.3115, 2.7527, 3.2335, 3.7059)
BLIET_1984_TABLE_7_II_SHAPE = ("anti", "sym", "sym", "anti", "sym", "anti", "sym", "anti")

RHO = 1025.0
G = 9.80665


# ----------------------------------------------------------------- taut string


def _string_modes(n_el, dim=3, ea=1.0e12, count=6, **kw):
    p = BLIET_1984_STRING
    mesh, pos, ten = taut_string(n_el, p["length"], p["tension"], p["mass"], ea)
    model = assemble(mesh, pos, ten, RHO, dim=dim, **kw)
    return model, natural_modes(model, count=count, added_mass=False)


def test_taut_string_matches_bliet_eq_3_5():
    _, m = _string_modes(200, dim=2, count=3)
    # 200 elements: consistent-mass error (kh)²/24 <= 9.3e-5 relative (1.2e-4 rad/s)
    # at n = 3; the printed references have 4 decimals (rounding 5e-5 rad/s).
    np.testing.assert_allclose(m.omega, BLIET_1984_EQ_3_5, atol=1.8e-4)
    assert m.method == "dense"


def test_taut_string_converges_at_second_order():
    p = BLIET_1984_STRING
    exact = np.arange(1, 4) * np.pi / p["length"] * np.sqrt(p["tension"] / p["mass"])
    err = [(_string_modes(n, dim=2, count=3)[1].omega - exact) / exact for n in (20, 40, 80)]
    # consistent mass converges from above at O(h²): the error falls by 4 per doubling
    # (2.5 % tolerance: the O(h⁴) remainder at 20 elements, mode 3, (kh)² ≈ 0.2).
    assert all((e > 0).all() for e in err)
    for coarse, fine in zip(err[:-1], err[1:]):
        np.testing.assert_allclose(coarse / fine, 4.0, rtol=0.025)


def test_lumped_mass_converges_from_below():
    p = BLIET_1984_STRING
    exact = np.arange(1, 4) * np.pi / p["length"] * np.sqrt(p["tension"] / p["mass"])
    _, lumped = _string_modes(40, dim=2, count=3, mass_matrix="lumped")
    _, consistent = _string_modes(40, dim=2, count=3)
    # lumped under-, consistent over-estimates by the same (kh)²/24 at leading order
    assert (lumped.omega < exact).all() and (consistent.omega > exact).all()
    np.testing.assert_allclose(lumped.omega - exact, -(consistent.omega - exact), rtol=0.02)


def test_string_in_plane_and_out_of_plane_modes_are_equal():
    _, m = _string_modes(60, dim=3, count=6)
    inp = m.omega[m.plane == "in-plane"]
    out = m.omega[m.plane == "out-of-plane"]
    assert inp.size == out.size == 3
    # the two transverse problems are identical matrices: equal to round-off
    np.testing.assert_allclose(inp, out, rtol=1e-12)
    np.testing.assert_allclose(m.out_of_plane[m.plane == "in-plane"], 0.0, atol=1e-12)


def test_string_in_an_oblique_vertical_plane_is_classified():
    p = BLIET_1984_STRING
    mesh, pos, ten = taut_string(
        40, p["length"], p["tension"], p["mass"], 1e12, direction=(1.0, 0.7, 0.5)
    )
    m = natural_modes(assemble(mesh, pos, ten, RHO), count=6, added_mass=False)
    # the line's plane is rotated 35° about z: the pairs still split cleanly
    assert sorted(m.plane.tolist()) == ["in-plane"] * 3 + ["out-of-plane"] * 3
    # equal up to the eigensolver's round-off: dense eigh errs by ~ε·λ_max in λ, and
    # λ_max/λ_1 ~ 1e8 here (EA/T = 1e6): 1e-6 relative is far below the FE error
    np.testing.assert_allclose(m.omega[0::2], m.omega[1::2], rtol=1e-6)


def test_string_axial_modes():
    p = BLIET_1984_STRING
    ea = 1.0e8  # axial modes low enough to list: √(EA/m) π/L ≈ 4.4 rad/s
    mesh, pos, ten = taut_string(200, p["length"], p["tension"], p["mass"], ea)
    model = assemble(mesh, pos, ten, RHO, dim=2)
    m = natural_modes(model, count=80, added_mass=False)
    axial_share = np.array(
        [np.sum(m.shapes[0::2, j] ** 2) / np.sum(m.shapes[:, j] ** 2) for j in range(m.count)]
    )
    axial = m.omega[axial_share > 0.999][:3]
    ref = np.arange(1, 4) * np.pi / p["length"] * np.sqrt(ea / p["mass"])
    # 200 elements: O((kh)²/24) <= 6e-5 for n <= 3
    np.testing.assert_allclose(axial, ref, rtol=1e-4)


def test_large_ea_over_t_keeps_low_modes_accurate():
    # EA/T = 1e6: axial modes ~1000× above the transverse ones; the transverse modes
    # must not lose accuracy to the stiffness contrast (condition number ~1e6 n²).
    _, m = _string_modes(200, dim=3, ea=1.0e12, count=6)
    p = BLIET_1984_STRING
    exact = np.repeat(np.arange(1, 4), 2) * np.pi / p["length"] * np.sqrt(p["tension"] / p["mass"])
    # FE error (kh)²/24 at 200 elements <= 6e-5; any round-off loss would show above it
    np.testing.assert_allclose(m.omega, exact, rtol=1e-4)
    fe_error = (m.omega - exact) / exact
    np.testing.assert_allclose(
        fe_error, (np.repeat(np.arange(1, 4), 2) * np.pi / 200) ** 2 / 24, rtol=0.01
    )


# ----------------------------------------------------------------- hanging chain


def test_hanging_chain_matches_bessel_zeros():
    length, mass = 100.0, 10.0
    ref = jn_zeros(0, 5) / 2.0
    # the thesis's table agrees to its 3 decimals except the first entry: j_0,1/2 =
    # 1.20241, printed 1.204 (a rounding misprint of 1.202)
    np.testing.assert_allclose(ref[1:], BLIET_1984_EQ_3_9[1:], atol=6e-4)
    assert ref[0] == pytest.approx(BLIET_1984_EQ_3_9[0], abs=2e-3)
    mesh, pos, ten = hanging_chain(100, length, mass, G, ea=1.0e12)
    model = assemble(mesh, pos, ten, RHO, dim=3, fixed_nodes=(0,))
    m = natural_modes(model, count=10, added_mass=False)
    x_modes = m.omega[m.plane == "in-plane"] * np.sqrt(length / G)
    y_modes = m.omega[m.plane == "out-of-plane"] * np.sqrt(length / G)
    # 100 elements: O(h²) FE error 3e-6 … 1.2e-3 for modes 1 … 4, 2.2e-3 at mode 5
    np.testing.assert_allclose(x_modes, ref, rtol=3e-3)
    np.testing.assert_allclose(x_modes, y_modes, rtol=1e-12)


# -------------------------------------------------------- Irvine–Caughey cable


def _irvine_symmetric(lam2: float, n: int) -> np.ndarray:
    """Roots x = kL/2 of tan x = x − (4/λ²) x³, one per branch of tan (Bliet eq. 3.79).

    g(x) = tan x − x + (4/λ²)x³ increases strictly on each branch ((2j−1)π/2,
    (2j+1)π/2) from −∞ to +∞, and has no root in (0, π/2): exactly one root per branch.
    """
    c = 4.0 / lam2
    eps = 1e-12
    return np.array(
        [
            brentq(
                lambda x: np.tan(x) - x + c * x**3,
                (2 * j - 1) * np.pi / 2 + eps,
                (2 * j + 1) * np.pi / 2 - eps,
                xtol=1e-14,
            )
            for j in range(1, n + 1)
        ]
    )


def _symmetry(model, shapes):
    """+1 for a symmetric vertical displacement about midspan, −1 antisymmetric."""
    z = shapes[model.dof(0, "z") :: model.dim]
    return np.sign(np.einsum("ij,ij->j", z, z[::-1]))


SPAN, H_IRVINE, SAG = 100.0, 1.0e5, 0.01


@pytest.mark.parametrize(
    "lam2", [1.0, 4 * np.pi**2 - 1, 4 * np.pi**2, 4 * np.pi**2 + 1, 100.0, 1000.0]
)
def test_irvine_caughey_shallow_sag(lam2):
    n_el = 200
    w = 8 * H_IRVINE * SAG / SPAN  # parabola: d = w L²/(8H)
    m = w / G
    mesh, pos, ten = shallow_parabola(n_el, SPAN, SAG, H_IRVINE, m, G, ea=1.0)
    dx = SPAN / n_el
    le = np.sum(mesh.l0**3 / dx**2)  # Irvine's L_e = ∫ (ds/dx)³ dx
    ea = lam2 * H_IRVINE * le / SPAN / (w * SPAN / H_IRVINE) ** 2
    mesh, pos, ten = shallow_parabola(n_el, SPAN, SAG, H_IRVINE, m, G, ea=ea)
    model = assemble(mesh, pos, ten, RHO, dim=2)
    modes = natural_modes(model, count=8, added_mass=False)

    c = np.sqrt(H_IRVINE / m)
    w_sym = 2 * _irvine_symmetric(lam2, 4) / SPAN * c
    w_anti = 2 * np.arange(1, 5) * np.pi / SPAN * c
    theory = sorted([(w, 1) for w in w_sym] + [(w, -1) for w in w_anti])
    # window below the 5th theoretical mode (+ half a spacing): same count, same types
    top = 0.5 * (theory[5][0] + theory[4][0])
    fe_w = modes.omega[modes.omega < top]
    fe_sym = _symmetry(model, modes.shapes)[modes.omega < top]
    assert fe_w.size == 5, "a mode is missing or spurious in the window"
    assert fe_sym.tolist() == [t for _, t in theory[:5]]
    # Shallow-sag theory neglects O(8(d/L)²) ≈ 8e-4 (tension variation, mass per
    # horizontal length); FE error (kh)²/24 <= 1e-4 for these modes at 200 elements.
    np.testing.assert_allclose(fe_w, [w for w, _ in theory[:5]], rtol=1.5e-3)


def test_irvine_crossover_not_degenerate_in_count():
    # At λ² = 4π² the first symmetric and antisymmetric modes coincide in theory; the
    # solver must return both (not one twice) and they must be the two shapes.
    n_el = 120
    w = 8 * H_IRVINE * SAG / SPAN
    m = w / G
    mesh, pos, ten = shallow_parabola(n_el, SPAN, SAG, H_IRVINE, m, G, ea=1.0)
    le = np.sum(mesh.l0**3 / (SPAN / n_el) ** 2)
    ea = 4 * np.pi**2 * H_IRVINE * le / SPAN / (w * SPAN / H_IRVINE) ** 2
    mesh, pos, ten = shallow_parabola(n_el, SPAN, SAG, H_IRVINE, m, G, ea=ea)
    model = assemble(mesh, pos, ten, RHO, dim=2)
    for method in ("dense", "banded", "sparse"):
        md = natural_modes(model, count=4, added_mass=False, method=method)
        assert sorted(_symmetry(model, md.shapes[:, :2]).tolist()) == [-1, 1], method
        # M-orthonormal: no duplicated vector
        mt = model.partition("M")[0].toarray()
        phi = md.shapes[model.free]
        np.testing.assert_allclose(phi.T @ mt @ phi, np.eye(4), atol=1e-9)


# ------------------------------------------------------------ Bliet's inclined guy


def _guy_catenary():
    """Elastic catenary of the guy, anchor at s = 0: H, V_a (solved from T_top, depth)."""
    p = BLIET_1984_GUY
    w, ea, length = p["weight"], p["ea"], p["length"]

    def z_top(h):
        va = np.sqrt(p["t_top"] ** 2 - h**2) - w * length
        return (p["t_top"] - np.hypot(h, va)) / w + (va * length + w * length**2 / 2) / ea

    h = brentq(lambda h: z_top(h) - p["depth"], 5e5, 1.3e6, xtol=1e-9)
    return h, np.sqrt(p["t_top"] ** 2 - h**2) - w * length


def _guy_shape(h, va, s):
    p = BLIET_1984_GUY
    w, ea = p["weight"], p["ea"]
    v = va + w * s
    x = h / w * (np.arcsinh(v / h) - np.arcsinh(va / h)) + h * s / ea
    z = (np.hypot(h, v) - np.hypot(h, va)) / w + (va * s + w * s**2 / 2) / ea
    return x, z, np.hypot(h, v)


def test_guy_statics_reproduce_bliet_fig_7_7():
    p = BLIET_1984_GUY

    # w from three printed numbers (T_top, T_bot, depth) with H, V_a unknown
    def eqs(q):
        h, va, w = q
        v = va + w * p["length"]
        z = (np.hypot(h, v) - np.hypot(h, va)) / w + (
            va * p["length"] + w * p["length"] ** 2 / 2
        ) / p["ea"]
        return [
            np.hypot(h, v) / p["t_top"] - 1,
            np.hypot(h, va) / p["t_bot"] - 1,
            z / p["depth"] - 1,
        ]

    w = fsolve(eqs, [1.1e6, 2e5, 450.0], xtol=1e-13)[2]
    assert w == pytest.approx(p["weight"], abs=0.01)  # not the printed 494.98
    h, va = _guy_catenary()
    x, _, _ = _guy_shape(h, va, p["length"])
    s = BLIET_1984_GUY_STATICS
    assert x == pytest.approx(s["dx"], abs=0.01)  # printed to 0.01 m
    assert np.degrees(np.arctan2(va, h)) == pytest.approx(s["phi_bot_deg"], abs=1e-3)
    vt = va + p["weight"] * p["length"]
    assert np.degrees(np.arctan2(vt, h)) == pytest.approx(s["phi_top_deg"], abs=1e-3)


@pytest.fixture(scope="module")
def guy_shooting():
    """Eigenfrequencies of the linear cable equations about the catenary, by shooting.

    Per unstretched arc length s, with static tension vector F = (H, V_a + w s),
    T = |F|, t = F/T, dynamic displacement u and tension-vector perturbation f:

        u' = (1/T + 1/EA) f − (t·f) t / T,      f' = −ω² [m u + m_a (u − (t·u) t)],

    u(0) = u(L) = 0.  In-plane (u, f in x–z): two shots with f(0) = e_x, e_z, roots of
    det[u_1(L), u_2(L)].  Out-of-plane (Sturm–Liouville ((T/(1+ε)) v')' + (m+m_a)ω²v =
    0): roots of v(L).  DOP853 at rtol 1e-11; roots bracketed on a 0.1 rad/s scan
    (roots are >= 0.29 rad/s apart) and refined with brentq.
    """
    p = BLIET_1984_GUY
    h, va = _guy_catenary()
    w, ea, length, m, ma = p["weight"], p["ea"], p["length"], p["mass"], p["added_mass"]

    def rhs_in(s, y, om):
        f0 = np.array([h, va + w * s])
        tt = np.hypot(*f0)
        t = f0 / tt
        out = np.empty(8)
        for j in (0, 4):
            u, f = y[j : j + 2], y[j + 2 : j + 4]
            out[j : j + 2] = (1 / tt + 1 / ea) * f - (t @ f) * t / tt
            out[j + 2 : j + 4] = -(om**2) * (m * u + ma * (u - (t @ u) * t))
        return out

    def det_in(om):
        y0 = np.array([0, 0, 1, 0, 0, 0, 0, 1.0])
        y = solve_ivp(
            rhs_in, (0, length), y0, args=(om,), method="DOP853", rtol=1e-11, atol=1e-14
        ).y[:, -1]
        return y[0] * y[5] - y[1] * y[4]

    def v_out(om):
        def rhs(s, y):
            tt = np.hypot(h, va + w * s)
            return [(1 / tt + 1 / ea) * y[1], -(om**2) * (m + ma) * y[0]]

        return solve_ivp(rhs, (0, length), [0.0, 1.0], method="DOP853", rtol=1e-11, atol=1e-14).y[
            0, -1
        ]

    def roots(fun, grid):
        vals = [fun(o) for o in grid]
        return np.array(
            [
                brentq(fun, grid[i], grid[i + 1], xtol=1e-13)
                for i in range(grid.size - 1)
                if np.sign(vals[i]) != np.sign(vals[i + 1])
            ]
        )

    grid = np.arange(0.05, 3.85, 0.1)
    return {"in": roots(det_in, grid), "out": roots(v_out, grid), "h": h, "va": va}


def _guy_model(n_el, h, va, dim=3):
    p = BLIET_1984_GUY
    s = np.linspace(0.0, p["length"], n_el + 1)
    x, z, _ = _guy_shape(h, va, s)
    mid = 0.5 * (s[1:] + s[:-1])
    tension = np.hypot(h, va + p["weight"] * mid)
    area = np.pi * p["diameter"] ** 2 / 4
    mesh = uniform_mesh(
        n_el,
        np.diff(s),
        p["ea"],
        p["mass"],
        diameter=p["diameter"],
        ca_normal=p["added_mass"] / (RHO * area),
    )
    pos = np.column_stack([x, np.zeros_like(x), z])
    return assemble(mesh, pos, tension, RHO, dim=dim)


def test_guy_against_shooting_solution(guy_shooting):
    ref_in, ref_out = guy_shooting["in"][:8], guy_shooting["out"][:8]
    assert ref_in.size == ref_out.size == 8
    model = _guy_model(200, guy_shooting["h"], guy_shooting["va"])
    m = natural_modes(model, count=16)
    fe_in = m.omega[m.plane == "in-plane"]
    fe_out = m.omega[m.plane == "out-of-plane"]
    # 200 elements: consistent-mass error ≈ (kh)²/24 <= 6.6e-4 at the 8th mode
    np.testing.assert_allclose(fe_in, ref_in, rtol=8e-4)
    np.testing.assert_allclose(fe_out, ref_out, rtol=8e-4)
    assert ((fe_in - ref_in) > 0).all()  # consistent mass: from above


def test_guy_bliet_table_7_ii_runs_high(guy_shooting):
    """Table 7-II (explicit centred differences on a coarse grid, Bliet §3.9/§7.3) is
    0.2 % (mode 1) to 2.2 % (mode 8) above the converged in-plane frequencies: a
    discretization error growing with the mode number, as a coarse grid's does.  The
    symmetric/antisymmetric labels of the table are reproduced."""
    ref = guy_shooting["in"][:8]
    excess = np.asarray(BLIET_1984_TABLE_7_II) / ref - 1.0
    assert (excess > 0.001).all() and (excess < 0.023).all()
    assert (np.diff(excess[3:]) > 0).all()  # grows with the mode number
    model = _guy_model(100, guy_shooting["h"], guy_shooting["va"])
    m = natural_modes(model, count=16)
    inplane = m.shapes[:, m.plane == "in-plane"][:, :8]
    # symmetry of the displacement normal to the chord, about mid-length
    chord = model.positions[-1] - model.positions[0]
    nrm = np.cross(chord / np.linalg.norm(chord), m.normal)
    un = np.einsum("c,ncj->nj", nrm, inplane.reshape(model.n_nodes, 3, -1))
    label = np.where(np.einsum("ij,ij->j", un, un[::-1]) > 0, "sym", "anti")
    assert tuple(label) == BLIET_1984_TABLE_7_II_SHAPE


# ----------------------------------------------------------------- solver paths


def test_sparse_and_banded_paths_equal_dense_at_400_elements():
    h, va = _guy_catenary()
    model = _guy_model(400, h, va, dim=2)  # 798 free DOFs (2-D keeps the dense solve short)
    dense = natural_modes(model, count=30, method="dense")
    auto = natural_modes(model, count=30)
    assert auto.method == "banded"  # 798-DOF block: Lanczos path
    for method in ("banded", "sparse"):
        other = natural_modes(model, count=30, method=method)
        assert other.method == method
        # dense eigh's eigenvalue error is ~ε·λ_max (λ_max/λ_1 ~ 1e7 for EA/T = 1e3 and
        # 400 elements), ARPACK's is smaller: agreement to 1e-8, far below FE error
        np.testing.assert_allclose(other.omega, dense.omega, rtol=1e-8)
        # same shapes up to round-off (non-degenerate modes, deterministic sign)
        np.testing.assert_allclose(
            np.abs(
                other.shapes.T @ model.M @ dense.shapes + other.shapes.T @ model.Ma @ dense.shapes
            ),
            np.eye(30),
            atol=1e-6,
        )
        assert (other.plane == dense.plane).all()


def test_degenerate_pairs_kept_on_lanczos_path():
    # a straight 3-D string of 200 elements: every transverse frequency is double;
    # the Lanczos path must return each exactly twice
    _, dense = _string_modes(200, dim=3, count=20)
    model, _ = _string_modes(200, dim=3, count=1)
    for method in ("banded", "sparse"):
        m = natural_modes(model, count=20, added_mass=False, method=method)
        # round-off ~ε·λ_max/λ (EA/T = 1e6): see test_string_in_an_oblique_vertical_plane
        np.testing.assert_allclose(m.omega, dense.omega, rtol=1e-6)
        # each double frequency: one in-plane and one out-of-plane mode
        for j in range(0, 20, 2):
            assert sorted(m.plane[j : j + 2]) == ["in-plane", "out-of-plane"]


def test_mass_normalization_and_fixed_dofs_zero():
    model, m = _string_modes(30, dim=3, count=5)
    phi = m.shapes
    np.testing.assert_allclose(phi.T @ (model.M @ phi), np.eye(5), atol=1e-12)
    assert (phi[model.fixed] == 0).all()
    # Rayleigh quotient = ω²
    np.testing.assert_allclose(np.einsum("ij,ij->j", phi, model.K @ phi), m.omega**2, rtol=1e-10)


def test_added_mass_lowers_frequencies_by_mass_ratio():
    p = BLIET_1984_STRING
    mesh = uniform_mesh(50, p["length"] / 50, 1e12, p["mass"], diameter=0.0889, ca_normal=1.0)
    pos = np.linspace([0, 0, 0], [p["length"], 0, 0], 51)
    model = assemble(mesh, pos, np.full(50, p["tension"]), RHO, dim=3)
    dry = natural_modes(model, count=4, added_mass=False)
    wet = natural_modes(model, count=4, added_mass=True)
    ma = RHO * np.pi * 0.0889**2 / 4
    # transverse modes only (axial ones are far above): exact √(m/(m+ma)) scaling
    np.testing.assert_allclose(
        wet.omega / dry.omega, np.sqrt(p["mass"] / (p["mass"] + ma)), rtol=1e-12
    )


def test_document_and_period():
    _, m = _string_modes(20, dim=2, count=3)
    doc = m.to_document()
    assert set(doc) == {"omega", "period", "plane"}
    np.testing.assert_allclose(doc["period"], 2 * np.pi / m.omega)
    assert doc["plane"] == ["in-plane"] * 3
    assert isinstance(m, Modes)


def test_zero_frequency_period_is_none():
    mesh, pos, ten = taut_string(10, 10.0, 100.0, 1.0, 1e6)
    model = assemble(mesh, pos, ten, RHO, dim=2, fixed_nodes=())
    m = natural_modes(model, count=3, added_mass=False)
    assert m.to_document()["period"][0] is None


def test_error_paths():
    model, _ = _string_modes(10, dim=2, count=1)
    with pytest.raises(InputError, match=r"count = 0: must be an integer >= 1"):
        natural_modes(model, count=0)
    with pytest.raises(InputError, match="method = 'qr'.*must be auto, dense, banded or sparse"):
        natural_modes(model, method="qr")
    with pytest.raises(InputError, match="must be an FEModel"):
        natural_modes("model")


# ------------------------------------------------------------------ from a scene

# A weightless line between two points at one depth: the statics is a straight string
# with T = EA (span/L0 − 1); transverse modes nπ/L √(T L/((m + m_a) L0)) (Bliet eq. 3.5
# with the mass per stretched length, m·L0/L).
TAUT_SCENE = {
    "environment": {"depth": 500.0, "rho": 1025.0},
    "lines": [
        {
            "name": "taut",
            "end_a": {"position": [0.0, 0.0, -300.0]},
            "end_b": {"position": [400.0, 0.0, -300.0]},
            "segments": [
                {
                    "length": 399.6,
                    "ea": 1.0e9,
                    "mass": 50.0,
                    "diameter": 0.1,
                    "weight": 0.0,
                    "ca_normal": 1.0,
                    "elements": 100,
                }
            ],
        }
    ],
}


def taut_scene_reference(n: int = 3) -> np.ndarray:
    l0, span, ea = 399.6, 400.0, 1.0e9
    t = ea * (span / l0 - 1.0)
    mt = 50.0 + RHO * np.pi * 0.1**2 / 4
    return np.arange(1, n + 1) * np.pi / span * np.sqrt(t * span / (mt * l0))


def test_modes_of_scene_weightless_string():
    pytest.importorskip("stochcable.statics")
    from stochcable.statics import natural_modes as modes_of_scene

    m = modes_of_scene(TAUT_SCENE, count=6)["taut"]
    ref = np.repeat(taut_scene_reference(3), 2)
    # 100 elements: consistent-mass error (nπ/100)²/24 <= 3.7e-4 at n = 3
    np.testing.assert_allclose(m.omega, ref, rtol=4e-4)
    assert sorted(m.plane[:2]) == ["in-plane", "out-of-plane"]
    m2 = modes_of_scene(TAUT_SCENE, count=3, dim=2)["taut"]
    np.testing.assert_allclose(m2.omega, ref[::2], rtol=4e-4)
    assert (m2.plane == "in-plane").all()


@pytest.mark.parametrize("dim, rotate", [(2, False), (3, False), (3, True)])
def test_dense_blocks_and_sparse_blocks_give_the_same_modes(dim, rotate):
    """natural_modes takes the dense solver's blocks straight from the dense matrices
    when the line lies in the x–z plane (the speed pass of issue 4); the sparse slices
    (the path of a rotated plane, and of any line before) must give the same modes to
    the bit: a line rotated about z has the same frequencies to round-off, and the
    component grouping of dense and sparse matrices is the same."""
    from stochcable.line.modes import _component_groups

    mesh, pos, ten = shallow_parabola(
        12, SPAN, SAG, H_IRVINE, 8.0 * H_IRVINE * SAG / SPAN / G, G, ea=1e7
    )
    if rotate:
        c, s = np.cos(0.7), np.sin(0.7)
        pos = pos @ np.array([[c, s, 0.0], [-s, c, 0.0], [0.0, 0.0, 1.0]])
    model = assemble(mesh, pos, ten, RHO, dim=dim)
    dense = natural_modes(model, 8, method="dense")
    auto = natural_modes(model, 8)
    np.testing.assert_array_equal(dense.omega, auto.omega)
    np.testing.assert_array_equal(dense.shapes, auto.shapes)
    a, b = model._free_free(model.K), model._free_free(model._mass_total)
    assert _component_groups(dim, a.toarray(), b.toarray()) == _component_groups(dim, a, b)
    if not rotate:  # the eigenvalues of the partition's (sparse) blocks; eigvals_only
        # takes another LAPACK path than the vectors: 1e-13 (round-off of 8 modes)
        from scipy.linalg import eigh

        groups = _component_groups(dim, a, b)
        lam = np.sort(
            np.concatenate(
                [
                    eigh(
                        model.partition("K")[0].toarray()[np.ix_(sel, sel)],
                        model.partition("MT")[0].toarray()[np.ix_(sel, sel)],
                        eigvals_only=True,
                    )
                    for sel in (
                        np.flatnonzero(np.isin(np.arange(a.shape[0]) % dim, g)) for g in groups
                    )
                ]
            )
        )
        np.testing.assert_allclose(dense.omega, np.sqrt(lam[:8]), rtol=1e-13)
    if dim == 3 and not rotate:
        assert _component_groups(3, a, b) == [[0, 2], [1]]  # in-plane and out-of-plane
    if rotate:  # the planar line's modes, rotated: the same frequencies (round-off)
        flat = natural_modes(
            assemble(
                mesh, pos @ np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]), ten, RHO, dim=3
            ),
            8,
        )
        np.testing.assert_allclose(dense.omega, flat.omega, rtol=1e-10)


@pytest.mark.parametrize("shape", ["rotated plane", "non-planar"])
def test_dense_rotation_path_is_the_sparse_path_to_the_bit(shape, monkeypatch):
    """The dense path of natural_modes (issue 6 pass E6: dense free–free blocks rotated
    by node blocks, _rotate_dense/_unrotate_dense) gives the modes of the sparse path
    (Kronecker rotation, sparse products and slices, the path of every small 3-D line
    before) to the bit, with the same dense eigensolver: the rotation sums run in the
    sparse products' order.  A line in a rotated vertical plane (two decoupled blocks)
    and a non-planar line (one coupled block)."""
    import scipy.sparse as sp

    import stochcable.line.modes as md

    mesh, pos, ten = shallow_parabola(
        12, SPAN, SAG, H_IRVINE, 8.0 * H_IRVINE * SAG / SPAN / G, G, ea=1e7
    )
    c, s = np.cos(2.1), np.sin(2.1)
    pos = pos @ np.array([[c, s, 0.0], [-s, c, 0.0], [0.0, 0.0, 1.0]])
    if shape == "non-planar":  # bow the interior nodes out of the chord's plane
        pos = pos.copy()
        pos[1:-1, 0] += 0.3 * np.sin(np.linspace(0.0, np.pi, pos.shape[0])[1:-1])
    model = assemble(mesh, pos, ten, RHO, dim=3)
    fast = natural_modes(model, 8)
    # the sparse path with the dense eigensolver: what "auto" ran before the pass
    solve_block = md._solve_block
    monkeypatch.setattr(md, "DENSE_MAX_DOF", -1)
    monkeypatch.setattr(
        md, "_solve_block", lambda a, b, k, method, u: solve_block(a, b, k, "dense", u)
    )
    ref = natural_modes(model, 8)
    monkeypatch.undo()
    assert fast.method == ref.method == "dense"
    np.testing.assert_array_equal(fast.omega, ref.omega)
    np.testing.assert_array_equal(fast.shapes, ref.shapes)
    np.testing.assert_array_equal(fast.out_of_plane, ref.out_of_plane)
    assert list(fast.plane) == list(ref.plane)
    # and the kernels themselves against the sparse products
    r = np.array(
        [
            [fast.normal[1], fast.normal[0], 0.0],
            [-fast.normal[0], fast.normal[1], 0.0],
            [0.0, 0.0, 1.0],
        ]
    )
    a = model._free_free(model.K)
    rot = sp.csr_array(sp.kron(sp.eye_array(a.shape[0] // 3), r, format="csr"))
    np.testing.assert_array_equal(md._rotate_dense(a.toarray(), r), (rot.T @ a @ rot).toarray())
    x = np.random.default_rng(3).standard_normal((a.shape[0], 5))
    np.testing.assert_array_equal(md._unrotate_dense(x, r), rot @ x)


def test_direct_sygvd_is_scipy_eigh():
    """_solve_dense calls LAPACK dsygvd as scipy.linalg.eigh(a, b) does (same routine,
    same arguments): the same eigenpairs to the bit; a mass matrix that is not positive
    definite raises LinAlgError with the reason."""
    from scipy.linalg import eigh

    from stochcable.line.modes import _solve_dense

    rng = np.random.default_rng(5)
    for n, k in ((78, 40), (39, 39), (5, 2)):
        x, y = rng.standard_normal((n, n)), rng.standard_normal((n, n))
        a, b = x @ x.T, y @ y.T + n * np.eye(n)
        lam, vec = _solve_dense(a, b, k)
        lr, vr = eigh(a, b, check_finite=False)
        np.testing.assert_array_equal(lam, lr[:k])
        np.testing.assert_array_equal(vec, vr[:, :k])
    with pytest.raises(np.linalg.LinAlgError, match="not positive definite"):
        _solve_dense(np.eye(3), -np.eye(3), 2)
