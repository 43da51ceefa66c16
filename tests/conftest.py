"""Test-session settings: one BLAS thread, and the service's batch-job store in a
temporary SQLite file (the module-level ``service.app.app`` and every ``create_app()``
read it), never in the working directory."""

from __future__ import annotations

import os
import tempfile

# One BLAS thread in the test process and in the servers and workers it starts (before
# NumPy is imported: no plugin imports it earlier): the suite runs analyses of small
# models beside servers and worker processes on two cores, where multi-threaded
# OpenBLAS spins against them (a 20-element, 80-frequency analysis took 1.0 s instead
# of 0.035 s); the numbers do not depend on it beyond round-off.  Tests of the BLAS
# settings set their own in their subprocesses.
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

_DB_DIR = tempfile.mkdtemp(prefix="stochcable-test-jobs-")
os.environ.setdefault("STOCHCABLE_JOBS_DATABASE", os.path.join(_DB_DIR, "jobs.sqlite"))
