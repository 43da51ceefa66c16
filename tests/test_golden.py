"""The result documents of every golden case are unchanged (tests/golden/record.py).

Recorded through the public CLI before the core was restructured into layered
subpackages; recomputed here on every run.  Numbers are compared to 1e-10 relative
(tests/_compare.py: BLAS thread counts change summation orders at ~1e-13, which the
contracting drag fixed point carries through unchanged), everything else exactly.  Wall
clock (``timing``, the pilot's ``wall_s``) is removed before comparing.
"""

from __future__ import annotations

import importlib.util
from pathlib import Path
from typing import Any

import pytest
from _compare import assert_close_documents

_SPEC = importlib.util.spec_from_file_location(
    "golden_record", Path(__file__).parent / "golden" / "record.py"
)
record = importlib.util.module_from_spec(_SPEC)
_SPEC.loader.exec_module(record)

_CLOCK = {"timing", "wall_s"}


def _without_clock(doc: Any) -> Any:
    if isinstance(doc, dict):
        return {k: _without_clock(v) for k, v in doc.items() if k not in _CLOCK}
    if isinstance(doc, list):
        return [_without_clock(v) for v in doc]
    return doc


@pytest.mark.parametrize("case", sorted(record.cases()))
def test_golden_documents_unchanged(case: str, tmp_path: Path) -> None:
    expected = _without_clock(record.load(case))
    got = _without_clock(record.compute(record.cases()[case], tmp_path))
    assert_close_documents(got, expected)


@pytest.mark.parametrize("case", sorted(record.cases()))
def test_switches_off_reproduce_the_linear_record(case: str, tmp_path: Path) -> None:
    """Both residual switches false (the defaults before issue 31): the documents the
    linear model recorded before the flip (golden/linear), to the same 1e-10."""
    expected = _without_clock(record.load(case, record.LINEAR))
    got = _without_clock(record.compute(record.linear(record.cases()[case]), tmp_path))
    assert_close_documents(got, expected)


# ------------------------------------------- single lines: the one drag fixed point

#: The single-line cases were re-recorded when a line became the group of one line
#: and no bodies (issue 13, "one engine"): the copies of their documents recorded
#: before are in golden/pre_unification.
PRE_UNIFICATION = Path(__file__).parent / "golden" / "pre_unification"

#: Allowed change of the single-line results, in units of the case's linearization
#: tolerance.  Both fixed points stop when the relative change of every σ is at most
#: tol; the drag map contracts by a factor L <= 1/2 per step on these cases (the
#: plain steps' changes fall by 0.1-0.4 per step), so each stopping point is within
#: L/(1 - L)·tol <= tol of the fixed point and the two within 2·tol of each other.
#: The outputs are linear responses to that drag, whose relative sensitivity to the
#: drag is at most 1 (a damping-controlled peak scales as 1/B): 2·tol bounds them too
#: (measured: 0.026·tol on the chain's end-tension spectra, 0.2·tol for the worst
#: number, the chain's per-element drag/inertia ratio).
PRE_UNIFICATION_K = 2.0

#: Since this record the truncated modes of a Foss line also take the kept modes'
#: damping forces (mode acceleration with the damping coupling,
#: stochcable.dynamics.solve.line_solve.damping_coupling): a change of the linear
#: model, not of the fixed point, measured 3.0e-4 on the inclined guy's end m0 (39 of
#: 78 modes kept) and nothing on lines that keep every mode; allowed on top where a
#: line's Foss solve truncates (:func:`_truncates`).
DAMPING_COUPLING_SHIFT = 5e-4


def _truncates(case: str, analyze_doc: dict) -> bool:
    """Whether a line of the case keeps fewer Foss modes than the 2(n_el − 1) in-plane
    free DOFs of its elements (a 3-D line has more: then it truncates too)."""
    lines = {ln["name"]: ln for ln in record.cases()[case]["lines"]}
    for name, out in analyze_doc["lines"].items():
        kept = out["modes"].get("kept")
        n_el = sum(seg.get("elements", 0) for seg in lines[name]["segments"])
        if kept is not None and kept < 2 * (n_el - 1):
            return True
    return False


#: The iteration record itself: the coarse evaluations are now counted in it.
_ITERATION_RECORD = {"iterations", "relative_change", "history"}

#: Keys the documents gained after the pre-unification record (new indicators).
_ADDED_SINCE = {"second_order"}


#: Warnings the library gives since the pre-unification record (a phrase of each): the
#: trapezoid rule's error on a resonant peak (stochcable.dynamics.outputs.resolution),
#: the element rules' estimate above 1 % (stochcable.fidelity.mesh_check).
_WARNINGS_ADDED_SINCE = ("the trapezoid rule is off by", "error of the end-tension σ")


#: Citations in warning texts rewritten since the pre-unification record (issue 36: the
#: source named as its author and year, not as the project's seed number).
_CITATIONS_SINCE = (("seed 001 eq. 5.2.2", "Tuah 1982, eq. 5.2.2"),)


def _numbers_close(a: Any, b: Any, rtol: float, path: str) -> None:
    """Numbers within ``rtol`` of the largest magnitude of their array (or of
    themselves), the iteration record skipped, everything else equal."""
    if isinstance(a, dict) and isinstance(b, dict):
        assert set(a) - _ADDED_SINCE == set(b), f"{path}: keys differ: {sorted(set(a) ^ set(b))}"
        for k in b:
            if k not in _ITERATION_RECORD and k not in _CLOCK:
                _numbers_close(a[k], b[k], rtol, f"{path}.{k}")
    elif isinstance(a, list) and isinstance(b, list):
        assert len(a) == len(b), f"{path}: lengths {len(a)} != {len(b)}"
        flat = [x for x in b if isinstance(x, (int, float)) and not isinstance(x, bool)]
        scale = max((abs(x) for x in flat), default=0.0)
        for i, (x, y) in enumerate(zip(a, b)):
            if isinstance(y, (int, float)) and not isinstance(y, bool):
                assert abs(x - y) <= rtol * scale, f"{path}[{i}]: {x!r} != {y!r}"
            else:
                _numbers_close(x, y, rtol, f"{path}[{i}]")
    elif isinstance(b, (int, float)) and not isinstance(b, bool):
        assert abs(a - b) <= rtol * abs(b), f"{path}: {a!r} != {b!r} (rtol {rtol})"
    elif isinstance(b, str):
        for before, now in _CITATIONS_SINCE:
            b = b.replace(before, now)
        assert a == b, f"{path}: {a!r} != {b!r}"
    else:
        assert a == b, f"{path}: {a!r} != {b!r}"


@pytest.mark.parametrize(
    "case", sorted(p.name.removesuffix(".json.gz") for p in PRE_UNIFICATION.glob("*.json.gz"))
)
def test_single_lines_agree_with_the_pre_unification_record(case: str) -> None:
    """The re-recorded single-line documents: statics and modes unchanged (1e-10),
    the analysis within PRE_UNIFICATION_K × tolerance of the documents recorded by the
    single-line fixed point (its own coarse start, no defect correction); for lines
    with a touchdown, whose seabed model changed since, the statics only."""
    import gzip
    import json

    with gzip.open(PRE_UNIFICATION / f"{case}.json.gz", "rt") as f:
        old = _without_clock(json.load(f))
    new = _without_clock(record.load(case, record.LINEAR))  # (the linear model's)
    assert_close_documents(new["statics"], old["statics"])
    if any(ln.get("touchdown") is not None for ln in new["statics"]["statics"]["lines"].values()):
        # the linear model of a line with a touchdown changed after this record: the
        # touchdown element is split at the static touchdown (stochcable.line.seabed)
        # instead of springing the grounded nodes only; its statics did not change
        return
    assert_close_documents(new["modes"], old["modes"])
    if "fidelity" in new["analyze"]:
        # the fidelity plan changed after this record: the discretization's share of
        # the target is what the linear model's own error leaves of it
        # (stochcable.fidelity.model_error), so the settings, not the engine, differ
        return
    tol = max(ln["linearization"]["tolerance"] for ln in old["analyze"]["lines"].values())
    new["analyze"]["warnings"] = [
        w for w in new["analyze"]["warnings"] if not any(t in w for t in _WARNINGS_ADDED_SINCE)
    ]
    rtol = PRE_UNIFICATION_K * tol + DAMPING_COUPLING_SHIFT * _truncates(case, new["analyze"])
    _numbers_close(new["analyze"], old["analyze"], rtol, f"{case}.analyze")
