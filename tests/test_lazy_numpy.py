"""NumPy's tool submodules that SciPy's import loads are lazy after a stochcable entry
point's import, and still work on first use (stochcable.lazy_numpy)."""

from __future__ import annotations

import subprocess
import sys

_CODE = """
import sys{pre}
import stochcable
stochcable.build_engine  # (the lazy entry point: NumPy, SciPy and the engine)
import numpy, scipy.linalg
print("numpy.f2py.crackfortran" in sys.modules, "numpy.testing._private.utils" in sys.modules)
numpy.testing.assert_allclose(1.0, 1.0)
from numpy.f2py import run_main
print(callable(run_main), numpy.f2py is sys.modules["numpy.f2py"])
print(type(sys.modules["numpy.f2py"]) is type(sys), "numpy.f2py.crackfortran" in sys.modules)
"""


def _run(pre: str = "") -> list[str]:
    code = _CODE.format(pre=pre)
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    return out.stdout.split()


def test_the_tool_submodules_are_bound_unexecuted_and_load_on_first_use():
    # bound to numpy (SciPy's star import found them) but not executed; the first
    # attribute access executes them as an import would
    assert _run() == ["False", "False", "True", "True", "True", "True"]


def test_a_submodule_imported_before_is_left_as_it_is():
    assert _run("; import numpy.testing") == ["False", "True", "True", "True", "True", "True"]
