"""One engine (issue 24): the two-mass impact damper is a preset of the general system.

A two-mass scenario in the 0.1 format ([system], [contact]) and the same system written
in the 0.2 format ([structure] kind = "oscillator" with one [[damper]] of equal
clearances at its coordinate) run on the same kernel: the same contacts (onset,
separation, approach and rebound speeds) and the same step count, bit for bit.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

import vibroimpact as vi
from vibroimpact.scenario.system import SystemScenario
from vibroimpact.scenario.two_mass import parse_scenario

# A released main mass (50 mm) on a stiff spring carrying the impact mass at rest in
# the middle of its enclosure: a dozen contacts on both walls in 3 s, with a law whose
# damping is latched at each onset and both dampers (C and c1) acting.
SYSTEM = {"main_mass": 1.0, "stiffness": 40.0, "damping": 0.01, "impact_mass": 0.25}
CLEARANCE = 0.01
CONTACT = {"law": "hertz-damped", "stiffness": 3000.0, "restitution": 0.7, "damping": 0.01}
START = {"main_displacement": 0.05, "impact_displacement": 0.05, "main_velocity": 0.02}


def toml_table(values: dict[str, Any]) -> str:
    return "".join(f"{key} = {value!r}\n".replace("'", '"') for key, value in values.items())


def two_mass_text(solver: dict[str, Any]) -> str:
    return (
        f"[system]\n{toml_table({**SYSTEM, 'clearance': CLEARANCE})}"
        f"[contact]\n{toml_table(CONTACT)}"
        f"[initial]\n{toml_table(START)}"
        f"[solver]\n{toml_table(solver)}"
    )


def general_text(solver: dict[str, Any]) -> str:
    structure = {
        "kind": "oscillator",
        "mass": SYSTEM["main_mass"],
        "stiffness": SYSTEM["stiffness"],
        "damping": SYSTEM["damping"],
    }
    damper = {"mass": SYSTEM["impact_mass"], "at": 0, "clearance": CLEARANCE, **CONTACT}
    initial = {
        "structure_displacement": [START["main_displacement"]],
        "structure_velocity": [START["main_velocity"]],
        "damper_displacement": [START["impact_displacement"]],
        "damper_velocity": [0.0],
    }
    return (
        f"[structure]\n{toml_table(structure)}"
        f"[[damper]]\n{toml_table(damper)}"
        f"[initial]\n{toml_table(initial)}"
        f"[solver]\n{toml_table(solver)}"
    )


# The two-mass call runs the preset on the general kernel: every method and stepping.
SOLVERS = [
    pytest.param({"method": "rk4", "stepping": "events", "dt": 1e-4}, id="rk4"),
    pytest.param({"method": "dop853", "rtol": 1e-10, "atol": 1e-13}, id="dop853"),
    pytest.param({"method": "dopri5", "rtol": 1e-9, "atol": 1e-13}, id="dopri5"),
    pytest.param({"method": "newmark-implicit", "dt": 1e-4}, id="newmark-implicit"),
    pytest.param({"method": "generalized-alpha", "dt": 1e-4}, id="generalized-alpha"),
    pytest.param({"method": "rk4", "stepping": "fixed", "dt": 1e-4}, id="rk4-fixed"),
    pytest.param({"method": "newmark", "stepping": "fixed", "dt": 1e-4}, id="newmark-fixed"),
    pytest.param(
        {"method": "newmark", "stepping": "fixed", "contact_timing": "step-count", "dt": 1e-4},
        id="newmark-fixed-step-count",
    ),
]


@pytest.mark.parametrize("solver", SOLVERS)
def test_the_two_mass_format_and_the_general_one_give_the_same_run(solver: dict[str, Any]) -> None:
    settings = {**solver, "t_end": 3.0}
    two_mass = parse_scenario(two_mass_text(settings), "two_mass.toml")
    assert isinstance(two_mass, vi.Scenario)
    old = two_mass.run()
    general = {key: value for key, value in settings.items() if key != "stepping"}
    if solver.get("stepping") == "fixed":
        general["stepping"] = "fixed"
    general_scenario = parse_scenario(general_text(general), "general.toml")
    assert isinstance(general_scenario, SystemScenario)
    new = general_scenario.run()
    assert len(old.contacts) >= 8
    assert new.contacts.pair == ["damper 0"] * len(old.contacts)
    for column in ("onset", "separation", "approach_speed", "rebound_speed", "duration"):
        np.testing.assert_array_equal(
            getattr(old.contacts, column), getattr(new.contacts, column), err_msg=column
        )
    assert (old.steps, old.rejected_steps, old.rhs_evaluations) == (
        new.steps,
        new.rejected_steps,
        new.rhs_evaluations,
    )
    # The history: the main mass is the structure's coordinate, the impact mass the damper's.
    np.testing.assert_array_equal(old.t, new.t)
    np.testing.assert_array_equal(old.main_displacement, new.structure_displacement[:, 0])
    np.testing.assert_array_equal(old.impact_velocity, new.damper_velocity[:, 0])
    assert old.final_time == new.final_time
