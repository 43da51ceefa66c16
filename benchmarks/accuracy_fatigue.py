"""Fatigue and non-Gaussian statistics of the accuracy page (docs/accuracy/lines.md,
benchmarks/accuracy_lines.py): spectral fatigue damage against rainflow damage of
time-domain records, the records' skewness and kurtosis, and what a Hermite
(Winterstein) transform with those moments does to the Gaussian damage and maximum.

Pure functions of arrays; the page's tables are written by accuracy_lines.py.

References
----------
Winterstein, S. R. (1988), Nonlinear vibration models for extremes and fatigue,
J. Eng. Mech. 114(10), 1772–1790: the Hermite model x = κ[u + h3(u² − 1) + h4(u³ − 3u)]
of a non-Gaussian response x (standardized) as a function of a standard Gaussian u, with
h3 = α3/6, h4 = (α4 − 3)/24 and κ = 1/√(1 + 2h3² + 6h4²) from its skewness α3 and
kurtosis α4 (the first-order moment fit).
"""

from __future__ import annotations

import math

import numpy as np
from scipy import stats

from stochcable.design.curves import FatigueCurve, fatigue_curve, tension_to_curve_quantity
from stochcable.design.hermite import HermiteModel, hermite_model_winterstein
from stochcable.design.hermite import hermite_level as _level
from stochcable.design.rainflow_fatigue import damage_rainflow
from stochcable.design.spectral_fatigue import damage_rate_dirlik

__all__ = [
    "periodic_density",
    "moments_of_record",
    "hermite_coefficients",
    "hermite_amplitude",
    "hermite_level",
    "hermite_damage_factor",
    "gaussian_expected_maximum",
    "dirlik_flife",
    "damage_rates",
    "phase_randomized",
    "low_passed",
]


def periodic_density(x: np.ndarray, dt: float) -> tuple[np.ndarray, np.ndarray]:
    """One-sided spectral density of a record that is one period of a periodic signal.

    Parameters
    ----------
    x : ndarray, shape (n,)
        One whole period, sampled every ``dt`` (a DSA realization measured over its
        period): its lines 2πj/(n·dt) are exact, without leakage. [unit]
    dt : float
        Sampling interval. [s]

    Returns
    -------
    omega : ndarray, shape (n//2,)
        The lines 2πj/(n·dt), j = 1 … n//2. [rad/s]
    density : ndarray, shape (n//2,)
        Each line's variance over the line spacing Δω = 2π/(n·dt): Σ density·Δω is the
        record's variance (the mean removed). [unit²·s/rad]
    """
    x = np.asarray(x, dtype=float)
    n = x.size
    c = np.fft.rfft(x - x.mean()) / n
    var = 2.0 * np.abs(c[1:]) ** 2
    if n % 2 == 0:
        var[-1] /= 2.0  # the Nyquist line is real: counted once
    dw = 2.0 * math.pi / (n * dt)
    return dw * np.arange(1, var.size + 1), var / dw


def phase_randomized(x: np.ndarray, rng: np.random.Generator, count: int) -> np.ndarray:
    """Gaussian surrogates of one period of a periodic record: its Fourier amplitudes
    with independent uniform phases (the same spectrum, line by line, the phase
    coupling that makes it non-Gaussian removed), ``count`` of them. [unit]

    Returns
    -------
    ndarray, shape (count, n)
        The surrogates, each with the record's mean and variance.
    """
    x = np.asarray(x, dtype=float)
    c = np.fft.rfft(x)
    mag = np.abs(c)
    phase = rng.uniform(0.0, 2.0 * math.pi, size=(count, c.size))
    out = mag * np.exp(1j * phase)
    out[:, 0] = c[0]  # the mean
    if x.size % 2 == 0:
        out[:, -1] = c[-1]  # the Nyquist line stays real
    return np.fft.irfft(out, n=x.size)


def low_passed(x: np.ndarray, dt: float, omega_max: float) -> np.ndarray:
    """Periodic records (last axis one period each) without their lines above
    ``omega_max`` [rad/s]. [unit]"""
    x = np.asarray(x, dtype=float)
    c = np.fft.rfft(x, axis=-1)
    w = 2.0 * math.pi * np.arange(c.shape[-1]) / (x.shape[-1] * dt)
    c[..., w > omega_max] = 0.0
    return np.fft.irfft(c, n=x.shape[-1], axis=-1)


def moments_of_record(x: np.ndarray) -> dict[str, float]:
    """Mean, σ, skewness α3 and kurtosis α4 (3 for a Gaussian) of a record. [unit, -]"""
    x = np.asarray(x, dtype=float)
    return {
        "mean": float(x.mean()),
        "std": float(x.std()),
        "skewness": float(stats.skew(x)),
        "kurtosis": float(stats.kurtosis(x, fisher=False)),
    }


def hermite_coefficients(skewness: float, kurtosis: float) -> tuple[float, float, float]:
    """Winterstein's (1988) first-order Hermite coefficients (h3, h4, κ) of a process
    with skewness α3 and kurtosis α4: h3 = α3/6, h4 = (α4 − 3)/24,
    κ = 1/√(1 + 2h3² + 6h4²) (:func:`stochcable.design.hermite_model_winterstein`). [-]"""
    model = hermite_model_winterstein(skewness, kurtosis)
    return model.h3, model.h4, model.kappa


def hermite_amplitude(u: np.ndarray, h4: float, kappa: float) -> np.ndarray:
    """Amplitude (half range) of a cycle of the Hermite process whose Gaussian cycle
    runs from −u to u (in σ): (g(u) − g(−u))/2 = κ[u + h4(u³ − 3u)] (h3 cancels in a
    cycle symmetric about the mean). [σ]"""
    u = np.asarray(u, dtype=float)
    return kappa * (u + h4 * (u**3 - 3.0 * u))


def hermite_level(u: np.ndarray | float, h3: float, h4: float, kappa: float) -> np.ndarray:
    """Winterstein's (1988) Hermite model: the standardized non-Gaussian level
    κ[u + h3(u² − 1) + h4(u³ − 3u)] of the standard Gaussian level u
    (:func:`stochcable.design.hermite_level`). [σ]"""
    return _level(u, HermiteModel(h3, h4, kappa))


def hermite_damage_factor(
    omega: np.ndarray, density: np.ndarray, slope: float, h4: float, kappa: float
) -> float:
    """Damage of the Hermite process over that of the Gaussian one with the same
    spectrum, for an S–N slope m: E[a_H^m]/E[a^m] with the Gaussian rainflow amplitudes
    a ~ Dirlik's density of the spectrum (FLife's ``Dirlik.get_PDF``) mapped cycle by
    cycle through :func:`hermite_amplitude` (Winterstein 1988). [-]

    Parameters
    ----------
    omega, density : ndarray
        The spectrum (one-sided) [rad/s], [unit²·s/rad].
    slope : float
        S–N slope m. [-]
    h4, kappa : float
        :func:`hermite_coefficients`. [-]
    """
    import FLife  # noqa: PLC0415 (a benchmark dependency)

    w = np.asarray(omega, dtype=float)
    sd = FLife.SpectralData(
        input={"PSD": 2.0 * math.pi * np.asarray(density), "f": w / (2 * math.pi)}
    )
    sigma = math.sqrt(sd.moments[0])
    u = np.linspace(1e-6, 12.0, 24001)  # amplitude in σ: the density is < 1e-30 beyond
    pdf = np.asarray(FLife.Dirlik(sd).get_PDF(u * sigma)) * sigma
    gauss = np.trapezoid(u**slope * pdf, u)
    herm = np.trapezoid(np.abs(hermite_amplitude(u, h4, kappa)) ** slope * pdf, u)
    return float(herm / gauss)


def dirlik_flife(omega: np.ndarray, density: np.ndarray, curve: FatigueCurve) -> float:
    """Dirlik's damage rate by FLife (an independent implementation; amplitudes, so
    the intercept a/2^m of a one-slope range curve) of a density in the curve's
    quantity [unit²·s/rad]. [1/s]"""
    import FLife  # noqa: PLC0415 (a benchmark dependency)

    w = np.asarray(omega, dtype=float)
    sd = FLife.SpectralData(
        input={"PSD": 2.0 * math.pi * np.asarray(density), "f": w / (2 * math.pi)}
    )
    m = curve.slopes[0]
    return 1.0 / FLife.Dirlik(sd).get_life(10.0 ** curve.log10_intercepts[0] / 2.0**m, m)


def gaussian_expected_maximum(tz: float, duration: float) -> float:
    """Expected largest maximum of a narrow-band Gaussian process over ``duration``,
    in σ above the mean: √(2 ln N) + γ/√(2 ln N), N = duration/Tz upcrossings. [σ]"""
    r = math.sqrt(2.0 * math.log(duration / tz))
    return r + 0.5772156649 / r


def damage_rates(
    records: list[np.ndarray],
    dt: float,
    spectrum: tuple[np.ndarray, np.ndarray],
    curve: FatigueCurve,
    factor: float,
) -> dict[str, np.ndarray | float]:
    """Damage rates [1/s] of a tension [N] in the curve's quantity (``factor`` [1/N]
    turns one into the other: :func:`stochcable.design.curves.tension_to_curve_quantity`):
    ``rainflow``, the rainflow damage of each record (one period each); ``dirlik_td``,
    Dirlik's damage of each record's own spectrum (:func:`periodic_density`) up to the
    top of ``spectrum``'s frequencies (above them a TD record holds little variance
    but, up to its Nyquist frequency, enough of the fourth moment to change Dirlik's
    peak rate: the chain's TD fairlead spectrum has a mean period between peaks of
    0.7 s, 3.6 s up to 6 rad/s);
    ``dirlik``, Dirlik's of ``spectrum`` (omega [rad/s], density [N²·s/rad])."""
    w_top = float(np.max(spectrum[0]))
    rain, own = [], []
    for x in records:
        y = np.asarray(x, dtype=float) * factor
        rain.append(damage_rainflow(y, curve, duration=y.size * dt))
        w, s = periodic_density(y, dt)
        keep = w <= w_top
        own.append(float(damage_rate_dirlik(w[keep], s[keep], curve)))
    w, s = spectrum
    return {
        "rainflow": np.array(rain),
        "dirlik_td": np.array(own),
        "dirlik": float(damage_rate_dirlik(w, np.asarray(s) * factor**2, curve)),
    }


# ---------------------------------------------------------------- the page's sections

SURROGATES = 20  # Gaussian surrogates per record (phase-randomized)
TARGET = 0.10  # issue 31: fatigue damage within 10 % of the TD's rainflow damage


def _factor(curve: FatigueCurve) -> float:
    """Tension → curve quantity.  The damage ratios of a one-slope curve do not depend
    on it (both sides scale by factor^m): chain bar diameter 0.12 m (the example's
    120 mm chain), a nominal 0.01 m² for the ropes."""
    if curve.name in ("dnv-studlink", "dnv-studless"):
        return tension_to_curve_quantity(curve, nominal_diameter=0.12)
    return tension_to_curve_quantity(curve, nominal_area=0.01)


def _ci(x: np.ndarray) -> tuple[float, float]:
    x = np.asarray(x, dtype=float)
    return float(x.mean()), float(
        stats.t.ppf(0.975, x.size - 1) * x.std(ddof=1) / math.sqrt(x.size)
    )


def _vs_mean(num: float, xs: np.ndarray) -> str:
    """num / mean(xs) − 1 with the half-width of mean(xs) carried over (first order)."""
    m, h = _ci(xs)
    return f"{100 * (num / m - 1.0):+.1f} ± {100 * num * h / m**2:.1f} %"


def _paired(a: np.ndarray, b: np.ndarray) -> str:
    m, h = _ci(np.asarray(a) / np.asarray(b) - 1.0)
    return f"{100 * m:+.1f} ± {100 * h:.1f} %"


def _share_above(x: np.ndarray, dt: float, omega: float) -> float:
    w, s = periodic_density(x, dt)
    return float(s[w > omega].sum() / s.sum())


#: frequency bands [rad/s] of the spectral check above the band: the linear band, the
#: geometric residual's second order (up to 2·ω_max), the drag's third (3·ω_max), the
#: drag's fifth order (5·ω_max: not in the FD) and above
BANDS = ((0.0, 2.0), (2.0, 4.0), (4.0, 6.0), (6.0, 10.0), (10.0, math.inf))
CHECK_LINES = ("chain", "deep")  # the lines of the spectral check's table


def band_shares(omega: np.ndarray, density: np.ndarray) -> np.ndarray:
    """The shares of the variance in each of :data:`BANDS` (trapezoid on a grid; a
    periodogram's lines, equally spaced, sum to the same). [-]"""
    w, s = np.asarray(omega, float), np.asarray(density, float)
    q = np.zeros_like(w)
    q[1:] += 0.5 * np.diff(w)
    q[:-1] += 0.5 * np.diff(w)
    v = q * s
    # (a node on a band's top edge, up to round-off, counts in that band with its whole
    # trapezoid weight: the split is exact to half a cell)
    tops = [hi + 1e-9 for _, hi in BANDS]
    return np.array([v[(w <= top) & (w > low)].sum()
                     for low, top in zip([-math.inf, *tops[:-1]], tops)]) / v.sum()  # fmt: skip


def _record_shares(recs: list[np.ndarray], dt: float) -> np.ndarray:
    return np.mean([band_shares(*periodic_density(x, dt)) for x in recs], axis=0)


def analyse_end(item: dict, rng: np.random.Generator) -> dict:
    """Every fatigue and non-Gaussian statistic of one line end (see :func:`sections`)."""
    curve = fatigue_curve(item["curve"])
    k = _factor(curve)
    m = curve.slopes[0]
    recs, dt = item["records"], item["dt"]
    rates = damage_rates(recs, dt, tuple(item["default"]), curve, k)
    lin = float(damage_rate_dirlik(item["linear"][0], item["linear"][1] * k * k, curve))
    flife = dirlik_flife(item["default"][0], item["default"][1] * k * k, curve)
    mom = [moments_of_record(x) for x in recs]
    skew = float(np.mean([d["skewness"] for d in mom]))
    kurt = float(np.mean([d["kurtosis"] for d in mom]))
    w_top = float(np.max(item["default"][0]))
    gauss_rain, gauss_low, above = [], [], []
    gauss_max, td_max, sur_skew, sur_kurt = [], [], [], []
    for x, d in zip(recs, mom):
        sur = phase_randomized(x, rng, SURROGATES)
        sur_skew.append(float(np.mean(stats.skew(sur, axis=1))))
        sur_kurt.append(float(np.mean(stats.kurtosis(sur, axis=1, fisher=False))))
        gauss_rain.append(
            np.mean([damage_rainflow(y * k, curve, duration=y.size * dt) for y in sur])
        )
        low = low_passed(sur, dt, w_top)
        gauss_low.append(
            np.mean([damage_rainflow(y * k, curve, duration=y.size * dt) for y in low])
        )
        above.append(_share_above(x, dt, w_top))
        gauss_max.append(float(np.mean((sur.max(axis=1) - d["mean"]) / d["std"])))
        td_max.append((float(x.max()) - d["mean"]) / d["std"])
    # a DSA record's own moments are not a Gaussian's (deterministic amplitudes: a few
    # dominant lines give a kurtosis below 3); the surrogates have the same bias, so
    # the non-Gaussian moments are the records' in excess of the surrogates'
    g_skew, g_kurt = float(np.mean(sur_skew)), float(np.mean(sur_kurt))
    h3, h4, kappa = hermite_coefficients(skew - g_skew, 3.0 + kurt - g_kurt)
    # the TD's spectrum (the seeds' mean) for the Hermite factor of its damage
    dens = [periodic_density(x, dt) for x in recs]
    keep = dens[0][0] <= float(np.max(item["default"][0]))  # as damage_rates
    w_td, s_td = dens[0][0][keep], np.mean([d[1][keep] for d in dens], axis=0)
    factor = hermite_damage_factor(w_td, s_td, m, h4, kappa)
    u = np.array(gauss_max)
    herm_max = hermite_level(u, h3, h4, kappa)
    m0, m2 = np.trapezoid(s_td, w_td), np.trapezoid(w_td**2 * s_td, w_td)
    u3h = gaussian_expected_maximum(2.0 * math.pi * math.sqrt(m0 / m2), 10800.0)
    w0, s0 = item["default"]
    sigma_fd = math.sqrt(float(np.trapezoid(s0, w0)))
    return {
        "curve": curve,
        "rates": rates,
        "linear": lin,
        "flife": flife,
        "skewness": skew,
        "kurtosis": kurt,
        "g_skewness": g_skew,
        "g_kurtosis": g_kurt,
        "h3": h3,
        "h4": h4,
        "factor": factor,
        "gauss_rain": np.array(gauss_rain),
        "gauss_low": np.array(gauss_low),
        "above": float(np.mean(above)),
        "above_md": (
            float(np.mean([_share_above(x, dt, w_top) for x in item["md_records"]]))
            if item.get("md_records")
            else None
        ),
        "w_top": w_top,
        "above_80": (
            float(np.mean([_share_above(x, dt, w_top) for x in item["td80_records"]]))
            if item.get("td80_records") and item.get("elements", 80) != 80
            else None
        ),
        "bands": {
            "FD default (corrected)": band_shares(*item["default"]),
            "FD linear": band_shares(*item["linear"]),
            f"reference TD, {item.get('elements', 80)} elements": _record_shares(recs, dt),
            **(
                {"reference TD, 80 elements": _record_shares(item["td80_records"], dt)}
                if item.get("td80_records") and item.get("elements", 80) != 80
                else {}
            ),
            **(
                {"MoorDyn, 80 segments": _record_shares(item["md_records"], dt)}
                if item.get("md_records")
                else {}
            ),
        },
        "gauss_max": u,
        "td_max": np.array(td_max),
        "herm_max": herm_max,
        "u3h": u3h,
        "herm_3h": float(hermite_level(u3h, h3, h4, kappa)),
        "sigma_ratio": sigma_fd / math.sqrt(m0),
        "sigma_fd": sigma_fd,
        "var_td": float(np.mean([d["std"] ** 2 for d in mom])),
        "std": float(np.mean([d["std"] for d in mom])),
        "mean": float(np.mean([d["mean"] for d in mom])),
    }


def sections(items: list[dict], seed: int = 31) -> list[str]:
    """The page's fatigue and non-Gaussian sections.

    Parameters
    ----------
    items : list of dict
        Per line end: ``line``, ``end`` (names), ``records`` (the reference TD's
        support-reaction records, one period per seed) [N], ``dt`` [s], ``default`` and
        ``linear`` ((omega [rad/s], density [N²·s/rad]) of the FD's end tension:
        corrected and linear), ``curve`` (a catalogue curve name), optionally
        ``md_records`` (MoorDyn's records of the same seeds) [N].
    seed : int
        Seed of the Gaussian surrogates' phases.
    """
    rng = np.random.default_rng(seed)
    res = [(it, analyse_end(it, rng)) for it in items]
    curves = sorted({(r["curve"].name, r["curve"].slopes[0]) for _, r in res})
    out = [
        "## Fatigue damage: spectral (Dirlik) against rainflow",
        "",
        "Damage rate of the end tension (support reaction) by Dirlik's method "
        "(`stochcable.design.damage_rate_dirlik`) on the FD's end-tension density — the "
        "default's corrected one (`LineResult.end_tension_density`, i.e. "
        "`corrected_spectra`) and the linear one — against the Palmgren–Miner sum of "
        "the rainflow-counted ranges (`stochcable.design.damage_rainflow`, fatpack's "
        "four-point count, each record one period of the periodic DSA, residue closed) "
        "of the reference TD's records of the same 5 seeds (one measured period of "
        "200 s each).  Curves (DNV-OS-E301, `stochcable.design.fatigue_curve`): "
        + ", ".join(f"`{n}` (m = {m:g})" for n, m in curves)
        + " — the studless-chain curve at the chain ends, the stranded-rope curve at the "
        "wire's and the synthetic rope's (the catalogue has no fibre-rope curve).  One "
        "slope: the ratios do not depend on the nominal area.  ± is the 95 % half-width "
        "of the TD's mean damage over the seeds (carried over to the ratio).  Last "
        "column: the library's Dirlik against FLife's (an independent implementation) on "
        "the same density.  Target "
        f"(issue 31): within {100 * TARGET:.0f} %.",
        "",
        "| line | end | curve | FD default Dirlik / TD rainflow − 1 | target met "
        "| FD linear Dirlik / TD rainflow − 1 | FD default Dirlik × Winterstein factor "
        "/ TD rainflow − 1 | check: stochcable's Dirlik / FLife's − 1 |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for it, r in res:
        rain = r["rates"]["rainflow"]
        d0 = r["rates"]["dirlik"]
        ok = "yes" if abs(round(d0 / rain.mean() - 1.0, 3)) <= TARGET else "**no**"
        out.append(
            f"| {it['line']} | {it['end']} | `{r['curve'].name}` | {_vs_mean(d0, rain)} "
            f"| {ok} | {_vs_mean(r['linear'], rain)} | {_vs_mean(d0 * r['factor'], rain)} "
            f"| {d0 / r['flife'] - 1.0:+.1e} |"
        )
    out += [
        "",
        "The FD default's error split into four factors (they multiply to the first "
        "column above; each a contribution to FD/TD − 1, paired per seed): the "
        "**spectrum** (Dirlik on the FD default's density over Dirlik on the TD's own "
        "spectrum — the records' periodograms, exact lines of a periodic record — up to "
        "the top ω_top of the FD's corrected density, 3× the band; with the part σ^m of "
        "it that the σ error alone gives); **Dirlik's method** (Dirlik on that TD "
        "spectrum over the rainflow damage of Gaussian surrogates of the records — their "
        f"Fourier amplitudes with random phases, {SURROGATES} per seed — low-passed at "
        "ω_top); the TD's content **above ω_top** (the surrogates low-passed over the "
        "full ones: a small variance, but it rides on the large cycles and lengthens "
        "their ranges); the **Gaussian assumption** (the full surrogates' rainflow "
        "damage over the TD records': the same spectrum line by line, the records' phase "
        "coupling — their non-Gaussian part — removed).  Winterstein's prediction of the "
        "last: 1/factor − 1 of the Hermite model with the records' excess moments "
        "(next section).",
        "",
        "| line | end | spectrum | … of which σ^m | Dirlik's method | TD above ω_top "
        "(its share of the variance; the 80-element TD's; MoorDyn's) | Gaussian "
        "assumption, measured | Gaussian assumption, Winterstein's prediction |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for it, r in res:
        rt = r["rates"]
        sig_m = r["sigma_ratio"] ** r["curve"].slopes[0] - 1.0
        n = rt["dirlik_td"].size
        out.append(
            f"| {it['line']} | {it['end']} "
            f"| {_paired(np.full(n, rt['dirlik']), rt['dirlik_td'])} | {100 * sig_m:+.1f} % "
            f"| {_paired(rt['dirlik_td'], r['gauss_low'])} "
            f"| {_paired(r['gauss_low'], r['gauss_rain'])} ({100 * r['above']:.2f} %; "
            + (f"{100 * r['above_80']:.2f} %; " if r["above_80"] is not None else "–; ")
            + (f"{100 * r['above_md']:.2f} %" if r["above_md"] is not None else "–")
            + ") "
            f"| {_paired(r['gauss_rain'], rt['rainflow'])} "
            f"| {100 * (1.0 / r['factor'] - 1):+.1f} % |"
        )
    out += [
        "",
        "### The spectrum above the band: FD against the time domains",
        "",
        "Where the end tension's variance lies, by band (share of σ², %; the TD's and "
        "MoorDyn's from the records' periodograms, mean over the seeds).  The fairlead "
        "motion stops at ω_max = 2 rad/s; the FD's corrected density carries the "
        "residuals' lines up to the support of their convolutions, 3·ω_max (the drag "
        "residual's third order; the geometric residual's second order reaches 2·ω_max); "
        "the drag's higher orders are evaluated lumped into its second and third "
        "(`stochcable.dynamics.residuals.drag_residual.LUMPED_ORDER`): their variance is "
        "in it, on those orders' lines, but nothing above 3·ω_max is; nor are the "
        "seabed's impacts.",
        "",
        "| line | end | source | "
        + " | ".join(
            f"{lo:g}–{hi:g} rad/s" if math.isfinite(hi) else f"> {lo:g} rad/s" for lo, hi in BANDS
        )
        + " |",
        "|---|---|---|" + "---|" * len(BANDS),
    ]
    for it, r in res:
        if it["line"] not in CHECK_LINES:
            continue
        for name, sh in r["bands"].items():
            out.append(
                f"| {it['line']} | {it['end']} | {name} | "
                + " | ".join(f"{100 * v:.3f}" for v in sh)
                + " |"
            )
    above = []
    for it, r in res:
        if it["line"] not in CHECK_LINES:
            continue
        fd = r["bands"]["FD default (corrected)"][1:].sum() * r["sigma_fd"] ** 2
        td = r["bands"][f"reference TD, {it.get('elements', 80)} elements"][1:3].sum()
        above.append(f"{it['line']} {it['end']} {fd / (td * r['var_td']):.2f}")
    out += [
        "",
        "Above ω_max the FD's corrected density holds this multiple of the TD's variance "
        "in 2–6 rad/s (FD σ² × its share over the TD records' mean σ² × theirs): "
        + ", ".join(above)
        + ".  The residuals' superharmonic lines carry more than the time domain has "
        "there, while σ agrees: the residual's split between the band and its "
        "superharmonics, not the corrected spectrum's support, is where the FD and the "
        "TD differ.",
        "",
        "## Non-Gaussian tension: how it enters extremes and fatigue",
        "",
        "The FD's corrected σ carries the variance of the nonlinear terms (the drag "
        "residual, the second-order geometric forces), but its extremes (Rayleigh maxima, "
        "MPM) and its spectral fatigue (Dirlik) treat the corrected tension as a "
        "**Gaussian** process with that spectrum: the non-Gaussian part — the skewness "
        "and kurtosis the quadratic drag, the geometric nonlinearity and the one-sided "
        "seabed give the tension — is not in them.  Its size, measured on the TD's "
        "records (mean over the 5 seeds; a Gaussian process has skewness 0 and kurtosis "
        "3, but one period of a DSA realization, its amplitudes deterministic, has a "
        "kurtosis below 3: the Gaussian surrogates show that baseline, and the "
        "non-Gaussian moments are the records' in excess of it, α3 − α3,s and "
        "3 + α4 − α4,s), and what Winterstein's (1988) Hermite model with those two "
        "moments predicts "
        "(`stochcable.design.hermite_model_winterstein` and `hermite_level`: "
        "x = κ[u + h3(u² − 1) + h4(u³ − 3u)], "
        "h3 = α3/6, h4 = (α4 − 3)/24; fatigue: each Gaussian rainflow cycle of Dirlik's "
        "amplitude density mapped through the model; maximum: the Gaussian surrogates' "
        "maximum u mapped through it):",
        "",
        "| line | end | skewness α3, TD / surrogates | kurtosis α4, TD / surrogates | h3 "
        "| h4 | largest maximum over 200 s, "
        "TD [σ above the mean] | the same, Gaussian surrogates [σ] | non-Gaussian effect "
        "on the dynamic maximum (measured) | Winterstein's prediction | on the total "
        "maximum (mean + dynamic), measured | Winterstein at the 3-h level (Gaussian "
        "expected maximum u₃ₕ [σ]: effect on the dynamic part) |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for it, r in res:
        td, g, hm = r["td_max"], r["gauss_max"], r["herm_max"]
        total = (r["mean"] + td * r["std"]) / (r["mean"] + g * r["std"]) - 1.0
        m_t, h_t = _ci(total)
        out.append(
            f"| {it['line']} | {it['end']} | {r['skewness']:+.3f} / {r['g_skewness']:+.3f} "
            f"| {r['kurtosis']:.3f} / {r['g_kurtosis']:.3f} "
            f"| {r['h3']:+.4f} | {r['h4']:+.4f} | {_ci(td)[0]:.2f} ± {_ci(td)[1]:.2f} "
            f"| {g.mean():.2f} | {_paired(td, g)} | {100 * (hm.mean() / g.mean() - 1):+.1f} % "
            f"| {100 * m_t:+.2f} ± {100 * h_t:.2f} % "
            f"| {r['u3h']:.2f}: {100 * (r['herm_3h'] / r['u3h'] - 1):+.1f} % |"
        )
    return out + [""] + _reading(res)


def _pct_range(values: list[float]) -> str:
    return f"{100 * min(values):+.1f} … {100 * max(values):+.1f} %"


def _reading(res: list[tuple[dict, dict]]) -> list[str]:
    """The conclusions of the two sections, their numbers read from the results."""
    gap = {(it["line"], it["end"]): r["rates"]["dirlik"] / r["rates"]["rainflow"].mean() - 1.0
           for it, r in res}  # fmt: skip
    lin = [r["linear"] / r["rates"]["rainflow"].mean() - 1.0 for _, r in res]
    miss = {k: v for k, v in gap.items() if abs(v) > TARGET}
    wint = {(it["line"], it["end"]): 1.0 / r["factor"] - 1.0 for it, r in res}
    meas = [float(np.mean(r["gauss_rain"] / r["rates"]["rainflow"]) - 1.0) for _, r in res]
    hw = [_ci(r["gauss_rain"] / r["rates"]["rainflow"])[1] for _, r in res]
    with_h = {(it["line"], it["end"]): r["rates"]["dirlik"] * r["factor"]
              / r["rates"]["rainflow"].mean() - 1.0 for it, r in res}  # fmt: skip
    sig_m = [r["sigma_ratio"] ** r["curve"].slopes[0] - 1.0 for _, r in res]
    band = [float(np.mean(r["gauss_low"] / r["gauss_rain"]) - 1.0) for _, r in res]
    ext = [r["herm_3h"] / r["u3h"] - 1.0 for _, r in res]
    peak_ci = [_ci(r["td_max"] / r["gauss_max"] - 1.0) for _, r in res]
    peak = [m for m, _ in peak_ci]
    out = [
        "### Reading",
        "",
        f"- **Fatigue, FD default against the TD's rainflow**: within {100 * TARGET:.0f} % "
        f"on {len(gap) - len(miss)} of {len(gap)} ends (mean over the seeds: "
        f"{_pct_range(list(gap.values()))}; the linear model {_pct_range(lin)})"
        + (
            "; outside: "
            + ", ".join(f"{ln} {e} {100 * v:+.1f} %" for (ln, e), v in miss.items())
            + " (see the CI: 5 records of 200 s)."
            if miss
            else "."
        ),
        f"- **What the FD's damage misses**, by factor: the σ error raised to the S–N "
        f"slope ({_pct_range(sig_m)}: a 1 % σ error is 3–4 % of damage), the TD's "
        f"content above the FD's top frequency ({_pct_range(band)}), Dirlik's method "
        "itself and the Gaussian assumption (next)."
        + "".join(
            f"  On {it['line']} {it['end']} that content is {100 * r['above_80']:.2f} % of "
            f"the variance at 80 elements (MoorDyn's 80 segments: "
            f"{100 * (r['above_md'] or math.nan):.2f} %) and {100 * r['above']:.3f} % at "
            f"the yardstick's {it['elements']}: a mesh artefact of the 80-element line "
            "in both simulators, not in the converged TD."
            for it, r in res
            if r["above_80"] is not None and r["above_80"] > 3.0 * r["above"]
        ),
        f"- **The non-Gaussian part**: the records' excess skewness and kurtosis are small "
        f"(|h3|, |h4| ≤ {max(max(abs(r['h3']), abs(r['h4'])) for _, r in res):.3f}); the "
        f"Gaussian assumption's measured effect on the damage is {_pct_range(meas)} with "
        f"half-widths of {100 * min(hw):.0f}–{100 * max(hw):.0f} % (one 200 s record per "
        "seed: rainflow damage is itself a noisy statistic), Winterstein's Hermite model "
        "with the measured moments "
        f"predicts {_pct_range(list(wint.values()))}.  On the largest 200 s maximum the "
        f"measured effect is {_pct_range(peak)}, "
        + (
            "inside the seeds' scatter on every end"
            if all(abs(m) <= h for m, h in peak_ci)
            else "outside the seeds' scatter on some ends"
        )
        + "; at the 3-h level the Hermite model moves the dynamic part of the expected "
        f"maximum by {_pct_range(ext)}.",
    ]
    if miss:
        out.append(
            "- **Would the Winterstein transform close the gap?**  Applied to the FD "
            "default's damage it gives "
            + ", ".join(f"{ln} {e} {100 * with_h[(ln, e)]:+.1f} %" for ln, e in miss)
            + " on the ends outside the target: "
            + (
                "it closes them."
                if all(abs(with_h[k]) <= TARGET for k in miss)
                else "it does not close them (the split above shows where their gap is)."
            )
        )
    return out + [""]
