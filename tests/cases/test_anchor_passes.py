"""The passes of a set with adaptive residual anchors (stochcable.cases.anchor_passes):
the anchors' starts, the passes' chunks and leads, and every case solved once."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import stochcable.cases.chunk as chunk_mod
from stochcable import load_example
from stochcable.cases import LineFatigue, run_cases, scatter_from_rows
from stochcable.cases.anchor_passes import (
    START_TOLERANCE,
    column_start,
    neighbour_starts,
    pass_chunks,
    split_last_pass,
)
from stochcable.cases.chunk import WARM_RUN

WIRE = LineFatigue("dnv-six-strand", nominal_area=1.2e-3)


def _states(hs=(1.0, 2.0, 3.0), tps=(6.0, 8.0, 10.0), heading=0.0):
    rows = [{"hs": h, "tp": tp, "heading": heading, "hours": 1.0} for h in hs for tp in tps]
    return scatter_from_rows(rows).states


def test_neighbour_starts_prefer_the_same_hs_then_the_nearest_period():
    """Of the computed cases of its heading: the same Hs at the nearest period, else
    the nearest Hs; none (at rest) without one; ties to the first."""
    states = _states()  # positions: 3·(Hs index) + (Tp index)
    known = {0: {"g": np.array([0.0])}, 2: {"g": np.array([2.0])}, 7: {"g": np.array([7.0])}}
    got = neighbour_starts(states, [1, 5, 6], known)
    assert got[0]["g"][0] == 0.0  # Hs 1, Tp 8: same Hs, Tp 6 and 10 tie: the first
    assert got[1]["g"][0] == 7.0  # Hs 2, Tp 10: none at Hs 2; Hs 3 Tp 8 (ln 1.5 < ln 2)
    assert got[2]["g"][0] == 7.0  # Hs 3, Tp 6: the same Hs
    other = _states(heading=90.0)
    assert neighbour_starts(other, [0], {}) == ({},)


def test_column_start_is_exact_for_a_power_of_hs():
    """σ = a·Hs^p per component (p within the bounds 0…2) is met to round-off between
    two cases of a column and beyond them; an exponent outside is clipped to the bound;
    a σ that is not positive takes the nearer case's."""
    a, p = np.array([0.3, 1.2, 0.0]), np.array([0.7, 1.6, 1.0])
    known = {j: {"g": a * h**p} for j, h in ((0, 1.0), (1, 3.0), (2, 4.0))}
    column = [(1.0, 0), (3.0, 1), (4.0, 2)]
    for hs in (2.0, 3.5, 6.0):  # between, between, beyond the largest
        got = column_start(hs, column, known)["g"]
        np.testing.assert_allclose(got[:2], (a * hs**p)[:2], rtol=1e-13)
        assert got[2] == 0.0
    steep = {0: {"g": np.array([1.0])}, 1: {"g": np.array([27.0])}}  # Hs^3 between 1 and 3
    got = column_start(2.0, [(1.0, 0), (3.0, 1)], steep)["g"][0]
    assert got == pytest.approx(2.0**2, rel=1e-13)  # the exponent clipped to 2


def test_neighbour_starts_interpolate_in_the_column():
    """With two computed cases of its column a case starts from their σ interpolated
    in Hs (log–log), not from the nearest one's."""
    states = _states(hs=(1.0, 2.0, 4.0), tps=(6.0,))
    known = {0: {"g": np.array([1.0])}, 2: {"g": np.array([4.0])}}
    got = neighbour_starts(states, [1], known)
    assert got[0]["g"][0] == pytest.approx(2.0, rel=1e-13)  # σ ∝ Hs between 1 and 4


def test_split_last_pass_starts_where_the_column_law_holds():
    """The last pass's cases between computed Hs of a column whose σ follow the law
    (checked on its interior computed case) start there; with the law missed by more
    than START_TOLERANCE only a case that would start its warm-start run at rest does;
    cases beyond the computed Hs and in columns without computed cases run warm."""
    states = _states(hs=(1.0, 2.0, 3.0, 4.0, 5.0), tps=(6.0, 8.0))  # pos 2·(Hs) + Tp
    law = {j: {"g": np.array([0.5 * states[j].hs])} for j in (0, 4, 6)}  # Tp 6 s: Hs 1, 3, 4
    first, starts, rest = split_last_pass(states, [2, 8, 1, 3], law)
    assert first == [2] and rest == [1, 3, 8]  # Hs 2 between; Hs 5 beyond; Tp 8: none
    assert starts[0]["g"][0] == pytest.approx(1.0, rel=1e-13)
    bent = dict(law)
    bent[4] = {"g": np.array([1.5 * (1.0 + 10 * START_TOLERANCE)])}
    first, _, rest = split_last_pass(states, [1, 2, 3], bent)
    assert first == [] and rest == [1, 2, 3]  # (2 continues the warm run after 1)
    first, _, rest = split_last_pass(states, [2, 3], bent)
    assert first == [2] and rest == [3]  # (2 would start its run at rest)


def test_pass_chunks_lead_with_the_pass_cases_of_the_run():
    """A pass's chunk that starts inside a warm-start run first solves the pass's earlier
    cases of that run only (the positions the pass leaves out are not solved)."""
    states = _states(hs=tuple(float(h) for h in range(1, 9)), tps=(6.0, 8.0, 10.0, 12.0))
    idx = [i for i in range(len(states)) if i % 3 != 0]
    chunks, leads, starts = pass_chunks(states, idx, False, 5)
    assert [c[0] for ch in chunks for c in ch] == idx
    assert all(not c[2] for ch in chunks for c in ch)
    for ch, lead in zip(chunks, leads):
        first = ch[0][0]
        assert [i for i, _ in lead] == [i for i in idx if first - first % WARM_RUN <= i < first]
    assert starts == tuple(() for _ in chunks)
    seeds = tuple({"g": np.array([float(i)])} for i in idx)
    chunks, leads, starts = pass_chunks(states, idx, True, 4, seeds)
    assert all(lead == () for lead in leads)
    assert [s["g"][0] for part in starts for s in part] == [float(i) for i in idx]


def test_every_case_of_an_adaptive_set_is_solved_once():
    """The anchors' passes and the last linear pass solve each case exactly once (no
    lead in one chunk), and the anchors are the cases computed with the residuals."""
    doc = load_example("taut_wire").model_dump(mode="json", exclude_none=True)
    doc["analysis"].pop("timeseries", None)
    doc["analysis"]["linearization"].update(drag_residual=True, geometric_residual=True)
    rows = [
        {"hs": h, "tp": tp, "gamma": 3.3, "hours": 1.0}
        for tp in (8.0, 10.0, 12.0)
        for h in (0.5, 1.0, 1.5, 2.0, 2.5, 3.0)
    ]
    seen: list[int] = []
    real = chunk_mod._solve_case  # noqa: SLF001 - counted, not replaced

    def counted(engine, sea, index):
        seen.append(index)
        return real(engine, sea, index)

    chunk_mod._solve_case = counted  # noqa: SLF001
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            res = run_cases(doc, scatter_from_rows(rows), fatigue=WIRE)
    finally:
        chunk_mod._solve_case = real  # noqa: SLF001
    assert sorted(seen) == list(range(len(rows)))
    assert all(r.status != "pending" for r in res.rows)


def test_a_column_start_meets_the_rest_start_in_fewer_evaluations():
    """A case started (own) from the σ of its column's neighbours interpolated in Hs
    (the taut wire at Tp 10 s, Hs 2.0 m between 1.5 and 2.5 m) converges to the
    fixed point of the rest start within the tolerance tol, in fewer evaluations
    than from the nearer neighbour's σ alone (measured: 1 evaluation against 2, and 5
    from rest; end_b σ 2.1e-6 from the rest start's, the neighbour's 1.6e-5: the
    answer is one contracting step from a point already within tol)."""
    from stochcable.dynamics.engine import build_engine
    from stochcable.dynamics.groups.group_fixed_point import warm_starts
    from stochcable.scene.model import Sea, load_scene
    from stochcable.scene.spectra import Jonswap

    doc = load_example("taut_wire").model_dump(mode="json", exclude_none=True)
    doc["analysis"].pop("timeseries", None)
    doc["analysis"]["linearization"].update(
        drag_residual=False, geometric_residual=False, tolerance=1e-4
    )
    scene = load_scene(doc)
    tol = scene.analysis.linearization.tolerance
    engine = build_engine(scene)

    def solve(hs, start=None):
        store = {} if start is None else {g: x[None] for g, x in start.items()}
        with warm_starts(store):
            line = engine.solve(Sea(spectrum=Jonswap(hs=hs, tp=10.0, gamma=2.0))).lines
        return next(iter(line.values())), {g: x[0].copy() for g, x in store.items()}

    (_, s_lo), (_, s_hi) = solve(1.5), solve(2.5)
    cold, _ = solve(2.0)
    start = column_start(2.0, [(1.5, 0), (2.5, 1)], {0: s_lo, 1: s_hi})
    got, _ = solve(2.0, start)
    near, _ = solve(2.0, s_lo)
    assert got.end_b.std == pytest.approx(cold.end_b.std, rel=tol)
    assert got.linearization.iterations < near.linearization.iterations
    assert got.linearization.iterations < cold.linearization.iterations
