"""Bad choices of method, stepping and tolerances: refused with the field named, through
the Python API, TOML scenarios and the command line; and what the command line
reports about the steps a method took."""

from __future__ import annotations

import json
import math
import subprocess
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

import vibroimpact as vi
from test_methods import mode_by_mode_oracle
from test_verification import table1_oracle
from vibroimpact._core import check_solver

RunCli = Callable[..., subprocess.CompletedProcess[str]]
WriteScenario = Callable[..., Path]

NAN = math.nan
INF = math.inf

SYSTEM = vi.ImpactDamper(main_mass=1.0, stiffness=1.0, impact_mass=0.25, clearance=0.01)
CONTACT = vi.Contact("hertz", stiffness=3000.0, damping=0.01)
START = vi.InitialState(impact_displacement=0.01, impact_velocity=0.1)

FIXED_ONLY = ["newmark-implicit", "generalized-alpha", "dopri5", "dop853"]

BAD_SETTINGS = [
    # stepping "fixed" is the paper's, for newmark and rk4 only
    *[(dict(method=m, dt=1e-4, stepping="fixed"), "stepping") for m in FIXED_ONLY],
    (dict(method="dop853", stepping="fixed"), "stepping"),
    # step counting needs fixed stepping
    (dict(method="rk4", dt=1e-4, stepping="events", contact_timing="step-count"), "contact_timing"),
    (
        dict(method="newmark", dt=1e-4, stepping="events", contact_timing="step-count"),
        "contact_timing",
    ),
    (dict(method="dop853", contact_timing="step-count"), "contact_timing"),
    (dict(method="newmark-implicit", dt=1e-4, contact_timing="step-count"), "contact_timing"),
    # the fixed-step methods need dt
    (dict(method="rk4"), "dt"),
    (dict(method="rk4", stepping="events"), "dt"),
    (dict(method="newmark"), "dt"),
    (dict(method="newmark-implicit"), "dt"),
    (dict(method="generalized-alpha"), "dt"),
    # dt, when given, is a step (the first one for the adaptive methods)
    (dict(method="dop853", dt=0.0), "dt"),
    (dict(method="dopri5", dt=-1e-3), "dt"),
    (dict(method="dopri5", dt=NAN), "dt"),
    # tolerances, checked whatever the method
    (dict(method="dop853", rtol=1e-16), "rtol"),
    (dict(method="dop853", rtol=0.0), "rtol"),
    (dict(method="dop853", rtol=-1e-8), "rtol"),
    (dict(method="dopri5", rtol=0.2), "rtol"),
    (dict(method="dopri5", rtol=NAN), "rtol"),
    (dict(method="dopri5", rtol=INF), "rtol"),
    (dict(method="rk4", dt=1e-4, rtol=1.0), "rtol"),
    (dict(method="dop853", atol=0.0), "atol"),
    (dict(method="dop853", atol=-1e-12), "atol"),
    (dict(method="dop853", atol=NAN), "atol"),
    (dict(method="dop853", atol=INF), "atol"),
    (dict(method="newmark", dt=1e-4, atol=0.0), "atol"),
    # generalised-alpha's spectral radius, checked whatever the method
    (dict(method="generalized-alpha", dt=1e-4, spectral_radius=-0.1), "spectral_radius"),
    (dict(method="generalized-alpha", dt=1e-4, spectral_radius=1.1), "spectral_radius"),
    (dict(method="generalized-alpha", dt=1e-4, spectral_radius=NAN), "spectral_radius"),
    (dict(method="generalized-alpha", dt=1e-4, spectral_radius=INF), "spectral_radius"),
    (dict(method="dop853", spectral_radius=2.0), "spectral_radius"),
    # names
    (dict(method="dop85"), "method"),
    (dict(method="DOP853"), "method"),
    (dict(method="rk45"), "method"),
    (dict(method="generalised-alpha", dt=1e-4), "method"),
    (dict(method=""), "method"),
    (dict(method="dop853", stepping="event"), "stepping"),
    (dict(method="dop853", stepping="Events"), "stepping"),
    (dict(method="rk4", dt=1e-4, stepping="adaptive"), "stepping"),
    (dict(method="rk4", dt=1e-4, stepping=""), "stepping"),
    # step budget
    (dict(method="dop853", max_steps=0), "max_steps"),
    (dict(method="rk4", dt=1e-4, stepping="events", max_steps=0), "max_steps"),
    (dict(method="dop853", max_steps=-1), "max_steps"),
    (dict(method="dop853", max_steps=2**70), "max_steps"),
]
BAD_IDS = [f"{field}-{i}" for i, (_, field) in enumerate(BAD_SETTINGS)]


def assert_names(err: BaseException, field: str) -> None:
    assert isinstance(err, ValueError) and isinstance(err, vi.InvalidInputError)
    message = str(err)
    assert field in message, message
    assert "\n" not in message


@pytest.mark.parametrize(("settings", "field"), BAD_SETTINGS, ids=BAD_IDS)
def test_simulate_refuses_bad_settings(settings: dict[str, Any], field: str) -> None:
    with pytest.raises(vi.InvalidInputError) as err:
        vi.simulate(SYSTEM, CONTACT, START, t_end=0.01, **settings)
    assert_names(err.value, field)


@pytest.mark.parametrize(("settings", "field"), BAD_SETTINGS, ids=BAD_IDS)
def test_check_solver_refuses_the_same(settings: dict[str, Any], field: str) -> None:
    with pytest.raises(vi.InvalidInputError) as err:
        check_solver(t_end=0.01, **settings)
    assert_names(err.value, field)


def test_unknown_names_list_the_choices() -> None:
    with pytest.raises(vi.InvalidInputError) as err:
        vi.simulate(SYSTEM, CONTACT, START, t_end=0.01, method="rk45")
    for name in ("newmark", "newmark-implicit", "generalized-alpha", "rk4", "dopri5", "dop853"):
        assert f'"{name}"' in str(err.value)
    with pytest.raises(vi.InvalidInputError) as err:
        vi.simulate(SYSTEM, CONTACT, START, t_end=0.01, method="dop853", stepping="exact")
    assert '"fixed"' in str(err.value) and '"events"' in str(err.value)


def test_fixed_stepping_error_names_the_methods_that_have_it() -> None:
    with pytest.raises(vi.InvalidInputError) as err:
        vi.simulate(SYSTEM, CONTACT, START, t_end=0.01, method="dopri5", stepping="fixed")
    message = str(err.value)
    assert "newmark" in message and "rk4" in message and "dopri5" in message


@pytest.mark.parametrize(
    "settings",
    [
        dict(method="dop853", rtol=1e-15),
        dict(method="dop853", rtol=0.1),
        dict(method="dopri5", atol=1e-300),
        dict(method="generalized-alpha", dt=1e-3, spectral_radius=0.0),
        dict(method="generalized-alpha", dt=1e-3, spectral_radius=1.0),
        dict(method="dop853", dt=1e-3),
        dict(method="rk4", dt=1e-3, stepping="fixed", contact_timing="step-count"),
        dict(method="newmark", dt=1e-3, stepping="events"),
    ],
)
def test_limits_are_accepted(settings: dict[str, Any]) -> None:
    sol = vi.simulate(SYSTEM, CONTACT, START, t_end=0.01, **settings)
    assert sol.final_time == pytest.approx(0.01, rel=1e-12)
    # Ten steps: a fixed step's count beyond max_steps is refused up front.
    check_solver(t_end=0.01, max_steps=10, **settings)


@pytest.mark.parametrize(
    ("settings", "stepping"),
    [
        (dict(method="rk4", dt=1e-3), "fixed"),
        (dict(method="newmark", dt=1e-3), "fixed"),
        (dict(method="rk4", dt=1e-3, stepping="events"), "events"),
        (dict(method="newmark-implicit", dt=1e-3), "events"),
        (dict(method="generalized-alpha", dt=1e-3), "events"),
        (dict(method="dopri5"), "events"),
        (dict(method="dop853"), "events"),
    ],
)
def test_default_stepping(settings: dict[str, Any], stepping: str) -> None:
    sol = vi.simulate(SYSTEM, CONTACT, START, t_end=0.01, **settings)
    assert sol.stepping == stepping
    assert sol.method == settings["method"]


def test_simulation_error_is_a_runtime_error() -> None:
    assert issubclass(vi.SimulationError, RuntimeError)
    assert not issubclass(vi.SimulationError, ValueError)
    with pytest.raises(vi.SimulationError) as err:
        vi.simulate(SYSTEM, CONTACT, START, t_end=0.2, method="dop853", max_steps=5)
    assert "max_steps" in str(err.value) and "\n" not in str(err.value)


# ----------------------------------------------------------------------- scenarios

SOLVER_HEAD = "[solver]\n"


def with_solver(toml: str, solver: str) -> str:
    """The Table 1 scenario with its [solver] table replaced."""
    head, tail = toml.split(SOLVER_HEAD)
    output = tail[tail.index("[output]") :]
    return f"{head}{SOLVER_HEAD}{solver}\n\n{output}"


BAD_SOLVERS = [
    ('method = "dop853"\nt_end = 0.2\nstepping = "fixed"', "stepping"),
    ('method = "generalized-alpha"\ndt = 1e-4\nt_end = 0.2\nstepping = "fixed"', "stepping"),
    (
        'method = "rk4"\ndt = 1e-4\nt_end = 0.2\nstepping = "events"\n'
        'contact_timing = "step-count"',
        "contact_timing",
    ),
    ('method = "rk4"\nt_end = 0.2', "dt"),
    ('method = "newmark-implicit"\nt_end = 0.2', "dt"),
    ('method = "dop853"\nt_end = 0.2\nrtol = 0.5', "rtol"),
    ('method = "dop853"\nt_end = 0.2\nrtol = 1e-20', "rtol"),
    ('method = "dop853"\nt_end = 0.2\natol = 0', "atol"),
    ('method = "dop853"\nt_end = 0.2\natol = -1e-9', "atol"),
    (
        'method = "generalized-alpha"\ndt = 1e-4\nt_end = 0.2\nspectral_radius = 1.5',
        "spectral_radius",
    ),
    ('method = "dop853"\nt_end = 0.2\nmax_steps = 0', "max_steps"),
    ('method = "dop853"\nt_end = 0.2\nmax_steps = -3', "max_steps"),
    ('method = "dop853"\nt_end = 0.2\nmax_steps = 1.5', "max_steps"),
    ('method = "dop853"\nt_end = 0.2\nmax_steps = "many"', "max_steps"),
    ('method = "dop853"\nt_end = 0.2\nstepping = 3', "stepping"),
    ('method = "dop853"\nt_end = 0.2\nstepping = "evnts"', "stepping"),
    ('method = "dop853"\nt_end = 0.2\nrtol = "1e-8"', "rtol"),
    ('method = "dop853"\nt_end = 0.2\nspectral_radius = true', "spectral_radius"),
    ('method = "dopri"\nt_end = 0.2', "method"),
]
BAD_SOLVER_IDS = [f"{key}-{i}" for i, (_, key) in enumerate(BAD_SOLVERS)]


@pytest.mark.parametrize(("solver", "key"), BAD_SOLVERS, ids=BAD_SOLVER_IDS)
def test_bad_solver_tables(table1_toml: str, solver: str, key: str) -> None:
    with pytest.raises(vi.ScenarioError) as err:
        vi.parse_scenario(with_solver(table1_toml, solver), "run.toml")
    assert isinstance(err.value, vi.InvalidInputError) and isinstance(err.value, ValueError)
    message = str(err.value)
    assert message.startswith("run.toml: [solver] "), message
    assert key in message and "\n" not in message


def test_misspelt_new_key_gets_a_suggestion(table1_toml: str) -> None:
    text = with_solver(table1_toml, 'method = "dop853"\nt_end = 0.2\nspectral_raduis = 0.5')
    with pytest.raises(vi.ScenarioError, match=r"\[solver\] unknown key 'spectral_raduis'") as err:
        vi.parse_scenario(text)
    assert "did you mean 'spectral_radius'" in str(err.value)


def test_dt_is_optional_for_the_adaptive_methods(table1_toml: str) -> None:
    scenario = vi.parse_scenario(with_solver(table1_toml, 'method = "dop853"\nt_end = 0.2'))
    assert scenario.dt is None and scenario.stepping is None
    assert scenario.solver_settings()["dt"] is None
    sol = scenario.run()
    assert sol.stepping == "events" and sol.method == "dop853"


def test_new_solver_keys_reach_the_run(table1_toml: str) -> None:
    solver = (
        'method = "generalized-alpha"\ndt = 1e-4\nt_end = 0.2\nstepping = "events"\n'
        "spectral_radius = 0.5\nrtol = 1e-9\natol = 1e-14\nmax_steps = 5000"
    )
    scenario = vi.parse_scenario(with_solver(table1_toml, solver))
    assert (scenario.stepping, scenario.spectral_radius, scenario.rtol, scenario.atol) == (
        "events",
        0.5,
        1e-9,
        1e-14,
    )
    assert scenario.max_steps == 5000
    got = scenario.run()
    want = vi.simulate(
        scenario.system,
        scenario.contact,
        scenario.initial,
        method="generalized-alpha",
        dt=1e-4,
        t_end=0.2,
        every=scenario.every,
        spectral_radius=0.5,
    )
    assert got.contacts.to_dicts() == want.contacts.to_dicts()
    assert (got.steps, got.rhs_evaluations) == (want.steps, want.rhs_evaluations)
    # A smaller step budget is enforced: 2000 fixed steps are refused before the run.
    with pytest.raises(vi.InvalidInputError, match="max_steps"):
        vi.parse_scenario(with_solver(table1_toml, solver.replace("5000", "100")))


@pytest.mark.parametrize(
    ("contact", "key"),
    [
        ('law = "hertz-damped"\nstiffness = 3000.0', "restitution"),
        ('law = "hertz-damped"\nstiffness = 3000.0\nrestitution = 0', "restitution"),
        ('law = "hertz-damped"\nstiffness = 3000.0\nrestitution = 1.5', "restitution"),
        ('law = "hertz-dampd"\nstiffness = 3000.0\nrestitution = 0.5', "law"),
    ],
)
def test_bad_hertz_damped_contact_tables(table1_toml: str, contact: str, key: str) -> None:
    text = table1_toml.replace('law = "hertz"\nstiffness = 3000.0\ndamping = 0.01', contact, 1)
    assert contact in text
    with pytest.raises(vi.ScenarioError) as err:
        vi.parse_scenario(text, "run.toml")
    message = str(err.value)
    assert message.startswith("run.toml: [contact] ") and key in message


def test_hertz_damped_scenario_runs(table1_toml: str) -> None:
    text = table1_toml.replace(
        'law = "hertz"\nstiffness = 3000.0\ndamping = 0.01',
        'law = "hertz-damped"\nstiffness = 3000.0\nrestitution = 0.6',
        1,
    )
    scenario = vi.parse_scenario(with_solver(text, 'method = "dop853"\nt_end = 0.2'))
    assert scenario.contact.law == "hertz-damped"
    assert scenario.contact.effective_restitution == 0.6
    sol = scenario.run()
    assert len(sol.contacts) == 1
    # The main spring and damper act during the contact, so the rebound is near the
    # law's e, not e: the SciPy mode-by-mode oracle gives it (DOP853 at its default
    # rtol 1e-8 here).
    exact = mode_by_mode_oracle(scenario.system, scenario.contact, scenario.initial, 0.2)
    assert len(exact.onsets) == 1
    assert sol.contacts.restitution[0] == pytest.approx(
        exact.rebound_speeds[0] / exact.approach_speeds[0], rel=1e-7
    )
    assert sol.contacts.restitution[0] == pytest.approx(0.6, rel=1e-2)


# ----------------------------------------------------------------- command line


def assert_one_line_error(proc: subprocess.CompletedProcess[str], status: int) -> str:
    assert proc.returncode == status, proc.stderr
    assert proc.stdout == ""
    assert "Traceback" not in proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("vibroimpact: error: "), proc.stderr
    return lines[0]


@pytest.mark.parametrize(
    ("solver", "key"),
    [
        ('method = "dopri5"\nt_end = 0.2\nstepping = "fixed"', "stepping"),
        ('method = "newmark"\nt_end = 0.2', "dt"),
        ('method = "dop853"\nt_end = 0.2\nrtol = 1', "rtol"),
        ('method = "dop853"\nt_end = 0.2\nmax_steps = 0', "max_steps"),
        (
            'method = "newmark"\ndt = 1e-4\nt_end = 0.2\nstepping = "events"\n'
            'contact_timing = "step-count"',
            "contact_timing",
        ),
    ],
)
def test_cli_bad_solver_exits_2(
    run_cli: RunCli, table1_toml: str, write_scenario: WriteScenario, solver: str, key: str
) -> None:
    path = write_scenario(with_solver(table1_toml, solver))
    line = assert_one_line_error(run_cli("simulate", str(path), "--json"), 2)
    assert str(path) in line and "[solver]" in line and key in line


def test_cli_json_reports_the_steps_of_an_adaptive_method(
    run_cli: RunCli, table1_toml: str, write_scenario: WriteScenario
) -> None:
    solver = 'method = "dop853"\nt_end = 0.2\nrtol = 1e-10'
    text = with_solver(table1_toml, solver)
    proc = run_cli("simulate", str(write_scenario(text)), "--json")
    assert proc.returncode == 0, proc.stderr
    assert proc.stderr == ""
    summary = json.loads(proc.stdout)
    assert summary["method"] == "dop853" and summary["stepping"] == "events"
    assert summary["dt"] is None
    for key in ("steps", "rejected_steps", "rhs_evaluations", "grazing_contacts"):
        assert isinstance(summary[key], int) and summary[key] >= 0, key
    # DOP853: 12 new evaluations per attempted step, accepted or rejected.
    attempts = summary["steps"] + summary["rejected_steps"]
    assert summary["rhs_evaluations"] >= 12 * attempts
    # The same numbers as the run in this process (the method is deterministic).
    direct = vi.parse_scenario(text).run()
    assert summary["steps"] == direct.steps
    assert summary["rejected_steps"] == direct.rejected_steps
    assert summary["rhs_evaluations"] == direct.rhs_evaluations
    # every = 7: the start, every 7th step and the last one.
    rows = 1 + direct.steps // 7 + (1 if direct.steps % 7 else 0)
    assert summary["history_rows"] == len(direct.t) == rows
    # And the physics: the Table 1 collision's duration by the SciPy oracle.
    (contact,) = summary["contacts"]
    assert contact["duration"] == pytest.approx(table1_oracle().duration, rel=1e-9)
    assert contact["restitution"] == pytest.approx(
        contact["rebound_speed"] / contact["approach_speed"], rel=1e-15
    )


def test_cli_text_reports_the_steps(
    run_cli: RunCli, table1_toml: str, write_scenario: WriteScenario
) -> None:
    text = with_solver(table1_toml, 'method = "dopri5"\nt_end = 0.2')
    direct = vi.parse_scenario(text).run()
    proc = run_cli("simulate", str(write_scenario(text)))
    assert proc.returncode == 0 and proc.stderr == ""
    first = proc.stdout.splitlines()[0]
    assert "dopri5 (events stepping)" in first
    assert f"{direct.steps} steps" in first
    assert f"{direct.rejected_steps} rejected" in first
    assert f"{direct.rhs_evaluations} force evaluations" in first


def test_cli_simulation_error_is_one_line(
    run_cli: RunCli, table1_toml: str, write_scenario: WriteScenario
) -> None:
    text = with_solver(table1_toml, 'method = "dop853"\nt_end = 0.2\nmax_steps = 10')
    line = assert_one_line_error(run_cli("simulate", str(write_scenario(text))), 1)
    assert "max_steps" in line
