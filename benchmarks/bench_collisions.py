"""Loose masses that collide with each other (issue 27): a column of 10 rigid particles in
a forced cavity, events per CPU second, against a peer measured in the same run.

The column: ten 10 g particles stacked 2 mm apart in the cavity of
examples/particle_column.toml (a 1 kg, 15 Hz, 5 % damped structure forced at 10 Hz with
30 N, under gravity), the lowest 2 mm above the floor, the highest 30 mm below the
ceiling, every pair rigid (``[[collision]]`` between neighbours), at restitution 0.9 and
0.6 (where the column collapses into touching clusters). Its events are the contacts
the run records (impacts, sticking onsets). The peer: the same cavity with one particle
alone, whose events are its impacts on the floor and ceiling: the cost of an event
where one pair can strike, against one where nine pairs and two walls can. CPU times are
medians of repeated calls from Python (call overhead included), one core.

    python benchmarks/bench_collisions.py [--quick]

Goal (issue 27): a column of 10 rigid particles in a forced cavity at least 1e6 events
per second.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

import vibroimpact as vi

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
from test_collisions import forced_column  # noqa: E402

T_END = 20.0


def column(count: int, restitution: float) -> vi.System:
    """The test suite's forced column, every pair rigid at ``restitution``."""
    return forced_column(count, {"law": "rigid", "restitution": restitution})


def events_per_second(system: vi.System, method: str, repeats: int) -> tuple[float, int, float]:
    """Median CPU time (s), events (contacts) and steps of ``T_END`` s."""
    times, sol = [], None
    for _ in range(repeats):
        start = time.process_time()
        sol = vi.simulate(system, method=method, t_end=T_END, history=False)
        times.append(time.process_time() - start)
    assert sol is not None
    return statistics.median(times), len(sol.contacts), sol.steps


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="fewer repeats (smoke test)")
    repeats = 3 if parser.parse_args().quick else 9
    print(f"rigid particles in a forced cavity, {T_END:g} s, medians of {repeats} runs")
    for method in ("exact", "dop853"):
        seconds, events, steps = events_per_second(column(1, 0.9), method, repeats)
        peer = events / seconds
        print(
            f"  {method:7s} one particle (peer)   : {events:6d} events, {steps:6d} steps in "
            f"{seconds * 1e3:7.1f} ms: {peer:.3e} events/s"
        )
        for restitution in (0.9, 0.6):
            seconds, events, steps = events_per_second(column(10, restitution), method, repeats)
            rate = events / seconds
            print(
                f"  {method:7s} ten particles, e {restitution}: {events:6d} events, {steps:6d} "
                f"steps in {seconds * 1e3:7.1f} ms: {rate:.3e} events/s, {rate / peer:.2f}x "
                f"the peer's; goal 1e6 events/s: {'meets' if rate >= 1e6 else 'misses'}"
            )


if __name__ == "__main__":
    main()
