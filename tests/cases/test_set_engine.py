"""The solver of a set's engine (:func:`stochcable.cases.chunk.set_engine`)."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from stochcable.analysis import analyze
from stochcable.cases import LineFatigue, run_cases, scatter_from_rows
from stochcable.cases.chunk import DIRECT_MIN_DOFS, case_sea, engine_template, set_engine
from stochcable.examples import load_example
from stochcable.scene.model import load_scene


def _wire() -> dict:
    doc = load_example("taut_wire").model_dump(mode="json", exclude_none=True)
    doc["analysis"].pop("timeseries", None)
    doc["analysis"]["linearization"].update(drag_residual=False, geometric_residual=False)
    return doc


def test_a_line_whose_foss_solve_keeps_every_mode_is_solved_directly_in_a_set():
    """The taut wire (38 free DOFs, every mode kept by the Foss solve): its set's
    engine solves it directly, and a set's first case (at rest, as analyze()) is
    analyze()'s Foss answer to round-off (1e-10: the same equations solved two ways);
    the chain (20 of 78 modes, a static correction) keeps its Foss solve, and so does
    Tuah's single leg (4 free DOFs, every mode: under DIRECT_MIN_DOFS)."""
    scene = load_scene(_wire())
    engine = set_engine(engine_template(scene, (), "jonswap"))
    (system,) = engine.systems.values()
    assert system.solver == "direct" and engine.scene.analysis.solver == "direct"
    assert engine.check is not None  # (the element check carried over: no second pilot)
    assert system.n_modes == system.model.free.size
    (chain,) = set_engine(load_example("chain_catenary")).systems.values()
    assert chain.solver == "foss" and chain.n_modes < chain.model.free.size
    (leg,) = set_engine(load_example("tuah_1982_single_leg")).systems.values()
    assert leg.solver == "foss" and leg.n_modes == leg.model.free.size < DIRECT_MIN_DOFS
    rows = [{"hs": hs, "tp": 9.0, "probability": 0.5} for hs in (2.0, 3.0)]
    sd = scatter_from_rows(rows)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        got = run_cases(scene, sd, fatigue=LineFatigue("dnv-six-strand", nominal_area=1.2e-3))
        one = analyze(scene.model_copy(update={"sea": case_sea(scene, sd.states[0], "jonswap")}))
    line = one.lines["wire"]
    assert line.n_modes == system.n_modes  # (analyze(): the Foss solve)
    for e in ("end_a", "end_b"):
        st = getattr(line, e)
        np.testing.assert_allclose(
            got.stats["wire"][e][0], (st.mean, st.std, st.tz, st.mpm_3h), rtol=1e-10
        )


def test_a_chunk_takes_the_compiled_banded_lu_at_any_size(monkeypatch):
    """Inside a chunk (``compiled.kernels_paid``) the residuals' banded adjoint rows
    take the compiled LU whatever their size — the taut wire's without the node
    motions' rows (189 lines × 38 DOFs × 9 rows) are under ``KERNEL_MIN_ENTRIES``,
    which ``analyze()`` keeps — and so do the direct fixed point's solves (LAPACK's
    gbsv outside a chunk); the case equals the engine's own solve of its sea on
    LAPACK's path to round-off (the same equations factored by two LU codes:
    1e-10, the set's agreement with ``analyze()`` in tests/cases/test_cases_run.py)."""
    pytest.importorskip("stochcable.dynamics.model.band_lu_kernels")
    import stochcable.dynamics.residuals.band_influence as bi
    import stochcable.dynamics.solve.line_solve as line_solve
    from stochcable.cases.chunk import _set_solves, solve_chunk
    from stochcable.compiled import KERNEL_MIN_ENTRIES, SET_KERNEL_MIN_ENTRIES, kernels_paid
    from stochcable.dynamics.model.band_lu import compiled_band_lu

    small = KERNEL_MIN_ENTRIES // 2
    assert not compiled_band_lu(small)
    with kernels_paid():
        assert compiled_band_lu(small) and compiled_band_lu(SET_KERNEL_MIN_ENTRIES)
        assert not compiled_band_lu(SET_KERNEL_MIN_ENTRIES - 1)
        monkeypatch.setenv("STOCHCABLE_NUMBA", "0")
        assert not compiled_band_lu(small)  # (no numba: LAPACK's, as outside)
        monkeypatch.delenv("STOCHCABLE_NUMBA")
    assert not compiled_band_lu(small)
    doc = _wire()
    doc["analysis"]["linearization"].update(drag_residual=True, geometric_residual=True)
    scene = load_scene(doc)
    sd = scatter_from_rows([{"hs": 2.0, "tp": 9.0, "hours": 1.0}])
    calls, solves = [], []
    real, real_solve = bi.band_factors, line_solve.band_solve
    monkeypatch.setattr(bi, "band_factors", lambda *a, **k: calls.append(1) or real(*a, **k))
    monkeypatch.setattr(
        line_solve, "band_solve", lambda *a, **k: solves.append(1) or real_solve(*a, **k)
    )
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        template = engine_template(scene, sd.states, "jonswap")
        engine = set_engine(template)
        with _set_solves():  # (as in a chunk, but LAPACK's gbsv: under the size)
            ref = engine.solve(case_sea(scene, sd.states[0], "jonswap")).lines["wire"]
        assert not calls and not solves
        fat = {"wire": LineFatigue("dnv-six-strand", nominal_area=1.2e-3)}
        got = solve_chunk(template, "jonswap", ((0, sd.states[0]),), fat, engine)
    assert calls and solves  # (the residuals' rows and the direct fixed point's solves)
    for e in ("end_a", "end_b"):
        st = getattr(ref, e)
        np.testing.assert_allclose(
            got.stats["wire"][e][0], (st.mean, st.std, st.tz, st.mpm_3h), rtol=1e-10
        )


def test_a_computed_cases_corrected_densities_are_one_damage_job_on_one_grid():
    """``chunk._corrected_rows``: the ends' and the elements' corrected densities on
    one grid are one damage-rate job over columns 0 … 2 + n_el (end_a, end_b, the
    elements: the row layout of ``ChunkResult.damage``), and its damage equals each
    row's alone to round-off (1e-12: the moments' products in another order); on
    different grids, one job each."""
    from stochcable.cases.chunk import _corrected_rows
    from stochcable.cases.fatigue_settings import curve_factor
    from stochcable.design import damage_rate

    rng = np.random.default_rng(5)
    om = np.linspace(0.1, 3.0, 60)
    ends = [(om, rng.random(60)), (om, rng.random(60))]
    el = (om, rng.random((3, 60)))
    (job,) = _corrected_rows(ends, el)
    assert job[0] == slice(0, None) and np.array_equal(job[1], om)
    np.testing.assert_array_equal(job[2], np.vstack([ends[0][1], ends[1][1], el[1]]))
    curve, _ = curve_factor(LineFatigue("dnv-six-strand", nominal_area=1.2e-3), 9.81, "wire")
    alone = [damage_rate(o, d, curve) for o, d in ends] + list(damage_rate(*el, curve))
    np.testing.assert_allclose(damage_rate(job[1], job[2], curve), alone, rtol=1e-12)
    other = (om * 1.01, el[1])
    jobs = _corrected_rows(ends, other)
    assert [j[0] for j in jobs] == [slice(0, 1), slice(1, 2), slice(2, None)]
    assert [j[0] for j in _corrected_rows(ends, None)] == [slice(0, 2)]
    assert [j[0] for j in _corrected_rows(None, el)] == [slice(2, None)]


def _leg() -> dict:
    doc = load_example("tuah_1982_single_leg").model_dump(mode="json", exclude_none=True)
    doc["analysis"].pop("timeseries", None)
    doc["analysis"]["linearization"].update(drag_residual=True, geometric_residual=True)
    return doc


def test_a_small_line_keeping_every_mode_solves_its_modal_equations_in_a_set(monkeypatch):
    """Tuah's single leg (4 free DOFs, every mode kept, under DIRECT_MIN_DOFS): inside a
    chunk its fixed point solves the modal equations per frequency (no Foss
    eigenproblem); the case equals the engine's own Foss solve of its sea, σ, Tz and
    MPM, to round-off (1e-12: the same equations, every mode kept, solved two ways;
    measured 2e-14), with the residuals on; outside a chunk (analyze()) the Foss solve
    stays.  Where the batched LU fails (a singular frequency) the Foss solve takes the
    evaluation, with the same numbers."""
    import stochcable.dynamics.groups.lineparts as lineparts
    import stochcable.dynamics.solve.line_solve as ms
    from stochcable.cases.chunk import solve_chunk
    from stochcable.dynamics.groups.lineparts import SMALL_MODAL_DOFS

    scene = load_scene(_leg())
    sd = scatter_from_rows([{"hs": 4.0, "tp": 9.0, "hours": 1.0}])
    fat = {"leg": LineFatigue("api-studless", mbs=2.0e5)}
    eig = []
    real = ms.foss_modes
    monkeypatch.setattr(ms, "foss_modes", lambda *a, **k: eig.append(1) or real(*a, **k))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        template = engine_template(scene, sd.states, "jonswap")
        engine = set_engine(template)
        ref = engine.solve(case_sea(scene, sd.states[0], "jonswap")).lines["leg"]
        assert eig and SMALL_MODAL_DOFS.get() == 0  # (outside a chunk: Foss)
        eig.clear()
        got = solve_chunk(template, "jonswap", ((0, sd.states[0]),), fat, engine)
        assert not eig and SMALL_MODAL_DOFS.get() == 0  # (restored after the chunk)
        calls, real_line = [], lineparts.FreeLine

        def singular(system, inp, damping, modal_direct=False):
            if modal_direct and inp.omega.size == ref.omega.size:  # (not the coarse stage's)
                calls.append(1)
                raise np.linalg.LinAlgError("Singular matrix")
            return real_line(system, inp, damping, modal_direct)

        monkeypatch.setattr(lineparts, "FreeLine", singular)
        back = solve_chunk(template, "jonswap", ((0, sd.states[0]),), fat, engine)
    assert calls and eig  # (the batched LU tried, then the Foss solve)
    for e in ("end_a", "end_b"):
        st = getattr(ref, e)
        want = (st.mean, st.std, st.tz, st.mpm_3h)
        np.testing.assert_allclose(got.stats["leg"][e][0], want, rtol=1e-12)
        np.testing.assert_allclose(back.stats["leg"][e][0], want, rtol=1e-12)
