"""The integration methods and the event-driven stepping, against independent values.

References, all computed here: the closed form of a damped oscillator (a run in which
the bodies never touch), SciPy's DOP853 at rtol 1e-12 with the contact onsets and
separations located as events (one collision, or a whole multi-contact run mode by
mode) and conservation of energy. The geometry of a trajectory that just touches,
just misses or just penetrates a wall, and the limits of a run, are in
test_methods_edges.py.

Expected orders: RK4 4, the Newmark family 2 (the paper's lagged Newmark is plain
average-acceleration Newmark while the bodies are apart), DOPRI5 5 and DOP853 8 in
error against work. Through a Hertz contact (F ~ delta^1.5) the first and the last
step of a contact integrate a t^1.5 forcing, whose local error is O(h^2.5) whatever
the method's order, so RK4 with events converges at order 2.5 there; the lagged
Newmark stays first order (its force lags one step).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cache
from typing import Any

import numpy as np
import pytest
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
from method_checks import (
    ELASTIC_CONTACT,
    SMOOTH_C,
    SMOOTH_CONTACT,
    SMOOTH_K,
    SMOOTH_M,
    SMOOTH_START,
    SMOOTH_SYSTEM,
    SMOOTH_W0,
    Rattle,
    mode_by_mode_oracle,
    table1_run,
)

EPS = np.finfo(float).eps


def log_slope(x: list[float] | np.ndarray, y: list[float] | np.ndarray) -> float:
    """Least-squares slope of log(y) against log(x)."""
    return float(np.polyfit(np.log(x), np.log(y), 1)[0])


# ------------------------------------------------- a) order on a smooth problem


def smooth_exact(t: np.ndarray) -> np.ndarray:
    """w(t) of M w'' + C w' + K w = 0, w(0) = w0, w'(0) = 0 (underdamped)."""
    wn = math.sqrt(SMOOTH_K / SMOOTH_M)
    zeta = SMOOTH_C / (2 * math.sqrt(SMOOTH_K * SMOOTH_M))
    wd = wn * math.sqrt(1 - zeta**2)
    decay = np.exp(-zeta * wn * t)
    return SMOOTH_W0 * decay * (np.cos(wd * t) + zeta * wn / wd * np.sin(wd * t))


def smooth_error(sol: vi.Solution) -> float:
    assert len(sol.contacts) == 0 and sol.grazing_contacts == 0
    # The impact mass never moves.
    assert np.all(sol.impact_displacement == 0.0) and np.all(sol.impact_velocity == 0.0)
    return float(np.max(np.abs(sol.main_displacement - smooth_exact(sol.t))))


def test_smooth_closed_form_solves_the_equation() -> None:
    """The reference itself: w'' from finite differences satisfies the ODE."""
    t = np.linspace(0.0, 4.0, 4001)
    h = t[1] - t[0]
    w = smooth_exact(t)
    wd = np.gradient(w, h, edge_order=2)
    wdd = np.gradient(wd, h, edge_order=2)
    residual = SMOOTH_M * wdd + SMOOTH_C * wd + SMOOTH_K * w
    # Second-order differences: error ~ h^2 w'''' / 12, about 1e-6 of K w0 here.
    assert np.max(np.abs(residual[5:-5])) < 1e-5 * SMOOTH_K * SMOOTH_W0
    assert abs(wd[0]) < 1e-6 * SMOOTH_W0
    assert w[0] == SMOOTH_W0


FIXED_STEP_ORDERS = [
    ("rk4", {"stepping": "fixed"}, 4),
    ("rk4", {"stepping": "events"}, 4),
    ("newmark", {"stepping": "fixed"}, 2),
    ("newmark", {"stepping": "events"}, 2),
    ("newmark-implicit", {}, 2),
    ("generalized-alpha", {"spectral_radius": 0.0}, 2),
    ("generalized-alpha", {"spectral_radius": 0.9}, 2),
    ("generalized-alpha", {"spectral_radius": 1.0}, 2),
]


@pytest.mark.parametrize(
    ("method", "options", "order"),
    FIXED_STEP_ORDERS,
    ids=[
        f"{m}-{'-'.join(str(v) for v in o.values()) or 'default'}" for m, o, _ in FIXED_STEP_ORDERS
    ],
)
def test_fixed_step_order_on_smooth_problem(
    method: str, options: dict[str, Any], order: int
) -> None:
    dts = [0.08, 0.04, 0.02, 0.01]
    errors = []
    for dt in dts:
        sol = vi.simulate(
            SMOOTH_SYSTEM, SMOOTH_CONTACT, SMOOTH_START, method=method, dt=dt, t_end=4.0, **options
        )
        assert sol.steps == round(4.0 / dt)
        errors.append(smooth_error(sol))
    assert errors[-1] < errors[0]
    assert log_slope(dts, errors) == pytest.approx(order, abs=0.2), errors


# rtol decades in the asymptotic range (above the round-off floor of w ~ 1e-2).
ADAPTIVE_SWEEPS = [
    ("dopri5", 5, [1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10]),
    ("dop853", 8, [1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11]),
]


@pytest.mark.parametrize(("method", "order", "rtols"), ADAPTIVE_SWEEPS, ids=["dopri5", "dop853"])
def test_adaptive_error_against_work(method: str, order: int, rtols: list[float]) -> None:
    """log(error) against log(rhs evaluations) has slope -order.

    With error-per-step control and local extrapolation the global error follows
    the tolerance while the work grows like rtol^(-1/order), plus a start-up cost
    (the first step's estimate and the steps growing from it) that does not shrink
    with rtol and steepens the slope at the loosest tolerances: on the general kernel
    (Hairer's first step, c04f48d) DOP853 takes 661 evaluations at rtol 1e-5 against
    0.1's 529, and 2881 against 2869 at 1e-11, so over the whole sweep its slope is
    -9.3 (0.1: -8.2). The slope is therefore fitted from the third tolerance on,
    where the work is mostly the method's: -8.9 for DOP853 and -5.5 for DOPRI5; 1.0
    is the tolerance (a fifth-order method's slope, -5, stays far outside it).
    """
    errors, work = [], []
    for rtol in rtols:
        sol = vi.simulate(
            SMOOTH_SYSTEM,
            SMOOTH_CONTACT,
            SMOOTH_START,
            method=method,
            t_end=30.0,
            rtol=rtol,
            atol=1e-15,
        )
        assert sol.final_time == 30.0
        errors.append(smooth_error(sol))
        work.append(sol.rhs_evaluations)
    # Tolerance proportionality: each decade of rtol buys about a decade of error.
    ratios = np.array(errors[:-1]) / np.array(errors[1:])
    assert np.all((ratios > 3) & (ratios < 30)), errors
    assert errors[-1] < 100 * rtols[-1] * SMOOTH_W0
    assert log_slope(work[2:], errors[2:]) == pytest.approx(-order, abs=1.0), (work, errors)


# ------------------------------------------------- b) the Table 1 collision


@dataclass(frozen=True)
class Collision:
    duration: float
    max_indentation: float
    rebound_ratio: float


@cache
def collision_oracle(contact_damping: float = CONTACT_DAMPING) -> Collision:
    """The Table 1 collision by SciPy's DOP853 (rtol 1e-12) from onset at t = 0.

    w = w' = 0, y - w = d, y' = 0.1 m/s: the separation instant is the duration.
    Hertz force (zero unless indented) plus c1 on the relative velocity in contact.
    """

    def rhs(_t: float, s: np.ndarray) -> list[float]:
        w, wd, y, yd = s
        delta, rate = (y - w) - CLEARANCE, yd - wd
        force = HERTZ_STIFFNESS * max(delta, 0.0) ** 1.5 + contact_damping * rate
        return [wd, (force - DAMPING * wd - STIFFNESS * w) / MAIN_MASS, yd, -force / IMPACT_MASS]

    def separation(_t: float, s: np.ndarray) -> float:
        return (s[2] - s[0]) - CLEARANCE

    def deepest(_t: float, s: np.ndarray) -> float:
        return s[3] - s[1]

    separation.terminal = True  # type: ignore[attr-defined]
    separation.direction = -1  # type: ignore[attr-defined]
    deepest.direction = -1  # type: ignore[attr-defined]
    sol = solve_ivp(
        rhs,
        (0.0, 1.0),
        [0.0, 0.0, CLEARANCE, APPROACH_SPEED],
        method="DOP853",
        rtol=1e-12,
        atol=1e-15,
        events=[separation, deepest],
    )
    assert sol.status == 1 and len(sol.t_events[1]) == 1
    end, deep = sol.y_events[0][0], sol.y_events[1][0]
    return Collision(
        duration=float(sol.t_events[0][0]),
        max_indentation=float(deep[2] - deep[0] - CLEARANCE),
        rebound_ratio=float(-(end[3] - end[1]) / APPROACH_SPEED),
    )


def collision_errors(sol: vi.Solution, exact: Collision) -> tuple[float, float, float]:
    """Relative errors of (duration, max indentation, rebound ratio) of the one contact."""
    c = sol.contacts
    assert len(c) == 1 and c.onset[0] == 0.0 and np.isfinite(c.separation[0])
    assert c.approach_speed[0] == APPROACH_SPEED
    return (
        abs(c.duration[0] / exact.duration - 1),
        abs(c.max_indentation[0] / exact.max_indentation - 1),
        abs(c.restitution[0] / exact.rebound_ratio - 1),
    )


def test_oracle_reproduces_the_reference_page() -> None:
    exact = collision_oracle()
    # /work/shared/reference/paper-model.md, "Independent checks", to its printed digits.
    assert exact.duration == pytest.approx(0.1089819, abs=6e-8)
    assert exact.max_indentation == pytest.approx(3.69668e-3, abs=6e-9)
    assert exact.rebound_ratio == pytest.approx(0.99635, abs=6e-6)


# (method, expected order of duration and max-indentation errors, finest-dt bounds)
EVENT_METHODS = [
    ("newmark", 1.0, (2e-3, 5e-3, 1e-2)),
    ("newmark-implicit", 2.0, (5e-6, 5e-6, 1e-7)),
    ("generalized-alpha", 2.0, (5e-6, 5e-6, 1e-7)),
    ("rk4", 2.5, (1e-9, 5e-9, 5e-9)),
]


@pytest.mark.parametrize(
    ("method", "order", "bounds"), EVENT_METHODS, ids=[m for m, _, _ in EVENT_METHODS]
)
def test_event_stepping_converges_on_the_table1_collision(
    method: str, order: float, bounds: tuple[float, float, float]
) -> None:
    exact = collision_oracle()
    dts = [1e-3, 5e-4, 2.5e-4, 1.25e-4]
    # The paper's lagged Newmark creates energy at the coarse steps (refused by default).
    loose = {"energy_tolerance": 1.0} if method == "newmark" else {}
    errors = np.array(
        [
            collision_errors(table1_run(method=method, dt=dt, stepping="events", **loose), exact)
            for dt in dts
        ]
    )
    for column in (0, 1):  # duration, max indentation
        assert log_slope(dts, errors[:, column]) == pytest.approx(order, abs=0.3), errors
    # The rebound ratio converges too (its error is small and noisy for the
    # higher-order methods: it depends on where the last step is cut).
    assert errors[-1, 2] < errors[0, 2] or errors[-1, 2] < 1e-9
    for got, bound in zip(errors[-1], bounds, strict=True):
        assert got < bound, errors[-1]


@pytest.mark.parametrize("method", ["dopri5", "dop853"])
def test_adaptive_methods_converge_on_the_table1_collision(method: str) -> None:
    exact = collision_oracle()
    runs = [table1_run(method=method, rtol=rtol) for rtol in (1e-6, 1e-8, 1e-10)]
    errors = np.array([collision_errors(sol, exact) for sol in runs])
    assert errors[0, 0] > errors[1, 0] > errors[2, 0]
    assert errors[2, 0] < 1e-9 and errors[2, 2] < 1e-9
    assert errors[2, 1] < 1e-9
    assert runs[2].stepping == "events"


def test_rk4_events_at_1e3_within_1e6_of_the_exact_duration() -> None:
    sol = table1_run(method="rk4", dt=1e-3, stepping="events")
    assert collision_errors(sol, collision_oracle())[0] < 1e-6


def test_dop853_at_rtol_1e10_within_1e10_of_the_exact_duration() -> None:
    sol = table1_run(method="dop853", rtol=1e-10)
    assert collision_errors(sol, collision_oracle())[0] < 1e-10


@pytest.mark.parametrize("method", ["dopri5", "dop853"])
def test_adaptive_max_indentation_follows_the_tolerance(method: str) -> None:
    """The deepest point is located on the method's own steps, not interpolated."""
    sol = table1_run(method=method, rtol=1e-10)
    assert collision_errors(sol, collision_oracle())[1] < 1e-9


def rk4_events_errors(contact_damping: float) -> list[float]:
    """Duration and max-indentation errors of RK4 with events at dt = 1e-3 and 1e-4."""
    exact = collision_oracle(contact_damping)
    errors: list[float] = []
    for dt in (1e-3, 1e-4):
        sol = table1_run(contact_damping, method="rk4", dt=dt, stepping="events", every=1000)
        errors += collision_errors(sol, exact)[:2]
    return errors


@pytest.mark.parametrize("contact_damping", [0.0, 0.2])
def test_rk4_with_events_converges_at_high_order_with_contact_damper(
    contact_damping: float,
) -> None:
    """The events version of test_verification's xfail (fixed stepping, c1 > 0): the
    force jump c1 * rate at onset and separation is now a step boundary."""
    d3, i3, d4, i4 = rk4_events_errors(contact_damping)
    assert d3 < 1e-6 and i3 < 1e-6
    # Order 2.5 (delta^1.5) over a decade: a factor of ~316.
    assert d3 / d4 > 100 and i3 / i4 > 100


# ------------------------------------------------- c) event location, many contacts

# The rattling run: main mass released from 0.05 m with the impact mass at rest in
# the middle; K = 40 N/m (the Table 1 spring of 1 N/m gives only two contacts in 3 s).
RATTLE_K = 40.0
RATTLE_E = 0.7
RATTLE_T = 3.0
RATTLE_SYSTEM = vi.ImpactDamper(
    main_mass=MAIN_MASS,
    stiffness=RATTLE_K,
    damping=DAMPING,
    impact_mass=IMPACT_MASS,
    clearance=CLEARANCE,
)
RATTLE_CONTACT = vi.Contact(
    "hertz-damped", stiffness=HERTZ_STIFFNESS, damping=CONTACT_DAMPING, restitution=RATTLE_E
)
RATTLE_START = vi.InitialState(main_displacement=0.05, impact_displacement=0.05)


@cache
def rattle_oracle(floored: bool = True) -> Rattle:
    return mode_by_mode_oracle(
        RATTLE_SYSTEM, RATTLE_CONTACT, RATTLE_START, RATTLE_T, floored=floored
    )


def test_rattle_oracle_rattles() -> None:
    exact = rattle_oracle()
    assert len(exact.onsets) >= 8
    assert len(exact.separations) in (len(exact.onsets), len(exact.onsets) - 1)
    # The first onset: free flight of the main mass, an independent closed form.
    wn = math.sqrt(RATTLE_K / MAIN_MASS)
    zeta = DAMPING / (2 * math.sqrt(RATTLE_K * MAIN_MASS))
    wd = wn * math.sqrt(1 - zeta**2)

    def gap(t: float) -> float:
        w = 0.05 * math.exp(-zeta * wn * t) * (math.cos(wd * t) + zeta * wn / wd * math.sin(wd * t))
        return (0.05 - w) - CLEARANCE

    assert exact.onsets[0] == pytest.approx(brentq(gap, 0.0, 0.3, xtol=1e-15), rel=1e-12)


RATTLE_RUNS = [
    ({"method": "rk4", "dt": 1e-4, "stepping": "events"}, 1e-9),
    ({"method": "dop853", "rtol": 1e-11}, 1e-9),
    ({"method": "dopri5", "rtol": 1e-11}, 1e-9),
    ({"method": "newmark-implicit", "dt": 1e-4}, 2e-5),
    ({"method": "generalized-alpha", "dt": 1e-4}, 2e-5),
]


@pytest.mark.parametrize(
    ("settings", "tolerance"), RATTLE_RUNS, ids=[s["method"] for s, _ in RATTLE_RUNS]
)
def test_located_events_match_the_oracle(settings: dict[str, Any], tolerance: float) -> None:
    exact = rattle_oracle()
    sol = vi.simulate(RATTLE_SYSTEM, RATTLE_CONTACT, RATTLE_START, t_end=RATTLE_T, **settings)
    c = sol.contacts
    closed = np.isfinite(c.separation)
    assert len(c) == len(exact.onsets) and closed.sum() == len(exact.separations)
    np.testing.assert_allclose(c.onset, exact.onsets, rtol=tolerance, atol=0)
    np.testing.assert_allclose(c.separation[closed], exact.separations, rtol=tolerance, atol=0)
    # Every located instant is a kept row (every = 1) and there the bodies are
    # exactly at the wall: |y - w| = d to the round-off of the stored doubles.
    for instants in (c.onset, c.separation[closed]):
        rows = np.searchsorted(sol.t, instants)
        np.testing.assert_array_equal(sol.t[rows], instants)
        w, y = sol.main_displacement[rows], sol.impact_displacement[rows]
        gap = np.abs(y - w) - CLEARANCE
        assert np.all(np.abs(gap) <= 8 * EPS * (np.abs(w) + np.abs(y) + CLEARANCE)), gap
    # The force is the law's plus the damper's; the law's part is zero at the wall. The
    # onset row is the state arriving there, indented by 0 to round-off of either sign:
    # its force is 0 (apart) or the damper's c1 * approach speed (indented by round-off).
    onset_rows = np.searchsorted(sol.t, c.onset)
    force = sol.contact_force[onset_rows]
    damper = CONTACT_DAMPING * c.approach_speed
    assert np.all((force == 0.0) | np.isclose(force, damper, rtol=1e-9, atol=0)), (force, damper)


def test_fixed_stepping_latches_the_located_approach_rate() -> None:
    """The paper's fixed stepping (RK4) on the rattling run: a step straddles each
    onset, and the hertz-damped law's latched rate must be the located onset's, not
    the rate at the start of that step (the main mass accelerates the gap in free
    flight, so the two differ by up to ~1e-3). The rebound of a rate-dependent law
    depends on the latched rate, so each contact's onset, approach and rebound are
    checked against the oracle: with the located latch the errors are below 4e-7 (s
    and m/s) at dt = 1e-4 s, falling with dt; with the provisional one 5e-5 s, 2e-4 s
    and 9e-5 m/s. Fixed stepping latches the located approach alone (the floor of the
    pressing is the event-driven contact's): the oracle without it."""
    exact = rattle_oracle(floored=False)
    sol = vi.simulate(
        RATTLE_SYSTEM,
        RATTLE_CONTACT,
        RATTLE_START,
        t_end=RATTLE_T,
        method="rk4",
        dt=1e-4,
        stepping="fixed",
    )
    c = sol.contacts
    closed = np.isfinite(c.separation)
    assert len(c) == len(exact.onsets) and closed.sum() == len(exact.separations)
    np.testing.assert_allclose(c.onset, exact.onsets, rtol=0, atol=1e-6)
    np.testing.assert_allclose(c.separation[closed], exact.separations, rtol=0, atol=1e-6)
    np.testing.assert_allclose(c.approach_speed, exact.approach_speeds, rtol=0, atol=1e-6)
    np.testing.assert_allclose(c.rebound_speed[closed], exact.rebound_speeds, rtol=0, atol=1e-6)


# ------------------------------------------------- d) energy


def mechanical_energy(sol: vi.Solution, system: vi.ImpactDamper) -> np.ndarray:
    """Kinetic + main spring + Hertz potential (0.4 K delta^2.5), computed here."""
    delta = np.maximum(
        np.abs(sol.impact_displacement - sol.main_displacement) - system.clearance, 0
    )
    return (
        0.5 * system.main_mass * sol.main_velocity**2
        + 0.5 * system.impact_mass * sol.impact_velocity**2
        + 0.5 * system.stiffness * sol.main_displacement**2
        + 0.4 * HERTZ_STIFFNESS * delta**2.5
    )


CONSERVATIVE_SYSTEM = vi.ImpactDamper(
    main_mass=MAIN_MASS, stiffness=RATTLE_K, impact_mass=IMPACT_MASS, clearance=CLEARANCE
)


@pytest.mark.parametrize(
    "options",
    [{"method": "newmark-implicit"}, {"method": "generalized-alpha", "spectral_radius": 1.0}],
    ids=["newmark-implicit", "generalized-alpha-rho1"],
)
def test_implicit_energy_error_is_bounded_and_second_order(options: dict[str, Any]) -> None:
    """e = 1, C = c1 = 0: energy is conserved by the model; the error of these
    methods stays bounded over a hundred contacts and shrinks at second order."""

    def relative_error(dt: float, t_end: float) -> np.ndarray:
        sol = vi.simulate(
            CONSERVATIVE_SYSTEM, ELASTIC_CONTACT, RATTLE_START, dt=dt, t_end=t_end, **options
        )
        assert len(sol.contacts) >= 10 * t_end / 3
        energy = mechanical_energy(sol, CONSERVATIVE_SYSTEM)
        error = energy / energy[0] - 1
        # energy_growth is max(E)/E(0) - 1, sampled every few steps.
        assert -1e-15 <= sol.energy_growth <= max(error.max(), 0.0) + 1e-15
        return error

    dts = [1e-3, 5e-4, 2.5e-4]
    errors = [float(np.max(np.abs(relative_error(dt, 3.0)))) for dt in dts]
    assert errors[0] < 1e-4
    assert log_slope(dts, errors) == pytest.approx(2.0, abs=0.3), errors
    # No drift: over ten times as long (about 100 contacts) the error stays at
    # the level of the first 3 s.
    long_run = np.abs(relative_error(5e-4, 30.0))
    assert long_run.max() < 3 * errors[1], (long_run.max(), errors[1])


def test_lagged_newmark_energy_drifts_for_contrast() -> None:
    """The paper's lagged Newmark (events) gains energy contact after contact."""
    sol = vi.simulate(
        CONSERVATIVE_SYSTEM,
        ELASTIC_CONTACT,
        RATTLE_START,
        method="newmark",
        stepping="events",
        dt=5e-4,
        t_end=3.0,
        energy_tolerance=1.0,  # the energy it creates is refused by default
    )
    energy = mechanical_energy(sol, CONSERVATIVE_SYSTEM)
    c = sol.contacts
    after = energy[np.searchsorted(sol.t, c.separation[np.isfinite(c.separation)])]
    assert after[-1] / energy[0] - 1 > 10 * (after[0] / energy[0] - 1) > 0


# ------------------------------------------------- e) statistics


def test_fixed_stepping_statistics() -> None:
    rk4 = table1_run(method="rk4", dt=1e-4)
    assert rk4.stepping == "fixed"
    assert (rk4.steps, rk4.rejected_steps, rk4.grazing_contacts) == (1500, 0, 0)
    # Four a step, and three more for the step in which the contact begins: it is taken
    # again from its start with the contact's force acting past the wall (its first stage,
    # at the start, is the same).
    assert len(rk4.contacts) == 1
    assert rk4.rhs_evaluations == 4 * rk4.steps + 3
    newmark = table1_run(method="newmark", dt=1e-4)
    assert newmark.stepping == "fixed"
    assert (newmark.steps, newmark.rejected_steps) == (1500, 0)
    assert newmark.rhs_evaluations == newmark.steps  # the force once per step, lagged


def test_event_stepping_statistics_of_fixed_step_methods() -> None:
    exact = rattle_oracle()
    events = len(exact.onsets) + len(exact.separations)
    for method in ("rk4", "newmark", "newmark-implicit", "generalized-alpha"):
        sol = vi.simulate(
            RATTLE_SYSTEM,
            RATTLE_CONTACT,
            RATTLE_START,
            method=method,
            dt=1e-4,
            t_end=RATTLE_T,
            stepping="events",
        )
        assert sol.stepping == "events"
        assert sol.rejected_steps == 0
        assert len(sol.contacts) == len(exact.onsets)
        # Each located event cuts one grid step in two.
        assert sol.steps == 30000 + events, method
        if method == "rk4":
            # Four evaluations per attempt; locating events costs extra attempts, and
            # each compliant onset one evaluation of the pressing (the law's latch).
            assert sol.rhs_evaluations > 4 * sol.steps
        else:
            assert sol.rhs_evaluations > sol.steps


def test_rk4_events_without_contact_costs_four_evaluations_a_step() -> None:
    sol = vi.simulate(
        SMOOTH_SYSTEM,
        SMOOTH_CONTACT,
        SMOOTH_START,
        method="rk4",
        dt=0.01,
        t_end=4.0,
        stepping="events",
    )
    assert (sol.steps, sol.rejected_steps, sol.rhs_evaluations) == (400, 0, 1600)


def test_newton_on_free_flight_needs_one_update_per_step() -> None:
    """The equations are linear while apart: one Newton update solves them exactly,
    so each step costs the residual evaluation of that update and at most one more
    confirming it (plus one at the start); a second update would cost a third."""
    for method in ("newmark-implicit", "generalized-alpha"):
        sol = vi.simulate(
            SMOOTH_SYSTEM, SMOOTH_CONTACT, SMOOTH_START, method=method, dt=0.01, t_end=4.0
        )
        assert len(sol.contacts) == 0 and sol.steps == 400
        assert 1 + sol.steps <= sol.rhs_evaluations <= 1 + 2 * sol.steps, sol.rhs_evaluations


@pytest.mark.parametrize(("method", "stages"), [("dopri5", 6), ("dop853", 12)])
def test_adaptive_statistics(method: str, stages: int) -> None:
    # Smooth run: one evaluation to start, then `stages` new ones per attempt
    # (first same as last), accepted or rejected.
    smooth = vi.simulate(SMOOTH_SYSTEM, SMOOTH_CONTACT, SMOOTH_START, method=method, t_end=4.0)
    assert smooth.stepping == "events"
    assert smooth.rhs_evaluations == 1 + stages * (smooth.steps + smooth.rejected_steps)
    # The collision: the error control rejects steps where F ~ delta^1.5 is rough.
    collision = table1_run(method=method, rtol=1e-8)
    assert collision.rejected_steps > 0
    assert collision.rhs_evaluations >= 1 + stages * (collision.steps + collision.rejected_steps)
    assert len(collision.t) == collision.steps + 1  # every = 1 keeps each accepted step
