"""Wave scatter diagrams: the sea states of a load-case set and their probabilities.

A diagram is read from a table (one row per sea state: Hs, Tp or Tz, optional γ,
heading, probability or hours) in CSV or JSON, or from the common occurrence-matrix form
(Hs × Tp or Tz counts, with a heading distribution).  The spectrum family is chosen once
for the diagram: Pierson–Moskowitz, or JONSWAP with γ given per row or from Hs and Tp
(DNV-RP-C205 §3.5.5.5).  Validation happens here, once; every error names the row and
the column (``scatter[3].hs``).
"""

from __future__ import annotations

import csv
import io
import json
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal

from stochcable.errors import InputError
from stochcable.scene.spectra import Jonswap, PiersonMoskowitz

__all__ = [
    "SeaState",
    "ScatterDiagram",
    "scatter_from_rows",
    "scatter_from_matrix",
    "read_scatter",
    "jonswap_gamma_dnv",
    "tz_over_tp",
]

Family = Literal["pierson_moskowitz", "jonswap"]
_FAMILIES = ("pierson_moskowitz", "jonswap")
#: Probabilities must sum to 1 within this (rounding of published tables). [-]
PROBABILITY_SUM_TOLERANCE = 1e-3


def jonswap_gamma_dnv(hs: float, tp: float) -> float:
    """Peak enhancement factor from Hs and Tp (DNV-RP-C205 (2010) §3.5.5.5). [-]

    γ = 5 for Tp/√Hs ≤ 3.6, exp(5.75 − 1.15·Tp/√Hs) for 3.6 < Tp/√Hs < 5, and 1 above
    (Tp in s, Hs in m).
    """
    r = tp / math.sqrt(hs)
    if r <= 3.6:
        return 5.0
    if r < 5.0:
        return math.exp(5.75 - 1.15 * r)
    return 1.0


def tz_over_tp(gamma: float) -> float:
    """Tz/Tp of a JONSWAP spectrum (DNV-RP-C205 (2010) §3.5.5.2; 0.7104 for PM, γ = 1):
    0.6673 + 0.05037γ − 0.006230γ² + 0.0003341γ³. [-]"""
    return 0.6673 + 0.05037 * gamma - 0.006230 * gamma**2 + 0.0003341 * gamma**3


@dataclass(frozen=True)
class SeaState:
    """One row of a scatter diagram.

    Attributes
    ----------
    hs : float
        Significant wave height. [m]
    tp : float
        Peak period. [s]
    gamma : float
        JONSWAP peak enhancement (1 for Pierson–Moskowitz). [-]
    heading : float
        Direction the waves travel toward, from +x toward +y. [deg]
    probability : float
        Probability of occurrence (normalized over the diagram). [-]
    """

    hs: float
    tp: float
    gamma: float
    heading: float
    probability: float

    def spectrum(self, family: Family) -> PiersonMoskowitz | Jonswap:
        """The scene's spectrum document of this sea state."""
        if family == "pierson_moskowitz":
            return PiersonMoskowitz(hs=self.hs, tp=self.tp)
        return Jonswap(hs=self.hs, tp=self.tp, gamma=self.gamma)


@dataclass(frozen=True)
class ScatterDiagram:
    """The sea states of a load-case set.

    Attributes
    ----------
    states : tuple of SeaState
        Sea states, probabilities summing to 1.
    family : {"pierson_moskowitz", "jonswap"}
        Spectrum family of every state.
    source : str
        Where the diagram comes from (free text).
    """

    states: tuple[SeaState, ...]
    family: Family = "jonswap"
    source: str = ""

    def __len__(self) -> int:
        return len(self.states)

    def to_document(self) -> dict[str, Any]:
        """The diagram as a JSON document :func:`read_scatter` reads back (rows with
        Hs, Tp, γ, heading and probability)."""
        rows = [
            {"hs": s.hs, "tp": s.tp, "gamma": s.gamma, "heading": s.heading,
             "probability": s.probability}
            for s in self.states
        ]  # fmt: skip
        return {"rows": rows, "spectrum": self.family, "source": self.source}

    def with_headings(
        self, headings: Sequence[float], parameter: str = "headings"
    ) -> ScatterDiagram:
        """Every state repeated for each heading with equal probability (the states'
        own headings are replaced).

        Parameters
        ----------
        headings : sequence of float
            Wave headings, at least one. [deg]
        parameter : str
            Name of the argument in error messages.
        """
        try:
            heads = [float(h) for h in headings]
        except (TypeError, ValueError):
            raise InputError(parameter, headings, "deg", "must be numbers") from None
        if not heads:
            raise InputError(parameter, headings, "deg", "must name at least one heading")
        for i, h in enumerate(heads):
            if not math.isfinite(h):
                raise InputError(f"{parameter}[{i}]", h, "deg", "must be finite")
        w = 1.0 / len(heads)
        states = tuple(
            SeaState(s.hs, s.tp, s.gamma, h, s.probability * w) for s in self.states for h in heads
        )
        return ScatterDiagram(states, self.family, self.source)


def _number(row: Mapping[str, Any], key: str, i: int, unit: str, *, positive: bool) -> float:
    raw = row.get(key)
    try:
        x = float(raw)
    except (TypeError, ValueError):
        raise InputError(f"scatter[{i}].{key}", raw, unit, "must be a number") from None
    if not math.isfinite(x) or (positive and x <= 0) or (not positive and x < 0):
        bound = "> 0" if positive else ">= 0"
        raise InputError(f"scatter[{i}].{key}", raw, unit, f"must be finite and {bound}")
    return x


def _blank(v: Any) -> bool:
    return v is None or (isinstance(v, str) and v.strip() == "")


def _state(row: Mapping[str, Any], i: int, family: Family) -> tuple[SeaState, float]:
    hs = _number(row, "hs", i, "m", positive=True)
    has_tp, has_tz = not _blank(row.get("tp")), not _blank(row.get("tz"))
    if has_tp == has_tz:
        raise InputError(f"scatter[{i}].tp", row.get("tp"), "s", "give exactly one of tp and tz")
    gamma = 1.0
    if family == "jonswap":
        if not _blank(row.get("gamma")):
            gamma = _number(row, "gamma", i, "-", positive=True)
            if not 1.0 <= gamma <= 20.0:
                raise InputError(f"scatter[{i}].gamma", gamma, "-", "must be in [1, 20]")
        elif has_tp:
            gamma = jonswap_gamma_dnv(hs, _number(row, "tp", i, "s", positive=True))
    if has_tp:
        tp = _number(row, "tp", i, "s", positive=True)
    else:
        tz = _number(row, "tz", i, "s", positive=True)
        if family == "jonswap" and _blank(row.get("gamma")):
            # γ depends on Tp and Tp on γ: a few fixed-point steps (contracting: the
            # γ(Tp) map has slope below 0.2 per second and Tz/Tp varies by < 0.1)
            tp = tz / tz_over_tp(1.0)
            for _ in range(50):
                gamma = jonswap_gamma_dnv(hs, tp)
                tp_new = tz / tz_over_tp(gamma)
                if abs(tp_new - tp) <= 1e-12 * tp:
                    break
                tp = tp_new
            gamma = jonswap_gamma_dnv(hs, tp)
        tp = tz / tz_over_tp(gamma)
    heading = 0.0
    if not _blank(row.get("heading")):
        raw = row.get("heading")
        try:
            heading = float(raw)
        except (TypeError, ValueError):
            raise InputError(f"scatter[{i}].heading", raw, "deg", "must be a number") from None
        if not math.isfinite(heading):
            raise InputError(f"scatter[{i}].heading", raw, "deg", "must be finite")
    has_p, has_h = not _blank(row.get("probability")), not _blank(row.get("hours"))
    if has_p == has_h:
        raise InputError(
            f"scatter[{i}].probability",
            row.get("probability"),
            "-",
            "give exactly one of probability and hours",
        )
    weight = (
        _number(row, "probability", i, "-", positive=False)
        if has_p
        else _number(row, "hours", i, "h", positive=False)
    )
    return SeaState(hs, tp, gamma, heading, weight), (1.0 if has_p else 0.0)


def scatter_from_rows(
    rows: Sequence[Mapping[str, Any]], *, family: Family = "jonswap", source: str = ""
) -> ScatterDiagram:
    """A diagram from table rows (mappings with keys hs, tp or tz, gamma, heading,
    probability or hours; see the module docstring).

    Parameters
    ----------
    rows : sequence of mapping
        One sea state per row.  Probabilities must sum to 1 (within 1e-3, the rounding
        of published tables) and are then normalized; hours (all rows in hours) are
        normalized by their total.
    family : {"pierson_moskowitz", "jonswap"}
        Spectrum family of every state.
    source : str
        Where the diagram comes from.

    Returns
    -------
    ScatterDiagram
    """
    if family not in _FAMILIES:
        raise InputError("spectrum", family, "-", f"must be one of {', '.join(_FAMILIES)}")
    if len(rows) == 0:
        raise InputError("scatter", rows, "-", "must have at least one sea state")
    for i, r in enumerate(rows):
        if not isinstance(r, Mapping):
            raise InputError(f"scatter[{i}]", type(r).__name__, "-", "must be a mapping (a row)")
    parsed = [_state(r, i, family) for i, r in enumerate(rows)]
    kinds = {k for _, k in parsed}
    if len(kinds) > 1:
        raise InputError("scatter", "mixed", "-", "give probability on every row or hours")
    total = math.fsum(s.probability for s, _ in parsed)
    if total <= 0:
        raise InputError("scatter", total, "-", "probabilities or hours must not all be zero")
    if kinds == {1.0} and abs(total - 1.0) > PROBABILITY_SUM_TOLERANCE:
        raise InputError(
            "scatter.probability",
            total,
            "-",
            f"must sum to 1 within {PROBABILITY_SUM_TOLERANCE} (give hours to have them "
            "normalized)",
        )
    states = tuple(
        SeaState(s.hs, s.tp, s.gamma, s.heading, s.probability / total) for s, _ in parsed
    )
    return ScatterDiagram(states, family, source)


def scatter_from_matrix(
    hs: Sequence[float],
    periods: Sequence[float],
    occurrence: Sequence[Sequence[float]],
    *,
    period: Literal["tp", "tz"] = "tz",
    headings: Mapping[float, float] | None = None,
    family: Family = "jonswap",
    source: str = "",
) -> ScatterDiagram:
    """A diagram from an occurrence matrix (rows Hs, columns Tp or Tz) and a heading
    distribution.

    Parameters
    ----------
    hs : sequence of float
        Class midpoints of Hs, one per matrix row. [m]
    periods : sequence of float
        Class midpoints of the period, one per column. [s]
    occurrence : sequence of sequence of float
        Counts or probabilities, >= 0 (normalized over the matrix). [-]
    period : {"tp", "tz"}
        Which period the columns hold.
    headings : mapping of float to float, optional
        Heading [deg] → probability (normalized); default {0: 1}.
    family : {"pierson_moskowitz", "jonswap"}
    source : str

    Returns
    -------
    ScatterDiagram
        One state per non-zero cell and heading.
    """
    headings = {0.0: 1.0} if headings is None else dict(headings)
    if len(occurrence) != len(hs):
        raise InputError("occurrence", len(occurrence), "-", f"must have {len(hs)} rows (hs)")
    h_total = math.fsum(float(p) for p in headings.values())
    for h, p in headings.items():
        if not (math.isfinite(float(p)) and float(p) >= 0):
            raise InputError(f"headings[{h}]", p, "-", "must be finite and >= 0")
    if h_total <= 0:
        raise InputError("headings", headings, "-", "probabilities must not all be zero")
    rows: list[dict[str, Any]] = []
    for i, (h, row) in enumerate(zip(hs, occurrence)):
        if len(row) != len(periods):
            raise InputError(f"occurrence[{i}]", len(row), "-", f"must have {len(periods)} columns")
        for j, (t, n) in enumerate(zip(periods, row)):
            try:
                n = float(n)
            except (TypeError, ValueError):
                raise InputError(f"occurrence[{i}][{j}]", n, "-", "must be a number") from None
            if not math.isfinite(n) or n < 0:
                raise InputError(f"occurrence[{i}][{j}]", n, "-", "must be finite and >= 0")
            if n == 0:
                continue
            for head, ph in headings.items():
                if float(ph) > 0:
                    rows.append({"hs": h, period: t, "heading": head, "hours": n * float(ph)})
    if not rows:
        raise InputError("occurrence", "all zero", "-", "must have a non-zero cell")
    return scatter_from_rows(rows, family=family, source=source)


def _rows_from_csv(text: str) -> list[dict[str, Any]]:
    lines = [ln for ln in text.splitlines() if ln.strip() and not ln.lstrip().startswith("#")]
    reader = csv.DictReader(io.StringIO("\n".join(lines)))
    rows = [{(k or "").strip().lower(): v for k, v in r.items()} for r in reader]
    return rows


def read_scatter(
    source: str | Path | Mapping[str, Any] | Sequence[Mapping[str, Any]],
    *,
    family: Family | None = None,
) -> ScatterDiagram:
    """Read a diagram from a CSV or JSON file, a JSON string or a parsed document.

    Parameters
    ----------
    source : path, str, mapping or sequence
        CSV: a header row with the column names (hs, tp or tz, gamma, heading,
        probability or hours; ``#`` lines are comments, the first ``# source:`` line
        is kept).  JSON: a list of rows, ``{"rows": [...], "spectrum": ..., "source":
        ...}``, or ``{"hs": [...], "tp" | "tz": [...], "occurrence": [[...]],
        "headings": {"0": 0.5, ...}}``.
    family : {"pierson_moskowitz", "jonswap"}, optional
        Spectrum family (default: the document's ``spectrum``, else JONSWAP).

    Returns
    -------
    ScatterDiagram
    """
    doc: Any = source
    src = ""
    if isinstance(source, (str, Path)):
        text = str(source)
        path = Path(text)
        if not text.lstrip().startswith(("[", "{")) and "\n" not in text:
            if not path.is_file():
                raise InputError("scatter", text, "-", "no such file")
            text = path.read_text(encoding="utf-8")
            src = path.name
        if text.lstrip().startswith(("[", "{")):
            try:
                doc = json.loads(text)
            except json.JSONDecodeError as exc:
                raise InputError("scatter", src or "JSON", "-", f"invalid JSON: {exc}") from None
        else:
            for ln in text.splitlines():
                if ln.lstrip().lower().startswith("# source:"):
                    src = ln.split(":", 1)[1].strip()
                    break
            return scatter_from_rows(_rows_from_csv(text), family=family or "jonswap", source=src)
    if isinstance(doc, Mapping):
        fam = family or doc.get("spectrum", "jonswap")
        src = str(doc.get("source", src))
        if "occurrence" in doc:
            pers = [k for k in ("tp", "tz") if doc.get(k) is not None]
            if len(pers) != 1:
                raise InputError("scatter.tp", doc.get("tp"), "s", "give exactly one of tp and tz")
            per = pers[0]
            heads = {}
            for k, v in (doc.get("headings") or {"0": 1}).items():
                try:
                    heads[float(k)] = float(v)
                except (TypeError, ValueError):
                    raise InputError(
                        f"scatter.headings[{k}]", v, "deg", "keys are headings, values "
                        "probabilities: both numbers"
                    ) from None  # fmt: skip
            return scatter_from_matrix(
                doc["hs"], doc[per], doc["occurrence"], period=per, headings=heads,
                family=fam, source=src,
            )  # fmt: skip
        if "rows" not in doc:
            raise InputError("scatter", sorted(doc), "-", "needs 'rows' or 'occurrence'")
        return scatter_from_rows(doc["rows"], family=fam, source=src)
    if isinstance(doc, Sequence):
        return scatter_from_rows(list(doc), family=family or "jonswap", source=src)
    raise InputError("scatter", type(source).__name__, "-", "must be a path, JSON or rows")
