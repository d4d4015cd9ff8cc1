"""Throughput and call overhead of the core, driven from Python.

Steps per second of both methods on the founding paper's Table 1 system
(Hyster-Hertz contact, e = 0.9) over 1e7 steps (history thinned so that
storage does not dominate), and the overhead of one ``simulate`` call of a
single step. Prints medians.

    python benchmarks/bench_steps.py [--steps N] [--repeats R]

Goals (issue 2): >= 2e7 steps/s for one trajectory, <= 5 us per call.
"""

from __future__ import annotations

import argparse
import statistics
import time

import vibroimpact as vi


def table1() -> tuple[vi.ImpactDamper, vi.Contact, vi.InitialState]:
    system = vi.ImpactDamper(
        main_mass=1.0, stiffness=1.0, damping=0.01, impact_mass=0.25, clearance=0.01
    )
    # e = 0.9: over 1e7 steps the paper's lagged Newmark pumps energy into an
    # elastic contact until the core reports a blow-up (see report.md).
    contact = vi.Contact("hyster-hertz", stiffness=3000.0, damping=0.01, restitution=0.9)
    start = vi.InitialState(impact_displacement=0.01, impact_velocity=0.1)
    return system, contact, start


def throughput(method: str, steps: int, repeats: int) -> tuple[float, int]:
    system, contact, start = table1()
    dt = 1e-4
    times = []
    contacts = 0
    for _ in range(repeats):
        t0 = time.perf_counter()
        sol = vi.simulate(
            system, contact, start, method=method, dt=dt, t_end=steps * dt, every=100_000
        )
        times.append(time.perf_counter() - t0)
        assert sol.steps == steps
        contacts = len(sol.contacts)
    return steps / statistics.median(times), contacts


def overhead(calls: int, repeats: int) -> float:
    system, contact, start = table1()
    medians = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        for _ in range(calls):
            vi.simulate(system, contact, start, method="newmark", dt=1e-4, t_end=1e-4)
        medians.append((time.perf_counter() - t0) / calls)
    return statistics.median(medians)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", type=int, default=10_000_000, help="steps per run")
    parser.add_argument("--repeats", type=int, default=5, help="runs per median")
    args = parser.parse_args()
    print(
        f"Table 1 system (e = 0.9), dt = 1e-4 s, {args.steps:.0e} steps, "
        f"median of {args.repeats} runs"
    )
    for method in ("newmark", "rk4"):
        rate, contacts = throughput(method, args.steps, args.repeats)
        goal = "meets" if rate >= 2e7 else "misses"
        print(f"  {method:8s} {rate:10.3e} steps/s  ({contacts} contacts; {goal} the 2e7 goal)")
    per_call = overhead(20_000, args.repeats)
    goal = "meets" if per_call <= 5e-6 else "misses"
    print(f"  call overhead (one-step simulate): {per_call * 1e6:.2f} us ({goal} the 5 us goal)")


if __name__ == "__main__":
    main()
