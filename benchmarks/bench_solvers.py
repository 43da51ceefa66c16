"""Benchmark of the frequency-domain solvers (stochcable.dynamics.model.solvers).

A 40-element 3-D line (120 DOF: 40 free nodes x 3, end A pinned, end B on a stiff
spring), consistent mass plus normal added mass, a lumped linearized drag damping
(3x3 blocks, non-proportional), 200 frequencies.  Prints the median wall time of
each path and its error against the dense direct solve.

Run:  python benchmarks/bench_solvers.py [--repeat 7]
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time

import numpy as np

from stochcable.dynamics.model.modal_solvers import (
    foss_decomposition,
    foss_transfer,
    modal_basis,
    solve_modal,
)
from stochcable.dynamics.model.solvers import matrix_bandwidth, solve_direct


def line_model(
    n_el: int = 40,
    length: float = 850.0,
    ea: float = 1.2326e9,
    mass: float = 288.0,
    diameter: float = 0.216,
    tension: float = 1.5e6,
    rho: float = 1025.0,
    can: float = 1.0,
    b_drag: float = 400.0,
):
    """Straight inclined 3-D line: K, M, C (dense, banded pattern) with 3 n_el DOF."""
    l0 = length / n_el
    e = np.array([0.97, 0.0, 0.243])
    e /= np.linalg.norm(e)
    P = np.outer(e, e)
    N = np.eye(3) - P
    ke = (ea / l0) * P + (tension / l0) * N
    ma = can * rho * np.pi * diameter**2 / 4
    me = mass * np.eye(3) + ma * N
    n_nodes = n_el + 1
    ndof = 3 * n_nodes
    K = np.zeros((ndof, ndof))
    M = np.zeros((ndof, ndof))
    C = np.zeros((ndof, ndof))
    two = np.array([[1.0, -1.0], [-1.0, 1.0]])
    cons = l0 * np.array([[1 / 3, 1 / 6], [1 / 6, 1 / 3]])
    for i in range(n_el):
        sl = slice(3 * i, 3 * i + 6)
        K[sl, sl] += np.kron(two, ke)
        M[sl, sl] += np.kron(cons, me)
        C[sl, sl] += np.kron(np.diag([0.5, 0.5]) * l0, b_drag * N + 0.05 * b_drag * P)
    K[-3:, -3:] += 1e7 * np.eye(3)  # end B on a stiff spring (fairlead)
    free = slice(3, ndof)  # end A pinned
    return K[free, free], M[free, free], C[free, free]


def timed(fn, repeat: int) -> tuple[float, object]:
    times, out = [], None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times), out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=7)
    ap.add_argument("--n-omega", type=int, default=200)
    args = ap.parse_args(argv)
    K, M, C = line_model()
    n = K.shape[0]
    w = np.linspace(0.05, 2.0, args.n_omega)
    rng = np.random.default_rng(0)
    F = rng.standard_normal((w.size, n)) + 1j * rng.standard_normal((w.size, n))
    lo, up = matrix_bandwidth(K, M, C)
    print(
        f"model: {n} DOF, bandwidth (l, u) = ({lo}, {up}), {w.size} frequencies, "
        f"median of {args.repeat}"
    )
    t_ref, ref = timed(lambda: solve_direct(K, M, C, F, w, method="dense"), args.repeat)

    def err(u):
        return float(np.abs(u - ref).max() / np.abs(ref).max())

    rows = [("solve_direct dense (batched LAPACK)", t_ref, 0.0)]
    for method in ("banded", "auto"):
        t, u = timed(lambda m=method: solve_direct(K, M, C, F, w, method=m), args.repeat)
        rows.append((f"solve_direct {method}", t, err(u)))
    t_basis, basis = timed(lambda: modal_basis(K, M), args.repeat)
    rows.append(("modal_basis (all modes, eigh)", t_basis, float("nan")))
    wn, phi = basis
    for nm in (n, 40, 20, 10):
        for meth in ("foss", "modal_direct"):
            t, u = timed(
                lambda nm=nm, meth=meth: solve_modal(
                    K, M, C, F, w, n_modes=nm, method=meth, basis=(wn, phi)
                ),
                args.repeat,
            )
            rows.append((f"solve_modal {meth:12s} {nm:3d} modes (+static corr.)", t, err(u)))
    Mh, Ch, Kh = phi.T @ M @ phi, phi.T @ C @ phi, phi.T @ K @ phi
    t_dec, fm = timed(lambda: foss_decomposition(Mh, Ch, Kh), args.repeat)
    fh = F @ phi
    t_tr, _ = timed(lambda: foss_transfer(fm, fh, w), args.repeat)
    rows.append(("  foss_decomposition (all modes)", t_dec, float("nan")))
    rows.append(("  foss_transfer (all modes, 200 w)", t_tr, float("nan")))
    width = max(len(r[0]) for r in rows)
    for name, t, e in rows:
        etxt = "" if np.isnan(e) else f"   rel. error {e:.1e}"
        print(f"{name:{width}s}  {1e3 * t:9.2f} ms{etxt}")
    print(
        f"natural frequencies: {wn[0]:.3f} .. {wn[-1]:.1f} rad/s; "
        f"modes below 2.5 x 2 rad/s: {int(np.sum(wn <= 5.0))}"
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
