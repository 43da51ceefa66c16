"""Hydrodynamic coefficient tables of bodies: reading and checking, shared by the scene
validation (an inline table is checked when the document is validated) and
:mod:`stochcable.bodies.data` (which builds the body records from them).

JSON table format
-----------------
::

    {"dofs": ["surge", "sway", "heave", "roll", "pitch", "yaw"],   # optional; or
                                                  # ["surge", "heave", "pitch"]
     "omega": [w1, w2, ...],                      # rad/s, strictly increasing
     "added_mass": [[[...], ...], ...],           # (n_omega, d, d) kg, kg·m, kg·m²
     "radiation_damping": [[[...], ...], ...],    # (n_omega, d, d) N·s/m, N·s, N·m·s
     "excitation": {"heading": [b1, ...],         # deg, strictly increasing
                    "re": [[[...], ...], ...],    # (n_heading, d, n_omega) N/m, N·m/m
                    "im": [[[...], ...], ...]},   # phase: e^{+iωt}, wave crest at the
                                                  # reference point
     "hydrostatic_stiffness": [[...], ...],       # optional (d, d) N/m, N, N·m
     "reference_point": [x, y, z]}                # optional, informative [m]

A matrix entry A[i][j] is the force in DOF i due to a unit motion of DOF j.
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

from stochcable.errors import InputError
from stochcable.validation import float_array, nonnegative

__all__ = [
    "BODY_DOFS",
    "PLANAR_BODY_DOFS",
    "SYMMETRY_TOLERANCE",
    "NEGATIVE_DAMPING_TOLERANCE",
    "parse_table",
    "checked_table",
    "check_matrices",
    "array3",
    "heading_weights",
]

#: Rigid-body DOF names (global axes, rotations about the reference point), as
#: :data:`stochcable.bodies.rigid.SPATIAL_DOFS`; planar scenes use the x–z subset.
BODY_DOFS = ("surge", "sway", "heave", "roll", "pitch", "yaw")
PLANAR_BODY_DOFS = ("surge", "heave", "pitch")

#: Largest accepted |A − Aᵀ| relative to max|A| (BEM matrices on coarse meshes are
#: symmetric only to a few per mille); the matrices are then symmetrized.
SYMMETRY_TOLERANCE = 2.0e-2
#: A damping diagonal below −this·max|B| is an error (round-off negatives are zeroed).
NEGATIVE_DAMPING_TOLERANCE = 1.0e-6


def check_matrices(
    name: str, a: np.ndarray, omega: np.ndarray, unit: str, damping: bool, tol: float
) -> np.ndarray:
    """Symmetry (and non-negative diagonal) per frequency; returns the symmetrized copy."""
    if not np.isfinite(a).all():
        k = int(np.flatnonzero(~np.isfinite(a).reshape(a.shape[0], -1).all(axis=1))[0])
        raise InputError(name, f"non-finite at omega = {omega[k]:g} rad/s", unit, "must be finite")
    top = np.abs(a).max(axis=(1, 2))
    asym = np.abs(a - np.swapaxes(a, 1, 2)).max(axis=(1, 2))
    with np.errstate(invalid="ignore", divide="ignore"):
        rel = np.where(top > 0, asym / np.where(top > 0, top, 1.0), 0.0)
    if (rel > tol).any():
        k = int(np.argmax(rel))
        raise InputError(
            name,
            f"max|A − Aᵀ|/max|A| = {rel[k]:.3g} at omega = {omega[k]:g} rad/s",
            unit,
            f"must be symmetric within {tol:g} of the largest entry",
        )
    out = 0.5 * (a + np.swapaxes(a, 1, 2))
    if damping:
        diag = np.einsum("wii->wi", out)
        neg = diag < -NEGATIVE_DAMPING_TOLERANCE * np.maximum(top, 1e-300)[:, None]
        if neg.any():
            k, i = (int(v[0]) for v in np.nonzero(neg))
            raise InputError(
                name,
                f"diagonal entry {i} = {diag[k, i]:.6g} at omega = {omega[k]:g} rad/s",
                unit,
                "must be >= 0 (radiation damping dissipates energy)",
            )
        idx = np.arange(out.shape[1])
        out[:, idx, idx] = np.maximum(diag, 0.0)
    return out


def checked_table(
    dofs, omega, am, bd, heading, exc, hs, ref, exc_point, source, tol
) -> dict[str, Any]:
    """The checked coefficient arrays of a table (shapes, symmetry within ``tol``,
    non-negative damping diagonal, matrices symmetrized), as the fields of
    :class:`stochcable.bodies.data.Hydrodynamics` by name."""
    d = len(dofs)
    w = float_array("omega", omega, "rad/s", nonnegative=True, increasing=True)
    am = np.asarray(am, dtype=float)
    bd = np.asarray(bd, dtype=float)
    for name, a, unit in (("added_mass", am, "kg"), ("radiation_damping", bd, "N·s/m")):
        if a.ndim != 3 or a.shape[1:] != (d, d):
            raise InputError(name, a.shape, unit, f"must have shape (n_omega, {d}, {d})")
        if a.shape[0] != w.size:
            raise InputError(
                name,
                a.shape,
                unit,
                f"has {a.shape[0]} frequencies but omega has {w.size}: give one "
                "matrix per frequency",
            )
    am = check_matrices("added_mass", am, w, "kg", False, tol)
    bd = check_matrices("radiation_damping", bd, w, "N·s/m", True, tol)
    h = None
    if exc is not None:
        if heading is None:
            raise InputError("excitation.heading", None, "rad", "must be given with the excitation")
        h = float_array("excitation.heading", heading, "rad", increasing=True)
        exc = np.asarray(exc, dtype=complex)
        if exc.shape != (h.size, d, w.size):
            raise InputError(
                "excitation",
                exc.shape,
                "N/m",
                f"must have shape (n_heading={h.size}, {d}, n_omega={w.size})",
            )
        if not np.isfinite(exc).all():
            raise InputError("excitation", "non-finite", "N/m", "must be finite")
    if hs is not None:
        hs = float_array("hydrostatic_stiffness", hs, "N/m", ndim=2)
        if hs.shape != (d, d):
            raise InputError("hydrostatic_stiffness", hs.shape, "N/m", f"must be ({d}, {d})")
    ref = np.zeros(3) if ref is None else float_array("reference_point", ref, "m")
    if ref.shape != (3,):
        raise InputError("reference_point", ref.shape, "m", "must be (x, y, z)")
    return {
        "dofs": tuple(dofs),
        "omega": w.copy(),
        "added_mass": am,
        "radiation_damping": bd,
        "heading": h,
        "excitation": exc,
        "hydrostatic_stiffness": hs,
        "reference_point": ref.copy(),
        "excitation_point": np.asarray(exc_point, dtype=float).copy(),
        "source": source,
    }


def parse_table(
    source: Mapping[str, Any] | str | Path,
    *,
    symmetry_tolerance: float = SYMMETRY_TOLERANCE,
) -> dict[str, Any]:
    """Read and check hydrodynamic coefficients in the JSON table format (module
    docstring).

    Parameters
    ----------
    source : mapping, JSON string or path
        The table document.
    symmetry_tolerance : float
        Accepted max|A − Aᵀ|/max|A| per frequency. [-]

    Returns
    -------
    dict
        The fields of :class:`stochcable.bodies.data.Hydrodynamics` by name
        (:func:`checked_table`); excitation headings converted from degrees to
        radians; phases referred to the reference point (``excitation_point`` = 0).

    Raises
    ------
    InputError
        Missing keys, missing frequencies or headings, wrong shapes, non-symmetric
        matrices, negative damping diagonal.
    """
    if isinstance(source, Mapping):
        doc, name = source, "table"
    else:
        text = str(source)
        p = Path(text) if len(text) < 4096 and not text.lstrip().startswith("{") else None
        if p is not None:
            if not p.is_file():
                raise InputError("source", text, "-", "file not found")
            text, name = p.read_text(), str(p)
        else:
            name = "table"
        try:
            doc = json.loads(text)
        except json.JSONDecodeError as exc:
            raise InputError(
                "source", name, "-", f"is not valid JSON ({exc.msg} at line {exc.lineno})"
            ) from None
    if not isinstance(doc, Mapping):
        raise InputError("source", type(doc).__name__, "-", "must be a JSON object")
    known = {
        "dofs",
        "omega",
        "added_mass",
        "radiation_damping",
        "excitation",
        "hydrostatic_stiffness",
        "reference_point",
        "title",
    }
    extra = sorted(set(doc) - known)
    if extra:
        raise InputError("source", extra, "-", f"unknown keys; allowed: {sorted(known)}")
    dofs = tuple(str(d).lower() for d in doc.get("dofs", BODY_DOFS))
    if dofs not in (tuple(BODY_DOFS), tuple(PLANAR_BODY_DOFS)):
        raise InputError(
            "dofs", list(dofs), "-", f"must be {list(BODY_DOFS)} or {list(PLANAR_BODY_DOFS)}"
        )
    for req in ("omega", "added_mass", "radiation_damping"):
        if req not in doc:
            raise InputError(req, None, "-", "is missing from the table")
    w = float_array("omega", doc["omega"], "rad/s", nonnegative=True, increasing=True)
    am = array3("added_mass", doc["added_mass"], "kg")
    bd = array3("radiation_damping", doc["radiation_damping"], "N·s/m")
    for nm, a in (("added_mass", am), ("radiation_damping", bd)):
        if a.shape[0] != w.size:
            raise InputError(
                nm,
                a.shape,
                "-",
                f"has {a.shape[0]} frequencies but omega has "
                f"{w.size}: give one matrix per frequency",
            )
    heading = exc = None
    if doc.get("excitation") is not None:
        e = doc["excitation"]
        if not isinstance(e, Mapping):
            raise InputError(
                "excitation", type(e).__name__, "-", "must be an object with heading, re, im"
            )
        for req in ("heading", "re", "im"):
            if req not in e:
                raise InputError(f"excitation.{req}", None, "-", "is missing from the table")
        hd = float_array("excitation.heading", e["heading"], "deg", increasing=True)
        if hd[-1] - hd[0] >= 360.0:
            raise InputError("excitation.heading", hd.tolist(), "deg", "must span less than 360")
        heading = np.radians(hd)
        re = array3("excitation.re", e["re"], "N/m")
        im = array3("excitation.im", e["im"], "N/m")
        if re.shape != im.shape:
            raise InputError(
                "excitation.im", im.shape, "N/m", f"must have the shape of excitation.re {re.shape}"
            )
        if re.shape[0] != heading.size:
            raise InputError(
                "excitation.re",
                re.shape,
                "N/m",
                f"has {re.shape[0]} headings but excitation.heading has {heading.size}",
            )
        if re.shape[2] != w.size:
            raise InputError(
                "excitation.re",
                re.shape,
                "N/m",
                f"has {re.shape[2]} frequencies but omega has {w.size}",
            )
        exc = re + 1j * im
    return checked_table(
        dofs,
        w,
        am,
        bd,
        heading,
        exc,
        doc.get("hydrostatic_stiffness"),
        doc.get("reference_point"),
        np.zeros(2),
        f"table:{name}",
        nonnegative("symmetry_tolerance", symmetry_tolerance, "-"),
    )


def array3(name: str, value: Any, unit: str) -> np.ndarray:
    """``value`` as a regular 3-D float array (InputError otherwise)."""
    try:
        a = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise InputError(
            name, "ragged or non-numeric", unit, "must be a regular 3-D array of numbers"
        ) from None
    if a.ndim != 3:
        raise InputError(name, a.shape, unit, f"must be a 3-D array (got {a.ndim}-D)")
    return a


def heading_weights(table: np.ndarray, beta: float, what: str) -> tuple[int, int, float]:
    """Two indices into a sorted heading ``table`` [rad] and the weight t of heading
    ``beta`` [rad] for linear interpolation (1 − t)·v[i] + t·v[j]: periodic in 2π, a
    table covering the full circle (its closing gap no larger than its largest step)
    wraps around; otherwise a heading outside it is an InputError naming ``what``."""
    n = table.size
    two_pi = 2.0 * math.pi
    b = table[0] + (beta - table[0]) % two_pi
    tol = 1e-9
    if n == 1:
        if min(abs(b - table[0]), two_pi - abs(b - table[0])) <= tol:
            return 0, 0, 0.0
        raise InputError(
            "heading",
            math.degrees(beta),
            "deg",
            f"is not in the {what} (one heading, "
            f"{math.degrees(table[0]):g} deg): add headings to the table",
        )
    if b <= table[-1] + tol:
        i = int(np.clip(np.searchsorted(table, b, side="right") - 1, 0, n - 2))
        t = float(np.clip((b - table[i]) / (table[i + 1] - table[i]), 0.0, 1.0))
        return i, i + 1, t
    gap = table[0] + two_pi - table[-1]
    if b >= table[0] + two_pi - tol:
        return 0, 0, 0.0
    if gap <= np.diff(table).max() * (1 + 1e-9):  # a full-circle table: wrap around
        return n - 1, 0, float((b - table[-1]) / gap)
    raise InputError(
        "heading",
        math.degrees(beta),
        "deg",
        f"is outside the {what}'s headings "
        f"[{math.degrees(table[0]):g}, {math.degrees(table[-1]):g}] deg",
    )
