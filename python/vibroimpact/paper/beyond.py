"""Beyond the paper: every method on the Table 1 collision, error against cost.

Each of vibroimpact's methods runs the founding paper's Table 1 collision at
several step sizes or tolerances; the error of its contact duration against
the model's exact one is set against the CPU time (median of repeated runs).
scipy's ``solve_ivp`` (RK45, DOP853, LSODA, with a separation event) runs the
same collision for comparison; scipy is a dependency, and should it be missing
anyway the comparison is left out with a note saying so.
"""

from __future__ import annotations

import math
import statistics
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from vibroimpact._core import Contact, ImpactDamper, InitialState, Solution, simulate
from vibroimpact.paper.data import PAPER_METHOD_LIMITS
from vibroimpact.scenario.two_mass import paper_collision

# Table 1 of the paper, at the onset of a 0.1 m/s collision (SI units).
MAIN_MASS, STIFFNESS, DAMPING = 1.0, 1.0, 0.01
IMPACT_MASS, CLEARANCE = 0.25, 0.01
HERTZ_STIFFNESS, CONTACT_DAMPING, APPROACH_SPEED = 3000.0, 0.01, 0.1
# Long enough for the contact (about 0.109 s) to end, short of the next one.
STUDY_TIME = 0.11

STEP_SIZES = (4e-3, 3e-3, 2.5e-3, 2.2e-3, 2e-3, 1e-3, 5e-4, 2e-4, 1e-4)
TOLERANCES = (1e-4, 1e-6, 1e-8, 1e-9, 1e-10, 1e-11, 1e-12)
# (label, method, stepping): the fixed-step runs.
FIXED_RUNS = (
    ("newmark (paper)", "newmark", "fixed"),
    ("rk4 (paper stepping)", "rk4", "fixed"),
    ("rk4 (events)", "rk4", "events"),
    ("newmark-implicit", "newmark-implicit", None),
    ("generalized-alpha", "generalized-alpha", None),
)
ADAPTIVE_RUNS = ("dopri5", "dop853")


@dataclass(frozen=True)
class StudyRun:
    """One run of the study: its contact duration, error and cost."""

    label: str
    setting: str
    dt: float | None
    rtol: float | None
    contact_duration: float
    error: float
    cpu_time: float
    rhs_evaluations: int


def table1(restitution: float | None = None) -> tuple[ImpactDamper, Contact, InitialState]:
    """The Table 1 system, its contact (Hertz, or Hyster-Hertz with ``restitution``), onset."""
    scenario = paper_collision(restitution)
    return scenario.system, scenario.contact, scenario.initial


def median_time(
    run: Callable[[], Any], min_repeats: int = 5, budget: float = 0.02
) -> tuple[Any, float]:
    """Run repeatedly after a warm-up; the last result and the median CPU time (s)."""
    result = run()
    times: list[float] = []
    while len(times) < min_repeats or (sum(times) < budget and len(times) < 1001):
        start = time.process_time()
        result = run()
        times.append(time.process_time() - start)
    return result, statistics.median(times)


def first_duration(sol: Solution) -> float:
    durations = sol.contacts.duration
    if len(durations) == 0 or not math.isfinite(durations[0]):
        raise RuntimeError("the collision did not end within the run")
    return float(durations[0])


def exact_duration(restitution: float | None = None) -> float:
    """The model's contact duration by DOP853 at rtol 1e-13 with located events."""
    system, contact, start = table1(restitution)
    sol = simulate(system, contact, start, method="dop853", rtol=1e-13, atol=1e-16, t_end=0.15)
    return first_duration(sol)


def ours(exact: float) -> list[StudyRun]:
    """Every method of ours at several step sizes or tolerances."""
    system, contact, start = table1()
    runs: list[StudyRun] = []

    def measure(label: str, setting: str, step: float | None, tol: float | None, **kw: Any) -> None:
        def once() -> Solution:
            return simulate(system, contact, start, t_end=STUDY_TIME, every=1_000_000, **kw)

        sol, cpu = median_time(once)
        duration = first_duration(sol)
        runs.append(
            StudyRun(
                label,
                setting,
                step,
                tol,
                duration,
                abs(duration / exact - 1.0),
                cpu,
                sol.rhs_evaluations,
            )
        )

    for label, method, stepping in FIXED_RUNS:
        limits = PAPER_METHOD_LIMITS if method == "newmark" else {}
        for dt in STEP_SIZES:
            measure(
                label, f"dt={dt:g}", dt, None, method=method, dt=dt, stepping=stepping, **limits
            )
    for method in ADAPTIVE_RUNS:
        for rtol in TOLERANCES:
            measure(
                method, f"rtol={rtol:g}", None, rtol, method=method, rtol=rtol, atol=rtol * 1e-3
            )
    return runs


def scipy_missing() -> str | None:
    """Why scipy's comparison cannot run, or None when it can."""
    try:
        import scipy.integrate  # noqa: F401
    except ImportError as err:
        return (
            f"scipy cannot be imported ({err}), so the comparison with its solve_ivp is "
            "left out; install it with `pip install scipy` (a dependency of vibroimpact)"
        )
    return None


def scipy_runs(exact: float) -> list[StudyRun]:
    """scipy's solve_ivp on the same collision (contact phase, separation event);
    none when scipy is missing (see :func:`scipy_missing`)."""
    if scipy_missing() is not None:
        return []
    import numpy as np
    from scipy.integrate import solve_ivp

    c1, k, d = CONTACT_DAMPING, HERTZ_STIFFNESS, CLEARANCE

    def rhs(_t: float, s: Any) -> Any:
        w, wd, y, yd = s
        indentation = (y - w) - d
        rate = yd - wd
        force = (k * indentation**1.5 if indentation > 0 else 0.0) + c1 * rate
        return np.array(
            [wd, (force - DAMPING * wd - STIFFNESS * w) / MAIN_MASS, yd, -force / IMPACT_MASS]
        )

    def separation(_t: float, s: Any) -> float:
        return float((s[2] - s[0]) - d)

    separation.terminal = True  # type: ignore[attr-defined]
    separation.direction = -1  # type: ignore[attr-defined]
    start = np.array([0.0, 0.0, d, APPROACH_SPEED])
    runs: list[StudyRun] = []
    for method in ("RK45", "DOP853", "LSODA"):
        for rtol in (1e-4, 1e-6, 1e-8, 1e-10):

            def once(method: str = method, rtol: float = rtol) -> Any:
                return solve_ivp(
                    rhs,
                    (0.0, STUDY_TIME),
                    start,
                    method=method,
                    rtol=rtol,
                    atol=rtol * 1e-3,
                    events=separation,
                )

            sol, cpu = median_time(once, min_repeats=3, budget=0.0)
            if len(sol.t_events[0]) == 0:
                continue
            duration = float(sol.t_events[0][0])
            runs.append(
                StudyRun(
                    f"scipy {method}",
                    f"rtol={rtol:g}",
                    None,
                    rtol,
                    duration,
                    abs(duration / exact - 1.0),
                    cpu,
                    int(sol.nfev),
                )
            )
    return runs


def cheapest(runs: list[StudyRun], error: float) -> StudyRun | None:
    """The run with the least CPU time whose error is at most ``error``."""
    good = [r for r in runs if r.error <= error]
    return min(good, key=lambda r: r.cpu_time) if good else None
