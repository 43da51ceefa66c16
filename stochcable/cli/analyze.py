"""``stochcable analyze SCENE.json``: run the analysis pipeline, print the result document.

Examples::

    stochcable analyze scene.json                       # result document on stdout
    stochcable analyze scene.json -o result.json --plot figs/
    stochcable analyze scene.json --timeseries full     # whole time series in the JSON

Progress (stage names and drag-linearization iterations) goes to stderr when stderr is
a terminal or with ``--progress``.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

import numpy as np

from stochcable.cli._output import require_matplotlib, write_json

__all__ = ["register", "run"]


def register(subparsers: Any) -> None:
    """Add the ``analyze`` sub-command."""
    p = subparsers.add_parser(
        "analyze",
        help="stochastic response of the lines of a scene (result document as JSON)",
        description="Run statics, drag linearization and the frequency-domain solve of "
        "a scene document and print the v1 result document.",
    )
    p.add_argument("scene", help="scene document (JSON file)")
    p.add_argument(
        "--format", choices=["json"], default="json", help="output format (default json)"
    )
    p.add_argument("-o", "--output", default=None, help="output file (default stdout)")
    p.add_argument(
        "--plot",
        metavar="DIR",
        default=None,
        help="write PNG figures (end-tension spectra, tension σ along the "
        "line, time-series window) into DIR",
    )
    p.add_argument(
        "--timeseries",
        choices=["window", "full", "none"],
        default="window",
        help="time series in the document: first 2048 samples (default), all, or none",
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
                f"  linearization '{line}': iteration {info['iteration']}, "
                f"change {info.get('change', float('nan')):.2e}"
            )
        elif stage == "done":
            msg = f"done in {info.get('total_s', 0.0):.2f} s"
        else:
            msg = stage + (f" '{line}'" if line else "")
        sys.stderr.write(f"stochcable analyze: {msg}\n")
        sys.stderr.flush()


def run(args: argparse.Namespace) -> int:
    """Run the analysis and write the result document (and figures)."""
    from stochcable.analysis import analyze
    from stochcable.cost import available_memory, check_memory, estimate_cost
    from stochcable.scene.model import load_scene

    scene = load_scene(Path(args.scene))
    # a scene too large for this machine: one sentence naming what to reduce, at once
    check_memory(estimate_cost(scene), available_memory(), "the memory available now")
    show = args.progress or (hasattr(sys.stderr, "isatty") and sys.stderr.isatty())
    result = analyze(scene, progress=_StderrProgress() if show else None)
    doc = result.to_document(timeseries=args.timeseries)
    if args.plot is not None:
        doc["plots"] = [str(p) for p in plot_result(result, Path(args.plot))]
    write_json(doc, args.output)
    return 0


def plot_result(result: Any, directory: Path) -> list[Path]:
    """Write the standard figures of a result as PNG files; returns their paths.

    - ``<line>_end_tension_spectra.png``: one-sided spectra of the end tensions;
    - ``<line>_tension_std.png``: σ of the dynamic effective tension along the line;
    - ``timeseries.png``: the first 600 s of η and of the end tensions.
    """
    plt = require_matplotlib()
    directory.mkdir(parents=True, exist_ok=True)
    paths: list[Path] = []
    for name, lr in result.lines.items():
        fig, ax = plt.subplots(figsize=(7, 4))
        for end in ("end_a", "end_b"):
            ax.plot(lr.omega, lr.end_tension_spectrum(end), label=end)
        ax.set_xlabel("ω [rad/s]")
        ax.set_ylabel("S_T(ω) [N²·s/rad]")
        ax.set_title(f"line {name}: end tension spectra")
        ax.legend()
        fig.tight_layout()
        p = directory / f"{name}_end_tension_spectra.png"
        fig.savefig(p, dpi=100)
        plt.close(fig)
        paths.append(p)

        fig, ax = plt.subplots(figsize=(7, 4))
        ax.plot(lr.s_elements, lr.tension_std)
        ax.set_xlabel("arc length from end_a s [m]")
        ax.set_ylabel("σ of dynamic tension [N]")
        ax.set_title(f"line {name}: dynamic tension σ")
        fig.tight_layout()
        p = directory / f"{name}_tension_std.png"
        fig.savefig(p, dpi=100)
        plt.close(fig)
        paths.append(p)
    ts = result.timeseries
    if ts is not None:
        n = int(np.searchsorted(ts.time, ts.time[0] + 600.0))
        n = max(n, 2)
        rows = 1 + len(ts.end_tension)
        fig, axes = plt.subplots(rows, 1, figsize=(8, 2.2 * rows), sharex=True, squeeze=False)
        ax0 = axes[0, 0]
        if ts.elevation is not None:
            ax0.plot(ts.time[:n], ts.elevation[:n], lw=0.8)
            ax0.set_ylabel("η [m]")
        for key, series in ts.end_motion.items():
            ax0.plot(ts.time[:n], series[:n], lw=0.8, label=key)
        if ts.end_motion:
            ax0.legend(fontsize=7)
        for k, (name, ends) in enumerate(ts.end_tension.items(), start=1):
            ax = axes[k, 0]
            for end, series in ends.items():
                ax.plot(ts.time[:n], series[:n], lw=0.8, label=end)
            ax.set_ylabel(f"{name} T [N]")
            ax.legend(fontsize=7)
        axes[-1, 0].set_xlabel("t [s]")
        fig.tight_layout()
        p = directory / "timeseries.png"
        fig.savefig(p, dpi=100)
        plt.close(fig)
        paths.append(p)
    return paths
