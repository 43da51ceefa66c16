"""Figures of a load-case set (stochcable.plots.cases): the heat map holds the annual
damage contributions of the cases, headings summed; the CLI writes the figures."""

from __future__ import annotations

import json

import numpy as np
import pytest

from stochcable.cases import LineFatigue, run_cases, scatter_from_rows
from stochcable.cli import main
from stochcable.design import SECONDS_PER_YEAR
from stochcable.errors import InputError
from stochcable.examples import load_example, resources

# one worker runs the module: its module fixtures run once (--dist loadgroup)
pytestmark = pytest.mark.xdist_group("test_plots_cases")

pytest.importorskip("matplotlib")


@pytest.fixture(scope="module")
def result():
    rows = [
        {"hs": hs, "tp": tp, "heading": hd, "probability": 1 / 8}
        for hs in (2.0, 4.0)
        for tp in (8.0, 11.0)
        for hd in (0.0, 180.0)
    ]
    fatigue = LineFatigue("dnv-six-strand", nominal_area=1.2e-3)
    return run_cases(load_example("taut_wire"), scatter_from_rows(rows), fatigue=fatigue)


def test_heat_map_holds_the_damage_contributions(result):
    import matplotlib.pyplot as plt

    from stochcable.plots import damage_grid, plot_damage_heatmap

    hs, tp, grid = damage_grid(result, "wire")
    d = result.damage_rate_ends["wire"][:, 1] * SECONDS_PER_YEAR / 8
    # each cell sums its two headings; the grid sums to the annual damage of the end
    expect = d.reshape(2, 2, 2).sum(axis=2)
    np.testing.assert_allclose(grid, expect, rtol=1e-14)
    assert grid.sum() == pytest.approx(result.totals["wire"].annual_damage["end_b"], rel=1e-12)
    fig = plot_damage_heatmap(result, "wire")
    ax = fig.axes[0]
    assert "Hs [m]" in ax.get_ylabel() and "Tp [s]" in ax.get_xlabel()
    np.testing.assert_allclose(ax.collections[0].get_array().reshape(2, 2), expect, rtol=1e-14)
    plt.close(fig)


def test_damage_along_line_and_errors(result):
    import matplotlib.pyplot as plt

    from stochcable.plots import plot_damage_along_line

    fig = plot_damage_along_line(result, "wire")
    y = fig.axes[0].lines[0].get_ydata()
    np.testing.assert_array_equal(y, result.totals["wire"].annual_damage["along"])
    plt.close(fig)
    with pytest.raises(InputError, match="not a line"):
        plot_damage_along_line(result, "nope")


def test_cli_writes_the_figures(tmp_path):
    scatter = tmp_path / "s.csv"
    scatter.write_text("hs,tp,probability\n2,8,0.5\n3,10,0.5\n")
    wire = str(resources.files("stochcable.examples") / "taut_wire.json")
    figs, out = str(tmp_path / "figs"), str(tmp_path / "r.json")
    args = ["cases", wire, "--scatter", str(scatter), "--curve", "dnv-six-strand",
            "--nominal-area", "1.2e-3", "--plot", figs, "-o", out]  # fmt: skip
    assert main(args) == 0
    assert sorted(p.name for p in (tmp_path / "figs").iterdir()) == [
        "wire_damage_along.png",
        "wire_damage_heatmap.png",
    ]
    assert json.loads((tmp_path / "r.json").read_text())["coverage"]["ok"] == 1.0
