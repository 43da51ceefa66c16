"""The checked public functions and their trusted kernels ``<name>_unchecked``
(docs/ARCHITECTURE.md, "Conventions"): on valid input the kernel gives the public
function's answer to the bit (the checks convert, never change, a valid value); the
public function still rejects bad input; the former names of the kernels still import.
"""

from __future__ import annotations

import dataclasses
import importlib

import numpy as np
import pytest

from stochcable.errors import InputError
from stochcable.examples import load_example
from stochcable.line.catenary import catenary_solve, catenary_solve_unchecked
from stochcable.line.mesh import mesh_line
from stochcable.line.statics import solve_line_statics, solve_line_statics_unchecked
from stochcable.results.records import stats_from_spectrum, stats_from_spectrum_unchecked
from stochcable.results.statistics import response_statistics, response_statistics_unchecked
from stochcable.sea.kinematics import wave_kinematics, wave_kinematics_unchecked

# Former name -> (module, new name): public names users may import keep working.
FORMER = {
    "elastic_catenary": ("stochcable.line.catenary", "catenary_solve_unchecked"),
    "line_statics": ("stochcable.line.statics", "solve_line_statics_unchecked"),
    "nodal_kinematics": ("stochcable.sea.kinematics", "wave_kinematics_unchecked"),
    "stats_from_validated": ("stochcable.results.records", "stats_from_spectrum_unchecked"),
}


@pytest.mark.parametrize("old, where", sorted(FORMER.items()))
def test_former_names_are_the_kernels(old, where):
    module = importlib.import_module(where[0])
    assert getattr(module, old) is getattr(module, where[1])
    assert old not in module.__all__


def test_former_stats_name_still_imports_from_the_result_documents():
    from stochcable.results.documents import stats_from_validated

    assert stats_from_validated is stats_from_spectrum_unchecked


def _spectrum(seed: int = 5) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    w = np.linspace(0.05, 2.0, 120)
    return w, rng.uniform(0.0, 1.0, w.size) ** 2


@pytest.mark.parametrize("duration", [10800.0, 3600.0])
def test_stats_kernel_equals_the_public_function(duration):
    w, dens = _spectrum()
    assert (
        stats_from_spectrum_unchecked(w, dens, 12.5, duration).as_dict()
        == stats_from_spectrum(w, dens, 12.5, duration).as_dict()
    )
    with pytest.raises(InputError, match="omega"):
        stats_from_spectrum(w[::-1], dens, 0.0, 10800.0)
    with pytest.raises(InputError, match="density .*1-D"):
        stats_from_spectrum(w, np.stack([dens, dens]), 0.0, 10800.0)


@pytest.mark.parametrize("rows", [1, 3])
def test_response_statistics_kernel_equals_the_public_function(rows):
    w, dens = _spectrum()
    s = dens if rows == 1 else np.stack([dens * (k + 1) for k in range(rows)])
    a = dataclasses.asdict(response_statistics(w, s, 3600.0))
    b = dataclasses.asdict(response_statistics_unchecked(w, s, 3600.0))
    for key in a:
        np.testing.assert_array_equal(a[key], b[key], err_msg=key)


@pytest.mark.parametrize(
    "args",
    [
        (350.0, 100.0, 400.0, 1000.0, 1e8, True),  # slack with seabed contact
        (300.0, 50.0, 300.0, 500.0, 1e7, False),  # taut
        (0.0, 100.0, 120.0, 100.0, float("inf"), False),  # vertical, folded
    ],
)
def test_catenary_kernel_equals_the_public_function(args):
    assert catenary_solve_unchecked(*args) == catenary_solve(*args)
    with pytest.raises(InputError, match="length"):
        catenary_solve(args[0], args[1], -1.0, *args[3:])


def test_line_statics_kernel_equals_the_public_function():
    scene = load_example("chain_catenary")
    env = scene.environment
    mesh = mesh_line(scene.lines[0], env.rho, env.g)
    for method in ("auto", "fe"):
        a = solve_line_statics(mesh, env, method, tolerance=1e-10, max_iterations=500)
        b = solve_line_statics_unchecked(mesh, env, method, None, 1e-10, 500)
        np.testing.assert_array_equal(a.positions, b.positions)
        np.testing.assert_array_equal(a.tension, b.tension)
    with pytest.raises(InputError, match="tolerance"):
        solve_line_statics(mesh, env, tolerance=2.0)


def test_wave_kinematics_kernel_equals_the_public_function():
    w = np.linspace(0.0, 2.0, 41)
    pts = np.array([[0.0, 0.0, 0.0], [10.0, -5.0, -20.0], [3.0, 2.0, 1.0]])
    full = wave_kinematics(w, pts, heading=0.3, depth=60.0)
    phase, cc, dry, vel, acc = wave_kinematics_unchecked(
        full.omega, full.wavenumber, full.points, 0.3, 60.0, 9.80665
    )
    np.testing.assert_array_equal(phase, full.elevation)
    np.testing.assert_array_equal(vel, full.velocity)
    np.testing.assert_array_equal(acc, full.acceleration)
    assert dry.tolist() == [False, False, True]
    with pytest.raises(InputError, match="depth"):
        wave_kinematics(w, pts, depth=-1.0)
