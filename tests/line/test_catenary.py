"""Tests of stochcable.line.catenary: the closed-form elastic catenary (Irvine 1981).

Independent references: numerical quadrature of the cable equations dx/ds = H/T + H/EA,
dz/ds = V/T + V/EA (a second method for every closure), the classic inextensible
catenary formulas, exact equilibrium identities, Bliet 1984, §7.3 (Bliet 1984 guy) and
Tuah 1982, §6.2 (Tuah 1982 suspended cable).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from references import BLIET_1984_GUY, TUAH_1982_EX2, TUAH_1982_EX2_ELASTIC_CATENARY
from scipy.integrate import quad
from scipy.optimize import brentq

from stochcable.errors import ConvergenceError, InputError
from stochcable.examples import load_example
from stochcable.line import catenary as cat
from stochcable.line import catenary_kernel
from stochcable.line.catenary import (
    catenary_from_top_tension,
    catenary_line,
    catenary_solve,
)
from stochcable.line.mesh import mesh_line
from stochcable.line.multisegment import catenary_multisegment
from stochcable.scene.model import Attachment

CHAIN_W = (288.0 - 1025.0 * math.pi * 0.216**2 / 4.0) * 9.80665  # DESIGN.md chain [N/m]
CHAIN_EA = 1.2326e9


def spans_by_quadrature(H, V0, w, length, ea):
    """Spans of a suspended stretch by adaptive quadrature of dx/ds, dz/ds (a second
    method, independent of the closed-form antiderivatives)."""
    c = 0.0 if math.isinf(ea) else 1.0 / ea

    def T(s):
        return math.hypot(H, V0 + w * s)

    pts = []
    if w != 0.0 and 0.0 < -V0 / w < length:
        pts = [-V0 / w]  # V = 0 inside: sharp H/T peak when H is small
    kw = dict(epsabs=1e-13 * length, epsrel=1e-13, limit=500, points=pts or None)
    x = quad(lambda s: H / T(s) + H * c, 0.0, length, **kw)[0]
    z = quad(lambda s: (V0 + w * s) / T(s) + (V0 + w * s) * c, 0.0, length, **kw)[0]
    return x, z


def check_closure_by_quadrature(sol, rtol):
    """x(L), z(L) integrated numerically from the solution's (H, V) equal the spans."""
    lb = sol.touchdown
    x, z = spans_by_quadrature(
        sol.H, 0.0 if lb > 0 else sol.V_a, sol.weight, sol.length - lb, sol.ea
    )
    c = 0.0 if math.isinf(sol.ea) else 1.0 / sol.ea
    x += lb * (1.0 + sol.H * c)
    scale = max(sol.length, math.hypot(sol.horizontal_span, sol.vertical_span))
    assert abs(x - sol.horizontal_span) <= rtol * scale
    assert abs(z - sol.vertical_span) <= rtol * scale


def check_identities(sol):
    """Exact identities of the (elastic) catenary for the solution."""
    H, w, L = sol.H, sol.weight, sol.length
    # T_b^2 = H^2 + V_b^2 and T_a^2 = H^2 + V_a^2 (definition of the tension vector)
    assert sol.tension_b == pytest.approx(math.hypot(H, sol.V_b), rel=1e-14)
    assert sol.tension_a == pytest.approx(math.hypot(H, sol.V_a), rel=1e-14)
    # vertical equilibrium: V_b - V_a = w * (suspended length)
    assert sol.V_b - sol.V_a == pytest.approx(w * (L - sol.touchdown), rel=1e-12)
    # tension along the line T(s) = sqrt(H^2 + (V_a + w s)^2) on the suspended part
    s = np.linspace(sol.touchdown, L, 7)
    _, _, t = sol.profile(s)
    np.testing.assert_allclose(t, np.hypot(H, sol.V_a + w * (s - sol.touchdown)), rtol=1e-14)
    # the profile ends at the spans (closure) to the solver's tolerance
    x, z, _ = sol.profile(L)
    scale = max(L, math.hypot(sol.horizontal_span, sol.vertical_span))
    assert abs(x - sol.horizontal_span) <= 2e-12 * scale  # solver tolerance 1e-12
    assert abs(z - sol.vertical_span) <= 2e-12 * scale


# ------------------------------------------------------------------------ basics


@pytest.mark.parametrize(
    "X, Z, L, w, ea, seabed",
    [
        (800.0, 180.0, 850.0, CHAIN_W, CHAIN_EA, True),  # DESIGN.md chain, grounded
        (800.0, 180.0, 850.0, CHAIN_W, CHAIN_EA, False),  # same, dipping below end_a
        (300.0, 400.0, 520.0, 50.0, 1e8, False),  # steep, suspended
        (100.0, -30.0, 120.0, 10.0, 1e6, False),  # end_b lower than end_a
        (500.0, 100.0, 560.0, -20.0, 1e8, False),  # buoyant line
        (50.0, 10.0, 49.9, 100.0, 1e7, False),  # taut: stretched
    ],
)
def test_closure_identities_and_quadrature(X, Z, L, w, ea, seabed):
    sol = catenary_solve(X, Z, L, w, ea, seabed=seabed)
    check_identities(sol)
    # second method: quadrature of the cable ODE; 1e-10 of the length (quad rtol 1e-13)
    check_closure_by_quadrature(sol, 1e-10)


def test_inextensible_limit_matches_classic_catenary():
    # Classic catenary (e.g. Irvine 1981 ch. 1): between supports at equal height,
    # L = 2a sinh(X/2a), sag = a (cosh(X/2a) - 1), a = H/w.
    X, L, w = 100.0, 120.0, 7.0
    a = brentq(lambda a: 2 * a * math.sinh(X / (2 * a)) - L, 1.0, 1e4, xtol=1e-14, rtol=1e-15)
    sol = catenary_solve(X, 0.0, L, w, math.inf)
    assert sol.H == pytest.approx(w * a, rel=1e-11)  # both solved to ~1e-13
    _, zmid, _ = sol.profile(L / 2)
    assert -zmid == pytest.approx(a * (math.cosh(X / (2 * a)) - 1.0), rel=1e-11)
    # The profile is the cosh curve z = a[cosh((x - x0)/a) - cosh(x0/a)] (any supports).
    sol = catenary_solve(150.0, 60.0, 200.0, w, math.inf)
    a = sol.H / w
    x0 = -a * math.asinh(sol.V_a / sol.H)  # abscissa of the (virtual) lowest point
    x, z, _ = sol.profile(np.linspace(0.0, 200.0, 41))
    np.testing.assert_allclose(
        z, a * (np.cosh((x - x0) / a) - math.cosh(x0 / a)), atol=1e-10 * 200.0
    )
    # and an elastic line with EA -> infinity tends to it (difference O(T/EA) = 1e-12)
    stiff = catenary_solve(150.0, 60.0, 200.0, w, 1e15)
    assert stiff.H == pytest.approx(sol.H, rel=1e-9)


def test_inextensible_touchdown_classic():
    # Classic grounded catenary (inextensible): suspended length Ls = V_b/w,
    # X = L - Ls + a asinh(Ls/a), Z = a (sqrt(1 + (Ls/a)^2) - 1), a = H/w.
    L, w = 850.0, 1000.0
    sol = catenary_solve(800.0, 180.0, L, w, math.inf, seabed=True)
    a, ls = sol.H / w, sol.V_b / w
    assert sol.touchdown == pytest.approx(L - ls, rel=1e-12)
    assert L - ls + a * math.asinh(ls / a) == pytest.approx(800.0, rel=1e-12)
    assert a * (math.sqrt(1 + (ls / a) ** 2) - 1) == pytest.approx(180.0, rel=1e-12)


def test_touchdown():
    sol = catenary_solve(800.0, 180.0, 850.0, CHAIN_W, CHAIN_EA, seabed=True)
    assert sol.grounded and sol.V_a == 0.0
    assert sol.tension_a == sol.H  # frictionless seabed: tension H on the ground
    # no vertical force at touchdown: the slope there is zero
    lb = sol.touchdown
    h = 1e-4 * lb
    x, z, t = sol.profile([lb - h, lb, lb + h])
    assert z[0] == 0.0 and z[1] == pytest.approx(0.0, abs=1e-12)
    slope = (z[2] - z[1]) / (x[2] - x[1])
    assert abs(slope) < 1e-3  # = w h / (2H) ~ 1e-4: zero slope up to the FD error
    assert t[1] == pytest.approx(sol.H, rel=1e-14)
    # grounded length consistent: stretched length lb(1 + H/EA), V_b = w (L - lb)
    assert sol.grounded_length == pytest.approx(lb * (1 + sol.H / CHAIN_EA), rel=1e-14)
    assert sol.V_b == pytest.approx(CHAIN_W * (850.0 - lb), rel=1e-12)
    # without the seabed the same line dips below end_a (V_a < 0)
    free = catenary_solve(800.0, 180.0, 850.0, CHAIN_W, CHAIN_EA, seabed=False)
    assert free.V_a < 0 and not free.grounded


def test_contact_transition_is_continuous():
    # At first contact (V_a = 0) the grounded and the free formulations meet with a
    # continuous slope dH/dX (the closure is C1 there).
    Z, L, w, ea = 100.0, 200.0, 100.0, 1e8
    Xc = brentq(lambda X: catenary_solve(X, Z, L, w, ea).V_a, 150.0, 170.0, xtol=1e-13)
    d = 1e-3
    left = catenary_solve(Xc - d, Z, L, w, ea, seabed=True)
    mid = catenary_solve(Xc, Z, L, w, ea, seabed=True)
    right = catenary_solve(Xc + d, Z, L, w, ea, seabed=True)
    assert left.grounded and not right.grounded
    assert left.touchdown < 1e-2  # tiny grounded length next to first contact
    slope_l = (mid.H - left.H) / d
    slope_r = (right.H - mid.H) / d
    assert slope_l == pytest.approx(slope_r, rel=1e-3)  # O(d) one-sided difference error


# ------------------------------------------------------------------------ limits


def test_taut_sag_over_span_1e_4():
    # Horizontal taut line: parabola H = w X^2 / (8 f) with relative error O((f/X)^2).
    X, w, ea = 1000.0, 1.0, 1e9
    H_target = w * X / (8e-4)  # sag/span = 1e-4
    L = X / (1.0 + H_target / ea) + (w * X) ** 2 * X / (24 * H_target**2)  # first guess
    sol = catenary_solve(X, 0.0, L, w, ea)
    _, zmid, _ = sol.profile(L / 2)
    sag = -zmid
    assert sag / X == pytest.approx(1e-4, rel=1e-2)  # L above is approximate
    # parabola with the weight per stretched length w/(1 + H/EA): relative error of
    # order (f/X)^2 = 1e-8
    assert sol.H * (1 + sol.H / ea) == pytest.approx(w * X**2 / (8 * sag), rel=1e-6)
    check_closure_by_quadrature(sol, 1e-10)


def test_very_slack_mostly_on_seabed():
    # 1000 m of line, the far end 50 m up and 955 m away: the smallest span with a
    # solution is 950 m (a vertical 50 m riser), so 95 % of the line lies on the seabed.
    sol = catenary_solve(955.0, 50.0, 1000.0, 500.0, 1e9, seabed=True)
    assert sol.touchdown > 0.9 * 1000.0
    check_identities(sol)
    check_closure_by_quadrature(sol, 1e-10)


def test_nearly_vertical_tends_to_vertical_solution():
    Z, L, w, ea = 100.0, 99.0, 50.0, 1e6  # taut vertical tether, V_a > 0
    vert = catenary_solve(0.0, Z, L, w, ea)
    assert vert.H == 0.0 and vert.V_a > 0
    # exact vertical line: Z = L + (V_a L + w L^2/2)/EA
    assert L + (vert.V_a * L + w * L * L / 2) / ea == pytest.approx(Z, rel=1e-14)
    for X in (1e-2, 1e-5, 1e-8):
        s = catenary_solve(X, Z, L, w, ea)
        # limit of x(L) = H [asinh(V_b/H) - asinh(V_a/H)]/w + H L/EA for H -> 0:
        # X = H [ln(V_b/V_a)/w + L/EA] + O(H^3/V^2)
        h_lim = X / (math.log(vert.V_b / vert.V_a) / w + L / ea)
        assert s.H == pytest.approx(h_lim, rel=1e-6)  # (H/V)^2 ~ 1e-8 neglected
        assert s.V_a == pytest.approx(vert.V_a, rel=10 * X)  # O(X^2) change
        check_identities(s)


def test_nearly_vertical_folded_line():
    # Slack line between two points almost on one vertical, no seabed: a folded U.
    Z, L, w, ea = 50.0, 150.0, 10.0, 1e7
    vert = catenary_solve(0.0, Z, L, w, ea)
    assert vert.V_a < 0 < vert.V_b
    # exact folded vertical line: the fold is at s* = -V_a/w, z(L) = (L - 2 s*) + ...
    s_star = -vert.V_a / w
    z_exact = (L - 2 * s_star) + (w * (L - s_star) ** 2 / 2 - w * s_star**2 / 2) / ea
    assert z_exact == pytest.approx(Z, rel=1e-13)
    s = catenary_solve(1e-3, Z, L, w, ea)
    assert s.V_a == pytest.approx(vert.V_a, rel=1e-3)  # H ln(1/H) convergence
    check_identities(s)


def test_ea_over_t_1e6():
    sol = catenary_solve(800.0, 180.0, 850.0, 1.0, 1e6 * 850.0, seabed=False)
    assert sol.tension_b == pytest.approx(sol.ea / 1e6, rel=0.5)  # EA/T ~ 1e6
    check_identities(sol)
    check_closure_by_quadrature(sol, 1e-10)


def test_weightless_and_buoyant():
    # w = 0: straight taut line, T = EA (chord/L - 1)
    s0 = catenary_solve(30.0, 40.0, 49.0, 0.0, 1e6)
    assert s0.tension_a == pytest.approx(1e6 * (50.0 / 49.0 - 1.0), rel=1e-14)
    assert s0.H / s0.V_a == pytest.approx(30.0 / 40.0, rel=1e-14)
    # w -> 0 tends to it continuously (O(w) change)
    s1 = catenary_solve(30.0, 40.0, 49.0, 1e-9, 1e6)
    assert s1.H == pytest.approx(s0.H, rel=1e-9)
    # buoyant line = mirror image (z -> -z) of the heavy line: H equal, V_a opposite
    up = catenary_solve(200.0, 80.0, 250.0, -30.0, 1e8)
    down = catenary_solve(200.0, -80.0, 250.0, 30.0, 1e8)
    assert up.H == pytest.approx(down.H, rel=1e-12)
    assert up.V_a == pytest.approx(-down.V_a, rel=1e-12)


def test_symmetric_u_equals_its_halves():
    X, L, w, ea = 400.0, 500.0, 80.0, 5e7
    full = catenary_solve(X, 0.0, L, w, ea)
    assert full.V_a == pytest.approx(-full.V_b, rel=1e-12)  # symmetry
    _, _, _ = full.profile(L / 2)
    assert full.V_a + w * L / 2 == pytest.approx(0.0, abs=1e-9 * w * L)  # V = 0 at the middle
    xm, zm, _ = full.profile(L / 2)
    assert xm == pytest.approx(X / 2, rel=1e-12)
    # the right half alone, from the lowest point to end_b, has V_a = 0 and the same H
    half = catenary_solve(X / 2, -zm, L / 2, w, ea)
    assert half.H == pytest.approx(full.H, rel=1e-11)
    assert abs(half.V_a) < 1e-9 * w * L


# ------------------------------------------------------------------------ errors


def test_error_paths():
    with pytest.raises(InputError, match=r"length = 80.0 \[m\].*stretch 25.0%"):
        catenary_solve(100.0, 0.0, 80.0, 1.0, 1e9)
    with pytest.raises(InputError, match=r"inextensible line must be longer"):
        catenary_solve(100.0, 0.0, 100.0, 1.0, math.inf)
    with pytest.raises(InputError, match=r"ea = -1.0 \[N\]: must be > 0"):
        catenary_solve(100.0, 0.0, 120.0, 1.0, -1.0)
    with pytest.raises(InputError, match=r"weight = nan \[N/m\]: must be finite"):
        catenary_solve(100.0, 0.0, 120.0, float("nan"), 1e9)
    with pytest.raises(InputError, match=r"horizontal_span = -1.0 \[m\]: must be >= 0"):
        catenary_solve(-1.0, 0.0, 120.0, 1.0, 1e9)
    with pytest.raises(InputError, match=r"weightless line must be taut"):
        catenary_solve(30.0, 40.0, 60.0, 0.0, 1e9)
    with pytest.raises(InputError, match=r"vertical_span = -5.0 \[m\]: must be > 0 with seabed"):
        catenary_solve(100.0, -5.0, 120.0, 1.0, 1e9, seabed=True)
    with pytest.raises(InputError, match=r"horizontal_span = 10.0 \[m\]: must be > 80 m.*pile up"):
        catenary_solve(10.0, 20.0, 100.0, 1.0, math.inf, seabed=True)
    with pytest.raises(InputError, match=r"coincide"):
        catenary_solve(0.0, 0.0, 10.0, 1.0, 1e9)
    with pytest.raises(InputError, match=r"tension_b = 1000.0 \[N\]: no horizontal span"):
        catenary_from_top_tension(426.7, 1036.32, 415.0, 1.3e9, 1000.0)


def test_convergence_error_reports_residual(monkeypatch):
    monkeypatch.setattr(cat, "MAX_NEWTON", 1)
    with pytest.raises(
        ConvergenceError,
        match=r"elastic catenary Newton did not converge: "
        r"residual \d\.\d+e[+-]\d+ after 1 iterations",
    ):
        catenary_solve(800.0, 180.0, 850.0, CHAIN_W, CHAIN_EA, seabed=True)


# ------------------------------------------------------------------------ seeds


def test_bliet_1984_inclined_guy():
    """Bliet 1984, §7.3: with T_top, EA, L, depth and w = (m - rho pi D^2/4) g, the elastic
    catenary reproduces the thesis's static angles, span and bottom tension."""
    g = BLIET_1984_GUY
    w = (g["mass"] - 1025.0 * math.pi * g["diameter"] ** 2 / 4.0) * 9.80665
    sol = catenary_from_top_tension(g["depth"], g["length"], w, g["ea"], g["top_tension"])
    assert sol.tension_b == pytest.approx(g["top_tension"], rel=1e-12)
    # The thesis does not state rho and g; a 0.1 % change of w moves the angles by
    # ~0.004 deg and the span by ~0.02 m, hence the tolerances (printed to 0.001 deg).
    assert sol.horizontal_span == pytest.approx(g["horizontal_span"], abs=0.05)
    assert math.degrees(sol.angle_b) == pytest.approx(g["angle_top_deg"], abs=0.01)
    assert math.degrees(sol.angle_a) == pytest.approx(g["angle_bottom_deg"], abs=0.01)
    chord = math.degrees(math.atan2(g["depth"], sol.horizontal_span))
    assert chord == pytest.approx(g["chord_angle_deg"], abs=0.01)
    assert sol.tension_a == pytest.approx(g["bottom_tension"], rel=2e-4)
    # The printed net weight 494.98 N/m contradicts the printed results (documented
    # seed inconsistency): it gives angles off by ~2 deg.
    bad = catenary_from_top_tension(
        g["depth"], g["length"], g["net_weight_printed"], g["ea"], g["top_tension"]
    )
    assert abs(math.degrees(bad.angle_a) - g["angle_bottom_deg"]) > 1.0


def tuah_ex2_inputs(ea_scale=1.0):
    t = TUAH_1982_EX2
    w = (t["cable_density"] - t["fluid_density"]) * t["area"] * t["g"]  # [lbf/ft]
    ea = t["youngs_modulus"] * t["area"] * ea_scale  # [lbf]
    return t["span"], t["segment_lengths"], w, ea, t["buoy"]


def test_tuah_1982_ex2_two_segment_cable():
    """Tuah 1982, §6.2: two catenary segments joined at a 900 lb buoy (ft, lbf)."""
    (X, Z), (L1, L2), w, ea, buoy = tuah_ex2_inputs()
    sol = catenary_multisegment(X, Z, [L1, L2], [w, w], [ea, ea], [-buoy])
    ref = TUAH_1982_EX2_ELASTIC_CATENARY
    # the recorded fixture (used by the FE statics tests) is this solution
    assert sol.H == pytest.approx(ref["H"], rel=1e-10)
    assert sol.V_start[0] == pytest.approx(ref["V_a"], rel=1e-10)
    assert sol.V_end[-1] == pytest.approx(ref["V_b"], rel=1e-10)
    np.testing.assert_allclose(sol.junctions[0], ref["junction"], rtol=1e-10)
    # node equilibrium at the buoy: V jumps by -900 lbf; vertical balance of the whole
    # line: V_b - V_a = w L - P
    assert sol.V_start[1] - sol.V_end[0] == pytest.approx(-buoy, rel=1e-13)
    assert sol.V_end[-1] - sol.V_start[0] == pytest.approx(w * (L1 + L2) - buoy, rel=1e-12)
    # second method: quadrature of each segment from its start force reproduces the spans
    x1, z1 = spans_by_quadrature(sol.H, sol.V_start[0], w, L1, ea)
    x2, z2 = spans_by_quadrature(sol.H, sol.V_start[1], w, L2, ea)
    assert x1 == pytest.approx(sol.junctions[0, 0], rel=1e-11)
    assert z1 == pytest.approx(sol.junctions[0, 1], rel=1e-11)
    assert x1 + x2 == pytest.approx(X, rel=1e-11)
    assert z1 + z2 == pytest.approx(Z, rel=1e-11)
    # the profile is continuous at the junction and ends at end_b
    x, z, _ = sol.profile([L1 - 1e-9, L1, L1 + 1e-9, L1 + L2])
    assert x[0] == pytest.approx(x[2], abs=1e-6) and z[0] == pytest.approx(z[2], abs=1e-6)
    assert (x[-1], z[-1]) == (pytest.approx(X, rel=1e-11), pytest.approx(Z, rel=1e-11))
    # The buoy lifts the line: the junction is a peak (the line slopes down after it),
    # as the shape of the seed's Figure 6.2-1.
    assert sol.V_start[1] < 0 < sol.V_end[0]


def test_tuah_1982_ex2_close_to_inextensible():
    """The seed compares its FE result with the inextensible catenary and finds close
    agreement: the elastic solution differs from it by less than the total stretch."""
    (X, Z), (L1, L2), w, ea, buoy = tuah_ex2_inputs()
    el = catenary_multisegment(X, Z, [L1, L2], [w, w], [ea, ea], [-buoy])
    inex = catenary_multisegment(X, Z, [L1, L2], [w, w], [math.inf, math.inf], [-buoy])
    s = np.linspace(0, L1 + L2, 301)
    xe, ze, te = el.profile(s)
    xi, zi, _ = inex.profile(s)
    stretch = float(np.trapezoid(te, s)) / ea  # total elastic elongation, ~4 ft
    assert 1.0 < stretch < 10.0
    assert np.max(np.hypot(xe - xi, ze - zi)) < stretch
    assert inex.H == pytest.approx(el.H, rel=0.05)  # strain 0.2-0.4 %: H within 5 %


# ------------------------------------------------------------------------ 3-D


def test_catenary_line_chain_example():
    scene = load_example("chain_catenary")
    env, line = scene.environment, scene.lines[0]
    res = catenary_line(line, env)
    mesh = mesh_line(line, env.rho, env.g)
    assert res.positions.shape == (mesh.n_nodes, 3)
    np.testing.assert_allclose(res.positions[0], line.end_a.position, atol=1e-12)
    np.testing.assert_allclose(res.positions[-1], line.end_b.position, atol=1e-8)
    assert np.all(res.positions[:, 1] == 0.0)  # vertical plane y = 0
    assert res.solution.grounded  # anchor on the seabed, 850 m of chain in 200 m
    assert np.all(res.positions[:, 2] >= -200.0 - 1e-9)  # never below the seabed
    # element tension at mid arc length lies between its node tensions
    lo = np.minimum(res.node_tension[:-1], res.node_tension[1:])
    hi = np.maximum(res.node_tension[:-1], res.node_tension[1:])
    assert np.all(res.element_tension >= lo - 1e-6) and np.all(res.element_tension <= hi + 1e-6)
    # the same from a LineMesh
    again = catenary_line(mesh, env)
    np.testing.assert_array_equal(again.positions, res.positions)


def test_catenary_line_rejects_multisegment_and_attachments():
    scene = load_example("tuah_1982_suspended_cable")
    with pytest.raises(InputError, match=r"needs exactly one segment"):
        catenary_line(scene.lines[0], scene.environment)
    base = load_example("chain_catenary")
    line = base.lines[0].model_copy(update={"attachments": (Attachment(at=400.0, buoyancy=1e4),)})
    with pytest.raises(InputError, match=r"without loaded attachments"):
        catenary_line(line, base.environment)


def test_scalar_closure_kernel_is_the_array_kernel():
    """The float kernel of the closure Newton (catenary_kernel.kernel_scalar, the speed pass
    of issue 4) returns the array kernel's numbers to the bit on every branch: V0, V1 of
    one sign (both signs), opposite signs, a zero end force, the asinh(d)/d series
    (|d| < 1e-6: w → 0), an inextensible line (c = 0)."""
    cases = [
        (3.0e5, 2.0e5, 2500.0, 850.0, 1.0 / 1.2e9),  # both up
        (3.0e5, -4.0e6, 2500.0, 850.0, 1.0 / 1.2e9),  # both down
        (3.0e5, -1.0e6, 2500.0, 850.0, 1.0 / 1.2e9),  # opposite signs
        (3.0e5, 0.0, 2500.0, 850.0, 1.0 / 1.2e9),  # zero force at the start
        (3.0e5, 1.0e4, 1e-9, 850.0, 1.0 / 1.2e9),  # series branch of asinh(d)/d
        (5.0e3, -2.0e3, 10.0, 100.0, 0.0),  # inextensible
        (1.0, 0.0, 0.0, 10.0, 1e-6),  # weightless, V0 = V1 = 0
    ]
    for H, V0, w, ls, c in cases:
        fast = catenary_kernel.kernel_scalar(H, V0, w, ls, c)
        ref = tuple(float(x) for x in catenary_kernel.kernel(H, V0, w, ls, c))
        assert fast == ref, (H, V0, w, ls, c)
