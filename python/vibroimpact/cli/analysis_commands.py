"""What the analyses' commands run (``orbit``, ``sweep``, ``bifurcation``,
``poincare``, ``basins``, ``continue``): their output and plots (:data:`COMMANDS`); their
arguments are in :mod:`vibroimpact.cli.analysis_parsers`."""

from __future__ import annotations

import argparse
import sys
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import numpy as np

from vibroimpact._core import InvalidInputError
from vibroimpact.analysis import (
    BIFURCATION_SAMPLES,
    AnalysisError,
    basins,
    bifurcation,
    check_periods,
    check_total,
    continue_orbit,
    orbit,
    orbit_derivatives,
    plots,
    poincare,
    runner,
    shown_amplitudes,
    shown_derivative,
    shown_label,
    shown_values,
    sweep,
    sweep_values,
)
from vibroimpact.analysis.limits import MAX_ITERATIONS, relative_tolerance, whole_count
from vibroimpact.analysis.maps import table_axes
from vibroimpact.analysis.runs import failed_everywhere
from vibroimpact.analysis.settings import named_in
from vibroimpact.cli.tangent_commands import run_curve, run_lyapunov
from vibroimpact.output import UsageError, check_plot, finite_or_none, json_text, structure_needed
from vibroimpact.scenario.system import SystemScenario
from vibroimpact.scenario.two_mass import load_scenario
from vibroimpact.units import derivative_units, parameter_units, with_units


def _system(path: Path, command: str) -> SystemScenario:
    scenario = load_scenario(path)
    if not isinstance(scenario, SystemScenario):
        raise UsageError(structure_needed(path, command))
    return scenario


def run_orbit(args: argparse.Namespace) -> int:
    scenario = _system(args.scenario, args.command)
    check_periods("", "--periods", args.periods, 1)
    check_periods("", "--settle", args.settle, 0)
    whole_count("--max-iterations", args.max_iterations, 1, MAX_ITERATIONS)
    relative_tolerance("--tolerance", args.tolerance)
    run = runner(scenario.data, scenario.base_dir)
    start = time.perf_counter()
    guess = run.map(run.initial_state(), args.settle) if args.settle else None
    found = orbit(
        run,
        guess,
        periods=args.periods,
        tolerance=args.tolerance,
        max_iterations=args.max_iterations,
    )
    derivatives = (
        orbit_derivatives(
            scenario.data,
            found,
            args.derivative,
            periods=args.periods,
            base_dir=scenario.base_dir,
        )
        if args.derivative
        else {}
    )
    cpu_time = time.perf_counter() - start
    summary = {
        "converged": found.converged,
        "state": found.arrays(run.n, run.k),
        "floquet_multipliers": [[float(m.real), float(m.imag)] for m in found.floquet_multipliers],
        "stable": found.stable,
        "jacobian": found.jacobian,
        "grazings": [{"time": t, "pair": p, "speed": v} for t, p, v in found.grazings],
        "impacts_per_period": found.impacts_per_period,
        "amplitude": [float(a) for a in found.amplitude],
        **(
            {
                "points": [float(v) for v in run.points],
                "point_amplitude": [float(a) for a in found.point_amplitude],
            }
            if len(run.points)
            else {}
        ),
        **(
            {
                "moments": [float(v) for v in run.moments],
                "moment_amplitude": [float(a) for a in found.moment_amplitude],
            }
            if len(run.moments)
            else {}
        ),
        **(
            {"derivatives": {path: d.to_dict() for path, d in derivatives.items()}}
            if derivatives
            else {}
        ),
        "periods": args.periods,
        "forcing_period": run.period,
        "iterations": found.iterations,
        "residual": finite_or_none(found.residual),
        "cpu_time": cpu_time,
    }
    if args.plot:
        plots.plot_history(args.plot, plots.orbit_history(run, found.state, args.periods))
    if args.json:
        print(json_text(summary))
        return 0
    lines = [
        f"{args.scenario}: {'converged' if found.converged else 'did NOT converge'} to a "
        f"{args.periods}-period orbit in {found.iterations} Newton iterations "
        f"(residual {found.residual:.2e}), {cpu_time * 1e3:.2f} ms",
        *(
            []
            if found.converged
            else [
                "(what follows is of the last Newton iterate, not of an orbit; start nearer "
                "it with --settle N, or allow more --max-iterations)"
            ]
        ),
        f"stable: {found.stable}; impacts per forcing period: {found.impacts_per_period:g}",
        "Floquet multipliers: "
        + ", ".join(
            f"{m.real:.6g}{m.imag:+.6g}i (|{abs(m):.6g}|)" for m in found.floquet_multipliers
        ),
        "amplitude (m): " + ", ".join(f"{a:.6g}" for a in found.amplitude),
        *(
            f"  at point {at:g}: amplitude {a:.6g} m"
            for at, a in zip(run.points, found.point_amplitude, strict=True)
        ),
        *(
            f"  bending moment at {at:g} m: amplitude {a:.6g} N m"
            for at, a in zip(run.moments, found.moment_amplitude, strict=True)
        ),
    ]
    for key, values in summary["state"].items():
        lines.append(f"{key} = [{', '.join(f'{v:.12g}' for v in values)}]")
    for path, d in derivatives.items():
        lines.append(
            f"d/d {path}: state [{', '.join(f'{v:.6g}' for v in d.state)}], amplitude "
            f"[{', '.join(f'{v:.6g}' for v in d.amplitude)}]"
        )
    if args.plot:
        lines.append(f"plot written to {args.plot}")
    print("\n".join(lines))
    return 0


def run_sweep(args: argparse.Namespace) -> int:
    scenario = _system(args.scenario, args.command)
    settings = scenario.data.get("sweep")
    if settings is None:
        raise UsageError(
            f"{args.scenario}: sweep needs a [sweep] section (parameter, start, stop, count)"
        )
    values = sweep_values(settings)
    # Each once, as the analysis takes them (derivative_paths).
    derivatives = list(dict.fromkeys(args.derivative or settings["derivatives"] or ()))
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
            derivatives=derivatives,
        )
    finally:
        if show:
            print(file=sys.stderr)
    cpu_time = time.perf_counter() - start
    # No point of the response: an error (exit 1, no plot), as bifurcation's; --json still
    # prints each point's error first.
    refusal = failed_everywhere("sweep", settings["parameter"], points)
    if refusal is not None and not args.json:
        raise refusal
    if args.plot:
        plots.plot_sweep(
            args.plot, settings["parameter"], points, scenario.data, derivatives=derivatives
        )
    if args.json:
        print(
            json_text(
                {
                    "parameter": settings["parameter"],
                    "points": [p.to_dict() for p in points],
                    "cpu_time": cpu_time,
                }
            )
        )
        if refusal is not None:
            raise refusal
        return 0
    print(
        f"{args.scenario}: {len(points)} points of {settings['parameter']} in "
        f"{cpu_time:.3f} s ({settings['settle_periods']} settle and "
        f"{settings['record_periods']} recorded periods each)"
    )
    # Coordinate 0's amplitudes, or the structure's at the first point where there are
    # points (a cantilever's modal coordinates are no deflection), else the first
    # bending moment's.
    shown, unit = shown_amplitudes(points[0])
    name = {"coordinate": "_0", "point": "@point0"}.get(shown, "@moment0")
    head = [
        "value",
        "direction",
        f"amplitude{name}",
        f"linear{name}",
        f"rms{name}",
        "impacts/period",
        "settled",
        *(f"d amplitude{name} / d {path}" for path in derivatives),
    ]
    if shown != "coordinate":
        print(f"({shown_label(points[0], shown)}, {unit})")
    value_unit = parameter_units(settings["parameter"], scenario.data) or "its own unit"
    print(f"(value: {settings['parameter']}, {value_unit}; amplitude, linear and rms: {unit})")
    for path in derivatives:
        print(f"(d amplitude{name} / d {path}: {derivative_units(unit, path, scenario.data)})")
    widths = [max(14, len(h)) for h in head]
    print("  ".join(f"{h:>{w}}" for h, w in zip(head, widths, strict=True)))
    for p in points:
        amplitude, linear, rms = shown_values(p, shown)
        cells = [
            f"{p.value:>14.6g}",
            f"{p.direction:>14}",
            f"{amplitude[0]:>14.6g}",
            f"{linear[0]:>14.6g}",
            f"{rms[0]:>14.6g}",
            f"{p.impacts_per_period:>14.4g}",
            f"{str(p.settled):>14}",
            *(
                f"{shown_derivative(p, shown, path):>{w}.6g}"
                for path, w in zip(derivatives, widths[len(head) - len(derivatives) :], strict=True)
            ),
        ]
        print("  ".join(cells) + (f"  error: {p.error}" if p.error else ""))
    if args.plot:
        print(f"plot written to {args.plot}")
    return 0


def _progress(enabled: bool) -> Any:
    def progress(done: int, total: int) -> None:
        if enabled:
            print(f"\r{done}/{total}", end="", file=sys.stderr, flush=True)

    return progress


def _section(scenario: SystemScenario, name: str, path: Path) -> dict[str, Any]:
    settings = scenario.data.get(name)
    if settings is None:
        raise UsageError(f"{path}: this command needs a [{name}] section")
    return dict(settings)


def run_bifurcation(args: argparse.Namespace) -> int:
    scenario = _system(args.scenario, args.command)
    settings = _section(scenario, "sweep", args.scenario)
    sample = args.sample or settings["sample"]
    pair = args.pair if args.pair is not None else settings["pair"]
    show = sys.stderr.isatty() and not args.json
    start = time.perf_counter()
    try:
        points = bifurcation(
            scenario.data,
            settings["parameter"],
            sweep_values(settings),
            direction=settings["direction"],
            settle_periods=settings["settle_periods"],
            sample_periods=settings["record_periods"],
            sample=sample,
            pair=pair,
            base_dir=scenario.base_dir,
            progress=_progress(show),
        )
    except AnalysisError as err:
        # The function's sample_periods is the section's record_periods; its pair,
        # --pair or the section's.
        message = str(err)
        if message.startswith("sample_periods:"):
            message = f"{args.scenario}: [sweep] record_periods:" + message[15:]
            raise AnalysisError(message) from None
        if message.startswith("pair:"):
            where = "--pair" if args.pair is not None else "[sweep] pair"
            raise AnalysisError(f"{args.scenario}: {where}:" + message[5:]) from None
        raise
    if show:
        print(file=sys.stderr)
    cpu_time = time.perf_counter() - start
    if args.plot:
        plots.plot_bifurcation(
            args.plot, settings["parameter"], points, scenario.data, sample=sample, pair=pair
        )
    rows = [
        {
            "value": p.value,
            "direction": p.direction,
            "strobe_displacement": [float(v) for v in p.strobe[:, 0]] if p.strobe.size else [],
            "samples": [float(v) for v in p.samples],
            **({"error": p.error} if p.error else {}),
        }
        for p in points
    ]
    if args.json:
        print(
            json_text(
                {
                    "parameter": settings["parameter"],
                    "sample": sample,
                    "sample_units": BIFURCATION_SAMPLES[sample],
                    "pair": pair,
                    "points": rows,
                    "cpu_time": cpu_time,
                }
            )
        )
        return 0
    parameter = with_units(settings["parameter"], scenario.data)
    print(f"{args.scenario}: {len(points)} values of {parameter} in {cpu_time:.3f} s")
    what = {
        "displacement": "stroboscopic displacement(s)",
        "impact-velocity": "impact velocities",
        "impact-phase": "impact phases",
    }[sample]
    for row in rows:
        if "error" in row:
            # A failed point has no samples: its error, not "0 distinct ... of 0".
            print(f"{row['value']:>12.6g} {row['direction']:>5}: failed: {row['error']}")
            continue
        samples = np.asarray(row["samples"])
        scale = float(np.max(np.abs(samples), initial=0.0)) or 1.0
        distinct = len(np.unique(np.round(samples / scale, 6)))
        print(
            f"{row['value']:>12.6g} {row['direction']:>5}: {distinct} distinct {what} of "
            f"{len(samples)}"
        )
    if args.plot:
        print(f"plot written to {args.plot}")
    return 0


@contextmanager
def _named_as(argument: str, key: str) -> Iterator[None]:
    """An analysis's refusal of its ``argument`` (the text its message begins with)
    named as the scenario or command line gives it, ``key``."""
    try:
        yield
    except AnalysisError as err:
        if str(err).startswith(argument):
            raise AnalysisError(key + str(err)[len(argument) :]) from None
        raise


def run_poincare(args: argparse.Namespace) -> int:
    scenario = _system(args.scenario, args.command)
    check_periods("", "--settle", args.settle, 0)
    check_periods("", "--periods", args.periods, 1)
    check_total(("--settle", args.settle), ("--periods", args.periods))
    run = runner(scenario.data, scenario.base_dir)
    start = time.perf_counter()
    with _named_as("periods ", "--periods "):
        section = poincare(run, settle_periods=args.settle, periods=args.periods)
    cpu_time = time.perf_counter() - start
    if args.plot:
        plots.plot_section(args.plot, section, run.period)
    if args.json:
        print(
            json_text(
                {
                    "forcing_period": run.period,
                    "strobe": section.strobe.tolist(),
                    "impact_phase": section.impact_phase.tolist(),
                    "impact_speed": section.impact_speed.tolist(),
                    "impact_pair": section.impact_pair,
                    "cpu_time": cpu_time,
                }
            )
        )
        return 0
    print(
        f"{args.scenario}: {len(section.strobe)} stroboscopic points and "
        # The impact section holds rigid impacts (a compliant contact has no instant).
        f"{len(section.impact_phase)} rigid impacts in {cpu_time:.3f} s"
    )
    if args.plot:
        print(f"plot written to {args.plot}")
    return 0


def run_basins(args: argparse.Namespace) -> int:
    scenario = _system(args.scenario, args.command)
    settings = _section(scenario, "basins", args.scenario)
    run = runner(scenario.data, scenario.base_dir)
    axes = table_axes(settings, run)
    show = sys.stderr.isatty() and not args.json
    start = time.perf_counter()
    result = basins(
        run,
        axes[0],
        axes[1],
        settle_periods=settings["settle_periods"],
        record_periods=settings["record_periods"],
        tolerance=settings["tolerance"],
        progress=_progress(show),
    )
    if show:
        print(file=sys.stderr)
    cpu_time = time.perf_counter() - start
    if args.plot:
        plots.plot_basins(args.plot, result, settings["x"]["state"], settings["y"]["state"])
    if args.json:
        print(
            json_text(
                {
                    "x": settings["x"]["state"],
                    "y": settings["y"]["state"],
                    "x_values": result.first.tolist(),
                    "y_values": result.second.tolist(),
                    "labels": result.labels.tolist(),
                    "attractors": result.attractors,
                    "cpu_time": cpu_time,
                }
            )
        )
        return 0
    print(f"{args.scenario}: {result.labels.size} starts in {cpu_time:.3f} s")
    for index, a in enumerate(result.attractors):
        share = float(np.mean(result.labels == index))
        print(
            f"attractor {index}: {a['period']}-periodic, {a['impacts_per_period']:g} impacts per "
            f"period, amplitude {a['amplitude']} m: {share:.1%} of the starts"
        )
    for label, name in ((-1, "not settled"), (-2, "failed"), (-3, "not admissible")):
        share = float(np.mean(result.labels == label))
        if share:
            print(f"{name}: {share:.1%}")
    if args.plot:
        print(f"plot written to {args.plot}")
    return 0


def run_continue(args: argparse.Namespace) -> int:
    scenario = _system(args.scenario, args.command)
    settings = _section(scenario, "continuation", args.scenario)
    show = sys.stderr.isatty() and not args.json
    start = time.perf_counter()
    with named_in("continuation", settings):
        branch = continue_orbit(
            scenario.data,
            settings["parameter"],
            stop=settings["stop"],
            periods=settings["periods"],
            step=settings["step"],
            max_points=settings["max_points"],
            tolerance=settings["tolerance"],
            base_dir=scenario.base_dir,
            progress=_progress(show),
            switch=settings["switch"],
        )
    if show:
        print(file=sys.stderr)
    cpu_time = time.perf_counter() - start
    if args.plot:
        plots.plot_branch(args.plot, branch, scenario.data)
    if args.json:
        print(json_text({**_branch_dict(branch), "cpu_time": cpu_time}))
        return 0
    print(
        f"{args.scenario}: {len(branch.points)} orbits of {branch.periods} period(s) along "
        f"{with_units(branch.parameter, scenario.data)} in {cpu_time:.3f} s; stopped: "
        f"{branch.stopped}"
    )
    located = {(b.kind, b.value) for b in branch.bifurcations}

    def flagged(p: Any, f: str) -> str:
        if f not in p.crossings:
            return f
        if (f, p.crossings[f]) in located:
            return f"{f} at {p.crossings[f]:.6g}"
        # An estimate between the two orbits, not a located bifurcation.
        return f"{f} near {p.crossings[f]:.6g} (not located)"

    for p in branch.points:
        flags = ", ".join(flagged(p, f) for f in p.flags)
        largest = float(np.max(np.abs(p.floquet_multipliers)))
        print(
            f"{p.value:>12.6g}  amplitude {p.amplitude[0]:.6g} m  max|multiplier| "
            f"{largest:.6f}  {'stable' if p.stable else 'unstable'}  "
            f"{p.impacts_per_period:g} impacts/period  {flags}"
        )
    for b in branch.bifurcations:
        print(f"{b.kind} located at {branch.parameter} = {b.value!r}")
    if branch.switched is not None:
        s = branch.switched
        print(
            f"period-doubled branch ({s.periods} periods): {len(s.points)} orbits, "
            f"stopped: {s.stopped}"
            + "".join(f"; {b.kind} located at {b.value!r}" for b in s.bifurcations)
        )
    if args.plot:
        print(f"plot written to {args.plot}")
    return 0


def _branch_dict(branch: Any) -> dict[str, Any]:
    """A continued branch as JSON: its points, located bifurcations and (with
    ``switch``) the period-doubled branch."""
    return {
        "parameter": branch.parameter,
        "periods": branch.periods,
        "stopped": branch.stopped,
        "points": [p.to_dict(branch.n, branch.k) for p in branch.points],
        "bifurcations": [b.to_dict(branch.n, branch.k) for b in branch.bifurcations],
        **({"switched": _branch_dict(branch.switched)} if branch.switched is not None else {}),
    }


def _naming_the_file(
    command: Callable[[argparse.Namespace], int],
) -> Callable[[argparse.Namespace], int]:
    """Errors of bad input raised while a command runs, prefixed with the scenario
    file as the errors of reading it are."""

    def run(args: argparse.Namespace) -> int:
        if getattr(args, "plot", None):
            check_plot(args.plot, [args.scenario])
        try:
            return command(args)
        except InvalidInputError as err:
            text = str(err)
            if text.startswith(str(args.scenario)):
                raise
            raise InvalidInputError(f"{args.scenario}: {text}") from None

    return run


COMMANDS = {
    name: _naming_the_file(command)
    for name, command in {
        "orbit": run_orbit,
        "sweep": run_sweep,
        "bifurcation": run_bifurcation,
        "poincare": run_poincare,
        "basins": run_basins,
        "continue": run_continue,
        "lyapunov": run_lyapunov,
        "curve": run_curve,
    }.items()
}
