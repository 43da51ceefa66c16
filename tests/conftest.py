"""Test-session settings: the service's batch-job store in a temporary SQLite file (the
module-level ``service.app.app`` and every ``create_app()`` read it), never in the
working directory."""

from __future__ import annotations

import os
import tempfile

_DB_DIR = tempfile.mkdtemp(prefix="stochcable-test-jobs-")
os.environ.setdefault("STOCHCABLE_JOBS_DATABASE", os.path.join(_DB_DIR, "jobs.sqlite"))
