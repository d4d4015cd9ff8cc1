"""What a run would refuse is refused where the System is built (its docstring's
promise when the solver has a t_end), and an analysis names the first thing wrong.

Independent references: the core's own refusal when the run starts (reached by
bypassing the Python check) and the forcing period's rule (a periodic analysis needs a
harmonic excitation)."""

from __future__ import annotations

import copy
import math
import pickle

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


@pytest.mark.timeout(60)
@pytest.mark.parametrize(
    "solver", [vi.Solver(method="rk4", dt=1e-4, t_end=0.05), vi.Solver(dt=1e-4), None]
)
def test_a_start_inside_a_wall_is_refused_where_the_system_is_built(
    solver: vi.Solver | None,
) -> None:
    # It was built (and loaded) and refused only by simulate: the run's own message now,
    # at once, whether or not the solver has a t_end.
    inside = vi.Initial(damper_displacement=[0.008])  # 3 mm past the 5 mm clearance
    bare = vi.System(structure=OSCILLATOR, dampers=[RIGID_DAMPER])
    sections = bare.model_sections() | {"initial": inside.to_dict()}
    with pytest.raises(vi.InvalidInputError) as run:
        prepare_system(**sections, solver={"t_end": 0.05, "dt": 1e-4}).run()
    assert "damper 0 starts 3.000000e-3 m inside its wall" in str(run.value)
    with pytest.raises(vi.InvalidInputError) as built:
        bare.replace(initial=inside, solver=solver)
    assert str(built.value) == str(run.value)
    # Touching its wall is a start, and runs.
    touching = bare.replace(initial=vi.Initial(damper_displacement=[0.005]), solver=solver)
    assert vi.simulate(touching, t_end=0.01, dt=1e-4).final_time == 0.01


@pytest.mark.timeout(60)
@pytest.mark.parametrize("method", ["rk4", "dop853"])
def test_a_damper_may_start_pressed_into_a_compliant_seat(method: str) -> None:
    # A damper resting on its Hertz seat under gravity is inside its wall by the
    # static indentation (m g / k)^(2/3): it had been refused as "starts ... inside its
    # wall" by simulate and study, where orbit and sweep took it. At the closed-form
    # equilibrium (the structure sagging by (M + m) g / K) nothing moves.
    mass, stiffness, damper_mass, clearance, hertz, g = 1.0, 1e4, 0.1, 0.002, 1e8, 9.81
    depth = (damper_mass * g / hertz) ** (2 / 3)
    sag = -(mass + damper_mass) * g / stiffness
    seat = sag - clearance - depth
    system = vi.System(
        structure=vi.Oscillator(mass=mass, stiffness=stiffness, damping=1.0),
        dampers=[
            vi.Damper(mass=damper_mass, at=0, clearance=clearance, law="hertz", stiffness=hertz)
        ],
        gravity=vi.Gravity(acceleration=g),
        initial=vi.Initial(structure_displacement=[sag], damper_displacement=[seat]),
    )
    sol = vi.simulate(system, method=method, t_end=0.2, dt=1e-5 if method == "rk4" else None)
    assert max(abs(x[0] - sag) for x in sol.structure_displacement) < 1e-12
    assert max(abs(y[0] - seat) for y in sol.damper_displacement) < 1e-12
    assert sol.contact_force[-1][0] == pytest.approx(damper_mass * g, rel=1e-9)
    # One contact, in progress from the start (no onset, no approach), never ended.
    assert len(sol.contacts) == 1
    assert sol.contacts.onset[0] == 0.0 and math.isnan(sol.contacts.separation[0])
    assert sol.contacts.max_indentation[0] == pytest.approx(depth, rel=1e-6)
    # A rigid seat there is still refused: no rigid body is inside another.
    rigid = vi.Damper(mass=damper_mass, at=0, clearance=clearance, law="rigid", restitution=0.5)
    with pytest.raises(vi.InvalidInputError, match="damper 0 starts 4.58.*e-6 m inside its wall"):
        system.replace(dampers=[rigid])


@pytest.mark.timeout(60)
@pytest.mark.parametrize(
    ("solver", "message"),
    [
        (vi.Solver(method="exakt"), r'^\[solver\] method must be one of .*got "exakt"'),
        (vi.Solver(rtol=-1.0), r"^\[solver\] rtol: must be in \[1e-15, 0.1\], got -1.0"),
        (vi.Solver(method="dop853", stepping="fixed"), r'^\[solver\] stepping: "fixed" takes'),
    ],
)
def test_a_solver_without_t_end_is_checked_where_the_system_is_built(
    solver: vi.Solver, message: str
) -> None:
    # Built, and refused only when run (a misspelt method too).
    with pytest.raises(vi.InvalidInputError, match=message):
        vi.System(structure=OSCILLATOR, solver=solver)
    # The same message as a solver with its t_end gets.
    with pytest.raises(vi.InvalidInputError, match=message):
        vi.System(structure=OSCILLATOR, solver=vi.Solver(**solver.to_dict(), t_end=1.0))


@pytest.mark.timeout(60)
def test_a_system_whose_solver_has_no_t_end_loads_back_and_runs_as_given() -> None:
    system = vi.System(
        structure=OSCILLATOR,
        dampers=[RIGID_DAMPER],
        excitations=[FORCE],
        solver=vi.Solver(method="dop853", rtol=1e-9),
    )
    text = system.to_toml()
    assert "t_end" not in text
    loaded = vi.load(text)  # it was refused: "[solver] missing key 't_end'"
    assert loaded == system
    ran, again = (vi.simulate(s, t_end=0.2) for s in (system, loaded))
    assert ran.final_state == again.final_state and len(ran.contacts) > 0
    # Its runs need their length; a file's misspelt method is still refused on loading.
    with pytest.raises(vi.InvalidInputError, match=r"missing key 't_end' \(the run's length"):
        vi.simulate(loaded)
    with pytest.raises(ValueError, match='got "dop835"'):
        vi.load(text.replace('"dop853"', '"dop835"'))


@pytest.mark.timeout(60)
def test_a_systems_analyses_are_read_only() -> None:
    # Changed in place, they passed by the checks a System makes when built (an unknown
    # section, a misspelt key), and a hashed System's analyses changed under it.
    table = {"parameter": "structure.stiffness", "start": 1000.0, "stop": 2000.0, "count": 5}
    keys = ["structure.damping"]
    system = vi.System(structure=OSCILLATOR, analyses={"sweep": dict(table, derivatives=keys)})
    for change in (
        lambda a: a.__setitem__("swep", {}),
        lambda a: a.update(poincare={}),
        lambda a: a["sweep"].__setitem__("count", 6),
        lambda a: a["sweep"]["derivatives"].append("structure.mass"),
        lambda a: a.pop("sweep"),
    ):
        with pytest.raises(TypeError, match=r"read-only: make a changed System"):
            change(system.analyses)
    assert system.analyses == {"sweep": dict(table, derivatives=keys)}
    # A copy to change: to_dict's tables, and replace.
    tables = system.to_dict()
    tables["sweep"]["derivatives"].append("structure.mass")
    assert type(tables["sweep"]) is dict and system.analyses["sweep"]["derivatives"] == keys
    changed = system.replace(analyses={"sweep": tables["sweep"]})
    assert changed.analyses["sweep"]["derivatives"] == [*keys, "structure.mass"]
    # Pickled (a Dask task) and copied, still read-only and equal.
    for other in (pickle.loads(pickle.dumps(system)), copy.deepcopy(system)):
        assert other == system
        with pytest.raises(TypeError):
            other.analyses["sweep"]["derivatives"].append("structure.mass")


@pytest.mark.timeout(60)
@pytest.mark.parametrize("method", ["dop853", "exact", "rk4"])
def test_natural_frequencies_beyond_a_double_are_refused(method: str) -> None:
    # 1e-200 kg on 1e200 N/m (w^2 = 1e400 s^-2): dop853 stopped as a "numerical blow-up"
    # (exit 1), the exact flow returned its start after a second (exit 0).
    overflowing = vi.Oscillator(mass=1e-200, stiffness=1e200, damping=0.0)
    solver = vi.Solver(method=method, t_end=1.0, dt=1e-3 if method == "rk4" else None)
    with pytest.raises(vi.InvalidInputError, match=r"natural frequencies overflow a double"):
        vi.System(structure=overflowing, solver=solver)
    # The largest a double holds runs its closed form (w = 1e10 rad/s over 1e-9 s).
    fine = vi.System(
        structure=vi.Oscillator(mass=1e-150, stiffness=1e-130, damping=0.0),
        initial=vi.Initial(structure_displacement=[1e-3]),
    )
    end = vi.simulate(fine, method="exact", t_end=1e-9).final_state["structure_displacement"][0]
    assert abs(end - 1e-3 * math.cos(1e10 * 1e-9)) < 1e-15
