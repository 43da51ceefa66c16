"""Tests of ``stochcable analyze``."""

from __future__ import annotations

import json
import math
import os
import re
import subprocess
import sys

import pytest
from _paths import ROOT

from stochcable.cli import main

SCENE = {
    "environment": {"depth": 100.0},
    "sea": {"spectrum": {"type": "pierson_moskowitz", "hs": 4.0, "tp": 9.0}, "heading": 0.0},
    "lines": [
        {
            "name": "leg1",
            "end_a": {"position": [-400.0, 0.0, -100.0]},
            "end_b": {
                "position": [0.0, 0.0, -10.0],
                "motion": {"surge": {"type": "pierson_moskowitz", "hs": 2.0, "tp": 10.0}},
            },
            "segments": [
                {
                    "length": 450.0,
                    "ea": 5.0e8,
                    "mass": 100.0,
                    "diameter": 0.1,
                    "cd_normal": 2.4,
                    "cd_axial": 1.15,
                    "elements": 12,
                }
            ],
        }
    ],
    "analysis": {
        "omega": {"min": 0.1, "max": 2.0, "count": 40},
        "timeseries": {"method": "dsa", "duration": 100.0, "dt": 0.5, "seed": 1},
    },
}


@pytest.fixture()
def scene_file(tmp_path):
    p = tmp_path / "scene.json"
    p.write_text(json.dumps(SCENE))
    return p


@pytest.mark.slow
def test_analyze_writes_the_v1_result_document_and_plots(scene_file, tmp_path, capsys):
    out = tmp_path / "result.json"
    figs = tmp_path / "figs"
    rc = main(
        [
            "analyze",
            str(scene_file),
            "--format",
            "json",
            "-o",
            str(out),
            "--plot",
            str(figs),
            "--progress",
        ]
    )
    assert rc == 0
    err = capsys.readouterr().err
    assert "statics" in err and "iteration 1" in err and "done" in err
    doc = json.loads(out.read_text())
    # DESIGN.md v1 result document keys
    st = doc["statics"]["lines"]["leg1"]
    assert {"end_a", "end_b", "touchdown", "nodes"} <= set(st)
    assert st["end_b"]["tension"] > 0
    assert isinstance(doc["modes"]["omega"], list)
    assert {"converged", "iterations", "relative_change"} <= set(doc["linearization"])
    line = doc["lines"]["leg1"]
    for end in ("end_a", "end_b"):
        assert {"mean", "std", "tz", "mpm_3h"} <= set(line[end]["tension"])
        assert math.isfinite(line[end]["tension"]["mpm_3h"])
    assert {"s", "std"} <= set(line["tension"]) and {"s", "std"} <= set(line["motion"])
    assert len(line["spectra"]["omega"]) == 40
    assert {"total_s", "statics_s", "solve_s"} <= set(doc["timing"])
    assert doc["timeseries"]["samples"] == 200
    names = sorted(p.name for p in figs.iterdir())
    assert names == [
        "leg1_end_tension_spectra.png",
        "leg1_modes.png",
        "leg1_tension_std.png",
        "statics.png",
        "timeseries.png",
    ]
    assert all((figs / n).stat().st_size > 1000 for n in names)


def test_analyze_prints_to_stdout_without_progress(scene_file, capsys):
    rc = main(["analyze", str(scene_file), "--timeseries", "none"])
    assert rc == 0
    captured = capsys.readouterr()
    doc = json.loads(captured.out)
    assert "timeseries" not in doc
    assert "stochcable analyze:" not in captured.err  # no progress: stderr not a TTY


def test_analyze_bad_scene_is_one_line_error(tmp_path, capsys):
    bad = dict(
        SCENE,
        lines=[dict(SCENE["lines"][0], segments=[dict(SCENE["lines"][0]["segments"][0], ea=-1.0)])],
    )
    p = tmp_path / "bad.json"
    p.write_text(json.dumps(bad))
    rc = main(["analyze", str(p)])
    assert rc == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1
    assert "lines[0].segments[0].ea" in err and "N" in err


def test_analyze_missing_file(tmp_path, capsys):
    rc = main(["analyze", str(tmp_path / "nope.json")])
    assert rc == 2
    assert "cannot be read" in capsys.readouterr().err


ANSI = re.compile(r"\x1b\[[0-9;?]*[A-Za-z]")


def _run_on_a_terminal(args: list[str]) -> tuple[str, str]:
    """Run ``python -m stochcable ARGS`` with stdout on a pseudo-terminal; returns the
    terminal's text (escape codes removed) and stderr."""
    import pty

    master, slave = pty.openpty()
    env = dict(os.environ, PYTHONPATH=str(ROOT), COLUMNS="400", LINES="50")
    proc = subprocess.Popen(
        [sys.executable, "-m", "stochcable", *args],
        stdout=slave,
        stderr=subprocess.PIPE,
        env=env,
        cwd=ROOT,
    )
    os.close(slave)
    chunks = []
    while True:
        try:
            data = os.read(master, 65536)
        except OSError:  # the pty closes when the child exits
            break
        if not data:
            break
        chunks.append(data)
    err = proc.stderr.read().decode()
    proc.wait(timeout=120)
    os.close(master)
    assert proc.returncode == 0, err
    return ANSI.sub("", b"".join(chunks).decode()), err


@pytest.mark.slow
def test_analyze_on_a_terminal_prints_a_summary(scene_file, capsys):
    text, err = _run_on_a_terminal(["analyze", str(scene_file), "--timeseries", "none"])
    assert main(["analyze", str(scene_file), "--timeseries", "none"]) == 0
    doc = json.loads(capsys.readouterr().out)  # piped: the JSON document
    assert not text.lstrip().startswith("{")
    assert "end tension [N]" in text and "drag linearization: converged" in text
    t = doc["lines"]["leg1"]["end_b"]["tension"]
    row = next(ln for ln in text.splitlines() if "leg1" in ln and "end_b" in ln)
    for key in ("mean", "std", "tz", "mpm_3h"):
        assert f"{t[key]:.4g}" in row, (key, row)
    # the end-motion spectrum's ω⁻⁵ tail warns; each warning is shown once, in the
    # summary, not again on stderr
    assert doc["warnings"]
    for msg in doc["warnings"]:
        assert (text + err).count(msg[:60]) == 1, msg


@pytest.mark.slow
def test_analyze_summary_of_a_foot_slug_second_scene_is_in_ft_and_lbf():
    scene = ROOT / "stochcable" / "examples" / "tuah_1982_disc_buoy_three_legs.json"
    text, _ = _run_on_a_terminal(["analyze", str(scene)])
    assert "end tension [lbf]" in text and "[ft]" in text
    assert "foot-slug-second" in text and "disc" in text


def test_summary_says_the_residuals_are_included_with_the_linear_sigma(tmp_path):
    """At the defaults the summary's end-tension table has the linear model's σ beside
    and a line names the residuals included; both switches false: neither."""
    import copy

    for asked in (True, False):
        scene = copy.deepcopy(SCENE)
        scene["analysis"].pop("timeseries")
        scene["analysis"]["linearization"] = dict.fromkeys(
            ("drag_residual", "geometric_residual"), asked
        )
        path, out, doc_out = tmp_path / "s.json", tmp_path / "s.txt", tmp_path / "s.out.json"
        path.write_text(json.dumps(scene))
        assert main(["analyze", str(path), "--format", "summary", "-o", str(out)]) == 0
        assert main(["analyze", str(path), "--format", "json", "-o", str(doc_out)]) == 0
        text = out.read_text(encoding="utf-8")
        flat = " ".join(text.split())  # (rich wraps the line at its width)
        said = (
            "the end tensions include the residuals of the linear model "
            "(drag_residual, geometric_residual); linear σ: the linear model alone"
        )
        assert (said in flat) is asked and ("linear σ" in text) is asked
        if asked:
            line = json.loads(doc_out.read_text(encoding="utf-8"))["lines"]["leg1"]
            row = next(ln for ln in text.splitlines() if "leg1" in ln and "end_b" in ln)
            linear = line["linear"]["end_b"]["tension"]["std"]
            assert f"{linear:.4g}" in row and f"{line['end_b']['tension']['std']:.4g}" in row
            assert linear < line["end_b"]["tension"]["std"]


def test_analyze_writes_netcdf_for_a_nc_output(scene_file, tmp_path, capsys):
    xr = pytest.importorskip("xarray")
    pytest.importorskip("netCDF4")
    nc = tmp_path / "result.nc"
    assert main(["analyze", str(scene_file), "-o", str(nc)]) == 0
    assert main(["analyze", str(scene_file), "--format", "json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    with xr.open_dataset(nc) as ds:
        for end in ("end_a", "end_b"):
            got = ds["end_tension_std"].sel(line="leg1", end=end).item()
            assert got == doc["lines"]["leg1"][end]["tension"]["std"]
        assert ds["end_tension_std"].attrs["units"] == "N"


def test_analyze_netcdf_format_needs_an_output_file(scene_file, capsys):
    assert main(["analyze", str(scene_file), "--format", "netcdf"]) == 2
    assert "--output" in capsys.readouterr().err
