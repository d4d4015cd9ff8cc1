"""Steps land where a run's inputs change: on each sample of a recorded signal (an adaptive
method's error estimate cannot see a kink ahead, so on a system at rest under a record that
begins with a quiet stretch it grew its steps past the whole pulse), and on the start of the
window from which peak and RMS are recorded (the step across it was left out). Values
against SciPy integrating each sample interval on its own, and against the closed form of a
free decay."""

from __future__ import annotations

import math
from itertools import pairwise
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import quad, solve_ivp

from vibroimpact.system import simulate_system

M, K, C = 2.0, 800.0, 1.6
# A ground acceleration at rest for 10 s, then one triangular pulse and back (m/s^2).
PULSE_TIMES = [0.0, 10.0, 10.5, 11.0, 11.5]
PULSE_VALUES = [0.0, 0.0, 9.81, -9.81, 0.0]


def pulse_oracle(t_end: float) -> tuple[float, np.ndarray]:
    """|x| at its largest and (x, v) at t_end of m x'' + c x' + k x = -m a(t), a linear
    between the samples and zero after them, each interval integrated on its own."""
    y = np.zeros(2)
    peak = 0.0
    knots = [*PULSE_TIMES, t_end]
    values = [*PULSE_VALUES, 0.0]
    for (t0, t1), (a0, a1) in zip(pairwise(knots), pairwise(values), strict=True):

        def rhs(
            t: float, s: np.ndarray, t0: float = t0, t1: float = t1, a0: float = a0, a1: float = a1
        ) -> list[float]:
            a = a0 + (a1 - a0) * (t - t0) / (t1 - t0)
            return [s[1], (-K * s[0] - C * s[1]) / M - a]

        r = solve_ivp(rhs, (t0, t1), y, method="DOP853", rtol=1e-12, atol=1e-15, dense_output=True)
        grid = np.linspace(t0, t1, max(2, int((t1 - t0) / 1e-4)))
        peak = max(peak, float(np.max(np.abs(r.sol(grid)[0]))))
        y = r.y[:, -1]
    return peak, y


@pytest.mark.parametrize("method", ["dopri5", "dop853"])
@pytest.mark.parametrize("t_end", [30.0, 60.0, 100.0])
def test_adaptive_steps_do_not_pass_over_a_pulse_after_a_quiet_stretch(
    tmp_path: Path, method: str, t_end: float
) -> None:
    # Before the steps landed on the samples, these runs reported no response at all.
    rows = "\n".join(f"{t!r},{a!r}" for t, a in zip(PULSE_TIMES, PULSE_VALUES, strict=True))
    (tmp_path / "ground.csv").write_text("t,a\n" + rows + "\n")
    sol = simulate_system(
        {"kind": "oscillator", "mass": M, "stiffness": K, "damping": C},
        excitation=[{"kind": "base", "signal": "recorded", "file": "ground.csv"}],
        t_end=t_end,
        method=method,
        rtol=1e-10,
        atol=1e-13,
        record_from=0.0,
        history=False,
        base_dir=tmp_path,
    )
    peak, state = pulse_oracle(t_end)
    assert peak > 1e-3
    assert sol.peak[0] == pytest.approx(peak, rel=1e-6)
    if t_end == 30.0:
        # 18.5 s of free decay after the pulse leave e^(-7.4) of it.
        final = sol.final_state
        assert final["structure_displacement"][0] == pytest.approx(state[0], abs=1e-9 * peak)
        assert sol.final_state["structure_velocity"][0] == pytest.approx(
            state[1], abs=1e-9 * peak * math.sqrt(K / M)
        )
    assert abs(sol.energy["residual"]) < 1e-6 * sol.energy["input_work"]


@pytest.mark.parametrize(
    ("method", "options", "rms_tolerance"),
    [
        # The exact flow's steps are an eighth of the period, where the quintic
        # interpolant would err by 2e-6: its mean square is the flow's own at the nodes.
        ("exact", {}, 1e-11),
        ("dop853", {"rtol": 1e-12, "atol": 1e-15}, 1e-8),
        ("rk4", {"dt": 1e-3}, 1e-9),
    ],
)
def test_peak_and_rms_cover_the_whole_window_from_record_from(
    method: str, options: dict[str, float], rms_tolerance: float
) -> None:
    # Free decay of a 1 Hz oscillator from x = 1; the window starts 0.02 s before the first
    # trough, inside a step of every method.
    m, k, c = 1.0, (2 * math.pi) ** 2, 0.4
    wn = math.sqrt(k / m)
    zeta = c / (2 * math.sqrt(k * m))
    wd = wn * math.sqrt(1 - zeta**2)

    def x(t: float) -> float:
        return math.exp(-zeta * wn * t) * (math.cos(wd * t) + zeta * wn / wd * math.sin(wd * t))

    trough = math.pi / wd
    record_from, t_end = trough - 0.02, trough + 2.0
    rms = math.sqrt(
        quad(lambda t: x(t) ** 2, record_from, t_end, limit=200, epsabs=0, epsrel=1e-13)[0]
        / (t_end - record_from)
    )
    sol = simulate_system(
        {"kind": "oscillator", "mass": m, "stiffness": k, "damping": c},
        initial={"structure_displacement": [1.0]},
        t_end=t_end,
        method=method,
        record_from=record_from,
        history=False,
        **options,
    )
    assert sol.recorded_time == pytest.approx(t_end - record_from, rel=1e-12)
    assert sol.peak[0] == pytest.approx(abs(x(trough)), rel=1e-9)
    assert sol.rms[0] == pytest.approx(rms, rel=rms_tolerance)


def test_a_tiny_first_step_grows_instead_of_stopping_as_chattering() -> None:
    # dt is an adaptive method's first step; 1e-60 s stopped the run as "chattering" (its
    # steps were below the time's round-off for a while) although no contact exists.
    structure = {"kind": "oscillator", "mass": 1.0, "stiffness": 100.0}
    force = [{"kind": "force", "at": 0, "signal": "harmonic", "amplitude": 1.0, "frequency": 1.0}]
    runs = [
        simulate_system(
            structure,
            excitation=force,
            t_end=1.0,
            method="dopri5",
            dt=dt,
            rtol=1e-10,
            atol=1e-13,
            history=False,
        )
        for dt in (1e-60, None)
    ]
    for key in ("structure_displacement", "structure_velocity"):
        assert runs[0].final_state[key][0] == pytest.approx(runs[1].final_state[key][0], rel=1e-8)


@pytest.mark.parametrize(
    ("method", "speed_tolerance"),
    # Near grazing the speed, sqrt(2 a depth), doubles the relative error of the depth:
    # dop853's default rtol (1e-8 of 0.05 m) is 1e-3 of a 5e-7 m overshoot.
    [("exact", 1e-6), ("dop853", 1e-2)],
)
@pytest.mark.parametrize("overshoot", [5e-6, 5e-7])
def test_an_orbit_that_just_passes_its_stop_hits_it_whatever_the_phase(
    method: str, speed_tolerance: float, overshoot: float
) -> None:
    # A 1 Hz oscillator (1 % damping) forced at 0.8 Hz, started on its linear orbit of
    # amplitude 0.05 m + overshoot, beside a rigid stop at 0.05 m: the orbit reaches
    # past the stop, so within one forcing period it hits it, at the speed of the orbit
    # where it crosses 0.05 m. The cubic through the step ends errs by 5e-5 m at the
    # exact flow's steps: the dip was judged on it, and most starts missed the impact.
    k = (2 * np.pi) ** 2
    c = 0.01 * 2 * np.sqrt(k)
    f = 0.8
    w = 2 * np.pi * f
    response = 1 / (k - w * w + 1j * c * w)
    amplitude = (0.05 + overshoot) / abs(response)
    structure = {"kind": "oscillator", "mass": 1.0, "stiffness": k, "damping": c}
    stop = [{"at": 0, "side": "upper", "gap": 0.05, "law": "rigid", "restitution": 0.8}]
    missed = []
    for start in np.linspace(0.1, 2 * np.pi - 0.1, 24):
        phase = start - np.angle(response)
        x = amplitude * response * np.exp(1j * phase)
        sol = simulate_system(
            structure,
            stop=stop,
            excitation=[
                {
                    "kind": "force",
                    "at": 0,
                    "signal": "harmonic",
                    "amplitude": amplitude,
                    "frequency": f,
                    "phase": phase,
                }
            ],
            initial={"structure_displacement": [x.real], "structure_velocity": [(1j * w * x).real]},
            method=method,
            t_end=1 / f,
            history=False,
        )
        # |X| sin(theta) at the crossing, cos(theta) = 0.05 / |X|.
        speed = w * abs(x) * np.sqrt(1 - (0.05 / abs(x)) ** 2)
        if list(sol.contacts.kind) != ["impact"] or not np.isclose(
            sol.contacts.approach_speed[0], speed, rtol=speed_tolerance
        ):
            missed.append(round(float(start), 3))
    assert not missed


def test_without_a_window_nothing_is_recorded_not_a_peak_of_zero() -> None:
    # The peak read 0.0 (which looks like a measurement) while the RMS read NaN.
    structure = {"kind": "oscillator", "mass": 1.0, "stiffness": 100.0}
    sol = simulate_system(
        structure,
        initial={"structure_displacement": [0.01]},
        t_end=0.2,
        method="dop853",
        history=False,
    )
    assert sol.recorded_time == 0.0
    assert np.isnan(sol.peak).all() and np.isnan(sol.rms).all()
