"""The first-order drag residual at a lightly drag-damped resonance that its own
higher harmonics excite: one oscillator m·x'' + k·x = c|u − x'|(u − x') in a narrow
Gaussian flow u (peak ω_p, its resonance ω_n ≈ 3ω_p), integrated in time (RK4), against
the frequency domain's answer: the linear response (b the statistical linearization's
fixed point, c·σ_v·√(8/π)) plus the first-order residual (the residual force
c|v|v − b·v of the *linear* relative velocity, sampled from the same phases, through
the same linear transfer).  The minimal form of the buoy's surge–pitch mode of
docs/accuracy/bodies.md ("Where the downwave fairlead's excess is"): the resonance's
variance, the two answers per seed (the same phases) and their ratio.

    OPENBLAS_NUM_THREADS=1 python3 benchmarks/drag_resonance_residual.py [--seeds 40]
"""

from __future__ import annotations

import argparse

import numpy as np

from stochcable.reference.moordyn_compare import student_interval


def run(seeds: int, period: float = 600.0, dt: float = 0.02) -> dict[str, np.ndarray]:
    """Per seed the displacement variance [m²] in the bands (< 1.5, 1.5–3, > 3 rad/s):
    ``"td"`` the time domain's (second period), ``"first"`` the first-order residual's,
    and the linear one ``"linear"`` (the same for every seed); ``"zeta"`` the
    linearization's damping ratio at ω_n."""
    m, c, wn, sig_u, wp = 3.0e4, 2050.0, 2.1, 0.3, 0.7  # [kg, N·s²/m², rad/s, m/s, rad/s]
    k = m * wn**2
    rng = np.random.default_rng(5)
    dw = 2.0 * np.pi / period
    w = dw * np.arange(1, int(1.4 / dw) + 1)
    w = w[w > 0.3]
    s = np.exp(-(((w - wp) / 0.12) ** 2))
    s *= sig_u**2 / np.sum(s * dw)
    a = np.sqrt(2.0 * s * dw)
    b = c * sig_u * np.sqrt(8.0 / np.pi)
    for _ in range(50):  # the fixed point on the relative velocity's σ
        vrel = 1.0 - 1j * w * b / (k - m * w**2 + 1j * w * b)
        b = c * np.sqrt(np.sum(np.abs(vrel) ** 2 * s * dw) * 8.0 / np.pi)
    nt = int(round(2.0 * period / dt))
    phases = rng.uniform(0.0, 2.0 * np.pi, (seeds, w.size))
    tt = np.arange(2 * nt + 1) * dt / 2.0
    u = np.stack([np.cos(np.outer(tt, w) + p) @ a for p in phases], axis=1)
    x, v = np.zeros(seeds), np.zeros(seeds)
    xs = np.empty((nt, seeds))

    def f(x: np.ndarray, v: np.ndarray, ui: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        r = ui - v
        return v, (c * np.abs(r) * r - k * x) / m

    for i in range(nt):
        k1 = f(x, v, u[2 * i])
        k2 = f(x + dt / 2 * k1[0], v + dt / 2 * k1[1], u[2 * i + 1])
        k3 = f(x + dt / 2 * k2[0], v + dt / 2 * k2[1], u[2 * i + 1])
        k4 = f(x + dt * k3[0], v + dt * k3[1], u[2 * i + 2])
        x = x + dt / 6 * (k1[0] + 2 * k2[0] + 2 * k3[0] + k4[0])
        v = v + dt / 6 * (k1[1] + 2 * k2[1] + 2 * k3[1] + k4[1])
        xs[i] = x
    xs = xs[nt // 2 :]
    tm = tt[::2][nt // 2 : nt]
    vl = np.stack([np.real(np.exp(1j * (np.outer(tm, w) + p)) @ (a * vrel)) for p in phases], 1)
    n = tm.size
    wf = 2.0 * np.pi * np.fft.rfftfreq(n, dt)
    xr = np.fft.rfft(c * np.abs(vl) * vl - b * vl, axis=0) / (k - m * wf**2 + 1j * wf * b)[:, None]
    xt = np.fft.rfft(xs - xs.mean(axis=0), axis=0)
    bands = ((0.0, 1.5), (1.5, 3.0), (3.0, 10.0))
    h_lin = b / (k - m * w**2 + 1j * w * b)
    out = {"td": [], "first": [], "linear": []}
    for lo, hi in bands:
        sel = (wf >= lo) & (wf < hi)
        out["td"].append((2.0 * np.abs(xt[sel]) ** 2 / n**2).sum(axis=0))
        out["first"].append((2.0 * np.abs(xr[sel]) ** 2 / n**2).sum(axis=0))
        out["linear"].append(np.sum((np.abs(h_lin) ** 2 * s * dw)[(w >= lo) & (w < hi)]))
    res = {key: np.asarray(val) for key, val in out.items()}
    res["zeta"] = np.asarray(b / (2.0 * m * wn))
    return res


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--seeds", type=int, default=40)
    args = ap.parse_args()
    r = run(args.seeds)
    print(f"linearization's damping ratio at the resonance: {float(r['zeta']):.4f}")
    print("band [rad/s] | linear [m²] | TD [m²] (95 %) | first-order residual | ratio (95 %)")
    for j, band in enumerate(("< 1.5", "1.5–3", "> 3")):
        td, fo = student_interval(r["td"][j]), student_interval(r["first"][j])
        q = student_interval(r["first"][j] / r["td"][j])
        print(
            f"{band} | {r['linear'][j]:.3e} | {td[0]:.3e} ± {td[1]:.1e} | "
            f"{fo[0]:.3e} ± {fo[1]:.1e} | {q[0]:.3f} ± {q[1]:.3f}"
        )


if __name__ == "__main__":
    main()
