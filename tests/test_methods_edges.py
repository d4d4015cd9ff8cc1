"""The integration methods at the edges of a contact and of a run, against the
geometry of the trajectory: a trajectory that just touches a wall grazes it, one that
just misses it is nothing, one that penetrates beyond the tolerance is a contact;
bouncing down ends in persistent contact or a chattering error; max_steps bounds a
run; Newton's updates on free flight and their translation invariance.
"""

from __future__ import annotations

import math
from functools import cache
from typing import Any

import numpy as np
import pytest

import vibroimpact as vi
from conftest import (
    APPROACH_SPEED,
    CLEARANCE,
    HERTZ_STIFFNESS,
    IMPACT_MASS,
    MAIN_MASS,
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
    time_limit,
)

GRAZE_SYSTEM = vi.ImpactDamper(
    main_mass=1.0, stiffness=1.0, impact_mass=IMPACT_MASS, clearance=CLEARANCE
)


GRAZE_METHODS = [
    {"method": "rk4", "dt": 1e-3, "stepping": "events"},
    {"method": "rk4", "dt": 1e-4, "stepping": "events"},
    {"method": "newmark-implicit", "dt": 1e-3},
    {"method": "generalized-alpha", "dt": 1e-3, "spectral_radius": 1.0},
]


GRAZE_IDS = ["rk4-1e-3", "rk4-1e-4", "newmark-implicit", "generalized-alpha"]


def graze_run(relative_overshoot: float, **settings: Any) -> vi.Solution:
    """The impact mass rests at y = 0; the main mass starts at w = 0 with w' = A,
    so y - w = -A sin t (K = M = 1, C = 0) reaches -A at t = pi/2: a peak
    indentation of A - d = d * relative_overshoot at the wall y - w = -d."""
    amplitude = CLEARANCE * (1 + relative_overshoot)
    start = vi.InitialState(main_velocity=amplitude)
    with time_limit(20):
        return vi.simulate(GRAZE_SYSTEM, ELASTIC_CONTACT, start, t_end=3.0, **settings)


@pytest.mark.parametrize("settings", GRAZE_METHODS, ids=GRAZE_IDS)
def test_touching_the_wall_is_a_graze(settings: dict[str, Any]) -> None:
    # Peak indentation 5e-15 m: half the kernel's graze tolerance (1e-12 * d).
    sol = graze_run(5e-13, **settings)
    assert len(sol.contacts) == 0
    assert sol.grazing_contacts == 1
    assert np.all(sol.contact_force == 0.0)


@pytest.mark.parametrize("settings", GRAZE_METHODS, ids=GRAZE_IDS)
def test_just_missing_the_wall_is_nothing(settings: dict[str, Any]) -> None:
    sol = graze_run(-1e-6, **settings)
    assert (len(sol.contacts), sol.grazing_contacts) == (0, 0)


@pytest.mark.parametrize("settings", GRAZE_METHODS, ids=GRAZE_IDS)
def test_penetrating_beyond_the_tolerance_is_a_contact(settings: dict[str, Any]) -> None:
    overshoot = 1e-9  # 1e-11 m, a thousand times the graze tolerance
    sol = graze_run(overshoot, **settings)
    assert (len(sol.contacts), sol.grazing_contacts) == (1, 0)
    c = sol.contacts
    # The force (K_hz delta^1.5 ~ 1e-13 N) barely acts: the contact spans the
    # arc where A sin t > d, t = pi/2 -+ acos(1 / (1 + overshoot)). The Newmark
    # family's period error (~(w dt)^2 / 12) shifts the arc by ~1e-7 s.
    half = math.acos(1 / (1 + overshoot))
    assert c.duration[0] == pytest.approx(2 * half, rel=1e-3)
    assert 0.5 * (c.onset[0] + c.separation[0]) == pytest.approx(math.pi / 2, abs=1e-6)
    assert c.max_indentation[0] == pytest.approx(CLEARANCE * overshoot, rel=1e-3)


@pytest.mark.parametrize("method", ["dopri5", "dop853"])
def test_adaptive_methods_graze_and_miss(method: str) -> None:
    # Deep contact found, a clear miss is nothing; neither hangs.
    assert len(graze_run(1e-2, method=method).contacts) == 1
    assert len(graze_run(1e-3, method=method).contacts) == 1
    missed = graze_run(-1e-6, method=method)
    assert (len(missed.contacts), missed.grazing_contacts) == (0, 0)


def test_dop853_finds_a_shallow_contact() -> None:
    assert len(graze_run(1e-4, method="dopri5").contacts) == 1
    assert len(graze_run(1e-4, method="dop853").contacts) == 1


# The impact mass starts 0.1 mm from the trailing wall while the main mass (w = -0.05
# m, K = 100 N/m) accelerates at +5 m/s^2 for a quarter period: a ball dropped on a
# table. Rigid impacts with e < 1 would make infinitely many ever-shorter bounces in
# finite time (Zeno); a compliant contact ends them in a persistent contact.
PRESSED_SYSTEM = vi.ImpactDamper(main_mass=1.0, stiffness=100.0, impact_mass=0.25, clearance=0.01)
PRESSED_CONTACT = vi.Contact("hertz-damped", stiffness=1e9, restitution=0.8)
PRESSED_START = vi.InitialState(main_displacement=-0.05, impact_displacement=-0.05 - 0.01 + 1e-4)
PRESSED_RUNS = [
    {"method": "dop853"},
    {"method": "dopri5"},
    {"method": "rk4", "dt": 1e-5, "stepping": "events"},
    {"method": "newmark-implicit", "dt": 1e-6},
    {"method": "generalized-alpha", "dt": 1e-6},
]


@cache
def pressed_reference() -> Rattle:
    # The flights shrink to about 1 ms: ten SciPy steps at least in each.
    return mode_by_mode_oracle(
        PRESSED_SYSTEM, PRESSED_CONTACT, PRESSED_START, 0.3, max_flight_step=1e-4
    )


@pytest.mark.parametrize("settings", PRESSED_RUNS, ids=[s["method"] for s in PRESSED_RUNS])
def test_bouncing_down_ends_in_persistent_contact_or_chattering_error(
    settings: dict[str, Any],
) -> None:
    try:
        with time_limit(30):
            sol = vi.simulate(PRESSED_SYSTEM, PRESSED_CONTACT, PRESSED_START, t_end=0.3, **settings)
    except vi.SimulationError as err:
        assert "chatter" in str(err).lower(), str(err)
        return
    c = sol.contacts
    assert 5 <= len(c) < 100
    # Bounces on the trailing wall (y - w = -d), ever slower and closer together,
    # then a contact that lasts until the main mass decelerates (a quarter period
    # is 0.157 s).
    assert np.all(np.diff(c.approach_speed) < 0)
    flights = c.onset[1:] - c.separation[:-1]
    assert np.all(flights > 0) and np.all(np.diff(flights) < 0)
    assert c.duration[-1] > 50 * c.duration[0]
    reference = pressed_reference()
    assert len(c) == len(reference.onsets)
    # Measured: onsets within 3e-6 and durations within 3e-5 (DOPRI5 at its default
    # tolerance), the others closer.
    np.testing.assert_allclose(c.onset, reference.onsets, rtol=1e-5)
    closed = np.isfinite(c.separation)
    np.testing.assert_allclose(
        c.duration[closed], reference.separations - reference.onsets[: closed.sum()], rtol=1e-4
    )


def test_a_stiff_contact_may_fail_newton_but_says_so() -> None:
    """Generalised-alpha at dt = 1e-4 on the pressed contact (K_hz = 1e9, contacts of
    ~1 ms): either the result agrees with DOP853 or a SimulationError names Newton
    and the remedy; never a hang."""
    try:
        with time_limit(30):
            sol = vi.simulate(
                PRESSED_SYSTEM,
                PRESSED_CONTACT,
                PRESSED_START,
                t_end=0.3,
                method="generalized-alpha",
                dt=1e-4,
            )
    except vi.SimulationError as err:
        assert isinstance(err, RuntimeError)
        assert "Newton" in str(err) and "dt" in str(err)
        return
    assert len(sol.contacts) == len(pressed_reference().onsets)


@pytest.mark.parametrize(
    "settings",
    [
        {"method": "dop853"},
        {"method": "dopri5"},
        {"method": "rk4", "dt": 1e-4, "stepping": "events"},
        {"method": "newmark", "dt": 1e-4, "stepping": "events"},
        {"method": "newmark-implicit", "dt": 1e-4},
        {"method": "generalized-alpha", "dt": 1e-4},
    ],
    ids=lambda s: s["method"],
)
def test_max_steps_bounds_a_run(settings: dict[str, Any]) -> None:
    if "dt" in settings:
        # A fixed step's count is known: 1500 steps are refused before the run.
        with pytest.raises(vi.InvalidInputError, match="max_steps"):
            table1_run(max_steps=10, **settings)
    else:
        with pytest.raises(vi.SimulationError, match="max_steps") as err:
            table1_run(max_steps=10, **settings)
        assert isinstance(err.value, RuntimeError)
    # Enough steps: the same run completes.
    assert table1_run(max_steps=100_000, **settings).final_time >= 0.15


@pytest.mark.parametrize("method", ["rk4", "newmark"])
def test_max_steps_bounds_fixed_stepping(method: str) -> None:
    with pytest.raises(vi.InvalidInputError, match="max_steps"):
        table1_run(method=method, dt=1e-4, max_steps=10)


def test_a_run_of_exactly_max_steps_completes() -> None:
    settings: dict[str, Any] = dict(method="rk4", dt=0.01, t_end=4.0, stepping="events")
    full = vi.simulate(SMOOTH_SYSTEM, SMOOTH_CONTACT, SMOOTH_START, **settings)
    assert full.steps == 400
    sol = vi.simulate(SMOOTH_SYSTEM, SMOOTH_CONTACT, SMOOTH_START, max_steps=400, **settings)
    assert sol.steps == 400


def test_newton_is_translation_invariant() -> None:
    """K = C = 0: shifting both bodies by 1 m to 1 km changes nothing physical. Each run
    is ten elastic contacts, each resolved by 200+ steps."""
    system = vi.ImpactDamper(
        main_mass=MAIN_MASS, stiffness=0.0, impact_mass=IMPACT_MASS, clearance=CLEARANCE
    )
    failures = []
    for method in ("newmark-implicit", "generalized-alpha"):
        for offset in (0.0, 1.0, 10.0, 100.0, 1000.0):
            start = vi.InitialState(
                main_displacement=offset,
                impact_displacement=offset,
                impact_velocity=APPROACH_SPEED,
            )
            for dt in np.linspace(4e-4, 6e-4, 11):
                try:
                    sol = vi.simulate(
                        system, ELASTIC_CONTACT, start, method=method, dt=float(dt), t_end=3.0
                    )
                except vi.SimulationError as err:
                    failures.append((method, offset, float(dt), str(err)))
                    continue
                assert sol.contacts.onset[0] == pytest.approx(0.1, rel=1e-6)
    assert failures == []


@pytest.mark.parametrize(
    "settings",
    [{"method": "rk4", "dt": 1e-3, "stepping": "events"}, {"method": "dop853"}],
    ids=["rk4", "dop853"],
)
def test_contacts_faster_than_the_time_resolution_stop_with_a_clear_error(
    settings: dict[str, Any],
) -> None:
    """A 1 nm gap and an absurdly stiff contact (K_hz = 1e30 N/m^1.5): contacts and
    flights of ~1e-13 s follow each other, below the run's time resolution. The run
    must stop at once with a SimulationError (chattering, or a step at round-off), or
    for a fixed step at the first contact, which it cannot resolve; never loop or
    hang."""
    system = vi.ImpactDamper(main_mass=1.0, stiffness=1.0, impact_mass=0.25, clearance=1e-9)
    contact = vi.Contact("hertz", stiffness=1e30)
    start = vi.InitialState(impact_velocity=0.1)
    expected = (
        (vi.NumericalBlowUpError, "cannot resolve")
        if "dt" in settings
        else (vi.SimulationError, "chattering|too small")
    )
    with time_limit(20):
        with pytest.raises(expected[0], match=expected[1]) as err:
            vi.simulate(system, contact, start, t_end=1.0, max_steps=10**7, **settings)
    assert "\n" not in str(err.value)


def test_newton_on_free_flight_takes_one_update_on_the_general_kernel() -> None:
    """The same smooth system as a vibroimpact.System (the general kernel): apart, one
    Newton update solves the linear equations exactly, one residual evaluation a step,
    and one more for the energy accumulators' rates at the step's end (the trapezoidal
    rule), plus one at the start (1 + 3 a step before the general kernel took it)."""
    system = vi.System(
        structure=vi.Oscillator(mass=SMOOTH_M, stiffness=SMOOTH_K, damping=SMOOTH_C),
        dampers=[vi.Damper(mass=0.25, at=0, clearance=1.0, law="hertz", stiffness=HERTZ_STIFFNESS)],
        initial=vi.Initial(structure_displacement=[SMOOTH_W0]),
    )
    for method in ("newmark-implicit", "generalized-alpha"):
        sol = vi.simulate(system, method=method, dt=0.01, t_end=4.0)
        assert sol.steps == 400 and len(sol.contacts) == 0
        assert sol.rhs_evaluations == 1 + 2 * sol.steps


@pytest.mark.parametrize("method", ["newmark-implicit", "generalized-alpha"])
@pytest.mark.timeout(60)
def test_an_implicit_method_holds_a_body_on_its_stop_whatever_its_mass(method: str) -> None:
    # A 0.1 kg oscillator pressed onto a rigid stop: Newton's test scaled by the
    # accelerations and the Jacobian's terms, all round-off while the pair is held, so
    # only a mass whose inverse is exact (a power of two) converged; the run stopped
    # with "Newton iterations did not converge ... reduce dt" (finer steps failed
    # sooner). The same system in units ten times larger (1 kg) had run.
    def run(scale: float, name: str, dt: float) -> Any:
        system = vi.System(
            structure=vi.Oscillator(
                mass=0.1 * scale, stiffness=39478.4 * scale, damping=125.66 * scale
            ),
            stops=[vi.Stop(at=0, side="upper", gap=0.01, law="rigid", restitution=0.7)],
            excitations=[
                vi.Force(at=0, signal=vi.Harmonic(amplitude=2368.7 * scale, frequency=10.0))
            ],
        )
        return vi.simulate(system, method=name, dt=dt, t_end=0.3, history=False)

    reference = run(1.0, "rk4", 1e-5)
    assert any(c.kind == "sticking" for c in reference.contacts.to_pandas().itertuples())
    for scale in (1.0, 3.0, 10.0):
        for dt in (5e-5, 5e-6):
            sol = run(scale, method, dt)
            assert sol.final_time == 0.3
            # The same motion (the implicit methods' error at these steps: 1e-3 of it).
            assert sol.final_state["structure_displacement"][0] == pytest.approx(
                reference.final_state["structure_displacement"][0], rel=2e-2, abs=1e-4
            )
