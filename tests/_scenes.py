"""Scene pieces shared by several test modules."""

from __future__ import annotations

import copy
import math

import numpy as np

from stochcable.examples import load_example


def three_chain_legs(n_el: int, attach: str | None = None) -> list[dict]:
    """Three 330 m chain legs (EA 5e8 N, 100 kg/m, D 0.1 m) at 0/120/240° from anchors
    at radius 300 m on the seabed at 100 m depth to fairleads at radius 5 m, z = −2 m:
    fixed positions, or points of the body ``attach`` (relative to its reference point
    at the origin). The three-leg buoy of benchmarks/bench_bodies.py."""
    lines = []
    for i in range(3):
        a = math.radians(120.0 * i)
        fair = [5.0 * math.cos(a), 5.0 * math.sin(a), -2.0]
        lines.append(
            {
                "name": f"leg{i + 1}",
                "end_a": {"position": [300.0 * math.cos(a), 300.0 * math.sin(a), -100.0]},
                "end_b": (
                    {"position": fair}
                    if attach is None
                    else {"attach": {"body": attach, "point": fair}}
                ),
                "segments": [
                    {"length": 330.0, "ea": 5e8, "mass": 100.0, "diameter": 0.1, "elements": n_el}
                ],
            }
        )
    return lines


def full_circle_excitation(doc: dict, step: float = 15.0) -> None:
    """The disc's excitation table (heading 0 only) over the whole circle: the disc is
    axisymmetric about z through its reference point, so the excitation of heading β
    is that of heading 0 with its force and moment vectors turned by β about z."""
    exc = doc["bodies"][0]["hydrodynamics"]["excitation"]
    f0 = np.asarray(exc["re"], float)[0] + 1j * np.asarray(exc["im"], float)[0]  # (6, n_w)
    heads = np.arange(0.0, 360.0, step)
    out = []
    for b in np.radians(heads):
        c, s = math.cos(b), math.sin(b)
        rot = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
        out.append(np.concatenate([rot @ f0[:3], rot @ f0[3:]]))
    out = np.array(out)
    exc.update(heading=heads.tolist(), re=out.real.tolist(), im=out.imag.tolist())


def vessel_rao_table(headings: list[float] | None = None) -> dict:
    """A vessel's 6-DOF RAO table (the ``prescribed`` document) on 60 frequencies.

    Without ``headings`` one RAO per DOF (no heading dimension).  With ``headings``
    [deg] an (n_heading, n_omega) table per DOF in which surge and pitch scale with
    cos β and sway and roll with sin β (a ship's head-to-beam trend; the 0° row is
    the heading-free table with sway and roll moved into the sin β terms)."""
    w = np.linspace(0.01, 5.0, 60)
    rao = {
        "surge": 0.8 * np.exp(-0.3j * w) / (1 + w**2),
        "sway": 0.3j / (1 + w**2),
        "heave": 1.0 / (1 + (w / 0.9) ** 4) + 0j,
        "roll": 0.01 * w * np.exp(-w) + 0j,
        "pitch": 0.02j * w * np.exp(-w),
    }
    doc: dict = {"omega": w.tolist()}
    if headings is not None:
        b = np.radians(np.asarray(headings, dtype=float))[:, None]
        trend = {"surge": np.cos(b), "sway": np.sin(b), "roll": np.sin(b), "pitch": np.cos(b)}
        rao = {k: trend.get(k, np.ones_like(b)) * v[None] for k, v in rao.items()}
        doc["heading"] = list(headings)
    doc.update({k: {"re": v.real.tolist(), "im": v.imag.tolist()} for k, v in rao.items()})
    return doc


def _vessel(doc: dict, headings: list[float] | None) -> None:
    """A prescribed vessel (:func:`vessel_rao_table`) and a riser from it, beside the
    buoy (ft-slug-lbf, as the example)."""
    doc["bodies"].append(
        {
            "name": "ship",
            "position": [600.0, 0.0, 0.0],
            "mass": 1e6,
            "prescribed": vessel_rao_table(headings),
        }
    )
    doc["lines"].append(
        {
            "name": "riser",
            "end_a": {"position": [800.0, 30.0, -100.0]},
            "end_b": {"attach": {"body": "ship", "point": [10.0, 0.0, -5.0]}},
            "segments": [
                {
                    "length": 265.0,
                    "ea": 1.0e6,
                    "mass": 0.5,
                    "diameter": 0.2,
                    "cd_normal": 1.2,
                    "elements": 8,
                }
            ],
        }
    )


def buoy_with_vessel(
    heading: float = 0.0,
    spreading: dict | None = None,
    *,
    full_circle: bool = False,
    vessel: bool = False,
    drag: bool = True,
    vessel_headings: list[float] | None = None,
) -> dict:
    """The seed §6.7 three-leg disc buoy example at sea ``heading`` [deg] with an
    optional ``spreading``; optionally the disc's excitation over the full circle, a
    vessel with a riser (its RAO table over ``vessel_headings`` when given), the drag
    off."""
    scene = load_example("tuah_1982_disc_buoy_three_legs")
    doc = copy.deepcopy(scene.model_dump(mode="json", exclude_none=True))
    doc["analysis"].pop("timeseries", None)
    if full_circle:
        full_circle_excitation(doc)
    if vessel:
        _vessel(doc, vessel_headings)
    if not drag:  # nothing couples the directions: the response is linear in the sea
        for line in doc["lines"]:
            for seg in line["segments"]:
                seg.update(cd_normal=0.0, cd_axial=0.0)
        doc["bodies"][0]["drag_area"] = [0.0, 0.0, 0.0]
    doc["sea"]["heading"] = heading
    if spreading is not None:
        doc["sea"]["spreading"] = spreading
    return doc
