"""Figures of an analysis result, labelled in the scene's unit system.

One set of plots for the command line (``stochcable analyze --plot DIR``) and the
documentation gallery: the static geometry with the touchdown points
(:func:`plot_statics`), the end tension spectra (:func:`plot_end_tension_spectra`),
the tension along a line with mean ± 3σ (:func:`plot_tension_along_line`), the mode
shapes (:func:`plot_mode_shapes`) and a window of the time series
(:func:`plot_timeseries`); :func:`plot_result` writes them all as PNG files.  A
load-case set: the damage by sea state over Hs × Tp (:func:`plot_damage_heatmap`) and
along each line (:func:`plot_damage_along_line`); :func:`plot_cases` writes both.

Axis labels come from the scene's unit system (:func:`stochcable.scene.units.unit_labels`
of ``environment.g``): a foot–slug–second scene is labelled in ft and lbf, since its
numbers are.  matplotlib is the optional extra ``plot``
(``pip install 'stochcable[plot]'``); it is imported when a plot is drawn.
"""

from stochcable.plots.cases import (
    damage_grid,
    plot_cases,
    plot_damage_along_line,
    plot_damage_heatmap,
)
from stochcable.plots.figures import (
    plot_end_tension_spectra,
    plot_mode_shapes,
    plot_result,
    plot_statics,
    plot_tension_along_line,
    plot_timeseries,
    pyplot,
)

__all__ = [
    "plot_statics",
    "plot_end_tension_spectra",
    "plot_tension_along_line",
    "plot_mode_shapes",
    "plot_timeseries",
    "plot_result",
    "pyplot",
    "damage_grid",
    "plot_damage_heatmap",
    "plot_damage_along_line",
    "plot_cases",
]
