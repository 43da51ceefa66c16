"""Tests of the ``stochcable spectrum`` and ``stochcable simulate`` commands."""

from __future__ import annotations

import json
import math
import subprocess
import sys

import numpy as np
import pytest

from stochcable.cli import main


def run(capsys, *argv):
    code = main(list(argv))
    out = capsys.readouterr()
    return code, out.out, out.err


def test_spectrum_pm_json(capsys):
    code, out, err = run(
        capsys, "spectrum", "pm", "--hs", "6", "--tp", "10", "--omega-max", "6", "--count", "3000"
    )
    assert code == 0
    d = json.loads(out)
    w = np.array(d["omega"])
    assert w[0] == pytest.approx(6 / 3000) and w[-1] == pytest.approx(6.0) and len(w) == 3000
    # grid to ~9.5 ωp: m0 tail (5/4)(ωp/ω_max)⁴ = 1.5e-4 of Hs²/16
    assert d["stats"]["hs"] == pytest.approx(6.0, rel=1e-4)
    assert d["stats"]["tp"] == pytest.approx(10.0, rel=2e-3)
    assert set(d["stats"]) >= {"m0", "m1", "m2", "m3", "m4", "hs", "tz", "tm01", "tp", "bandwidth"}
    assert d["units"]["omega"] == "rad/s"


def test_spectrum_peak_in_hz_and_rad_s_agree(capsys):
    _, a, _ = run(capsys, "spectrum", "jonswap", "--hs", "3", "--tp", "8")
    _, b, _ = run(capsys, "spectrum", "jonswap", "--hs", "3", "--fp", "0.125")
    _, c, _ = run(capsys, "spectrum", "jonswap", "--hs", "3", "--omega-p", str(2 * math.pi / 8))
    da, db, dc = (json.loads(x) for x in (a, b, c))
    np.testing.assert_allclose(da["density"], db["density"], rtol=1e-13)
    np.testing.assert_allclose(da["density"], dc["density"], rtol=1e-13)


def test_spectrum_other_types_and_csv(capsys, tmp_path):
    for argv in (
        ["issc", "--hs", "4", "--t1", "7"],
        ["bretschneider", "--hs", "4", "--tp", "9"],
        ["pm", "--wind-speed", "15"],
        ["pm", "--m0", "28", "--omega-p", "0.5"],
        [
            "ochi-hubble",
            "--hs1",
            "3",
            "--tp1",
            "15",
            "--lambda1",
            "2",
            "--hs2",
            "4",
            "--tp2",
            "8",
            "--lambda2",
            "1",
        ],
    ):
        code, out, err = run(capsys, "spectrum", *argv)
        assert code == 0, err
    table = tmp_path / "s.csv"
    table.write_text("omega,density\n0.2,0\n0.5,2\n1.0,0\n")
    code, out, err = run(
        capsys,
        "spectrum",
        "table",
        "--table",
        str(table),
        "--format",
        "csv",
        "--omega-max",
        "1.0",
        "--count",
        "10",
    )
    assert code == 0, err
    rows = out.strip().splitlines()
    assert rows[0] == "omega,density" and len(rows) == 11
    vals = np.array([[float(x) for x in r.split(",")] for r in rows[1:]])
    np.testing.assert_allclose(vals[4], [0.5, 2.0])


def test_simulate_seed_case_json(capsys, tmp_path):
    out = tmp_path / "eta.json"
    code, _, err = run(
        capsys,
        "simulate",
        "pm",
        "--m0",
        "28",
        "--omega-p",
        "0.5",
        "--duration",
        "256",
        "--dt",
        "0.25",
        "--method",
        "dsa",
        "--seed",
        "1",
        "-o",
        str(out),
    )
    assert code == 0, err
    d = json.loads(out.read_text())
    assert len(d["time"]) == len(d["elevation"]) == 1024
    # DSA: sample variance (mean removed; the mean is 0 to round-off) = Riemann sum
    assert d["stats"]["variance"] == pytest.approx(d["stats"]["m0_grid"], rel=1e-12)
    assert d["stats"]["m0"] == 28.0
    assert d["stats"]["m0_grid"] == pytest.approx(28.0, rel=1e-5)


def test_simulate_csv_npy_and_reproducible(capsys, tmp_path):
    f1, f2 = tmp_path / "a.npy", tmp_path / "b.csv"
    assert (
        run(
            capsys,
            "simulate",
            "jonswap",
            "--hs",
            "2",
            "--tp",
            "7",
            "--seed",
            "4",
            "--method",
            "nsa",
            "--format",
            "npy",
            "-o",
            str(f1),
        )[0]
        == 0
    )
    assert (
        run(
            capsys,
            "simulate",
            "jonswap",
            "--hs",
            "2",
            "--tp",
            "7",
            "--seed",
            "4",
            "--method",
            "nsa",
            "--format",
            "csv",
            "-o",
            str(f2),
        )[0]
        == 0
    )
    a = np.load(f1)
    b = np.loadtxt(f2, delimiter=",", skiprows=1)
    np.testing.assert_array_equal(a["elevation"], b[:, 1])
    assert a.shape == (1024,)


def test_plot(capsys, tmp_path):
    pytest.importorskip("matplotlib")
    png = tmp_path / "s.png"
    assert run(capsys, "spectrum", "pm", "--hs", "6", "--tp", "10", "--plot", str(png))[0] == 0
    assert png.stat().st_size > 1000
    png2 = tmp_path / "e.png"
    assert (
        run(
            capsys,
            "simulate",
            "pm",
            "--hs",
            "6",
            "--tp",
            "10",
            "--seed",
            "1",
            "--plot",
            str(png2),
            "-o",
            str(tmp_path / "x.json"),
        )[0]
        == 0
    )
    assert png2.stat().st_size > 1000


@pytest.mark.parametrize(
    "argv,flag",
    [
        (["spectrum", "pm", "--hs", "-6", "--tp", "10"], "--hs = -6.0 [m]: must be >= 1e-06"),
        (["spectrum", "pm", "--hs", "6", "--tp", "0"], "--tp = 0.0 [s]: must be >= 0.001"),
        (["spectrum", "pm", "--hs", "6"], "--tp = None [s]: is required for the pm spectrum"),
        (["spectrum", "pm", "--tp", "10"], "--hs = None: is required for the pm spectrum"),
        (
            ["spectrum", "pm", "--hs", "6", "--tp", "10", "--fp", "0.1"],
            "--fp = 0.1: give only one of",
        ),
        (["spectrum", "pm", "--hs", "nan", "--tp", "10"], "--hs = nan [m]: must be finite"),
        (
            ["spectrum", "jonswap", "--hs", "6", "--tp", "10", "--gamma", "0.5"],
            "--gamma = 0.5: must be >= 1",
        ),
        (
            ["spectrum", "pm", "--hs", "6", "--tp", "10", "--count", "1"],
            "--count = 1: must be an integer >= 2",
        ),
        (
            ["spectrum", "pm", "--hs", "6", "--tp", "10", "--omega-max", "-1"],
            "--omega-max = -1.0 [rad/s]",
        ),
        (
            ["spectrum", "table", "--table", "/nonexistent.csv"],
            "--table = '/nonexistent.csv': cannot be read",
        ),
        (
            ["simulate", "pm", "--hs", "6", "--tp", "10", "--duration", "255.75"],
            "--duration = 255.75 [s]: --duration/--dt = 1023 must be an even integer >= 2",
        ),
        (["simulate", "pm", "--hs", "6", "--tp", "10", "--dt", "0"], "--dt = 0.0 [s]: must be > 0"),
        (
            ["simulate", "pm", "--hs", "6", "--tp", "10", "--format", "npy"],
            "--output = None: is required",
        ),
        (
            ["simulate", "pm", "--hs", "6", "--tp", "10", "--seed", "-3"],
            "--seed = -3: must be >= 0",
        ),
    ],
)
def test_bad_input_exit_2_one_line(capsys, argv, flag):
    code, out, err = run(capsys, *argv)
    assert code == 2
    lines = err.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in err
    assert flag in lines[0]


def test_simulate_too_many_samples_is_one_sentence_before_any_allocation():
    # issue 19: --duration 1e12 once ended in "Unable to allocate 74.5 GiB"; the
    # bound is checked before any work (a subprocess: the real exit code and stderr)
    argv = ["simulate", "pm", "--hs", "6", "--tp", "10", "--duration", "1e12", "--dt", "0.25"]
    p = subprocess.run(
        [sys.executable, "-m", "stochcable", *argv], capture_output=True, text=True, timeout=60
    )
    assert p.returncode == 2 and p.stdout == "" and "Traceback" not in p.stderr
    assert p.stderr.splitlines() == [
        "stochcable simulate: error: --duration = 1000000000000.0 [s]: --duration/--dt = "
        "4e+12 samples exceeds the limit of 4194304 (--max-samples; default 2^22, the "
        "service's STOCHCABLE_MAX_SAMPLES): shorten --duration, raise --dt or raise "
        "--max-samples"
    ]


def test_simulate_sample_bound_is_an_option(capsys):
    base = ["simulate", "pm", "--hs", "6", "--tp", "10", "--dt", "0.25", "--seed", "1"]
    code, _, err = run(capsys, *base, "--duration", "1e308", "--dt", "1e-300")
    assert code == 2 and "--duration/--dt = inf samples exceeds the limit" in err
    code, _, err = run(capsys, *base, "--duration", "512", "--max-samples", "1024")
    assert code == 2 and "2048 samples exceeds the limit of 1024 (--max-samples" in err
    code, out, _ = run(capsys, *base, "--duration", "512", "--max-samples", "2048")
    assert code == 0 and len(json.loads(out)["elevation"]) == 2048
    code, _, err = run(capsys, *base, "--max-samples", "1")
    assert code == 2 and err.strip() == (
        "stochcable simulate: error: --max-samples = 1: must be >= 2"
    )


def test_arithmetic_error_in_the_core_is_one_line_exit_2(capsys):
    # a grid far below the ISSC peak (omega_p = 4849 rad/s): m0·m4 underflows, 0/0
    code, out, err = run(
        capsys, "spectrum", "issc", "--hs", "1e4", "--t1", "1e-3", "--omega-max", "1000"
    )
    assert code == 2 and out == "" and len(err.strip().splitlines()) == 1
    assert err.startswith(
        "stochcable spectrum: error: numerical failure (ZeroDivisionError: float division "
        "by zero): an input is outside the range the model handles numerically"
    )


def test_memory_error_anywhere_is_one_line_exit_2(capsys, monkeypatch):
    import stochcable.cli.simulate as sim

    def out_of_memory(*_a, **_k):
        # what numpy's _ArrayMemoryError (a MemoryError) says
        raise MemoryError(
            "Unable to allocate 74.5 GiB for an array with shape (5000000000000,) and "
            "data type float64"
        )

    monkeypatch.setattr(sim, "simulate_sea", out_of_memory)
    code, out, err = run(capsys, "simulate", "pm", "--hs", "6", "--tp", "10")
    assert code == 2 and out == "" and len(err.strip().splitlines()) == 1
    assert err.startswith("stochcable simulate: error: out of memory (Unable to allocate ")
    assert "reduce the size of the problem" in err

    def bare(*_a, **_k):
        raise MemoryError

    monkeypatch.setattr(sim, "simulate_sea", bare)
    code, _, err = run(capsys, "simulate", "pm", "--hs", "6", "--tp", "10")
    assert code == 2 and err.startswith("stochcable simulate: error: out of memory (a MemoryError)")


@pytest.mark.parametrize(
    "content,flag",
    [
        ("omega,density\n0.5,1\n0.2,1\n", "--table omega"),
        ("omega,density\n0.2,1\n0.5,-1\n", "--table density"),
        ("0.2,1\n0.5\n", "--table"),
    ],
)
def test_bad_table(capsys, tmp_path, content, flag):
    f = tmp_path / "t.csv"
    f.write_text(content)
    code, out, err = run(capsys, "spectrum", "table", "--table", str(f))
    assert code == 2 and flag in err and len(err.strip().splitlines()) == 1


def test_coarse_dt_warns_on_stderr(capsys):
    code, out, err = run(
        capsys,
        "simulate",
        "pm",
        "--hs",
        "6",
        "--tp",
        "10",
        "--dt",
        "1.5",
        "--duration",
        "300",
        "--seed",
        "1",
    )
    assert code == 0
    assert "warning:" in err and "above the Nyquist frequency" in err and "use dt <=" in err
