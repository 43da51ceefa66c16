"""``stochcable cases`` end to end: CSV, NetCDF and JSON outputs, headings, the bundled
scatter diagram, and its error paths (one line on stderr, exit code 2)."""

from __future__ import annotations

import json

import numpy as np
import pytest

from stochcable.cli import main
from stochcable.examples import resources

WIRE = str(resources.files("stochcable.examples") / "taut_wire.json")
NORTH_ATLANTIC = str(resources.files("stochcable.examples") / "scatter_north_atlantic.csv")


@pytest.fixture
def scatter(tmp_path):
    path = tmp_path / "s.csv"
    path.write_text("hs,tp,gamma,probability\n2,8,2,0.5\n3,10,3.3,0.5\n")
    return str(path)


def test_json_to_stdout_with_headings(scatter, capsys):
    args = ["cases", WIRE, "--scatter", scatter, "--headings", "0,180",
            "--curve", "dnv-six-strand", "--nominal-area", "1.2e-3", "--dff", "3"]  # fmt: skip
    assert main(args) == 0
    doc = json.loads(capsys.readouterr().out)
    assert len(doc["cases"]) == 4 and {c["heading"] for c in doc["cases"]} == {0.0, 180.0}
    assert sum(c["probability"] for c in doc["cases"]) == pytest.approx(1.0)
    life = doc["totals"]["wire"]["fatigue_life_years"]["end_b"]
    annual = doc["totals"]["wire"]["annual_damage"]["end_b"]
    assert life == pytest.approx(1.0 / (3.0 * annual), rel=1e-12)


def test_csv_and_netcdf_outputs(scatter, tmp_path):
    import xarray as xr

    csv_out, nc_out = tmp_path / "r.csv", tmp_path / "r.nc"
    common = ["cases", WIRE, "--scatter", scatter, "--curve", "api-six-strand",
              "--mbs", "2.2e6", "--mean-load-ratio", "0.3"]  # fmt: skip
    assert main([*common, "-o", str(csv_out)]) == 0
    assert main([*common, "-o", str(nc_out)]) == 0
    rows = csv_out.read_text().splitlines()
    ds = xr.load_dataset(nc_out)
    assert len(rows) == 3 and ds.sizes["case"] == 2
    col = rows[0].split(",").index("wire.end_b.damage_rate")
    got = np.array([float(r.split(",")[col]) for r in rows[1:]])
    np.testing.assert_array_equal(got, ds["damage_rate"].sel(line="wire", end="end_b").values)


@pytest.mark.slow
def test_bundled_north_atlantic_diagram_runs(tmp_path):
    out = tmp_path / "na.json"
    args = ["cases", WIRE, "--scatter", NORTH_ATLANTIC, "--curve", "dnv-six-strand",
            "--nominal-area", "1.2e-3", "-o", str(out)]  # fmt: skip
    assert main(args) == 0
    doc = json.loads(out.read_text())
    assert len(doc["cases"]) > 100
    assert doc["coverage"]["with_response"] == pytest.approx(1.0)


@pytest.mark.parametrize(
    ("extra", "message"),
    [
        (["--headings", "north"], "--headings"),
        (["--curve", "dnv-studless"], "nominal_area"),
        (["-o", "out.xlsx"], "--output"),
        (["--curve", "nope"], "curve"),
    ],
)
def test_errors_are_one_line(scatter, capsys, extra, message):
    assert main(["cases", WIRE, "--scatter", scatter, *extra]) == 2
    err = capsys.readouterr().err
    assert err.startswith("stochcable cases: error:") and message in err
    assert err.count("\n") == 1


@pytest.mark.slow
def test_local_cluster_from_the_command_line(scatter, tmp_path):
    pytest.importorskip("distributed")
    a, b = tmp_path / "a.json", tmp_path / "b.json"
    common = ["cases", WIRE, "--scatter", scatter, "--curve", "dnv-six-strand",
              "--nominal-area", "1.2e-3"]  # fmt: skip
    assert main([*common, "-o", str(a)]) == 0
    assert main([*common, "--workers", "2", "-o", str(b)]) == 0
    assert json.loads(a.read_text()) == json.loads(b.read_text())


def test_case_warnings_are_summarized_once(tmp_path, capsys):
    # the chain example in short seas warns of its surface element (ResolutionWarning)
    chain = str(resources.files("stochcable.examples") / "chain_catenary.json")
    path = tmp_path / "s.csv"
    path.write_text("hs,tp,probability\n2,5,0.5\n3,6,0.5\n")
    assert main(["cases", chain, "--scatter", str(path), "-o", str(tmp_path / "r.json")]) == 0
    err = capsys.readouterr().err
    assert "stochcable: warning:" not in err
    assert err.count("cases have warnings") == 1 and "e.g. case 0:" in err
    doc = json.loads((tmp_path / "r.json").read_text())
    assert all(c["warnings"] for c in doc["cases"])
