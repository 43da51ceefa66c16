"""Spectrum arguments shared by ``stochcable spectrum`` and ``stochcable simulate``.

Periods [s] and frequencies in Hz are accepted here, at the edge, and converted to
angular frequency [rad/s] before anything reaches the core.
"""

from __future__ import annotations

import argparse
import math
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from stochcable import validation as v
from stochcable.errors import InputError
from stochcable.sea import spectra
from stochcable.sea.limits import (
    GAMMA_RANGE,
    HEIGHT_RANGE,
    M0_RANGE,
    OMEGA_P_RANGE,
    PERIOD_RANGE,
    SHAPE_RANGE,
    SIGMA_RANGE,
    WIND_SPEED_RANGE,
)

__all__ = ["SPECTRUM_TYPES", "add_spectrum_arguments", "SpectrumChoice", "spectrum_from_args"]

SPECTRUM_TYPES = ("pm", "jonswap", "bretschneider", "issc", "ochi-hubble", "table")


def add_spectrum_arguments(parser: argparse.ArgumentParser) -> None:
    """Add the spectrum type and its parameters to ``parser``."""
    parser.add_argument(
        "type",
        choices=SPECTRUM_TYPES,
        help="spectrum: pm (Pierson-Moskowitz), jonswap, bretschneider, "
        "issc (ITTC, Hs and T1), ochi-hubble (two peaks), table (CSV)",
    )
    grp = parser.add_argument_group("spectrum parameters (SI; periods in s, --fp in Hz)")
    grp.add_argument("--hs", type=float, help="significant wave height 4*sqrt(m0) [m]")
    grp.add_argument("--tp", type=float, help="peak period [s]")
    grp.add_argument("--fp", type=float, help="peak frequency [Hz] (instead of --tp)")
    grp.add_argument(
        "--omega-p", type=float, help="peak angular frequency [rad/s] (instead of --tp)"
    )
    grp.add_argument(
        "--m0", type=float, help="pm: zeroth moment m0 = Hs^2/16 [m^2] (instead of --hs)"
    )
    grp.add_argument(
        "--wind-speed", type=float, help="pm: wind speed at 19.5 m [m/s] (instead of --hs/--tp)"
    )
    grp.add_argument(
        "--g",
        type=float,
        default=spectra.G_STANDARD,
        help="gravity for --wind-speed [m/s^2] (default 9.80665)",
    )
    grp.add_argument(
        "--gamma",
        type=float,
        default=3.3,
        help=f"jonswap: peak enhancement in [{GAMMA_RANGE[0]:g}, {GAMMA_RANGE[1]:g}] [-] "
        "(default 3.3)",
    )
    for side, where, default in (("a", "below", 0.07), ("b", "above", 0.09)):
        grp.add_argument(
            f"--sigma-{side}",
            type=float,
            default=default,
            help=f"jonswap: width {where} peak in [{SIGMA_RANGE[0]:g}, {SIGMA_RANGE[1]:g}] "
            f"[-] (default {default})",
        )
    grp.add_argument("--t1", type=float, help="issc: mean period T1 = Tm01 [s]")
    for j, what in ((1, "swell (low-frequency)"), (2, "wind sea (high-frequency)")):
        grp.add_argument(f"--hs{j}", type=float, help=f"ochi-hubble: {what} Hs [m]")
        grp.add_argument(f"--tp{j}", type=float, help=f"ochi-hubble: {what} peak period [s]")
        grp.add_argument(f"--lambda{j}", type=float, help=f"ochi-hubble: {what} shape [-]")
    grp.add_argument(
        "--table",
        metavar="CSV",
        help="table: CSV file with columns omega [rad/s], density [m^2 s/rad] "
        "(optional header line)",
    )


@dataclass(frozen=True)
class SpectrumChoice:
    """A spectrum chosen on the command line."""

    name: str
    density: Callable[[np.ndarray], np.ndarray]
    m0: float
    parameters: dict[str, Any] = field(default_factory=dict)


def _need(args: argparse.Namespace, attr: str, flag: str, kind: str) -> Any:
    value = getattr(args, attr)
    if value is None:
        raise InputError(flag, None, "-", f"is required for the {kind} spectrum")
    return value


def _height(args: argparse.Namespace, attr: str, kind: str, zero: bool = False) -> float:
    """``--<attr>``, a significant wave height in ``HEIGHT_RANGE`` (or 0 with ``zero``). [m]"""
    flag = f"--{attr}"
    hs = _need(args, attr, flag, kind)
    return 0.0 if zero and hs == 0.0 else v.in_range(flag, hs, "m", *HEIGHT_RANGE)


def _peak_omega(args: argparse.Namespace, kind: str, required: bool = True) -> float | None:
    given = [
        (f, x)
        for f, x in (("--tp", args.tp), ("--fp", args.fp), ("--omega-p", args.omega_p))
        if x is not None
    ]
    if len(given) > 1:
        raise InputError(
            given[1][0],
            given[1][1],
            "-",
            f"give only one of --tp, --fp, --omega-p (also got {given[0][0]})",
        )
    if not given:
        if required:
            raise InputError(
                "--tp", None, "s", f"is required for the {kind} spectrum (or --fp / --omega-p)"
            )
        return None
    flag, x = given[0]
    if flag == "--tp":
        return 2.0 * math.pi / v.in_range("--tp", x, "s", *PERIOD_RANGE)
    if flag == "--fp":
        return 2.0 * math.pi * v.in_range("--fp", x, "Hz", *(1.0 / t for t in PERIOD_RANGE[::-1]))
    return v.in_range("--omega-p", x, "rad/s", *OMEGA_P_RANGE)


def _read_table(path: str) -> tuple[np.ndarray, np.ndarray]:
    try:
        lines = Path(path).read_text(encoding="utf-8").splitlines()
    except OSError as exc:
        raise InputError("--table", path, "-", f"cannot be read ({exc.strerror})") from None
    rows = []
    header_seen = False
    for i, line in enumerate(lines, start=1):
        line = line.strip()
        if not line or line.startswith("#"):
            continue
        parts = [p.strip() for p in line.split(",")]
        try:
            vals = [float(p) for p in parts]
        except ValueError:
            if not rows and not header_seen:
                header_seen = True
                continue  # header line
            raise InputError(
                "--table", path, "-", f"line {i} is not two numbers: {line!r}"
            ) from None
        if len(vals) != 2:
            raise InputError("--table", path, "-", f"line {i} must have 2 columns (omega,density)")
        rows.append(vals)
    if len(rows) < 2:
        raise InputError("--table", path, "-", "needs at least 2 rows of omega,density")
    arr = np.array(rows)
    wt = v.float_array("--table omega", arr[:, 0], "rad/s", nonnegative=True, increasing=True)
    st = v.float_array("--table density", arr[:, 1], "m²·s/rad", nonnegative=True)
    return wt, st


def spectrum_from_args(args: argparse.Namespace) -> SpectrumChoice:
    """Validate the spectrum flags (naming the flag on error) and build the spectrum."""
    kind = args.type
    if kind in ("pm", "bretschneider"):
        if kind == "pm" and args.wind_speed is not None:
            u = v.in_range("--wind-speed", args.wind_speed, "m/s", *WIND_SPEED_RANGE)
            g = v.positive("--g", args.g, "m/s²")
            m0 = 0.0081 * u**4 / (4.0 * 0.74 * g * g)
            return SpectrumChoice(
                "pierson_moskowitz_wind",
                lambda w: spectra.spectrum_pierson_moskowitz_wind(w, u, g),
                m0,
                {"wind_speed": u, "g": g},
            )
        wp = _peak_omega(args, kind)
        if kind == "pm" and args.m0 is not None:
            if args.hs is not None:
                raise InputError("--m0", args.m0, "m²", "give either --hs or --m0, not both")
            m0 = v.in_range("--m0", args.m0, "m²", *M0_RANGE)
        else:
            m0 = _height(args, "hs", kind) ** 2 / 16.0
        name = "pierson_moskowitz" if kind == "pm" else "bretschneider"
        return SpectrumChoice(
            name,
            lambda w: spectra.spectrum_pierson_moskowitz_m0(w, m0, wp),
            m0,
            {"m0": m0, "hs": 4.0 * math.sqrt(m0), "omega_p": wp, "tp": 2.0 * math.pi / wp},
        )
    if kind == "jonswap":
        hs = _height(args, "hs", kind)
        wp = _peak_omega(args, kind)
        tp = args.tp if args.tp is not None else 2.0 * math.pi / wp  # --tp kept exactly
        gamma = v.in_range("--gamma", args.gamma, "-", *GAMMA_RANGE)
        sa = v.in_range("--sigma-a", args.sigma_a, "-", *SIGMA_RANGE)
        sb = v.in_range("--sigma-b", args.sigma_b, "-", *SIGMA_RANGE)
        return SpectrumChoice(
            "jonswap",
            lambda w: spectra.spectrum_jonswap(w, hs, tp, gamma, sa, sb),
            hs * hs / 16.0,
            {"hs": hs, "tp": tp, "gamma": gamma, "sigma_a": sa, "sigma_b": sb},
        )
    if kind == "issc":
        hs = _height(args, "hs", kind)
        t1 = v.in_range("--t1", _need(args, "t1", "--t1", kind), "s", *PERIOD_RANGE)
        return SpectrumChoice(
            "issc", lambda w: spectra.spectrum_issc(w, hs, t1), hs * hs / 16.0, {"hs": hs, "t1": t1}
        )
    if kind == "ochi-hubble":
        p = {}
        for j in (1, 2):
            p[f"hs{j}"] = _height(args, f"hs{j}", kind, zero=True)
            tp = _need(args, f"tp{j}", f"--tp{j}", kind)
            p[f"tp{j}"] = v.in_range(f"--tp{j}", tp, "s", *PERIOD_RANGE)
            lam = _need(args, f"lambda{j}", f"--lambda{j}", kind)
            p[f"lambda{j}"] = v.in_range(f"--lambda{j}", lam, "-", *SHAPE_RANGE)
        if p["hs1"] == 0.0 and p["hs2"] == 0.0:
            raise InputError("--hs1", 0.0, "m", "--hs1 and --hs2 must not both be 0")
        return SpectrumChoice(
            "ochi_hubble",
            lambda w: spectra.spectrum_ochi_hubble(w, **p),
            (p["hs1"] ** 2 + p["hs2"] ** 2) / 16.0,
            p,
        )
    # table
    path = _need(args, "table", "--table", kind)
    wt, st = _read_table(path)
    m0 = float(np.trapezoid(st, wt))
    if m0 <= 0.0:
        raise InputError("--table", path, "-", "density is zero everywhere")
    return SpectrumChoice(
        "table",
        lambda w: spectra.spectrum_table(w, wt, st),
        m0,
        {"file": str(path), "rows": int(wt.size)},
    )
