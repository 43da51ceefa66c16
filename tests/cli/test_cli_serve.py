"""``stochcable serve``: starts uvicorn, announces the docs URL, answers /health."""

from __future__ import annotations

import os
import re
import shlex
import socket
import subprocess
import sys
import time

import httpx
import pytest

from stochcable.cli import main
from stochcable.cli.serve import banner


def _free_port() -> int:
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def test_banner_names_the_docs_and_an_example():
    text = banner("127.0.0.1", 8000)
    assert "http://127.0.0.1:8000/docs" in text
    assert (
        "curl -s http://127.0.0.1:8000/v1/examples/chain_catenary | curl -s -X POST "
        "http://127.0.0.1:8000/v1/analyses -H 'Content-Type: application/json' -d @-" in text
    )
    assert "http://[::1]:8000/docs" in banner("::1", 8000)
    # a wildcard bind address is announced, but the example request goes to loopback
    assert "curl -s http://127.0.0.1:80/v1/examples" in banner("0.0.0.0", 80)


def _headers(args: list[str], env: dict[str, str]) -> dict[str, str]:
    """The ``-H`` options of a curl command, with ``$NAME`` read from ``env`` as a shell
    does inside double quotes."""
    out = {}
    for i, a in enumerate(args):
        if a == "-H":
            name, value = args[i + 1].split(": ")
            out[name] = re.sub(r"\$(\w+)", lambda m: env[m.group(1)], value)
    return out


def _run_banner_pipeline(line: str, env: dict[str, str] | None = None) -> httpx.Response:
    """Execute the banner's ``curl A | curl -X POST B -H H -d @-`` with httpx."""
    get, post = (shlex.split(part) for part in line.split("try:", 1)[1].split("|"))
    assert get[:2] == ["curl", "-s"] and post[:4] == ["curl", "-s", "-X", "POST"]
    env = env or {}
    scene = httpx.get(get[-1], headers=_headers(get, env), timeout=30.0)
    assert scene.status_code == 200, scene.text
    assert post[-2:] == ["-d", "@-"]
    return httpx.post(post[4], content=scene.content, headers=_headers(post, env), timeout=60.0)


def test_banner_points_to_the_page():
    assert "open http://127.0.0.1:8000/ in a browser" in banner("127.0.0.1", 8000)
    assert "open http://127.0.0.1:80/ in a browser" in banner("0.0.0.0", 80)


def test_banner_request_carries_the_key_when_keys_are_on():
    text = banner("127.0.0.1", 8000, keys=True)
    example = text.splitlines()[1]
    assert example.count('-H "Authorization: Bearer $STOCHCABLE_KEY"') == 2  # both requests
    assert "STOCHCABLE_KEY" in text.splitlines()[2]
    assert "Authorization" not in banner("127.0.0.1", 8000)


def test_non_loopback_without_keys_is_refused(capsys, monkeypatch):
    monkeypatch.delenv("STOCHCABLE_API_KEYS", raising=False)
    monkeypatch.delenv("STOCHCABLE_INSECURE", raising=False)
    assert main(["serve", "--host", "0.0.0.0", "--port", "0"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("stochcable serve: error: --host = '0.0.0.0': 0.0.0.0 is not a loopback")
    assert "STOCHCABLE_API_KEYS" in err and "--insecure" in err


def test_bad_port_is_a_one_line_error(capsys):
    assert main(["serve", "--port", "70000"]) == 2
    err = capsys.readouterr().err
    assert err.strip() == "stochcable serve: error: --port = 70000: must be in 0 … 65535"


@pytest.mark.slow
def test_serve_starts_uvicorn_and_answers():
    port = _free_port()
    env = {**os.environ, "STOCHCABLE_MAX_SAMPLES": "4096"}
    proc = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "stochcable",
            "serve",
            "--port",
            str(port),
            "--log-level",
            "warning",
        ],
        stderr=subprocess.PIPE,
        text=True,
        env=env,
    )
    try:
        first = proc.stderr.readline()
        assert f"docs at http://127.0.0.1:{port}/docs" in first
        example = proc.stderr.readline()
        deadline = time.monotonic() + 15.0
        while True:
            try:
                resp = httpx.get(f"http://127.0.0.1:{port}/health", timeout=1.0)
                break
            except httpx.TransportError:
                assert time.monotonic() < deadline, "server did not answer within 15 s"
                assert proc.poll() is None, proc.stderr.read()
                time.sleep(0.1)
        assert resp.json() == {"status": "ok"}
        # the worker read the limits from the environment
        resp = httpx.post(
            f"http://127.0.0.1:{port}/v1/sea/realizations",
            json={
                "spectrum": {"type": "jonswap", "hs": 2.0, "tp": 8.0},
                "duration": 8192.0,
                "dt": 1.0,
            },
        )
        assert "limit of 4096 (STOCHCABLE_MAX_SAMPLES)" in resp.text
        # the example request the start-up message shows works as printed
        resp = _run_banner_pipeline(example)
        assert resp.status_code == 200, resp.text
        assert resp.json()["lines"]["leg1"]["end_b"]["tension"]["std"] > 0
    finally:
        proc.terminate()
        proc.wait(10.0)


@pytest.mark.slow
def test_keyed_banner_request_works_as_printed():
    port = _free_port()
    env = {**os.environ, "STOCHCABLE_API_KEYS": "k1,k2", "STOCHCABLE_ANALYSIS_WORKERS": "1"}
    proc = subprocess.Popen(
        [sys.executable, "-m", "stochcable", "serve", "--port", str(port)]
        + ["--log-level", "warning"],
        stderr=subprocess.PIPE,
        text=True,
        env=env,
    )
    try:
        assert f"open http://127.0.0.1:{port}/ in a browser" in proc.stderr.readline()
        example = proc.stderr.readline()
        deadline = time.monotonic() + 30.0
        while True:
            try:
                httpx.get(f"http://127.0.0.1:{port}/health", timeout=1.0)
                break
            except httpx.TransportError:
                assert time.monotonic() < deadline, "server did not answer within 30 s"
                time.sleep(0.1)
        resp = _run_banner_pipeline(example, {"STOCHCABLE_KEY": "k2"})
        assert resp.status_code == 200, resp.text
        assert resp.json()["lines"]["leg1"]["end_b"]["tension"]["std"] > 0
        # the key is what lets it through
        get = shlex.split(example.split("try:", 1)[1].split("|")[0])
        bad = httpx.get(get[-1], headers=_headers(get, {"STOCHCABLE_KEY": "nope"}))
        assert bad.status_code == 401
    finally:
        proc.terminate()
        proc.wait(10.0)
