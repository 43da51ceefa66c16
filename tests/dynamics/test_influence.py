"""The end influence through the linear solve's modal basis
(stochcable.dynamics.residuals.influence.modal_influence) against the banded
adjoint solve (end_influence): equal to round-off where every mode is kept (the taut
wire: 38 modes on 38 free DOFs), close where the truncated ones enter by their static
correction (the bundled chain, the two-segment line of benchmarks/residual_cost.py),
and not used where the line is not solved by its modes."""

from __future__ import annotations

import sys
import warnings

import numpy as np
import pytest
from _paths import ROOT

import stochcable.dynamics.outputs.line_result as line_result_module
import stochcable.dynamics.residuals.influence as rl
from stochcable import analyze
from stochcable.dynamics.residuals.along_line import element_rhs, stations

sys.path.insert(0, str(ROOT / "benchmarks"))
import residual_cost  # noqa: E402


def _system(doc: dict) -> tuple:
    """The (system, damping) a line's along-line evaluation is given."""
    seen = {}
    orig = line_result_module.along_line_residual

    def spy(system, damping, *args, **kw):
        seen.update(system=system, damping=damping)
        return orig(system, damping, *args, **kw)

    line_result_module.along_line_residual = spy
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            analyze(residual_cost.with_variant(doc, "both"))
    finally:
        line_result_module.along_line_residual = orig
    return seen["system"], seen["damping"]


def _row_errors(name: str, monkeypatch: pytest.MonkeyPatch) -> np.ndarray:
    """‖modal − banded‖/‖banded‖ of each row (2 ends, 7 stations) on 120 lines to
    6 rad/s (the residual lines' span on these lines)."""
    system, damping = _system(residual_cost.lines()[name])
    w = np.linspace(0.05, 6.0, 120)
    extra = element_rhs(system.model, stations(system.model))
    ref = rl.end_influence(system, damping, w, extra)
    monkeypatch.setattr(rl, "MODAL_SHARE", 1.0)  # (also where the banded solve is cheaper)
    got = rl.modal_influence(system, damping, w, extra)
    assert got is not None
    diff = (got - ref).reshape(ref.shape[0], -1)
    return np.linalg.norm(diff, axis=1) / np.linalg.norm(ref.reshape(ref.shape[0], -1), axis=1)


def test_modal_influence_with_every_mode_is_the_banded_solve(monkeypatch):
    """The taut wire keeps all its 38 modes: no static correction, the complex-mode sum
    is A⁻¹ itself (6e-14 measured; round-off of the eigenvector matrix's inverse)."""
    assert np.all(_row_errors("taut", monkeypatch) < 1e-10)


@pytest.mark.parametrize("name, bound", [("chain", 5e-3), ("two-segment", 3e-2)])
def test_modal_influence_with_the_static_correction(monkeypatch, name, bound):
    """Modes up to MODAL_SPAN × the top line and the rest by their static correction:
    every row within 0.2 % of the banded solve on the chain, 1.2 % on the two-segment
    line (its synthetic rope's axial modes, the first at 18 rad/s, 3× the top line;
    measured, bounds 2.5× that); the corrected σ moves by ≤ 2e-4 (docs/benchmarks/
    residual_cost.md), the influence's error entering the residual variance only."""
    err = _row_errors(name, monkeypatch)
    assert np.all(err < bound), err
    assert np.all(err > 1e-8)  # (the static correction is used: not a banded solve)


def test_modal_influence_not_used_on_a_directly_solved_line():
    """A line the linear model solves directly (the 20-element chain) has no modal
    basis to reuse: None, and the callers' banded solve."""
    from _scenes import chain_surge_doc

    system, damping = _system(chain_surge_doc(20))
    assert system.solver == "direct"
    assert rl.modal_influence(system, damping, np.linspace(0.1, 3.0, 5)) is None


def test_modal_rows_transfer_is_the_dense_contraction():
    """The factored rows (influence.ModalRows) contracted with load cases through the
    modes equal the formed rows contracted node by node, for dense and sparse cases
    and after slicing rows and lines (the static correction's ω terms on the end rows
    only): to round-off (measured 1e-15)."""
    from scipy import sparse

    system, damping = _system(residual_cost.lines()["chain"])
    w = np.linspace(0.05, 6.0, 60)
    extra = element_rhs(system.model, stations(system.model))
    rows = rl.modal_influence(system, damping, w, extra)
    assert isinstance(rows, rl.ModalRows) and rows.rc is not None
    n, d = system.model.n_nodes, system.model.dim
    unit = np.random.default_rng(3).normal(size=(n, d, 11))
    for g in (rows, rows[:2], rows[2:][..., 5:40:3], rows[1:4][..., np.arange(7, 30)]):
        dense = np.asarray(g)
        ref = np.einsum("onkw,nkl->olw", dense, unit)
        scale = np.abs(ref).max()
        assert np.abs(g.transfer(unit) - ref).max() < 1e-12 * scale
        flat = sparse.csr_matrix(unit.reshape(n * d, -1).T)
        assert np.abs(g.transfer(flat) - ref).max() < 1e-12 * scale
    assert np.abs(np.asarray(rows[2:][..., 5:40:3]) - np.asarray(rows)[2:, ..., 5:40:3]).max() == 0


def test_kept_influence_on_the_same_lines_is_the_general_lookup():
    """EndInfluence._find on the very lines it keeps (the shortcut: the kept rows
    themselves) gives what the nearest-line lookup gives on lines within its 1e-12
    tolerance of them, for all rows and a slice of rows."""
    rng = np.random.default_rng(2)
    om = np.linspace(0.1, 5.0, 30)
    g = rng.normal(size=(4, 3, 2, om.size)) + 1j * rng.normal(size=(4, 3, 2, om.size))
    kept = [(om[::2].copy(), g[..., ::2].copy()), (om.copy(), g)]
    near = om * (1.0 + 1e-14)  # (not equal: the general lookup)
    for rows in (slice(None), slice(1, 3)):
        same = rl.EndInfluence._find(kept, om.copy(), rows)
        ref = rl.EndInfluence._find(kept, near, rows)
        assert same is not None and ref is not None
        assert np.array_equal(np.asarray(same), np.asarray(ref))
        assert np.array_equal(np.asarray(same), g[rows])
    assert rl.EndInfluence._find(kept, om[:5] + 0.01) is None


def test_kept_influence_lookup_is_the_nearest_line_of_every_frequency():
    """EndInfluence._find (its shortcut for every step-th line, then the general search)
    against a brute-force lookup: each frequency's nearest kept line, None where one is
    more than 1e-12 relative from every line — strided runs, a run's first and last
    apart (line_subset's), an offset grid, a frequency between lines, one frequency,
    a reversed and a shuffled request, frequencies beyond the lines."""
    rng = np.random.default_rng(5)
    om = 0.05 * np.arange(1, 41)
    g = rng.normal(size=(3, 2, 2, om.size)) + 1j * rng.normal(size=(3, 2, 2, om.size))
    kept = [(om[:7].copy(), g[..., :7].copy()), (om.copy(), g)]

    def brute(w):
        for o, gk in kept:
            near = np.argmin(np.abs(o[None, :] - w[:, None]), axis=1)
            if np.all(np.abs(o[near] - w) <= 1e-12 * np.abs(w)):
                return gk[..., near]
        return None

    idx = [
        np.arange(40), np.arange(3, 40, 3), np.arange(0, 20, 2),
        np.r_[0, np.arange(1, 30, 2), 30], np.array([7]), np.arange(40)[::-1],
        rng.permutation(40)[:12], np.arange(2, 6),
    ]  # fmt: skip
    asks = [om[i] * (1.0 + 3e-15) for i in idx]
    asks += [om[4:9] + 0.01, np.r_[om[3:8], 2.5], np.r_[om[30:], 2.05], np.array([0.02])]
    for w in asks:
        for rows in (slice(None), slice(1, 3)):
            ref = brute(w)
            got = rl.EndInfluence._find(kept, w, rows)
            assert (got is None) == (ref is None), w
            if ref is not None:
                assert np.array_equal(np.asarray(got), ref[rows])


def test_modal_rows_of_some_extra_columns_are_those_of_all():
    """modal_influence's ``cols`` (some of the extra rows alone: their modal sums only,
    no end rows; or the end rows alone, ``ENDS``) equal those rows of the full rows to
    round-off (the same sums by a smaller product: measured 0), and
    EndInfluence.extra_kept keeps them apart from the full rows' lines; where a
    frequency is above the modal limit: None.  EndInfluence solves the end rows alone
    and the extra rows where first asked, on the end rows' lines up to the highest
    asked."""
    system, damping = _system(residual_cost.lines()["chain"])
    w = np.linspace(0.3, 1.2, 17)
    extra = element_rhs(system.model, stations(system.model))
    full = np.asarray(rl.modal_influence(system, damping, w, extra))
    scale = np.abs(full[2:]).max()
    for cols in (slice(0, 3), slice(2, 7), slice(None)):
        part = rl.modal_influence(system, damping, w, extra, cols)
        assert isinstance(part, rl.ModalRows)
        ref = full[2:][cols]
        assert part.shape == ref.shape
        assert np.abs(np.asarray(part) - ref).max() <= 1e-13 * scale
    shared = rl.EndInfluence(system, damping, extra)
    got = shared.extra_kept(w, slice(2, 5))
    assert np.abs(np.asarray(got) - full[4:7]).max() <= 1e-13 * scale
    assert not shared._kept_x and shared.extra_kept(w, slice(2, 5)) is got
    top = float(system.modes.omega[-1])
    assert rl.modal_influence(system, damping, np.r_[w, 2.0 * top], extra, slice(0, 3)) is None
    # complex right-hand sides (complex products and static rows): the rows scale with them
    cplx = np.asarray(rl.modal_influence(system, damping, w, extra * (1.0 + 0.5j)))
    assert np.abs(cplx[2:] - (1.0 + 0.5j) * full[2:]).max() <= 1e-13 * scale
    assert np.abs(cplx[:2] - full[:2]).max() <= 1e-13 * np.abs(full[:2]).max()
    # the end rows alone first, the extra rows then on the end rows' lines up to the
    # highest asked (not on all of them), equal to the rows of all
    ends = rl.modal_influence(system, damping, w, extra, rl.ENDS)
    assert np.abs(np.asarray(ends) - full[:2]).max() <= 1e-13 * np.abs(full[:2]).max()
    shared = rl.EndInfluence(system, damping, extra)
    assert np.abs(np.asarray(shared.on(w)) - full[:2]).max() <= 1e-13 * np.abs(full[:2]).max()
    assert not shared._kept_x
    got = shared.extra_on(w[1:12:2], slice(1, 6))
    assert shared._kept_x[0][0].size == 12
    assert np.abs(np.asarray(got) - full[3:8, ..., 1:12:2]).max() <= 1e-13 * scale
    assert shared.extra_kept(w[:12], slice(0, 2)) is not None and len(shared._kept_x) == 1
