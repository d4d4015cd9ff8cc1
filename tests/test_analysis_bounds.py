"""The analyses' bounds, from Python as from their sections and the command line: what a
second probe as a new user found taken and run (a curve followed in its own parameter, a
basins grid over one entry, counts without a bound, a tolerance that takes any state, a
one-point sweep that dropped its stop). Each is refused before anything runs, naming the
argument, as an ``AnalysisError`` (a ``ValueError``) or exit status 2 in one line."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

import vibroimpact as vi
from test_hostile_inputs import BASE, Cli, parse_error, refused, write
from vibroimpact.analysis import AnalysisError, curve
from vibroimpact.analysis.settings import sweep_settings

ROOT = Path(__file__).resolve().parents[1]


def test_a_sweep_of_one_point_to_another_stop_is_refused(tmp_path: Path, run_cli: Cli) -> None:
    # count = 1 swept start alone, dropping stop without a word.
    text = BASE + '[sweep]\nparameter = "excitation.0.frequency"\nstart = 7.0\nstop = 13.0\n'
    said = "[sweep] count: must be >= 2 to reach stop (13) from start (7), got 1"
    refused(run_cli("sweep", str(write(tmp_path, text + "count = 1\n"))), said)
    table = {"parameter": "excitation.0.frequency", "start": 7.0, "stop": 7.0, "count": 1}
    assert sweep_settings(table)["count"] == 1  # one point, start = stop: taken
    with pytest.raises(AnalysisError, match="must be >= 2 to reach stop"):
        sweep_settings({**table, "stop": 13.0})


def test_the_analyses_python_calls_refuse_what_their_sections_refuse() -> None:
    # Each was taken from Python and ran: a curve followed in its own parameter (84
    # "flip" points, none a flip), a basins grid over one entry or of no start, and
    # counts and tolerances without a bound (a shooting of 1e9 iterations, hours; a
    # tolerance of 1e300 reported any state as a converged orbit).
    system = vi.load(ROOT / "examples" / "frf_impact_damper.toml")
    ball = vi.load(ROOT / "examples" / "ball_table_continuation.toml")
    frequency = "excitation.0.frequency"
    cases: list[tuple[Callable[[], object], str]] = [
        (
            lambda: vi.orbit(system, max_iterations=10**9),
            "max_iterations: must be a whole number in [1, 10000], got 1000000000",
        ),
        (lambda: vi.orbit(system, tolerance=1.0), "tolerance: must be in (0, 1)"),
        (lambda: vi.orbit(system, tolerance=1e300), "tolerance: must be in (0, 1)"),
        (
            lambda: vi.sweep(system, frequency, np.linspace(9.0, 11.0, 100_001)),
            "values: must be 1 to 100000 values, got 100001",
        ),
        (
            lambda: vi.continue_orbit(system, frequency, stop=11.0, max_points=100_001),
            "max_points: must be a whole number in [2, 100000], got 100001",
        ),
        (
            lambda: vi.continue_orbit(system, frequency, stop=11.0, tolerance=2.0),
            "tolerance: must be in (0, 1)",
        ),
        (
            lambda: vi.basins(system, (0, [0.01, 0.02]), (0, [0.005])),
            "second[0] (the state index): must differ from first's, both 0",
        ),
        (
            lambda: vi.basins(system, (0, np.array([])), (1, [0.1])),
            "first[1] (the values): must hold at least one value",
        ),
        (
            lambda: curve(
                ball,
                "flip",
                "excitation.0.amplitude",
                start=11.772,
                stop=17.0,
                second="excitation.0.amplitude",
                second_stop=20.0,
                step=0.1,
            ),
            "second: must be another parameter than 'excitation.0.amplitude'",
        ),
        # Targets the scenario cannot take ran to a corrector's or Newton's failure,
        # which hid why (one took 9 s).
        (
            lambda: vi.continue_orbit(ball, "stop.0.restitution", stop=1.5),
            "stop: must be a value the scenario takes (stop.0.restitution = 1.5: ",
        ),
        (
            lambda: vi.continue_orbit(system, frequency, stop=-1.0),
            "stop: must be a value the scenario takes (excitation.0.frequency = -1: ",
        ),
        (
            lambda: curve(
                ball,
                "flip",
                "excitation.0.amplitude",
                start=11.772,
                stop=17.0,
                second="stop.0.restitution",
                second_stop=1.5,
                step=0.1,
            ),
            "second_stop: must be a value the scenario takes (",
        ),
    ]
    for call, said in cases:
        with pytest.raises(AnalysisError) as err:
            call()
        assert isinstance(err.value, ValueError) and said in str(err.value), str(err.value)
    # Within the bounds the shooting runs (a loose tolerance still converges to an orbit).
    assert vi.orbit(system, tolerance=0.5, max_iterations=10_000).residual < 0.5


def test_the_command_line_refuses_a_tolerance_that_takes_any_state(
    tmp_path: Path, run_cli: Cli
) -> None:
    # It printed "converged to a 1-period orbit ... (residual 1.00e+00)" and exit 0.
    path = ROOT / "examples" / "frf_impact_damper.toml"
    refused(run_cli("orbit", str(path), "--tolerance", "1e300"), "--tolerance", "(0, 1)")
    text = BASE + '[continuation]\nparameter = "excitation.0.amplitude"\nstop = 9.0\n'
    assert "[continuation] tolerance: must be in (0, 1)" in parse_error(text + "tolerance = 1.0\n")


@pytest.mark.timeout(60)
@pytest.mark.parametrize("periods", [997, 121])
def test_lyapunov_periods_that_split_into_no_blocks_are_refused(periods: int) -> None:
    # A tangent-dynamics probe: --periods 997 printed "-6.90575 +- nan" (one block, no
    # spread to take) and drew the running plot as one point.
    system = vi.load(ROOT / "examples" / "bouncing_ball_table.toml")
    with pytest.raises(AnalysisError, match=rf"periods: {periods} forcing periods do not split"):
        vi.lyapunov(system, settle=0, periods=periods)
    found = vi.lyapunov(system, settle=0, periods=periods + 3 if periods == 997 else 120)
    assert np.all(np.isfinite(found.standard_error))
    assert len(found.running_time) == 10
