"""Poincare sections, bifurcation diagrams and basins of attraction of forced 0.2
systems, built on the stroboscopic states and the located impacts of the core's
runs (see :mod:`vibroimpact.analysis`). SI units throughout.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from functools import partial
from pathlib import Path
from typing import Any

import numpy as np

from vibroimpact import arguments
from vibroimpact._core import MAX_RECORD_BYTES, InvalidInputError
from vibroimpact.analysis.limits import (
    MAX_PERIODS,
    MAX_STARTS,
    AnalysisError,
    check_total,
    whole_count,
)
from vibroimpact.analysis.parameters import state_index, with_parameter
from vibroimpact.analysis.runs import (
    Runner,
    as_runner,
    begun,
    check_kept,
    checked_run,
    failed_everywhere,
    runner,
)
from vibroimpact.analysis.settings import BIFURCATION_SAMPLES, chosen_settings
from vibroimpact.analysis.steady import steady_state
from vibroimpact.analysis.sweeps import from_carried
from vibroimpact.messages import shown
from vibroimpact.model.system import System, sections_of
from vibroimpact.summary import summarised


@summarised
@dataclass
class Section:
    """A Poincare section: ``strobe`` rows of the state ``(x, v)`` at each forcing
    period (after settling), and at each impact its phase in the forcing period
    (``impact_phase``, rad in [0, 2 pi)), its ``impact_speed`` (m/s) and the
    ``impact_pair`` it belongs to."""

    strobe: np.ndarray
    impact_phase: np.ndarray
    impact_speed: np.ndarray
    impact_pair: list[str]


@arguments.typed()
def poincare(
    run: Runner | System | Mapping[str, Any],
    state: np.ndarray | None = None,
    *,
    settle_periods: int = 200,
    periods: int = 500,
) -> Section:
    """Settle ``settle_periods`` forcing periods, then sample ``periods`` more: the
    stroboscopic section and the impact section. ``run``: a :class:`Runner` or a
    :class:`~vibroimpact.System`."""
    run = as_runner(run)
    state = checked_run(run, state)
    settle_periods = whole_count("settle_periods", settle_periods, 0)
    periods = whole_count("periods", periods, 1, MAX_PERIODS)
    check_total(("settle_periods", settle_periods), ("periods", periods))
    z = run.initial_state() if state is None else np.asarray(state, dtype=float)
    if settle_periods:
        z = run.map(z, settle_periods)
    check_kept(run, z, periods, "periods")
    raw = run.periods(z, periods, strobe=True)
    contacts = raw["contacts"]
    onset = np.asarray(contacts["onset"])
    kinds = list(contacts["kind"])
    impacts = np.array([kind == "impact" for kind in kinds], dtype=bool)
    pairs = list(raw["pairs"])
    phase = (2 * math.pi * onset[impacts] / run.period) % (2 * math.pi)
    return Section(
        strobe=np.asarray(raw["strobe"]).reshape(-1, len(z)),
        impact_phase=phase,
        impact_speed=np.asarray(contacts["approach_speed"])[impacts],
        impact_pair=[pairs[p] for p, hit in zip(contacts["pair"], impacts, strict=True) if hit],
    )


@summarised
@dataclass
class BifurcationPoint:
    """The sampled stroboscopic states at one parameter value, and the ``samples``
    of the chosen quantity (see :data:`BIFURCATION_SAMPLES`): ``strobe[:, 0]`` for
    ``"displacement"``, else one value per impact of the chosen pair."""

    value: float
    direction: str
    strobe: np.ndarray
    error: str | None = None
    samples: np.ndarray = field(default_factory=lambda: np.zeros(0))


def _impact_samples(
    raw: Mapping[str, Any], sample: str, pair: str | None, period: float
) -> np.ndarray:
    """The approach speed (m/s) or phase (rad) of each impact of ``pair`` (every
    pair's where None) in a run that starts at a multiple of the forcing period."""
    contacts = raw["contacts"]
    names = list(raw["pairs"])
    chosen = np.array(
        [
            new and kind in ("impact", "compliant") and (pair is None or names[index] == pair)
            for kind, index, new in zip(
                contacts["kind"], contacts["pair"], begun(contacts), strict=True
            )
        ],
        dtype=bool,
    )
    if sample == "impact-velocity":
        return np.asarray(np.asarray(contacts["approach_speed"], dtype=float)[chosen])
    onset = np.asarray(contacts["onset"], dtype=float)[chosen]
    return np.asarray((2 * math.pi * onset / period) % (2 * math.pi))


def _check_pair(run: Runner, sample: str, pair: str | None) -> None:
    if pair is not None:
        spec = run.prepared.spec
        names = [
            f"{kind} {j}"
            for kind in ("damper", "stop", "collision")
            for j in range(len(spec.get(kind, ())))
        ]
        if pair not in names:
            raise AnalysisError(
                f"pair: must name one of the scenario's pairs ({', '.join(names) or 'none'}), "
                f"got {shown(pair)}"
            )
        if sample == "displacement":
            raise AnalysisError('pair: only for sample = "impact-velocity" or "impact-phase"')


def _sampled(
    run: Runner, settle_periods: int, sample_periods: int, start: np.ndarray | None
) -> dict[str, Any]:
    """The run of ``sample_periods`` periods, with the strobe, after settling for
    ``settle_periods`` from ``start`` (``None``: the scenario's ``[initial]``)."""
    z = run.initial_state() if start is None else start
    if settle_periods:
        z = run.map(z, settle_periods)
    return run.periods(z, sample_periods, strobe=True)


@arguments.typed()
def bifurcation(
    data: Mapping[str, Any] | System,
    parameter: str,
    values: Sequence[float] | np.ndarray,
    *,
    direction: str = "up",
    settle_periods: int = 200,
    sample_periods: int = 50,
    sample: str = "displacement",
    pair: str | None = None,
    base_dir: Path | None = None,
    progress: Callable[[int, int], None] | None = None,
) -> list[BifurcationPoint]:
    """A bifurcation diagram: for each value of ``parameter`` (a dotted path), in
    increasing order (``"up"``; the values sorted, as :func:`~vibroimpact.sweep` sorts
    them), decreasing (``"down"``) or both, settle from the last
    point's state (see :func:`~vibroimpact.analysis.from_carried`), keep
    ``sample_periods`` stroboscopic states and sample ``sample`` over those periods:
    ``"displacement"`` (structure coordinate 0's stroboscopic displacement, m),
    ``"impact-velocity"`` (each impact's approach speed, m/s) or ``"impact-phase"``
    (each impact's ``w t`` modulo 2 pi, rad), the impacts of ``pair`` (``"stop 0"``,
    ``"damper 1"``; every pair's where None). ``data``: a :class:`~vibroimpact.System`
    or a scenario's sections."""
    data, base_dir = sections_of(data, base_dir)
    arguments.text("parameter", parameter)
    values = arguments.numbers("values", values)
    base_dir = arguments.directory("base_dir", base_dir)
    arguments.callback("progress", progress)
    settle_periods = whole_count("settle_periods", settle_periods, 0)
    sample_periods = whole_count("sample_periods", sample_periods, 1)
    check_total(("settle_periods", settle_periods), ("sample_periods", sample_periods))
    if not isinstance(sample, str) or sample not in BIFURCATION_SAMPLES:
        raise AnalysisError(
            "sample: must be one of "
            + ", ".join(f'"{name}"' for name in BIFURCATION_SAMPLES)
            + f", got {shown(sample)}"
        )
    legs = _legs(direction, [float(v) for v in values])
    points: list[BifurcationPoint] = []
    state: np.ndarray | None = None
    total = sum(len(v) for _, v in legs)
    if total:
        # Every point's samples are kept: refused before any run where they would
        # pass a run's memory limit (1e5 points of 1e6 periods had grown to an abort).
        first = _runner_at(data, parameter, legs[0][1][0], base_dir)
        _check_pair(first, sample, pair)
        width = len(first.initial_state())
        kept = 8.0 * total * sample_periods * width
        if kept > MAX_RECORD_BYTES:
            raise AnalysisError(
                f"sample_periods: {total} points of {sample_periods} periods would keep "
                f"{kept / 2**20:.0f} MiB of samples, more than the {MAX_RECORD_BYTES >> 20} "
                "MiB a run's records may take: sample fewer periods or fewer values"
            )
    for leg, leg_values in legs:
        for value in leg_values:
            run = _runner_at(data, parameter, value, base_dir)
            try:
                raw = from_carried(partial(_sampled, run, settle_periods, sample_periods), state)
            except InvalidInputError:
                raise
            except Exception as err:  # a run that cannot complete: recorded
                points.append(BifurcationPoint(value, leg, np.zeros((0, 0)), str(err)))
            else:
                state = np.asarray(raw["final_state"], dtype=float)
                strobe = np.asarray(raw["strobe"]).reshape(-1, len(state))
                samples = (
                    strobe[:, 0]
                    if sample == "displacement"
                    else _impact_samples(raw, sample, pair, run.period)
                )
                points.append(BifurcationPoint(value, leg, strobe, samples=samples))
            if progress is not None:
                progress(len(points), total)
    # No point of the diagram: the command had printed "0 distinct ... of 0" for each.
    refusal = failed_everywhere("bifurcation", parameter, points)
    if refusal is not None:
        raise refusal
    return points


@summarised
@dataclass
class Basins:
    """Basins of attraction over a grid of two initial values: ``labels[i, j]`` is
    the attractor reached from ``(first[i], second[j])``, an index into
    ``attractors`` (each with its ``period``, ``impacts_per_period``, ``amplitude``);
    -1 where the run did not settle, -2 where it failed, -3 where the start is not
    admissible (a pair inside its wall)."""

    first: np.ndarray
    second: np.ndarray
    labels: np.ndarray
    attractors: list[dict[str, Any]]


def _axis(name: str, value: Any) -> tuple[int, np.ndarray]:
    """An axis of :func:`basins`: a pair (an index into the flat state, its values)."""
    if isinstance(value, str | bytes | Mapping) or not isinstance(value, Sequence):
        raise AnalysisError(
            f"{name}: must be a pair (an index into the state, its values), got {shown(value)}"
        )
    if len(value) != 2:
        raise AnalysisError(
            f"{name}: must be a pair (an index into the state, its values), got {len(value)} items"
        )
    index = whole_count(f"{name}[0] (the state index)", value[0], 0)
    return index, arguments.numbers(f"{name}[1] (the values)", value[1])


def table_axes(
    settings: Mapping[str, Any], run: Runner
) -> tuple[tuple[int, np.ndarray], tuple[int, np.ndarray]]:
    """:func:`basins`'s ``first`` and ``second`` from a checked ``[basins]`` table's
    ``x`` and ``y`` (``{state, start, stop, count}``) for ``run``'s state."""
    axes = []
    for axis in ("x", "y"):
        a = settings[axis]
        try:
            index = state_index(a["state"], run.n, run.k)
        except AnalysisError as err:
            raise AnalysisError(f"[basins] {axis}.state: {err}") from None
        axes.append((index, np.linspace(a["start"], a["stop"], a["count"])))
    return axes[0], axes[1]


@arguments.typed()
def basins(
    run: Runner | System | Mapping[str, Any],
    first: tuple[int, np.ndarray] | None = None,
    second: tuple[int, np.ndarray] | None = None,
    *,
    state: np.ndarray | None = None,
    settle_periods: int | None = None,
    record_periods: int | None = None,
    tolerance: float | None = None,
    progress: Callable[[int, int], None] | None = None,
) -> Basins:
    """For each pair of values of two state components (``(index into the flat
    state (x, v), values)``), starting from ``state`` (default ``[initial]``) with
    those two set, find the steady state and group the results into attractors:
    same period, same impacts per period and amplitudes within 1e-3 relative.
    ``run``: a :class:`Runner` or a :class:`~vibroimpact.System`. Without ``first``
    and ``second``, the ``[basins]`` table of a System (one loaded from a scenario
    keeps it) gives them (its ``x`` and ``y``), and every setting not given here
    (``settle_periods`` 200, ``record_periods`` 20, ``tolerance`` 1e-6 where neither
    says)."""
    data = sections_of(run)[0] if isinstance(run, (System, Mapping)) else {}
    given = {
        "first": first,
        "second": second,
        "settle_periods": settle_periods,
        "record_periods": record_periods,
        "tolerance": tolerance,
        # The table's axes (where it gives them): what first and second are made of.
        **dict.fromkeys(("x", "y")),
    }
    chosen = chosen_settings(data, "basins", given, ("first", "second"))
    run = as_runner(run)
    if first is None or second is None:
        first, second = table_axes(chosen, run)
    settle_periods, record_periods = chosen["settle_periods"], chosen["record_periods"]
    tolerance = chosen["tolerance"]
    # Checked here: each start's steady state would take a bad count for a start
    # inside a wall (every label -3).
    state = checked_run(run, state)
    first, second = _axis("first", first), _axis("second", second)
    arguments.callback("progress", progress)
    settle_periods = whole_count("settle_periods", settle_periods, 0)
    record_periods = whole_count("record_periods", record_periods, 1)
    check_total(("settle_periods", settle_periods), ("record_periods", record_periods))
    arguments.positive("tolerance", tolerance)
    base = run.initial_state() if state is None else np.asarray(state, dtype=float)
    for name, (index, _) in (("first", first), ("second", second)):
        if not 0 <= index < len(base):
            raise AnalysisError(f"{name}: a state index in [0, {len(base)}), got {index}")
    if first[0] == second[0]:
        # The second would overwrite the first at every start: a grid over one entry.
        raise AnalysisError(
            f"second[0] (the state index): must differ from first's, both {first[0]}: the "
            "grid is over two entries of the state"
        )
    for name, (_, values) in (("first", first), ("second", second)):
        if len(values) == 0:
            raise AnalysisError(f"{name}[1] (the values): must hold at least one value, got none")
    if len(first[1]) * len(second[1]) > MAX_STARTS:
        raise AnalysisError(
            f"first, second: {len(first[1])} x {len(second[1])} starts, more than "
            f"{MAX_STARTS}; give fewer values"
        )
    a_values, b_values = np.asarray(first[1], float), np.asarray(second[1], float)
    labels = np.full((len(a_values), len(b_values)), -2, dtype=int)
    attractors: list[dict[str, Any]] = []
    done = 0
    for i, a in enumerate(a_values):
        for j, b in enumerate(b_values):
            z = base.copy()
            z[first[0]] = a
            z[second[0]] = b
            try:
                result = steady_state(
                    run,
                    z,
                    settle_periods=settle_periods,
                    record_periods=record_periods,
                    tolerance=tolerance,
                )
            except InvalidInputError:
                labels[i, j] = -3  # a start inside a wall
            except Exception:  # a run that cannot complete
                labels[i, j] = -2
            else:
                if not result.settled:
                    labels[i, j] = -1
                else:
                    labels[i, j] = _attractor(attractors, result)
            done += 1
            if progress is not None:
                progress(done, labels.size)
    return Basins(a_values, b_values, labels, attractors)


def _attractor(attractors: list[dict[str, Any]], result: Any) -> int:
    for index, known in enumerate(attractors):
        if (
            known["period"] == result.period
            and known["impacts_per_period"] == result.impacts_per_period
            and np.allclose(known["amplitude"], result.amplitude, rtol=1e-3, atol=0.0)
        ):
            return index
    attractors.append(
        {
            "period": result.period,
            "impacts_per_period": result.impacts_per_period,
            "amplitude": [float(a) for a in result.amplitude],
        }
    )
    return len(attractors) - 1


def _runner_at(
    data: Mapping[str, Any], parameter: str, value: float, base_dir: Path | None
) -> Runner:
    try:
        return runner(with_parameter(data, parameter, value), base_dir)
    except InvalidInputError as err:
        raise AnalysisError(f"{parameter} = {value:g}: {err}") from None


def _legs(direction: str, values: list[float]) -> list[tuple[str, list[float]]]:
    if direction not in ("up", "down", "both"):
        raise AnalysisError(f'direction must be one of "up", "down", "both", got "{direction}"')
    # Sorted, as a sweep sorts them: "up" is towards larger values whatever the order
    # given (a leg given 12, 11, 11.5 ran in that order and was labelled "up").
    values = sorted(values)
    legs: list[tuple[str, list[float]]] = []
    if direction in ("up", "both"):
        legs.append(("up", values))
    if direction in ("down", "both"):
        legs.append(("down", values[::-1]))
    return legs
