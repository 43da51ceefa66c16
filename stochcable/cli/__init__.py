"""The ``stochcable`` command line.

Each sub-command lives in its own module in this package and exposes
``register(subparsers)``, which adds its parser and sets ``func`` to a callable taking
the parsed namespace and returning an exit code.  Modules are discovered, so adding a
command is adding a file.  Errors a user causes, and running out of memory, are printed
as one line on stderr with exit code 2; no traceback.
"""

from __future__ import annotations

import argparse
import importlib
import pkgutil
import sys
import warnings
from collections.abc import Callable, Sequence

from stochcable import runtime
from stochcable.errors import StochcableError

__all__ = ["main", "build_parser"]


def build_parser() -> argparse.ArgumentParser:
    """Build the top-level parser with every sub-command module found in this package."""
    from stochcable import __version__

    parser = argparse.ArgumentParser(
        prog="stochcable",
        description="Frequency-domain stochastic response of marine cables in random seas.",
    )
    parser.add_argument("--version", action="version", version=f"stochcable {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    sub.required = True
    for info in sorted(pkgutil.iter_modules(__path__), key=lambda m: m.name):
        if info.name.startswith("_"):
            continue
        module = importlib.import_module(f"{__name__}.{info.name}")
        register = getattr(module, "register", None)
        if register is not None:
            register(sub)
    return parser


def warning_printer() -> Callable[..., None]:
    """A ``warnings.showwarning`` that writes each message once on stderr
    (``stochcable: warning: ...``), however often it is issued, as the summary lists
    the result's warnings once."""
    seen: set[str] = set()

    def show(message, category, filename, lineno, file=None, line=None):  # noqa: ANN001
        text = str(message)
        if text not in seen:
            seen.add(text)
            sys.stderr.write(f"stochcable: warning: {text}\n")

    return show


def main(argv: Sequence[str] | None = None) -> int:
    """Run the CLI; returns the process exit code."""
    parser = build_parser()
    args = parser.parse_args(argv)
    warnings.showwarning = warning_printer()
    runtime.configure()  # the command line's process settings (stochcable.runtime)
    try:
        return int(args.func(args) or 0)
    except StochcableError as exc:
        sys.stderr.write(f"stochcable {args.command}: error: {exc}\n")
        return 2
    except (OSError, ValueError) as exc:  # unreadable file, malformed JSON
        sys.stderr.write(f"stochcable {args.command}: error: {exc}\n")
        return 2
    except ArithmeticError as exc:  # overflow or 0/0 in the core from extreme input
        sys.stderr.write(
            f"stochcable {args.command}: error: numerical failure ({type(exc).__name__}: "
            f"{exc}): an input is outside the range the model handles numerically (check "
            "magnitudes and units: periods, heights, frequencies, depth)\n"
        )
        return 2
    except MemoryError as exc:  # numpy's "Unable to allocate ..." or a bare MemoryError
        what = str(exc).splitlines()[0] if str(exc) else "a MemoryError"
        sys.stderr.write(
            f"stochcable {args.command}: error: out of memory ({what}); reduce the size "
            "of the problem (elements, frequencies, time-series samples)\n"
        )
        return 2


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
