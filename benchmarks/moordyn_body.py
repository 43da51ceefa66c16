"""A free buoy on three chain legs in 3-D: stochcable's frequency domain (default:
with the drag and geometric residuals; linear: without) against MoorDyn's time domain
(docs/accuracy/bodies.md, "MoorDyn: a free buoy on three legs in 3-D").

The mooring of benchmarks/bench_bodies.py made MoorDyn-representable
(:func:`stochcable.reference.moordyn_body.three_leg_buoy_scene`: a submerged buoy,
constant buoyancy, translational added mass, per-direction drag carried in MoorDyn by
a drag rod; no radiation damping, no hydrostatic matrix); MoorDyn runs the same DSA
sea components as the frequency domain (externally set linear kinematics at the
static positions, :func:`stochcable.reference.moordyn_body.simulate_body_moordyn`)
for several seeds; the table gives the σ of the fairlead and anchor tensions of the
three legs and of the buoy's surge, heave and pitch, MoorDyn's with its Student-t
95 % interval over the seeds.

    OPENBLAS_NUM_THREADS=1 nice -n 19 python3 benchmarks/moordyn_body.py \
        [--seeds 6] [--period 600] [--hs 3]

CPU: ≈ 75 s per seed at T = 600 s (a 1200 s record, dtM 2.5 ms, 20 elements per leg)
plus ≈ 20 s for the two frequency-domain analyses and the statics (measured on the
shared 2-core machine at load ≈ 4).
"""

from __future__ import annotations

import argparse
import time
import warnings

import numpy as np

import stochcable
from stochcable.reference.moordyn_body import simulate_body_moordyn, three_leg_buoy_scene
from stochcable.reference.moordyn_compare import student_interval
from stochcable.statics import solve_statics

LEGS = ("leg1", "leg2", "leg3")


def fd_sigmas(doc: dict, residuals: bool) -> dict[str, float]:
    """Frequency-domain σ of the table's records (with or without the residuals)."""
    d = {**doc, "analysis": {**doc["analysis"]}}
    d["analysis"]["linearization"] = {"drag_residual": residuals, "geometric_residual": residuals}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        r = stochcable.analyze(stochcable.load_scene(d))
    out = {f"{n}.end_b": r.lines[n].end_b.std for n in LEGS}
    out |= {f"{n}.end_a": r.lines[n].end_a.std for n in LEGS}
    m = r.bodies["buoy"].motion_std
    return out | {"surge": m[0], "heave": m[2], "pitch": m[4]}


def td_sigmas(rec) -> dict[str, float]:  # noqa: ANN001
    """MoorDyn σ of the same records over the measured period."""
    out = {f"{n}.end_b": rec.fairlead[:, i].std() for i, n in enumerate(rec.lines)}
    out |= {f"{n}.end_a": rec.anchor[:, i].std() for i, n in enumerate(rec.lines)}
    return out | {k: rec.motion[:, j].std() for k, j in (("surge", 0), ("heave", 2), ("pitch", 4))}


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--seeds", type=int, default=6)
    ap.add_argument("--period", type=float, default=600.0)
    ap.add_argument("--hs", type=float, default=3.0)
    args = ap.parse_args()
    doc = three_leg_buoy_scene(hs=args.hs)
    t0 = time.process_time()
    st = solve_statics(stochcable.load_scene(doc))
    fd_d, fd_l = fd_sigmas(doc, True), fd_sigmas(doc, False)
    t_fd = time.process_time() - t0
    runs = []
    t0 = time.process_time()
    for seed in range(args.seeds):
        runs.append(simulate_body_moordyn(doc, period=args.period, rng=seed))
    t_td = time.process_time() - t0
    r0 = runs[0]
    pos = st.bodies["buoy"].position
    print(
        f"statics: buoy z FD {pos[2]:.4f} m, MoorDyn {r0.static_pose[2]:.4f} m; "
        + "; ".join(
            f"{n} fairlead FD {st.lines[n].node_tension[-1] / 1e3:.2f} kN MoorDyn "
            f"{r0.static_fairlead[i] / 1e3:.2f} kN, anchor FD "
            f"{st.lines[n].node_tension[0] / 1e3:.2f} kN MoorDyn {r0.static_anchor[i] / 1e3:.2f} kN"
            for i, n in enumerate(r0.lines)
        )
    )
    print(
        f"CPU: FD (statics + default + linear) {t_fd:.0f} s; MoorDyn {args.seeds} × "
        f"{2 * args.period:g} s simulated {t_td:.0f} s"
    )
    print("| record | FD linear | FD default | MoorDyn (95 %) | linear/MD − 1 | default/MD − 1 |")
    print("|---|---|---|---|---|---|")
    tds = [td_sigmas(r) for r in runs]
    for k in fd_d:
        m, h = student_interval(np.array([t[k] for t in tds]))
        unit, s = ("kN", 1e-3) if "." in k else (("mrad", 1e3) if k == "pitch" else ("m", 1.0))
        print(
            f"| {k} [{unit}] | {s * fd_l[k]:.4g} | {s * fd_d[k]:.4g} | {s * m:.4g} ± {s * h:.2g} "
            f"| {100 * (fd_l[k] / m - 1):+.1f} % | {100 * (fd_d[k] / m - 1):+.1f} % "
            f"(± {100 * h / m:.1f} %) |"
        )


if __name__ == "__main__":
    main()
