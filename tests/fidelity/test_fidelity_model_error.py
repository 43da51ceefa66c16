"""The linear model's own error in the fidelity plan (stochcable.fidelity.model_error):
the calibrated class of each line, the second-order stretching term, the largest line."""

from __future__ import annotations

from types import SimpleNamespace

import pytest

from stochcable.fidelity.model_error import BED_ERROR, CALIBRATION, linearization_model_error


def _line(std_factor=None):
    so = None if std_factor is None else SimpleNamespace(std_factor=std_factor)
    return SimpleNamespace(indicators=SimpleNamespace(second_order=so))


def test_classes_stretching_and_the_largest_line():
    td, sus = CALIBRATION["touchdown"], CALIBRATION["suspended"]
    # the calibration's figures are the measured ones (docs/benchmarks/fd_budget.md:
    # TD/FD − 1 = +5.13 % / +8.34 %, i.e. FD/TD − 1 = −4.9 % / −7.7 %)
    assert td.fairlead == pytest.approx(1 - 1 / 1.0513, abs=5e-4)
    assert td.anchor == pytest.approx(1 - 1 / 1.0834, abs=5e-4) and td.error == td.anchor
    err, basis = linearization_model_error({"a": _line()}, {"a": None})
    assert err == sus.error and "suspended" in basis
    err, basis = linearization_model_error({"a": _line(1.0), "b": _line()}, {"a": None, "b": 400.0})
    assert err == td.error and "'b' (touchdown)" in basis and "fd_budget" in basis
    # a near-straight line whose second-order σ factor is 1.18: low by 1 − 1/1.18
    err, basis = linearization_model_error({"g": _line(1.18)}, {"g": None})
    assert err == pytest.approx(1.0 - 1.0 / 1.18) and "second-order stretching" in basis
    # non-finite or absent factors fall back on the calibration
    err, _ = linearization_model_error({"g": _line(float("nan"))}, {"g": None})
    assert err == sus.error


def _record(computed: bool, reason: str = ""):
    return SimpleNamespace(computed=computed, reason=reason)


def _corrected(lin: dict, cor: dict, kinds: dict, std_factor=None):
    """A line result whose residuals ``kinds`` were asked (records), with linear and
    corrected end σ."""
    line = _line(std_factor)
    line.residuals = kinds
    line.end_a = SimpleNamespace(std=cor["end_a"])
    line.end_b = SimpleNamespace(std=cor["end_b"])
    line.linear_end = lambda e: SimpleNamespace(std=lin[e])
    return line


def test_computed_residuals_replace_the_calibration():
    """With the drag residual computed, the estimate is the square of the residuals'
    σ share (the larger end) — plus the one-sided bed on a grounded line — and no
    class constant; the stretching term is dropped when the geometric residual is
    computed (it is part of it) and kept when it is not."""
    lin = {"end_a": 100.0, "end_b": 200.0}
    cor = {"end_a": 104.0, "end_b": 216.0}  # shares 4 % and 8 %: r = 0.08 at end_b
    both = {"drag_residual": _record(True), "geometric_residual": _record(True)}
    err, basis = linearization_model_error({"s": _corrected(lin, cor, both)}, {"s": None})
    assert err == pytest.approx(0.08**2) and err != CALIBRATION["suspended"].error
    assert "end_b" in basis and "8 %" in basis and "calibrated" not in basis
    err, basis = linearization_model_error({"t": _corrected(lin, cor, both)}, {"t": 300.0})
    assert err == pytest.approx(0.08**2 + BED_ERROR) and "one-sided bed" in basis
    assert err < CALIBRATION["touchdown"].error  # (the point: the measured share is used)
    # the residuals moving σ down count by their size too
    down = {"end_a": 95.0, "end_b": 200.0}
    err, _ = linearization_model_error({"s": _corrected(lin, down, both)}, {"s": None})
    assert err == pytest.approx(0.05**2)
    # a strongly stretched near-straight line: with the geometric residual computed the
    # stretching is in it; with the drag residual alone it still counts
    err, _ = linearization_model_error({"g": _corrected(lin, cor, both, 1.18)}, {"g": None})
    assert err == pytest.approx(0.08**2)
    drag_only = {"drag_residual": _record(True)}
    err, basis = linearization_model_error(
        {"g": _corrected(lin, cor, drag_only, 1.18)}, {"g": None}
    )
    assert err == pytest.approx(1.0 - 1.0 / 1.18) and "stretching" in basis


def test_a_residual_out_of_scope_keeps_the_calibration_and_says_why():
    lin = cor = {"end_a": 1.0, "end_b": 1.0}
    kinds = {"drag_residual": _record(False, "a line on free bodies is not covered")}
    err, basis = linearization_model_error({"b": _corrected(lin, cor, kinds)}, {"b": 10.0})
    assert err == CALIBRATION["touchdown"].error
    assert "not computed: a line on free bodies" in basis


def test_the_plan_reads_the_pilot_s_computed_residuals():
    """choose_fidelity on the taut wire with both residuals on: the plan's model error
    is the one its pilot's computed residuals give (the pilot is the analysis the
    planner ran), not the calibration constant; off, it is the constant."""
    from stochcable import analyze, load_example
    from stochcable.fidelity import choose_fidelity
    from stochcable.fidelity.model_error import residual_model_error

    pilots = []

    def evaluate(sc):
        pilots.append(analyze(sc))
        return pilots[-1]

    doc = load_example("taut_wire").model_dump(mode="json", exclude_none=True)
    doc["analysis"]["linearization"].update(drag_residual=True, geometric_residual=True)
    plan = choose_fidelity(doc, 0.05, evaluate=evaluate)
    lr = pilots[-1].lines["wire"]
    assert lr.residuals["drag_residual"].computed
    want, _ = residual_model_error("wire", lr, grounded=False)
    assert plan.error_estimate["linearization_model"] == pytest.approx(want, rel=1e-12)
    assert want > 1e-4  # the taut wire's residual share is ≈ 18 % at its fairlead
    assert "computed residuals" in plan.model_error_basis
    doc["analysis"]["linearization"].update(drag_residual=False, geometric_residual=False)
    off = choose_fidelity(doc, 0.05, evaluate=analyze)
    assert off.error_estimate["linearization_model"] == CALIBRATION["suspended"].error
