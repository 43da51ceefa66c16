"""POST /v1/spectra: sample a spectrum document and compute its statistics."""

from __future__ import annotations

import math

from fastapi import APIRouter
from starlette.responses import Response

from service.dependencies import MediaTypeDep, RunnerDep, SettingsDep
from service.encoding import JSON, array_responses, columns_response, json_response
from service.limits import check_frequencies
from service.schemas import SpectrumRequest, SpectrumResponse, peak_period
from stochcable.errors import InputError
from stochcable.scene.spectra import TableSpectrum
from stochcable.sea.spectra import spectrum_statistics

router = APIRouter(prefix="/v1", tags=["spectra"])

_LAYOUT = (
    "Columns: omega [rad/s], density [unit²·s/rad]; the statistics as JSON in the "
    "X-Stochcable-Stats header."
)


@router.post(
    "/spectra",
    operation_id="compute_spectrum",
    response_model=SpectrumResponse,
    responses=array_responses(SpectrumResponse, _LAYOUT, 413, 422, 504),
    summary="Sample a wave spectrum and compute its moments",
)
async def compute_spectrum(
    body: SpectrumRequest, settings: SettingsDep, runner: RunnerDep, media: MediaTypeDep
) -> Response:
    """S(ω) of the spectrum document on the grid, with m0…m4, Hs, Tz, Tm01, Tp and the
    bandwidth, exactly as :func:`stochcable.sea.spectra.spectrum_statistics` gives them."""
    check_frequencies(body.omega_count(), settings)
    return await runner.run(_spectrum, body, media)


def _spectrum(body: SpectrumRequest, media: str) -> Response:
    omega = body.omega_values()
    try:
        density = body.spectrum.spectral_density(omega, body.g)
        stats = spectrum_statistics(omega, density).as_dict()
    except ArithmeticError as exc:  # overflow, underflow to 0/0 (the service's strict FP)
        raise _out_of_range(body, exc) from None
    if media == JSON:
        return json_response({"omega": omega, "density": density, "stats": stats})
    return columns_response({"omega": omega, "density": density}, media, stats)


def _out_of_range(body: SpectrumRequest, exc: ArithmeticError) -> InputError:
    """The input that put the density or its moments m0…m4 outside double precision.

    A table's density above 1e100 unit²·s/rad: ``spectrum.density``.  Otherwise the
    grid (``omega``) when one is given: far from the spectral peak, ω⁴·S overflows
    (ω beyond ~1e75 rad/s) or the far tail underflows so that m0·m4 = 0.  Else the
    spectrum itself.
    """
    why = f"{type(exc).__name__}: {exc}"
    spectrum = body.spectrum
    if isinstance(spectrum, TableSpectrum) and max(spectrum.density) > 1e100:
        return InputError(
            "spectrum.density",
            max(spectrum.density),
            "unit²·s/rad",
            f"the table's largest density is so large that its spectral moments m0…m4 "
            f"overflow double precision ({why}); give the density in a smaller unit",
        )
    w_p = 2.0 * math.pi / peak_period(spectrum, body.g)
    if body.omega is not None:
        grid = body.omega
        return InputError(
            "omega",
            [grid.min, grid.max],
            "rad/s",
            f"the spectrum sampled on this grid (min, max; {grid.count} frequencies) has "
            f"moments m0…m4 outside double precision ({why}): the grid lies too far from the "
            f"spectral peak (omega_p = {w_p:.6g} "
            f"rad/s); give a grid around the peak, e.g. up to 6·omega_p = {6.0 * w_p:.6g} "
            "rad/s, or omit omega for the default grid",
        )
    return InputError(
        "spectrum",
        spectrum.type,
        "-",
        f"the spectral density or its moments m0…m4 are outside double precision ({why}) "
        f"near omega_p = {w_p:.6g} rad/s: check the magnitudes and units of the spectrum's "
        "parameters",
    )
