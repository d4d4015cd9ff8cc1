"""The ``vibroimpact`` command (also ``python -m vibroimpact``).

Exit status: 0 on success, 2 for bad input (arguments, scenario files,
parameter values, unwritable output), 1 for a run that could not be completed
(numerical blow-up, chattering, Newton failure, max_steps), 130 when
interrupted. Errors are one line on stderr, never a traceback.
"""

from __future__ import annotations

import argparse
import contextlib
import csv
import os
import signal
import sys
import threading
import time
import warnings
from collections.abc import Sequence
from pathlib import Path
from typing import Any, NoReturn

from vibroimpact._core import (
    InvalidInputError,
    NumericalBlowUpError,
    SimulationError,
    Solution,
    __version__,
)
from vibroimpact.cli.analysis_commands import COMMANDS
from vibroimpact.cli.analysis_parsers import add_commands
from vibroimpact.cli.study_commands import add_command as add_study
from vibroimpact.cli.study_commands import run_study_command
from vibroimpact.messages import short_numbers
from vibroimpact.output import (
    UsageError,
    check_csv,
    finite_or_none,
    json_text,
    path_argument,
    written_whole,
)
from vibroimpact.paper import run_paper
from vibroimpact.scenario.system import (
    SystemScenario,
    check_history_file,
    expected_rows,
    record_files,
    system_lines,
    system_summary,
    write_system_history,
)
from vibroimpact.scenario.two_mass import Scenario, ScenarioError, load_scenario, paper_collision
from vibroimpact.units import contact_table

HISTORY_COLUMNS = (
    ("t", "time, s"),
    ("main_displacement", "w, m"),
    ("main_velocity", "w', m/s"),
    ("impact_displacement", "y, m"),
    ("impact_velocity", "y', m/s"),
    ("contact_force", "force between the bodies, N"),
)


# What the energy columns are: printed under the table, the same words as in the help.
ENERGY_DISSIPATED_TEXT = (
    "dissipated (J) is the work of the contact's dissipative forces (the law's hysteresis "
    "and the contact damper c1) during the contact, not the net change of the energy"
)
ENERGY_CHANGE_TEXT = (
    "net change (J) is the system's mechanical energy at separation minus at onset, the "
    "main damper's losses included: a positive value is energy the method created"
)
# Energy growth (relative) above which `simulate` says the run gained energy.
ENERGY_NOTE = 0.01


class _Parser(argparse.ArgumentParser):
    """argparse's parser whose usage errors are one line, as every other error is (not
    the usage lines first), pointing to the command's help; exit status 2. The
    commands' parsers are of this class too (``add_subparsers`` makes its own kind)."""

    def _print_message(self, message: str, file: Any = None) -> None:
        # argparse's own drops a failed write (help into a full output: exit 0, nothing
        # said); here it reaches main, which says it.
        if message:
            stream = file or sys.stderr
            stream.write(message)
            stream.flush()

    def error(self, message: str) -> NoReturn:
        self.exit(2, f"{self.prog}: error: {_one_line(message)} (see {self.prog} --help)\n")


def _one_line(text: str) -> str:
    """An error's text on one line: the line breaks of a name it quotes (a path may
    hold them) written as ``\\n``."""
    return text.replace("\r", "\\r").replace("\n", "\\n")


def _parser() -> argparse.ArgumentParser:
    parser = _Parser(
        prog="vibroimpact",
        description="Simulate impact dampers and vibro-impact systems (SI units).",
    )
    parser.add_argument("--version", action="version", version=f"vibroimpact {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)

    paper = sub.add_parser(
        "paper",
        help="reproduce the founding paper's tables and figures, with a report",
        description=(
            "Reproduce Afsharfard & Farshidianfar (2012): writes tables 2 and 3 (CSV), the "
            "figures (PNG) and report.md, which lists every file written, and prints the "
            "tables. CPU times are measured on this machine (medians of repeated runs). "
            "Each file is written whole or not at all."
        ),
    )
    paper.add_argument(
        "--out",
        type=path_argument,
        default=Path("paper-results"),
        metavar="DIR",
        help="output folder (default: paper-results/)",
    )

    simulate = sub.add_parser(
        "simulate",
        help="run one scenario (TOML); without a file, the paper's Table 1 collision",
        description=(
            "Run one scenario and print its contacts (SI units). Without SCENARIO, the "
            "founding paper's Table 1 collision (Hertz, 0.1 m/s, Newmark-beta, dt = 1e-4 s, "
            f"0.3 s). In the table of contacts: {ENERGY_DISSIPATED_TEXT}. "
            f"{ENERGY_CHANGE_TEXT}. A contact still open at the end of the run shows 'open' "
            "for its separation, duration, rebound, restitution and net change (null in "
            "--json); a value a closed contact has none of (the restitution of a sticking "
            "interval or of a contact that started at rest) shows '-'."
        ),
    )
    simulate.add_argument("scenario", nargs="?", type=path_argument, help="scenario file (.toml)")
    simulate.add_argument(
        "--out",
        type=path_argument,
        metavar="FILE.csv",
        help="write the time history to a CSV file (whole or not at all: a run that fails "
        "leaves an existing file as it was)",
    )
    simulate.add_argument(
        "--json",
        action="store_true",
        help="print one JSON object (steps, contacts, ...); a quantity not defined for a "
        "contact still open at the end of the run is null",
    )
    add_commands(sub)
    add_study(sub)
    return parser


def run_summary(scenario: Scenario, sol: Solution, cpu_time: float) -> dict[str, Any]:
    """The JSON-ready summary of a run: settings, statistics and contacts (SI units)."""
    return {
        "method": scenario.method,
        "dt": scenario.dt,
        "t_end": scenario.t_end,
        "final_time": sol.final_time,
        "stepping": sol.stepping,
        "steps": sol.steps,
        "rejected_steps": sol.rejected_steps,
        "rhs_evaluations": sol.rhs_evaluations,
        "grazing_contacts": sol.grazing_contacts,
        "history_rows": len(sol.t),
        "cpu_time": cpu_time,
        "energy_growth": finite_or_none(sol.energy_growth),
        "contacts": [
            {key: finite_or_none(value) for key, value in row.items()}
            for row in sol.contacts.to_dicts()
        ],
    }


def write_history(path: Path, sol: Solution) -> None:
    """Write the time history as CSV, one row per kept step, whole or not at all."""
    columns = [getattr(sol, name) for name, _ in HISTORY_COLUMNS]
    with written_whole(path) as f:
        writer = csv.writer(f)
        writer.writerow(name for name, _ in HISTORY_COLUMNS)
        for row in zip(*columns, strict=True):
            writer.writerow(repr(float(v)) for v in row)


def contact_lines(sol: Solution) -> list[str]:
    """The text table of contacts, then what its two energy columns mean.

    Columns come from ``ContactTable.columns``; a value left undefined because the
    contact is still open at the end of the run (NaN in the table) reads ``open``, one a
    closed contact has none of reads ``-`` (see ``units.contact_table``).
    """
    lines = contact_table(sol.contacts.to_dicts(), list(sol.contacts.columns), 15)
    return [*lines, f"  {ENERGY_DISSIPATED_TEXT}", f"  {ENERGY_CHANGE_TEXT}"]


def _run(scenario: Scenario | SystemScenario, path: Path | None) -> Any:
    """The scenario's run; its refusal of the input (a start inside a wall, found when
    the run begins) as the scenario's error, naming the file as a refusal when it is
    read does."""
    try:
        return scenario.run()
    except InvalidInputError as err:
        text = str(err)
        if path is None or text.startswith(f"{path}:"):
            raise ScenarioError(text) from None
        raise ScenarioError(f"{path}: {text}") from None


def _simulate_system(args: argparse.Namespace, scenario: SystemScenario) -> int:
    if args.out:
        # Nor the records it reads (user trial: --out replaced the accelerogram).
        check_csv(args.out, [args.scenario, *record_files(scenario)])
        # Known before the run where its steps are fixed: refused before it starts.
        check_history_file(scenario.prepared, expected_rows(scenario.prepared))
    start = time.perf_counter()
    sol = _run(scenario, args.scenario)
    cpu_time = time.perf_counter() - start
    if args.out:
        write_system_history(args.out, sol, scenario.prepared)
    if args.json:
        print(json_text(system_summary(scenario, sol, cpu_time)))
        return 0
    print("\n".join(system_lines(str(args.scenario), sol, cpu_time, scenario.prepared.output)))
    if args.out:
        print(f"history ({len(sol.t)} rows) written to {args.out}")
    return 0


def _simulate(args: argparse.Namespace) -> int:
    if args.out:
        check_csv(args.out, [args.scenario] if args.scenario else [])
    scenario = load_scenario(args.scenario) if args.scenario else paper_collision()
    keeps = (
        scenario.prepared.output["history"]
        if isinstance(scenario, SystemScenario)
        else scenario.history
    )
    if args.out and not keeps:
        raise UsageError(
            f"--out writes the history, which {args.scenario} does not keep "
            "([output] history = false): drop --out or keep the history"
        )
    if isinstance(scenario, SystemScenario):
        return _simulate_system(args, scenario)
    start = time.perf_counter()
    sol = _run(scenario, args.scenario)
    cpu_time = time.perf_counter() - start
    if args.out:
        write_history(args.out, sol)
    summary = run_summary(scenario, sol, cpu_time)
    if args.json:
        print(json_text(summary))
        return 0
    name = str(args.scenario) if args.scenario else "the paper's Table 1 collision"
    step = f"dt = {scenario.dt:g} s" if scenario.dt is not None else f"rtol = {scenario.rtol:g}"
    print(
        f"{name}: {scenario.method} ({sol.stepping} stepping), {step}, {sol.steps} steps "
        f"({sol.rejected_steps} rejected, {sol.rhs_evaluations} force evaluations) "
        f"to t = {sol.final_time:g} s in {cpu_time * 1e3:.3f} ms"
    )
    if sol.energy_growth > ENERGY_NOTE:
        print(
            f"note: the energy of this unforced system grew by {sol.energy_growth:.1%}; "
            "that is numerical error: reduce dt or use a more accurate method"
        )
    print(f"{len(sol.contacts)} contact(s)")
    if len(sol.contacts):
        print("\n".join(contact_lines(sol)))
    if args.out:
        print(f"history ({len(sol.t)} rows) written to {args.out}")
    return 0


class _Terminated(BaseException):
    """SIGTERM or SIGHUP, raised where the program is, so that cleanups run."""

    def __init__(self, signum: int) -> None:
        super().__init__(signum)
        self.signum = signum


def _terminate(signum: int, frame: Any) -> None:
    raise _Terminated(signum)


# What ends a run like Ctrl-C does: a termination request (SIGTERM, what `timeout` and
# schedulers send) and a closed terminal (SIGHUP, where the system has it), each with
# its message and exit status (128 + the signal's number).
_ENDINGS = {
    getattr(signal, name): message
    for name, message in (("SIGTERM", "terminated"), ("SIGHUP", "hung up (terminal closed)"))
    if hasattr(signal, name)
}


def _handle_endings() -> dict[int, Any]:
    """Turn the signals of ``_ENDINGS`` into :class:`_Terminated` (a SIGHUP ignored, as
    under nohup, stays ignored); returns the handlers they had."""
    previous: dict[int, Any] = {}
    for signum in _ENDINGS:
        handler = signal.getsignal(signum)
        if signum == getattr(signal, "SIGHUP", None) and handler == signal.SIG_IGN:
            continue
        previous[signum] = signal.signal(signum, _terminate)
    return previous


def _print_notes(stop: BaseException) -> None:
    """What a stopped job added to its exception (a study: the chunks it kept, and the
    command that resumes it), a line each."""
    for note in getattr(stop, "__notes__", ()):
        print(f"vibroimpact: {note}", file=sys.stderr)


def _show_warning(
    message: Warning | str,
    category: type[Warning],
    filename: str,
    lineno: int,
    file: Any = None,
    line: str | None = None,
) -> None:
    print(f"vibroimpact: warning: {message}", file=sys.stderr)


def _escape_unencodable() -> list[tuple[Any, str]]:
    """Standard output and error write what their encoding cannot hold as escapes
    (``backslashreplace``); returns each stream changed with its former handler."""
    changed = []
    for stream in (sys.stdout, sys.stderr):
        errors = getattr(stream, "errors", None)
        if hasattr(stream, "reconfigure") and errors in ("strict", None):
            with contextlib.suppress(ValueError, OSError):
                stream.reconfigure(errors="backslashreplace")
                changed.append((stream, errors or "strict"))
    return changed


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; returns the exit status."""
    # A termination request or a closed terminal ends the run like Ctrl-C does, so
    # that a file being written is removed and an earlier result stays whole.
    main_thread = threading.current_thread() is threading.main_thread()
    previous = _handle_endings() if main_thread else {}
    # Warnings as one line each, as errors are (not Python's file:line format).
    shown = warnings.showwarning
    warnings.showwarning = _show_warning
    # A terminal or pipe that cannot encode a name (a path in another script under
    # PYTHONIOENCODING=ascii) gets it escaped, not a UnicodeEncodeError.
    encodings = _escape_unencodable()
    try:
        # In here: --help or --version into a full output is said as a run's is.
        args = _parser().parse_args(argv)
        if args.command == "paper":
            return run_paper(args.out)
        if args.command in COMMANDS:
            return COMMANDS[args.command](args)
        if args.command == "study":
            return run_study_command(args)
        return _simulate(args)
    except (InvalidInputError, UsageError) as err:
        print(f"vibroimpact: error: {_one_line(short_numbers(str(err)))}", file=sys.stderr)
        _print_notes(err)
        return 2
    except (NumericalBlowUpError, SimulationError) as err:
        # The input was valid but the run could not be completed.
        print(f"vibroimpact: error: {_one_line(short_numbers(str(err)))}", file=sys.stderr)
        _print_notes(err)
        return 1
    except KeyboardInterrupt as stop:
        print("vibroimpact: interrupted", file=sys.stderr)
        _print_notes(stop)
        return 130
    except _Terminated as ending:
        print(f"vibroimpact: {_ENDINGS[ending.signum]}", file=sys.stderr)
        _print_notes(ending)
        return 128 + ending.signum
    except MemoryError as err:
        # The machine refused memory the up-front limits did not foresee (a process
        # limit below the machine's memory, `ulimit -v`): one line, not a traceback.
        detail = f" ({err})" if str(err) else ""
        print(
            f"vibroimpact: error: out of memory{detail}: shorten t_end, raise every or "
            "set history = false (a study: fewer runs or a smaller chunk_size)",
            file=sys.stderr,
        )
        return 1
    except BrokenPipeError:
        # The reader (e.g. `| head`) left early: not an error of ours. Point
        # stdout at devnull so that Python's exit flush does not fail again.
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 0
    except OSError as err:
        # What the system refused (the output full: `--json > /dev/full`, a file size
        # limit), said in one line as every error is; the run itself did not fail.
        where = f"{err.filename}: " if err.filename else "writing the output: "
        print(f"vibroimpact: error: {_one_line(f'{where}{err.strerror or err}')}", file=sys.stderr)
        _print_notes(err)
        with contextlib.suppress(OSError):
            os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 1
    finally:
        warnings.showwarning = shown
        for stream, errors in encodings:
            stream.reconfigure(errors=errors)
        for signum, handler in previous.items():
            signal.signal(signum, handler)
