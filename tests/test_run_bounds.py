"""Every run knows its memory by bytes, not only rows: a wide system's history, strobes
that would pass the limit, or an analysis asked for 1e12 forcing periods are refused
before the run starts, with one line naming the key; a ball at rest on a floor stays at
rest whatever its restitution."""

from __future__ import annotations

import subprocess
import tomllib
from collections.abc import Callable
from pathlib import Path

import pytest

import vibroimpact as vi
from test_hostile_inputs import refused
from vibroimpact.analysis import MAX_PERIODS, AnalysisError, runner, sweep_settings
from vibroimpact.system import prepare_system

ROOT = Path(__file__).resolve().parents[1]
Cli = Callable[..., subprocess.CompletedProcess[str]]

# A soft 200-mode cantilever (its fastest mode is stable with RK4 at dt = 1 ms) with a
# damper at the tip: rows of 1 + 2 (200 + 1) = 403 values.
WIDE_BEAM = """
[structure]
kind = "cantilever"
length = 1.0
youngs_modulus = 1e3
second_moment = 1e-9
mass_per_length = 1.0
modes = 200
damping_ratio = 0.01
[[damper]]
mass = 0.01
at = 1.0
clearance = 0.001
law = "hertz"
stiffness = 1e3
[solver]
method = "rk4"
dt = 1e-3
t_end = 1e4
"""


def test_the_limit_is_the_cores() -> None:
    assert vi.MAX_RECORD_BYTES == 2**31


def test_a_wide_history_is_refused_by_its_bytes_though_its_rows_fit(
    tmp_path: Path, run_cli: Cli
) -> None:
    # 1e7 rows are within max_rows (2e7) but are 1e7 x 403 x 8 bytes = 30 GiB: it once
    # grew until the allocator aborted the process.
    path = tmp_path / "wide.toml"
    path.write_text(WIDE_BEAM, encoding="utf-8")
    message = refused(run_cli("simulate", str(path)), "403 values", "2048 MiB", "every")
    assert "30746 MiB" in message
    # Without the damper, from Python: rows of 401 values.
    with pytest.raises(vi.InvalidInputError, match="401 values"):
        vi.simulate_system(
            {
                "kind": "cantilever",
                "length": 1.0,
                "youngs_modulus": 1e3,
                "second_moment": 1e-9,
                "mass_per_length": 1.0,
                "modes": 200,
            },
            method="rk4",
            dt=1e-3,
            t_end=1e4,
        )


def test_a_narrow_history_of_the_same_rows_is_not_refused_up_front() -> None:
    # The same row count of a one-coordinate system is 1e7 x 3 x 8 = 229 MiB: the
    # byte check must not refuse it (prepared only, not run).
    prepared = prepare_system(
        {"kind": "oscillator", "mass": 1.0, "stiffness": 1.0},
        solver={"method": "rk4", "dt": 1e-3, "t_end": 1e4},
        output={"history": True},
    )
    assert prepared.solver["t_end"] == 1e4


def test_strobes_beyond_the_limit_are_refused_up_front() -> None:
    with pytest.raises(vi.InvalidInputError, match="strobe_period") as caught:
        vi.simulate_system(
            {"kind": "oscillator", "mass": 1.0, "stiffness": 1.0},
            method="dop853",
            t_end=1e4,
            history=False,
            strobe_period=1e-4,
        )
    assert "1.000e+08 rows" in str(caught.value)
    # A strobe per second of the same run is kept.
    done = vi.simulate_system(
        {"kind": "oscillator", "mass": 1.0, "stiffness": 1.0},
        initial={"structure_displacement": [1.0]},
        method="dop853",
        t_end=20.0,
        history=False,
        strobe_period=1.0,
    )
    assert len(done.strobe_time) == 20


def test_the_paper_api_refuses_a_history_beyond_the_bytes_even_with_max_rows_raised() -> None:
    # 1e8 rows of 48 bytes (4.6 GiB) with max_rows raised to 1e9.
    with pytest.raises(vi.InvalidInputError, match="2048 MiB"):
        vi.simulate(
            vi.ImpactDamper(main_mass=1.0, stiffness=1.0, impact_mass=0.25, clearance=0.01),
            vi.Contact("hertz", stiffness=3000.0),
            vi.InitialState(),
            method="rk4",
            dt=1e-6,
            t_end=100.0,
            max_rows=10**9,
            max_steps=10**9 - 1,  # not the default, which conftest bounds for tests
        )


FORCED = (ROOT / "examples" / "frf_impact_damper.toml").read_text(encoding="utf-8")


@pytest.mark.parametrize("key", ["settle_periods", "record_periods"])
def test_sweep_periods_beyond_the_bound_are_refused(key: str) -> None:
    table = {"parameter": "excitation.0.frequency", "start": 7.0, "stop": 13.0, "count": 3}
    table[key] = 10**12
    with pytest.raises(AnalysisError, match=rf"\[sweep\] {key}: .*{MAX_PERIODS}"):
        sweep_settings(table)
    # Settling and recording together (the other at its default, 200 or 50): the limit.
    most = MAX_PERIODS - {"settle_periods": 50, "record_periods": 200}[key]
    table[key] = most
    assert sweep_settings(table)[key] == most
    table[key] = most + 1
    with pytest.raises(AnalysisError, match=rf"{MAX_PERIODS} forcing periods in all"):
        sweep_settings(table)


def test_a_runner_refuses_a_run_of_too_many_periods(tmp_path: Path) -> None:
    path = tmp_path / "f.toml"
    path.write_text(FORCED, encoding="utf-8")
    run = runner(tomllib.loads(FORCED), tmp_path)
    x0 = run.initial_state()
    with pytest.raises(AnalysisError, match="periods"):
        run.periods(x0, 10**12)
    with pytest.raises(AnalysisError, match="periods"):
        run.shoot(x0, 10**12, 1e-9, 10)


@pytest.mark.parametrize(("flag", "value"), [("--settle", "1000000000000"), ("--periods", "0")])
def test_poincare_periods_out_of_bounds_exit_2(
    tmp_path: Path, run_cli: Cli, flag: str, value: str
) -> None:
    path = tmp_path / "f.toml"
    path.write_text(FORCED, encoding="utf-8")
    refused(run_cli("poincare", str(path), flag, value), flag, str(MAX_PERIODS))


@pytest.mark.timeout(30)
def test_lyapunov_refuses_settling_and_recording_beyond_the_bound_together(
    tmp_path: Path, run_cli: Cli
) -> None:
    # Each was checked alone: --settle 9999999 --periods 10 started a run of hours
    # (poincare and the sweep refused the same sum).
    path = tmp_path / "f.toml"
    path.write_text(FORCED, encoding="utf-8")
    system = vi.load(path)
    with pytest.raises(AnalysisError, match=rf"{MAX_PERIODS} forcing periods in all"):
        vi.lyapunov(system, settle=MAX_PERIODS - 9, periods=10)
    done = run_cli("lyapunov", str(path), "--settle", str(MAX_PERIODS - 1), "--periods", "10")
    refused(done, f"got {MAX_PERIODS + 9}")


@pytest.mark.timeout(30)
def test_lyapunov_averages_over_at_least_ten_of_the_slowest_natural_periods(
    tmp_path: Path,
) -> None:
    # A 10 Hz oscillator forced at 1e8 Hz, never touching its damper, gave +77.8 and
    # -80.4 1/s ("chaotic") over 1000 forcing periods (1e-5 s), where both are -1.26:
    # the stretches of a transient. Refused, naming periods and what would do.
    def forced_at(frequency: float) -> vi.System:
        path = tmp_path / f"f{frequency:g}.toml"
        path.write_text(FORCED.replace("frequency = 10.0", f"frequency = {frequency}", 1))
        return vi.load(path)

    with pytest.raises(AnalysisError, match=r"periods: .*too fast for its slowest mode"):
        vi.lyapunov(forced_at(1e8))
    with pytest.raises(
        AnalysisError, match=r"periods: 1000 forcing periods span 0.1 s, .*>= 10001"
    ):
        vi.lyapunov(forced_at(1e4))
    # Over 20 natural periods it runs: the exponents sum to the flow's trace, -C / M
    # (Liouville), the free damper's two are 0.
    found = vi.lyapunov(forced_at(1e4), periods=20_000)
    assert found.impacts == 0
    assert sorted(found.exponents)[2:] == [0.0, 0.0]
    assert sum(found.exponents) == pytest.approx(-2.513, rel=1e-9)


def test_sweeping_a_matrix_says_a_sweep_varies_one_number() -> None:
    # "structure.stiffness = 1: [structure] stiffness: must be an array of rows" pointed
    # at the value's format; a matrices structure has no one number to vary.
    data = {
        "structure": {
            "kind": "matrices",
            "mass": [[1.0]],
            "stiffness": [[100.0]],
            "damping": [[0.0]],
        }
    }
    message = r'is an array in the scenario, not one number; .* kind "matrices"'
    with pytest.raises(AnalysisError, match=message):
        vi.analysis.with_parameter(data, "structure.stiffness", 1.0)


def test_orbit_periods_out_of_bounds_exit_2(tmp_path: Path, run_cli: Cli) -> None:
    path = tmp_path / "f.toml"
    path.write_text(FORCED, encoding="utf-8")
    refused(run_cli("orbit", str(path), "--periods", "100000000"), "--periods")


@pytest.mark.parametrize("restitution", [1.0, 0.8])
@pytest.mark.parametrize("method", ["rk4", "dopri5", "exact"])
def test_a_ball_at_rest_on_the_floor_stays_there(restitution: float, method: str) -> None:
    # Once stopped as "chattering" with e = 1 (micro-bounces of round-off that never
    # accumulate), and released and re-landed at once with dopri5.
    done = vi.simulate_system(
        {"kind": "oscillator", "mass": 0.2, "stiffness": 0.0},
        stop=[{"at": 0, "side": "lower", "gap": 1.0, "law": "rigid", "restitution": restitution}],
        gravity=9.81,
        initial={"structure_displacement": [-1.0]},
        method=method,
        t_end=6.0,
        **({"dt": 1e-3} if method == "rk4" else {}),
    )
    assert list(done.contacts.kind) == ["sticking"]
    assert done.contacts.onset[0] < 1e-6
    assert abs(done.final_state["structure_displacement"][0] + 1.0) < 1e-12
    assert abs(done.energy["residual"]) < 1e-12


def test_an_analysis_refuses_strobes_beyond_the_memory_limit(tmp_path: Path) -> None:
    # Settling keeps a state a period: 1e7 periods of a 200-mode beam's 403 values
    # would be 30 GiB, computed for minutes before the run stopped at the limit.
    data = tomllib.loads(
        WIDE_BEAM.replace("t_end = 1e4", "t_end = 0.01").replace(
            "[[damper]]",
            '[[excitation]]\nkind = "force"\n'
            'at = 1.0\nsignal = "harmonic"\namplitude = 1.0\nfrequency = 1.0\n[[damper]]',
        )
    )
    run = runner(data, tmp_path)
    with pytest.raises(AnalysisError, match="settle or record fewer periods"):
        run.periods(run.initial_state(), 10**7, strobe=True)
