"""Motion RAO tables of the scene: a line end's (surge, sway, heave) and a vessel's six
DOFs per unit wave amplitude, over frequency and optionally over wave heading.

A table without ``heading`` holds one RAO per DOF over ω, given for the sea's heading
and used for every direction of the sea.  With ``heading`` (deg, the direction the
waves travel toward, from +x toward +y, as ``sea.heading``) every DOF is an
(n_heading, n_omega) table and the RAO of a sea direction θ is interpolated linearly
in its real and imaginary parts between the two neighbouring headings (as the body
excitation tables, :func:`stochcable.scene.tables.heading_weights`; a table covering
the full circle wraps around).  So a scatter diagram over headings, or a short-crested
sea, moves the vessel as its RAOs say for each direction.

References
----------
Tuah, H. (1982), Cable dynamics in an ocean environment, PhD thesis, Oregon State University.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any, ClassVar

import numpy as np
from pydantic import model_validator

from stochcable.scene.base import LocatedValueError, _Doc, _f
from stochcable.scene.tables import BODY_DOFS, heading_weights

__all__ = ["ComplexTable", "MotionRao", "VesselMotion", "check_rao_headings", "uncovered_heading"]


class ComplexTable(_Doc):
    """Complex values as separate real and imaginary parts: over ω (n_omega,), or in an
    RAO table with headings over heading and ω (n_heading, n_omega)."""

    re: tuple[float, ...] | tuple[tuple[float, ...], ...]
    im: tuple[float, ...] | tuple[tuple[float, ...], ...]

    @model_validator(mode="after")
    def _same_shape(self) -> ComplexTable:
        try:
            re, im = np.asarray(self.re, dtype=float), np.asarray(self.im, dtype=float)
        except ValueError:
            raise ValueError("re and im must be regular (every row of one length)") from None
        if re.shape != im.shape:
            raise ValueError(f"re {re.shape} and im {im.shape} differ in shape")
        return self

    def values(self) -> np.ndarray:
        """The complex values, shape (n_omega,) or (n_heading, n_omega)."""
        return np.asarray(self.re, dtype=float) + 1j * np.asarray(self.im, dtype=float)


class _RaoTable(_Doc):
    """Frequencies, optional headings and one complex table per DOF of ``DOFS``."""

    DOFS: ClassVar[tuple[str, ...]] = ()

    omega: tuple[float, ...] = _f("Angular frequencies, strictly increasing", "rad/s", min_length=2)
    heading: tuple[float, ...] | None = _f(
        "Wave headings of the table (direction of travel, from +x toward +y), strictly "
        "increasing, spanning < 360; with it every DOF is an (n_heading, n_omega) table, "
        "interpolated linearly over heading; without it the RAO applies to every direction",
        "deg",
        default=None,
        min_length=1,
    )

    @model_validator(mode="after")
    def _check(self) -> _RaoTable:
        w = np.asarray(self.omega)
        if w[0] < 0 or (np.diff(w) <= 0).any():
            raise ValueError("omega must be >= 0 and strictly increasing")
        if self.heading is not None:
            h = np.asarray(self.heading)
            if (np.diff(h) <= 0).any() or h[-1] - h[0] >= 360.0:
                raise ValueError(
                    f"heading {list(self.heading)} deg must be strictly increasing and "
                    "span less than 360 deg"
                )
        given = {k: getattr(self, k) for k in self.DOFS}
        if all(v is None for v in given.values()):
            raise ValueError(f"give at least one of {', '.join(self.DOFS)}")
        shape = (len(self.omega),) if self.heading is None else (len(self.heading), len(w))
        for k, v in given.items():
            if v is not None and np.shape(v.re) != shape:
                what = "omega" if self.heading is None else "(heading, omega)"
                raise ValueError(f"{k} has shape {np.shape(v.re)} but {what} gives {shape}")
        return self

    def transfer(self, omega: np.ndarray, heading: float | None = None) -> np.ndarray:
        """RAO per unit wave amplitude at ``omega`` [rad/s] for waves travelling toward
        ``heading`` [rad], shape (n_dof, n_omega), zero outside the frequency table.

        ``heading`` is needed only by a table with headings (InputError "heading" when it
        falls outside a table that does not cover the full circle)."""
        omega = np.asarray(omega, dtype=float)
        out = np.zeros((len(self.DOFS), omega.size), dtype=complex)
        w = np.asarray(self.omega)
        weights = None
        if self.heading is not None:
            if heading is None:
                raise ValueError("the RAO table has headings: give the wave heading")
            weights = heading_weights(np.radians(self.heading), heading, "RAO table")
        for i, k in enumerate(self.DOFS):
            t = getattr(self, k)
            if t is None:
                continue
            v = t.values()
            if weights is not None:
                a, b, s = weights
                v = (1.0 - s) * v[a] + s * v[b]
            out[i] = np.interp(omega, w, v.real, 0.0, 0.0) + 1j * np.interp(
                omega, w, v.imag, 0.0, 0.0
            )
        return out


def check_rao_headings(sea: Any, bodies: Sequence[Any], lines: Sequence[Any]) -> None:
    """Every RAO table with headings (the vessels' ``prescribed``, the line ends'
    ``motion.rao``) covers every direction of ``sea`` (its heading and spreading);
    else a LocatedValueError at the table's ``heading``."""
    if sea is None:
        return
    ds = sea.direction_set()
    dirs = np.array([sea.heading_rad]) if ds is None else ds.heading
    tables = [(("bodies", j, "prescribed"), b.prescribed) for j, b in enumerate(bodies)]
    for i, ln in enumerate(lines):
        for end in ("end_a", "end_b"):
            m = getattr(ln, end).motion
            tables.append((("lines", i, end, "motion", "rao"), m and m.rao))
    for loc, table in tables:
        why = None if table is None else uncovered_heading(table, dirs)
        if why is not None:
            raise LocatedValueError(
                (*loc, "heading"),
                list(table.heading),
                f"{why}: extend the RAO table's headings to every direction of the sea "
                "(its heading and spreading)",
            )


def uncovered_heading(table: _RaoTable, headings_rad: np.ndarray) -> str | None:
    """Why ``table`` cannot give the RAO of every heading in ``headings_rad`` [rad]
    (the sea's directions), or None when it can (a table without headings always can)."""
    if table.heading is None:
        return None
    for beta in np.atleast_1d(headings_rad):
        try:
            heading_weights(np.radians(table.heading), float(beta), "RAO table")
        except ValueError as exc:  # InputError
            return f"the sea direction {math.degrees(float(beta)) % 360.0:g} deg {exc}"
    return None


class MotionRao(_RaoTable):
    """End motion RAOs relative to the sea: metres of motion per metre of wave amplitude."""

    DOFS: ClassVar[tuple[str, ...]] = ("surge", "sway", "heave")

    surge: ComplexTable | None = None
    sway: ComplexTable | None = None
    heave: ComplexTable | None = None


class VesselMotion(_RaoTable):
    """A prescribed (vessel) body motion: 6-DOF RAOs per unit wave amplitude.

    Translations in m/m, rotations in rad/m, about the body reference point, global
    axes, phase relative to the wave elevation at the global origin x = y = 0
    (e^{+iωt}, as the end-motion RAOs); zero outside the frequency table.  Without
    ``heading`` the table is for the sea's heading and applies to every direction; with
    it, interpolated per direction of the sea.
    The body is not solved for: lines attached to it see the end motion T(r)·ξ
    (Tuah (1982), eqs. 3.3.6–3.3.7), nothing couples back.
    """

    DOFS: ClassVar[tuple[str, ...]] = BODY_DOFS

    surge: ComplexTable | None = None
    sway: ComplexTable | None = None
    heave: ComplexTable | None = None
    roll: ComplexTable | None = None
    pitch: ComplexTable | None = None
    yaw: ComplexTable | None = None

    @property
    def out_of_plane(self) -> bool:
        """True when a sway, roll or yaw RAO is non-zero."""
        return any(
            getattr(self, k) is not None and np.any(getattr(self, k).values() != 0)
            for k in ("sway", "roll", "yaw")
        )
