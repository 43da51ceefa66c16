"""Figures of a load-case set: where the fatigue damage comes from and where it goes."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from stochcable.cases import CaseSetResult
from stochcable.design import SECONDS_PER_YEAR
from stochcable.errors import InputError
from stochcable.plots.figures import pyplot

__all__ = ["damage_grid", "plot_damage_heatmap", "plot_damage_along_line", "plot_cases"]


def _check_line(result: CaseSetResult, line: str) -> None:
    if line not in result.lines:
        raise InputError("line", line, "-", f"is not a line of the set ({', '.join(result.lines)})")


def damage_grid(result: CaseSetResult, line: str, end: str = "end_b") -> tuple[np.ndarray, ...]:
    """Annual damage contributions p_i·d_i·year of the cases on the Hs × Tp grid, summed
    over headings.

    Returns
    -------
    hs : ndarray, shape (n_hs,)
        The diagram's distinct Hs. [m]
    tp : ndarray, shape (n_tp,)
        The distinct Tp. [s]
    grid : ndarray, shape (n_hs, n_tp)
        Annual damage from each cell (NaN where no case, 0 where failed). [1/year]
    """
    _check_line(result, line)
    j = ("end_a", "end_b").index(end)
    states = result.scatter.states
    hs = np.unique([s.hs for s in states])
    tp = np.unique(np.round([s.tp for s in states], 9))
    grid = np.full((hs.size, tp.size), np.nan)
    d = np.nan_to_num(result.damage_rate_ends[line][:, j])
    for s, di in zip(states, d):
        a, b = np.searchsorted(hs, s.hs), np.searchsorted(tp, round(s.tp, 9))
        grid[a, b] = np.nan_to_num(grid[a, b]) + s.probability * di * SECONDS_PER_YEAR
    return hs, tp, grid


def plot_damage_heatmap(result: CaseSetResult, line: str, end: str = "end_b") -> Any:
    """Annual damage by sea state over the Hs × Tp grid (log colour scale).

    Returns
    -------
    matplotlib.figure.Figure
    """
    plt = pyplot()
    from matplotlib.colors import LogNorm

    hs, tp, grid = damage_grid(result, line, end)
    fig, ax = plt.subplots(figsize=(7, 5))
    positive = grid[np.isfinite(grid) & (grid > 0)]
    norm = LogNorm(positive.min(), positive.max()) if positive.size else None
    masked = np.ma.masked_where(~np.isfinite(grid) | (grid <= 0), grid)
    mesh = ax.pcolormesh(tp, hs, masked, norm=norm, shading="nearest", cmap="viridis")
    fig.colorbar(mesh, ax=ax, label="annual damage of the sea state [1/year]")
    ax.set_xlabel("peak period Tp [s]")
    ax.set_ylabel("significant wave height Hs [m]")
    ax.set_title(f"line {line}, {end}: fatigue damage by sea state")
    fig.tight_layout()
    return fig


def plot_damage_along_line(result: CaseSetResult, line: str) -> Any:
    """Annual damage and fatigue life of every element along a line.

    Returns
    -------
    matplotlib.figure.Figure
    """
    _check_line(result, line)
    t = result.totals[line]
    if "along" not in t.annual_damage:
        raise InputError("line", line, "-", "has no fatigue settings: no damage to plot")
    plt = pyplot()
    s = result.s_elements[line]
    fig, (ax0, ax1) = plt.subplots(2, 1, figsize=(7, 5.5), sharex=True)
    ax0.semilogy(s, t.annual_damage["along"], color="tab:red")
    ax0.set_ylabel("annual damage [1/year]")
    ax0.set_title(f"line {line}: fatigue along the line (end_a at s = 0)")
    ax1.semilogy(s, t.fatigue_life["along"], color="k")
    ax1.set_ylabel("fatigue life with DFF [years]")
    ax1.set_xlabel("unstretched arc length from end_a s [m]")
    fig.tight_layout()
    return fig


def plot_cases(result: CaseSetResult, directory: str | Path, dpi: int = 100) -> list[Path]:
    """Write the heat map of each line's fairlead (end_b) damage and the damage along
    each line with fatigue settings as PNG files; returns their paths."""
    plt = pyplot()
    out = Path(directory)
    out.mkdir(parents=True, exist_ok=True)
    paths = []
    for line in result.lines:
        if "along" not in result.totals[line].annual_damage:
            continue
        for name, fig in (
            (f"{line}_damage_heatmap.png", plot_damage_heatmap(result, line)),
            (f"{line}_damage_along.png", plot_damage_along_line(result, line)),
        ):
            fig.savefig(out / name, dpi=dpi)
            plt.close(fig)
            paths.append(out / name)
    return paths
