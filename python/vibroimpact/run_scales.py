"""The time scales a run must resolve, checked before it starts (SI units): the
fastest natural mode of the system between contacts against the run's step. A fixed-step
explicit method (rk4) is unstable on a mode whose period is shorter than its step; an
adaptive method or the exact flow steps at least once in each period of that mode, so a
run through more than ``max_steps`` of them stops at ``max_steps`` (a mass of 1e-300 kg
had blown up advising a smaller dt; a stiffness of 1e308 N/m filled the rows limit). Kept apart from
``system.py``, which calls it, so that the one rule serves runs and analyses.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from typing import Any

import numpy as np

from vibroimpact.messages import shown

# The fixed-step methods that are explicit: stable only where the step is a fraction of
# the fastest mode's period (the implicit ones are stable on any mode).
EXPLICIT_FIXED_STEP = ("rk4",)
# The methods that step at least once in each period of the fastest mode: the adaptive
# ones and the exact flow (a stiffness of 1e308 had kept 20 million history rows, 500 MB,
# by t = 1.6e-147 s).
MODE_STEPPED = ("dopri5", "dop853", "exact")


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


def check_natural_period(
    solver: Mapping[str, Any],
    highest: Callable[[], float],
    fail: Callable[[str, str], Exception],
) -> None:
    """Refuse a run whose ``solver`` (checked: method, t_end, dt, max_steps) cannot resolve
    the system's fastest mode, ``highest()`` Hz (called only for the methods it binds)."""
    method = solver["method"]
    if method not in EXPLICIT_FIXED_STEP and method not in MODE_STEPPED:
        return
    frequency = highest()
    if not frequency > 0:
        return
    period = 1 / frequency
    if method in EXPLICIT_FIXED_STEP and period < solver["dt"]:
        raise fail(
            "[solver] dt: ",
            f"the fastest mode's period, {period:.3g} s ({frequency:.3g} Hz), is below "
            f"dt = {shown(solver['dt'])} s, where {method} is unstable: reduce dt below "
            f"{period / 4:.3g} s, use an implicit method (newmark-implicit, "
            "generalized-alpha), or check mass and stiffness",
        )
    steps = solver["t_end"] * frequency
    if method in MODE_STEPPED and steps > solver["max_steps"]:
        raise fail(
            "[solver] ",
            f"t_end = {shown(solver['t_end'])} s spans {steps:.3g} periods of the fastest "
            f"mode ({frequency:.3g} Hz), and {method} steps at least once in each: more "
            f"than max_steps ({solver['max_steps']}); shorten t_end below "
            f"{solver['max_steps'] / frequency:.3g} s, raise max_steps, or check mass and "
            "stiffness",
        )
