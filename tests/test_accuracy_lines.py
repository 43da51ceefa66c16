"""The accuracy page's claim on one line (benchmarks/accuracy_lines.py, issue 31): the
default analysis — the residual switches true — gives the chain's end-tension σ within
the target of the nonlinear time-domain reference, where the linear model does not."""

from __future__ import annotations

import sys
import warnings

import numpy as np
import pytest
from _paths import ROOT

from stochcable import analyze

sys.path.insert(0, str(ROOT / "benchmarks"))
import accuracy_lines  # noqa: E402
import moordyn_check  # noqa: E402

# four 400 s reference simulations of the chain at 80 elements (≈ 10 s each on one
# core of the 2-core VM, quiet) and two FD analyses: the slow tier
pytestmark = [pytest.mark.slow, pytest.mark.xdist_group("test_accuracy_lines")]

SEEDS = (1, 2, 3, 4)


def _fd(variant: str) -> tuple[float, float]:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the example's explicit 40 elements warn
        lr = analyze(accuracy_lines.fd_document("chain", variant)).lines["leg1"]
    return lr.end_b.std, lr.end_a.std


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
