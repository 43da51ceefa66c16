"""Property-based API test (schemathesis, in-process ASGI; the analyses run in the
app's worker processes): every check schemathesis has — no 5xx, status codes, content
types, headers and bodies as documented, schema-violating requests rejected,
schema-valid ones accepted, allowed methods.

Two expectations are widened, each for a reason the schema cannot carry: a body of
either kind may be refused as too large (413, before it is parsed), an unknown example
name is a 404, and a schema-valid body may be refused with 422 and its reason, for the
constraints between fields (``exactly one of (hs, tp), (m0, omega_p) or wind_speed``),
the physics checks (an anchor above the water) and the configured size limits
(``limit_exceeded``), which JSON Schema does not express.

Bounded: 25 examples per operation (10 for ``POST /v1/analyses`` and 5 for ``POST
/v1/batches``, whose generated scenes are the costliest to make: ≈ 30 s each), small
service limits so generated durations, grids and meshes stay cheap (max_elements 200,
max_frequencies 400, a 5 s run-time bound that also stops an abandoned analysis at its
next iteration); ≈ 1.5 min in all.
"""

from __future__ import annotations

import pytest
import schemathesis
from hypothesis import HealthCheck, settings
from schemathesis.checks import CHECKS as REGISTRY
from schemathesis.checks import load_all_checks
from schemathesis.config import SchemathesisConfig

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
CONFIG = SchemathesisConfig.from_dict(
    {
        "checks": {
            "negative_data_rejection": {"expected-statuses": [400, 404, 405, 406, 413, 415, 422]},
            "positive_data_acceptance": {"expected-statuses": ["2XX", 404, 413, 422]},
        }
    }
)
schema = schemathesis.openapi.from_asgi("/openapi.json", APP, config=CONFIG)
# property-based runs over every operation: minutes (the slow tier, docs/manual/testing.md)
pytestmark = pytest.mark.slow
load_all_checks()
CHECKS = REGISTRY.get_all()


HEAVY = "^(run_analysis|submit_batch)$"  # bodies holding a generated scene (slow to make)


@schema.exclude(operation_id_regex=HEAVY).parametrize()
@settings(max_examples=25, deadline=None, derandomize=True, suppress_health_check=list(HealthCheck))
def test_api(case):
    case.call_and_validate(checks=CHECKS)


@schema.include(operation_id="run_analysis").parametrize()
@settings(max_examples=6, deadline=None, derandomize=True, suppress_health_check=list(HealthCheck))
def test_analyses(case):
    case.call_and_validate(checks=CHECKS)


@schema.include(operation_id="submit_batch").parametrize()
@settings(max_examples=3, deadline=None, derandomize=True, suppress_health_check=list(HealthCheck))
def test_batches(case):
    case.call_and_validate(checks=CHECKS)
