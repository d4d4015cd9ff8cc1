"""Fixed stepping of 0.2 systems (``[solver] stepping = "fixed"``), each contact's
``energy_change`` and the history's contact-force column."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import vibroimpact as vi

OSCILLATOR = {"kind": "oscillator", "mass": 1.0, "stiffness": 0.0, "damping": 0.0}
HERTZ = {"mass": 0.05, "at": 0, "clearance": 1e-3, "law": "hertz", "stiffness": 1e9}


def run(damper: dict[str, Any], **solver: Any) -> vi.SystemSolution:
    return vi.simulate_system(
        OSCILLATOR,
        damper=[damper],
        initial={"damper_velocity": [0.5]},
        t_end=0.01,
        dt=1e-6,
        **{"method": "rk4", **solver},
    )


def test_a_linear_contact_lasts_half_a_period_located_or_counted() -> None:
    # Two free bodies on a linear spring k1: half the period of the effective mass.
    k1 = 1e6
    law = {**HERTZ, "law": "linear", "stiffness": k1}
    half = np.pi * np.sqrt(0.05 * 1.0 / 1.05 / k1)
    located = run(law, stepping="fixed").contacts
    assert abs(located.duration[0] - half) < 1e-5 * half
    counted = run(law, stepping="fixed", contact_timing="step-count").contacts
    assert abs(counted.duration[0] - half) <= 2e-6
    # Counted in whole steps: the onset is a grid time.
    assert counted.onset[0] == pytest.approx(round(counted.onset[0] / 1e-6) * 1e-6, abs=1e-15)


@pytest.mark.parametrize("stepping", ["events", "fixed"])
def test_energy_change_is_what_an_undamped_contact_dissipates(stepping: str) -> None:
    law = {**HERTZ, "law": "hyster-hertz", "restitution": 0.6}
    c = run(law, stepping=stepping).contacts
    assert c.energy_dissipated[0] > 1e-4
    assert c.energy_change[0] == pytest.approx(-c.energy_dissipated[0], rel=1e-5)
    assert c.to_dicts()[0]["energy_change"] == c.energy_change[0]


@pytest.mark.timeout(60)
@pytest.mark.parametrize("method", ["rk4", "newmark", "newmark-implicit", "generalized-alpha"])
def test_a_contact_open_at_the_end_reports_what_it_dissipated_so_far(method: str) -> None:
    # Fixed steps sum a contact's dissipation themselves, but a contact still open at
    # the run's end was closed by the events' rule (the loss slot less its value at the
    # onset, which fixed steps never set): 2.7e-9 J, or -4.7e-8 J under newmark, for the
    # ledger's 9.9e-4 J (an adversarial probe). Independent value: the ledger's contact
    # loss, this contact's alone (the run's only one).
    law = {**HERTZ, "law": "hertz-damped", "restitution": 0.01, "stiffness": 1e7}
    sol = vi.simulate_system(
        OSCILLATOR,
        damper=[law],
        initial={"damper_velocity": [0.5]},
        t_end=2.5e-3,
        dt=1e-6,
        method=method,
        stepping="fixed",
    )
    (contact,) = sol.contacts.to_dicts()
    assert np.isnan(contact["separation"])
    assert contact["energy_dissipated"] == pytest.approx(sol.energy["contact"], rel=1e-4)
    assert sol.energy["contact"] > 1e-4


def test_the_contact_force_column_is_the_law_s_force() -> None:
    sol = run(HERTZ, stepping="fixed")
    assert sol.contact_force_pairs == ["damper 0"]
    assert sol.contact_force.shape == (len(sol.t), 1)
    # Indentation from the kept rows: k delta^1.5 where the bodies overlap, 0 apart.
    relative = sol.damper_displacement[:, 0] - sol.structure_displacement[:, 0]
    indentation = np.abs(relative) - 1e-3
    expected = np.where(indentation > 0, 1e9 * np.clip(indentation, 0, None) ** 1.5, 0.0)
    assert np.max(expected) > 100.0
    assert np.allclose(sol.contact_force[:, 0], expected, rtol=1e-12, atol=1e-9)
    # Events stepping keeps the column too.
    assert run(HERTZ).contact_force.shape == (len(run(HERTZ).t), 1)


@pytest.mark.parametrize(
    ("damper", "solver", "message"),
    [
        (
            {"mass": 0.05, "at": 0, "clearance": 1e-3, "law": "rigid", "restitution": 0.6},
            {"stepping": "fixed"},
            "stepping",
        ),
        (HERTZ, {"stepping": "fixed", "method": "dop853"}, "[solver] stepping"),
        (HERTZ, {"contact_timing": "step-count"}, "[solver] contact_timing"),
        (HERTZ, {"stepping": "fix"}, "[solver] stepping"),
        (HERTZ, {"stepping": "fixed", "contact_timing": "counted"}, "[solver] contact_timing"),
    ],
)
def test_bad_stepping_is_refused_naming_the_key(
    damper: dict[str, Any], solver: dict[str, Any], message: str
) -> None:
    with pytest.raises(vi.InvalidInputError, match=message.replace("[", r"\[")):
        run(damper, **solver)


def test_a_scenario_steps_fixed_and_reports_energy_change(tmp_path: Path) -> None:
    scenario = tmp_path / "fixed.toml"
    scenario.write_text(
        """
[structure]
kind = "oscillator"
mass = 1.0
stiffness = 0.0

[[damper]]
mass = 0.05
at = 0
clearance = 1e-3
law = "hertz"
stiffness = 1e9

[initial]
damper_velocity = [0.5]

[solver]
method = "rk4"
dt = 1e-6
t_end = 0.01
stepping = "fixed"
contact_timing = "step-count"
"""
    )
    done = subprocess.run(
        [sys.executable, "-m", "vibroimpact", "simulate", str(scenario), "--json"],
        capture_output=True,
        text=True,
        timeout=50,
        check=False,
    )
    assert done.returncode == 0, done.stderr
    contacts = json.loads(done.stdout)["contacts"]
    assert contacts and "energy_change" in contacts[0]
    assert contacts[0]["energy_change"] == pytest.approx(0.0, abs=1e-6 * 0.5 * 0.05 * 0.25)
