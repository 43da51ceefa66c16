"""The compiled element kinematics (stochcable.dynamics.loads.kinematics_kernels) against the
NumPy form (kinematics_closed_forms.kinematics_block, ``STOCHCABLE_NUMBA=0``): the same
formulas, so equal to a few ulps of each element's largest value.

The closed forms themselves are checked against quadrature of the nodal kinematics
along the elements in tests/dynamics/test_wave_loads.py (test_closed_form_element_integrals_
equal_quadrature), which runs with either path."""

from __future__ import annotations

import math

import numpy as np
import pytest

pytest.importorskip("numba")

from stochcable.dynamics.loads import element_kinematics as ek  # noqa: E402
from stochcable.dynamics.loads import kinematics_closed_forms as closed_forms  # noqa: E402
from stochcable.dynamics.loads.element_kinematics import element_wave_kinematics  # noqa: E402
from stochcable.sea.kinematics import wavenumber  # noqa: E402

G = 9.80665

# The same formulas on both paths; they differ by the rounding of libm's exponential
# against NumPy's vectorized one, e^{2a} formed as (e^a)², the kernel's in-line cos and
# sin (an ulp or two of libm's) and x⁻¹ formed once: a few ulps of the terms, which are
# bounded by the element's largest value (the moments are sums of at most a few terms of
# that size; a relative 1e-13 leaves room for a phase k·χ ~ 1e3 multiplying one ulp of
# the angle's cos and sin).  The series/closed-form switch is the same (|x| < 0.5; at
# the switch both forms are exact to ~4e-16).  1e-300 for elements whose values are all
# zero (dry).
RTOL = 1e-13


def _line(depth: float) -> np.ndarray:
    """One polyline with every kind of element: vertical, horizontal (dz = 0) under
    water, rising through the waterline, wholly dry (inclined and horizontal), sinking
    through it, ending exactly at z = 0, horizontal at z = 0, then down; ~30 m elements
    (k·L up to ~110 at 6 rad/s).  z scaled to the depth in shallow water."""
    pts = np.array(
        [
            [0.0, 0.0, -40.0],
            [0.0, 0.0, -10.0],  # vertical
            [30.0, 0.0, -10.0],  # horizontal
            [58.0, 10.0, -10.0],  # horizontal, oblique
            [80.0, 15.0, 8.0],  # rising through z = 0
            [100.0, 15.0, 12.0],  # dry
            [110.0, 20.0, 12.0],  # dry, horizontal
            [130.0, 20.0, -5.0],  # sinking through z = 0
            [150.0, 20.0, 0.0],  # ending at z = 0
            [170.0, 25.0, 0.0],  # horizontal at z = 0
            [190.0, 25.0, -30.0],
            [200.0, 28.0, -40.0],
        ]
    )
    if depth < 40.0:
        pts[:, 2] = np.where(pts[:, 2] < 0.0, pts[:, 2] * depth / 40.0, pts[:, 2])
    return pts


def _long_line(n_el: int = 200, far: float = 0.0) -> np.ndarray:
    """A catenary-like line 1,200 m long from 190 m below the surface to 5 m below (large
    phases k·χ, short elements: the series branch), shifted ``far`` along x."""
    s = np.linspace(0.0, 1.0, n_el + 1)
    x = 1200.0 * s + far
    return np.c_[x, 0.3 * (x - far), -190.0 + 185.0 * s**2]


def _both(monkeypatch, *args):
    """(compiled, NumPy) kinematics of ``args`` (the compiled loop on any grid size),
    kept (the default working-memory target)."""
    monkeypatch.delenv("STOCHCABLE_WORKING_MEMORY_MB", raising=False)
    monkeypatch.setenv("STOCHCABLE_NUMBA", "0")
    ref = element_wave_kinematics(*args)
    monkeypatch.delenv("STOCHCABLE_NUMBA", raising=False)
    monkeypatch.setattr(ek, "KERNEL_MIN_ENTRIES", 0)  # the compiled loop on any grid
    got = element_wave_kinematics(*args)
    return got, ref


def _assert_close(got: np.ndarray, ref: np.ndarray, scale: np.ndarray, what: str) -> float:
    """|got − ref| <= RTOL·scale + 1e-300 (scale broadcast); the worst ratio."""
    assert np.all(np.isfinite(got)), what
    err = np.abs(got - ref)
    bound = RTOL * scale + 1e-300
    worst = float(np.max(err / bound)) * RTOL
    assert np.all(err <= bound), f"{what}: worst |Δ|/scale {worst:.2e}"
    return worst


def _compare(got, ref) -> None:
    """Moments per element and part, to the largest |value| of that element and part
    over the ends and frequencies; the mean squares per element: the horizontal to its
    largest value, the vertical to the element's largest |v|² (where the NumPy form
    cancels, very shallow water, its error is ~1e-16 of that; the docstring of
    element_wave_kinematics)."""
    pg, pr = got.moments.parts, ref.moments.parts  # (n_el, 2, 2, n_w)
    _assert_close(pg, pr, np.abs(pr).max(axis=(1, 3), keepdims=True), "moments")
    sg = np.stack([got.square.horizontal, got.square.vertical])  # (2, n_w, n_el)
    sr = np.stack([ref.square.horizontal, ref.square.vertical])
    h_scale = np.abs(sr[0]).max(axis=0)
    _assert_close(sg[0], sr[0], h_scale, "horizontal mean square")
    v_scale = np.maximum(h_scale, np.abs(sr[1]).max(axis=0))
    _assert_close(sg[1], sr[1], v_scale, "vertical mean square")


CASES = [
    ("deep, heading 0", _line(math.inf), 0.0, math.inf, np.linspace(0.0, 6.0, 121)),
    ("deep, oblique", _line(math.inf), 0.7, math.inf, np.linspace(0.0, 6.0, 121)),
    ("h = 200, heading 0", _line(200.0), 0.0, 200.0, np.linspace(0.0, 6.0, 121)),
    ("h = 200, oblique", _line(200.0), -2.3, 200.0, np.linspace(0.0, 6.0, 121)),
    (
        "h = 5, kh << 1 and large",
        _line(5.0),
        0.4,
        5.0,
        np.r_[0.0, np.geomspace(1e-4, 0.3, 20), np.linspace(0.4, 6.0, 30)],
    ),
    ("h = 200, long line", _long_line(), 0.4, 200.0, np.linspace(0.0, 6.0, 61)),
    ("deep, long line", _long_line(), 0.4, math.inf, np.linspace(0.0, 6.0, 61)),
    # phases k·χ beyond 1e6 (the kernel's cos and sin from libm there)
    ("deep, 300 km along the waves", _long_line(4, 3e5), 0.0, math.inf, np.linspace(0, 6, 13)),
]


@pytest.mark.parametrize("label, pts, heading, depth, w", CASES, ids=[c[0] for c in CASES])
def test_kernel_equals_numpy_element_kinematics(monkeypatch, label, pts, heading, depth, w):
    got, ref = _both(monkeypatch, w, pts, heading, depth, G)
    _compare(got, ref)
    np.testing.assert_array_equal(got.wet_fraction, ref.wet_fraction)


def test_dry_elements_are_zero_and_wet_ones_loaded(monkeypatch):
    pts = _line(200.0)
    got, ref = _both(monkeypatch, np.linspace(0.0, 6.0, 31), pts, 0.0, 200.0, G)
    dry = got.wet_fraction == 0.0
    assert dry.sum() == 2  # the two elements above the surface
    assert np.all(got.moments.parts[dry] == 0.0)
    assert np.all(np.abs(got.moments.parts[~dry][..., 1:]).max(axis=(1, 2, 3)) > 0.0)
    for part in (got.square.horizontal, got.square.vertical):
        assert np.all(part[:, dry] == 0.0)


@pytest.mark.parametrize("depth", [200.0, math.inf])
def test_elements_high_above_the_water_are_zero_on_both_paths(monkeypatch, depth):
    # a guy's top element 100–150 m above the water at 6 rad/s: k·z ≈ 550, 2k·z > 709
    # (e^{2kz} overflows; times the zero wet length it was NaN on the NumPy path)
    pts = np.array([[0.0, 0.0, -50.0], [60.0, 0.0, -1.0], [90.0, 0.0, 100.0], [120, 0, 150.0]])
    got, ref = _both(monkeypatch, np.linspace(0.0, 6.0, 13), pts, 0.0, depth, G)
    for ek_ in (got, ref):
        assert np.all(np.isfinite(ek_.moments.parts)) and np.all(np.isfinite(ek_.square.full()))
        assert np.all(ek_.moments.parts[2:] == 0.0) and np.all(ek_.square.horizontal[:, 2:] == 0)
    _compare(got, ref)


def test_direct_call_writes_a_strided_block_only(monkeypatch):
    """The kernel on a block of frequencies writes that block of the (strided) views
    only, the same numbers as the NumPy form."""
    from stochcable.dynamics.loads.kinematics_kernels import kinematics_block

    pts = _line(200.0)
    w = np.linspace(0.0, 6.0, 40)
    k = wavenumber(w, 200.0, G)
    monkeypatch.setenv("STOCHCABLE_WORKING_MEMORY_MB", "0.001")  # kept: none (a source)
    geo = element_wave_kinematics(w, pts, 0.3, 200.0, G).moments.source.geometry
    n_el = pts.shape[0] - 1
    sl = slice(7, 29)
    out = {}
    for env in ("0", None):
        parts = np.full((n_el, 2, 2, w.size), np.nan + 0j)
        sq = np.full((2, w.size, n_el), np.nan)
        if env is None:
            kinematics_block(w[sl], k[sl], *geo, parts[..., sl], sq[:, sl])
        else:
            closed_forms.kinematics_block(w[sl], k[sl], geo, parts[..., sl], sq[:, sl])
        assert np.all(np.isnan(parts[..., : sl.start])) and np.all(np.isnan(parts[..., sl.stop :]))
        assert np.all(np.isnan(sq[:, : sl.start])) and np.all(np.isnan(sq[:, sl.stop :]))
        out[env] = parts[..., sl], sq[:, sl]
    (pg, sg), (pr, sr) = out[None], out["0"]
    _assert_close(pg, pr, np.abs(pr).max(axis=(1, 3), keepdims=True), "moments")
    _assert_close(sg, sr, np.abs(sr).max(axis=(0, 1)), "mean squares")
