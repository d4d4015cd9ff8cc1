"""The tangent flow (issue 26): orbits and Lyapunov spectra, against their peers in the same run.

1. A periodic orbit with its Floquet multipliers by shooting (``analysis.orbit``), its
   Jacobian from the tangent flow through the impacts (``jacobian="tangent"``) against
   central finite differences of whole runs (``jacobian="differences"``), from the same
   start. Two systems:
   - the forced damped impact damper of bench_analyses.py (10 Hz structure, 1 % damping,
     0.05 kg loose mass, clearance 10 mm, rigid e = 0.6, forced at 8 Hz; four impacts a
     period), from its settled state and from it perturbed by 1 % (Newton has work to do).
     Accuracy: the product of the multipliers against the identity
     det = e^(2 N) exp(-c T / M) (N impacts in the orbit's time T: each impact multiplies
     phase volume by e^2, the structure's damper by exp(-c t / M));
   - the undamped damper of Masri and Caughey (1966) (tests/masri_caughey.py: mu 0.05,
     r 0.6, d 6, e 0.3, its stable symmetric two-impact orbit), from its closed-form state
     perturbed by 1 %. Accuracy: every multiplier against the closed form's.
2. The whole Lyapunov spectrum (``vibroimpact.lyapunov``) of the forced damper over 10,000
   forcing periods from its settled state, against Benettin's method the usual way: scipy's
   solve_ivp (DOP853, rtol 1e-10, terminal events on both walls, Newton's impact map; part
   1 of bench_analyses.py) running the reference trajectory and four perturbed ones
   (perturbation 1e-8 along each column of an orthonormal basis) one forcing period at a
   time, the differences re-orthonormalised by QR each period. scipy is timed over fewer
   periods and scaled per period (saying so); the two spectra are compared over those
   same periods. On the settled (periodic) motion the spectrum is also checked against
   the orbit's multipliers (ln |mu| / T) and its sum against the phase-volume identity.

CPU times are medians of repeated calls from Python (call overhead included), on one
core; SI units throughout.

    python benchmarks/bench_tangent.py [--quick]

Goals (issue 26): an orbit with its multipliers of the forced rigid damper at least 2x
faster than finite-difference shooting, and more accurate; the full Lyapunov spectrum of a
forced two-mass rigid damper over 10,000 forcing periods in under 0.1 s on one core with
the exact method, and at least 100x faster than solve_ivp with events re-orthonormalising
perturbed runs; a 100-point flip curve in under 2 s (part 3: the ball on the table's,
against a continuation locating the flip afresh at each value of the second parameter).
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

import vibroimpact as vi
from vibroimpact import analysis as an

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))
from bench_analyses import (  # noqa: E402
    DAMPER,
    PERIOD,
    C,
    E,
    M,
    goal,
    median_time,
    scipy_map,
    spectrum_distance,
)

from masri_caughey import masri_caughey, mc_scenario, mc_si  # noqa: E402

EXACT_DAMPER = {**DAMPER, "solver": {"method": "exact"}}
PERIODS = 10_000
# Benettin's perturbation (m and m/s, the state's own units): forward differences err by
# O(delta) and by the integrator's error over delta; 1e-8 balances them here (1e-6 and
# 1e-10 agree with the tangent flow 100x and 4x less well).
DELTA = 1e-8
RTOL = 1e-10


def cpu_median(run: Callable[[], Any], repeats: int) -> tuple[float, float, Any]:
    """The median wall and CPU (process) times of ``repeats`` calls, and the last result."""
    walls, cpus, result = [], [], None
    for _ in range(repeats):
        w0, c0 = time.perf_counter(), time.process_time()
        result = run()
        walls.append(time.perf_counter() - w0)
        cpus.append(time.process_time() - c0)
    return float(np.median(walls)), float(np.median(cpus)), result


def log_volume(impacts: float, span: float) -> float:
    """The logarithm of the tangent map's determinant over ``span`` s with ``impacts``
    impacts (no sticking): e^2 per impact, exp(-c t / M) from the structure's damper (the
    loose mass has none)."""
    return 2 * impacts * math.log(E) - C / M * span


def settled_damper() -> tuple[an.Runner, np.ndarray, int]:
    run = an.runner(EXACT_DAMPER)
    steady = an.steady_state(run, settle_periods=500, record_periods=10)
    assert steady.settled and steady.period is not None
    return run, steady.state, steady.period


def shoot_both(
    run: an.Runner, seed: np.ndarray, periods: int, repeats: int
) -> dict[str, tuple[float, an.Orbit, float, float]]:
    """Per Jacobian: the orbit's median time, the orbit, core runs per call and the median
    time of the shooting alone (``Runner.shoot``, without the orbit's amplitudes)."""
    out = {}
    for jacobian in ("tangent", "differences"):
        run.runs = 0
        seconds, found = median_time(
            lambda j=jacobian: an.orbit(run, seed, periods=periods, jacobian=j), repeats
        )
        runs = run.runs / repeats
        shooting, _ = median_time(
            lambda j=jacobian: run.shoot(seed, periods, 1e-10, 40, j), repeats
        )
        out[jacobian] = (seconds, found, runs, shooting)
    return out


def orbits(quick: bool) -> None:
    repeats = 7 if quick else 41
    run, settled, period = settled_damper()
    print(
        "1. periodic orbits with their Floquet multipliers (analysis.orbit): the Jacobian "
        "by the tangent flow against central differences, same start"
    )
    print(
        f"   forced damped damper (bench_analyses.py's: 1 % damping, e = {E}, 8 Hz), settled "
        f"period {period}; accuracy: |prod(multipliers) / (e^(2N) exp(-cT/M)) - 1|"
    )
    ratios = {}
    for label, seed in (("settled", settled), ("settled x 1.01", settled * 1.01)):
        both = shoot_both(run, seed, period, repeats)
        for jacobian, (seconds, found, runs, shooting) in both.items():
            impacts = found.impacts_per_period * period
            det = float(np.prod(found.floquet_multipliers).real)
            err = abs(det / math.exp(log_volume(impacts, period * PERIOD)) - 1)
            print(
                f"   from {label:<15} {jacobian:<12}: {seconds * 1e3:.3f} ms ({runs:.0f} core "
                f"runs, {found.iterations} iterations; the shooting alone "
                f"{shooting * 1e3:.3f} ms), determinant error {err:.1e}"
            )
        tangent, differences = both["tangent"], both["differences"]
        apart = spectrum_distance(
            differences[1].floquet_multipliers, tangent[1].floquet_multipliers
        )
        ratios[label] = (differences[0] / tangent[0], differences[3] / tangent[3])
        print(
            f"   {'':<20}differences / tangent: {ratios[label][0]:.1f}x the orbit, "
            f"{ratios[label][1]:.1f}x the shooting; multipliers apart by {apart:.1e}"
        )
    errors = masri_caughey_orbit(repeats)
    ratio = ratios["settled x 1.01"][0]
    print(
        f"   goal (a), the damped damper from its settled state x 1.01: {ratio:.1f}x "
        f"({goal(ratio >= 2)} the 2x goal; from the settled state itself, where Newton "
        f"takes one step and the orbit's own amplitude run weighs most, "
        f"{ratios['settled'][0]:.1f}x); more accurate: {goal(errors[0] < errors[1])} "
        f"(Masri-Caughey multipliers {errors[0]:.1e} against {errors[1]:.1e})"
    )


def masri_caughey_orbit(repeats: int) -> tuple[float, float]:
    """The undamped Masri-Caughey orbit by both Jacobians: times and multiplier errors
    against the closed form. Returns (tangent error, differences error)."""
    mu, r, d, e = 0.05, 0.6, 6.0, 0.3
    root = masri_caughey(mu, r, d, e)[0]
    run = an.runner(mc_scenario(mu, r, d, e, root["phase"]))
    exact = np.linalg.eigvals(root["monodromy"])
    print(
        f"   Masri-Caughey undamped damper (mu {mu}, r {r}, d {d}, e {e}), its stable "
        "two-impact orbit from the closed form x 1.01; accuracy: multipliers against the "
        "closed form's (largest distance, best paired)"
    )
    errors = []
    both = shoot_both(run, mc_si(root["mid"]) * 1.01, 1, repeats)
    for jacobian, (seconds, found, runs, shooting) in both.items():
        err = spectrum_distance(found.floquet_multipliers, exact)
        errors.append(err)
        print(
            f"   {jacobian:<36}: {seconds * 1e3:.3f} ms ({runs:.0f} core runs, "
            f"{found.iterations} iterations; the shooting alone {shooting * 1e3:.3f} ms), "
            f"multiplier error {err:.1e}"
        )
    print(
        f"   {'':<20}differences / tangent: {both['differences'][0] / both['tangent'][0]:.1f}x "
        "the orbit"
    )
    return errors[0], errors[1]


def scipy_benettin(z0: np.ndarray, periods: int) -> tuple[np.ndarray, int]:
    """Benettin's method on scipy's stroboscopic map (bench_analyses.scipy_map): the
    reference and one run per basis column, perturbed by DELTA, each period; the
    differences re-orthonormalised by QR (the columns in vibroimpact's state order, so
    that both sides orthonormalise the same basis). Returns the spectrum (1/s,
    descending) and the solve_ivp calls."""
    calls = [0]
    size = len(z0)
    basis, logs, z = np.eye(size), np.zeros(size), z0.copy()
    for _ in range(periods):
        image = scipy_map(z, 1, RTOL, calls)
        moved = np.column_stack(
            [
                (scipy_map(z + DELTA * basis[:, i], 1, RTOL, calls) - image) / DELTA
                for i in range(size)
            ]
        )
        basis, upper = np.linalg.qr(moved)
        signs = np.sign(np.diag(upper))
        basis *= signs
        logs += np.log(np.abs(np.diag(upper)))
        z = image
    return np.sort(logs / (periods * PERIOD))[::-1], calls[0]


def lyapunov(quick: bool) -> None:
    run, settled, period = settled_damper()
    found = an.orbit(run, settled, periods=period)
    from_multipliers = np.sort(np.log(np.abs(found.floquet_multipliers)) / (period * PERIOD))[::-1]
    lyap = an.lyapunov_runner(EXACT_DAMPER)
    print(
        f"2. the Lyapunov spectrum of the forced damper over {PERIODS} forcing periods "
        "(vibroimpact.lyapunov, method exact, settle = 0 from the settled state)"
    )
    wall, cpu, spectrum = cpu_median(
        lambda: vi.lyapunov(lyap, settled, settle=0, periods=PERIODS), 3 if quick else 7
    )
    values = ", ".join(
        f"{v:.5f} +- {s:.1e}"
        for v, s in zip(spectrum.exponents, spectrum.standard_error, strict=True)
    )
    volume = log_volume(spectrum.impacts, spectrum.time) / spectrum.time
    print(
        f"   {wall * 1e3:.1f} ms wall, {cpu * 1e3:.1f} ms CPU (median of "
        f"{3 if quick else 7}); {spectrum.impacts} impacts, {len(spectrum.grazings)} grazings"
    )
    print(f"   exponents (1/s): {values}")
    print(
        "   checks: ln|multipliers| / T of the orbit it settled on: "
        + ", ".join(f"{v:.5f}" for v in from_multipliers)
        + f" (largest difference {np.max(np.abs(spectrum.exponents - from_multipliers)):.1e}); "
        f"sum {spectrum.exponents.sum():.10f} against (2 N ln e - c t / M) / t = {volume:.10f}"
    )
    print(
        f"   goal (b), under 0.1 s: {goal(cpu < 0.1)} by CPU time ({cpu * 1e3:.1f} ms), "
        f"{goal(wall < 0.1)} by the clock ({wall * 1e3:.1f} ms)"
    )
    short = 20 if quick else 100
    same = vi.lyapunov(lyap, settled, settle=0, periods=short)
    start = time.perf_counter()
    theirs, calls = scipy_benettin(settled, short)
    seconds = time.perf_counter() - start
    scaled = seconds * PERIODS / short
    print(
        f"   scipy Benettin (solve_ivp DOP853 rtol {RTOL:.0e}, wall events, Newton impact map, "
        f"perturbation {DELTA:.0e}, QR every period): {short} periods in {seconds:.2f} s "
        f"({calls} solve_ivp calls), scaled x{PERIODS // short} to {PERIODS} periods: "
        f"{scaled:.0f} s"
    )
    relative = np.abs(theirs - same.exponents) / np.abs(same.exponents)
    print(
        f"   over the same {short} periods: vibroimpact "
        + ", ".join(f"{v:.6f}" for v in same.exponents)
        + "; scipy "
        + ", ".join(f"{v:.6f}" for v in theirs)
        + f"; largest relative difference {np.max(relative):.1e}"
    )
    ratio = scaled / wall
    print(
        f"   goal (b), >= 100x solve_ivp: {ratio:.0f}x by the clock "
        f"({goal(ratio >= 100)} the 100x goal; scipy scaled from {short} periods)"
    )


FLIP_CURVE = Path(__file__).resolve().parent.parent / "examples" / "ball_table_flip_curve.toml"


def flip_curve(quick: bool) -> None:
    """Goal (c): the 101-point flip curve of examples/ball_table_flip_curve.toml (the
    ball on the table, its flip followed from e = 0.5 to 0.8), against the usual way of
    drawing one: a continuation in the first parameter at each value of the second,
    locating the flip afresh (timed at a few values of the second, scaled per point)."""
    import tomllib

    data = tomllib.loads(FLIP_CURVE.read_text(encoding="utf-8"))
    wall, cpu, found = cpu_median(lambda: an.curve_of(data), 3 if quick else 7)
    settings = data["curve"]
    print(
        f"3. the flip curve of {FLIP_CURVE.name} ({settings['parameter']} against "
        f"{settings['second']} in steps of {settings['step']})"
    )
    print(
        f"   {len(found.points)} points in {wall:.3f} s wall, {cpu:.3f} s CPU "
        f"(median of {3 if quick else 7}); stopped: {found.stopped}"
    )
    samples = found.points[:: max(1, len(found.points) // (3 if quick else 6))]
    start = time.perf_counter()
    for point in samples:
        moved = an.with_parameter(data, settings["second"], point.values[settings["second"]])
        # Towards the flip, the way it lies from the scenario's value (favouring the
        # peer, which would otherwise search both ways).
        ahead = point.values[settings["parameter"]] > settings["start"]
        stop = (
            settings["stop"]
            if ahead
            else settings["start"] - (settings["stop"] - settings["start"])
        )
        branch = an.continue_orbit(moved, settings["parameter"], stop=stop)
        assert any(b.kind == "flip" for b in branch.bifurcations)
    per_point = (time.perf_counter() - start) / len(samples)
    print(
        f"   a continuation locating the flip afresh: {per_point * 1e3:.1f} ms a point "
        f"(over {len(samples)} values of {settings['second']}), "
        f"{per_point * len(found.points):.2f} s for {len(found.points)} points: "
        f"{per_point * len(found.points) / wall:.1f}x the curve"
    )
    print(
        f"   goal (c), a 100-point flip curve under 2 s: "
        f"{goal(wall < 2 and len(found.points) >= 100)} ({wall:.3f} s, {len(found.points)} points)"
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="fewer repeats (smoke test)")
    args = parser.parse_args()
    start = time.perf_counter()
    orbits(args.quick)
    lyapunov(args.quick)
    flip_curve(args.quick)
    print(f"(benchmark wall time {time.perf_counter() - start:.0f} s)")


if __name__ == "__main__":
    main()
