"""Several pairs at one point: contacts that start at the same instant, impacts of
several pairs at once, and the sticking phases they lead to, by every method. Found
by fuzzing random forced systems (tests/fuzz_events.py); each test failed before
its fix."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from vibroimpact.system import simulate_system

OSCILLATOR = {"kind": "oscillator", "mass": 1.0, "stiffness": 3947.8, "damping": 2.513}


def forced(amplitude: float, frequency: float) -> list[dict[str, Any]]:
    return [
        {
            "kind": "force",
            "at": 0,
            "signal": "harmonic",
            "amplitude": amplitude,
            "frequency": frequency,
        }
    ]


def first_reach(amplitude: float, frequency: float, level: float) -> float:
    """When the oscillator alone, forced from rest, first reaches `level` (m): SciPy
    at tight tolerance, with an event (the dampers at rest at the centre do not
    touch it before)."""
    m, k, c = OSCILLATOR["mass"], OSCILLATOR["stiffness"], OSCILLATOR["damping"]
    w = 2 * np.pi * frequency

    def rates(t: float, y: np.ndarray) -> list[float]:
        return [y[1], (amplitude * np.cos(w * t) - c * y[1] - k * y[0]) / m]

    def reach(t: float, y: np.ndarray) -> float:
        return float(y[0] - level)

    reach.terminal = True  # type: ignore[attr-defined]
    reach.direction = 1  # type: ignore[attr-defined]
    sol = solve_ivp(rates, (0, 1), [0, 0], rtol=1e-12, atol=1e-15, events=reach)
    return float(sol.t_events[0][0])


def runs_to_the_end(method: str, t_end: float, residual: float, **kw: Any) -> Any:
    """The oscillator with `kw` (dampers, stops, excitation) by `method` to `t_end`
    (s), checked to get there with its energy balance closing to `residual` of the
    input work."""
    run = simulate_system(OSCILLATOR, method=method, t_end=t_end, history=False, **kw)
    assert run.final_time == t_end
    energy = run.energy
    assert abs(energy["residual"]) < residual * energy["input_work"]
    return run


@pytest.mark.parametrize("method", ["rk4", "dop853", "dopri5", "newmark-implicit"])
def test_two_hertz_dampers_touching_at_one_instant_both_start_their_contacts(
    method: str,
) -> None:
    """Two Hertz dampers at rest at the centre of equal clearances: the structure
    reaches both walls at one instant. Only the located one used to switch; the
    other, on its wall to round-off, was found at the next step's start, and the
    first one's contact, begun a hair before its wall, then read as ending:
    'chattering ... 2.2e-14 s apart' (rk4 at 7.4 ms)."""
    amplitude, frequency, clearance = 19.47, 13.79, 0.0005
    dampers = [
        {"mass": 0.0296, "at": 0, "clearance": clearance, "law": "hertz", "stiffness": 5.94e7},
        {"mass": 0.1247, "at": 0, "clearance": clearance, "law": "hertz", "stiffness": 3.07e6},
    ]
    run = simulate_system(
        OSCILLATOR,
        damper=dampers,
        excitation=forced(amplitude, frequency),
        method=method,
        t_end=0.5,
        history=False,
        **({"dt": 1e-5} if method in ("rk4", "newmark-implicit") else {}),
    )
    assert run.final_time == 0.5
    onset, pair = np.asarray(run.contacts.onset), np.asarray(run.contacts.pair)
    first = [onset[pair == name][0] for name in ("damper 0", "damper 1")]
    touch = first_reach(amplitude, frequency, clearance)
    # The adaptive methods locate the touch on their own solution (rtol 1e-9).
    assert first == pytest.approx([touch, touch], abs=1e-9)
    energy = run.energy
    assert abs(energy["residual"]) < 1e-4 * energy["input_work"]


def test_implicit_newmark_holds_a_sticking_damper_whose_accelerations_vanish() -> None:
    """A plastic damper sticking to its oscillator, implicit Newmark: when the
    pair's accelerations pass through zero, Newton's iterations were judged against
    the accelerations alone and could not reach 1e-12 of zero ('Newton iterations did
    not converge', t = 0.084 s). They are now judged against the equation's terms.
    The run agrees with the exact flow to second order in the step."""
    kw: dict[str, Any] = {
        "damper": [
            {"mass": 0.18707655596023412, "at": 0, "clearance": 0.0005, "law": "rigid"}
            | {"restitution": 0.0}
        ],
        "excitation": forced(29.754963756026775, 14.619026726518346),
        "t_end": 0.5,
        "history": False,
    }
    exact = simulate_system(OSCILLATOR, **kw, method="exact")
    errors = []
    for dt in (1e-4, 5e-5):
        run = simulate_system(OSCILLATOR, **kw, method="newmark-implicit", dt=dt)
        assert list(run.contacts.kind) == list(exact.contacts.kind)
        assert "sticking" in list(run.contacts.kind)
        errors.append(
            abs(
                run.final_state["structure_displacement"][0]
                - exact.final_state["structure_displacement"][0]
            )
        )
    assert errors[0] < 1e-6
    assert errors[0] / errors[1] > 3.0  # second order: 4


@pytest.mark.parametrize("restitution", [0.0, 0.5, 1.0])
@pytest.mark.parametrize("method", ["exact", "dop853", "rk4", "newmark-implicit"])
def test_a_mass_striking_two_dampers_at_once_obeys_newtons_law_for_both(
    method: str, restitution: float
) -> None:
    """A free 1 kg mass at 1 m/s reaches two resting 0.1 kg dampers at one instant.
    Newton's law for both contacts at once (the complementarity problem) gives each
    damper the impulse (1 + e) v / (1/m + 2/M): both leave at e v relative to the
    mass. Applied one after the other, the first damper took (1 + e) v / (1/m + 1/M)
    and the second less (1.36 and 1.18 m/s instead of 1.25 for e = 0.5)."""
    big, small, speed, clearance = 1.0, 0.1, 1.0, 0.001
    damper = {"mass": small, "at": 0, "clearance": clearance, "law": "rigid"}
    run = simulate_system(
        {"kind": "oscillator", "mass": big, "stiffness": 0.0},
        damper=[{**damper, "restitution": restitution}] * 2,
        initial={"structure_velocity": [speed]},
        method=method,
        # Before the dampers cross their clearances to the far walls.
        t_end=clearance / speed + 1e-3,
        history=False,
        **({"dt": 1e-4} if method in ("rk4", "newmark-implicit") else {}),
    )
    impulse = (1 + restitution) * speed / (1 / small + 2 / big)
    final = run.final_state
    assert final["damper_velocity"] == pytest.approx([impulse / small] * 2, rel=1e-12)
    assert final["structure_velocity"][0] == pytest.approx(speed - 2 * impulse / big, rel=1e-12)
    kinds = list(run.contacts.kind)
    assert kinds == ["impact", "impact"]
    assert np.asarray(run.contacts.onset) == pytest.approx([clearance / speed] * 2, rel=1e-12)
    before = 0.5 * big * speed**2
    after = 0.5 * big * (speed - 2 * impulse / big) ** 2 + impulse**2 / small
    lost = float(np.sum(run.contacts.energy_dissipated))
    assert lost == pytest.approx(before - after, rel=1e-9, abs=1e-15)
    assert np.asarray(run.contacts.restitution) == pytest.approx([restitution] * 2, abs=1e-12)


def test_two_dampers_settling_on_one_wall_accumulate_and_rest_together() -> None:
    """Two rigid dampers settling on their lower walls of one forced oscillator
    (exact flow; found by fuzzing): each plastic landing kicks the structure and
    launches the other, whose landing launches the first again, the flights
    falling by the mass ratio each time. The run used to stop, after 8 such
    landings 1e-9 s apart, as 'chattering at t = 6.64 s'. A lift-off by less than
    the resolution is now summed, the pair held, and the run goes on."""
    damper = {"mass": 0.1688, "at": 0, "clearance": 0.0005, "law": "rigid", "restitution": 0.3}
    stop = {"at": 0, "side": "upper", "gap": 0.00567497129924516, "law": "rigid"}
    run = runs_to_the_end(
        "exact",
        10.0,
        1e-8,
        damper=[
            {**damper, "mass": 0.16884397816396696},
            {**damper, "mass": 0.15903138441417722},
        ],
        stop=[{**stop, "restitution": 0.5}],
        excitation=forced(26.35036061947917, 8.188928741641144),
    )
    kinds, pairs = np.asarray(run.contacts.kind), np.asarray(run.contacts.pair)
    for name in ("damper 0", "damper 1"):
        assert "sticking" in kinds[pairs == name]


def test_a_rebound_too_short_for_the_step_is_found_after_another_pairs_event() -> None:
    """dop853, two rigid dampers (found by fuzzing): damper 0 rebounds from a wall at
    1.8 mm/s, a flight of microseconds in a step of 8.6 ms that the interpolant
    cannot see. Damper 1's event cut the step later; damper 0, past its wall by
    then, was located from the step's start, where it sat on the wall leaving it:
    the event was put at the start again and again ('chattering at t = 2.0956 s').
    Shorter probes now find a point of the flight to bracket its landing from."""
    dampers = [
        {"mass": 0.1445470700878202, "at": 0, "clearance": 0.0005, "law": "rigid"},
        {"mass": 0.19805409785681555, "at": 0, "clearance": 0.003, "law": "rigid"},
    ]
    # The step's cap, 1e-3 t_end, is what made the rebound too short for it.
    run = runs_to_the_end(
        "dop853",
        10.0,
        1e-6,
        damper=[{**dampers[0], "restitution": 0.6}, {**dampers[1], "restitution": 1.0}],
        excitation=forced(29.143731101830376, 9.884406268804401),
    )
    assert len(run.contacts.kind) > 1000


def test_a_plastic_landing_with_no_pressing_yet_is_not_found_again_without_end() -> None:
    """Exact flow, a plastic damper, a second damper and a stop (found by fuzzing):
    damper 0 lands plastically at an instant when its wall's pull turns, so it sits
    exactly on the wall (gap 0, rate 0) neither pressed nor leaving. It was found
    again at once at the same instant, without end ('chattering at t = 5.62 s'). A
    touch at rest and not pressed, on the wall or past it, is now put a few units of
    round-off off the wall; it lands at rest, and sticks, once pressed."""
    dampers = [
        {"mass": 0.06772191308601166, "at": 0, "clearance": 0.0005, "law": "rigid"},
        {"mass": 0.09730589585434458, "at": 0, "clearance": 0.01, "law": "rigid"},
    ]
    stop = {"at": 0, "side": "upper", "gap": 0.0013707396460258272, "law": "rigid"}
    runs_to_the_end(
        "exact",
        10.0,
        1e-8,
        damper=[{**dampers[0], "restitution": 0.0}, {**dampers[1], "restitution": 0.6}],
        stop=[{**stop, "restitution": 0.5}],
        excitation=forced(8.279043125879216, 6.6121596473149635),
    )


def test_a_system_come_to_rest_on_its_walls_goes_on() -> None:
    """Exact flow, a plastic damper and a plastic stop (found by fuzzing): the
    structure stuck on its stop and the damper on its wall bring everything to rest
    at once, every speed round-off (1e-16 m/s). A damper past its wall by round-off,
    'leaving' or 'arriving' at such speeds, was found again at every step
    ('chattering at t = 4.2 s', then at 8.43 s). A rate that would take the system's
    time scale to move a gap by its round-off is now at rest, whatever the other
    speeds."""
    run = runs_to_the_end(
        "exact",
        10.0,
        1e-8,
        damper=[
            {"mass": 0.07193791018257657, "at": 0, "clearance": 0.0005, "law": "rigid"}
            | {"restitution": 0.0}
        ],
        stop=[
            {"at": 0, "side": "lower", "gap": 0.0010704076589561416, "law": "rigid"}
            | {"restitution": 0.0}
        ],
        excitation=forced(11.751122402454829, 10.401324381194478),
    )
    pairs, kinds = np.asarray(run.contacts.pair), np.asarray(run.contacts.kind)
    assert "sticking" in kinds[pairs == "stop 0"] and "sticking" in kinds[pairs == "damper 0"]


def test_a_sticking_pair_with_no_force_left_is_released() -> None:
    """dopri5, a Hertz and a plastic damper and a plastic stop, sampled every period
    (found by fuzzing): the structure sticking on its stop was found to release
    where its constraint force was exactly zero (-0.0) at the step's start, but
    another pair's touch at the same instant took the event, and the stop, its
    force not below zero, was kept sticking and found again at once, without end
    ('chattering at t = 4.41 s'). A sticking pair with no force holding it is
    released with the others at the instant."""
    damper = {"at": 0, "clearance": 0.0005}
    runs_to_the_end(
        "dopri5",
        10.0,
        1e-5,
        damper=[
            {**damper, "mass": 0.11852494089604164, "law": "hertz", "stiffness": 2803170.870139846},
            {**damper, "mass": 0.06677492790643907, "law": "rigid", "restitution": 0.0},
        ],
        stop=[
            {"at": 0, "side": "lower", "gap": 0.008925610132667024, "law": "rigid"}
            | {"restitution": 0.0}
        ],
        excitation=forced(24.59992253737289, 10.350754504853889),
        strobe_period=0.0966113146177952,
    )


@pytest.mark.parametrize("method", ["exact", "dop853", "dopri5", "rk4", "newmark-implicit"])
def test_two_dampers_with_no_clearance_move_as_one_body_with_the_structure(method: str) -> None:
    """Two plastic dampers with zero clearance on a forced oscillator (found by a
    review): once a damper stuck on one wall, its other wall, touching at rest
    with a pressing of round-off, was stuck too; the two dependent constraints
    made the sticking forces' system singular, and partial pivoting dropped the
    other damper's row, which then passed 2.5 cm through its wall with 7 % of the
    energy unaccounted, and no error. And where the force passed from one wall to
    the other, round-off released and re-stuck the walls without end (rk4,
    newmark-implicit: 'chattering'); a damper with no clearance, once stuck, is now
    locked to its point, its force of either sign. The three bodies move as one:
    mass 1.15 kg on the oscillator's spring and damper (SciPy at tight tolerance)."""
    damper = {"at": 0, "clearance": 0.0, "law": "rigid", "restitution": 0.0}
    amplitude, frequency = 10.0, 8.0
    run = simulate_system(
        OSCILLATOR,
        damper=[{**damper, "mass": 0.1}, {**damper, "mass": 0.05}],
        excitation=forced(amplitude, frequency),
        method=method,
        t_end=1.0,
        history=True,
        **({"dt": 1e-4} if method in ("rk4", "newmark-implicit") else {}),
    )
    x = np.asarray(run.structure_displacement)[:, 0]
    relative = np.asarray(run.damper_displacement) - x[:, None]
    assert np.abs(relative).max() < 1e-9
    total, k, c = 1.15, OSCILLATOR["stiffness"], OSCILLATOR["damping"]
    w = 2 * np.pi * frequency
    one_body = solve_ivp(
        lambda t, y: [y[1], (amplitude * np.cos(w * t) - c * y[1] - k * y[0]) / total],
        (0, 1.0),
        [0.0, 0.0],
        rtol=1e-12,
        atol=1e-15,
        dense_output=True,
    )
    # To the adaptive methods' tolerance (rtol 1e-9, over 8 forcing periods), or
    # the fixed steps' error (newmark-implicit, second order at dt 1e-4: 1e-3).
    error = 1e-3 if method == "newmark-implicit" else 1e-7
    assert x == pytest.approx(one_body.sol(np.asarray(run.t))[0], abs=error * np.abs(x).max())
    energy = run.energy
    # Newmark's accumulators follow the trapezoidal rule: second order too.
    assert (
        abs(energy["residual"])
        < (10 if method == "newmark-implicit" else 1) * 1e-6 * energy["input_work"]
    )


def test_a_crossing_behind_two_simultaneous_touches_is_located() -> None:
    """dop853, three dampers (found by a review): two dampers reached their walls
    together at an event's cut, and the search for a pair that crossed earlier in
    the step kept finding those two, on their walls to round-off, never the third,
    which had crossed before: it was resolved late, 0.13 mm past its wall. Only a
    pair past its wall beyond round-off now counts as having crossed first."""
    damper = {"at": 0, "law": "rigid"}
    run = simulate_system(
        OSCILLATOR,
        damper=[
            {**damper, "mass": 0.061246510405959007, "clearance": 0.003, "restitution": 0.0},
            {**damper, "mass": 0.11718249301492117, "clearance": 0.003, "restitution": 0.0},
            {**damper, "mass": 0.16651546906983242, "clearance": 0.0005, "restitution": 1.0},
        ],
        excitation=forced(17.400933626643578, 9.834499085400061),
        method="dop853",
        t_end=3.0,
        history=True,
    )
    relative = np.asarray(run.damper_displacement) - np.asarray(run.structure_displacement)
    assert (np.abs(relative) - [0.003, 0.003, 0.0005]).max() < 1e-12


def test_a_sticking_released_before_its_accumulation_instant_ends_there() -> None:
    """rk4 at dt 1e-4, base-excited, a rigid and two Hertz dampers (found by a
    review and by fuzzing): a summed chattering sequence's sticking starts at its
    accumulation instant, up to a step after the impact where the sum is made; a
    release before that instant gave a sticking record ending 8e-6 s before it
    began. It now ends there, with no duration."""
    damper = {"at": 0}
    run = simulate_system(
        OSCILLATOR,
        damper=[
            {**damper, "mass": 0.1521614122245563, "clearance": 0.01}
            | {"law": "rigid", "restitution": 0.3},
            {**damper, "mass": 0.18195048845544462, "clearance": 0.01}
            | {"law": "hertz", "stiffness": 813817.0414405251},
            {**damper, "mass": 0.19981491764154813, "clearance": 0.0005}
            | {"law": "hertz", "stiffness": 35247925.79987347},
        ],
        excitation=[
            {"kind": "base", "signal": "harmonic", "amplitude": 19.27921490786087}
            | {"frequency": 8.626968570578484}
        ],
        method="rk4",
        dt=1e-4,
        t_end=10.0,
        history=False,
    )
    onset, separation = np.asarray(run.contacts.onset), np.asarray(run.contacts.separation)
    ended = np.isfinite(separation)
    assert "sticking" in list(run.contacts.kind)
    assert (separation[ended] >= onset[ended]).all()
    assert (np.asarray(run.contacts.duration)[ended] >= 0).all()


FIXED_STEP = {"rk4": 1e-4, "newmark-implicit": 1e-4}
# Each method's error here, relative to the amplitude: exact to round-off, the
# adaptive ones to their tolerance, the fixed steps to their order at dt 1e-4.
ACCURACY = {"exact": 1e-9, "dop853": 1e-5, "dopri5": 1e-5, "rk4": 1e-6, "newmark-implicit": 1e-3}


@pytest.mark.parametrize("method", ["exact", "dop853", "rk4", "newmark-implicit"])
def test_a_locked_damper_is_not_released_by_another_dampers_impact(method: str) -> None:
    """A damper with no clearance is a mass fixed to its point (found by a review):
    another damper's impact at the instant it stuck pulled the structure off its
    sticking wall, and it was released, then struck its other wall zero away,
    again and again ('chattering at t = 0.087 s' for e = 0.8; 16 impacts that
    never were for e = 0). The run matches the 1.1 kg oscillator with only the
    rattling damper."""
    rattling = {"at": 0, "clearance": 0.003, "law": "rigid", "restitution": 0.8, "mass": 0.05}
    excitation = forced(10.0, 8.0)
    step = {"dt": FIXED_STEP[method]} if method in FIXED_STEP else {}
    reference = simulate_system(
        {**OSCILLATOR, "mass": 1.1},
        damper=[rattling],
        excitation=excitation,
        method="exact",
        t_end=1.0,
        history=False,
    )
    for restitution in (0.8, 0.0):
        locked = {"at": 0, "clearance": 0.0, "law": "rigid", "mass": 0.1}
        run = simulate_system(
            OSCILLATOR,
            damper=[{**locked, "restitution": restitution}, rattling],
            excitation=excitation,
            method=method,
            t_end=1.0,
            history=False,
            **step,
        )
        pairs, kinds = np.asarray(run.contacts.pair), np.asarray(run.contacts.kind)
        assert list(kinds[pairs == "damper 0"]) == ["sticking"]
        x, expected = (
            state["structure_displacement"][0] for state in (run.final_state, reference.final_state)
        )
        # The amplitude is about 1 cm; newmark-implicit's error over 8 periods
        # with the rattling damper's impacts, second order at dt 1e-4: 1 %.
        tolerance = {"exact": 1e-9, "dop853": 1e-4, "rk4": 1e-6, "newmark-implicit": 2e-2}
        assert abs(x - expected) < tolerance[method] * 0.01


@pytest.mark.parametrize("method", ["exact", "dop853", "dopri5", "rk4", "newmark-implicit"])
def test_a_damper_with_no_clearance_started_moving_joins_its_structure_at_once(
    method: str,
) -> None:
    """No clearance, e = 0.8, the damper started at 0.1 m/s relative to its
    structure (found by a review): the rebounds between two walls zero apart add up
    at t = 0, to moving together with momentum conserved, 0.015 / 1.15 m/s; it used
    to stop as 'chattering at t = 4.9e-78 s'. The two then oscillate as one body:
    x = v0 / w sin(w t), w = sqrt(k / 1.15)."""
    stiffness, speed = 3947.8, 0.015 / 1.15
    run = simulate_system(
        {"kind": "oscillator", "mass": 1.0, "stiffness": stiffness, "damping": 0.0},
        damper=[{"at": 0, "clearance": 0.0, "law": "rigid", "restitution": 0.8, "mass": 0.15}],
        initial={"damper_velocity": [0.1]},
        method=method,
        t_end=0.5,
        history=True,
        **({"dt": FIXED_STEP[method]} if method in FIXED_STEP else {}),
    )
    w = np.sqrt(stiffness / 1.15)
    x, t = np.asarray(run.structure_displacement)[:, 0], np.asarray(run.t)
    assert np.abs(x - speed / w * np.sin(w * t)).max() < ACCURACY[method] * speed / w
    assert list(run.contacts.kind) == ["sticking"]
    assert run.contacts.onset[0] < 1e-12
