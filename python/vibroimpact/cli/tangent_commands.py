"""The tangent-dynamics commands (``lyapunov``, ``curve``): their arguments, what each
runs, its output and plots."""

from __future__ import annotations

import argparse
import re
import time
from typing import Any

from vibroimpact.analysis import (
    AnalysisError,
    check_periods,
    curve_of,
    curve_regions,
    lyapunov,
    lyapunov_runner,
    plots,
)
from vibroimpact.output import UsageError, json_text, path_argument, structure_needed
from vibroimpact.scenario.system import SystemScenario
from vibroimpact.scenario.two_mass import load_scenario
from vibroimpact.units import with_units


def add_tangent_parsers(sub: Any) -> None:
    """Register ``lyapunov`` and ``curve`` on the command line's subparsers."""
    parser = sub.add_parser(
        "lyapunov",
        help="the Lyapunov spectrum of a scenario with [structure] through its impacts (exact)",
        description=(
            "Settle --settle forcing periods from the scenario's [initial] state, then "
            "carry the tangent flow over --periods periods through every impact by its "
            "saltation matrix, re-orthonormalising it after each (Benettin's QR): prints "
            "the whole spectrum (1/s, descending; -inf: a direction lost where a pair "
            "stuck, null in JSON) with each exponent's standard error over 10 blocks, the "
            "time averaged over (s) and the impacts in it. An unforced scenario is "
            "averaged over [solver] t_end from [initial]."
        ),
    )
    parser.add_argument("scenario", type=path_argument, help="scenario file (.toml, [structure])")
    parser.add_argument(
        "--settle", type=int, metavar="N", help="forcing periods settled first (100)"
    )
    parser.add_argument(
        "--periods", type=int, metavar="N", help="forcing periods averaged over (1000)"
    )
    parser.add_argument("--json", action="store_true", help="print one JSON object")
    parser.add_argument(
        "--plot",
        type=path_argument,
        metavar="FILE.png",
        help="plot each exponent's estimate against the time averaged over",
    )
    curve_parser = sub.add_parser(
        "curve",
        help="a curve of bifurcations in two parameters, from a [curve] section",
        description=(
            "Locate the [curve] kind of bifurcation (flip, fold, neimark-sacker or grazing: "
            "where the orbit touches a stop at zero speed) of the "
            "K-period orbit (periods) along its branch in [curve] parameter, from start to "
            "stop (the orbit found from [initial] at start), by Newton's method on the "
            "extended system with the Floquet multipliers of the tangent flow through the "
            "impacts; then follow it as [curve] second steps by step from the scenario's "
            "value to second_stop. Prints each point's two values; --json gives points "
            "[{values, state, floquet_multipliers}]."
        ),
    )
    curve_parser.add_argument(
        "scenario", type=path_argument, help="scenario file (.toml) with [curve]"
    )
    curve_parser.add_argument("--json", action="store_true", help="print one JSON object")
    curve_parser.add_argument(
        "--plot",
        type=path_argument,
        metavar="FILE.png",
        help="plot the curve in its plane, with the regions it bounds labelled",
    )


#: lyapunov's keywords where its messages name them ("settle 100 and periods 2: ...",
#: "periods: ..., give periods >= 11"), not its words ("forcing periods span").
_FLAGGED = re.compile(r"(?<![\w-])(settle|periods)(?=:| \d| >=)")


def run_lyapunov(args: argparse.Namespace) -> int:
    scenario = load_scenario(args.scenario)
    if not isinstance(scenario, SystemScenario):
        raise UsageError(structure_needed(args.scenario, "lyapunov"))
    if args.settle is not None:
        check_periods("", "--settle", args.settle, 0)
    if args.periods is not None:
        check_periods("", "--periods", args.periods, 1)
    run = lyapunov_runner(scenario.data, scenario.base_dir)
    forced = bool(scenario.data.get("excitation"))
    if not forced and (args.settle is not None or args.periods is not None):
        raise UsageError(
            "--settle and --periods take a forced scenario; an unforced one is averaged "
            "over [solver] t_end"
        )
    start = time.perf_counter()
    try:
        found = lyapunov(run, settle=args.settle, periods=args.periods)
    except AnalysisError as err:
        # The analysis names its keywords; here they are the flags.
        raise AnalysisError(_FLAGGED.sub(r"--\1", str(err))) from None
    cpu_time = time.perf_counter() - start
    summary = {
        "exponents": [float(v) for v in found.exponents],
        "standard_error": [float(v) for v in found.standard_error],
        "time": found.time,
        "impacts": found.impacts,
        "settle": found.settle,
        "periods": found.periods,
        "forcing_period": run.period if forced else None,
        "grazings": [
            {"time": t, "pair": pair, "speed": speed} for t, pair, speed in found.grazings
        ],
        "cpu_time": cpu_time,
    }
    if args.plot:
        plots.plot_lyapunov(args.plot, found)
    if args.json:
        print(json_text(summary))
        return 0
    lines = [
        f"{args.scenario}: Lyapunov spectrum over {found.time:.6g} s"
        + (f" ({found.periods} forcing periods after {found.settle})" if forced else "")
        + f", {found.impacts} impacts, {cpu_time * 1e3:.1f} ms",
        *(
            f"  {value:>14.6g} 1/s  +- {error:.2g}"
            for value, error in zip(found.exponents, found.standard_error, strict=True)
        ),
        f"largest: {found.largest:.6g} 1/s"
        + (" (chaotic)" if found.largest > 3 * found.standard_error[0] else ""),
    ]
    if found.grazings:
        lines.append(
            f"{len(found.grazings)} grazing(s), where the flow has no derivative: the first "
            f"at {found.grazings[0][0]:.6g} s ({found.grazings[0][1]})"
        )
    if args.plot:
        lines.append(f"plot written to {args.plot}")
    print("\n".join(lines))
    return 0


def run_curve(args: argparse.Namespace) -> int:
    scenario = load_scenario(args.scenario)
    if not isinstance(scenario, SystemScenario):
        raise UsageError(structure_needed(args.scenario, "curve"))
    if "curve" not in scenario.data:
        raise UsageError(f"{args.scenario}: curve needs a [curve] section")
    start = time.perf_counter()
    found = curve_of(scenario.data, scenario.base_dir)
    cpu_time = time.perf_counter() - start
    if args.plot:
        regions = curve_regions(found, scenario.data, scenario.base_dir)
        plots.plot_curve(args.plot, found, regions, scenario.data)
    if args.json:
        print(
            json_text(
                {
                    "kind": found.kind,
                    "parameter": found.parameter,
                    "second": found.second,
                    "periods": found.periods,
                    "stopped": found.stopped,
                    "points": [p.to_dict(found.n, found.k) for p in found.points],
                    "cpu_time": cpu_time,
                }
            )
        )
        return 0
    lines = [
        f"{args.scenario}: {len(found.points)} points of the {found.kind} curve of "
        f"{found.periods}-period orbits in {cpu_time:.3f} s; stopped: {found.stopped}",
        f"{with_units(found.second, scenario.data):>24}  "
        f"{with_units(found.parameter, scenario.data)}",
        *(
            f"{p.values[found.second]:>24.10g}  {p.values[found.parameter]:.12g}"
            for p in found.points
        ),
    ]
    if args.plot:
        lines.append(f"plot written to {args.plot}")
    print("\n".join(lines))
    return 0
