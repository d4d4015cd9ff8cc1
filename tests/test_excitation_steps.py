"""What a fixed step can follow of an excitation that is not a sum of harmonics (a new
user's probe): a recorded pulse shorter than the step had fallen between two steps' stages
and was lost whole (x = 0, input work 0) by rk4, newmark-implicit and generalized-alpha,
without a word, where a harmonic that fast is refused up front. And a sum of no
harmonics, which had run as no forcing."""

from __future__ import annotations

import math
import subprocess
import sys
from pathlib import Path

import pytest

import vibroimpact as vi

M, K, C = 1.0, (2 * math.pi) ** 2, 0.1
# A 1 ms triangle of 100 N at 5 s: an impulse of 0.05 N s.
PULSE = vi.Recorded(time=[0.0, 5.0, 5.0005, 5.001, 8.0], value=[0.0, 0.0, 100.0, 0.0, 0.0])


def struck() -> vi.System:
    return vi.System(
        structure=vi.Oscillator(mass=M, stiffness=K, damping=C),
        excitations=[vi.Force(at=0, signal=PULSE)],
    )


def impulse_response(t: float) -> float:
    """x(t) of the oscillator struck by 0.05 N s at the pulse's centre, 5.0005 s."""
    wn, zeta = math.sqrt(K / M), C / (2 * math.sqrt(K * M))
    wd = wn * math.sqrt(1 - zeta * zeta)
    s = t - 5.0005
    return 0.05 / (M * wd) * math.exp(-zeta * wn * s) * math.sin(wd * s)


@pytest.mark.timeout(60)
@pytest.mark.parametrize(
    ("method", "dt"), [("rk4", 3e-3), ("newmark-implicit", 1e-2), ("generalized-alpha", 3e-3)]
)
def test_a_fixed_step_that_would_pass_over_a_recorded_pulse_is_refused(
    method: str, dt: float
) -> None:
    with pytest.raises(
        vi.InvalidInputError, match=r'"recorded" excitation changes every 5\.000e-4'
    ):
        vi.simulate(struck(), method=method, dt=dt, t_end=6.0, history=False)


@pytest.mark.timeout(60)
@pytest.mark.parametrize(("method", "dt"), [("rk4", 1e-4), ("dop853", None)])
def test_steps_that_see_the_pulse_give_its_impulse_response(method: str, dt: float | None) -> None:
    options = {} if dt is None else {"dt": dt}
    sol = vi.simulate(struck(), method=method, t_end=6.0, history=False, **options)
    expected = impulse_response(6.0)
    assert sol.final_state["structure_displacement"][0] == pytest.approx(expected, rel=1e-3)


@pytest.mark.timeout(60)
def test_the_command_line_refuses_it_on_one_line(tmp_path: Path) -> None:
    scenario = tmp_path / "pulse.toml"
    text = struck().to_toml()
    assert "[solver]" not in text
    scenario.write_text(text + '\n[solver]\nmethod = "rk4"\ndt = 3e-3\nt_end = 6.0\n')
    done = subprocess.run(
        [sys.executable, "-m", "vibroimpact", "simulate", str(scenario)],
        capture_output=True,
        text=True,
        timeout=50,
        check=False,
    )
    assert done.returncode == 2, done.stderr
    (line,) = done.stderr.strip().splitlines()
    assert "changes every 5.000e-4 s" in line and "dt = 3e-3 s" in line


@pytest.mark.timeout(60)
def test_a_sum_of_no_harmonics_is_refused() -> None:
    # (Refused when the System is built, as its other signals' checks are.)
    with pytest.raises(vi.InvalidInputError, match="harmonics signal needs at least one term"):
        vi.System(
            structure=vi.Oscillator(mass=M, stiffness=K, damping=C),
            excitations=[vi.Force(at=0, signal=vi.Harmonics(amplitudes=[], frequencies=[]))],
        )
