"""The HTTP service reads ``lines[i].drag_form`` (docs/travelling.md)."""

from __future__ import annotations

from fastapi.testclient import TestClient

from service.app import create_app
from service.settings import Settings


def test_bad_drag_form_is_a_422_naming_the_field():
    doc = {
        "environment": {"depth": 100.0},
        "lines": [
            {
                "name": "l",
                "end_a": {"position": [0.0, 0.0, -100.0]},
                "end_b": {"position": [90.0, 0.0, -10.0]},
                "segments": [{"length": 130.0, "ea": 1e8, "mass": 50.0, "diameter": 0.1}],
                "drag_form": "morison",
            }
        ],
    }
    with TestClient(create_app(Settings())) as client:
        r = client.post("/v1/analyses", json=doc)
    assert r.status_code == 422
    assert "drag_form" in r.text and "hu_jin" in r.text
