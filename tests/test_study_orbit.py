"""Studies with ``analysis = "orbit"``: each point settled, then its periodic orbit shot
for in the core with its Floquet multipliers (a Hessenberg QR eigensolver in Rust).
Against closed forms for a forced linear oscillator (multipliers of modulus
exp(-zeta wn T), amplitude |F / (K - w^2 M + i w C)|), and against
``analyses.orbit`` (numpy's eigenvalues) for a forced impact damper."""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from study_checks import FORCED_DAMPER, assert_refused, load_study  # noqa: E402
from vibroimpact import study as st
from vibroimpact.analysis import orbit, runner, with_parameter

ROOT = Path(__file__).resolve().parents[1]
M, K, ZETA, F0 = 1.0, 3947.8, 0.02, 5.0
WN = math.sqrt(K / M)
C = 2 * ZETA * WN * M

LINEAR = f"""
[structure]
kind = "oscillator"
mass = {M}
stiffness = {K}
damping = {C}

[[excitation]]
kind = "force"
at = 0
signal = "harmonic"
amplitude = {F0}
frequency = 10.0

[solver]
method = "exact"
t_end = 1.0

[study]
analysis = "orbit"
settle_periods = 5
metrics = ["amplitude", "impacts_per_period", "stable", "largest_multiplier"]

[study.axes]
"excitation.0.frequency" = [5.0, 9.5, 10.0, 12.0]
"""

DAMPER = (
    FORCED_DAMPER
    + """
[study]
analysis = "orbit"
settle_periods = 60
metrics = ["amplitude", "impacts_per_period", "stable", "largest_multiplier"]

[study.axes]
"excitation.0.frequency" = [9.0, 10.0, 11.0]
"""
)


def load(tmp_path: Path, text: str) -> st.Study:
    return load_study(tmp_path / "study.toml", text)


def test_a_forced_linear_oscillators_orbits_match_the_closed_form(tmp_path: Path) -> None:
    ds = st.run(load(tmp_path, LINEAR), tmp_path / "out.nc")
    assert int(ds["status"].max()) == 0
    for frequency in (5.0, 9.5, 10.0, 12.0):
        point = ds.sel({"excitation.0.frequency": frequency})
        w, period = 2 * math.pi * frequency, 1 / frequency
        # The monodromy is exp(A T): both multipliers of modulus exp(-zeta wn T). Its
        # central differences err by ~1e-7 at resonance (10 Hz), where the two
        # multipliers nearly coincide and move most with the matrix.
        decay = math.exp(-ZETA * WN * period)
        assert point["largest_multiplier"].item() == pytest.approx(decay, rel=1e-6)
        assert point["stable"].item() == 1.0
        amplitude = F0 / abs(K - w * w * M + 1j * w * C)
        assert point["amplitude"].values[0] == pytest.approx(amplitude, rel=1e-8)
        assert point["impacts_per_period"].item() == 0.0


def test_an_impact_dampers_orbits_match_the_analysis(tmp_path: Path) -> None:
    study = load(tmp_path, DAMPER)
    ds = st.run(study, tmp_path / "out.nc")
    assert int(ds["status"].max()) == 0
    base = {k: v for k, v in study.data.items() if k != "study"}
    stable_seen = False
    for frequency in (9.0, 10.0, 11.0):
        data = with_parameter(base, "excitation.0.frequency", frequency)
        run = runner(data)
        settled = run.map(run.initial_state(), 60)
        result = orbit(run, settled)
        assert result.converged
        point = ds.sel({"excitation.0.frequency": frequency})
        # Rust's Hessenberg QR against numpy's LAPACK on the same monodromy.
        largest = float(np.abs(result.floquet_multipliers).max())
        assert point["largest_multiplier"].item() == pytest.approx(largest, rel=1e-9)
        assert point["stable"].item() == float(result.stable)
        np.testing.assert_allclose(point["amplitude"].values, result.amplitude, rtol=1e-9)
        assert point["impacts_per_period"].item() == result.impacts_per_period
        stable_seen |= result.stable
    assert stable_seen


def test_orbit_metrics_belong_to_the_orbit_analysis(tmp_path: Path) -> None:
    with pytest.raises(ValueError, match="stable.*not kept by analysis.*orbit"):
        load(tmp_path, LINEAR.replace('analysis = "orbit"', 'analysis = "run"'))
    with pytest.raises(ValueError, match="rms.*not kept.*orbit"):
        load(tmp_path, LINEAR.replace('metrics = ["amplitude"', 'metrics = ["rms", "amplitude"'))
    with pytest.raises(ValueError, match=r"orbit_periods.*in \[1, 10000000\]"):
        load(
            tmp_path, LINEAR.replace("settle_periods = 5", "settle_periods = 5\norbit_periods = 0")
        )


SECOND_FORCE = """
[[excitation]]
kind = "force"
at = 0
signal = "harmonic"
amplitude = {amplitude}
frequency = {frequency}
"""


def with_second_force(text: str, amplitude: float, frequency: float) -> str:
    """``text`` with a second harmonic force on the mass (after the first)."""
    head, tail = text.split("[solver]")
    return head + SECOND_FORCE.format(amplitude=amplitude, frequency=frequency) + "[solver]" + tail


def test_two_harmonics_with_a_common_period_give_the_superposed_orbit(tmp_path: Path) -> None:
    # 10 Hz and 20 Hz on the linear oscillator: the orbit is the sum of the two
    # steady responses, its amplitude their sum's largest |x| over a period.
    text = with_second_force(LINEAR, 3.0, 20.0).replace(
        '"excitation.0.frequency" = [5.0, 9.5, 10.0, 12.0]', '"excitation.0.amplitude" = [5.0]'
    )
    ds = st.run(load(tmp_path, text), tmp_path / "out.nc")
    assert int(ds["status"].max()) == 0
    t = np.linspace(0.0, 0.1, 200_001)
    x = np.zeros_like(t)
    for force, frequency in ((F0, 10.0), (3.0, 20.0)):
        w = 2 * math.pi * frequency
        x += (force / (K - w * w * M + 1j * w * C) * np.exp(1j * w * t)).real
    assert ds["amplitude"].values[0, 0] == pytest.approx(np.abs(x).max(), rel=1e-8)


@pytest.mark.parametrize(
    ("second", "words"),
    [
        (
            SECOND_FORCE.format(amplitude=1.0, frequency=10.0 * math.sqrt(2.0)),
            ["excitation 1", "14.14", "no common period"],
        ),
        (
            '[[excitation]]\nkind = "base"\nsignal = "white-noise"\nintensity = 1e-4\n'
            "cutoff_frequency = 50.0\nduration = 2.0\nseed = 1\n",
            ["excitation 1", '"white-noise" signal has no period'],
        ),
    ],
    ids=["harmonics with no common period", "a random excitation"],
)
def test_an_orbit_study_of_forcing_with_no_period_is_refused(
    tmp_path: Path, run_cli: Any, second: str, words: list[str]
) -> None:
    head, tail = LINEAR.split("[solver]")
    path = tmp_path / "study.toml"
    path.write_text(head + second + "[solver]" + tail)
    out = tmp_path / "out.nc"
    assert_refused(run_cli("study", str(path), "--out", str(out)), words, out)


def test_a_point_an_axis_makes_aperiodic_fails_alone(tmp_path: Path) -> None:
    # The second force at 20 Hz, then at 10 sqrt(2) Hz: no common period with 10 Hz.
    text = with_second_force(LINEAR, 1.0, 20.0).replace(
        '"excitation.0.frequency" = [5.0, 9.5, 10.0, 12.0]',
        f'"excitation.1.frequency" = [20.0, {10.0 * math.sqrt(2.0)!r}]',
    )
    ds = st.run(load(tmp_path, text), tmp_path / "out.nc")
    status = ds["status"].values
    assert status[0] == 0 and status[1] > 0
    assert "no common period" in str(ds.attrs["reasons"])
    assert np.isnan(ds["amplitude"].values[1]).all()


def test_points_with_no_orbit_near_their_start_fail_with_newtons_reason(tmp_path: Path) -> None:
    # Holmes's ball shot for from its scenario's start at once (no settling), over a
    # range of table accelerations where most period-one orbits are far away or unstable:
    # Newton's method fails at some points. Each such point fails alone with that
    # reason (before, a Newton step deep inside the table failed the point as an
    # "initial state inside its wall", a start the user never gave).
    text = (ROOT / "examples" / "bouncing_ball_table.toml").read_text(encoding="utf-8")
    text += """
[study]
analysis = "orbit"
settle_periods = 0
metrics = ["amplitude", "impacts_per_period", "stable", "largest_multiplier"]

[study.axes]
"excitation.0.amplitude" = { start = 5.0, stop = 60.0, count = 12 }
"""
    ds = st.run(load(tmp_path, text), tmp_path / "out.nc")
    status = ds["status"].values
    reasons = json.loads(ds.attrs["reasons"])
    assert (status == 0).any() and (status > 0).any(), status
    assert reasons and all("no orbit of 1 forcing period(s) found" in r for r in reasons), reasons
    failed = status > 0
    assert np.isnan(ds["largest_multiplier"].values[failed]).all()
    assert np.isfinite(ds["largest_multiplier"].values[~failed]).all()
