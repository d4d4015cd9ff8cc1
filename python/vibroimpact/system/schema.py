"""vibroimpact 0.2 systems: any structure, several dampers and stops, excitations, rigid impacts.

A system is described by the same sections as a TOML scenario (SI units):

- ``structure``: ``kind = "oscillator"`` (``mass``, ``stiffness``, ``damping``),
  ``"matrices"`` (``mass``, ``stiffness``, ``damping`` as n x n arrays of rows; M
  symmetric positive definite, K and C symmetric positive semi-definite) or
  ``"cantilever"`` (``length``, ``youngs_modulus``, ``second_moment``,
  ``mass_per_length``, ``modes``, ``damping_ratio``; modal coordinates). In place of
  ``second_moment`` a ``section`` (``"rectangle"``: ``width``, ``height``;
  ``"circle"``: ``diameter``; ``"tube"``: ``outer_diameter``, ``inner_diameter``; m),
  in place of ``mass_per_length`` a ``density`` (kg/m^3) times its area, and a
  ``material`` (``"steel"``, ``"aluminium"``, ``"titanium"``) for Young's modulus and
  the density: see :mod:`vibroimpact.system.beam`.
- ``damper`` (a list): a loose mass (``mass``, kg) rattling against the point ``at``
  (a coordinate index, or m along a cantilever) with ``clearance`` on each side or
  ``lower_clearance`` and ``upper_clearance`` (m; ``inf``: no wall on that side, as a
  mass on a floor), and a ``law``.
- ``stop`` (a list): the point ``at`` hits a stop fixed to the base; ``side = "upper"``
  keeps it at or below ``+gap``, ``"lower"`` at or above ``-gap`` (m); a ``law``. With
  ``against`` (a second point) the stop is carried by that point instead, so that the
  two pound on each other: ``"upper"`` keeps ``x_at - x_against <= gap``.
- ``collision`` (a list): two loose masses that strike each other, ``dampers = [i, j]``
  (damper i below damper j), touching when damper i's displacement minus damper j's
  reaches ``gap`` (m); a ``law``.
- Dry (Coulomb) friction: a damper's ``friction`` (kinetic coefficient),
  ``static_friction`` (>= ``friction``, default equal) and ``normal_force`` (N: the
  weight of a horizontal damper, or a preload) between it and its carrier; and
  ``friction`` (a list) between the structure's point ``at`` and ``against`` (another
  point; default the base): ``coefficient``, ``static_coefficient``, ``normal_force``.
  While sliding a force ``coefficient * normal_force`` opposes the relative velocity;
  the sides stick when it reaches zero and the force holding them is within
  ``static_coefficient * normal_force``, and slip again when it is not.
- Laws: ``"rigid"`` (Newton's restitution ``restitution`` in [0, 1], located
  instantaneous impacts, chattering summed to its accumulation instant, then
  sticking) or a compliant law of :class:`vibroimpact.Contact` (``stiffness``,
  ``restitution``, ``damping``).
- ``gravity``: ``acceleration`` (m/s^2, along -x; 9.81 when the section is empty).
- ``excitation`` (a list, summed): ``kind = "force"`` at a point ``at`` (N) or
  ``"base"`` (a support acceleration, m/s^2: every coordinate is relative to the
  base, and stops move with it), with a ``signal``: ``"harmonic"`` (``amplitude *
  cos(2 pi frequency t + phase)``, Hz, rad), ``"sweep"`` (``start_frequency``,
  ``end_frequency``, ``duration``, ``sweep = "linear" | "logarithmic"``),
  ``"harmonics"`` (``amplitudes``, ``frequencies``, ``phases``), ``"recorded"``
  (``file``, a CSV of time and value, or ``time`` and ``value`` arrays; linear
  interpolation, ``scale``, zero outside the record), ``"white-noise"`` (two-sided
  ``intensity`` S0 per rad/s up to ``cutoff_frequency``, ``seed``) and
  ``"kanai-tajimi"`` (also ``ground_frequency``, ``ground_damping``); random signals
  are the same bit for bit for the same seed on every platform.
"""

from __future__ import annotations

import difflib
import math
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from vibroimpact._core import (
    DEFAULT_ENERGY_TOLERANCE,
    DEFAULT_MAX_ROWS,
    MAX_PAIRS,
    MAX_SIGNAL_SAMPLES,
    METHOD_OPTIONS,
    METHODS,
    RUN_DEFAULTS,
    Contact,
    InvalidInputError,
)
from vibroimpact.arguments import integer_hint, real, shown_range, whole_range
from vibroimpact.messages import short_numbers, shown
from vibroimpact.system.beam import DIMENSIONS, resolve_cantilever
from vibroimpact.system.points import _check_point, structure_coordinates
from vibroimpact.system.record_file import check_record, read_record

#: The largest scenario file read, bytes. A scenario is a few kB; a cap keeps a wrong
#: path (a disk image, /dev/zero) from filling the memory, and bounds the parse
#: (tomllib reads about 1 MiB/s).
MAX_SCENARIO_BYTES = 4 * 2**20

#: A 0.2 scenario's sections of the system and its run, in the order they are written.
RUN_SECTIONS = (
    "structure",
    "damper",
    "stop",
    "collision",
    "friction",
    "gravity",
    "excitation",
    "initial",
    "solver",
    "output",
)
_NUMBER, _TEXT, _WHOLE, _NUMBERS, _MATRIX = "number", "string", "whole number", "array", "matrix"
_REQ = object()
_TEXTS = "array of strings"
#: A damper's side: a number, or inf for no wall there.
_WALL = "number or inf"

# The keys of each section: (type, default; _REQ where required, None where optional).
_STRUCTURE: dict[str, dict[str, tuple[str, Any]]] = {
    "oscillator": {
        "mass": (_NUMBER, _REQ),
        "stiffness": (_NUMBER, _REQ),
        "damping": (_NUMBER, 0.0),
    },
    "matrices": {"mass": (_MATRIX, _REQ), "stiffness": (_MATRIX, _REQ), "damping": (_MATRIX, None)},
    # Young's modulus, the second moment and the mass per length are each given
    # directly or by a material and a section (resolved by .beam; one way each).
    "cantilever": {
        "length": (_NUMBER, _REQ),
        "youngs_modulus": (_NUMBER, None),
        "second_moment": (_NUMBER, None),
        "mass_per_length": (_NUMBER, None),
        "modes": (_WHOLE, _REQ),
        "damping_ratio": (_NUMBER, 0.0),
        "section": (_TEXT, None),
        **{key: (_NUMBER, None) for key in DIMENSIONS},
        "material": (_TEXT, None),
        "density": (_NUMBER, None),
    },
}
_LAW: dict[str, tuple[str, Any]] = {
    "law": (_TEXT, _REQ),
    "stiffness": (_NUMBER, None),
    "restitution": (_NUMBER, None),
    "damping": (_NUMBER, 0.0),
}
_DAMPER = {
    "mass": (_NUMBER, _REQ),
    "at": (_NUMBER, _REQ),
    "clearance": (_NUMBER, None),
    "lower_clearance": (_WALL, None),
    "upper_clearance": (_WALL, None),
    **_LAW,
    "friction": (_NUMBER, None),
    "static_friction": (_NUMBER, None),
    "normal_force": (_NUMBER, None),
}
_STOP = {
    "at": (_NUMBER, _REQ),
    "side": (_TEXT, _REQ),
    "gap": (_NUMBER, _REQ),
    "against": (_NUMBER, None),
    **_LAW,
}
_COLLISION = {
    "dampers": (_NUMBERS, _REQ),
    "gap": (_NUMBER, _REQ),
    **_LAW,
}
_FRICTION = {
    "at": (_NUMBER, _REQ),
    "against": (_NUMBER, None),
    "coefficient": (_NUMBER, _REQ),
    "static_coefficient": (_NUMBER, None),
    "normal_force": (_NUMBER, _REQ),
}
_GRAVITY = {"acceleration": (_NUMBER, 9.81)}
_EXCITATION = {
    "kind": (_TEXT, _REQ),
    "at": (_NUMBER, None),
    "signal": (_TEXT, _REQ),
    "amplitude": (_NUMBER, None),
    "frequency": (_NUMBER, None),
    "phase": (_NUMBER, None),
    "start_frequency": (_NUMBER, None),
    "end_frequency": (_NUMBER, None),
    "duration": (_NUMBER, None),
    "sweep": (_TEXT, None),
    "amplitudes": (_NUMBERS, None),
    "frequencies": (_NUMBERS, None),
    "phases": (_NUMBERS, None),
    "file": (_TEXT, None),
    "time": (_NUMBERS, None),
    "value": (_NUMBERS, None),
    "scale": (_NUMBER, None),
    "intensity": (_NUMBER, None),
    "cutoff_frequency": (_NUMBER, None),
    "ground_frequency": (_NUMBER, None),
    "ground_damping": (_NUMBER, None),
    "seed": (_WHOLE, None),
}
_INITIAL = {
    "structure_displacement": (_NUMBERS, ()),
    "structure_velocity": (_NUMBERS, ()),
    "damper_displacement": (_NUMBERS, ()),
    "damper_velocity": (_NUMBERS, ()),
}


def default_stepping(kind: str, method: str) -> str:
    """The stepping (``"fixed"`` or ``"events"``) a run of ``method`` on a model of
    ``kind`` (``"two-mass"`` or ``"system"``) takes where none is given: the core
    registry's (``_core.RUN_DEFAULTS``)."""
    return "fixed" if method in RUN_DEFAULTS[kind]["fixed_by_default"] else "events"


#: The solver settings of a 0.2 run and their defaults: the method, its stepping and
#: contact timing, the method options' and max_steps' are the core's registry's
#: (``_core.RUN_DEFAULTS["system"]``, ``_core.METHOD_OPTIONS``).
SYSTEM_SOLVER_DEFAULTS: dict[str, Any] = {
    "method": RUN_DEFAULTS["system"]["method"],
    "dt": None,
    "rtol": METHOD_OPTIONS["rtol"]["default"],
    "atol": METHOD_OPTIONS["atol"]["default"],
    "max_steps": METHOD_OPTIONS["max_steps"]["default"],
    # The same limits as the two-mass runs, from the core.
    "energy_tolerance": DEFAULT_ENERGY_TOLERANCE,
    "max_rows": DEFAULT_MAX_ROWS,
    "beta": METHOD_OPTIONS["beta"]["default"],
    "gamma": METHOD_OPTIONS["gamma"]["default"],
    "spectral_radius": METHOD_OPTIONS["spectral_radius"]["default"],
    # Steps cut at every event, or fixed steps of dt not cut at contacts (compliant
    # laws only), their onsets located inside the step or counted in whole steps.
    "stepping": default_stepping("system", RUN_DEFAULTS["system"]["method"]),
    "contact_timing": RUN_DEFAULTS["system"]["contact_timing"],
}
_SOLVER = {
    "method": (_TEXT, SYSTEM_SOLVER_DEFAULTS["method"]),
    "dt": (_NUMBER, None),
    "t_end": (_NUMBER, _REQ),
    "rtol": (_NUMBER, SYSTEM_SOLVER_DEFAULTS["rtol"]),
    "atol": (_NUMBER, SYSTEM_SOLVER_DEFAULTS["atol"]),
    "max_steps": (_WHOLE, SYSTEM_SOLVER_DEFAULTS["max_steps"]),
    "energy_tolerance": (_NUMBER, SYSTEM_SOLVER_DEFAULTS["energy_tolerance"]),
    "max_rows": (_WHOLE, SYSTEM_SOLVER_DEFAULTS["max_rows"]),
    "beta": (_NUMBER, SYSTEM_SOLVER_DEFAULTS["beta"]),
    "gamma": (_NUMBER, SYSTEM_SOLVER_DEFAULTS["gamma"]),
    "spectral_radius": (_NUMBER, SYSTEM_SOLVER_DEFAULTS["spectral_radius"]),
    "stepping": (_TEXT, SYSTEM_SOLVER_DEFAULTS["stepping"]),
    "contact_timing": (_TEXT, SYSTEM_SOLVER_DEFAULTS["contact_timing"]),
}
_OUTPUT = {
    "every": (_WHOLE, 1),
    "history": ("boolean", True),
    "record_from": (_NUMBER, None),
    "strobe_period": (_NUMBER, None),
    "points": (_NUMBERS, ()),
    "moments": (_NUMBERS, ()),
}
_INT64 = range(-(2**63), 2**63)
# The core registry's methods, the paper's lagged "newmark" among them.
_METHODS = tuple(METHODS)
# Those that step by dt (and take stepping = "fixed").
_FIXED_STEP = tuple(name for name in _METHODS if "fixed" in METHODS[name]["steppings"])
_SIDES = ("upper", "lower")
_LOADS = ("force", "base")
_SIGNALS = ("harmonic", "sweep", "harmonics", "recorded", "white-noise", "kanai-tajimi")
_SWEEPS = ("linear", "logarithmic")
# The keys each signal takes (a key of another signal is an error, not ignored).
_SIGNAL_KEYS: dict[str, set[str]] = {
    "harmonic": {"amplitude", "frequency", "phase"},
    "sweep": {"amplitude", "start_frequency", "end_frequency", "duration", "sweep", "phase"},
    "harmonics": {"amplitudes", "frequencies", "phases"},
    "recorded": {"file", "time", "value", "scale"},
    "white-noise": {"intensity", "cutoff_frequency", "duration", "seed"},
    "kanai-tajimi": {
        "intensity",
        "ground_frequency",
        "ground_damping",
        "cutoff_frequency",
        "duration",
        "seed",
    },
}


def _choice(where: str, key: str, value: Any, choices: Sequence[str]) -> None:
    """Refuse a ``value`` of ``key`` that is not one of the strings ``choices`` (or not a
    string at all: a list or a table is named as such, never looked up)."""
    listed = ", ".join(f'"{c}"' for c in choices)
    if value is None:
        raise _fail(where, f"missing key {key!r} (one of {listed})")
    if not isinstance(value, str):
        raise _fail(where, f"{key} must be one of {listed} (a string), got {shown(value)}")
    if value not in choices:
        raise _fail(where, f'{key} must be one of {listed}, got "{value}"')


def _check_law(where: str, d: Mapping[str, Any], given: Mapping[str, Any]) -> None:
    """A pair's law: "rigid" with a restitution in [0, 1] (and nothing else), or a
    compliant law that :class:`vibroimpact.Contact` accepts with the same values.
    ``given`` is the table as written, to tell a key left out from its default."""
    if d["law"] == "rigid":
        e = d["restitution"]
        if e is None:
            raise _fail(where, "missing key 'restitution' (law \"rigid\" needs one in [0, 1])")
        if not 0.0 <= e <= 1.0:
            raise _fail(where, f'law "rigid" needs restitution in [0, 1], got {e!r}')
        for key in ("stiffness", "damping"):
            if key in given:
                raise _fail(where, f'{key} applies to compliant laws only, not to law "rigid"')
        return
    try:
        Contact(
            d["law"],
            stiffness=1.0 if d["stiffness"] is None else d["stiffness"],
            damping=d["damping"],
            restitution=d["restitution"],
        )
    except InvalidInputError as err:
        message = short_numbers(str(err)).replace(
            "law must be one of ", 'law must be one of "rigid", '
        )
        raise _fail(where, message) from None
    if d["stiffness"] is None:
        raise _fail(where, f'law {d["law"]!r} needs a stiffness (N/m^1.5, N/m for "linear")')


def _fail(where: str, message: str) -> InvalidInputError:
    return InvalidInputError(f"{where}{message}")


def _value(where: str, kind: str, value: Any) -> Any:
    """``value`` checked as ``kind``: numbers finite, whole numbers in 64 bits. NumPy
    real scalars count as numbers; booleans never do."""
    # The common cases first, at once: a scenario's floats and whole numbers.
    if kind == _NUMBER and type(value) is float and math.isfinite(value):
        return value
    if kind == _WHOLE and type(value) is int and 2 <= value < 2**63:  # above every low
        return value
    if kind == _WALL:
        wall = real(value)
        if wall == math.inf:
            return math.inf
        if wall is not None and not math.isfinite(wall):
            # inf is allowed (no wall); -inf and nan are not.
            raise _fail(where, f"must be a number >= 0 m, or inf for no wall, got {wall}")
        kind = _NUMBER
    if kind == _NUMBER:
        number = real(value)
        if number is None:
            if _too_deep(value):
                # Arrays within arrays thousands deep: no structure has them.
                raise _fail("", "a value is nested too deeply (arrays within arrays)")
            raise _fail(where, f"must be a number, got {shown(value)}")
        if isinstance(number, int) and number not in _INT64:
            raise _fail(where, "is an integer beyond 64 bits; write it as a float (e.g. 1e30)")
        number = float(number)
        if not math.isfinite(number):
            raise _fail(where, f"must be a finite number, got {number}")
        return number
    if kind == _WHOLE:
        whole = real(value)
        low, high = whole_range(where)
        if isinstance(whole, float) and whole.is_integer() and abs(whole) >= 2**63:
            # A whole number no integer key takes (1e19, 1e30).
            raise _fail(
                where, f"must be a whole number in {shown_range(low, high)}, got {shown(value)}"
            )
        if not isinstance(whole, int):
            # The key's own range, if any, is checked after (modes: [1, 200]).
            raise _fail(where, f"must be a whole number{integer_hint(whole)}, got {shown(value)}")
        if not low <= whole < 2**63:  # above high and below 2^63: the key's own check
            raise _fail(
                where, f"must be a whole number in {shown_range(low, high)}, got {shown(value)}"
            )
        return whole
    if kind == _TEXT:
        if not isinstance(value, str):
            raise _fail(where, f"must be a string, got {shown(value)}")
        return value
    if kind == "boolean":
        if not isinstance(value, bool | np.bool_):
            raise _fail(where, f"must be true or false, got {shown(value)}")
        return bool(value)
    if kind == _NUMBERS:
        if isinstance(value, str | bytes) or not _is_array(value, 1):
            raise _fail(where, f"must be an array of numbers, got {shown(value)}")
        if len(value) > MAX_SIGNAL_SAMPLES:
            # Refused before a value is read: checking each takes a while.
            raise _fail(
                where, f"holds {len(value)} values; at most {MAX_SIGNAL_SAMPLES} are allowed"
            )
        if isinstance(value, np.ndarray) and value.dtype.kind == "f":
            # A float array at once (a recorded signal's samples).
            bad = np.flatnonzero(~np.isfinite(value))
            if bad.size:
                i = int(bad[0])
                raise _fail(f"{where[:-2]}[{i}]: ", f"must be a finite number, got {value[i]}")
            return list(value.tolist())
        if isinstance(value, list | tuple) and set(map(type, value)) == {float}:
            # Python floats only (a part's record, a file's array): checked at once, in
            # C (one by one, a 1e7-sample record took seconds at each of four checks).
            finite = np.isfinite(np.fromiter(value, float, len(value)))
            if finite.all():
                return list(value)
        return [_value(f"{where[:-2]}[{i}]: ", _NUMBER, v) for i, v in enumerate(value)]
    if kind == _TEXTS:
        if isinstance(value, str | bytes) or not _is_array(value, 1):
            raise _fail(where, f"must be an array of strings, got {shown(value)}")
        return [_value(f"{where[:-2]}[{i}]: ", _TEXT, v) for i, v in enumerate(value)]
    # _MATRIX: an array of rows.
    if isinstance(value, str | bytes) or not _is_array(value, 2):
        raise _fail(where, f"must be an array of rows (n x n), got {shown(value)}")
    return [_value(f"{where[:-2]}[{i}]: ", _NUMBERS, row) for i, row in enumerate(value)]


def _collisions(tables: list[Any], dampers: int) -> list[dict[str, Any]]:
    """The ``[[collision]]`` tables checked: ``dampers``, two different damper indices
    (the lower first), ``gap`` >= 0 m, and a law as for any pair."""
    out = []
    for j, table in enumerate(tables):
        where = f"[[collision]] {j}: "
        d = _table(where, table, _COLLISION)
        if dampers < 2:
            raise _fail(
                where,
                f"a collision is between two [[damper]] (loose masses), and the system has "
                f"{dampers}: add the dampers, or strike a wall with a [[stop]]",
            )
        pair = d["dampers"]
        if (
            len(pair) != 2
            or not all(float(i).is_integer() and 0 <= i < dampers for i in pair)
            or pair[0] == pair[1]
        ):
            raise _fail(
                where,
                f"dampers must be two different [[damper]] indices (0 to {dampers - 1}), "
                f"the lower first, got {shown(table['dampers'])}",
            )
        d["dampers"] = [int(i) for i in pair]
        if not d["gap"] >= 0:
            raise _fail(where, f"gap must be >= 0 m, got {d['gap']}")
        _check_law(where, d, table)
        out.append(d)
    return out


def _check_friction(where: str, d: dict[str, Any], keys: tuple[str, str, str]) -> None:
    """Coulomb friction's ``keys`` (kinetic coefficient, static coefficient, normal
    force) in ``d``: the kinetic >= 0, the static (filled with the kinetic where left
    out) >= the kinetic, the normal force >= 0 N."""
    kinetic, held, normal = keys
    if not d[kinetic] >= 0:
        raise _fail(where, f"{kinetic} must be >= 0 (a coefficient), got {d[kinetic]}")
    if d[held] is None:
        d[held] = d[kinetic]
    elif not d[held] >= d[kinetic]:
        raise _fail(
            where,
            f"{held} must be >= {kinetic} = {d[kinetic]} (sticking holds more), got {d[held]}",
        )
    if d[normal] is None:
        raise _fail(where, f"{normal} is required with {kinetic} (N: the weight, or a preload)")
    if not (d[normal] >= 0 and math.isfinite(d[normal])):
        raise _fail(where, f"{normal} must be a finite number >= 0 N, got {d[normal]}")
    if not math.isfinite(d[held] * d[normal]):
        raise _fail(
            where, f"{held} times {normal} must be a finite force (N), got {d[held] * d[normal]}"
        )


def _frictions(tables: list[Any], structure: dict[str, Any]) -> list[dict[str, Any]]:
    """The ``[[friction]]`` tables checked: a point ``at``, optional ``against``, and
    Coulomb's coefficients and normal force."""
    out = []
    for j, table in enumerate(tables):
        where = f"[[friction]] {j}: "
        d = _table(where, table, _FRICTION)
        for key in ("at", "against"):
            if d[key] is not None:
                _check_point(f"friction {j} {key}", table[key], d[key], structure)
        _check_friction(where, d, ("coefficient", "static_coefficient", "normal_force"))
        if d["against"] is None:
            del d["against"]
        out.append(d)
    return out


def initial_table(initial: Any, spec: Mapping[str, Any]) -> dict[str, Any]:
    """The ``[initial]`` table checked against the system ``spec`` (as
    :func:`system_spec` gives it): its arrays of numbers, each of the structure's
    coordinates or the dampers' count of values, or none (zeros)."""
    table = _table("[initial] ", {} if initial is None else initial, _INITIAL)
    n, k = structure_coordinates(spec["structure"]), len(spec["damper"])
    for key, size in zip(_INITIAL, (n, n, k, k), strict=True):
        got = len(table[key])
        if got and got != size:
            whose = "structure coordinate" if key.startswith("structure") else "[[damper]]"
            raise _fail(
                f"[initial] {key}: ",
                f"must have {size} value{'' if size == 1 else 's'} (one a {whose}), or none, "
                f"got {got}",
            )
    return table


def initial_arrays(table: Mapping[str, Any]) -> list[Any]:
    """The four arrays of a checked ``[initial]`` table (:func:`initial_table`) in the
    order the core takes them: the structure's displacements and velocities, then the
    dampers'."""
    return [table[key] for key in _INITIAL]


def _too_deep(value: Any, limit: int = 32) -> bool:
    """Whether ``value`` is arrays within arrays more than ``limit`` deep."""
    for _ in range(limit):
        if not isinstance(value, list | tuple) or not value:
            return False
        value = value[0]
    return True


def _is_array(value: Any, ndim: int) -> bool:
    """Whether ``value`` is a sequence, or a NumPy array of ``ndim`` dimensions."""
    if isinstance(value, np.ndarray):
        return value.ndim == ndim
    return isinstance(value, Sequence)


def _table(where: str, table: Any, schema: Mapping[str, tuple[str, Any]]) -> dict[str, Any]:
    """A table checked against ``schema``: unknown keys refused (with a suggestion),
    types checked, defaults filled, required keys demanded."""
    if not isinstance(table, Mapping):
        raise _fail(where, f"must be a table, got {shown(table)}")
    out: dict[str, Any] = {}
    for key, value in table.items():
        if key not in schema:
            raise _unknown_key(where, key, list(schema), "allowed:")
        out[key] = _value(f"{where}{key}: ", schema[key][0], value)
    for key, (_, default) in schema.items():
        if key not in out:
            if default is _REQ:
                raise _fail(where, f"missing key {key!r}")
            out[key] = default
    return out


def _unknown_key(where: str, key: Any, names: list[str], intro: str) -> InvalidInputError:
    """The error of an unknown ``key`` of a table: ``names`` (the keys allowed, after
    ``intro``) and the closest of them as a suggestion."""
    close = difflib.get_close_matches(str(key), names, n=1)
    hint = f"; did you mean {close[0]!r}?" if close else ""
    return _fail(where, f"unknown key {key!r} ({intro} {', '.join(names)}){hint}")


def _list(name: str, value: Any) -> list[Any]:
    if isinstance(value, Mapping):
        return [value]
    if isinstance(value, str | bytes) or not isinstance(value, Sequence):
        raise _fail("", f"{name} must be a list of tables ([[{name}]]), got {shown(value)}")
    return list(value)


def not_a_table(name: str, value: Any) -> str:
    """What is said of a section ``[name]`` that is not a table: a list of tables is
    ``[[name]]`` written for ``[name]``."""
    if isinstance(value, list) and value and all(isinstance(v, Mapping) for v in value):
        count = f"{len(value)} table" + ("s" if len(value) > 1 else "")
        return f"[{name}] must be a table, got a list of {count} ([[{name}]]): write [{name}], once"
    return f"[{name}] must be a table, got {shown(value)}"


def structure_spec(structure: Any) -> dict[str, Any]:
    """The ``[structure]`` table checked, its defaults filled and a cantilever's section
    and material resolved to what the core takes (see :func:`system_spec`)."""
    if not isinstance(structure, Mapping):
        raise _fail("", not_a_table("structure", structure))
    kind = structure.get("kind")
    _choice("[structure] ", "kind", kind, tuple(_STRUCTURE))
    schema = {"kind": (_TEXT, _REQ), **_STRUCTURE[str(kind)]}
    table = _table("[structure] ", structure, schema)
    if kind == "cantilever":
        if not 1 <= table["modes"] <= 200:
            raise _fail(
                "[structure] modes: ", f"must be a whole number in [1, 200], got {table['modes']}"
            )
        table = resolve_cantilever(table)
    if kind == "matrices" and table["damping"] is None:
        size = len(table["mass"])
        table["damping"] = [[0.0] * size for _ in range(size)]
    return table


def system_spec(
    structure: Any,
    damper: Any = (),
    stop: Any = (),
    gravity: Any = None,
    excitation: Any = (),
    base_dir: Path | None = None,
    *,
    collision: Any = (),
    friction: Any = (),
) -> dict[str, Any]:
    """The sections of a system, checked and with their defaults filled (see the module
    docstring); errors name the section and key."""
    spec: dict[str, Any] = {"structure": structure_spec(structure)}
    damper_tables, stop_tables = _list("damper", damper), _list("stop", stop)
    collision_tables, friction_tables = _list("collision", collision), _list("friction", friction)
    pairs = len(damper_tables) + len(stop_tables) + len(collision_tables) + len(friction_tables)
    if pairs > MAX_PAIRS:
        # Before any is read: simultaneous impacts solve over every pair, a matrix
        # that grows as their square (70,000 stops aborted asking for 39 GB).
        raise _fail(
            "[[damper]], [[stop]], [[collision]], [[friction]]: ",
            f"at most {MAX_PAIRS} pairs in all, got {pairs}",
        )
    collisions = _collisions(collision_tables, len(damper_tables))
    dampers = []
    for j, table in enumerate(damper_tables):
        d = _table(f"[[damper]] {j}: ", table, _DAMPER)
        both = d["clearance"]
        if both is not None and not both >= 0:
            raise _fail(f"[[damper]] {j}: ", f"clearance must be >= 0 m (each side), got {both}")
        for side in ("lower_clearance", "upper_clearance"):
            if d[side] is None:
                if both is None:
                    raise _fail(
                        f"[[damper]] {j}: ",
                        "give clearance (each side) or lower_clearance and upper_clearance",
                    )
                d[side] = both
            elif both is not None:
                raise _fail(f"[[damper]] {j}: ", f"give clearance or {side}, not both")
            elif not d[side] >= 0:
                raise _fail(
                    f"[[damper]] {j}: ",
                    f"{side} must be >= 0 m, or inf for no wall on that side, got {d[side]}",
                )
        if d["friction"] is not None:
            _check_friction(f"[[damper]] {j}: ", d, ("friction", "static_friction", "normal_force"))
        else:
            for key in ("static_friction", "normal_force"):
                if d[key] is not None:
                    raise _fail(
                        f"[[damper]] {j}: ", f"{key} needs friction (the kinetic coefficient)"
                    )
                del d[key]
            del d["friction"]
        rubs = bool(d.get("normal_force")) and bool(d.get("friction") or d.get("static_friction"))
        held = any(j in c["dampers"] for c in collisions) or rubs
        if d["lower_clearance"] == d["upper_clearance"] == math.inf and not held:
            raise _fail(
                f"[[damper]] {j}: ",
                "lower_clearance and upper_clearance are both inf (no wall) and neither a "
                "[[collision]] nor friction holds it: give one side a finite clearance",
            )
        del d["clearance"]
        _check_point(f"damper {j} at", table["at"], d["at"], spec["structure"])
        _check_law(f"[[damper]] {j}: ", d, table)
        dampers.append(d)
    spec["damper"] = dampers
    stops = []
    for j, table in enumerate(stop_tables):
        d = _table(f"[[stop]] {j}: ", table, _STOP)
        _choice(f"[[stop]] {j}: ", "side", d["side"], _SIDES)
        for key in ("at", "against"):
            if d[key] is not None:
                _check_point(f"stop {j} {key}", table[key], d[key], spec["structure"])
        _check_law(f"[[stop]] {j}: ", d, table)
        stops.append(d)
    spec["stop"] = stops
    spec["collision"] = collisions
    spec["friction"] = _frictions(friction_tables, spec["structure"])
    if gravity is None:
        spec["gravity"] = {"acceleration": 0.0}
    else:
        if isinstance(gravity, int | float) and not isinstance(gravity, bool):
            gravity = {"acceleration": gravity}
        spec["gravity"] = _table("[gravity] ", gravity, _GRAVITY)
        if not spec["gravity"]["acceleration"] >= 0:
            raise _fail("[gravity] acceleration: ", "must be >= 0 (m/s^2, along -x)")
    excitations = []
    for j, table in enumerate(_list("excitation", excitation)):
        where = f"[[excitation]] {j}: "
        signal = table.get("signal") if isinstance(table, Mapping) else None
        if isinstance(signal, str) and signal in _SIGNAL_KEYS:
            # An unknown key: the keys of this signal, not of every signal.
            own = ["kind", "at", "signal", *sorted(_SIGNAL_KEYS[signal])]
            for key in table:
                if key not in _EXCITATION:
                    raise _unknown_key(where, key, own, f"signal {signal!r} takes")
        e = _table(where, table, _EXCITATION)
        _choice(where, "kind", e["kind"], _LOADS)
        _choice(where, "signal", e["signal"], _SIGNALS)
        if e["sweep"] is not None:
            _choice(where, "sweep", e["sweep"], _SWEEPS)
        if e["kind"] == "force" and e["at"] is None:
            raise _fail(where, 'kind "force" needs the point it acts at: at')
        if e["kind"] == "base" and e["at"] is not None:
            raise _fail(where, 'at applies to kind "force" only: a base motion moves every point')
        if e["at"] is not None:
            _check_point(f"excitation {j} at", table["at"], e["at"], spec["structure"])
        extra = sorted(set(table) - {"kind", "at", "signal"} - _SIGNAL_KEYS[e["signal"]])
        if extra:
            allowed = ", ".join(sorted(_SIGNAL_KEYS[e["signal"]]))
            raise _fail(
                where,
                f"{', '.join(extra)} not used by signal {e['signal']!r} (it takes {allowed})",
            )
        if e["signal"] == "harmonics":
            _check_harmonics(where, e)
        if e["file"] is not None:
            if e["time"] is not None or e["value"] is not None:
                raise _fail(where, "give file or time and value, not both")
            if not e["file"].strip():
                raise _fail(
                    where, "file: must name a CSV file of time and value, got an empty string"
                )
            path = Path(e["file"])
            if base_dir is not None and not path.is_absolute():
                path = base_dir / path
            times, values, row = read_record(path, f"{where}file: ")
            check_record(f"{where}file: ", times, values, row, e["scale"])
            e["time"], e["value"] = times, values
        elif e["signal"] == "recorded" and e["time"] is not None and e["value"] is not None:
            check_record(
                where,
                e["time"],
                e["value"],
                lambda i: f"time[{i}]",
                e["scale"],
                lambda i: f"value[{i}]",
            )
        elif e["signal"] == "recorded":
            raise _fail(
                where,
                "a recorded signal needs file (a CSV of time and value), or time and value "
                "(arrays of numbers)",
            )
        excitations.append({k: v for k, v in e.items() if v is not None and k != "file"})
    spec["excitation"] = excitations
    return spec


def _check_harmonics(where: str, e: dict[str, Any]) -> None:
    """A sum of harmonics: as many frequencies as amplitudes, and as many phases when
    they are given (left out, each is 0)."""
    amplitudes, frequencies, phases = e["amplitudes"], e["frequencies"], e["phases"]
    if amplitudes is None or frequencies is None:
        return  # the core names the key that is missing
    if len(frequencies) != len(amplitudes):
        raise _fail(
            where,
            f"amplitudes and frequencies must have the same length, got {len(amplitudes)} "
            f"and {len(frequencies)}",
        )
    if phases is not None and len(phases) != len(amplitudes):
        raise _fail(
            where,
            f"phases must have one entry per amplitude ({len(amplitudes)}), got "
            f"{len(phases)}; or leave phases out (each 0)",
        )
