"""The MoorDyn input file as tables: sections, rows and their positions in the file.

MoorDyn (Hall 2015-2024) reads a text file of sections, each opened by a header line
that holds ``---`` and the section's name.  A table section has a row of column names
and a row of units before its data rows; OPTIONS hold ``value name`` rows; OUTPUTS
hold channel names up to ``END``.  Version 1 (MoorDyn-C 1.x, MoorDyn-F 1.x: LINE
DICTIONARY, NODE or CONNECTION PROPERTIES, LINE PROPERTIES, SOLVER OPTIONS) and
version 2 (LINE TYPES, POINTS, LINES, OPTIONS, ...) differ in their section names and
columns; this module reads both into one form, :class:`MoorDynTables`, keeping each
row's line number for the messages.  The meaning of the rows is
:mod:`stochcable.io.moordyn_read`'s.

References
----------
Hall, M. (2024), MoorDyn v2 input file documentation,
https://moordyn.readthedocs.io/en/latest/inputs.html.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field

from stochcable.errors import InputError

__all__ = [
    "MoorDynInputError",
    "Row",
    "Table",
    "MoorDynTables",
    "is_moordyn_text",
    "split_tables",
]

#: Section kinds and the header words that open them (upper case; MoorDyn-C 2.7
#: ``findStartOfSection`` matches them anywhere in a line holding ``---``).  Order
#: matters: "LINE TYPES" before "LINES".
_SECTIONS: tuple[tuple[str, tuple[str, ...]], ...] = (
    ("line_types", ("LINE DICTIONARY", "LINE TYPES")),
    ("rod_types", ("ROD DICTIONARY", "ROD TYPES")),
    ("bodies", ("BODIES", "BODY LIST", "BODY PROPERTIES")),
    ("rods", ("RODS", "ROD LIST", "ROD PROPERTIES")),
    (
        "points",
        ("POINTS", "POINT LIST", "POINT PROPERTIES", "CONNECTION PROPERTIES", "NODE PROPERTIES"),
    ),
    ("lines", ("LINES", "LINE LIST", "LINE PROPERTIES")),
    ("options", ("OPTIONS",)),
    ("outputs", ("OUTPUT",)),
    ("failure", ("FAILURE",)),
    ("other", ("EXTERNAL", "CONTROL", "SYROPE", "BODY", "ROD")),
)

#: The sections whose first two rows are the column names and the units.
_TABLES = ("line_types", "rod_types", "bodies", "rods", "points", "lines", "failure")

_COUNT_ROW = re.compile(r"^\s*\d+\s+N\w+")  # MoorDyn-F 1.x: "3  NTypes - number of ..."


class MoorDynInputError(InputError):
    """An error in a MoorDyn input file, at a line (1-based) and column (1-based).

    The message names the file's line, the column, the section and what is wrong:
    ``MoorDyn file line 17, column 3 (LINES) = 'R1A': ...``.
    """

    def __init__(self, line: int, column: int, section: str, value: object, why: str) -> None:
        self.line = int(line)
        self.column = int(column)
        self.section = section
        where = f"MoorDyn file line {self.line}, column {self.column}"
        if section:
            where += f" ({section})"
        super().__init__(where, value, "-", why)


@dataclass(frozen=True)
class Row:
    """One data row of a section: its tokens, their 1-based columns and its line."""

    line: int
    tokens: tuple[str, ...]
    columns: tuple[int, ...]
    text: str

    def error(self, section: str, index: int, why: str) -> MoorDynInputError:
        """An error about token ``index`` (past the end: the row's end)."""
        if index < len(self.tokens):
            return MoorDynInputError(
                self.line, self.columns[index], section, self.tokens[index], why
            )
        return MoorDynInputError(
            self.line, len(self.text.rstrip()) + 1, section, self.text.strip(), why
        )

    def number(self, section: str, index: int, name: str) -> float:
        """Token ``index`` as a finite float (an error naming the column otherwise)."""
        if index >= len(self.tokens):
            raise self.error(section, index, f"no value for {name}: too few columns")
        try:
            v = float(self.tokens[index].replace("D", "E").replace("d", "e"))
        except ValueError:
            raise self.error(section, index, f"{name} must be a number") from None
        if v != v or v in (float("inf"), float("-inf")):
            raise self.error(section, index, f"{name} must be finite")
        return v

    def integer(self, section: str, index: int, name: str) -> int:
        """Token ``index`` as an integer."""
        v = self.number(section, index, name)
        if v != int(v):
            raise self.error(section, index, f"{name} must be a whole number")
        return int(v)


@dataclass(frozen=True)
class Table:
    """A section: its name as written, header line, column names and data rows."""

    kind: str
    title: str
    line: int
    names: tuple[str, ...] = ()
    rows: tuple[Row, ...] = ()


@dataclass(frozen=True)
class MoorDynTables:
    """The sections of a MoorDyn file by kind, and the free text before the first."""

    description: str
    sections: dict[str, Table] = field(default_factory=dict)
    n_lines: int = 0

    def get(self, kind: str) -> Table | None:
        """The section of that kind, or None."""
        return self.sections.get(kind)


def is_moordyn_text(text: str) -> bool:
    """True when ``text`` looks like a MoorDyn input file: its first non-blank line
    holds ``---`` and the word MoorDyn, or a line holding ``---`` names one of the
    LINE TYPES / LINE DICTIONARY sections."""
    for raw in text.splitlines():
        s = raw.strip()
        if not s:
            continue
        if s.startswith("{"):
            return False
        if "---" in s and "MOORDYN" in s.upper():
            return True
        break
    return any(
        "---" in raw and ("LINE TYPES" in raw.upper() or "LINE DICTIONARY" in raw.upper())
        for raw in text.splitlines()
    )


def _kind(header: str) -> str | None:
    up = header.upper()
    if "MOORDYN" in up or "NEED THIS LINE" in up:
        return None
    for kind, words in _SECTIONS:
        if any(w in up for w in words):
            return kind
    return None


def _tokens(text: str) -> tuple[tuple[str, ...], tuple[int, ...]]:
    toks, cols = [], []
    for m in re.finditer(r"\S+", text.replace("\t", " ")):
        toks.append(m.group(0))
        cols.append(m.start() + 1)
    return tuple(toks), tuple(cols)


def _is_units_row(tokens: tuple[str, ...]) -> bool:
    return bool(tokens) and all(t[0] in "([" for t in tokens)


def split_tables(text: str) -> MoorDynTables:
    """Split a MoorDyn file into its sections.

    Parameters
    ----------
    text : str
        The file's text.

    Returns
    -------
    MoorDynTables

    Raises
    ------
    MoorDynInputError
        A table without its column-name or units row, a section named twice, text
        after the OUTPUTS' ``END`` (other than the closing ``---`` line), or no
        LINE TYPES / LINES / POINTS section.
    """
    lines = text.splitlines()
    description: list[str] = []
    sections: dict[str, Table] = {}
    i = 0
    n = len(lines)
    # free text before the first section: the title line(s)
    while i < n and ("---" not in lines[i] or _kind(lines[i]) is None):
        s = lines[i].strip()
        if s and "---" not in s and not re.match(r"^\S+\s+Echo\b", s, re.IGNORECASE):
            description.append(s)
        i += 1
    after_end = False
    while i < n:
        raw = lines[i]
        kind = _kind(raw) if "---" in raw else None
        if kind is None:
            s = raw.strip()
            if s and "---" not in s and after_end:
                raise MoorDynInputError(
                    i + 1,
                    len(raw) - len(raw.lstrip()) + 1,
                    "OUTPUTS",
                    s,
                    "text after the END line (only the closing '---' line may follow)",
                )
            i += 1
            continue
        title = raw.strip("- \t")
        if kind in sections:
            raise MoorDynInputError(
                i + 1,
                1,
                title,
                title,
                f"a second {title} section (the first is at line {sections[kind].line})",
            )
        start = i + 1
        j = start
        body: list[tuple[int, str]] = []
        while j < n and "---" not in lines[j]:
            if lines[j].strip():
                body.append((j + 1, lines[j]))
            j += 1
        names: tuple[str, ...] = ()
        rows: list[Row] = []
        if kind in _TABLES:
            if body and _COUNT_ROW.match(body[0][1]) and not _is_units_row(_tokens(body[0][1])[0]):
                toks = _tokens(body[0][1])[0]
                if (
                    len(toks) >= 2
                    and toks[1].upper().startswith("N")
                    and not toks[1][1:2].isdigit()
                ):
                    body = body[1:]
            if not body:
                raise MoorDynInputError(
                    i + 1,
                    1,
                    title,
                    title,
                    "the section has no row of column names and no units row",
                )
            names = _tokens(body[0][1])[0]
            if len(body) < 2 or not _is_units_row(_tokens(body[1][1])[0]):
                ln = body[1][0] if len(body) >= 2 else body[0][0] + 1
                got = body[1][1].strip() if len(body) >= 2 else ""
                raise MoorDynInputError(
                    ln,
                    1,
                    title,
                    got,
                    "missing units row: the row after the column names must give "
                    "each column's unit in parentheses, e.g. (m) (kg/m) (N)",
                )
            data = body[2:]
        else:
            data = body
        for ln, t in data:
            toks, cols = _tokens(t)
            if kind == "outputs" and after_end:
                raise MoorDynInputError(
                    ln,
                    cols[0],
                    title,
                    t.strip(),
                    "text after the END line (only the closing '---' line may follow)",
                )
            if kind == "outputs" and toks and toks[0].upper() == "END":
                after_end = True
                if len(toks) > 1:
                    raise MoorDynInputError(
                        ln, cols[1], title, toks[1], "text after END on the END line"
                    )
                continue
            rows.append(Row(ln, toks, cols, t))
        key = kind if kind != "other" else f"other:{title}"
        sections[key] = Table(kind, title, i + 1, names, tuple(rows))
        i = j
    for kind, name, v1 in (
        ("line_types", "LINE TYPES", "LINE DICTIONARY"),
        ("points", "POINTS", "NODE PROPERTIES"),
        ("lines", "LINES", "LINE PROPERTIES"),
    ):
        if kind not in sections:
            raise MoorDynInputError(
                n, 1, name, "missing", f"the file has no {name} section (v1: {v1})"
            )
    return MoorDynTables(" ".join(description), sections, n)
