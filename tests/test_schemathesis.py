"""Property-based API test (schemathesis, in-process ASGI): no generated request,
valid or not, gets a 5xx, and every answer conforms to the documented schema.

Bounded: 25 examples per operation (10 for ``POST /v1/analyses``, whose generated
scenes are the costliest), small service limits so generated durations, grids and
meshes stay cheap (max_elements 200, max_frequencies 400, a 5 s run-time bound that
also stops an abandoned analysis at its next iteration); runs in well under a minute.
"""

from __future__ import annotations

import schemathesis
from hypothesis import HealthCheck, settings
from schemathesis.checks import not_a_server_error, response_schema_conformance

from service.app import create_app
from service.settings import Settings

APP = create_app(
    Settings(
        max_samples=2**12,
        max_frequencies=400,
        max_points=8,
        max_elements=200,
        max_run_seconds=5.0,
        max_body_bytes=256 * 1024,
    )
)
schema = schemathesis.openapi.from_asgi("/openapi.json", APP)
CHECKS = [not_a_server_error, response_schema_conformance]


@schema.exclude(operation_id="run_analysis").parametrize()
@settings(max_examples=25, deadline=None, derandomize=True, suppress_health_check=list(HealthCheck))
def test_api(case):
    case.call_and_validate(checks=CHECKS)


@schema.include(operation_id="run_analysis").parametrize()
@settings(max_examples=10, deadline=None, derandomize=True, suppress_health_check=list(HealthCheck))
def test_analyses(case):
    case.call_and_validate(checks=CHECKS)
