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


# The two-mass call runs on the 0.1 kernel until the general kernel keeps the earlier
# issues' bars for it and is as fast as 0.1 on every method (throughput example, quiet
# machine, sixth stop, general against 0.1 in the same run): the Newmark family is there
# (paper's Newmark fixed 1.01e8 against 9.2e7 steps/s, with events 5.9e7 against 4.8e7,
# newmark-implicit 2.60e7 against 2.30e7, generalized-alpha 2.63e7 against 2.30e7) and
# RK4 with events is level (5.31e7 against 5.34e7); DOP853 at rtol 1e-10 takes 20.5 us a
# collision against 0.1's 10.1 us (issue 3's goal 20 us), DOPRI5 29.1 against 20.3 us, and
# a short run's set-up costs several us more (`vibroimpact paper`'s Table 3 ranks methods
# by CPU time).
_ON_THE_0_1_KERNEL = pytest.mark.xfail(
    strict=True,
    reason="the two-mass call runs on the 0.1 kernel until the general kernel is as fast "
    "on every method (DOP853 at rtol 1e-10 20.5 us a collision against 0.1's 10.1 us and "
    "issue 3's 20 us; fixed RK4 6.2e7 against 7.8e7 steps/s; a short run's set-up)",
)


def _events(solver: dict[str, Any], name: str) -> Any:
    return pytest.param(solver, id=name, marks=_ON_THE_0_1_KERNEL)


SOLVERS = [
    _events({"method": "rk4", "stepping": "events", "dt": 1e-4}, "rk4"),
    _events({"method": "dop853", "rtol": 1e-10, "atol": 1e-13}, "dop853"),
    _events({"method": "dopri5", "rtol": 1e-9, "atol": 1e-13}, "dopri5"),
    _events({"method": "newmark-implicit", "dt": 1e-4}, "newmark-implicit"),
    _events({"method": "generalized-alpha", "dt": 1e-4}, "generalized-alpha"),
    pytest.param(
        {"method": "rk4", "stepping": "fixed", "dt": 1e-4},
        id="rk4-fixed",
        marks=pytest.mark.xfail(
            strict=True,
            reason="two-mass fixed RK4 stays on the 0.1 kernel until the general kernel's "
            "keeps numba's pace (6.2e7 against numba's 7.1e7 and 0.1's 7.8e7 steps/s, "
            "throughput example, sixth stop)",
        ),
    ),
    # The general kernel's fixed-step Newmark is 0.1's to the bit.
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
