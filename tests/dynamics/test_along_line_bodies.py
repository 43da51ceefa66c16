"""The residuals along a line on free bodies
(stochcable.dynamics.residuals.along_line_bodies): the element tensions per unit node
force through the coupled group.

Independent checks: the element tensions of the coupled influence against the
assembled lines–body system solved directly (couple + coupled_load +
solve_coupled_direct, dense); a line without attached ends keeps the ends-held
influence; the coupled end influence in place of the elements' gives the kinds' end
lines of the line on its body (the plumbing); the anchor element's residual ratio
against the anchor's."""

from __future__ import annotations

import numpy as np
import pytest
from _scenes import along_line_arguments, coupled_leg_motions
from test_body_residual import buoy_group  # noqa: F401  (the fixture)

from stochcable import load_example
from stochcable.dynamics.groups import CoupledLine
from stochcable.dynamics.residuals.along_line import element_influence, element_lines, element_rows
from stochcable.dynamics.residuals.along_line_3d import vector_lines
from stochcable.dynamics.residuals.along_line_bodies import ElementCoupledInfluence
from stochcable.dynamics.residuals.body_residual import CoupledInfluence, coupled_influences

RHO = 1025.0


def test_element_influence_through_the_body_equals_the_assembled_system(buoy_group):  # noqa: F811
    """Random node forces on one 3-D leg of the buoy (three load cases, frequencies up
    to 3·ω_max as the residual lines reach): the element tensions r_e·u of the
    assembled coupled system's solution against the coupled element influence, to
    1e-9 of the largest (the dense solve's conditioning, as the end test's); the
    body's motion changes them (the ends-held influence differs by more than 1e-3)."""
    scene, cls, loads, body, lin = buoy_group
    w = np.linspace(0.1, 6.0, 25)
    damp = {cl.name: lin.lines[cl.name].damping for cl in cls}
    infl = coupled_influences(cls, [body], damp, lin.body_drag)
    cl = cls[0]
    model = cl.system.model
    n, d = model.n_nodes, model.dim
    elements = np.array([0, 3, model.n_elements - 1])
    rng = np.random.default_rng(4)
    f = rng.standard_normal((model.n_dof, 3)) + 1j * rng.standard_normal((model.n_dof, 3))
    g = ElementCoupledInfluence(infl[cl.name], elements).on(w)  # (n_el, n, d, n_w)
    got = np.einsum("enkw,nkc->ewc", g, f.reshape(n, d, 3))
    u = coupled_leg_motions(buoy_group, f, w)  # (n_w, n, d, 3)
    rows = element_rows(model)[elements]
    ref = np.einsum("ed,wedc->ewc", rows[:, 0], u[:, elements]) + np.einsum(
        "ed,wedc->ewc", rows[:, 1], u[:, elements + 1]
    )
    np.testing.assert_allclose(got, ref, rtol=1e-9, atol=1e-9 * np.abs(ref).max())
    held = element_influence(cl.system, damp[cl.name], w, elements)
    held = np.einsum("enkw,nkc->ewc", held, f.reshape(n, d, 3))
    assert np.abs(held - ref).max() > 1e-3 * np.abs(ref).max()


def test_a_line_without_attached_ends_keeps_the_held_element_influence(buoy_group):  # noqa: F811
    """The same leg with no end on a body: the ends-held element influence (to
    round-off)."""
    scene, cls, loads, body, lin = buoy_group
    cl = cls[1]
    damp = {cl.name: lin.lines[cl.name].damping}
    base = coupled_influences([CoupledLine(cl.system, cl.channels)], [body], damp, {})[cl.name]
    w = np.linspace(0.2, 4.0, 7)
    at = np.array([0, 5, 9])
    got = ElementCoupledInfluence(base, at).on(w)
    ref = element_influence(cl.system, damp[cl.name], w, at)
    np.testing.assert_allclose(got, ref, rtol=1e-10, atol=1e-12 * np.abs(ref).max())


@pytest.fixture(scope="module", params=["single", "three"])
def buoy(request):
    """The disc buoy's leg(s) (single: a planar body; three: 3-D legs), both
    residuals; each line's along-line arguments kept."""
    name = f"tuah_1982_disc_buoy_{request.param}_leg{'s' if request.param == 'three' else ''}"
    doc = load_example(name).model_dump(mode="json")
    doc["analysis"].pop("timeseries", None)
    doc["analysis"]["linearization"].update(drag_residual=True, geometric_residual=True)
    return along_line_arguments(doc)


def test_coupled_end_rows_reproduce_the_kinds_end_lines(buoy):
    """Each line's captured residual loads contracted with its coupled end influence
    (in place of the elements') give each kind's end lines of the line on the buoy to
    round-off (1e-10): the element tensions see the same loads through the same
    group."""
    result, seen = buoy
    for name, line in result.lines.items():
        sn = seen[name]
        assert line.along_line.computed, line.along_line.reason
        system, damping = sn["system"], sn["damping"]
        probe = sn["influence_of"](np.array([0]))
        ends = CoupledInfluence(probe.name, probe.lines, probe.bodies, probe.body_drag)
        for kind, tap in sn["taps"].items():
            if getattr(tap, "vectors", None):
                got = vector_lines(system, damping, tap.vectors[0], ends)
            else:
                got = element_lines(system, damping, kind, tap.captures, ends, feedthrough=False)
            _, ref = line.residuals[kind].lines[0]
            for k, end in enumerate(("end_a", "end_b")):
                scale = np.abs(ref[end]).max()
                assert scale > 0
                np.testing.assert_allclose(got[k], ref[end], rtol=1e-10, atol=1e-12 * scale)


def test_anchor_element_on_a_buoy_line_carries_the_anchor_residual(buoy):
    """The residuals' σ ratio of the anchor element against the anchor's (measured 2e-4
    on the single leg; 3e-3 allowed as the planar chain's): on the three legs the
    element tensions carry every leg's loads (their own from the line's records, the
    others' and the cross terms as the group's part, residuals.group_motion) as the
    ends do (measured 1e-4 to 3e-4), and every element raised by the residuals."""
    result, _ = buoy
    for line in result.lines.values():
        ratio_el = line.tension_std[0] / line.tension_std_linear[0]
        ratio_end = line.end_a.std / line.linear["end_a"].std
        assert ratio_el == pytest.approx(ratio_end, rel=3e-3)
        assert np.all(line.tension_std > line.tension_std_linear)
