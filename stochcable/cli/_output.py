"""Shared output helpers for CLI sub-commands: JSON, CSV and NPY writers, plot import."""

from __future__ import annotations

import io
import json
import sys
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

from stochcable.errors import InputError

__all__ = ["to_jsonable", "write_json", "write_columns", "require_matplotlib", "read_json_file"]


def to_jsonable(obj: Any) -> Any:
    """Convert numpy arrays/scalars and complex numbers to plain JSON types."""
    if isinstance(obj, Mapping):
        return {str(k): to_jsonable(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [to_jsonable(v) for v in obj]
    if isinstance(obj, np.ndarray):
        if np.iscomplexobj(obj):
            return {"re": obj.real.tolist(), "im": obj.imag.tolist()}
        return obj.tolist()
    if isinstance(obj, (np.floating, np.integer, np.bool_)):
        return obj.item()
    if isinstance(obj, complex):
        return {"re": obj.real, "im": obj.imag}
    if hasattr(obj, "model_dump"):
        return to_jsonable(obj.model_dump(mode="json"))
    return obj


def _open_out(output: str | None, binary: bool = False):
    if output in (None, "-"):
        return sys.stdout.buffer if binary else sys.stdout
    return open(output, "wb" if binary else "w", encoding=None if binary else "utf-8")


def write_json(obj: Any, output: str | None) -> None:
    """Write ``obj`` as JSON to ``output`` (path) or stdout."""
    text = json.dumps(to_jsonable(obj), allow_nan=False)
    fh = _open_out(output)
    try:
        fh.write(text + "\n")
    finally:
        if fh is not sys.stdout:
            fh.close()


def write_columns(columns: Mapping[str, np.ndarray], fmt: str, output: str | None) -> None:
    """Write equal-length 1-D columns as CSV (header row) or NPY (structured array)."""
    names = list(columns)
    arrays = [np.asarray(columns[n], dtype=float) for n in names]
    if fmt == "csv":
        buf = io.StringIO()
        buf.write(",".join(names) + "\n")
        np.savetxt(buf, np.column_stack(arrays), delimiter=",", fmt="%.17g")
        fh = _open_out(output)
        try:
            fh.write(buf.getvalue())
        finally:
            if fh is not sys.stdout:
                fh.close()
    elif fmt == "npy":
        if output in (None, "-"):
            raise InputError("--output", output, "-", "is required with --format npy (binary)")
        rec = np.empty(arrays[0].shape[0], dtype=[(n, float) for n in names])
        for n, a in zip(names, arrays):
            rec[n] = a
        np.save(Path(output), rec)
    else:  # pragma: no cover - argparse restricts choices
        raise InputError("--format", fmt, "-", "must be json, csv or npy")


def require_matplotlib():
    """Import matplotlib with the Agg backend or raise a clear error naming the extra."""
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        raise InputError(
            "--plot",
            "requested",
            "-",
            "needs matplotlib: pip install 'stochcable[plot]'",
        ) from None
    return plt


def read_json_file(name: str, path: str) -> Any:
    """Read a JSON document, turning I/O and syntax errors into InputError."""
    try:
        text = Path(path).read_text(encoding="utf-8")
    except OSError as exc:
        raise InputError(name, path, "-", f"cannot be read ({exc.strerror})") from None
    try:
        return json.loads(text)
    except json.JSONDecodeError as exc:
        raise InputError(
            name, path, "-", f"is not valid JSON ({exc.msg} at line {exc.lineno})"
        ) from None
