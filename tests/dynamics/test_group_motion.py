"""The residuals in the motions of free bodies of several lines
(stochcable.dynamics.residuals.group_motion): the body DOFs as output rows of the
group's joint sums over every line's residual loads.

Independent checks: the body DOFs per unit load of every leg against the assembled
lines–body system solved directly; the joint drag sum's body lines against the same
sum formed from the assembled system's transfers; the closed form against Monte Carlo
(tests/dynamics/test_body_residual.py, the two-leg cross-terms test); a mirrored
two-leg buoy's motions; a symmetric three-leg buoy's sway stays at rest (the cross
terms cancel it, a sum of the legs' variances would not); switches off give the linear
motion bit for bit; a single-line group keeps its own path."""

from __future__ import annotations

import warnings

import numpy as np
from _scenes import analyzed_group as _group_of
from _scenes import assembled_group as _assembled
from _scenes import two_leg_buoy_doc as _two_leg_doc
from test_body_residual import buoy_group  # noqa: F401  (a fixture)

import stochcable.dynamics.groups.results as group_results
from stochcable import analyze, load_example
from stochcable.bodies.coupling import coupled_load
from stochcable.dynamics.residuals import drag_residual
from stochcable.dynamics.residuals.body_motion import BodyCoupledInfluence
from stochcable.dynamics.residuals.body_residual import coupled_influences
from stochcable.dynamics.residuals.group_motion import BodyRows, body_rows_of
from stochcable.dynamics.residuals.residual_lines import load_transfer
from stochcable.reference.bodies import solve_coupled_direct


def _body_rows(system, name, unit, w, bodies):
    """Every body DOF (group order) per unit load case ``unit`` (n_nodes, d, k) on line
    ``name`` of the assembled system: (n_dof, k, n_w)."""
    n = unit.shape[0] * unit.shape[1]
    f = np.broadcast_to(unit.reshape(n, -1), (w.size, n, unit.shape[2]))
    x = solve_coupled_direct(system, coupled_load(system, w, line_loads={name: f}), w, "dense")
    rows = np.concatenate([system.body_dofs[b.name] for b in bodies])
    return np.transpose(x[:, rows], (1, 2, 0))


def test_body_rows_of_every_leg_equal_the_assembled_system():
    """Two-leg planar buoy: the body DOFs per unit drag panel load of each leg through
    the group (the rows the joint sums take, and the single-line path's) against the
    assembled lines–body system solved directly, at the residual's lines: to 1e-9 of
    the largest (measured ~1e-13; the dense solve's conditioning)."""
    from stochcable.dynamics.residuals.drag_residual import drag_components

    _, cls, bodies, clin = _group_of(_two_leg_doc())
    system, damp = _assembled(cls, bodies, clin)
    infl = coupled_influences(cls, bodies, damp, clin.body_drag, clin.lines)
    for c in cls:
        comp = drag_components(c.system, c.channels, clin.lines[c.name], 3, True)
        w = comp.w_out[:: max(1, comp.w_out.size // 30)]
        ref = _body_rows(system, c.name, comp.unit, w, bodies)
        assert np.abs(ref).max() > 0
        for through in (BodyCoupledInfluence(infl[c.name]), BodyRows(infl).body(c.name)):
            got = load_transfer(c.system, damp[c.name], comp.unit, w, through)
            np.testing.assert_allclose(got, ref, rtol=0, atol=1e-9 * np.abs(ref).max())


def test_three_leg_body_rows_equal_the_assembled_system(buoy_group):  # noqa: F811
    """Three 3-D legs on a 6-DOF buoy: each leg's unit node forces (random, fixed seed)
    to the body DOFs, as above: to 1e-9 of the largest."""
    _, cls, _, body, lin = buoy_group
    system, damp = _assembled(cls, [body], lin)
    infl = coupled_influences(cls, [body], damp, lin.body_drag)
    rng = np.random.default_rng(5)
    w = np.linspace(0.1, 4.0, 12)
    for c in cls:
        m = c.system.model
        unit = rng.standard_normal((m.n_nodes, m.dim, 3))
        got = load_transfer(c.system, damp[c.name], unit, w, BodyRows(infl).body(c.name))
        ref = _body_rows(system, c.name, unit, w, [body])
        np.testing.assert_allclose(got, ref, rtol=0, atol=1e-9 * np.abs(ref).max())


def _rows_run(doc: dict, monkeypatch) -> tuple:
    """``doc`` analysed with its group's BodyRows kept (and its group)."""
    seen = {}
    real = group_results.body_rows_of

    def keep(influences, stations=None):  # noqa: ANN001, ANN202
        seen["rows"] = real(influences, stations)
        return seen["rows"]

    monkeypatch.setattr(group_results, "body_rows_of", keep)
    res, cls, bodies, clin = _group_of(doc)
    return res, cls, bodies, clin, seen["rows"]


def test_joint_body_lines_equal_the_sums_of_the_assembled_transfers(monkeypatch):
    """Two-leg planar buoy, every panel and element kept (floors 0), cells not
    integrated: the drag (Mehler) and geometric (Isserlis) joint sums' body lines
    equal the same closed forms over both legs' components with the body DOFs per
    unit component of the assembled system: to 1e-8 of the largest line (the
    transfers agree to ~1e-13; the sums add them in another order)."""
    from stochcable.dynamics.residuals import geometric_residual
    from stochcable.dynamics.residuals.drag_residual import residual_output_lines
    from stochcable.dynamics.residuals.geometric_residual import quadratic_output_lines

    monkeypatch.setattr(drag_residual, "PANEL_FLOOR", 0.0)
    monkeypatch.setattr(geometric_residual, "ELEMENT_FLOOR", 0.0)
    monkeypatch.setattr(BodyRows, "_cells", lambda self, p, t, w, b, of, n: np.ones((n, w.size)))
    _, cls, bodies, clin, rows = _rows_run(_two_leg_doc(), monkeypatch)
    system, _ = _assembled(cls, bodies, clin)
    kept = next(iter(rows.influences.values())).shared["components"]
    keys = {k[0]: k for k in rows.lines}
    assert set(keys) == {"drag", "geometric"}
    comps = [kept[keys["drag"], c.name] for c in cls]
    t = np.concatenate([_body_rows(system, c.name, k.unit, k.w_out, bodies)
                        for c, k in zip(cls, comps)], axis=1)  # fmt: skip
    ref = residual_output_lines(
        np.concatenate([k.lines for k in comps], axis=1),
        np.concatenate([k.scale for k in comps]),
        np.concatenate([k.coeffs for k in comps]),
        t,
        comps[0].n_fft,
    )
    got = rows.lines[keys["drag"]][1]
    np.testing.assert_allclose(got, ref, rtol=0, atol=1e-8 * np.abs(ref).max())
    comps = [kept[keys["geometric"], c.name] for c in cls]
    n_t = len(comps[0].terms)
    t = np.concatenate([
        _body_rows(system, c.name, k.unit, k.w_out, bodies).reshape(3, n_t, -1, k.w_out.size)
        for c, k in zip(cls, comps)], axis=2)  # fmt: skip
    proc = [np.concatenate([k.proc[i] for k in comps], axis=1) for i in range(len(comps[0].proc))]
    ref = quadratic_output_lines(proc, comps[0].terms, t.reshape(3, -1, t.shape[3]), comps[0].n_fft)
    got = rows.lines[keys["geometric"]][1]
    np.testing.assert_allclose(got, ref, rtol=0, atol=1e-8 * np.abs(ref).max())


def _quiet(doc: dict):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return analyze(doc)


def test_mirrored_two_leg_buoy_mirrors_the_body_motion():
    """The two-leg buoy mirrored (sea from the other side, wind reversed): the body's
    corrected σ of surge, heave and pitch equal the original's to 1e-10 (mirrored
    solves: the same arithmetic up to order, as the legs' residuals); the correction
    moves surge (by more than 4 %: measured +8.4 %)."""
    mirror = _quiet(_two_leg_doc(heading=180.0, wind=-100.0))
    doc = _two_leg_doc()
    doc["bodies"][0].pop("hydrodynamics")
    res = _quiet(doc)
    (a,), (b,) = res.bodies.values(), mirror.bodies.values()
    for dof in a.dofs:
        np.testing.assert_allclose(b.motion[dof].std, a.motion[dof].std, rtol=1e-10)
        np.testing.assert_allclose(b.motion_linear[dof].std, a.motion_linear[dof].std, rtol=1e-10)
    assert a.motion["surge"].std > 1.04 * a.motion_linear["surge"].std


def _three_legs(residuals: bool) -> dict:
    doc = load_example("tuah_1982_disc_buoy_three_legs").model_dump(mode="json")
    doc["analysis"]["linearization"].update(drag_residual=residuals, geometric_residual=residuals)
    doc["analysis"].pop("timeseries", None)
    return doc


def test_three_leg_buoy_sway_stays_at_rest_and_switches_off_give_the_linear_motion():
    """The three-leg disc buoy (legs symmetric about the sea's plane): its residual
    moves surge (measured σ +42 %) but not sway, whose linear σ is 0 — the joint sum's
    cross terms between the two side legs cancel it (a sum of each leg's variance
    would read 1.5 ft): below 1e-6 of surge's σ (round-off).  Switches off: no linear
    copy and the statistics of the linear copy of the run with them, bit for bit."""
    on = next(iter(_quiet(_three_legs(True)).bodies.values()))
    off = next(iter(_quiet(_three_legs(False)).bodies.values()))
    assert on.motion_linear is not None and off.motion_linear is None
    for k in off.dofs:
        assert off.motion[k] == on.motion_linear[k]
    assert on.motion["surge"].std > 1.2 * on.motion_linear["surge"].std
    assert on.motion["sway"].std < 1e-6 * on.motion["surge"].std


def test_three_leg_fairleads_move_alike_with_their_residuals():
    """The three-leg disc buoy's fairlead nodes move with the buoy, at arms that differ
    in x and y only: their x σ (surge + pitch × the common z arm) are equal in the
    linear model (to 0.1 %) and stay so with every leg's residual loads, each node's
    own part from its leg's record and the group's part from the joint sums: within
    0.5 % (measured 0.23 %; with the leg's own loads only they differed by 10 %)."""
    res = _quiet(_three_legs(True))
    x = [float(np.asarray(ln.motion_std)[-1][0]) for ln in res.lines.values()]
    lin = [float(np.asarray(ln.motion_std_linear)[-1][0]) for ln in res.lines.values()]
    assert max(lin) / min(lin) - 1 < 1e-3
    assert max(x) / min(x) - 1 < 5e-3
    assert min(x) > 1.2 * max(lin)


def test_a_single_line_group_keeps_its_own_path():
    """A group of one line gets no joint body rows (residuals.body_motion's path, its
    own loads being the group's; tests/dynamics/test_body_motion.py)."""
    _, cls, bodies, clin = _group_of(
        load_example("tuah_1982_disc_buoy_single_leg").model_dump(mode="json")
    )
    damp = {c.name: clin.lines[c.name].damping for c in cls}
    infl = coupled_influences(cls, bodies, damp, clin.body_drag, clin.lines)
    assert len(infl) == 1 and body_rows_of(infl) is None
    assert "extra_rows" not in next(iter(infl.values())).shared


def _station_refs(system, cl, unit_line, unit, w, el, nodes):
    """Line ``cl``'s element tensions at ``el`` and node motions at ``nodes`` (d each,
    node-major) per unit load case ``unit`` on line ``unit_line`` of the assembled
    system: (n_el + n_nodes·d, k, n_w)."""
    from stochcable.bodies.coupling import expand_line
    from stochcable.dynamics.residuals.influence import element_rows

    n = unit.shape[0] * unit.shape[1]
    f = np.broadcast_to(unit.reshape(n, -1), (w.size, n, unit.shape[2]))
    x = solve_coupled_direct(system, coupled_load(system, w, line_loads={unit_line: f}), w, "dense")
    m = cl.system.model
    u = expand_line(system, cl.name, x).reshape(w.size, m.n_nodes, m.dim, -1)
    rows = element_rows(m)[el]
    ten = np.einsum("ed,wedc->ecw", rows[:, 0], u[:, el]) + np.einsum(
        "ed,wedc->ecw", rows[:, 1], u[:, el + 1]
    )
    mot = np.transpose(u[:, nodes].reshape(w.size, -1, u.shape[3]), (1, 2, 0))
    return np.concatenate([ten, mot])


def test_station_rows_of_every_leg_equal_the_assembled_system():
    """Two-leg planar buoy: each leg's element-station tensions and node-station motions
    per unit drag panel load on either leg (its own: ends-held rows plus the body's
    path; the other's: through the body only) against the assembled lines–body system
    solved directly: to 1e-9 of the largest (the dense solve's conditioning)."""
    from stochcable.dynamics.residuals.along_line import stations
    from stochcable.dynamics.residuals.along_line_motion import motion_stations
    from stochcable.dynamics.residuals.drag_residual import drag_components

    _, cls, bodies, clin = _group_of(_two_leg_doc())
    system, damp = _assembled(cls, bodies, clin)
    infl = coupled_influences(cls, bodies, damp, clin.body_drag, clin.lines)
    st = {c.name: (stations(c.system.model), motion_stations(c.system.model)) for c in cls}
    rows = BodyRows(infl, st)
    for c in cls:  # the loaded leg
        comp = drag_components(c.system, c.channels, clin.lines[c.name], 3, True)
        w = comp.w_out[:: max(1, comp.w_out.size // 20)]
        for tgt in cls:
            of = {kind: o for kind, line, _, o in rows.sets if line == tgt.name}
            got = np.concatenate([
                load_transfer(c.system, damp[c.name], comp.unit, w, of[k](c.name))
                for k in ("elements", "nodes")
            ])  # fmt: skip
            ref = _station_refs(system, tgt, c.name, comp.unit, w, *st[tgt.name])
            assert np.abs(ref).max() > 0
            np.testing.assert_allclose(got, ref, rtol=0, atol=1e-9 * np.abs(ref).max())


def test_station_group_part_equals_the_sums_of_the_assembled_transfers(monkeypatch):
    """Two-leg planar buoy, every panel kept, cells not integrated: each leg's stations'
    group part of the drag residual equals the Mehler sum over both legs' panels less
    the sum over the leg's own, with the stations' rows of the assembled system: to
    1e-8 of the joint sum's largest line (the transfers agree to ~1e-13; a difference
    of two sums)."""
    from stochcable.dynamics.residuals.along_line import stations
    from stochcable.dynamics.residuals.along_line_motion import motion_stations
    from stochcable.dynamics.residuals.drag_residual import residual_output_lines as rol

    monkeypatch.setattr(drag_residual, "PANEL_FLOOR", 0.0)
    monkeypatch.setattr(BodyRows, "_cells", lambda self, p, t, w, b, of, n: np.ones((n, w.size)))
    _, cls, bodies, clin, rows = _rows_run(_two_leg_doc(), monkeypatch)
    system, _ = _assembled(cls, bodies, clin)
    kept = next(iter(rows.influences.values())).shared["components"]
    key = next(k for k in rows.stations if k[0] == "drag")
    comps = {c.name: kept[key, c.name] for c in cls}
    for tgt in cls:
        at = (stations(tgt.system.model), motion_stations(tgt.system.model))
        t = {
            c.name: _station_refs(system, tgt, c.name, comps[c.name].unit, comps[c.name].w_out, *at)
            for c in cls
        }
        allc = [comps[c.name] for c in cls]
        joint = rol(
            np.concatenate([k.lines for k in allc], axis=1),
            np.concatenate([k.scale for k in allc]),
            np.concatenate([k.coeffs for k in allc]),
            np.concatenate([t[c.name] for c in cls], axis=1),
            allc[0].n_fft,
        )
        own_c = comps[tgt.name]
        own = rol(own_c.lines, own_c.scale, own_c.coeffs, t[tgt.name], own_c.n_fft)
        ref = joint - own
        got = np.concatenate(
            [rows.stations[key]["elements", tgt.name][1], rows.stations[key]["nodes", tgt.name][1]]
        )
        np.testing.assert_allclose(got, ref, rtol=0, atol=1e-8 * np.abs(joint).max())
        assert np.abs(ref).max() > 1e-3 * np.abs(joint).max()


def test_mirrored_two_leg_buoy_mirrors_the_legs_along_line():
    """The two-leg buoy mirrored: each leg's element tension σ and node motion σ (with
    its own and the other leg's residual loads) are the other leg's in the original,
    to 1e-9 (mirrored solves; the stations' sums in another order); the other leg's
    loads move them (the group's part: more than 0.1 % of the residual's variance
    somewhere; measured 4 %)."""
    mirror = _quiet(_two_leg_doc(heading=180.0, wind=-100.0))
    doc = _two_leg_doc()
    doc["bodies"][0].pop("hydrodynamics")
    res = _quiet(doc)
    for a, b in (("leg", "leg2"), ("leg2", "leg")):
        np.testing.assert_allclose(mirror.lines[b].tension_std, res.lines[a].tension_std, rtol=1e-9)
        np.testing.assert_allclose(
            mirror.lines[b].motion_std, res.lines[a].motion_std, rtol=1e-9, atol=1e-12
        )
    for name in ("leg", "leg2"):
        along = res.lines[name].along_line
        assert along.computed and len(along.lines["drag_residual"]) >= 2
        group = along.lines["drag_residual"][-1][1].sum(axis=1)
        assert np.max(np.abs(group)) > 1e-3 * np.max(np.abs(along.variance))


def test_group_station_motions_beyond_the_range_fall_back_node_by_node(monkeypatch):
    """A multi-line group adds its share to a leg's node motions
    (``group_stations.with_station_parts``): with the range limit lowered (0.02, so that
    some of the two-leg buoy's node motions cross it and others do not), the motions
    beyond it — the leg's own and those the group's share pushes over — are the linear
    model's to the bit, zero in every variance line, and the others keep their
    residuals (the group's path once checked the stations as a whole and added its
    share onto the nodes the line had left linear).  12 elements a leg: their motions'
    residual shares run 0.3–1.2 of the linear variance at the default limit, on both
    sides of 0.5."""
    import stochcable.dynamics.residuals.along_line_motion as alm

    monkeypatch.setattr(alm, "RESIDUAL_VARIANCE_LIMIT", 0.5)
    doc = _two_leg_doc()
    doc["bodies"][0].pop("hydrodynamics")
    for leg in doc["lines"]:
        leg["segments"][0]["elements"] = 12
    doc["analysis"].pop("timeseries", None)
    res = _quiet(doc)
    for line in res.lines.values():
        mr, lin = line.motion_residual, line.motion_std_linear
        assert mr.computed and mr.beyond.shape == lin.shape
        assert mr.beyond.any() and (~mr.beyond & (lin > 0)).any()
        np.testing.assert_array_equal(line.motion_std[mr.beyond], lin[mr.beyond])
        assert not np.any(mr.variance[mr.beyond])
        for parts in mr.lines.values():
            for _, v in parts:
                assert not np.any(v[mr.beyond])
        kept = ~mr.beyond & (lin > 0)
        ratio = line.motion_std[kept] ** 2 / lin[kept] ** 2 - 1.0
        assert np.all(ratio <= 0.5 + 1e-12) and np.any(ratio > 0.1)
