"""The two-mass RK4 path against the same arithmetic compiled by numba, side by side.

The founding paper's Table 1 system with the Hertz law and the contact damper
(no rate-dependent law, so the trajectory is the accelerations' alone), RK4 at
dt = 1e-4 s for 1e7 steps from a 0.1 m/s collision. The numba kernel repeats the
core's operations in the core's order (per-unit-mass coefficients, the side of
the nearer wall, the law's force clamped at zero, RK4's stage sums), so the two
final states must agree bit for bit; the speed ratio is printed with medians of
repeated runs.

    pip install numba   # not a dependency of vibroimpact
    python benchmarks/bench_numba.py

Goal (issue 8): the two-mass RK4 path at least as fast as numba's.
"""

from __future__ import annotations

import math
import statistics
import time

import vibroimpact as vi

M, K, C, m, d = 1.0, 1.0, 0.01, 0.25, 0.01
K_HZ, C1 = 3000.0, 0.01
DT, STEPS = 1e-4, 10_000_000


def ours() -> tuple[float, tuple[float, float, float, float]]:
    system = vi.ImpactDamper(main_mass=M, stiffness=K, damping=C, impact_mass=m, clearance=d)
    contact = vi.Contact("hertz", stiffness=K_HZ, damping=C1)
    start = vi.InitialState(impact_displacement=d, impact_velocity=0.1)
    t0 = time.perf_counter()
    sol = vi.simulate(
        system,
        contact,
        start,
        method="rk4",
        stepping="fixed",
        dt=DT,
        t_end=STEPS * DT,
        history=False,
        max_steps=STEPS,
    )
    seconds = time.perf_counter() - t0
    s = sol.final_state
    return seconds, (
        s.main_displacement,
        s.main_velocity,
        s.impact_displacement,
        s.impact_velocity,
    )


def build() -> object:
    from numba import njit

    damping_per_mass, stiffness_per_mass = C / M, K / M
    inverse_main, inverse_impact = 1.0 / M, 1.0 / m

    @njit(cache=False)
    def accelerations(w: float, wv: float, y: float, yv: float) -> tuple[float, float]:
        main = -(damping_per_mass * wv + stiffness_per_mass * w)
        u = y - w
        if abs(u) > d:
            side = 1.0 if (u > 0.0 or (u == 0.0 and yv - wv >= 0.0)) else -1.0
            indentation = side * u - d
            rate = side * (yv - wv)
            law = K_HZ * indentation * math.sqrt(indentation) if indentation > 0.0 else 0.0
            total = law + C1 * rate if indentation > 0.0 else 0.0
            push = side * total
            return main + push * inverse_main, -push * inverse_impact
        return main, 0.0

    @njit(cache=False)
    def run(steps: int, dt: float) -> tuple[float, float, float, float]:
        w, wv, y, yv = 0.0, 0.0, d, 0.1
        half = 0.5 * dt
        sixth = dt / 6.0
        for _ in range(steps):
            a1w, a1y = accelerations(w, wv, y, yv)
            k1 = (wv, a1w, yv, a1y)
            a2w, a2y = accelerations(
                w + half * k1[0], wv + half * k1[1], y + half * k1[2], yv + half * k1[3]
            )
            k2 = (wv + half * k1[1], a2w, yv + half * k1[3], a2y)
            a3w, a3y = accelerations(
                w + half * k2[0], wv + half * k2[1], y + half * k2[2], yv + half * k2[3]
            )
            k3 = (wv + half * k2[1], a3w, yv + half * k2[3], a3y)
            a4w, a4y = accelerations(
                w + dt * k3[0], wv + dt * k3[1], y + dt * k3[2], yv + dt * k3[3]
            )
            k4 = (wv + dt * k3[1], a4w, yv + dt * k3[3], a4y)
            w = w + sixth * (k1[0] + 2.0 * (k2[0] + k3[0]) + k4[0])
            wv = wv + sixth * (k1[1] + 2.0 * (k2[1] + k3[1]) + k4[1])
            y = y + sixth * (k1[2] + 2.0 * (k2[2] + k3[2]) + k4[2])
            yv = yv + sixth * (k1[3] + 2.0 * (k2[3] + k3[3]) + k4[3])
        return w, wv, y, yv

    run(10, DT)  # compile
    return run


def main() -> None:
    try:
        kernel = build()
    except ImportError:
        raise SystemExit("numba is not installed: pip install numba") from None
    mine, theirs = [], []
    state_ours = state_numba = None
    for _ in range(5):
        seconds, state_ours = ours()
        mine.append(seconds)
        t0 = time.perf_counter()
        state_numba = kernel(STEPS, DT)  # type: ignore[operator]
        theirs.append(time.perf_counter() - t0)
    a, b = statistics.median(mine), statistics.median(theirs)
    same = state_ours == tuple(state_numba)  # type: ignore[arg-type]
    print(f"Table 1 system, Hertz law, RK4 at dt = {DT} s, {STEPS:.0e} steps, median of 5 runs")
    print(f"  vibroimpact  {STEPS / a:.3e} steps/s")
    print(f"  numba        {STEPS / b:.3e} steps/s")
    print(f"  ratio (vibroimpact / numba) {b / a:.2f} (goal >= 1)")
    print(f"  final states bit for bit the same: {same}")
    if not same:
        print(f"    vibroimpact {state_ours}\n    numba       {state_numba}")


if __name__ == "__main__":
    main()
