"""The frequency grid's resolution of a resonance (stochcable.dynamics.outputs.resolution):
the trapezoid rule's error bound on a Lorentzian peak against the rule itself, and the
warning on the inclined guy's lightly damped mode, cured by the count it names."""

from __future__ import annotations

import copy
import re
import warnings

import numpy as np
import pytest

from stochcable.analysis import analyze
from stochcable.dynamics.outputs.resolution import RESONANCE_PEAK_ERROR, peak_quadrature_error
from stochcable.errors import ResolutionWarning
from stochcable.examples import load_example


@pytest.mark.parametrize("ratio", [0.3, 0.59, 0.83, 1.0, 2.0])
def test_peak_error_bounds_the_trapezoid_rule_on_a_lorentzian(ratio):
    # |H|² = 1/((ω − ω0)² + γ²) on a uniform grid of spacing h = ratio·b (b = 2γ), the
    # peak at every offset from the grid: the rule's relative error against the exact
    # π/γ spans [tanh(a/2) − 1, coth(a/2) − 1], a = πb/h.  A grid ±4000 b wide: the
    # truncated tails are 2/(π·4000) = 1.6e-4 of the integral, so they are added back in
    # closed form (2·arctan's complement) and the comparison holds to 1e-9.
    b = 0.02
    gamma, h = b / 2.0, ratio * b
    n = int(4000 * b / h)
    errors = []
    for offset in np.linspace(0.0, 1.0, 41):
        w = (np.arange(-n, n + 1) + offset) * h
        f = 1.0 / (w**2 + gamma**2)
        trap = h * np.sum(f) - 0.5 * h * (f[0] + f[-1])
        tails = np.pi / 2 - np.arctan(-w[0] / gamma) + np.pi / 2 - np.arctan(w[-1] / gamma)
        errors.append((trap + tails / gamma) * gamma / np.pi - 1.0)
    bound = float(peak_quadrature_error(b, h))
    a = np.pi * b / h
    assert max(errors) == pytest.approx(bound, rel=1e-6, abs=1e-9)
    assert min(errors) == pytest.approx(np.tanh(a / 2) - 1.0, rel=1e-6, abs=1e-9)


def test_peak_error_of_an_undamped_mode_is_unbounded():
    assert peak_quadrature_error(0.0, 0.01) == np.inf


def test_peak_error_figures_quoted_in_the_docs():
    # RESONANCE_PEAK_ERROR's note and the warnings page: 1 % at Δω = 0.59 b, 9 % at b
    assert peak_quadrature_error(1.0, 0.593) == pytest.approx(0.01, rel=0.02)
    assert peak_quadrature_error(1.0, 1.0) == pytest.approx(0.09, rel=0.01)


def _guy_warning(doc: dict) -> str | None:
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        analyze(doc)
    found = [
        str(w.message)
        for w in caught
        if issubclass(w.category, ResolutionWarning) and "does not resolve" in str(w.message)
    ]
    return found[0] if found else None


def test_the_guys_lightly_damped_mode_warns_and_the_named_count_cures_it():
    # mode 2 of the inclined guy (ζ = 0.67 %): half-power bandwidth 0.016 rad/s against
    # the 300-point grid's 0.0132: ±4.6 % on the peak (its end-tension σ is 4 % off the
    # time domain's, docs/ACCURACY.md)
    doc = load_example("inclined_guy").model_dump(mode="json", exclude_none=True)
    doc["analysis"].pop("timeseries", None)
    msg = _guy_warning(doc)
    assert msg is not None and "mode 2 at 1.193 rad/s" in msg
    off = float(re.search(r"off by up to ±([\d.]+)%", msg).group(1))
    assert 4.0 < off < 5.0 and f"threshold {RESONANCE_PEAK_ERROR:.0%}" in msg
    count = int(re.search(r"analysis\.omega\.count >= (\d+)", msg).group(1))
    finer = copy.deepcopy(doc)
    finer["analysis"]["omega"]["count"] = count
    assert _guy_warning(finer) is None


# ------------------------------------------------------------ the grid-top (tail) warning
def _tail_scene(sea_top: float, motion_top: float) -> dict:
    """The taut wire on the grid 0.2–3 rad/s, its sea and its top end's surge flat
    tables from 0.2 rad/s to the given tops: white inputs, so the tension spectrum is
    still ≈ 1.1 m0 at the grid's top (measured), 20 times the threshold."""
    doc = load_example("taut_wire").model_dump(mode="json", exclude_none=True)

    def table(top):
        w = np.linspace(0.2, top, 30)
        return {"type": "table", "omega": w.tolist(), "density": [1e-4] * 30}

    doc["sea"]["spectrum"] = table(sea_top)
    doc["lines"][0]["end_b"]["motion"] = {"surge": table(motion_top)}
    return doc


def _tail_warnings(doc) -> list[str]:
    with warnings.catch_warnings(record=True) as rec:
        warnings.simplefilter("always")
        analyze(doc)
    return [str(r.message) for r in rec if "top of the grid" in str(r.message)]


def test_grid_top_warning_is_quiet_when_the_inputs_end_at_the_grid_top():
    assert _tail_warnings(_tail_scene(3.0, 3.0)) == []


@pytest.mark.parametrize("sea_top, motion_top", [(3.0, 4.0), (5.0, 3.0)])
def test_grid_top_warning_says_where_the_input_ends(sea_top, motion_top):
    messages = _tail_warnings(_tail_scene(sea_top, motion_top))
    assert len(messages) == 2  # end_a and end_b
    top = max(sea_top, motion_top)
    assert all(f"the excitation goes on to {top:.4g} rad/s" in m for m in messages)


def test_excitation_end_of_tables_and_of_an_analytic_spectrum():
    from stochcable.dynamics.loads.channels import Channel
    from stochcable.dynamics.outputs.resolution import excitation_end

    omega = np.linspace(0.2, 3.0, 50)

    def channel(density):
        return Channel(
            name="sea", kind="sea", omega=omega, spectrum=density(omega), density=density
        )

    def flat(top):
        return lambda w: np.where((w >= 0.2) & (w <= top), 1.0, 0.0)

    assert excitation_end((channel(flat(3.0)),), omega) == 3.0
    assert excitation_end((channel(flat(2.0)),), omega) == omega[omega <= 2.0][-1]
    assert excitation_end((channel(flat(7.5)),), omega) == pytest.approx(7.5, rel=1e-8)
    assert excitation_end((channel(flat(2.0)), channel(flat(7.5))), omega) == pytest.approx(7.5)
    assert excitation_end((channel(lambda w: w**-5.0),), omega) == np.inf
    assert excitation_end((), omega) == 3.0  # no input: nothing beyond the grid
