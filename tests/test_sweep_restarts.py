"""A sweep's restarts from the last point's state (vibroimpact.analyses): a clearance
swept down restarts where the damper would start inside a wall, a damper stuck to its
wall restarts stuck, a state inside its wall by round-off is put on it, a whole-number
key stays whole, and a key the analyses do not use is refused.
"""

from __future__ import annotations

import math
import tomllib
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import vibroimpact as vi
from vibroimpact import analysis as an


def _rattling(clearance: float) -> dict[str, Any]:
    return {
        "structure": {"kind": "oscillator", "mass": 1.0, "stiffness": 3947.8, "damping": 2.513},
        "damper": [
            {"mass": 0.05, "at": 0, "clearance": clearance, "law": "rigid", "restitution": 0.6}
        ],
        "excitation": [
            {"kind": "force", "at": 0, "signal": "harmonic", "amplitude": 5.0, "frequency": 10.0}
        ],
        "solver": {"method": "exact", "t_end": 1.0},
    }


@pytest.mark.parametrize("analysis", ["sweep", "bifurcation"])
def test_a_clearance_swept_down_restarts_where_the_damper_would_start_inside_a_wall(
    analysis: str,
) -> None:
    # Each point starts from the last one's state; sweeping a clearance down leaves
    # the damper outside the new, narrower cavity. That point starts from [initial]
    # instead (the whole sweep used to stop, blaming [initial]).
    values = [0.002, 0.004, 0.006, 0.008, 0.010]
    data = _rattling(0.005)
    if analysis == "sweep":
        points: list[Any] = an.sweep(
            data,
            "damper.0.clearance",
            values,
            direction="down",
            settle_periods=20,
            record_periods=5,
        )
        fresh = an.steady_state(
            an.runner(_rattling(values[0])), None, settle_periods=20, record_periods=5
        )
        # The last point (0.002 m, the damper 4e-3 m or so off centre before it) restarted:
        # it is the run from [initial], to the bit.
        assert points[-1].value == values[0]
        assert np.array_equal(points[-1].amplitude, fresh.amplitude)
    else:
        from vibroimpact.analysis import bifurcation

        points = bifurcation(
            data,
            "damper.0.clearance",
            values,
            direction="down",
            settle_periods=20,
            sample_periods=5,
        )
    assert len(points) == len(values)
    assert all(p.error is None for p in points), [p.error for p in points]


@pytest.mark.parametrize("path", ["solver.t_end", "output.every"])
def test_a_sweep_of_a_key_the_analyses_do_not_use_is_refused(path: str) -> None:
    # Accepted, it gave identical points (found by a user trial).
    table = {"parameter": path, "start": 1.0, "stop": 2.0, "count": 2}
    with pytest.raises(an.AnalysisError, match="not used by the analyses"):
        an.sweep_settings(table)


@pytest.mark.parametrize(
    ("method", "options"), [("exact", {}), ("dop853", {}), ("rk4", {"dt": 1e-4})]
)
def test_a_sweep_restarts_from_a_state_with_its_damper_stuck_to_the_wall(
    method: str, options: dict[str, float]
) -> None:
    # A damper of no clearance and no rebound rides with the structure: the added-mass
    # closed form F / |K - w^2 (M + m) + i w C|. Each point starts from the last one's
    # end, where the stuck pair sits round-off (to 1.7e-12 m) inside its wall: the sweep
    # stopped there with "starts ... inside its wall" (exit 2).
    sections = {
        "structure": {"kind": "oscillator", "mass": 1.0, "stiffness": 3947.8, "damping": 2.513},
        "damper": [{"mass": 0.05, "at": 0, "clearance": 0.0, "law": "rigid", "restitution": 0.0}],
        "excitation": [
            {"kind": "force", "at": 0, "signal": "harmonic", "amplitude": 5.0, "frequency": 10.0}
        ],
        "solver": {"method": method, **options},
    }
    frequencies = [9.0, 10.0, 11.0]
    points = an.sweep(sections, "excitation.0.frequency", np.array(frequencies))
    for point, f in zip(points, frequencies, strict=True):
        w = 2 * math.pi * f
        closed = 5.0 / abs(3947.8 - w * w * 1.05 + 1j * w * 2.513)
        assert point.error is None
        assert point.amplitude[0] == pytest.approx(closed, rel=1e-6)


def test_a_state_inside_its_wall_by_round_off_of_nothing_is_put_on_the_wall() -> None:
    # A ball on a table at the origin (gap 0): a run's end can leave it 4e-31 m inside,
    # a round-off of no length at all, which 1e-8 of its gap's scale (itself 4e-31 m)
    # did not cover: the continuation stopped there with "starts 3.94e-31 m inside its
    # wall". Resumed, such a state is on the wall: the same period as from the wall.
    sections = {
        "structure": {"kind": "oscillator", "mass": 0.05, "stiffness": 0.0},
        "stop": [{"at": 0, "side": "lower", "gap": 0.0, "law": "rigid", "restitution": 0.5}],
        "gravity": {"acceleration": 9.81},
        "excitation": [
            {"kind": "base", "signal": "harmonic", "amplitude": 11.772, "frequency": 10.0}
        ],
        "solver": {"method": "exact"},
    }
    run = an.runner(sections)
    inside = run.map(np.array([-3.94e-31, 0.16]), 1)
    on_wall = run.map(np.array([0.0, 0.16]), 1)
    assert np.array_equal(inside, on_wall)
    # A start the user gives is held to round-off of its own scale, as before.
    with pytest.raises(ValueError, match="inside its wall"):
        vi.simulate_system(
            sections["structure"],
            stop=sections["stop"],
            gravity=sections["gravity"],
            initial={"structure_displacement": [-3.94e-31], "structure_velocity": [0.16]},
            t_end=0.1,
            method="exact",
        )


def test_a_whole_number_key_swept_stays_a_whole_number() -> None:
    # A sweep's values are floats: structure.modes = 3.0 was refused by the check of
    # a whole number ("got 3.0", user trial). A float key stays a float.
    beam = Path(__file__).resolve().parents[1] / "examples" / "beam_two_dampers.toml"
    data = {"structure": tomllib.loads(beam.read_text(encoding="utf-8"))["structure"]}
    changed = an.with_parameter(data, "structure.modes", 4.0)
    assert changed["structure"]["modes"] == 4 and isinstance(changed["structure"]["modes"], int)
    length = an.with_parameter(data, "structure.length", 1.0)["structure"]["length"]
    assert isinstance(length, float)
    # And it runs, with 4 modes.
    run = an.runner(
        changed
        | {
            "excitation": [
                {
                    "kind": "force",
                    "at": 0.5,
                    "signal": "harmonic",
                    "amplitude": 0.01,
                    "frequency": 10.0,
                }
            ],
            "solver": {"method": "exact"},
        }
    )
    assert run.n == 4
