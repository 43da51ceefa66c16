"""``stochcable statics SCENE.json``: static equilibrium of every line of a scene."""

from __future__ import annotations

import argparse

from stochcable.cli._output import require_matplotlib, write_json
from stochcable.io import load_scene
from stochcable.statics import StaticsResult, solve_statics

__all__ = ["register", "run"]


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add the ``statics`` sub-command."""
    p = subparsers.add_parser(
        "statics",
        help="static equilibrium of the scene's lines (catenary or finite elements)",
        description="Solve the static equilibrium of every line of a scene and print "
        "the 'statics' part of the result document (effective tensions, node positions, "
        "touchdown).",
    )
    p.add_argument("scene", help="scene document (JSON file) or MoorDyn input file")
    p.add_argument("--format", choices=["json"], default="json", help="output format")
    p.add_argument("-o", "--output", default=None, help="output file (default stdout)")
    p.add_argument(
        "--method",
        choices=["auto", "fe", "catenary"],
        default="auto",
        help="auto: closed-form catenary where it applies, FE otherwise",
    )
    p.add_argument(
        "--plot",
        default=None,
        metavar="FILE.png",
        help="draw each line's static shape (x-z, and plan view if 3-D)",
    )
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Run the sub-command; returns the exit code."""
    scene = load_scene(args.scene)
    plt = require_matplotlib() if args.plot else None
    result = solve_statics(scene, method=args.method)
    write_json({"statics": result.to_document()}, args.output)
    if plt is not None:
        _plot(plt, scene, result, args.plot)
    return 0


def _plot(plt, scene, result: StaticsResult, path: str) -> None:  # noqa: ANN001
    import numpy as np

    three_d = not scene.is_planar
    ncols = 2 if three_d else 1
    fig, axes = plt.subplots(1, ncols, figsize=(7 * ncols, 4.5), squeeze=False)
    ax = axes[0, 0]
    depth = scene.environment.depth
    xs = np.concatenate([ls.positions[:, 0] for ls in result.lines.values()])
    lo, hi = float(xs.min()), float(xs.max())
    pad = 0.05 * max(hi - lo, 1.0)
    ax.axhline(0.0, color="tab:blue", lw=0.8, label="surface")
    ax.fill_between(
        [lo - pad, hi + pad], -depth, -depth - 0.03 * depth, color="tan", label="seabed"
    )
    for name, ls in result.lines.items():
        ax.plot(ls.positions[:, 0], ls.positions[:, 2], ".-", ms=2, label=name)
        if three_d:
            axes[0, 1].plot(ls.positions[:, 0], ls.positions[:, 1], ".-", ms=2, label=name)
    ax.set_xlabel("x [m]")
    ax.set_ylabel("z [m]")
    ax.set_title("static shape, x-z")
    ax.legend(fontsize=8)
    if three_d:
        axes[0, 1].set_xlabel("x [m]")
        axes[0, 1].set_ylabel("y [m]")
        axes[0, 1].set_title("plan view")
        axes[0, 1].set_aspect("equal", adjustable="datalim")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
