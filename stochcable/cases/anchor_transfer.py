"""The interpolated corrections of one heading of a load-case set with adaptive residual
anchors (:mod:`stochcable.cases.residual_anchors`): each column's ratios at any Hs from
its computed cases, and a column without computed cases' linearly in the period from
its neighbours'.

A column (one period and heading) interpolates its ratios in Hs between its computed
cases by the power law of :func:`~stochcable.cases.anchor_layout.correction_rows` —
its *own* curve.  Where the corrections bend along a column but vary smoothly from one
period to the next (Tuah's single leg: its end σ correction rises from +5 % at Hs 1 m
to +12 % at 4 m and falls again, and a power law between computed Hs one step apart
misses σ, Tz and damage ratios by 3e-3 … 8e-3, where linear in Tp between periods
1 s apart misses by 3.5e-3 at most), a column can borrow the shape of its
*parents* instead: the two columns whose middle it is in the bisection of the
heading's periods (:meth:`HeadingCurves.parents`; the shortest and longest period
have none).  Its *transferred* curve is its parents' curves interpolated to its
period — quadratic in the period through them and the other end of the interval
whose middle one of them is, where there is one, else linear between them — the
*base*, which carries the bend, plus its own departure from the base at its computed
Hs, interpolated linearly in Hs (constant beyond them): what a column adds to its
parents is nearly linear in Hs, so it needs a few computed Hs instead of all (Tuah,
Tp 6–15 s every 1 s: 47 of 100 cases computed instead of 91,
docs/benchmarks/cases.md).  A third curve interpolates the end
tensions' residual moments instead of their ratios
(:mod:`stochcable.cases.anchor_moments`: where the linear response bends with Hs and
the residuals do not, the taut wire near resonance).  Each column takes the curve —
its ratios', its moments', or the transferred one (not the shortest and longest
period's) — that meets the middle of its first three computed Hs (smallest, middle,
largest: always computed together) best from the other two.  The checks in Hs of
:func:`~stochcable.cases.residual_anchors.next_anchors` test the curve a column uses,
so the error is measured on what is interpolated; a parent's curve may itself be
transferred (from its own parents, up to the heading's shortest and longest periods).
Everything depends on the computed numbers only.
"""

from __future__ import annotations

import numpy as np

from stochcable.cases.anchor_layout import Column, correction_rows
from stochcable.cases.anchor_moments import MomentCoordinates, power_rows

__all__ = ["HeadingCurves"]


class HeadingCurves:
    """The ratios of one heading's columns (module notes).

    Parameters
    ----------
    cols : list of Column
        The heading's columns, ordered by period.
    ok : ndarray of bool, shape (n,)
        Whether a case's residuals were computed (and it has a response).
    r : ndarray, shape (n, q)
        The cases' ratios (:func:`~stochcable.cases.anchor_layout.check_ratios`). [-]
    scale : ndarray, shape (n, q)
        Each case's ratios' tolerances in units of σ's. [-]
    law : str
        "power" (the adaptive anchors': each column's curve chosen, :meth:`column_law`)
        or "hs2" (the fixed anchors': the ratios linear in Hs² only).
    moments : MomentCoordinates, optional
        The ratios in the residual moments' coordinates (without: no column of
        moments).

    Curves are kept per column and Hs once formed: an instance serves one set of
    computed cases (``ok``, ``r``).
    """

    def __init__(
        self,
        cols: list[Column],
        ok: np.ndarray,
        r: np.ndarray,
        scale: np.ndarray,
        law: str,
        moments: MomentCoordinates | None = None,
    ) -> None:
        self.cols, self.ok, self.r, self.scale, self.law = cols, ok, r, scale, law
        self.moments = moments if law == "power" else None
        n = len(cols)
        # (columns that never transfer: every one for the fixed anchors)
        self.own = set(range(n)) if law != "power" else {0, n - 1}
        self._anchors = [c.anchors(ok) for c in cols]
        self._laws: dict[int, str] = {}
        self._curves: dict[tuple[int, float, bool], np.ndarray | None] = {}

    def has(self, j: int) -> bool:
        """Whether column ``j`` has computed cases."""
        return bool(self._anchors[j][1].size)

    def parents(self, j: int) -> tuple[int, int] | None:
        """The ends of the interval of columns whose middle ``j`` is in the bisection
        of the heading's periods (:func:`~stochcable.cases.residual_anchors.next_anchors`);
        None for the shortest and longest period."""
        a, b = 0, len(self.cols) - 1
        while b - a >= 2:
            m = (a + b) // 2
            if m == j:
                return a, b
            a, b = (a, m) if j < m else (m, b)
        return None

    def base(self, j: int, hs: float) -> np.ndarray | None:
        """The curves of column ``j``'s parents (:meth:`parents`) at ``hs`` [m],
        quadratic in the period through them and the other end of the interval whose
        middle one of them is (j lies between the parents, so this interpolates);
        linear between the parents where there is no such column or its computed Hs
        do not reach over j's (None: a root, or a parent whose computed Hs do not)."""
        p = self.parents(j)
        if p is None or not (self._covers(p[0], j) and self._covers(p[1], j)):
            return None
        a, b = p
        third = None
        for x in (a, b):
            up = self.parents(x)
            if up is not None:
                third = next((y for y in up if y not in (a, b)), third)
        c = None if third is None or not self._covers(third, j) else self.curve(third, hs)
        if c is None:
            return self.between(a, b, j, hs)
        ra, rb = self.curve(a, hs), self.curve(b, hs)
        if ra is None or rb is None:
            return None
        t = [self.cols[k].period for k in (a, b, third)]
        x = self.cols[j].period
        w = [
            (x - t[1]) * (x - t[2]) / ((t[0] - t[1]) * (t[0] - t[2])),
            (x - t[0]) * (x - t[2]) / ((t[1] - t[0]) * (t[1] - t[2])),
            (x - t[0]) * (x - t[1]) / ((t[2] - t[0]) * (t[2] - t[1])),
        ]
        return w[0] * ra + w[1] * rb + w[2] * c

    def _covers(self, k: int, j: int) -> bool:
        """Whether column ``k``'s computed Hs reach over column ``j``'s Hs (no curve is
        extrapolated into a base)."""
        h = self._anchors[k][0]
        col = self.cols[j]
        return bool(h.size) and h[0] <= col.hs[0] and h[-1] >= col.hs[-1]

    def _departure(self, j: int, hs: float, at: np.ndarray, idx: np.ndarray) -> np.ndarray:
        """The base at ``hs`` plus column ``j``'s departures from it at the Hs ``at``
        (its cases ``idx``), linear in Hs between them (constant beyond)."""
        dep = np.array([self.r[i] - self.base(j, float(h)) for h, i in zip(at, idx)])
        k = int(np.clip(np.searchsorted(at, hs, side="right") - 1, 0, max(at.size - 2, 0)))
        if at.size == 1 or hs <= at[0]:
            d = dep[0]
        elif hs >= at[-1]:
            d = dep[-1]
        else:
            t = (hs - at[k]) / (at[k + 1] - at[k])
            d = (1.0 - t) * dep[k] + t * dep[k + 1]
        return self.base(j, hs) + d

    def transferred(self, j: int) -> bool:
        """Whether column ``j`` uses the transferred curve (module notes)."""
        return self.column_law(j) == "transfer"

    def column_law(self, j: int) -> str:
        """The curve column ``j`` uses: "ratios" (its own, of the ratios), "moments"
        (its own, of the end tensions' residual moments,
        :mod:`stochcable.cases.anchor_moments`) or "transfer" (module notes)."""
        if j not in self._laws:
            self._laws[j] = self._choose(j)
        return self._laws[j]

    def _choose(self, j: int) -> str:
        """The law that meets column ``j``'s middle computed Hs of its first three
        best from the other two (ties: the earlier of ratios, moments, transfer)."""
        col = self.cols[j]
        n = len(col.hs)
        if self.law != "power" or n < 3:
            return "ratios"
        k = (0, (n - 1) // 2, n - 1)
        first = [col.members[x][0] for x in k]
        if not all(self.ok[i] for i in first):
            return "ratios"
        got, sc = self.r[first[1]], self.scale[first[1]]
        live = (got != 0) & np.isfinite(sc)
        best, law = np.inf, "ratios"
        for name in ("ratios", "moments", "transfer"):
            guess = self._guess(j, name, k[0], k[2])
            if guess is None:
                continue
            miss = np.max(np.abs(guess[live] / got[live] - 1.0) / sc[live], initial=0.0)
            if miss < best:  # (NaN never)
                best, law = miss, name
        return law

    def _guess(self, j: int, law: str, a: int, b: int) -> np.ndarray | None:
        """Column ``j``'s ratios at the middle Hs of its interval (a, b) (indices of its
        sorted Hs) by ``law`` from the interval's ends alone (None: not available)."""
        col = self.cols[j]
        m = (a + b) // 2
        hs, at = float(col.hs[m]), col.hs[[a, b]]
        ends = np.array([col.members[a][0], col.members[b][0]])
        if law == "transfer":
            if j in self.own or self.base(j, float(col.hs[a])) is None:
                return None
            return self._departure(j, hs, at, ends)
        ratio = correction_rows(hs, at, self.r[ends], self.law)
        if law == "ratios":
            return ratio
        if self.moments is None:
            return None
        got = self.moments.ratios(power_rows(hs, at, self.moments.y[ends]), col.members[m][0])
        return np.where(np.isfinite(got), got, ratio)

    def curve(self, j: int, hs: float, own: bool = False) -> np.ndarray | None:
        """Column ``j``'s ratios at ``hs`` [m] from its computed cases by the law it
        uses (:meth:`column_law`) (None: no computed case).  A column of moments turns
        its moments into ratios with the linear σ and Tz of its case at ``hs``: for
        another column's use (``own`` False: a base, or linear in the period) only at
        a computed case's Hs, else its ratios' law — the checks, made before the other
        cases are solved, test what is then interpolated."""
        key = (j, hs, own)
        if key not in self._curves:
            h, idx = self._anchors[j]
            law = self.column_law(j) if idx.size else ""
            out = None
            if law == "transfer" and self.base(j, hs) is not None:
                out = self._departure(j, hs, h, idx)
            elif idx.size:
                out = correction_rows(hs, h, self.r[idx], self.law)
                case = self._case(j, hs)
                if case is not None and not (own or self.ok[case]):
                    case = None
                if law == "moments" and case is not None and self.moments is not None:
                    got = self.moments.ratios(power_rows(hs, h, self.moments.y[idx]), case)
                    out = np.where(np.isfinite(got), got, out)
            self._curves[key] = out
        return self._curves[key]

    def _case(self, j: int, hs: float) -> int | None:
        """A case of column ``j`` at ``hs`` [m] (None: none)."""
        col = self.cols[j]
        k = int(np.searchsorted(col.hs, hs))
        return col.members[k][0] if k < col.hs.size and col.hs[k] == hs else None

    def interval(self, j: int, a: int, b: int) -> np.ndarray:
        """Column ``j``'s ratios at the middle Hs of its interval (a, b) (indices of its
        sorted Hs) from the interval's ends alone, by the law it uses: the check in
        Hs."""
        guess = self._guess(j, self.column_law(j), a, b)
        return self._guess(j, "ratios", a, b) if guess is None else guess

    def between(self, a: int, b: int, j: int, hs: float) -> np.ndarray | None:
        """Column ``j``'s ratios at ``hs`` linear in the period between columns ``a``
        and ``b``'s curves (None: either has no computed case)."""
        ra, rb = self.curve(a, hs), self.curve(b, hs)
        if ra is None or rb is None:
            return None
        pa, pb = self.cols[a].period, self.cols[b].period
        t = (self.cols[j].period - pa) / (pb - pa)
        return (1.0 - t) * ra + t * rb

    def estimate(self, j: int, hs: float) -> np.ndarray | None:
        """The ratios of a case of column ``j`` at ``hs`` [m]: its column's curve where
        it has computed cases, else linear in the period between the nearest columns
        with some on either side (the one side's at the diagram's edge); None: no
        column of the heading has one."""
        own = self.curve(j, hs, own=True)
        if own is not None:
            return own
        lo = next((k for k in range(j - 1, -1, -1) if self.has(k)), None)
        hi = next((k for k in range(j + 1, len(self.cols)) if self.has(k)), None)
        if lo is not None and hi is not None:
            return self.between(lo, hi, j, hs)
        side = lo if lo is not None else hi
        return None if side is None else self.curve(side, hs)
