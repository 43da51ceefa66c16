"""``stochcable modes``: natural frequencies of every line of a scene about its statics.

    stochcable modes SCENE.json [--count N] [--dim {2,3}] [--in-air]
                     [--format json] [-o FILE] [--plot FILE.png]

Output document (JSON)::

    {"modes": {"omega": [...],                     # the first line's, as in the
                                                   # result contract "modes": {"omega"}
               "lines": {name: {"omega": [rad/s], "period": [s],
                                "plane": ["in-plane" | "out-of-plane" | "mixed"]}}}}

A travelling line (``axial_speed`` ≠ 0) lists its complex modes (docs/travelling.md): its
entry adds ``growth`` (Re λ, [1/s]), ``axial_speed``, ``critical_speed`` (√(T/m) at the
lowest-tension point, [m/s]) and ``stability`` ("stable", "divergence", "flutter"); a
speed at or above the critical speed is refused, naming it.  ``--plot`` draws the lines
at rest only.

The top-level ``modes.omega`` repeats the first line's frequencies so that the document
satisfies DESIGN.md's result contract (``"modes": {"omega": [...]}``) for the common
one-line scene; ``modes.lines`` is complete.  Periods of zero-frequency modes are null.
The model is 3-D by default, so out-of-plane modes are listed even for a planar scene
(``--dim 2`` keeps the in-plane modes of x–z lines only).  ``--plot`` draws the first
four mode shapes of each line over its static shape (in-plane modes in the line's
vertical plane, out-of-plane modes as the displacement normal to it).
"""

from __future__ import annotations

import argparse

import numpy as np

from stochcable.cli._output import require_matplotlib, write_json

__all__ = ["register", "run"]

_PLOT_MODES = 4


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add the ``modes`` sub-command."""
    p = subparsers.add_parser(
        "modes",
        help="natural frequencies and mode shapes of the lines of a scene",
        description="Solve the statics of a scene, then the natural modes of each line "
        "(K φ = ω² (M + Ma) φ) about it.",
    )
    p.add_argument("scene", metavar="SCENE.json", help="scene document")
    p.add_argument("--count", type=int, default=10, help="modes per line (default 10)")
    p.add_argument(
        "--dim",
        type=int,
        choices=(2, 3),
        default=3,
        help="3: all modes, classified in-/out-of-plane (default); "
        "2: in-plane only (lines in the x–z plane)",
    )
    p.add_argument("--in-air", action="store_true", help="without added mass")
    p.add_argument("--format", choices=("json",), default="json", help="output format")
    p.add_argument("-o", "--output", default=None, help="output file (default stdout)")
    p.add_argument(
        "--plot",
        metavar="FILE.png",
        default=None,
        help="draw the first mode shapes over the static shape",
    )
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Run ``stochcable modes``; returns the exit code."""
    from stochcable.line.modes import natural_modes
    from stochcable.line.transport.matrices import check_line_speeds
    from stochcable.line.transport.modes import modes_document
    from stochcable.statics import scene_fe_models
    from stochcable.validation import positive_int

    count = positive_int("--count", args.count)
    plt = require_matplotlib() if args.plot else None
    from stochcable.errors import PhysicsWarning, warn
    from stochcable.scene.model import load_scene

    scene = load_scene(args.scene)
    if scene.bodies:
        warn(
            "the scene has bodies: these are the modes of each line with its ends held "
            "at their static positions; the coupled modes of lines and bodies are in "
            "the result of 'stochcable analyze' under bodies.<name>.modes",
            PhysicsWarning,
        )
    models = scene_fe_models(scene, dim=args.dim)
    speeds = check_line_speeds(scene.lines, models)
    lines, modes = {}, {}
    for name, model in models.items():  # travelling lines: complex modes (docs/travelling.md)
        if name in speeds:
            lines[name] = modes_document(model, speeds[name], count, added_mass=not args.in_air)
        else:
            modes[name] = natural_modes(model, count=count, added_mass=not args.in_air)
            lines[name] = modes[name].to_document()
    first = next(iter(lines.values()))
    write_json({"modes": {"omega": first["omega"], "lines": lines}}, args.output)
    if plt is not None and modes:  # the lines at rest (--plot draws no complex modes)
        _plot(plt, {name: models[name] for name in modes}, modes, args.plot)
    return 0


def _plot(plt, models, modes, path: str) -> None:
    n = len(models)
    fig, axes = plt.subplots(n, 2, figsize=(11, 3.6 * n), squeeze=False)
    for row, (name, model) in enumerate(models.items()):
        m = modes[name]
        pos = model.positions
        normal = m.normal
        h_dir = np.cross(normal, [0.0, 0.0, 1.0])
        xh = (pos - pos[0]) @ h_dir
        z = pos[:, 2]
        size = max(float(np.ptp(xh)), float(np.ptp(z)), 1e-9)
        ax_in, ax_out = axes[row]
        for ax in (ax_in, ax_out):
            ax.plot(xh, z, "k-", lw=2, label="static")
        for j in range(min(_PLOT_MODES, m.count)):
            u = np.zeros((model.n_nodes, 3))
            u[:, list(model.components)] = m.shapes[:, j].reshape(model.n_nodes, model.dim)
            scale = 0.08 * size / max(float(np.abs(u).max()), 1e-300)
            label = f"ω = {m.omega[j]:.4g} rad/s ({m.plane[j]})"
            if m.plane[j] == "out-of-plane":
                ax_out.plot(xh, z + scale * (u @ normal), "--", label=label)
            else:
                du = scale * u
                ax_in.plot(xh + du @ h_dir, z + du[:, 2], "--", label=label)
        ax_in.set_title(f"{name}: in-plane (and mixed) modes")
        ax_out.set_title(f"{name}: out-of-plane modes (normal displacement drawn up)")
        for ax in (ax_in, ax_out):
            ax.set_xlabel("horizontal distance in the line's plane [m]")
            ax.set_ylabel("z [m]")
            ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
