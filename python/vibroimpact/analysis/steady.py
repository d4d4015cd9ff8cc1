"""The steady response of a forced system: settled, its stroboscopic period found, then
recorded (located peaks and RMS values); and the linear response of the structure alone,
which a damper's reduction is measured against."""

from __future__ import annotations

import warnings
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from vibroimpact import arguments
from vibroimpact._core import InvalidInputError, _strobe_period
from vibroimpact.analysis.limits import check_total, whole_count
from vibroimpact.analysis.runs import Runner, _impacts, _prepare, as_runner, checked_run
from vibroimpact.messages import shown
from vibroimpact.model.system import System
from vibroimpact.summary import summarised
from vibroimpact.system import PreparedRun, linear_parts, moment_weights, point_weights


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
    onsets: list[float] = []
    z = state
    for _ in range(count):
        raw = run._periods(z, 1, record=True)
        peaks.append(np.asarray(raw["peaks"], dtype=float))
        squares = squares + np.asarray(raw["square_integrals"], dtype=float)
        time += float(raw["recorded_time"])
        kinds += list(raw["contacts"]["kind"])
        onsets += list(raw["contacts"]["onset"])
        z = np.asarray(raw["final_state"], dtype=float)
    rows = np.array(peaks)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # a quantity with no peak: NaN
        largest, least = np.nanmax(rows, axis=0), np.nanmin(rows, axis=0)
    merged = {
        "peaks": largest,
        "square_integrals": squares,
        "recorded_time": time,
        "contacts": {"kind": kinds, "onset": onsets},
        "final_state": z,
    }
    return merged, least


@summarised
@dataclass
class SteadyState:
    """A steady response (SI units): per structure coordinate the located
    ``amplitude`` (largest ``|displacement|``, m) and ``rms`` (m) over the recorded
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


@arguments.typed()
def steady_state(
    run: Runner | System | Mapping[str, Any],
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
