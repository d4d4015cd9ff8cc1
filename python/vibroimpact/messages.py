"""Values as error messages show them: short and exact, whatever their size.

An error is one line: a number is written as Python's ``repr`` writes it (``1e+300``,
``9223372036854775807``), never as its full decimal expansion, and the core's messages,
whose numbers are formatted in full (``1e300`` as a 301-digit integer), are shortened the
same way before they reach the user.
"""

from __future__ import annotations

import re
import reprlib
from typing import Any

import numpy as np

# Values quoted in messages are cut short: an error is one line.
_SHORT = reprlib.Repr()
_SHORT.maxlevel, _SHORT.maxlist, _SHORT.maxdict = 2, 4, 4
_SHORT.maxstring, _SHORT.maxlong, _SHORT.maxother = 40, 24, 40

# A decimal number of 21 or more digits standing alone (not part of a word, a name or a
# longer number: longer than any 64-bit integer, so never an integer quoted as given), or
# a fraction with 6 or more leading zeros: the core's way of writing a large or a tiny
# float in full.
_LONG = re.compile(r"(?<![\w.])-?(?:\d{21,}(?:\.\d+)?|0\.0{6,}\d+)(?![\w.])")


def shown(value: Any) -> str:
    """``value`` as a message quotes it: a number by its ``repr`` (exact and short: an
    integer of more than 24 digits is written as its float), anything else cut short."""
    if isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, int) and not isinstance(value, bool) and abs(value) >= 10**24:
        try:
            return f"{float(value):.6e}"
        except OverflowError:
            return f"an integer of about {int(value.bit_length() * 0.30103) + 1} digits"
    if isinstance(value, float):
        return repr(value)
    # One line: a NumPy array's repr breaks its rows over lines.
    return re.sub(r"\s*\n\s*", " ", _SHORT.repr(value))


def short_numbers(text: str) -> str:
    """``text`` with every number written in full (21 digits or more, or 6 leading zeros
    after the point) rewritten as the ``repr`` of its float, exact and short."""
    return _LONG.sub(lambda m: repr(float(m.group())), text)


def unknown_section(name: str, value: Any, allowed: str) -> str:
    """The message for a name at a scenario's top level that is none of its sections:
    a table (``[title]``), or a key written above the first section (``title = "x"``),
    which is no section at all. ``allowed`` is the note in parentheses."""
    table = isinstance(value, dict) or (
        isinstance(value, list) and bool(value) and all(isinstance(v, dict) for v in value)
    )
    if table:
        return f"unknown section [{name}] ({allowed})"
    return (
        f"unknown key {name!r} above the first section: a scenario holds sections only ({allowed})"
    )
