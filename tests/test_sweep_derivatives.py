"""Sensitivities beside the frequency response (issue 26): ``sweep(..., derivatives=...)``
and ``vibroimpact sweep --derivative``.

Independent references:

- A forced damped linear oscillator whose stop is never reached: the steady amplitude
  ``X = F0 / D``, ``D = sqrt((k - m w^2)^2 + (c w)^2)``, so ``dX/dF0 = 1 / D``,
  ``dX/dk = -F0 (k - m w^2) / D^3`` and ``dX/dc = -F0 c w^2 / D^3``.
- An impacting point of ``examples/frf_impact_damper.toml``: the central difference of
  the amplitudes of two orbits found by shooting at ``p +- h`` (``orbit``, Newton to
  1e-12), independent of the implicit function theorem the sweep uses.
"""

from __future__ import annotations

import json
import math
import subprocess
import tomllib
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from vibroimpact.analysis import orbit, runner, steady_state, sweep, with_parameter
from vibroimpact.analysis.sensitivities import Derivative

ROOT = Path(__file__).resolve().parents[1]
FRF = ROOT / "examples" / "frf_impact_damper.toml"
PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"
RunCli = Callable[..., subprocess.CompletedProcess[str]]

MASS, STIFFNESS, DAMPING, FORCE = 1.0, 3947.8, 2.513, 5.0
AMPLITUDE, STIFF, DAMP = "excitation.0.amplitude", "structure.stiffness", "structure.damping"


def oscillator_with_a_far_stop() -> dict[str, Any]:
    """A 10 Hz oscillator (2 % damping) and a rigid stop 1 m away: it never reaches it."""
    return {
        "structure": {
            "kind": "oscillator",
            "mass": MASS,
            "stiffness": STIFFNESS,
            "damping": DAMPING,
        },
        "stop": [{"at": 0, "side": "upper", "gap": 1.0, "law": "rigid", "restitution": 0.8}],
        "excitation": [
            {"kind": "force", "at": 0, "signal": "harmonic", "amplitude": FORCE, "frequency": 7.0}
        ],
        "solver": {"method": "exact", "t_end": 1.0},
    }


def closed_form(frequency: float) -> dict[str, float]:
    """d amplitude / d (F0, k, c) of the linear oscillator at ``frequency`` (Hz)."""
    w = 2 * math.pi * frequency
    real, imaginary = STIFFNESS - MASS * w * w, DAMPING * w
    d = math.hypot(real, imaginary)
    return {
        AMPLITUDE: 1 / d,
        STIFF: -FORCE * real / d**3,
        DAMP: -FORCE * DAMPING * w * w / d**3,
    }


@pytest.mark.timeout(60)
def test_a_linear_sweeps_derivatives_are_the_closed_forms() -> None:
    frequencies = [6.0, 8.0, 9.5, 10.0, 10.5, 13.0]  # either side of resonance and at it
    points = sweep(
        oscillator_with_a_far_stop(),
        "excitation.0.frequency",
        frequencies,
        settle_periods=300,
        record_periods=5,
        derivatives=[AMPLITUDE, STIFF, DAMP],
    )
    assert [p.value for p in points] == frequencies
    for p in points:
        assert p.settled and p.impacts_per_period == 0, p.value
        assert p.derivatives is not None, p.value
        expected = closed_form(p.value)
        assert set(p.derivatives) == set(expected)
        for path, value in expected.items():
            got = p.derivatives[path].amplitude
            assert got.shape == (1,)
            assert got[0] == pytest.approx(value, rel=1e-6), (p.value, path)
        # X = F0 / D: linear in F0, so its derivative is X / F0 (the sweep's own amplitude).
        assert p.derivatives[AMPLITUDE].amplitude[0] == pytest.approx(
            p.amplitude[0] / FORCE, rel=1e-6
        )
    # Below resonance a stiffer structure moves less, above it more: the sign changes.
    stiffness = [p.derivatives[STIFF].amplitude[0] for p in points if p.derivatives]
    assert stiffness[0] < 0 < stiffness[-1]


def frf_data() -> dict[str, Any]:
    return tomllib.loads(FRF.read_text(encoding="utf-8"))


@pytest.mark.timeout(60)
def test_a_damper_at_rest_leaves_the_structures_derivative_defined() -> None:
    # 7 Hz: the damper never reaches its walls and stays where it started (multipliers
    # 1: I - M singular in its state alone). The structure is the linear oscillator.
    (point,) = sweep(frf_data(), "excitation.0.frequency", [7.0], derivatives=[AMPLITUDE])
    assert point.settled and point.impacts_per_period == 0 and point.derivatives is not None
    w = 2 * math.pi * 7.0
    expected = 1 / abs(STIFFNESS - MASS * w * w + 1j * DAMPING * w)
    assert point.derivatives[AMPLITUDE].amplitude[0] == pytest.approx(expected, rel=1e-8)
    # The damper's own state does not move with the force.
    assert np.all(point.derivatives[AMPLITUDE].state[[1, 3]] == 0.0)


def orbit_amplitude(data: dict[str, Any], path: str, value: float, state: np.ndarray) -> float:
    found = orbit(runner(with_parameter(data, path, value)), state, tolerance=1e-12)
    assert found.converged and found.impacts_per_period > 0
    return float(found.amplitude[0])


@pytest.mark.timeout(60)
@pytest.mark.parametrize("path", ["damper.0.clearance", AMPLITUDE])
def test_an_impacting_points_derivative_is_that_of_two_orbits(path: str) -> None:
    data = frf_data()
    (point,) = sweep(data, "excitation.0.frequency", [11.5], derivatives=[path], record_periods=10)
    assert point.settled and point.impacts_per_period == 2
    assert point.derivatives is not None
    derivative = point.derivatives[path].amplitude[0]
    at = with_parameter(data, "excitation.0.frequency", 11.5)
    # The sweep's one point settled from [initial]: the same here.
    found = orbit(runner(at), steady_state(runner(at), record_periods=10).state)
    value = float(at["damper"][0]["clearance"] if path.startswith("damper") else FORCE)
    h = 1e-4 * value
    start = found.state
    difference = (
        orbit_amplitude(at, path, value + h, start) - orbit_amplitude(at, path, value - h, start)
    ) / (2 * h)
    assert abs(derivative) > 1e-3 * point.amplitude[0] / value  # not a vanishing one
    assert derivative == pytest.approx(difference, rel=1e-5)


@pytest.mark.timeout(60)
def test_a_point_without_a_stable_orbit_has_no_derivatives() -> None:
    # 9.5 Hz from [initial]: no period of at most 8 forcing periods, and the orbit
    # shot from where the response ended is not one it tends to: no number is given.
    data = frf_data()
    (point,) = sweep(data, "excitation.0.frequency", [9.5], derivatives=[AMPLITUDE])
    at = runner(with_parameter(data, "excitation.0.frequency", 9.5))
    found = orbit(at, steady_state(at).state)
    assert not point.settled and not (found.converged and found.stable)
    assert point.derivatives is None and point.to_dict()["derivatives"] is None


def test_without_derivatives_a_point_holds_none_and_its_json_is_unchanged() -> None:
    (point,) = sweep(
        oscillator_with_a_far_stop(), "excitation.0.frequency", [7.0], settle_periods=10
    )
    assert point.derivatives == {} and "derivatives" not in point.to_dict()
    point.derivatives = None
    assert point.to_dict()["derivatives"] is None
    point.derivatives = {AMPLITUDE: Derivative(np.zeros(2), np.ones(1))}
    assert point.to_dict()["derivatives"] == {AMPLITUDE: {"state": [0.0, 0.0], "amplitude": [1.0]}}


def frf_scenario(tmp_path: Path, sweep_keys: str = "") -> Path:
    """The example with a short sweep (three values, up)."""
    text = FRF.read_text(encoding="utf-8")
    head = text.split("[sweep]")[0]
    path = tmp_path / "frf.toml"
    path.write_text(
        head + '[sweep]\nparameter = "excitation.0.frequency"\nstart = 11.0\nstop = 12.0\n'
        "count = 3\nrecord_periods = 10\n" + sweep_keys,
        encoding="utf-8",
    )
    return path


def test_the_cli_json_has_each_points_derivatives(run_cli: RunCli, tmp_path: Path) -> None:
    scenario = frf_scenario(tmp_path)
    done = run_cli(
        "sweep", str(scenario), "--derivative", "damper.0.clearance", "--derivative",
        AMPLITUDE, "--json",
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    points = json.loads(done.stdout)["points"]
    assert len(points) == 3
    python = sweep(
        frf_data(),
        "excitation.0.frequency",
        [11.0, 11.5, 12.0],
        record_periods=10,
        derivatives=["damper.0.clearance", AMPLITUDE],
    )
    for row, p in zip(points, python, strict=True):
        assert set(row["derivatives"]) == {"damper.0.clearance", AMPLITUDE}
        for path, d in row["derivatives"].items():
            assert len(d["state"]) == 4 and len(d["amplitude"]) == 1
            assert p.derivatives is not None
            assert d["amplitude"][0] == pytest.approx(p.derivatives[path].amplitude[0], rel=1e-12)
    # Without --derivative the output is as before.
    plain = json.loads(run_cli("sweep", str(scenario), "--json").stdout)["points"]
    assert all("derivatives" not in row for row in plain)


def test_the_scenario_key_and_the_table(run_cli: RunCli, tmp_path: Path) -> None:
    # Named twice: one column (it had been printed twice; a probe).
    twice = 'derivatives = ["damper.0.clearance", "damper.0.clearance"]\n'
    scenario = frf_scenario(tmp_path, twice)
    done = run_cli("sweep", str(scenario))
    assert done.returncode == 0, done.stderr
    lines = done.stdout.splitlines()
    assert "(d amplitude_0 / d damper.0.clearance: m per m)" in lines
    (head,) = [line for line in lines if line.split()[:1] == ["value"]]
    assert head.split()[-5:] == ["d", "amplitude_0", "/", "d", "damper.0.clearance"]
    assert head.count("damper.0.clearance") == 1
    rows = [line.split() for line in lines[lines.index(head) + 1 :]]
    table = json.loads(run_cli("sweep", str(scenario), "--json").stdout)["points"]
    for row, point in zip(rows, table, strict=True):
        expected = point["derivatives"]["damper.0.clearance"]["amplitude"][0]
        assert float(row[-1]) == pytest.approx(expected, rel=1e-5)


def test_the_plot_is_written(run_cli: RunCli, tmp_path: Path) -> None:
    scenario = frf_scenario(tmp_path)
    plot = tmp_path / "sensitivity.png"
    done = run_cli("sweep", str(scenario), "--derivative", AMPLITUDE, "--plot", str(plot))
    assert done.returncode == 0, done.stderr
    assert plot.stat().st_size > 10_000
    assert plot.read_bytes().startswith(PNG_SIGNATURE)


@pytest.mark.parametrize(
    ("given", "named"),
    [
        ("damper.0.nothing", "damper.0.nothing"),
        ("damper.4.clearance", "damper.4.clearance"),
        ("nowhere.0.x", "nowhere.0.x"),
    ],
)
def test_a_bad_derivative_path_is_refused_with_one_line(
    run_cli: RunCli, tmp_path: Path, given: str, named: str
) -> None:
    done = run_cli("sweep", str(frf_scenario(tmp_path)), "--derivative", given)
    assert done.returncode == 2
    assert done.stdout == "" and "Traceback" not in done.stderr
    (line,) = done.stderr.strip().splitlines()
    assert named in line


def test_a_bad_scenario_key_is_refused(run_cli: RunCli, tmp_path: Path) -> None:
    done = run_cli("sweep", str(frf_scenario(tmp_path, 'derivatives = ["sweep.x"]\n')))
    assert done.returncode == 2 and "Traceback" not in done.stderr
    (line,) = done.stderr.strip().splitlines()
    assert "[sweep] derivatives" in line and "sweep.x" in line
