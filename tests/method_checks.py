"""What the tests of the integration methods (test_methods.py,
test_methods_edges.py) share.
"""

from __future__ import annotations

import math
import signal
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

import vibroimpact as vi
from conftest import (
    APPROACH_SPEED,
    CLEARANCE,
    CONTACT_DAMPING,
    DAMPING,
    HERTZ_STIFFNESS,
    IMPACT_MASS,
    MAIN_MASS,
    STIFFNESS,
)


@contextmanager
def time_limit(seconds: int) -> Iterator[None]:
    """Raise TimeoutError if the block runs longer (the kernel polls signals)."""

    def expire(_signum: int, _frame: object) -> None:
        raise TimeoutError(f"still running after {seconds} s")

    previous = signal.signal(signal.SIGALRM, expire)
    signal.alarm(seconds)
    try:
        yield
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, previous)


def exact_hysteresis(e: float) -> float:
    """alpha with alpha (1 + e) = ln((1 + alpha) / (1 - alpha e)), 0 for e = 1."""
    if e == 1.0:
        return 0.0
    return float(
        brentq(
            lambda a: a * (1 + e) - (math.log1p(a) - math.log1p(-a * e)),
            1e-6,
            (1 - 1e-12) / e,
            xtol=1e-15,
        )
    )


# A damped main oscillator; the impact mass rests in the middle of a 1 m clearance
# and is never reached (|y - w| <= 0.01 m).
SMOOTH_M, SMOOTH_K, SMOOTH_C, SMOOTH_W0 = 1.0, 4.0, 0.2, 0.01


SMOOTH_SYSTEM = vi.ImpactDamper(
    main_mass=SMOOTH_M, stiffness=SMOOTH_K, damping=SMOOTH_C, impact_mass=0.25, clearance=1.0
)


SMOOTH_CONTACT = vi.Contact("hertz", stiffness=HERTZ_STIFFNESS)
SMOOTH_START = vi.InitialState(main_displacement=SMOOTH_W0)


def table1_run(contact_damping: float = CONTACT_DAMPING, **settings: Any) -> vi.Solution:
    system = vi.ImpactDamper(
        main_mass=MAIN_MASS,
        stiffness=STIFFNESS,
        damping=DAMPING,
        impact_mass=IMPACT_MASS,
        clearance=CLEARANCE,
    )
    contact = vi.Contact("hertz", stiffness=HERTZ_STIFFNESS, damping=contact_damping)
    start = vi.InitialState(impact_displacement=CLEARANCE, impact_velocity=APPROACH_SPEED)
    return vi.simulate(system, contact, start, t_end=0.15, **settings)


@dataclass(frozen=True)
class Rattle:
    onsets: np.ndarray
    separations: np.ndarray
    # Relative normal speeds at each onset and at each separation, m/s.
    approach_speeds: np.ndarray
    rebound_speeds: np.ndarray


def mode_by_mode_oracle(
    system: vi.ImpactDamper,
    contact: vi.Contact,
    start: vi.InitialState,
    t_end: float,
    max_flight_step: float = np.inf,
    floored: bool = True,
) -> Rattle:
    """A run with a hertz-damped contact, mode by mode with SciPy's DOP853 (rtol 1e-13).

    Free flight until |y - w| = d (event), then the contact (hertz-damped force
    with the approach rate latched at onset, clamped at zero, plus c1) until the
    indentation returns to zero (event), and so on to the end. The latched rate is
    the approach, or where that is slower, the speed ``sqrt(2 a delta_s)`` the pressing
    ``a`` (m/s^2, the main mass's acceleration against the wall at onset) gives over
    the static indentation ``delta_s = (m_eff a / K_hz)^(2/3)``, as the law is
    documented (``vi.SystemContacts``): a slow landing is damped as one set down on
    the contact (``floored``; without it, the approach alone: fixed stepping's latch, as
    the paper's). SciPy sees an event
    only as a sign change between its steps: flights shorter than its step need
    `max_flight_step` (s) below them.
    """
    assert contact.law == "hertz-damped" and contact.restitution is not None
    alpha = exact_hysteresis(contact.restitution)
    k, c, m_main, m_imp, d = (
        system.stiffness,
        system.damping,
        system.main_mass,
        system.impact_mass,
        system.clearance,
    )
    k_hz, c1 = contact.stiffness, contact.damping
    options: dict[str, Any] = dict(method="DOP853", rtol=1e-13, atol=1e-16)
    t = 0.0
    state = np.array(
        [
            start.main_displacement,
            start.main_velocity,
            start.impact_displacement,
            start.impact_velocity,
        ]
    )
    onsets: list[float] = []
    separations: list[float] = []
    approaches: list[float] = []
    rebounds: list[float] = []
    while True:

        def free(_t: float, s: np.ndarray) -> list[float]:
            return [s[1], (-c * s[1] - k * s[0]) / m_main, s[3], 0.0]

        def upper(_t: float, s: np.ndarray) -> float:
            return (s[2] - s[0]) - d

        def lower(_t: float, s: np.ndarray) -> float:
            return -(s[2] - s[0]) - d

        for event in (upper, lower):
            event.terminal = True  # type: ignore[attr-defined]
            event.direction = 1  # type: ignore[attr-defined]
        sol = solve_ivp(
            free, (t, t_end), state, events=[upper, lower], max_step=max_flight_step, **options
        )
        if sol.status == 0:
            break
        hit = 0 if len(sol.t_events[0]) else 1
        side = 1.0 if hit == 0 else -1.0
        t, state = float(sol.t_events[hit][0]), sol.y_events[hit][0]
        approach = side * (state[3] - state[1])
        onsets.append(t)
        approaches.append(approach)
        pressing = max(side * (c * state[1] + k * state[0]) / m_main, 0.0)
        effective_mass = m_main * m_imp / (m_main + m_imp)
        resting = math.sqrt(2 * pressing * (effective_mass * pressing / k_hz) ** (2 / 3))
        resting = resting if floored else 0.0

        def contact(
            _t: float, s: np.ndarray, side: float = side, v0: float = max(approach, resting)
        ) -> list[float]:
            delta, rate = side * (s[2] - s[0]) - d, side * (s[3] - s[1])
            law = k_hz * max(delta, 0.0) ** 1.5 * (1 + alpha * rate / v0)
            push = side * (max(law, 0.0) + c1 * rate)
            return [s[1], (push - c * s[1] - k * s[0]) / m_main, s[3], -push / m_imp]

        def apart(_t: float, s: np.ndarray, side: float = side) -> float:
            return side * (s[2] - s[0]) - d

        apart.terminal = True  # type: ignore[attr-defined]
        apart.direction = -1  # type: ignore[attr-defined]
        sol = solve_ivp(contact, (t, t_end), state, events=apart, **options)
        if sol.status == 0:
            break
        t, state = float(sol.t_events[0][0]), sol.y_events[0][0]
        separations.append(t)
        rebounds.append(-side * (state[3] - state[1]))
    return Rattle(np.array(onsets), np.array(separations), np.array(approaches), np.array(rebounds))


ELASTIC_CONTACT = vi.Contact("hertz", stiffness=HERTZ_STIFFNESS)
