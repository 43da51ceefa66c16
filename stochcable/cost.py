"""The cost of an analysis before it runs: peak memory and time from the scene's sizes.

:func:`estimate_cost` reads only the sizes of a scene document (finite elements,
frequencies, input channels, bodies, time-series samples) and returns a
:class:`CostEstimate`; nothing is allocated.  The HTTP service refuses a document whose
estimate exceeds its memory budget before any work starts, and the command line
refuses one that would not fit in the machine's available memory
(:func:`check_memory`), so a scene too large for the machine answers one sentence
naming the inputs to reduce instead of running out of memory halfway.

The model
---------
The engine's large arrays are frequency-domain arrays with one axis over the
frequencies (``analysis.omega.count`` = n_ω), one over the nodes of a line
(n_nodes = elements + 1, three DOFs each) and one over the line's input channels
(:class:`stochcable.dynamics.loads.channels.Channel`: the sea, one per end-motion spectrum DOF,
and the three translations of an end attached to a body).  A line without an end on
a body holds for the whole grid only its converged response (its free nodes' part: d
complex per node and channel, which the result keeps); everything else — the sea's
element kinematics (formed per block when they do not fit a quarter of the working
memory target), the loads, the solves, the variance sums, the outputs — runs over
blocks of frequencies whose temporaries stay within the working-memory target
(``STOCHCABLE_WORKING_MEMORY_MB``, 48 MiB by default,
:mod:`stochcable.dynamics.loads.freqblocks`).  A line on a body also holds its node response
per channel and the coupling columns of the body's solve.  The peak resident memory is
therefore

    M ≈ M_0 + n_ω · Σ_lines c_M · n_nodes · n_ch  +  c_T · N_t · (1 + Σ_lines n_ch),

with c_M the free lines' constant or the attached lines' one, M_0 the blocks'
temporaries and the small arrays, N_t = duration/dt the time-series samples (the
realization, the transfer functions interpolated onto the N_t/2 FFT frequencies and
the synthesized records; with the residuals two more channels a line, each end
tension's Gaussian residual component, :mod:`stochcable.dynamics.timeseries.residual_series`),
and the time

    t ≈ k_M · n_ω · Σ_lines n_nodes · n_ch · (1 + n_bodies)  +  k_T · N_t · (1 + Σ n_ch).

The modes (at most the line's DOFs, dense only up to a few hundred DOFs per block) and
the Foss state space (2 n_modes per line) are smaller than the nodal arrays and are in
M_0.

Constants (fitted on the peak RSS above the warmed-up process: a fresh subprocess,
one BLAS thread, the VmHWM reset after two small analyses that load the compiled
kernels; ``benchmarks/bench_cost.py``, x86-64, numpy 2, 2 cores):

=====================================  =====  ======  =========  =======  =============
scene                                  n_el   n_ω     channels   ΔRSS     B/(node·ω·ch)
=====================================  =====  ======  =========  =======  =============
taut_wire (sea only)                   200    1000    1          68 MB    3
taut_wire                              400    1000    1          85 MB    43
chain_catenary (sea + fairlead surge)  200    1000    2          79 MB    30
chain_catenary                         400    1000    2          100 MB   40
chain_catenary                         200    3000    2          119 MB   43
taut_wire                              1000   4000    1          250 MB   46
chain_catenary                         1000   4000    2          344 MB   35
disc buoy, three legs (free body)      3×100  1000    4 per leg  219 MB   125
disc buoy, three legs                  3×200  1000    4 per leg  328 MB   108
=====================================  =====  ======  =========  =======  =============

(the ratio is (ΔRSS − M_0)/(n_ω Σ n_nodes n_ch)) so c_M = 64 B for free lines (the
ratio grows towards the kept response's 16 B per DOF, 48 B per node of a line in 3-D,
as the grid grows: 46 on the taut wire at 1,000 × 4,000; a third above it, so the
estimate is not below the peak) and 150 B for lines on a body (125 with a fifth
added: the mesh check after the solve brought the three-leg buoy at 100 × 600 to
1.1001 × the estimate at 140 B),
M_0 = 64 MiB (the working-memory target's temporaries and the small
arrays); c_T = 110 B per sample and
channel (chain_catenary, 2^20 and 2^22 samples with the whole record in the result
document: 320 B per sample).  Time on the same machine: 0.9–1.2 µs per
node·frequency·channel for single lines, 2.1–2.4 µs with a free body (k_M = 1.3 µs,
the body factor 1 + n_bodies), k_T = 1.7 µs per sample and channel.  Times are
indicative (they scale with the CPU and the drag iterations); the memory model is
what the budgets use.

The constants are in one place (the ``*_BYTES_*`` and ``*_SECONDS_*`` module
constants) so that a change of the engine's array layout updates them here only:
rerun ``benchmarks/bench_cost.py`` and take the largest bytes-per-node·frequency·channel
ratio of each kind of line, rounded up.

The adaptive-fidelity planner (``analysis.fidelity``) chooses its own elements and
frequencies: the scene it plans is refused when its estimate exceeds the memory
available (:func:`stochcable.fidelity.limits.check_plan_memory`); the service's check
of the document as given does not see the plan, and the workers' address-space limit
bounds a planned analysis beyond the service's budget.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from stochcable.errors import InputError
from stochcable.scene.model import Scene, load_scene
from stochcable.scene.residual_kinds import ResidualSize, asked_residuals

__all__ = [
    "CostEstimate",
    "estimate_cost",
    "check_memory",
    "available_memory",
    "BYTES_PER_NODE_FREQUENCY_CHANNEL",
    "BYTES_PER_NODE_FREQUENCY_CHANNEL_ATTACHED",
    "BYTES_PER_SAMPLE_CHANNEL",
    "BASE_BYTES",
    "SECONDS_PER_NODE_FREQUENCY_CHANNEL",
    "SECONDS_PER_SAMPLE_CHANNEL",
]

BYTES_PER_NODE_FREQUENCY_CHANNEL = 64
"""Peak bytes per node, frequency and input channel of a line without an end on a
body (c_M). [B]"""

BYTES_PER_NODE_FREQUENCY_CHANNEL_ATTACHED = 150
"""Peak bytes per node, frequency and input channel of a line with an end on a body
(c_M). [B]"""

BYTES_PER_SAMPLE_CHANNEL = 110
"""Peak bytes per time-series sample and channel, plus one for the sea (c_T). [B]"""

BASE_BYTES = 64 * 2**20
"""Peak bytes of an analysis independent of its size (M_0: the frequency blocks'
temporaries, modes, statics, small arrays). [B]"""

SECONDS_PER_NODE_FREQUENCY_CHANNEL = 1.3e-6
"""Wall time per node, frequency and channel on the calibration machine (k_M). [s]"""

SECONDS_PER_SAMPLE_CHANNEL = 1.7e-6
"""Wall time per time-series sample and channel on the calibration machine (k_T). [s]"""

_BODY_TIME_FACTOR = 1.0  # extra time per free body (coupled solves): 2.6 µs vs 1.2 µs

#: The residuals of the linear model (every kind of
#: :mod:`stochcable.scene.residual_kinds` the scene asks for): their peak memory and
#: time are the kinds' cost terms (``memory``, ``seconds``; the largest memory of one
#: kind on one line, the sum of the times).
#:
#: Memory (issue 31): an upper bound, the residual's arrays counted from the sizes
#: (``ResidualSize``: elements, frequencies, channels, dimension, the uniform grid's
#: lines and amplitude lines) times 2.0 (``RESIDUAL_MEMORY_MARGIN``): copies of the
#: response per node, frequency and channel (drag: its pieces' velocities, 208 B planar,
#: 288 B in 3-D per piece·ω·channel; geometric: the node displacements and their
#: differences, 96 B per node·ω·channel, and its processes' lines) and pair terms
#: (geometric: d² element pairs on its ~3·32 lines, every element counted, up to 400
#: elements; planar drag: 64 panel components squared; 3-D drag: its covariance blocks).
#: Peak RSS above the warmed-up process measured against the whole estimate (MB): taut
#: wire 200 × 600: 305 / 412, 400 × 600: 1081 / 1379; chain 150 × 600: 108 / 294, in
#: 3-D 288 / 516, 400 × 2000: 611 / 1770; three-leg buoy 100 × 600: 267 / 476
#: (tests/test_cost.py; before the element tensions', node motions' and shared legs'
#: residuals, with a margin of 1.25: the buoy now peaks at 641 MB, the inclined guy at
#: 200 elements at 538 MB).  On a line with seabed contact the geometric residual skips
#: the elements on the bed (their forces do not reach the ends), which the bound counts:
#: it is then up to 3× the measured peak.
#:
#: Time: measured with the drag and geometric residuals: an
#: analysis of the chain, the inclined guy and the taut wire with both measured 0.53,
#: 0.65 and 0.16 s against 0.72, 0.79 and 0.18 s estimated (the chain at 160 elements:
#: 0.90 against 0.80 s); the caps are those of :mod:`stochcable.dynamics.residuals.residual_lines`
#: and the residual modules.  In a sea the drag residual splits the elements near
#: the surface (:mod:`stochcable.dynamics.residuals.drag_segments`; 40 elements: the chain 54
#: panels, the guy 53), counted as a quarter of the panel cap more in every sea (the
#: chain and the guy: 1.12 and 1.43 s measured against 1.29 and 1.36 s estimated, on a
#: loaded host; the taut wire, 10 m below the surface, splits none: 0.21 against 0.52 s,
#: on the safe side).  A 3-D line (``seconds_3d``): the vector drag residual measured
#: 8.7–14× the planar formula (the taut wire at heading 45°, 10–80 elements: 0.05–0.27 s;
#: the three-leg buoy's legs at 20 and 40 elements; the chain at 45°: 0.34 s against
#: 0.023 s planar), 14 taken; the geometric 2.3–3.2× (3 taken).  A line with an end on a
#: free body: its residuals through the coupled influence, 1.14–1.15× (1.25 taken).
_RESIDUAL_LINES = 63


#: Factor on a line's residual times where an end is on a free body: the coupled
#: influence (body_residual) solved on the residual's lines, measured 1.14 on the
#: three-leg buoy (3-D legs of 40 elements) and 1.15 on the single leg on the disc
#: buoy (40 elements). [-]
_BODY_RESIDUAL_FACTOR = 1.25


def _uniform_lines(w: np.ndarray, stride: int = 1) -> tuple[int, int]:
    """Lines n_j of the residuals' uniform grid of the analysis frequencies ``w``
    (every ``stride``-th of at most ``_RESIDUAL_LINES`` + 1) and its amplitude lines
    n_j · ranks (the most frequencies on one line: each its own channel), as
    :class:`stochcable.dynamics.residuals.residual_lines.UniformGrid` forms them
    without the inputs' tails (tests/test_cost.py checks they agree). [-]"""
    w = np.asarray(w, dtype=float)
    steps = np.diff(w)
    base = max(float(steps.min()) if steps.size else float(w[0]), float(w[-1]) / _RESIDUAL_LINES)
    step = stride * base
    n_j = int(np.rint(w[-1] / step)) + 1
    index = np.clip(np.rint(w / step).astype(int), 0, n_j - 1)
    ranks = int(np.bincount(index).max())
    return n_j, n_j * ranks


def _residual_cost(scene: Scene) -> tuple[float, int]:
    """Estimated time [s] and peak memory [B] of the residuals the scene asks for: the
    time summed over the lines and kinds, the memory the largest of one kind on one
    line (the kinds run one after the other, line by line, and free their
    temporaries)."""
    kinds = asked_residuals(scene.analysis.linearization)
    if not kinds:
        return 0.0, 0
    w = scene.analysis.omega.values()
    n_j, samples = _uniform_lines(w)
    half_j, half_samples = _uniform_lines(w, 2)
    in_sea = scene.sea is not None
    dim = 2 if scene.is_planar else 3
    seconds, memory = 0.0, 0
    for line in scene.lines:
        n_el = sum(int(s.elements) for s in line.segments)
        size = ResidualSize(
            elements=n_el,
            frequencies=w.size,
            channels=1 + _end_channels(line.end_a) + _end_channels(line.end_b),
            dim=dim,
            lines=n_j,
            samples=samples,
            half_lines=half_j,
            half_samples=half_samples,
        )
        on_body = any(getattr(e, "attach", None) is not None for e in (line.end_a, line.end_b))
        line_s = sum(
            k.seconds(n_el, min(n_j, _RESIDUAL_LINES), in_sea) * (k.seconds_3d if dim == 3 else 1.0)
            for k in kinds
        )
        seconds += line_s * (_BODY_RESIDUAL_FACTOR if on_body else 1.0)
        memory = max(memory, *(k.memory(size) for k in kinds))
    return seconds, memory


@dataclass(frozen=True)
class CostEstimate:
    """Estimated peak memory and time of one analysis.

    Attributes
    ----------
    memory_bytes : int
        Peak resident memory above the imported process. [B]
    seconds : float
        Wall time on the calibration machine (indicative). [s]
    operations : float
        Node·frequency·channel products of the frequency-domain arrays plus
        sample·channel products of the time series. [-]
    frequencies : int
        ``analysis.omega.count``. [-]
    nodes : int
        Finite-element nodes of all lines. [-]
    channels : int
        Input channels summed over the lines. [-]
    samples : int
        Time-series samples duration/dt (0 without time series). [-]
    bodies : int
        Bodies of the scene. [-]
    spectral_bytes : int
        Part of ``memory_bytes`` in the frequency-domain arrays. [B]
    timeseries_bytes : int
        Part of ``memory_bytes`` in the time series. [B]
    residual_bytes : int
        Part of ``memory_bytes`` in the residuals' temporaries (the largest of one
        kind on one line). [B]
    largest_line : str
        Field path of the segment with the most elements (``lines[i].segments[j].elements``).
    largest_elements : int
        Its number of elements. [-]
    """

    memory_bytes: int
    seconds: float
    operations: float
    frequencies: int
    nodes: int
    channels: int
    samples: int
    bodies: int
    spectral_bytes: int
    timeseries_bytes: int
    residual_bytes: int
    largest_line: str
    largest_elements: int

    @property
    def parameter(self) -> str:
        """The input whose reduction lowers the memory most (a field path)."""
        if self.timeseries_bytes > max(self.spectral_bytes, self.residual_bytes):
            return "analysis.timeseries.duration"
        if self.frequencies >= self.nodes:
            return "analysis.omega.count"
        return self.largest_line

    def reduce_hint(self) -> str:
        """Which inputs to reduce, largest share first (one sentence)."""
        spectral = (
            f"analysis.omega.count ({self.frequencies}) or the elements of the lines "
            f"({self.nodes} nodes; most in {self.largest_line}), memory ∝ frequencies × "
            f"nodes × channels ({self.channels})"
        )
        series = (
            f"analysis.timeseries duration/dt ({self.samples} samples) or drop analysis.timeseries"
        )
        residual = (
            f"analysis.omega.count ({self.frequencies}) or the elements of the lines "
            f"({self.nodes} nodes; most in {self.largest_line}) for the residuals' "
            "temporaries (∝ elements × "
            "frequencies, and elements² up to 400 elements), or set "
            "analysis.linearization.drag_residual / geometric_residual false"
        )
        shares = [(self.spectral_bytes, spectral)]
        if self.samples:
            shares.append((self.timeseries_bytes, series))
        if self.residual_bytes:
            shares.append((self.residual_bytes, residual))
        parts = [text for _, text in sorted(shares, key=lambda p: -p[0])]
        return "reduce " + "; then ".join(parts)

    def describe(self) -> str:
        """``estimated peak memory 3.4 TB (n_ω × nodes × channels = …)``."""
        return (
            f"estimated peak memory {_fmt_bytes(self.memory_bytes)} "
            f"({self.frequencies} frequencies × {self.nodes} nodes × channels "
            f"{self.channels}"
            + (f"; {self.samples} time-series samples" if self.samples else "")
            + (f"; residuals {_fmt_bytes(self.residual_bytes)}" if self.residual_bytes else "")
            + ")"
        )


def _fmt_bytes(n: float) -> str:
    for unit in ("B", "kB", "MB", "GB", "TB"):
        if abs(n) < 1000.0 or unit == "TB":
            return f"{n:.3g} {unit}"
        n /= 1000.0
    return f"{n:.3g} TB"  # pragma: no cover


def _end_channels(end: Any) -> int:
    """Input channels an end adds: one per end-motion spectrum DOF, three if attached."""
    n = 0
    motion = getattr(end, "motion", None)
    if motion is not None:
        n += sum(getattr(motion, dof) is not None for dof in ("surge", "sway", "heave"))
    if getattr(end, "attach", None) is not None:
        n += 3
    return n


def estimate_cost(scene: Scene | Mapping[str, Any]) -> CostEstimate:
    """Peak memory and time of ``analyze(scene)`` from the scene's sizes alone.

    Parameters
    ----------
    scene : Scene or mapping
        The scene document (validated with :func:`stochcable.load_scene` when a mapping).

    Returns
    -------
    CostEstimate
        Memory [B] and time [s] estimates and the sizes they were computed from.

    Notes
    -----
    M ≈ M_0 + n_ω Σ c_M n_nodes n_ch + c_T N_t (1 + Σ n_ch), with the constants and
    their calibration in the module docstring.  An analysis with
    ``analysis.fidelity`` runs pilot analyses of its own choosing; the estimate is that
    of the document as given.
    """
    if not isinstance(scene, Scene):
        scene = load_scene(scene, allow_files=True)
    n_w = int(scene.analysis.omega.count)
    node_channels = 0
    node_bytes = 0  # Σ_lines c_M n_nodes n_ch
    nodes = 0
    channels = 0
    largest, largest_path = -1, "lines[0].segments[0].elements"
    for i, line in enumerate(scene.lines):
        n_nodes = sum(int(s.elements) for s in line.segments) + 1
        n_ch = 1 + _end_channels(line.end_a) + _end_channels(line.end_b)
        nodes += n_nodes
        channels += n_ch
        node_channels += n_nodes * n_ch
        attached = any(getattr(e, "attach", None) is not None for e in (line.end_a, line.end_b))
        c_m = (
            BYTES_PER_NODE_FREQUENCY_CHANNEL_ATTACHED
            if attached
            else BYTES_PER_NODE_FREQUENCY_CHANNEL
        )
        node_bytes += c_m * n_nodes * n_ch
        for j, s in enumerate(line.segments):
            if s.elements > largest:
                largest, largest_path = int(s.elements), f"lines[{i}].segments[{j}].elements"
    ts = scene.analysis.timeseries
    samples = 0
    if ts is not None:
        ratio = ts.duration / ts.dt
        samples = int(round(ratio)) if ratio < 2**62 else 2**62
    spectral = n_w * node_bytes
    # the residuals' Gaussian component of each end tension: one more series per end
    # (its realization's work arrays and the component, as a channel's)
    series_channels = 1 + channels
    if asked_residuals(scene.analysis.linearization):
        series_channels += 2 * len(scene.lines)
    series = BYTES_PER_SAMPLE_CHANNEL * samples * series_channels
    n_bodies = len(scene.bodies)
    ops_spectral = float(n_w) * node_channels
    ops_series = float(samples) * series_channels
    residual_seconds, residual_bytes = _residual_cost(scene)
    seconds = (
        SECONDS_PER_NODE_FREQUENCY_CHANNEL * ops_spectral * (1.0 + _BODY_TIME_FACTOR * n_bodies)
        + SECONDS_PER_SAMPLE_CHANNEL * ops_series
        + residual_seconds
    )
    return CostEstimate(
        memory_bytes=int(BASE_BYTES + spectral + series + residual_bytes),
        seconds=seconds,
        operations=ops_spectral + ops_series,
        frequencies=n_w,
        nodes=nodes,
        channels=channels,
        samples=samples,
        bodies=n_bodies,
        spectral_bytes=int(spectral),
        timeseries_bytes=int(series),
        residual_bytes=int(residual_bytes),
        largest_line=largest_path,
        largest_elements=max(largest, 0),
    )


def check_memory(estimate: CostEstimate, limit_bytes: int, limit_name: str) -> None:
    """Raise InputError when the estimated peak memory exceeds ``limit_bytes``.

    Parameters
    ----------
    estimate : CostEstimate
        From :func:`estimate_cost`.
    limit_bytes : int
        The budget. [B]
    limit_name : str
        What the budget is, for the message (``"the available memory"``).

    Raises
    ------
    InputError
        Naming the input to reduce first (:attr:`CostEstimate.parameter`), the estimate,
        the budget and what to reduce.
    """
    if estimate.memory_bytes <= limit_bytes:
        return
    raise InputError(
        estimate.parameter,
        _value_of(estimate),
        "-",
        f"the analysis needs an {estimate.describe()}, more than {limit_name} "
        f"({_fmt_bytes(limit_bytes)}); {estimate.reduce_hint()}",
    )


def available_memory() -> int:
    """Memory the machine can give a new computation now (psutil ``available``). [B]"""
    import psutil

    return int(psutil.virtual_memory().available)


def _value_of(estimate: CostEstimate) -> int:
    p = estimate.parameter
    if p == "analysis.timeseries.duration":
        return estimate.samples
    if p == "analysis.omega.count":
        return estimate.frequencies
    return estimate.largest_elements
