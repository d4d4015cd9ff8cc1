"""Stepped sweeps of one parameter, each point the steady response from the last
point's state (jumps and hysteresis show), beside the linear response; the points'
reductions and what a sweep's table and plot show."""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from functools import partial
from pathlib import Path
from typing import Any, TypeVar

import numpy as np

from vibroimpact import arguments
from vibroimpact._core import InvalidInputError
from vibroimpact.analysis.limits import MAX_POINTS, AnalysisError
from vibroimpact.analysis.parameters import with_parameter
from vibroimpact.analysis.runs import runner
from vibroimpact.analysis.sensitivities import Derivative, derivative_paths, settled_derivatives
from vibroimpact.analysis.settings import _DIRECTIONS, chosen_settings
from vibroimpact.analysis.steady import SteadyState, linear_response, steady_state
from vibroimpact.messages import shown
from vibroimpact.model.system import System, sections_of
from vibroimpact.summary import summarised
from vibroimpact.system import _choice

_T = TypeVar("_T")


def _floats(name: str, value: Any) -> np.ndarray:
    """An array of numbers (any shape; NaN allowed: a run that failed)."""
    try:
        if value is None or isinstance(value, str | bytes | Mapping):
            raise TypeError
        return np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise AnalysisError(f"{name}: must be an array of numbers, got {shown(value)}") from None


@summarised
@dataclass
class SweepPoint:
    """One point of a sweep (see :func:`sweep`)."""

    value: float
    direction: str
    settled: bool
    amplitude: np.ndarray
    rms: np.ndarray
    impacts_per_period: float
    linear_amplitude: np.ndarray
    error: str | None = None
    #: At each of ``[output] points`` (m), as ``amplitude``, ``rms`` and
    #: ``linear_amplitude`` per coordinate.
    points: np.ndarray = field(default_factory=lambda: np.zeros(0))
    point_amplitude: np.ndarray = field(default_factory=lambda: np.zeros(0))
    point_rms: np.ndarray = field(default_factory=lambda: np.zeros(0))
    linear_point_amplitude: np.ndarray = field(default_factory=lambda: np.zeros(0))
    #: At each of ``[output] moments`` (m), the bending moment's (N m).
    moments: np.ndarray = field(default_factory=lambda: np.zeros(0))
    moment_amplitude: np.ndarray = field(default_factory=lambda: np.zeros(0))
    moment_rms: np.ndarray = field(default_factory=lambda: np.zeros(0))
    linear_moment_amplitude: np.ndarray = field(default_factory=lambda: np.zeros(0))
    #: Where the response did not settle, the smallest of the periods' peaks (see
    #: :attr:`SteadyState.least_period_peak`).
    least_period_peak: np.ndarray = field(default_factory=lambda: np.zeros(0))
    #: With ``sweep(..., derivatives=paths)``: the derivatives of the orbit through the
    #: point's settled state in each path (see :func:`settled_derivatives`), or None
    #: where there is no orbit to differentiate; empty where none were asked for.
    derivatives: dict[str, Derivative] | None = field(default_factory=dict)

    def to_dict(self) -> dict[str, Any]:
        def floats(a: np.ndarray) -> list[float | None]:
            return [float(v) if math.isfinite(v) else None for v in a]

        followed: dict[str, Any] = {}
        for kind, where in (("point", self.points), ("moment", self.moments)):
            if len(where):
                amplitude, linear, rms = shown_values(self, kind)
                followed |= {
                    f"{kind}s": [float(v) for v in where],
                    f"{kind}_amplitude": floats(amplitude),
                    f"{kind}_rms": floats(rms),
                    f"linear_{kind}_amplitude": floats(linear),
                    f"{kind}_reduction": _reductions(amplitude, linear),
                }
        return {
            "value": self.value,
            "direction": self.direction,
            "amplitude": floats(self.amplitude),
            "rms": floats(self.rms),
            "impacts_per_period": self.impacts_per_period,
            "settled": self.settled,
            "linear_amplitude": floats(self.linear_amplitude),
            "reduction": _reductions(self.amplitude, self.linear_amplitude),
            **followed,
            **({"error": self.error} if self.error else {}),
            **(
                {}
                if self.derivatives == {}
                else {
                    "derivatives": None
                    if self.derivatives is None
                    else {path: d.to_dict() for path, d in self.derivatives.items()}
                }
            ),
        }


def shown_amplitudes(point: SweepPoint) -> tuple[str, str]:
    """Which amplitudes a sweep's table and plot show, and their unit: those of the
    structure at the first of ``[output] points`` (``"point"``, m), else of the first
    bending moment (``"moment"``, N m), else of coordinate 0 (``"coordinate"``, m)."""
    if len(point.points):
        return "point", "m"
    if len(point.moments):
        return "moment", "N m"
    return "coordinate", "m"


def shown_values(point: SweepPoint, shown: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The amplitudes, linear amplitudes and RMS values of kind ``shown`` (see
    :func:`shown_amplitudes`)."""
    if shown == "point":
        return point.point_amplitude, point.linear_point_amplitude, point.point_rms
    if shown == "moment":
        return point.moment_amplitude, point.linear_moment_amplitude, point.moment_rms
    return point.amplitude, point.linear_amplitude, point.rms


def shown_derivative(point: SweepPoint, shown: str, path: str) -> float:
    """The derivative in ``path`` (per unit of it) of the first amplitude of kind
    ``shown`` (see :func:`shown_amplitudes`): NaN where the point has none."""
    if not point.derivatives or path not in point.derivatives:
        return math.nan
    d = point.derivatives[path]
    values = {"point": d.point_amplitude, "moment": d.moment_amplitude}.get(shown, d.amplitude)
    return float(values[0]) if len(values) else math.nan


def shown_label(point: SweepPoint, shown: str) -> str:
    """What the shown amplitudes are, in words."""
    if shown == "point":
        return f"amplitude at [output] points[0] = {point.points[0]:g}"
    if shown == "moment":
        return f"bending moment amplitude at [output] moments[0] = {point.moments[0]:g} m"
    return "amplitude of structure coordinate 0"


def reductions(amplitude: Any, linear: Any) -> np.ndarray:
    """``1 - amplitude / linear`` along the last axis, NaN where either is not finite or
    the linear amplitude is round-off: at most 1e-9 of the largest of its row (a node of
    the response, such as the moment at a free tip, where the ratio is of round-offs)."""
    amplitude, linear = _floats("amplitude", amplitude), _floats("linear", linear)
    finite = np.isfinite(amplitude) & np.isfinite(linear)
    scale = np.max(np.abs(np.where(finite, linear, 0.0)), axis=-1, keepdims=True, initial=0.0)
    defined = finite & (np.abs(linear) > 1e-9 * scale)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(defined, 1.0 - amplitude / np.where(defined, linear, 1.0), np.nan)


def _reductions(amplitude: np.ndarray, linear: np.ndarray) -> list[float | None]:
    """:func:`reductions` for JSON: None where undefined."""
    return [float(r) if math.isfinite(r) else None for r in reductions(amplitude, linear)]


def sweep_values(settings: Mapping[str, Any]) -> np.ndarray:
    """The parameter's values of a checked ``[sweep]`` section."""
    if settings["spacing"] == "log":
        return np.geomspace(settings["start"], settings["stop"], settings["count"])
    return np.linspace(settings["start"], settings["stop"], settings["count"])


def from_carried(attempt: Callable[[np.ndarray | None], _T], state: np.ndarray | None) -> _T:
    """``attempt(state)``, the state carried from the last point of a sweep; or
    ``attempt(None)``, from the scenario's ``[initial]``, where that state is not
    admissible at this point (a clearance swept down past where the damper was)."""
    try:
        return attempt(state)
    except InvalidInputError:
        if state is None:
            raise
        return attempt(None)


class _PointFailure(Exception):
    """A sweep point the method cannot take: recorded with its reason."""


@arguments.typed()
def sweep(
    data: Mapping[str, Any] | System,
    parameter: str | None = None,
    values: Sequence[float] | np.ndarray | None = None,
    *,
    direction: str | None = None,
    settle_periods: int | None = None,
    record_periods: int | None = None,
    tolerance: float | None = None,
    base_dir: Path | None = None,
    progress: Callable[[int, int], None] | None = None,
    derivatives: Sequence[str] | None = None,
) -> list[SweepPoint]:
    """A stepped sweep of ``parameter`` (a dotted path into the scenario's sections)
    over ``values`` (sorted: ``"up"`` is towards larger values whatever their order as
    given), ``"up"``, ``"down"`` or ``"both"`` (up, then
    down from where up ended), each point starting from the last one's state, so
    that jumps and hysteresis show (from ``[initial]`` where that state is not
    admissible: see :func:`from_carried`). A point whose run fails is reported with
    its error (and the next starts from the last good state). ``data``: a
    :class:`~vibroimpact.System` or a scenario's sections. ``derivatives``: dotted
    paths such as ``"damper.0.clearance"``; at each point, the derivatives of the
    orbit through its settled state in each (:attr:`SweepPoint.derivatives`, per unit
    of the parameter; see :func:`settled_derivatives`). Without ``parameter`` and
    ``values``, the ``[sweep]`` table of ``data`` (a System loaded from a scenario
    keeps it) gives them, and every setting not given here (``direction`` ``"up"``,
    ``settle_periods`` 200, ``record_periods`` 50, ``tolerance`` 1e-6 where neither
    says)."""
    data, base_dir = sections_of(data, base_dir)
    given = {
        "parameter": parameter,
        "values": values,
        "direction": direction,
        "settle_periods": settle_periods,
        "record_periods": record_periods,
        "tolerance": tolerance,
        "derivatives": derivatives,
        # The table's (where it gives the values): what they are made of.
        **dict.fromkeys(("start", "stop", "count", "spacing")),
    }
    chosen = chosen_settings(data, "sweep", given, ("parameter", "values"))
    if values is None:
        chosen["values"] = sweep_values(chosen)
    return _sweep(data, chosen["parameter"], chosen["values"], chosen, base_dir, progress)


def _sweep(
    data: Mapping[str, Any],
    parameter: str,
    values: Sequence[float] | np.ndarray,
    settings: Mapping[str, Any],
    base_dir: Path | None,
    progress: Callable[[int, int], None] | None,
) -> list[SweepPoint]:
    """:func:`sweep` with every setting chosen (``settings``: its keywords')."""
    direction, derivatives = settings["direction"], settings["derivatives"]
    settle_periods, record_periods = settings["settle_periods"], settings["record_periods"]
    tolerance = settings["tolerance"]
    arguments.text("parameter", parameter)
    paths = derivative_paths(data, derivatives)
    values = sorted(arguments.numbers("values", values).tolist())
    if not 1 <= len(values) <= MAX_POINTS:
        # As a [sweep]'s count: each point is hundreds of forcing periods and a result.
        raise AnalysisError(f"values: must be 1 to {MAX_POINTS} values, got {len(values)}")
    _choice("", "direction", direction, _DIRECTIONS)
    base_dir = arguments.directory("base_dir", base_dir)
    arguments.callback("progress", progress)
    legs: list[tuple[str, list[float]]] = []
    if direction in ("up", "both"):
        legs.append(("up", values))
    if direction in ("down", "both"):
        legs.append(("down", values[::-1]))
    points: list[SweepPoint] = []
    state: np.ndarray | None = None
    total = sum(len(v) for _, v in legs)
    for leg, leg_values in legs:
        for value in leg_values:
            changed = with_parameter(data, parameter, value)
            try:
                run = runner(changed, base_dir)
                linear, linear_at_points, linear_moments = linear_response(
                    changed, base_dir, run.prepared
                )
            except InvalidInputError as err:
                raise AnalysisError(f"{parameter} = {value:g}: {err}") from None
            try:
                try:
                    run.system()
                except InvalidInputError as err:
                    if not points:
                        # At the first point: a kind the method never takes (a
                        # compliant law for the exact flow), refused.
                        raise AnalysisError(f"{parameter} = {value:g}: {err}") from None
                    # What the method cannot take at this value alone (the exact flow
                    # and an undamped mode forced at its frequency): the point fails,
                    # the sweep goes on (user trial: it ended the sweep).
                    raise _PointFailure(str(err)) from None
                result = from_carried(
                    partial(
                        steady_state,
                        run,
                        settle_periods=settle_periods,
                        record_periods=record_periods,
                        tolerance=tolerance,
                    ),
                    state,
                )
            except InvalidInputError:
                raise
            except Exception as err:  # a run that cannot be completed: record it
                error: str | None = str(err)

                def nan(size: int) -> np.ndarray:
                    return np.full(size, np.nan)

                result = SteadyState(
                    settled=False,
                    period=None,
                    amplitude=nan(len(linear)),
                    rms=nan(len(linear)),
                    impacts_per_period=math.nan,
                    state=np.zeros(0),
                    strobe=np.zeros((0, 0)),
                    point_amplitude=nan(len(run.points)),
                    point_rms=nan(len(run.points)),
                    moment_amplitude=nan(len(run.moments)),
                    moment_rms=nan(len(run.moments)),
                )
            else:
                error = None
                state = result.state
            derived: dict[str, Derivative] | None = {}
            if paths:
                derived = (
                    None if error else settled_derivatives(changed, run, result, paths, base_dir)
                )
            points.append(
                SweepPoint(
                    value=value,
                    direction=leg,
                    settled=result.settled,
                    amplitude=result.amplitude,
                    rms=result.rms,
                    impacts_per_period=result.impacts_per_period,
                    linear_amplitude=linear,
                    error=error,
                    points=run.points,
                    point_amplitude=result.point_amplitude,
                    point_rms=result.point_rms,
                    linear_point_amplitude=linear_at_points,
                    moments=run.moments,
                    moment_amplitude=result.moment_amplitude,
                    moment_rms=result.moment_rms,
                    linear_moment_amplitude=linear_moments,
                    least_period_peak=result.least_period_peak,
                    derivatives=derived,
                )
            )
            if progress is not None:
                progress(len(points), total)
    return points
