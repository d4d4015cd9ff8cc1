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
