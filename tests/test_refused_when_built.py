"""What a run would refuse is refused where the System is built (its docstring's
promise when the solver has a t_end), and an analysis names the first thing wrong.

Independent references: the core's own refusal when the run starts (reached by
bypassing the Python check) and the forcing period's rule (a periodic analysis needs a
harmonic excitation)."""

from __future__ import annotations

import pytest

import vibroimpact as vi
from vibroimpact.system import prepare_system

OSCILLATOR = vi.Oscillator(mass=1.0, stiffness=3947.8, damping=2.513)
FORCE = vi.Force(at=0, signal=vi.Harmonic(amplitude=5.0, frequency=10.0))
FIXED = vi.Solver(method="rk4", dt=1e-4, t_end=0.05, stepping="fixed")
RIGID_DAMPER = vi.Damper(mass=0.05, at=0, clearance=0.005, law="rigid", restitution=0.6)
HERTZ_DAMPER = vi.Damper(mass=0.05, at=0, clearance=0.005, law="hertz", stiffness=1e9)
RIGID_STOP = vi.Stop(at=0, side="upper", gap=0.01, law="rigid", restitution=0.5)


def core_refusal(system: vi.System) -> str:
    """The core's message for ``system`` run with fixed steps: prepared with events
    (which the Python check lets through), switched to fixed, then run."""
    sections = system.model_sections()
    run = prepare_system(**sections, solver=FIXED.to_dict() | {"stepping": "events"})
    run.solver["stepping"] = "fixed"
    with pytest.raises(vi.InvalidInputError) as caught:
        run.run()
    return str(caught.value)


@pytest.mark.parametrize(
    ("dampers", "stops", "pair"),
    [
        ([RIGID_DAMPER], [], 0),
        ([HERTZ_DAMPER], [RIGID_STOP], 1),
        ([HERTZ_DAMPER, RIGID_DAMPER], [], 1),
    ],
)
def test_fixed_stepping_with_a_rigid_pair_is_refused_on_construction(
    dampers: list[vi.Damper], stops: list[vi.Stop], pair: int
) -> None:
    unchecked = vi.System(structure=OSCILLATOR, dampers=dampers, stops=stops, excitations=[FORCE])
    expected = core_refusal(unchecked)
    assert f"pair {pair} is rigid" in expected  # the core numbers dampers, then stops
    with pytest.raises(vi.InvalidInputError) as built:
        unchecked.replace(solver=FIXED)
    assert str(built.value) == expected
    # Without the solver the model is fine; simulate refuses it the same way.
    with pytest.raises(vi.InvalidInputError) as simulated:
        vi.simulate(unchecked, method="rk4", dt=1e-4, t_end=0.05, stepping="fixed")
    assert str(simulated.value) == expected


def test_fixed_stepping_with_compliant_pairs_is_built_and_runs() -> None:
    system = vi.System(
        structure=OSCILLATOR, dampers=[HERTZ_DAMPER], excitations=[FORCE], solver=FIXED
    )
    assert vi.simulate(system).steps == round(0.05 / 1e-4)


def test_an_orbit_of_an_unforced_system_names_the_missing_excitation() -> None:
    unforced = vi.System(structure=OSCILLATOR, dampers=[RIGID_DAMPER])
    # Its default solver (rk4, t_end 1 s) also lacks a dt: the excitation is named first.
    for analysis in (vi.orbit, vi.steady_state):
        with pytest.raises(vi.InvalidInputError, match="needs a harmonic excitation") as caught:
            analysis(unforced)
        assert "dt" not in str(caught.value)
    # With the excitation, the missing dt is what is left to name.
    with pytest.raises(vi.InvalidInputError, match=r"\[solver\] dt: is required"):
        vi.orbit(unforced.replace(excitations=[FORCE]))
