"""The forcing periods an analysis can run: an adaptive or exact run steps at least once
in each period of the structure's fastest mode, so a forcing period of more than
``max_steps`` of those is beyond it (a sweep from 1e-300 Hz had failed each point as a
numerical blow-up advising a smaller dt); a fixed-step run takes ``period / dt`` steps
whatever the modes (an implicit method is stable on a mode far faster than its step;
its two steps a period are checked with the run's own settings, by the core's
registry's ``check_run``). An adaptive or exact run judges
positions to ``atol``: a forcing that moves the structure by less than ``atol`` a period
is not resolved (a 5 Hz oscillator forced at 1e9 Hz had failed its energy balance), and a
body on no spring is resolved only while the round-off of the run's times stays below
the time its largest acceleration takes to move it by ``atol`` (a ball on a table at
1e-20 Hz had failed as 'step size too small', at 1e-300 Hz as a blow-up). Refused when
the analysis is set up, naming the frequency and the range a run can take. SI units.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

from vibroimpact._core import METHOD_OPTIONS, InvalidInputError
from vibroimpact.messages import shown
from vibroimpact.system import _FIXED_STEP, linear_parts

# The relative round-off of a run's times (float64).
_TIME_ROUND_OFF = float(np.finfo(float).eps)


def highest_frequency(mass: np.ndarray, stiffness: np.ndarray) -> float:
    """The highest natural frequency (Hz) of ``M x'' + K x = 0``; 0 where nothing is
    held by a spring (or where M is not positive definite: refused elsewhere)."""
    try:
        # M = L L^T: the eigenvalues of L^-1 K L^-T are w^2.
        lower = np.linalg.cholesky(mass)
        inverse = np.linalg.inv(lower)
        squares = np.linalg.eigvalsh(inverse @ stiffness @ inverse.T)
    except np.linalg.LinAlgError:
        return 0.0
    top = float(squares[-1])
    return math.sqrt(top) / (2 * math.pi) if math.isfinite(top) and top > 0 else 0.0


def _parts(data: Mapping[str, Any], base_dir: Path | None) -> dict[str, Any]:
    return linear_parts(
        data["structure"],
        damper=data.get("damper", ()),
        stop=data.get("stop", ()),
        gravity=data.get("gravity"),
        excitation=data.get("excitation", ()),
        base_dir=base_dir,
    )


def _accelerations(parts: Mapping[str, Any]) -> tuple[float, float]:
    """The largest acceleration amplitude (m/s^2) the harmonic loads give a coordinate
    (``M^-1`` times the load) and the largest the constant load (gravity) gives."""
    inverse = np.linalg.inv(parts["mass"])
    forcing = 0.0
    for load in parts["harmonics"]:
        if load["omega"] > 0:
            shape = np.asarray(load["shape"], dtype=float)
            forcing = max(forcing, abs(load["amplitude"]) * float(np.max(np.abs(inverse @ shape))))
    constant = np.asarray(parts["constant"], dtype=float)
    weight = float(np.max(np.abs(inverse @ constant))) if constant.size else 0.0
    return forcing, weight


def _refuse(period: float, reason: str, advice: str) -> InvalidInputError:
    return InvalidInputError(f"forcing frequency {shown(1 / period)} Hz: {reason}; {advice}")


def _check_fixed_step(period: float, dt: float, max_steps: int) -> None:
    if period / dt > max_steps:
        raise _refuse(
            period,
            f"its period, {period:.6g} s, takes {period / dt:.3g} steps of dt = {shown(dt)} s, "
            f"more than a run's max_steps ({max_steps})",
            f"set the [[excitation]] frequency to at least {1 / (max_steps * dt):.3g} Hz",
        )


def check_forcing_period(
    data: Mapping[str, Any], period: float, max_steps: int, base_dir: Path | None = None
) -> None:
    """Refuse a forcing ``period`` (s) no run can step through: for a fixed-step method,
    more than ``max_steps`` steps of ``dt`` (fewer than two are refused with the run's
    settings, before this); for an adaptive or exact one, more than ``max_steps`` periods
    of the system's fastest mode, a forcing moving the structure less than ``atol`` a
    period, or (a body on no spring) a period whose times' round-off exceeds the time its
    largest acceleration takes to move it by ``atol``."""
    solver = data.get("solver", {})
    if solver.get("method") in _FIXED_STEP:
        # Checked by the run's own settings: a fixed step is given.
        _check_fixed_step(period, float(solver["dt"]), max_steps)
        return
    parts = _parts(data, base_dir)
    highest = highest_frequency(parts["mass"], parts["stiffness"])
    atol = float(solver.get("atol", METHOD_OPTIONS["atol"]["default"]))
    forcing, weight = _accelerations(parts)
    largest = max(forcing, weight)
    # A free body: no mode sets its time scale, so the one the run must resolve is the
    # time its largest acceleration takes to move it by atol.
    resolved = math.sqrt(2 * atol / largest) if highest == 0 and largest > 0 else math.inf
    lowest = max(highest / max_steps, _TIME_ROUND_OFF / resolved)
    top = math.sqrt(forcing / atol) / (2 * math.pi) if forcing > 0 else math.inf
    works = (
        f"set the [[excitation]] frequency to at least {lowest:.3g} Hz"
        if top == math.inf
        else f"set the [[excitation]] frequency to at least {lowest:.3g} Hz and at most "
        f"{top:.3g} Hz"
    )
    if highest > 0 and period * highest > max_steps:
        raise _refuse(
            period,
            f"its period, {period:.6g} s, spans {period * highest:.3g} periods of the "
            f"system's fastest mode ({highest:.6g} Hz), more than a run's max_steps "
            f"({max_steps}) steps through",
            works,
        )
    if _TIME_ROUND_OFF * period > resolved:
        raise _refuse(
            period,
            f"a body on no spring: the round-off of the run's times, {_TIME_ROUND_OFF:.3g} "
            f"of the period {period:.3g} s, exceeds the {resolved:.3g} s its largest "
            f"acceleration ({largest:.3g} m/s^2) takes to move it by atol ({shown(atol)} m)",
            works,
        )
    omega = 2 * math.pi / period
    # Divided twice: omega^2 overflows beyond 1e154 Hz.
    moved = forcing / omega / omega
    if forcing > 0 and moved < atol:
        raise _refuse(
            period,
            f"the forcing ({forcing:.3g} m/s^2) moves the structure by {moved:.3g} m a "
            f"period, below the atol ({shown(atol)} m) a run resolves",
            works,
        )
