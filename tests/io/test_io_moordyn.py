"""stochcable.io: MoorDyn input files read into scenes, written back, and the errors of
bad files (tests/data/moordyn: public MoorDyn files, SOURCE.md)."""

from __future__ import annotations

import math
import warnings

import pytest
from _paths import MOORDYN_DATA

from stochcable.errors import InputError, PhysicsWarning
from stochcable.io import is_moordyn, load_scene, read_moordyn, write_moordyn
from stochcable.io.moordyn_file import MoorDynInputError

DATA = MOORDYN_DATA
READABLE = [
    "oc3_hywind_v1.txt",
    "oc3_hywind_v2.txt",
    "wd0050_chain.txt",
    "coupled_body.txt",
    "clump_weight_lifting.txt",
    "tripod_network.txt",
    "stochcable_clump_buoy.txt",
    "stochcable_buoy_network.txt",
    "stochcable_openfast_v1_counts.txt",
    # OpenFAST's regression-test inputs (tests/data/moordyn/openfast/SOURCE.md)
    "openfast/OC3Hywind_MoorDyn.dat",
    "openfast/OC4DeepCwindSemi_MoorDyn.dat",
    "openfast/MRSemi_MoorDyn.dat",
    "openfast/ITIBarge4_MoorDyn.dat",
    "openfast/MIT_NREL_TLP_MoorDyn.dat",
    "openfast/MHK_RM1_Floating_MoorDyn.dat",
]


def _read(name: str):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PhysicsWarning)
        return read_moordyn(DATA / name)


def _close(a, b, path="scene"):
    """Documents equal, numbers to 1e-12 relative (β = BA/EA with BA = β·EA written:
    one rounding each way)."""
    if isinstance(a, dict):
        assert a.keys() == b.keys(), path
        for k in a:
            _close(a[k], b[k], f"{path}.{k}")
    elif isinstance(a, (list, tuple)):
        assert len(a) == len(b), path
        for i, (u, v) in enumerate(zip(a, b)):
            _close(u, v, f"{path}[{i}]")
    elif isinstance(a, float) and isinstance(b, float):
        assert math.isclose(a, b, rel_tol=1e-12, abs_tol=1e-300), (path, a, b)
    else:
        assert a == b, (path, a, b)


# ------------------------------------------------------------------ mapping


def test_v1_and_v2_of_the_same_mooring_read_alike():
    v1, v2 = _read("oc3_hywind_v1.txt"), _read("oc3_hywind_v2.txt")
    for sc in (v1, v2):
        assert [ln.name for ln in sc.lines] == ["line1", "line2", "line3"]
        assert [b.name for b in sc.bodies] == ["vessel"]
        assert sc.bodies[0].prescribed is not None  # fairleads of a prescribed vessel
        assert sc.environment.depth == 320.0 and sc.environment.rho == 1025.0
        assert sc.environment.seabed.stiffness == 3.0e6
        assert sc.environment.seabed.damping == 3.0e5
        ln = sc.lines[0]
        assert ln.end_a.position == (853.87, 0.0, -320.0)
        assert ln.end_b.attach.body == "vessel" and ln.end_b.attach.point == (5.2, 0.0, -70.0)
        sg = ln.segments[0]
        assert (sg.length, sg.elements, sg.diameter, sg.mass, sg.ea) == (
            902.2,
            20,
            0.09,
            77.7066,
            384.243e6,
        )
    # v1 dictionary: Can Cat Cdn Cdt = 1.0 0.0 1.6 0.05; v2: Cd Ca CdAx CaAx = 1.6 1.0 0.1 0
    s1, s2 = v1.lines[0].segments[0], v2.lines[0].segments[0]
    assert (s1.cd_normal, s1.ca_normal, s1.cd_axial) == (1.6, 1.0, 0.05)
    assert (s2.cd_normal, s2.ca_normal, s2.cd_axial) == (1.6, 1.0, 0.1)
    # defaults where the option is absent: MoorDyn v1 g = 9.8, v2 9.80665
    assert v1.environment.g == 9.8 and v2.environment.g == 9.80665


def test_moordyn_f_v1_count_rows_and_nine_column_types():
    # MoorDyn-F 1.x: "3 NLines"-style count rows, CONNECTION PROPERTIES, and a LINE
    # TYPES table in v1's order (Can Cat Cdn Cdt, no EI) under the v2 header
    sc = _read("stochcable_openfast_v1_counts.txt")
    sg = sc.lines[0].segments[0]
    assert (sg.cd_normal, sg.ca_normal, sg.cd_axial) == (1.6, 1.0, 0.1)
    assert (sg.length, sg.elements) == (902.2, 20)
    assert sc.lines[1].end_a.position == (-426.935, 739.47, -320.0)
    assert sc.lines[2].end_b.attach.point == (-2.6, -4.5, -70.0)


def test_ba_becomes_stiffness_proportional_damping():
    sc = _read("oc3_hywind_v2.txt")
    sg = sc.lines[0].segments[0]
    # BA = -0.8: ζ = 0.8, BA = ζ·(L/N)·√(EA·m) (MoorDyn-C Line::initialize); β = BA/EA
    beta = 0.8 * (902.2 / 20) * math.sqrt(sg.mass / sg.ea)
    assert sc.analysis.structural_damping.beta == pytest.approx(beta, rel=1e-12)
    v1 = _read("oc3_hywind_v1.txt")  # cIntDamp 1e8 N·s: β = 1e8/EA
    assert v1.analysis.structural_damping.beta == pytest.approx(1e8 / 384.243e6, rel=1e-12)


def test_two_line_free_points_join_lines_and_carry_clump_weights_and_buoys():
    sc = _read("stochcable_clump_buoy.txt")
    (ln,) = sc.lines
    assert [s.length for s in ln.segments] == [250.0, 260.0, 150.0]
    assert [s.elements for s in ln.segments] == [25, 26, 15]
    clump, buoy = ln.attachments
    assert (clump.at, clump.mass, clump.buoyancy, clump.drag_area) == (250.0, 20000.0, 0.0, 1.0)
    rho, g = 1025.0, 9.80665
    assert buoy.at == 510.0 and buoy.mass == 0.0
    assert buoy.buoyancy == pytest.approx(rho * g * 15.0, rel=1e-15)
    assert buoy.added_mass == pytest.approx(1.0 * rho * 15.0, rel=1e-15)  # Ca·ρ·V
    assert ln.end_a.position == (-600.0, 0.0, -150.0)  # the Fixed end is end_a
    assert ln.end_b.attach.body == "vessel"


def test_free_points_of_three_or_more_lines_become_point_bodies():
    sc = _read("stochcable_buoy_network.txt")
    assert [b.name for b in sc.bodies] == ["vessel", "point1"]
    buoy = sc.body("point1")
    assert buoy.mass == 8000.0 and buoy.displaced_volume == 80.0
    assert buoy.drag_area == (3.0, 3.0, 3.0)
    assert buoy.added_mass[0][0] == pytest.approx(0.8 * 1025.0 * 80.0)
    assert set(buoy.fixed_dofs) == {"roll", "pitch", "yaw"} and buoy.prescribed is None
    ends = [(ln.end_a, ln.end_b) for ln in sc.lines]
    assert all(b.attach.body == "point1" for _, b in ends[:3])
    assert ends[3][0].attach.body == "point1" and ends[3][1].attach.body == "vessel"


def test_a_free_point_network_keeps_every_line():
    sc = _read("tripod_network.txt")
    # 11 MoorDyn lines: the float (1) and its tether (2) joined at point 1, three legs of
    # three lines each joined at two free points; the four-line junction (point 3) and
    # the float's free end (point 2) are point bodies
    assert [len(ln.segments) for ln in sc.lines] == [2, 3, 3, 3]
    assert sum(s.length for ln in sc.lines for s in ln.segments) == pytest.approx(
        0.63 + 1.11374 + 3 * (6.0 + 11.75240030480061 + 4.42)
    )
    assert sorted(b.name for b in sc.bodies) == ["point1", "point2"]
    assert sc.environment.depth == 16.0


def test_a_coupled_body_carries_its_points():
    sc = _read("coupled_body.txt")
    (body,) = sc.bodies
    assert body.name == "body1" and body.position == (0.0, 0.0, -70.0)
    assert body.prescribed is not None
    assert sc.lines[0].end_b.attach.point == (5.2, 0.0, 0.0)
    # the same fairlead as the Vessel point of the OC3 file
    assert sc.end_position("line1", "end_b").tolist() == [5.2, 0.0, -70.0]


def test_rods_are_refused_naming_the_row():
    with pytest.raises(MoorDynInputError, match=r"line 19, column 1 \(RODS\).*rods are not"):
        read_moordyn(DATA / "bodies_and_rods.dat")


def test_openfast_inputs_read_as_their_platforms():
    # (file, lines, fairlead depth [m], water depth [m]: the deepest anchor)
    for name, n, z, depth in (
        ("OC3Hywind_MoorDyn.dat", 3, -70.0, 320.0),
        ("OC4DeepCwindSemi_MoorDyn.dat", 3, -14.0, 200.0),
        ("MRSemi_MoorDyn.dat", 6, -14.0, 200.0),
        ("ITIBarge4_MoorDyn.dat", 8, -4.0, 150.0),
        ("MIT_NREL_TLP_MoorDyn.dat", 8, -47.89, 200.0),
        ("MHK_RM1_Floating_MoorDyn.dat", 6, -10.0, 50.0),
    ):
        sc = _read(f"openfast/{name}")
        assert len(sc.lines) == n and [b.name for b in sc.bodies] == ["vessel"], name
        assert sc.environment.depth == depth, name
        for ln in sc.lines:
            assert ln.end_b.attach.body == "vessel" and ln.end_b.attach.point[2] == z, name
    # the TLP's BA is in N·s: β = BA/EA = 6e6 / 1.5e9 s
    tlp = _read("openfast/MIT_NREL_TLP_MoorDyn.dat")
    assert tlp.analysis.structural_damping.beta == pytest.approx(4e-3, rel=1e-12)


def test_fast_farm_turbine_points_are_refused_naming_the_row():
    # FAST.Farm's Turbine<n> points are relative to a turbine placed by the .fstf file
    with pytest.raises(MoorDynInputError, match=r"line 21, column 6 \(POINTS\).*Turbine<n>"):
        read_moordyn(DATA / "openfast" / "SharedMooring2.dat")


def test_ignored_options_and_properties_are_named():
    with pytest.warns(PhysicsWarning) as rec:
        read_moordyn(DATA / "wd0050_chain.txt")
    text = " ".join(str(w.message) for w in rec)
    assert "options ignored" in text and "FrictionCoefficient" in text and "cfl" in text
    with pytest.warns(PhysicsWarning, match="EI"):
        read_moordyn(DATA / "tripod_network.txt")


# ------------------------------------------------------------------ round trip


@pytest.mark.parametrize("name", READABLE)
def test_read_write_read_gives_the_same_scene(name):
    sc = _read(name)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PhysicsWarning)
        again = read_moordyn(write_moordyn(sc, static_positions=False))
    _close(sc.model_dump(mode="json"), again.model_dump(mode="json"))


def test_load_scene_detects_a_moordyn_file(tmp_path):
    path = DATA / "oc3_hywind_v2.txt"
    assert is_moordyn(path) and is_moordyn(path.read_text())
    assert is_moordyn(DATA / "oc3_hywind_v1.txt")  # no MoorDyn header line: its sections
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PhysicsWarning)
        assert load_scene(path) == read_moordyn(path)
        assert load_scene(str(path)) == read_moordyn(path)
    doc = tmp_path / "scene.json"
    doc.write_text(load_scene(path).model_dump_json())
    assert not is_moordyn(doc)
    assert load_scene(doc) == load_scene(path)


def test_writer_splits_a_segment_at_an_attachment():
    sc = _read("wd0050_chain.txt")
    doc = sc.model_dump(mode="json")
    doc["lines"][0]["attachments"] = [{"at": 100.0, "mass": 5000.0}]
    text = write_moordyn(doc, static_positions=False)
    again = read_moordyn(text)
    (ln,) = again.lines
    assert [s.length for s in ln.segments] == [100.0, 310.0]
    assert [s.elements for s in ln.segments] == [10, 31]  # 41 shared in proportion
    assert ln.attachments[0].at == 100.0 and ln.attachments[0].mass == 5000.0


def test_writer_refuses_a_weight_override():
    doc = _read("wd0050_chain.txt").model_dump(mode="json")
    doc["lines"][0]["segments"][0]["weight"] = 3000.0
    with pytest.raises(InputError, match=r"segments\[0\]\.weight.*MoorDyn"):
        write_moordyn(doc)


# ------------------------------------------------------------------ bad files


GOOD = (DATA / "stochcable_clump_buoy.txt").read_text()


def _bad(text: str) -> MoorDynInputError:
    with pytest.raises(MoorDynInputError) as info:
        read_moordyn(text)
    msg = str(info.value)
    assert "\n" not in msg  # one line
    return info.value


def test_missing_section():
    lines = GOOD.splitlines()
    i = next(k for k, t in enumerate(lines) if "LINES" in t and "---" in t)
    err = _bad("\n".join(lines[:i] + lines[i + 4 :]))
    assert "no LINES section" in str(err)


def test_wrong_column_count_names_line_and_column():
    err = _bad(GOOD.replace("2 poly 2 3 260 26 -", "2 poly 2 3 260"))
    assert err.line == 19 and err.column == 15
    assert "5 columns, but the section has 7" in str(err)


def test_unknown_attachment():
    err = _bad(GOOD.replace("2 poly 2 3 260 26 -", "2 poly 2 9 260 26 -"))
    assert (err.line, err.column) == (19, 10) and "there is no point 9" in str(err)
    err = _bad(GOOD.replace("2 poly 2 3 260 26 -", "2 poly 2 R1A 260 26 -"))
    assert "no rod 1" in str(err)
    err = _bad(GOOD.replace("4 Coupled", "4 Winch1"))
    assert err.line == 14 and "unknown point attachment" in str(err)


def test_unknown_line_type():
    err = _bad(GOOD.replace("2 poly 2 3", "2 nylon 2 3"))
    assert (err.line, err.column) == (19, 3) and "unknown line type" in str(err)


def test_missing_units_row():
    err = _bad(GOOD.replace("(#) (-) (m) (m) (m) (kg) (m^3) (m^2) (-)\n", ""))
    assert err.line == 10 and "missing units row" in str(err)


def test_text_after_end():
    text = GOOD.replace(
        "------------------------- need this line",
        "---------------------- OUTPUTS ----\nFairTen1\nEND\nAnchTen1\n--- need this line",
    )
    err = _bad(text)
    assert err.line == 31 and "after the END" in str(err)
    ok = text.replace("AnchTen1\n", "")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PhysicsWarning)
        assert read_moordyn(ok).lines[0].name == "line1"


def test_bad_numbers_and_nonlinear_ea():
    err = _bad(GOOD.replace("chain 0.15 140 1.2e9", "chain 0.15 140 ea_table.txt"))
    assert (err.line, err.column) == (6, 16) and "non-linear" in str(err)
    err = _bad(GOOD.replace("chain 0.15 140 1.2e9", "chain 0.15 -140 1.2e9"))
    assert "Mass/m must be > 0" in str(err)
    err = _bad(GOOD.replace("2 Free -420", "3 Free -420"))
    assert "IDs must be 1, 2, 3" in str(err)


def test_a_scene_check_names_the_file_row():
    text = (DATA / "wd0050_chain.txt").read_text().replace("410       41", "300       41")
    err = _bad(text)
    assert (
        err.line == 15 and "MoorDyn line(s) 1" in str(err) and "shorter than its span" in str(err)
    )


def test_mutated_files_give_input_errors_only():
    """Never a traceback: 600 random edits of the shipped files (a line deleted,
    truncated, a token replaced, a line inserted, text appended) read to a scene or
    raise an InputError, nothing else."""
    import random

    from stochcable.errors import StochcableError

    rng = random.Random(20261128)
    files = sorted(DATA.glob("*.txt")) + [DATA / "bodies_and_rods.dat"]
    texts = {f: f.read_text().splitlines() for f in files}
    tokens = ["x", "-1", "0", "1e400", "nan", "R1A", "Body9", "P0", "|", "END"]
    inserts = ["END", "--- POINTS ---", "garbage here", "1 2 3", "---"]
    for _ in range(600):
        lines = list(texts[rng.choice(files)])
        k = rng.randrange(len(lines))
        op = rng.randrange(5)
        if op == 0:
            del lines[k]
        elif op == 1:
            lines[k] = lines[k][: rng.randrange(len(lines[k]) + 1)]
        elif op == 2 and lines[k].split():
            t = lines[k].split()
            t[rng.randrange(len(t))] = rng.choice(tokens)
            lines[k] = " ".join(t)
        elif op == 3:
            lines.insert(k, rng.choice(inserts))
        else:
            lines[k] += " extra"
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            try:
                read_moordyn("\n".join(lines) + "\n")
            except StochcableError:
                pass
