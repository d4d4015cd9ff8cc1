"""Forcing frequencies and natural periods a run cannot resolve are refused up front,
naming what to change (issue 23: a sweep from 1e-300 Hz had failed each point as a
blow-up advising a smaller dt; a free body had no bound at all)."""

from __future__ import annotations

import math
import re
import subprocess
import sys
import tomllib
from pathlib import Path
from typing import Any

import pytest

from vibroimpact import DEFAULT_ENERGY_TOLERANCE, InvalidInputError, SimulationError
from vibroimpact.analysis import bifurcation, runner
from vibroimpact.system import prepare_system

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"


def _ball(frequency: float, method: str) -> dict[str, Any]:
    data = tomllib.loads((EXAMPLES / "bouncing_ball_table.toml").read_text())
    data["excitation"][0]["frequency"] = frequency
    data["solver"]["method"] = method
    return data


def _oscillator(frequency: float, method: str) -> dict[str, Any]:
    """The issue's 5 Hz oscillator, forced by 1 N."""
    return {
        "structure": {"kind": "oscillator", "mass": 1.0, "stiffness": 986.96044, "damping": 0.6283},
        "excitation": [
            {
                "kind": "force",
                "signal": "harmonic",
                "amplitude": 1.0,
                "frequency": frequency,
                "at": 0,
            }
        ],
        "solver": {"method": method, "t_end": 2.0, "dt": 1e-3},
    }


@pytest.mark.parametrize("method", ["dop853", "exact"])
@pytest.mark.parametrize("frequency", [1e-300, 1e-100, 1e-20, 1e-12])
def test_a_free_body_forced_too_slowly_is_refused_naming_the_frequency(
    frequency: float, method: str
) -> None:
    # The ball's time scale: gravity and the table (11.772 m/s^2) move it by atol = 1e-12 m
    # in sqrt(2e-12 / 11.772) = 4.12e-7 s; the run's times keep that to 4.12e-7 / 2.22e-16
    # s, 5.39e-10 Hz. dop853 had failed as "step size too small" at 1e-20 Hz.
    with pytest.raises(
        InvalidInputError,
        match=rf"frequency {frequency!r} Hz.*at least 5\.39e-10 Hz and at most 5\.46e\+05 Hz",
    ):
        runner(_ball(frequency, method))


@pytest.mark.parametrize("method", ["dop853", "exact"])
def test_a_free_body_forced_too_fast_is_refused(method: str) -> None:
    # 11.772 / (2 pi 1e6)^2 = 2.98e-13 m a period, below atol.
    with pytest.raises(InvalidInputError, match=r"forcing frequency 1000000\.0 Hz.*2\.98e-13 m"):
        runner(_ball(1e6, method))


@pytest.mark.parametrize("frequency", [1e-9, 10.0, 1e5])
def test_a_free_body_in_range_is_accepted(frequency: float) -> None:
    assert runner(_ball(frequency, "dop853")).period == pytest.approx(1 / frequency)


@pytest.mark.parametrize("method", ["exact", "dop853", "dopri5", "rk4"])
@pytest.mark.parametrize("frequency", [1e9, 1e300])
def test_an_oscillator_forced_beyond_what_the_method_resolves_is_refused(
    frequency: float, method: str
) -> None:
    # exact had blown up advising "reduce dt", dop853 and rk4 failed the energy balance.
    with pytest.raises(
        InvalidInputError, match=r"frequency \S+ Hz.*(atol|two steps|exact flow steps)"
    ):
        runner(_oscillator(frequency, method))


def test_an_oscillator_forced_in_range_is_accepted() -> None:
    for method in ("exact", "dop853", "rk4"):
        assert runner(_oscillator(5.0, method)).period == pytest.approx(0.2)
    assert runner(_oscillator(1e4, "dop853")).period == pytest.approx(1e-4)


def test_the_sweep_command_refuses_a_free_body_at_1e_300_hz(tmp_path: Path) -> None:
    text = (EXAMPLES / "bouncing_ball_table.toml").read_text()
    text = text.replace("frequency = 10.0", "frequency = 1e-300").replace(
        'method = "exact"', 'method = "dop853"'
    )
    text += (
        '\n[sweep]\nparameter = "excitation.0.frequency"\nstart = 1e-300\nstop = 1e-300\n'
        "count = 1\nsettle_periods = 10\nrecord_periods = 5\n"
    )
    path = tmp_path / "ball.toml"
    path.write_text(text)
    for command in ("sweep", "bifurcation"):
        done = subprocess.run(
            [sys.executable, "-m", "vibroimpact", command, str(path)],
            capture_output=True,
            text=True,
            timeout=50,
        )
        assert done.returncode == 2, done.stdout + done.stderr
        lines = done.stderr.strip().splitlines()
        assert len(lines) == 1 and "forcing frequency 1e-300 Hz" in lines[0]


@pytest.mark.parametrize("method", ["dop853", "exact", "rk4"])
@pytest.mark.parametrize("change", [{"mass": 1e-300}, {"stiffness": 1e308}])
def test_a_natural_period_the_run_cannot_resolve_is_refused(
    change: dict[str, float], method: str
) -> None:
    # mass 1e-300 kg: a 5e150 Hz mode; dop853 had blown up advising "reduce dt", or filled
    # max_rows after seconds.
    data = _oscillator(5.0, method)
    data["structure"].update(change)
    key = r"\[solver\] dt: the fastest mode" if method == "rk4" else r"\[solver\] t_end = 2\.0 s"
    with pytest.raises(
        InvalidInputError, match=key + r".*max_steps|" + key + r".*below 2\.22 steps"
    ):
        prepare_system(
            data["structure"],
            excitation=data["excitation"],
            solver={**data["solver"], "method": method},
        )


@pytest.mark.parametrize("fixed", [False, True])
def test_rk4_is_refused_where_it_is_unstable_and_runs_where_it_is_stable(fixed: bool) -> None:
    # RK4 is stable on an undamped mode while omega dt <= 2 sqrt(2): a period of at least
    # pi / sqrt(2) = 2.221 steps. A period of 1.5 steps had run, grown by 1e63 and stopped
    # on the energy check ("energy balance violated", exit 1).
    dt = 1e-3
    stepping = {"stepping": "fixed"} if fixed else {}
    for steps, stable in [(1.5, False), (2.2, False), (2.25, True), (3.0, True)]:
        stiffness = (2 * math.pi / (steps * dt)) ** 2  # 1 kg, undamped
        structure = {"kind": "oscillator", "mass": 1.0, "stiffness": stiffness}
        initial = {"structure_displacement": [1e-3]}
        # RK4 damps so coarse a mode (by 99 % in 0.03 s, which the energy check would
        # call impossible): the tolerance admits it, to see it bounded.
        solver = {"method": "rk4", "t_end": 0.2, "dt": dt, "energy_tolerance": 1.0, **stepping}
        if not stable:
            with pytest.raises(
                InvalidInputError, match=r"below 2\.22 steps of dt = 0\.001 s"
            ) as err:
                prepare_system(structure, initial=initial, solver=solver)
            # The step it advises is an accurate one, not the stability limit (a run at
            # the limit it had named failed the energy check by 21 %), and it runs.
            advised = float(re.search(r"reduce dt to about (\S+) s", str(err.value))[1])
            assert advised == pytest.approx(steps * dt / 20, rel=1e-2)
            kept = {**solver, "dt": advised, "energy_tolerance": DEFAULT_ENERGY_TOLERANCE}
            sol = prepare_system(structure, initial=initial, solver=kept).run()
            assert abs(sol.final_state["structure_displacement"][0]) <= 1e-3
            continue
        sol = prepare_system(structure, initial=initial, solver=solver).run()
        # Stable: RK4 damps such a coarse mode, never grows it.
        assert 0 < abs(sol.final_state["structure_displacement"][0]) <= 1e-3


def test_a_resolvable_natural_period_runs() -> None:
    # 5 Hz for 2 s: 10 periods; rk4 at dt = 1e-3 s takes 200 steps a period.
    for method in ("rk4", "dop853", "exact"):
        data = _oscillator(5.0, method)
        solution = prepare_system(
            data["structure"], excitation=data["excitation"], solver=data["solver"]
        ).run()
        assert solution.t[-1] == pytest.approx(2.0)


def test_a_bifurcation_whose_every_run_fails_is_an_error() -> None:
    # max_steps = 10: every point's run stops at it; the command had printed
    # "0 distinct stroboscopic displacement(s) of 0" for each, exit 0.
    data = _ball(10.0, "dop853")
    data["solver"]["max_steps"] = 10
    with pytest.raises(SimulationError, match=r"failed at every value of .*\(2\).*max_steps"):
        bifurcation(data, "excitation.0.frequency", [10.0, 11.0], settle_periods=1)


def test_a_sweep_command_whose_every_run_fails_exits_1_without_a_plot(
    run_cli: Any, tmp_path: Path
) -> None:
    # It had exited 0 and written its plot of nothing, where bifurcation exits 1.
    text = (EXAMPLES / "bouncing_ball_table.toml").read_text(encoding="utf-8")
    assert "[sweep]" not in text and "max_steps" not in text
    sweep = '[sweep]\nparameter = "excitation.0.frequency"\nstart = 10.0\nstop = 11.0\ncount = 2\n'
    scenario = tmp_path / "ball.toml"
    text = text.replace('method = "exact"', 'method = "dop853"')
    scenario.write_text(text + "max_steps = 10\n\n" + sweep, encoding="utf-8")
    assert tomllib.loads(scenario.read_text())["solver"]["max_steps"] == 10
    done = run_cli("sweep", str(scenario), "--plot", "sweep.png")
    assert done.returncode == 1, done.stdout + done.stderr
    (line,) = done.stderr.strip().splitlines()
    assert "sweep: the run failed at every value of excitation.0.frequency (2)" in line
    assert "max_steps" in line
    assert not (tmp_path / "sweep.png").exists()


@pytest.mark.parametrize("method", ["rk4", "newmark-implicit", "generalized-alpha", "exact"])
def test_simulate_refuses_a_forcing_its_steps_cannot_follow(method: str) -> None:
    # The 5 Hz oscillator forced at 1e9 Hz: rk4 at dt = 1e-3 s had reported 1.1e-4 J stored
    # (aliased; the truth is ~1e-40 J), exact filled max_rows by t = 2.5e-3 s.
    data = _oscillator(1e9, method)
    if method == "exact":
        del data["solver"]["dt"]
    expected = r"t_end = 2\.0 s spans 2e\+09" if method == "exact" else r"below two steps"
    with pytest.raises(
        InvalidInputError, match=r"\[\[excitation\]\] 0: frequency 1000000000\.0 Hz.*" + expected
    ):
        prepare_system(data["structure"], excitation=data["excitation"], solver=data["solver"])


def test_simulate_keeps_an_adaptive_first_step_and_a_followed_forcing() -> None:
    # dop853's dt is only its first step; 400 Hz at dt = 1e-3 s has 2.5 steps a period.
    for method, frequency in (("dop853", 1e9), ("rk4", 400.0), ("exact", 4e8)):
        data = _oscillator(frequency, method)
        data["solver"].pop("dt") if method == "exact" else None
        prepare_system(data["structure"], excitation=data["excitation"], solver=data["solver"])
