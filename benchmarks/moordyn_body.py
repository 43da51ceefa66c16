"""A free buoy on three chain legs in 3-D: stochcable's frequency domain (default:
with the drag and geometric residuals; linear: without) against MoorDyn's time domain
(docs/accuracy/bodies.md, "MoorDyn: a free buoy on three legs in 3-D").

The mooring of benchmarks/bench_bodies.py made MoorDyn-representable
(:func:`stochcable.reference.moordyn_body.three_leg_buoy_scene`: a submerged buoy,
constant buoyancy, translational added mass, per-direction drag carried in MoorDyn by
three drag rods; no radiation damping, no hydrostatic matrix); MoorDyn runs the same DSA
sea components as the frequency domain (externally set linear kinematics at the
static positions, :func:`stochcable.reference.moordyn_body.simulate_body_moordyn`)
for several seeds; the table gives the σ of the fairlead and anchor tensions of the
three legs and of the buoy's surge, heave and pitch, MoorDyn's with its Student-t
95 % interval over the seeds.

    OPENBLAS_NUM_THREADS=1 nice -n 19 python3 benchmarks/moordyn_body.py \
        [--seeds 16] [--period 900] [--hs 3] [--elements 20] [--bands]

``--bands``: the variance of the tensions per frequency band, the frequency domain's
(the density with the residuals, ``end_tension_density``; the linear one) against
MoorDyn's periodograms (mean over the seeds, the 95 % half-width): where the residual's
variance goes (docs/accuracy/bodies.md, "Where the downwave fairlead's excess is").

CPU: ≈ 38 s per seed at T = 900 s, 25 s at T = 600 s (dtM 2.5 ms, 20 elements per leg)
plus ≈ 6 s for the statics, the two frequency-domain analyses and a calm run (the
table of docs/accuracy/bodies.md: 607 s of MoorDyn for 16 × 900 s, on the shared 2-core
machine at load ≈ 3).
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


def fd_sigmas(doc: dict, residuals: bool, period: float = 900.0) -> dict[str, float]:
    """Frequency-domain σ of the table's records (with or without the residuals); the
    linear one also as "<record> dsa": its transfer function on MoorDyn's DSA grid
    (Δω = 2π/period), σ² = Σ |H(ω_j)|² S(ω_j) Δω, what any one seed's linear record has
    over the measured period (the amplitudes are fixed, only the phases random)."""
    d = {**doc, "analysis": {**doc["analysis"]}}
    d["analysis"]["linearization"] = {"drag_residual": residuals, "geometric_residual": residuals}
    sc = stochcable.load_scene(d)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        r = stochcable.analyze(sc)
    out = {f"{n}.end_b": r.lines[n].end_b.std for n in LEGS}
    out |= {f"{n}.end_a": r.lines[n].end_a.std for n in LEGS}
    out |= {f"{n}.last element": r.lines[n].tension_std[-1] for n in LEGS}
    m = r.bodies["buoy"].motion_std
    out |= {"surge": m[0], "heave": m[2], "pitch": m[4]}
    if not residuals:
        dw = 2.0 * np.pi / period
        w = dw * np.arange(np.ceil(0.1 / dw), np.floor(2.0 / dw) + 1)
        s = sc.sea.spectrum.spectral_density(w, sc.environment.g) * dw
        body = r.bodies["buoy"]
        h = {f"{n}.{e}": (r.lines[n].omega, r.lines[n].end_tension_transfer[e][0])
             for n in LEGS for e in ("end_b", "end_a")}  # fmt: skip
        for n in LEGS:
            h[f"{n}.last element"] = (r.lines[n].omega, r.lines[n].tension_transfer[0, -1])
        h |= {k: (body.omega, body.motion_transfer[0, j])
              for k, j in (("surge", 0), ("heave", 2), ("pitch", 4))}  # fmt: skip
        for k, (wf, hf) in h.items():
            out[k + " dsa"] = float(np.sqrt(np.sum(np.interp(w, wf, np.abs(hf) ** 2) * s)))
    return out


def td_sigmas(rec) -> dict[str, float]:  # noqa: ANN001
    """MoorDyn σ of the same records over the measured period."""
    out = {f"{n}.end_b": rec.fairlead[:, i].std() for i, n in enumerate(rec.lines)}
    out |= {f"{n}.end_a": rec.anchor[:, i].std() for i, n in enumerate(rec.lines)}
    out |= {f"{n}.last element": rec.fairlead_segment[:, i].std() for i, n in enumerate(rec.lines)}
    return out | {k: rec.motion[:, j].std() for k, j in (("surge", 0), ("heave", 2), ("pitch", 4))}


BANDS = (0.0, 0.3, 0.6, 1.0, 1.5, 1.9, 2.0, 2.1, 2.2, 2.3, 2.5, 3.0, 20.0)


def band_table(doc: dict, runs: list) -> None:  # noqa: ANN001
    """Print the tensions' variance per band of :data:`BANDS` [rad/s]: the frequency
    domain's default (its density with the residuals) and linear, MoorDyn's mean
    periodogram over ``runs`` with its Student-t 95 % half-width. [kN²]"""
    res = {}
    for residuals in (True, False):
        d = {**doc, "analysis": {**doc["analysis"]}}
        d["analysis"]["linearization"] = {
            "drag_residual": residuals,
            "geometric_residual": residuals,
        }
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            res[residuals] = stochcable.analyze(stochcable.load_scene(d))
    edges = np.asarray(BANDS)
    for i, n in enumerate(LEGS[:2]):
        for end, field in (("end_b", "fairlead"), ("end_a", "anchor")):
            fd = []
            for residuals in (True, False):
                w, s = res[residuals].lines[n].end_tension_density(end)
                area = np.concatenate([[0.0], np.cumsum(0.5 * (s[1:] + s[:-1]) * np.diff(w))])
                fd.append(np.diff(np.interp(edges, w, area)))  # (the trapezoid's, cut at edges)
            td = []
            for r in runs:
                x = getattr(r, field)[:, i]
                x = x - x.mean()
                wf = 2.0 * np.pi * np.fft.rfftfreq(x.size, r.t[1] - r.t[0])
                p = 2.0 * np.abs(np.fft.rfft(x)) ** 2 / x.size**2
                td.append([p[(wf >= a) & (wf < b)].sum() for a, b in zip(edges[:-1], edges[1:])])
            td = np.asarray(td)
            print(f"{n}.{end} [kN²]: band [rad/s] | FD default | FD linear | MoorDyn (95 %)")
            for k, (a, b) in enumerate(zip(edges[:-1], edges[1:])):
                m, h = student_interval(td[:, k])
                print(
                    f"  [{a:g}, {b:g}) | {1e-6 * fd[0][k]:.4g} | {1e-6 * fd[1][k]:.4g} | "
                    f"{1e-6 * m:.4g} ± {1e-6 * h:.2g}"
                )


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--seeds", type=int, default=16)
    ap.add_argument("--period", type=float, default=900.0)
    ap.add_argument("--hs", type=float, default=3.0)
    ap.add_argument("--elements", type=int, default=20, help="elements (segments) per leg")
    ap.add_argument("--bands", action="store_true", help="the tensions' variance per band")
    args = ap.parse_args()
    doc = three_leg_buoy_scene(hs=args.hs, elements=args.elements)
    t0 = time.process_time()
    st = solve_statics(stochcable.load_scene(doc))
    fd_d, fd_l = fd_sigmas(doc, True), fd_sigmas(doc, False, args.period)
    t_fd = time.process_time() - t0
    runs = []
    t0 = time.process_time()
    for seed in range(args.seeds):
        runs.append(simulate_body_moordyn(doc, period=args.period, rng=seed))
    t_td = time.process_time() - t0
    # MoorDyn's statics: the means of a calm run (its initial-condition solve stops at
    # TmaxIC with the buoy 0.05 m off, ringing in heave without a sea)
    calm = {k: v for k, v in doc.items() if k != "sea"}
    r0 = simulate_body_moordyn(calm, period=60.0, rng=0)
    pos = st.bodies["buoy"].position
    n, z = LEGS[1], r0.static_pose[2] + r0.motion[:, 2].mean()
    print(
        f"statics: buoy z FD {pos[2]:.4f} m, MoorDyn {z:.4f} m; "
        f"{n} fairlead FD {st.lines[n].node_tension[-1] / 1e3:.3f} kN MoorDyn "
        f"{r0.fairlead[:, 1].mean() / 1e3:.3f} kN, anchor FD "
        f"{st.lines[n].node_tension[0] / 1e3:.3f} kN MoorDyn {r0.anchor[:, 1].mean() / 1e3:.3f} kN"
    )
    print(
        f"CPU: FD (statics + default + linear) {t_fd:.0f} s; MoorDyn {args.seeds} × "
        f"{2 * args.period:g} s simulated {t_td:.0f} s"
    )
    print("| record | FD linear | FD default | MoorDyn (95 %) | linear/MD − 1 | default/MD − 1 |")
    print("|---|---|---|---|---|---|")
    tds = [td_sigmas(r) for r in runs]
    grid = max(abs(fd_l[k + " dsa"] / fd_l[k] - 1.0) for k in fd_d)
    print(f"linear σ on the DSA grid against the FD's: within {100 * grid:.2f} %")
    for k in fd_d:
        m, h = student_interval(np.array([t[k] for t in tds]))
        unit, s = ("kN", 1e-3) if "." in k else (("mrad", 1e3) if k == "pitch" else ("m", 1.0))
        print(
            f"| {k} [{unit}] | {s * fd_l[k]:.4g} | {s * fd_d[k]:.4g} | {s * m:.4g} ± {s * h:.2g} "
            f"| {100 * (fd_l[k] / m - 1):+.1f} % | {100 * (fd_d[k] / m - 1):+.1f} % "
            f"(± {100 * h / m:.1f} %) |"
        )
    if args.bands:
        band_table(doc, runs)


if __name__ == "__main__":
    main()
