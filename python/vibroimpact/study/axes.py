"""A study's axes (``[study.axes]``: lists of values or ``{start, stop, count}``) and
random draws (``[study.random]``), each checked, counted before any array is made, and
made; the seeds of random signals among them."""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from vibroimpact.analysis.limits import single_value_drops_stop
from vibroimpact.arguments import real
from vibroimpact.study.limits import MAX_STUDY_RUNS, StudyError
from vibroimpact.system import _NUMBER, _REQ, _TEXT, _WHOLE, _choice, _table

_SPACINGS = ("linear", "log")
_AXIS = {
    "start": (_NUMBER, _REQ),
    "stop": (_NUMBER, _REQ),
    "count": (_WHOLE, _REQ),
    "spacing": (_TEXT, "linear"),
}


def _check_path(where: str, path: str) -> None:
    """Refuse a dotted path whose index is not a whole number from 0 (``-1``, ``+1``):
    Python would read a negative one from the end; or is written with leading zeros
    (``00``): a second spelling of a path would make a second axis of one parameter."""
    for part in path.split(".")[1:]:
        if part.lstrip("+-").isdigit() and not (
            part.isascii() and part.isdigit() and str(int(part)) == part
        ):
            raise StudyError(
                f"{where}{part!r}: an index is a whole number from 0, without leading zeros"
            )


def _listed(spec: Any) -> Any:
    """An axis given as a numpy array (from Python) as the list a file gives."""
    return spec.tolist() if isinstance(spec, np.ndarray) and spec.ndim == 1 else spec


def _axis_count(path: str, spec: Any) -> int:
    """The number of values of an axis, checked (and a seed axis's values) without
    making them."""
    where = f"[study.axes] {path!r}: "
    spec = _listed(spec)
    if not isinstance(spec, Mapping):
        return len(_axis_values(path, spec))
    allowed = f"{where}count: must be a whole number in [1, {MAX_STUDY_RUNS:,}]"
    given = spec.get("count")
    if isinstance(given, int) and not isinstance(given, bool) and given < 1:
        # One range for every count refused (a negative one had been told [0, 2^63 - 1]).
        raise StudyError(f"{allowed}, got {given}")
    axis = _table(where, spec, _AXIS)
    _choice(where, "spacing", axis["spacing"], _SPACINGS)
    count: int = axis["count"]
    if count > MAX_STUDY_RUNS:
        raise StudyError(f"{allowed}, got {count}")
    dropped = single_value_drops_stop(where, axis["start"], axis["stop"], count)
    if dropped:
        raise StudyError(dropped)
    if axis["spacing"] == "log" and not (axis["start"] > 0 and axis["stop"] > 0):
        raise StudyError(f'{where}start, stop: must be > 0 for spacing = "log"')
    if _is_seed(path):
        # The ends, and the step between them: all whole when these are.
        step = (axis["stop"] - axis["start"]) / (count - 1) if count > 1 else 0.0
        _check_seeds(where, np.array([axis["start"], axis["stop"]]))
        if not float(step).is_integer():
            raise StudyError(
                f"{where}a seed must be a whole number in [0, 2^53]: start, stop and count "
                f"give a step of {step!r}"
            )
    return count


def _is_seed(path: str) -> bool:
    """Whether ``path`` is a random signal's seed (``excitation.N.seed``)."""
    parts = path.split(".")
    return len(parts) == 3 and parts[0] == "excitation" and parts[2] == "seed"


#: Seeds travel among the study's values as floats: whole numbers up to 2^53.
_MAX_SEED = 2**53


def _check_seeds(where: str, values: np.ndarray) -> None:
    bad = [v for v in values if not (0 <= v <= _MAX_SEED and float(v).is_integer())]
    if bad:
        raise StudyError(f"{where}a seed must be a whole number in [0, 2^53], got {float(bad[0])}")


def _distribution(path: str, spec: Any, samples: int) -> tuple[str, float, float]:
    """A ``[study.random]`` entry checked: its law and two numbers (``"from"``, the
    first seed and the last, for a seed)."""
    where = f"[study.random] {path!r}: "
    if _is_seed(path):
        # A seed of its own for each sample: from, from + 1, ... (no draw taken).
        first = spec.get("from") if isinstance(spec, Mapping) and len(spec) == 1 else None
        if isinstance(first, bool) or not isinstance(first, int):
            raise StudyError(
                f"{where}a seed is given as {{from = N}}: seed N + k for sample k, got {spec!r:.40}"
            )
        _check_seeds(where, np.array([first, first + max(samples - 1, 0)], dtype=float))
        return "from", float(first), float(first + max(samples - 1, 0))
    if (
        not isinstance(spec, Mapping)
        or len(spec) != 1
        or not isinstance(next(iter(spec)), str)
        or next(iter(spec)) not in _LAWS
    ):
        raise StudyError(
            f"{where}must be one of {{uniform = [low, high]}}, {{normal = [mean, std]}} "
            "(or {from = N} for a seed)"
        )
    law, bounds = next(iter(spec.items()))
    if (
        isinstance(bounds, str)
        or not isinstance(bounds, Sequence)
        or len(bounds) != 2
        or any(isinstance(b, bool) or not isinstance(b, int | float) for b in bounds)
        or not all(math.isfinite(b) for b in bounds)
    ):
        raise StudyError(f"{where}{law} must be two finite numbers, got {bounds!r:.40}")
    a, b = float(bounds[0]), float(bounds[1])
    if law == "uniform" and not a < b:
        raise StudyError(f"{where}uniform needs low < high, got [{a}, {b}]")
    if law == "normal" and not b >= 0:
        raise StudyError(f"{where}normal needs std >= 0, got {b}")
    return law, a, b


def _draws(path: str, spec: Any, samples: int, generator: np.random.Generator) -> np.ndarray:
    """A ``[study.random]`` entry's values for the samples (seeds: no draw taken)."""
    law, a, b = _distribution(path, spec, samples)
    if law == "from":
        return np.arange(samples, dtype=float) + a
    if law == "uniform":
        return generator.uniform(a, b, samples)
    return generator.normal(a, b, samples)


_LAWS = ("uniform", "normal")


def _tidy(values: np.ndarray) -> np.ndarray:
    """Each of ``values`` that is a few units in the last place from a decimal of 12
    significant digits replaced by it (0.005, not linspace's 0.004999999999999999, so
    that ``.sel(0.005)`` finds it: the runs use these values); the others (2/3 of
    something) as they are."""
    short = np.array([float(f"{v:.12g}") for v in values])
    close = np.abs(short - values) <= 4 * np.spacing(np.abs(values))
    return np.where(close, short, values)


def _axis_values(path: str, spec: Any) -> np.ndarray:
    where = f"[study.axes] {path!r}: "
    spec = _listed(spec)
    if isinstance(spec, Mapping):
        _axis_count(path, spec)
        axis = _table(where, spec, _AXIS)
        if axis["spacing"] == "log":
            return _tidy(np.geomspace(axis["start"], axis["stop"], axis["count"]))
        return _tidy(np.linspace(axis["start"], axis["stop"], axis["count"]))
    if isinstance(spec, str) or not isinstance(spec, Sequence) or not spec:
        raise StudyError(f"{where}must be a list of numbers or {{start, stop, count}}")
    values = []
    for v in spec:
        # NumPy's scalars too (a list of np.float32 values), as an array's are.
        number = real(v)
        if number is None or not math.isfinite(number):
            raise StudyError(f"{where}must hold finite numbers, got {v!r:.40}")
        values.append(float(number))
    return np.asarray(values)
