"""Forced-response analyses of 0.2 systems: steady state, frequency response sweeps
and periodic orbits with their Floquet multipliers.

Every analysis runs whole periods ``T`` of the forcing (the common period of its
harmonics, :func:`forcing_period`; the forcing is T-periodic, so a run of whole periods
may restart its clock at 0) on
the core's event-driven kernel with the scenario's method; ``method = "exact"``
(linear structure, rigid pairs, harmonic forcing) is exact between impacts and the
fastest. Peaks are located by the kernel (where a velocity changes sign, or at an
impact), never read off output samples. SI units throughout.
"""

from __future__ import annotations

import copy
import math
import warnings
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from functools import partial
from pathlib import Path
from typing import Any, TypeVar

import numpy as np

from vibroimpact import arguments
from vibroimpact._core import (
    MAX_RECORD_BYTES,
    InvalidInputError,
    PreparedSystem,
    SimulationError,
    _strobe_period,
)
from vibroimpact._core import _forcing_period as _core_forcing_period
from vibroimpact.forcing_limits import check_forcing_period
from vibroimpact.messages import shown
from vibroimpact.model.system import System, sections_of
from vibroimpact.summary import summarised
from vibroimpact.system import (
    _NUMBER,
    _REQ,
    _TEXT,
    _WHOLE,
    PreparedRun,
    _choice,
    _table,
    linear_parts,
    moment_weights,
    point_weights,
    prepare_system,
    split_observed,
    structure_coordinates,
)

_INITIAL = (
    "structure_displacement",
    "structure_velocity",
    "damper_displacement",
    "damper_velocity",
)
_T = TypeVar("_T")

_SECTIONS = ("structure", "damper", "stop", "gravity", "excitation", "initial", "solver", "output")


class AnalysisError(InvalidInputError):
    """An analysis that cannot be set up as asked (a ValueError)."""


def forcing_period(data: Mapping[str, Any]) -> float:
    """The forcing period (s) of a scenario's sections: every excitation a sum of
    harmonics (``"harmonic"``, ``"harmonics"``; 0 Hz terms are constant), the period
    ``1 / f0`` of the highest ``f0`` of which every frequency is a whole multiple (10 and
    15 Hz: 0.2 s). The core's rule, the one studies apply."""
    arguments.sections("data", data)
    parts: list[tuple[str, list[float] | None]] = []
    for excitation in data.get("excitation", ()) or ():
        table = excitation if isinstance(excitation, Mapping) else {}
        signal = str(table.get("signal"))
        given: list[Any]
        if signal == "harmonic":
            given = [table.get("frequency")]
        elif signal == "harmonics":
            given = list(table.get("frequencies") or [])
        else:
            parts.append((signal, None))
            continue
        frequencies = [f for f in given if isinstance(f, int | float) and not isinstance(f, bool)]
        if len(frequencies) != len(given):
            raise AnalysisError(
                f"excitation {len(parts)}: frequencies must be numbers (Hz) for a periodic "
                f"analysis, got {given!r:.60}"
            )
        parts.append((signal, [float(f) for f in frequencies]))
    try:
        return _core_forcing_period(parts)
    except InvalidInputError as err:
        raise AnalysisError(str(err)) from None


def with_parameter(data: Mapping[str, Any], path: str, value: float) -> dict[str, Any]:
    """A deep copy of a scenario's sections with the dotted ``path`` (such as
    ``"excitation.0.frequency"`` or ``"damper.0.clearance"``) set to ``value``."""
    arguments.sections("data", data)
    arguments.text("path", path)
    value = arguments.number("value", value)
    out = copy.deepcopy(dict(data))
    parts = path.split(".")
    if parts[0] not in _SECTIONS or len(parts) < 2:
        raise AnalysisError(
            f"parameter {path!r}: must be a dotted path into a section ({', '.join(_SECTIONS)}),"
            ' such as "excitation.0.frequency"'
        )
    with_parameter_path_check(path, "")
    node: Any = out
    for depth, key in enumerate(parts[:-1]):
        try:
            if isinstance(node, list):
                if not (key.isascii() and key.isdigit()):
                    raise ValueError(key)  # an index counts from 0, never from the end
                node = node[int(key)]
            else:
                if key not in node and depth == 0 and key in ("gravity", "initial", "output"):
                    node[key] = {}
                node = node[key]
        except (KeyError, IndexError, ValueError, TypeError):
            raise AnalysisError(
                f"parameter {path!r}: {'.'.join(parts[: depth + 1])} is not in the scenario"
            ) from None
        if isinstance(node, Mapping) is False and not isinstance(node, list):
            raise AnalysisError(f"parameter {path!r}: {'.'.join(parts[: depth + 1])} is a value")
    if isinstance(node, list):
        raise AnalysisError(f"parameter {path!r}: ends on a list; name an entry's key")
    current = node.get(parts[-1]) if isinstance(node, Mapping) else None
    if isinstance(current, int) and not isinstance(current, bool) and float(value).is_integer():
        # A whole-number key (a cantilever's modes, a seed) stays one: a sweep's
        # values are floats, which its check refused ("got 3.0", user trial).
        value = int(value)
    node[parts[-1]] = value
    return out


def _prepare(data: Mapping[str, Any], base_dir: Path | None) -> PreparedRun:
    # Refused here, naming the section (a KeyError or a TypeError had named nothing).
    if "structure" not in data:
        raise InvalidInputError(
            "[structure] is required: the analyses take a 0.2 scenario (a [structure] "
            "section, its dampers, stops and excitations)"
        )
    if not isinstance(data.get("solver", {}), Mapping):
        raise InvalidInputError(f"[solver] must be a table, got {shown(data['solver'])}")
    solver = dict(data.get("solver", {}))
    solver.setdefault("t_end", 1.0)
    output = data.get("output", {})
    # Of [output], the analyses keep only the points and moments they report.
    followed = {
        key: output[key]
        for key in ("points", "moments")
        if isinstance(output, Mapping) and key in output
    }
    return prepare_system(
        data["structure"],
        damper=data.get("damper", ()),
        stop=data.get("stop", ()),
        gravity=data.get("gravity"),
        excitation=data.get("excitation", ()),
        initial=data.get("initial"),
        solver=solver,
        output=followed,
        base_dir=base_dir,
    )


@dataclass
class Runner:
    """Runs of one checked system from any state over whole forcing periods."""

    prepared: PreparedRun
    period: float
    n: int = 0
    k: int = 0
    runs: int = 0
    _prepared_system: PreparedSystem | None = field(default=None, repr=False)

    def __post_init__(self) -> None:
        self.n = structure_coordinates(self.prepared.spec["structure"])
        self.k = len(self.prepared.spec.get("damper", ()))

    @property
    def points(self) -> np.ndarray:
        """The points ``[output] points`` follows (m along a cantilever, or indices)."""
        return np.asarray(self.prepared.output["points"], dtype=float)

    @property
    def moments(self) -> np.ndarray:
        """Where ``[output] moments`` follows a cantilever's bending moment (m)."""
        return np.asarray(self.prepared.output["moments"], dtype=float)

    def amplitudes(self, recorded: Mapping[str, Any]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The located peaks of a recorded run: of each structure coordinate and of the
        structure at each point (m), and of the bending moment at each of the moments
        (N m)."""
        arguments.instance("recorded", recorded, Mapping, "Runner.periods(..., record=True)")
        return split_observed(np.asarray(recorded["peaks"], dtype=float), self.n, len(self.points))

    def rms(self, recorded: Mapping[str, Any]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The RMS values of a recorded run, as :meth:`amplitudes`."""
        arguments.instance("recorded", recorded, Mapping, "Runner.periods(..., record=True)")
        rms = np.sqrt(np.asarray(recorded["square_integrals"]) / recorded["recorded_time"])
        return split_observed(rms, self.n, len(self.points))

    def initial_state(self) -> np.ndarray:
        """The scenario's ``[initial]`` as a flat state ``(x, v)``."""
        n, k = self.n, self.k
        init = self.prepared.initial
        parts = [np.zeros(n), np.zeros(k), np.zeros(n), np.zeros(k)]
        for slot, key in zip(
            (0, 2, 1, 3),
            (
                "structure_displacement",
                "structure_velocity",
                "damper_displacement",
                "damper_velocity",
            ),
            strict=True,
        ):
            if len(init[key]):
                parts[slot] = np.asarray(init[key], dtype=float)
        return np.concatenate(parts)

    def _run(
        self, state: np.ndarray | None, t_end: float, *, record: bool, strobe: bool
    ) -> dict[str, Any]:
        z = self.initial_state() if state is None else state
        if len(z) != 2 * (self.n + self.k):
            raise AnalysisError(
                f"state: must have {2 * (self.n + self.k)} values (x then v), got {len(z)}"
            )
        try:
            raw = self.system().run(
                np.asarray(z, dtype=float).tolist(),
                t_end,
                record_from=0.0 if record else None,
                strobe_period=self.period if strobe else None,
            )
        except SimulationError as err:
            if "max_rows" not in str(err):
                raise
            # The core's advice (every, history, t_end) is about a run's own keys: an
            # analysis sets the periods.
            raise SimulationError(
                f"{round(t_end / self.period)} forcing periods in one run kept more contacts "
                f"than [solver] max_rows ({str(err).partition(': ')[0]}): settle or record "
                "fewer periods, or raise max_rows"
            ) from None
        self.runs += 1
        return raw

    def system(self) -> PreparedSystem:
        """The core's checked system with its method (made once)."""
        if self._prepared_system is None:
            self._prepared_system = PreparedSystem(
                self.prepared.binding_spec(), **self.prepared.method_arguments()
            )
        return self._prepared_system

    def periods(
        self, state: np.ndarray, count: int, *, record: bool = False, strobe: bool = False
    ) -> dict[str, Any]:
        """Run ``count`` forcing periods from ``state``."""
        state = arguments.state("state", state, 2 * (self.n + self.k))  # type: ignore[assignment]
        check_periods("", "count", whole_count("count", count, 1), 1)
        record, strobe = arguments.flag("record", record), arguments.flag("strobe", strobe)
        return self._periods(state, count, record=record, strobe=strobe)

    def _periods(
        self, state: np.ndarray | None, count: int, *, record: bool = False, strobe: bool = False
    ) -> dict[str, Any]:
        """:meth:`periods` of a state and count already checked (the loops of
        :meth:`map` and of a response recorded period by period)."""
        width = 1 + 2 * (self.n + self.k)
        if strobe and count * width * 8 > MAX_RECORD_BYTES:
            # A state a period: known before the run, as a fixed-step history is.
            raise AnalysisError(
                f"periods: {count} stroboscopic states of {width} values, "
                f"{count * width * 8 / 2**20:.0f} MiB, more than the "
                f"{MAX_RECORD_BYTES >> 20} MiB a run's records may take: settle fewer periods"
            )
        return self._run(state, count * self.period, record=record, strobe=strobe)

    def map(self, state: np.ndarray, count: int) -> np.ndarray:
        """The stroboscopic map over ``count`` periods, run :data:`SETTLE_CHUNK` periods
        at a time: a run keeps its contacts, which settling never reads (ten million
        periods of a bouncing ball had kept 20 million, 1.6 GB, up to the row limit)."""
        check_periods("", "count", whole_count("count", count, 1), 1)
        z = arguments.state("state", state, 2 * (self.n + self.k))
        for start in range(0, count, SETTLE_CHUNK):
            z = np.asarray(
                self._periods(z, min(SETTLE_CHUNK, count - start))["final_state"], dtype=float
            )
        assert z is not None  # count >= 1: the loop ran
        return z

    def shoot(
        self, state: np.ndarray, count: int, tolerance: float, max_iterations: int
    ) -> dict[str, Any]:
        """Newton's shooting over ``count`` periods from ``state``, in the core (see
        :func:`orbit`)."""
        check_periods("", "count", whole_count("count", count, 1), 1)
        if len(state) != 2 * (self.n + self.k):
            raise AnalysisError(
                f"state: must have {2 * (self.n + self.k)} values (x then v), got {len(state)}"
            )
        shot: dict[str, Any] = self.system().shoot(
            [float(v) for v in state],
            count * self.period,
            tolerance=tolerance,
            max_iterations=max_iterations,
            forcing_period=self.period,
        )
        self.runs += int(shot["maps"])
        return shot


def as_runner(run: Runner | System) -> Runner:
    """The analyses' entry: a :class:`~vibroimpact.System` as its :class:`Runner`
    (anything else as it is, for :func:`checked_run` to check)."""
    return runner(run) if isinstance(run, System) else run


def checked_run(run: Any, state: Any) -> np.ndarray | None:
    """``run`` checked as a :class:`Runner` and ``state`` as one of its flat states
    (or None)."""
    arguments.instance("run", run, Runner, "vibroimpact.analyses.runner(sections)")
    return arguments.state("state", state, 2 * (run.n + run.k))


def _floats(name: str, value: Any) -> np.ndarray:
    """An array of numbers (any shape; NaN allowed: a run that failed)."""
    try:
        if value is None or isinstance(value, str | bytes | Mapping):
            raise TypeError
        return np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise AnalysisError(f"{name}: must be an array of numbers, got {shown(value)}") from None


def runner(data: Mapping[str, Any] | System, base_dir: Path | None = None) -> Runner:
    """A :class:`Runner` of a :class:`~vibroimpact.System` or of a scenario's sections
    (as parsed from TOML)."""
    data, base_dir = sections_of(data, base_dir)
    base_dir = arguments.directory("base_dir", base_dir)
    prepared, period = _prepare(data, base_dir), forcing_period(data)
    check_forcing_period(data, period, prepared.solver["max_steps"], base_dir)
    return Runner(prepared, period)


def _impacts(raw: Mapping[str, Any]) -> int:
    kinds = raw["contacts"]["kind"]
    return sum(1 for kind in kinds if kind in ("impact", "compliant"))


def _recorded_by_period(
    run: Runner, state: np.ndarray, count: int
) -> tuple[dict[str, Any], np.ndarray]:
    """``count`` recorded forcing periods from ``state``, run one period at a time:
    the window's record as one run gives it (the largest located peaks, the square
    integrals, time and contacts summed, the final state) and the smallest of the
    periods' located peaks (the spread of a response that does not repeat)."""
    peaks: list[np.ndarray] = []
    squares: Any = 0.0
    time = 0.0
    kinds: list[str] = []
    z = state
    for _ in range(count):
        raw = run._periods(z, 1, record=True)
        peaks.append(np.asarray(raw["peaks"], dtype=float))
        squares = squares + np.asarray(raw["square_integrals"], dtype=float)
        time += float(raw["recorded_time"])
        kinds += list(raw["contacts"]["kind"])
        z = np.asarray(raw["final_state"], dtype=float)
    rows = np.array(peaks)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # a quantity with no peak: NaN
        largest, least = np.nanmax(rows, axis=0), np.nanmin(rows, axis=0)
    merged = {
        "peaks": largest,
        "square_integrals": squares,
        "recorded_time": time,
        "contacts": {"kind": kinds},
        "final_state": z,
    }
    return merged, least


@summarised
@dataclass
class SteadyState:
    """A steady response (SI units): per structure coordinate the located
    ``amplitude`` (largest |displacement|, m) and ``rms`` (m) over the recorded
    periods, and the same of the structure at each of ``[output] points``
    (``point_amplitude``, ``point_rms``); ``impacts_per_period``; ``settled`` and the
    ``period`` (in forcing periods) after which the stroboscopic state repeats, or
    None."""

    settled: bool
    period: int | None
    amplitude: np.ndarray
    rms: np.ndarray
    impacts_per_period: float
    state: np.ndarray
    strobe: np.ndarray = field(repr=False)
    point_amplitude: np.ndarray = field(default_factory=lambda: np.zeros(0))
    point_rms: np.ndarray = field(default_factory=lambda: np.zeros(0))
    #: The bending moment's (N m) at each of ``[output] moments``.
    moment_amplitude: np.ndarray = field(default_factory=lambda: np.zeros(0))
    moment_rms: np.ndarray = field(default_factory=lambda: np.zeros(0))
    #: Where the response did not settle: the smallest of the recorded periods'
    #: located peaks (m; N m for moments) of each coordinate, then of the structure
    #: at each point, then of each moment (``amplitude`` is the largest); empty where
    #: it settled.
    least_period_peak: np.ndarray = field(default_factory=lambda: np.zeros(0))


def steady_state(
    run: Runner | System,
    state: np.ndarray | None = None,
    *,
    settle_periods: int = 200,
    record_periods: int = 50,
    tolerance: float = 1e-6,
    max_period: int = 8,
) -> SteadyState:
    """Run ``settle_periods`` forcing periods from ``state`` (default the scenario's
    ``[initial]``), find the smallest p <= ``max_period`` with the stroboscopic state
    repeating after p periods within ``tolerance`` (relative to the size of the
    motion: each coordinate's state (x, v) counts as the amplitude ``hypot(x, v /
    w)``, w the forcing's angular frequency), then record ``record_periods`` periods,
    rounded up to a whole number of p (impacts counted over part of an orbit differ
    with where the window ends). ``run``: a :class:`Runner` or a
    :class:`~vibroimpact.System`."""
    run = as_runner(run)
    state = checked_run(run, state)
    settle_periods = whole_count("settle_periods", settle_periods, 0)
    record_periods = whole_count("record_periods", record_periods, 1)
    max_period = whole_count("max_period", max_period, 1)
    check_total(("settle_periods", settle_periods), ("record_periods", record_periods))
    arguments.positive("tolerance", tolerance)
    x0 = run.initial_state() if state is None else np.asarray(state, dtype=float)
    period: int | None = None
    strobe = np.zeros((0, len(x0)))
    if settle_periods > 0:
        raw = run.periods(x0, settle_periods, strobe=True)
        strobe = np.asarray(raw["strobe"]).reshape(-1, len(x0))
        x0 = np.asarray(raw["final_state"], dtype=float)
        period = _strobe_period(strobe, run.period, tolerance, max_period)
    if period is not None:
        record_periods = -(-record_periods // period) * period
    least = np.zeros(0)
    if period is None:
        # Not periodic: each period's peak, for the spread of the amplitudes.
        recorded, least = _recorded_by_period(run, x0, record_periods)
    else:
        recorded = run.periods(x0, record_periods, record=True)
    amplitude, point_amplitude, moment_amplitude = run.amplitudes(recorded)
    rms, point_rms, moment_rms = run.rms(recorded)
    return SteadyState(
        settled=period is not None,
        period=period,
        amplitude=amplitude,
        rms=rms,
        impacts_per_period=_impacts(recorded) / record_periods,
        state=np.asarray(recorded["final_state"], dtype=float),
        strobe=strobe,
        point_amplitude=point_amplitude,
        point_rms=point_rms,
        moment_amplitude=moment_amplitude,
        moment_rms=moment_rms,
        least_period_peak=least,
    )


def linear_amplitude(data: Mapping[str, Any], base_dir: Path | None = None) -> np.ndarray:
    """Per structure coordinate, the steady amplitude (m) of the structure alone
    (dampers and stops removed) under the scenario's harmonic excitations, from
    ``(K - w^2 M + i w C) Q = F``, the loads of one frequency summed as phasors: exact
    for one frequency; for several, the sum of their amplitudes (a bound). NaN where a
    rigid-body mode makes it unbounded."""
    return linear_response(data, base_dir)[0]


def linear_response(
    data: Mapping[str, Any], base_dir: Path | None = None, prepared: PreparedRun | None = None
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`linear_amplitude`, and the same of the structure at each of ``[output]
    points`` (m) and of its bending moment at each of ``[output] moments`` (N m):
    ``|w . Q|``, ``w`` the coordinates' weights there (a cantilever's mode shapes, or
    ``E I phi''``), summed over the frequencies as the coordinates' are. ``prepared``:
    the sections already checked (a sweep's runner has them)."""
    arguments.sections("data", data)
    base_dir = arguments.directory("base_dir", base_dir)
    if prepared is not None and not isinstance(prepared, PreparedRun):
        raise InvalidInputError(f"prepared: must be a PreparedRun or None, got {shown(prepared)}")
    prepared = prepared or _prepare(data, base_dir)
    parts = linear_parts(
        data["structure"], excitation=data.get("excitation", ()), base_dir=base_dir
    )
    n = parts["n"]
    beam = prepared.spec["structure"]
    weights = np.array(
        [point_weights(beam, at) for at in prepared.output["points"]]
        + [moment_weights(beam, at) for at in prepared.output["moments"]]
    ).reshape(-1, n)
    p = len(prepared.output["points"])
    m, k, c = parts["mass"], parts["stiffness"], parts["damping"]
    # Loads of one frequency add as phasors (two equal loads in quadrature are
    # sqrt 2 of one, in opposition nothing); the frequencies' amplitudes add.
    phasors: dict[float, np.ndarray] = {}
    for h in parts["harmonics"]:
        force = h["amplitude"] * np.exp(1j * h["phase"]) * np.asarray(h["shape"])
        phasors[h["omega"]] = phasors.get(h["omega"], 0) + force
    total, at_points = np.zeros(n), np.zeros(len(weights))
    for w, force in phasors.items():
        matrix = k - w * w * m + 1j * w * c
        try:
            q = np.linalg.solve(matrix, force)
        except np.linalg.LinAlgError:
            return np.full(n, np.nan), np.full(p, np.nan), np.full(len(weights) - p, np.nan)
        total += np.abs(q)
        at_points += np.abs(weights @ q[:n])
    return total, at_points[:p], at_points[p:]


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


#: The most values a ``[sweep]`` may step through (``count``), or a ``[continuation]``
#: find (``max_points``): each is a point of the result kept in memory and hundreds of
#: forcing periods of computing.
MAX_POINTS = 100_000
#: The most starts of ``[basins]`` (``x.count`` times ``y.count``).
MAX_STARTS = 1_000_000
#: The most forcing periods one run of an analysis may settle or record: with a few
#: impacts and tens of steps a period that is already minutes of computing, and every
#: kept impact is memory; a longer run is a typo (1e12 for 1e2), refused before it starts.
MAX_PERIODS = 10_000_000
arguments.WHOLE_RANGES.update(
    settle_periods=(0, MAX_PERIODS),
    record_periods=(1, MAX_PERIODS),
    periods=(1, MAX_PERIODS),
    orbit_periods=(1, MAX_PERIODS),
    max_points=(2, MAX_POINTS),
)
arguments.WHOLE_RANGES["[sweep] count"] = (1, MAX_POINTS)


def whole_count(name: str, value: Any, low: int) -> int:
    """``value`` as a Python int when it is a whole number >= ``low`` (an int or a
    NumPy integer, never a boolean); else :class:`AnalysisError` naming ``name``."""
    if isinstance(value, np.integer):
        value = int(value)
    if not isinstance(value, int) or isinstance(value, bool) or value < low:
        raise AnalysisError(f"{name}: must be a whole number >= {low}, got {shown(value)}")
    return value


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


#: The forcing periods a long recording's first stretch runs to estimate its contacts
#: (:func:`check_kept`); only recordings of ten times as many are estimated.
PROBE_PERIODS = 1000


def check_kept(run: Runner, state: np.ndarray, count: int, name: str) -> None:
    """Refuse up front a recording of ``count`` periods from ``state`` whose contacts,
    at the rate of its first :data:`PROBE_PERIODS`, would pass ``[solver] max_rows``
    (``poincare --settle 0 --periods 10000000`` of a bouncing ball had run 15 s into
    1.2 GB before the row limit stopped it). ``name`` is the count's name."""
    if count < 10 * PROBE_PERIODS:
        return
    seen = len(run.periods(state, PROBE_PERIODS)["contacts"]["onset"])
    expected = seen * (count / PROBE_PERIODS)
    limit = run.prepared.solver["max_rows"]
    if expected > limit:
        raise AnalysisError(
            f"{name} {count}: would keep about {expected:.3g} contacts ({seen / PROBE_PERIODS:g}"
            f" a period over the first {PROBE_PERIODS}), more than [solver] max_rows ({limit});"
            f" record at most {int(limit / seen * PROBE_PERIODS)} periods, or raise max_rows"
        )


#: The forcing periods one run of a settling map covers (:meth:`Runner.map`): its
#: contacts, a few per period, stay well within a run's rows.
SETTLE_CHUNK = 100_000


def check_periods(where: str, key: str, value: int, low: int) -> None:
    """``value`` forcing periods must be a whole number in [``low``, MAX_PERIODS]; the
    error names ``where`` (``"[sweep] "``, ``"--settle"``...) and ``key``."""
    if not low <= value <= MAX_PERIODS:
        raise AnalysisError(
            f"{where}{key}: must be >= {low} and at most {MAX_PERIODS} forcing periods, got {value}"
        )


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
    the stroboscopic ``tolerance`` of settling, and for bifurcation ``sample`` (see
    :data:`BIFURCATION_SAMPLES`) and ``pair`` (whose impacts it samples)."""
    out = _table("[sweep] ", table, _SWEEP)
    _choice("[sweep] ", "direction", out["direction"], _DIRECTIONS)
    _choice("[sweep] ", "sample", out["sample"], tuple(BIFURCATION_SAMPLES))
    _choice("[sweep] ", "spacing", out["spacing"], _SPACINGS)
    if out["count"] < 1:
        raise AnalysisError(f"[sweep] count: must be >= 1, got {out['count']}")
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
    return out


_CONTINUATION = {
    "parameter": (_TEXT, _REQ),
    "stop": (_NUMBER, _REQ),
    "periods": (_WHOLE, 1),
    "step": (_NUMBER, None),
    "max_points": (_WHOLE, 200),
    "tolerance": (_NUMBER, 1e-9),
}


def continuation_settings(table: Any) -> dict[str, Any]:
    """The ``[continuation]`` section checked, with its defaults: ``parameter`` (a
    dotted path, continued from the scenario's value), ``stop``, ``periods`` (K),
    ``step`` (about, in the parameter's unit), ``max_points``, ``tolerance``."""
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
        checked = _table(f"[basins] {axis}.", table[axis], _AXIS)
        name, _, index = checked["state"].partition(".")
        if name not in _STATE_KEYS or not (index.isascii() and index.isdigit()):
            raise AnalysisError(
                f"[basins] {axis}.state: must be one of {', '.join(_STATE_KEYS)} with an "
                f'index, such as "structure_displacement.0", got {checked["state"]!r}'
            )
        if checked["count"] < 1:
            raise AnalysisError(f"[basins] {axis}.count: must be >= 1, got {checked['count']}")
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
    check_total(
        ("[basins] settle_periods", out["settle_periods"]),
        ("record_periods", out["record_periods"]),
    )
    return out


def state_index(path: str, n: int, k: int) -> int:
    """The index in the flat state ``(x, v)`` of ``"structure_velocity.0"`` etc."""
    arguments.text("path", path)
    n, k = whole_count("n", n, 0), whole_count("k", k, 0)
    name, _, index = path.partition(".")
    d = n + k
    places = {
        "structure_displacement": (n, 0),
        "damper_displacement": (k, n),
        "structure_velocity": (n, d),
        "damper_velocity": (k, d + n),
    }
    if name not in places or not (index.isascii() and index.isdigit()):
        raise AnalysisError(
            f"path: must be one of {', '.join(places)} and an index from 0 (such as "
            f'"structure_velocity.0"), got {path!r}'
        )
    i = int(index)
    size, offset = places[name]
    if i >= size:
        raise AnalysisError(f"{path}: must index one of the system's {size} {name} values (from 0)")
    return offset + i


def with_parameter_path_check(path: str, section: str = "[sweep]") -> None:
    """Refuse a ``parameter`` that is not a dotted path into a section, or whose
    index is not a whole number from 0 (``-1`` would count from the end)."""
    parts = path.split(".")
    where = f"{section} parameter" if section else f"parameter {path!r}"
    if parts[0] not in _SECTIONS or len(parts) < 2 or "" in parts:
        raise AnalysisError(
            f"{where}: must be a dotted path into a section "
            f'({", ".join(_SECTIONS)}), such as "excitation.0.frequency", got {path!r}'
        )
    for part in parts[1:]:
        if part.lstrip("+-").isdigit() and not (part.isascii() and part.isdigit()):
            raise AnalysisError(f"{where}: {part!r} in {path!r}: an index is a whole number from 0")
    if path == "solver.t_end" or parts[0] == "output":
        # The analyses run whole forcing periods and keep what they need: these
        # keys would change nothing, point after point.
        raise AnalysisError(
            f"{where}: {path!r} is not used by the analyses (they run settle and record "
            "periods, not [solver] t_end, and of [output] follow its points only); choose a "
            "parameter of the system"
        )


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


def sweep(
    data: Mapping[str, Any] | System,
    parameter: str,
    values: Sequence[float] | np.ndarray,
    *,
    direction: str = "up",
    settle_periods: int = 200,
    record_periods: int = 50,
    tolerance: float = 1e-6,
    base_dir: Path | None = None,
    progress: Callable[[int, int], None] | None = None,
) -> list[SweepPoint]:
    """A stepped sweep of ``parameter`` (a dotted path into the scenario's sections)
    over ``values`` (sorted: ``"up"`` is towards larger values whatever their order as
    given), ``"up"``, ``"down"`` or ``"both"`` (up, then
    down from where up ended), each point starting from the last one's state, so
    that jumps and hysteresis show (from ``[initial]`` where that state is not
    admissible: see :func:`from_carried`). A point whose run fails is reported with
    its error (and the next starts from the last good state). ``data``: a
    :class:`~vibroimpact.System` or a scenario's sections."""
    data, base_dir = sections_of(data, base_dir)
    arguments.text("parameter", parameter)
    values = sorted(arguments.numbers("values", values).tolist())
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
                )
            )
            if progress is not None:
                progress(len(points), total)
    return points


@summarised
@dataclass
class Orbit:
    """A periodic orbit of ``periods`` forcing periods found by shooting."""

    converged: bool
    state: np.ndarray
    floquet_multipliers: np.ndarray
    stable: bool
    impacts_per_period: float
    amplitude: np.ndarray
    iterations: int
    residual: float
    monodromy: np.ndarray = field(repr=False)
    #: The largest |displacement| (m) on the orbit at each of ``[output] points``, and
    #: |bending moment| (N m) at each of ``[output] moments``.
    point_amplitude: np.ndarray = field(default_factory=lambda: np.zeros(0))
    moment_amplitude: np.ndarray = field(default_factory=lambda: np.zeros(0))

    def arrays(self, n: int, k: int) -> dict[str, list[float]]:
        """The state as the four arrays of ``[initial]``."""
        d = n + k
        s = self.state
        return {
            "structure_displacement": [float(v) for v in s[:n]],
            "structure_velocity": [float(v) for v in s[d : d + n]],
            "damper_displacement": [float(v) for v in s[n:d]],
            "damper_velocity": [float(v) for v in s[d + n :]],
        }


def orbit(
    run: Runner | System,
    state: np.ndarray | None = None,
    *,
    periods: int = 1,
    tolerance: float = 1e-10,
    max_iterations: int = 40,
) -> Orbit:
    """Shoot for an orbit of ``periods`` forcing periods from ``state`` (default the
    scenario's ``[initial]``): Newton's method on ``P(z) - z = 0``, ``P`` the
    stroboscopic map over ``periods`` periods, its Jacobian by central finite
    differences (across impacts: the saltation is in the differences). At the orbit
    the Jacobian is the monodromy matrix; its eigenvalues are the Floquet multipliers
    and the orbit is stable when all lie inside the unit circle. Newton steps that
    would start inside a wall are halved. ``run``: a :class:`Runner` or a
    :class:`~vibroimpact.System`."""
    run = as_runner(run)
    state = checked_run(run, state)
    periods = whole_count("periods", periods, 1)
    arguments.positive("tolerance", tolerance)
    max_iterations = whole_count("max_iterations", max_iterations, 1)
    z = run.initial_state() if state is None else np.asarray(state, dtype=float)
    shot = run.shoot(z, periods, tolerance, max_iterations)
    size = len(z)
    z = np.asarray(shot["state"], dtype=float)
    jac = np.asarray(shot["monodromy"], dtype=float).reshape(size, size)
    converged = bool(shot["converged"])
    iterations = int(shot["iterations"])
    residual = float(shot["residual"])
    multipliers = np.linalg.eigvals(jac)
    recorded = run.periods(z, periods, record=True)
    amplitude, point_amplitude, moment_amplitude = run.amplitudes(recorded)
    return Orbit(
        converged=converged,
        state=z,
        floquet_multipliers=multipliers,
        stable=bool(converged and np.all(np.abs(multipliers) < 1.0)),
        impacts_per_period=_impacts(recorded) / periods,
        amplitude=amplitude,
        iterations=iterations,
        residual=residual,
        monodromy=jac,
        point_amplitude=point_amplitude,
        moment_amplitude=moment_amplitude,
    )


#: Sections of analyses, checked when a scenario is read.
SETTINGS: dict[str, Callable[[Any], dict[str, Any]]] = {
    "sweep": sweep_settings,
    "continuation": continuation_settings,
    "basins": basins_settings,
}
