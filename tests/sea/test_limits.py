"""One source for every range (stochcable.sea.limits): the scene's models (their
pydantic constraints), the sea's public functions (their InputError) and the command
line (``stochcable spectrum``) accept each range's ends and reject the next float
outside, for every parameter that has a range."""

from __future__ import annotations

import math

import numpy as np
import pytest
from pydantic import ValidationError

from stochcable.cli import main
from stochcable.errors import InputError
from stochcable.scene import spectra as scene
from stochcable.scene import spreading as scene_spreading
from stochcable.sea import spectra, spreading
from stochcable.sea.limits import (
    GAMMA_RANGE,
    HEIGHT_RANGE,
    M0_RANGE,
    OMEGA_P_RANGE,
    PERIOD_RANGE,
    SHAPE_RANGE,
    SIGMA_RANGE,
    SPREADING_EXPONENT_MAX,
    WIND_SPEED_RANGE,
)

JS = {"hs": 2.0, "tp": 10.0}
OH = {"hs1": 1.0, "tp1": 12.0, "lambda1": 2.0, "hs2": 2.0, "tp2": 6.0, "lambda2": 1.0}

# (range, scene model, field = function parameter, other fields/arguments,
#  sea function, CLI spectrum type, CLI flag)
CASES = {
    "jonswap.hs": (HEIGHT_RANGE, scene.Jonswap, "hs", JS, spectra.spectrum_jonswap, "jonswap"),
    "jonswap.tp": (PERIOD_RANGE, scene.Jonswap, "tp", JS, spectra.spectrum_jonswap, "jonswap"),
    "jonswap.gamma": (GAMMA_RANGE, scene.Jonswap, "gamma", JS, spectra.spectrum_jonswap, "jonswap"),
    "jonswap.sigma_a": (
        SIGMA_RANGE,
        scene.Jonswap,
        "sigma_a",
        JS,
        spectra.spectrum_jonswap,
        "jonswap",
    ),
    "jonswap.sigma_b": (
        SIGMA_RANGE,
        scene.Jonswap,
        "sigma_b",
        JS,
        spectra.spectrum_jonswap,
        "jonswap",
    ),
    "pm.m0": (
        M0_RANGE,
        scene.PiersonMoskowitz,
        "m0",
        {"m0": 1.0, "omega_p": 0.5},
        spectra.spectrum_pierson_moskowitz_m0,
        "pm",
    ),
    "pm.omega_p": (
        OMEGA_P_RANGE,
        scene.PiersonMoskowitz,
        "omega_p",
        {"m0": 1.0, "omega_p": 0.5},
        spectra.spectrum_pierson_moskowitz_m0,
        "pm",
    ),
    "pm.wind_speed": (
        WIND_SPEED_RANGE,
        scene.PiersonMoskowitz,
        "wind_speed",
        {"wind_speed": 10.0},
        spectra.spectrum_pierson_moskowitz_wind,
        "pm",
    ),
    "issc.hs": (
        HEIGHT_RANGE,
        scene.Issc,
        "hs",
        {"hs": 2.0, "t1": 8.0},
        spectra.spectrum_issc,
        "issc",
    ),
    "issc.t1": (
        PERIOD_RANGE,
        scene.Issc,
        "t1",
        {"hs": 2.0, "t1": 8.0},
        spectra.spectrum_issc,
        "issc",
    ),
    "ochi_hubble.tp1": (
        PERIOD_RANGE,
        scene.OchiHubble,
        "tp1",
        OH,
        spectra.spectrum_ochi_hubble,
        "ochi-hubble",
    ),
    "ochi_hubble.lambda2": (
        SHAPE_RANGE,
        scene.OchiHubble,
        "lambda2",
        OH,
        spectra.spectrum_ochi_hubble,
        "ochi-hubble",
    ),
    "ochi_hubble.hs2": (
        HEIGHT_RANGE,
        scene.OchiHubble,
        "hs2",
        OH,
        spectra.spectrum_ochi_hubble,
        "ochi-hubble",
    ),
}


def _flag(field: str) -> str:
    return "--" + field.replace("_", "-")


def _ends(limits: tuple[float, float]) -> list[tuple[float, bool]]:
    """(value, accepted): both ends, and the next float outside each."""
    lo, hi = (float(x) for x in limits)
    return [
        (lo, True),
        (hi, True),
        (np.nextafter(lo, -np.inf), False),
        (np.nextafter(hi, np.inf), False),
    ]


def _scene_accepts(model, kwargs) -> bool:
    try:
        model(**kwargs)
    except ValidationError:
        return False
    return True


def _function_accepts(fn, kwargs) -> bool:
    try:
        fn(np.array([0.5, 1.0]), **kwargs)
    except InputError:
        return False
    return True


def _cli_accepts(capsys, kind, kwargs, field) -> bool | None:
    """True when ``stochcable spectrum`` takes the flags, False when it refuses
    ``field``'s flag by name, None when a bad value got past it (the sea function's
    error names its parameter instead of the flag)."""
    argv = ["spectrum", kind, "--count", "2"]
    for key, value in kwargs.items():
        argv += [_flag(key), repr(float(value))]
    main(argv)
    err = capsys.readouterr().err
    if f"{_flag(field)} = " in err:
        return False
    return None if f" {field} = " in err else True


@pytest.mark.parametrize("case", sorted(CASES))
def test_scene_constraints_are_the_range(case):
    limits, model, field, *_ = CASES[case]
    meta = {type(m).__name__: m for m in model.model_fields[field].metadata}
    assert meta["Le"].le == limits[1]
    if field not in ("hs1", "hs2"):  # Ochi-Hubble: 0 (no part) or in the range
        assert meta["Ge"].ge == limits[0]


@pytest.mark.parametrize("case", sorted(CASES))
def test_scene_function_and_cli_agree_at_the_ends(case, capsys):
    limits, model, field, base, fn, kind = CASES[case]
    for value, accepted in _ends(limits):
        kw = {**base, field: value}
        got = {
            "scene": _scene_accepts(model, kw),
            "function": _function_accepts(fn, kw),
            "cli": _cli_accepts(capsys, kind, kw, field),
        }
        assert got == dict.fromkeys(got, accepted), f"{field} = {value!r}"


def test_ochi_hubble_takes_a_zero_height_everywhere(capsys):
    kw = {**OH, "hs1": 0.0}
    assert _scene_accepts(scene.OchiHubble, kw)
    assert _function_accepts(spectra.spectrum_ochi_hubble, kw)
    assert _cli_accepts(capsys, "ochi-hubble", kw, "hs1")
    both = {**kw, "hs2": 0.0}
    assert not _scene_accepts(scene.OchiHubble, both)
    assert not _function_accepts(spectra.spectrum_ochi_hubble, both)


@pytest.mark.parametrize(
    "model, field, fn",
    [
        (scene_spreading.Cos2sSpreading, "s", spreading.directions_cos2s),
        (scene_spreading.CosnSpreading, "n", spreading.directions_cosn),
    ],
)
def test_spreading_exponent_range_agrees(model, field, fn):
    top = SPREADING_EXPONENT_MAX
    for value, accepted in [(top, True), (np.nextafter(top, math.inf), False), (0.0, False)]:
        assert _scene_accepts(model, {field: value, "directions": 3}) is accepted
        try:
            fn(0.0, value, 3)
            ok = True
        except InputError:
            ok = False
        assert ok is accepted, f"{field} = {value!r}"
