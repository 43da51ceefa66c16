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
