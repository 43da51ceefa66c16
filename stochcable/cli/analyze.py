"""``stochcable analyze SCENE.json``: run the analysis pipeline, report the result.

On a terminal the command prints a summary (tensions, motions, linearization,
warnings); piped, or with ``--format json``, it writes the result document as JSON;
``-o result.nc`` writes the result as NetCDF (:mod:`stochcable.results.datasets`).

Examples::

    stochcable analyze scene.json                       # summary on a terminal
    stochcable analyze scene.json > result.json         # result document (piped)
    stochcable analyze scene.json -o result.json --plot figs/
    stochcable analyze scene.json -o result.nc          # NetCDF (xarray Dataset)
    stochcable analyze scene.json --timeseries full     # whole time series in the JSON

Progress (stage names and drag-linearization iterations) goes to stderr when stderr is
a terminal or with ``--progress``.
"""

from __future__ import annotations

import argparse
import sys
import warnings
from pathlib import Path
from typing import Any

from stochcable.cli._output import (
    output_format,
    require_matplotlib,
    write_json,
    write_netcdf_document,
    write_summary,
)
from stochcable.cli._scene_args import add_scene_arguments, scene_from_args

__all__ = ["register", "run"]


def register(subparsers: Any) -> None:
    """Add the ``analyze`` sub-command."""
    p = subparsers.add_parser(
        "analyze",
        help="stochastic response of the lines of a scene (summary, JSON or NetCDF)",
        description="Run statics, drag linearization and the frequency-domain solve of "
        "a scene document; print a summary on a terminal, else the v1 result document "
        "as JSON.",
    )
    p.add_argument("scene", help="scene document (JSON file) or MoorDyn input file")
    add_scene_arguments(p)
    p.add_argument(
        "--format",
        choices=["summary", "json", "netcdf"],
        default=None,
        help="output format (default: netcdf for an -o file ending in .nc, json for "
        "other -o files and when stdout is not a terminal, else summary)",
    )
    p.add_argument("-o", "--output", default=None, help="output file (default stdout)")
    p.add_argument(
        "--plot",
        metavar="DIR",
        default=None,
        help="write PNG figures (static shape, end-tension spectra, tension along the "
        "line with mean ± 3σ, mode shapes, time-series window) into DIR",
    )
    p.add_argument(
        "--timeseries",
        choices=["window", "full", "none"],
        default="window",
        help="time series in the document: first 2048 samples (default), all, or none",
    )
    p.add_argument(
        "--timeseries-linear",
        action="store_true",
        help="also put the linear model's end tensions (tension_linear) beside the "
        "time series that carry the residuals' component",
    )
    p.add_argument(
        "--progress",
        action="store_true",
        help="report stages on stderr even when it is not a terminal",
    )
    p.set_defaults(func=run)


class _StderrProgress:
    """Prints stage names and linearization iterations on stderr."""

    def __init__(self) -> None:
        self._last = None

    def __call__(self, stage: str, info: Any) -> None:
        line = info.get("line") if hasattr(info, "get") else None
        if stage == "linearization" and info.get("iteration"):
            msg = (
                f"  linearization{f' {line!r}' if line else ''}: iteration {info['iteration']}, "
                f"change {info.get('change', float('nan')):.2e}"
            )
        elif stage == "done":
            msg = f"done in {info.get('total_s', 0.0):.2f} s"
        else:
            msg = stage + (f" '{line}'" if line else "")
        sys.stderr.write(f"stochcable analyze: {msg}\n")
        sys.stderr.flush()


def run(args: argparse.Namespace) -> int:
    """Run the analysis and write the summary, the result document or NetCDF (and figures)."""
    from stochcable.analysis import analyze
    from stochcable.cost import available_memory, check_memory, estimate_cost

    fmt = output_format(args.format, args.output)
    scene = scene_from_args(args)
    # a scene too large for this machine: one sentence naming what to reduce, at once
    check_memory(estimate_cost(scene), available_memory(), "the memory available now")
    plt = require_matplotlib() if args.plot is not None else None
    show = args.progress or (hasattr(sys.stderr, "isatty") and sys.stderr.isatty())
    with warnings.catch_warnings():
        if fmt == "summary":
            # the summary lists the run's warnings once (result.warnings); they are
            # not echoed on stderr as well
            warnings.simplefilter("ignore")
        result = analyze(scene, progress=_StderrProgress() if show else None)
    doc = result.to_document(timeseries=args.timeseries, timeseries_linear=args.timeseries_linear)
    plots: list[str] = []
    if plt is not None:
        from stochcable.plots import plot_result

        plots = [str(p) for p in plot_result(result, Path(args.plot))]
        doc["plots"] = plots
    if fmt == "netcdf":
        write_netcdf_document(result, args.output, args.timeseries_linear)
    elif fmt == "summary":
        write_summary(doc, args.output, title=str(args.scene), plots=plots)
    else:
        write_json(doc, args.output)
    return 0
