"""Shared output helpers for CLI sub-commands: JSON, CSV, NPY and NetCDF writers, the
result summary a person reads (rich), the choice of output format, plot import."""

from __future__ import annotations

import io
import json
import sys
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

from stochcable.errors import InputError
from stochcable.scene.residual_kinds import RESIDUAL_KINDS

__all__ = [
    "to_jsonable",
    "write_json",
    "write_columns",
    "require_matplotlib",
    "read_json_file",
    "output_format",
    "write_summary",
    "residuals_included",
    "write_netcdf_document",
]


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


def output_format(fmt: str | None, output: str | None) -> str:
    """The output format of ``analyze``: the one asked for, else ``netcdf`` for an
    ``-o`` file ending in ``.nc``, ``json`` for another ``-o`` file or when stdout is
    not a terminal (piped), else ``summary``."""
    if fmt is not None:
        if fmt == "netcdf" and output in (None, "-"):
            raise InputError("--output", output, "-", "is required with --format netcdf")
        return fmt
    if output not in (None, "-"):
        return "netcdf" if str(output).lower().endswith(".nc") else "json"
    return "summary" if sys.stdout.isatty() else "json"


def write_netcdf_document(result: Any, output: str) -> None:
    """Write a result as NetCDF (:meth:`Result.to_netcdf`)."""
    try:
        result.to_netcdf(Path(output))
    except ImportError as exc:
        raise InputError(
            "--output",
            output,
            "-",
            f"NetCDF needs xarray and netCDF4 ({exc}): pip install 'stochcable[bodies]'",
        ) from None


def _g(x: Any) -> str:
    return "-" if x is None else f"{float(x):.4g}"


def residuals_included(doc: Mapping[str, Any]) -> tuple[str, ...]:
    """The residual kinds a result document's end statistics carry (computed on some
    line), in registry order."""
    lines = doc["lines"].values()
    return tuple(
        k for k in RESIDUAL_KINDS if any((ln.get(k) or {}).get("computed") for ln in lines)
    )


def write_summary(
    doc: Mapping[str, Any], output: str | None, title: str = "", plots: Any = ()
) -> None:
    """Print the summary of a result document a person reads (rich tables).

    Per line and end the tension statistics (mean, σ, Tz, 3-hour most probable
    maximum; with the residuals of the linear model, a line saying so and the linear
    σ beside), the largest motion σ along each line, the bodies' motion, the drag
    linearization, the warnings (each once) and the figures written.
    """
    from rich.console import Console
    from rich.markup import escape
    from rich.table import Table

    fh = _open_out(output)
    console = Console(file=fh, highlight=False, force_terminal=None if fh is sys.stdout else False)
    u = doc.get("units") or {"system": "SI", "length": "m", "force": "N"}
    f, ln = u["force"], u["length"]
    try:
        console.print(f"[bold]stochcable analyze[/bold] {escape(title)}  (units: {u['system']})")
        lin = doc["linearization"]
        state = "[green]converged[/green]" if lin["converged"] else "[red]NOT converged[/red]"
        console.print(
            f"drag linearization: {state} in {lin['iterations']} iterations "
            f"(last relative change {lin['relative_change']:.2e})"
        )
        kinds = residuals_included(doc)
        table = Table(title=escape(f"end tension [{f}]; Tz [s]"))
        for col in ("line", "end", "mean", "σ", "Tz", "MPM 3 h") + (("linear σ",) if kinds else ()):
            table.add_column(col, justify="left" if col in ("line", "end") else "right")
        for name, line in doc["lines"].items():
            for end in ("end_a", "end_b"):
                t, lin = line[end]["tension"], (line.get("linear") or {}).get(end)
                row = [_g(t["mean"]), _g(t["std"]), _g(t["tz"]), _g(t["mpm_3h"])]
                row += [_g(lin and lin["tension"]["std"])] if kinds else []
                table.add_row(name, end, *row)
        console.print(table)
        if kinds:
            console.print(
                f"the end tensions include the residuals of the linear model "
                f"({', '.join(kinds)}); linear σ: the linear model alone"
            )
        table = Table(title=escape(f"largest motion σ along each line [{ln}]"))
        for col in ("line", "σx", "σy", "σz", "iterations", "converged"):
            table.add_column(col, justify="left" if col == "line" else "right")
        for name, line in doc["lines"].items():
            std = np.asarray(line["motion"]["std"], dtype=float).reshape(-1, 3)
            rec = line["linearization"]
            table.add_row(
                escape(name),
                *(_g(v) for v in std.max(axis=0)),
                str(rec["iterations"]),
                "yes" if rec["converged"] else "[red]no[/red]",
            )
        console.print(table)
        bodies = doc.get("bodies") or {}
        if bodies:
            table = Table(title=escape(f"body motion (translations [{ln}], rotations [deg])"))
            for col in ("body", "dof", "mean", "σ", "Tz [s]"):
                table.add_column(col, justify="left" if col in ("body", "dof") else "right")
            for name, body in bodies.items():
                for dof, m in body["motion"].items():
                    rot = dof in ("roll", "pitch", "yaw")
                    k = 57.29577951308232 if rot else 1.0  # rad -> deg for rotations
                    table.add_row(
                        escape(name), dof, _g(m["mean"] * k), _g(m["std"] * k), _g(m["tz"])
                    )
            console.print(table)
        messages = list(dict.fromkeys(doc.get("warnings") or []))
        if messages:
            console.print(f"[bold yellow]{len(messages)} warning(s):[/bold yellow]")
            for k, msg in enumerate(messages, start=1):
                console.print(f"  {k}. {escape(msg)}")
        else:
            console.print("no warnings")
        for p in plots:
            console.print(f"figure: {escape(str(p))}")
        total = (doc.get("timing") or {}).get("total_s")
        if total is not None:
            console.print(f"analysed in {total:.2f} s")
    finally:
        if fh is not sys.stdout:
            fh.close()
