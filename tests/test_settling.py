"""When a forced response has settled, against closed forms: a linear oscillator at
its exact resonance (strobed at its zero crossing) is settled with its amplitude
F / (c w); a transient's stroboscopic distance from the closed-form decay
exp(-zeta w_n t) lies between two tolerances, settled under one and not the other, in
the analyses and in studies alike; basins count impacts over whole orbits."""

from __future__ import annotations

import math
import tomllib
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from numpy.typing import NDArray

from study_checks import load_study  # noqa: E402
from vibroimpact import analysis as an
from vibroimpact import study as st
from vibroimpact.analysis import basins

Array = NDArray[np.float64]

# 5 Hz undamped (k = (10 pi)^2 m), 1 % damping, 1 N.
MASS, STIFFNESS, DAMPING, FORCE = 1.0, 986.96044, 0.6283, 1.0


def oscillator(frequency: float, phase: float = 0.0) -> dict[str, Any]:
    return {
        "structure": {
            "kind": "oscillator",
            "mass": MASS,
            "stiffness": STIFFNESS,
            "damping": DAMPING,
        },
        "excitation": [
            {
                "kind": "force",
                "at": 0,
                "signal": "harmonic",
                "amplitude": FORCE,
                "frequency": frequency,
                "phase": phase,
            }
        ],
        "solver": {"method": "exact", "t_end": 1.0},
    }


def steady_amplitude(frequency: float) -> float:
    w = 2 * math.pi * frequency
    return FORCE / abs(STIFFNESS - MASS * w * w + 1j * DAMPING * w)


def closed_form_strobe(frequency: float, periods: int) -> Array:
    """The states (x, v) at t = T, 2T... of the oscillator started at rest, forced by
    F cos(w t): the steady response plus the transient decaying as exp(-zeta w_n t)."""
    w = 2 * math.pi * frequency
    big_x = FORCE / (STIFFNESS - MASS * w * w + 1j * DAMPING * w)
    sigma = DAMPING / (2 * MASS)  # zeta w_n
    wd = math.sqrt(STIFFNESS / MASS - sigma**2)
    a = -big_x.real
    b = (-(1j * w * big_x).real + sigma * a) / wd
    t = np.arange(1, periods + 1) / frequency
    decay = np.exp(-sigma * t)
    x = (big_x * np.exp(1j * w * t)).real + decay * (a * np.cos(wd * t) + b * np.sin(wd * t))
    v = (1j * w * big_x * np.exp(1j * w * t)).real + decay * (
        (b * wd - sigma * a) * np.cos(wd * t) - (sigma * b + a * wd) * np.sin(wd * t)
    )
    return np.column_stack([x, v])


def strobe_distances(strobe: Array, frequency: float) -> list[float]:
    """The documented criterion on closed-form states: the amplitude hypot(x, v / w) of
    the difference of the last state and the one p periods earlier, over the largest
    amplitude of the last 17 states, for p = 1..8."""
    w = 2 * math.pi * frequency
    scale = np.max(np.hypot(strobe[-17:, 0], strobe[-17:, 1] / w))
    out = []
    for p in range(1, 9):
        d = strobe[-1] - strobe[-1 - p]
        out.append(float(math.hypot(d[0], d[1] / w) / scale))
    return out


def test_exact_resonance_is_settled_with_its_closed_form_amplitude() -> None:
    # At 5 Hz the strobed displacement is nought (the response lags the force by a
    # quarter period) and was 1e-10 m of round-off: scaled by it, the state had
    # "repeated" only after 5 periods, or never.
    for frequency in (4.99, 5.0, 5.01):
        result = an.steady_state(
            an.runner(oscillator(frequency)), settle_periods=1000, record_periods=20
        )
        assert result.settled and result.period == 1, frequency
        assert result.impacts_per_period == 0
        assert result.amplitude[0] == pytest.approx(steady_amplitude(frequency), rel=1e-6)
    w = 2 * math.pi * 5.0
    assert steady_amplitude(5.0) == pytest.approx(FORCE / (DAMPING * w), rel=1e-6)
    points = an.sweep(
        oscillator(4.99), "excitation.0.frequency", [4.99, 5.0, 5.01], settle_periods=1000
    )
    for p in points:
        assert p.error is None and p.settled, p.value
        assert p.amplitude[0] == pytest.approx(steady_amplitude(p.value), rel=1e-6)


STUDY = """
[structure]
kind = "oscillator"
mass = 1.0
stiffness = 986.96044
damping = 0.6283

[[damper]]
mass = 0.05
at = 0
clearance = 1.0          # m: never reached (the structure moves 0.05 m)
law = "rigid"
restitution = 0.6

[[excitation]]
kind = "force"
at = 0
signal = "harmonic"
amplitude = 1.0
frequency = 5.0

[solver]
method = "exact"
t_end = 1.0

[study]
analysis = "steady-state"
settle_periods = SETTLE
record_periods = 20
tolerance = TOLERANCE
metrics = ["amplitude", "impacts_per_period", "settled"]

[study.axes]
AXES
"""


def study_text(settle: int, tolerance: float, axes: str) -> str:
    return (
        STUDY.replace("SETTLE", str(settle))
        .replace("TOLERANCE", repr(tolerance))
        .replace("AXES", axes)
    )


def test_a_study_at_exact_resonance_is_settled(tmp_path: Path) -> None:
    text = study_text(1000, 1e-6, '"excitation.0.frequency" = [4.99, 5.0, 5.01]\n')
    ds = st.run(load_study(tmp_path / "s.toml", text), tmp_path / "s.nc")
    for f in (4.99, 5.0, 5.01):
        point = ds.sel({"excitation.0.frequency": f})
        assert bool(point["settled"].item()), f
        assert point["impacts_per_period"].item() == 0
        amplitude = point["amplitude"].values[0]
        assert amplitude == pytest.approx(steady_amplitude(f), rel=1e-6)


@pytest.mark.parametrize("frequency", [5.0, 3.0])
def test_a_transient_between_two_tolerances(frequency: float, tmp_path: Path) -> None:
    # From rest, after 60 periods the transient exp(-zeta w_n t) is still a few 1e-4
    # of the motion: the criterion's distance, worked out from the closed form, lies
    # between the two tolerances.
    settle = 60
    distances = strobe_distances(closed_form_strobe(frequency, settle), frequency)
    smallest = min(distances)
    assert 1e-6 < smallest < 1e-2  # far above the method's round-off
    above, below = smallest * 1.05, smallest / 1.05
    period = 1 + next(p for p, d in enumerate(distances) if d <= above)
    run = an.runner(oscillator(frequency))
    settled = an.steady_state(run, settle_periods=settle, record_periods=1, tolerance=above)
    assert settled.settled and settled.period == period
    unsettled = an.steady_state(run, settle_periods=settle, record_periods=1, tolerance=below)
    assert not unsettled.settled and unsettled.period is None
    # The study's criterion is the same.
    axes = f'"excitation.0.frequency" = [{frequency}]\n'
    for tolerance, expected in ((above, 1.0), (below, 0.0)):
        folder = tmp_path / f"{expected:g}"
        folder.mkdir()
        text = study_text(settle, tolerance, axes)
        ds = st.run(load_study(folder / "s.toml", text), folder / "s.nc")
        assert float(ds["settled"].values.ravel()[0]) == expected, tolerance


BASINS = Path(__file__).resolve().parents[1] / "examples" / "ball_table_basins.toml"


def test_basins_count_impacts_over_whole_orbits() -> None:
    # Gamma = 1.7: a period-8 orbit. Its impacts over 20 recorded periods (2.5 orbits)
    # had depended on where the window began: one attractor listed six times.
    with BASINS.open("rb") as f:
        data = tomllib.load(f)
    data["excitation"][0]["amplitude"] = 16.677
    run = an.runner(data)
    settings = data["basins"]
    grid = [
        (
            an.state_index(settings[axis]["state"], run.n, run.k),
            np.linspace(settings[axis]["start"], settings[axis]["stop"], settings[axis]["count"]),
        )
        for axis in ("x", "y")
    ]
    result = basins(
        run,
        grid[0],
        grid[1],
        settle_periods=settings["settle_periods"],
        record_periods=settings["record_periods"],
    )
    # The orbit's impacts over 3 orbits (the 20 periods asked, rounded up to whole
    # orbits), from each of its 8 stroboscopic states: the same whatever the phase the
    # window starts at (over 20 periods they were 66 to 84).
    z = run.map(np.array([0.015, 0.16]), settings["settle_periods"])
    counts = set()
    for _ in range(8):
        kinds = run.periods(z, 24)["contacts"]["kind"]
        counts.add(sum(kind == "impact" for kind in kinds))
        z = run.map(z, 1)
    (count,) = counts
    # No two attractors alike: each listed once.
    amplitudes = [a["amplitude"][0] for a in result.attractors]
    for i, a in enumerate(amplitudes):
        for b in amplitudes[:i]:
            assert abs(a - b) > 1e-6 * abs(a), result.attractors
    # The start the orbit was counted from is on the grid: (0.015 m, 0.16 m/s).
    row = int(np.argmin(np.abs(grid[0][1] - 0.015)))
    column = int(np.argmin(np.abs(grid[1][1] - 0.16)))
    reached = result.attractors[result.labels[row, column]]
    assert reached["period"] == 8
    assert reached["impacts_per_period"] == count / 24


# Four starts on the period-8 orbit of Holmes's ball at Gamma 1.7.
_STARTS = [0.0, 0.0015, 0.003, 0.015]


def _period_eight_study(tmp_path: Path, record: int) -> tuple[Any, an.Runner]:
    """A steady-state study of the period-8 orbit from :data:`_STARTS`, recording
    ``record`` periods, and a runner of its scenario; checks that every start reached
    the one orbit."""
    text = (
        BASINS.read_text().split("[basins]")[0].replace("amplitude = 11.772", "amplitude = 16.677")
    )
    text += (
        '[study]\nanalysis = "steady-state"\nsettle_periods = 200\n'
        f'record_periods = {record}\nmetrics = ["amplitude", "impacts_per_period", "settled"]\n'
        f'[study.axes]\n"initial.structure_displacement.0" = {_STARTS}\n'
        '"initial.structure_velocity.0" = [0.16]\n'
    )
    study = load_study(tmp_path / "s.toml", text)
    ds = st.run(study, tmp_path / "s.nc")
    run = an.runner({k: v for k, v in study.data.items() if k != "study"})
    amplitudes = ds["amplitude"].values.ravel()
    assert np.ptp(amplitudes) < 1e-9 * amplitudes[0]  # one orbit
    return ds, run


def test_a_study_counts_impacts_over_whole_orbits(tmp_path: Path) -> None:
    # The same period-8 orbit from four starts: its impacts over the 20 recorded
    # periods were 2.95 to 3.6 a period, with where the orbit stood when recording
    # began; over the 16 periods of two whole orbits they are one number.
    ds, run = _period_eight_study(tmp_path, 20)
    for x0, per_period in zip(_STARTS, ds["impacts_per_period"].values.ravel(), strict=True):
        contacts = run.periods(np.array([x0, 0.16]), 220)["contacts"]
        onsets = np.asarray(contacts["onset"]) / run.period
        whole = [
            k == "impact" and 200 <= t < 216 for k, t in zip(contacts["kind"], onsets, strict=True)
        ]
        assert per_period == sum(whole) / 16, x0


@pytest.mark.parametrize("record", [1, 7])
def test_a_study_recording_less_than_an_orbit_counts_a_whole_one(
    tmp_path: Path, record: int
) -> None:
    # record_periods below the orbit's 8 periods had counted part of it: 1.857 to
    # 3.571 a period from one attractor with 7, 1 to 14 with 1. A steady-state study
    # records at least 8 periods; its count is the one steady_state gives.
    ds, run = _period_eight_study(tmp_path, record)
    for x0, per_period in zip(_STARTS, ds["impacts_per_period"].values.ravel(), strict=True):
        steady = an.steady_state(
            run, np.array([x0, 0.16]), settle_periods=200, record_periods=record
        )
        assert steady.period == 8
        assert per_period == steady.impacts_per_period, x0


def test_a_free_bodys_impacts_do_not_depend_on_the_runs_length() -> None:
    # A ball on no spring: the time below which its chatter is summed had been a
    # millionth of the run's length, so the same period-8 orbit (its strobe the same
    # to 1e-15) counted 31, 30 and 28 impacts per 8 periods in runs of 8, 16 and 56.
    data = tomllib.loads(BASINS.read_text())
    data["excitation"][0]["amplitude"] = 16.677
    run = an.runner(data)
    z = run.map(np.array([0.015, 0.16]), 200)
    assert np.allclose(run.map(z, 8), z, rtol=0, atol=1e-12)  # a period-8 orbit
    counts = set()
    for orbits in (1, 2, 7, 20):
        kinds = run.periods(z, 8 * orbits)["contacts"]["kind"]
        counts.add(sum(kind == "impact" for kind in kinds) / orbits)
    assert len(counts) == 1, counts
