"""TOML scenarios of 0.2 systems (a ``[structure]`` section) and what the command line
prints and writes for them.

Sections: ``[structure]`` and ``[solver]`` (required), ``[[damper]]``, ``[[stop]]``,
``[gravity]``, ``[[excitation]]``, ``[initial]``, ``[output]``; see
:mod:`vibroimpact.system` and the README. Every key is checked: an unknown key, a
wrong type or a bad value is an error naming the file, the section and the key.
"""

from __future__ import annotations

import csv
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from vibroimpact._core import MAX_RECORD_BYTES, InvalidInputError
from vibroimpact.messages import unknown_section
from vibroimpact.model.system import ANALYSIS_SECTIONS
from vibroimpact.output import finite_or_none, written_whole
from vibroimpact.system import (
    _FIXED_STEP,
    RUN_SECTIONS,
    PreparedRun,
    SystemSolution,
    prepare_system,
    structure_coordinates,
)
from vibroimpact.system.parameter_keys import check_parameter_keys
from vibroimpact.units import contact_table

SECTIONS = (*RUN_SECTIONS, *ANALYSIS_SECTIONS)


@dataclass(frozen=True)
class SystemScenario:
    """A checked 0.2 scenario (see :func:`vibroimpact.system.prepare_system`)."""

    source: str
    prepared: PreparedRun
    #: The parsed sections, for analyses that vary them.
    data: dict[str, Any] = field(default_factory=dict, compare=False, repr=False)
    base_dir: Path | None = None

    @property
    def solver(self) -> dict[str, Any]:
        return dict(self.prepared.solver)

    def run(self) -> SystemSolution:
        """Integrate the scenario; errors name the file."""
        try:
            return self.prepared.run()
        except InvalidInputError as err:
            raise InvalidInputError(f"{self.source}: {err}") from None


def system_scenario(data: dict[str, Any], source: str, base_dir: Path | None) -> SystemScenario:
    """A 0.2 scenario from parsed TOML, every section checked; errors name the file,
    the section and the key."""
    for name in data:
        if name not in SECTIONS:
            allowed = f"allowed with [structure]: {', '.join(SECTIONS)}"
            raise InvalidInputError(f"{source}: {unknown_section(name, data[name], allowed)}")
    if "solver" not in data:
        raise InvalidInputError(f"{source}: missing section [solver]")
    try:
        prepared = prepare_system(
            data["structure"],
            damper=data.get("damper", ()),
            stop=data.get("stop", ()),
            collision=data.get("collision", ()),
            friction=data.get("friction", ()),
            gravity=data.get("gravity"),
            excitation=data.get("excitation", ()),
            initial=data.get("initial"),
            solver=data["solver"],
            output=data.get("output"),
            base_dir=base_dir,
        )
    except InvalidInputError as err:
        raise InvalidInputError(f"{source}: {err}") from None
    data = dict(data)
    from vibroimpact.analysis import SETTINGS
    from vibroimpact.study import checked_study_settings

    # [study] is checked, its axes and draws left unmade (a study makes them).
    for section, check in {**SETTINGS, "study": checked_study_settings}.items():
        if section in data:
            try:
                data[section] = check(data[section])
            except InvalidInputError as err:
                raise InvalidInputError(f"{source}: {err}") from None
    try:
        check_parameter_keys(data)
    except InvalidInputError as err:
        raise InvalidInputError(f"{source}: {err}") from None
    return SystemScenario(source, prepared, data, base_dir)


def system_summary(
    scenario: SystemScenario, sol: SystemSolution, cpu_time: float
) -> dict[str, Any]:
    """The JSON-ready summary of a run (SI units): settings, statistics, the final state,
    the energy balance, the contacts with the pair each belongs to and, when ``[output]``
    asks for them, the reductions: from ``record_from`` the ``peak`` and ``rms`` of each
    structure coordinate (m) over ``recorded_time`` (s), and ``point_peak`` and
    ``point_rms`` (m) at each of ``points`` (``[output] points``) and ``moment_peak`` and
    ``moment_rms`` (N m) at each of ``moments``, every ``strobe_period`` the
    ``strobe`` states (rows of the flat state: the structure's then the dampers'
    displacements, then their velocities) at ``strobe_time``."""
    solver = scenario.solver
    output = scenario.prepared.output
    reductions: dict[str, Any] = {}
    if output["record_from"] is not None:
        reductions |= {
            "record_from": output["record_from"],
            "recorded_time": sol.recorded_time,
            "peak": [finite_or_none(float(v)) for v in sol.peak],
            "rms": [finite_or_none(float(v)) for v in sol.rms],
        }
        if len(sol.points):
            reductions |= {
                "points": [float(v) for v in sol.points],
                "point_peak": [finite_or_none(float(v)) for v in sol.point_peak],
                "point_rms": [finite_or_none(float(v)) for v in sol.point_rms],
            }
        if len(sol.moments):
            reductions |= {
                "moments": [float(v) for v in sol.moments],
                "moment_peak": [finite_or_none(float(v)) for v in sol.moment_peak],
                "moment_rms": [finite_or_none(float(v)) for v in sol.moment_rms],
            }
    if output["strobe_period"] is not None:
        reductions |= {
            "strobe_period": output["strobe_period"],
            "strobe_time": [float(v) for v in sol.strobe_time],
            "strobe": [[float(v) for v in row] for row in sol.strobe],
        }
    return {
        "method": sol.method,
        "dt": solver.get("dt"),
        "t_end": solver.get("t_end"),
        "final_time": sol.final_time,
        "steps": sol.steps,
        "rejected_steps": sol.rejected_steps,
        "rhs_evaluations": sol.rhs_evaluations,
        "grazing_contacts": sol.grazing_contacts,
        "history_rows": len(sol.t),
        "cpu_time": cpu_time,
        "final_state": {key: [float(v) for v in value] for key, value in sol.final_state.items()},
        "energy": dict(sol.energy),
        "contacts": [
            {k: (v if isinstance(v, str) else finite_or_none(v)) for k, v in row.items()}
            for row in sol.contacts.to_dicts()
        ],
        **reductions,
    }


def history_columns(sol: SystemSolution) -> list[tuple[str, Any]]:
    """The CSV columns: ``t``, then each coordinate's displacement and velocity, then
    the structure's displacement at each of ``[output] points`` and the bending moment
    (N m) at each of ``moments``."""
    columns: list[tuple[str, Any]] = [("t", sol.t)]
    for name in (
        "structure_displacement",
        "structure_velocity",
        "damper_displacement",
        "damper_velocity",
    ):
        array = getattr(sol, name)
        columns += [(f"{name}_{i}", array[:, i]) for i in range(array.shape[1])]
    columns += [
        (f"point_displacement_{j}", sol.displacement_at(at)) for j, at in enumerate(sol.points)
    ]
    columns += [(f"bending_moment_{j}", sol.moment_at(at)) for j, at in enumerate(sol.moments)]
    return columns


def record_files(scenario: SystemScenario) -> list[Path]:
    """The files of the scenario's recorded signals, as it reads them."""
    files = []
    excitations = scenario.data.get("excitation", ())
    for e in [excitations] if isinstance(excitations, Mapping) else excitations:
        if isinstance(e, Mapping) and isinstance(e.get("file"), str):
            path = Path(e["file"])
            base = scenario.base_dir
            files.append(path if path.is_absolute() or base is None else base / path)
    return files


def expected_rows(run: PreparedRun) -> float:
    """The history rows a run of fixed steps keeps at least (the exact flow's steps are at
    most its dt); 0 where the steps are not fixed."""
    solver, output = run.solver, run.output
    stepped = solver["method"] in (*_FIXED_STEP, "exact")
    if solver["dt"] is None or not stepped or not output["history"]:
        return 0.0
    return float(solver["t_end"] / solver["dt"] / output["every"] + 2)


def check_history_file(run: PreparedRun, rows: float) -> None:
    """Refuse a CSV history of ``rows`` rows whose values (the state's columns and
    one per point and moment) would pass what a run's records may hold: each point or
    moment column is a whole array in memory, and the file ~25 bytes a value."""
    output = run.output
    columns = 1 + 2 * structure_coordinates(run.spec["structure"]) + 2 * len(run.spec["damper"])
    derived = len(output["points"]) + len(output["moments"])
    size = rows * (columns + derived) * 8
    if size > MAX_RECORD_BYTES:
        raise InvalidInputError(
            f"--out: the history would hold {rows:.3g} rows of {columns + derived} columns "
            f"({derived} for [output] points and moments), {size / 2**20:.0f} MiB, more than "
            f"the {MAX_RECORD_BYTES >> 20} MiB a run's records may take: raise [output] every, "
            "follow fewer points and moments, or shorten t_end"
        )


def write_system_history(path: Path, sol: SystemSolution, run: PreparedRun) -> None:
    """Write the history as CSV, whole or not at all (see :func:`check_history_file`)."""
    check_history_file(run, len(sol.t))
    columns = history_columns(sol)
    with written_whole(path) as f:
        writer = csv.writer(f)
        writer.writerow(name for name, _ in columns)
        for row in zip(*(values for _, values in columns), strict=True):
            writer.writerow(repr(float(v)) for v in row)


def system_lines(
    name: str, sol: SystemSolution, cpu_time: float, output: dict[str, Any] | None = None
) -> list[str]:
    """What ``vibroimpact simulate`` prints for a 0.2 run (with the reductions that
    ``output``, the checked ``[output]`` section, asks for)."""
    e = sol.energy
    lines = [
        f"{name}: {sol.method}, {sol.steps} steps ({sol.rejected_steps} rejected, "
        f"{sol.rhs_evaluations} force evaluations) to t = {sol.final_time:g} s in "
        f"{cpu_time * 1e3:.3f} ms",
        (
            "energy (J): stored {:.6g} -> {:.6g}, input work {:.6g}, dissipated {:.6g} (viscous "
            "{:.6g}, contact {:.6g}, impacts {:.6g}"
            # Dry friction's loss where there is one (a frictionless run's line as it was).
            + (f", friction {e['friction']:.6g}" if e.get("friction") else "")
            + "), residual {:.3g}"
        ).format(
            *(
                e[key] + 0.0
                for key in (
                    "stored_start",
                    "stored_end",
                    "input_work",
                    "dissipated",
                    "viscous",
                    "contact",
                    "impact",
                    "residual",
                )
            )
        ),
    ]
    output = output or {}
    if output.get("record_from") is not None:
        lines.append(
            f"from t = {output['record_from']:g} s ({sol.recorded_time:g} s recorded): peak (m) "
            + ", ".join(f"{v:.7g}" for v in sol.peak)
            + "; rms (m) "
            + ", ".join(f"{v:.7g}" for v in sol.rms)
        )
        for at, peak, rms in zip(sol.points, sol.point_peak, sol.point_rms, strict=True):
            lines.append(f"  at point {at:g}: peak {peak:.7g} m, rms {rms:.7g} m")
        for at, peak, rms in zip(sol.moments, sol.moment_peak, sol.moment_rms, strict=True):
            lines.append(f"  bending moment at {at:g} m: peak {peak:.7g} N m, rms {rms:.7g} N m")
    if output.get("strobe_period") is not None:
        lines.append(
            f"{len(sol.strobe_time)} stroboscopic state(s), every {output['strobe_period']:g} s "
            "(--json prints them: strobe, strobe_time)"
        )
    lines.append(f"{len(sol.contacts)} contact(s)")
    if len(sol.contacts):
        head = [
            "pair",
            "kind",
            "onset",
            "duration",
            "approach_speed",
            "restitution",
            "energy_dissipated",
        ]
        lines += contact_table(sol.contacts.to_dicts(), head, 17)
    return lines
