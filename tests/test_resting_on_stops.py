"""Bodies set at rest on a rigid stop at displacement 0 and pressed onto it stay there.

Every pair of these systems touches at rest, so no free distance gives the gaps a length
scale: the round-off of a gap at displacement 0 is itself about 0, and a body that the
flow moved by round-off landed again at 1e-9 m/s, a flight no landing test took for
rest. The exact flow recorded such phantom impacts: 43 for a ball on a table shaken at
half of g (restitution 1), 26 and then a chattering sequence at every release for one
shaken at g, twenty million in 1e-4 s (the run then refused) for a mass on a spring that
gravity presses onto a stop at its unstretched length. The independent values: while
the force holding the body is positive, ``m (g + a_table(t)) > 0`` for a table shaken at
``Gamma < 1`` and ``m g`` for the sprung mass, nothing lifts it, so the run has one
sticking contact from t = 0 that never ends, no impact, and the body's state stays 0.
"""

from __future__ import annotations

import math
from typing import Any

import pytest

import vibroimpact as vi

G = 9.81
METHODS = ["exact", "dop853", "rk4"]


def _run(system: vi.System, method: str) -> vi.SystemSolution:
    step = {"dt": 1e-4} if method == "rk4" else {}
    return vi.simulate(system, method=method, t_end=2.0, history=False, **step)


def _stays_at_rest(sol: vi.SystemSolution) -> None:
    table = sol.contacts.to_pandas()
    assert list(table["kind"]) == ["sticking"]
    assert table["onset"].iloc[0] == 0.0
    assert sol.final_time == 2.0
    state = sol.final_state
    assert abs(state["structure_displacement"][0]) < 1e-15
    assert abs(state["structure_velocity"][0]) < 1e-12


@pytest.mark.timeout(60)
@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize(("gamma", "restitution"), [(0.5, 1.0), (0.99, 1.0), (0.9, 0.5)])
def test_a_ball_resting_on_a_table_shaken_below_g_stays_on_it(
    method: str, gamma: float, restitution: float
) -> None:
    # Holmes's table: the ball's coordinate is relative to the table, whose acceleration
    # Gamma g sin(w t) never exceeds g: the table's reaction never reaches zero.
    system = vi.System(
        structure=vi.Oscillator(mass=0.05, stiffness=0.0, damping=0.0),
        stops=[vi.Stop(at=0, side="lower", gap=0.0, law="rigid", restitution=restitution)],
        gravity=vi.Gravity(acceleration=G),
        excitations=[vi.Base(signal=vi.Harmonic(amplitude=gamma * G, frequency=10.0))],
    )
    _stays_at_rest(_run(system, method))


@pytest.mark.timeout(60)
@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("restitution", [0.5, 1.0])
def test_a_sprung_mass_pressed_by_gravity_onto_a_stop_stays_on_it(
    method: str, restitution: float
) -> None:
    # The spring at its unstretched length holds nothing; gravity presses the mass onto
    # the stop with m g for ever.
    system = vi.System(
        structure=vi.Oscillator(mass=0.05, stiffness=100.0, damping=0.0),
        stops=[vi.Stop(at=0, side="lower", gap=0.0, law="rigid", restitution=restitution)],
        gravity=vi.Gravity(acceleration=G),
    )
    _stays_at_rest(_run(system, method))


def _pressed_onto_a_stop(gap: float, damper: dict[str, Any], gravity: bool) -> vi.System:
    """A 1 kg, 2000 N/m structure on a linear stop (12000 N/m) ``gap`` below it, carrying
    a 50 g damper of no clearance, pressed onto the stop by a 20 Hz force of 8 N starting
    at its trough (or by gravity)."""
    force = vi.Force(at=0, signal=vi.Harmonic(amplitude=8.0, frequency=20.0, phase=math.pi))
    return vi.System(
        structure=vi.Oscillator(mass=1.0, stiffness=2000.0),
        dampers=[vi.Damper(mass=0.05, at=0, clearance=0.0, **damper)],
        stops=[vi.Stop(at=0, side="lower", gap=gap, law="linear", stiffness=12000.0)],
        excitations=[] if gravity else [force],
        gravity=vi.Gravity(acceleration=G) if gravity else None,
    )


@pytest.mark.timeout(60)
@pytest.mark.parametrize(
    ("damper", "gravity", "method"),
    [
        ({"law": "hertz", "stiffness": 1e4}, False, "rk4"),
        ({"law": "hertz", "stiffness": 1e4}, False, "dop853"),
        ({"law": "hertz-damped", "stiffness": 1e4, "restitution": 0.5}, False, "dopri5"),
        ({"law": "linear", "stiffness": 1e4}, False, "dop853"),
        ({"law": "rigid", "restitution": 0.5}, True, "dop853"),
        ({"law": "rigid", "restitution": 0.5}, True, "exact"),
    ],
)
def test_pairs_set_touching_and_pressed_run_as_pairs_a_hair_apart(
    damper: dict[str, Any], gravity: bool, method: str
) -> None:
    # Pairs touching at t = 0 with nothing moving (a contact beginning at 3e-162 m/s):
    # rk4 had refused the contact as lasting 0 s ("reduce dt to about 0.0e0 s"), dop853
    # had restarted at a step of 0 s after it and looped with no end (the square of the
    # speed underflowed in both), and with gravity a contact's 7e-40 J had been refused
    # as energy created (1.0 of nothing in play). The independent value: the same system
    # with the stop 1e-12 m away, which every method ran.
    step = {"dt": 1e-5} if method == "rk4" else {}
    touching, apart = (
        vi.simulate(_pressed_onto_a_stop(gap, damper, gravity), method=method, t_end=0.2, **step)
        for gap in (0.0, 1e-12)
    )
    assert touching.final_time == apart.final_time == 0.2
    assert touching.steps < 2 * apart.steps + 100
    x0, x1 = (s.final_state["structure_displacement"][0] for s in (touching, apart))
    assert x0 == pytest.approx(x1, rel=1e-6, abs=1e-11)
