"""TOML text of a scenario's sections: the plain values a scenario holds (tables,
arrays of tables, numbers, strings, booleans, arrays), written so that ``tomllib``
reads back the same values bit for bit (floats by their shortest round-trip repr)."""

from __future__ import annotations

import math
import re
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from vibroimpact._core import InvalidInputError
from vibroimpact.messages import shown

_BARE_KEY = re.compile(r"[A-Za-z0-9_-]+")


def toml_text(sections: Mapping[str, Any]) -> str:
    """The TOML text of ``sections``: each a table (``[name]``) or a list of tables
    (``[[name]]``); tables within a section are written inline."""
    lines: list[str] = []
    for name, section in sections.items():
        if isinstance(section, Mapping):
            lines += [f"[{_key(name)}]", *_pairs(section, name), ""]
        elif _is_array(section) and all(isinstance(t, Mapping) for t in section):
            for table in section:
                lines += [f"[[{_key(name)}]]", *_pairs(table, name), ""]
        else:
            raise InvalidInputError(
                f"[{name}]: a section must be a table or a list of tables, got {shown(section)}"
            )
    return "\n".join(lines)


def _pairs(table: Mapping[str, Any], where: str) -> list[str]:
    return [f"{_key(key)} = {_value(value, f'{where}.{key}')}" for key, value in table.items()]


def _key(key: Any) -> str:
    if not isinstance(key, str):
        raise InvalidInputError(f"a key must be a string, got {shown(key)}")
    return key if _BARE_KEY.fullmatch(key) else _string(key)


def _string(text: str) -> str:
    """A TOML basic string: quotes, backslashes and control characters escaped."""
    out = []
    for char in text:
        if char in '"\\':
            out.append("\\" + char)
        elif ord(char) < 0x20 or ord(char) == 0x7F:
            out.append(f"\\u{ord(char):04x}")
        else:
            out.append(char)
    return '"' + "".join(out) + '"'


def _is_array(value: Any) -> bool:
    return isinstance(value, np.ndarray) or (
        isinstance(value, Sequence) and not isinstance(value, str | bytes)
    )


def _value(value: Any, where: str) -> str:
    if isinstance(value, bool | np.bool_):
        return "true" if value else "false"
    if isinstance(value, int | np.integer):
        return str(int(value))
    if isinstance(value, float | np.floating):
        number = float(value)
        if math.isnan(number):
            return "nan"
        if math.isinf(number):
            return "inf" if number > 0 else "-inf"
        return repr(number)
    if isinstance(value, str):
        return _string(value)
    if isinstance(value, Mapping):
        inner = ", ".join(
            f"{_key(key)} = {_value(item, f'{where}.{key}')}" for key, item in value.items()
        )
        return "{ " + inner + " }" if inner else "{}"
    if _is_array(value):
        items = value.tolist() if isinstance(value, np.ndarray) else value
        return "[" + ", ".join(_value(item, f"{where}[]") for item in items) + "]"
    raise InvalidInputError(f"{where}: TOML has no value like {shown(value)}")
