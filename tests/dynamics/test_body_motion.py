"""The residuals in a free body's motions (stochcable.dynamics.residuals.body_motion).

Independent checks: the body DOF rows per unit node force carried to the fairlead by
rigid-body kinematics (translation + rotation × arm) equal the fairlead node's rows
of the coupled node influence (itself checked against the assembled lines–body
system, tests/dynamics/test_along_line_motion.py); on the single-leg disc buoy the
fairlead node's residual variance equals the body's residual carried to it through
the same rows; switches off give the linear statistics bit for bit."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from test_body_residual import buoy_group  # noqa: F401  (the fixture)

import stochcable.dynamics.groups.results as group_results
from stochcable import analyze, load_example
from stochcable.dynamics.residuals.along_line_bodies import NodeCoupledInfluence
from stochcable.dynamics.residuals.body_motion import BodyCoupledInfluence, body_motion_parts
from stochcable.dynamics.residuals.body_residual import coupled_influences


def rigid_3d(r: np.ndarray) -> np.ndarray:
    """The point motion (3, 6) of the 6 DOFs at arm ``r``: t + θ × r."""
    x, y, z = r
    return np.hstack([np.eye(3), np.array([[0, z, -y], [-z, 0, x], [y, -x, 0]])])


def test_body_rows_carried_to_the_fairlead_equal_its_node_rows(buoy_group):  # noqa: F811
    """The three-leg buoy (6 DOFs), each leg, 25 frequencies to 6 rad/s: T(r)·ξ rows
    equal the fairlead node's coupled rows to 1e-9 of the largest (the same solves in
    another order: round-off; bound as the node test's)."""
    scene, cls, loads, body, lin = buoy_group
    w = np.linspace(0.1, 6.0, 25)
    damp = {cl.name: lin.lines[cl.name].damping for cl in cls}
    infl = coupled_influences(cls, [body], damp, lin.body_drag)
    for cl in cls:
        model = cl.system.model
        xi = BodyCoupledInfluence(infl[cl.name]).on(w)  # (6, n, d, n_w)
        node = NodeCoupledInfluence(infl[cl.name], np.array([model.n_nodes - 1])).on(w)
        arm = np.asarray(model.positions[-1]) - np.asarray(body.position)
        got = np.einsum("pk,knjw->pnjw", rigid_3d(arm), xi)
        np.testing.assert_allclose(got, node, rtol=0, atol=1e-9 * np.abs(node).max())
        assert np.abs(xi[3:]).max() > 1e-3 * np.abs(xi[:3]).max()  # (rotations count)


def _disc(residuals: bool) -> dict:
    doc = load_example("tuah_1982_disc_buoy_single_leg").model_dump(mode="json")
    doc["analysis"]["linearization"].update(drag_residual=residuals, geometric_residual=residuals)
    doc["analysis"].pop("timeseries", None)
    return doc


def test_disc_buoy_fairlead_residual_is_the_bodys_carried_to_it(monkeypatch):
    """Single-leg disc buoy (planar: surge, heave, pitch about +y): the fairlead node's
    residual variance (its station, x and z) equals the variance of the body's rows
    carried to the fairlead (u_x = surge + θ r_z, u_z = heave − θ r_x) driven by the
    same residual loads, to 1e-9 relative (same loads, rows and resonant cells:
    round-off), and the line's own record to 2e-3 (its cells chosen over its four
    stations); the body's surge σ rises with them."""
    seen = []

    def spy(system, damping, applied, taps, influence, transfer, spectra):  # noqa: ANN001, ANN202
        out = body_motion_parts(system, damping, applied, taps, influence, transfer, spectra)
        seen.append((system, damping, applied, taps, influence, transfer, spectra))
        return out

    monkeypatch.setattr(group_results, "body_motion_parts", spy)
    # (the line's own loads: the body's own drag residual, one more part of the node's
    # record, is tests/dynamics/test_body_drag_residual.py's)
    monkeypatch.setattr(group_results, "body_drag_residual", lambda *a, **k: None)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = analyze(_disc(True))
    (system, damping, applied, taps, influence, transfer, spectra) = seen[0]
    leg = next(iter(res.lines.values()))
    body = next(iter(res.bodies.values()))
    model = system.model
    # the arm from the body's static pose (its statistics' mean) to the fairlead node
    rx = model.positions[-1][0] - body.motion["surge"].mean
    rz = model.positions[-1][2] - body.motion["heave"].mean
    t = np.array([[1.0, 0.0, rz], [0.0, 1.0, -rx]])  # (x, z) of (surge, heave, pitch)

    class Carried(BodyCoupledInfluence):
        def through_bodies(self, c, tf, xi, free):  # noqa: ANN001, ANN202
            full = np.zeros((xi.shape[0], 3, xi.shape[2]), dtype=complex)
            full[:, free] = xi
            return np.einsum("pk,wka->wpa", t, full)

    carried = Carried(influence)
    carried.elements = np.arange(2)
    lin_t = np.einsum("pk,ckw->cpw", t, transfer)
    parts = body_motion_parts(system, damping, applied, taps, carried, lin_t, spectra)
    got = sum(v.sum(axis=1) for _, v in parts)
    node = NodeCoupledInfluence(influence, np.array([model.n_nodes - 1]))
    lin_n = np.asarray(leg.motion_transfer)[:, -1][:, [0, 2]]
    ref = sum(
        v.sum(axis=1)
        for _, v in body_motion_parts(system, damping, applied, taps, node, lin_n, spectra)
    )
    np.testing.assert_allclose(got, ref, rtol=1e-9)
    # the line's own record: its stations' sub-sampled resonant cells are chosen over
    # all four station nodes' rows (bent_cells), the body's over its three DOFs: the
    # same rows and loads, another cell set (measured 1.1e-3 in x; z, 1e-3 of x's
    # variance, 7e-3)
    rec = leg.motion_residual.variance[-1][[0, 2]]
    np.testing.assert_allclose(got, rec, rtol=2e-3, atol=1e-2 * abs(rec[0]))
    assert body.motion["surge"].std > 1.2 * body.motion_linear["surge"].std


def test_switches_off_give_the_linear_body_motion():
    """Residuals off: no linear copy and the statistics equal the linear ones of the
    run with them, bit for bit."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        on = next(iter(analyze(_disc(True)).bodies.values()))
        off = next(iter(analyze(_disc(False)).bodies.values()))
    assert off.motion_linear is None and on.motion_linear is not None
    for k in off.dofs:
        assert off.motion[k] == on.motion_linear[k]
    assert "std_linear" in on.to_document()["motion"]["surge"]
    assert "std_linear" not in off.to_document()["motion"]["surge"]


def test_prescribed_bodies_stay_linear():
    """A vessel moving by its RAO keeps the linear motion (a group of several lines:
    tests/dynamics/test_group_motion.py)."""
    doc = load_example("cable_laying").model_dump(mode="json")
    doc["analysis"].pop("timeseries", None)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = analyze(doc)
    for b in res.bodies.values():
        assert b.motion_linear is None


def test_dataset_carries_the_linear_body_sigma():
    """The xarray view: body_motion_std_linear beside body_motion_std (the document's
    std_linear)."""
    pytest.importorskip("xarray")
    from stochcable.results.datasets import dataset_from_result

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = analyze(_disc(True))
    ds = dataset_from_result(res)
    body = next(iter(res.bodies.values()))
    got = float(ds["body_motion_std_linear"].sel(body=body.name, dof="surge"))
    assert got == body.motion_linear["surge"].std
    assert float(ds["body_motion_std"].sel(body=body.name, dof="surge")) == body.motion["surge"].std
