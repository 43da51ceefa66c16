"""The computations the worker processes run (:mod:`service.workers`).

Module-level functions, pickled by reference: the HTTP process sends the function and
its arguments (the scene document as the validated model, never arrays) and gets back
what it returns (the encoded result document).
"""

from __future__ import annotations

from stochcable.scene.model import Scene

from .encoding import all_finite, dumps
from .errors import NumericalError, memory_error
from .limits import checked_call

__all__ = ["analysis_job", "non_finite_error"]


def analysis_job(
    scene: Scene, timeseries: str, netcdf: bool = False, timeseries_linear: bool = False
) -> tuple[bytes, int]:
    """Analyse a scene and encode its result document (in a worker process).

    Parameters
    ----------
    scene : Scene
        The validated scene document.
    timeseries : {"window", "full", "none"}
        Time series in the document.
    netcdf : bool
        Answer the result as a NetCDF-4 file (its Dataset) instead of JSON.
    timeseries_linear : bool
        Also the linear model's end tensions beside the series that carry the
        residuals' component.

    Returns
    -------
    body : bytes
        The v1 result document as compact JSON, or the NetCDF file.
    n_warnings : int
        Entries of its ``warnings`` list.

    Raises
    ------
    LimitExceeded
        On MemoryError (the worker's address-space limit), naming what to reduce.
    NumericalError
        For non-finite results or arithmetic failures of the core on accepted input.
    """
    from stochcable.analysis import analyze
    from stochcable.cost import estimate_cost

    try:
        # the core's own floating-point policy (the result equals analyze()'s);
        # arithmetic failures escaping it become NumericalError (422)
        result = checked_call(False, analyze, scene)
        doc = result.to_document(timeseries=timeseries, timeseries_linear=timeseries_linear)
        if not all_finite(doc):
            raise non_finite_error(scene, doc)
        if netcdf:
            from stochcable.results.datasets import dataset_from_result, netcdf_bytes

            dataset = dataset_from_result(result, timeseries_linear=timeseries_linear)
            return netcdf_bytes(dataset), len(doc.get("warnings", ()))
        return dumps(doc), len(doc.get("warnings", ()))
    except MemoryError as exc:
        hint = estimate_cost(scene).reduce_hint()
        raise memory_error(exc, hint) from None


def non_finite_error(scene: Scene, doc: dict) -> NumericalError:
    """NumericalError naming the first line or body whose results are not finite."""
    for key, items in (("lines", scene.lines), ("bodies", scene.bodies)):
        names = [item.name for item in items]
        for name, part in (doc.get(key) or {}).items():
            if not all_finite(part) and name in names:
                return NumericalError(
                    f"the results of {key[:-1]} {name!r} contain non-finite values (NaN or inf)",
                    parameter=f"{key}[{names.index(name)}]",
                )
    return NumericalError("the result document contains non-finite values (NaN or inf)")
