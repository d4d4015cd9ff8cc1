"""The ``orbit`` and ``sweep`` commands: their arguments, output and plots."""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

from vibroimpact.analyses import (
    AnalysisError,
    SweepPoint,
    orbit,
    runner,
    sweep,
    sweep_values,
)
from vibroimpact.output import UsageError, finite_or_none, written_whole
from vibroimpact.scenario import load_scenario
from vibroimpact.system_scenario import SystemScenario


def add_commands(sub: Any) -> None:
    """Register ``orbit`` and ``sweep`` on the command line's subparsers."""
    orbit_parser = sub.add_parser(
        "orbit",
        help="shoot for a periodic orbit of a forced 0.2 scenario, with its stability",
        description=(
            "Newton's method on the stroboscopic map over K periods of the first harmonic "
            "excitation, from the scenario's [initial] state: prints whether it converged, "
            "the state on the orbit at t = 0 (the four arrays of [initial], SI), the Floquet "
            "multipliers (eigenvalues of the monodromy matrix, by finite differences through "
            "the impacts), stability, impacts per forcing period and the amplitude (largest "
            "|structure displacement| over the orbit, m, per coordinate)."
        ),
    )
    orbit_parser.add_argument("scenario", type=Path, help="scenario file (.toml, [structure])")
    orbit_parser.add_argument(
        "--periods", type=int, default=1, metavar="K", help="forcing periods of the orbit (1)"
    )
    orbit_parser.add_argument(
        "--tolerance",
        type=float,
        default=1e-10,
        help="largest |P(z) - z| relative to the largest displacement and velocity (1e-10)",
    )
    orbit_parser.add_argument("--json", action="store_true", help="print one JSON object")

    sweep_parser = sub.add_parser(
        "sweep",
        help="stepped sweep of a parameter (frequency response), from a [sweep] section",
        description=(
            "For each value of [sweep] parameter (a dotted path such as "
            '"excitation.0.frequency"), from start to stop in count steps, up, down or '
            "both: settle settle_periods forcing periods from the last point's state, then "
            "record record_periods; prints per point the amplitude (located peaks, m) and "
            "RMS (m) per structure coordinate, impacts per period, whether the stroboscopic "
            "state settled, and the structure's linear response without dampers and stops."
        ),
    )
    sweep_parser.add_argument("scenario", type=Path, help="scenario file (.toml) with [sweep]")
    sweep_parser.add_argument("--json", action="store_true", help="print one JSON object")
    sweep_parser.add_argument(
        "--plot",
        type=Path,
        metavar="FILE.png",
        help="plot the response against the parameter, with and without the dampers",
    )


def _system(path: Path) -> SystemScenario:
    scenario = load_scenario(path)
    if not isinstance(scenario, SystemScenario):
        raise UsageError(f"{path}: orbit and sweep take a 0.2 scenario (a [structure] section)")
    return scenario


def run_orbit(args: argparse.Namespace) -> int:
    scenario = _system(args.scenario)
    if args.periods < 1:
        raise UsageError(f"--periods must be >= 1, got {args.periods}")
    if not args.tolerance > 0:
        raise UsageError(f"--tolerance must be > 0, got {args.tolerance}")
    run = runner(scenario.data, scenario.base_dir)
    start = time.perf_counter()
    found = orbit(run, periods=args.periods, tolerance=args.tolerance)
    cpu_time = time.perf_counter() - start
    summary = {
        "converged": found.converged,
        "state": found.arrays(run.n, run.k),
        "floquet_multipliers": [[float(m.real), float(m.imag)] for m in found.floquet_multipliers],
        "stable": found.stable,
        "impacts_per_period": found.impacts_per_period,
        "amplitude": [float(a) for a in found.amplitude],
        "periods": args.periods,
        "forcing_period": run.period,
        "iterations": found.iterations,
        "residual": finite_or_none(found.residual),
        "cpu_time": cpu_time,
    }
    if args.json:
        print(json.dumps(summary))
        return 0
    lines = [
        f"{args.scenario}: {'converged' if found.converged else 'did NOT converge'} to a "
        f"{args.periods}-period orbit in {found.iterations} Newton iterations "
        f"(residual {found.residual:.2e}), {cpu_time * 1e3:.2f} ms",
        f"stable: {found.stable}; impacts per forcing period: {found.impacts_per_period:g}",
        "Floquet multipliers: "
        + ", ".join(
            f"{m.real:.6g}{m.imag:+.6g}i (|{abs(m):.6g}|)" for m in found.floquet_multipliers
        ),
        "amplitude (m): " + ", ".join(f"{a:.6g}" for a in found.amplitude),
    ]
    for key, values in summary["state"].items():
        lines.append(f"{key} = [{', '.join(f'{v:.12g}' for v in values)}]")
    print("\n".join(lines))
    return 0


def run_sweep(args: argparse.Namespace) -> int:
    scenario = _system(args.scenario)
    settings = scenario.data.get("sweep")
    if settings is None:
        raise UsageError(
            f"{args.scenario}: sweep needs a [sweep] section (parameter, start, stop, count)"
        )
    values = sweep_values(settings)
    start = time.perf_counter()
    show = sys.stderr.isatty() and not args.json

    def progress(done: int, total: int) -> None:
        if show:
            print(f"\r{done}/{total} points", end="", file=sys.stderr, flush=True)

    try:
        points = sweep(
            scenario.data,
            settings["parameter"],
            values,
            direction=settings["direction"],
            settle_periods=settings["settle_periods"],
            record_periods=settings["record_periods"],
            tolerance=settings["tolerance"],
            base_dir=scenario.base_dir,
            progress=progress,
        )
    except AnalysisError as err:
        raise AnalysisError(f"{args.scenario}: {err}") from None
    if show:
        print(file=sys.stderr)
    cpu_time = time.perf_counter() - start
    if args.plot:
        plot_sweep(args.plot, settings["parameter"], points)
    if args.json:
        print(
            json.dumps(
                {
                    "parameter": settings["parameter"],
                    "points": [p.to_dict() for p in points],
                    "cpu_time": cpu_time,
                }
            )
        )
        return 0
    print(
        f"{args.scenario}: {len(points)} points of {settings['parameter']} in "
        f"{cpu_time:.3f} s ({settings['settle_periods']} settle and "
        f"{settings['record_periods']} recorded periods each)"
    )
    head = ["value", "direction", "amplitude_0", "linear_0", "rms_0", "impacts/period", "settled"]
    print("  ".join(f"{h:>14}" for h in head))
    for p in points:
        cells = [
            f"{p.value:>14.6g}",
            f"{p.direction:>14}",
            f"{p.amplitude[0]:>14.6g}",
            f"{p.linear_amplitude[0]:>14.6g}",
            f"{p.rms[0]:>14.6g}",
            f"{p.impacts_per_period:>14.4g}",
            f"{str(p.settled):>14}",
        ]
        print("  ".join(cells) + (f"  error: {p.error}" if p.error else ""))
    if args.plot:
        print(f"plot written to {args.plot}")
    return 0


def plot_sweep(path: Path, parameter: str, points: list[SweepPoint]) -> None:
    """The amplitude of structure coordinate 0 against the parameter, each direction,
    with the linear structure's beside it; PNG, written whole."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 4.5))
    values = np.array([p.value for p in points])
    order = np.argsort(values, kind="stable")
    linear = np.array([p.linear_amplitude[0] for p in points])
    ax.plot(values[order], linear[order], "k--", lw=1, label="without dampers (linear)")
    for direction, marker in (("up", "^"), ("down", "v")):
        chosen = [p for p in points if p.direction == direction]
        if chosen:
            ax.plot(
                [p.value for p in chosen],
                [p.amplitude[0] for p in chosen],
                marker=marker,
                ms=3,
                lw=1,
                label=f"with dampers, sweep {direction}",
            )
    unit = " (Hz)" if parameter.endswith("frequency") else ""
    ax.set_xlabel(f"{parameter}{unit}")
    ax.set_ylabel("amplitude of structure coordinate 0 (m)")
    ax.legend()
    ax.grid(alpha=0.3)
    fig.tight_layout()
    with written_whole(path, binary=True) as f:
        fig.savefig(f, format="png", dpi=120)
    plt.close(fig)
