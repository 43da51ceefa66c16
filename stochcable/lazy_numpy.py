"""NumPy's tool submodules that SciPy's import loads and no analysis uses, loaded lazily.

Every SciPy subpackage (``scipy.linalg``, ``scipy.sparse``) imports SciPy's array-API
layer, which clones NumPy's namespace with ``from numpy import *``; that star import
loads each of NumPy's lazily imported submodules, among them ``numpy.f2py`` (the
Fortran wrapper generator, with ``charset_normalizer`` where it is installed) and
``numpy.testing`` (with ``unittest``): ≈ 45 % of SciPy's import and ≈ 13 % of the
first analysis of the chain (docs/benchmarks/first_analysis.md).  :func:`defer` puts
those two in ``sys.modules`` as lazy modules (``importlib.util.LazyLoader``, the
standard library's lazy import): the star import binds them without executing them,
and the first attribute access (``numpy.testing.assert_allclose``, ``from numpy.f2py
import ...``) executes the module as an import would.  A submodule already imported
is left as it is.
"""

from __future__ import annotations

import importlib.util
import sys

__all__ = ["DEFERRED", "defer"]

DEFERRED = ("numpy.f2py", "numpy.testing")
"""NumPy submodules made lazy by :func:`defer` (``numpy.ma`` is not: ``numpy.unique``
uses it)."""


def defer() -> None:
    """Make the :data:`DEFERRED` submodules of NumPy lazy, unless already imported.

    Imports NumPy.  Call before SciPy's first import to take effect.
    """
    import numpy

    for name in DEFERRED:
        if name in sys.modules:
            continue
        spec = importlib.util.find_spec(name)
        if spec is None or spec.loader is None:
            continue
        spec.loader = importlib.util.LazyLoader(spec.loader)
        module = importlib.util.module_from_spec(spec)
        sys.modules[name] = module
        spec.loader.exec_module(module)
        # as the import system binds a submodule to its package
        setattr(numpy, name.rpartition(".")[2], module)
