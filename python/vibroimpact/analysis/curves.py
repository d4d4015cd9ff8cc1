"""Two-parameter curves of bifurcations (flip, fold, Neimark-Sacker, grazing) of forced
0.2 systems: the bifurcation first located along the orbit's branch in one parameter
(:func:`~vibroimpact.analysis.continue_orbit`, then Newton on the extended system, see
``vibroimpact.analysis.located``), then followed as a second parameter steps, each
point Newton's method on the extended system ``P_p(z) - z = 0, g(z, p) = 0`` from the
last two points' extrapolation (a grazing's: ``P_p(z) - z = 0`` with the wall's gap and
its rate zero at the touch, see ``vibroimpact.analysis.grazing``). The multipliers come
from the tangent flow through the impacts and contacts. SI units."""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from vibroimpact import arguments
from vibroimpact.analysis.continuation import _Arc, _value_of, check_step, continue_orbit
from vibroimpact.analysis.grazing import away_from_zero, locate_grazing, struck
from vibroimpact.analysis.limits import (
    MAX_PERIODS,
    MAX_POINTS,
    AnalysisError,
    relative_tolerance,
    whole_count,
)
from vibroimpact.analysis.located import Bifurcation, refine
from vibroimpact.analysis.parameters import with_parameter
from vibroimpact.analysis.runs import runner, state_arrays
from vibroimpact.analysis.settings import CURVE_KINDS
from vibroimpact.model.system import System, sections_of
from vibroimpact.summary import summarised


@summarised
@dataclass
class CurvePoint:
    """One point of a curve: the two parameters' ``values`` (by their paths), the
    orbit's state at t = 0 and its Floquet multipliers there."""

    values: dict[str, float]
    state: np.ndarray
    floquet_multipliers: np.ndarray

    def to_dict(self, n: int, k: int) -> dict[str, Any]:
        return {
            "values": dict(self.values),
            "state": state_arrays(self.state, n, k),
            "floquet_multipliers": [
                [float(m.real), float(m.imag)] for m in self.floquet_multipliers
            ],
        }


@summarised
@dataclass
class Curve:
    """A curve of bifurcations of ``kind`` in the plane of ``parameter`` and
    ``second``, and why it stopped."""

    kind: str
    parameter: str
    second: str
    periods: int
    points: list[CurvePoint]
    stopped: str
    n: int
    k: int
    #: Where the curve started: the bifurcation located on the branch in
    #: ``parameter`` at the scenario's value of ``second``.
    first: Bifurcation | None = field(default=None, repr=False)


def curve(
    data: Mapping[str, Any] | System,
    kind: str,
    parameter: str,
    *,
    start: float,
    stop: float,
    second: str,
    second_stop: float,
    step: float,
    periods: int = 1,
    max_points: int = 200,
    tolerance: float = 1e-9,
    base_dir: Path | None = None,
    progress: Callable[[int, int], None] | None = None,
) -> Curve:
    """The curve of bifurcations of ``kind`` (``"flip"``, ``"fold"``, ``"neimark-sacker"``,
    ``"grazing"``: where the orbit touches a wall, a stop or a damper's side, at zero speed)
    of the ``periods``-period orbit: located first along the branch in ``parameter``
    from ``start`` to ``stop`` (the orbit found from the scenario's ``[initial]`` at
    ``start``), then followed in ``second`` from the scenario's value towards
    ``second_stop`` in steps of ``step`` (halved where Newton fails, down to a 64th), at
    most ``max_points`` points. ``data``: a
    :class:`~vibroimpact.System` or a scenario's sections."""
    data, base_dir = sections_of(data, base_dir)
    if kind not in CURVE_KINDS:
        listed = ", ".join(f'"{k}"' for k in CURVE_KINDS)
        raise AnalysisError(f"kind: must be one of {listed}, got {kind!r}")
    start, stop = arguments.number("start", start), arguments.number("stop", stop)
    second_stop = arguments.number("second_stop", second_stop)
    step = arguments.positive("step", step)
    periods = whole_count("periods", periods, 1, MAX_PERIODS)
    max_points = whole_count("max_points", max_points, 2, MAX_POINTS)
    tolerance = relative_tolerance("tolerance", tolerance)
    arguments.text("second", second)
    if second == parameter:
        # Followed in itself, the located point only moves along its own branch: no
        # curve, but the search reported one.
        raise AnalysisError(f"second: must be another parameter than {parameter!r}")
    s0 = _value_of(data, second)
    if second_stop == s0:
        raise AnalysisError(f"second_stop: must be a value other than {second} = {s0:g}")
    check_step("step", step, second_stop - s0)
    at_start = with_parameter(data, parameter, start)
    try:
        # As continue_orbit's stop: a target the scenario cannot take is refused.
        runner(with_parameter(at_start, second, second_stop), base_dir)
    except ValueError as err:
        raise AnalysisError(f"second_stop: must be a value the scenario takes ({err})") from None
    branch = continue_orbit(
        at_start,
        parameter,
        stop=stop,
        periods=periods,
        tolerance=tolerance,
        base_dir=base_dir,
    )
    found = [b for b in branch.bifurcations if b.kind == kind]
    if not found:
        seen = ", ".join(f"{b.kind} at {b.value:.6g}" for b in branch.bifurcations) or "none"
        raise AnalysisError(
            f"no {kind} of the {periods}-period orbit located along {parameter} from "
            f"{start:g} to {stop:g} at {second} = {s0:g} (located: {seen}; the branch "
            f"stopped: {branch.stopped}): widen start and stop ([curve] start, stop)"
        )
    first = found[0]
    n, k = branch.n, branch.k
    size = len(first.state)
    dim = size // 2
    x_scale = max(float(np.max(np.abs(first.state[:dim]))), 1e-12)
    period = runner(with_parameter(data, parameter, first.value), base_dir).period
    v_scale = max(float(np.max(np.abs(first.state[dim:]))), 2 * math.pi / period * x_scale)
    p_scale = abs(stop - start)
    scale = np.concatenate([np.full(dim, x_scale), np.full(dim, v_scale), [p_scale]])
    points = [
        CurvePoint({parameter: first.value, second: s0}, first.state, first.floquet_multipliers)
    ]
    history = [np.concatenate([first.state, [first.value]]) / scale]
    if first.time is not None:
        # A grazing's touch's instant too, in the orbit's periods.
        span = periods * period
        history[0] = np.concatenate([history[0], [away_from_zero(first.time, span) / span]])
    direction = 1.0 if second_stop > s0 else -1.0
    s, h = s0, step
    stopped = "max_points"
    while len(points) < max_points:
        if progress is not None:
            progress(len(points), max_points)
        if (s - second_stop) * direction >= 0:
            stopped = "reached second_stop"
            break
        trial_s = s + direction * min(h, abs(second_stop - s))
        arc = _Arc(
            with_parameter(data, second, trial_s),
            parameter,
            periods,
            tolerance,
            base_dir,
            stop - start,
        )
        arc.size, arc.scale = size, scale
        if len(history) >= 2:
            # The last two points' line, stretched to this step.
            ratio = (trial_s - s) / (s - points[-2].values[second])
            guess = history[-1] + ratio * (history[-1] - history[-2])
        else:
            guess = history[-1]
        located = _locate(arc, first, guess)
        if located is None:
            if h > step / 64:
                h /= 2
                continue
            stopped = f"Newton failed at {second} = {trial_s:g} (the curve may end or turn)"
            break
        value, state, multipliers, w = located
        points.append(CurvePoint({parameter: value, second: trial_s}, state, multipliers))
        history.append(w)
        s = trial_s
        h = min(2 * h, step)
    return Curve(kind, parameter, second, periods, points, stopped, n, k, first)


def _locate(
    arc: _Arc, first: Bifurcation, guess: np.ndarray
) -> tuple[float, np.ndarray, np.ndarray, np.ndarray] | None:
    """The bifurcation of ``first``'s kind (and wall, for a grazing) near the scaled
    unknowns ``guess``: its parameter's value, state, multipliers and scaled unknowns;
    None where Newton fails."""
    if first.kind == "grazing":
        assert first.pair is not None
        touch = locate_grazing(arc, first.pair, guess)
        if touch is None:
            return None
        return touch.value, touch.state, touch.floquet_multipliers, touch.unknowns
    located = refine(arc, first.kind, guess)
    if located is None:
        return None
    point, w = located
    return point.value, point.state, point.floquet_multipliers, w


@arguments.typed()
def curve_of(data: Mapping[str, Any] | System, base_dir: Path | None = None) -> Curve:
    """The curve a scenario's ``[curve]`` section asks for (see :func:`curve`)."""
    from vibroimpact.analysis.settings import curve_settings, named_in

    data, base_dir = sections_of(data, base_dir)
    if "curve" not in data:
        raise AnalysisError("data: a [curve] section is needed")
    settings = curve_settings(data["curve"])
    with named_in("curve", settings):
        return curve(
            data,
            settings["kind"],
            settings["parameter"],
            start=settings["start"],
            stop=settings["stop"],
            second=settings["second"],
            second_stop=settings["second_stop"],
            step=settings["step"],
            periods=settings["periods"],
            max_points=settings["max_points"],
            tolerance=settings["tolerance"],
            base_dir=base_dir,
        )


def curve_regions(
    found: Curve, data: Mapping[str, Any] | System, base_dir: Path | None = None
) -> list[tuple[str, float, float]]:
    """The regions the curve bounds, read at its middle point: the orbit shot for a
    little either side of the curve in ``parameter`` (a sixth of the curve's range in
    it, or a twentieth of its value), each side labelled by its stability (and, either
    side of a grazing curve, by whether the orbit strikes the wall). ``(label, second's
    value, parameter's value)`` for each side where an orbit is found."""
    from vibroimpact.analysis.orbits import orbit

    data, base_dir = sections_of(data, base_dir)
    middle = found.points[len(found.points) // 2]
    p, s = middle.values[found.parameter], middle.values[found.second]
    values = [q.values[found.parameter] for q in found.points]
    offset = max(float(np.ptp(values)) / 6, abs(p) / 20, 1e-9)
    regions = []
    for side in (-1.0, 1.0):
        moved = with_parameter(
            with_parameter(data, found.second, s), found.parameter, p + side * offset
        )
        try:
            shot = orbit(runner(moved, base_dir), middle.state, periods=found.periods)
        except (AnalysisError, ValueError):
            continue
        if not shot.converged:
            continue
        label = f"{found.periods}-period orbit " + ("stable" if shot.stable else "unstable")
        if found.first is not None and found.first.pair is not None:
            # Either side of a grazing curve: whether the orbit strikes the wall.
            hit = found.first.pair in struck(runner(moved, base_dir), shot.state, found.periods)
            label += (", strikes " if hit else ", misses ") + found.first.pair
        regions.append((label, s, p + side * offset))
    return regions
