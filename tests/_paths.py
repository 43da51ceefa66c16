"""Where the tests find the repository and their reference files.

Tests live in folders mirroring the package (tests/sea/, tests/line/, ...), so a path built
from a test's own ``__file__`` would depend on how deep it sits; they take these instead.
"""

from __future__ import annotations

from pathlib import Path

#: The tests' root folder: the helper modules, tests/golden/, tests/data/ and
#: tests/residual_variances_v1.json.
TESTS = Path(__file__).resolve().parent

#: The repository's root (benchmarks/, docs/, stochcable/).
ROOT = TESTS.parent

#: MoorDyn input files (tests/data/moordyn/).
MOORDYN_DATA = TESTS / "data" / "moordyn"
