"""POST /v1/spectra: sample a spectrum document and compute its statistics."""

from __future__ import annotations

from fastapi import APIRouter
from starlette.responses import Response

from service.dependencies import MediaTypeDep, RunnerDep, SettingsDep
from service.encoding import JSON, array_responses, columns_response, json_response
from service.limits import check_frequencies
from service.schemas import SpectrumRequest, SpectrumResponse
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
    density = body.spectrum.spectral_density(omega, body.g)
    stats = spectrum_statistics(omega, density).as_dict()
    if media == JSON:
        return json_response({"omega": omega, "density": density, "stats": stats})
    return columns_response({"omega": omega, "density": density}, media, stats)
