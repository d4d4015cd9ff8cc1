"""Studies at scale (issue 10), side by side in one run.

1. Overhead per run: a study of runs of one step each, against the same runs made one by
   one through the Python API (the peer), on 1 and on all threads.
2. An RK4 ensemble of the impact damper (a one-mode structure and a loose mass with a
   Hertz contact), metrics only: trajectory-steps per second on 1 and on all threads,
   beside the same runs through the single-run API in a Python loop.
3. A 1e6-run study: its time and peak memory, killed part way and resumed, and the
   resumed file compared with the uninterrupted one byte for byte.

    python benchmarks/bench_study.py [--quick]
"""

from __future__ import annotations

import os
import resource
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

import vibroimpact as vi
from vibroimpact import study as st
from vibroimpact.scenario.system import SystemScenario

QUICK = "--quick" in sys.argv
CORES = os.cpu_count() or 1

DAMPER = """
[structure]
kind = "oscillator"
mass = 1.0
stiffness = 1.0
damping = 0.01

[[damper]]
mass = 0.25
at = 0
clearance = 0.01
law = "hertz"
stiffness = 3000.0

[solver]
method = "rk4"
dt = {dt}
t_end = {t_end}
"""


def study_of(text: str, axes: str, extra: str = "") -> st.Study:
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "study.toml"
        path.write_text(text + '\n[study]\nanalysis = "run"\nmetrics = ["peak"]\n' + extra + axes)
        sc = vi.load_scenario(path)
        assert isinstance(sc, SystemScenario)
        return st.study_of(sc.data, str(path))


def median_time(work: object, repeats: int) -> float:
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        work()  # type: ignore[operator]
        times.append(time.perf_counter() - start)
    return float(np.median(times))


def overhead() -> None:
    runs = 20_000 if QUICK else 200_000
    text = DAMPER.format(dt=1e-4, t_end=1e-4)
    s = study_of(
        text,
        "[study.axes]\n"
        f'"initial.damper_velocity.0" = {{ start = 0.0, stop = 0.1, count = {runs} }}\n',
    )
    rebuilt = study_of(
        text,
        f'[study.axes]\n"damper.0.clearance" = {{ start = 0.005, stop = 0.02, count = {runs} }}\n',
    )
    fixed = study_of(
        text,
        "[study.axes]\n"
        f'"initial.damper_velocity.0" = {{ start = 0.0, stop = 0.1, count = {runs} }}\n',
        'stepping = "fixed"\n',
    )
    print(f"1. overhead per run: {runs} runs of one RK4 step (metrics only)")
    for label, study in (
        ("the start varied (one system, one method a thread)", s),
        ("the clearance varied (the system made again each run)", rebuilt),
        ('the start varied, stepping = "fixed" (lockstep)', fixed),
    ):
        for threads in sorted({1, CORES}):
            t = median_time(lambda n=threads, st=study: st.run_chunk(range(0, runs), n), 3)
            print(f"   {label}, {threads} thread(s): {t / runs * 1e6:.2f} us per run")
    peer_runs = 2000
    data = {k: v for k, v in s.data.items() if k != "study"}

    def loop() -> None:
        for v in np.linspace(0.0, 0.1, peer_runs):
            vi.simulate_system(
                data["structure"],
                damper=data["damper"],
                initial={"damper_velocity": [float(v)]},
                method="rk4",
                dt=1e-4,
                t_end=1e-4,
                history=False,
            )

    t = median_time(loop, 3)
    per = t / peer_runs * 1e6
    one = median_time(lambda: s.run_chunk(range(0, runs), 1), 1) / runs * 1e6
    print(
        f"   peer, a Python loop over simulate_system: {per:.1f} us per run "
        f"({per / one:.0f}x the engine on 1 thread)"
    )
    print("   goal: below 2 us per run")


def numba_ensemble(runs: int, steps: int, dt: float) -> float | None:
    """Seconds for the same ensemble by numba ``prange`` over all cores (the peer the
    issue names), or None without numba. The arithmetic of the fixed-step kernel."""
    try:
        from numba import njit, prange
    except ImportError:
        return None
    d, khz, c1, inv_m, inv_md = 0.01, 3000.0, 0.0, 1.0, 4.0

    @njit(inline="always")
    def acc(w: float, wv: float, y: float, yv: float) -> tuple[float, float]:
        main = -(0.01 * wv + 1.0 * w)
        u = y - w
        if abs(u) > d:
            side = 1.0 if u > 0.0 else -1.0
            ind = side * u - d
            rate = side * (yv - wv)
            push = side * (khz * ind * np.sqrt(ind) + c1 * rate)
            return main + push * inv_m, -push * inv_md
        return main, 0.0

    @njit(parallel=True)
    def run(velocities: np.ndarray, steps: int, dt: float) -> np.ndarray:
        peaks = np.zeros(velocities.size)
        half, sixth = 0.5 * dt, dt / 6.0
        for i in prange(velocities.size):
            w, wv, y, yv = 0.0, 0.0, 0.0, velocities[i]
            peak = 0.0
            for _ in range(steps):
                a1w, a1y = acc(w, wv, y, yv)
                a2w, a2y = acc(w + half * wv, wv + half * a1w, y + half * yv, yv + half * a1y)
                k2w, k2y = wv + half * a1w, yv + half * a1y
                a3w, a3y = acc(w + half * k2w, wv + half * a2w, y + half * k2y, yv + half * a2y)
                k3w, k3y = wv + half * a2w, yv + half * a2y
                a4w, a4y = acc(w + dt * k3w, wv + dt * a3w, y + dt * k3y, yv + dt * a3y)
                k4w, k4y = wv + dt * a3w, yv + dt * a3y
                w = w + sixth * (wv + 2.0 * (k2w + k3w) + k4w)
                wv = wv + sixth * (a1w + 2.0 * (a2w + a3w) + a4w)
                y = y + sixth * (yv + 2.0 * (k2y + k3y) + k4y)
                yv = yv + sixth * (a1y + 2.0 * (a2y + a3y) + a4y)
                peak = max(peak, abs(w))
            peaks[i] = peak
        return peaks

    velocities = np.linspace(0.05, 0.15, runs)
    run(velocities[:2], 10, dt)  # compile
    return median_time(lambda: run(velocities, steps, dt), 3)


def ensemble() -> None:
    runs = 2000 if QUICK else 10_000
    steps = 20_000
    dt = 1e-4
    text = DAMPER.format(dt=dt, t_end=steps * dt)
    axes = (
        "[study.axes]\n"
        f'"initial.damper_velocity.0" = {{ start = 0.05, stop = 0.15, count = {runs} }}\n'
    )
    fixed = study_of(text, axes, 'stepping = "fixed"\n')
    events = study_of(text, axes)
    print(
        f"2. RK4 ensemble of the impact damper: {runs} runs of {steps} steps, dt = {dt} s "
        "(metrics only)"
    )
    rates = {}
    for threads in sorted({1, CORES}):
        t = median_time(lambda n=threads: fixed.run_chunk(range(0, runs), n), 3)
        rates[threads] = runs * steps / t
        print(
            f'   study engine, stepping = "fixed" (lockstep), {threads} thread(s): '
            f"{rates[threads]:.3e} trajectory-steps/s"
        )
    if CORES > 1:
        print(f"   scaling: {rates[CORES] / rates[1]:.2f}x on {CORES} threads")
    sample = max(runs // 20, 8)
    t = median_time(lambda: events.run_chunk(range(0, sample), 1), 1)
    print(
        f'   study engine, stepping = "events" (contacts located by cutting steps), 1 thread: '
        f"{sample * steps / t:.3e} trajectory-steps/s"
    )

    def loop() -> None:
        system = vi.ImpactDamper(
            main_mass=1.0, stiffness=1.0, damping=0.01, impact_mass=0.25, clearance=0.01
        )
        contact = vi.Contact("hertz", stiffness=3000.0, damping=0.0)
        for v in np.linspace(0.05, 0.15, sample):
            vi.simulate(
                system,
                contact,
                vi.InitialState(impact_velocity=float(v)),
                method="rk4",
                stepping="fixed",
                dt=dt,
                t_end=steps * dt,
                history=False,
            )

    t = median_time(loop, 3)
    loop_rate = sample * steps / t
    print(
        f"   peer, a Python loop over the single-run API (vi.simulate, fixed RK4), 1 thread: "
        f"{loop_rate:.3e} trajectory-steps/s (the engine on 1 thread: {rates[1] / loop_rate:.1f}x)"
    )
    t_numba = numba_ensemble(runs, steps, dt)
    if t_numba is None:
        print("   peer, numba prange: numba not installed (pip install numba)")
    else:
        rate = runs * steps / t_numba
        print(
            f"   peer, numba prange on {CORES} threads: {rate:.3e} trajectory-steps/s "
            f"(engine / numba on {CORES} threads: {rates[CORES] / rate:.2f})"
        )
    goal = "meets" if rates[1] >= 1.2e8 else "misses"
    print(f"   goal: one worker >= 1.2e8 trajectory-steps/s ({goal})")


def million() -> None:
    count = 100 if QUICK else 1000
    runs = count * count
    text = DAMPER.format(dt=1e-4, t_end=1e-4)
    axes = (
        f'[study.axes]\n"damper.0.clearance" = {{ start = 0.005, stop = 0.02, count = {count} }}\n'
        f'"initial.damper_velocity.0" = {{ start = 0.0, stop = 0.1, count = {count} }}\n'
    )
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "million.toml"
        path.write_text(
            text
            + '\n[study]\nanalysis = "run"\nmetrics = ["peak", "impacts"]\nchunk_size = 20000\n'
            + axes
        )
        whole, resumed = Path(tmp) / "whole.nc", Path(tmp) / "resumed.nc"
        command = [sys.executable, "-m", "vibroimpact", "study", str(path)]
        start = time.perf_counter()
        done = subprocess.run([*command, "--out", str(whole)], capture_output=True, text=True)
        elapsed = time.perf_counter() - start
        assert done.returncode == 0, done.stderr
        print(
            f"3. a study of {runs} runs (one RK4 step each, 2 metrics): {elapsed:.2f} s "
            f"from the command line, {elapsed / runs * 1e6:.2f} us per run all in"
        )
        process = subprocess.Popen(
            [*command, "--out", str(resumed)], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL
        )
        parts = resumed.with_name(resumed.name + ".parts")
        deadline = time.monotonic() + 120
        while len(list(parts.glob("chunk-*.npz"))) < 3 and time.monotonic() < deadline:
            time.sleep(0.01)
        process.send_signal(signal.SIGKILL)
        process.wait()
        kept = len(list(parts.glob("chunk-*.npz")))
        done = subprocess.run([*command, "--out", str(resumed)], capture_output=True, text=True)
        assert done.returncode == 0, done.stderr
        same = resumed.read_bytes() == whole.read_bytes()
        print(
            f"   killed after {kept} of {-(-runs // 20000)} chunks, resumed: the file is "
            f"{'the same, byte for byte' if same else 'DIFFERENT'} "
            f"({whole.stat().st_size / 1e6:.1f} MB)"
        )
    peak = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024
    print(f"   peak resident memory of a study process: {peak:.0f} MB")


if __name__ == "__main__":
    print(f"({CORES} cores)")
    overhead()
    ensemble()
    million()
