"""Tests of stochcable.scene.model: validation at the boundary, round trip, JSON Schema drift."""

from __future__ import annotations

import copy
import json
import math

import numpy as np
import pytest
from _paths import ROOT

from stochcable.errors import InputError
from stochcable.examples import list_examples, load_example
from stochcable.scene.model import Scene, load_scene, scene_json_schema
from stochcable.scene.schema import DEFAULT_SCHEMA_PATH, scene_schema_text, write_scene_schema


@pytest.fixture()
def chain_doc() -> dict:
    return load_example("chain_catenary").model_dump(mode="json")


@pytest.mark.parametrize("name", list_examples())
def test_examples_load_and_round_trip(name):
    scene = load_example(name)
    doc = scene.model_dump(mode="json")
    again = load_scene(json.dumps(doc))
    assert again == scene
    assert Scene.model_validate(doc) == scene


def test_load_scene_sources(tmp_path, chain_doc):
    path = tmp_path / "s.json"
    path.write_text(json.dumps(chain_doc))
    s1, s2, s3 = load_scene(path), load_scene(str(path)), load_scene(chain_doc)
    assert s1 == s2 == s3 and load_scene(s1) is s1
    with pytest.raises(InputError, match=r"scene = .*cannot be read"):
        load_scene(tmp_path / "missing.json")
    with pytest.raises(InputError, match=r"is not valid JSON"):
        load_scene("{not json")


def _mutated(doc, fn):
    d = copy.deepcopy(doc)
    fn(d)
    return d


def _seg(d):
    return d["lines"][0]["segments"][0]


@pytest.mark.parametrize(
    "mutate, pattern",
    [
        (
            lambda d: _seg(d).__setitem__("ea", -1.0),
            r"^lines\[0\]\.segments\[0\]\.ea = -1\.0 \[N\]: Input should be greater than 0",
        ),
        (
            lambda d: _seg(d).__setitem__("ea", 0.0),
            r"^lines\[0\]\.segments\[0\]\.ea = 0\.0 \[N\]: Input should be greater than 0",
        ),
        (
            lambda d: _seg(d).__setitem__("elements", 0),
            r"^lines\[0\]\.segments\[0\]\.elements = 0: Input should be greater than or equal to 1",
        ),
        (
            lambda d: _seg(d).__setitem__("mass", float("nan")),
            r"^lines\[0\]\.segments\[0\]\.mass = nan \[kg/m\]: Input should be a finite number",
        ),
        (
            lambda d: d["environment"].__setitem__("depth", math.inf),
            r"^environment\.depth = inf \[m\]: Input should be a finite number",
        ),
        (
            lambda d: _seg(d).__setitem__("length", 500.0),
            r"^lines\[0\]: the line \(500 m unstretched\) is shorter than its span \(820 m\): "
            r"it would have to stretch 64\.0% \(> 10 %\)",
        ),
        (
            lambda d: d["lines"][0]["end_a"].__setitem__("position", [-800.0, 0.0, 5.0]),
            r"^lines\[0\]\.end_a\.position = \[-800\.0, 0\.0, 5\.0\] \[m\]: z = 5\.0 is above "
            r"the still-water level: the anchor end \(end_a\) must have z <= 0",
        ),
        (
            lambda d: d["lines"][0]["end_b"].__setitem__("position", [0.0, 0.0, -250.0]),
            r"lines\[0\]\.end_b\.position z = -250\.0 m is below the seabed \(depth 200\.0 m\)",
        ),
        (
            lambda d: d["lines"].append(copy.deepcopy(d["lines"][0])),
            r"line names must be unique; repeated: \['leg1'\]",
        ),
        (
            lambda d: d["sea"]["spectrum"].update({"m0": 2.0, "omega_p": 0.6}),
            r"^sea\.spectrum: give exactly one of \(hs, tp\), \(m0, omega_p\) or wind_speed",
        ),
        (
            lambda d: d["sea"].__setitem__(
                "spectrum", {"type": "table", "omega": [0.1, 0.3, 0.2], "density": [1, 2, 3]}
            ),
            r"^sea\.spectrum: omega must be >= 0 and strictly increasing",
        ),
        (
            lambda d: _seg(d).__setitem__("colour", "red"),
            r"^lines\[0\]\.segments\[0\]\.colour = 'red': Extra inputs are not permitted",
        ),
        (lambda d: d.__setitem__("foo", 1), r"^foo = 1: Extra inputs are not permitted"),
        (
            lambda d: d["lines"][0].__setitem__("attachments", [{"at": 900.0}]),
            r"attachments\[0\]\.at = 900\.0 m is beyond the line length 850\.0 m",
        ),
        (
            lambda d: d["analysis"]["omega"].update({"min": 2.0, "max": 1.0}),
            r"^analysis\.omega: max \(1\.0 rad/s\) must exceed min \(2\.0 rad/s\)",
        ),
    ],
    ids=[
        "ea<0",
        "ea=0",
        "elements<1",
        "nan",
        "inf",
        "too-short",
        "anchor-above-surface",
        "end-below-seabed",
        "duplicate-names",
        "pm-both-forms",
        "table-omega",
        "extra-field",
        "extra-top",
        "attachment-beyond",
        "omega-order",
    ],
)
def test_validation_errors_name_path_unit_constraint(chain_doc, mutate, pattern):
    with pytest.raises(InputError, match=pattern):
        load_scene(_mutated(chain_doc, mutate))


def test_anchor_above_the_surface_names_the_field(chain_doc):
    # issue 19: the scene-level check named no field (parameter "scene")
    doc = _mutated(
        chain_doc, lambda d: d["lines"][0]["end_a"].__setitem__("position", [-800, 0, 5])
    )
    with pytest.raises(InputError) as info:
        load_scene(doc)
    err = info.value
    assert err.parameter == "lines[0].end_a.position" and err.unit == "m"
    assert err.value == [-800.0, 0.0, 5.0]
    assert err.constraint.startswith("z = 5.0 is above the still-water level: the anchor end")
    # end_b above the water is modelled (weight in air, no buoyancy, no wave or current
    # load: test_statics.py, test_wave_loads.py); at the still-water level exactly too
    for z in (30.0, 0.0):
        doc = _mutated(
            chain_doc, lambda d, z=z: d["lines"][0]["end_b"].__setitem__("position", [0, 0, z])
        )
        assert load_scene(doc).lines[0].end_b.position == (0.0, 0.0, z)


def test_input_error_attributes(chain_doc):
    with pytest.raises(InputError) as info:
        load_scene(_mutated(chain_doc, lambda d: _seg(d).__setitem__("ea", -1.0)))
    err = info.value
    assert (err.parameter, err.value, err.unit) == ("lines[0].segments[0].ea", -1.0, "N")
    assert "greater than 0" in err.constraint


def test_nested_spectrum_error_has_unit(chain_doc):
    bad = _mutated(chain_doc, lambda d: d["sea"]["spectrum"].__setitem__("hs", -2.0))
    with pytest.raises(InputError, match=r"^sea\.spectrum\.hs = -2\.0 \[m\]: Input should be"):
        load_scene(bad)
    pm = {"type": "pierson_moskowitz", "hs": 2.0, "tp": -2.0}
    bad = _mutated(chain_doc, lambda d: d["lines"][0]["end_b"]["motion"].__setitem__("surge", pm))
    with pytest.raises(InputError, match=r"motion\.surge\.tp = -2\.0 \[s\]: Input should be"):
        load_scene(bad)


def test_is_planar(chain_doc):
    assert load_scene(chain_doc).is_planar
    moved = _mutated(
        chain_doc, lambda d: d["lines"][0]["end_b"].__setitem__("position", [0.0, 5.0, -20.0])
    )
    assert not load_scene(moved).is_planar
    oblique = _mutated(chain_doc, lambda d: d["sea"].__setitem__("heading", 30.0))
    assert not load_scene(oblique).is_planar
    head_sea = _mutated(chain_doc, lambda d: d["sea"].__setitem__("heading", 180.0))
    assert load_scene(head_sea).is_planar
    cross_current = _mutated(
        chain_doc, lambda d: d["environment"]["current"][0].__setitem__("heading", 90.0)
    )
    assert not load_scene(cross_current).is_planar
    sway = _mutated(
        chain_doc,
        lambda d: d["lines"][0]["end_b"]["motion"].__setitem__(
            "sway", {"type": "pierson_moskowitz", "hs": 1.0, "tp": 8.0}
        ),
    )
    assert not load_scene(sway).is_planar


def test_schema_committed_file_matches_models():
    """Drift test: regenerate with `python -m stochcable.scene.schema`."""
    committed = (ROOT / DEFAULT_SCHEMA_PATH).read_text(encoding="utf-8")
    assert committed == scene_schema_text(), (
        "openapi/scene.schema.json is stale: run `python -m stochcable.scene.schema`"
    )


def test_schema_content_and_writer(tmp_path):
    schema = scene_json_schema()
    assert schema["$schema"].endswith("2020-12/schema")
    assert set(schema["required"]) == {"environment", "lines"}
    seg = schema["$defs"]["Segment"]
    assert seg["additionalProperties"] is False
    assert seg["properties"]["ea"]["unit"] == "N"
    assert seg["properties"]["ea"]["exclusiveMinimum"] == 0
    out = write_scene_schema(tmp_path / "sub" / "scene.schema.json")
    assert json.loads(out.read_text(encoding="utf-8")) == schema


def test_schema_command_line(tmp_path, monkeypatch, capsys):
    # `python -m stochcable.scene.schema [path]`: --help is help, not a file named
    # "--help"; a path is written
    from stochcable.scene.schema import main

    monkeypatch.chdir(tmp_path)
    with pytest.raises(SystemExit) as exc:
        main(["--help"])
    assert exc.value.code == 0 and "output file" in capsys.readouterr().out
    assert list(tmp_path.iterdir()) == []
    assert main(["s.json"]) == 0
    assert json.loads((tmp_path / "s.json").read_text(encoding="utf-8")) == json.loads(
        scene_schema_text()
    )


# ------------------------------------------------------------------ bodies (issue 6)


@pytest.fixture()
def disc_doc() -> dict:
    return load_example("tuah_1982_disc_buoy_single_leg").model_dump(mode="json", exclude_none=True)


def test_body_end_validation(disc_doc):
    neither = _mutated(disc_doc, lambda d: d["lines"][0].__setitem__("end_b", {}))
    with pytest.raises(
        InputError,
        match=r"lines\[0\]\.end_b: give the end's position or "
        r"attach it to a body",
    ):
        load_scene(neither)
    moving = _mutated(
        disc_doc,
        lambda d: d["lines"][0]["end_b"].__setitem__(
            "motion", {"heave": {"type": "pierson_moskowitz", "hs": 1.0, "tp": 8.0}}
        ),
    )
    with pytest.raises(InputError, match=r"an end attached to a body cannot have a motion"):
        load_scene(moving)
    dup = _mutated(disc_doc, lambda d: d["bodies"].append(copy.deepcopy(d["bodies"][0])))
    with pytest.raises(InputError, match=r"body names must be unique; repeated: \['disc'\]"):
        load_scene(dup)
    # the span check uses the body position for attached ends
    far = _mutated(disc_doc, lambda d: d["bodies"][0].__setitem__("position", [200.0, 0, 0]))
    # the disc scene is in feet (g = 32.174 ft/s²): the message quotes its lengths in ft
    with pytest.raises(
        InputError,
        match=r"lines\[0\]: the line \(339 ft unstretched\) is "
        r"shorter than its span",
    ):
        load_scene(far)
    bad_table = _mutated(
        disc_doc,
        lambda d: d["bodies"][0]["hydrodynamics"]["radiation_damping"][0][0].__setitem__(0, -5.0),
    )
    with pytest.raises(
        InputError,
        match=r"bodies\[0\]\.hydrodynamics: radiation_damping .*"
        r"must be >= 0",
    ):
        load_scene(bad_table)


def test_body_scene_geometry_and_planarity(disc_doc):
    scene = load_scene(disc_doc)
    assert scene.is_planar and not scene.uses_files
    np.testing.assert_allclose(scene.end_position("leg", "end_b"), [0.0, 0.0, -2.5])
    # pitch +0.1 rad about +y: the point 2.5 below the reference moves toward -x
    p = scene.end_position("leg", "end_b", {"disc": ([1.0, 0.0, 0.0], [0.0, 0.1, 0.0])})
    np.testing.assert_allclose(p, [1.0 - 2.5 * math.sin(0.1), 0.0, -2.5 * math.cos(0.1)])
    line = scene.resolved_line(scene.lines[0])
    assert line.end_b.position == (0.0, 0.0, -2.5) and line.end_b.attach is None
    # a vessel sway RAO, a body off the plane, an attachment off the plane: not planar
    vessel = {"omega": [0.1, 2.0], "sway": {"re": [0.1, 0.1], "im": [0.0, 0.0]}}
    for fn in (
        lambda d: d["bodies"][0].__setitem__("prescribed", vessel),
        lambda d: d["bodies"][0].__setitem__("wind_force", [0.0, 5.0, 0.0]),
        lambda d: d["lines"][0]["end_b"]["attach"].__setitem__("point", [0, 1.0, -2.5]),
    ):
        d = _mutated(disc_doc, fn)
        d["bodies"][0] = _six_dof(d["bodies"][0])
        assert not load_scene(d).is_planar


def _six_dof(body: dict) -> dict:
    """The planar disc body with 6×6 constant matrices and no table."""
    b = copy.deepcopy(body)
    b.pop("hydrodynamics")
    for k in ("added_mass", "radiation_damping", "hydrostatic_stiffness"):
        m3 = np.asarray(b[k])
        m6 = np.zeros((6, 6))
        m6[np.ix_([0, 2, 4], [0, 2, 4])] = m3
        b[k] = m6.tolist()
    return b


def test_vessel_motion_transfer():
    from stochcable.scene.model import VesselMotion

    v = VesselMotion(
        omega=(0.5, 1.0),
        heave={"re": [1.0, 0.5], "im": [0.0, 1.0]},
        pitch={"re": [0.0, 0.2], "im": [0.0, 0.0]},
    )
    t = v.transfer(np.array([0.1, 0.75, 1.0, 2.0]))
    assert t.shape == (6, 4)
    np.testing.assert_allclose(t[2], [0.0, 0.75 + 0.5j, 0.5 + 1j, 0.0])  # zero outside
    np.testing.assert_allclose(t[4], [0.0, 0.1, 0.2, 0.0])
    assert not t[[0, 1, 3, 5]].any() and not v.out_of_plane
    with pytest.raises(ValueError, match="give at least one of surge"):
        VesselMotion(omega=(0.5, 1.0))
