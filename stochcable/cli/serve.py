"""``stochcable serve``: run the HTTP service (FastAPI app ``service.app:app``) with uvicorn."""

from __future__ import annotations

import argparse
import sys

__all__ = ["register", "run", "banner", "EXAMPLE", "KEY_VARIABLE"]


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add the ``serve`` sub-command."""
    p = subparsers.add_parser(
        "serve",
        help="run the HTTP service",
        description="Run the stochcable HTTP service with uvicorn. Limits are read from "
        "STOCHCABLE_* environment variables (STOCHCABLE_MAX_SAMPLES, "
        "STOCHCABLE_MAX_BODY_BYTES, STOCHCABLE_MAX_RUN_SECONDS, ...).",
    )
    p.add_argument(
        "--host", default=None, help="interface to bind (default STOCHCABLE_HOST or 127.0.0.1)"
    )
    p.add_argument(
        "--port", type=int, default=None, help="TCP port (default STOCHCABLE_PORT or 8000)"
    )
    p.add_argument(
        "--workers",
        type=int,
        default=None,
        help="worker processes (default STOCHCABLE_WORKERS or 1)",
    )
    p.add_argument(
        "--insecure",
        action="store_true",
        help="serve on a non-loopback address without API keys (STOCHCABLE_API_KEYS)",
    )
    p.add_argument(
        "--log-level",
        default="info",
        choices=["critical", "error", "warning", "info", "debug"],
        help="uvicorn log level (default info)",
    )
    p.set_defaults(func=run)


EXAMPLE = "chain_catenary"
"""Bundled example scene analysed by the request the start-up message shows."""


KEY_VARIABLE = "STOCHCABLE_KEY"
"""Shell variable the start-up message's example request reads the API key from (the
message never prints a key)."""


def banner(host: str, port: int, keys: bool = False) -> str:
    """The message printed on start: the page to open in a browser, the interactive docs,
    and a copy-pasteable request analysing a bundled example scene (carrying the
    ``Authorization`` header, from ``$STOCHCABLE_KEY``, when API keys are on)."""
    shown = f"[{host}]" if ":" in host else host
    base = f"http://{shown}:{port}"
    # a wildcard bind address is not a destination: the page and example go to loopback
    local = {"0.0.0.0": "127.0.0.1", "": "127.0.0.1", "::": "[::1]"}.get(host, shown)
    url = f"http://{local}:{port}"
    auth = f' -H "Authorization: Bearer ${KEY_VARIABLE}"' if keys else ""
    text = (
        f"stochcable service on {base} — open {url}/ in a browser; docs at {base}/docs\n"
        f"try: curl -s{auth} {url}/v1/examples/{EXAMPLE} | curl -s -X POST "
        f"{url}/v1/analyses{auth} -H 'Content-Type: application/json' -d @-\n"
    )
    if keys:
        text += f"(API keys are on: set {KEY_VARIABLE} to one of STOCHCABLE_API_KEYS first)\n"
    return text


def run(args: argparse.Namespace) -> int:
    """Start uvicorn; returns when the server stops."""
    import os

    import uvicorn

    from service.settings import Settings, insecure_bind_message
    from stochcable.errors import InputError

    settings = Settings()
    host = args.host if args.host is not None else settings.host
    port = args.port if args.port is not None else settings.port
    workers = args.workers if args.workers is not None else settings.workers
    if not 0 <= port <= 65535:
        raise InputError("--port", port, "-", "must be in 0 … 65535")
    if workers < 1:
        raise InputError("--workers", workers, "-", "must be >= 1")
    if args.insecure:
        os.environ[Settings.env_name("insecure")] = "1"
    why = insecure_bind_message(host, Settings())
    if why is not None:
        raise InputError("--host", host, "-", why)
    # each worker process imports service.app:app and reads the STOCHCABLE_* variables
    os.environ[Settings.env_name("host")] = host
    sys.stderr.write(banner(host, port, keys=bool(Settings().keys)))
    sys.stderr.flush()
    uvicorn.run("service.app:app", host=host, port=port, workers=workers, log_level=args.log_level)
    return 0
