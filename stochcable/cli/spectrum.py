"""``stochcable spectrum``: evaluate a wave spectrum on a frequency grid, with statistics."""

from __future__ import annotations

import argparse

import numpy as np

from stochcable import validation as v
from stochcable.cli._output import require_matplotlib, write_columns, write_json
from stochcable.cli._spectrum_args import add_spectrum_arguments, spectrum_from_args
from stochcable.sea.spectra import spectrum_statistics

UNITS = {
    "omega": "rad/s",
    "density": "m^2*s/rad",
    "m0": "m^2",
    "m1": "m^2*rad/s",
    "m2": "m^2*(rad/s)^2",
    "m3": "m^2*(rad/s)^3",
    "m4": "m^2*(rad/s)^4",
    "hs": "m",
    "tz": "s",
    "tm01": "s",
    "tp": "s",
    "bandwidth": "-",
}


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add the ``spectrum`` sub-command."""
    p = subparsers.add_parser(
        "spectrum",
        help="evaluate a wave spectrum S(omega) and its statistics",
        description="Evaluate a one-sided wave spectrum S(omega) [m^2 s/rad] on the grid "
        "omega_i = i*omega_max/count, i = 1..count (0 excluded), and its moments "
        "(trapezoid on that grid), Hs, Tz, Tm01, Tp and bandwidth.",
    )
    add_spectrum_arguments(p)
    p.add_argument(
        "--omega-max", type=float, default=3.0, help="largest grid frequency [rad/s] (default 3.0)"
    )
    p.add_argument(
        "--count", type=int, default=200, help="number of grid frequencies (default 200)"
    )
    p.add_argument("--format", choices=("json", "csv"), default="json", help="output format")
    p.add_argument("-o", "--output", help="output file (default stdout)")
    p.add_argument("--plot", metavar="FILE.png", help="also plot S(omega) to this image")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Run ``stochcable spectrum``."""
    choice = spectrum_from_args(args)
    omega_max = v.positive("--omega-max", args.omega_max, "rad/s")
    count = v.positive_int("--count", args.count, minimum=2)
    omega = omega_max / count * np.arange(1, count + 1)
    density = choice.density(omega)
    stats = spectrum_statistics(omega, density)
    if args.plot:
        plt = require_matplotlib()
        fig, ax = plt.subplots(figsize=(6, 4))
        ax.plot(omega, density)
        ax.set_xlabel("omega [rad/s]")
        ax.set_ylabel("S [m^2 s/rad]")
        ax.set_title(f"{choice.name}: Hs = {stats.hs:.3g} m, Tp = {stats.tp:.3g} s")
        fig.tight_layout()
        fig.savefig(args.plot)
        plt.close(fig)
    if args.format == "csv":
        write_columns({"omega": omega, "density": density}, "csv", args.output)
    else:
        write_json(
            {
                "spectrum": choice.name,
                "parameters": choice.parameters,
                "omega": omega,
                "density": density,
                "stats": stats.as_dict(),
                "units": UNITS,
            },
            args.output,
        )
    return 0
