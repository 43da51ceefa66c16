"""The linear model's own error in the fidelity plan (stochcable.fidelity.model_error):
the calibrated class of each line, the second-order stretching term, the largest line."""

from __future__ import annotations

from types import SimpleNamespace

import pytest

from stochcable.fidelity.model_error import CALIBRATION, linearization_model_error


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
