"""The coarse start of the coupled drag fixed point (:mod:`stochcable.dynamics.groups.
fixedpoint`).

On a grid of at least ``COARSE_MIN_FREQUENCIES`` points the iteration first runs on
a frequency subset G (every ``COARSE_STRIDE``-th frequency and the last) to
``COARSE_TOLERANCE_FACTOR`` times the tolerance.  The σ integrals on the subset are
the full grid's trapezoid rule on the cubic interpolant of the integrand
(:func:`stochcable.dynamics.linearization.coarse_grid.interpolatory_weights`, as the single-line
coarse start of :mod:`stochcable.dynamics`); subset frequencies whose σ weight is at most
``COARSE_NEGLIGIBLE`` (1e-12) of the largest in every channel (the spectrum's empty
tail) are then left out (their σ contributions are below round-off).  A Foss line
solves its modal equations per frequency there
(:class:`~stochcable.dynamics.groups.modal_parts.ModalLine`: the same modal system, no
Foss eigenproblem).  Then, at the coarse map's last input x, one full-grid evaluation
F(x); while its relative change exceeds the tolerance, a defect correction: the
coarse map scaled by the ratio r = F(x)/G(x) (per component, clipped to [0.1, 10])
reproduces F at x, and its fixed point is the next full-grid point.  Each round first
takes one step of the corrected map from the Anderson extrapolation
(:func:`_warm_step`) of the last ``_WARM_MEMORY`` coarse secant pairs; when that
step's change is within a tenth of the full-grid change it is the next full-grid
point, else the corrected map is iterated from it (coarse evaluations) to 0.5 % of
the full-grid change.  At most ``COARSE_CORRECTIONS`` rounds, a round that does not
contract the full-grid change by 0.3 hands over to the plain full-grid iteration.
The usual convergence test on the full grid ends the iteration, so the answer is
the full-grid fixed point (tested equal within the tolerance to ``coarse=False``);
the coarse model only moves the start (what it saves: docs/benchmarks/dynamics.md,
"Coarse start of the drag fixed point").  The
record's ``iterations`` and ``history`` list every evaluation in order, coarse and
full.  Used by default under both solvers when the tolerance is at least
``COARSE_MIN_TOLERANCE`` (tighter: the coarse stage's 1e-6 floor and slower rounds
make it cost more than it saves).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from stochcable.dynamics.groups.fixed_point_state import EvaluationCount, FixedPointRun
from stochcable.dynamics.groups.group import GroupSystem, SigmaMap
from stochcable.dynamics.groups.inputs import BodyLoads, CoupledLine
from stochcable.dynamics.linearization.coarse_grid import interpolatory_weights, subset_inputs
from stochcable.dynamics.linearization.iteration import relative_change
from stochcable.dynamics.linearization.variance import (
    drag_coefficients,
    end_motion_projections,
    fluid_terms,
)
from stochcable.dynamics.loads.channels import Channel
from stochcable.dynamics.model.blocks import add_blocks, block_matvec, line_prep
from stochcable.dynamics.solve.line_loads import attached_velocity, drag_blocks
from stochcable.errors import ConvergenceError, SolverError

__all__ = [
    "COARSE_CORRECTIONS",
    "COARSE_MAX_FRACTION",
    "COARSE_MIN_FREQUENCIES",
    "COARSE_MIN_TOLERANCE",
    "COARSE_NEGLIGIBLE",
    "COARSE_STRIDE",
    "COARSE_TOLERANCE_FACTOR",
    "CoarseStart",
    "coarse_group",
    "coarse_subset",
    "full_grid_arrays",
    "narrow_features",
    "uniform_subset",
]

#: Errors of a coarse model that hand over to the full grid alone (its checks).
_COARSE_FAILURES = (SolverError, ConvergenceError, np.linalg.LinAlgError)

#: Coarse start: every COARSE_STRIDE-th frequency and the last, used when the grid
#: has at least COARSE_MIN_FREQUENCIES points; the coarse iteration stops at
#: COARSE_TOLERANCE_FACTOR times the linearization tolerance (at least 1e-6).
COARSE_STRIDE = 4
COARSE_MIN_FREQUENCIES = 64
COARSE_TOLERANCE_FACTOR = 0.25
#: Default coarse start for linearization tolerances at least this (tighter ones: the
#: coarse iterations stall at their 1e-6 floor and the rounds contract less; on the
#: test mooring 1e-7 needed 6 full + 15 coarse evaluations against 8 full).
COARSE_MIN_TOLERANCE = 1e-6
#: Defect-correction rounds of the coarse start (coarse fixed point of the corrected
#: map, then one full-grid evaluation) before the plain full-grid iteration.
COARSE_CORRECTIONS = 3
#: Coarse frequencies whose σ weight (quadrature weight × spectrum) is at most this
#: fraction of the largest in every channel are left out of the coarse evaluations
#: (their σ contributions are below the coarse stage's round-off).
COARSE_NEGLIGIBLE = 1e-12


#: A group without bodies: the coarse stage is skipped when its subset, refined around
#: the narrow features (:func:`coarse_subset`), holds more than this fraction of the
#: grid (many narrow resonances: the full grid alone is cheaper; the inclined guy).
COARSE_MAX_FRACTION = 0.35


def coarse_subset(
    g: GroupSystem, x_rest: np.ndarray | None = None, method: str = "seed"
) -> np.ndarray | None:
    """Indices of the coarse-start grid.

    Parameters
    ----------
    g : GroupSystem
        Its ``sizes`` set when ``x_rest`` is given.
    x_rest : ndarray, optional
        The at-rest σ of the fixed point (the starting drag of the narrow-feature
        test of a group without bodies). [m/s]
    method : str, optional
        Drag linearization method (of ``x_rest``).

    Returns
    -------
    ndarray of int or None
        Every ``COARSE_STRIDE``-th frequency and the last; None when the grid has
        fewer than ``COARSE_MIN_FREQUENCIES`` points or the subset is not below 3/4
        of it.  A group without bodies (a line alone) also keeps ± ``COARSE_STRIDE``
        points around its narrow features (:func:`narrow_features`) and is None
        above ``COARSE_MAX_FRACTION`` of the grid.

    Notes
    -----
    The narrow-feature refinement needs the group's modes and their damping: for a
    group without bodies they are the line's fixed-end modes (``system.modes``); a
    group with bodies keeps the uniform subset and relies on the defect correction
    (its coupled modes would be the ones to test).
    """
    n = g.omega.size
    if n < COARSE_MIN_FREQUENCIES:
        return None
    keep = np.zeros(n, dtype=bool)
    keep[::COARSE_STRIDE] = True
    keep[-1] = True
    if g.bodies or x_rest is None:
        idx = np.flatnonzero(keep)
        return idx if idx.size < 0.75 * n else None
    centers = narrow_features(g, x_rest, method)
    if centers.size:
        span = centers[:, None] + np.arange(-COARSE_STRIDE, COARSE_STRIDE + 1)
        keep[np.clip(span, 0, n - 1).ravel()] = True
    idx = np.flatnonzero(keep)
    return idx if idx.size <= COARSE_MAX_FRACTION * n else None


def narrow_features(g: GroupSystem, x_rest: np.ndarray, method: str) -> np.ndarray:
    """Grid indices of the features of a group without bodies that the stride-
    ``COARSE_STRIDE`` subset cannot resolve: half-power band narrower than two coarse
    spacings.

    Parameters
    ----------
    g : GroupSystem
        Without bodies; ``sizes`` set.
    x_rest : ndarray
        The at-rest σ (the starting drag). [m/s]
    method : str
        Drag linearization method.

    Returns
    -------
    ndarray of int
        The peak of each channel spectrum whose band S_i >= S_i,max/2 is narrow, and
        the grid point nearest each natural frequency inside the grid whose
        bandwidth 2ζ_jω_j = φ_jᵀCφ_j (mass-normalized φ_j, C the structural damping
        plus the starting drag, :func:`stochcable.dynamics.outputs.indicators.
        modal_bandwidths` of the modes inside) is narrow.
    """
    w = g.omega
    n = w.size
    spacing = COARSE_STRIDE * np.gradient(w)
    centers = []
    spectra = np.stack([c.spectrum for c in g.channels], axis=1)
    for s_i in spectra.T:  # channels: is the half-power band of the peak narrow?
        k = int(np.argmax(s_i))
        if s_i[k] <= 0:
            continue
        low = s_i < 0.5 * s_i[k]
        lo = k - int(np.argmax(low[k::-1])) if np.any(low[: k + 1]) else 0
        hi = k + int(np.argmax(low[k:])) if np.any(low[k:]) else n - 1
        if w[hi] - w[lo] < 2.0 * spacing[k]:
            centers.append(np.array([k]))
    sigmas, _ = g.split(x_rest)
    drag = {}
    g.start_drag = (x_rest, drag)  # the first evaluation at x_rest reuses them
    for cl in g.lines:
        wn = np.asarray(cl.system.modes.omega)
        inside = np.flatnonzero((wn > w[0]) & (wn < w[-1]))
        system = cl.system
        if not inside.size:
            drag[cl.name] = drag_coefficients(system, sigmas[cl.name], method)
            continue
        damping = drag[cl.name] = drag_coefficients(system, sigmas[cl.name], method)
        prep = line_prep(system)
        c = add_blocks(prep.S, drag_blocks(system, damping))
        phi = system.modes.shapes[system.model.free][:, inside]
        band = np.einsum("ij,ij->j", phi, prep.free_rows(block_matvec(c, prep.nodes(phi))))
        near = np.clip(np.searchsorted(w, wn[inside]), 1, n - 1)
        near -= (wn[inside] - w[near - 1]) < (w[near] - wn[inside])  # nearest point
        centers.append(near[band < 2.0 * spacing[near]])
    return np.concatenate(centers) if centers else np.zeros(0, dtype=int)


#: Defect-correction rounds start with the warm step (:func:`_warm_step`) over the
#: last _WARM_MEMORY coarse evaluations (3: on the benchmark 1 coarse evaluation per
#: round instead of 3; 4 was worse there, docs/BENCHMARKS.md pass E5).
_WARM_ROUNDS = True
_WARM_MEMORY = 3


def _warm_step(pairs: Sequence[tuple[np.ndarray, np.ndarray]], ratio: np.ndarray) -> np.ndarray:
    """Anderson step (type II, unmixed) of the corrected coarse map y -> r·G(y) from
    its secant pairs: the coarse evaluations (x_j, G(x_j)), the last at the current
    full-grid point. [m/s]"""
    x = np.array([p[0] for p in pairs]).T
    res = np.array([ratio * p[1] - p[0] for p in pairs]).T
    f = res[:, -1]
    step = x[:, -1] + f
    if x.shape[1] > 1:
        dx, dr = np.diff(x, axis=1), np.diff(res, axis=1)
        gamma, *_ = np.linalg.lstsq(dr, f, rcond=1e-12)
        step = step - (dx + dr) @ gamma
    return np.maximum(step, 0.0)


def uniform_subset(n: int) -> np.ndarray:
    """Every ``COARSE_STRIDE``-th index of ``range(n)`` and the last."""
    return np.unique(np.r_[np.arange(0, n, COARSE_STRIDE), n - 1])


def full_grid_arrays(g: GroupSystem, method: str) -> None:
    """The full grid's drag-independent arrays of the σ map of each line without
    attached ends (end-motion projections, attachment velocities, fluid terms: its full-grid
    evaluations need them anyway), computed before a coarse group slices them
    (:func:`~stochcable.dynamics.linearization.coarse_grid.subset_inputs`) instead of computing
    its own."""
    for cl in g.lines:
        if not cl.attached():
            inp = g.inp_phys[cl.name]
            end_motion_projections(cl.system, inp, method)
            attached_velocity(cl.system, line_prep(cl.system), inp)
            fluid_terms(cl.system, inp, method)


def coarse_group(g: GroupSystem, idx: np.ndarray) -> GroupSystem:
    """The group on the frequencies ``g.omega[idx]``: σ integrals by the full grid's
    trapezoid rule on the subset's cubic interpolant
    (:func:`stochcable.dynamics.linearization.coarse_grid.interpolatory_weights`), the
    lines' inputs sliced from the full grid's
    (:func:`stochcable.dynamics.linearization.coarse_grid.subset_inputs`), Foss lines
    solved per frequency in modal coordinates
    (:class:`~stochcable.dynamics.groups.modal_parts.ModalLine`); the frequencies of negligible
    σ weight (``COARSE_NEGLIGIBLE``) left out after the weights are formed."""
    spectra = np.stack([c.spectrum for c in g.channels], axis=1)[idx]
    quadrature = interpolatory_weights(g.omega, idx)
    weights = quadrature[:, None] * spectra
    # frequencies whose σ weight is negligible in every channel (the spectrum's empty
    # tail) are dropped after the weights are formed: the other weights, the mean
    # squares and the inputs stay those of the interpolant on ``idx``
    ref = np.max(np.abs(weights), axis=0, initial=0.0)
    keep = np.flatnonzero(np.any(np.abs(weights) > COARSE_NEGLIGIBLE * ref, axis=1))
    if not 4 <= keep.size < idx.size:
        keep = None
    inp = {
        cl.name: subset_inputs(
            cl.system, tuple(cl.channels), g.inp_phys[cl.name], idx, keep, quadrature
        )
        for cl in g.lines
    }
    if keep is not None:
        idx, weights = idx[keep], weights[keep]
    gc = GroupSystem(
        [_sliced_line(cl, idx) for cl in g.lines],
        g.bodies,
        {k: _sliced_loads(v, idx) for k, v in g.loads.items()},
        g.rho,
        [_sliced_channel(c, idx, light=True) for c in g.channels],
        inp_phys=inp,
        weights=weights,
    )
    gc.sizes = g.sizes
    gc.start_drag = g.start_drag
    gc.modal_direct = True
    return gc


_CHANNEL_ARRAYS = (
    "velocity",
    "acceleration",
    "motion_a",
    "motion_b",
    "element_velocity",
    "element_velocity_square",
    "element_square",
    "element_velocity_parts",
    "element_ends",
    "element_end_square",
)
_NODAL_ARRAYS = ("velocity", "acceleration")


def _sliced_channel(c: Channel, idx: np.ndarray, light: bool = False) -> Channel:
    """The channel on the frequencies ``omega[idx]`` (every array's first axis);
    ``light``: its name, grid and spectrum alone (the group's channel list and a line
    without attached ends, whose coarse solve reads its sliced inputs only).

    Nodal kinematics computed on first use (a channel with ``nodal``, the sea
    channel of :func:`stochcable.dynamics.loads.channels.line_channels`) stay lazy: the sliced
    channel's ``nodal`` slices the full channel's on first access (the coarse stage
    never reads them; slicing them eagerly computed them on the full grid, ≈ 0.4 ms
    per line, docs/BENCHMARKS.md pass E5c)."""
    if light:
        return Channel(
            name=c.name,
            kind=c.kind,
            omega=c.omega[idx],
            spectrum=c.spectrum[idx],
            density=c.density,
        )
    lazy = c.nodal is not None
    kw: dict[str, Any] = {
        k: getattr(c, k)[idx]
        for k in _CHANNEL_ARRAYS
        if not (lazy and k in _NODAL_ARRAYS) and getattr(c, k) is not None
    }
    if lazy:

        def nodal() -> tuple[np.ndarray | None, np.ndarray | None]:
            v, a = c.velocity, c.acceleration
            return (None if v is None else v[idx], None if a is None else a[idx])

        kw.update(velocity=None, acceleration=None, nodal=nodal)
    return dataclasses.replace(c, omega=c.omega[idx], spectrum=c.spectrum[idx], **kw)


def _sliced_line(cl: CoupledLine, idx: np.ndarray) -> CoupledLine:
    light = not cl.attached()  # no unit channels to build from its channels
    return dataclasses.replace(
        cl, channels=tuple(_sliced_channel(c, idx, light) for c in cl.channels)
    )


def _sliced_loads(ld: BodyLoads, idx: np.ndarray) -> BodyLoads:
    return BodyLoads(force=ld.force[idx], velocity=ld.velocity[idx], current=ld.current)


class CoarseStart:
    """The coarse stage of a group's fixed point: the coarse map, its start and the
    defect-correction rounds (module docstring).

    Parameters
    ----------
    g : GroupSystem
        The full-grid group (``sizes`` set).
    idx : ndarray of int
        The coarse subset (:func:`coarse_subset`).
    run : FixedPointRun
        The fixed point's method, density, progress, settings and name.
    count : EvaluationCount
        The record shared with the full-grid map (evaluation count, last change).
    group : GroupSystem, optional
        The coarse group on ``idx`` when already built (:func:`coarse_group`).

    Attributes
    ----------
    history : tuple of float
        The relative changes of the coarse evaluations and of the full-grid
        evaluations made inside the rounds, in order.
    """

    def __init__(
        self,
        g: GroupSystem,
        idx: np.ndarray,
        run: FixedPointRun,
        count: EvaluationCount,
        group: GroupSystem | None = None,
    ) -> None:
        full_grid_arrays(g, run.method)
        gc = coarse_group(g, idx) if group is None else group
        # the coarse map keeps no evaluation (its last response): the stage reads its
        # σ only, and the full grid's evaluations run beside it
        self.raw: SigmaMap | None = SigmaMap(
            gc, run.method, run.rho, count, run.progress, run.names, None, keep_last=False
        )
        self.run, self.count = run, count
        self.lin, self.gname = run.lin, run.gname
        # the coarse model is only good to its defect: no tighter than 1e-6 (round-off
        # noise of the σ stalls tighter coarse iterations; the full grid finishes)
        self.tol = max(run.lin.tolerance * COARSE_TOLERANCE_FACTOR, 1e-6)
        self.last: dict[str, np.ndarray] = {}
        self.pairs: list[tuple[np.ndarray, np.ndarray]] = []
        self.history: tuple[float, ...] = ()

    def __call__(self, y: np.ndarray) -> np.ndarray:
        """The coarse map, remembering its inputs and outputs."""
        if self.raw is None:
            raise RuntimeError("the coarse stage is over: its map is released")
        out = self.raw(y)
        self.last["x"], self.last["g"] = np.array(y, dtype=float), out
        self.pairs.append((self.last["x"], out))
        return out

    def start(self, x_rest: np.ndarray) -> np.ndarray | None:
        """The coarse fixed point from the rest start: the full grid's start (the
        coarse map's last input, whose coarse response is known), None when the
        coarse model failed (singular or non-finite: the full grid alone)."""
        lin = self.lin
        try:
            xc = self(x_rest)
            hc: tuple[float, ...] = (self.count.change,)
            if np.all(np.isfinite(xc)) and hc[0] > self.tol:
                fc = self.run.iterate(
                    self,
                    xc,
                    tol=self.tol,
                    max_iterations=lin.max_iterations,
                    allow_unconverged=True,
                    name=self.gname + " (coarse start)",
                )
                hc = hc + tuple(fc.history)
            ok = bool(np.all(np.isfinite(self.last["g"])))
        except _COARSE_FAILURES:
            ok = False
        if not ok:
            return None
        self.history = hc
        return self.last["x"]

    def correct(
        self,
        update: Callable[[np.ndarray], np.ndarray],
        x0: np.ndarray,
        change0: float,
    ) -> tuple[np.ndarray, float, int]:
        """The defect-correction rounds after the first full-grid evaluation.

        Parameters
        ----------
        update : callable
            The full-grid map (sharing :attr:`count`: its ``change`` after each
            evaluation).
        x0 : ndarray
            The full-grid map's output at the coarse start. [m/s]
        change0 : float
            Its relative change. [-]

        Returns
        -------
        (x0, change0, rounds)
            The last full-grid output, its relative change and the rounds made.
        """
        lin = self.lin
        x_full = self.last["x"]
        rounds = 0
        while (
            rounds < COARSE_CORRECTIONS
            and np.all(np.isfinite(x0))
            and change0 > lin.tolerance
            and rounds + 2 < lin.max_iterations
        ):
            try:
                x_next, hist = self._round(x_full, x0, change0)
            except _COARSE_FAILURES:
                break
            if not (np.all(np.isfinite(self.last["g"])) and np.all(np.isfinite(x_next))):
                break
            self.history = self.history + (change0,) + hist
            rounds += 1
            x_full = x_next
            x0 = update(x_full)
            prev, change0 = change0, self.count.change
            if change0 > 0.3 * prev:  # not contracting: the plain full-grid iteration
                break
        # the full grid finishes: the coarse group and its arrays are not needed again
        self.raw = None
        self.pairs.clear()
        return x0, change0, rounds

    def _round(
        self, x_full: np.ndarray, x0: np.ndarray, change0: float
    ) -> tuple[np.ndarray, tuple[float, ...]]:
        """One round: the coarse map scaled by the full/coarse ratio at the last
        full-grid point ``x_full`` (output ``x0``) has that point's full-grid
        response; its fixed point (coarse evaluations) is the next full-grid point.
        Returns it and the round's coarse changes."""
        last = self.last
        if x_full is not last["x"]:
            # the coarse response at the last full-grid point (warm rounds)
            self(x_full)
            self.history = self.history + (self.count.change,)
            last["x"] = x_full
        g_in = last["g"]
        ratio = np.clip(np.divide(x0, g_in, out=np.ones_like(x0), where=g_in > 0), 0.1, 10.0)
        tol_r = max(self.tol, 0.005 * change0)
        hist: tuple[float, ...] = ()
        start = x0
        if _WARM_ROUNDS and len(self.pairs) > 1:
            # one step of the corrected map from the Anderson extrapolation of the
            # last coarse secant pairs (its Jacobian is the coarse one, scaled);
            # accepted when it moved the corrected map 10x closer than the
            # full-grid change, else its result starts the corrected iteration
            y0 = _warm_step(self.pairs[-_WARM_MEMORY:], ratio)
            h = ratio * self(y0)
            hist = (relative_change(h, y0),)
            start = h
        if hist and hist[0] <= max(tol_r, 0.1 * change0):
            return h, hist
        fc = self.run.iterate(
            lambda y, r=ratio: r * self(y),
            start,
            tol=tol_r,
            max_iterations=self.lin.max_iterations,
            allow_unconverged=True,
            name=self.gname + " (coarse correction)",
        )
        return last["x"], hist + fc.history
