"""The typed model's results and analyses (issue 24): the periodic and parameter
analyses and the studies take a System as they take its scenario's dict; the results'
contact tables as pandas and histories as xarray hold the run's own values.
"""

from __future__ import annotations

import sys
import tomllib
from typing import Any

import numpy as np
import pytest

import vibroimpact as vi
from model_checks import ROOT, issue_example


def ball_table() -> vi.System:
    return vi.load(ROOT / "examples" / "bouncing_ball_table.toml")


def test_the_periodic_analyses_take_a_system() -> None:
    system = ball_table()
    sections = tomllib.loads((ROOT / "examples" / "bouncing_ball_table.toml").read_text())
    run = vi.runner(sections)
    found, expected = vi.orbit(system), vi.orbit(run)
    assert found.converged and found.stable
    assert np.array_equal(found.state, expected.state)
    # Holmes: the period-one orbit's multipliers have modulus e = 0.5.
    assert np.allclose(np.abs(found.floquet_multipliers), 0.5, rtol=1e-6)
    steady = vi.steady_state(system, settle_periods=20, record_periods=4)
    again = vi.steady_state(run, settle_periods=20, record_periods=4)
    assert np.array_equal(steady.amplitude, again.amplitude)
    assert steady.impacts_per_period == 1.0
    section = vi.poincare(system, settle_periods=5, periods=3)
    same = vi.poincare(run, settle_periods=5, periods=3)
    assert len(section.impact_speed) == 3
    assert np.array_equal(section.impact_speed, same.impact_speed)
    basins = vi.basins(system, (0, [0.015]), (1, [0.16]), settle_periods=50, record_periods=2)
    assert basins.labels.shape == (1, 1) and basins.labels[0, 0] == 0
    with pytest.raises(vi.InvalidInputError, match="run"):
        vi.orbit(5)  # type: ignore[arg-type]  # (sections are taken: see below)


def test_the_parameter_analyses_and_studies_take_a_system() -> None:
    system = ball_table()
    sections = tomllib.loads((ROOT / "examples" / "bouncing_ball_table.toml").read_text())
    kw: dict[str, Any] = {"settle_periods": 10, "record_periods": 2}
    swept = vi.sweep(system, "excitation.0.amplitude", [11.772, 12.0], **kw)
    plain = vi.sweep(sections, "excitation.0.amplitude", [11.772, 12.0], **kw)
    assert [p.to_dict() for p in swept] == [p.to_dict() for p in plain]
    amplitude: dict[str, Any] = {"settle_periods": 5, "sample_periods": 2}
    bif = vi.bifurcation(system, "excitation.0.amplitude", [11.772], **amplitude)
    same = vi.bifurcation(sections, "excitation.0.amplitude", [11.772], **amplitude)
    assert len(bif[0].samples) == 2 and np.array_equal(bif[0].samples, same[0].samples)
    branch = vi.continue_orbit(system, "excitation.0.amplitude", stop=12.0, max_points=2)
    assert len(branch.points) == 2 and branch.points[0].stable
    study = vi.load(ROOT / "examples" / "clearance_study.toml")
    assert vi.study_of(study).runs == vi.study_of(study.to_dict()).runs == 108
    with pytest.raises(vi.InvalidInputError, match="sections .* or a vibroimpact.System, got"):
        vi.sweep(None, "excitation.0.amplitude", [1.0])  # type: ignore[arg-type]


def test_results_as_pandas_and_xarray() -> None:
    sol = vi.simulate(vi.load(ROOT / "examples" / "beam_two_dampers.toml"), t_end=0.2)
    frame = sol.contacts.to_pandas()
    assert list(frame.columns) == list(sol.contacts.columns)
    assert len(frame) == len(sol.contacts) > 0
    assert np.array_equal(frame["onset"].to_numpy(), sol.contacts.onset)
    assert list(frame["pair"]) == sol.contacts.pair
    data = sol.to_xarray()
    assert data.sizes == {
        "time": len(sol.t),
        "structure_coordinate": 3,
        "damper": 2,
        "contact_pair": len(sol.contact_force_pairs),
    }
    assert np.array_equal(data["time"].to_numpy(), sol.t)
    assert np.array_equal(data["damper_velocity"].to_numpy(), sol.damper_velocity)
    assert data["structure_displacement"].dims == ("time", "structure_coordinate")
    # UDUNITS, as the contact tables and the analyses' Datasets write it (it read m/s).
    assert data["structure_velocity"].attrs["units"] == "m s-1"
    assert data.attrs["energy_units"] == "J"
    assert data.attrs["steps"] == sol.steps and data.attrs["contacts"] == len(sol.contacts)
    text = repr(sol)
    assert "steps=" in text and f"contacts={len(sol.contacts)}" in text and "\n" not in text


def test_the_two_mass_results_as_pandas_and_xarray() -> None:
    damper = vi.ImpactDamper(main_mass=1.0, stiffness=1.0, impact_mass=0.25, clearance=0.01)
    start = vi.InitialState(impact_displacement=0.01, impact_velocity=0.1)
    contact = vi.Contact("hertz", stiffness=3000.0)
    sol = vi.simulate(damper, contact, start, method="rk4", dt=1e-4, t_end=0.3)
    frame = vi.to_pandas(sol.contacts)
    assert list(frame.columns) == list(vi.ContactTable.columns) and len(frame) == 1
    assert frame["separation"][0] == sol.contacts.separation[0]
    data = vi.to_xarray(sol)
    assert data.sizes == {"time": len(sol.t)}
    assert np.array_equal(data["contact_force"].to_numpy(), sol.contact_force)
    assert data["contact_force"].attrs["units"] == "N" and data.attrs["steps"] == sol.steps
    # The 0.2 results through the same functions, as their methods give them.
    general = vi.simulate(issue_example(), method="exact", t_end=0.2)
    assert vi.to_pandas(general.contacts).equals(general.contacts.to_pandas())
    assert vi.to_xarray(general).identical(general.to_xarray())
    with pytest.raises(vi.InvalidInputError, match="contacts: must be a contact table"):
        vi.to_pandas(sol)
    with pytest.raises(vi.InvalidInputError, match="sol: must be a run's solution"):
        vi.to_xarray(sol.contacts)


def test_to_pandas_says_when_pandas_is_missing(monkeypatch: pytest.MonkeyPatch) -> None:
    sol = vi.simulate(issue_example(), method="exact", t_end=0.2)
    monkeypatch.setitem(sys.modules, "pandas", None)
    with pytest.raises(ImportError, match="to_pandas\\(\\) needs pandas"):
        sol.contacts.to_pandas()


@pytest.mark.timeout(60)
def test_a_sweep_of_a_system_takes_its_own_sweep_table() -> None:
    # vi.sweep(vi.load(file)) had refused the file's own [sweep] ("missing a required
    # argument: 'parameter'") where study_of and the command read it (a new user).
    table = {
        "parameter": "excitation.0.amplitude",
        "start": 11.0,
        "stop": 12.0,
        "count": 3,
        "direction": "both",
        "settle_periods": 10,
        "record_periods": 2,
    }
    system = ball_table().replace(analyses={"sweep": table})
    explicit = vi.sweep(
        system,
        "excitation.0.amplitude",
        [11.0, 11.5, 12.0],
        direction="both",
        settle_periods=10,
        record_periods=2,
    )
    own = vi.sweep(system)
    assert [(p.value, p.direction) for p in own] == [(p.value, p.direction) for p in explicit]
    assert [p.amplitude.tolist() for p in own] == [p.amplitude.tolist() for p in explicit]
    # A keyword given still wins over the table's.
    up = vi.sweep(system, direction="up")
    assert [p.direction for p in up] == ["up"] * 3
    with pytest.raises(ValueError, match="parameter and values together"):
        vi.sweep(system, "excitation.0.amplitude")
    with pytest.raises(ValueError, match=r"a \[sweep\] table"):
        vi.sweep(ball_table().replace(analyses={}))
    # A key that is no number: said of the parameter, not as the value its schema refused.
    with pytest.raises(ValueError, match="'rigid' in the scenario, not a number"):
        vi.sweep(system, "stop.0.law", [1.0])


@pytest.mark.timeout(120)
def test_a_continuation_of_a_system_takes_its_own_continuation_table() -> None:
    # As vi.sweep takes [sweep]: vi.continue_orbit(vi.load(file)) had refused the file's
    # own [continuation] ("missing a required argument: 'parameter'"; a new user).
    system = vi.load(ROOT / "examples" / "ball_table_continuation.toml")
    table = dict(system.analyses["continuation"])
    table.update(stop=13.0, max_points=6)
    system = system.replace(analyses={"continuation": table})
    own = vi.continue_orbit(system)
    explicit = vi.continue_orbit(
        system, table["parameter"], stop=13.0, max_points=6, step=0.3, switch=True
    )
    assert [p.value for p in own.points] == [p.value for p in explicit.points]
    assert len(own.points) >= 2
    with pytest.raises(ValueError, match="parameter and stop together"):
        vi.continue_orbit(system, table["parameter"])


@pytest.mark.timeout(120)
def test_basins_of_a_system_take_its_own_basins_table() -> None:
    # As vi.sweep takes [sweep]: vi.basins(vi.load(file)) had refused the file's own
    # [basins] ("missing a required argument: 'first'").
    system = vi.load(ROOT / "examples" / "ball_table_basins.toml")
    table = dict(system.analyses["basins"])
    table.update(
        x={"state": "structure_displacement.0", "start": 0.005, "stop": 0.02, "count": 2},
        y={"state": "structure_velocity.0", "start": -0.2, "stop": 0.2, "count": 2},
        settle_periods=30,
        record_periods=4,
    )
    system = system.replace(analyses={"basins": table})
    own = vi.basins(system)
    # The table's axes by hand: the state is (x, v) of the one coordinate.
    first, second = (0, np.linspace(0.005, 0.02, 2)), (1, np.linspace(-0.2, 0.2, 2))
    explicit = vi.basins(system, first, second, settle_periods=30, record_periods=4)
    assert own.labels.tolist() == explicit.labels.tolist()
    assert own.attractors == explicit.attractors
    assert own.labels.shape == (2, 2) and (own.labels >= 0).any()
    # A keyword given overrides the table (whose 4 is valid).
    with pytest.raises(ValueError, match="record_periods"):
        vi.basins(system, record_periods=0)
    with pytest.raises(ValueError, match="first and second together"):
        vi.basins(system, first)
    with pytest.raises(ValueError, match=r"a \[basins\] table"):
        vi.basins(system.replace(analyses={}))


@pytest.mark.timeout(120)
def test_the_runner_analyses_take_a_scenarios_sections_too() -> None:
    # The getting-started page says so; orbit, steady_state, poincare, basins (and
    # lyapunov) had refused a dict ("run: must be a Runner", a new user's trial) where
    # sweep, bifurcation and continuation took it. Each gives what the System gives.
    path = ROOT / "examples" / "ball_table_basins.toml"
    sections = tomllib.loads(path.read_text())
    system = vi.load(path)
    orbit, expected = vi.orbit(sections), vi.orbit(system)
    assert orbit.converged
    assert np.array_equal(orbit.floquet_multipliers, expected.floquet_multipliers)
    steady = vi.steady_state(sections, settle_periods=20, record_periods=4)
    own = vi.steady_state(system, settle_periods=20, record_periods=4)
    assert steady.settled and np.array_equal(steady.state, own.state)
    section = vi.poincare(sections, settle_periods=5, periods=10)
    own_section = vi.poincare(system, settle_periods=5, periods=10)
    assert np.array_equal(section.strobe, own_section.strobe)
    axes = (0, np.linspace(0.005, 0.02, 2)), (1, np.linspace(-0.2, 0.2, 2))
    basins = vi.basins(sections, *axes, settle_periods=20, record_periods=4)
    own_basins = vi.basins(system, *axes, settle_periods=20, record_periods=4)
    assert basins.labels.tolist() == own_basins.labels.tolist()
    spectrum = vi.lyapunov(sections, settle=5, periods=20)
    assert np.array_equal(spectrum.exponents, vi.lyapunov(system, settle=5, periods=20).exponents)
