"""A typed 0.2 system: a structure with its dampers, stops, excitations, gravity and
initial state, checked by the scenario format's one schema (:mod:`vibroimpact.system`).
"""

from __future__ import annotations

import copy
import math
import re
import warnings
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field, fields
from pathlib import Path, PurePath
from typing import Any, TypeVar

import numpy as np

from vibroimpact import arguments
from vibroimpact._core import METHODS, InvalidInputError, PreparedSystem
from vibroimpact.arguments import directory
from vibroimpact.messages import shown, unknown_section
from vibroimpact.model.modes import frequencies_summary
from vibroimpact.model.parts import (
    SIGNALS,
    Base,
    Cantilever,
    Collision,
    Damper,
    Force,
    Friction,
    Gravity,
    Initial,
    Matrices,
    Oscillator,
    Output,
    Part,
    PartKeywordError,
    Recorded,
    Signal,
    Solver,
    Stop,
    Structure,
    keywords_checked,
)
from vibroimpact.model.toml_text import toml_text
from vibroimpact.notebook import system_html
from vibroimpact.system import (
    _FIXED_STEP,
    _OUTPUT,
    _SOLVER,
    RUN_SECTIONS,
    _fail,
    _table,
    _unknown_key,
    initial_arrays,
    initial_table,
    prepare_system,
    solver_table,
    system_spec,
)
from vibroimpact.system.parameter_keys import check_parameter_keys
from vibroimpact.system.run import checked_output
from vibroimpact.system.schema import MAX_SCENARIO_BYTES, not_a_table

_P = TypeVar("_P", bound=Part)

#: s: the step and length of the one-step run a System's solver and output are checked
#: by where its runs are given their length (or their step) when run.
PROBE_STEP = 1e-9
#: The method an output without a solver is checked with: one that needs no step.
ADAPTIVE_PROBE = next(name for name, m in METHODS.items() if m["kind"] == "adaptive")

#: The sections of analyses and studies a System carries as read (see ``analyses``).
ANALYSIS_SECTIONS = ("sweep", "continuation", "basins", "curve", "study")
_STRUCTURES: dict[str, type[Structure]] = {c.kind: c for c in (Oscillator, Matrices, Cantilever)}
_SIGNAL_OF: dict[str, type[Signal]] = {c.kind: c for c in SIGNALS}


@keywords_checked
@dataclass(frozen=True, kw_only=True, repr=False)
class System:
    """A vibro-impact system (SI units), built from typed parts named as the sections
    of a TOML scenario: ``structure`` (:class:`Oscillator`, :class:`Matrices` or
    :class:`Cantilever`), ``dampers`` (``[[damper]]``), ``stops`` (``[[stop]]``),
    ``collisions`` (``[[collision]]``: loose masses striking each other),
    ``frictions`` (``[[friction]]``: dry-friction elements on the structure),
    ``excitations`` (``[[excitation]]``: :class:`Force` or :class:`Base`), ``gravity``
    and ``initial``.

    Its run settings ride along when given (or read from a file by
    :func:`vibroimpact.load`): ``solver`` and ``output`` are the ``[solver]`` and
    ``[output]`` a plain :func:`vibroimpact.simulate` of it uses (its keywords override
    them), ``analyses`` the ``[sweep]``, ``[continuation]``, ``[basins]`` and
    ``[study]`` tables as written (checked when read from a file, and by the analysis
    that uses them; read-only: ``replace(analyses=...)`` makes a changed System).
    ``base_dir`` is the folder a recorded signal's relative ``file`` is
    read from (the scenario's, for a loaded system; by default the working directory
    when the System is made), kept absolute.

    Every value is checked on construction by the scenario's schema, with the error a
    file gets (``[[damper]] 0: law "rigid" needs restitution in [0, 1], got 1.5``), and
    the ``initial`` state as a run checks it (every pair apart or touching); the
    solver's keys, method and ranges, and with its ``t_end`` the whole run (steps, rows,
    memory) and its output. ``to_dict()`` gives the TOML sections, ``to_toml()`` the
    scenario text.
    """

    structure: Structure
    dampers: Sequence[Damper] = ()
    stops: Sequence[Stop] = ()
    collisions: Sequence[Collision] = ()
    frictions: Sequence[Friction] = ()
    excitations: Sequence[Force | Base] = ()
    gravity: Gravity | None = None
    initial: Initial | None = None
    solver: Solver | None = None
    output: Output | None = None
    analyses: Mapping[str, Any] = field(default_factory=dict, hash=False)
    base_dir: Path | None = field(default=None, compare=False)

    def __post_init__(self) -> None:
        _instance("structure", self.structure, Structure, "Oscillator, Matrices or Cantilever")
        for name, kind in (
            ("dampers", Damper),
            ("stops", Stop),
            ("collisions", Collision),
            ("frictions", Friction),
        ):
            object.__setattr__(self, name, _parts(name, getattr(self, name), kind, kind.__name__))
        excitations = _parts("excitations", self.excitations, (Force, Base), "Force or Base")
        for j, excitation in enumerate(excitations):
            _instance(f"excitations[{j}].signal", excitation.signal, Signal, _SIGNAL_NAMES)
        object.__setattr__(self, "excitations", excitations)
        optional: tuple[tuple[str, type[Part]], ...] = (
            ("gravity", Gravity),
            ("initial", Initial),
            ("solver", Solver),
            ("output", Output),
        )
        for name, part in optional:
            if getattr(self, name) is not None:
                _instance(name, getattr(self, name), part, part.__name__)
        if not isinstance(self.analyses, Mapping):
            raise InvalidInputError(
                f"System analyses: must be a dict of tables ({', '.join(ANALYSIS_SECTIONS)}), "
                f"got {shown(self.analyses)}"
            )
        for name in self.analyses:
            if name not in ANALYSIS_SECTIONS:
                raise InvalidInputError(
                    f"System analyses: unknown section {shown(name)} (allowed: "
                    f"{', '.join(ANALYSIS_SECTIONS)})"
                )
        # The System's own copy: a caller's dict changed later does not change it. NumPy
        # arrays and numbers in it as the lists and numbers TOML writes (an axis given as
        # an array made two equal Systems' comparison raise numpy's "ambiguous").
        # Read-only: a table changed in place would pass by the checks below.
        object.__setattr__(self, "analyses", _plain_values(self.analyses, read_only=True))
        base_dir = directory("base_dir", self.base_dir)
        if base_dir is None and self._reads_relative_file():
            # The folder such a file is read from now, kept: after a chdir the same
            # System read another folder's record, with no error.
            base_dir = Path.cwd()
        # Absolute, as vi.loads keeps it (two spellings of one folder compare equal).
        object.__setattr__(self, "base_dir", None if base_dir is None else base_dir.resolve())
        self._check()

    def __eq__(self, other: object) -> bool:
        """Systems are equal where their parts, settings and analyses are; and, where a
        recorded signal reads a relative ``file``, their ``base_dir`` too (the same text
        read from two folders reads two records)."""
        if other.__class__ is not self.__class__:
            return NotImplemented
        compared = [f.name for f in fields(self) if f.compare]
        if any(getattr(self, name) != getattr(other, name) for name in compared):
            return False
        return not self._reads_relative_file() or self.base_dir == other.base_dir

    def _reads_relative_file(self) -> bool:
        """Whether a recorded signal reads a ``file`` by a relative path."""
        return any(
            isinstance(e.signal, Recorded)
            and isinstance(e.signal.file, str | PurePath)
            and not Path(e.signal.file).is_absolute()
            for e in self.excitations
        )

    def __repr__(self) -> str:
        given = ", ".join(
            f"{f.name}={_shown_field(getattr(self, f.name))}"
            for f in fields(self)
            if getattr(self, f.name) not in (None, (), {})
        )
        return f"System({given})"

    def _repr_html_(self) -> str:
        """A summary table for notebooks: the structure, each damper, stop and
        excitation with its units, the structure's first natural frequencies, and the
        settings given."""
        return system_html(self, frequencies_summary(self))

    def _check(self) -> None:
        """Every value through the scenario's schema (its errors, word for word), then
        through the core, which holds the model's ranges (a damper's mass > 0, a
        frequency >= 0, ...): a System that is built is one that runs, and a bad value is
        refused where it is written, not when it is first simulated."""
        sections = self.to_dict()
        check_parameter_keys(sections)
        _check_analyses(sections)
        model = self.model_sections()
        if self.solver is not None and self.solver.t_end is not None:
            run = prepare_system(
                **model,
                solver=sections["solver"],
                output=sections.get("output"),
                base_dir=self.base_dir,
            )
            start = initial_arrays(run.initial)
            PreparedSystem(run.binding_spec(), **run.method_arguments(), initial=start)
            return
        initial = model.pop("initial")
        try:
            spec = system_spec(**model, base_dir=self.base_dir)
        except RecursionError:
            raise _fail("", "a value is nested too deeply (arrays within arrays)") from None
        table = initial_table(initial, spec)
        _core_check(spec, initial_arrays(table))
        output = sections.get("output")
        if output is not None:
            checked_output(_table("[output] ", output, _OUTPUT), spec)
        if self.solver is not None or output is not None:
            # Its runs are given their length: the rest is checked now, as a run of one
            # step checks it (a misspelt method, a law or stepping the method does not
            # take, a step too long for the structure, a strobe period <= 0 built, and
            # were refused only when run); the output alone with a method that needs no
            # step. The window's start is checked against the length when it is given.
            given = sections.get("solver", {"method": ADAPTIVE_PROBE})
            solver = solver_table(given, length_given=False)
            # A fixed step given at run time is checked then (a short one here).
            step = solver["dt"] or (PROBE_STEP if solver["method"] in _FIXED_STEP else None)
            probe = dict(given, t_end=step or PROBE_STEP)
            if step is not None:
                probe["dt"] = step
            window_left_out = {k: v for k, v in (output or {}).items() if k != "record_from"}
            run = prepare_system(
                **(model | {"initial": initial}),
                solver=probe,
                output=window_left_out,
                base_dir=self.base_dir,
            )
            PreparedSystem(run.binding_spec(), **run.method_arguments())

    def model_sections(self) -> dict[str, Any]:
        """The model's sections as :func:`vibroimpact.system.prepare_system` takes them
        (``structure``, ``damper``, ``stop``, ``collision``, ``friction``, ``gravity``,
        ``excitation``, ``initial``)."""
        sections = self.to_dict()
        return {
            "structure": sections["structure"],
            "damper": sections.get("damper", []),
            "stop": sections.get("stop", []),
            "collision": sections.get("collision", []),
            "friction": sections.get("friction", []),
            "gravity": sections.get("gravity"),
            "excitation": sections.get("excitation", []),
            "initial": sections.get("initial"),
        }

    def to_dict(self) -> dict[str, Any]:
        """The scenario's sections as ``tomllib`` reads them: ``structure``, ``damper``,
        ``stop``, ``collision``, ``friction``, ``gravity``, ``excitation`` (lists of tables),
        ``initial``, ``solver``, ``output`` and the analyses' tables, each where given."""
        sections: dict[str, Any] = {"structure": self.structure.to_dict()}
        listed = (
            ("damper", self.dampers),
            ("stop", self.stops),
            ("collision", self.collisions),
            ("friction", self.frictions),
        )
        for name, parts in listed:
            if parts:
                sections[name] = [part.to_dict() for part in parts]
        if self.gravity is not None:
            sections["gravity"] = self.gravity.to_dict()
        if self.excitations:
            sections["excitation"] = [part.to_dict() for part in self.excitations]
        for name in ("initial", "solver", "output"):
            part = getattr(self, name)
            if part is not None:
                sections[name] = part.to_dict()
        analyses: dict[str, Any] = _plain_values(self.analyses)
        return sections | analyses

    @arguments.typed()
    def to_toml(self, *, solver: Solver | None = None, output: Output | None = None) -> str:
        """The system as a 0.2 scenario (TOML text, SI units) that
        :func:`vibroimpact.load` reads back into an equal System (a recorded signal's
        relative ``file`` is written as given: the text read from ``base_dir``, or saved
        there, reads the same record); ``solver`` and
        ``output`` in place of the system's own (a scenario run from the command line
        needs a ``[solver]`` with ``t_end``)."""
        system = self
        if solver is not None or output is not None:
            system = self.replace(
                solver=self.solver if solver is None else solver,
                output=self.output if output is None else output,
            )
        for index, excitation in enumerate(system.excitations):
            name = getattr(excitation.signal, "file", None)
            if isinstance(name, str) and _not_utf8(name):
                raise InvalidInputError(
                    f"System.to_toml: [[excitation]] {index} file: {name!r} is not UTF-8 "
                    "text, which a TOML file holds; rename the file (it runs from Python)"
                )
        text = toml_text(system.to_dict())
        size = len(text.encode("utf-8"))
        if size > MAX_SCENARIO_BYTES:
            # loads() reads it; load() of a file refuses one this large.
            warnings.warn(
                f"System.to_toml: the scenario is {size / 2**20:.1f} MiB, more than the "
                f"{MAX_SCENARIO_BYTES // 2**20} MiB a scenario file may be: vibroimpact.load "
                "refuses it saved as a file (loads reads the text); keep a long record in a "
                "CSV file (Recorded(file=...))",
                stacklevel=2,
            )
        return text

    def replace(self, **changes: Any) -> System:
        """A copy with ``changes`` (fields by name), checked as a new System."""
        values = {f.name: getattr(self, f.name) for f in fields(self)}
        for name in changes:
            if name not in values:
                raise InvalidInputError(
                    f"System.replace: unknown field {name!r} (fields: {', '.join(values)})"
                )
        return System(**(values | changes))

    @classmethod
    @arguments.typed()
    def from_dict(cls, sections: Mapping[str, Any], base_dir: Path | None = None) -> System:
        """A System of a scenario's sections (as ``tomllib`` reads a 0.2 scenario, or
        :meth:`to_dict` gives); checked first as they are, so that a bad table gets the
        file's error (an unknown key included)."""
        if not isinstance(sections, Mapping):
            raise InvalidInputError(
                f"sections: must be a dict of tables (as tomllib reads a scenario), got "
                f"{shown(sections)}"
            )
        known = {name for name in RUN_SECTIONS if name not in ("solver", "output")}
        for name in sections:
            if name not in known | {"solver", "output", *ANALYSIS_SECTIONS}:
                allowed = (
                    f"allowed: {', '.join(sorted(known))}, solver, output, "
                    f"{', '.join(ANALYSIS_SECTIONS)}"
                )
                raise InvalidInputError(unknown_section(name, sections[name], allowed))
        if "structure" not in sections:
            raise InvalidInputError("missing section [structure]")
        try:
            return cls._of_tables(sections, base_dir)
        except (PartKeywordError, TypeError, KeyError, AttributeError):
            # A table the parts cannot take (an unknown key, a missing kind): the
            # schema's error names it.
            model = {name: sections.get(name) for name in known}
            spec = system_spec(
                model["structure"],
                model["damper"] or (),
                model["stop"] or (),
                model["gravity"],
                model["excitation"] or (),
                directory("base_dir", base_dir),
                collision=model["collision"] or (),
                friction=model["friction"] or (),
            )
            start = initial_table(model["initial"], spec)
            for name, schema in (("solver", _SOLVER), ("output", _OUTPUT)):
                table = sections.get(name)
                if table is None:
                    continue
                if not isinstance(table, Mapping):
                    raise _fail("", not_a_table(name, table)) from None
                for key in table:
                    if key not in schema:
                        raise _unknown_key(f"[{name}] ", key, list(schema), "allowed:") from None
            # A key the core requires (a random signal's seed): its error names it.
            _core_check(spec, initial_arrays(start))
            raise

    @classmethod
    def _of_tables(cls, sections: Mapping[str, Any], base_dir: Path | None) -> System:
        if not isinstance(sections["structure"], Mapping):
            # ([[structure]]: a list, which dict() refused naming nothing.)
            raise TypeError("[structure] is not a table: the schema's error names it")
        structure = dict(sections["structure"])
        kind = _STRUCTURES[str(structure.pop("kind"))]
        gravity = sections.get("gravity")
        if gravity is not None and not isinstance(gravity, Mapping):
            gravity = {"acceleration": gravity}  # a number, as the schema takes it
        return cls(
            structure=kind(**structure),
            dampers=_tables(Damper, sections.get("damper")),
            stops=_tables(Stop, sections.get("stop")),
            collisions=_tables(Collision, sections.get("collision")),
            frictions=_tables(Friction, sections.get("friction")),
            excitations=[_excitation(dict(e)) for e in listed_tables(sections.get("excitation"))],
            gravity=_part(Gravity, gravity),
            initial=_part(Initial, sections.get("initial")),
            solver=_part(Solver, sections.get("solver")),
            output=_part(Output, sections.get("output")),
            analyses={name: sections[name] for name in ANALYSIS_SECTIONS if name in sections},
            base_dir=base_dir,
        )


_SIGNAL_NAMES = ", ".join(c.__name__ for c in SIGNALS[:-1]) + f" or {SIGNALS[-1].__name__}"


def _shown_field(value: Any) -> str:
    """A field in the repr: a list of parts as a list."""
    return repr(list(value)) if isinstance(value, tuple) else repr(value)


def _instance(name: str, value: Any, kind: type | tuple[type, ...], wanted: str) -> None:
    # A Structure or a Signal itself is none of its kinds (it has no `kind`: an
    # AttributeError had followed).
    if not isinstance(value, kind) or not hasattr(type(value), "kind") and kind in _KINDED:
        named = re.sub(r"\b([A-Z]\w+)", r"vibroimpact.\1", wanted)
        raise InvalidInputError(f"System {name}: must be a {named}, got {shown(value)}")


#: The parts whose concrete kinds each name a TOML ``kind`` or ``signal``.
_KINDED = (Structure, Signal)


def _parts(name: str, value: Any, kind: type | tuple[type, ...], wanted: str) -> tuple[Any, ...]:
    """A list of parts as a tuple, each checked as one of ``kind``."""
    if isinstance(value, Part) or isinstance(value, str | bytes | Mapping):
        raise InvalidInputError(
            f"System {name}: must be a list of vibroimpact.{wanted} (one in a list too), "
            f"got {shown(value)}"
        )
    if not isinstance(value, Sequence):
        raise InvalidInputError(f"System {name}: must be a list, got {shown(value)}")
    for j, part in enumerate(value):
        _instance(f"{name}[{j}]", part, kind, wanted)
    return tuple(value)


def _not_utf8(text: str) -> bool:
    """Whether ``text`` holds what UTF-8 cannot write (a file name's undecodable bytes,
    which Python keeps as lone surrogates)."""
    try:
        text.encode("utf-8")
    except UnicodeEncodeError:
        return True
    return False


def listed_tables(value: Any) -> list[Mapping[str, Any]]:
    """An array of tables (or one table) as a list; a TypeError where it is neither
    (``excitation = "abc"`` had been taken letter by letter, a message naming nothing:
    the schema's error names the section)."""
    if value is None:
        return []
    tables = [value] if isinstance(value, Mapping) else value
    if not isinstance(tables, list | tuple) or not all(isinstance(t, Mapping) for t in tables):
        raise TypeError("not an array of tables: the schema's error names it")
    return list(tables)


def _part(kind: type[_P], table: Any) -> _P | None:
    return None if table is None else kind(**table)


def _tables(kind: type[_P], value: Any) -> list[_P]:
    return [kind(**table) for table in listed_tables(value)]


def _excitation(table: dict[str, Any]) -> Force | Base:
    """An ``[[excitation]]`` table (checked) as a Force or a Base with its signal."""
    load, signal = table.pop("kind"), _SIGNAL_OF[table.pop("signal")]
    if load == "force":
        at = table.pop("at")
        return Force(at=at, signal=signal(**table))
    return Base(signal=signal(**table))


def sections_of(data: Any, base_dir: Path | None = None) -> tuple[Mapping[str, Any], Path | None]:
    """The analyses' entry: a :class:`System` as its sections (and its ``base_dir``
    where none is given), or a scenario's sections (a dict of tables) as they are;
    anything else is refused naming ``data``."""
    if isinstance(data, System):
        return data.to_dict(), data.base_dir if base_dir is None else base_dir
    if not isinstance(data, Mapping):
        raise InvalidInputError(
            "data: must be a scenario's sections (a dict of tables, as tomllib parses a "
            f"scenario) or a vibroimpact.System, got {shown(data)}"
        )
    return data, base_dir


class ReadOnlyTable(dict):  # type: ignore[type-arg]
    """An analysis's table in a :class:`System`: a dict that is not changed in place (a
    change would pass by the checks a System makes when it is built); make a changed
    System with ``System.replace(analyses=...)``."""

    def _refuse(self, *args: Any, **kwargs: Any) -> None:
        raise TypeError(
            "System.analyses is read-only: make a changed System with "
            "system.replace(analyses={...})"
        )

    __setitem__ = __delitem__ = __ior__ = _refuse  # type: ignore[assignment]
    clear = pop = popitem = setdefault = update = _refuse  # type: ignore[assignment]

    def __reduce__(self) -> tuple[Any, ...]:
        # Pickled and copied as the dict it holds (dict's own way sets items one by one).
        return (ReadOnlyTable, (dict(self),))


class ReadOnlyList(list):  # type: ignore[type-arg]
    """An array in a :class:`System`'s analyses (see :class:`ReadOnlyTable`)."""

    _refuse = ReadOnlyTable._refuse
    __setitem__ = __delitem__ = __iadd__ = __imul__ = _refuse  # type: ignore[assignment]
    append = extend = insert = pop = remove = clear = sort = reverse = _refuse

    def __reduce__(self) -> tuple[Any, ...]:
        return (ReadOnlyList, (list(self),))


def _plain_values(value: Any, read_only: bool = False) -> Any:
    """A copy of ``value`` (an analysis's tables) with NumPy arrays as lists and NumPy
    numbers as Python's, dicts and lists copied all the way down (``read_only``: as
    :class:`ReadOnlyTable` and :class:`ReadOnlyList`)."""
    table, array = (ReadOnlyTable, ReadOnlyList) if read_only else (dict, list)
    if isinstance(value, Mapping):
        return table({key: _plain_values(v, read_only) for key, v in value.items()})
    if isinstance(value, np.ndarray | np.generic):
        value = value.tolist()
        return _plain_values(value, read_only) if isinstance(value, list) else value
    if isinstance(value, list | tuple):
        return array([_plain_values(v, read_only) for v in value])
    return copy.deepcopy(value)


def _core_check(spec: dict[str, Any], initial: list[list[float]]) -> None:
    """The model's ranges and required keys, which the core holds (a damper's mass > 0, a
    frequency >= 0, a random signal's seed), and the ``initial`` state's arrays (every pair
    apart or touching), checked on the schema's ``spec`` as a run checks them: its error
    names the key. Any run length: these checks do not depend on it, but for a random
    signal that lasts the run, whose samples a run of its own length counts (here it
    lasts two of its sample intervals: a 1e8 Hz cutoff was refused as 1 s of samples
    before any run was asked for)."""
    excitations = [_brief_noise(excitation) for excitation in spec["excitation"]]
    binding = {
        **spec,
        "excitation": excitations,
        "gravity": spec["gravity"]["acceleration"],
        "points": [],
        "moments": [],
    }
    PreparedSystem(binding, t_end=1.0, initial=initial)


def _brief_noise(excitation: dict[str, Any]) -> dict[str, Any]:
    """``excitation`` with a random signal that lasts the run (no ``duration``) made to
    last two of its sample intervals (``1 / cutoff_frequency``), where its cutoff is a
    positive number (else left to be refused by name)."""
    cutoff = excitation.get("cutoff_frequency")
    if (
        excitation.get("signal") not in ("white-noise", "kanai-tajimi")
        or "duration" in excitation
        or not isinstance(cutoff, int | float)
        or isinstance(cutoff, bool)
        or not 0 < cutoff < math.inf
    ):
        return excitation
    return {**excitation, "duration": 1.0 / cutoff}


#: The check of each analysis's table and the study's (section -> check), as a scenario
#: file's are checked when it is read: registered by the analyses and the study when
#: imported (``vibroimpact`` imports them), which are built on the model.
ANALYSIS_CHECKS: dict[str, Callable[[Any], object]] = {}


def _check_analyses(sections: Mapping[str, Any]) -> None:
    """The analyses' and the study's tables among ``sections`` (a System built with a bad
    one wrote a file that vi.load refused)."""
    for name, check in ANALYSIS_CHECKS.items():
        if name in sections:
            check(sections[name])
