"""The arguments of the public functions checked for their type, each refused with an
:class:`~vibroimpact.InvalidInputError` (a ValueError) naming the argument and what it
takes: ``None`` for a number, a string for a list, a dict for an array, a 2-D array for
a list of values would otherwise fail deep inside as an AttributeError or a TypeError.
"""

from __future__ import annotations

import difflib
import functools
import inspect
import math
import os
import re
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any, TypeVar

import numpy as np

from vibroimpact._core import InvalidInputError
from vibroimpact.messages import shown

_F = TypeVar("_F", bound=Callable[..., Any])

#: The largest whole number a scenario may hold (64-bit signed).
LARGEST_WHOLE = 2**63 - 1
#: The range of each whole-number key of a scenario, by the key's name (or its section
#: and name, ``"[sweep] count"``, where sections differ), as its error
#: states it (a key not listed: [0, 2^63 - 1]); the modules that own keys with a bound
#: of their own add them (analyses: the forcing periods of a run).
WHOLE_RANGES: dict[str, tuple[int, int]] = {
    "modes": (1, 200),  # a cantilever's: the core's most
    "every": (1, LARGEST_WHOLE),
    "max_steps": (1, LARGEST_WHOLE),
    "max_rows": (1, LARGEST_WHOLE),
}


def whole_range(where: str) -> tuple[int, int]:
    """The range of the whole-number key that ``where`` (``"[structure] modes: "``)
    names: its entry in :data:`WHOLE_RANGES`, else [0, 2^63 - 1]."""
    place = where.rstrip(": ")
    if place in WHOLE_RANGES:  # a key of one section ("[sweep] count")
        return WHOLE_RANGES[place]
    return WHOLE_RANGES.get(place.rsplit(" ", 1)[-1], (0, LARGEST_WHOLE))


def integer_hint(value: Any) -> str:
    """For a whole number written as a float (61.0, as JSON, MATLAB or pandas write it),
    how to write it: TOML and Python tell an integer from a float by its decimal point."""
    # (Not past the largest whole number a key takes: 1e30 would be told to be written
    # as an integer no key takes.)
    if isinstance(value, float) and value.is_integer() and abs(value) <= LARGEST_WHOLE:
        return f" written as an integer ({int(value)}, not {value})"
    return ""


def shown_range(low: int, high: int) -> str:
    """``[low, high]`` as a message writes it (2^63 - 1 by name)."""
    return f"[{low}, {'2^63 - 1' if high == LARGEST_WHOLE else high}]"


def real(value: Any) -> int | float | None:
    """``value`` as a Python int or float when it is a real number: an int, a float, a
    NumPy integer or floating scalar, or a 0-d array of one; None for anything else,
    booleans (Python's or NumPy's) included."""
    if isinstance(value, np.ndarray) and value.ndim == 0 and value.dtype.kind in "iuf":
        value = value[()]
    # NumPy's times are integers to it (int() of one fails): no number of seconds.
    if isinstance(value, bool | np.bool_ | np.timedelta64 | np.datetime64):
        return None
    if isinstance(value, np.integer):
        return int(value)
    if isinstance(value, np.floating):
        return float(value)
    if isinstance(value, int | float):
        return value
    return None


def _real(value: Any) -> float | None:
    """:func:`real` as a float (an int beyond a float's range as an infinity)."""
    exact = real(value)
    if exact is None:
        return None
    try:
        return float(exact)
    except OverflowError:
        return math.copysign(math.inf, exact)


def sections(name: str, value: Any) -> Mapping[str, Any]:
    """A scenario's sections: a mapping of section names to tables (as ``tomllib``
    parses a scenario)."""
    if not isinstance(value, Mapping):
        raise InvalidInputError(
            f"{name}: must be a scenario's sections (a dict of tables, as tomllib parses "
            f"a scenario), got {shown(value)}"
        )
    return value


def text(name: str, value: Any) -> str:
    """A string."""
    if not isinstance(value, str):
        raise InvalidInputError(f"{name}: must be a string, got {shown(value)}")
    return value


def choice(name: str, value: Any, allowed: tuple[str, ...]) -> str:
    """One of the strings ``allowed``."""
    if not isinstance(value, str) or value not in allowed:
        listed = ", ".join(f'"{a}"' for a in allowed)
        raise InvalidInputError(f"{name}: must be one of {listed}, got {shown(value)}")
    return value


def number(name: str, value: Any) -> float:
    """A finite real number (an int, a float or a NumPy real; not a boolean)."""
    real = _real(value)
    if real is None:
        raise InvalidInputError(f"{name}: must be a number, got {shown(value)}")
    if not math.isfinite(real):
        raise InvalidInputError(f"{name}: must be a finite number, got {shown(real)}")
    return real


def flag(name: str, value: Any) -> bool:
    """True or False (a Python or NumPy boolean; not a string or a number)."""
    if not isinstance(value, bool | np.bool_):
        raise InvalidInputError(f"{name}: must be True or False, got {shown(value)}")
    return bool(value)


def positive(name: str, value: Any) -> float:
    """A finite number > 0."""
    real = number(name, value)
    if not real > 0:
        raise InvalidInputError(f"{name}: must be > 0, got {shown(real)}")
    return real


def numbers(name: str, value: Any) -> np.ndarray:
    """A one-dimensional array of finite numbers (a list, a tuple or a 1-D array)."""
    if (
        type(value) is np.ndarray
        and value.dtype == np.float64
        and value.ndim == 1
        and math.isfinite(value.sum())
    ):
        # The analyses' own states, checked once a run (a finite sum has no NaN or
        # infinity in it; an overflowing one goes the long way).
        return value
    if isinstance(value, str | bytes | Mapping) or not _sequence(value):
        raise InvalidInputError(
            f"{name}: must be a list or 1-D array of numbers, got {shown(value)}"
        )
    array = np.asarray(value, dtype=object) if not isinstance(value, np.ndarray) else value
    if array.ndim != 1:
        raise InvalidInputError(
            f"{name}: must be a list or 1-D array of numbers, got {array.ndim} dimensions "
            f"(shape {array.shape})"
        )
    if array.dtype.kind in "iuf":
        out = np.asarray(array, dtype=float)
    else:
        out = np.empty(len(array))
        for i, v in enumerate(array):
            out[i] = number(f"{name}[{i}]", v)
    finite = np.isfinite(out)
    if not finite.all():
        i = int(np.flatnonzero(~finite)[0])
        raise InvalidInputError(f"{name}[{i}]: must be a finite number, got {shown(out[i])}")
    return out


def _sequence(value: Any) -> bool:
    if isinstance(value, np.ndarray):
        return True
    try:
        len(value)
        iter(value)
    except TypeError:
        return False
    return True


def state(name: str, value: Any, size: int) -> np.ndarray | None:
    """A flat state (x, v) of ``size`` finite numbers, or None (the scenario's
    ``[initial]``)."""
    if value is None:
        return None
    out = numbers(name, value)
    if len(out) != size:
        raise InvalidInputError(
            f"{name}: must have {size} values (the displacements, then the velocities), "
            f"got {len(out)}"
        )
    return out


def callback(name: str, value: Any) -> Callable[..., Any] | None:
    """A function to call, or None."""
    if value is not None and not callable(value):
        raise InvalidInputError(f"{name}: must be a function or None, got {shown(value)}")
    return value  # type: ignore[no-any-return]


def directory(name: str, value: Any) -> Path | None:
    """A folder (a str or a path), or None."""
    if value is None:
        return None
    if not isinstance(value, str | os.PathLike):
        raise InvalidInputError(f"{name}: must be a folder (a str or a Path), got {shown(value)}")
    return Path(value)


def path(name: str, value: Any) -> Path:
    """A file's path (a str or a path)."""
    if not isinstance(value, str | os.PathLike):
        raise InvalidInputError(f"{name}: must be a path (a str or a Path), got {shown(value)}")
    return Path(value)


def instance(name: str, value: Any, kind: type, made_by: str) -> Any:
    """An instance of ``kind``, which ``made_by`` makes."""
    if not isinstance(value, kind):
        raise InvalidInputError(
            f"{name}: must be {_article(kind)} (from {made_by}), got {shown(value)}"
        )
    return value


class KeywordError(InvalidInputError, TypeError):
    """A call given a keyword it does not take, a positional value where only keywords
    go, or missing one it needs: a ``ValueError`` as every bad input is here, and the
    ``TypeError`` Python raises for it."""


def _unknown_keyword(keywords: Mapping[str, Any], signature: inspect.Signature) -> str:
    """Python's words for the first of ``keywords`` that ``signature`` does not take
    (none where it takes any), else an empty string."""
    parameters = signature.parameters.values()
    if any(p.kind is inspect.Parameter.VAR_KEYWORD for p in parameters):
        return ""
    unknown = [key for key in keywords if key not in signature.parameters]
    return f"got an unexpected keyword argument {unknown[0]!r}" if unknown else ""


def _closest_keyword(words: str, signature: inspect.Signature) -> str:
    """`` (did you mean 'periods'?)`` for Python's "unexpected keyword argument
    'period'" where ``signature`` has a keyword that close; else nothing."""
    unknown = re.search(r"unexpected keyword argument '(\w+)'", words)
    if unknown is None:
        return ""
    close = difflib.get_close_matches(unknown[1], list(signature.parameters), n=1)
    return f" (did you mean {close[0]!r}?)" if close else ""


def typed(**kinds: tuple[type, ...] | type) -> Callable[[_F], _F]:
    """A core function whose arguments of the wrong type (PyO3 raises a TypeError
    naming the argument only in a note) are refused naming it: on a TypeError the
    arguments are checked against ``kinds`` (name: the types allowed), and the first
    wrong one is an InvalidInputError; else the argument PyO3's note names. Valid
    calls cost nothing."""

    def wrap(function: _F) -> _F:
        signature = inspect.signature(function)

        @functools.wraps(function)
        def call(*args: Any, **kwargs: Any) -> Any:
            try:
                return function(*args, **kwargs)
            except TypeError as err:
                try:
                    bound = signature.bind(*args, **kwargs)
                except TypeError as wrong:
                    # A missing or unknown argument: Python's own words say which (an
                    # unknown keyword first: a misspelt one is also a missing one), and
                    # the closest keyword the function takes.
                    words = _unknown_keyword(kwargs, signature) or str(wrong)
                    hint = _closest_keyword(words, signature)
                    raise KeywordError(f"{function.__name__}() {words}{hint}") from None
                for key, allowed in kinds.items():
                    if key in bound.arguments and not isinstance(bound.arguments[key], allowed):
                        names = allowed if isinstance(allowed, tuple) else (allowed,)
                        wanted = " or ".join(_article(t) for t in names)
                        raise InvalidInputError(
                            f"{key} must be {wanted}, got {shown(bound.arguments[key])}"
                        ) from None
                # PyO3 names the argument it could not take in a note.
                for note in getattr(err, "__notes__", ()):
                    named = re.fullmatch(r"while processing '(\w+)'", note)
                    if named and named[1] in bound.arguments:
                        value = shown(bound.arguments[named[1]])
                        raise InvalidInputError(
                            f"{named[1]} has the wrong type ({err}), got {value}"
                        ) from None
                raise

        return call  # type: ignore[return-value]

    return wrap


def _article(kind: type) -> str:
    """``kind`` as a message names what it takes: "a str", "an ImpactDamper", "None"."""
    if kind is type(None):
        return "None"
    return f"{'an' if kind.__name__[0] in 'AEIOU' else 'a'} {kind.__name__}"
