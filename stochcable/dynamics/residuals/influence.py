"""The end tensions' (and other outputs') influence of unit node forces on a line, for
the residuals of the linear model: the adjoint banded solve per frequency stack
(:func:`end_influence`), or the linear solve's modal (Foss) basis with the truncated
modes' static correction on long lines (:func:`modal_influence`), kept per line and
linearization (:class:`EndInfluence`) and shared by the residual kinds, the element
tensions' stations and the node motions' (:class:`SharedRows`)."""

from __future__ import annotations

from typing import Any

import numpy as np

from stochcable.dynamics.model.blocks import add_blocks, block_matvec, line_prep, real_gemm
from stochcable.dynamics.model.modal_solvers import foss_modes
from stochcable.dynamics.residuals.band_influence import (
    BAND_STACK_BYTES,
    LineAdjoint,
    adjoint_rows,
    band_stack,
    end_coupling,
    end_directions,
    end_influence,
)
from stochcable.dynamics.residuals.modal_rows import (
    STATIC_ROWS,
    ModalRows,
    ModalSums,
    static_rows,
)
from stochcable.dynamics.solve.line_loads import drag_blocks
from stochcable.errors import SolverError
from stochcable.line.fem import SLACK_EA_RATIO

__all__ = [
    "BAND_STACK_BYTES",
    "MODAL_INFLUENCE",
    "MODAL_SHARE",
    "MODAL_SPAN",
    "ModalRows",
    "adjoint_rows",
    "EndInfluence",
    "SharedRows",
    "band_stack",
    "element_directions",
    "element_frames",
    "element_lengths",
    "element_rows",
    "end_influence",
    "geometric_feedthrough",
    "modal_influence",
    "shared_rows",
]

#: The shared end influence (:class:`EndInfluence`) taken through the linear solve's
#: modal basis where the line is solved that way (:func:`modal_influence`), not by a
#: banded solve per frequency (:func:`end_influence`). [-]
MODAL_INFLUENCE = True
#: The modes :func:`modal_influence` keeps: the linear solve's and every computed mode
#: up to this multiple of the highest residual line (the rest by their static
#: correction, whose error grows as (ω/ω_n)²). [-]
MODAL_SPAN = 4.0
#: :func:`modal_influence` is used where it keeps at most this share of the line's
#: free DOFs as modes (its cost grows with their cube: the taut wire's 38 of 38 cost
#: more than its banded solve, 6.6 against 5.3 ms; the chain's 23 of 78: 2.3 against
#: 6.9 ms). [-]
MODAL_SHARE = 0.4
#: :func:`modal_influence`'s ``cols`` for the end rows alone. [-]
ENDS = "ends"


class EndInfluence:
    """The end influence (:func:`end_influence`) of one line and drag, kept for the
    frequencies asked: a later request for some of them (the geometric residual's
    lines, every second of the drag residual's) is taken from it.

    ``extra`` (optional, ((n_nodes − 2)·d, k)): more adjoint right-hand sides (the
    element tensions' rows of :mod:`.along_line`), their rows kept beside the ends'
    (:meth:`extra_on`): the end rows alone first (on all the residual's lines), the
    extra rows where asked — through the modal basis (:func:`modal_influence`) on the
    end rows' lines up to the highest asked (:meth:`_extend`), by the banded solve on
    the lines asked, each with both sets in one factorization."""

    def __init__(self, system: Any, damping: Any, extra: np.ndarray | None = None) -> None:
        self.system = system
        self.damping = damping
        self.extra = extra
        self._kept: list[tuple[np.ndarray, np.ndarray]] = []  # (the end rows)
        self._kept_x: list[tuple[np.ndarray, np.ndarray]] = []  # (the extra rows)
        self._kept_c: dict[tuple, list] = {}  # (some extra rows, by their columns)
        self._modal = MODAL_INFLUENCE
        self._adjoint: LineAdjoint | None = None

    def adjoint(self, w: np.ndarray) -> LineAdjoint:
        """The line's banded adjoint, its factors kept (made at the first solve, the job
        all rows on ``w``)."""
        if self._adjoint is None:
            k = 2 + (0 if self.extra is None else self.extra.shape[1])
            nf = (self.system.model.n_nodes - 2) * self.system.model.dim
            self._adjoint = LineAdjoint(self.system, self.damping, w.size * nf * k)
        return self._adjoint

    @staticmethod
    def _find(kept: list, w: np.ndarray, rows: slice = slice(None)) -> np.ndarray | None:
        """The rows ``rows`` of the kept influence whose lines hold every frequency of
        ``w`` (to 1e-12 relative: the nearest line's), on them (a view where they are
        every step-th line), or None."""
        if not w.size:
            return None
        w0, w1 = float(w[0]), float(w[min(1, w.size - 1)])
        lo = hi = None
        for om, g in kept:
            if om.size == w.size and (om is w or np.array_equal(om, w)):  # (the same lines)
                return g if rows == slice(None) else g[rows]
            # w's first two frequencies on these lines first (scalars, no array pass): a
            # frequency on none of them, or w every step-th of them (the usual requests)
            i0, i1 = _nearest(om, w0), _nearest(om, w1)
            if abs(float(om[i0]) - w0) > 1e-12 * abs(w0):
                continue  # (the first frequency is on none of these lines)
            step = i1 - i0 if w.size > 1 else 1
            if step > 0 and i0 + step * (w.size - 1) < om.size:
                run = om[i0 : i0 + step * (w.size - 1) + 1 : step]
                if np.all(np.abs(run - w) <= 1e-12 * np.abs(w)):  # (as the search below)
                    g = g if rows == slice(None) else g[rows]
                    return g[..., i0 : i0 + step * (w.size - 1) + 1 : step]
            if lo is None:
                lo, hi = float(w.min()), float(w.max())
            if lo < om[0] - 1e-12 * abs(lo) or hi > om[-1] + 1e-12 * abs(hi):
                continue  # (a frequency outside these lines: none nearer than the ends')
            at = np.clip(np.searchsorted(om, w), 0, om.size - 1)
            near = np.where(np.abs(om[at - 1] - w) < np.abs(om[at] - w), at - 1, at)
            if np.all(np.abs(om[near] - w) <= 1e-12 * np.abs(w)):  # (np.allclose's test)
                g = g if rows == slice(None) else g[rows]  # (the rows first: fewer gathered)
                step = near[1] - near[0] if near.size > 1 else 1
                if step > 0 and np.array_equal(near, near[0] + step * np.arange(near.size)):
                    return g[..., near[0] : near[-1] + 1 : step]  # (a view: every step-th line)
                return g[..., near]
        return None

    def _solve(self, w: np.ndarray, extra: bool) -> None:
        g = None
        if self._modal:  # (the end rows alone first: the extra rows on the lines they need)
            part = None if extra or self.extra is None else ENDS
            g = modal_influence(self.system, self.damping, w, self.extra, part)
        if g is None:
            self._modal = False
            g = self.adjoint(w).rows(w, self.extra if extra else None)
        self._kept.append((w.copy(), g[:2]))
        if g.shape[0] > 2:
            self._kept_x.append((w.copy(), g[2:]))

    def on(self, w: np.ndarray) -> np.ndarray:
        """The influence on ``w``, shape (2, n_nodes, d, n_w). [N/N]"""
        w = np.asarray(w, dtype=float)
        g = self._find(self._kept, w)
        if g is None:
            self._solve(w, extra=False)
            g = self._kept[-1][1]
        return g

    def extra_on(self, w: np.ndarray, cols: slice = slice(None)) -> np.ndarray:
        """The ``extra`` rows ``cols`` on ``w``, shape (k, n_nodes, d, n_w). [N/N]"""
        w = np.asarray(w, dtype=float)
        g = self._find(self._kept_x, w, cols)
        if g is None and self._extend(w):
            g = self._find(self._kept_x, w, cols)
        if g is None:
            self._solve(w, extra=True)
            g = self._kept_x[-1][1][cols]
        return g

    def _extend(self, w: np.ndarray) -> bool:
        """Through the modal basis, the extra rows formed on the kept end rows' lines up
        to the highest of ``w`` where they hold all of ``w`` (the element tensions' and
        node motions' lines: the chain's 122 of 189), kept; False where they do not
        (or the line is not modal)."""
        if not self._modal or self.extra is None:
            return False
        for om, _ in self._kept:
            at = self._find([(om, np.arange(om.size))], w)  # (w's lines among om's)
            if at is None:
                continue
            top = om[: int(np.max(at)) + 1]
            g = modal_influence(self.system, self.damping, top, self.extra, slice(None))
            if g is not None:
                self._kept_x.append((top.copy(), g))
                return True
        return False

    def extra_kept(self, w: np.ndarray, cols: slice = slice(None)) -> np.ndarray | None:
        """The ``extra`` rows ``cols`` on ``w`` where they are kept, or solved by the
        modal basis (no factorization); None otherwise (the caller's own solve of its
        rows: a banded solve of all the rows where one set is asked, e.g. at a set's
        cells, costs the others' right-hand sides for nothing). [N/N]"""
        w = np.asarray(w, dtype=float)
        g = self._find(self._kept_x, w, cols)
        if g is None and self._extend(w):
            g = self._find(self._kept_x, w, cols)
        if g is not None:
            return g
        key = (cols.start, cols.stop)
        g = self._find(self._kept_c.get(key, []), w)
        if g is None and self._modal:  # (these rows alone: the misfit's own frequencies)
            g = modal_influence(self.system, self.damping, w, self.extra, cols)
            if g is None:
                return self.extra_on(w, cols)
            self._kept_c.setdefault(key, []).append((w.copy(), g))
        if g is None and self._adjoint is not None:  # (by substitution in kept factors)
            g = self._adjoint.kept_rows(w, self.extra[:, cols])
            if g is not None:
                self._kept_c.setdefault(key, []).append((w.copy(), g))
        return g

    def extra_transfer(
        self, w: np.ndarray, unit: np.ndarray, cols: slice = slice(None)
    ) -> np.ndarray | None:
        """The ``extra`` rows ``cols`` on ``w`` per unit load case ``unit`` (n_nodes, d,
        n_load), shape (k, n_load, n_w), where the banded path's kept factors hold ``w``
        and the rows are not formed yet: contracted with the loads as they are solved
        (:meth:`~.band_influence.LineAdjoint.kept_transfer`; the deep wire's node rows:
        1.6 MB never written nor transposed); None otherwise (the caller's product of
        :meth:`extra_kept`'s rows). [unit/unit]"""
        w = np.asarray(w, dtype=float)
        if self._modal or self._adjoint is None or self._find(self._kept_x, w) is not None:
            return None
        if self._find(self._kept_c.get((cols.start, cols.stop), []), w) is not None:
            return None
        return self._adjoint.kept_transfer(w, self.extra[:, cols], unit)


def _nearest(om: np.ndarray, x: float) -> int:
    """The index of the line of ``om`` (increasing) nearest ``x`` (the lower of two
    equally near), as :meth:`EndInfluence._find`'s search takes it."""
    at = min(int(np.searchsorted(om, x)), om.size - 1)
    return at - 1 if at > 0 and abs(float(om[at - 1]) - x) < abs(float(om[at]) - x) else at


class SharedRows:
    """Rows ``cols`` of a shared :class:`EndInfluence`'s ``extra`` rows as an
    ``influence`` of :func:`load_transfer` (``on(w)``): the element tensions' and the
    node motions' stations solved with the end rows (:mod:`.along_line`,
    :mod:`.along_line_motion`)."""

    def __init__(self, shared: EndInfluence, cols: slice) -> None:
        self.shared = shared
        self.cols = cols
        self.elements: np.ndarray | None = None  # (the element tensions' stations, if so)
        self._own: list[tuple[np.ndarray, np.ndarray]] = []

    def on(self, w: np.ndarray) -> np.ndarray:
        """The rows on ``w``, shape (k, n_nodes, d, n_w): the shared ones where kept
        (or modal), else these rows alone by the banded solve (kept here)."""
        w = np.asarray(w, dtype=float)
        g = self.shared.extra_kept(w, self.cols)
        if g is not None:
            return g
        g = EndInfluence._find(self._own, w)
        if g is None:
            g = self.shared.adjoint(w).rows(w, self.shared.extra[:, self.cols], ends=False)
            self._own.append((w.copy(), g))
        return g


def shared_rows(shared: Any, rhs: np.ndarray, start: int) -> SharedRows | None:
    """The :class:`SharedRows` of ``shared`` whose ``extra`` columns from ``start`` are
    ``rhs`` ((n_nodes − 2)·d, k), None where they are not (or ``shared`` has none)."""
    extra = getattr(shared, "extra", None)
    cols = slice(start, start + rhs.shape[1])
    if extra is None or extra.shape[1] < cols.stop or not np.array_equal(extra[:, cols], rhs):
        return None
    return SharedRows(shared, cols)


def modal_influence(
    system: Any,
    damping: Any,
    w: np.ndarray,
    extra: np.ndarray | None = None,
    cols: slice | str | None = None,
) -> np.ndarray | None:
    """:func:`end_influence` through the linear solve's own modal (Foss) basis: the
    kept modes' complex-mode sum plus the static correction of the truncated ones
    (Tuah 1982, §5.3), the transfer the linear response itself is solved with, its
    basis widened to every computed mode up to :data:`MODAL_SPAN` times the highest
    frequency (:func:`_influence_modes`).  Every right-hand side is a fixed vector or,
    for the end rows, g_K − ω²g_M + iωg_C (:func:`end_coupling`), so each is projected
    once and the frequencies enter through the modal denominators only: no
    factorization per frequency (the chain's 2 + 7 rows on 189 lines: 2.3 against
    6.9 ms).  Frequencies above the highest computed mode over :data:`MODAL_SPAN`
    (where not every mode is computed) by the banded solve; None where the line is not
    solved that way (the direct solver, a travelling line or a steady lift: Aᵀ ≠ A, a
    defective Foss pencil): the caller's banded solve then.  ``cols`` (a slice of the
    ``extra`` columns): those rows alone (the end rows not formed), where every ``w``
    is below the limit (None otherwise); :data:`ENDS`: the end rows alone. [N/N]"""
    if system.solver != "foss" or system.gyro is not None or system.lift is not None:
        return None
    w = np.asarray(w, dtype=float)
    om = np.asarray(system.modes.omega, dtype=float)
    n_comp = min(system.modes.shapes.shape[1], om.size)
    nf = (system.model.n_nodes - 2) * system.model.dim
    limit = np.inf if n_comp >= nf else float(om[n_comp - 1]) / MODAL_SPAN
    low = w <= limit
    kept = _influence_modes(system, line_prep(system), float(np.max(w[low], initial=0.0)))
    if MODAL_SHARE * nf < kept[0].shape[1]:  # (a short line: its banded solve is cheaper)
        return None
    if not low.any() or (isinstance(cols, slice) and not low.all()):
        return None
    if low.all():
        return _modal_rows(system, damping, w, extra, cols)
    lo = _modal_rows(system, damping, w[low], extra, cols)
    if lo is None:
        return None
    out = np.empty(lo.shape[:-1] + (w.size,), dtype=complex)
    out[..., low] = np.asarray(lo)
    out[..., ~low] = end_influence(system, damping, w[~low], None if cols == ENDS else extra)
    return out


def _modal_rows(
    system: Any,
    damping: Any,
    w: np.ndarray,
    extra: np.ndarray | None,
    cols: slice | str | None = None,
) -> ModalRows | None:
    """:func:`modal_influence` on ``w`` (all below its limit; ``cols``: those of the
    extra rows alone, or :data:`ENDS`); None for a defective Foss pencil."""
    n = system.model.n_nodes
    held = _modal_projection(system, damping, float(w[-1]) if w.size else 0.0, extra)
    if held is None:
        return None
    phi, foss, p, r, (sums, rc, ends) = held
    m = phi.shape[1]
    if cols is not None and cols != ENDS:  # (their modal sums alone, static rows sliced)
        at = range(p.shape[1] - 6)[cols]
        z = sums(w, slice(6 + at.start, 6 + at.stop), 0 if rc is None else 1)
        rows = slice(2 + at.start, 2 + at.stop)
        return ModalRows(phi, z, w, None if rc is None else rc[:, :, rows], ends[:, rows], n)
    # the modal coordinates (2 + k, m + c, n_w) (the end rows alone: 2): the end rows'
    # g_K − ω²g_M + iωg_C per ω, then the static coordinates 1, −ω², iω
    k = 2 if cols == ENDS else p.shape[1] - 4
    c = 0 if rc is None else STATIC_ROWS
    z = np.empty((k, m + c, w.size), dtype=complex)
    s = sums(w, slice(0, 6 if cols == ENDS else None))  # (6 (+ k), m, n_w)
    z[:2, :m] = s[0:2] - s[2:4] * (w * w) + s[4:6] * (1j * w)
    z[2:, :m] = s[6:]
    static_rows(np.moveaxis(z[:, m:], 1, 0), w)
    if rc is None:
        return ModalRows(phi, z, w, None, ends[:, :k], n)
    return ModalRows(phi, z, w, rc[:, :, :k], ends[:, :k], n)


def _modal_projection(
    system: Any, damping: Any, w_top: float, extra: np.ndarray | None
) -> tuple | None:
    """The frequency-independent part of :func:`_modal_rows`, kept on the line for
    its later calls with the same ``damping`` and ``extra`` (the cells' and the
    misfit's frequencies after the lines'): (Φ_f, the Foss modes, the right-hand
    sides' modal loads p (2m, 6 + k), their static corrections (n_f·d, 6 + k) or None,
    and the rows' fixed parts: the modal sums' terms (:class:`ModalSums`), the static
    rows (3, n_f·d, 2 + k) or None, ê of both ends (2, 2 + k, d)).  None for a
    defective Foss pencil."""
    prep = line_prep(system)
    phi, mh, kh = _influence_modes(system, prep, w_top)
    key = ("influence_projection", extra is None)
    held = prep.cache.get(key)
    if (
        held is not None
        and held[0] is damping
        and held[1] is extra
        and held[2][0].shape[1] >= phi.shape[1]
    ):
        return held[2]
    c = add_blocks(prep.S, drag_blocks(system, damping))
    fk = prep.cache.get("influence_foss")  # (one decomposition for both right-hand sides)
    if fk is not None and fk[0] is damping and fk[1][0].shape[1] >= phi.shape[1]:
        (phi, mh, kh), foss = fk[1], fk[2]
    else:
        ch = phi.T @ prep.free_rows(block_matvec(c, prep.nodes(phi)))
        try:
            foss = foss_modes(mh, 0.5 * (ch + ch.T), kh)
        except SolverError:
            return None
        prep.cache["influence_foss"] = (damping, (phi, mh, kh), foss)
    e_a, e_b = end_directions(system)
    g = end_coupling(system, prep, c, (e_a, e_b), None)  # (3, n_f·d, 2)
    k_x = 0 if extra is None else extra.shape[1]
    cols = np.concatenate([g[0], g[1], g[2]] + ([extra] if k_x else []), axis=1)
    real = not np.any(cols.imag)  # (real right-hand sides: real products, real static rows)
    cols = np.ascontiguousarray(cols.real if real else cols, dtype=float if real else complex)
    nf, m = phi.shape
    sign = np.ones(6 + k_x)
    sign[:6] = -1.0  # the end rows: T = ê·F_end − (A⁻¹g)ᵀF_f
    modal = phi.T @ cols if real else real_gemm(phi.T, cols)  # (m, 6 + k)
    p = (foss.weights @ modal) * sign  # (2m, 6 + k)
    r = None
    if m < nf:
        zh = np.linalg.solve(kh, modal if real else modal.view(float))
        back = phi @ zh if real else real_gemm(phi, np.ascontiguousarray(zh).view(complex))
        r = (prep.k_solve(cols) - back) * sign
    # the rows' frequency-independent parts: the modal sums' terms, the static rows
    # (r₀, r₁, r₂; the end rows' three, the others' r₀) and ê of both ends
    rc = None
    if r is not None:
        rc = np.zeros((3, nf, 2 + k_x), dtype=r.dtype)
        rc[:, :, :2] = np.stack([r[:, 0:2], r[:, 2:4], r[:, 4:6]])
        rc[0, :, 2:] = r[:, 6:]
    d = system.model.dim
    ends = np.zeros((2, 2 + k_x, d))
    ends[0, 0], ends[1, 1] = e_a, e_b
    out = (phi, foss, p, r, (ModalSums(foss.chi, p, foss.lambdas), rc, ends))
    prep.cache[key] = (damping, extra, out)
    return out


def _influence_modes(
    system: Any, prep: Any, w_top: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(Φ_f, M̂, K̂) of the modes :func:`modal_influence` keeps: the linear solve's, and
    every computed mode up to :data:`MODAL_SPAN` times the highest frequency asked."""
    om = np.asarray(system.modes.omega, dtype=float)
    m = max(int(system.n_modes), int(np.count_nonzero(om <= MODAL_SPAN * w_top)))
    m = min(m, system.modes.shapes.shape[1], (system.model.n_nodes - 2) * system.model.dim)
    return prep.modal(system, m)


def element_directions(system: Any) -> list[np.ndarray]:
    """The element tangent and the normals the line's model moves along, each (n_el, 3):
    (t, n) with n the normal in the plane of a planar model (t × the out-of-plane
    axis), (t, n₁, n₂) in 3-D."""
    t, n1, n2 = system.frames
    comps = list(system.model.components)
    if len(comps) == 3:
        return [t, n1, n2]
    plane = np.zeros(3)
    plane[[i for i in range(3) if i not in comps][0]] = 1.0
    normal = np.cross(plane, t)
    return [t, normal / np.linalg.norm(normal, axis=1)[:, None]]


def element_rows(model: Any) -> np.ndarray:
    """The element tension rows (n_el, 2, d): δT_e = rows[e, 0]·u_e + rows[e, 1]·u_{e+1}
    (as :func:`stochcable.dynamics.outputs.line_result.element_tension_transfer`). [N/m]"""
    rows = model.tension_rows
    if rows is None:
        ea = np.where(model.slack, SLACK_EA_RATIO * model.mesh.ea, model.mesh.ea)
        t = model.tangents * (ea / model.l0)[:, None]
        rows = np.stack([-t, t], axis=1)
    return np.asarray(rows, dtype=float)


def element_lengths(system: Any) -> tuple[np.ndarray, np.ndarray]:
    """The static length l and the unstretched length L₀ of each element (n_el each) as
    the geometric residual takes them: the chord, and for the element the linear model
    splits at the static touchdown (:attr:`stochcable.line.fem.FEModel.bed`) its
    suspended part's share 1 − ξ of each. [m]"""
    model = system.model
    length = np.linalg.norm(np.diff(np.asarray(system.positions, dtype=float), axis=0), axis=1)
    l0 = np.array(model.mesh.l0, dtype=float)
    bed = getattr(model, "bed", None)
    if bed is not None and bed.element is not None:
        length[bed.element] *= 1.0 - bed.fraction
        l0[bed.element] *= 1.0 - bed.fraction
    return length, l0


def element_frames(system: Any) -> list[np.ndarray]:
    """:func:`element_directions` with the element split at the static touchdown
    (:attr:`stochcable.line.fem.FEModel.bed`) along its suspended part: its tangent, the
    normals made normal to it (Gram–Schmidt)."""
    frames = element_directions(system)
    bed = getattr(system.model, "bed", None)
    if bed is None or bed.element is None:
        return frames
    k = bed.element
    frames = [f.copy() for f in frames]
    frames[0][k] = 0.0
    frames[0][k, list(system.model.components)] = bed.sub_tangents[1]
    for j in range(1, len(frames)):
        n = frames[j][k] - sum((frames[i][k] @ frames[j][k]) * frames[i][k] for i in range(j))
        frames[j][k] = n / np.linalg.norm(n)
    return frames


def geometric_feedthrough(system: Any, n_all: int) -> np.ndarray:
    """Each element tension per unit of the geometric residual's components (its
    :func:`~stochcable.dynamics.residuals.residual_lines.load_transfer` columns,
    component-major: ½|b_e|² first), shape (n_el, n_all).
    [N/m]

    To second order the stretch of element e is a + |b|²/(2l) (|ℓ| = |l·t + Δu|, Δu =
    a·t + b): the linear model's tension (EA/L₀)·a (the rows of
    :func:`element_rows`) misses (EA/L₀)·½|b|²/l, the element's own share of the
    quadratic force κ·½|b|² it applies as a node pair (the pair's response through
    the line, r_e·A⁻¹F, is the rest).  The products a·b_k do not stretch it.  The
    element split at the touchdown: its suspended part's, l and L₀ those of
    :func:`element_lengths` (its row's norm is not EA/L₀: it holds the split node's
    motion too)."""
    model = system.model
    stiff = np.linalg.norm(element_rows(model)[:, 1], axis=1)
    length, l0 = element_lengths(system)
    n_el = stiff.size
    out = np.zeros((n_el, n_all))
    el = np.arange(n_el)
    bed = getattr(model, "bed", None)
    if bed is not None and bed.element is not None:
        k, d, comps = bed.element, model.dim, list(model.components)
        ea = float(np.asarray(model.mesh.ea, dtype=float)[k])
        stiff[k] = ea / l0[k]
        # the pair's − on the massless split node t moves it by K_tt⁻¹F_t besides
        # R·u_ab: (EA/L₀)e_s·K_tt⁻¹ = (R_b e_s)ᵀ (R_b = K_tt⁻¹k_b, k_b e_s = (EA/L₀)e_s)
        kappa = (stiff[k] - float(system.statics.tension[k]) / length[k]) / length[k]
        r_e = np.asarray(bed.transform, dtype=float)[d : 2 * d, d:] @ bed.sub_tangents[1]
        for i, f in enumerate(element_frames(system)):
            out[k, i * n_el + k] += kappa * (r_e @ f[k, comps])
    out[el, el] -= stiff / length
    return out
