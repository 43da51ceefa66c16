"""Comparison of result documents computed in different threads or processes.

The same analysis run in the main thread and in a service worker thread can differ in
the last bits: the BLAS thread count (threadpoolctl cannot always limit OpenBLAS from a
worker thread) changes the summation order, a relative 1e-13 effect that the
linearization's fixed-point iteration carries through unchanged (it contracts).  Documents
are therefore compared with numbers to ``rtol`` (default 1e-10, far above that round-off
and far below any modelling change) and everything else exactly.  The linearization's
``relative_change`` and ``history`` are differences of nearly equal σ (|Δσ|/σ ~ 1e-5),
so their own round-off is ~1e-13/1e-5 relative: they are dimensionless and compared
to an absolute 1e-9 instead.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

_ABSOLUTE = {"relative_change": 1e-9, "history": 1e-9}


def assert_close_documents(
    a: Any, b: Any, rtol: float = 1e-10, path: str = "doc", atol: float = 0.0
) -> None:
    """Assert two JSON-like documents are equal, numbers within ``rtol`` (or ``atol``)."""
    if isinstance(a, bool) or isinstance(b, bool) or a is None or b is None:
        assert a == b, f"{path}: {a!r} != {b!r}"
    elif isinstance(a, (int, float)) and isinstance(b, (int, float)):
        assert math.isclose(a, b, rel_tol=rtol, abs_tol=atol), (
            f"{path}: {a!r} != {b!r} (rtol {rtol}, atol {atol})"
        )
    elif isinstance(a, Mapping) and isinstance(b, Mapping):
        assert set(a) == set(b), f"{path}: keys differ: {sorted(set(a) ^ set(b))}"
        for k in a:
            assert_close_documents(a[k], b[k], rtol, f"{path}.{k}", _ABSOLUTE.get(k, atol))
    elif (
        isinstance(a, Sequence)
        and not isinstance(a, str)
        and isinstance(b, Sequence)
        and not isinstance(b, str)
    ):
        assert len(a) == len(b), f"{path}: lengths {len(a)} != {len(b)}"
        for i, (x, y) in enumerate(zip(a, b)):
            assert_close_documents(x, y, rtol, f"{path}[{i}]", atol)
    else:
        assert a == b, f"{path}: {a!r} != {b!r}"
