"""The analyses' sections of a scenario (``[sweep]``, ``[continuation]``, ``[basins]``)
checked, with their defaults: what reading a scenario checks (:data:`SETTINGS`)."""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable, Iterator, Mapping
from contextlib import contextmanager
from typing import Any

from vibroimpact.analysis.limits import (
    MAX_POINTS,
    MAX_STARTS,
    AnalysisError,
    check_periods,
    check_total,
    relative_tolerance,
    single_value_drops_stop,
)
from vibroimpact.analysis.parameters import with_parameter_path_check
from vibroimpact.messages import shown
from vibroimpact.model.system import ANALYSIS_CHECKS
from vibroimpact.system import _NUMBER, _REQ, _TEXT, _WHOLE, _choice, _table
from vibroimpact.system.schema import _TEXTS

_DIRECTIONS = ("up", "down", "both")
_SPACINGS = ("linear", "log")
_SWEEP = {
    "parameter": (_TEXT, _REQ),
    "start": (_NUMBER, _REQ),
    "stop": (_NUMBER, _REQ),
    "count": (_WHOLE, _REQ),
    "spacing": (_TEXT, "linear"),
    "direction": (_TEXT, "up"),
    "settle_periods": (_WHOLE, 200),
    "record_periods": (_WHOLE, 50),
    "tolerance": (_NUMBER, 1e-6),
    # Read by sweep only: the parameters each point's orbit is differentiated in.
    "derivatives": (_TEXTS, ()),
    # Read by bifurcation only: what it samples, and at which pair's impacts.
    "sample": (_TEXT, "displacement"),
    "pair": (_TEXT, None),
}
#: What a bifurcation diagram samples, and the unit of each: structure coordinate 0's
#: displacement at each forcing period (stroboscopic), or at each impact (a rigid
#: impact or a compliant contact's onset) its approach speed or its phase ``w t``
#: modulo 2 pi in the forcing period (on the scenario's clock).
BIFURCATION_SAMPLES = {"displacement": "m", "impact-velocity": "m/s", "impact-phase": "rad"}


def sweep_settings(table: Any) -> dict[str, Any]:
    """The ``[sweep]`` section checked and with its defaults: ``parameter`` (a
    dotted path such as ``"excitation.0.frequency"``), ``start``, ``stop``, ``count``
    (>= 1), ``spacing`` (``"linear"`` or ``"log"``), ``direction`` (``"up"``,
    ``"down"``, ``"both"``), ``settle_periods`` (>= 0), ``record_periods`` (>= 1),
    the stroboscopic ``tolerance`` of settling, for sweep ``derivatives`` (dotted paths:
    each point's orbit is differentiated in them), and for bifurcation ``sample`` (see
    :data:`BIFURCATION_SAMPLES`) and ``pair`` (whose impacts it samples)."""
    out = _table("[sweep] ", table, _SWEEP)
    _choice("[sweep] ", "direction", out["direction"], _DIRECTIONS)
    _choice("[sweep] ", "sample", out["sample"], tuple(BIFURCATION_SAMPLES))
    _choice("[sweep] ", "spacing", out["spacing"], _SPACINGS)
    if out["count"] < 1:
        raise AnalysisError(f"[sweep] count: must be >= 1, got {out['count']}")
    dropped = single_value_drops_stop("[sweep] ", out["start"], out["stop"], out["count"])
    if dropped:
        raise AnalysisError(dropped)
    for key, low in (("settle_periods", 0), ("record_periods", 1)):
        check_periods("[sweep] ", key, out[key], low)
    check_total(
        ("[sweep] settle_periods", out["settle_periods"]), ("record_periods", out["record_periods"])
    )
    if out["count"] > MAX_POINTS:
        raise AnalysisError(f"[sweep] count: must be at most {MAX_POINTS}, got {out['count']}")
    if not out["tolerance"] > 0:
        raise AnalysisError(f"[sweep] tolerance: must be > 0, got {out['tolerance']}")
    if out["spacing"] == "log" and not (out["start"] > 0 and out["stop"] > 0):
        raise AnalysisError('[sweep] start, stop: must be > 0 for spacing = "log"')
    if not math.isfinite(out["start"]) or not math.isfinite(out["stop"]):
        raise AnalysisError("[sweep] start, stop: must be finite")
    with_parameter_path_check(out["parameter"])
    for path in out["derivatives"]:
        try:
            with_parameter_path_check(path, "")
        except AnalysisError as err:
            raise AnalysisError(f"[sweep] derivatives: {err}") from None
    return out


_CONTINUATION = {
    "parameter": (_TEXT, _REQ),
    "stop": (_NUMBER, _REQ),
    "periods": (_WHOLE, 1),
    "step": (_NUMBER, None),
    "max_points": (_WHOLE, 200),
    "tolerance": (_NUMBER, 1e-9),
    # At a located flip, go on along the period-doubled branch.
    "switch": ("boolean", False),
}


def continuation_settings(table: Any) -> dict[str, Any]:
    """The ``[continuation]`` section checked, with its defaults: ``parameter`` (a
    dotted path, continued from the scenario's value), ``stop``, ``periods`` (K),
    ``step`` (about, in the parameter's unit), ``max_points``, ``tolerance``, ``switch``
    (at a located flip, go on along the period-doubled branch)."""
    out = _table("[continuation] ", table, _CONTINUATION)
    with_parameter_path_check(out["parameter"], "[continuation]")
    check_periods("[continuation] ", "periods", out["periods"], 1)
    if out["max_points"] < 2:
        raise AnalysisError(f"[continuation] max_points: must be >= 2, got {out['max_points']}")
    if out["max_points"] > MAX_POINTS:
        raise AnalysisError(
            f"[continuation] max_points: must be at most {MAX_POINTS}, got {out['max_points']}"
        )
    for key in ("step", "tolerance"):
        if out[key] is not None and not out[key] > 0:
            raise AnalysisError(f"[continuation] {key}: must be > 0, got {out[key]}")
    relative_tolerance("[continuation] tolerance", out["tolerance"])
    return out


_AXIS = {
    "state": (_TEXT, _REQ),
    "start": (_NUMBER, _REQ),
    "stop": (_NUMBER, _REQ),
    "count": (_WHOLE, _REQ),
}
_BASINS = {
    "x": ("table", _REQ),
    "y": ("table", _REQ),
    "settle_periods": (_WHOLE, 200),
    "record_periods": (_WHOLE, 20),
    "tolerance": (_NUMBER, 1e-6),
}
_STATE_KEYS = (
    "structure_displacement",
    "structure_velocity",
    "damper_displacement",
    "damper_velocity",
)


def basins_settings(table: Any) -> dict[str, Any]:
    """The ``[basins]`` section checked: ``x`` and ``y``, each ``{state =
    "structure_displacement.0", start, stop, count}`` (an entry of one of the four
    arrays of ``[initial]``), ``settle_periods``, ``record_periods``, ``tolerance``."""
    if not isinstance(table, Mapping):
        raise AnalysisError(f"[basins]: must be a table, got {table!r:.60}")
    out = _table(
        "[basins] ",
        {k: v for k, v in table.items() if k not in ("x", "y")},
        {key: spec for key, spec in _BASINS.items() if key not in ("x", "y")},
    )
    for axis in ("x", "y"):
        if axis not in table:
            raise AnalysisError(f"[basins] missing key {axis!r} ({{state, start, stop, count}})")
        given = table[axis]
        # Said here: _table's own "missing key" reads after "[basins] x." as one word.
        required = [key for key, (_, default) in _AXIS.items() if default is _REQ]
        mapping = isinstance(given, Mapping)
        missing = [key for key in required if key not in given] if mapping else []
        if not mapping or missing:
            problem = f"missing key {missing[0]!r}" if missing else f"got {shown(given)}"
            raise AnalysisError(
                f"[basins] {axis}: must be a table {{state, start, stop, count}}, {problem}"
            )
        checked = _table(f"[basins] {axis}.", given, _AXIS)
        name, _, index = checked["state"].partition(".")
        if name not in _STATE_KEYS or not (index.isascii() and index.isdigit()):
            raise AnalysisError(
                f"[basins] {axis}.state: must be one of {', '.join(_STATE_KEYS)} with an "
                f'index, such as "structure_displacement.0", got {checked["state"]!r}'
            )
        if checked["count"] < 1:
            raise AnalysisError(f"[basins] {axis}.count: must be >= 1, got {checked['count']}")
        ends = (checked["start"], checked["stop"])
        dropped = single_value_drops_stop(f"[basins] {axis}.", *ends, checked["count"])
        if dropped:
            raise AnalysisError(dropped)
        out[axis] = checked
    x, y = (out[a]["state"].partition(".") for a in ("x", "y"))
    if (x[0], int(x[2])) == (y[0], int(y[2])):
        raise AnalysisError(
            f"[basins] y.state: must differ from x.state, both {out['y']['state']!r}: the "
            "grid is over two entries of [initial]"
        )
    starts = out["x"]["count"] * out["y"]["count"]
    if starts > MAX_STARTS:
        raise AnalysisError(
            f"[basins] x.count, y.count: {out['x']['count']} x {out['y']['count']} = {starts} "
            f"starts, more than {MAX_STARTS}; lower the counts"
        )
    for key, low in (("settle_periods", 0), ("record_periods", 1)):
        check_periods("[basins] ", key, out[key], low)
    if not out["tolerance"] > 0:
        # As [sweep]'s: read only when the basins ran, a tolerance of 0 or less was taken.
        raise AnalysisError(f"[basins] tolerance: must be > 0, got {out['tolerance']}")
    check_total(
        ("[basins] settle_periods", out["settle_periods"]),
        ("record_periods", out["record_periods"]),
    )
    return out


#: The bifurcations a two-parameter curve follows.
CURVE_KINDS = ("flip", "fold", "neimark-sacker", "grazing")
_CURVE = {
    "kind": (_TEXT, _REQ),
    "parameter": (_TEXT, _REQ),
    "start": (_NUMBER, _REQ),
    "stop": (_NUMBER, _REQ),
    "second": (_TEXT, _REQ),
    "second_stop": (_NUMBER, _REQ),
    "step": (_NUMBER, _REQ),
    "periods": (_WHOLE, 1),
    "max_points": (_WHOLE, 200),
    "tolerance": (_NUMBER, 1e-9),
}


def curve_settings(table: Any) -> dict[str, Any]:
    """The ``[curve]`` section checked, with its defaults: ``kind`` (the bifurcation
    followed: ``"flip"``, ``"fold"``, ``"neimark-sacker"``), ``parameter`` (a dotted path:
    the bifurcation is first located along the orbit's branch from ``start`` to ``stop``
    of it), ``second`` (a dotted path, followed from the scenario's value to
    ``second_stop`` in steps of ``step``), ``periods`` (K), ``max_points``,
    ``tolerance``."""
    out = _table("[curve] ", table, _CURVE)
    _choice("[curve] ", "kind", out["kind"], CURVE_KINDS)
    with_parameter_path_check(out["parameter"], "[curve]")
    with_parameter_path_check(out["second"], "[curve] second:")
    if out["parameter"] == out["second"]:
        raise AnalysisError(f"[curve] second: must be another parameter than {out['parameter']!r}")
    check_periods("[curve] ", "periods", out["periods"], 1)
    if out["start"] == out["stop"]:
        raise AnalysisError(f"[curve] stop: must differ from start {out['start']!r}")
    for key in ("step", "tolerance"):
        if not out[key] > 0:
            raise AnalysisError(f"[curve] {key}: must be > 0, got {out[key]}")
    relative_tolerance("[curve] tolerance", out["tolerance"])
    if not 2 <= out["max_points"] <= MAX_POINTS:
        raise AnalysisError(
            f"[curve] max_points: must be in [2, {MAX_POINTS}], got {out['max_points']}"
        )
    return out


def chosen_settings(
    data: Mapping[str, Any],
    section: str,
    given: Mapping[str, Any],
    required: tuple[str, ...],
) -> dict[str, Any]:
    """An analysis's settings: each of ``given`` that is not None, the rest from
    ``data``'s ``[section]`` table (checked, its defaults filled) where every one of
    ``required`` is omitted (a System loaded from a file keeps its tables), else the
    table's defaults."""
    missing = [key for key in required if given[key] is None]
    if missing and len(missing) < len(required):
        raise AnalysisError(
            f"{', '.join(missing)}: give {' and '.join(required)} together, or none (a "
            f"[{section}] table gives them)"
        )
    if missing:
        table = data.get(section)
        if table is None:
            raise AnalysisError(
                f"{' and '.join(required)}: give them, or a System (or sections) with a "
                f"[{section}] table"
            )
        base = SETTINGS[section](table)
    else:
        schema = {"sweep": _SWEEP, "continuation": _CONTINUATION, "basins": _BASINS}[section]
        base = {key: default for key, (_, default) in schema.items() if default is not _REQ}
    return {key: base.get(key) if value is None else value for key, value in given.items()}


@contextmanager
def named_in(section: str, keys: Iterable[str]) -> Iterator[None]:
    """An analysis's refusal of one of a table's ``keys`` (its message begins ``key:``,
    the keyword's name) named as the scenario names it: ``[section] key: ...``."""
    try:
        yield
    except AnalysisError as err:
        key, colon, _ = str(err).partition(":")
        if colon and key in set(keys):
            raise AnalysisError(f"[{section}] {err}") from None
        raise


#: Sections of analyses, checked when a scenario is read.
SETTINGS: dict[str, Callable[[Any], dict[str, Any]]] = {
    "sweep": sweep_settings,
    "continuation": continuation_settings,
    "curve": curve_settings,
    "basins": basins_settings,
}
ANALYSIS_CHECKS.update(SETTINGS)
