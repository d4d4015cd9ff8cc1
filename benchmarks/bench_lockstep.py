"""Lockstep lanes against the event-driven study of the same runs (issue 24).

The acceptance case: a 2-mode cantilever with two ``hertz-damped`` dampers and a
harmonic tip force, 1,000 runs (40 forcing frequencies x 25 clearances), RK4 at
dt = 1e-5 s. The same study with ``[study] stepping = "fixed"`` (lockstep lanes) and
``"events"`` (one event-driven run a row), on one thread, alternated; medians of the
wall times and their ratio (goal: the lanes at least 5x faster).

    python benchmarks/bench_lockstep.py [--quick] [--t-end 0.2]
"""

from __future__ import annotations

import statistics
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

import vibroimpact as vi
from vibroimpact import study as st
from vibroimpact.scenario.system import SystemScenario

QUICK = "--quick" in sys.argv
T_END = float(sys.argv[sys.argv.index("--t-end") + 1]) if "--t-end" in sys.argv else 0.2
DT = 1e-5

CANTILEVER = """
[structure]
kind = "cantilever"
length = 0.5
youngs_modulus = 7e10
second_moment = 1e-10
mass_per_length = 0.27
modes = 2
damping_ratio = 0.01

[[damper]]
mass = 0.01
at = 0.5
clearance = 2e-4
law = "hertz-damped"
stiffness = 1e7
restitution = 0.6

[[damper]]
mass = 0.01
at = 0.25
clearance = 1e-4
law = "hertz-damped"
stiffness = 1e7
restitution = 0.6

[[excitation]]
kind = "force"
at = 0.5
signal = "harmonic"
amplitude = 0.5
frequency = 8.0

[solver]
method = "rk4"
dt = {dt}
t_end = {t_end}

[study]
analysis = "run"
stepping = "{stepping}"
metrics = ["peak", "rms", "impacts"]
chunk_size = 1000

[study.axes]
"excitation.0.frequency" = {{ start = 4.0, stop = 40.0, count = {frequencies} }}
"damper.0.clearance" = {{ start = 1e-4, stop = 5e-4, count = 25 }}
"""


def study(stepping: str, frequencies: int) -> st.Study:
    text = CANTILEVER.format(dt=DT, t_end=T_END, stepping=stepping, frequencies=frequencies)
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "study.toml"
        path.write_text(text)
        sc = vi.load_scenario(path)
        assert isinstance(sc, SystemScenario)
        return st.study_of(sc.data, str(path))


def main() -> None:
    frequencies = 4 if QUICK else 40
    studies = {s: study(s, frequencies) for s in ("fixed", "events")}
    runs = studies["fixed"].runs
    times: dict[str, list[float]] = {"fixed": [], "events": []}
    results = {}
    for _ in range(1 if QUICK else 3):
        for stepping, s in studies.items():
            start = time.perf_counter()
            results[stepping] = s.run_chunk(range(runs), threads=1)
            times[stepping].append(time.perf_counter() - start)
    steps = runs * round(T_END / DT)
    fixed, events = (statistics.median(times[s]) for s in ("fixed", "events"))
    print(f"{runs} runs of {round(T_END / DT)} steps (t_end {T_END} s, dt {DT} s), one thread")
    print(f"lockstep lanes (fixed): {fixed:.3f} s median, {steps / fixed:.3e} trajectory-steps/s")
    print(f"event-driven (events): {events:.3f} s median, {steps / events:.3e} steps/s")
    print(f"ratio events / fixed: {events / fixed:.2f}x (goal >= 5)")
    failed = int(np.count_nonzero(np.asarray(results["fixed"]["status"])))
    print(f"failed lanes: {failed}")


if __name__ == "__main__":
    main()
