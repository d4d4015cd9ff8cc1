"""The analyses' commands on the command line's parser (``orbit``, ``sweep``,
``bifurcation``, ``poincare``, ``basins``, ``continue``): their arguments and help; what
each runs is in :mod:`vibroimpact.cli.analysis_commands`."""

from __future__ import annotations

import argparse
from typing import Any

from vibroimpact.analysis import BIFURCATION_SAMPLES
from vibroimpact.cli.tangent_commands import add_tangent_parsers
from vibroimpact.output import path_argument


def add_commands(sub: Any) -> None:
    """Register ``orbit`` and ``sweep`` on the command line's subparsers."""
    _add_orbit(sub)
    _add_sweep(sub)


def _add_orbit(sub: Any) -> None:
    """The ``orbit`` command's parser."""
    orbit_parser = sub.add_parser(
        "orbit",
        help="shoot for a periodic orbit of a forced scenario with [structure], with its stability",
        description=(
            "Newton's method on the stroboscopic map over K forcing periods (the common "
            "period of the harmonic excitations), from the scenario's [initial] state: "
            "prints whether it converged, "
            "the state on the orbit at t = 0 (the four arrays of [initial], SI), the Floquet "
            "multipliers (eigenvalues of the monodromy matrix: the tangent flow through the "
            "impacts and contacts; finite differences from Python, "
            'vibroimpact.orbit(..., jacobian="differences")), stability, '
            "impacts per forcing period and the amplitude (largest |structure "
            "displacement| over the orbit, m, per coordinate)."
        ),
    )
    orbit_parser.add_argument(
        "scenario", type=path_argument, help="scenario file (.toml, [structure])"
    )
    orbit_parser.add_argument(
        "--periods", type=int, default=1, metavar="K", help="forcing periods of the orbit (1)"
    )
    orbit_parser.add_argument(
        "--tolerance",
        type=float,
        default=1e-10,
        help="largest |P(z) - z| relative to the largest displacement and velocity (1e-10)",
    )
    orbit_parser.add_argument(
        "--settle",
        type=int,
        default=0,
        metavar="N",
        help="forcing periods run from [initial] before shooting, the guess then the state "
        "they end at (0: [initial] itself); a guess near the orbit is what Newton needs",
    )
    orbit_parser.add_argument(
        "--max-iterations",
        type=int,
        default=40,
        metavar="N",
        help="Newton iterations at most (40); each is a run of K periods and its tangent flow",
    )
    orbit_parser.add_argument(
        "--derivative",
        action="append",
        metavar="PATH",
        default=[],
        help="also the orbit's derivatives in this parameter (a dotted path such as "
        '"damper.0.clearance"; repeatable), by the implicit function theorem on the '
        "shooting equations: its state at t = 0 and its amplitude per structure "
        "coordinate, per unit of the parameter",
    )
    orbit_parser.add_argument("--json", action="store_true", help="print one JSON object")
    orbit_parser.add_argument(
        "--plot",
        type=path_argument,
        metavar="FILE.png",
        help="plot the orbit's time history and phase portrait with its impacts marked",
    )


def _add_sweep(sub: Any) -> None:
    """The ``sweep`` command's parser."""
    sweep_parser = sub.add_parser(
        "sweep",
        help="stepped sweep of a parameter (frequency response), from a [sweep] section",
        description=(
            "For each value of [sweep] parameter (a dotted path such as "
            '"excitation.0.frequency"), from start to stop in count steps, up, down or '
            "both: settle settle_periods forcing periods from the last point's state, then "
            "record record_periods; prints per point the amplitude (located peaks, m) and "
            "RMS (m) per structure coordinate (of coordinate 0 in the table; with [output] "
            "points, of the structure at the first point, and --json gives them all), "
            "impacts per period, whether the stroboscopic state settled, and the "
            "structure's linear response without dampers and stops."
        ),
    )
    sweep_parser.add_argument(
        "scenario", type=path_argument, help="scenario file (.toml) with [sweep]"
    )
    sweep_parser.add_argument(
        "--derivative",
        action="append",
        metavar="PATH",
        default=[],
        help="also, at each point, the derivatives of the orbit through its settled state "
        'in this parameter (a dotted path such as "damper.0.clearance"; repeatable; '
        "default [sweep] derivatives), as orbit --derivative: its state at t = 0 and its "
        "amplitudes, per unit of the parameter (m per its unit); null where the orbit "
        "is not found",
    )
    sweep_parser.add_argument("--json", action="store_true", help="print one JSON object")
    sweep_parser.add_argument(
        "--plot",
        type=path_argument,
        metavar="FILE.png",
        help="plot the response against the parameter, with and without the dampers "
        "(with derivatives, d amplitude / d PATH beside it)",
    )

    bif = sub.add_parser(
        "bifurcation",
        help="bifurcation diagram: stroboscopic samples against a [sweep] parameter",
        description=(
            "For each value of the [sweep] section's parameter (up, down or both, each "
            "point starting from the last one's state), settle settle_periods forcing "
            "periods, then sample the next record_periods: the stroboscopic displacement "
            "of structure coordinate 0 (m, each period), or at each impact its approach "
            "speed (m/s) or phase w t mod 2 pi (rad); prints or plots the samples."
        ),
    )
    _outputs(bif, "scenario file (.toml) with [sweep]", "plot the diagram")
    bif.add_argument(
        "--sample",
        choices=list(BIFURCATION_SAMPLES),
        help="what to sample: displacement (stroboscopic, m), impact-velocity (approach "
        "speed at each impact, m/s) or impact-phase (w t mod 2 pi at each impact, rad); "
        "default [sweep] sample, else displacement",
    )
    bif.add_argument(
        "--pair",
        metavar="PAIR",
        help='the pair whose impacts are sampled ("stop 0", "damper 1"); default '
        "[sweep] pair, else every pair",
    )

    sec = sub.add_parser(
        "poincare",
        help="Poincare sections: stroboscopic and at impacts",
        description=(
            "From the scenario's [initial] state, settle --settle forcing periods, then "
            "sample --periods more: the state at each period (stroboscopic section) and each "
            "rigid impact's phase (rad) and speed (m/s) (compliant onsets: bifurcation --sample)."
        ),
    )
    sec.add_argument("scenario", type=path_argument, help="scenario file (.toml, [structure])")
    sec.add_argument("--settle", type=int, default=200, help="forcing periods to settle (200)")
    sec.add_argument("--periods", type=int, default=500, help="forcing periods sampled (500)")
    sec.add_argument("--json", action="store_true", help="print one JSON object")
    sec.add_argument("--plot", type=path_argument, metavar="FILE.png", help="plot both sections")

    bas = sub.add_parser(
        "basins",
        help="basins of attraction over two initial values, from a [basins] section",
        description=(
            "For each start on a grid of two entries of [initial] ([basins] x and y: state "
            '= "structure_displacement.0" and the like, start, stop, count), find the '
            "steady state and group the starts by the attractor they reach (period, impacts "
            "per period, amplitude)."
        ),
    )
    _outputs(bas, "scenario file (.toml) with [basins]", "plot the basins")

    cont = sub.add_parser(
        "continue",
        help="continue a periodic orbit in a parameter (pseudo-arclength), from [continuation]",
        description=(
            "From the orbit found from [initial] at the scenario's value of [continuation] "
            "parameter, follow the branch of K-period orbits (periods) towards stop, "
            "through folds, with Floquet multipliers and stability at each point, flagging "
            "folds, flips, Neimark-Sacker and branch points, and grazing (a change of "
            "impacts per period)."
        ),
    )
    _outputs(cont, "scenario file (.toml) with [continuation]", "plot the branch")
    add_tangent_parsers(sub)


def _outputs(parser: argparse.ArgumentParser, scenario: str, plot: str) -> None:
    """The scenario argument, --json and --plot of an analysis command."""
    parser.add_argument("scenario", type=path_argument, help=scenario)
    parser.add_argument("--json", action="store_true", help="print one JSON object")
    parser.add_argument("--plot", type=path_argument, metavar="FILE.png", help=plot)
