"""The residual moments of a load-case set's end tensions: the coordinates in which a
column of the adaptive residual anchors may interpolate its end corrections instead of
their ratios (:class:`~stochcable.cases.anchor_transfer.HeadingCurves`).

A corrected end tension's spectral density is the linear one plus the residuals', so
its moments are the linear ones plus the residuals': m0 = σ_lin² + Δm0 and
m2 = m0_lin·(2π/Tz_lin)² + Δm2 (Tz = 2π·√(m0/m2)).  Where the residuals grow as a power
of Hs while the linear response does not — the taut wire near resonance, its drag
damping bending σ_lin against Hs — the ratios σ/σ_lin and Tz/Tz_lin bend too (the end_b
σ correction at Tp 12 s rises to +26 % at Hs 2.75 m and falls to +23 % at 3.5 m), but
Δm0 and Δm2 stay powers of Hs (a power law between computed Hs 0.5 m apart meets σ and
Tz to 1e-5 there, the ratios' law misses by 3e-2; docs/benchmarks/cases.md).  The end
damage rate follows as its ratio over the narrow-band proxy (σ/σ_lin)^m·(Tz_lin/Tz),
m the S-N slope of the line's curve: what the proxy leaves of the correction (the
spectrum's shape through the spectral method) varies slowly.  The 3-h MPM and the
elements' damage keep their ratios.  Every coordinate is interpolated as a power of Hs
between computed cases where its two values share a sign, else linearly in Hs²
(:func:`power_rows`), and turned back into ratios with the linear values of the case it
is wanted at (:meth:`MomentCoordinates.ratios`).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from stochcable.design import FatigueCurve, fatigue_curve

__all__ = ["MomentCoordinates", "damage_slopes", "power_rows"]


@dataclass(frozen=True)
class MomentCoordinates:
    """The cases' ratios in the moments' coordinates (module notes).

    Attributes
    ----------
    y : ndarray, shape (n, q)
        Per case: Δm0 [force²] and Δm2/(2π)² [force²/s²] of every end, the damage's
        ratio over its proxy less 1 (the proxy's slope known, else the ratio less 1),
        and every other ratio less 1, in the layout of
        :func:`~stochcable.cases.anchor_layout.check_ratios`.
    ends : tuple of (int, int, int, float)
        Per end: the columns of σ, Tz and the damage rate (−1: none) and the S-N slope
        (nan: no proxy).
    std, tz : ndarray, shape (n, n_ends)
        Per case and end the linear σ [force] and Tz [s].
    """

    y: np.ndarray
    ends: tuple[tuple[int, int, int, float], ...]
    std: np.ndarray
    tz: np.ndarray

    @classmethod
    def of(
        cls,
        r: np.ndarray,
        linear: Mapping[str, np.ndarray],
        damage_ends: Mapping[str, Any],
        slopes: Mapping[str, float] | None = None,
    ) -> MomentCoordinates:
        """The coordinates of the ratios ``r`` (n, q) of
        :func:`~stochcable.cases.anchor_layout.check_ratios` (``linear`` and
        ``damage_ends`` as given it; ``slopes`` the S-N slope of each line's curve)."""
        y = np.asarray(r, dtype=float) - 1.0
        ends, std, tz = [], [], []
        k = 0
        for name, lin in linear.items():
            m = float((slopes or {}).get(name, math.nan))
            for e in range(2):
                d = k + 3 if name in damage_ends else -1
                ends.append((k, k + 1, d, m))
                std.append(lin[:, e, 0])
                tz.append(lin[:, e, 1])
                k += 4 if d >= 0 else 3
        n = y.shape[0]
        s = np.column_stack(std) if std else np.zeros((n, 0))
        t = np.column_stack(tz) if tz else np.zeros((n, 0))
        with np.errstate(all="ignore"):
            for c, (i_s, i_t, i_d, m) in enumerate(ends):
                rs, rt = y[:, i_s] + 1.0, y[:, i_t] + 1.0
                v0, v2 = s[:, c] ** 2, (s[:, c] / t[:, c]) ** 2
                if i_d >= 0 and math.isfinite(m):
                    y[:, i_d] = (y[:, i_d] + 1.0) * rt / rs**m - 1.0
                y[:, i_s] = (rs * rs - 1.0) * v0
                y[:, i_t] = (rs * rs / (rt * rt) - 1.0) * v2
        return cls(y, tuple(ends), s, t)

    def ratios(self, y: np.ndarray, case: int) -> np.ndarray:
        """The ratios (q,) of the coordinates ``y`` (q,) at case ``case`` (its linear σ
        and Tz); NaN where they give no positive moment. [-]"""
        out = np.asarray(y, dtype=float) + 1.0
        with np.errstate(all="ignore"):
            for c, (i_s, i_t, i_d, m) in enumerate(self.ends):
                s, t = self.std[case, c], self.tz[case, c]
                if not (s > 0 and t > 0 and math.isfinite(s) and math.isfinite(t)):
                    out[[i_s, i_t]] = np.nan
                    continue
                m0 = s * s + y[i_s]
                m2 = (s / t) ** 2 + y[i_t]
                if m0 <= 0 or m2 <= 0:
                    out[[i_s, i_t]] = np.nan
                    continue
                rs, rt = math.sqrt(m0) / s, math.sqrt(m0 / m2) / t
                out[i_s], out[i_t] = rs, rt
                if i_d >= 0 and math.isfinite(m):
                    out[i_d] = (y[i_d] + 1.0) * rs**m / rt
        return out


def power_rows(hs: float, anchors: np.ndarray, y: np.ndarray) -> np.ndarray:
    """The coordinates (q,) at ``hs`` [m] between the anchors' (``anchors`` sorted
    distinct Hs [m], their coordinates ``y`` (m, q)): a power of Hs between the two
    around it where their values share a sign, else linear in Hs²; constant beyond the
    anchors."""
    h = np.asarray(anchors, dtype=float)
    y = np.asarray(y, dtype=float)
    if h.size == 1 or hs <= h[0]:
        return y[0].copy()
    if hs >= h[-1]:
        return y[-1].copy()
    k = int(np.searchsorted(h, hs, side="right")) - 1
    h0, h1, y0, y1 = h[k], h[k + 1], y[k], y[k + 1]
    out = y0 + (y1 - y0) * (hs * hs - h0 * h0) / (h1 * h1 - h0 * h0)
    if h0 > 0:
        same = y0 * y1 > 0
        if np.any(same):
            expo = math.log(hs / h0) / math.log(h1 / h0)
            q = np.where(same, y1 / np.where(same, y0, 1.0), 1.0)
            out = np.where(same, y0 * q**expo, out)
    return out


def damage_slopes(fatigue: Mapping[str, Any]) -> dict[str, float]:
    """The S-N slope of each line's curve (``fatigue``: the set's validated
    :class:`~stochcable.cases.fatigue_settings.LineFatigue` per line; the first
    segment's slope of a curve with two). [-]"""
    out = {}
    for name, settings in fatigue.items():
        curve = settings.curve
        if isinstance(curve, str):
            curve = fatigue_curve(curve, mean_load_ratio=settings.mean_load_ratio)
        if isinstance(curve, FatigueCurve) and curve.slopes:
            out[name] = float(curve.slopes[0])
    return out
