"""Tests of stochcable.line.statics: FE statics against the closed-form elastic catenary
(stochcable.line.catenary, Irvine 1981), conservation of force, symmetry, Tuah 1982, §6.2."""

from __future__ import annotations

import math

import numpy as np
import pytest

from stochcable.errors import ConvergenceError, InputError
from stochcable.line.mesh import mesh_line
from stochcable.line.multisegment import catenary_multisegment
from stochcable.line.statics import solve_fe, solve_line_statics
from stochcable.scene.model import load_scene
from stochcable.statics import solve_statics

# DESIGN.md "Scene and result documents": the chain leg of the example scene.
CHAIN = dict(
    length=850.0,
    ea=1.2326e9,
    mass=288.0,
    diameter=0.216,
    cd_normal=1.333,
    cd_axial=0.2034,
    elements=100,
)


def make(
    end_a,
    end_b,
    segments,
    depth=200.0,
    current=(),
    attachments=(),
    stiffness=3e6,
    rho=1025.0,
    g=9.80665,
):
    scene = load_scene(
        {
            "environment": {
                "depth": depth,
                "rho": rho,
                "g": g,
                "current": list(current),
                "seabed": {"stiffness": stiffness},
            },
            "lines": [
                {
                    "name": "l",
                    "end_a": {"position": list(end_a)},
                    "end_b": {"position": list(end_b)},
                    "segments": list(segments),
                    "attachments": list(attachments),
                }
            ],
        }
    )
    env = scene.environment
    return mesh_line(scene.lines[0], env.rho, env.g), env, scene


def fe(mesh, env, **kw):
    return solve_line_statics(mesh, env, method="fe", **kw)


def richardson(seg, end_a, end_b, n, **kw):
    """FE end tensions and positions at n and 2n elements, extrapolated for O(1/n²)."""
    out = []
    for k in (n, 2 * n):
        m, env, _ = make(end_a, end_b, [dict(seg, elements=k)], **kw)
        r = fe(m, env)
        out.append((np.array([r.tension_a, r.tension_b]), r.positions[:: k // n]))
    (t1, p1), (t2, p2) = out
    return (4 * t2 - t1) / 3, (4 * p2 - p1) / 3, (t1, t2)


@pytest.mark.parametrize(
    "case,length,end_a,end_b",
    [
        ("slack", 500.0, (-400.0, 0.0, -100.0), (0.0, 0.0, -20.0)),
        ("taut", 407.0, (-400.0, 0.0, -100.0), (0.0, 0.0, -20.0)),
    ],
)
def test_fe_converges_to_catenary(case, length, end_a, end_b):
    # A chain of straight bars with the weight lumped at the nodes is not the
    # continuous catenary: its chords are shorter than the arcs by O(l0³ κ²) each,
    # so node positions and end tensions differ by O(1/n²).  Check the rate (error
    # ratio 4 from n = 40 to 80) and that the Richardson extrapolation of the two
    # meets the closed form to 1e-6 relative.
    seg = dict(CHAIN, length=length)
    m, env, _ = make(end_a, end_b, [seg])
    cat = solve_line_statics(m, env, method="catenary")
    ref_t = np.array([cat.tension_a, cat.tension_b])
    t_ex, p_ex, (t1, t2) = richardson(seg, end_a, end_b, 40)
    e1 = np.abs(t1 - ref_t) / ref_t
    e2 = np.abs(t2 - ref_t) / ref_t
    # second order: ratio between 3.5 and 4.5 (higher-order terms at n = 40)
    assert np.all((e1 / e2 > 3.5) & (e1 / e2 < 4.5))
    assert np.max(np.abs(t_ex - ref_t) / ref_t) < 1e-6
    m40, env40, _ = make(end_a, end_b, [dict(seg, elements=40)])
    cat40 = solve_line_statics(m40, env40, method="catenary")
    assert np.max(np.abs(p_ex - cat40.positions)) < 1e-6 * length


def test_fe_seabed_touchdown_matches_catenary():
    # Anchor on the seabed.  The FE seabed is a penalty spring: a grounded line sinks
    # w/(k D) into it, 3.8e-6 m with k = 3e9 Pa/m, so the stiff bed reproduces the
    # rigid-bed catenary up to that and to the O(1/n²) discretization (Richardson).
    end_a, end_b = (-800.0, 0.0, -200.0), (0.0, 0.0, -20.0)
    m, env, _ = make(end_a, end_b, [CHAIN], stiffness=3e9)
    cat = solve_line_statics(m, env, method="catenary")
    assert cat.touchdown is not None and cat.touchdown > 300.0
    r = fe(m, env)
    w = float(m.weight[0])
    pen = w / (3e9 * 0.216)
    grounded = r.grounded[1:-1]
    assert grounded.sum() > 10
    # grounded nodes sit at the penalty penetration (uniform, exact for a flat line)
    zg = r.positions[1:-1][grounded, 2]
    assert np.allclose(zg[:-3], -200.0 - pen, rtol=0, atol=1e-9)
    # end tensions: O(1/n²) discretization of the suspended part at n = 100 sets H to
    # about 1e-4 (measured 9.3e-5 at the anchor, where the grounded end force is the
    # first element's tension H, the seabed carrying the weight lumped on the anchor)
    assert abs(r.tension_a / cat.tension_a - 1) < 1.5e-4
    assert abs(r.force_a[2]) < 1e-6 * r.tension_a  # horizontal pull only, as the catenary
    assert abs(r.tension_b / cat.tension_b - 1) < 1e-4
    # touchdown interpolated within a fraction of an element (8.5 m)
    assert abs(r.touchdown - cat.touchdown) < 0.05 * 8.5


def test_auto_uses_catenary_and_fe_otherwise():
    m, env, scene = make((-400, 0, -100), (0, 0, -20), [dict(CHAIN, length=500.0)])
    assert solve_line_statics(m, env).method == "catenary"
    m2, env2, _ = make(
        (-400, 0, -100),
        (0, 0, -20),
        [dict(CHAIN, length=500.0)],
        current=[{"z": 0.0, "speed": 0.5}],
    )
    assert solve_line_statics(m2, env2).method == "fe"
    with pytest.raises(InputError, match="there is a current"):
        solve_line_statics(m2, env2, method="catenary")
    with pytest.raises(InputError, match="method"):
        solve_line_statics(m, env, method="newton")


def test_equilibrium_end_forces_balance_loads():
    # Sum of forces on the line: supports + weight + attachments + drag = 0.  The end
    # forces are what the line exerts, so force_a + force_b = total external load.
    segs = [dict(CHAIN, length=300.0, elements=30), dict(CHAIN, length=200.0, elements=20)]
    atts = [{"at": 300.0, "buoyancy": 3e5}, {"at": 100.0, "mass": 1e4}]
    m, env, _ = make((-400, 0, -150), (0, 0, -20), segs, attachments=atts, depth=1000.0)
    r = fe(m, env)
    total = np.array([0.0, 0.0, -np.sum(m.weight * m.l0) + 3e5 - 1e4 * env.g])
    scale = np.sum(np.abs(m.weight * m.l0)) + 3e5
    # interior residual 1e-10 of the reference force, summed over 51 nodes
    assert np.allclose(r.force_a + r.force_b, total, rtol=0, atol=1e-8 * scale)
    assert r.residual < 1e-9


def test_symmetric_u_shape():
    m, env, _ = make(
        (-200, 0, -50), (200, 0, -50), [dict(CHAIN, length=500.0, elements=50)], depth=500.0
    )
    r = fe(m, env)
    p = r.positions
    # mirror x -> -x reverses the node order; round-off of a 1e-10 relative residual
    assert np.allclose(p[:, 0], -p[::-1, 0], atol=1e-7)
    assert np.allclose(p[:, 2], p[::-1, 2], atol=1e-7)
    assert np.allclose(r.tension, r.tension[::-1], rtol=1e-8)
    assert r.tension_a == pytest.approx(r.tension_b, rel=1e-9)


# Tuah 1982, §6.2 (Tuah 1982): two segments, 500 ft and 1000 ft, from (0, 0) to
# (1200, 500) ft, A0 = 0.0218 ft², E = 8.12e6 psf, cable 3.35 slug/ft³, water
# 2.0 slug/ft³, a 900 lb buoy at the junction (imperial units, g = 32.174 ft/s²).
TUAH_1982_6_2 = dict(
    area=0.0218,
    E=8.12e6,
    rho_c=3.35,
    rho_f=2.0,
    buoy=900.0,
    lengths=(500.0, 1000.0),
    end_b=(1200.0, 500.0),
)


def test_seed_001_example_6_2_two_segments_with_buoy():
    d = TUAH_1982_6_2
    g = 32.174
    diam = math.sqrt(4 * d["area"] / math.pi)
    seg = dict(ea=d["E"] * d["area"], mass=d["rho_c"] * d["area"], diameter=diam)
    segs = [
        dict(seg, length=d["lengths"][0], elements=40),
        dict(seg, length=d["lengths"][1], elements=80),
    ]
    end_a = (0.0, 0.0, -600.0)
    end_b = (d["end_b"][0], 0.0, -600.0 + d["end_b"][1])
    m, env, _ = make(
        end_a,
        end_b,
        segs,
        depth=2000.0,
        rho=d["rho_f"],
        g=g,
        attachments=[{"at": 500.0, "buoyancy": d["buoy"]}],
    )
    r = fe(m, env)
    w = (d["rho_c"] - d["rho_f"]) * d["area"] * g
    ref = catenary_multisegment(
        d["end_b"][0],
        d["end_b"][1],
        d["lengths"],
        [w, w],
        [seg["ea"]] * 2,
        junction_loads=[-d["buoy"]],
    )
    # O(1/n²) discretization with 120 elements: 1e-4 relative (measured below 3e-5)
    assert r.tension_a == pytest.approx(ref.tension_a, rel=1e-4)
    assert r.tension_b == pytest.approx(ref.tension_b, rel=1e-4)
    j = int(np.argmin(np.abs(m.s0 - 500.0)))
    assert r.positions[j, 0] == pytest.approx(ref.junctions[0, 0], abs=0.05)
    assert r.positions[j, 2] + 600.0 == pytest.approx(ref.junctions[0, 1], abs=0.05)


def test_3d_line_equals_rotated_planar_one():
    th = math.radians(37.0)
    rot = np.array([[math.cos(th), -math.sin(th), 0], [math.sin(th), math.cos(th), 0], [0, 0, 1]])
    a, b = np.array([-800.0, 0, -200]), np.array([0.0, 0, -20])
    m2, env, _ = make(a, b, [CHAIN])
    m3, env3, _ = make(rot @ a, rot @ b, [CHAIN])
    r2 = fe(m2, env)
    r3 = solve_fe(m3, env3, None, 1e-10, 500, force_3d=True)  # full 3-DOF path
    assert np.allclose(r3.positions, r2.positions @ rot.T, atol=1e-7)
    assert r3.tension_a == pytest.approx(r2.tension_a, rel=1e-9)
    assert np.allclose(r3.force_b, rot @ r2.force_b, atol=1e-9 * r2.tension_b)


@pytest.mark.parametrize(
    "name,end_a,end_b,seg,depth",
    [
        (
            "nearly taut",
            (-400, 0, -100),
            (0, 0, -100),
            dict(CHAIN, length=400.0 * (1 + 1e-8)),
            200.0,
        ),
        (
            "very slack, mostly grounded",
            (-800, 0, -200),
            (0, 0, -20),
            dict(CHAIN, length=960.0),
            200.0,
        ),
        ("nearly vertical", (-5, 0, -200), (0, 0, -20), dict(CHAIN, length=180.1), 300.0),
        ("EA/T 1e6", (-400, 0, -100), (0, 0, -20), dict(CHAIN, length=500.0, ea=1e12), 200.0),
        ("400 elements", (-800, 0, -200), (0, 0, -20), dict(CHAIN, elements=400), 200.0),
        (
            "very slack, 400 elements",
            (-800, 0, -200),
            (0, 0, -20),
            dict(CHAIN, length=960.0, elements=400),
            200.0,
        ),
        (
            "very slack, 800 elements",
            (-800, 0, -200),
            (0, 0, -20),
            dict(CHAIN, length=960.0, elements=800),
            200.0,
        ),
    ],
)
def test_hard_cases_match_catenary(name, end_a, end_b, seg, depth):
    m, env, _ = make(end_a, end_b, [seg], depth=depth)
    cat = solve_line_statics(m, env, method="catenary")
    r = fe(m, env)
    # FE vs continuous catenary: the lumped model resolves the end loads and the
    # touchdown (where the last grounded node carries part of the suspended weight) to
    # about one element weight w·l0; relative to the end tension that bounds the
    # difference (O(1/n²) where neither occurs, see test_fe_converges_to_catenary).
    bound = max(2e-4, float(m.weight[0] * m.l0[0]) / min(cat.tension_a, cat.tension_b))
    assert r.tension_b == pytest.approx(cat.tension_b, rel=bound)
    assert r.tension_a == pytest.approx(cat.tension_a, rel=bound)
    assert np.max(np.abs(r.positions - cat.positions)) < 2e-3 * m.length
    # the start is the exact lumped chain (no current): Newton ends in a few steps
    assert r.iterations <= 10


def test_current_deflects_downstream_taut_string():
    # A taut horizontal line across a uniform current U (heading 90 deg, +y): the
    # drag load q = ½ρ Cd D U² per length deflects it downstream (+y), and the small-
    # deflection string gives the midspan sag q L²/(8 T).  Weightless line
    # (weight = 0) so the deflection is purely horizontal.
    seg = dict(
        length=100.0, ea=1e7, mass=10.0, diameter=0.1, cd_normal=1.2, weight=0.0, elements=50
    )
    m, env, _ = make(
        (-100.5, 0, -50),
        (0.5, 0, -50),
        [seg],
        depth=100.0,
        current=[{"z": 0.0, "speed": 1.0, "heading": 90.0}],
    )
    r = fe(m, env)
    q = 0.5 * 1025.0 * 1.2 * 0.1 * 1.0**2
    T = float(np.mean(r.tension))
    mid = r.positions[25]
    assert mid[1] > 0.0  # downstream
    sag = q * 101.0**2 / (8.0 * T)
    # string formula neglects the O((sag/L)²) stretch and obliquity: 1 % agreement
    assert mid[1] == pytest.approx(sag, rel=1e-2)
    assert abs(mid[2] + 50.0) < 1e-9


def test_nonconvergence_raises_with_residual():
    # CPU-independent by a wide margin: the start (the lumped chain) has a residual of
    # 1.2e-4, one Newton step leaves 1.5e-8, 150x the tolerance 1e-10, while round-off
    # differences between CPUs are below 1e-13 of the reference force here
    m, env, _ = make((-800, 0, -200), (0, 0, -20), [CHAIN])
    with pytest.raises(ConvergenceError, match=r"statics Newton did not converge: residual"):
        fe(m, env, max_iterations=1)


def test_solve_statics_document():
    _, _, scene = make((-800, 0, -200), (0, 0, -20), [dict(CHAIN, elements=20)])
    doc = solve_statics(scene).to_document()
    line = doc["lines"]["l"]
    assert line["method"] == "catenary"
    assert line["end_a"]["tension"] > 0 and len(line["nodes"]) == 21
    assert len(line["tension"]) == 20 and line["touchdown"] > 0


# ------------------------------------------------------------------ undetermined shapes


def test_slack_grounded_line_longer_than_span_plus_depth_is_input_error():
    # 985 m > 800 m + 179.97 m (the elastic vertical hanging length to end_b): the
    # surplus lies slack on a frictionless bed, zero horizontal tension, position
    # undetermined.  Raised up front, before any iteration, for fe and auto alike.
    m, env, _ = make((-800, 0, -200), (0, 0, -20), [dict(CHAIN, length=985.0)])
    for method in ("fe", "auto"):
        with pytest.raises(
            InputError,
            match=r"lines\['l'\]\.length = 985.*800 m \+ 179\.968"
            r".*without seabed friction.*undetermined.*shorten",
        ):
            solve_line_statics(m, env, method=method)
    # just below the threshold the line is determined and solves
    m2, env2, _ = make((-800, 0, -200), (0, 0, -20), [dict(CHAIN, length=975.0)])
    assert fe(m2, env2).tension_a > 0.0


def test_weightless_slack_line_is_input_error():
    seg = dict(length=120.0, ea=1e7, mass=10.0, diameter=0.1, weight=0.0)
    m, env, _ = make((-100, 0, -50), (0, 0, -50), [seg])
    with pytest.raises(InputError, match="weightless line longer.*undetermined"):
        fe(m, env)


# ------------------------------------------------------------- attachments, catenary


def test_clump_weight_two_segments_matches_multisegment_catenary():
    # Heavy chain + light wire with a 20 t clump weight at the junction, free hanging
    # (deep water).  Reference: piecewise elastic catenary, V jumps by the clump
    # weight at the junction (catenary_multisegment).  O(1/n²) discretization at 2 x 100
    # elements: 1e-4 relative on the end tensions, 0.05 m on the junction.
    segs = [
        dict(CHAIN, length=400.0, elements=100),
        dict(length=300.0, ea=5e8, mass=60.0, diameter=0.1, elements=100),
    ]
    clump = 2e4
    m, env, _ = make(
        (-300, 0, -500), (0, 0, -20), segs, depth=1000.0, attachments=[{"at": 400.0, "mass": clump}]
    )
    r = fe(m, env)
    ws = [float(m.weight[0]), float(m.weight[-1])]
    ref = catenary_multisegment(
        300.0, 480.0, [400.0, 300.0], ws, [1.2326e9, 5e8], junction_loads=[clump * env.g]
    )
    assert r.tension_a == pytest.approx(ref.tension_a, rel=1e-4)
    assert r.tension_b == pytest.approx(ref.tension_b, rel=1e-4)
    j = int(np.argmin(np.abs(m.s0 - 400.0)))
    assert r.positions[j, 0] + 300.0 == pytest.approx(ref.junctions[0, 0], abs=0.05)
    assert r.positions[j, 2] + 500.0 == pytest.approx(ref.junctions[0, 1], abs=0.05)


# ------------------------------------------------------------- above the water line


def test_fairlead_above_water_dry_weight_force_balance():
    # end_b 15 m above the still-water level: the elements above z = 0 weigh mass·g,
    # the one crossing z = 0 its wet fraction f of w_sub and 1 - f of mass·g.  The end
    # forces must balance exactly that weight (conservation; residual 1e-10 of the
    # reference force summed over the nodes), and differ from the all-wet weight by
    # the buoyancy of the dry length (so the check can fail).
    seg = dict(CHAIN, length=700.0, elements=100)
    m, env, _ = make((-600, 0, -150), (0, 0, 15), [seg], depth=1000.0)  # no bed contact
    r = fe(m, env)
    z = r.positions[:, 2]
    za, zb = z[:-1], z[1:]
    dz = np.where(zb != za, np.abs(zb - za), 1.0)
    f = np.clip(-np.minimum(za, zb) / dz, 0.0, 1.0)
    f = np.where((za <= 0) & (zb <= 0), 1.0, np.where((za > 0) & (zb > 0), 0.0, f))
    mixed = (f > 0) & (f < 1)
    assert mixed.sum() == 1 and (f == 0).sum() >= 1  # a partly submerged element
    w_dry = 288.0 * env.g
    W = np.sum(m.l0 * (w_dry + f * (m.weight - w_dry)))
    scale = float(np.sum(m.l0 * w_dry))
    assert r.force_a[2] + r.force_b[2] == pytest.approx(-W, abs=1e-8 * scale)
    assert abs(r.force_a[0] + r.force_b[0]) < 1e-8 * scale
    W_wet = np.sum(m.l0 * m.weight)
    assert abs(W - W_wet) > 1e3 * 1e-8 * scale
    # the partly submerged element's fraction enters (counting it wet would not balance)
    k = int(np.flatnonzero(mixed)[0])
    assert abs(m.l0[k] * (w_dry - m.weight[k]) * (1 - f[k])) > 1e3 * 1e-8 * scale


def test_fairlead_above_water_against_two_weight_catenary():
    # issue 19: the part of a line above the still-water level is modelled (weight in
    # air, no buoyancy).  Reference: an elastic catenary of two segments, the submerged
    # weight below the waterline and the weight in air above it, the junction's arc
    # length s* chosen so that it lies at z = 0 (catenary_multisegment; the effective
    # tension below equals the true tension at z = 0, so H and V are continuous there).
    # The FE converges to it as O(1/n²), its waterline crossing included.
    from scipy.optimize import brentq

    errs = []
    for n in (100, 200):
        m, env, _ = make(
            (-600, 0, -150), (0, 0, 15), [dict(CHAIN, length=700.0, elements=n)], depth=1000.0
        )
        r = fe(m, env)
        ws = [float(m.weight[0]), 288.0 * env.g]  # submerged, in air [N/m]

        def ref_of(s, ws=ws):
            return catenary_multisegment(600.0, 165.0, [s, 700.0 - s], ws, [1.2326e9] * 2)

        s_star = brentq(lambda s: ref_of(s).junctions[0, 1] - 150.0, 500.0, 699.0, xtol=1e-12)
        ref = ref_of(s_star)
        z = r.positions[:, 2]
        k = int(np.flatnonzero((z[:-1] <= 0.0) & (z[1:] > 0.0))[0])
        s_fe = m.s0[k] + (m.s0[k + 1] - m.s0[k]) * -z[k] / (z[k + 1] - z[k])
        errs.append(
            (r.tension_a / ref.tension_a - 1.0, r.tension_b / ref.tension_b - 1.0, s_fe - s_star)
        )
    e100, e200 = np.array(errs[0]), np.array(errs[1])
    # measured: 1.6e-5, 1.5e-5 and -4.1e-3 m at 100 elements; 4x smaller at 200
    assert np.all(np.abs(e200[:2]) < 1e-5) and abs(e200[2]) < 2e-3
    assert np.all((e100 / e200 > 3.5) & (e100 / e200 < 4.5))  # second order
    # all wet (the buoyancy of the dry 19 m counted) would be far off
    wet = catenary_multisegment(600.0, 165.0, [700.0], [ws[0]], [1.2326e9])
    assert abs(wet.tension_b / ref.tension_b - 1.0) > 100 * abs(e100[1])


# ------------------------------------------------------------------------- current


def _drag_on_line(r, m, env, u_of_z):
    """Drag force on the line [N], recomputed from the positions: Morison normal and
    axial drag per stretched length at the element midpoints (DESIGN.md)."""
    p = r.positions
    d = np.diff(p, axis=0)
    l = np.linalg.norm(d, axis=1)
    e = d / l[:, None]
    u = u_of_z(0.5 * (p[1:, 2] + p[:-1, 2]))
    ua = np.sum(u * e, axis=1)
    un = u - ua[:, None] * e
    cn = 0.5 * env.rho * m.cd_normal * m.diameter
    ct = 0.5 * env.rho * m.cd_axial * np.pi * m.diameter
    f = (cn * np.linalg.norm(un, axis=1))[:, None] * un + (ct * np.abs(ua) * ua)[:, None] * e
    return np.sum(l[:, None] * f, axis=0)


@pytest.mark.parametrize(
    "current",
    [
        [{"z": 0.0, "speed": 1.5, "heading": 0.0}],
        [{"z": 0.0, "speed": 1.5, "heading": 90.0}],
        # sheared profile: the tangent leaves out dU/dz (linear convergence in the
        # asymptotic phase), still converged to 1e-10 within the budget
        [{"z": 0.0, "speed": 2.0, "heading": 30.0}, {"z": -300.0, "speed": 0.2, "heading": 0.0}],
    ],
)
def test_current_drag_balance_heavy_line(current):
    # Conservation: the supports carry weight + integrated drag, so the horizontal end
    # forces sum to the total drag, recomputed here from the converged positions.
    m, env, _ = make(
        (-400, 0, -150), (0, 0, -20), [dict(CHAIN, length=500.0)], current=current, depth=1000.0
    )
    r = fe(m, env)

    def u_of_z(z):
        return env.current_velocity(z)

    drag = _drag_on_line(r, m, env, u_of_z)
    scale = float(np.sum(m.weight * m.l0))
    assert np.linalg.norm(drag[:2]) > 1e-2 * scale  # the drag is not negligible
    # residual 1e-10 of the reference force per node, 101 nodes
    # the end forces are what the line exerts on its supports: they sum to the loads
    assert np.allclose(r.force_a[:2] + r.force_b[:2], drag[:2], rtol=0, atol=1e-7 * scale)
    assert r.force_a[2] + r.force_b[2] == pytest.approx(-scale + drag[2], abs=1e-7 * scale)
    assert r.iterations < 60


def test_load_stepping_rescues_drag_dominated_line():
    # A light line (net weight 19 N/m) in a 2 m/s current (drag 370 N/m).  The load
    # stepping of the drag is reached by construction, not by the full-load Newton
    # failing (whether that stalls depends on the CPU's floating point): with
    # full_load_iterations=0 the first attempt at full drag takes no iteration, and
    # its start (the current-free equilibrium) is far from the equilibrium with
    # current, so only the stepping can converge.
    from stochcable.line.chain import initial_guess
    from stochcable.line.equilibrium import LocalFrame, StaticsModel, StaticsSolver

    seg = dict(length=600.0, ea=1e8, mass=20.0, diameter=0.15, elements=60)
    m, env, _ = make(
        (-400, 0, -100), (0, 0, -20), [seg], current=[{"z": 0.0, "speed": 2.0, "heading": 0.0}]
    )
    frame = LocalFrame(m, env)
    model = StaticsModel(m, env, frame)
    r_start = StaticsSolver(model, 1e-10, 500).status(initial_guess(m, env, frame, model))[0]
    assert r_start > 1e-2  # the start is not an equilibrium with the drag
    r = solve_fe(m, env, None, 1e-10, 500, full_load_iterations=0)
    assert r.residual < 1e-10
    drag = _drag_on_line(r, m, env, env.current_velocity)
    assert np.linalg.norm(drag[:2]) > 1.5 * float(np.sum(m.weight * m.l0))  # drag-dominated
    # the end forces (what the line exerts on its supports) balance the drag
    assert r.force_a[0] + r.force_b[0] == pytest.approx(drag[0], rel=1e-6)
    assert r.force_a[1] + r.force_b[1] == pytest.approx(drag[1], abs=1e-6 * abs(drag[0]))
    # the default (a quarter of the budget at full drag first, then the stepping)
    # reaches the same equilibrium, whichever path converges on this CPU
    d = fe(m, env)
    np.testing.assert_allclose(d.positions, r.positions, rtol=0, atol=1e-6)


def _chain_in_current():
    """A 20-element chain in a 0.5 m/s current: its mesh, environment, frame, private
    FE statics model and the initial guess (for the model-level tests below)."""
    from stochcable.line.chain import initial_guess
    from stochcable.line.equilibrium import LocalFrame, StaticsModel

    m, env, _ = make(
        (-800, 0, -200),
        (0, 0, -20),
        [dict(CHAIN, elements=20)],
        current=[{"z": 0.0, "speed": 0.5, "heading": 0.0}],
    )
    frame = LocalFrame(m, env)
    model = StaticsModel(m, env, frame)
    return m, env, frame, model, initial_guess(m, env, frame, model)


def test_repeated_residual_reuses_the_same_numbers():
    """StaticsModel.forces remembers the residual of the last position (the Newton iteration
    asks twice per accepted point): a repeated call returns the numbers of a fresh
    model to the bit, with or without the tangent, also with current drag (whose nodal
    drag forces the line search reads) and after the drag factor changes."""
    from stochcable.line.equilibrium import LocalFrame, StaticsModel

    m, env, frame, b, x = _chain_in_current()
    x2 = x.copy()
    x2[1:-1, -1] += 0.1
    for beta in (1.0, 0.5):
        b.beta = beta
        for X in (x, x2):
            b.forces(X, tangent=False)  # remembered without the tangent ...
            got = b.forces(X.copy())  # ... then asked again with it
            drag_nodes = b.drag_nodes.copy()
            ref = StaticsModel(m, env, LocalFrame(m, env))  # fresh: no memory
            ref.beta = beta
            want = ref.forces(X)
            for g_, w_ in zip(got[:2], want[:2]):
                np.testing.assert_array_equal(g_, w_)
            assert got[2] == want[2]
            for g_, w_ in zip(got[3], want[3]):
                np.testing.assert_array_equal(g_, w_)
            np.testing.assert_array_equal(drag_nodes, ref.drag_nodes)
            got[0][:] = 0.0  # callers may change the returned residual
            np.testing.assert_array_equal(b.forces(X, tangent=False)[0], want[0])


def test_chain_shots_batched_end_equals_single_shots() -> None:
    """The batched end closure of the chain start (the central-difference Jacobian's
    four shots in one call) gives the last node of each single shot to the bit, for
    shots lifting off the bed at the anchor, part-way, and not at all (all grounded),
    on and off the seabed."""
    from stochcable.examples import load_example
    from stochcable.line.chain import chain_shots
    from stochcable.line.equilibrium import LocalFrame, StaticsModel

    scene = load_scene(load_example("chain_catenary"))
    env = scene.environment
    mesh = mesh_line(scene.lines[0], env.rho, env.g)
    frame = LocalFrame(mesh, env)
    model = StaticsModel(mesh, env, frame)
    a = frame.to_local(mesh.end_a[None, :])[0]
    zi = frame.dim - 1
    kb = np.where(model.kb > 0.0, model.kb, np.inf)
    P = -model.node_fz.copy()
    W = mesh.l0 * model.w_sub
    P[:-1] += 0.5 * W
    P[1:] += 0.5 * W
    total = float(np.sum(P))
    rng = np.random.default_rng(11)
    H = np.exp(rng.uniform(np.log(1e-3 * total), np.log(10.0 * total), 60))
    # V0 from all lifted (> 0) through lifting part-way to never lifting (< -total)
    V0 = np.r_[rng.uniform(-1.5 * total, 0.5 * total, 57), 0.2 * total, -0.5 * total, -2.0 * total]
    for on_bed in (True, False):
        shoot, shoot_ends = chain_shots(mesh, model, a, zi, on_bed, kb)
        ends = shoot_ends(H, V0, P)
        single = np.array([[shoot(h, v, P)[0][-1], shoot(h, v, P)[1][-1]] for h, v in zip(H, V0)])
        assert np.array_equal(ends, single)  # bit-equal: the same float operations


def test_banded_solve_is_scipy_solve_banded():
    """banded_solve calls LAPACK gbsv as scipy.linalg.solve_banded does after its
    checks (issue 6 pass E6: ≈ 40 banded solves per body statics): the same solution
    to the bit for one and several right-hand sides; a singular matrix raises
    LinAlgError."""
    from scipy.linalg import LinAlgError, solve_banded

    from stochcable.line.banded import banded_solve

    rng = np.random.default_rng(7)
    for bw, n, nrhs in ((3, 40, None), (5, 117, None), (5, 117, 3)):
        band = rng.standard_normal((2 * bw + 1, n))
        band[bw] += 4.0 * bw  # diagonally dominant: a regular matrix
        b = rng.standard_normal(n if nrhs is None else (n, nrhs))
        ab = np.zeros((3 * bw + 1, n), order="F")
        ab[bw:] = band
        got = banded_solve(ab, b, bw)
        np.testing.assert_array_equal(got, solve_banded((bw, bw), band, b))
    singular = np.zeros((3 * 3 + 1, 6), order="F")
    with pytest.raises(LinAlgError, match="singular"):
        banded_solve(singular, np.ones(6), 3)


def test_converged_status_skips_the_tangent_and_solves_the_same():
    """The Newton asks its status without the tangent (issue 6 pass E6: a converged
    point needs none) and builds it from the residual memo before a step: the status
    numbers are those with the tangent, and the tangent built afterwards is a fresh
    model's to the bit (with current drag, whose nodal forces the line search reads)."""
    from stochcable.line.equilibrium import LocalFrame, StaticsModel, StaticsSolver

    m, env, frame, model, x = _chain_in_current()
    lazy = StaticsSolver(model, 1e-10, 100).status(x, tangent=False)
    assert lazy[3] is None
    tangent = model.forces(x)[3]
    ref_model = StaticsModel(m, env, LocalFrame(m, env))
    full = StaticsSolver(ref_model, 1e-10, 100).status(x)
    assert lazy[:2] == full[:2]
    np.testing.assert_array_equal(lazy[2], full[2])
    for got, want in zip(tangent, full[3]):
        np.testing.assert_array_equal(got, want)
