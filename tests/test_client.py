"""stochcable.client against a real uvicorn server on a free loopback port: the
client returns the same objects and numbers as the local API and clear errors."""

from __future__ import annotations

import json
import socket
import threading
import time
import warnings

import httpx
import numpy as np
import pytest
import uvicorn
from _compare import assert_close_documents

import stochcable
import stochcable.errors
from service.app import create_app
from service.settings import Settings
from stochcable.analysis import analyze
from stochcable.client import AnalysisDocument, Client, ClientError, ServiceError
from stochcable.examples import load_example
from stochcable.results.documents import ResponseStats
from stochcable.scene.model import Jonswap, OmegaGrid, Scene
from stochcable.sea.kinematics import kinematics_timeseries
from stochcable.sea.realization import simulate_sea
from stochcable.sea.spectra import SpectrumStatistics, spectrum_statistics

# one worker runs the module: its module fixtures run once (--dist loadgroup)
pytestmark = pytest.mark.xdist_group("test_client")

JONSWAP = Jonswap(hs=4.0, tp=8.0)


def _free_port() -> int:
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@pytest.fixture(scope="module")
def base_url():
    port = _free_port()
    config = uvicorn.Config(
        create_app(Settings(max_samples=2**16)),
        host="127.0.0.1",
        port=port,
        log_level="warning",
        lifespan="off",
        timeout_graceful_shutdown=2,
    )
    server = uvicorn.Server(config)
    thread = threading.Thread(target=server.run, daemon=True)
    thread.start()
    deadline = time.monotonic() + 10.0
    while not server.started:
        if time.monotonic() > deadline or not thread.is_alive():
            pytest.fail("uvicorn did not start within 10 s")
        time.sleep(0.02)
    yield f"http://127.0.0.1:{port}"
    server.should_exit = True
    thread.join(10.0)


@pytest.fixture
def client(base_url):
    with Client(base_url, timeout=30.0) as c:
        yield c


def test_health_and_version(client):
    assert client.health() == {"status": "ok"}
    assert client.version() == {"stochcable": stochcable.__version__, "api": "v1"}


def test_spectrum_returns_the_core_statistics(client):
    grid = OmegaGrid(min=0.1, max=4.0, count=300)
    res = client.spectrum(JONSWAP, omega=grid)
    omega = grid.values()
    density = JONSWAP.spectral_density(omega)
    assert isinstance(res.stats, SpectrumStatistics)
    assert res.stats == spectrum_statistics(omega, density)  # exact: JSON floats round-trip
    assert np.array_equal(res.omega, omega) and np.array_equal(res.density, density)


def test_spectrum_from_a_plain_document(client):
    res = client.spectrum({"type": "pierson_moskowitz", "m0": 28.0, "omega_p": 0.5})
    # Tuah 1982, §6.5: m0 = 28 ft²; the default grid (to 6 wp) keeps all but ~0.05 %
    assert res.stats.m0 == pytest.approx(28.0, rel=1e-3)


@pytest.mark.parametrize("binary", [True, False])
def test_realization_equals_the_local_simulation(client, binary):
    points = [[0.0, 0.0, -3.0], [20.0, 5.0, -15.0]]
    res = client.realization(
        JONSWAP,
        duration=512.0,
        dt=0.25,
        method="nsa",
        seed=11,
        points=points,
        heading=45.0,
        depth=40.0,
        binary=binary,
    )
    sea = simulate_sea(JONSWAP.spectral_density, 512.0, 0.25, method="nsa", rng=11)
    vel, acc = kinematics_timeseries(sea, np.array(points), np.radians(45.0), 40.0)
    assert np.array_equal(res.time, sea.time)
    assert np.array_equal(res.elevation, sea.elevation)
    assert np.array_equal(res.velocity, vel) and np.array_equal(res.acceleration, acc)
    # mean square of the record = sum a_m^2/2 (Parseval), to rounding of 2048 terms
    assert res.variance == pytest.approx(sea.variance_grid, rel=1e-12)
    assert res.dt == 0.25


def test_input_error_raises_client_error_with_path_and_unit(client):
    with pytest.raises(
        ClientError,
        match=r"HTTP 422: spectrum\.hs \[m\]: Input should be "
        r"greater than or equal to 0.000001",
    ) as info:
        client.spectrum({"type": "jonswap", "hs": -1.0, "tp": 8.0})
    assert info.value.status == 422
    assert info.value.detail[0]["parameter"] == "spectrum.hs"
    assert isinstance(info.value, stochcable.StochcableError)


def test_limit_raises_client_error_naming_the_bound(client):
    with pytest.raises(
        ClientError,
        match=r"duration/dt = 131072 samples exceeds the limit "
        r"of 65536 \(STOCHCABLE_MAX_SAMPLES\)",
    ):
        client.realization(JONSWAP, duration=32768.0, dt=0.25)


def test_unreachable_service_raises_service_error():
    with Client(f"http://127.0.0.1:{_free_port()}", timeout=2.0) as c:
        with pytest.raises(ServiceError, match="cannot reach") as info:
            c.health()
    assert info.value.status is None and not isinstance(info.value, ClientError)


def test_examples(client):
    examples = pytest.importorskip("stochcable.examples")
    if not hasattr(examples, "list_examples"):
        pytest.skip("stochcable.examples.list_examples not written yet")
    names = [e.name for e in client.examples()]
    assert names == examples.list_examples()
    scene = client.example(names[0])
    assert isinstance(scene, Scene) and scene == examples.load_example(names[0])
    with pytest.raises(ClientError, match=r"HTTP 404: unknown example 'nope'; known examples"):
        client.example("nope")


# ------------------------------------------------------------------ analyses


@pytest.fixture(scope="module")
def chain_local():
    return analyze(load_example("chain_catenary"))


def _without_timing(doc) -> dict:
    out = json.loads(json.dumps(dict(doc)))
    out.pop("timing")
    return out


def test_readme_pipeline_get_the_example_and_post_it(base_url, chain_local):
    # curl -s .../v1/examples/chain_catenary | curl -s -X POST .../v1/analyses
    #      -H 'Content-Type: application/json' -d @-      (the start-up message)
    scene = httpx.get(f"{base_url}/v1/examples/chain_catenary", timeout=30.0).content
    resp = httpx.post(
        f"{base_url}/v1/analyses",
        content=scene,
        timeout=60.0,
        headers={"Content-Type": "application/json"},
    )
    assert resp.status_code == 200, resp.text
    assert_close_documents(_without_timing(resp.json()), _without_timing(chain_local.to_document()))


def test_analyze_returns_the_local_objects(client, chain_local):
    res = client.analyze(client.example("chain_catenary"))
    assert isinstance(res, AnalysisDocument)
    # the document equals the local one to round-off (tests/_compare.py: worker thread)
    assert_close_documents(_without_timing(res), _without_timing(chain_local.to_document()))
    line, local = res.lines["leg1"], chain_local.lines["leg1"]
    assert isinstance(line.end_b, ResponseStats)
    for end in ("end_a", "end_b"):
        assert_close_documents(getattr(line, end).as_dict(), getattr(local, end).as_dict())
    assert line.end_b_tension_std == pytest.approx(local.end_b.std, rel=1e-10)
    assert local.end_b.std > 0
    for name in (
        "tension_std",
        "tension_mean",
        "s_elements",
        "s_nodes",
        "motion_std",
        "omega",
        "listed_modes",
    ):
        np.testing.assert_allclose(
            getattr(line, name), getattr(local, name), rtol=1e-10, atol=0, err_msg=name
        )
    np.testing.assert_allclose(
        line.end_tension_spectrum("end_b"), local.end_tension_spectrum("end_b"), rtol=1e-10
    )
    assert line.channels == local.channels and line.n_modes == local.n_modes
    assert res.converged and res.warnings == chain_local.warnings
    ts, local_ts = res.timeseries, chain_local.timeseries
    n = ts.time.size  # the first 2048 samples of 2400
    assert n == 2048 and ts.samples == local_ts.time.size
    assert np.array_equal(ts.elevation, local_ts.elevation[:n])  # no BLAS involved
    np.testing.assert_allclose(
        ts.end_tension["leg1"]["end_b"],
        local_ts.end_tension["leg1"]["end_b"][:n],
        rtol=1e-10,
        atol=1e-10 * np.abs(local_ts.end_tension["leg1"]["end_b"]).max(),
    )


def test_analyze_from_a_plain_document_without_timeseries(client):
    doc = load_example("taut_wire").model_dump(mode="json")
    res = client.analyze(doc, timeseries="none")
    assert res.timeseries is None and "timeseries" not in res
    assert_close_documents(
        res.lines["wire"].end_b.as_dict(), analyze(doc).lines["wire"].end_b.as_dict()
    )


def test_analyze_bodies_scene_returns_body_motion_series(client):
    """The time-series window of a scene with a body carries the body's motion per DOF,
    equal to the local realization's first samples (same seed, round-off from BLAS)."""
    doc = load_example("tuah_1982_disc_buoy_single_leg").model_dump(mode="json")
    doc["analysis"]["timeseries"] = {"method": "dsa", "duration": 64.0, "dt": 0.5, "seed": 2}
    res = client.analyze(doc)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        local = analyze(doc).timeseries
    ts = res.timeseries
    assert set(ts.body_motion) == {"disc"}
    assert list(ts.body_motion["disc"]) == ["surge", "heave", "pitch"]
    for dof, series in ts.body_motion["disc"].items():
        want = local.body_motion["disc"][dof][: series.size]
        np.testing.assert_allclose(
            series, want, rtol=1e-10, atol=1e-10 * np.abs(want).max(), err_msg=dof
        )
    assert np.std(ts.body_motion["disc"]["heave"]) > 0


def test_analyze_gives_the_linear_series_when_asked(client):
    """timeseries_linear: the window's linear end tensions beside the corrected ones
    (the local result's, round-off from BLAS)."""
    doc = load_example("tuah_1982_single_leg").model_dump(mode="json")
    ts = client.analyze(doc, timeseries_linear=True).timeseries
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        local = analyze(doc).timeseries
    for end, series in ts.end_tension_linear["leg"].items():
        want = local.end_tension_linear["leg"][end][: series.size]
        np.testing.assert_allclose(series, want, rtol=1e-10, atol=1e-10 * np.abs(want).max())
    assert client.analyze(doc).timeseries.end_tension_linear == {}


def test_analyze_unconverged_raises_client_error_with_the_reason(client):
    # CPU-independent by a wide margin: the first iteration's relative change is 0.81
    # (measured), 80 times the example's tolerance 1e-2
    doc = load_example("tuah_1982_single_leg").model_dump(mode="json")
    doc["analysis"]["linearization"]["max_iterations"] = 1
    with pytest.raises(
        ClientError,
        match=r"HTTP 422: drag linearization of line 'leg' did "
        r"not converge.*max_iterations",
    ) as info:
        client.analyze(doc)
    assert info.value.detail[0]["type"] == "convergence_error"


def test_analyze_bad_timeseries_mode_is_refused_locally(client):
    with pytest.raises(stochcable.errors.InputError, match="timeseries = 'all'"):
        client.analyze({}, timeseries="all")


def test_analyze_timeout_raises_service_error(base_url):
    with Client(base_url, timeout=0.001) as c:
        with pytest.raises(ServiceError, match="timed out") as info:
            c.analyze(load_example("chain_catenary"))
    assert info.value.status is None and not isinstance(info.value, ClientError)


def test_binary_answers_are_read_in_wide_socket_reads(base_url, monkeypatch):
    # httpcore's default 64 KiB reads cost ~4x the time of the 8 MiB .npy transfer
    # (docs/BENCHMARKS.md "Service"); this fails when httpx/httpcore internals change
    # so that the client's widening no longer applies
    import stochcable.client as client_module

    seen = []
    original = client_module._wide_reads

    def spy(resp):
        cm = original(resp)

        class Watch:
            def __enter__(self):
                cm.__enter__()
                conn = resp.stream._stream._httpcore_stream._stream._connection
                seen.append(conn.READ_NUM_BYTES)

            def __exit__(self, *exc):
                return cm.__exit__(*exc)

        return Watch()

    monkeypatch.setattr(client_module, "_wide_reads", spy)
    with Client(base_url, timeout=30.0) as c:
        res = c.realization(JONSWAP, duration=64.0, dt=0.25)
        conns = [pc._connection for pc in c._http._transport._pool.connections]
    assert seen == [4 << 20] and res.elevation.size == 256
    # restored afterwards: JSON answers on the same connection keep 64 KiB reads
    assert [x.READ_NUM_BYTES for x in conns] == [64 * 1024]
