"""What a new user sees first (issue 23): the repr of every result the public API
returns, the Poincare and frequency-response plots, and the bifurcation diagram's
impact samples against Holmes's closed form."""

from __future__ import annotations

import tomllib
from pathlib import Path
from typing import Any

import numpy as np

import vibroimpact as vi
from vibroimpact import analyses, continuation, maps
from vibroimpact.scenario import load_scenario

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"
#: A repr longer than this is no summary.
SHORT = 600


def _sections(name: str) -> dict[str, Any]:
    with open(EXAMPLES / name, "rb") as f:
        return tomllib.load(f)


# ---------------------------------------------------------------------- repr


def test_a_system_runs_repr_is_a_short_summary() -> None:
    # 300+ contacts of two dampers, 1872 rows: printed whole it had been tens of kB.
    sol = load_scenario(EXAMPLES / "beam_two_dampers.toml").run()
    text = repr(sol)
    assert len(text) < SHORT, text
    assert "\n" not in text
    for said in (
        "cantilever",
        "method='dopri5'",
        f"steps={sol.steps}",
        f"contacts={len(sol.contacts)}",
        f"rows={len(sol.t)}",
        "t_end=1 s",
        "structure_displacement",
        "energy",
        "damper 0, damper 1",
    ):
        assert said in text, said
    assert text.count("damper 0") == 1
    contacts = repr(sol.contacts)
    assert len(contacts) < SHORT and f"{len(sol.contacts)} contacts" in contacts
    assert "approach_speed" in contacts and contacts.count("damper 0") == 1


def test_a_two_body_runs_repr_gives_the_time_reached_and_fields(
    table1_system: vi.ImpactDamper, hertz_contact: vi.Contact, onset_state: vi.InitialState
) -> None:
    sol = vi.simulate(table1_system, hertz_contact, onset_state, method="rk4", dt=1e-4, t_end=0.2)
    text = repr(sol)
    assert len(text) < SHORT, text
    for said in ('method="rk4"', "t_end=0.2 s", f"steps={sol.steps}", "rows=", "main_velocity"):
        assert said in text, said


def test_every_analysis_result_has_a_short_repr() -> None:
    data = _sections("ball_table_bifurcation.toml")
    run = analyses.runner(data)
    results: list[Any] = [
        analyses.steady_state(run, settle_periods=20, record_periods=5),
        analyses.orbit(run, run.initial_state()),
        *analyses.sweep(data, "excitation.0.amplitude", [12.0], settle_periods=20),
        # 500 periods of strobe rows and impacts: thousands of numbers.
        maps.poincare(run, settle_periods=10, periods=500),
        *maps.bifurcation(data, "excitation.0.amplitude", [12.0], sample_periods=400),
        maps.basins(
            run, (0, np.linspace(0.0, 0.03, 12)), (1, np.linspace(-0.4, 0.4, 12)), settle_periods=20
        ),
        continuation.continue_orbit(data, "excitation.0.amplitude", stop=13.0, step=0.1),
    ]
    for result in results:
        text = repr(result)
        assert len(text) < SHORT, (type(result).__name__, len(text), text[:200])
        assert text.startswith(type(result).__name__ + "(")
    branch = results[-1]
    assert f"<{len(branch.points)} items>" in repr(branch)
    assert len(repr(branch.points[0])) < SHORT
