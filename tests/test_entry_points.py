"""One way to give a scene: every public entry point takes what ``analyze()`` takes.

A :class:`~stochcable.scene.model.Scene`, a mapping (the scene document), a path (``str``
or :class:`pathlib.Path`) or JSON text, all through the one coercion
(:func:`stochcable.scene.model.load_scene`).  Every entrance runs on every form and
gives the answer of the ``Scene`` form (the same numbers: a deterministic pipeline on
the same validated scene, compared exactly); a bad input is an ``InputError`` naming
the parameter.  The client's entrances are checked up to the request body they send
(the service's own tests run it).
"""

from __future__ import annotations

import json
import warnings
from pathlib import Path

import numpy as np
import pytest

import stochcable
from stochcable.cases import ScatterDiagram, SeaState, run_cases
from stochcable.client import Client
from stochcable.errors import InputError
from stochcable.examples import load_example
from stochcable.reference.cable import simulate_line_timedomain

# the taut wire, coarsened: every entrance runs in tens of milliseconds
_DOC = load_example("taut_wire").model_dump(mode="json")
_DOC["lines"][0]["segments"][0]["elements"] = 8
_DOC["analysis"]["omega"] = {"min": 0.3, "max": 2.0, "count": 40}


class _Sent(Exception):
    """Raised by the fake transport of the client tests with the body it was given."""


def _client_body(method: str):
    def run(scene):
        client = Client("http://127.0.0.1:9")  # never reached: the fake sends nothing

        def fake_request(verb, path, json_body=None, **kwargs):
            raise _Sent(json_body["scene"] if "scene" in json_body else json_body)

        client._request = fake_request
        args = (scene,) if method == "analyze" else (scene, [{"hs": 2, "tp": 8, "p": 1}])
        try:
            getattr(client, method)(*args)
        except _Sent as sent:
            return json.dumps(sent.args[0], sort_keys=True)
        raise AssertionError("the client sent nothing")

    return run


def _scatter() -> ScatterDiagram:
    return ScatterDiagram(
        (SeaState(hs=2.0, tp=8.0, gamma=1.0, heading=0.0, probability=1.0),),
        "pierson_moskowitz",
        "test",
    )


def _timedomain(scene):
    h = simulate_line_timedomain(scene, duration=8.0, seed=1, ramp=2.0)
    return h.element_tension


# entrance name -> (run it on a scene, what to compare)
ENTRANCES = {
    "analyze": lambda s: stochcable.analyze(s).to_document()["lines"]["wire"]["tension"],
    "build_engine": lambda s: stochcable.build_engine(s).solve().to_document()["lines"],
    "solve_statics": lambda s: stochcable.solve_statics(s).to_document(),
    "natural_modes": lambda s: stochcable.natural_modes(s, count=4)["wire"].omega,
    "simulate_line_timedomain": _timedomain,
    "run_cases": lambda s: run_cases(s, _scatter()).stats["wire"],
    "Client.analyze": _client_body("analyze"),
    "Client.submit_batch": _client_body("submit_batch"),
}


def _forms(tmp_path: Path) -> dict:
    path = tmp_path / "scene.json"
    path.write_text(json.dumps(_DOC), encoding="utf-8")
    return {
        "mapping": _DOC,
        "path str": str(path),
        "Path": path,
        "JSON text": json.dumps(_DOC),
    }


def _equal(a, b) -> None:
    if isinstance(a, dict):
        assert a.keys() == b.keys()
        for k in a:
            if k != "timing":
                _equal(a[k], b[k])
    elif isinstance(a, (list, tuple, np.ndarray)) and not isinstance(a, str):
        np.testing.assert_array_equal(np.asarray(a, dtype=object), np.asarray(b, dtype=object))
    else:
        assert a == b


@pytest.mark.parametrize("entrance", sorted(ENTRANCES))
def test_every_entrance_takes_every_form_of_a_scene(entrance, tmp_path):
    run = ENTRANCES[entrance]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        reference = run(stochcable.load_scene(_DOC))
        for form, value in _forms(tmp_path).items():
            try:
                _equal(run(value), reference)
            except AssertionError as exc:
                raise AssertionError(f"{entrance} on a {form}: {exc}") from None


BAD = {
    "a number": (42, r"scene = 'int'.*must be a Scene, a mapping"),
    "a missing file": ("no/such/scene.json", r"scene = 'no/such/scene.json'.*cannot be read"),
    "broken JSON": ('{"lines": [', r"scene = .*is not valid JSON"),
}


@pytest.mark.parametrize("bad", sorted(BAD))
@pytest.mark.parametrize("entrance", sorted(ENTRANCES))
def test_a_bad_scene_is_an_input_error_naming_the_parameter(entrance, bad):
    value, match = BAD[bad]
    with pytest.raises(InputError, match=match) as info:
        ENTRANCES[entrance](value)
    assert info.value.parameter == "scene"


def test_a_scene_is_validated_once():
    # a Scene goes through as it is: no second validation, no copy
    scene = stochcable.load_scene(_DOC)
    assert stochcable.load_scene(scene) is scene


def test_natural_modes_of_a_model_stay_below():
    from stochcable.line.modes import natural_modes
    from stochcable.statics import scene_fe_models

    model = scene_fe_models(_DOC)["wire"]
    np.testing.assert_array_equal(
        stochcable.natural_modes(model, count=4).omega, natural_modes(model, count=4).omega
    )
