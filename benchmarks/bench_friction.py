"""Coulomb friction (issue 27): a horizontal impact damper with friction on a forced
structure over 1,000 forcing periods, on the exact flow, against scipy's solve_ivp
with events and a hand-written stick-slip switch, measured in the same run.

The system (tests/friction_reference.py, ``HorizontalDamper``): a 1 kg, 9.6 Hz, lightly
damped structure forced with 30 N at 10 Hz, carrying a 0.1 kg mass in a +-10 mm cavity
(rigid walls, e = 0.6) that slides on the cavity's floor with mu = 0.2 (static 0.3)
under its weight: impacts, chattering sequences ending on a wall, sliding, sticking and
slipping every period. The peer is that module's scipy integration (DOP853 with terminal
events on each wall, on the sliding speed and on the static limit, restarted at each
event with the mode it switches to): scipy's cost grows with the period count, so its
1,000 periods are scaled from the first ``PEER_PERIODS`` (transient included, where
events are as frequent). Accuracy: each run's state after ``PEER_PERIODS`` periods
against scipy at rtol 1e-12 with steps of 1e-5 s; the peer runs at the settings that
reach the same accuracy (rtol 1e-10, steps of at most 1e-4 s: longer steps pass over a
stop and a return to the wall together, see the module) and at loose ones for scale.
CPU times are medians of repeated calls, one core.

    python benchmarks/bench_friction.py [--quick]

Goal (issue 27): at least 100x faster than scipy with events and a stick-slip switch, at
no worse accuracy.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

import numpy as np

import vibroimpact as vi

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
from friction_reference import HorizontalDamper, simulate  # noqa: E402

PERIODS = 1000
PEER_PERIODS = 20


def _state(sol: vi.SystemSolution) -> np.ndarray:
    f = sol.final_state
    return np.array(
        [
            f["structure_displacement"][0],
            f["damper_displacement"][0],
            f["structure_velocity"][0],
            f["damper_velocity"][0],
        ]
    )


def _median(call, repeats: int) -> tuple[float, object]:
    times, out = [], None
    for _ in range(repeats):
        start = time.process_time()
        out = call()
        times.append(time.process_time() - start)
    return statistics.median(times), out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="fewer repeats")
    repeats = 3 if parser.parse_args().quick else 7
    params = HorizontalDamper()
    period = 1.0 / params.frequency
    system = vi.System.from_dict(params.toml_sections())
    short = PEER_PERIODS * period

    truth, _ = simulate(params, short, rtol=1e-12, atol=1e-15, max_step=1e-5)
    ours_short = _state(vi.simulate(system, method="exact", t_end=short, history=False))
    ours_time, sol = _median(
        lambda: vi.simulate(system, method="exact", t_end=PERIODS * period, history=False),
        repeats,
    )
    events = len(sol.contacts)
    print(
        f"exact flow, {PERIODS} periods: {ours_time * 1e3:.1f} ms (median of {repeats}), "
        f"{events} contacts recorded, {sol.steps} steps; ledger residual "
        f"{sol.energy['residual']:.1e} J of {sol.energy['input_work']:.0f} J input, "
        f"friction {sol.energy['friction']:.2f} J"
    )
    ours_error = np.abs(ours_short - truth).max()
    print(f"  its state after {PEER_PERIODS} periods against scipy at rtol 1e-12: {ours_error:.1e}")
    for label, rtol, step in (("matched", 1e-10, 1e-4), ("loose", 1e-8, 1e-3)):
        peer_time, (state, peer_events) = _median(
            lambda rtol=rtol, step=step: simulate(
                params, short, rtol=rtol, atol=rtol * 1e-3, max_step=step
            ),
            max(1, repeats // 3),
        )
        scaled = peer_time * PERIODS / PEER_PERIODS
        error = np.abs(state - truth).max()
        print(
            f"scipy {label} (rtol {rtol:g}, steps <= {step:g} s): {peer_time:.2f} s for "
            f"{PEER_PERIODS} periods ({peer_events} events), {scaled:.1f} s scaled to "
            f"{PERIODS}; error {error:.1e}; ratio {scaled / ours_time:.0f}x (goal >= 100x)"
        )


if __name__ == "__main__":
    main()
