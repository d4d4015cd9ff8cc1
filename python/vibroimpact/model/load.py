"""Any scenario file as a typed :class:`~vibroimpact.System`: the 0.2 format (a
``[structure]`` section) as written, and the 0.1 two-mass format (``[system]`` and
``[contact]``) as the system it describes, an oscillator with one damper."""

from __future__ import annotations

import os
from pathlib import Path

from vibroimpact import arguments
from vibroimpact._core import InvalidInputError
from vibroimpact.messages import unknown_section
from vibroimpact.model.parts import Damper, Initial, Oscillator, Output, Solver
from vibroimpact.model.system import System
from vibroimpact.scenario.system import SECTIONS, system_scenario
from vibroimpact.scenario.two_mass import (
    Scenario,
    ScenarioError,
    read_scenario_text,
    read_toml,
    two_mass_scenario,
)
from vibroimpact.system import default_stepping


@arguments.typed()
def load(source: str | os.PathLike[str]) -> System:
    """The :class:`~vibroimpact.System` of a scenario: a path to a TOML file, or the
    TOML text itself (a str holding a line break, as :meth:`System.to_toml` writes it).

    Every key is checked as ``vibroimpact simulate`` checks it, with its errors
    (:class:`~vibroimpact.ScenarioError`, a ValueError, naming the file, section and
    key). A 0.2 scenario keeps its ``[solver]``, ``[output]`` and analyses' tables
    (``system.solver``, ``system.output``, ``system.analyses``), so that
    ``vi.simulate(vi.load(path))`` runs what the command line runs; a recorded signal's
    relative ``file`` is read from the scenario's folder (``system.base_dir``). A
    ``[solver]`` without ``t_end`` (as a System whose Solver has none writes it) is
    read with its other keys checked; its runs are then given ``t_end``.

    A 0.1 two-mass scenario becomes its System: an :class:`Oscillator` (``main_mass``,
    ``stiffness``, ``damping``) with one :class:`Damper` at point 0 (``impact_mass``,
    the same ``clearance`` each side, the ``[contact]`` law, ``stiffness``,
    ``restitution`` and contact ``damping``) and the ``[initial]`` state (main mass as
    the structure's coordinate, impact mass as the damper's). Its ``[output]`` is kept,
    and its ``[solver]`` with its stepping written out (0.1's default is ``"fixed"`` for
    ``"newmark"`` and ``"rk4"``, 0.2's ``"events"``), so that the general kernel runs the
    file's method as the file asks, bit for bit as ``vibroimpact simulate`` of the file
    runs it (both run the general kernel).
    """
    if isinstance(source, str) and "\n" in source:
        return loads(source)
    if isinstance(source, str) and not source.strip():
        # Path("") is the working folder: "cannot read scenario '.': Is a directory".
        raise InvalidInputError("source: an empty path; give a scenario file")
    path = arguments.path("path", source)
    return loads(read_scenario_text(path), str(path), path.parent)


@arguments.typed()
def loads(text: str, source: str = "<scenario>", base_dir: Path | None = None) -> System:
    """The :class:`~vibroimpact.System` of a scenario's TOML text (see :func:`load`);
    ``source`` names it in errors, ``base_dir`` is the folder of its recorded files
    (kept absolute: a relative one would be read from wherever the run is made)."""
    arguments.text("text", text)
    arguments.text("source", source)
    base_dir = arguments.directory("base_dir", base_dir)
    if base_dir is not None:
        # Made absolute now: after a chdir, a relative folder read another folder's
        # record (no contact, no error), and two spellings of one path compared unequal.
        base_dir = base_dir.resolve()
    data = read_toml(text, source)
    if "structure" not in data:
        return _two_mass(two_mass_scenario(data, source), data)
    solver = data.get("solver")
    try:
        if solver is not None and not (isinstance(solver, dict) and "t_end" not in solver):
            # Every section checked as a run of the file checks it (errors name the file).
            system_scenario(data, source, base_dir)
        else:
            # A system written without [solver] (System.to_toml of a bare System), or
            # with one whose runs are given their length (its Solver has no t_end):
            # the System checks its parts.
            for name in data:
                if name not in SECTIONS:
                    allowed = f"allowed with [structure]: {', '.join(SECTIONS)}"
                    raise ScenarioError(f"{source}: {unknown_section(name, data[name], allowed)}")
    except ValueError as err:
        raise ScenarioError(str(err)) from None
    try:
        return System.from_dict(data, base_dir)
    except ValueError as err:
        raise ScenarioError(f"{source}: {err}") from None


def _two_mass(scenario: Scenario, data: dict[str, object]) -> System:
    """The System a checked 0.1 scenario describes (see :func:`load`)."""
    main, contact, start = scenario.system, scenario.contact, scenario.initial
    solver_table = dict(data.get("solver", {}))  # type: ignore[call-overload]
    stepping = scenario.stepping or default_stepping("two-mass", scenario.method)
    # The two kinds' defaults differ (the core registry's RUN_DEFAULTS: the paper's
    # "newmark", with "newmark" and "rk4" in fixed steps, against "rk4" by events):
    # written out, so that the general kernel runs the file's method as the 0.1 file asks.
    solver_table["method"] = scenario.method
    if stepping == default_stepping("system", scenario.method):
        solver_table.pop("stepping", None)
        solver_table.pop("contact_timing", None)  # fixed stepping's only
    else:
        solver_table["stepping"] = stepping
    solver = Solver(**solver_table)
    output = data.get("output")
    return System(
        structure=Oscillator(mass=main.main_mass, stiffness=main.stiffness, damping=main.damping),
        dampers=[
            Damper(
                mass=main.impact_mass,
                at=0,
                clearance=main.clearance,
                law=contact.law,
                stiffness=contact.stiffness,
                restitution=contact.restitution,
                damping=contact.damping,
            )
        ],
        initial=Initial(
            structure_displacement=(start.main_displacement,),
            structure_velocity=(start.main_velocity,),
            damper_displacement=(start.impact_displacement,),
            damper_velocity=(start.impact_velocity,),
        ),
        solver=solver,
        output=None if output is None else Output(**output),  # type: ignore[arg-type]
    )
