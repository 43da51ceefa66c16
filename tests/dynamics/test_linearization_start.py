"""The coarse start of the drag linearization of a single line (the one fixed point,
stochcable.dynamics.groups.group_fixed_point, applied to a line alone through
stochcable.dynamics.groups.line_fixed_point.linearize; its coarse start stochcable.dynamics.groups.
coarse): the frequency-subset fixed point only supplies the start, the answer is the
full-grid fixed point; narrow resonances are kept at full resolution; the subset
quadrature; the single-BLAS-thread limit in worker threads."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from stochcable.dynamics.groups import coarse as dcoarse
from stochcable.dynamics.groups import freeline as dfreeline
from stochcable.dynamics.groups import line_fixed_point as dfixedpoint
from stochcable.dynamics.groups.group import GroupSystem
from stochcable.dynamics.groups.inputs import CoupledLine
from stochcable.dynamics.linearization import coarse_grid as dgrid
from stochcable.dynamics.linearization import variance as dvariance
from stochcable.dynamics.loads.channels import line_channels
from stochcable.dynamics.model import blocks as dblocks
from stochcable.dynamics.model import system as dsystem
from stochcable.dynamics.outputs import line_result as doutputs
from stochcable.dynamics.solve import line_loads as dloads
from stochcable.dynamics.solve import line_solve as dsolve
from stochcable.scene.model import load_scene
from stochcable.statics import solve_statics

# one worker runs the module: its module fixtures run once (--dist loadgroup)
pytestmark = pytest.mark.xdist_group("test_linearization_start")

EXAMPLE = Path(dsystem.__file__).resolve().parents[2] / "examples" / "chain_catenary.json"


def _chain(omega_count: int | None = None, **env) -> tuple:
    doc = json.loads(EXAMPLE.read_text())
    doc["analysis"].pop("timeseries", None)
    if omega_count is not None:
        doc["analysis"]["omega"]["count"] = omega_count
    doc["environment"].update(env)
    scene = load_scene(doc)
    line = scene.lines[0]
    st = solve_statics(scene, method="fe")
    system = dsystem.build_line_system(scene, line, st.lines[line.name])
    omega = scene.analysis.omega.values()
    return scene, system, line_channels(scene, line, system.positions, omega)


@pytest.fixture(scope="module")
def chain():
    return _chain()


def _sigma(lin) -> np.ndarray:
    return np.r_[lin.record.sigma_normal, lin.record.sigma_axial]


def _tight(scene):
    lin = scene.analysis.linearization.model_copy(update={"tolerance": 1e-10})
    return scene.analysis.model_copy(update={"linearization": lin})


def _counted(monkeypatch) -> list[tuple[bool, int]]:
    """Record (coarse?, number of frequencies) of every response evaluation of a line
    alone (its FreeLine solves: the coarse stage solves per frequency in modal
    coordinates, ``modal_direct``)."""
    calls: list[tuple[bool, int]] = []
    solve_free = dfreeline.solve_free

    def counted(system, inp, damping, *, modal_direct=False):
        calls.append((modal_direct, inp.omega.size))
        return solve_free(system, inp, damping, modal_direct=modal_direct)

    monkeypatch.setattr(dfreeline, "solve_free", counted)
    return calls


@pytest.mark.filterwarnings("ignore::stochcable.errors.ResolutionWarning")  # the cut tail
def test_coarse_start_converges_to_the_full_grid_fixed_point(chain, monkeypatch):
    scene, system, ch = chain
    calls = _counted(monkeypatch)
    coarse = dfixedpoint.linearize(system, ch, scene.analysis)
    stage, calls[:] = list(calls), []
    full = dfixedpoint.linearize(system, ch, scene.analysis, coarse=False)
    assert not any(c for c, _ in calls)  # coarse=False: the full grid only
    ref = dfixedpoint.linearize(system, ch, _tight(scene), coarse=False)
    tol = scene.analysis.linearization.tolerance
    n = ch[0].omega.size
    # the coarse stage ran on a real subset; the record lists every evaluation in
    # order, coarse and full-grid (the one fixed point's record)
    sub = [k for c, k in stage if c]
    assert sub and max(sub) <= dcoarse.COARSE_MAX_FRACTION * n
    rec = coarse.record
    assert rec.converged and rec.iterations == len(rec.history) == len(stage)
    assert rec.history[-1] == rec.relative_change <= tol
    # the point of the coarse start: fewer full-grid evaluations
    assert sum(1 for c, _ in stage if not c) < full.record.iterations
    # same fixed point: both within the tolerance of the tight one (the map
    # contracts by <= 0.5 per step here, so the distance is <= 2 tol; round-off aside)
    s_ref = _sigma(ref)
    for lin in (coarse, full):
        assert np.max(np.abs(_sigma(lin) / s_ref - 1)) < 2 * tol
    # the outputs: end tension σ (the benchmark quantities) within 1e-4 relative
    out_c = doutputs.line_result(system, ch, coarse, scene.analysis)
    out_f = doutputs.line_result(system, ch, full, scene.analysis)
    for end in ("end_a", "end_b"):
        a, b = getattr(out_c, end).std, getattr(out_f, end).std
        assert abs(a / b - 1) < 1e-4


def test_small_grid_has_no_coarse_stage(chain, monkeypatch):
    scene, system, ch = chain
    w = ch[0].omega[::4]  # 50 frequencies < COARSE_MIN_FREQUENCIES
    assert w.size < dcoarse.COARSE_MIN_FREQUENCIES
    sub = line_channels(scene, system.line, system.positions, w)
    calls = _counted(monkeypatch)
    lin = dfixedpoint.linearize(system, sub, scene.analysis)
    assert not any(c for c, _ in calls)  # no coarse evaluation
    assert (
        lin.record.iterations
        == dfixedpoint.linearize(system, sub, scene.analysis, coarse=False).record.iterations
    )


def test_interpolatory_weights_integrate_cubics_as_the_full_grid():
    # a log grid and a subset with an irregular dense patch: the weights must give the
    # full grid's trapezoid sum of any cubic exactly (interpolation of a cubic by a
    # 4-point Lagrange stencil is exact), and not of a quartic (the test can fail)
    w = np.geomspace(0.05, 3.0, 157)
    idx = np.unique(np.r_[np.arange(0, 157, 4), 156, np.arange(60, 75)])
    q = dblocks.trapezoid_weights(w)
    wts = dgrid.interpolatory_weights(w, idx)
    for f in (np.ones_like, lambda x: x, lambda x: 2 - x**2, lambda x: x**3 - x):
        assert wts @ f(w[idx]) == pytest.approx(q @ f(w), rel=1e-12, abs=1e-12)
    quartic = (w - 1.0) ** 4
    assert abs(wts @ quartic[idx] - q @ quartic) > 1e-8
    # against the subset's own trapezoid rule on a smooth spectrum-like integrand
    f = w**-5 * np.exp(-1.25 * (0.6 / w) ** 4) * 1e2
    trap = dblocks.trapezoid_weights(w[idx]) @ f[idx]
    assert abs(wts @ f[idx] / (q @ f) - 1) < 0.1 * abs(trap / (q @ f) - 1)


def test_narrow_resonance_is_not_missed_by_the_coarse_subset():
    # no current and no seabed dashpots: with 3 % of the converged drag the in-band
    # modes (0.85, 1.25, 1.77 rad/s) have half-power bandwidths of ~0.013 rad/s, below
    # two coarse spacings (0.065 rad/s on 240 frequencies; on the example's 200 the three
    # windows and the stride points fill 70 or 71 points of the 70 the coarse subset
    # may have, depending on where the modes fall between the grid points)
    scene, system, ch = _chain(
        omega_count=240, current=[], seabed={"stiffness": 3e6, "damping": 0.0}
    )
    lin = dfixedpoint.linearize(system, ch, scene.analysis, coarse=False)
    weak = dvariance.drag_coefficients(system, 0.03 * lin.damping.sigma, "seed")
    inp = dloads.line_inputs(system, ch)
    w = inp.omega
    # the coarse subset of the line alone (a group without bodies) at that drag
    g = GroupSystem([CoupledLine(system, ch)], [], {}, system.environment.rho, ch)
    g.sizes = {system.name: weak.sigma.size}
    idx = dcoarse.coarse_subset(g, weak.sigma, "seed")
    assert idx is not None
    wn = system.modes.omega
    for wj in wn[(wn > w[0]) & (wn < w[-1])]:
        k = int(np.argmin(np.abs(w - wj)))
        window = np.arange(k - dcoarse.COARSE_STRIDE, k + dcoarse.COARSE_STRIDE + 1)
        assert np.isin(window, idx).all()  # full resolution around the resonance
    u, _ = dsolve.solve_free(system, inp, weak)
    full = dvariance.sigmas_from_free(system, inp, u, "seed")

    def err(sel: np.ndarray) -> float:
        sub = dgrid.subset_inputs(system, ch, inp, sel)
        s = dvariance.sigmas_from_free(system, sub, np.ascontiguousarray(u[:, :, sel]), "seed")
        return float(np.max(np.abs(s - full)) / np.max(full))

    # the uniform subset misses the peaks (tens of %), the windowed one does not
    # (measured 0.6 %: the tails between the coarse points remain)
    assert err(np.unique(np.r_[np.arange(0, w.size, dcoarse.COARSE_STRIDE), w.size - 1])) > 0.1
    assert err(idx) < 0.02
    # and the linearization of that line still ends at the full-grid fixed point
    c = dfixedpoint.linearize(system, ch, scene.analysis)
    f = dfixedpoint.linearize(system, ch, scene.analysis, coarse=False)
    tol = scene.analysis.linearization.tolerance
    assert np.max(np.abs(_sigma(c) / _sigma(f) - 1)) < 4 * tol  # each within 2 tol
