"""The drag residual of a 3-D line along the line
(stochcable.dynamics.residuals.along_line_3d): the vector residual's force
cross-spectra, kept as the kind forms them, contracted with the element tensions.

Independent checks: the 3-D element influence against a forward dense solve; the same
contraction with the end influence in place of the elements' against the kind's own
end lines (the plumbing of the kept blocks and the misfit); the end elements' residual
against the ends'; the time domain (slow)."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
from _scenes import along_line_arguments, forward_dense_motions, guy_3d_doc

from stochcable import analyze
from stochcable.dynamics.residuals.along_line import element_influence, element_lines, element_rows
from stochcable.dynamics.residuals.along_line_3d import vector_lines, vector_misfit_lines
from stochcable.dynamics.residuals.residual_lines import EndInfluence

ENDS = ("end_a", "end_b")


@pytest.fixture(scope="module")
def guy():
    """The 3-D guy's line and the arguments of its along-line evaluation."""
    return along_line_arguments(guy_3d_doc(), "")


def test_element_influence_of_a_3d_line_equals_a_forward_dense_solve(guy):
    """A random node load at three frequencies (one at the first mode): the element
    tensions of the dense forward solve against the adjoint influence, within 1e-9 of
    the largest (round-off of two solves of 117 unknowns)."""
    _, seen = guy
    system, damping = seen["system"], seen["damping"]
    model = system.model
    n, d = model.n_nodes, model.dim
    assert d == 3
    rng = np.random.default_rng(5)
    load = rng.standard_normal((n, d)) + 1j * rng.standard_normal((n, d))
    w = np.array([0.2, float(system.modes.omega[0]), 2.1])
    g = element_influence(system, damping, w)
    rows = element_rows(model)
    for j, u in enumerate(forward_dense_motions(system, damping, load, w)):
        direct = np.einsum("ed,ed->e", rows[:, 0], u[:-1]) + np.einsum(
            "ed,ed->e", rows[:, 1], u[1:]
        )
        adjoint = np.einsum("end,nd->e", g[..., j], load)
        assert np.max(np.abs(adjoint - direct)) < 1e-9 * np.max(np.abs(direct))


def test_end_rows_reproduce_the_3d_kinds_end_lines(guy):
    """The kept blocks of the vector drag residual (and its seed-form misfit) and the
    geometric residual's pair lines, contracted with the end influence, give each
    kind's end lines to round-off (1e-10)."""
    line, seen = guy
    system, damping = seen["system"], seen["damping"]
    taps = seen["taps"]
    end = EndInfluence(system, damping)
    drag = taps["drag_residual"]
    assert len(drag.vectors) == 1 and len(drag.misfits) == 1
    rec = line.residuals["drag_residual"]
    got = [vector_lines(system, damping, drag.vectors[0], end)]
    linear = np.stack([line.end_tension_transfer[e] for e in ENDS], axis=1)
    got.append(vector_misfit_lines(system, damping, drag.misfits[0], end, linear,
                                   line.input_spectra))  # fmt: skip
    geo = taps["geometric_residual"]
    rec_geo = line.residuals["geometric_residual"]
    got_geo = element_lines(system, damping, "geometric_residual", geo.captures, end, False)
    for lines, (_, ref) in zip([*got, got_geo], [*rec.lines, rec_geo.lines[0]], strict=True):
        for k, e in enumerate(ENDS):
            scale = np.abs(ref[e]).max()
            assert scale > 0
            np.testing.assert_allclose(lines[k], ref[e], rtol=1e-10, atol=1e-12 * scale)


def test_3d_end_elements_carry_the_end_residuals(guy):
    """The residuals' σ ratio of the first and last elements against the ends' (the
    element's stretch against the support reaction: the half element's inertia and
    drag between them; measured 2e-4 / 1.7e-3, 3e-3 allowed as the planar chain's), and
    every element's σ raised by the residuals (the seed form's misfit may lower the
    σ, the Hermite orders ≥ 2 raise it more here: +15 % at the ends)."""
    line, _ = guy
    al = line.along_line
    assert al.computed and set(al.lines) == {"drag_residual", "geometric_residual"}
    for el, e in ((0, "end_a"), (-1, "end_b")):
        ratio_el = line.tension_std[el] / line.tension_std_linear[el]
        ratio_end = getattr(line, e).std / line.linear[e].std
        assert ratio_el == pytest.approx(ratio_end, rel=3e-3)
    assert np.all(line.tension_std > 1.05 * line.tension_std_linear)


@pytest.mark.slow
def test_3d_element_tensions_within_the_time_domain_interval():
    """The 3-D guy's element tension σ (elements 10, 20, 30) against the reference TD
    (seeds 1–5, 1200 s records without the first 200 s, the analysis band: as the end
    test of tests/dynamics/test_drag_residual_3d.py): the corrected σ within the 95 %
    interval of the TD mean, the linear σ more than two half-widths off.  ≈ 120 s."""
    from scipy import stats

    from stochcable.reference.cable import simulate_line_timedomain
    from stochcable.scene.model import load_scene

    doc = guy_3d_doc()
    doc["analysis"]["linearization"]["tolerance"] = 1e-8
    scene = load_scene(doc)
    els = [10, 20, 30]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        line = next(iter(analyze(scene).lines.values()))
        band = (float(line.omega[0]), float(line.omega[-1]))
        td = []
        for seed in range(1, 6):
            h = simulate_line_timedomain(scene, duration=1200.0, seed=seed, band=band)
            td.append(h.element_tension_std(start=200.0)[els])
    td = np.array(td)
    mean = td.mean(axis=0)
    half = stats.t.ppf(0.975, len(td) - 1) * td.std(axis=0, ddof=1) / math.sqrt(len(td))
    np.testing.assert_array_less(np.abs(line.tension_std[els] - mean), half)
    np.testing.assert_array_less(2 * half, np.abs(line.tension_std_linear[els] - mean))
