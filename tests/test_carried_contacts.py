"""Analyses that restart their runs at period boundaries continue a compliant contact
in progress there (its onset, a damped law's latched approach rate) instead of
beginning it afresh: the answers equal one continuous run's.

The forcing's phase of 0.0535 rad puts the stroboscopic instant inside a contact of
the settled orbit; before, steady_state reported 2.1 impacts a period (a contact
counted at both ends of the restart) and an amplitude 32 % high for hertz-damped (the
Hunt-Crossley force latched at mid-contact's slow indentation rate kicked the orbit),
and the Poincare section of a period-1 orbit spread over 1e-3 m.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import vibroimpact as vi
from vibroimpact import analysis as an
from vibroimpact import study as st
from vibroimpact.analysis.parameters import shifted
from vibroimpact.analysis.runs import state_arrays

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
FREQUENCY = 11.5
PERIOD = 1.0 / FREQUENCY


def _sections(law: str, phase: float) -> dict[str, Any]:
    return {
        "structure": {"kind": "oscillator", "mass": 1.0, "stiffness": 3947.8, "damping": 2.513},
        "damper": [
            {
                "mass": 0.05,
                "at": 0,
                "clearance": 0.005,
                "law": law,
                "stiffness": 1e8,
                "restitution": 0.8,
            }
        ],
        "excitation": [
            {
                "kind": "force",
                "at": 0,
                "signal": "harmonic",
                "amplitude": 5.0,
                "frequency": FREQUENCY,
                "phase": phase,
            }
        ],
        "solver": {"method": "dop853"},
    }


def _period_two(
    stiffness: float, forcing: tuple[float, float, float]
) -> tuple[dict[str, Any], Any, an.Orbit]:
    """A hertz-damped damper of ``stiffness`` forced at ``(frequency, amplitude, phase)``
    (Hz, N, rad), settled to a period-2 orbit: the sections, the steady state and the
    orbit shot from it."""
    frequency, amplitude, phase = forcing
    sections = _sections("hertz-damped", phase)
    sections["damper"][0]["stiffness"] = stiffness
    sections["excitation"][0].update(frequency=frequency, amplitude=amplitude)
    run = an.runner(sections)
    settled = an.steady_state(run, settle_periods=400, record_periods=8)
    assert settled.period == 2
    found = an.orbit(run, settled.state, periods=2)
    assert found.converged
    return sections, settled, found


def _continuous(sections: dict[str, Any], settle: int, record: int) -> Any:
    """One run over settle + record periods, recorded over the last ``record``."""
    return vi.simulate_system(
        sections["structure"],
        damper=sections["damper"],
        excitation=sections["excitation"],
        method="dop853",
        t_end=(settle + record) * PERIOD,
        record_from=settle * PERIOD,
        history=False,
    )


@pytest.mark.timeout(120)
@pytest.mark.parametrize(("law", "phase"), [("hertz-damped", 0.0535), ("hyster-hertz", 0.0)])
def test_steady_state_with_its_strobe_inside_a_contact_equals_one_continuous_run(
    law: str, phase: float
) -> None:
    settle, record = 300, 20
    sections = _sections(law, phase)
    run = an.runner(sections)
    # The settled orbit's strobe falls inside a contact (the premise).
    settled = run.periods(run.initial_state(), settle)
    assert any(c is not None for c in settled["open_contacts"])
    steady = an.steady_state(run, settle_periods=settle, record_periods=record)
    one = _continuous(sections, settle, record)
    assert steady.settled and steady.period == 1
    # Located peaks of the same orbit, run in one piece or in two.
    assert steady.amplitude[0] == pytest.approx(one.peak[0], rel=1e-6)
    onsets = np.asarray(one.contacts.onset, dtype=float)
    in_window = int(np.count_nonzero(onsets >= settle * PERIOD))
    assert steady.impacts_per_period == in_window / record == 2.0


@pytest.mark.timeout(120)
def test_a_poincare_section_of_a_period_one_orbit_through_a_contact_is_one_point() -> None:
    run = an.runner(_sections("hertz-damped", 0.0535))
    section = an.poincare(run, settle_periods=300, periods=20)
    strobe = np.asarray(section.strobe)
    assert np.ptp(strobe[:, 0]) < 1e-9 * np.max(np.abs(strobe[:, 0]))


@pytest.mark.timeout(120)
def test_a_run_continued_from_another_carries_its_open_contact() -> None:
    # One run of 12 periods against 7 then 5: the second continues the contact the
    # first left open, its onset before its start by the first's remaining time.
    run = an.runner(_sections("hertz-damped", 0.0535))
    start = np.asarray(run.periods(run.initial_state(), 300)["final_state"])
    whole = run.periods(start, 12)
    first = run.periods(start, 7)
    (carried,) = [c for c in first["open_contacts"] if c is not None]
    approach_rate, onset, approach_speed, depth = carried
    # Its onset relative to the first run's end (before it).
    assert -7 * PERIOD < onset < 0.0 and approach_rate >= approach_speed > 0.0 and depth > 0.0
    second = run.periods(np.asarray(first["final_state"]), 5)
    continued = second["contacts"]
    assert continued["onset"][0] == onset
    assert continued["approach_speed"][0] == approach_speed
    # Counted once: the first run's open record and the second's begun ones make
    # the whole run's contacts, and so does the state at the end.
    begun = int(np.count_nonzero(an.runs.begun(continued)))
    assert len(first["contacts"]["onset"]) + begun == len(whole["contacts"]["onset"])
    scale = np.max(np.abs(whole["final_state"]))
    assert np.allclose(second["final_state"], whole["final_state"], rtol=0, atol=1e-6 * scale)
    # (A fresh start there ends 0.22 m/s off.)
    # From a state no run ended at (given by hand, an ulp away) the contact begins at
    # the start, its approach rate the indentation rate there.
    by_hand = np.array(first["final_state"])
    by_hand[0] = np.nextafter(by_hand[0], 1.0)
    fresh = an.runner(_sections("hertz-damped", 0.0535)).periods(by_hand, 5)
    assert fresh["contacts"]["onset"][0] == 0.0
    assert fresh["contacts"]["approach_speed"][0] < approach_speed


@pytest.mark.timeout(60)
def test_carried_contacts_a_run_cannot_have_left_are_refused() -> None:
    run = an.runner(_sections("hertz-damped", 0.0535))
    system = run.system()
    state = list(run.initial_state())
    with pytest.raises(ValueError, match="one per interaction"):
        system.run(state, PERIOD, carried=[None])
    with pytest.raises(ValueError, match="onset finite and <= 0"):
        system.run(state, PERIOD, carried=[None, [1.0, 0.5, 1.0, 0.0]])


@pytest.mark.timeout(120)
def test_a_sweeps_next_point_continues_the_contact_the_last_left_open() -> None:
    # Each point is a new runner from the last point's state, there inside a contact:
    # the way down repeats the way up's run of 26 periods from 26 T, which one
    # continuous run gives (before: amplitude 5.6e-3 high, 2.04 impacts a period).
    sections = _sections("hertz-damped", 0.0535)
    down = an.sweep(
        sections,
        "excitation.0.frequency",
        [FREQUENCY],
        direction="both",
        settle_periods=0,
        record_periods=26,
    )[1]
    one = _continuous(sections, 26, 26)
    assert down.amplitude[0] == pytest.approx(one.peak[0], rel=1e-6)
    assert down.rms[0] == pytest.approx(one.rms[0], rel=1e-6)
    onsets = np.asarray(one.contacts.onset, dtype=float)
    assert down.impacts_per_period == np.count_nonzero(onsets >= 26 * PERIOD) / 26 == 2.0
    # A bifurcation diagram's second point likewise: its impacts, each once.
    point = an.bifurcation(
        sections,
        "excitation.0.frequency",
        [FREQUENCY],
        direction="both",
        settle_periods=0,
        sample_periods=26,
        sample="impact-velocity",
    )[1]
    speeds = np.asarray(one.contacts.approach_speed)[onsets >= 26 * PERIOD]
    assert np.allclose(np.sort(point.samples), np.sort(speeds), rtol=1e-6, atol=0)


@pytest.mark.timeout(120)
def test_lyapunov_exponents_of_a_periodic_orbit_through_a_contact_at_its_strobe() -> None:
    # A stable period-1 orbit, its strobe inside a contact: its exponents are the
    # Floquet multipliers' ln |mu| / T (the orbit shot with the strobe moved out of the
    # contact by the phase). Before, each block began the contact afresh: +2.1 1/s
    # largest and 408 impacts for 400.
    outside = an.runner(_sections("hertz-damped", 0.2035))
    settled = an.steady_state(outside, settle_periods=300, record_periods=1).state
    multipliers = an.orbit(outside, settled).floquet_multipliers
    exact = np.sort(np.log(np.abs(multipliers)) / PERIOD)[::-1]
    inside = an.lyapunov(an.runner(_sections("hertz-damped", 0.0535)), settle=200, periods=1000)
    assert inside.impacts == 2000
    # Measured: within 0.17 1/s of the exact over 1000 periods, 0.87 over 200 (the
    # strobe outside the contact: 0.08 and 0.28; the tangent of the latched rate is
    # not carried across the blocks).
    assert np.all(np.abs(inside.exponents - exact) < 0.3), (inside.exponents, exact)


@pytest.mark.timeout(120)
def test_an_orbit_whose_section_falls_inside_a_damped_contact_is_shot_on_a_clear_one() -> None:
    # From the settled state at a phase whose strobe is inside a hertz-damped contact,
    # Newton on the map of (x, v) (which begins the contact afresh) had converged to
    # the non-impacting linear orbit: 0 impacts a period, 3.89e-3 m. The section is now
    # moved out of the contact; the orbit is the settled one, its multipliers those of
    # the same orbit shot with the strobe outside the contact.
    inside = an.runner(_sections("hertz-damped", 0.0535))
    settled = an.steady_state(inside, settle_periods=300, record_periods=1)
    found = an.orbit(inside, settled.state)
    assert found.converged and found.impacts_per_period == 2.0
    assert found.amplitude[0] == pytest.approx(settled.amplitude[0], rel=1e-6)
    scale = np.max(np.abs(settled.state))
    # (The settled state is settled to 1e-6 of the motion: 4e-6 measured.)
    assert np.allclose(found.state, settled.state, rtol=0, atol=1e-4 * scale)
    outside = an.runner(_sections("hertz-damped", 0.2035))
    reference = an.orbit(outside, an.steady_state(outside, settle_periods=300).state)
    assert np.allclose(
        np.sort_complex(found.floquet_multipliers),
        np.sort_complex(reference.floquet_multipliers),
        rtol=0,
        atol=1e-6,
    )


def _latching_stop(phase: float) -> dict[str, Any]:
    """A 1 Hz oscillator under a ``hertz-damped`` stop (e = 0.5) forced at 1.2 Hz: its
    period-one orbit presses the stop once a period."""
    return {
        "structure": {
            "kind": "oscillator",
            "mass": 1.0,
            "stiffness": 39.478418,
            "damping": 0.62831853,
        },
        "stop": [
            {
                "at": 0,
                "side": "upper",
                "gap": 0.05,
                "law": "hertz-damped",
                "stiffness": 3000.0,
                "restitution": 0.5,
            }
        ],
        "excitation": [
            {
                "kind": "force",
                "at": 0,
                "signal": "harmonic",
                "amplitude": 1.0,
                "frequency": 1.2,
                "phase": phase,
            }
        ],
        "solver": {"method": "dop853", "rtol": 1e-11, "atol": 1e-14},
    }


@pytest.mark.timeout(120)
def test_an_orbit_found_inside_a_damped_contact_from_a_clear_guess_is_shot_clear() -> None:
    # A physicist's probe: at this phase the section falls 2 % into the orbit's contact,
    # and the guess 1.8 mm outside the wall. The section had been moved only where the
    # guess was inside: Newton converged on the map that begins the contact afresh at
    # the section, a false orbit (x 0.051596 against 0.051841, |mu| 0.4337 against
    # 0.4368), reported converged. Independent values: the settled motion from the same
    # guess, and the multipliers of the orbit shot on a section clear of any contact.
    run = an.runner(_latching_stop(0.5902227891646016))
    guess = np.array([0.0481592, 0.65869533])
    found = an.orbit(run, guess, tolerance=1e-12)
    settled = an.steady_state(run, guess, settle_periods=300, record_periods=10)
    assert found.converged and settled.settled
    assert found.state[0] > 0.05  # inside the stop's contact at the section
    assert np.allclose(found.state, settled.state, rtol=0, atol=1e-6)
    clear = an.orbit(an.runner(_latching_stop(0.0)), np.array([-0.0024, 0.697]), tolerance=1e-12)
    assert np.allclose(
        np.abs(found.floquet_multipliers), np.abs(clear.floquet_multipliers), atol=1e-6
    )


@pytest.mark.timeout(120)
@pytest.mark.parametrize(
    ("stiffness", "path", "stop"),
    [(1e5, "frequency", 12.0), (1e6, "amplitude", 6.0)],
)
def test_a_continuation_whose_section_falls_inside_a_damped_contact_follows_the_orbits(
    stiffness: float, path: str, stop: float
) -> None:
    # A soft contact (1e5 N/m^1.5) lasts 14 % of a period, from 4.7 % of a period before
    # the scenario's section: the continuation shot from (x, v) there (the map begins
    # the contact afresh), and its second point was another map's orbit, 3 impacts a
    # period and 0.107 from the orbit at its frequency (2 impacts). It now moves its
    # section clear of the contacts, and every point is the orbit `orbit` finds at its
    # value. At 1e6 the first point had not been (0.5 % off in amplitude, |mu| 0.889 for
    # 0.892): its state, scaled and back, lost an ulp, and the contact open at the
    # section was begun afresh.
    sections = _sections("hertz-damped", 0.0)
    sections["damper"][0]["stiffness"] = stiffness
    settled = an.steady_state(an.runner(sections), settle_periods=300, record_periods=1)
    contacts = an.runner(sections).periods(settled.state, 1)["contacts"]
    assert np.asarray(contacts["onset"])[0] < 0.0  # the section is inside a contact
    sections["initial"] = state_arrays(settled.state, 1, 1)
    branch = an.continue_orbit(sections, f"excitation.0.{path}", stop=stop, max_points=6)
    assert len(branch.points) == 6
    for point in branch.points:
        at = dict(sections, excitation=[dict(sections["excitation"][0], **{path: point.value})])
        found = an.orbit(an.runner(at), point.state)
        assert found.converged and found.impacts_per_period == point.impacts_per_period == 2.0
        scale = np.max(np.abs(found.state))
        assert np.allclose(point.state, found.state, rtol=0, atol=1e-6 * scale)
        assert point.amplitude[0] == pytest.approx(found.amplitude[0], rel=1e-6)
        assert np.allclose(
            np.sort(np.abs(point.floquet_multipliers)),
            np.sort(np.abs(found.floquet_multipliers)),
            rtol=0,
            atol=1e-6,
        )


@pytest.mark.timeout(120)
@pytest.mark.parametrize(("path", "step"), [("amplitude", 0.01), ("frequency", 1e-4)])
def test_an_orbits_derivatives_through_a_section_inside_a_damped_contact(
    path: str, step: float
) -> None:
    # The orbit's state at a section 4.7 % of a period into a hertz-damped contact: the
    # implicit function theorem on the map of (x, v) there (which begins the contact
    # afresh) had given the damper's velocity's derivative in the amplitude 3 times too
    # large and the amplitude's 16 % small. Now equal to central differences of the
    # orbits themselves.
    sections = _sections("hertz-damped", 0.0)
    sections["damper"][0]["stiffness"] = 1e5
    run = an.runner(sections)
    found = an.orbit(run, an.steady_state(run, settle_periods=300, record_periods=1).state)
    key = f"excitation.0.{path}"
    derivative = an.orbit_derivatives(sections, found, [key])[key]
    value = sections["excitation"][0][path]
    sides = []
    for shift in (step, -step):
        at = dict(sections, excitation=[dict(sections["excitation"][0], **{path: value + shift})])
        sides.append(an.orbit(an.runner(at), found.state))
    differences = (sides[0].state - sides[1].state) / (2 * step)
    scale = np.max(np.abs(differences))
    assert np.allclose(derivative.state, differences, rtol=0, atol=1e-4 * scale)
    amplitude = (sides[0].amplitude - sides[1].amplitude) / (2 * step)
    assert derivative.amplitude == pytest.approx(amplitude, rel=1e-4)


@pytest.mark.timeout(120)
def test_an_orbit_shot_on_a_moved_section_reports_the_monodromy_of_its_own() -> None:
    # The orbit's state is on the scenario's section (inside a contact); its monodromy
    # had been the moved section's (the same multipliers, another matrix). Now the
    # scenario's section's: as differences of continuous runs from a clear instant
    # through that section and one period on, M = D(two) D(one)^-1.
    sections = _sections("hertz-damped", 0.0)
    sections["damper"][0]["stiffness"] = 1e5
    run = an.runner(sections)
    found = an.orbit(run, an.steady_state(run, settle_periods=300, record_periods=1).state)
    fraction = 0.3
    clear = an.runner(shifted(sections, fraction))
    start = np.asarray(
        run._run(found.state, fraction * PERIOD, record=False, strobe=False)["final_state"]
    )

    def after(z: np.ndarray, periods: float) -> np.ndarray:
        end = clear._run(z, (periods - fraction) * PERIOD, record=False, strobe=False)[
            "final_state"
        ]
        return np.asarray(end, dtype=float)

    one, two = np.zeros((4, 4)), np.zeros((4, 4))
    for j in range(4):
        e = np.zeros(4)
        e[j] = 1e-7 * max(abs(start[j]), 1e-3)
        one[:, j] = after(start + e, 1) - after(start - e, 1)
        two[:, j] = after(start + e, 2) - after(start - e, 2)
    expected = two @ np.linalg.inv(one)
    scale = np.max(np.abs(expected))
    assert np.allclose(found.monodromy, expected, rtol=0, atol=1e-5 * scale)


@pytest.mark.timeout(120)
@pytest.mark.parametrize("phase", [0.0, 2.0])
def test_an_orbit_studys_section_inside_a_damped_contact_is_moved_clear(phase: float) -> None:
    # At phase 0 the settled state is 4.7 % of a period into a hertz-damped contact: the
    # core's orbit study shot from (x, v) there (the contact begun afresh) and reported 3
    # impacts a period for 2, the largest multiplier 0.852 for 0.894 and an amplitude
    # 13 % high. It now shoots on a section clear of the contact: the orbit `orbit`
    # finds, as at phase 2 (strobe outside the contacts).
    sections = _sections("hertz-damped", phase)
    sections["damper"][0]["stiffness"] = 1e5
    run = an.runner(sections)
    found = an.orbit(run, an.steady_state(run, settle_periods=300, record_periods=1).state)
    metrics = ["amplitude", "impacts_per_period", "stable", "largest_multiplier"]
    study = st.study_of(
        dict(
            sections,
            solver={"method": "dop853", "t_end": 1.0},
            study={
                "analysis": "orbit",
                "settle_periods": 300,
                "metrics": metrics,
                "axes": {"excitation.0.amplitude": [5.0]},
            },
        )
    )
    point = study.run_chunk(range(1), threads=1)
    assert int(np.asarray(point["status"])[0]) == 0
    assert float(np.asarray(point["impacts_per_period"])[0]) == found.impacts_per_period == 2.0
    largest = float(np.max(np.abs(found.floquet_multipliers)))
    assert float(np.asarray(point["largest_multiplier"])[0]) == pytest.approx(largest, abs=1e-6)
    amplitude = float(np.asarray(point["peak"]).ravel()[0])
    assert amplitude == pytest.approx(found.amplitude[0], rel=1e-6)


@pytest.mark.timeout(120)
def test_a_two_period_orbit_through_damped_contacts_keeps_its_own_point() -> None:
    # A period-2 orbit whose two points on the section are both inside hertz-damped
    # contacts: orbit had returned the other point (one period on from the moved
    # section), and orbit_derivatives carried the derivative there, 100 % off the
    # derivative of the orbit's own point. Now the orbit's own point (the settled
    # state's), and its derivative equal to central differences of the orbits.
    sections, settled, found = _period_two(1e6, (10.5, 6.0, 5.760))
    scale = np.max(np.abs(found.state))
    assert np.allclose(found.state, settled.state, rtol=0, atol=1e-4 * scale)
    key, step = "excitation.0.amplitude", 6e-4
    derivative = an.orbit_derivatives(sections, found, [key])[key]
    sides = []
    for shift in (step, -step):
        at = dict(sections, excitation=[dict(sections["excitation"][0], amplitude=6.0 + shift)])
        sides.append(an.orbit(an.runner(at), found.state, periods=2, tolerance=1e-12).state)
    differences = (sides[0] - sides[1]) / (2 * step)
    size = np.max(np.abs(differences))
    assert np.allclose(derivative.state, differences, rtol=0, atol=2e-3 * size)


@pytest.mark.timeout(120)
def test_a_damped_contact_landing_below_its_floor_has_the_monodromy_of_differences() -> None:
    # A period-2 orbit one of whose contacts lands slower than the pressing's rate: its
    # law latches the floor sqrt(2 a delta_s), which moves with the state through the
    # pressing. The tangent flow had given that onset no derivative (a grazing): the
    # monodromy 24 % off central differences of the map, |mu| 0.579 for 0.144. Now the
    # floor's derivative is carried, and the monodromy is the differences'.
    sections, _, found = _period_two(1e5, (11.0, 15.0, 0.5236))
    run, z = an.runner(sections), found.state
    contacts = run.periods(z, 2)["contacts"]
    assert np.all(np.asarray(contacts["onset"]) > 0.0)  # the section is clear
    differences = np.zeros((4, 4))
    for j in range(4):
        e = np.zeros(4)
        e[j] = 1e-7 * max(abs(z[j]), 1e-3)
        ends = [np.asarray(run.periods(z + s * e, 2)["final_state"]) for s in (1.0, -1.0)]
        differences[:, j] = (ends[0] - ends[1]) / (2 * e[j])
    scale = np.max(np.abs(differences))
    assert np.allclose(found.monodromy, differences, rtol=0, atol=1e-5 * scale)


@pytest.mark.timeout(180)
@pytest.mark.parametrize(
    ("key", "relative_step"),
    [("excitation.0.amplitude", 1e-4), ("damper.0.stiffness", 1e-4), ("damper.0.mass", 1e-5)],
)
def test_an_orbit_through_a_floor_onset_has_the_parameter_derivative_of_differences(
    key: str, relative_step: float
) -> None:
    # The floor sqrt(2 a delta_s) the contact landing slower than the pressing latches
    # moves with a parameter too: through the law's stiffness, the damper's mass and
    # the pressing. Without that term the orbit's derivative was 1.8 % off central
    # differences of the orbits in the amplitude, 17 % in the contact stiffness and
    # 4.1 % in the damper's mass; with it, to a few 1e-7.
    sections, _, found = _period_two(1e5, (11.0, 15.0, 0.5236))
    section, _, field = key.split(".")
    table = "excitation" if section == "excitation" else "damper"
    base = float(sections[table][0][field])
    step = relative_step * base
    derivative = an.orbit_derivatives(sections, found, [key])[key]
    sides = []
    for shift in (step, -step):
        moved = dict(sections[table][0], **{field: base + shift})
        at = dict(sections, **{table: [moved, *sections[table][1:]]})
        sides.append(an.orbit(an.runner(at), found.state, periods=2, tolerance=1e-12).state)
    differences = (sides[0] - sides[1]) / (2 * step)
    size = np.max(np.abs(differences))
    assert np.allclose(derivative.state, differences, rtol=0, atol=1e-5 * size)


def _one_contact_a_period(law: str, phase: float) -> dict[str, Any]:
    """A 1 Hz oscillator (5 % damping) under a stop of ``law`` 10 mm above rest, forced
    at 1.6 Hz: one contact a period; a ``phase`` of 0.482 rad puts t = 0 inside it."""
    stop: dict[str, Any] = {"at": 0, "side": "upper", "gap": 0.01, "law": law}
    stop.update({"stiffness": 1e5} if law == "hertz" else {"stiffness": 2000.0, "damping": 2.0})
    force = {"kind": "force", "at": 0, "signal": "harmonic", "amplitude": 1.0}
    return {
        "structure": {
            "kind": "oscillator",
            "mass": 1.0,
            "stiffness": 39.47841760435743,
            "damping": 0.6283185307179586,
        },
        "stop": [stop],
        "excitation": [{**force, "frequency": 1.6, "phase": phase}],
        "solver": {"method": "dop853", "rtol": 1e-12, "atol": 1e-15},
    }


@pytest.mark.timeout(120)
@pytest.mark.parametrize("law", ["hertz", "linear"])
def test_an_orbit_through_a_contact_at_its_section_counts_each_contact_once(law: str) -> None:
    # A law that latches no approach rate keeps its section inside the contact: its run
    # from there had counted the contact in progress at t = 0 as one begun, 2 impacts a
    # period for 1 (and 4 for 3 over 3 periods; a probe of the tangent analyses). The
    # same orbit with its section outside the contact (phase 0) counts 1.
    outside = an.runner(_one_contact_a_period(law, 0.0))
    reference = an.orbit(outside, an.steady_state(outside, settle_periods=60).state)
    assert reference.converged and reference.impacts_per_period == 1.0
    inside = an.runner(_one_contact_a_period(law, 0.4819615307562894))
    start = an.steady_state(inside, settle_periods=60).state
    for periods in (1, 3):
        found = an.orbit(inside, start, periods=periods)
        assert found.converged and found.impacts_per_period == 1.0, (periods, found)
    # Its multipliers are the phase-shifted orbit's (one orbit, another section).
    np.testing.assert_allclose(
        np.sort_complex(found.floquet_multipliers),
        np.sort_complex(reference.floquet_multipliers**3),
        rtol=1e-6,
    )
    # The run from a state inside a contact no run began says so: onset -0.0. (No run
    # kept in this process: the orbit's own recording may end on its state to the bit,
    # whose open contact a run from there would continue.)
    an.runs._CARRIED.clear()
    raw = inside.periods(found.state, 1)
    assert np.signbit(raw["contacts"]["onset"][0]) and raw["contacts"]["onset"][0] == 0.0
    assert list(an.runs.begun(raw["contacts"])) == [False, True]


@pytest.mark.timeout(120)
def test_lyapunov_counts_a_stick_across_its_blocks_cuts_once() -> None:
    # A plastic damper (e = 0) sticks after each of its two impacts a period, and a stick
    # spans each cut between the spectrum's blocks: the next block found it again at its
    # start, a landing at 1e-8 m/s, and counted it as an impact (2,010 for 1,000 periods,
    # 210 for 100). The independent count: the impacts one continuous run records over
    # the same periods from the same settled state.
    system = vi.load(EXAMPLES / "frf_impact_damper.toml")
    damper = dataclasses.replace(system.dampers[0], restitution=0.0)
    system = system.replace(dampers=[damper])
    found = vi.lyapunov(system, settle=100, periods=100)
    run = an.lyapunov_runner(system)
    settled = run.map(run.initial_state(), 100)
    whole = run.periods(settled, 100, record=True)
    kinds = list(whole["contacts"]["kind"])
    assert found.impacts == kinds.count("impact") == 200
