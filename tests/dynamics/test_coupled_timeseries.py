"""Time series of lines coupled to bodies and of the bodies
(stochcable.dynamics.timeseries.group_transfer,
stochcable.dynamics.timeseries.synthesis.simulate_timeseries with ``coupled=``; GitHub issue 6).

Independent checks: the DSA variance of every series against the band sum of the
response spectrum of the transfer synthesized (Parseval, round-off) and against the
frequency-domain σ of the Result (a separate solve on the analysis grid); the series
against the direct O(N²) circular convolution of η and of the end-motion realization
with the impulse responses of the Result's transfer functions (Tuah 1982, §5.1: one
realization drives everything); the infinitely heavy (fixed) body against the line
with a fixed fairlead (a line alone, the group without bodies); NSA variances
against their exact sampling distribution; the chunked solve against the one-piece
solve; the vessel (prescribed body) and its riser against the RAO.

The scenes are the planar seed-§6.5 disc buoy on one leg (stochcable/examples, ft-slug
units) on a realization grid: T = 256 s, dt = 0.5 s, Δω = 2π/256 rad/s, the analysis
grid ω_m, m = 2 … 160, so the Result's transfer functions are on the realization grid.
"""

from __future__ import annotations

import copy
import math
import warnings

import numpy as np
import pytest
from scipy import stats

from stochcable.analysis import analyze
from stochcable.dynamics.timeseries.group_transfer import coupled_group_transfer, frequency_chunks
from stochcable.errors import InputError
from stochcable.examples import load_example
from stochcable.sea.realization import simulate_sea

# The example's 3-element leg has large motions (its warnings are the subject of
# other tests); the grid cuts the PM end-motion tail on purpose.
pytestmark = [
    pytest.mark.xdist_group("test_coupled_timeseries"),
    pytest.mark.filterwarnings("ignore::stochcable.errors.PhysicsWarning"),
    pytest.mark.filterwarnings("ignore::stochcable.errors.ResolutionWarning"),
]

T_L, DT, M = 256.0, 0.5, (2, 160)
D_OMEGA = 2.0 * math.pi / T_L
SINGLE_LEG = "tuah_1982_disc_buoy_single_leg"
# the fixed points below are converged to 1e-11 (relative change of every σ)
FP_TOLERANCE = 1e-11


def _doc(
    method: str = "dsa",
    seed: int = 5,
    *,
    vessel: bool = True,
    anchor_motion: bool = True,
    floating: bool = False,
) -> dict:
    """Disc buoy on one leg (free, planar), the leg's anchor surging with a PM
    spectrum, (``vessel``) a riser hanging from a prescribed vessel and (``floating``)
    a second disc without lines, held in surge by a spring."""
    doc = copy.deepcopy(load_example(SINGLE_LEG).model_dump(mode="json"))
    doc["analysis"]["omega"] = {
        "min": M[0] * D_OMEGA,
        "max": M[1] * D_OMEGA,
        "count": M[1] - M[0] + 1,
    }
    # the linear model's σ (the series are linear; the residuals reach lines on bodies)
    doc["analysis"]["linearization"] = {
        "tolerance": FP_TOLERANCE,
        "max_iterations": 200,
        "drag_residual": False,
        "geometric_residual": False,
    }
    doc["analysis"]["timeseries"] = {"method": method, "duration": T_L, "dt": DT, "seed": seed}
    doc["lines"][0]["segments"][0]["elements"] = 6
    if anchor_motion:
        doc["lines"][0]["end_a"]["motion"] = {
            "surge": {"type": "pierson_moskowitz", "hs": 1.0, "tp": 9.0}
        }
    if floating:
        b = copy.deepcopy(doc["bodies"][0])
        b.update(
            name="float",
            position=[100.0, 0.0, 0.0],
            wind_force=[0.0, 0.0, 0.0],
            extra_stiffness=[[50.0, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, 0.0]],
        )
        doc["bodies"].append(b)
    if vessel:
        w = np.linspace(0.01, 5.0, 60)
        rao = {
            "surge": 0.8 * np.exp(-0.3j * w) / (1 + w**2),
            "heave": 1.0 / (1 + (w / 0.9) ** 4) + 0j,
            "pitch": 0.02j * w * np.exp(-w),
        }
        doc["bodies"].append(
            {
                "name": "ship",
                "position": [300.0, 0.0, 0.0],
                "mass": 1e6,
                "prescribed": {
                    "omega": w.tolist(),
                    **{k: {"re": v.real.tolist(), "im": v.imag.tolist()} for k, v in rao.items()},
                },
            }
        )
        doc["lines"].append(
            {
                "name": "riser",
                "end_a": {"position": [500.0, 0.0, -100.0]},
                "end_b": {"attach": {"body": "ship", "point": [10.0, 0.0, -5.0]}},
                "segments": [
                    {
                        "length": 260.0,
                        "ea": 1.0e6,
                        "mass": 0.5,
                        "diameter": 0.2,
                        "cd_normal": 1.2,
                        "elements": 8,
                    }
                ],
            }
        )
    return doc


@pytest.fixture(scope="module")
def dsa_result():
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        res = analyze(_doc())
    return res, [str(w.message) for w in caught]


@pytest.fixture(scope="module")
def sea_only_result():
    """The sea as the only channel: the DSA variance of a series is then exact (two
    channels add a cross term of their independent phases)."""
    return analyze(_doc(anchor_motion=False, floating=True))


def _band() -> slice:
    return slice(M[0], M[1] + 1)


def _sea_density(res):
    scene = res.scene
    w = res.timeseries.omega
    s = np.zeros_like(w)
    s[1:-1] = scene.sea.spectrum.spectral_density(w[1:-1], scene.environment.g)
    return s


def _channel_spectra(res, names):
    """Input spectrum of each channel on the realization grid (0 at ω_0 and ω_N)."""
    ts = res.timeseries
    out = []
    for n in names:
        if n == "sea":
            out.append(_sea_density(res))
        else:
            line, end, dof = n.split(".")
            ln = next(x for x in res.scene.lines if x.name == line)
            spec = getattr(getattr(ln, end).motion, dof)
            s = np.zeros_like(ts.omega)
            s[1:-1] = spec.spectral_density(ts.omega[1:-1], res.scene.environment.g)
            out.append(s)
    return np.stack(out)


def _series(res):
    """(label, dynamic part of the series, transfer (n_ch, N+1), channel names, FD
    spectrum on the analysis grid) for every coupled/vessel series of the result."""
    ts = res.timeseries
    out = []
    for end in ("end_a", "end_b"):
        mean = getattr(res.lines["leg"], end).mean
        out.append(
            (
                f"leg.{end}",
                ts.end_tension["leg"][end] - mean,
                ts.end_tension_transfer["leg"][end],
                ts.channels["leg"],
                res.lines["leg"].end_tension_spectrum(end),
            )
        )
    for body in res.timeseries.body_motion:
        b = res.bodies[body]
        spec = b.motion_spectrum
        for i, dof in enumerate(b.dofs):
            out.append(
                (
                    f"{body}.{dof}",
                    ts.body_motion[body][dof] - b.motion[dof].mean,
                    ts.body_motion_transfer[body][:, i],
                    ts.body_channels[body],
                    spec[i],
                )
            )
    return out


# ------------------------------------------------------------- DSA: Parseval


def test_dsa_variance_equals_band_sum_and_result_sigma(sea_only_result):
    res = sea_only_result
    ts = res.timeseries
    assert ts.channels["leg"] == ("sea",)
    assert ts.body_channels == {"disc": ("sea",), "float": ("sea",), "ship": ("sea",)}
    assert list(ts.body_motion["disc"]) == ["surge", "heave", "pitch"]
    checked = 0
    for label, x, h, names, s_fd in _series(res):
        s_in = _channel_spectra(res, names)
        band_sum = float(np.sum(np.abs(h) ** 2 * s_in) * D_OMEGA)
        if band_sum == 0.0:  # the ship's sway, roll, yaw (planar RAO)
            assert np.all(x == 0.0), label
            continue
        # DSA: the record's variance is the band sum of |H|²SΔω exactly (Parseval over
        # the periodic record; round-off of the FFTs only)
        assert np.mean(x**2) == pytest.approx(band_sum, rel=1e-10), label
        assert abs(np.mean(x)) < 1e-9 * math.sqrt(band_sum), label
        # The Result's σ² is the trapezoid rule of its spectrum on the analysis grid,
        # which here is the realization band: the band sum is that trapezoid plus the
        # two half end weights, ½Δω(S_first + S_last) (the grid-quadrature difference,
        # exact on this grid); the spectra come from two solves of the same linear
        # system at the same drag: round-off
        sigma = res.lines["leg"] if label.startswith("leg") else None
        m0 = (
            getattr(sigma, label[4:]).m0
            if sigma is not None
            else res.bodies[label.split(".")[0]].motion[label.split(".")[1]].m0
        )
        assert m0 + 0.5 * D_OMEGA * (s_fd[0] + s_fd[-1]) == pytest.approx(band_sum, rel=1e-9), label
        checked += 1
    # both leg ends, the 3 DOFs of the disc, the line-less float and the ship
    assert checked == 2 + 3 + 3 + 3


def test_dsa_three_leg_buoy_in_3d():
    """The seed §6.7 disc on three legs (3-D, 6 DOFs): every leg end and body DOF
    with motion has the DSA variance of its band sum and the Result's σ² plus the end
    half-weights (as above); the mirror-symmetric sway, roll, yaw stay ~0."""
    doc = load_example("tuah_1982_disc_buoy_three_legs").model_dump(mode="json")
    doc["analysis"]["omega"] = {
        "min": M[0] * D_OMEGA,
        "max": M[1] * D_OMEGA,
        "count": M[1] - M[0] + 1,
    }
    doc["analysis"]["timeseries"] = {"method": "dsa", "duration": T_L, "dt": DT, "seed": 2}
    doc["analysis"]["linearization"].update(drag_residual=False, geometric_residual=False)
    res = analyze(doc)
    ts = res.timeseries
    s_sea = _sea_density(res)
    b = res.bodies["disc"]
    items = [
        (
            ts.end_tension[n][e] - getattr(res.lines[n], e).mean,
            ts.end_tension_transfer[n][e][0],
            getattr(res.lines[n], e).m0,
            res.lines[n].end_tension_spectrum(e),
        )
        for n in res.lines
        for e in ("end_a", "end_b")
    ]
    spec = b.motion_spectrum
    items += [
        (
            ts.body_motion["disc"][k] - b.motion[k].mean,
            ts.body_motion_transfer["disc"][0, i],
            b.motion[k].m0,
            spec[i],
        )
        for i, k in enumerate(b.dofs)
        if k in ("surge", "heave", "pitch")
    ]
    for x, h, m0, s_fd in items:
        band_sum = float(np.sum(np.abs(h) ** 2 * s_sea) * D_OMEGA)
        # Parseval (round-off) and the trapezoid + end half-weights (two solves of one
        # system: round-off)
        assert np.mean(x**2) == pytest.approx(band_sum, rel=1e-10)
        assert m0 + 0.5 * D_OMEGA * (s_fd[0] + s_fd[-1]) == pytest.approx(band_sum, rel=1e-9)
    # heading 0 mirrors about x: sway, roll, yaw vanish to round-off against surge
    surge = float(np.std(ts.body_motion["disc"]["surge"]))
    for k in ("sway", "roll", "yaw"):
        assert float(np.std(ts.body_motion["disc"][k])) < 1e-8 * surge


def test_transfer_outside_the_band_is_zero_and_warning_is_gone(dsa_result):
    res, messages = dsa_result
    ts = res.timeseries
    assert ts.channels["leg"] == ("sea", "leg.end_a.surge")
    assert ts.body_channels == {"disc": ("sea", "leg.end_a.surge"), "ship": ("sea",)}
    for h in (ts.end_tension_transfer["leg"]["end_b"], ts.body_motion_transfer["disc"]):
        assert np.all(h[..., : M[0]] == 0.0) and np.all(h[..., M[1] + 1 :] == 0.0)
    assert not any("time series are not simulated" in m for m in messages)
    assert set(ts.end_tension) == {"leg", "riser"}


# --------------------------------------------------- convolution consistency


def _circular_convolution(h: np.ndarray, x: np.ndarray) -> np.ndarray:
    """y_n = Σ_k h_k x_{(n−k) mod N}, by the direct O(N²) sum (no FFT)."""
    n = x.size
    idx = (np.arange(n)[:, None] - np.arange(n)[None, :]) % n
    return x[idx] @ h


def _on_grid(res, values: np.ndarray) -> np.ndarray:
    full = np.zeros(res.timeseries.omega.size, dtype=complex)
    full[_band()] = values
    return full


def _inputs(res, names):
    ts = res.timeseries
    return [ts.elevation if n == "sea" else ts.end_motion[n] for n in names]


@pytest.mark.parametrize("end", ["end_a", "end_b"])
def test_coupled_tension_is_the_convolution_of_eta_and_the_anchor_motion(dsa_result, end):
    """The coupled line's tension = η ⊛ h_sea + x ⊛ h_x with h = irfft of the
    Result's transfer functions (solved on the analysis grid, not the series')."""
    res, _ = dsa_result
    ts = res.timeseries
    line = res.lines["leg"]
    assert line.channels == ts.channels["leg"]
    n_t = ts.time.size
    y = ts.end_tension["leg"][end] - getattr(line, end).mean
    expected = sum(
        _circular_convolution(np.fft.irfft(_on_grid(res, h), n_t), x)
        for h, x in zip(line.end_tension_transfer[end], _inputs(res, line.channels))
    )
    scale = float(np.max(np.abs(expected)))
    assert scale > 0.0
    # round-off: FFTs vs the direct sum, two solves of the same system (1e-9 above);
    # a wrong channel order or realization (seed scheme) is an O(1) error
    np.testing.assert_allclose(y, expected, rtol=0, atol=1e-9 * scale)
    swapped = sum(
        _circular_convolution(np.fft.irfft(_on_grid(res, h), n_t), x)
        for h, x in zip(line.end_tension_transfer[end], _inputs(res, line.channels)[::-1])
    )
    assert np.max(np.abs(swapped - y)) > 0.1 * scale


@pytest.mark.parametrize("body", ["disc", "ship"])
def test_body_motion_is_the_convolution_of_its_inputs(dsa_result, body):
    res, _ = dsa_result
    ts = res.timeseries
    b = res.bodies[body]
    assert b.channels == ts.body_channels[body]
    n_t = ts.time.size
    for i, dof in enumerate(b.dofs):
        y = ts.body_motion[body][dof] - b.motion[dof].mean
        expected = sum(
            _circular_convolution(np.fft.irfft(_on_grid(res, h), n_t), x)
            for h, x in zip(b.motion_transfer[:, i], _inputs(res, b.channels))
        )
        scale = float(np.max(np.abs(expected)))
        if scale == 0.0:
            assert np.all(y == 0.0)
            continue
        # round-off as above
        np.testing.assert_allclose(y, expected, rtol=0, atol=1e-9 * scale, err_msg=dof)


def test_vessel_riser_series_moves_with_the_vessel(dsa_result):
    """The riser hangs from the vessel: its series' transfer is the Result's (the end
    moving with the RAO in the sea channel), not the one of a held end."""
    res, _ = dsa_result
    ts = res.timeseries
    h = ts.end_tension_transfer["riser"]["end_b"][0, _band()]
    ref = res.lines["riser"].end_tension_transfer["end_b"][0]
    # the same system solved twice at the same frequencies: round-off
    np.testing.assert_allclose(h, ref, rtol=1e-9, atol=1e-12 * np.max(np.abs(ref)))
    # the elevation is the stand-alone realization with the seed
    spec, g = res.scene.sea.spectrum, res.scene.environment.g
    eta = simulate_sea(
        lambda w: np.where(w > 0, spec.spectral_density(np.where(w > 0, w, 1.0), g), 0.0),
        T_L,
        DT,
        "dsa",
        rng=5,
    )
    np.testing.assert_allclose(ts.elevation, eta.elevation, rtol=0, atol=1e-12)


# ----------------------------------------------------- limit: a fixed body


def _fixed_body_docs():
    doc = _doc(vessel=False)
    body = doc["bodies"][0]
    big = 1e15
    body.update(
        mass=big,
        inertia=np.diag([big] * 3).tolist(),
        hydrodynamics=None,
        added_mass=None,
        radiation_damping=None,
        drag_area=[0.0, 0.0, 0.0],
        wind_force=[0.0, 0.0, 0.0],
        displaced_volume=None,
        fixed_dofs=["surge", "heave", "pitch"],
    )
    ref = copy.deepcopy(doc)
    ref.pop("bodies")
    return doc, ref


def test_fixed_heavy_body_gives_the_fixed_fairlead_series():
    """All DOFs fixed and m, I = 1e15: the leg's series equal those of the same leg
    with its fairlead fixed at the attachment point (independent path), the same seed."""
    doc, ref = _fixed_body_docs()
    res = analyze(doc)
    fair = res.statics.lines["leg"].positions[-1]
    ref["lines"][0]["end_b"] = {"position": fair.tolist()}
    rref = analyze(ref)
    ts, tr = res.timeseries, rref.timeseries
    assert ts.channels["leg"] == ("sea", "leg.end_a.surge")
    assert tr.channels["leg"] == ("sea", "end_a.surge")
    np.testing.assert_array_equal(
        ts.end_motion["leg.end_a.surge"], tr.end_motion["leg.end_a.surge"]
    )
    for end in ("end_a", "end_b"):
        a, b = ts.end_tension["leg"][end], tr.end_tension["leg"][end]
        scale = float(np.std(b))
        # the two fixed points agree to ~FP_TOLERANCE (relative σ change; measured
        # 5e-13 of σ); were the DOFs not held, the 1e15 body would lag by |F|/(ω²m)
        # ~ 1e2/(0.049²·1e15) ft, a tension change k·ξ ~ 5e2·4e-11 lbf ~ 3e-10 σ
        np.testing.assert_allclose(a - b, 0.0, atol=1e-9 * scale)
        assert scale > 0.0
    disc = ts.body_motion["disc"]
    assert max(float(np.std(v)) for v in disc.values()) < 1e-9


# ------------------------------------------------------------- NSA: χ² band


def test_nsa_variance_within_its_sampling_band():
    """NSA: the record's variance is Σ_m c_m E_m, c_m = |H_m|²S_mΔω, E_m iid Exp(1)
    (a_m² = SΔω(α² + β²), (α² + β²)/2 ~ Exp(1)); its mean Σc and variance Σc² give a
    Satterthwaite χ²_ν/ν band, ν = 2(Σc)²/Σc² (≈ 47 for the heave here).  Each of 6
    seeds must fall in the two-sided 1e-3 band, their mean in the pooled χ²_{6ν}/6ν
    band (a factor-2 error in the NSA amplitudes fails it), and the scatter is real
    (not DSA)."""
    ratios: dict[str, list[float]] = {"heave": [], "tension": []}
    nus: dict[str, float] = {}
    for seed in range(6):
        res = analyze(_doc("nsa", seed=seed, vessel=False, anchor_motion=False))
        ts = res.timeseries
        s_sea = _sea_density(res)
        for key, x, h in (
            (
                "heave",
                ts.body_motion["disc"]["heave"] - res.bodies["disc"].motion["heave"].mean,
                ts.body_motion_transfer["disc"][0, 1],
            ),
            (
                "tension",
                ts.end_tension["leg"]["end_b"] - res.lines["leg"].end_b.mean,
                ts.end_tension_transfer["leg"]["end_b"][0],
            ),
        ):
            c = np.abs(h) ** 2 * s_sea * D_OMEGA
            nu = 2.0 * c.sum() ** 2 / np.sum(c**2)
            lo, hi = stats.chi2.ppf([5e-4, 1 - 5e-4], nu) / nu
            r = float(np.mean(x**2) / c.sum())
            assert lo < r < hi, (key, seed, r, lo, hi)
            ratios[key].append(r)
            nus[key] = nu
    for key, rs in ratios.items():
        n = len(rs) * nus[key]
        lo, hi = stats.chi2.ppf([5e-4, 1 - 5e-4], n) / n
        assert lo < np.mean(rs) < hi, (key, rs)
        assert np.std(rs) > 1e-3


# ------------------------------------------------------------------ chunks


def test_chunked_solve_equals_one_piece(dsa_result):
    """The band solved in chunks of 64 frequencies equals the one-piece solve (the
    solve is independent per frequency: round-off)."""
    res, _ = dsa_result
    from stochcable.dynamics.groups import analyze_coupled

    scene = res.scene
    out = analyze_coupled(scene, res.statics, scene.analysis)
    (group,) = out.groups
    w = res.timeseries.omega[_band()]
    whole = coupled_group_transfer(scene, group, w, budget=2**40)
    parts = coupled_group_transfer(scene, group, w, budget=1)
    assert len(list(frequency_chunks(w.size, 10**9, 1))) == math.ceil(w.size / 64)
    np.testing.assert_allclose(
        parts.body_motion["disc"],
        whole.body_motion["disc"],
        rtol=1e-12,
        atol=1e-14 * np.max(np.abs(whole.body_motion["disc"])),
    )
    for end in ("end_a", "end_b"):
        a, b = parts.end_tension["leg"][end], whole.end_tension["leg"][end]
        np.testing.assert_allclose(a, b, rtol=1e-12, atol=1e-14 * np.max(np.abs(b)))


def test_group_transfer_refuses_bad_frequencies(dsa_result):
    res, _ = dsa_result
    from stochcable.dynamics.groups import analyze_coupled

    (group,) = analyze_coupled(res.scene, res.statics, res.scene.analysis).groups
    with pytest.raises(InputError, match=r"omega.*rad/s"):
        coupled_group_transfer(res.scene, group, [0.0, 0.5])
    with pytest.raises(InputError, match="budget"):
        coupled_group_transfer(res.scene, group, [0.5], budget=0)


def test_document_has_the_body_series(dsa_result):
    res, _ = dsa_result
    doc = res.to_document()["timeseries"]
    assert set(doc["bodies"]) == {"disc", "ship"}
    assert list(doc["bodies"]["disc"]["motion"]) == ["surge", "heave", "pitch"]
    assert len(doc["bodies"]["ship"]["motion"]["roll"]) == doc["window"]
    assert set(doc["lines"]) == {"leg", "riser"}
    np.testing.assert_array_equal(
        doc["bodies"]["disc"]["motion"]["heave"],
        res.timeseries.body_motion["disc"]["heave"][: doc["window"]],
    )
