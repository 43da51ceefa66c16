"""Loads of the relative flow on a travelling line and its static shape in them
(stochcable.line.transport.relative_flow), against Hu & Jin (2001)'s eq. (6) and closed form."""

from __future__ import annotations

import numpy as np
import pytest

from stochcable.errors import InputError
from stochcable.line.transport.relative_flow import (
    FlowShape,
    hu_jin_flow_force,
    static_shape_in_flow,
    steady_lift_force,
)
from stochcable.reference.travelling_cable import equilibrium_hu_jin

RHO, DC, CD, CF = 1025.0, 0.02, 1.2, 0.5


def test_force_is_eq6_at_small_slopes():
    """f_y = ½ρbDC_D V_f²(1 − λ0v′)(1 − k̄v′), lift ½ρb²DC_L V_f²(1 − k̄v′)² to first
    order in the slope v′ (Hu & Jin 2001, eq. 6 at rest)."""
    vf, lam0 = 0.3, 4.0
    c = lam0 * vf
    b, kbar = np.hypot(1.0, lam0), lam0 / (1.0 + lam0**2)
    q = 0.5 * RHO * DC * vf**2
    for vp in (0.0, 1e-4, -1e-4):
        t = np.array([[1.0, vp, 0.0]]) / np.hypot(1.0, vp)
        f = hu_jin_flow_force(t, c, vf, RHO, DC, CD, CF * CD)[0]
        fy = q * b * CD * (1 - lam0 * vp) * (1 - kbar * vp)
        fz = q * b * b * CF * CD * (1 - kbar * vp) ** 2
        # second-order terms: (λ0 v′)² ≈ 2e-7 relative
        np.testing.assert_allclose(f, [0.0, fy, fz], rtol=1e-6, atol=1e-12)
    with pytest.raises(InputError, match="tangents"):
        hu_jin_flow_force(np.ones((2, 2)), c, vf, RHO, DC, CD, CF * CD)


def _cable(d: float, n_el: int = 40):
    """A sagged cable of span 100 m, μ = 0.1 (EA = wH/(μ²d³)), its sine start
    pre-stretched by the parabola's tension wH²/(8D)."""
    h, w, mu = 100.0, 10.0, 0.1
    ea = w * h / (mu**2 * d**3)
    x = np.linspace(0.0, h, n_el + 1)
    pos = np.column_stack([x, 0 * x, -d * h * np.sin(np.pi * x / h)])
    l0 = np.linalg.norm(np.diff(pos, axis=0), axis=1) / (1 + w * h / (8 * d) / ea)
    return pos, l0, ea, w, mu


def test_at_rest_the_cable_lies_in_the_resultant_plane():
    """Uniform loads (c = 0): the equilibrium is the plane catenary under the resultant,
    the mid-span at atan2(f_D, w − f_L) exactly."""
    pos, l0, ea, w, _ = _cable(0.05, 20)
    vf = 0.6
    load = lambda e: hu_jin_flow_force(e, 0.0, vf, RHO, DC, CD, CF * CD)  # noqa: E731
    shape = static_shape_in_flow(pos, l0, ea, w, load, steps=4)
    q = 0.5 * RHO * DC * vf**2
    # the flow loads the stretched length, the weight the unstretched one: the
    # resultant turns by the strain T/EA ≈ 3e-6 along the line; 1e-5 rad
    ref = np.arctan2(q * CD, w - q * CF * CD)
    assert shape.midspan_angle() == pytest.approx(ref, abs=1e-5)


def test_fe_reproduces_the_closed_form_where_the_reduction_holds():
    """Sag/span d = 0.02, μ = 0.1, c_f = 0.5, a drag that lifts the cable at λ0 ≈ 5
    (λ0·d ≤ 0.4: the one-mode reduction's slope terms λ0 v′ ≤ λ0πd stay below 1.3):
    the FE mid-span angle within 2° of eqs. 39–42 across the swing-up (measured
    ≤ 0.3°), the groups X = D_f v_f from the physical loads (X = f_D H/(EA d³))."""
    d = 0.02
    pos, l0, ea, w, mu = _cable(d)
    x0 = mu**2 / 13.0  # b² c_f X0 = μ² at λ0 = 5: the transition
    vf = np.sqrt(x0 / mu**2 * w / (0.5 * RHO * DC * CD))
    start, worst = pos, 0.0
    for lam0 in (0.0, 2.0, 3.0, 4.0, 4.5, 5.0, 5.5, 6.0, 8.0, 12.0, 20.0):
        load = lambda e, c=lam0 * vf: hu_jin_flow_force(e, c, vf, RHO, DC, CD, CF * CD)  # noqa: E731
        shape = static_shape_in_flow(start, l0, ea, w, load, steps=4 if lam0 == 0 else 1)
        start = shape.positions
        b = np.hypot(1.0, lam0)
        ref = equilibrium_hu_jin(
            mu, lam0, d=d, c_f=CF, v_f=1.0, d_f=b * x0, figure_scaling=False
        ).phi[0]
        worst = max(worst, abs(shape.midspan_angle() - ref))
    assert np.degrees(worst) < 2.0
    assert shape.midspan_angle() > 3.0  # at the top by λ0 = 20


def test_swing_up_speed_levels_the_midspan():
    """At the swing-up speed of eq. (38) the FE mid-span stands level with the chord
    (φ ≈ π/2, within 2°: the drag and slope terms), below it hangs, above it rises."""
    from stochcable.reference.travelling_cable import swing_up_speed_hu_jin

    d = 0.02
    pos, l0, ea, w, _ = _cable(d)
    vf = 0.1
    c_up = swing_up_speed_hu_jin(w, RHO, DC, CF * CD, vf)
    # the lift alone: ½ρC_L D(V_f² + c²) = w
    assert 0.5 * RHO * CF * CD * DC * (vf**2 + c_up**2) == pytest.approx(w, rel=1e-12)
    start, angles = pos, []
    for c in (0.0, 0.5 * c_up, 0.9 * c_up, c_up, 1.1 * c_up):
        load = lambda e, c=c: hu_jin_flow_force(e, c, vf, RHO, DC, CD, CF * CD)  # noqa: E731
        shape = static_shape_in_flow(start, l0, ea, w, load, steps=4 if c == 0 else 2)
        start = shape.positions
        angles.append(shape.midspan_angle())
    assert angles[3] == pytest.approx(np.pi / 2, abs=np.radians(2.0))
    assert angles[2] < np.pi / 2 < angles[4]


# ------------------------------------------------- the steady lift of the scene statics


def test_steady_lift_is_eq6_lift_across_the_flow():
    """On a chord along x̂ in a flow V_f ŷ: ½ρC_L D V_f² b²(1 − k̄v′)² ẑ to first order in
    the slope v′ (Hu & Jin 2001, eq. 6), the same for either end first and either flow
    sense; no lift without a cross-flow or on a vertical element (no up side)."""
    vf, lam0, coef = 0.3, 4.0, 0.5 * RHO * CF * CD * DC
    c = lam0 * vf
    b, kbar = np.hypot(1.0, lam0), lam0 / (1.0 + lam0**2)
    u = np.array([[0.0, vf, 0.0]])
    for vp in (0.0, 1e-4, -1e-4):
        t = np.array([[1.0, vp, 0.0]]) / np.hypot(1.0, vp)
        f = steady_lift_force(t, u, c, np.array([coef]))[0]
        ref = coef * vf**2 * b**2 * (1 - kbar * vp) ** 2
        # second-order terms: (λ0 v′)² ≈ 2e-7 relative
        np.testing.assert_allclose(f, [0.0, 0.0, ref], rtol=1e-6, atol=1e-12)
        # the other end first (−t, −c: the same motion) and the flow reversed
        np.testing.assert_allclose(steady_lift_force(-t, u, -c, np.array([coef]))[0], f)
        back = steady_lift_force(t, -u, c, np.array([coef]))[0]
        assert back[2] == pytest.approx(coef * (vf**2 + 2 * c * vf * vp / np.hypot(1, vp) + c**2))
    tilted = np.array([[np.cos(0.3), 0.0, np.sin(0.3)]])
    none = [
        (tilted, np.array([[0.5, 0.0, 0.1]])),  # current in the line's vertical plane
        (np.array([[0.0, 0.0, 1.0]]), u),  # vertical element
        (np.array([[0.0, 1.0, 0.0]]), u),  # flow along the element
    ]
    for t, uu in none:
        np.testing.assert_array_equal(steady_lift_force(t, uu, c, np.array([coef])), 0.0)


def _scene_of(pos, l0, ea, w, vf, c, cl, n_el):
    """The cable of :func:`_cable` as a scene line, 100 m deep, in a cross-current."""
    return {
        "environment": {
            "depth": 500.0,
            "rho": RHO,
            "current": [{"z": 0.0, "speed": vf, "heading": 90.0}],
        },
        "lines": [
            {
                "name": "hj",
                "end_a": {"position": [0.0, 0.0, -100.0]},
                "end_b": {"position": [float(pos[-1, 0]), 0.0, -100.0]},
                "segments": [
                    {
                        "length": float(l0.sum()),
                        "ea": ea,
                        "mass": 1.0,
                        "diameter": DC,
                        "cd_normal": CD,
                        "weight": w,
                        "cl_steady": cl,
                        "elements": n_el,
                    }
                ],
                "axial_speed": c,
            }
        ],
    }


def test_scene_statics_lift_against_the_closed_form_and_a_second_solver():
    """The scene statics of the travelling cable of the FE-in-flow check (d = 0.02,
    μ = 0.1, c_f = 0.5, lifted at λ0 = 5): the mid-span angle equals the relative-flow
    FE of :func:`static_shape_in_flow` under the same loads (the cross-flow drag
    ½ρC_D D|U_n|U_n and :func:`steady_lift_force`; another Newton, global axes, its
    own Jacobian) to 1e-5 rad (measured 5e-9), and eqs. 39–42 with the groups of this
    drag (X without Hu & Jin's b: c_f → b c_f, D_f → X) within 0.3° across the
    swing-up to the top (measured 0.1°), through the public scene path."""
    from stochcable.statics import solve_statics

    d, n_el = 0.02, 40
    pos, l0, ea, w, mu = _cable(d, n_el)
    x0 = mu**2 / 13.0  # b² c_f X0 = μ² at λ0 = 5: the transition
    vf = np.sqrt(x0 / mu**2 * w / (0.5 * RHO * DC * CD))
    ones = np.ones(n_el)
    u = np.array([[0.0, vf, 0.0]]) * ones[:, None]

    def load(e, c):
        ua = np.einsum("ij,ij->i", u, e)
        un = u - ua[:, None] * e
        drag = 0.5 * RHO * CD * DC * np.linalg.norm(un, axis=1)[:, None] * un
        return drag + steady_lift_force(e, u, c, 0.5 * RHO * CF * CD * DC * ones)

    start = pos + np.array([0.0, 0.0, -100.0])
    for lam0 in (0.0, 4.0, 5.0, 5.5, 8.0, 20.0):
        c = lam0 * vf
        st = solve_statics(_scene_of(pos, l0, ea, w, vf, c, CF * CD, n_el)).lines["hj"]
        phi = FlowShape(st.positions, st.tension, 0, 0.0).midspan_angle()
        fe = static_shape_in_flow(start, l0, ea, w, lambda e, c=c: load(e, c), steps=4)
        start = fe.positions
        assert phi == pytest.approx(fe.midspan_angle(), abs=1e-5)
        b = np.hypot(1.0, lam0)
        ref = equilibrium_hu_jin(mu, lam0, d=d, c_f=CF * b, v_f=1.0, d_f=x0, figure_scaling=False)
        assert phi == pytest.approx(ref.phi[0], abs=np.radians(0.3))
    assert phi > 3.0  # at the top by λ0 = 20


def test_scene_lift_zero_or_planar_changes_nothing():
    """cl_steady = 0, and a lift in a planar problem (current in the line's vertical
    plane: no up side across it), give the statics without lift to the bit."""
    from stochcable.statics import solve_statics

    pos, l0, ea, w, _ = _cable(0.05, 20)
    ref = solve_statics(_scene_of(pos, l0, ea, w, 0.3, 1.0, 0.0, 20)).lines["hj"]
    doc = _scene_of(pos, l0, ea, w, 0.3, 1.0, 0.6, 20)
    doc["environment"]["current"][0]["heading"] = 0.0
    planar = _scene_of(pos, l0, ea, w, 0.3, 1.0, 0.0, 20)
    planar["environment"]["current"][0]["heading"] = 0.0
    np.testing.assert_array_equal(
        solve_statics(doc).lines["hj"].positions, solve_statics(planar).lines["hj"].positions
    )
    lifted = solve_statics(_scene_of(pos, l0, ea, w, 0.3, 1.0, 0.6, 20)).lines["hj"]
    assert lifted.positions[10, 2] > ref.positions[10, 2]  # C_L > 0 lifts
