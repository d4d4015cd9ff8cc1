"""The bounds of the analyses, checked before a run starts: whole counts, the forcing
periods one run may settle and record, the points of a sweep and the starts of a basins
grid; :class:`AnalysisError`, what an analysis that cannot be set up raises."""

from __future__ import annotations

from typing import Any

import numpy as np

from vibroimpact import _core, arguments
from vibroimpact._core import InvalidInputError
from vibroimpact.messages import shown


class AnalysisError(InvalidInputError):
    """An analysis that cannot be set up as asked (a ValueError)."""


#: The most values a ``[sweep]`` may step through (``count``), or a ``[continuation]``
#: find (``max_points``): each is a point of the result kept in memory and hundreds of
#: forcing periods of computing.
MAX_POINTS = 100_000
#: The most starts of ``[basins]`` (``x.count`` times ``y.count``).
MAX_STARTS = 1_000_000
#: The most forcing periods one run of an analysis may settle or record (the core's
#: registry): with a few impacts and tens of steps a period that is already minutes of
#: computing, and every kept impact is memory; a longer run is a typo (1e12 for 1e2),
#: refused before it starts.
MAX_PERIODS: int = _core.MAX_PERIODS
arguments.WHOLE_RANGES.update(
    settle_periods=(0, MAX_PERIODS),
    record_periods=(1, MAX_PERIODS),
    periods=(1, MAX_PERIODS),
    orbit_periods=(1, MAX_PERIODS),
    max_points=(2, MAX_POINTS),
)
arguments.WHOLE_RANGES["[sweep] count"] = (1, MAX_POINTS)


#: The most Newton iterations of a shooting (``max_iterations``): it converges in a few,
#: or not at all; each is a run of the orbit's periods, so 1e9 was hours of computing.
MAX_ITERATIONS = 10_000


def single_value_drops_stop(where: str, start: float, stop: float, count: int) -> str | None:
    """The error (or None) of ``count`` values from ``start`` to ``stop`` where one value,
    ``start`` alone, would drop ``stop`` without a word; ``where`` prefixes ``count``."""
    if count == 1 and start != stop:
        return (
            f"{where}count: must be >= 2 to reach stop ({stop:g}) from start ({start:g}), "
            "got 1 (one value: set stop = start)"
        )
    return None


def whole_count(name: str, value: Any, low: int, high: int | None = None) -> int:
    """``value`` as a Python int when it is a whole number >= ``low`` (and at most
    ``high`` where given: an int or a NumPy integer, never a boolean); else
    :class:`AnalysisError` naming ``name``."""
    if isinstance(value, np.integer):
        value = int(value)
    if not isinstance(value, int) or isinstance(value, bool) or value < low:
        hint = arguments.integer_hint(arguments.real(value))
        raise AnalysisError(f"{name}: must be a whole number >= {low}{hint}, got {shown(value)}")
    if high is not None and value > high:
        raise AnalysisError(f"{name}: must be a whole number in [{low}, {high}], got {value}")
    return value


def relative_tolerance(name: str, value: Any) -> float:
    """A Newton solve's relative tolerance, in (0, 1): at 1 or more any state passes
    (an orbit reported converged that is none); else :class:`AnalysisError`."""
    checked = float(arguments.positive(name, value))
    if not checked < 1.0:
        raise AnalysisError(
            f"{name}: must be in (0, 1) (relative: 1 or more takes any state for an orbit), "
            f"got {shown(checked)}"
        )
    return checked


def check_total(settle: tuple[str, int], record: tuple[str, int]) -> None:
    """A run that settles ``settle = (name, periods)`` and then records ``record``
    spans at most MAX_PERIODS forcing periods in all: refused up front, naming both
    (``("--settle", 10**7), ("--periods", 10**7)`` had run 21 s into 1.6 GB of
    contacts before the row limit stopped it)."""
    if settle[1] + record[1] > MAX_PERIODS:
        raise AnalysisError(
            f"{settle[0]} {settle[1]} and {record[0]} {record[1]}: a run settles and records "
            f"at most {MAX_PERIODS} forcing periods in all, got {settle[1] + record[1]}; "
            f"settle or record fewer"
        )


def check_periods(where: str, key: str, value: int, low: int) -> None:
    """``value`` forcing periods must be a whole number in [``low``, MAX_PERIODS]; the
    error names ``where`` (``"[sweep] "``, ``"--settle"``...) and ``key``."""
    if not low <= value <= MAX_PERIODS:
        raise AnalysisError(
            f"{where}{key}: must be >= {low} and at most {MAX_PERIODS} forcing periods, got {value}"
        )
