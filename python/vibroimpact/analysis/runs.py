"""Runs of one checked 0.2 system from any state over whole forcing periods (the
:class:`Runner` every analysis takes), and the up-front checks of what a run would keep."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from vibroimpact import arguments
from vibroimpact._core import (
    MAX_RECORD_BYTES,
    InvalidInputError,
    PreparedSystem,
    SimulationError,
    interactions,
    tangent_map,
)
from vibroimpact.analysis.limits import MAX_PERIODS, AnalysisError, check_periods, whole_count
from vibroimpact.analysis.parameters import forcing_period
from vibroimpact.model.system import System, sections_of
from vibroimpact.system import (
    PreparedRun,
    prepare_system,
    split_observed,
    structure_coordinates,
)
from vibroimpact.system.schema import not_a_table


def _prepare(data: Mapping[str, Any], base_dir: Path | None) -> PreparedRun:
    # Refused here, naming the section (a KeyError or a TypeError had named nothing).
    if "structure" not in data:
        raise InvalidInputError(
            "[structure] is required: the analyses take a system on a structure (a "
            "[structure] section, its dampers, stops and excitations)"
        )
    if not isinstance(data.get("solver", {}), Mapping):
        raise InvalidInputError(not_a_table("solver", data["solver"]))
    solver = dict(data.get("solver", {}))
    solver.setdefault("t_end", 1.0)
    output = data.get("output", {})
    # Of [output], the analyses keep only the points and moments they report; their
    # runs keep no history, so t_end / dt rows are no limit of theirs (an unforced
    # lyapunov over 1e5 s had been refused for a history it never keeps).
    followed = {
        key: output[key]
        for key in ("points", "moments")
        if isinstance(output, Mapping) and key in output
    } | {"history": False}
    return prepare_system(
        data["structure"],
        damper=data.get("damper", ()),
        stop=data.get("stop", ()),
        collision=data.get("collision", ()),
        friction=data.get("friction", ()),
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
    _walls: list[dict[str, Any]] | None = field(default=None, repr=False)

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
        z = np.asarray(z, dtype=float)
        try:
            raw = self.system().run(
                z.tolist(),
                t_end,
                record_from=0.0 if record else None,
                strobe_period=self.period if strobe else None,
                carried=carried_from(z, self.interaction_count()),
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
        self._carry(raw)
        return raw

    def _carry(self, raw: Mapping[str, Any]) -> None:
        """Keep the contacts ``raw`` left open (onsets relative to its end), for a run
        from its final state."""
        carried = list(raw["open_contacts"])
        if any(c is not None for c in carried):
            if len(_CARRIED) >= CARRIED_STATES:
                del _CARRIED[next(iter(_CARRIED))]
            final = np.asarray(raw["final_state"], dtype=float).tobytes()
            _CARRIED[final, len(carried)] = carried

    def walls(self) -> list[dict[str, Any]]:
        """The system's interactions (a damper's two walls, each stop, collision and
        friction element), as the compiled core's ``interactions`` gives them (made
        once)."""
        if self._walls is None:
            self._walls = interactions(self.system())
        return self._walls

    def interaction_count(self) -> int:
        """The length of the system's runs' ``open_contacts``: one per interaction."""
        return len(self.walls())

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
                f"{MAX_RECORD_BYTES >> 20} MiB a run's records may take: settle or record "
                "fewer periods"
            )
        return self._run(state, count * self.period, record=record, strobe=strobe)

    def map(self, state: np.ndarray, count: int) -> np.ndarray:
        """The stroboscopic map over ``count`` periods, run ``SETTLE_CHUNK`` periods
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

    def tangent(
        self,
        state: np.ndarray,
        t_end: float,
        parameters: Sequence[tuple[Runner, Runner, float]] = (),
    ) -> dict[str, Any]:
        """The tangent map of a run of ``t_end`` s from ``state``: ``state`` (the
        end's), ``rate`` (its time derivative there), ``matrix`` (d end state / d start
        state), ``impacts`` and ``grazings`` (the compiled core's ``tangent_map``); and
        ``parameters``, the derivatives of the end state by each parameter of
        ``parameters`` (one column each, at fixed ``t_end``), each given as the
        runners of the system made at ``p + delta`` and ``p - delta`` (or at ``p`` and
        ``p +- 2 delta``, one-sided at a parameter's bound), and ``delta``:
        carried by the tangent flow beside the map (the forward sensitivity
        equations, the rates' and gaps' own quotients between the two systems, see
        ``core::analysis::tangent::parameters``)."""
        z = arguments.state("state", state, 2 * (self.n + self.k))
        assert z is not None
        t_end = arguments.positive("t_end", t_end)
        if t_end > MAX_PERIODS * self.period:
            # As the analyses' periods are bounded (1e9 s of a bouncing ball ran for hours;
            # 1e12 s stopped as a chattering no run of it has).
            raise AnalysisError(
                f"t_end: {t_end:.6g} s is {t_end / self.period:.3g} forcing periods, more "
                f"than the {MAX_PERIODS} a run of an analysis may take"
            )
        shifted = [(up.system(), down.system(), float(delta)) for up, down, delta in parameters]
        raw = tangent_map(self.system(), [float(v) for v in z], float(t_end), shifted)
        size = len(z)
        raw["matrix"] = np.asarray(raw["matrix"], dtype=float).reshape(size, size)
        raw["parameters"] = np.asarray(raw["parameters"], dtype=float).reshape(size, len(shifted))
        self.runs += 1
        return raw

    def shoot(
        self,
        state: np.ndarray,
        count: int,
        tolerance: float,
        max_iterations: int,
        jacobian: str = "differences",
    ) -> dict[str, Any]:
        """Newton's shooting over ``count`` periods from ``state``, in the core (see
        :func:`orbit`), its Jacobian by the tangent flow (``jacobian = "tangent"``) or
        central differences."""
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
            jacobian=jacobian,
        )
        self.runs += int(shot["maps"])
        return shot


def state_arrays(state: np.ndarray, n: int, k: int) -> dict[str, list[float]]:
    """A flat state (``n`` structure coordinates then ``k`` dampers; displacements,
    then velocities) as the four arrays of ``[initial]``, SI."""
    d = n + k
    return {
        "structure_displacement": [float(v) for v in state[:n]],
        "structure_velocity": [float(v) for v in state[d : d + n]],
        "damper_displacement": [float(v) for v in state[n:d]],
        "damper_velocity": [float(v) for v in state[d + n :]],
    }


def failed_everywhere(
    command: str, parameter: str, points: Sequence[Any]
) -> SimulationError | None:
    """The error of ``command``'s map of ``parameter`` whose run failed at every one of
    its ``points`` (each with ``value`` and ``error``): nothing to show, an error rather
    than a map of nothing. None where any point ran."""
    failed = [point for point in points if point.error is not None]
    if not points or len(failed) < len(points):
        return None
    return SimulationError(
        f"{command}: the run failed at every value of {parameter} ({len(points)}); "
        f"at {failed[0].value:g}: {failed[0].error}"
    )


def as_runner(run: Runner | System | Mapping[str, Any]) -> Runner:
    """The analyses' entry: a :class:`~vibroimpact.System` or a scenario's sections
    as its :class:`Runner` (anything else as it is, for :func:`checked_run` to
    check). Sections had been refused by the analyses that take a Runner, where the
    others took them (a new user's trial of the getting-started page)."""
    return runner(run) if isinstance(run, (System, Mapping)) else run


def checked_run(run: Any, state: Any) -> np.ndarray | None:
    """``run`` checked as a :class:`Runner` and ``state`` as one of its flat states
    (or None)."""
    arguments.instance("run", run, Runner, "vibroimpact.analysis.runner(sections)")
    return arguments.state("state", state, 2 * (run.n + run.k))


@arguments.typed()
def runner(data: Mapping[str, Any] | System, base_dir: Path | None = None) -> Runner:
    """A :class:`Runner` of a :class:`~vibroimpact.System` or of a scenario's sections
    (as parsed from TOML)."""
    data, base_dir = sections_of(data, base_dir)
    base_dir = arguments.directory("base_dir", base_dir)
    # The forcing first: a system without a harmonic excitation has no orbit to find,
    # whatever its solver lacks (an unforced system had been refused for its dt).
    period = forcing_period(data)
    prepared = _prepare(data, base_dir)
    prepared.check_forcing_period(period)
    return Runner(prepared, period)


#: The final states whose open contacts the runners keep (:func:`carried_from`).
CARRIED_STATES = 64

#: The compliant contacts open at the end of the runners' last runs, by the bytes of
#: their final states: a run continued from one of them, by the same runner or by the
#: next point's of a sweep, continues them (their onsets and a damped law's latched
#: approach rate, which (x, v) do not hold) rather than beginning them afresh, counted
#: twice. Only runs that ended inside a contact are kept.
_CARRIED: dict[tuple[bytes, int], list[Any]] = {}


def carried_from(state: np.ndarray, count: int) -> list[Any] | None:
    """The contacts a run of a system of ``count`` interactions ending at ``state`` (x
    then v) left open, onsets relative to its end (``PreparedSystem.run``'s
    ``carried``); None where no run kept ended there inside a contact."""
    return _CARRIED.get((np.asarray(state, dtype=float).tobytes(), count))


def begun(contacts: Mapping[str, Any]) -> np.ndarray:
    """Which of a run's ``contacts`` began in it: not those it continued from the
    run before (their onsets < 0), nor one in progress at its start that no run began
    (onset -0.0: a state given inside a contact)."""
    onsets = np.asarray(contacts["onset"], dtype=float)
    began: np.ndarray = (onsets >= 0.0) & ~np.signbit(onsets)
    return began


def _impacts(raw: Mapping[str, Any]) -> int:
    """The impacts and compliant contacts that began in the run ``raw``."""
    contacts = raw["contacts"]
    return sum(
        1
        for kind, new in zip(contacts["kind"], begun(contacts), strict=True)
        if new and kind in ("impact", "compliant")
    )


#: The forcing periods a long recording's first stretch runs to estimate its contacts
#: (:func:`check_kept`); only recordings of ten times as many are estimated.
PROBE_PERIODS = 1000


def check_kept(run: Runner, state: np.ndarray, count: int, name: str) -> None:
    """Refuse up front a recording of ``count`` periods from ``state`` whose contacts,
    at the rate of its first ``PROBE_PERIODS``, would pass ``[solver] max_rows``
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
