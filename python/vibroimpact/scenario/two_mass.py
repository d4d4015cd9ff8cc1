"""TOML scenarios: one run of the impact damper described in a file.

Every key is checked: unknown or mistyped keys, wrong types and out-of-range
values raise :class:`ScenarioError` (a ``ValueError``) naming the file, the
section and the key. See ``examples/`` and the README for the format.
"""

from __future__ import annotations

import difflib
import inspect
import math
import reprlib
import stat
import tomllib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from vibroimpact import arguments
from vibroimpact._core import (
    METHOD_OPTIONS,
    RUN_DEFAULTS,
    Contact,
    ImpactDamper,
    InitialState,
    InvalidInputError,
    Solution,
    check_solver,
    simulate,
)
from vibroimpact.scenario.system import SECTIONS, SystemScenario, system_scenario
from vibroimpact.system.schema import MAX_SCENARIO_BYTES


class ScenarioError(InvalidInputError):
    """A scenario file that cannot be read or does not describe a valid run."""


_NUMBER = "number"
_TEXT = "string"
_WHOLE = "whole number"
_BOOLEAN = "boolean"
# TOML integers are 64-bit: "If an integer cannot be represented losslessly, an
# error must be thrown" (TOML 1.0). Python's parser reads any size, so we check.
_TOML_INTEGERS = range(-(2**63), 2**63)
# Values quoted in error messages are cut short: an error is one line.
_SHORT = reprlib.Repr()
_SHORT.maxlevel, _SHORT.maxlist, _SHORT.maxdict = 2, 4, 4
_SHORT.maxstring, _SHORT.maxlong, _SHORT.maxother = 40, 24, 40

# The solver's and the output's defaults are simulate's own (one source: its signature); a
# default of None leaves the choice to the core (max_rows, energy_tolerance).
_DEFAULTS: dict[str, Any] = {
    name: parameter.default for name, parameter in inspect.signature(simulate).parameters.items()
}
# The method options' defaults, and the two-mass damper's method and contact timing,
# are the core registry's (the one place they are written; the stepping, left None, is
# the method's own there too).
_DEFAULTS.update({name: option["default"] for name, option in METHOD_OPTIONS.items()})
_DEFAULTS.update({key: RUN_DEFAULTS["two-mass"][key] for key in ("method", "contact_timing")})

# section -> key -> (type, default; a default of _REQUIRED means the key must be given)
_REQUIRED = object()
_SCHEMA: dict[str, dict[str, tuple[str, Any]]] = {
    "system": {
        "main_mass": (_NUMBER, _REQUIRED),
        "stiffness": (_NUMBER, _REQUIRED),
        "damping": (_NUMBER, 0.0),
        "impact_mass": (_NUMBER, _REQUIRED),
        "clearance": (_NUMBER, _REQUIRED),
    },
    "contact": {
        "law": (_TEXT, _REQUIRED),
        "stiffness": (_NUMBER, _REQUIRED),
        "restitution": (_NUMBER, None),
        "damping": (_NUMBER, 0.0),
    },
    "initial": {
        "main_displacement": (_NUMBER, 0.0),
        "main_velocity": (_NUMBER, 0.0),
        "impact_displacement": (_NUMBER, 0.0),
        "impact_velocity": (_NUMBER, 0.0),
    },
    "solver": {
        "method": (_TEXT, _DEFAULTS["method"]),
        "dt": (_NUMBER, _DEFAULTS["dt"]),
        "t_end": (_NUMBER, _REQUIRED),
        "stepping": (_TEXT, _DEFAULTS["stepping"]),
        "beta": (_NUMBER, _DEFAULTS["beta"]),
        "gamma": (_NUMBER, _DEFAULTS["gamma"]),
        "spectral_radius": (_NUMBER, _DEFAULTS["spectral_radius"]),
        "rtol": (_NUMBER, _DEFAULTS["rtol"]),
        "atol": (_NUMBER, _DEFAULTS["atol"]),
        "max_steps": (_WHOLE, _DEFAULTS["max_steps"]),
        "contact_timing": (_TEXT, _DEFAULTS["contact_timing"]),
        "energy_tolerance": (_NUMBER, _DEFAULTS["energy_tolerance"]),
        "max_rows": (_WHOLE, _DEFAULTS["max_rows"]),
    },
    "output": {
        "every": (_WHOLE, _DEFAULTS["every"]),
        "history": (_BOOLEAN, _DEFAULTS["history"]),
    },
}
_REQUIRED_SECTIONS = ("system", "contact", "solver")


@dataclass(frozen=True)
class Scenario:
    """A validated run: the system, its contact, the initial state and the solver settings.

    Times in s, ``every`` keeps every N-th step of the history (``history`` False keeps
    none); ``max_rows`` and ``energy_tolerance`` bound the run (None: the core's
    defaults, see :func:`vibroimpact.simulate`).
    """

    system: ImpactDamper
    contact: Contact
    initial: InitialState
    method: str = _DEFAULTS["method"]
    dt: float | None = _DEFAULTS["dt"]
    # Required, as in the file's [solver] section; keyword-only so it may follow the
    # defaulted fields.
    t_end: float = field(kw_only=True)
    stepping: str | None = None
    beta: float = _DEFAULTS["beta"]
    gamma: float = _DEFAULTS["gamma"]
    spectral_radius: float = _DEFAULTS["spectral_radius"]
    rtol: float = _DEFAULTS["rtol"]
    atol: float = _DEFAULTS["atol"]
    max_steps: int = _DEFAULTS["max_steps"]
    contact_timing: str = _DEFAULTS["contact_timing"]
    every: int = 1
    energy_tolerance: float | None = _DEFAULTS["energy_tolerance"]
    history: bool = _DEFAULTS["history"]
    max_rows: int | None = _DEFAULTS["max_rows"]

    def solver_settings(self) -> dict[str, Any]:
        """The keyword arguments of :func:`vibroimpact.simulate` this scenario sets."""
        return {
            "dt": self.dt,
            "t_end": self.t_end,
            "method": self.method,
            "every": self.every,
            "contact_timing": self.contact_timing,
            "stepping": self.stepping,
            "beta": self.beta,
            "gamma": self.gamma,
            "spectral_radius": self.spectral_radius,
            "rtol": self.rtol,
            "atol": self.atol,
            "max_steps": self.max_steps,
            "energy_tolerance": self.energy_tolerance,
            "history": self.history,
            "max_rows": self.max_rows,
        }

    def run(self) -> Solution:
        """Integrate the scenario (see :func:`vibroimpact.simulate`)."""
        return simulate(self.system, self.contact, self.initial, **self.solver_settings())


def paper_collision(
    restitution: float | None = None, method: str = _DEFAULTS["method"], dt: float = 1e-4
) -> Scenario:
    """The founding paper's Table 1 system at the onset of a 0.1 m/s collision.

    ``M = 1 kg, K = 1 N/m, C = 0.01 N s/m, m = 0.25 kg, c1 = 0.01 N s/m,
    K_hz = 3000 N/m^1.5``, clearance 0.01 m; Hertz contact, or Hyster-Hertz
    with ``restitution``. Runs 0.3 s.
    """
    law = "hertz" if restitution is None else "hyster-hertz"
    return Scenario(
        system=ImpactDamper(
            main_mass=1.0, stiffness=1.0, damping=0.01, impact_mass=0.25, clearance=0.01
        ),
        contact=Contact(law, stiffness=3000.0, damping=0.01, restitution=restitution),
        initial=InitialState(impact_displacement=0.01, impact_velocity=0.1),
        method=method,
        dt=dt,
        t_end=0.3,
    )


def _fail(source: str, where: str, message: str) -> ScenarioError:
    return ScenarioError(f"{source}: {where}{message}")


def _check_type(source: str, section: str, key: str, kind: str, value: Any) -> Any:
    where = f"[{section}] {key}: "
    shown = _SHORT.repr(value)
    if isinstance(value, int) and not isinstance(value, bool) and value not in _TOML_INTEGERS:
        raise _fail(
            source,
            where,
            f"an integer of {len(str(abs(value)))} digits ({shown}) is outside TOML's "
            "64-bit integers; write it as a float (e.g. 1e30)",
        )
    if kind == _NUMBER:
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise _fail(source, where, f"must be a number, got {shown}")
        value = float(value)
        if not math.isfinite(value):
            raise _fail(source, where, f"must be a finite number, got {value}")
        return value
    if kind == _WHOLE:
        if isinstance(value, bool) or not isinstance(value, int):
            raise _fail(source, where, f"must be a whole number, got {shown}")
        return value
    if kind == _BOOLEAN:
        if not isinstance(value, bool):
            raise _fail(source, where, f"must be true or false, got {shown}")
        return value
    if not isinstance(value, str):
        raise _fail(source, where, f"must be a string, got {shown}")
    return value


def _unknown(source: str, where: str, key: str, allowed: list[str]) -> ScenarioError:
    close = difflib.get_close_matches(key, allowed, n=1)
    hint = f"; did you mean {close[0]!r}?" if close else ""
    return _fail(source, where, f"unknown key {key!r} (allowed: {', '.join(allowed)}){hint}")


def _sections(data: dict[str, Any], source: str) -> dict[str, dict[str, Any]]:
    sections: dict[str, dict[str, Any]] = {}
    for name, table in data.items():
        if name not in _SCHEMA:
            raise _unknown(source, "", name, list(_SCHEMA))
        if not isinstance(table, dict):
            raise _fail(
                source, "", f"{name!r} must be a table ([{name}]), got {_SHORT.repr(table)}"
            )
        schema = _SCHEMA[name]
        values: dict[str, Any] = {}
        for key, value in table.items():
            if key not in schema:
                raise _unknown(source, f"[{name}] ", key, list(schema))
            values[key] = _check_type(source, name, key, schema[key][0], value)
        sections[name] = values
    for name in _REQUIRED_SECTIONS:
        if name not in sections:
            # A scenario is a two-mass damper ([system]) or any structure ([structure]).
            either = " (or [structure], for a structure of any kind)" if name == "system" else ""
            raise _fail(source, "", f"missing section [{name}]{either}")
    for name, schema in _SCHEMA.items():
        values = sections.setdefault(name, {})
        for key, (_, default) in schema.items():
            if key not in values:
                if default is _REQUIRED:
                    raise _fail(source, f"[{name}] ", f"missing key {key!r}")
                values[key] = default
    return sections


def parse_scenario(
    text: str, source: str = "<scenario>", base_dir: Path | None = None
) -> Scenario | SystemScenario:
    """Build a scenario from TOML text; ``source`` names it in errors.

    A file with a ``[structure]`` section describes a 0.2 system
    (:class:`~vibroimpact.scenario.system.SystemScenario`; recorded signals' files
    are read relative to ``base_dir``); one with ``[system]`` and ``[contact]``,
    the two-mass impact damper (:class:`Scenario`).
    """
    arguments.text("text", text)
    arguments.text("source", source)
    base_dir = arguments.directory("base_dir", base_dir)
    data = read_toml(text, source)
    if "structure" in data:
        try:
            return system_scenario(data, source, base_dir)
        except InvalidInputError as err:
            raise ScenarioError(str(err)) from None
    # A section only a structure's file has, and no [system]: [structure] left out
    # (not a two-mass file with an unknown section).
    theirs = [name for name in data if name in SECTIONS and name not in _SCHEMA]
    if theirs and "system" not in data:
        raise ScenarioError(
            f"{source}: missing section [structure]: [{theirs[0]}] belongs to a system on a "
            "structure, which [structure] describes (a two-mass damper's file has [system] "
            "and [contact] instead)"
        )
    return two_mass_scenario(data, source)


def read_toml(text: str, source: str) -> dict[str, Any]:
    """The tables of a scenario's TOML text; invalid TOML is a :class:`ScenarioError`
    naming ``source``. A byte-order mark before it (Notepad's, PowerShell's) is no part of
    the text: TOML's parser had refused the file at its first character."""
    try:
        return tomllib.loads(text.removeprefix("\ufeff"))
    except RecursionError:
        # The parser recurses once per level of nested arrays or inline tables.
        raise ScenarioError(f"{source}: invalid TOML: values nested too deeply") from None
    except tomllib.TOMLDecodeError as err:
        raise ScenarioError(f"{source}: invalid TOML: {err}") from None
    except ValueError as err:
        # The parser's int() refusing a number of thousands of digits; what follows the
        # colon advises on a Python setting, no help to the author of a scenario.
        reason = str(err).split(":")[0]
        raise ScenarioError(f"{source}: invalid TOML: a value it cannot read ({reason})") from None


def two_mass_scenario(data: dict[str, Any], source: str) -> Scenario:
    """The two-mass :class:`Scenario` of a 0.1 scenario's tables, every key checked."""
    s = _sections(data, source)

    def build(section: str, make: Any) -> Any:
        try:
            return make(**s[section])
        except InvalidInputError as err:
            raise _fail(source, f"[{section}] ", str(err)) from None

    system = build("system", ImpactDamper)
    contact = build("contact", Contact)
    initial = build("initial", InitialState)
    scenario = Scenario(system, contact, initial, **s["solver"], **s["output"])
    _validate_solver(scenario, source)
    return scenario


def _validate_solver(scenario: Scenario, source: str) -> None:
    try:
        check_solver(**scenario.solver_settings())
    except InvalidInputError as err:
        section = "output" if str(err).startswith("every ") else "solver"
        raise _fail(source, f"[{section}] ", str(err)) from None


def load_scenario(path: str | Path) -> Scenario | SystemScenario:
    """Read and validate a TOML scenario file (UTF-8, at most ``MAX_SCENARIO_BYTES``)."""
    path = arguments.path("path", path)
    # The folder made absolute: a study's Dask workers, started elsewhere, read a
    # recorded signal's relative file from it (".", theirs, had not found it).
    return parse_scenario(read_scenario_text(path), str(path), path.parent.resolve())


def read_scenario_text(path: Path) -> str:
    """The text of a scenario file (a regular file of UTF-8 text, at most
    ``MAX_SCENARIO_BYTES``); what cannot be read is a :class:`ScenarioError`."""
    try:
        # Checked before opening: opening a FIFO waits for a writer, for ever.
        if not stat.S_ISREG(path.stat().st_mode) and not path.is_dir():
            raise ScenarioError(
                f"cannot read scenario {str(path)!r}: not a regular file (a TOML scenario)"
            )
        with path.open("rb") as f:
            data = f.read(MAX_SCENARIO_BYTES + 1)
        if len(data) > MAX_SCENARIO_BYTES:
            raise ScenarioError(
                f"cannot read scenario {str(path)!r}: larger than "
                f"{MAX_SCENARIO_BYTES // 2**20} MiB; is it a scenario (TOML text)?"
            )
        text = data.decode("utf-8")
    except (OSError, UnicodeDecodeError) as err:
        reason = err.strerror if isinstance(err, OSError) and err.strerror else str(err)
        raise ScenarioError(f"cannot read scenario {str(path)!r}: {reason}") from None
    return text
