"""The line's drag form (docs/travelling.md): cross flow ½ρC_dD|V_n|V_n or Hu & Jin
(2001, eq. 6) ½ρC_dD|V|V_n, in the statics and the linearization."""

from __future__ import annotations

import numpy as np
import pytest

RHO, CD, DIA = 1025.0, 1.2, 0.1
SPAN = np.array([300.0, 0.0, 200.0])  # an inclined chord (34° up)
U = np.array([0.8, 1.0, 0.0])  # current with an axial part on the chord


def _scene(form: str, c: float) -> dict:
    return {
        "environment": {
            "depth": 500.0,
            "rho": RHO,
            "current": [
                {
                    "z": 0.0,
                    "speed": float(np.hypot(*U[:2])),
                    "heading": float(np.degrees(np.arctan2(U[1], U[0]))),
                }
            ],
        },
        "lines": [
            {
                "name": "taut",
                "end_a": {"position": [0.0, 0.0, -400.0]},
                "end_b": {"position": (SPAN + [0.0, 0.0, -400.0]).tolist()},
                "segments": [
                    {
                        "length": float(np.linalg.norm(SPAN)) / 1.001,
                        "ea": 1.0e10,
                        "mass": 50.0,
                        "diameter": DIA,
                        "cd_normal": CD,
                        "weight": 0.0,
                        "elements": 40,
                    }
                ],
                "axial_speed": c,
                "drag_form": form,
            }
        ],
    }


@pytest.mark.parametrize("form", ["cross_flow", "hu_jin"])
@pytest.mark.parametrize("c", [0.0, 2.0])
def test_taut_inclined_cable_normal_drag_closed_form(form, c):
    """A weightless taut straight cable (T ≈ 10 MN, slopes ~3e-3) in a uniform flow
    with transport: the mid-span deflection along the normal flow V_n is f L²/(8T) of
    the uniform load f = ½ρC_dD|V|·|V_n| (Hu & Jin) or ½ρC_dD|V_n|² (cross flow),
    V = U − c e.  A string with equal nodal loads has its nodes on the parabola, so the
    tolerance 1e-4 covers the load's follower change with the slope (second order,
    ~1e-5)."""
    from stochcable.statics import solve_statics

    st = solve_statics(_scene(form, c)).lines["taut"]
    length = float(np.linalg.norm(SPAN))
    e = SPAN / length
    w = U @ e - c
    vn = U - (U @ e) * e
    mag = np.hypot(np.linalg.norm(vn), w) if form == "hu_jin" else np.linalg.norm(vn)
    f = 0.5 * RHO * CD * DIA * mag * np.linalg.norm(vn)
    t = float(np.mean(st.tension))
    mid = st.positions[20] - (st.positions[0] + st.positions[-1]) / 2
    sag = mid @ (vn / np.linalg.norm(vn))
    assert sag == pytest.approx(f * length**2 / (8.0 * t), rel=1e-4)


def test_hu_jin_without_axial_flow_is_cross_flow():
    """No axial relative flow on the chord (current normal, no transport): |V| = |V_n|
    up to the deflected tangents' axial flow U·e ~ slope·U (slopes ~3e-3, so |V|/|V_n|
    − 1 ~ 5e-6): the same statics to 1e-5 relative (measured 5e-7)."""
    from stochcable.statics import solve_statics

    docs = [_scene(f, 0.0) for f in ("cross_flow", "hu_jin")]
    for d in docs:
        d["environment"]["current"][0]["heading"] = 90.0  # along y, normal to the chord
    a, b = (solve_statics(d).lines["taut"].positions for d in docs)
    np.testing.assert_allclose(a, b, rtol=1e-5, atol=1e-9)


def test_cli_statics_carries_the_drag_form(tmp_path, capsys):
    """``stochcable statics`` reads the field: with transport the Hu & Jin normal drag
    (|V|/|V_n| = 2.4 here) raises the end tension of the taut cable."""
    import json

    from stochcable.cli import main

    tension = {}
    for form in ("cross_flow", "hu_jin"):
        f = tmp_path / f"{form}.json"
        f.write_text(json.dumps(_scene(form, 2.0)))
        assert main(["statics", str(f), "--format", "json"]) == 0
        doc = json.loads(capsys.readouterr().out)
        tension[form] = doc["statics"]["lines"]["taut"]["end_b"]["tension"]
    assert tension["hu_jin"] > tension["cross_flow"]


def test_bad_drag_form_names_the_field():
    from stochcable.errors import InputError
    from stochcable.scene.model import load_scene

    with pytest.raises(InputError, match=r"lines\[0\]\.drag_form.*'cross_flow' or 'hu_jin'"):
        load_scene(_scene("morison", 0.0))


def test_statics_tangent_of_the_hu_jin_drag_by_differences():
    """The statics' analytic tangent −∂R/∂X with the Hu & Jin drag (its extra term
    (rel/|V|) V_n uᵀ) equals central differences of the residual (h = 1e-6 m: error
    ~1e-7 N/m of round-off, against drag-tangent entries ~40 N/m; measured 3e-7) on a
    travelling 3-D line in an oblique current, at perturbed (non-equilibrium) nodes."""
    from dataclasses import replace

    from stochcable.line.equilibrium import LocalFrame, StaticsModel
    from stochcable.line.mesh import mesh_line
    from stochcable.scene.model import load_scene

    doc = _scene("hu_jin", 1.5)
    doc["environment"]["current"][0].update(speed=0.7, heading=30.0)
    doc["lines"][0]["segments"][0].update(ea=1e5, elements=8)
    scene = load_scene(doc)
    env = scene.environment
    m = mesh_line(scene.lines[0], env.rho, env.g)
    assert m.drag_form == "hu_jin"
    frame = LocalFrame(m, env)
    model = StaticsModel(m, env, frame)
    ends = frame.to_local(np.stack([m.end_a, m.end_b]))
    x = np.linspace(ends[0], ends[1], m.n_nodes)
    x[1:-1] += np.random.default_rng(34).normal(scale=3.0, size=x[1:-1].shape)
    kd, ku, kl = model.forces(x)[3]
    h, worst, big = 1e-6, 0.0, 0.0
    for i in range(1, m.n_nodes - 1):
        for c in range(x.shape[1]):
            xp, xm = x.copy(), x.copy()
            xp[i, c] += h
            xm[i, c] -= h
            dr = (model.forces(xp, tangent=False)[0] - model.forces(xm, tangent=False)[0]) / (2 * h)
            for j, col in ((i, kd[i][:, c]), (i - 1, ku[i - 1][:, c]), (i + 1, kl[i][:, c])):
                worst = max(worst, float(np.abs(-dr[j] - col).max()))
                big = max(big, float(np.abs(col).max()))
    assert worst <= 1e-6 * big
    cross = StaticsModel(replace(m, drag_form="cross_flow"), env, frame).forces(x)[3][0]
    assert np.abs(cross - kd).max() > 1e-3 * big  # the form changes the tangent
