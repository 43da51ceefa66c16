"""The figures of :mod:`stochcable.plots`: each takes an analysis result
(:class:`~stochcable.results.documents.Result`) and returns a matplotlib Figure whose
labels are in the scene's unit system."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from stochcable.scene.units import UnitLabels, unit_labels

__all__ = [
    "pyplot",
    "plot_statics",
    "plot_end_tension_spectra",
    "plot_tension_along_line",
    "plot_mode_shapes",
    "plot_timeseries",
    "plot_result",
]

#: Ratio of the largest to the smallest positive value above which an axis is logarithmic.
LOG_SPAN = 1.0e3
#: Ratio of the largest to the smallest frequency above which the ω axis is logarithmic.
OMEGA_LOG_SPAN = 20.0
#: Length of the time-series window plotted by default. [s]
WINDOW = 600.0
_ENDS = ("end_a", "end_b")


def pyplot() -> Any:
    """``matplotlib.pyplot``, or an ImportError that names the extra to install."""
    try:
        import matplotlib.pyplot as plt
    except ImportError:
        raise ImportError(
            "stochcable.plots needs matplotlib: pip install 'stochcable[plot]'"
        ) from None
    return plt


def _labels(result: Any) -> UnitLabels:
    return unit_labels(result.scene.environment.g)


def _line(result: Any, line: str | None) -> Any:
    if line is None:
        return next(iter(result.lines.values()))
    if line not in result.lines:
        from stochcable.errors import InputError

        raise InputError(
            "line", line, "-", f"is not a line of the result ({', '.join(result.lines)})"
        )
    return result.lines[line]


def _spans_decades(values: np.ndarray) -> bool:
    v = np.asarray(values, dtype=float)
    pos = v[v > 0]
    return pos.size > 1 and float(pos.max()) > LOG_SPAN * float(pos.min())


def _horizontal(result: Any) -> tuple[bool, dict[str, np.ndarray]]:
    """Horizontal coordinate of every line's static nodes: x when every line lies in the
    x–z plane, else the horizontal distance from the line's end_b."""
    positions = {n: np.asarray(lr.statics.positions) for n, lr in result.lines.items()}
    planar = all(np.allclose(p[:, 1], 0.0) for p in positions.values())
    if planar:
        return True, {n: p[:, 0] for n, p in positions.items()}
    return False, {n: np.hypot(*(p[:, :2] - p[-1, :2]).T) for n, p in positions.items()}


def plot_statics(result: Any) -> Any:
    """Static shape of every line, its touchdown point and the seabed.

    Parameters
    ----------
    result : Result
        An analysis result.

    Returns
    -------
    matplotlib.figure.Figure
    """
    plt = pyplot()
    u = _labels(result)
    planar, horizontal = _horizontal(result)
    fig, ax = plt.subplots(figsize=(7, 4))
    for name, lr in result.lines.items():
        p = np.asarray(lr.statics.positions)
        (h,) = ax.plot(horizontal[name], p[:, 2], marker=".", ms=3, label=name)
        td = lr.statics.touchdown
        if td is not None and td > 0:
            s0 = np.asarray(lr.statics.mesh.s0)
            x_td = np.interp(td, s0, horizontal[name])
            z_td = np.interp(td, s0, p[:, 2])
            ax.plot([x_td], [z_td], "v", color=h.get_color(), ms=8, label=f"{name} touchdown")
    depth = result.scene.environment.depth
    if depth is not None and np.isfinite(depth):
        ax.axhline(-depth, color="saddlebrown", lw=1.0, label="seabed")
    ax.axhline(0.0, color="tab:blue", lw=0.6, ls=":", label="still water level")
    xlabel = "x" if planar else "horizontal distance from end_b"
    ax.set_xlabel(f"{xlabel} [{u.length}]")
    ax.set_ylabel(f"z [{u.length}]")
    ax.set_title("static shape: " + ", ".join(result.lines))
    ax.legend(fontsize=8)
    fig.tight_layout()
    return fig


def plot_end_tension_spectra(result: Any, line: str | None = None) -> Any:
    """One-sided spectra of the dynamic tension at both ends of a line.

    Log axes where the spectra span more than three decades (:data:`LOG_SPAN`).

    Parameters
    ----------
    result : Result
        An analysis result.
    line : str, optional
        Line name (default the first line).

    Returns
    -------
    matplotlib.figure.Figure
    """
    plt = pyplot()
    u = _labels(result)
    lr = _line(result, line)
    fig, ax = plt.subplots(figsize=(7, 4))
    spectra = {end: lr.end_tension_spectrum(end) for end in _ENDS}
    for end, s in spectra.items():
        stats = getattr(lr, end)
        ax.plot(lr.omega, s, label=f"{end}: σ = {stats.std:.4g} {u.force}")
    if _spans_decades(np.concatenate(list(spectra.values()))):
        ax.set_yscale("log")
        top = max(float(s.max()) for s in spectra.values())
        if top > 0:
            ax.set_ylim(top * 1e-8, top * 3)
    w = np.asarray(lr.omega)
    if w.size > 1 and w.min() > 0 and w.max() > OMEGA_LOG_SPAN * w.min():
        ax.set_xscale("log")
    ax.set_xlabel("ω [rad/s]")
    ax.set_ylabel(f"S_T(ω) [{u.force}²·s/rad]")
    ax.set_title(f"line {lr.name}: end tension spectra")
    ax.legend()
    ax.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    return fig


def plot_tension_along_line(result: Any, line: str | None = None) -> Any:
    """Static tension along a line with mean ± 3σ of the dynamic tension, and σ.

    Parameters
    ----------
    result : Result
        An analysis result.
    line : str, optional
        Line name (default the first line).

    Returns
    -------
    matplotlib.figure.Figure
    """
    plt = pyplot()
    u = _labels(result)
    lr = _line(result, line)
    s, mean, std = lr.s_elements, lr.tension_mean, lr.tension_std
    fig, (ax0, ax1) = plt.subplots(2, 1, figsize=(7, 5.5), sharex=True)
    ax0.plot(s, mean, color="k", label="mean (static)")
    ax0.fill_between(s, mean - 3 * std, mean + 3 * std, alpha=0.3, label="mean ± 3σ")
    ax0.axhline(0.0, color="tab:red", lw=0.8, ls="--", label="zero tension")
    ax0.set_ylabel(f"effective tension [{u.force}]")
    ax0.set_title(f"line {lr.name}: tension along the line (end_a at s = 0)")
    ax0.legend(fontsize=8)
    ax1.plot(s, std, color="tab:orange", label="σ of the dynamic tension")
    ax1.set_xlabel(f"unstretched arc length from end_a s [{u.length}]")
    ax1.set_ylabel(f"σ_T [{u.force}]")
    ax1.legend(fontsize=8)
    fig.tight_layout()
    return fig


def plot_mode_shapes(result: Any, line: str | None = None, count: int = 4) -> Any:
    """The lowest natural modes of a line: displacement components along the line.

    Each mode is scaled to a largest displacement of 1.

    Parameters
    ----------
    result : Result
        An analysis result.
    line : str, optional
        Line name (default the first line).
    count : int
        Number of modes. [-]

    Returns
    -------
    matplotlib.figure.Figure
    """
    plt = pyplot()
    u = _labels(result)
    lr = _line(result, line)
    modes, model = lr.modes, lr.model
    n = int(min(count, modes.count))
    fig, axes = plt.subplots(
        max(n, 1), 1, figsize=(7, 1.9 * max(n, 1) + 0.6), sharex=True, squeeze=False
    )
    shapes = np.asarray(modes.shapes).reshape(model.n_nodes, model.dim, -1)
    for k in range(n):
        ax = axes[k, 0]
        phi = shapes[:, :, k]
        scale = float(np.abs(phi).max()) or 1.0
        for c, axis in enumerate(model.components):
            ax.plot(lr.s_nodes, phi[:, c] / scale, label="xyz"[axis])
        ax.set_ylabel("φ / max|φ| [-]")
        ax.set_title(
            f"line {lr.name}: mode {k + 1}, ω = {modes.omega[k]:.4g} rad/s "
            f"(T = {modes.period[k]:.3g} s, {modes.plane[k]})",
            fontsize=9,
        )
        ax.legend(fontsize=7, loc="upper right")
    axes[-1, 0].set_xlabel(f"unstretched arc length from end_a s [{u.length}]")
    fig.tight_layout()
    return fig


def plot_timeseries(result: Any, window: float = WINDOW) -> Any | None:
    """The first ``window`` seconds of the time series: sea, end motions, end tensions.

    Parameters
    ----------
    result : Result
        An analysis result (None is returned when it has no time series).
    window : float
        Length of the window. [s]

    Returns
    -------
    matplotlib.figure.Figure or None
    """
    ts = result.timeseries
    if ts is None:
        return None
    plt = pyplot()
    u = _labels(result)
    n = max(int(np.searchsorted(ts.time, ts.time[0] + window)), 2)
    rows = 1 + len(ts.end_tension)
    fig, axes = plt.subplots(rows, 1, figsize=(8, 2.2 * rows + 0.4), sharex=True, squeeze=False)
    ax0 = axes[0, 0]
    if ts.elevation is not None:
        ax0.plot(ts.time[:n], ts.elevation[:n], lw=0.8, label="η (wave elevation)")
    for key, series in ts.end_motion.items():
        ax0.plot(ts.time[:n], series[:n], lw=0.8, label=key)
    ax0.set_ylabel(f"η, motion [{u.length}]")
    ax0.set_title(f"time series ({ts.method.upper()}, seed {ts.seed}): first {window:g} s")
    ax0.legend(fontsize=7, loc="upper right")
    for k, (name, ends) in enumerate(ts.end_tension.items(), start=1):
        ax = axes[k, 0]
        for end, series in ends.items():
            ax.plot(ts.time[:n], series[:n], lw=0.8, label=f"{name} {end}")
        ax.set_ylabel(f"T [{u.force}]")
        ax.legend(fontsize=7, loc="upper right")
    axes[-1, 0].set_xlabel("t [s]")
    fig.tight_layout()
    return fig


def plot_result(result: Any, directory: str | Path, dpi: int = 100) -> list[Path]:
    """Write every figure of a result as PNG files into ``directory``.

    Files: ``statics.png``; per line ``<line>_end_tension_spectra.png``,
    ``<line>_tension_std.png``, ``<line>_modes.png``; ``timeseries.png`` when the
    result has a time series.

    Parameters
    ----------
    result : Result
        An analysis result.
    directory : str or Path
        Output directory (created if missing).
    dpi : int
        Resolution. [dots per inch]

    Returns
    -------
    list of Path
        The files written.
    """
    plt = pyplot()
    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    figures: list[tuple[str, Any]] = [("statics", plot_statics(result))]
    for name in result.lines:
        figures.append((f"{name}_end_tension_spectra", plot_end_tension_spectra(result, name)))
        figures.append((f"{name}_tension_std", plot_tension_along_line(result, name)))
        figures.append((f"{name}_modes", plot_mode_shapes(result, name)))
    ts = plot_timeseries(result)
    if ts is not None:
        figures.append(("timeseries", ts))
    paths = []
    for stem, fig in figures:
        p = directory / f"{stem}.png"
        fig.savefig(p, dpi=dpi)
        plt.close(fig)
        paths.append(p)
    return paths
