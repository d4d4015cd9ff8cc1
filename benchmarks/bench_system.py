"""0.2 systems against scipy's solve_ivp with events, at equal error.

A harmonically forced impact damper (rigid impacts, e = 0.6) started on its
Masri-Caughey two-impacts-per-cycle orbit, so that the exact answer is known at
every instant (shared/reference/forced-oracles.md): both sides integrate
``PERIODS`` forcing periods at several tolerances (the orbit is unstable at these
parameters, so only a few); the error is the primary's displacement at the end
against the closed form, relative to the static deflection. For each error target the
cheapest run of each side and the speed ratio are printed. Then the dropped
ball (e = 0.8, 1 m, to 6 s): time per run. Then the 3-mode cantilever with two
dampers of examples/beam_two_dampers.toml (RK4 with events, to 0.15 s: at 1 s the
rigid damper chatters beyond RK4's step and the run stops, as it should): steps per
second with the file's laws and with both dampers hertz-damped, at dt = 1e-5 and
1e-6, against a peer measured in the same run, the same system with its dampers'
clearances 1 m (no contact, every event test still made). CPU times are medians of
repeated calls from Python (call overhead included).

    python benchmarks/bench_system.py

Goals (issue 8): the forced damper over 1000 periods under 5 ms and >= 100x faster
than solve_ivp with events at equal accuracy; the ball under 100 us per run; the
cantilever with two dampers >= 1e7 steps/s.
"""

from __future__ import annotations

import math
import statistics
import time
import tomllib
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

import vibroimpact as vi

PERIODS = 3
M, K, F0, m, e = 1.0, 100.0, 1.0, 0.1, 0.6
WN, XST, MU = math.sqrt(K / M), F0 / K, m / M
R, D = 0.8, 2.0
W = R * WN
P = 1 / (1 - R * R)
A1 = 1 + (2 * MU * R / math.pi) * math.tan(math.pi / (2 * R))
B1 = (2 / math.pi) * (1 - e) * (1 + MU) / (1 + e)
Q = (A1 * D + math.sqrt((A1 * D) ** 2 - (A1 * A1 + B1 * B1) * (D * D - 4 * P * P))) / (
    2 * (A1 * A1 + B1 * B1)
)
PHI = math.atan2(B1 * Q, A1 * Q - D / 2)
AMPLITUDE = 2 * MU * R * Q / math.pi / math.cos(math.pi / (2 * R))


def primary(tau: float) -> float:
    """The primary's displacement (scaled) on the orbit, tau = wn t from an impact."""
    half = math.pi / R
    k = math.floor(tau / half)
    local = tau - k * half
    x = P * math.cos(R * local + PHI) + AMPLITUDE * math.sin(local - math.pi / (2 * R))
    return x if k % 2 == 0 else -x


def start() -> list[float]:
    rate = -P * R * math.sin(PHI) + AMPLITUDE * math.cos(-math.pi / (2 * R))
    return [XST * primary(0.0), WN * XST * rate, XST * Q, WN * XST * (-2 * R * Q / math.pi)]


def median_time(run: Callable[[], Any], repeats: int = 5) -> tuple[float, Any]:
    times, result = [], None
    for _ in range(repeats):
        t0 = time.perf_counter()
        result = run()
        times.append(time.perf_counter() - t0)
    return statistics.median(times), result


def ours(rtol: float, t_end: float) -> float:
    x0, v0, y0, u0 = start()
    sol = vi.simulate_system(
        {"kind": "oscillator", "mass": M, "stiffness": K},
        damper=[{"mass": m, "at": 0, "clearance": D * XST / 2, "law": "rigid", "restitution": e}],
        excitation=[
            {
                "kind": "force",
                "at": 0,
                "signal": "harmonic",
                "amplitude": F0,
                "frequency": W / (2 * math.pi),
                "phase": PHI,
            }
        ],
        initial={
            "structure_displacement": [x0],
            "structure_velocity": [v0],
            "damper_displacement": [y0],
            "damper_velocity": [u0],
        },
        t_end=t_end,
        method="dop853",
        rtol=rtol,
        atol=rtol * 1e-3,
        history=False,
    )
    return float(sol.final_state["structure_displacement"][0])


def theirs(rtol: float, t_end: float) -> float:
    from scipy.integrate import solve_ivp

    half = D * XST / 2

    def rhs(t: float, y: np.ndarray) -> list[float]:
        force = F0 * math.cos(W * t + PHI)
        return [y[1], (force - K * y[0]) / M, y[3], 0.0]

    def upper(t: float, y: np.ndarray) -> float:
        return half - (y[2] - y[0])

    def lower(t: float, y: np.ndarray) -> float:
        return half + (y[2] - y[0])

    for event in (upper, lower):
        event.terminal = True  # type: ignore[attr-defined]
        event.direction = -1  # type: ignore[attr-defined]
    t, y = 0.0, np.array(start())
    while t < t_end:
        r = solve_ivp(
            rhs, (t, t_end), y, method="DOP853", events=(upper, lower), rtol=rtol, atol=rtol * 1e-3
        )
        t, y = float(r.t[-1]), r.y[:, -1].copy()
        if r.status == 1:
            after = -e * (y[3] - y[1])
            momentum = M * y[1] + m * y[3]
            y[1] = (momentum - m * after) / (M + m)
            y[3] = y[1] + after
            # Step off the wall the event was located on.
            t = math.nextafter(t, math.inf)
    return float(y[0])


def main() -> None:
    t_end = PERIODS * 2 * math.pi / W
    exact = XST * primary(WN * t_end)
    rows: dict[str, list[tuple[float, float, float]]] = {"vibroimpact": [], "scipy": []}
    for rtol in (1e-6, 1e-8, 1e-10, 1e-12):
        for name, run in (("vibroimpact", ours), ("scipy", theirs)):
            seconds, x = median_time(lambda run=run, rtol=rtol: run(rtol, t_end), 3)
            rows[name].append((rtol, seconds, abs(x - exact) / XST))
    print(f"forced impact damper on its Masri-Caughey orbit, {PERIODS} periods, DOP853 both sides")
    for name, runs in rows.items():
        for rtol, seconds, error in runs:
            print(f"  {name:<12} rtol {rtol:.0e}: {seconds * 1e3:9.3f} ms, error {error:.1e}")
    for target in (1e-4, 1e-6, 1e-8):
        best = {
            name: min((s for _, s, err in runs if err <= target), default=None)
            for name, runs in rows.items()
        }
        a, b = best["vibroimpact"], best["scipy"]
        if a is None or b is None:
            print(f"  error <= {target:.0e}: not reached by one side")
            continue
        print(
            f"  error <= {target:.0e}: vibroimpact {a * 1e3:.3f} ms, scipy {b * 1e3:.1f} ms, "
            f"ratio {b / a:.0f}x (goal 100x)"
        )
    # The orbit is unstable at these parameters, so 1000 periods are timed, not scored.
    long = 1000 * 2 * math.pi / W
    for rtol in (1e-6, 1e-8):
        seconds, _ = median_time(lambda rtol=rtol: ours(rtol, long), 3)
        print(f"  1000 periods, vibroimpact rtol {rtol:.0e}: {seconds * 1e3:.1f} ms (goal 5 ms)")

    def ball() -> Any:
        return vi.simulate_system(
            {"kind": "oscillator", "mass": 0.2, "stiffness": 0.0},
            stop=[{"at": 0, "side": "lower", "gap": 1.0, "law": "rigid", "restitution": 0.8}],
            gravity={},
            t_end=6.0,
            method="rk4",
            dt=1e-2,
            history=False,
        )

    seconds, sol = median_time(ball, 51)
    t_inf = math.sqrt(2 / 9.81) * 1.8 / 0.2
    print(
        f"ball dropped 1 m (e = 0.8) to 6 s, RK4 dt 1e-2: {seconds * 1e6:.0f} us per run "
        f"(goal 100 us); rests at {sol.contacts.onset[-1]:.10f} s, exact {t_inf:.10f} s"
    )
    cantilever()


BEAM = Path(__file__).resolve().parents[1] / "examples" / "beam_two_dampers.toml"


def cantilever() -> None:
    """Steps per second of the 3-mode cantilever with two dampers, RK4 with events."""
    scenario = tomllib.loads(BEAM.read_text(encoding="utf-8"))
    laws: dict[str, dict[str, Any]] = {
        "the file's laws (hertz-damped, rigid)": {},
        "both hertz-damped": {"law": "hertz-damped", "stiffness": 1e7, "restitution": 0.6},
        "peer: clearances 1 m, no contact": {
            "clearance": 1.0,
            "lower_clearance": 1.0,
            "upper_clearance": 1.0,
        },
    }

    def run(dt: float, change: dict[str, Any]) -> Any:
        dampers = []
        for given in scenario["damper"]:
            damper = dict(given) | {k: v for k, v in change.items() if "clearance" not in k}
            for key in ("clearance", "lower_clearance", "upper_clearance"):
                if key in given and key in change:
                    damper[key] = change[key]
            dampers.append(damper)
        return vi.simulate_system(
            scenario["structure"],
            damper=dampers,
            excitation=scenario["excitation"],
            t_end=0.15,
            method="rk4",
            dt=dt,
            history=False,
            max_steps=10**9,
        )

    print("3-mode cantilever, two dampers, RK4 with events, to 0.15 s (goal 1e7 steps/s)")
    for dt, repeats in ((1e-5, 21), (1e-6, 7)):
        rates = {}
        for name, change in laws.items():
            seconds, sol = median_time(lambda dt=dt, change=change: run(dt, change), repeats)
            rates[name] = sol.steps / seconds
            contacts = len(sol.contacts.onset)
            print(
                f"  dt {dt:.0e}, {name}: {rates[name]:.2e} steps/s "
                f"({sol.steps} steps, {contacts} contacts)"
            )
        peer = rates.pop("peer: clearances 1 m, no contact")
        for name, rate in rates.items():
            verdict = "meets" if rate >= 1e7 else "misses"
            print(f"  dt {dt:.0e}, {name}: {rate / peer:.2f}x the peer; {verdict} the goal")


if __name__ == "__main__":
    main()
