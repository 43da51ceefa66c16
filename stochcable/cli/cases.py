"""``stochcable cases``: a scene over a wave scatter diagram — end tension statistics per
sea state, spectral fatigue damage and life, long-term extremes.

    stochcable cases SCENE.json --scatter FILE.csv|json [--headings 0,45,...]
                     [--spectrum jonswap|pierson_moskowitz] [--curve dnv-studless]
                     [--nominal-diameter D | --nominal-area A | --mbs F]
                     [--method dirlik] [--dff 3] [--years 100] [-o out.nc|csv|json]
                     [--workers N | --scheduler tcp://HOST:PORT] [--plot DIR]

With ``--headings`` every row of the diagram is repeated for each heading with equal
probability (the headings of the file are then ignored).  A progress bar is shown on a
terminal (stderr), not when output is piped.  Without ``-o`` the JSON document goes to
stdout.  ``--workers N`` runs the set on a local Dask cluster of N worker processes,
``--scheduler`` on an existing one (the results are the same, bit for bit).
"""

from __future__ import annotations

import argparse
import contextlib
import json
import sys
import warnings
from pathlib import Path

from stochcable.cases import LineFatigue, ScatterDiagram, read_scatter, run_cases
from stochcable.cases.chunk import prepare_worker
from stochcable.cases.results import case_dataset, case_document, case_summary_csv
from stochcable.cli._scene_args import add_scene_arguments, scene_from_args
from stochcable.design import curve_names
from stochcable.errors import InputError

__all__ = ["register", "run"]


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add the ``cases`` sub-command."""
    p = subparsers.add_parser(
        "cases",
        help="a scene over a wave scatter diagram: fatigue damage and long-term extremes",
        description="Solve the scene for every sea state of a scatter diagram (one engine "
        "built once), then the spectral fatigue damage of every line and the long-term "
        "most probable maximum tension.",
    )
    p.add_argument("scene", metavar="SCENE.json", help="scene template (or a MoorDyn file)")
    add_scene_arguments(p, sea=False)
    p.add_argument("--scatter", required=True, help="scatter diagram (CSV or JSON)")
    p.add_argument("--headings", default=None, help="comma-separated headings [deg]")
    p.add_argument(
        "--spectrum", choices=("jonswap", "pierson_moskowitz"), default=None,
        help="spectrum family (default: the file's, else jonswap)",
    )  # fmt: skip
    p.add_argument("--curve", default=None, help=f"fatigue curve: {', '.join(curve_names())}")
    p.add_argument("--nominal-diameter", type=float, default=None, help="chain bar d [m]")
    p.add_argument("--nominal-area", type=float, default=None, help="nominal area [m²]")
    p.add_argument("--mbs", type=float, default=None, help="minimum breaking strength [N]")
    p.add_argument("--mean-load-ratio", type=float, default=None, help="API rope Lm [-]")
    p.add_argument(
        "--method", default="dirlik",
        choices=("dirlik", "benasciutti_tovo", "wirsching_light", "narrow_band"),
        help="spectral fatigue method (default dirlik)",
    )  # fmt: skip
    p.add_argument("--dff", type=float, default=1.0, help="design fatigue factor (default 1)")
    p.add_argument("--years", type=float, default=100.0, help="return period [years]")
    p.add_argument("-o", "--output", default=None, help="out.nc, out.csv or out.json")
    p.add_argument(
        "--workers", type=int, default=None,
        help="run on a local Dask cluster of this many worker processes",
    )  # fmt: skip
    p.add_argument("--scheduler", default=None, help="an existing Dask scheduler (tcp://HOST:PORT)")
    p.add_argument("--plot", metavar="DIR", default=None, help="damage heat maps and lines (PNG)")
    p.set_defaults(func=run)


def _with_headings(scatter: ScatterDiagram, text: str) -> ScatterDiagram:
    try:
        heads = [float(h) for h in text.split(",") if h.strip()]
    except ValueError:
        raise InputError("--headings", text, "deg", "must be comma-separated numbers") from None
    return scatter.with_headings(heads, "--headings")


@contextlib.contextmanager
def _executor(args: argparse.Namespace):
    """None (this process), a LocalCluster's client (``--workers``) or a client of an
    existing scheduler (``--scheduler``)."""
    if args.workers is None and args.scheduler is None:
        yield None
        return
    if args.workers is not None and args.workers < 1:
        raise InputError("--workers", args.workers, "-", "must be >= 1")
    try:
        import distributed
    except ImportError:
        raise InputError(
            "--workers" if args.scheduler is None else "--scheduler",
            args.workers if args.scheduler is None else args.scheduler,
            "-",
            "needs Dask: pip install 'stochcable[dask]'",
        ) from None
    if args.scheduler is not None:
        with distributed.Client(args.scheduler, timeout=30) as client:
            client.run(prepare_worker)  # the CLI's process settings on every worker
            yield client
        return
    with (
        distributed.LocalCluster(n_workers=args.workers, threads_per_worker=1,
                                 dashboard_address=None) as cluster,
        distributed.Client(cluster) as client,
    ):  # fmt: skip
        client.run(prepare_worker)  # the CLI's process settings on every worker
        yield client


def run(args: argparse.Namespace) -> int:
    """Run the set and write its results."""
    scene = scene_from_args(args)
    scatter = read_scatter(args.scatter, family=args.spectrum)
    if args.headings is not None:
        scatter = _with_headings(scatter, args.headings)
    fatigue = None
    if args.curve is not None:
        fatigue = LineFatigue(
            args.curve, args.nominal_diameter, args.nominal_area, args.mbs,
            args.mean_load_ratio, args.method, args.dff,
        )  # fmt: skip
    out = args.output
    suffix = Path(out).suffix.lower() if out else ".json"
    if suffix not in (".nc", ".csv", ".json"):
        raise InputError("--output", out, "-", "must end in .nc, .csv or .json")
    bar = None
    if sys.stderr.isatty():
        from tqdm import tqdm

        bar = tqdm(total=len(scatter.states), unit="case", file=sys.stderr)

    def progress(done: int, total: int) -> None:
        if bar is not None:
            if total != bar.total:  # (the adaptive anchors' later passes add cases)
                bar.total = total
                bar.refresh()
            bar.update(done - bar.n)

    try:
        # a case's warnings are in its row (and the output): summarized below, not
        # streamed once per case and message
        with _executor(args) as executor, warnings.catch_warnings():
            warnings.simplefilter("ignore")
            result = run_cases(
                scene, scatter, fatigue=fatigue, years=args.years, progress=progress,
                executor=executor,
            )  # fmt: skip
    finally:
        if bar is not None:
            bar.close()
    warned = [r for r in result.rows if r.warnings]
    if warned:
        first = warned[0]
        sys.stderr.write(
            f"stochcable cases: {len(warned)} of {len(result.rows)} cases have warnings "
            f"(listed per case in the output), e.g. case {first.index}: {first.warnings[0]}\n"
        )
    failed = [r for r in result.rows if r.status != "ok"]
    if failed:
        sys.stderr.write(
            f"stochcable cases: {len(failed)} of {len(result.rows)} cases not ok "
            f"(probability covered by ok cases: {result.coverage['ok']:.4g})\n"
        )
    if args.plot is not None:
        from stochcable.plots import plot_cases

        for path in plot_cases(result, args.plot):
            sys.stderr.write(f"stochcable cases: wrote {path}\n")
    if suffix == ".nc":
        case_dataset(result).to_netcdf(out)
    elif suffix == ".csv":
        Path(out).write_text(case_summary_csv(result), encoding="utf-8")
    else:
        text = json.dumps(case_document(result), indent=1)
        if out:
            Path(out).write_text(text, encoding="utf-8")
        else:
            sys.stdout.write(text + "\n")
    return 0
