"""Tests of stochcable.errors: message formats and the thread-safe warning record."""

from __future__ import annotations

import threading
import warnings

import numpy as np
import pytest

from stochcable.errors import (
    ConvergenceError,
    InputError,
    PhysicsWarning,
    ResolutionWarning,
    collect_warnings,
    warn,
)


def test_input_error_names_parameter_value_unit_constraint():
    err = InputError("hs", -1.0, "m", "must be > 0")
    assert str(err) == "hs = -1.0 [m]: must be > 0"
    assert (err.parameter, err.value, err.unit, err.constraint) == ("hs", -1.0, "m", "must be > 0")
    assert isinstance(err, ValueError)
    # dimensionless: no unit bracket; long arrays summarized, not dumped
    assert str(InputError("gamma", 0.5, "-", "must be >= 1")) == "gamma = 0.5: must be >= 1"
    assert "array(shape=(100,))" in str(InputError("omega", np.zeros(100), "rad/s", "bad"))


def test_convergence_error_reports_residual_and_hint():
    err = ConvergenceError("statics Newton", 12, 3.2e-3, 1e-10, hint="add elements", partial=7)
    assert "statics Newton did not converge: residual 3.200e-03 after 12 iterations" in str(err)
    assert str(err).endswith("(tolerance 1.0e-10); add elements")
    assert err.partial == 7


def test_collect_warnings_records_and_still_warns():
    with pytest.warns(ResolutionWarning, match="coarse"):
        with collect_warnings() as got:
            warn("grid too coarse", ResolutionWarning)
    assert [type(w) for w in got] == [ResolutionWarning]
    assert str(got[0]) == "grid too coarse"


def test_collect_warnings_nests_and_records_even_when_filtered():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        with collect_warnings() as outer:
            warn("a")
            with collect_warnings() as inner:
                warn("b")
    assert [str(w) for w in outer] == ["a", "b"]
    assert [str(w) for w in inner] == ["b"]
    assert all(isinstance(w, PhysicsWarning) for w in outer)


def test_collect_warnings_is_per_thread():
    # warnings.catch_warnings is process-global before Python 3.14: two analyses in
    # two service threads must not lose or swap each other's warnings
    got: dict[int, list[str]] = {}
    barrier = threading.Barrier(4)

    def run(k: int) -> None:
        with collect_warnings() as sink:
            barrier.wait()
            for i in range(200):
                warn(f"thread {k} #{i}")
        got[k] = [str(w) for w in sink]

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        threads = [threading.Thread(target=run, args=(k,)) for k in range(4)]
        for t in threads:
            t.start()
        for t in threads:
            t.join()
    for k in range(4):
        assert got[k] == [f"thread {k} #{i}" for i in range(200)]
