"""A recorded signal's samples: its CSV file read with NumPy within a bounded size, and
the checks the core needs (at least two samples, finite, times increasing strictly,
values within floating point), each error naming the excitation and the sample's place
as a user counts it (the file's line, or the arrays' index).

A file of :data:`MAX_RECORDED_FILE_BYTES` (64 MiB, about 7 million samples) is parsed
into two float arrays by NumPy's reader (about 3 times the file's size in memory at
the peak, where lists of Python floats took 20 times); a larger one is refused before
it is read.
"""

from __future__ import annotations

import io
import itertools
import re
import stat
import sys
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import numpy as np

from vibroimpact._core import InvalidInputError
from vibroimpact.messages import shown

#: The largest CSV file a recorded signal may read (bytes): a record of millions of
#: samples fits, a wrong path (a disk image, /dev/zero) is refused before it fills the
#: memory.
MAX_RECORDED_FILE_BYTES = 64 * 2**20

# A number as a CSV writes it, the same as NumPy's reader takes: decimal digits with an
# optional point and exponent (inf and nan are read, then refused as not finite, naming
# their line). Python's float() would also take "1_0" (as 10) and other digits than
# ASCII: neither is a number in a CSV.
_CELL = r"[+-]?(?:(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][+-]?[0-9]+)?|inf(?:inity)?|nan)"
_NUMBER = re.compile(_CELL, re.IGNORECASE | re.ASCII)
# A line with a # after something else than blanks.
_TRAILING_COMMENT = re.compile(rb"^[ \t]*[^#\s][^\n#]*#", re.MULTILINE)
# Columns apart by commas, semicolons, tabs or spaces.
_SEPARATOR = re.compile(r"\s*[,;]\s*|\s+")
# A cell meant as a number (a sign, a point or a digit first): a first line of such
# cells is a sample, mistyped or not, never a header naming the columns.
_MEANT_AS_NUMBER = re.compile(r"[+-]?\.?\d")

# The largest magnitude a sample (times scale) may have: half the largest float, so
# that the interpolation's differences stay finite (the core's bound).
_LARGEST = 0.5 * sys.float_info.max
# The shortest interval between two samples: the smallest normal float (s); only
# times within _NEAR_ZERO of zero have floats closer than it.
_SHORTEST = sys.float_info.min
_NEAR_ZERO = 1e-280

Row = Callable[[int], str]


def _fail(where: str, message: str) -> InvalidInputError:
    return InvalidInputError(f"{where}{message}")


def read_record(path: Path, where: str) -> tuple[np.ndarray, np.ndarray, Row]:
    """Time and value columns of a CSV file (lines starting with # and blank lines are
    skipped, and a first line that is not numbers, which names the columns), and the
    place of each sample (``"rec.csv line 3"``). ``where`` names the excitation and its
    ``file`` key. Only a regular file of at most :data:`MAX_RECORDED_FILE_BYTES` is
    read; a row must hold exactly two numbers."""
    data = _read_bytes(path, where)
    rows = _Rows(data, path.name)
    start = rows.first_data_line()
    if start is not None:
        # The usual file (one separator throughout, nothing but numbers after the
        # header) at NumPy's speed; anything else goes line by line, which names the
        # first line that is wrong or reads what is right.
        separator = "," if "," in start[1] else ";" if ";" in start[1] else None
        # Lines starting with # are skipped; a # after a number is not a comment.
        comments = "#" if b"#" in data and not _TRAILING_COMMENT.search(data) else None
        try:
            table = np.loadtxt(
                io.TextIOWrapper(io.BytesIO(data), encoding="utf-8-sig"),
                dtype=float,
                delimiter=separator,
                comments=comments,
                skiprows=start[0] - 1,
                ndmin=2,
            )
        except ValueError:
            table = None
        if table is not None and table.shape[1] == 2:
            return table[:, 0], table[:, 1], rows  # views: no copy of 100 MB
    time, value = rows.parse(where)
    return time, value, rows


def _read_bytes(path: Path, where: str) -> bytes:
    """The file's bytes, checked as UTF-8: a regular file of at most
    :data:`MAX_RECORDED_FILE_BYTES`, refused before it is read."""
    name = str(path)
    if "\0" in name:
        # The system's calls refuse it with Python's "embedded null byte", naming nothing.
        raise _fail(where, f"{name!r} holds a null character, which no file name can")
    too_large = (
        f"{name!r} is larger than {MAX_RECORDED_FILE_BYTES // 2**20} MiB, the limit of a "
        "recorded signal"
    )
    try:
        # Checked before opening: opening a FIFO would wait for a writer.
        info = path.stat()
        if not stat.S_ISREG(info.st_mode):
            raise _fail(where, f"{name!r} is not a regular file (a CSV of time and value)")
        if info.st_size > MAX_RECORDED_FILE_BYTES:
            raise _fail(where, too_large)
        with path.open("rb") as f:
            data = f.read(MAX_RECORDED_FILE_BYTES + 1)
        if len(data) > MAX_RECORDED_FILE_BYTES:
            raise _fail(where, too_large)  # it grew after the check
        data.decode("utf-8")  # checked whole here, read a piece at a time below
    except (OSError, UnicodeDecodeError) as err:
        reason = err.strerror if isinstance(err, OSError) and err.strerror else str(err)
        raise _fail(where, f"cannot read {name!r}: {reason}") from None
    return data


class _Rows:
    """The data lines of a record file, as numbered in the file (1 for its first line)."""

    def __init__(self, data: bytes, name: str) -> None:
        self.data, self.name = data, name

    def lines(self) -> Iterator[tuple[int, str]]:
        """Each line that is neither blank nor a comment, stripped, with its number (a
        byte-order mark, as spreadsheets write one, is not part of the first line)."""
        text = io.TextIOWrapper(io.BytesIO(self.data), encoding="utf-8-sig")
        for number, line in enumerate(text, start=1):
            line = line.strip()
            if line and not line.startswith("#"):
                yield number, line

    def first_data_line(self) -> tuple[int, str] | None:
        """The first line of samples (after a header naming the columns, if any)."""
        lines = self.lines()
        for number, line in lines:
            if not _names_columns(line):
                return number, line
            return next(lines, None)  # the first line named the columns
        return None

    def parse(self, where: str) -> tuple[np.ndarray, np.ndarray]:
        """The samples read line by line into arrays, or the error of the first line
        that does not hold two numbers."""
        size = self.data.count(b"\n") + self.data.count(b"\r") + 1  # lines at most
        time, value = np.empty(size), np.empty(size)
        count = 0
        for i, (number, line) in enumerate(self.lines()):
            cells = _SEPARATOR.split(line)
            wrong = [c for c in cells if not _NUMBER.fullmatch(c)]
            if wrong:
                if i == 0 and _names_columns(line):
                    continue
                raise _fail(
                    where,
                    f"{self.name} line {number}: not two numbers: {shown(wrong[0])} is not a "
                    f"number in a CSV (digits, a point, an exponent): {line!r:.60}",
                )
            if len(cells) != 2:
                raise _fail(
                    where,
                    f"{self.name} line {number}: needs two columns, time and value, got "
                    f"{len(cells)}: {line!r:.60}",
                )
            time[count], value[count] = float(cells[0]), float(cells[1])
            count += 1
        return time[:count].copy(), value[:count].copy()

    def __call__(self, index: int) -> str:
        """The place of sample ``index``: its line in the file."""
        first = self.first_data_line()
        numbers = (n for n, _ in self.lines() if first is not None and n >= first[0])
        return f"{self.name} line {next(itertools.islice(numbers, index, None))}"


def _names_columns(line: str) -> bool:
    """Whether the first line names the columns: a cell before any comment that is not
    a number and not meant as one (``time``, ``El Centro 1940 NS``; ``0,1_0`` is a
    mistyped sample, ``0,100 # start`` a sample with a comment after it, which the rule
    had read as a header and dropped without a word). An empty cell names nothing
    (``0,`` is a sample missing its value), and two cells of which the first is a time
    are a sample (``0,e``): both had been dropped as headers."""
    cells = _SEPARATOR.split(line.split("#", 1)[0].strip())
    if len(cells) == 2 and _meant_as_number(cells[0]):
        return False
    return any(c and not _meant_as_number(c) for c in cells)


def _meant_as_number(cell: str) -> bool:
    """Whether a cell is a number or meant as one (see :data:`_MEANT_AS_NUMBER`)."""
    return bool(_NUMBER.fullmatch(cell) or _MEANT_AS_NUMBER.match(cell))


def check_record(
    where: str, time: Any, value: Any, row: Row, scale: float | None, value_row: Row | None = None
) -> None:
    """A record's samples as the core needs them (at least two, finite, times
    increasing strictly, each value times ``scale`` within floating point), refused here
    so that the error names the excitation and ``row(i)``, the place of sample i
    (``value_row(i)`` for a value alone, if given)."""
    if len(time) != len(value):
        raise _fail(
            where,
            f"time and value must have the same length, got {len(time)} and {len(value)}",
        )
    if len(time) < 2:
        raise _fail(where, f"a recorded signal needs at least 2 samples, got {len(time)}")
    t, v = np.asarray(time, dtype=float), np.asarray(value, dtype=float)
    bad = np.flatnonzero(~(np.isfinite(t) & np.isfinite(v)))
    if bad.size:
        i = int(bad[0])
        raise _fail(
            where,
            f"{row(i)}: must be finite numbers, got time {shown(t[i])} and value {shown(v[i])}",
        )
    back = np.flatnonzero(~(t[1:] > t[:-1]))
    if back.size:
        i = int(back[0]) + 1
        raise _fail(
            where,
            f"{row(i)}: times must increase strictly, got {shown(t[i])} s after "
            f"{shown(t[i - 1])} s",
        )
    # Times, as values, within half the largest float: the interval between two samples
    # (-1e308 to 1e308) had overflowed, and the interpolation taken the first value.
    beyond = np.flatnonzero(~(np.abs(t) <= _LARGEST))
    if beyond.size:
        i = int(beyond[0])
        raise _fail(
            where,
            f"{row(i)}: time {shown(t[i])} s is beyond what a run can take (|time| at most "
            f"{_LARGEST:.3e} s, half the largest float)",
        )
    factor = 1.0 if scale is None else abs(scale)
    with np.errstate(over="ignore"):
        beyond = np.flatnonzero(~(np.abs(v) * factor <= _LARGEST))
    if beyond.size:
        i = int(beyond[0])
        scaled = "" if scale is None else f" times scale {shown(scale)}"
        raise _fail(
            where,
            f"{(value_row or row)(i)}: value {shown(v[i])}{scaled} is beyond what a run can take "
            f"(|value{' x scale' if scaled else ''}| at most {_LARGEST:.3e}, half the largest "
            "float)",
        )
    # An interval a normal float: 0 then 1e-320 s (subnormal, two significant digits)
    # had failed the run's energy ledger. Only times near zero can be so close (an
    # interval is at least the spacing of floats at its ends); looked for there alone,
    # so that a long record takes no more memory.
    near = np.flatnonzero((t > -_NEAR_ZERO) & (t < _NEAR_ZERO))
    ends = np.union1d(near, near + 1)
    ends = ends[(ends >= 1) & (ends < len(t))]
    close = ends[t[ends] - t[ends - 1] < _SHORTEST]
    if close.size:
        i = int(close[0])
        raise _fail(
            where,
            f"{row(i)}: time {shown(t[i])} s is {shown(t[i] - t[i - 1])} s after "
            f"{shown(t[i - 1])} s: samples must be at least {_SHORTEST:.3g} s apart (a normal "
            "float)",
        )
