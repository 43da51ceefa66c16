"""The house rules of the code layout (docs/ARCHITECTURE.md, "Guards"), checked on the
source of ``stochcable/`` and ``service/``:

(a) no module imports a private name (``_name``, not a dunder) from a module of another
    unit — a unit is a subpackage (``stochcable.dynamics``, ``service.routers``) or a
    top-level module (``stochcable.runtime``, ``service.limits``); modules of one
    subpackage may share private helpers.  A private module (``stochcable.cli._output``)
    is imported only inside its own package.  Imports inside functions count.
(b) no module of ``stochcable/`` is longer than :data:`MODULE_LIMIT` lines;
(c) no function is longer than :data:`FUNCTION_LIMIT` lines of code (from its ``def``
    to its end, the docstring not counted: documentation is read apart from the code);
(d) a function ``<name>_unchecked`` (a trusted kernel) has its checked twin ``<name>``
    in the same module, which calls it (docs/ARCHITECTURE.md, "Conventions").

Each rule has an explicit allow-list of today's offenders (the restructure of issue 13
is in progress) that may only shrink: an entry is also an upper bound (an allowed
module or function may not grow), and an entry no longer needed fails the test so that
it is removed.  Failures name the module (file:line) and what to do.
"""

from __future__ import annotations

import ast
import sys
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
PACKAGES = ("stochcable", "service")

MODULE_LIMIT = 600
"""Largest module of stochcable/, lines. [-]"""

FUNCTION_LIMIT = 150
"""Largest function, lines of code (def line to end, docstring excluded). [-]"""

# Today's offenders (issue 13 in progress), path -> lines now.  Only remove entries; the
# number is the most the module may have until it is split.
LONG_MODULES: dict[str, int] = {}

# path::qualified name -> lines of code now.  Only remove entries.
LONG_FUNCTIONS: dict[str, int] = {}

# (importer, module, private name) -> what should replace it.  Only remove entries.
PRIVATE_IMPORTS: dict[tuple[str, str, str], str] = {}


# ---------------------------------------------------------------------------- source


@dataclass(frozen=True)
class Module:
    name: str  # dotted, e.g. stochcable.dynamics.line
    path: Path
    rel: str  # path relative to the repository, with /
    tree: ast.Module
    is_package: bool

    @property
    def package(self) -> str:
        """The package this module is in (itself for an __init__)."""
        return self.name if self.is_package else self.name.rpartition(".")[0]


def _modules() -> list[Module]:
    out = []
    for pkg in PACKAGES:
        for path in sorted((ROOT / pkg).rglob("*.py")):
            rel = path.relative_to(ROOT).as_posix()
            parts = list(path.relative_to(ROOT).with_suffix("").parts)
            is_package = parts[-1] == "__init__"
            if is_package:
                parts = parts[:-1]
            tree = ast.parse(path.read_text(encoding="utf-8"), filename=rel)
            out.append(Module(".".join(parts), path, rel, tree, is_package))
    return out


MODULES = _modules()
MODULE_NAMES = {m.name for m in MODULES}


def _private(name: str) -> bool:
    return name.startswith("_") and not (name.startswith("__") and name.endswith("__"))


def _unit(module: str) -> str:
    """stochcable.dynamics.line -> stochcable.dynamics; stochcable.runtime -> itself."""
    return ".".join(module.split(".")[:2])


def _absolute(module: Module, node: ast.ImportFrom) -> str:
    if not node.level:
        return node.module or ""
    base = module.package.split(".")
    if node.level > 1:
        base = base[: len(base) - (node.level - 1)]
    return ".".join(base + ([node.module] if node.module else []))


@dataclass(frozen=True)
class Import:
    line: int
    module: str  # absolute module imported from (or imported)
    name: str | None  # the name imported from it (None: `import module`)


def _imports(module: Module) -> Iterator[Import]:
    """Every import of the module, at any depth (functions, classes, conditionals)."""
    for node in ast.walk(module.tree):
        if isinstance(node, ast.Import):
            for alias in node.names:
                yield Import(node.lineno, alias.name, None)
        elif isinstance(node, ast.ImportFrom):
            src = _absolute(module, node)
            for alias in node.names:
                yield Import(node.lineno, src, alias.name)


def _ours(name: str) -> bool:
    return name.split(".")[0] in PACKAGES


# ----------------------------------------------------------------------- (a) privates


def _private_import_violations() -> list[tuple[tuple[str, str, str], str]]:
    found = []
    for m in MODULES:
        for imp in _imports(m):
            if not _ours(imp.module):
                continue
            # a private module on the path: only inside its parent package
            parts = imp.module.split(".")
            if imp.name is not None and f"{imp.module}.{imp.name}" in MODULE_NAMES:
                parts = parts + [imp.name]  # `from pkg import _module`
            for i, part in enumerate(parts):
                if _private(part):
                    parent = ".".join(parts[:i])
                    if not (m.name == parent or m.name.startswith(parent + ".")):
                        found.append(
                            (
                                (m.rel, ".".join(parts[: i + 1]), part),
                                f"{m.rel}:{imp.line}: imports the private module "
                                f"{'.'.join(parts[: i + 1])} from outside {parent}",
                            )
                        )
                    break
            else:
                # a private name from a module of another unit
                if (
                    imp.name is not None
                    and _private(imp.name)
                    and _unit(imp.module) != _unit(m.name)
                ):
                    found.append(
                        (
                            (m.rel, imp.module, imp.name),
                            f"{m.rel}:{imp.line}: imports the private name "
                            f"{imp.name} from {imp.module} (another unit than "
                            f"{_unit(m.name)})",
                        )
                    )
    return found


def _module_aliases(module: Module) -> dict[str, str]:
    """Local names bound to one of our modules by an import (``from pkg import mod as x``,
    ``import pkg.mod as x``), anywhere in the module."""
    out = {}
    for node in ast.walk(module.tree):
        if isinstance(node, ast.Import):
            for alias in node.names:
                if alias.asname and alias.name in MODULE_NAMES:
                    out[alias.asname] = alias.name
        elif isinstance(node, ast.ImportFrom):
            src = _absolute(module, node)
            for alias in node.names:
                if f"{src}.{alias.name}" in MODULE_NAMES:
                    out[alias.asname or alias.name] = f"{src}.{alias.name}"
    return out


def _private_attribute_violations() -> list[tuple[tuple[str, str, str], str]]:
    """``mod._name`` and ``getattr(mod, "_name")`` on a module of another unit."""
    found = []
    for m in MODULES:
        aliases = _module_aliases(m)
        for node in ast.walk(m.tree):
            target = attr = None
            if isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name):
                target, attr = node.value.id, node.attr
            elif (
                isinstance(node, ast.Call)
                and isinstance(node.func, ast.Name)
                and node.func.id in ("getattr", "setattr", "hasattr")
                and len(node.args) >= 2
                and isinstance(node.args[0], ast.Name)
                and isinstance(node.args[1], ast.Constant)
                and isinstance(node.args[1].value, str)
            ):
                target, attr = node.args[0].id, node.args[1].value
            if target in aliases and _private(attr) and _unit(aliases[target]) != _unit(m.name):
                found.append(
                    (
                        (m.rel, aliases[target], attr),
                        f"{m.rel}:{node.lineno}: uses the private name {attr} of "
                        f"{aliases[target]} (another unit than {_unit(m.name)})",
                    )
                )
    return found


def test_no_private_names_imported_across_subpackages():
    found = _private_import_violations() + _private_attribute_violations()
    new = [msg for key, msg in found if key not in PRIVATE_IMPORTS]
    assert not new, (
        "private names reached across subpackages: make the name public (documented) in "
        "the module that owns it, or move the code to the subpackage that uses it:\n  "
        + "\n  ".join(new)
    )
    stale = sorted(set(PRIVATE_IMPORTS) - {key for key, _ in found})
    assert not stale, (
        "remove these entries from PRIVATE_IMPORTS in "
        f"tests/test_architecture.py (no longer imported): {stale}"
    )


# -------------------------------------------------------------------- (b) module size


def _lines(path: Path) -> int:
    return len(path.read_text(encoding="utf-8").splitlines())


def test_modules_are_at_most_the_line_limit():
    sizes = {m.rel: _lines(m.path) for m in MODULES if m.rel.startswith("stochcable/")}
    problems = []
    for rel, n in sorted(sizes.items()):
        allowed = LONG_MODULES.get(rel, MODULE_LIMIT)
        if n > allowed:
            how = (
                "split it"
                if rel not in LONG_MODULES
                else f"it is on the allow-list at {allowed} lines and may not grow"
            )
            problems.append(f"{rel}:1: {n} lines > {allowed} ({how})")
    assert not problems, f"modules over {MODULE_LIMIT} lines:\n  " + "\n  ".join(problems)
    stale = sorted(rel for rel in LONG_MODULES if rel not in sizes or sizes[rel] <= MODULE_LIMIT)
    assert not stale, (
        "remove these entries from LONG_MODULES in "
        f"tests/test_architecture.py (gone or within {MODULE_LIMIT} lines): "
        f"{stale}"
    )


# ------------------------------------------------------------------ (c) function size


def _functions(tree: ast.AST, prefix: str = "") -> Iterator[tuple[str, ast.AST]]:
    for node in ast.iter_child_nodes(tree):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
            qual = f"{prefix}{node.name}"
            if not isinstance(node, ast.ClassDef):
                yield qual, node
            yield from _functions(node, qual + ".")
        else:
            yield from _functions(node, prefix)


def _code_lines(node: ast.FunctionDef | ast.AsyncFunctionDef) -> int:
    """Lines from the def to the end, without the docstring."""
    span = node.end_lineno - node.lineno + 1
    first = node.body[0]
    if (
        isinstance(first, ast.Expr)
        and isinstance(first.value, ast.Constant)
        and isinstance(first.value.value, str)
    ):
        span -= first.end_lineno - first.lineno + 1
    return span


def test_functions_are_at_most_the_line_limit():
    sizes, where = {}, {}
    for m in MODULES:
        for qual, node in _functions(m.tree):
            key = f"{m.rel}::{qual}"
            sizes[key] = _code_lines(node)
            where[key] = f"{m.rel}:{node.lineno}"
    problems = []
    for key, n in sorted(sizes.items()):
        allowed = LONG_FUNCTIONS.get(key, FUNCTION_LIMIT)
        if n > allowed:
            how = (
                "split it into steps"
                if key not in LONG_FUNCTIONS
                else f"it is on the allow-list at {allowed} lines and may not grow"
            )
            problems.append(
                f"{where[key]}: {key.split('::')[1]} has {n} lines of code > {allowed} ({how})"
            )
    assert not problems, f"functions over {FUNCTION_LIMIT} lines of code:\n  " + "\n  ".join(
        problems
    )
    stale = sorted(k for k in LONG_FUNCTIONS if k not in sizes or sizes[k] <= FUNCTION_LIMIT)
    assert not stale, (
        "remove these entries from LONG_FUNCTIONS in "
        f"tests/test_architecture.py (gone or within {FUNCTION_LIMIT} lines): "
        f"{stale}"
    )


# -------------------------------------------------------------- the checks themselves


@pytest.mark.parametrize(
    "source, importer, expected",
    [
        ("from stochcable.dynamics.line import _x", "stochcable.results.documents", 1),
        ("from stochcable.dynamics.line import _x", "stochcable.dynamics.groups", 0),
        ("def f():\n    from stochcable.errors import _local", "stochcable.runtime", 1),
        ("from stochcable.errors import __version__", "stochcable.runtime", 0),
        ("from stochcable.cli._output import write_json", "stochcable.cli.analyze", 0),
        ("from stochcable.cli._output import write_json", "stochcable.client", 1),
        ("from stochcable.cli import _output", "stochcable.client", 1),
        ("from .._output import write_json", "stochcable.cli.sub.mod", 0),
        ("from ..errors import _hidden", "service.routers.sea", 1),
        ("from numpy import _private", "stochcable.sea.fft", 0),
        ("from stochcable.dynamics import engine as a\na._state", "stochcable.runtime", 1),
        (
            "from stochcable.dynamics import engine as a\ngetattr(a, '_state', 0)",
            "stochcable.runtime",
            1,
        ),
        ("import stochcable.dynamics.engine as a\na.public", "stochcable.runtime", 0),
    ],
)
def test_private_import_rule_on_snippets(monkeypatch, source, importer, expected):
    this = sys.modules[__name__]
    m = Module(importer, Path("x.py"), importer.replace(".", "/") + ".py", ast.parse(source), False)
    monkeypatch.setattr(this, "MODULES", [m])
    monkeypatch.setattr(this, "MODULE_NAMES", MODULE_NAMES | {"stochcable.cli._output"})
    assert len(_private_import_violations() + _private_attribute_violations()) == expected


# ------------------------------------------------------- checked and unchecked functions


def _unchecked_pair_violations(modules: list[Module]) -> list[str]:
    """(d) docs/ARCHITECTURE.md "Conventions": a trusted kernel ``<name>_unchecked`` sits
    in the module of its checked twin ``<name>``, which validates and then calls it."""
    problems = []
    for m in modules:
        defs = {n.name: n for n in m.tree.body if isinstance(n, ast.FunctionDef)}
        for name, node in defs.items():
            if not name.endswith("_unchecked"):
                continue
            twin = defs.get(name.removesuffix("_unchecked"))
            calls = twin is not None and any(
                isinstance(c, ast.Call) and getattr(c.func, "id", None) == name
                for c in ast.walk(twin)
            )
            if not calls:
                problems.append(
                    f"{m.rel}:{node.lineno}: {name} needs its checked twin "
                    f"{name.removesuffix('_unchecked')}() in this module, calling it after "
                    "the input checks"
                )
    return problems


def test_every_unchecked_kernel_has_its_checked_twin():
    problems = _unchecked_pair_violations(MODULES)
    assert not problems, "\n".join(problems)


@pytest.mark.parametrize(
    "source, expected",
    [
        ("def f(x):\n    return f_unchecked(x)\ndef f_unchecked(x):\n    return x", 0),
        ("def f_unchecked(x):\n    return x", 1),
        ("def f(x):\n    return x\ndef f_unchecked(x):\n    return x", 1),
    ],
)
def test_unchecked_pair_rule_on_snippets(source, expected):
    m = Module("stochcable.x", Path("x.py"), "stochcable/x.py", ast.parse(source), False)
    assert len(_unchecked_pair_violations([m])) == expected
