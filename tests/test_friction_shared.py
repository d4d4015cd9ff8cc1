"""Friction elements that share a carrier (issue 27, from a new user's probe): a stuck
damper's slip where another friction damper slides on the same structure, a structure
held by its own friction element carrying a stuck damper, two dampers thrown apart on
one carrier, the names of the pairs, and a study whose runs differ in their friction
elements. Each is checked against an independent value: a run of another method at a
tight tolerance, the state at rest, or the closed form of a block sliding to rest."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import vibroimpact as vi
from study_checks import load_study
from vibroimpact import study as st


def _two_friction_dampers() -> vi.System:
    """A forced oscillator carrying two rigid dampers that rub on it; the heavier
    (static 0.9 x 1.34 N) sticks, slips where the force holding it passes 1.206 N while
    the lighter slides, and sticks again."""
    return vi.System(
        structure=vi.Oscillator(mass=1.0, stiffness=3371.0, damping=2.85),
        dampers=[
            vi.Damper(
                mass=0.047,
                at=0,
                clearance=0.01,
                law="rigid",
                restitution=0.5,
                friction=0.34,
                normal_force=0.24,
            ),
            vi.Damper(
                mass=0.059,
                at=0,
                clearance=0.01,
                law="rigid",
                restitution=0.5,
                friction=0.48,
                static_friction=0.9,
                normal_force=1.34,
            ),
        ],
        excitations=[vi.Force(at=0, signal=vi.Harmonic(amplitude=6.67, frequency=7.54))],
    )


def _stuck_intervals(sol: Any, pair: str) -> list[tuple[float, float]]:
    table = sol.contacts
    return [
        (float(table.onset[i]), float(table.duration[i]))
        for i in range(len(table))
        if table.pair[i] == pair and table.kind[i] == "sticking"
    ]


@pytest.mark.timeout(60)
def test_a_slip_between_two_steps_is_found_as_a_tight_reference_finds_it() -> None:
    """The exact method's steps (an eighth of a period, about 13 ms) passed over the
    slip at 0.1525 s: the holding force peaks past the static force between two steps'
    ends, and the damper was reported stuck to 0.2033 s while it took 1.23 N to hold.
    The force's interpolant between the ends now finds it."""
    system = _two_friction_dampers()
    reference = _stuck_intervals(
        vi.simulate(system, method="dop853", t_end=0.3, rtol=1e-12, atol=1e-14),
        "damper 1 friction",
    )
    # Three stuck intervals: the slip at 0.1525 s and two more stick-slips after.
    assert len(reference) == 3
    assert reference[0][0] == 0.0 and 0.15 < reference[0][1] < 0.155
    for method, settings in (("exact", {}), ("dop853", {"dt": 1e-5}), ("rk4", {"dt": 1e-4})):
        found = _stuck_intervals(
            vi.simulate(system, method=method, t_end=0.3, **settings), "damper 1 friction"
        )
        assert len(found) == len(reference), (method, found)
        for (onset, duration), (onset_ref, duration_ref) in zip(found, reference, strict=True):
            assert onset == pytest.approx(onset_ref, abs=1e-7), method
            assert duration == pytest.approx(duration_ref, abs=1e-7), method


def _held_structure() -> vi.System:
    """A structure held 1 mm from rest by its own friction element (4 N of spring
    force against 6 N static) carrying a rigid damper that rubs on it, all at rest."""
    return vi.System(
        structure=vi.Oscillator(mass=1.0, stiffness=4000.0, damping=2.0),
        dampers=[
            vi.Damper(
                mass=0.1,
                at=0,
                clearance=0.01,
                law="rigid",
                restitution=0.6,
                friction=0.2,
                normal_force=0.981,
            )
        ],
        frictions=[vi.Friction(at=0, coefficient=0.3, normal_force=20.0)],
        initial=vi.Initial(structure_displacement=[0.001]),
    )


@pytest.mark.parametrize(
    ("method", "settings"),
    [("exact", {}), ("dop853", {}), ("rk4", {"dt": 1e-3}), ("generalized-alpha", {"dt": 1e-3})],
)
@pytest.mark.timeout(60)
def test_a_structure_held_by_friction_with_a_stuck_damper_stays_at_rest(
    method: str, settings: dict[str, float]
) -> None:
    """Both elements stuck from the start and for good: each sticking made the other's
    rate of round-off (1e-19 m/s) a slide, and the run stopped as chattering at
    t = 1.8e-18 s."""
    sol = vi.simulate(_held_structure(), method=method, t_end=1.0, **settings)
    assert sol.final_state["structure_displacement"][0] == pytest.approx(0.001, abs=1e-12)
    assert abs(sol.final_state["structure_velocity"][0]) < 1e-12
    assert abs(sol.final_state["damper_velocity"][0]) < 1e-12
    # One stuck interval each, from the start and still open at the end.
    for pair in ("damper 0 friction", "friction 0"):
        intervals = _stuck_intervals(sol, pair)
        assert len(intervals) == 1 and intervals[0][0] == 0.0, (pair, intervals)
        assert math.isnan(intervals[0][1])
    assert abs(sol.energy["friction"]) < 1e-12


@pytest.mark.parametrize(
    ("method", "settings"),
    [
        ("exact", {}),
        ("dop853", {}),
        ("dopri5", {}),
        ("rk4", {"dt": 1e-4}),
        ("generalized-alpha", {"dt": 1e-4}),
    ],
)
@pytest.mark.timeout(60)
def test_two_dampers_thrown_apart_on_one_carrier_slide_to_rest(
    method: str, settings: dict[str, float]
) -> None:
    """Two 0.1 kg dampers thrown apart at 1 m/s on a sprung carrier: their friction
    forces on it cancel, so each slides to rest as a block on a still floor, v^2 / (2 mu
    g) = 0.2548 m in v / (mu g) = 0.5097 s, and friction takes their 0.1 J. At that
    instant each one's stop made the other's rate of round-off a slide back (rk4,
    dop853 and generalized-alpha stopped there as chattering)."""
    damper = {
        "mass": 0.1,
        "at": 0,
        "clearance": 5.0,
        "law": "rigid",
        "restitution": 0.5,
        "friction": 0.2,
        "normal_force": 0.981,
    }
    system = vi.System(
        structure=vi.Oscillator(mass=1.0, stiffness=100.0, damping=0.0),
        dampers=[vi.Damper(**damper), vi.Damper(**damper)],
        initial=vi.Initial(damper_velocity=[1.0, -1.0]),
    )
    sol = vi.simulate(system, method=method, t_end=2.0, **settings)
    deceleration = 0.2 * 0.981 / 0.1
    distance = 1.0 / (2.0 * deceleration)
    np.testing.assert_allclose(
        sol.final_state["damper_displacement"], [distance, -distance], rtol=1e-6
    )
    assert sol.energy["friction"] == pytest.approx(0.1, rel=1e-9)
    for j in (0, 1):
        (onset, _), *rest = _stuck_intervals(sol, f"damper {j} friction")
        assert onset == pytest.approx(1.0 / deceleration, rel=1e-6) and not rest


@pytest.mark.timeout(30)
def test_friction_elements_are_numbered_among_themselves() -> None:
    """A [[friction]] element is "friction 0" beside a damper's own friction (it was
    "friction 1": numbered among every friction), in the contacts and the pairs."""
    sol = vi.simulate(_held_structure(), method="exact", t_end=0.01)
    assert "friction 0" in sol.pairs and "friction 1" not in sol.pairs
    assert set(sol.contacts.pair) == {"damper 0 friction", "friction 0"}


_STUDY = """
[structure]
kind = "oscillator"
mass = 1.0
stiffness = 3947.8
damping = 2.513

[[damper]]
mass = 0.05
at = 0
clearance = 0.005
law = "rigid"
restitution = 0.6
friction = 0.2
static_friction = 0.3
normal_force = 0.49

[[friction]]
at = 0
coefficient = 0.05
normal_force = 2.0

[[excitation]]
kind = "force"
at = 0
signal = "harmonic"
amplitude = 5.0
frequency = 10.0

[solver]
method = "dop853"
t_end = 0.3

[study]
analysis = "run"
metrics = ["energy_dissipated"]
"""


@pytest.mark.timeout(120)
def test_a_study_whose_runs_drop_a_friction_element_keeps_every_pair(tmp_path: Path) -> None:
    """Runs of no friction force (normal_force 0) and failed runs have the same pairs
    as the others: the study's Dataset was a reshape error (a traceback, no file)."""
    text = (
        _STUDY + '[study.axes]\n"friction.0.normal_force" = [0.0, 2.0]\n'
        '"damper.0.friction" = [0.0, 0.2, 0.5]\n'
    )
    data = st.run(load_study(tmp_path / "study.toml", text), tmp_path / "out.nc", threads=1)
    assert list(data["pair"].values) == ["damper 0", "damper 0 friction", "friction 0"]
    dissipated = data["energy_dissipated"]
    ok = data["status"] == 0
    # damper.0.friction 0.5 is refused (static_friction 0.3 below it): those runs fail.
    assert int(ok.sum()) == 4
    # The metric is the contacts' and impacts' losses and the friction elements'
    # sliding: the walls' impacts take energy in every completed run, a friction
    # element some where it has a force, and none where it has none.
    done = dissipated.where(ok)
    assert np.all(done.sel({"pair": "damper 0"}).values[ok.values] > 0.0)
    damper_friction = done.sel({"pair": "damper 0 friction", "damper.0.friction": 0.2})
    assert np.all(damper_friction.values > 0.0)
    assert np.all(done.sel({"pair": "damper 0 friction", "damper.0.friction": 0.0}).values == 0)
    element = done.sel({"pair": "friction 0", "damper.0.friction": [0.0, 0.2]})
    assert np.all(element.sel({"friction.0.normal_force": 0.0}).values == 0.0)
    assert np.all(element.sel({"friction.0.normal_force": 2.0}).values > 0.0)
    failed = dissipated.sel({"damper.0.friction": 0.5})
    assert np.all(np.isnan(failed.values))


@pytest.mark.timeout(60)
@pytest.mark.parametrize("record_from", [0.0, 0.2])
def test_a_studys_friction_energy_is_the_sliding_blocks_kinetic_energy(
    tmp_path: Path, record_from: float
) -> None:
    """A 0.1 kg damper thrown at 1 m/s on a carrier too heavy to move (1e9 kg), in a
    study over its friction coefficient: its element's energy_dissipated over the
    recorded window is the block's kinetic energy lost while sliding, m (v(t0)^2 -
    v(t1)^2) / 2, v falling at mu N / m to rest (closed form). It read 0 J: a stuck
    interval, the element's only record, loses nothing, and the slides are in none."""
    text = _THROWN + (
        f'[study]\nanalysis = "run"\nrecord_from = {record_from}\n'
        'metrics = ["energy_dissipated"]\n[study.axes]\n"damper.0.friction" = [0.1, 0.2]\n'
    )
    data = st.run(load_study(tmp_path / "study.toml", text), tmp_path / "out.nc", threads=1)
    assert np.all(data["status"] == 0)
    for mu in (0.1, 0.2):
        speed = 1.0 - mu * 0.981 / 0.1 * record_from
        lost = data["energy_dissipated"].sel({"pair": "damper 0 friction", "damper.0.friction": mu})
        assert float(lost) == pytest.approx(0.5 * 0.1 * speed**2, rel=1e-7)


_THROWN = """
[structure]
kind = "oscillator"
mass = 1e9
stiffness = 1e11
damping = 0.0

[[damper]]
mass = 0.1
at = 0
clearance = 5.0
law = "rigid"
restitution = 0.5
friction = 0.2
normal_force = 0.981

[initial]
damper_velocity = [1.0]

[solver]
method = "exact"
t_end = 2.0
"""
