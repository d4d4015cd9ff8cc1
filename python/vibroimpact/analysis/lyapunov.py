"""Lyapunov exponents of a 0.2 system through its impacts: the whole spectrum by
Benettin's method, the tangent flow carried through every event by its saltation matrix
and re-orthonormalised after each (all in the core), with its convergence."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from vibroimpact import arguments
from vibroimpact._core import lyapunov_spectrum
from vibroimpact.analysis.limits import (
    MAX_PERIODS,
    AnalysisError,
    check_periods,
    check_total,
    whole_count,
)
from vibroimpact.analysis.parameters import forcing_period
from vibroimpact.analysis.runs import Runner, _prepare, as_runner, carried_from, checked_run
from vibroimpact.model.modes import structure_frequencies
from vibroimpact.model.system import System, sections_of
from vibroimpact.summary import summarised

#: Blocks the averaging time is cut into for the standard errors.
BLOCKS = 10


@summarised
@dataclass
class Lyapunov:
    """The Lyapunov spectrum of a run (1/s, descending; minus infinity for a direction
    lost where a pair stuck), with each exponent's standard error over ``BLOCKS`` (10)
    consecutive blocks of the averaging time."""

    exponents: np.ndarray
    standard_error: np.ndarray
    #: The time averaged over (s), the settling excluded.
    time: float
    #: Events whose impulses acted, or where a compliant contact began, over that time.
    impacts: int
    #: Forcing periods settled first and averaged over (None: an unforced system,
    #: averaged over ``[solver] t_end``).
    settle: int | None = None
    periods: int | None = None
    #: Grazings met: ``(time s, pair, closing speed m/s)``, where the flow has no
    #: derivative (the exponents are then one-sided).
    grazings: list[tuple[float, str, float]] = field(default_factory=list)
    #: The estimates after each block (1/s, one row per block, ordered as
    #: ``exponents``) and the time each row averages over (s): the convergence.
    running: np.ndarray = field(default_factory=lambda: np.zeros((0, 0)), repr=False)
    running_time: np.ndarray = field(default_factory=lambda: np.zeros(0), repr=False)

    @property
    def largest(self) -> float:
        """The largest exponent, 1/s (> 0: chaos; 0: a neutral direction)."""
        return float(self.exponents[0])


def lyapunov_runner(data: Mapping[str, Any] | System, base_dir: Path | None = None) -> Runner:
    """A :class:`Runner` for :func:`lyapunov`: a forced system's (whole forcing
    periods), or an unforced one's (no excitation: its ``period`` is ``[solver]
    t_end``, the time averaged over)."""
    sections, base_dir = sections_of(data, base_dir)
    if sections.get("excitation"):
        period = forcing_period(sections)
        prepared = _prepare(sections, base_dir)
        prepared.check_forcing_period(period)
        return Runner(prepared, period)
    prepared = _prepare(sections, base_dir)
    return Runner(prepared, float(prepared.solver["t_end"]))


@arguments.typed()
def lyapunov(
    run: Runner | System | Mapping[str, Any],
    state: np.ndarray | None = None,
    *,
    settle: int | None = None,
    periods: int | None = None,
) -> Lyapunov:
    """The Lyapunov spectrum from ``state`` (default the scenario's ``[initial]``):
    ``settle`` forcing periods run first (default 100), then the tangent flow over
    ``periods`` (default 1000), carried through every impact by its saltation matrix
    and re-orthonormalised (QR) after each; the exponents are the logarithms of the
    stretches over the time (1/s). A system without excitation is averaged over
    ``[solver] t_end`` from ``state``, without settling. ``run``: a
    :class:`Runner` (see :func:`lyapunov_runner`) or a :class:`~vibroimpact.System`."""
    if isinstance(run, (System, Mapping)):
        run = lyapunov_runner(run)
    run = as_runner(run)
    state = checked_run(run, state)
    forced = bool(run.prepared.spec.get("excitation"))
    z = run.initial_state() if state is None else np.asarray(state, dtype=float)
    if forced:
        settle = 100 if settle is None else whole_count("settle", settle, 0)
        periods = 1000 if periods is None else whole_count("periods", periods, 1, MAX_PERIODS)
        check_periods("", "settle", settle, 0)
        check_periods("", "periods", periods, 1)
        check_total(("settle", settle), ("periods", periods))
        _check_window(run, periods)
        if settle:
            z = run.map(z, settle)
        blocks = _blocks(periods)
        block_time = periods // blocks * run.period
    else:
        if settle is not None or periods is not None:
            raise AnalysisError(
                "settle and periods: an unforced system has no forcing period; it is "
                "averaged over [solver] t_end"
            )
        blocks = BLOCKS
        block_time = run.period / BLOCKS
    # A contact in progress at the settled state continues (carried_from), and each
    # block continues the last one's.
    carried = carried_from(z, run.interaction_count())
    raw = lyapunov_spectrum(
        run.system(), [float(v) for v in z], block_time, blocks, carried=carried
    )
    run.runs += blocks
    exponents = np.asarray(raw["exponents"], dtype=float)
    return Lyapunov(
        exponents=exponents,
        standard_error=np.asarray(raw["standard_error"], dtype=float),
        time=float(raw["time"]),
        impacts=int(raw["impacts"]),
        settle=settle if forced else None,
        periods=periods if forced else None,
        grazings=[tuple(g) for g in raw["grazings"]],
        running=np.asarray(raw["running"], dtype=float).reshape(blocks, len(exponents)),
        running_time=block_time * np.arange(1, blocks + 1),
    )


#: The averaging time spans at least this many of the structure's longest natural period.
MIN_NATURAL_PERIODS = 10


def _check_window(run: Runner, periods: int) -> None:
    """Refuse an averaging time, ``periods`` forcing periods, shorter than
    :data:`MIN_NATURAL_PERIODS` of the structure's slowest mode (rigid modes aside):
    its exponents would be the stretches of a transient, not rates the motion keeps (a
    5 Hz oscillator forced at 1e8 Hz, never touching its damper: +77.8 and -80.4 1/s,
    "chaotic", where both are -1.26)."""
    frequencies = structure_frequencies(run.prepared.spec["structure"])
    # Rigid modes aside (their 0 Hz to round-off).
    springs = frequencies[frequencies > 1e-6 * frequencies.max(initial=0.0)]
    if not len(springs):
        return  # no spring: no natural period to span
    slowest = 1.0 / springs.min()
    need = int(np.ceil(MIN_NATURAL_PERIODS * slowest / run.period * (1 - 1e-9)))
    if periods >= need:
        return
    span = f"{periods} forcing periods span {periods * run.period:.3g} s"
    why = (
        f"under {MIN_NATURAL_PERIODS} of the structure's slowest natural period "
        f"({slowest:.3g} s): the exponents would be a transient's stretches, not rates"
    )
    if need > MAX_PERIODS:
        raise AnalysisError(
            f"periods: {span}, {why}; {need:.3g} periods would be needed, beyond the "
            f"{MAX_PERIODS} an analysis runs: the forcing is too fast for its slowest mode"
        )
    raise AnalysisError(f"periods: {span}, {why}; give periods >= {need}")


def _blocks(periods: int) -> int:
    """The most blocks, up to :data:`BLOCKS`, that divide ``periods`` into whole
    forcing periods each; refused where only one does beyond one period (997: the
    standard error, over blocks, would be NaN and the running plot one point)."""
    blocks = next(b for b in range(min(BLOCKS, periods), 0, -1) if periods % b == 0)
    if blocks == 1 and periods > 1:
        nearest = max(BLOCKS, round(periods / BLOCKS) * BLOCKS)
        raise AnalysisError(
            f"periods: {periods} forcing periods do not split into 2 to {BLOCKS} blocks of "
            f"whole periods, over which the standard error is taken; give a multiple of "
            f"{BLOCKS} (e.g. {nearest})"
        )
    return blocks
