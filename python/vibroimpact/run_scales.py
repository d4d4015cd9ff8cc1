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
from collections.abc import Callable, Mapping, Sequence
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


def frequency_bound(mass: Sequence[float], stiffness: Sequence[float], dim: int) -> float:
    """An upper bound (Hz) of :func:`highest_frequency` without its eigenvalues, from M and
    K flat (row-major, ``dim`` x ``dim``): w^2 is at most the largest eigenvalue of K,
    itself at most K's largest absolute row sum, over the smallest of M, at least its
    smallest Gershgorin disc's lower end (infinite where that end is not above 0); 0 where
    K is zero. Plain Python: on a few coordinates NumPy's calls cost more than the sums."""
    rows = range(0, dim * dim, dim)
    top = max((sum(abs(v) for v in stiffness[r : r + dim]) for r in rows), default=0.0)
    if not top > 0:
        return 0.0
    lowest = min(
        2 * mass[r + i] - sum(abs(v) for v in mass[r : r + dim]) for i, r in enumerate(rows)
    )
    return math.sqrt(top / lowest) / (2 * math.pi) if lowest > 0 else math.inf


def _resolves(solver: Mapping[str, Any], frequency: float) -> bool:
    """Whether a run of ``solver`` resolves a fastest mode of ``frequency`` Hz."""
    method = solver["method"]
    if method in EXPLICIT_FIXED_STEP and frequency * solver["dt"] > 1:
        return False
    return not (method in MODE_STEPPED and solver["t_end"] * frequency > solver["max_steps"])


def check_natural_period(
    solver: Mapping[str, Any],
    matrices: Callable[[], tuple[list[float], list[float], int]],
    fail: Callable[[str, str], Exception],
) -> None:
    """Refuse a run whose ``solver`` (checked: method, t_end, dt, max_steps) cannot resolve
    the system's fastest mode, of ``matrices()`` (M and K flat, and their size; called
    only for the methods it binds; the eigenvalues only where :func:`frequency_bound` does
    not settle it: they had cost a dropped ball's run a quarter of its time)."""
    method = solver["method"]
    if method not in EXPLICIT_FIXED_STEP and method not in MODE_STEPPED:
        return
    mass, stiffness, dim = matrices()
    if _resolves(solver, frequency_bound(mass, stiffness, dim)):
        return
    shape = (dim, dim)
    frequency = highest_frequency(
        np.asarray(mass).reshape(shape), np.asarray(stiffness).reshape(shape)
    )
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


def _harmonic_frequencies(excitation: Any) -> list[tuple[int, float]]:
    """Each checked excitation's harmonic frequencies (Hz), with its index."""
    found: list[tuple[int, float]] = []
    for index, table in enumerate(excitation or ()):
        if table.get("signal") == "harmonic":
            found.append((index, float(table["frequency"])))
        elif table.get("signal") == "harmonics":
            found.extend((index, float(f)) for f in table["frequencies"])
    return found


def check_forcing_steps(
    solver: Mapping[str, Any],
    excitation: Any,
    fixed_step: bool,
    fail: Callable[[str, str], Exception],
) -> None:
    """Refuse a harmonic forcing the run's steps cannot follow: a fixed step samples it
    below two steps a period (its result aliased: rk4 at dt = 1e-3 s had reported 1e-4 J
    stored from a 1e9 Hz force whose true response holds 1e-40 J), and the exact flow
    steps at least once in each of its periods, so ``t_end`` spanning more than
    ``max_steps`` of them is beyond it (it had filled max_rows by t = 2.5e-3 s).
    ``fixed_step``: the method steps by ``dt`` (an adaptive method's is its first step)."""
    method = solver["method"]
    for index, frequency in _harmonic_frequencies(excitation):
        where = f"[[excitation]] {index}: "
        if fixed_step and frequency * 2 * solver["dt"] > 1:
            raise fail(
                where,
                f"frequency {shown(frequency)} Hz is sampled below two steps of dt = "
                f"{shown(solver['dt'])} s a period: give at most {1 / (2 * solver['dt']):.3g} "
                f"Hz, or reduce dt below {1 / (20 * frequency):.3g} s",
            )
        if method == "exact" and frequency * solver["t_end"] > solver["max_steps"]:
            raise fail(
                where,
                f"frequency {shown(frequency)} Hz: t_end = {shown(solver['t_end'])} s spans "
                f"{frequency * solver['t_end']:.3g} of its periods, and the exact flow steps "
                f"at least once in each: more than max_steps ({solver['max_steps']}); give at "
                f"most {solver['max_steps'] / solver['t_end']:.3g} Hz or shorten t_end",
            )
