"""The accuracy page (benchmarks/accuracy_lines.py, issue 31): its tables from a
synthetic cache whose answers are known, and its claim on one line — the default
analysis (the residual switches true) gives the chain's end-tension σ within the target
of the nonlinear time-domain reference, where the linear model does not."""

from __future__ import annotations

import math
import sys
import warnings

import numpy as np
import pytest
from _paths import ROOT

from stochcable import analyze

sys.path.insert(0, str(ROOT / "benchmarks"))
import accuracy_fatigue  # noqa: E402
import accuracy_lines  # noqa: E402
import moordyn_check  # noqa: E402

pytestmark = pytest.mark.xdist_group("test_accuracy_lines")

SEEDS = (1, 2, 3, 4)
N, DT = 4000, 0.05  # one 200 s period of the page's records
LINES_W = 2.0 * math.pi / (N * DT) * np.arange(20, 50)  # the records' lines [rad/s]


def _record(seed: int, scale: float) -> np.ndarray:
    """A periodic record with the same amplitudes for every seed (a DSA realization:
    its periodogram does not depend on the phases) [N]."""
    t = DT * np.arange(N)
    phases = np.random.default_rng(seed).uniform(0.0, 2.0 * math.pi, LINES_W.size)
    return 1e6 + scale * np.cos(np.outer(t, LINES_W) + phases).sum(axis=1)


def _synthetic(tmp_path) -> tuple[dict, object]:
    """Every run of the page: the simulations' σ and records, and FD answers 1 % above
    the TD's σ whose densities are the records' own spectrum."""
    cache, records = {}, tmp_path / "records"
    spectra = {}
    for run in accuracy_lines.runs():
        key = moordyn_check.run_key(run)
        if run["sim"] in ("reference", "moordyn"):
            x = {q: _record(run["seed"], s) for q, s in (("reaction_b", 1e4), ("reaction_a", 9e3))}
            accuracy_lines.record_path(records, run).parent.mkdir(exist_ok=True)
            np.savez(accuracy_lines.record_path(records, run), t=DT * np.arange(N), **x)
            cache[key] = {
                **{q: float(v.std()) for q, v in x.items()},
                "motion_exact": 0.5,
                "static_b": 1.1e6,
                "wall": 1.0,
                "load": [1.0, 1.0, 1.0],
            }
            spectra = {q: accuracy_fatigue.periodic_density(v, DT) for q, v in x.items()}
    for run in accuracy_lines.runs():
        if run["sim"] != "fd":
            continue
        ref = {"line": run["line"], "sim": "reference", "seed": 1, "elements": 80}
        td = cache[moordyn_check.run_key(ref)]
        dens = {
            "end_" + q[-1]: {k: [w.tolist(), s.tolist()] for k in ("answer", "linear")}
            for q, (w, s) in spectra.items()
        }
        cache[moordyn_check.run_key(run)] = {
            **{q: 1.01 * td[q] for q in ("reaction_b", "reaction_a")},
            **{
                f"{p}_{e}": 0.97 * td[f"reaction_{e}"]
                for p in ("linear", "lines", "lines_residual")
                for e in "ab"
            },
            "density": dens,
            "motion_std": 0.5,
            "elements": 40,
            "segment_elements": [40],
            "omega": [0.05, 2.0, 200],
            "solver": "foss",
            "modes": 20,
            "tolerance": 1e-4,
            "warnings": [],
            "plan": {
                "error_estimate": {
                    "discretization": 0.01,
                    "linearization_model": 0.02,
                    "total": 0.03,
                },
                "model_error_basis": "line 'x': the computed residuals change the end_a "
                "tension σ by 14 %; the corrected σ's remaining error is its square",
            },
            "wall": 1.0,
            "load": [1.0, 1.0, 1.0],
        }
    return cache, records


def test_page_reads_the_ratios_and_the_fatigue_split_from_the_runs(tmp_path, monkeypatch):
    """FD σ 1 % above every seed's TD σ: every default / TD ratio reads +1.00 %, the
    target is met (at the table's precision); the FD density is the records' own
    spectrum: the 'spectrum' factor of the damage and its σ^m part are zero."""
    monkeypatch.setattr(accuracy_fatigue, "SURROGATES", 2)
    cache, records = _synthetic(tmp_path)
    page = accuracy_lines.write_page(cache, records)
    rows = [
        r for r in page.splitlines() if r.startswith("| chain | fairlead | +1.00 ± 0.00 % | yes")
    ]
    assert len(rows) == 1
    split = [r.split("|") for r in page.splitlines() if r.startswith("| deep | anchor | ")]
    spectrum = [c for c in split if "%;" in c[6]][0]  # the fatigue split's row
    assert abs(float(spectrum[3].split("%")[0].split("±")[0])) < 0.05  # densities equal
    assert abs(float(spectrum[4].split("%")[0])) < 0.05  # its σ^m part (σ from the density)
    assert "| current | anchor |" in page and "Not re-run for this regeneration" in page
    assert "| 2.00 % (residuals) | 3.00 % |" in page  # the plan's model estimate, its basis


def test_reference_mesh_is_the_coarsest_whose_doubling_moves_less_than_the_rule():
    """deep: 80 → 160 moves σ by −1 %, 160 → 320 by +0.1 % (< 0.2 %): the yardstick is
    the 160-element TD and the ratios are taken against it; chain: 80 → 160 moves 0 %:
    80; a line whose finer mesh has not run: 80."""
    cache = {}
    for line, moves in (("deep", {160: 0.99, 320: 0.99 * 1.001}), ("chain", {160: 1.0})):
        for s in moordyn_check.SEEDS:
            for n, f in {80: 1.0, **moves}.items():
                run = {"line": line, "sim": "reference", "seed": s, "elements": n}
                cache[moordyn_check.run_key(run)] = {"reaction_b": f * 100.0 + s,
                                                     "reaction_a": f * 50.0 + s}  # fmt: skip
    assert accuracy_lines.reference_mesh(cache, "deep") == 160
    steps = accuracy_lines.mesh_moves(cache, "deep")
    assert [(n, n2) for n, n2, _ in steps] == [(80, 160), (160, 320)]
    assert steps[0][2][0] == pytest.approx(
        -0.01 * 100 / np.mean([100 + s for s in moordyn_check.SEEDS]), rel=0.02
    )
    assert accuracy_lines.reference_mesh(cache, "chain") == 80
    assert accuracy_lines.reference_mesh(cache, "twoseg") == 80  # (no 160 runs)
    assert accuracy_lines._ref(cache, "deep")[0]["reaction_b"] == pytest.approx(0.99 * 100 + 1)


# the slow test: four 400 s reference simulations of the chain at 80 elements (≈ 10 s
# each on one core of the 2-core VM, quiet; 80 s loaded) and two FD analyses


def _fd(variant: str) -> tuple[float, float]:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the example's explicit 40 elements warn
        lr = analyze(accuracy_lines.fd_document("chain", variant)).lines["leg1"]
    return lr.end_b.std, lr.end_a.std


@pytest.mark.slow
def test_chain_default_sigma_is_within_the_target_of_the_reference():
    """FD default / TD − 1, mean over seeds 1–4: within the target (1 % at the
    fairlead, 2 % at the anchor) widened by two standard errors of the 4-seed mean (the
    nonlinear TD's σ scatters by 1.4 % from seed to seed, docs/accuracy/lines.md), so
    2.4 % / 3.4 %; the linear model (−4.0 % / −5.5 % on the page's 5 seeds) is outside
    both, and the correction moves σ up by 2.5–5 %."""
    td = []
    for seed in SEEDS:
        run = {"line": "chain", "sim": "reference", "seed": seed, **moordyn_check.BASE}
        td.append(moordyn_check.summarize(*moordyn_check.simulate(run)))
    td_b = np.array([r["reaction_b"] for r in td])
    td_a = np.array([r["reaction_a"] for r in td])
    default, linear = _fd("default"), _fd("linear")
    err_b, err_a = np.mean(default[0] / td_b - 1.0), np.mean(default[1] / td_a - 1.0)
    lin_b, lin_a = np.mean(linear[0] / td_b - 1.0), np.mean(linear[1] / td_a - 1.0)
    assert abs(err_b) <= 0.024, err_b
    assert abs(err_a) <= 0.034, err_a
    assert lin_b < -0.024 and lin_a < -0.034, (lin_b, lin_a)
    assert 0.025 < default[0] / linear[0] - 1.0 < 0.05
    assert 0.025 < default[1] / linear[1] - 1.0 < 0.06
