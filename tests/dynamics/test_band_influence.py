"""The residuals' banded adjoint rows (stochcable.dynamics.residuals.band_influence):
the compiled path (factors kept, rows by substitution) against LAPACK's stacked gbsv
path on the accuracy page's deep catenary (banded: 20 elements, 38 free DOFs), the
rows a shared influence hands out from its kept factors against a fresh solve, and
STOCHCABLE_NUMBA=0 taking the LAPACK path."""

from __future__ import annotations

import numpy as np
import pytest
from test_influence import _system

import stochcable.dynamics.residuals.band_influence as bi
from stochcable.dynamics.residuals.along_line import element_rhs, stations
from stochcable.dynamics.residuals.along_line_motion import node_rows, solved_stations
from stochcable.dynamics.residuals.influence import EndInfluence

pytest.importorskip("stochcable.dynamics.model.band_lu_kernels")

import residual_cost  # noqa: E402 (benchmarks/, on the path through test_influence)


@pytest.fixture(scope="module")
def deep():
    system, damping = _system(residual_cost.lines()["deep"])
    model = system.model
    extra = np.hstack(
        [element_rhs(model, stations(model)), node_rows(model, solved_stations(model))]
    )
    return system, damping, extra


def _lapack(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(bi, "compiled_band_lu", lambda entries: False)


def test_compiled_rows_equal_lapack(deep, monkeypatch):
    """End rows with the element and node rows (2 + 7 + 14) on 189 lines across the
    line's resonances: the compiled LU equals gbsv's to round-off (measured 4e-15 of
    each row's scale)."""
    system, damping, extra = deep
    w = np.linspace(0.02, 6.0, 189)
    got = bi.LineAdjoint(system, damping, entries=2**20).rows(w, extra)
    _lapack(monkeypatch)
    ref = bi.end_influence(system, damping, w, extra)
    scale = np.abs(ref).reshape(ref.shape[0], -1).max(axis=1)
    err = np.abs(got - ref).reshape(ref.shape[0], -1).max(axis=1) / scale
    assert np.all(err < 1e-12), err
    np.testing.assert_array_equal(got[:, [0, -1]], ref[:, [0, -1]])  # (ê and zeros)
    adj = bi.adjoint_rows(system, damping, extra, w)
    np.testing.assert_allclose(adj, ref[2:], rtol=0, atol=1e-12 * scale.max())


def test_kept_factors_give_the_other_rows(deep):
    """A shared influence solved by the banded path keeps its factors: the element and
    node rows asked later on some of its lines (every second one, any subset) are
    substitutions equal to a solve of all rows at once; on lines it did not factor:
    None (the caller's own solve)."""
    system, damping, extra = deep
    w = np.linspace(0.02, 6.0, 189)
    shared = EndInfluence(system, damping, extra)
    shared._modal = False  # (the deep wire is banded anyway: MODAL_SHARE)
    ends = shared.on(w)
    full = bi.LineAdjoint(system, damping, entries=2**20).rows(w, extra)
    np.testing.assert_array_equal(ends, full[:2])
    sub = w[::2]
    rows = shared.extra_kept(sub, slice(7, 21))  # (the node rows)
    np.testing.assert_allclose(rows, full[9:23, ..., ::2], rtol=0, atol=1e-14 * np.abs(full).max())
    assert np.shares_memory(shared.extra_kept(sub, slice(7, 21)), rows)  # (kept)
    np.testing.assert_array_equal(shared.extra_kept(w[[3, 7]], slice(0, 7)), full[2:9, ..., [3, 7]])
    assert shared.extra_kept(np.array([0.0301]), slice(0, 7)) is None


def test_numba_off_takes_lapack(deep, monkeypatch):
    """STOCHCABLE_NUMBA=0: no compiled path (gbsv in stacks; no factors kept)."""
    system, damping, extra = deep
    monkeypatch.setenv("STOCHCABLE_NUMBA", "0")
    adj = bi.LineAdjoint(system, damping, entries=2**20)
    w = np.linspace(0.02, 6.0, 40)
    adj.rows(w, extra)
    assert adj.kept_rows(w, extra) is None


def test_kept_transfer_is_the_rows_times_the_loads(deep):
    """The node rows contracted with load cases as they are solved
    (EndInfluence.extra_transfer, never formed) equal sparse_transfer of the rows
    themselves (the motions' product: round-off, the sums in another order); None
    once the rows are formed (the caller's product then) and on lines not factored."""
    from stochcable.dynamics.residuals.along_line_3d import sparse_transfer

    system, damping, extra = deep
    n = system.model.n_nodes
    rng = np.random.default_rng(3)
    unit = np.zeros((n, 2, 12))  # load cases on node pairs, the end nodes' included
    for load, k in enumerate(rng.integers(0, n - 1, size=12)):
        unit[k : k + 2, :, load] = rng.normal(size=(2, 2))
    w = np.linspace(0.02, 6.0, 189)
    shared = EndInfluence(system, damping, extra)
    shared._modal = False
    shared.on(w)
    sub = w[1::3]
    got = shared.extra_transfer(sub, unit, slice(7, 21))
    ref = sparse_transfer(shared.extra_kept(sub, slice(7, 21)), unit)
    np.testing.assert_allclose(got, ref, rtol=0, atol=1e-14 * np.abs(ref).max())
    assert shared.extra_transfer(sub, unit, slice(7, 21)) is None  # (rows formed now)
    assert shared.extra_transfer(np.array([0.0301]), unit, slice(0, 7)) is None


def test_long_line_factored_in_stacks(deep, monkeypatch):
    """Factors beyond KEPT_FACTOR_BYTES (a long line solved directly) are made and used
    stack by stack, not kept: the same rows (bitwise: the same kernels per frequency),
    and no substitution from kept factors afterwards."""
    system, damping, extra = deep
    w = np.linspace(0.02, 6.0, 50)
    ref = bi.LineAdjoint(system, damping, entries=2**20).rows(w, extra)
    monkeypatch.setattr(bi, "KEPT_FACTOR_BYTES", 7 * 16 * 38 * 10)  # (7 frequencies)
    adj = bi.LineAdjoint(system, damping, entries=2**20)
    np.testing.assert_array_equal(adj.rows(w, extra), ref)
    assert adj.kept_rows(w, extra) is None
