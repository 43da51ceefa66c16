"""Tests of stochcable.runtime: the explicit process settings (configure, the BLAS
limit, the allocator) and the per-line thread pool.

Independent checks: threadpoolctl's own view of the BLAS libraries, the environment,
a fresh interpreter for what a plain import does, the serial loop (same bits), the
calling thread's warning collector, the environment switch and the BLAS gate.
"""

from __future__ import annotations

import json
import os
import platform
import subprocess
import sys
import threading

import numpy as np
import pytest

from stochcable import runtime
from stochcable import runtime as _parallel
from stochcable.errors import PhysicsWarning, SolverError, collect_warnings, warn
from stochcable.runtime import single_blas_thread


def _eig_item(seed: int) -> tuple[np.ndarray, str]:
    rng = np.random.default_rng(seed)
    a = rng.normal(size=(60, 60))
    return np.linalg.eigvals(a), threading.current_thread().name


def _count_pool(monkeypatch) -> list[int]:
    """Count the pool hand-offs of line_map (the items then go to whichever thread
    is free first)."""
    used: list[int] = []
    real = _parallel._executor

    def spy(n):
        used.append(n)
        return real(n)

    monkeypatch.setattr(_parallel, "_executor", spy)
    return used


def test_same_bits_and_order_as_the_loop(monkeypatch):
    monkeypatch.setenv("STOCHCABLE_THREADS", "2")
    used = _count_pool(monkeypatch)
    serial = [_eig_item(s)[0] for s in range(5)]
    with single_blas_thread():
        out = _parallel.line_map(_eig_item, range(5))
    assert used == [1]  # the calling thread and one pool worker
    assert [np.array_equal(a, b) for (a, _), b in zip(out, serial)] == [True] * 5


def test_disabled_by_the_environment_and_outside_single_blas(monkeypatch):
    used = _count_pool(monkeypatch)
    monkeypatch.setenv("STOCHCABLE_THREADS", "1")
    main = threading.current_thread().name
    with single_blas_thread():
        assert {n for _, n in _parallel.line_map(_eig_item, range(3))} == {main}
    monkeypatch.setenv("STOCHCABLE_THREADS", "2")
    monkeypatch.delenv("OPENBLAS_NUM_THREADS", raising=False)
    monkeypatch.delenv("OMP_NUM_THREADS", raising=False)
    # BLAS not limited to one thread here: no pool (no oversubscription)
    assert {n for _, n in _parallel.line_map(_eig_item, range(3))} == {main}
    # one item: no pool
    with single_blas_thread():
        assert _parallel.line_map(_eig_item, [0])[0][1] == main
    assert used == []
    monkeypatch.setenv("STOCHCABLE_THREADS", "junk")
    assert _parallel.thread_count() == 1


def test_no_nesting_warnings_forwarded_and_first_exception(monkeypatch):
    monkeypatch.setenv("STOCHCABLE_THREADS", "2")

    def inner(i: int) -> bool:
        return _parallel.pool_active()

    def outer(i: int) -> list[str]:
        warn(f"item {i}", PhysicsWarning)
        # a nested map runs in the thread of the item itself
        names = {threading.current_thread().name}
        _parallel.line_map(lambda j: names.add(threading.current_thread().name), range(3))
        assert len(names) == 1
        return _parallel.line_map(inner, range(2))

    with (
        single_blas_thread(),
        collect_warnings() as outer_caught,
        collect_warnings() as caught,
        pytest.warns(PhysicsWarning),
    ):
        out = _parallel.line_map(outer, range(3))
    assert out == [[True, True]] * 3
    # forwarded to every collector of the calling thread, once each, in item order
    # (whichever thread ran the item)
    assert [str(w) for w in caught] == ["item 0", "item 1", "item 2"]
    assert [str(w) for w in outer_caught] == ["item 0", "item 1", "item 2"]

    def fails(i: int) -> int:
        if i >= 1:
            raise SolverError(f"item {i} failed")
        return i

    with single_blas_thread(), pytest.raises(SolverError, match="item 1 failed"):
        _parallel.line_map(fails, range(3))


def test_default_is_no_pool(monkeypatch):
    """Opt-in (module docstring: measured gain only on an idle machine)."""
    monkeypatch.delenv("STOCHCABLE_THREADS", raising=False)
    assert _parallel.thread_count() == 1
    monkeypatch.setenv("STOCHCABLE_THREADS", "0")
    assert _parallel.thread_count() == 1
    monkeypatch.setenv("STOCHCABLE_THREADS", "3")
    assert _parallel.thread_count() == 3


def test_single_blas_thread_applies_in_worker_threads():
    threadpoolctl = pytest.importorskip("threadpoolctl")

    def blas_threads() -> list[int]:
        return [
            d["num_threads"] for d in threadpoolctl.threadpool_info() if d["user_api"] == "blas"
        ]

    before = blas_threads()
    seen: dict[str, list[int]] = {}
    with runtime.single_blas_thread():  # the main thread first (it used to keep control)
        seen["main"] = blas_threads()

    def work() -> None:
        with runtime.single_blas_thread():
            seen["worker"] = blas_threads()

    t = threading.Thread(target=work)
    t.start()
    t.join()
    assert all(n == 1 for n in seen["main"]) and all(n == 1 for n in seen["worker"])
    assert blas_threads() == before  # restored


_PLAIN_IMPORT = """
import json, os, sys
import threadpoolctl
before = os.environ.get("OMP_WAIT_POLICY")
import stochcable
from stochcable.examples import load_example
from stochcable import runtime
seen = []
def progress(stage, info):
    if stage == "linearization" and not seen:
        seen.append([d["num_threads"] for d in threadpoolctl.threadpool_info()
                     if d["user_api"] == "blas"])
stochcable.analyze(load_example("taut_wire"), progress=progress)
after = os.environ.get("OMP_WAIT_POLICY")
runtime.configure()
configured = []
def progress2(stage, info):
    if stage == "linearization" and not configured:
        configured.append([d["num_threads"] for d in threadpoolctl.threadpool_info()
                           if d["user_api"] == "blas"])
stochcable.analyze(load_example("taut_wire"), progress=progress2)
print(json.dumps({"before": before, "after": after, "during": seen[0],
                  "allocator": runtime._allocator_state["done"],
                  "omp": os.environ.get("OMP_WAIT_POLICY"),
                  "configured": configured[0],
                  "restored": [d["num_threads"] for d in threadpoolctl.threadpool_info()
                               if d["user_api"] == "blas"]}))
"""


def test_library_changes_no_process_setting_until_configured():
    # a fresh interpreter with two BLAS threads allowed: a plain `import stochcable` and
    # an analysis leave OMP_WAIT_POLICY, the allocator and the BLAS threads alone;
    # runtime.configure() then gives the small model one BLAS thread during the
    # analysis, restored afterwards, and sets the passive OpenMP policy
    pytest.importorskip("threadpoolctl")
    env = {
        k: v
        for k, v in os.environ.items()
        if k not in ("OMP_WAIT_POLICY", "MALLOC_TOP_PAD_", "STOCHCABLE_MALLOC_TUNING")
    }
    env.update(OPENBLAS_NUM_THREADS="2", OMP_NUM_THREADS="2")
    out = subprocess.run(
        [sys.executable, "-c", _PLAIN_IMPORT], capture_output=True, text=True, env=env, timeout=120
    )
    assert out.returncode == 0, out.stderr
    got = json.loads(out.stdout)
    assert got["before"] is None and got["after"] is None
    if not got["during"]:
        pytest.skip("no BLAS library visible to threadpoolctl")
    assert max(got["during"]) == 2  # the process's own setting, untouched
    assert got["configured"] == [1] * len(got["configured"])
    assert max(got["restored"]) == 2
    assert got["omp"] == "PASSIVE"
    assert got["allocator"] is (sys.platform.startswith("linux"))


def test_configure_switches_and_env_policy_respected(monkeypatch):
    monkeypatch.setenv("OMP_WAIT_POLICY", "ACTIVE")
    saved = runtime.configured()
    try:
        runtime.configure(small_model_blas=False, allocator=False)
        assert runtime.configured() == {"configured": True, "small_model_blas": False}
        assert os.environ["OMP_WAIT_POLICY"] == "ACTIVE"  # the user's choice stays
        runtime.configure()
        assert runtime.configured()["small_model_blas"] is True
    finally:
        runtime._settings.update(saved)


@pytest.mark.slow
def test_cli_and_service_configure_the_process():
    # the command line and the service apply the settings at start
    code = (
        "import sys; from stochcable import runtime; from stochcable.cli import main;"
        "main(['spectrum', 'pm', '--hs', '2', '--tp', '8', '--format', 'json', '-o',"
        " '/dev/null']); a = runtime.configured()['configured'];"
        "runtime._settings['configured'] = False;"
        "import service.app; print(a, runtime.configured()['configured'])"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    assert out.stdout.split() == ["True", "True"]


_FAULTS_PER_CASE = """
import json, resource, warnings
warnings.simplefilter("ignore")
from stochcable import runtime
runtime.configure()
from stochcable.dynamics.engine import build_engine
from stochcable.examples import load_example
scene = load_example("chain_catenary")
lin = scene.analysis.linearization.model_copy(
    update=dict(drag_residual=RESIDUALS, geometric_residual=RESIDUALS)
)
analysis = scene.analysis.model_copy(update={"linearization": lin})
scene = scene.model_copy(update={"analysis": analysis})
engine = build_engine(scene)
for _ in range(3):
    engine.solve()
f0 = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
for _ in range(20):
    engine.solve()
print(json.dumps((resource.getrusage(resource.RUSAGE_SELF).ru_minflt - f0) / 20))
"""


@pytest.mark.slow
@pytest.mark.skipif(
    not sys.platform.startswith("linux") or platform.libc_ver()[0] != "glibc",
    reason="glibc's malloc only",
)
def test_configured_worker_keeps_its_temporaries_mapped_under_a_dask_nanny():
    # A Dask nanny starts its workers with MALLOC_TRIM_THRESHOLD_=65536, which freezes
    # glibc's mmap threshold at 128 KiB: every larger temporary of a solve was mapped
    # and faulted in afresh, ≈ 350 minor page faults a chain case (10–30 % of its time)
    # against ≈ 0.1 in the main process.  configure() sets the threshold explicitly.
    # Bound: a tenth of the frozen threshold's count (the configured count is ≈ 0.1;
    # the bound leaves room for the allocator's own bookkeeping on other glibc builds).
    # The linear model (its solve's temporaries; the residuals': the next test).
    assert _faults_per_case(residuals=False) < 35


def _faults_per_case(residuals: bool) -> float:
    """Minor page faults per chain case in a process started as a Dask nanny does."""
    env = {k: v for k, v in os.environ.items() if not k.startswith(("MALLOC_", "STOCHCABLE_"))}
    env["MALLOC_TRIM_THRESHOLD_"] = "65536"
    code = _FAULTS_PER_CASE.replace("RESIDUALS", str(residuals))
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, env=env, timeout=300
    )
    assert out.returncode == 0, out.stderr
    return json.loads(out.stdout)


@pytest.mark.slow
@pytest.mark.skipif(
    not sys.platform.startswith("linux") or platform.libc_ver()[0] != "glibc",
    reason="glibc's malloc only",
)
def test_the_residuals_temporaries_stay_mapped_too():
    # issue 31: ≈ 1200 faults per case once (the residuals' temporaries above the mmap
    # threshold); 0.1–1.8 in 24 runs since the pairs and their outputs are formed in
    # 512 kB blocks (no (n, n, n_o) array of every pair)
    assert _faults_per_case(residuals=True) < 35


_SPECTRA_ONLY = """
import json, sys, warnings
warnings.simplefilter("ignore")
import stochcable
from stochcable.examples import load_example
d = load_example("chain_catenary").model_dump(mode="json", exclude_none=True)
d["analysis"].pop("timeseries", None)
stochcable.analyze(d)
print(json.dumps([m for m in ("pyfftw", "dask.array", "xarray") if m in sys.modules]))
"""


def test_an_analysis_without_records_loads_no_fft_library():
    # pyfftw imports dask.array, xarray and pandas whenever dask is installed (≈ 0.7 s
    # of every command's and batch worker's start); an analysis that synthesizes no
    # record needs none of them (stochcable.sea.fft imports pyfftw on first use)
    out = subprocess.run(
        [sys.executable, "-c", _SPECTRA_ONLY], capture_output=True, text=True, timeout=300
    )
    assert out.returncode == 0, out.stderr
    assert json.loads(out.stdout) == []


_WITH_RECORDS = """
import json, sys, warnings
warnings.simplefilter("ignore")
if sys.argv[1] == "dask-first":
    import dask.array
import stochcable
from stochcable.examples import load_example
doc = load_example("chain_catenary").model_dump(mode="json")
doc["analysis"]["timeseries"]["duration"] = 9000.0  # 36,000 samples: pyfftw (sea.fft)
r = stochcable.analyze(doc)
import pyfftw
print(json.dumps({"dask_array": "dask.array" in sys.modules,
                  "dask_interface": hasattr(pyfftw.interfaces, "dask_fft"),
                  "record": bool(r.timeseries is not None)}))
"""


@pytest.mark.slow
@pytest.mark.parametrize("order", ["alone", "dask-first"])
def test_records_load_pyfftw_without_its_dask_interface(order):
    # pyfftw's optional dask interface imports dask.array (≈ 0.5 s of the first record of
    # every process): hidden from pyfftw's import unless something imported it first,
    # and dask.array stays importable and whole either way
    out = subprocess.run(
        [sys.executable, "-c", _WITH_RECORDS, order], capture_output=True, text=True, timeout=300
    )
    assert out.returncode == 0, out.stderr
    got = json.loads(out.stdout)
    assert got["record"]
    first = order == "dask-first"
    assert got["dask_array"] is first and got["dask_interface"] is first
