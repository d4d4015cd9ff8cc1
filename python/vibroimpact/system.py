"""vibroimpact 0.2 systems: any structure, several dampers and stops, excitations, rigid impacts.

A system is described by the same sections as a TOML scenario (SI units):

- ``structure``: ``kind = "oscillator"`` (``mass``, ``stiffness``, ``damping``),
  ``"matrices"`` (``mass``, ``stiffness``, ``damping`` as n x n arrays of rows; M
  symmetric positive definite, K and C symmetric positive semi-definite) or
  ``"cantilever"`` (``length``, ``youngs_modulus``, ``second_moment``,
  ``mass_per_length``, ``modes``, ``damping_ratio``; modal coordinates).
- ``damper`` (a list): a loose mass (``mass``, kg) rattling against the point ``at``
  (a coordinate index, or m along a cantilever) with ``clearance`` on each side or
  ``lower_clearance`` and ``upper_clearance`` (m), and a ``law``.
- ``stop`` (a list): the point ``at`` hits a stop fixed to the base; ``side = "upper"``
  keeps it at or below ``+gap``, ``"lower"`` at or above ``-gap`` (m); a ``law``. With
  ``against`` (a second point) the stop is carried by that point instead, so that the
  two pound on each other: ``"upper"`` keeps ``x_at - x_against <= gap``.
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
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from vibroimpact._core import (
    DEFAULT_ENERGY_TOLERANCE,
    DEFAULT_MAX_ROWS,
    MAX_ENERGY_TOLERANCE,
    MAX_PAIRS,
    MAX_POINTS,
    MAX_SIGNAL_SAMPLES,
    METHOD_OPTIONS,
    METHODS,
    Contact,
    InvalidInputError,
    cantilever_mode_shape,
)
from vibroimpact._core import _check_options as check_options
from vibroimpact._core import _check_run as check_run
from vibroimpact._core import linear_parts as _linear_parts
from vibroimpact._core import simulate_system as _simulate_system
from vibroimpact.arguments import directory, shown_range, whole_range
from vibroimpact.messages import short_numbers, shown
from vibroimpact.record_file import check_record, read_record
from vibroimpact.summary import contacts_frame, contacts_repr, history_dataset, solution_repr

__all__ = [
    "PreparedRun",
    "SystemContacts",
    "SystemSolution",
    "prepare_system",
    "simulate_system",
    "SYSTEM_SOLVER_DEFAULTS",
]

_NUMBER, _TEXT, _WHOLE, _NUMBERS, _MATRIX = "number", "string", "whole number", "array", "matrix"
_REQ = object()

# The keys of each section: (type, default; _REQ where required, None where optional).
_STRUCTURE: dict[str, dict[str, tuple[str, Any]]] = {
    "oscillator": {
        "mass": (_NUMBER, _REQ),
        "stiffness": (_NUMBER, _REQ),
        "damping": (_NUMBER, 0.0),
    },
    "matrices": {"mass": (_MATRIX, _REQ), "stiffness": (_MATRIX, _REQ), "damping": (_MATRIX, None)},
    "cantilever": {
        "length": (_NUMBER, _REQ),
        "youngs_modulus": (_NUMBER, _REQ),
        "second_moment": (_NUMBER, _REQ),
        "mass_per_length": (_NUMBER, _REQ),
        "modes": (_WHOLE, _REQ),
        "damping_ratio": (_NUMBER, 0.0),
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
    "lower_clearance": (_NUMBER, None),
    "upper_clearance": (_NUMBER, None),
    **_LAW,
}
_STOP = {
    "at": (_NUMBER, _REQ),
    "side": (_TEXT, _REQ),
    "gap": (_NUMBER, _REQ),
    "against": (_NUMBER, None),
    **_LAW,
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
#: The solver settings of a 0.2 run and their defaults: the method options' and
#: max_steps' are the core's registry's (``_core.METHOD_OPTIONS``).
SYSTEM_SOLVER_DEFAULTS: dict[str, Any] = {
    "method": "rk4",
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
    "stepping": "events",
    "contact_timing": "located",
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


def real(value: Any) -> int | float | None:
    """``value`` as a Python int or float when it is a real number: an int, a float, a
    NumPy integer or floating scalar, or a 0-d array of one; None for anything else,
    booleans (Python's or NumPy's) included."""
    if isinstance(value, np.ndarray) and value.ndim == 0 and value.dtype.kind in "iuf":
        value = value[()]
    if isinstance(value, bool | np.bool_):
        return None
    if isinstance(value, np.integer):
        return int(value)
    if isinstance(value, np.floating):
        return float(value)
    if isinstance(value, int | float):
        return value
    return None


def _value(where: str, kind: str, value: Any) -> Any:
    """``value`` checked as ``kind``: numbers finite, whole numbers in 64 bits. NumPy
    real scalars count as numbers; booleans never do."""
    # The common cases first, at once: a scenario's floats and whole numbers.
    if kind == _NUMBER and type(value) is float and math.isfinite(value):
        return value
    if kind == _WHOLE and type(value) is int and 2 <= value < 2**63:  # above every low
        return value
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
        if not isinstance(whole, int):
            # The key's own range, if any, is checked after (modes: [1, 200]).
            raise _fail(where, f"must be a whole number, got {shown(value)}")
        low, high = whole_range(where)
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
        return [_value(f"{where[:-2]}[{i}]: ", _NUMBER, v) for i, v in enumerate(value)]
    # _MATRIX: an array of rows.
    if isinstance(value, str | bytes) or not _is_array(value, 2):
        raise _fail(where, f"must be an array of rows (n x n), got {shown(value)}")
    return [_value(f"{where[:-2]}[{i}]: ", _NUMBERS, row) for i, row in enumerate(value)]


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


def _check_point(name: str, given: Any, at: float, structure: dict[str, Any]) -> None:
    """A point ``at`` on the structure: a coordinate index of an oscillator or of
    matrices, a position along a cantilever (m); ``name`` such as ``"damper 0 at"``,
    worded as the core words it. ``given`` is the value as written, quoted in the
    error short and exact (the core would write 1e300 as 301 digits)."""
    if structure["kind"] == "cantilever":
        length = structure["length"]
        if not (math.isfinite(length) and length > 0):
            # The beam's own error first, worded as the core's: a point cannot be
            # placed on a beam of no length ("in [0, -1.0] m", user trial).
            raise _fail("", f"structure.length must be a finite number > 0, got {shown(length)}")
        if not 0.0 <= at <= length:
            raise _fail(
                "",
                f"{name} must be a position along the beam in [0, {length!r}] m, got "
                f"{shown(given)}",
            )
        return
    size = structure_coordinates(structure)
    if size and not (at.is_integer() and 0 <= at < size):
        raise _fail(
            "",
            f"{name} must be a coordinate index, a whole number in [0, {size - 1}], got "
            f"{shown(given)}",
        )


def point_weights(structure: Mapping[str, Any], at: Any, name: str = "at") -> np.ndarray:
    """The weights of a checked ``[structure]``'s coordinates at a point: the
    displacement there is ``weights @ coordinates``. For a cantilever ``at`` is a
    position along the beam (m from the clamp) and the weights are the mode shapes
    there; otherwise ``at`` is a coordinate index and the weights pick it. ``name``
    names ``at`` in the error."""
    value = real(at)
    if value is None:
        raise _fail("", f"{name} must be a number, got {shown(at)}")
    _check_point(name, at, float(value), dict(structure))
    n = structure_coordinates(structure)
    if structure["kind"] == "cantilever":
        length = float(structure["length"])
        return np.array([cantilever_mode_shape(length, i + 1, float(value)) for i in range(n)])
    weights = np.zeros(n)
    weights[int(value)] = 1.0
    return weights


def moment_weights(structure: Mapping[str, Any], at: Any, name: str = "at") -> np.ndarray:
    """The weights of a checked cantilever's modal coordinates in its bending moment at
    ``at`` m from the clamp (N m per unit coordinate): ``E I phi_i''(at)``."""
    value = real(at)
    if value is None:
        raise _fail("", f"{name} must be a number, got {shown(at)}")
    _check_bends(name, structure)
    _check_point(name, at, float(value), dict(structure))
    length, stiffness = (
        float(structure["length"]),
        structure["youngs_modulus"] * structure["second_moment"],
    )
    n = structure_coordinates(structure)
    return np.array(
        [stiffness * cantilever_mode_shape(length, i + 1, float(value), 2) for i in range(n)]
    )


def _check_bends(name: str, structure: Mapping[str, Any]) -> None:
    """Only a cantilever has bending moments (``name`` asks for them)."""
    if structure["kind"] != "cantilever":
        raise _fail(
            "", f'{name}: only a cantilever has bending moments (structure.kind = "cantilever")'
        )


def split_observed(
    values: np.ndarray, n: int, points: int
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """What the core reduces over its observed quantities (along the last axis), split:
    the ``n`` structure coordinates, then the ``points`` points, then the moments."""
    return values[..., :n], values[..., n : n + points], values[..., n + points :]


def structure_coordinates(structure: Mapping[str, Any]) -> int:
    """The coordinates of a checked ``[structure]``: 1 for an oscillator, one per DOF
    of matrices, one per mode of a cantilever."""
    kind = structure["kind"]
    if kind == "oscillator":
        return 1
    if kind == "cantilever":
        return int(structure["modes"])
    return len(structure["mass"])


def system_spec(
    structure: Any,
    damper: Any = (),
    stop: Any = (),
    gravity: Any = None,
    excitation: Any = (),
    base_dir: Path | None = None,
) -> dict[str, Any]:
    """The sections of a system, checked and with their defaults filled (see the module
    docstring); errors name the section and key."""
    if not isinstance(structure, Mapping):
        raise _fail("", f"[structure] must be a table, got {shown(structure)}")
    kind = structure.get("kind")
    _choice("[structure] ", "kind", kind, tuple(_STRUCTURE))
    schema = {"kind": (_TEXT, _REQ), **_STRUCTURE[str(kind)]}
    spec: dict[str, Any] = {"structure": _table("[structure] ", structure, schema)}
    if kind == "cantilever" and not 1 <= spec["structure"]["modes"] <= 200:
        raise _fail(
            "[structure] modes: ",
            f"must be a whole number in [1, 200], got {spec['structure']['modes']}",
        )
    if kind == "matrices" and spec["structure"]["damping"] is None:
        size = len(spec["structure"]["mass"])
        spec["structure"]["damping"] = [[0.0] * size for _ in range(size)]
    damper_tables, stop_tables = _list("damper", damper), _list("stop", stop)
    if len(damper_tables) + len(stop_tables) > MAX_PAIRS:
        # Before any is read: simultaneous impacts solve over every pair, a matrix
        # that grows as their square (70,000 stops aborted asking for 39 GB).
        raise _fail(
            "[[damper]], [[stop]]: ",
            f"at most {MAX_PAIRS} pairs in all, got {len(damper_tables) + len(stop_tables)}",
        )
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


@dataclass(frozen=True)
class SystemContacts:
    """The contacts of a 0.2 run, one entry per contact, as NumPy arrays (SI units).

    ``pair`` names the pair ("damper 0", "stop 1"); ``kind`` is "compliant",
    "impact" (a rigid impact: zero duration) or "sticking" (a rigid pair moving
    together from the accumulation instant of its chattering sequence to its
    release). ``energy_dissipated`` is the work of the contact's dissipative
    forces, or the kinetic energy an impact takes (J). ``energy_change`` is the net
    change of the system's stored mechanical energy over the contact (J, at separation
    minus at onset): ``-energy_dissipated`` where no other damper or force acts, to the
    method's accuracy; an impact's is the kinetic energy it takes, negated. A contact
    still open at the end has NaN ``separation``, ``duration``, ``rebound_speed``,
    ``restitution`` and ``energy_change`` (a sticking pair's is NaN too); a
    contact that started at rest (its approach, m/s, at round-off: a body set down on a
    stop, an elastic contact ringing about its static indentation) was never an impact and
    has NaN ``restitution``. A damped Hertz law (``"hyster-hertz"``, ``"hertz-damped"``)
    takes its damping from the approach speed, but never from one slower than
    ``sqrt(2 a delta_s)``, the speed the pressing ``a`` (m/s^2) gives over the static
    indentation ``delta_s = (m a / K)^(2/3)`` (m): a body set down on it settles there.
    """

    pair: list[str]
    kind: list[str]
    onset: np.ndarray
    separation: np.ndarray
    duration: np.ndarray
    max_indentation: np.ndarray
    approach_speed: np.ndarray
    rebound_speed: np.ndarray
    restitution: np.ndarray
    energy_dissipated: np.ndarray
    energy_change: np.ndarray

    columns = (
        "pair",
        "kind",
        "onset",
        "separation",
        "duration",
        "max_indentation",
        "approach_speed",
        "rebound_speed",
        "restitution",
        "energy_dissipated",
        "energy_change",
    )

    def __len__(self) -> int:
        return len(self.pair)

    def __repr__(self) -> str:
        return contacts_repr(self)

    def to_pandas(self) -> Any:
        """The table as a ``pandas.DataFrame``, one row per contact (pandas needed)."""
        return contacts_frame(self)

    def to_dicts(self) -> list[dict[str, Any]]:
        """One dict per contact, keyed by the column names."""
        return [
            {name: _plain(getattr(self, name)[i]) for name in self.columns}
            for i in range(len(self))
        ]


def _plain(x: Any) -> Any:
    return x if isinstance(x, str) else float(x)


@dataclass(frozen=True)
class SystemSolution:
    """What :func:`simulate_system` returns.

    History arrays have one row per kept step: ``structure_displacement`` (m, rows
    x n), ``structure_velocity``, ``damper_displacement`` (rows x k),
    ``damper_velocity``; all relative to the base. ``energy`` (J): ``input_work``,
    ``dissipated`` (``viscous`` + ``contact`` + ``impact``), ``stored_start``,
    ``stored_end`` and ``residual`` = stored_end - stored_start - input_work +
    dissipated (numerical error; checked against ``energy_tolerance``).
    """

    t: np.ndarray
    structure_displacement: np.ndarray
    structure_velocity: np.ndarray
    damper_displacement: np.ndarray
    damper_velocity: np.ndarray
    contacts: SystemContacts
    final_state: dict[str, np.ndarray]
    final_time: float
    energy: dict[str, float]
    steps: int
    rejected_steps: int
    rhs_evaluations: int
    grazing_contacts: int
    method: str
    pairs: list[str] = field(default_factory=list)
    #: Per structure coordinate, from ``record_from`` on: the largest |displacement|
    #: (m, located where the velocity changes sign or at an impact) and the RMS (m);
    #: NaN where nothing was recorded (no ``record_from``).
    peak: np.ndarray = field(default_factory=lambda: np.zeros(0))
    rms: np.ndarray = field(default_factory=lambda: np.zeros(0))
    recorded_time: float = 0.0
    #: The state at each multiple of ``strobe_period`` (rows of the four arrays of
    #: ``[initial]``, concatenated as the history's columns) and its times (s).
    strobe: np.ndarray = field(default_factory=lambda: np.zeros((0, 0)))
    strobe_time: np.ndarray = field(default_factory=lambda: np.zeros(0))
    #: The checked ``[structure]`` the run integrated.
    structure: dict[str, Any] = field(default_factory=dict)
    #: The points ``[output] points`` follows (as a damper's ``at``: m from a
    #: cantilever's clamp, or a coordinate index), and from ``record_from`` on the
    #: largest |displacement| (m, located) and the RMS (m) of the structure at each;
    #: NaN where nothing was recorded.
    points: np.ndarray = field(default_factory=lambda: np.zeros(0))
    point_peak: np.ndarray = field(default_factory=lambda: np.zeros(0))
    point_rms: np.ndarray = field(default_factory=lambda: np.zeros(0))
    #: The positions along a cantilever (m from the clamp) ``[output] moments``
    #: follows, and from ``record_from`` on the largest |bending moment| (N m) and its
    #: RMS (N m) at each.
    moments: np.ndarray = field(default_factory=lambda: np.zeros(0))
    moment_peak: np.ndarray = field(default_factory=lambda: np.zeros(0))
    moment_rms: np.ndarray = field(default_factory=lambda: np.zeros(0))
    #: At each kept time, the force of each pair with a compliant law (N, > 0 pushing
    #: it apart, 0 apart: the law's and its contact damper's), rows x pairs; the
    #: pairs' names in ``contact_force_pairs``.
    contact_force: np.ndarray = field(default_factory=lambda: np.zeros((0, 0)))
    contact_force_pairs: list[str] = field(default_factory=list)

    def shape_at(self, at: float) -> np.ndarray:
        """The structure coordinates' weights at a point: the displacement there is
        ``structure_displacement @ shape_at(at)``. For a cantilever ``at`` is a position
        along the beam (m from the clamp) and the weights are the mode shapes there
        (``cantilever_mode_shape(length, i + 1, at)``); otherwise ``at`` is a coordinate
        index and the weights pick it."""
        if not self.structure:
            raise InvalidInputError("at: this solution does not hold its structure")
        return point_weights(self.structure, at)

    def displacement_at(self, at: float) -> np.ndarray:
        """The structure's displacement (m, relative to the base) at a point (see
        :meth:`shape_at`: a cantilever's deflection at ``at`` m from the clamp), at each
        kept time ``t``."""
        return np.asarray(self.structure_displacement @ self.shape_at(at), dtype=float)

    def moment_at(self, at: float) -> np.ndarray:
        """A cantilever's bending moment (N m) ``E I w''`` at ``at`` m from the clamp,
        at each kept time ``t``."""
        if not self.structure:
            raise InvalidInputError("at: this solution does not hold its structure")
        return np.asarray(
            self.structure_displacement @ moment_weights(self.structure, at), dtype=float
        )

    def velocity_at(self, at: float) -> np.ndarray:
        """The structure's velocity (m/s, relative to the base) at a point (see
        :meth:`shape_at`), at each kept time ``t``."""
        return np.asarray(self.structure_velocity @ self.shape_at(at), dtype=float)

    def __repr__(self) -> str:
        return solution_repr(self)

    def to_xarray(self) -> Any:
        """The history as an ``xarray.Dataset`` over ``time`` (s), with named
        coordinates and units, the statistics and energy as attributes (contacts:
        ``contacts.to_pandas()``)."""
        return history_dataset(self)


def simulate_system(
    structure: Mapping[str, Any],
    *,
    damper: Any = (),
    stop: Any = (),
    gravity: Any = None,
    excitation: Any = (),
    initial: Mapping[str, Any] | None = None,
    t_end: float,
    method: str = SYSTEM_SOLVER_DEFAULTS["method"],
    dt: float | None = None,
    rtol: float = SYSTEM_SOLVER_DEFAULTS["rtol"],
    atol: float = SYSTEM_SOLVER_DEFAULTS["atol"],
    beta: float = SYSTEM_SOLVER_DEFAULTS["beta"],
    gamma: float = SYSTEM_SOLVER_DEFAULTS["gamma"],
    spectral_radius: float = SYSTEM_SOLVER_DEFAULTS["spectral_radius"],
    every: int = 1,
    history: bool = True,
    max_steps: int = SYSTEM_SOLVER_DEFAULTS["max_steps"],
    energy_tolerance: float = SYSTEM_SOLVER_DEFAULTS["energy_tolerance"],
    max_rows: int = SYSTEM_SOLVER_DEFAULTS["max_rows"],
    base_dir: Path | None = None,
    record_from: float | None = None,
    strobe_period: float | None = None,
    points: Any = (),
    moments: Any = (),
    stepping: str = SYSTEM_SOLVER_DEFAULTS["stepping"],
    contact_timing: str = SYSTEM_SOLVER_DEFAULTS["contact_timing"],
) -> SystemSolution:
    """Integrate a 0.2 system from ``initial`` to ``t_end`` (s).

    The sections are those of a TOML scenario (see the module docstring), as dicts
    (``damper``, ``stop`` and ``excitation`` as lists of dicts). ``initial`` holds
    ``structure_displacement``, ``structure_velocity``, ``damper_displacement``,
    ``damper_velocity`` (arrays, SI; zeros where left out). ``method``: ``"rk4"``
    (fixed step ``dt``), ``"dopri5"`` or ``"dop853"`` (``rtol``, ``atol``),
    ``"newmark-implicit"`` (``beta``, ``gamma``) or ``"generalized-alpha"``
    (``spectral_radius``), implicit with Newton's method, fixed step ``dt``; or
    ``"exact"``: the closed-form flow of a linear structure with rigid or linear pairs and
    harmonic (or no) excitation, exact to round-off between impacts (``dt``, if
    given, caps its step of an eighth of the fastest period). Every
    event (contact onset, separation, rigid impact, release) is located to
    round-off. ``every`` keeps every N-th step; ``history=False`` keeps none (the
    contacts and the final state only). A run stops with a clear error past
    ``max_steps`` steps, past ``max_rows`` history rows and contacts, or when its
    energy balance is off by more than ``energy_tolerance`` (in (0, 1]) of the energies in play.
    From ``record_from`` (s) on, each structure coordinate's located peak and RMS
    are kept (``peak``, ``rms``), and the structure's at each of ``points`` (as a
    damper's ``at``: m from a cantilever's clamp, or a coordinate index; ``point_peak``,
    ``point_rms``), and a cantilever's bending moment at each of ``moments`` (m from the
    clamp; ``moment_peak``, ``moment_rms``, N m); every ``strobe_period`` (s) the state is kept
    (``strobe``; fixed steps are shortened to divide it). ``stepping="fixed"`` takes
    steps of ``dt`` not cut at contacts (fixed-step methods and compliant laws only), each
    contact's onset and separation located inside its step by interpolation
    (``contact_timing="located"``) or counted in whole steps (``"step-count"``, as the
    founding paper counted them). The GIL is released while integrating; Ctrl-C
    interrupts.
    """
    run = prepare_system(
        structure,
        damper=damper,
        stop=stop,
        gravity=gravity,
        excitation=excitation,
        initial=initial,
        solver={
            "method": method,
            "t_end": t_end,
            "rtol": rtol,
            "atol": atol,
            "max_steps": max_steps,
            "energy_tolerance": energy_tolerance,
            "max_rows": max_rows,
            "beta": beta,
            "gamma": gamma,
            "spectral_radius": spectral_radius,
            "stepping": stepping,
            "contact_timing": contact_timing,
            **({} if dt is None else {"dt": dt}),
        },
        output={
            "every": every,
            "history": history,
            **({} if record_from is None else {"record_from": record_from}),
            **({} if strobe_period is None else {"strobe_period": strobe_period}),
            "points": points,
            "moments": moments,
        },
        base_dir=base_dir,
    )
    return run.run()


@dataclass(frozen=True)
class PreparedRun:
    """A checked 0.2 run, ready to integrate (see :func:`prepare_system`)."""

    spec: dict[str, Any]
    initial: dict[str, list[float]]
    solver: dict[str, Any]
    output: dict[str, Any]

    def binding_spec(self) -> dict[str, Any]:
        """The sections as the binding takes them (gravity as a number, the points
        ``[output]`` follows)."""
        return {
            **self.spec,
            "gravity": self.spec["gravity"]["acceleration"],
            "points": list(self.output["points"]),
            "moments": list(self.output["moments"]),
        }

    def method_arguments(self) -> dict[str, Any]:
        """The solver settings as the binding's keyword arguments."""
        return {
            key: self.solver[key]
            for key in (
                "method",
                "t_end",
                "dt",
                "rtol",
                "atol",
                "beta",
                "gamma",
                "spectral_radius",
                "max_steps",
                "max_rows",
                "energy_tolerance",
                "stepping",
                "contact_timing",
            )
        }

    def run(self) -> SystemSolution:
        """Integrate it."""
        init, solver, output = self.initial, self.solver, self.output
        try:
            raw = _simulate_system(
                self.binding_spec(),
                [init[k] for k in _INITIAL],
                **self.method_arguments(),
                every=output["every"],
                history=output["history"],
                record_from=output["record_from"],
                strobe_period=output["strobe_period"],
            )
        except InvalidInputError as err:
            # The core writes its numbers in full: 1e300 as 301 digits.
            raise type(err)(short_numbers(str(err))) from None
        return _solution(
            raw, solver["method"], self.spec["structure"], output["points"], output["moments"]
        )


def prepare_system(
    structure: Any,
    *,
    damper: Any = (),
    stop: Any = (),
    gravity: Any = None,
    excitation: Any = (),
    initial: Any = None,
    solver: Mapping[str, Any],
    output: Mapping[str, Any] | None = None,
    base_dir: Path | None = None,
) -> PreparedRun:
    """Check every section of a 0.2 run (the sections of a TOML scenario, as dicts)
    and fill their defaults; errors name the section and key."""
    base_dir = directory("base_dir", base_dir)
    try:
        spec = system_spec(structure, damper, stop, gravity, excitation, base_dir)
    except RecursionError:
        # Arrays nested thousands deep: no structure has them.
        raise _fail("", "a value is nested too deeply (arrays within arrays)") from None
    # "is None", not "or": an array given for a table has no truth value.
    init = _table("[initial] ", {} if initial is None else initial, _INITIAL)
    solver = _table("[solver] ", solver, _SOLVER)
    output = _table("[output] ", {} if output is None else output, _OUTPUT)
    _choice("[solver] ", "method", solver["method"], _METHODS)
    _choice("[solver] ", "stepping", solver["stepping"], ("events", "fixed"))
    _choice("[solver] ", "contact_timing", solver["contact_timing"], ("located", "step-count"))
    if solver["stepping"] == "events" and solver["contact_timing"] != "located":
        raise _fail(
            "[solver] contact_timing: ",
            '"step-count" needs stepping = "fixed" (with events the instants are located)',
        )
    if solver["stepping"] == "fixed" and solver["method"] not in _FIXED_STEP:
        raise _fail(
            "[solver] stepping: ",
            f'"fixed" takes a fixed-step method ({", ".join(_FIXED_STEP)}), '
            f"not {solver['method']!r}",
        )
    for key in ("t_end", "energy_tolerance"):
        if not solver[key] > 0:
            raise _fail(f"[solver] {key}: ", f"must be > 0, got {solver[key]}")
    if not solver["energy_tolerance"] <= MAX_ENERGY_TOLERANCE:
        # The core's bound: beyond it the residual may exceed all the energy in play.
        raise _fail(
            "[solver] energy_tolerance: ",
            f"must be in (0, {MAX_ENERGY_TOLERANCE:g}], got {solver['energy_tolerance']}",
        )
    _check_method_options(solver)
    if solver["dt"] is not None and not solver["dt"] > 0:
        raise _fail("[solver] dt: ", f"must be > 0, got {solver['dt']}")
    for section, key in (("output", "every"), ("solver", "max_steps"), ("solver", "max_rows")):
        value = (output if section == "output" else solver)[key]
        if value < 1:
            raise _fail(f"[{section}] {key}: ", f"must be >= 1, got {value}")
    if output["strobe_period"] is not None and not output["strobe_period"] > 0:
        raise _fail("[output] strobe_period: ", f"must be > 0 s, got {output['strobe_period']}")
    # The up-front limits (steps, the fastest mode and forcing against the step, rows,
    # memory) are the core's (its registry's check_run), with their messages.
    try:
        check_run(
            spec,
            **{key: solver[key] for key in ("method", "dt", "t_end", "max_steps", "max_rows")},
            every=output["every"],
            history=output["history"],
            strobe_period=output["strobe_period"],
        )
    except InvalidInputError as err:
        raise _fail("", short_numbers(str(err))) from None
    if output["record_from"] is not None and not output["record_from"] >= 0:
        raise _fail("[output] record_from: ", f"must be >= 0 s, got {output['record_from']}")
    if output["record_from"] is not None and not output["record_from"] < solver["t_end"]:
        raise _fail(
            "[output] record_from: ",
            f"must be before [solver] t_end ({solver['t_end']!r} s), got {output['record_from']!r}",
        )
    followed = len(output["points"]) + len(output["moments"])
    if followed > MAX_POINTS:
        raise _fail(
            "[output] points, moments: ",
            f"{followed} in all; at most {MAX_POINTS} are allowed (together)",
        )
    if output["moments"]:
        _check_bends("[output] moments", spec["structure"])
    for key in ("points", "moments"):
        for j, at in enumerate(output[key]):
            _check_point(f"[output] {key}[{j}]", at, float(at), spec["structure"])
            if at in output[key][:j]:
                raise _fail(f"[output] {key}: ", f"{shown(at)} is given twice")
    if followed and output["record_from"] is None:
        # Points ask for their peaks: of the whole run where no window is given
        # (user trial: they were silently left out).
        output["record_from"] = 0.0
    return PreparedRun(spec, init, solver, output)


def _solution(
    raw: dict[str, Any],
    method: str,
    structure: Mapping[str, Any],
    points: Sequence[float] = (),
    moments: Sequence[float] = (),
) -> SystemSolution:
    n, k = raw["n"], raw["k"]
    recorded = raw["recorded_time"] > 0
    width = 2 * (n + k)
    states = raw["states"].reshape(-1, width)
    final = raw["final_state"]
    c = raw["contacts"]
    pairs = list(raw["pairs"])
    observed = n + len(points) + len(moments)
    peaks = raw["peaks"] if recorded else np.full(observed, np.nan)
    peak, point_peak, moment_peak = split_observed(peaks, n, len(points))
    rms, point_rms, moment_rms = split_observed(
        np.sqrt(raw["square_integrals"] / raw["recorded_time"])
        if recorded
        else np.full(observed, np.nan),
        n,
        len(points),
    )
    contacts = SystemContacts(
        pair=[pairs[p] for p in c["pair"]],
        kind=list(c["kind"]),
        **{name: c[name] for name in SystemContacts.columns[2:]},
    )
    return SystemSolution(
        t=raw["time"],
        structure_displacement=states[:, :n],
        damper_displacement=states[:, n : n + k],
        structure_velocity=states[:, n + k : 2 * n + k],
        damper_velocity=states[:, 2 * n + k :],
        contacts=contacts,
        final_state={
            "structure_displacement": final[:n],
            "structure_velocity": final[n + k : 2 * n + k],
            "damper_displacement": final[n : n + k],
            "damper_velocity": final[2 * n + k :],
        },
        final_time=raw["final_time"],
        energy=dict(raw["energy"]),
        steps=raw["steps"],
        rejected_steps=raw["rejected_steps"],
        rhs_evaluations=raw["rhs_evaluations"],
        grazing_contacts=raw["grazing_contacts"],
        method=method,
        pairs=pairs,
        # Nothing recorded (no record_from): neither peak nor RMS, not a peak of 0.
        peak=peak,
        rms=rms,
        points=np.asarray(points, dtype=float),
        point_peak=point_peak,
        point_rms=point_rms,
        moments=np.asarray(moments, dtype=float),
        moment_peak=moment_peak,
        moment_rms=moment_rms,
        recorded_time=raw["recorded_time"],
        strobe=raw["strobe"].reshape(-1, width),
        strobe_time=raw["strobe_time"],
        structure=dict(structure),
        contact_force=raw["contact_forces"].reshape(
            len(raw["time"]), len(raw["contact_force_pairs"])
        ),
        contact_force_pairs=[pairs[p] for p in raw["contact_force_pairs"]],
    )


def _check_method_options(solver: Mapping[str, Any]) -> None:
    """The method options in the core registry's ranges (every one, whatever the
    method: the core checks them), its message naming ``[solver] key``."""
    try:
        check_options(**{key: solver[key] for key in METHOD_OPTIONS if key != "max_steps"})
    except InvalidInputError as err:
        # The core names the option; the value is written as given.
        key = str(err).partition(" must be ")[0]
        if key not in METHOD_OPTIONS:
            raise _fail("[solver] ", short_numbers(str(err))) from None
        allowed = METHOD_OPTIONS[key]["allowed"]
        raise _fail(f"[solver] {key}: ", f"must be {allowed}, got {solver[key]}") from None


def linear_parts(
    structure: Mapping[str, Any],
    *,
    damper: Any = (),
    stop: Any = (),
    gravity: Any = None,
    excitation: Any = (),
    base_dir: Path | None = None,
) -> dict[str, Any]:
    """The system between contacts as a linear one over all its coordinates
    (structure, then dampers; sections as for :func:`simulate_system`):
    ``M x'' + C x' + K x = constant + sum of harmonic loads``. Returns ``mass``,
    ``stiffness``, ``damping`` (``dim x dim`` arrays, SI), ``constant`` (gravity's
    weight, N) and ``harmonics``: each ``amplitude``, ``omega`` (rad/s), ``phase`` and
    ``shape`` (the load is ``amplitude cos(omega t + phase) shape``, N). Signals
    other than harmonics are refused."""
    base_dir = directory("base_dir", base_dir)
    spec = system_spec(structure, damper, stop, gravity, excitation, base_dir)
    raw = _linear_parts({**spec, "gravity": spec["gravity"]["acceleration"]})
    dim = raw["n"] + raw["k"]
    return {
        "n": raw["n"],
        "k": raw["k"],
        "mass": np.asarray(raw["mass"]).reshape(dim, dim),
        "stiffness": np.asarray(raw["stiffness"]).reshape(dim, dim),
        "damping": np.asarray(raw["damping"]).reshape(dim, dim),
        "constant": np.asarray(raw["constant"]),
        "harmonics": [dict(h) for h in raw["harmonics"]],
    }
