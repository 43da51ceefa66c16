"""The residuals along the line (stochcable.dynamics.residuals.along_line): the element
tensions' residual variance from the residual kinds' own load cross-spectra.

Independent checks: the element influence against a forward dense solve of the
finite-element equations with a random load (no adjoint, no band storage, no LAPACK
band solver); the same contraction with the end rows in place of the elements against
the kinds' own end lines (the plumbing of the captured loads); the end elements'
residual against the ends' (a different output: the element's stretch, not the
support reaction; they differ by the half element's inertia and drag); the stations'
interpolation against every element; the switches off leave the linear σ."""

from __future__ import annotations

import copy
import sys
import warnings

import numpy as np
import pytest
from _paths import ROOT
from _scenes import (
    CHAIN_PERIOD,
    along_line_arguments,
    chain_surge_doc,
    forward_dense_motions,
    periodic_surge_td,
)

from stochcable import analyze
from stochcable.dynamics.residuals.along_line import (
    Capture,
    capture_outputs,
    element_influence,
    element_lines,
    element_rows,
    fill_lines,
    line_subset,
    load_power,
    station_weights,
    stations,
)
from stochcable.dynamics.residuals.residual_lines import EndInfluence, dense_pair_outputs


@pytest.fixture(scope="module")
def chain():
    """The chain's line at 20 elements, fairlead surge, both residuals; the arguments
    of its along-line evaluation kept (system, damping, applied, taps)."""
    return along_line_arguments(chain_surge_doc(20), "")


def test_element_influence_equals_a_forward_dense_solve(chain):
    """A random node load at three frequencies (one near the line's first mode): the
    element tensions of the forward solve u_f = A⁻¹F_f (dense, numpy.linalg), δT_e =
    r_e·(u_e, u_e+1), against the adjoint influence times the load, within 1e-9 of the
    largest (round-off of two well-conditioned solves of 42 unknowns)."""
    _, seen = chain
    system, damping = seen["system"], seen["damping"]
    model = system.model
    n, d = model.n_nodes, model.dim
    rng = np.random.default_rng(11)
    load = rng.standard_normal((n, d)) + 1j * rng.standard_normal((n, d))
    w = np.array([0.05, float(system.modes.omega[0]), 1.3])
    g = element_influence(system, damping, w)  # (n_el, n, d, n_w)
    rows = element_rows(model)
    for j, u in enumerate(forward_dense_motions(system, damping, load, w)):
        direct = np.einsum("ed,ed->e", rows[:, 0], u[:-1]) + np.einsum(
            "ed,ed->e", rows[:, 1], u[1:]
        )
        adjoint = np.einsum("end,nd->e", g[..., j], load)
        assert np.max(np.abs(adjoint - direct)) < 1e-9 * np.max(np.abs(direct))


def test_end_rows_reproduce_the_kinds_end_lines(chain):
    """The captured load cross-spectra contracted with the end influence (in place of
    the elements' and without the geometric forces' own stretch) give each kind's end
    lines to round-off: the loads, their columns and the cell factors are the kinds', and
    each pair is contracted once (the dense form adds a repeated pair once)."""
    line, seen = chain
    system, damping = seen["system"], seen["damping"]
    for kind, tap in seen["taps"].items():
        assert len(tap.captures) == 1 and tap.unmatched == 0
        got = element_lines(
            system, damping, kind, tap.captures, EndInfluence(system, damping), feedthrough=False
        )
        _, ref = line.residuals[kind].lines[0]
        for k, end in enumerate(("end_a", "end_b")):
            assert np.allclose(got[k], ref[end], rtol=1e-10, atol=1e-12 * np.abs(ref[end]).max())


def test_end_elements_carry_the_end_residuals(chain):
    """Each kind's residual variance at the first and last element against its end
    tension's (the chain at 40 elements: 2e-4 / 3e-4 apart; here at 20 elements within
    8e-4, the half element's inertia and drag between the support and the element:
    3e-3 allowed), and the corrected σ ratio alike (1.1e-3 measured); the geometric
    forces' own stretch is what makes them agree (without it the kept elements'
    residuals jump ×10 along the line)."""
    line, _ = chain
    al = line.along_line
    assert al.computed
    for kind, ((_, v), *_) in al.lines.items():
        rec = line.residuals[kind]
        for el, end in ((0, "end_a"), (-1, "end_b")):
            ref = rec.lines[0][1][end].sum()
            assert v[el].sum() == pytest.approx(ref, rel=3e-3)
    for el, end in ((0, "end_a"), (-1, "end_b")):
        ratio_el = line.tension_std[el] / line.tension_std_linear[el]
        ratio_end = getattr(line, end).std / line.linear[end].std
        assert ratio_el == pytest.approx(ratio_end, rel=3e-3)


def test_element_density_integrates_to_the_corrected_variance(chain):
    """Each element's density with the residuals (linear density from the element
    tension transfer, plus the residual lines) integrates by the trapezoid rule to its
    corrected σ² (1e-9: the corrected spectrum's scale makes it so to round-off) and
    reaches the superharmonics above the analysis band, up to the drag residual's top
    line (those above it, whose bound at the ends is below LINE_TOL, not formed: here
    1.76 × the band's top)."""
    line, _ = chain
    lin = line.tension_spectrum
    top = float(line.drag_residual.lines[0][0][-1])
    assert top > 1.5 * line.omega[-1]
    for el in (0, 7, line.tension_std.size - 1):
        spec = line.along_line.density(el, line.omega, lin[el])
        area = np.trapezoid(spec.density, spec.omega)
        assert area == pytest.approx(line.tension_std[el] ** 2, rel=1e-9)
        assert spec.omega[-1] >= top


def test_stations_interpolate_every_element():
    """Stations: every element of a short line; else both ends, the segment junctions
    and evenly spaced ones; the weights interpolate a linear function exactly."""

    class _Mesh:
        segment = np.r_[np.zeros(12, int), np.ones(18, int)]

    class _Model:
        n_elements = 30
        mesh = _Mesh()

    at = stations(_Model(), 5)
    assert at[0] == 0 and at[-1] == 29 and {11, 12} <= set(at.tolist())
    assert np.array_equal(stations(_Model(), 40), np.arange(30))
    s = np.sort(np.random.default_rng(2).uniform(0, 100, 30))
    wts = station_weights(s, at)
    assert np.allclose(wts.sum(axis=1), 1.0)
    assert np.allclose(wts @ (3.0 * s[at] - 1.0), 3.0 * s - 1.0)


def test_switches_off_leave_the_linear_element_tensions(chain):
    """Residuals off: no along-line record, the element σ the linear one to the bit;
    on: the linear σ kept beside (the same numbers)."""
    line, _ = chain
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        off = analyze(chain_surge_doc(20, residual=False)).lines["leg1"]
    assert off.along_line is None and off.tension_std_linear is None
    assert np.array_equal(off.tension_std, line.tension_std_linear)
    assert "std_linear" not in off.to_document()["tension"]
    doc = copy.deepcopy(line.to_document()["tension"])
    assert doc["std_linear"] == line.tension_std_linear.tolist()


def test_lines_on_a_stride_fill_the_others():
    """The first line, every second from line 1 (the multiples of 2Δ) and the last; the
    others interpolated linearly (exact for a linear spectrum, its sum the
    trapezoid's)."""
    sel = line_subset(9, 2)
    assert sel.tolist() == [0, 1, 3, 5, 7, 8] and line_subset(8, 2).tolist() == [0, 1, 3, 5, 7]
    ramp = 3.0 + 0.5 * np.arange(8.0)
    at = line_subset(8, 2)
    assert np.allclose(fill_lines(ramp[None, at], at, 8)[0], ramp, rtol=0, atol=1e-15)


def test_element_tensions_on_every_second_line(monkeypatch):
    """The element tensions' residual lines on every second line (along_line.line_stride:
    where the ends' lines summed that way stay within 0.2 %) against every line: every
    element's corrected σ within 1e-4 on the chain (measured 1.3e-5; 3.9e-5 on the
    two-segment line); the inclined guy, whose 0.7 %-damped mode fails the ends' check,
    keeps every line (bitwise)."""
    import stochcable.dynamics.residuals.residual_lines as rl

    sys.path.insert(0, str(ROOT / "benchmarks"))
    import residual_cost

    docs = {n: residual_cost.with_variant(residual_cost.lines(guy=True)[n], "both")
            for n in ("chain", "guy")}  # fmt: skip
    got = {}
    for stride in (1, 2):
        monkeypatch.setattr(rl, "ALONG_STRIDE", stride)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            got[stride] = {n: next(iter(analyze(d).lines.values())).tension_std
                           for n, d in docs.items()}  # fmt: skip
    assert np.max(np.abs(got[2]["chain"] / got[1]["chain"] - 1)) < 1e-4
    assert np.max(np.abs(got[2]["chain"] / got[1]["chain"] - 1)) > 0  # (strided)
    assert np.array_equal(got[2]["guy"], got[1]["guy"])


def _td_element_sigma(doc: dict, seed: int, elements: list[int], **variant) -> np.ndarray:
    """TD σ of the ``elements``' tension over the second of the two periods of
    :func:`_scenes.periodic_surge_td` (the phases of the ends' TD)."""
    h = periodic_surge_td(doc, seed, **variant)
    return h.element_tension_std(start=CHAIN_PERIOD - 1e-9)[elements]


@pytest.mark.slow
def test_mid_line_drag_correction_matches_the_time_domain_quadratic_drag_shift():
    """The chain's line at 40 elements, fairlead surge (as the end test of
    tests/dynamics/test_drag_residual.py): the TD with the FD's linear drag against the
    TD with quadratic drag (same phases, linear bed) measures the quadratic drag's own
    effect on the tension of elements 10, 20 and 30; the drag residual along the line
    predicts it within the 95 % CI of the paired shift over seeds 1–4 (Student t:
    ±2 %).  Measured: +7.1 / +6.6 / +5.8 % in the TD against +6.6 / +6.0 / +5.4 %
    predicted (the ends: +7.4 / +4.7 % against +6.8 / +4.1 %, the same 0.5 % short)."""
    from scipy import stats

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        line = analyze(chain_surge_doc(40)).lines["leg1"]
    els = [10, 20, 30]
    lin = line.tension_std_linear[els]
    drag = sum(v.sum(axis=1) for _, v in line.along_line.lines["drag_residual"])[els]
    pred = np.sqrt(1.0 + drag / lin**2) - 1.0
    b = (np.asarray(line.linearization.b_normal), np.asarray(line.linearization.b_axial))
    doc = chain_surge_doc(40, residual=False)
    shifts = []
    for seed in (1, 2, 3, 4):
        td_lin = _td_element_sigma(doc, seed, els, drag="linear", linear_drag=b, seabed="linear")
        td_quad = _td_element_sigma(doc, seed, els, drag="static_tangent", seabed="linear")
        shifts.append((td_quad - td_lin) / lin)
    shifts = np.array(shifts)
    half = stats.t.ppf(0.975, len(shifts) - 1) * shifts.std(axis=0, ddof=1) / 2.0
    assert np.all(pred > 0.02)
    np.testing.assert_array_less(np.abs(pred - shifts.mean(axis=0)), half)


def test_element_influence_of_a_travelling_line_by_the_adjoint():
    """A travelling line (speed −5 m/s: the skew gyroscopic G, so Aᵀ has C − G): the
    element influence equals the forward dense solve with the full impedance
    (tests/dynamics/test_transport_solve.py's end influence check), to 1e-9."""
    from test_transport_solve import _damping, _system

    from stochcable.line.fem import build_fe_model
    from stochcable.line.transport.matrices import transport_matrices

    with pytest.warns(Warning):
        scene, system = _system(-5.0)
    damping = _damping(system, np.random.default_rng(7))
    w = np.array([0.3, 1.7])
    got = element_influence(system, damping, w)  # (n_el, n_nodes, d, n_w)
    rest = build_fe_model(system.statics, scene.environment, dim=2)
    tr = transport_matrices(rest, -5.0)
    k, m = tr.K.toarray(), (rest.M + rest.Ma).toarray()
    c = damping.matrix.toarray() + rest.Cs.toarray() + tr.G.toarray()
    fr, d = rest.free, rest.dim
    rows = element_rows(system.model)
    for i, x in enumerate(w):
        z = k - x * x * m + 1j * x * c
        for dof in fr[[0, 5, -1]]:
            f = np.zeros(k.shape[0])
            f[dof] = 1.0
            u = np.zeros(k.shape[0], complex)
            u[fr] = np.linalg.solve(z[np.ix_(fr, fr)], f[fr])
            u = u.reshape(-1, d)
            t = np.einsum("ed,ed->e", rows[:, 0], u[:-1]) + np.einsum("ed,ed->e", rows[:, 1], u[1:])
            g = got[:, dof // d, dof % d, i]
            assert np.max(np.abs(g - t)) <= 1e-9 * np.max(np.abs(t))


def test_capture_outputs_read_the_lines_as_views():
    """The lines of a capture's dense G read run by run as views (every line, every
    second with the first and last apart, single lines) give the contraction of the
    rows gathered by index, bitwise; G in single precision contracted in double gives
    the double contraction of the same (widened) numbers to round-off."""
    rng = np.random.default_rng(7)
    n, n_o, n_out = 5, 23, 3
    g = (rng.normal(size=(n_o, n * n)) + 1j * rng.normal(size=(n_o, n * n))).astype(np.complex64)
    cap = Capture(np.arange(1.0, n_o + 1), np.zeros((2, 1, n)), np.arange(n), None, [], g)
    for sel in (
        line_subset(n_o, 1),
        line_subset(n_o, 2),
        line_subset(22, 2),
        line_subset(1, 2),
        line_subset(0, 2),
        np.array([0, 4, 5, 9]),
    ):
        t = rng.normal(size=(n_out, n, sel.size)) + 1j * rng.normal(size=(n_out, n, sel.size))
        got = capture_outputs(cap, t, sel, np.complex64)
        assert np.array_equal(got, dense_pair_outputs(g[sel], t, np.complex64))
        wide = capture_outputs(cap, t, sel, complex)
        ref = dense_pair_outputs(g[sel].astype(complex), t)
        assert np.allclose(wide, ref, rtol=1e-12, atol=1e-12 * np.abs(ref).max(initial=0.0))


def _columns_by_column_bytes(transfer: np.ndarray, h: np.ndarray) -> np.ndarray | None:
    """The former matching of _columns_of: each column's first line and then the whole
    column as the bytes of its own contiguous copy."""
    if h.shape[0] != transfer.shape[0] or h.shape[2] < transfer.shape[2]:
        return None
    h = h[:, :, : transfer.shape[2]]
    first = {np.ascontiguousarray(h[:, j, 0]).tobytes(): j for j in range(h.shape[1])}
    keys = [np.ascontiguousarray(transfer[:, c, 0]).tobytes() for c in range(transfer.shape[1])]
    if len(first) == h.shape[1] and all(k in first for k in keys):
        kept = np.array([first[k] for k in keys], dtype=int)
        if np.array_equal(h[:, kept], transfer):
            return kept
    cols = [np.ascontiguousarray(transfer[:, c]).tobytes() for c in range(transfer.shape[1])]
    index = {np.ascontiguousarray(h[:, j]).tobytes(): j for j in range(h.shape[1])}
    if all(c in index for c in cols):
        return np.array([index[c] for c in cols], dtype=int)
    return None


def test_columns_of_match_the_former_column_by_column_bytes():
    """The tap's matching of a contraction's transfer to its load transfer (the first
    lines' bytes taken as rows of one contiguous array) gives the former per-column
    matching's columns: a permuted subset of a transposed (load-major) ``h`` on its
    leading lines, first lines that repeat (whole columns then), a column not in ``h``
    and a transfer longer than ``h`` (None)."""
    from stochcable.dynamics.residuals.along_line import _columns_of

    rng = np.random.default_rng(11)
    n_out, n_all, n_h = 2, 30, 40
    raw = rng.normal(size=(n_all, n_out, n_h)) + 1j * rng.normal(size=(n_all, n_out, n_h))
    h = np.transpose(raw, (1, 0, 2))  # (the load transfer's layout: a transposed view)
    pick = rng.permutation(n_all)[:17]
    repeat = h.copy()
    repeat[:, 5, 0] = repeat[:, 9, 0]  # (two first lines equal, the columns not)
    other = h[:, pick, :25].copy()
    other[1, 3, 7] += 1.0  # (a column that is not in h)
    cases = [
        (np.ascontiguousarray(h[:, pick, :25]), h),
        (np.ascontiguousarray(h[:, pick]), h),
        (repeat[:, [9, 5, 2], :12].copy(), repeat),
        (other, h),
        (np.ascontiguousarray(h[:, pick]), h[:, :, :20]),
    ]
    for transfer, hh in cases:
        ref = _columns_by_column_bytes(transfer, hh)
        got = _columns_of(transfer, hh)
        assert (got is None) == (ref is None)
        if ref is not None:
            assert np.array_equal(got, ref)
    assert np.array_equal(_columns_of(*cases[0]), pick)
    assert np.array_equal(_columns_of(*cases[2]), [9, 5, 2])
    assert _columns_of(*cases[3]) is None


def test_load_power_is_the_moduli_squared() -> None:
    """load_power's real contraction of the interleaved parts against Σ_p |h|² by
    np.abs (complex, a strided view, real; round-off: the same squares summed in
    another order, 16 terms: within 4 ulp of the largest)."""
    rng = np.random.default_rng(3)
    h = rng.standard_normal((5, 16, 9)) + 1j * rng.standard_normal((5, 16, 9))
    h[:, :, 4] *= 1e-150  # (a line of tiny moduli, where hypot and the squares differ)
    for x in (h, h[:, :, ::2], h.real):
        ref = np.sum(np.abs(x) ** 2, axis=1)
        got = load_power(x)
        assert got.shape == ref.shape
        np.testing.assert_allclose(got, ref, rtol=1e-15 * x.shape[1], atol=0.0)


def test_misfit_lines_against_the_difference_of_squares(monkeypatch) -> None:  # noqa: ANN001
    """misfit_lines (the bundled chain's element tensions and node motions, both
    residuals: its misfit on split elements) against Σ_c q·S_c(|H_L + H_c|² − |H_L|²)
    formed directly: H_c by an einsum over the misfit loads of the transfer at each
    frequency's line (at the frequency itself where :func:`bent_cells` marks the cell),
    q the trapezoid weights.  Round-off: the difference of two squares loses the
    digits of |H_L|² (H_c is 1e-2 of it and less), so the lines agree to 1e-14 of
    the outputs' linear variance lines, not of their own size."""
    import stochcable.dynamics.residuals.along_line as al
    import stochcable.dynamics.residuals.along_line_motion as alm
    from stochcable.dynamics.model.blocks import trapezoid_weights
    from stochcable.dynamics.residuals.residual_lines import load_transfer

    sys.path.insert(0, str(ROOT / "benchmarks"))
    import residual_cost

    seen = []
    orig = al.misfit_lines

    def spy(*args):  # noqa: ANN002, ANN202
        seen.append(args)
        return orig(*args)

    monkeypatch.setattr(al, "misfit_lines", spy)
    monkeypatch.setattr(alm, "misfit_lines", spy)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        analyze(residual_cost.with_variant(residual_cost.lines()["chain"], "both"))
    assert len(seen) == 2  # (the element tensions' and the node motions')
    for system, damping, (unit, load, w), w_lines, influence, linear, spectra in seen:
        at = np.clip(np.rint(w / w_lines[0]).astype(int) - 1, 0, w_lines.size - 1)
        on_lines = load_transfer(system, damping, unit, w_lines[: at.max() + 2], influence)
        h = on_lines[:, :, at]
        bent = np.flatnonzero(al.bent_cells(on_lines)[at])
        assert bent.size  # (the resonant cells' own frequencies at work)
        h[:, :, bent] = load_transfer(system, damping, unit, w[bent], influence)
        h_c = np.einsum("opw,cpw->cow", h, load)
        q = trapezoid_weights(w)[None, None] * spectra[:, None]
        ref = np.sum(q * (np.abs(linear + h_c) ** 2 - np.abs(linear) ** 2), axis=0)
        scale = np.sum(q * np.abs(linear) ** 2, axis=0)
        got = orig(system, damping, (unit, load, w), w_lines, influence, linear, spectra)
        assert got.shape == ref.shape and np.any(ref)
        assert np.max(np.abs(got - ref) / np.max(scale, axis=1, keepdims=True)) < 1e-14
