"""POST /v1/scenes/moordyn: a MoorDyn file as a scene document, or a 422 naming the
file's line and column."""

from __future__ import annotations

import json
import warnings

import pytest
from _paths import MOORDYN_DATA
from fastapi.testclient import TestClient

from service.app import create_app
from service.settings import Settings
from stochcable.errors import PhysicsWarning
from stochcable.io import read_moordyn
from stochcable.scene.model import load_scene

DATA = MOORDYN_DATA


@pytest.fixture(scope="module")
def client():
    with TestClient(create_app(Settings())) as c:
        yield c


@pytest.mark.parametrize("name", ["oc3_hywind_v1.txt", "stochcable_buoy_network.txt"])
def test_the_answer_is_the_scene_read_moordyn_gives(client, name):
    text = (DATA / name).read_text()
    r = client.post("/v1/scenes/moordyn", content=text, headers={"Content-Type": "text/plain"})
    assert r.status_code == 200, r.text
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PhysicsWarning)
        assert load_scene(r.json()) == read_moordyn(DATA / name)
    notes = json.loads(r.headers["X-Stochcable-Warnings"])
    assert any("options ignored" in n for n in notes)


def test_a_bad_file_is_a_422_naming_line_and_column(client):
    text = (DATA / "stochcable_clump_buoy.txt").read_text()
    bad = text.replace("2 poly 2 3 260 26 -", "2 poly 2 9 260 26 -")
    r = client.post("/v1/scenes/moordyn", content=bad, headers={"Content-Type": "text/plain"})
    assert r.status_code == 422
    (item,) = r.json()["detail"]
    assert (item["line"], item["column"], item["type"]) == (19, 10, "input_error")
    assert "MoorDyn file line 19, column 10 (LINES)" in item["msg"]
    assert "there is no point 9" in item["msg"]


def test_rods_and_non_text_are_422(client):
    r = client.post("/v1/scenes/moordyn", content=(DATA / "bodies_and_rods.dat").read_bytes())
    assert r.status_code == 422 and r.json()["detail"][0]["line"] == 19
    r = client.post("/v1/scenes/moordyn", content=b"\xff\xfe--- MoorDyn")
    assert r.status_code == 422 and "UTF-8" in r.json()["detail"][0]["msg"]
    r = client.post("/v1/scenes/moordyn", content=b"/etc/passwd")  # never a server path
    assert r.status_code == 422 and r.json()["detail"][0]["line"] >= 1
