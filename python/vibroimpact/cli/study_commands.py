"""The ``study`` command: a ``[study]`` grid of runs into a NetCDF file or a Zarr store."""

from __future__ import annotations

import argparse
import json
import shlex
import sys
import time
from collections.abc import Mapping
from typing import Any

import numpy as np

from vibroimpact._core import InvalidInputError
from vibroimpact.output import (
    UsageError,
    check_output,
    check_plot,
    json_text,
    path_argument,
    structure_needed,
)
from vibroimpact.scenario.system import SystemScenario
from vibroimpact.scenario.two_mass import load_scenario
from vibroimpact.study import (
    MAX_WORKERS,
    PER_COORDINATE,
    base_metrics,
    check_threads,
    every_run_failed,
    output_kind,
    run,
    study_of,
    terminal_progress,
)


def add_command(sub: Any) -> None:
    """Register ``study`` on the command line's subparsers."""
    parser = sub.add_parser(
        "study",
        help="a grid of runs varying [study.axes], metrics into a NetCDF 4 file or Zarr store",
        description=(
            "Run every combination of the [study.axes] values of a scenario with "
            "[structure] on all cores (or --workers N), each run reduced to the [study] "
            "metrics, and write "
            "them as an xarray Dataset (one dimension per axis, a status variable, the "
            "reasons of failed runs in its attributes) in NetCDF 4 (--out RESULT.nc: HDF5 "
            "by h5netcdf, 64-bit integers, strings, compressed; xr.open_dataset reads it) "
            "or Zarr (--out RESULT.zarr, needs vibroimpact[zarr]). Finished chunks are kept "
            "beside the output (OUT.parts/): a study interrupted or killed resumes where "
            "it stopped when run again, and gives the same file or store."
        ),
    )
    parser.add_argument("scenario", type=path_argument, help="scenario file (.toml) with [study]")
    parser.add_argument(
        "--out",
        type=path_argument,
        required=True,
        metavar="RESULT.nc|RESULT.zarr",
        help="NetCDF 4 file (.nc) or Zarr store (.zarr; needs vibroimpact[zarr]) to write",
    )
    parser.add_argument(
        "--workers",
        type=int,
        default=0,
        metavar="N",
        help=f"threads, or processes with --dask local (default 0: all cores; at most "
        f"{MAX_WORKERS})",
    )
    parser.add_argument(
        "--dask",
        metavar="ADDRESS",
        help="run the chunks as tasks of a Dask cluster (a scheduler address, or 'local' "
        "for a LocalCluster of --workers processes); needs vibroimpact[dask]",
    )
    parser.add_argument("--json", action="store_true", help="print a JSON summary")
    parser.add_argument(
        "--plot",
        type=path_argument,
        metavar="FILE.png",
        help="heat map of --metric over the axes --x and --y (the others reduced to their "
        "worst, the largest value), the optimum (smallest) marked",
    )
    parser.add_argument("--metric", help="the metric to plot (default: the first one)")
    parser.add_argument("--x", help="the axis across (default: the first)")
    parser.add_argument("--y", help="the axis up (default: the second)")


def run_study_command(args: argparse.Namespace) -> int:
    check_threads(args.workers, "--workers")
    # The output's suffix (and zarr, for a store) before anything runs.
    if output_kind(args.out) != ".zarr":
        check_output(args.out, "--out", [args.scenario])
    if args.plot:
        check_plot(args.plot, [args.scenario])
    for flag, value in (("--metric", args.metric), ("--x", args.x), ("--y", args.y)):
        if value is not None and not args.plot:
            # They choose the map's metric and axes only: without a map they did nothing.
            raise UsageError(f"{flag} chooses what --plot draws: give --plot FILE.png too")
    scenario = load_scenario(args.scenario)
    if not isinstance(scenario, SystemScenario):
        raise UsageError(structure_needed(args.scenario, "study"))
    try:
        study = study_of(scenario.data, str(args.scenario), scenario.base_dir)
    except InvalidInputError as err:
        text = str(err)
        if not text.startswith(str(args.scenario)):
            text = f"{args.scenario}: {text}"
        raise InvalidInputError(text) from None
    axes = list(study.settings["axes"])
    output = study.data.get("output")
    output = output if isinstance(output, Mapping) else {}
    # With [output] points (moments) the per-coordinate metrics are also kept at each.
    kept = base_metrics(study.settings["metrics"])
    allowed = list(kept)
    per_coordinate = [m for m in kept if m in PER_COORDINATE]
    for key, prefix in (("points", "point_"), ("moments", "moment_")):
        if output.get(key):
            allowed += [prefix + m for m in per_coordinate]
    first = study.settings["metrics"][0]
    # A cantilever's coordinates are modes: where there are points (or moments) the
    # map is of the first (user trial: the default map showed half the tip's
    # deflection).
    chosen = [f"{kind}_{first}" for kind in ("point", "moment")] + [first]
    metric = args.metric or next(m for m in chosen if m in allowed)
    x = args.x or axes[0]
    y = args.y or (axes[1] if len(axes) > 1 else None)
    if args.plot and len(axes) < 2:
        raise UsageError(
            f"--plot draws a heat map over two axes; the study has one ({axes[0]}): add an "
            "axis or drop --plot"
        )
    if args.plot:
        metrics = ", ".join(allowed)
        if metric not in allowed:
            raise UsageError(
                f"--metric must be one of the study's metrics ({metrics}), got {metric!r}"
            )
        for flag, axis in (("--x", x), ("--y", y)):
            if axis is None or axis not in axes:
                raise UsageError(
                    f"{flag} must be one of the study's axes ({', '.join(axes)}), got {axis!r}"
                )
        if x == y:
            raise UsageError("--x and --y must be two different axes")
    start = time.perf_counter()
    # `run` keeps an earlier output where every run fails (its notice says so).
    earlier = args.out.exists() or args.out.is_symlink()
    dataset = run(
        study,
        args.out,
        threads=args.workers,
        progress=terminal_progress(),
        dask=args.dask,
        notice=lambda line: print(f"vibroimpact: {line}", file=sys.stderr),
        resume=f"run again: {_command(args)}",
    )
    if args.plot:
        from vibroimpact.analysis.plots import plot_study

        plot_study(args.plot, dataset, metric, x, str(y))
    elapsed = time.perf_counter() - start
    failed = int(np.count_nonzero(dataset["status"].values))
    # Every run failed: the file is written (its reasons say why) unless it would
    # replace an earlier result; nothing was computed, which the exit status says too.
    status = 1 if every_run_failed(dataset) else 0
    written = not (status and earlier)
    summary: dict[str, Any] = {
        "out": str(args.out),
        "written": written,
        "runs": study.runs,
        "failed": failed,
        "reasons": json.loads(dataset.attrs["reasons"]),
        "axes": {path: len(values) for path, values in study.settings["axes"].items()},
        "metrics": list(study.settings["metrics"]),
        "cpu_time": elapsed,
    }
    if args.json:
        print(json_text(summary))
    else:
        where = f"written to {args.out}" if written else f"{args.out} not written"
        print(f"{args.scenario}: {study.runs} runs ({failed} failed) in {elapsed:.3f} s, {where}")
        if args.plot:
            print(f"plot written to {args.plot}")
        # A few reasons; a large failed region has one per value (the file has all).
        reasons = summary["reasons"]
        for reason in reasons[:_REASONS_SHOWN]:
            print(f"  failed: {reason}")
        if len(reasons) > _REASONS_SHOWN:
            print(
                f"  ... and {len(reasons) - _REASONS_SHOWN} more reasons (every one in the "
                + (
                    "file's attrs['reasons'], numbered by its status)"
                    if written
                    else "--json output's reasons)"
                )
            )
    if status:
        print(f"vibroimpact: error: every one of the {study.runs} runs failed", file=sys.stderr)
    return status


#: The failure reasons the text summary lists.
_REASONS_SHOWN = 5


def _command(args: argparse.Namespace) -> str:
    """The ``study`` command line of ``args`` (what resumes it), quoted for a shell."""
    words = ["vibroimpact", "study", str(args.scenario), "--out", str(args.out)]
    for flag, value in (
        ("--workers", args.workers or None),
        ("--dask", args.dask),
        ("--plot", args.plot),
        ("--metric", args.metric),
        ("--x", args.x),
        ("--y", args.y),
    ):
        if value is not None:
            words += [flag, str(value)]
    if args.json:
        words.append("--json")
    return shlex.join(words)
