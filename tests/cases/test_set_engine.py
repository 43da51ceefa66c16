"""The solver of a set's engine (:func:`stochcable.cases.chunk.set_engine`)."""

from __future__ import annotations

import warnings

import numpy as np

from stochcable.analysis import analyze
from stochcable.cases import LineFatigue, run_cases, scatter_from_rows
from stochcable.cases.chunk import case_sea, engine_template, set_engine
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
    the chain (20 of 78 modes, a static correction) keeps its Foss solve."""
    scene = load_scene(_wire())
    (system,) = set_engine(engine_template(scene, (), "jonswap")).systems.values()
    assert system.solver == "direct"
    assert system.n_modes == system.model.free.size
    (chain,) = set_engine(load_example("chain_catenary")).systems.values()
    assert chain.solver == "foss" and chain.n_modes < chain.model.free.size
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
