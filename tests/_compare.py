"""Comparison of result documents computed in different threads or processes.

The same analysis run in the main thread and in a service worker thread can differ in
the last bits: the BLAS thread count (threadpoolctl cannot always limit OpenBLAS from a
worker thread) changes the summation order, a relative 1e-13 effect that the
linearization's fixed-point iteration carries through unchanged (it contracts).  Documents
are therefore compared with numbers to ``rtol`` (default 1e-10, far above that round-off
and far below any modelling change) and everything else exactly.  The linearization's
``relative_change`` and ``history`` are differences of nearly equal σ (|Δσ|/σ ~ 1e-5),
so their own round-off is ~1e-13/1e-5 relative: they are dimensionless and compared
to an absolute 1e-9 instead; so is the statics' relative ``residual`` force at
convergence (~1e-12: round-off itself, its digits differ between BLAS paths — an
AMD EPYC without AVX-512 reads 1.87e-12 where the recording machine read 2.07e-12).
A strumming mode's ``tension_range`` per element is the axial stretch t·Δφ of a
mostly transverse mode shape φ (a cancellation) of a mode whose eigenvector carries
round-off over its neighbour's frequency gap: it is compared to 1e-8 relative (measured
6.6e-10 between the two machines above on the chain in current).  Its
``amplitude_over_d`` is the root of the lock-in balance found by least squares, whose
conditioning amplifies round-off: 1.5e-10 relative between AMD EPYCs with and without
AVX-512 on the chain in current; compared to 1e-8 relative, or 1e-12 absolute (a
trillionth of a diameter: nothing).
The numbers of a list (a vector, a spectrum) are compared
to ``rtol`` times the largest of them: a component that is zero by symmetry carries
only round-off.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

_ABSOLUTE = {
    "relative_change": 1e-9,
    "history": 1e-9,
    "residual": 1e-9,
    "amplitude_over_d": 1e-12,
}
#: Keys compared to a larger relative tolerance (module docstring).
_RELATIVE = {"tension_range": 1e-8, "amplitude_over_d": 1e-8}


def _numbers(v: Any) -> bool:
    """A non-empty list of numbers."""
    return (
        isinstance(v, list)
        and bool(v)
        and all(isinstance(x, (int, float)) and not isinstance(x, bool) for x in v)
    )


def _sibling_scale(doc: Mapping) -> dict[str, float]:
    """For a mapping of records with numeric fields (a body's surge, sway, ...): the
    largest magnitude of each numeric field over the records (empty otherwise)."""
    recs = list(doc.values())
    if len(recs) < 2 or not all(isinstance(r, Mapping) for r in recs):
        return {}
    out: dict[str, float] = {}
    for r in recs:
        for k, v in r.items():
            if isinstance(v, (int, float)) and not isinstance(v, bool):
                out[k] = max(out.get(k, 0.0), abs(v))
    return out


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
        scale = _sibling_scale(b)
        lists = [v for v in b.values() if _numbers(v)]
        if len(lists) > 1 and len(lists) == len(b):
            # spectra per DOF: relative to the largest of them (a DOF at rest by
            # symmetry has a spectrum of round-off)
            atol = max(atol, rtol * max(max(abs(x) for x in v) for v in lists))
        for k in a:
            floor = _ABSOLUTE.get(k, atol)
            if scale and isinstance(b[k], Mapping):
                assert set(a[k]) == set(b[k]), f"{path}.{k}: keys differ"
                top = scale.get("std", 0.0)
                if "std" in b[k] and abs(b[k]["std"]) <= rtol * top:
                    # a record at rest by symmetry (a body's sway in a head sea): its σ
                    # is round-off, its periods and shape factors ratios of round-off
                    assert abs(a[k]["std"]) <= 10.0 * rtol * top, f"{path}.{k}.std"
                    continue
                # the same statistic of sibling records relative to the largest of them
                for leaf, v in b[k].items():
                    fl = _ABSOLUTE.get(leaf, floor)
                    fl = max(fl, rtol * scale[leaf]) if leaf in scale else fl
                    assert_close_documents(a[k][leaf], v, rtol, f"{path}.{k}.{leaf}", fl)
                continue
            rk = max(rtol, _RELATIVE.get(k, 0.0))
            assert_close_documents(a[k], b[k], rk, f"{path}.{k}", floor)
    elif (
        isinstance(a, Sequence)
        and not isinstance(a, str)
        and isinstance(b, Sequence)
        and not isinstance(b, str)
    ):
        assert len(a) == len(b), f"{path}: lengths {len(a)} != {len(b)}"
        nums = [abs(x) for x in a if isinstance(x, (int, float)) and not isinstance(x, bool)]
        if nums and len(nums) == len(a):
            # a vector's components relative to its magnitude: the zero component of a
            # planar response (a sway force of 1e-15 N beside 1e5 N) is round-off
            atol = max(atol, rtol * max(nums))
        for i, (x, y) in enumerate(zip(a, b)):
            assert_close_documents(x, y, rtol, f"{path}[{i}]", atol)
    else:
        assert a == b, f"{path}: {a!r} != {b!r}"
