"""POST /v1/sea/realizations: a random sea realization (DSA/NSA) and its kinematics."""

from __future__ import annotations

import math

import numpy as np
from fastapi import APIRouter
from starlette.responses import Response

from service.dependencies import MediaTypeDep, RunnerDep, SettingsDep
from service.encoding import JSON, NPY, array_responses, columns_response, json_response
from service.limits import check_points, check_samples
from service.schemas import RealizationRequest, RealizationResponse
from stochcable.errors import InputError
from stochcable.sea.kinematics import kinematics_timeseries
from stochcable.sea.realization import simulate_sea

router = APIRouter(prefix="/v1", tags=["sea"])

_LAYOUT = (
    "Columns: time [s] (CSV only: in the NPY answer the sample times are t_n = n·dt, "
    "n = 0, 1, ..., not sent), elevation [m], then for each point p = 0, 1, ... "
    "velocity_p_x, velocity_p_y, velocity_p_z [m/s] and acceleration_p_x, "
    "acceleration_p_y, acceleration_p_z [m/s²]; the statistics as JSON in the "
    "X-Stochcable-Stats header."
)


@router.post(
    "/sea/realizations",
    operation_id="simulate_sea",
    response_model=RealizationResponse,
    responses=array_responses(RealizationResponse, _LAYOUT, 413, 422, 504),
    summary="Simulate a random sea realization and its wave kinematics",
)
async def simulate_sea_realization(
    body: RealizationRequest, settings: SettingsDep, runner: RunnerDep, media: MediaTypeDep
) -> Response:
    """η(t) by :func:`stochcable.sea.realization.simulate_sea` (Tuah 1982, §5.1; duration/dt must be an
    even number of samples) and, at ``points``, the velocity and acceleration by
    :func:`stochcable.sea.kinematics.kinematics_timeseries` from the same amplitudes.
    Use ``Accept: application/x-npy`` for long records."""  # noqa: E501 - the OpenAPI description, kept verbatim
    n_points = len(body.points) if body.points else 0
    check_points(n_points, settings)
    check_samples(body.duration, body.dt, n_points, settings)
    return await runner.run(_realization, body, media)


_SQUARE_CHUNK = 65536


def _mean_square(x: np.ndarray) -> float:
    """Σ x²/len(x) in cache-sized chunks: no temporary of the record's size, and no BLAS
    call (np.dot would wake OpenBLAS's threads, which then spin and compete with the
    next computation on a 2-core machine)."""
    buf = np.empty(min(_SQUARE_CHUNK, x.size))
    total = 0.0
    for a in range(0, x.size, _SQUARE_CHUNK):
        seg = x[a : a + _SQUARE_CHUNK]
        sq = buf[: seg.size]
        np.multiply(seg, seg, out=sq)
        total += float(np.add.reduce(sq))
    return total / x.size


def _realization(body: RealizationRequest, media: str) -> Response:
    spectrum, g = body.spectrum, body.g

    def density(w: np.ndarray) -> np.ndarray:
        return spectrum.spectral_density(w, g)

    try:
        sea = simulate_sea(density, body.duration, body.dt, method=body.method, rng=body.seed)
    except InputError as exc:
        if exc.parameter != "density":
            raise
        # the core names its callable argument; the request's input is the spectrum
        raise InputError(
            "spectrum", spectrum.type, "-", f"{exc.constraint} (sampled on the record's grid)"
        ) from None
    # target variance: the Riemann sum over the simulated lines m = 1 … N-1 (X_0 = X_N = 0),
    # as simulate_sea computed it from the S it evaluated (no second evaluation of S)
    variance = _mean_square(sea.elevation)
    stats = {"variance": variance, "m0": sea.m0}
    kin = None
    if body.points:
        kin = kinematics_timeseries(
            sea,
            np.asarray(body.points, dtype=float),
            math.radians(body.heading),
            body.depth_or_inf(),
            g,
        )
    if media == JSON:
        payload = {"time": sea.time, "elevation": sea.elevation, "stats": stats}
        if kin is not None:
            payload["kinematics"] = {"velocity": kin[0], "acceleration": kin[1]}
        return json_response(payload)
    # NPY: no time column (t_n = n·dt): it would double the answer for one known column
    columns = (
        {"elevation": sea.elevation}
        if media == NPY
        else {"time": sea.time, "elevation": sea.elevation}
    )
    if kin is not None:
        for name, arr in (("velocity", kin[0]), ("acceleration", kin[1])):
            for p in range(arr.shape[0]):
                for c, axis in enumerate("xyz"):
                    columns[f"{name}_{p}_{axis}"] = arr[p, c]
    # a finite sum of squares means every elevation sample is finite (the check the
    # encoder would otherwise repeat over the 8 MiB); kinematics columns are still checked
    return columns_response(
        columns, media, stats, finite=("elevation",) if math.isfinite(variance) else ()
    )
