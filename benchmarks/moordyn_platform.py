"""A moored platform read from a MoorDyn file, driven by vessel RAOs: stochcable's
frequency domain against MoorDyn's time domain (docs/ACCURACY.md, "A moored platform
from a MoorDyn file").

The OC3-Hywind spar's three chains (tests/data/moordyn/oc3_hywind_v2.txt, the MoorDyn
repository's test model), a JONSWAP sea (Hs 6 m, Tp 11 s, heading 0) and a surge/heave
RAO of the vessel; MoorDyn runs the file stochcable writes, its fairleads moved by the
same RAOs on a periodic DSA realization of the sea (stochcable.reference.moordyn_vessel)
for several seeds; the table gives the fairlead tension σ of both and their ratio with
its Student-t 95 % interval over the seeds.

    python3 benchmarks/moordyn_platform.py [--seeds 3] [--period 300]
"""

from __future__ import annotations

import argparse
import time
import warnings

import numpy as np

import stochcable
from stochcable.io import read_moordyn
from stochcable.reference.moordyn_compare import student_interval
from stochcable.reference.moordyn_vessel import simulate_vessel_moordyn

SEA = {"spectrum": {"type": "jonswap", "hs": 6.0, "tp": 11.0}, "heading": 0.0}
RAO = {
    "omega": [0.0, 0.3, 0.6, 1.0, 1.5, 3.0],
    "surge": {"re": [1.0, 0.9, 0.5, 0.15, 0.03, 0.0], "im": [0.0] * 6},
    "heave": {"re": [1.0, 0.95, 0.6, 0.2, 0.05, 0.0], "im": [0.0] * 6},
}
BAND = (0.2, 2.0)


def platform_scene(path: str = "tests/data/moordyn/oc3_hywind_v2.txt") -> stochcable.Scene:
    """The MoorDyn file with the sea, the vessel RAO and a fine frequency grid."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        doc = read_moordyn(path).model_dump(mode="json", exclude_none=True)
    doc["sea"] = SEA
    doc["bodies"][0]["prescribed"] = RAO
    doc["analysis"]["omega"] = {"min": BAND[0], "max": BAND[1], "count": 400}
    return stochcable.load_scene(doc)


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--seeds", type=int, default=3)
    ap.add_argument("--period", type=float, default=300.0)
    args = ap.parse_args()
    sc = platform_scene()
    t0 = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        fd = stochcable.analyze(sc)
    t_fd = time.perf_counter() - t0
    runs = []
    t0 = time.perf_counter()
    for seed in range(args.seeds):
        runs.append(simulate_vessel_moordyn(sc, period=args.period, band=BAND, rng=seed))
    t_td = time.perf_counter() - t0
    names = runs[0].lines
    print(f"FD {t_fd:.1f} s; MoorDyn {args.seeds} × {2 * args.period:g} s simulated: {t_td:.0f} s")
    print("| line | FD mean [kN] | TD mean [kN] | FD σ [kN] | TD σ [kN] | TD/FD σ (95 %) |")
    print("| --- | --- | --- | --- | --- | --- |")
    for i, name in enumerate(names):
        fd_l = fd.lines[name].end_b
        std = np.array([r.std[i] for r in runs])
        mean = np.array([r.mean[i] for r in runs])
        m, h = student_interval(std / fd_l.std)
        print(
            f"| {name} | {fd_l.mean / 1e3:.1f} | {mean.mean() / 1e3:.1f} | "
            f"{fd_l.std / 1e3:.2f} | {std.mean() / 1e3:.2f} | {m:.3f} ± {h:.3f} |"
        )


if __name__ == "__main__":
    main()
