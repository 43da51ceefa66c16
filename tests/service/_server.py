"""A real ``stochcable serve`` in a subprocess on 127.0.0.1 (a free port), with
STOCHCABLE_* settings: the tests of behaviour that depends on processes (restarts, kills,
concurrency) start the service as a user would."""

from __future__ import annotations

import os
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import httpx
import psutil

ROOT = Path(__file__).resolve().parents[2]


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class Server:
    """``stochcable serve`` in a subprocess, with STOCHCABLE_* settings."""

    def __init__(self, **settings: str) -> None:
        self.port = _free_port()
        env = {**os.environ, "PYTHONPATH": str(ROOT)}
        env.update({f"STOCHCABLE_{k.upper()}": str(v) for k, v in settings.items()})
        self.proc = subprocess.Popen(
            [sys.executable, "-m", "stochcable", "serve", "--host", "127.0.0.1"]
            + ["--port", str(self.port), "--log-level", "warning"],
            env=env,
            cwd=ROOT,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
        )
        self.url = f"http://127.0.0.1:{self.port}"
        deadline = time.monotonic() + 120.0
        while time.monotonic() < deadline:
            try:
                if httpx.get(self.url + "/health", timeout=1.0).status_code == 200:
                    return
            except httpx.HTTPError:
                pass
            if self.proc.poll() is not None:
                raise RuntimeError("stochcable serve exited at start")
            time.sleep(0.2)
        self.stop()
        raise RuntimeError("stochcable serve did not answer /health within 120 s")

    @property
    def process(self) -> psutil.Process:
        return psutil.Process(self.proc.pid)

    def workers(self) -> list[psutil.Process]:
        """The worker processes: children of the fork server (itself a child)."""
        me = self.proc.pid
        return [p for p in self.process.children(recursive=True) if p.ppid() != me]

    def post(self, doc: dict, timeout: float, query: str = "?timeseries=none") -> httpx.Response:
        return httpx.post(self.url + "/v1/analyses" + query, json=doc, timeout=timeout)

    def kill(self) -> None:
        """SIGKILL the server and its worker processes (a crash: nothing is cleaned up)."""
        procs = [self.process, *self.process.children(recursive=True)]
        for p in procs:
            try:
                p.kill()
            except psutil.NoSuchProcess:
                pass
        psutil.wait_procs(procs, timeout=10)

    def stop(self) -> None:
        self.proc.send_signal(signal.SIGINT)
        try:
            self.proc.wait(15.0)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            self.proc.wait(5.0)
