"""``stochcable simulate``: a random sea elevation record by DSA or NSA (Tuah 1982, §5.1)."""

from __future__ import annotations

import argparse

from stochcable import validation as v
from stochcable.cli._output import require_matplotlib, write_columns, write_json
from stochcable.cli._spectrum_args import add_spectrum_arguments, spectrum_from_args
from stochcable.errors import InputError
from stochcable.sea.realization import simulate_sea

# the default bound on duration/dt: the service's default STOCHCABLE_MAX_SAMPLES
MAX_SAMPLES = 2**22

UNITS = {
    "time": "s",
    "elevation": "m",
    "variance": "m^2",
    "m0": "m^2",
    "m0_grid": "m^2",
    "dt": "s",
    "duration": "s",
}


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add the ``simulate`` sub-command."""
    p = subparsers.add_parser(
        "simulate",
        help="simulate a random sea elevation record (DSA or NSA)",
        description="Simulate eta(t) on t = 0, dt, ..., duration - dt by the FFT with "
        "deterministic (dsa) or random (nsa) spectral amplitudes. "
        "duration/dt must be an even integer.",
    )
    add_spectrum_arguments(p)
    p.add_argument("--duration", type=float, default=256.0, help="record length [s] (default 256)")
    p.add_argument("--dt", type=float, default=0.25, help="time step [s] (default 0.25)")
    p.add_argument(
        "--max-samples",
        type=int,
        default=MAX_SAMPLES,
        help="refuse a record of more than this many samples duration/dt (default 2^22 = "
        "4194304, the service's STOCHCABLE_MAX_SAMPLES; 16 bytes of memory or more each)",
    )
    p.add_argument(
        "--method",
        choices=("dsa", "nsa"),
        default="dsa",
        help="spectral amplitudes: dsa (deterministic) or nsa (random)",
    )
    p.add_argument(
        "--seed",
        type=int,
        default=None,
        help="integer seed of the PCG64 generator (default: fresh entropy)",
    )
    p.add_argument("--format", choices=("json", "csv", "npy"), default="json", help="output format")
    p.add_argument("-o", "--output", help="output file (default stdout; required for npy)")
    p.add_argument("--plot", metavar="FILE.png", help="also plot eta(t) to this image")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Run ``stochcable simulate``."""
    choice = spectrum_from_args(args)
    duration = v.positive("--duration", args.duration, "s")
    dt = v.positive("--dt", args.dt, "s")
    if args.seed is not None and args.seed < 0:
        raise InputError("--seed", args.seed, "-", "must be >= 0")
    ratio = duration / dt
    if args.max_samples < 2:
        raise InputError("--max-samples", args.max_samples, "-", "must be >= 2")
    if not ratio <= args.max_samples:  # also an infinite ratio
        raise InputError(
            "--duration",
            duration,
            "s",
            f"--duration/--dt = {ratio:.6g} samples exceeds the limit of {args.max_samples} "
            "(--max-samples; default 2^22, the service's STOCHCABLE_MAX_SAMPLES): shorten "
            "--duration, raise --dt or raise --max-samples",
        )
    n_t = round(ratio)
    if abs(ratio - n_t) > 1e-9 * max(ratio, 1.0) or n_t < 2 or n_t % 2:
        raise InputError(
            "--duration",
            duration,
            "s",
            f"--duration/--dt = {ratio:.10g} must be an even integer >= 2",
        )
    if args.format == "npy" and args.output in (None, "-"):
        raise InputError("--output", args.output, "-", "is required with --format npy")
    real = simulate_sea(choice.density, duration, dt, method=args.method, rng=args.seed)
    if args.plot:
        plt = require_matplotlib()
        fig, ax = plt.subplots(figsize=(8, 3))
        ax.plot(real.time, real.elevation, lw=0.7)
        ax.set_xlabel("t [s]")
        ax.set_ylabel("eta [m]")
        ax.set_title(f"{choice.name}, {args.method.upper()}, seed {args.seed}")
        fig.tight_layout()
        fig.savefig(args.plot)
        plt.close(fig)
    if args.format == "json":
        s = choice.density(real.omega)
        m0_grid = float(s[1:-1].sum()) * real.d_omega  # Σ S(ω_m)Δω, m = 1 … N−1
        stats = {"variance": float(real.elevation.var()), "m0_grid": m0_grid, "m0": choice.m0}
        write_json(
            {
                "spectrum": choice.name,
                "parameters": choice.parameters,
                "method": real.method,
                "seed": real.seed,
                "dt": real.dt,
                "duration": real.duration,
                "time": real.time,
                "elevation": real.elevation,
                "stats": stats,
                "units": UNITS,
            },
            args.output,
        )
    else:
        write_columns({"time": real.time, "elevation": real.elevation}, args.format, args.output)
    return 0
