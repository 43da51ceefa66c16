"""Tests of stochcable.plots: labels in the scene's unit system, titles, log axes."""

from __future__ import annotations

import sys
import warnings

import numpy as np
import pytest

from stochcable.analysis import analyze
from stochcable.examples import load_example

# one worker runs the module: its module fixtures run once (--dist loadgroup)
pytestmark = pytest.mark.xdist_group("test_plots")

matplotlib = pytest.importorskip("matplotlib")
matplotlib.use("Agg")

from stochcable import plots  # noqa: E402


def _analyze(name):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the examples' documented warnings
        return analyze(load_example(name))


@pytest.fixture(scope="module")
def fss():
    """A foot-slug-second scene: lengths in ft, forces in lbf."""
    return _analyze("tuah_1982_disc_buoy_three_legs")


@pytest.fixture(scope="module")
def chain():
    return _analyze("chain_catenary")


def _texts(fig):
    """Every axis label and title of a figure, read back from it."""
    out = []
    for ax in fig.axes:
        out += [ax.get_xlabel(), ax.get_ylabel(), ax.get_title()]
    return out


def test_foot_slug_second_scene_is_labelled_in_ft_and_lbf(fss):
    import matplotlib.pyplot as plt

    figs = [
        plots.plot_statics(fss),
        plots.plot_end_tension_spectra(fss, "leg2"),
        plots.plot_tension_along_line(fss, "leg2"),
        plots.plot_mode_shapes(fss, "leg2"),
    ]
    labels = [t for f in figs for t in _texts(f)]
    joined = " ".join(labels)
    assert "[ft]" in joined and "[lbf]" in joined and "lbf²·s/rad" in joined
    # no SI label on a scene whose numbers are in ft and lbf
    assert not any("[m]" in t or "[N]" in t or "N²" in t for t in labels), labels
    assert plots.plot_statics(fss).axes[0].get_ylabel() == "z [ft]"
    spectra = figs[1].axes[0]
    assert "leg2" in spectra.get_title()
    legend = [t.get_text() for t in spectra.get_legend().get_texts()]
    assert any(t.startswith("end_a") and t.endswith("lbf") for t in legend)
    plt.close("all")


def test_si_scene_labels_touchdown_and_log_axes(chain):
    import matplotlib.pyplot as plt

    fig = plots.plot_statics(chain)
    ax = fig.axes[0]
    assert ax.get_xlabel() == "x [m]" and ax.get_ylabel() == "z [m]"
    legend = [t.get_text() for t in ax.get_legend().get_texts()]
    assert "leg1 touchdown" in legend and "seabed" in legend
    # the touchdown marker lies on the seabed
    (td,) = [ln for ln in ax.get_lines() if ln.get_label() == "leg1 touchdown"]
    assert td.get_ydata()[0] == pytest.approx(-chain.scene.environment.depth, abs=0.5)
    spectra = plots.plot_end_tension_spectra(chain).axes[0]
    lr = chain.lines["leg1"]
    s = lr.end_tension_spectrum("end_a")
    assert s[s > 0].max() > plots.figures.LOG_SPAN * s[s > 0].min()  # spans decades
    assert spectra.get_yscale() == "log"
    assert spectra.get_ylabel() == "S_T(ω) [N²·s/rad]"
    band = plots.plot_tension_along_line(chain).axes[0]
    assert band.get_ylabel() == "effective tension [N]"
    # the mean ± 3σ band is drawn about the static tension: its edges differ by 6σ
    poly = band.collections[0].get_paths()[0].vertices
    top = poly[:, 1].max() - (lr.tension_mean + 3 * lr.tension_std).max()
    assert abs(top) < 1e-6 * lr.tension_mean.max()
    plt.close("all")


def test_timeseries_window_labels(chain):
    import matplotlib.pyplot as plt

    fig = plots.plot_timeseries(chain, window=100.0)
    assert fig.axes[-1].get_xlabel() == "t [s]"
    assert fig.axes[1].get_ylabel() == "T [N]"
    line = fig.axes[1].get_lines()[0]
    assert line.get_xdata()[-1] - line.get_xdata()[0] <= 100.0
    plt.close("all")


@pytest.mark.slow
def test_plot_result_writes_every_figure(fss, tmp_path):
    paths = plots.plot_result(fss, tmp_path)
    names = sorted(p.name for p in paths)
    expected = ["statics.png"] + [
        f"leg{k}_{kind}.png"
        for k in (1, 2, 3)
        for kind in ("end_tension_spectra", "modes", "tension_std")
    ]
    assert names == sorted(expected)
    assert all(p.stat().st_size > 1000 for p in paths)


def test_missing_matplotlib_names_the_extra(monkeypatch):
    monkeypatch.setitem(sys.modules, "matplotlib.pyplot", None)
    with pytest.raises(ImportError, match=r"stochcable\[plot\]"):
        plots.pyplot()


def test_mode_shape_title_carries_frequency(chain):
    import matplotlib.pyplot as plt

    fig = plots.plot_mode_shapes(chain, count=2)
    w = chain.lines["leg1"].modes.omega
    assert f"{w[0]:.4g} rad/s" in fig.axes[0].get_title()
    assert np.isclose(max(abs(v) for ln in fig.axes[0].get_lines() for v in ln.get_ydata()), 1.0)
    plt.close("all")
