"""The sea's element kinematics formed per block when read
(stochcable.dynamics.loads.element_parts, element_kinematics.KinematicsBlocks): a grid whose
kinematics do not fit a quarter of the working-memory target keeps none, and every
read (a block of frequencies, the end elements, a frequency subset, the weighted and
projected sums) gives the numbers of the kinematics formed and kept.

Every quantity is elementwise in ω, so a block formed alone holds the same operations
on the same inputs as the whole grid; the comparison allows 1e-14 of the array's
largest value, the few-ulp differences SIMD and scalar tails of the vectorized
exponentials may leave (NumPy path), and the sums over frequency regrouped by blocks.
"""

from __future__ import annotations

import numpy as np
import pytest

from stochcable.dynamics.loads.element_kinematics import element_wave_kinematics

#: Tolerance relative to the array's largest |value| (module notes). [-]
RTOL = 1e-14


def _line(n_el: int = 30) -> np.ndarray:
    """A catenary-like line from the seabed (z = −60 m) through the surface to z = +4 m
    (elements crossing the waterline and dry ones), heading off the x axis."""
    s = np.linspace(0.0, 1.0, n_el + 1)
    return np.column_stack([300.0 * s, 40.0 * s, -60.0 + 64.0 * s**2])


def _close(got: np.ndarray, ref: np.ndarray) -> None:
    scale = float(np.max(np.abs(ref), initial=0.0))
    np.testing.assert_allclose(got, ref, rtol=0.0, atol=RTOL * scale + 1e-300)


@pytest.fixture(params=[60.0, np.inf], ids=["depth60", "deep"])
def pair(request, monkeypatch):
    """(kept, formed when read) kinematics of the same line and grid, ω = 0 included."""
    w = np.linspace(0.0, 4.0, 301)
    kw = {"heading": 0.4, "depth": request.param}
    monkeypatch.delenv("STOCHCABLE_WORKING_MEMORY_MB", raising=False)  # kept: the default
    kept = element_wave_kinematics(w, _line(), **kw)
    monkeypatch.setenv("STOCHCABLE_WORKING_MEMORY_MB", "0.01")  # quarter: 2.6 kB
    lazy = element_wave_kinematics(w, _line(), **kw)
    return kept, lazy


def test_a_large_grid_keeps_no_kinematics(pair) -> None:
    kept, lazy = pair
    assert kept.moments.parts is not None and kept.square.horizontal is not None
    assert lazy.moments.parts is None and lazy.square.horizontal is None
    assert lazy.moments.nbytes == 0 and lazy.square.nbytes == 0
    assert kept.moments.nbytes == 30 * 301 * 64 and kept.square.nbytes == 30 * 301 * 16


def test_blocks_and_subsets_formed_when_read_equal_the_kept(pair) -> None:
    kept, lazy = pair
    for freq in (slice(None), slice(7, 8), slice(100, 251), np.array([0, 5, 300, 17])):
        _close(lazy.moments.block((0, 1, 2), freq), kept.moments.block((0, 1, 2), freq))
        _close(lazy.moments.stacked(freq), kept.moments.stacked(freq))
    for got, ref in zip(lazy.moments.ends((0, 2)), kept.moments.ends((0, 2))):
        _close(got, ref)
    _close(lazy.velocity, kept.velocity)
    _close(lazy.velocity_square, kept.velocity_square)
    idx = np.arange(0, 301, 3)
    sub_l, sub_k = lazy.moments[idx], kept.moments[idx]
    assert sub_l.parts is None  # (still above the target: formed when read)
    _close(sub_l.block((0, 2)), sub_k.block((0, 2)))
    _close(lazy.square[idx].full(), kept.square[idx].full())


def test_sums_over_frequency_formed_by_blocks_equal_the_kept(pair) -> None:
    kept, lazy = pair
    rng = np.random.default_rng(21)
    wts = rng.uniform(0.0, 1.0, kept.omega.size)
    _close(lazy.square.weighted(wts, (0, 1, 2)), kept.square.weighted(wts, (0, 1, 2)))
    e = np.diff(_line(), axis=0)
    e /= np.linalg.norm(e, axis=1)[:, None]
    proj = np.eye(3)[None] - e[:, :, None] * e[:, None, :]
    ref = np.clip(np.einsum("weij,eij->we", kept.velocity_square, proj), 0.0, None).T @ wts
    _close(lazy.square.projected_sum(proj, wts), ref)
    _close(kept.square.projected_sum(proj, wts), ref)


def test_a_small_subset_of_a_large_grid_is_kept(monkeypatch) -> None:
    w = np.linspace(0.05, 3.0, 400)
    monkeypatch.setenv("STOCHCABLE_WORKING_MEMORY_MB", "0.5")  # quarter: 131 kB
    lazy = element_wave_kinematics(w, _line(), depth=80.0)  # 30 × 400 × 80 B = 960 kB
    assert lazy.moments.parts is None
    sub = lazy.moments[np.arange(0, 400, 8)]  # 50 frequencies: 120 kB, kept
    assert sub.parts is not None
    _close(sub.parts, lazy.moments.stacked(np.arange(0, 400, 8)))


@pytest.mark.parametrize("depth", [60.0, 5.0, np.inf])
def test_squares_alone_are_those_formed_with_the_moments(depth, monkeypatch):
    # KinematicsBlocks.square forms the mean square without the moments (the sums that
    # read no moments): the same NumPy operations, so the same bits — ω = 0 (the
    # long-wave limit), dry elements (zeros) and shallow water (the clipped vertical
    # part) included
    monkeypatch.setenv("STOCHCABLE_NUMBA", "0")
    line = _line()
    if depth < 60.0:
        line[:, 2] = np.where(line[:, 2] < 0.0, line[:, 2] * depth / 60.0, line[:, 2])
    ek = element_wave_kinematics(np.linspace(0.0, 4.0, 301), line, heading=0.4, depth=depth)
    monkeypatch.setenv("STOCHCABLE_WORKING_MEMORY_MB", "0.01")
    src = element_wave_kinematics(ek.omega, line, heading=0.4, depth=depth).moments.source
    both = src.form()[1]
    np.testing.assert_array_equal(src.square(), both)
    np.testing.assert_array_equal(src.square(slice(40, 77)), both[:, 40:77])
    assert np.all(both[:, :, ek.wet_fraction == 0.0] == 0.0) and np.all(both >= 0.0)


@pytest.mark.parametrize("depth", [60.0, np.inf], ids=["depth60", "deep"])
def test_velocity_alone_is_the_kinematics_velocity(depth, monkeypatch) -> None:
    """element_wave_velocity (the moments formed without the mean square) gives
    element_wave_kinematics(...).velocity bitwise — elements crossing the waterline and
    dry ones, ω = 0 — and a source's moments alone (KinematicsBlocks.moments) those it
    forms with the squares; its arguments are checked as the kinematics' are."""
    from stochcable.dynamics.loads.element_kinematics import element_wave_velocity
    from stochcable.errors import InputError

    w = np.linspace(0.0, 4.0, 61)
    ref = element_wave_kinematics(w, _line(), heading=0.4, depth=depth)
    got = element_wave_velocity(w, _line(), heading=0.4, depth=depth)
    assert np.array_equal(got, ref.velocity) and np.any(got != 0.0)
    monkeypatch.setenv("STOCHCABLE_WORKING_MEMORY_MB", "0.01")  # (a source kept, no parts)
    src = element_wave_kinematics(w, _line(), heading=0.4, depth=depth).moments.source
    for freq in (slice(None), slice(3, 40), np.array([0, 9, 60])):
        parts, square = src.form(freq)
        assert np.array_equal(src.moments(freq), parts) and square is not None
    with pytest.raises(InputError, match="depth"):
        element_wave_velocity(w, _line(), heading=0.4, depth=30.0)


def test_end_square_weighted_sum_kept_for_the_same_weights() -> None:
    """EndSquare.weighted keeps its last sum: asked again with equal weights (another
    array) it returns the same numbers as a fresh evaluation, as a copy (the caller's
    in-place sums do not reach the kept one); other weights are summed anew."""
    w = np.linspace(0.0, 4.0, 61)
    ends = element_wave_kinematics(w, _line(), heading=0.4, depth=60.0).ends
    fresh = element_wave_kinematics(w, _line(), heading=0.4, depth=60.0).ends
    q = np.random.default_rng(1).uniform(size=w.size)
    first = ends.weighted(q)
    first += 1.0  # (a caller's in-place sum)
    again = ends.weighted(q.copy())
    assert np.array_equal(again, fresh.weighted(q)) and np.any(again != first)
    other = ends.weighted(2.0 * q)
    assert np.array_equal(other, fresh.weighted(2.0 * q))
    assert np.array_equal(ends.weighted(q), again)


@pytest.mark.parametrize("depth", [60.0, np.inf], ids=["depth60", "deep"])
def test_mean_velocity_is_the_sum_of_the_moments(depth) -> None:
    """element_mean_velocity (∫ v dξ over the wet part in one closed form, the drag
    residual's split pieces) equals the sum of element_wave_velocity's two moments to
    round-off (1e-14 of the largest: the same integral, φ1 alone against φ1 − ψ + ψ) —
    elements crossing the waterline and dry ones, ω = 0 (the long-wave limit) — in its
    horizontal part along the heading and its vertical part; its arguments are checked
    as the kinematics' are."""
    from stochcable.dynamics.loads.element_kinematics import (
        element_mean_velocity,
        element_wave_velocity,
    )
    from stochcable.errors import InputError

    w = np.linspace(0.0, 4.0, 61)
    beta = 0.4
    pts = np.vstack([_line(), [310.0, 42.0, 8.0]])  # (and a dry element above z = +4 m)
    got = element_mean_velocity(w, pts, heading=beta, depth=depth)  # (n_el, 2, n_w)
    ref = element_wave_velocity(w, pts, heading=beta, depth=depth).sum(axis=2)
    as_xyz = np.stack(
        [got[:, 0] * np.cos(beta), got[:, 0] * np.sin(beta), got[:, 1]], axis=-1
    ).transpose(1, 0, 2)  # (n_w, n_el, 3), as the moments' components
    scale = np.abs(ref).max()
    assert scale > 0.0 and np.abs(as_xyz - ref).max() <= 1e-14 * scale
    dry = np.all(ref == 0.0, axis=(0, 2))
    assert dry[-1] and np.all(got[dry] == 0.0)  # (the dry element: exact zeros)
    # ω = 0: finite depth's long-wave limit √(g/h) over the wet part, deep water's 0
    assert np.any(got[:, 0, 0] != 0.0) == np.isfinite(depth)
    with pytest.raises(InputError, match="depth"):
        element_mean_velocity(w, _line(), heading=beta, depth=30.0)
