"""The two-mass RK4 path against the same arithmetic compiled by numba, side by side.

The founding paper's Table 1 system with the Hertz law and the contact damper
(no rate-dependent law, so the trajectory is the accelerations' alone), RK4 at
dt = 1e-4 s for 1e7 steps from a 0.1 m/s collision. The numba kernel repeats the
general kernel's operations in its order (per-unit-mass coefficients, each
wall's gap as its row times the coordinates plus the clearance, the law's force
where indented, the main mass's acceleration as (-C/M) w' - (K/M) w, RK4's
stages as the tableau's weights times the step: `y + (h/6) k1 + (h/3) k2 +
(h/3) k3 + (h/6) k4`, summed left to right), so the two final states must agree
bit for bit; the speed ratio is printed with medians of repeated runs. The
kernel also integrates the energy ledger (the damping's and each wall's
dissipation); the numba loop does not.

Two numba kernels run. One takes the system's parameters as arguments, as
vibroimpact's kernel does: the same arithmetic. The other freezes them into
the compiled code as constants, as a one-off script would; LLVM then drops the
multiplications by this system's unit mass and stiffness (exact, so the bits
stay the same): fewer operations than a kernel for any system can do.

    pip install numba   # not a dependency of vibroimpact
    python benchmarks/bench_numba.py

Goal (issue 8): the two-mass RK4 path at least as fast as numba's.

Where the time goes: the same runs of 2e5 steps (a third of them in contact) and of
1e7 (a thirteenth) give, for each side, the cost of a step in free flight and of one
with the pair indented (two runs, two unknowns; the steps in contact counted along
the same trajectory).
"""

from __future__ import annotations

import math
import statistics
import time
from collections.abc import Callable
from typing import NamedTuple

import vibroimpact as vi

M, K, C, m, d = 1.0, 1.0, 0.01, 0.25, 0.01
K_HZ, C1 = 3000.0, 0.01
DT, STEPS = 1e-4, 10_000_000
# The short run of the decomposition (a third of its steps in contact).
SHORT = 200_000


def ours(steps: int = STEPS) -> tuple[float, tuple[float, float, float, float]]:
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
        t_end=steps * DT,
        history=False,
        max_steps=steps,
    )
    seconds = time.perf_counter() - t0
    s = sol.final_state
    return seconds, (
        s.main_displacement,
        s.main_velocity,
        s.impact_displacement,
        s.impact_velocity,
    )


def build() -> tuple[Kernel, Kernel]:
    """The kernel with the parameters as arguments, and with them frozen."""
    return kernel(frozen=False), kernel(frozen=True)


def kernel(frozen: bool) -> Kernel:
    """The RK4 loop with the system's parameters taken at run time or, with
    ``frozen``, captured as compile-time constants (the argument then unread)."""
    from numba import njit

    params = (C / M, K / M, 1.0 / M, 1.0 / m, d, K_HZ, C1)

    @njit(cache=False)
    def accelerations(
        p: tuple[float, ...], w: float, wv: float, y: float, yv: float
    ) -> tuple[float, float]:
        damping_per_mass, stiffness_per_mass, inverse_main, inverse_impact, clearance, hertz, c1 = (
            params if frozen else p
        )
        main = (-damping_per_mass) * wv - stiffness_per_mass * w
        u = y - w
        if abs(u) > clearance:
            side = 1.0 if (u > 0.0 or (u == 0.0 and yv - wv >= 0.0)) else -1.0
            indentation = side * u - clearance
            rate = side * (yv - wv)
            law = hertz * indentation * math.sqrt(indentation) if indentation > 0.0 else 0.0
            total = law + c1 * rate if indentation > 0.0 else 0.0
            push = side * total
            return main + push * inverse_main, -push * inverse_impact
        return main, 0.0

    @njit(cache=False)
    def run(p: tuple[float, ...], steps: int, dt: float) -> tuple[float, float, float, float]:
        w, wv, y, yv = 0.0, 0.0, d, 0.1
        # The tableau's weights times the step, as the kernel makes them.
        half = dt * 0.5
        b1, b2 = dt * (1.0 / 6.0), dt * (1.0 / 3.0)
        for _ in range(steps):
            a1w, a1y = accelerations(p, w, wv, y, yv)
            k1 = (wv, a1w, yv, a1y)
            a2w, a2y = accelerations(
                p, w + half * k1[0], wv + half * k1[1], y + half * k1[2], yv + half * k1[3]
            )
            k2 = (wv + half * k1[1], a2w, yv + half * k1[3], a2y)
            a3w, a3y = accelerations(
                p, w + half * k2[0], wv + half * k2[1], y + half * k2[2], yv + half * k2[3]
            )
            k3 = (wv + half * k2[1], a3w, yv + half * k2[3], a3y)
            a4w, a4y = accelerations(
                p, w + dt * k3[0], wv + dt * k3[1], y + dt * k3[2], yv + dt * k3[3]
            )
            k4 = (wv + dt * k3[1], a4w, yv + dt * k3[3], a4y)
            w = w + b1 * k1[0] + b2 * k2[0] + b2 * k3[0] + b1 * k4[0]
            wv = wv + b1 * k1[1] + b2 * k2[1] + b2 * k3[1] + b1 * k4[1]
            y = y + b1 * k1[2] + b2 * k2[2] + b2 * k3[2] + b1 * k4[2]
            yv = yv + b1 * k1[3] + b2 * k2[3] + b2 * k3[3] + b1 * k4[3]
        return w, wv, y, yv

    @njit(cache=False)
    def count(
        p: tuple[float, ...], steps: int, short: int, dt: float
    ) -> tuple[int, int, float, float, float, float]:
        # `run`'s steps, written again (`run` calling a shared step ran 15 % slower,
        # which would flatter the ratio), counting those that start with the pair
        # indented: among the first `short` and among all.
        w, wv, y, yv = 0.0, 0.0, d, 0.1
        half = dt * 0.5
        b1, b2 = dt * (1.0 / 6.0), dt * (1.0 / 3.0)
        indented, indented_short = 0, 0
        for n in range(steps):
            if n == short:
                indented_short = indented
            if abs(y - w) > d:
                indented += 1
            a1w, a1y = accelerations(p, w, wv, y, yv)
            k1 = (wv, a1w, yv, a1y)
            a2w, a2y = accelerations(
                p, w + half * k1[0], wv + half * k1[1], y + half * k1[2], yv + half * k1[3]
            )
            k2 = (wv + half * k1[1], a2w, yv + half * k1[3], a2y)
            a3w, a3y = accelerations(
                p, w + half * k2[0], wv + half * k2[1], y + half * k2[2], yv + half * k2[3]
            )
            k3 = (wv + half * k2[1], a3w, yv + half * k2[3], a3y)
            a4w, a4y = accelerations(
                p, w + dt * k3[0], wv + dt * k3[1], y + dt * k3[2], yv + dt * k3[3]
            )
            k4 = (wv + dt * k3[1], a4w, yv + dt * k3[3], a4y)
            w = w + b1 * k1[0] + b2 * k2[0] + b2 * k3[0] + b1 * k4[0]
            wv = wv + b1 * k1[1] + b2 * k2[1] + b2 * k3[1] + b1 * k4[1]
            y = y + b1 * k1[2] + b2 * k2[2] + b2 * k3[2] + b1 * k4[2]
            yv = yv + b1 * k1[3] + b2 * k2[3] + b2 * k3[3] + b1 * k4[3]
        return indented_short, indented, w, wv, y, yv

    run(params, 10, DT)  # compile
    return Kernel(
        lambda n, dt: run(params, n, dt),
        lambda n, short, dt: count(params, n, short, dt),
    )


class Kernel(NamedTuple):
    """A compiled RK4 loop: ``run(steps, dt)`` its final state; ``indented(steps,
    short, dt)`` how many of the same steps start with the pair indented (among the
    first ``short``, among all), then the final state."""

    run: Callable[[int, float], tuple[float, float, float, float]]
    indented: Callable[[int, int, float], tuple[int, int, float, float, float, float]]


def per_step(short: float, long: float, indented: tuple[int, int]) -> tuple[float, float]:
    """Seconds a step in free flight and a step in contact, from the times of
    the ``SHORT`` and ``STEPS`` runs and their steps in contact."""
    (a, b), (c, e) = (SHORT - indented[0], indented[0]), (STEPS - indented[1], indented[1])
    determinant = a * e - b * c
    return (short * e - b * long) / determinant, (a * long - c * short) / determinant


def main() -> None:
    try:
        arguments, frozen = build()
    except ImportError:
        raise SystemExit("numba is not installed: pip install numba") from None
    times: dict[str, list[float]] = {"vibroimpact": [], "arguments": [], "frozen": []}
    states: dict[str, object] = {}
    for _ in range(5):
        seconds, states["vibroimpact"] = ours()
        times["vibroimpact"].append(seconds)
        for name, kernel in (("arguments", arguments), ("frozen", frozen)):
            t0 = time.perf_counter()
            states[name] = tuple(kernel.run(STEPS, DT))
            times[name].append(time.perf_counter() - t0)
    ours_s = statistics.median(times["vibroimpact"])
    print(f"Table 1 system, Hertz law, RK4 at dt = {DT} s, {STEPS:.0e} steps, median of 5 runs")
    print(f"  vibroimpact                           {STEPS / ours_s:.3e} steps/s")
    labels = {
        "arguments": "numba, parameters as arguments",
        "frozen": "numba, parameters frozen as constants",
    }
    for name, label in labels.items():
        theirs = statistics.median(times[name])
        same = states[name] == states["vibroimpact"]
        print(
            f"  {label:38s}{STEPS / theirs:.3e} steps/s: ratio {theirs / ours_s:.2f}, "
            f"final states bit for bit the same: {same}"
        )
        if not same:
            print(f"    vibroimpact {states['vibroimpact']}\n    numba       {states[name]}")
    print("  goal (issue 8): ratio >= 1 against the same arithmetic (parameters as arguments)")
    finals = [states["vibroimpact"], states["arguments"]]
    decompose(arguments, ours_s, statistics.median(times["arguments"]), finals)


def decompose(
    arguments: Kernel, ours_long: float, theirs_long: float, finals: list[object]
) -> None:
    """Each side's cost of a step in free flight and in contact (see the doc):
    only where both sides' final states are the counting kernel's."""
    short_count, long_count, *state = arguments.indented(STEPS, SHORT, DT)
    indented, counted = (short_count, long_count), tuple(state)
    if any(final != counted for final in finals):
        print(
            "  per step: not split (the final states differ: the counts are another trajectory's)"
        )
        return
    short: dict[str, list[float]] = {"vibroimpact": [], "numba": []}
    for _ in range(21):
        short["vibroimpact"].append(ours(SHORT)[0])
        t0 = time.perf_counter()
        arguments.run(SHORT, DT)
        short["numba"].append(time.perf_counter() - t0)
    ours_free, ours_contact = per_step(statistics.median(short["vibroimpact"]), ours_long, indented)
    free, contact = per_step(statistics.median(short["numba"]), theirs_long, indented)
    print(
        f"  per step (steps in contact: {indented[0]} of {SHORT:.0e}, {indented[1]} of "
        f"{STEPS:.0e}):"
    )
    print(
        f"    free flight: vibroimpact {ours_free * 1e9:.0f} ns, numba {free * 1e9:.0f} ns, "
        f"ratio {free / ours_free:.2f}"
    )
    print(
        f"    in contact:  vibroimpact {ours_contact * 1e9:.0f} ns, numba {contact * 1e9:.0f} ns, "
        f"ratio {contact / ours_contact:.2f}"
    )


if __name__ == "__main__":
    main()
