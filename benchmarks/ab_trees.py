"""A/B timing of two source trees of stochcable, alternating processes.

Runs the same public calls — ``stochcable.analyze`` on the reference chain
(stochcable/examples/chain_catenary.json without its time series) and on the three-leg
buoy of bench_bodies.py (Foss and direct) — in fresh interpreters that import
stochcable from tree A, then tree B, then A … (``PYTHONPATH`` set per process), so that
the host's slow drifts fall on both sides alike.  Each process warms up, then times
``--calls`` analyses and reports the median; the script prints per-round medians and,
per case, the median over rounds and the B/A ratio.  Where the tree has
``stochcable.runtime.configure`` it is applied first (the settings of the CLI and the
service; older trees applied them inside ``analyze``).

Run:  python benchmarks/ab_trees.py OLD_TREE NEW_TREE [--rounds 6] [--calls 15]
(e.g. ``git worktree add /tmp/old <commit>``; OLD_TREE=/tmp/old, NEW_TREE=.)
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
from pathlib import Path

_SNIPPET = r"""
import json, math, statistics, sys, time, warnings
warnings.simplefilter("ignore")
import stochcable
try:
    from stochcable import runtime
    runtime.configure()
except (ImportError, AttributeError):
    pass
from stochcable import analyze, load_scene
sys.path.insert(0, {bench!r})
from bench_bodies import scene_doc  # the tree's own copy (its imports match the tree)
from pathlib import Path
chain = json.loads(Path({example!r}).read_text())
chain["analysis"].pop("timeseries", None)
cases = {{"chain": chain, "bodies_foss": scene_doc("foss"), "bodies_direct": scene_doc("direct")}}
cases = {{k: v for k, v in cases.items() if k in {cases_wanted!r}}}
out = {{}}
for name, doc in cases.items():
    scene = load_scene(doc)
    for _ in range(2):
        analyze(scene)
    ts = []
    for _ in range({calls}):
        t0 = time.perf_counter(); analyze(scene); ts.append(time.perf_counter() - t0)
    out[name] = statistics.median(ts)
print(json.dumps(out))
"""


def _run(tree: Path, calls: int, bench: Path, example: Path, cases: list[str]) -> dict[str, float]:
    env = dict(os.environ, PYTHONPATH=str(tree))
    code = _SNIPPET.format(bench=str(bench), example=str(example), calls=calls, cases_wanted=cases)
    out = subprocess.run(
        [sys.executable, "-c", code],
        capture_output=True,
        text=True,
        env=env,
        cwd=str(tree),
        check=True,
    )
    return json.loads(out.stdout.strip().splitlines()[-1])


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("old", type=Path)
    ap.add_argument("new", type=Path)
    ap.add_argument("--rounds", type=int, default=6)
    ap.add_argument("--calls", type=int, default=15)
    ap.add_argument(
        "--cases",
        nargs="+",
        default=["chain", "bodies_foss", "bodies_direct"],
        help="cases to time (chain, bodies_foss, bodies_direct)",
    )
    args = ap.parse_args()
    here = Path(__file__).resolve().parent
    example = here.parent / "stochcable" / "examples" / "chain_catenary.json"
    res: dict[str, dict[str, list[float]]] = {"A": {}, "B": {}}
    for r in range(args.rounds):
        for side, tree in (("A", args.old), ("B", args.new)):
            got = _run(
                tree.resolve(), args.calls, tree.resolve() / "benchmarks", example, args.cases
            )
            for k, v in got.items():
                res[side].setdefault(k, []).append(v)
            print(
                f"round {r + 1} {side}: "
                + ", ".join(f"{k} {1e3 * v:.1f} ms" for k, v in got.items()),
                flush=True,
            )
    for k in res["A"]:
        a = statistics.median(res["A"][k])
        b = statistics.median(res["B"][k])
        a_min, b_min = min(res["A"][k]), min(res["B"][k])
        print(
            f"{k}: median of rounds A {1e3 * a:.1f} ms, B {1e3 * b:.1f} ms, B/A {b / a:.3f}; "
            f"fastest round A {1e3 * a_min:.1f} ms, B {1e3 * b_min:.1f} ms, "
            f"B/A {b_min / a_min:.3f}"
        )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
