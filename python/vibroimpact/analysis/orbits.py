"""Periodic orbits found by shooting (Newton's method on the stroboscopic map, in the
core), with their Floquet multipliers and stability."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from vibroimpact import arguments
from vibroimpact.analysis.limits import MAX_ITERATIONS, MAX_PERIODS, relative_tolerance, whole_count
from vibroimpact.analysis.parameters import shifted
from vibroimpact.analysis.runs import Runner, _impacts, as_runner, checked_run, state_arrays
from vibroimpact.model.system import System
from vibroimpact.summary import summarised


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
    #: The Jacobian of the map at the orbit, on the scenario's section (where :func:`orbit`
    #: shot on a section moved out of a contact whose law latches its rate, carried back
    #: by the flow; its eigenvalues, the multipliers, are the same on any section;
    #: ``grazings``' times are then from the moved section).
    monodromy: np.ndarray = field(repr=False)
    #: How the monodromy was made: ``"tangent"`` (the tangent flow through the impacts,
    #: exact) or ``"differences"`` (central differences of whole runs).
    jacobian: str = "differences"
    #: Grazings met on the orbit's tangent flow: ``(time s, pair, closing speed m/s)``,
    #: where the flow has no derivative (the multipliers are then one-sided).
    grazings: list[tuple[float, str, float]] = field(default_factory=list)
    #: The largest ``|displacement|`` (m) on the orbit at each of ``[output] points``, and
    #: ``|bending moment|`` (N m) at each of ``[output] moments``.
    point_amplitude: np.ndarray = field(default_factory=lambda: np.zeros(0))
    moment_amplitude: np.ndarray = field(default_factory=lambda: np.zeros(0))
    #: The forcing periods the orbit takes to close (``monodromy`` is over these).
    periods: int = 1

    def arrays(self, n: int, k: int) -> dict[str, list[float]]:
        """The state as the four arrays of ``[initial]``."""
        return state_arrays(self.state, n, k)


#: The fractions of the forcing period :func:`_clear_section` tries, in order.
_SECTION_FRACTIONS = np.arange(1, 20) / 20


def _latching_walls(run: Runner) -> list[tuple[np.ndarray, float]]:
    """The row ``h`` and offset (m) of each interaction whose law latches its approach
    rate at the contact's onset, which a state (x, v) does not hold (its gap ``offset +
    h . x``)."""
    return [
        (np.asarray(it["h"], dtype=float), float(it["offset"]))
        for it in run.walls()
        if it["latches"]
    ]


def _in_contact(walls: list[tuple[np.ndarray, float]], z: np.ndarray) -> bool:
    """Whether any of ``walls`` is in contact at the state ``z`` (x then v)."""
    return any(offset + float(np.dot(h, z[: len(h)])) < 0.0 for h, offset in walls)


def _clear_section(run: Runner, z: np.ndarray) -> tuple[Runner, np.ndarray, float]:
    """``run``, ``z`` and 0 where no latching contact is open at ``z``; else the runner
    of the system whose forcing starts ``fraction`` of a period later, the state there
    on the run from ``z``, and that fraction: the first of :data:`_SECTION_FRACTIONS`
    clear of such contacts (the Floquet multipliers do not depend on the section). As
    the continuation's section moves away from impacts."""
    walls = _latching_walls(run)
    if not _in_contact(walls, z):
        return run, z, 0.0
    for fraction in _SECTION_FRACTIONS:
        end = run._run(z, fraction * run.period, record=False, strobe=False)["final_state"]
        moved = np.asarray(end, dtype=float)
        if not _in_contact(walls, moved):
            spec = shifted(run.prepared.spec, float(fraction))
            return Runner(replace(run.prepared, spec=spec), run.period), moved, float(fraction)
    return run, z, 0.0


@arguments.typed()
def orbit(
    run: Runner | System | Mapping[str, Any],
    state: np.ndarray | None = None,
    *,
    periods: int = 1,
    tolerance: float = 1e-10,
    max_iterations: int = 40,
    jacobian: str = "auto",
) -> Orbit:
    """Shoot for an orbit of ``periods`` forcing periods from ``state`` (default the
    scenario's ``[initial]``): Newton's method on ``P(z) - z = 0``, ``P`` the
    stroboscopic map over ``periods`` periods. Its Jacobian (``jacobian``):
    ``"tangent"``, the tangent flow carried through every impact by its saltation
    matrix (exact through rigid impacts, to the method's accuracy through compliant
    contacts); ``"differences"``, central finite differences of
    whole runs (across impacts the saltation is in the differences); ``"auto"`` (the
    default), the tangent flow (through dry friction's stops, sticking and slips too, each
    by its saltation). At the orbit the Jacobian is
    the monodromy matrix; its eigenvalues are the Floquet multipliers and the orbit is
    stable when all lie inside the unit circle. Newton steps that would start inside a
    wall are halved. ``run``: a :class:`Runner` or a :class:`~vibroimpact.System`."""
    run = as_runner(run)
    state = checked_run(run, state)
    periods = whole_count("periods", periods, 1, MAX_PERIODS)
    tolerance = relative_tolerance("tolerance", tolerance)
    max_iterations = whole_count("max_iterations", max_iterations, 1, MAX_ITERATIONS)
    jacobian = arguments.choice("jacobian", jacobian, ("auto", "tangent", "differences"))
    if jacobian == "auto":
        jacobian = "tangent"
    z = run.initial_state() if state is None else np.asarray(state, dtype=float)
    # A section inside a contact whose law latches its approach rate is moved out of it:
    # the map of (x, v) there would begin the contact afresh (see _clear_section).
    shooting, z, moved = _clear_section(run, z)
    shot = shooting.shoot(z, periods, tolerance, max_iterations, jacobian)
    found = np.asarray(shot["state"], dtype=float)
    if not moved and _in_contact(_latching_walls(run), found):
        # The guess was clear of those contacts, the point found is not: it solved the
        # map that begins the contact afresh at the section, not the motion's (a
        # physicist's probe: "converged" on a false orbit, its multipliers 0.7 % off).
        # Shot again from a section clear of the point's contact.
        shooting, z, moved = _clear_section(run, found)
        if moved:
            shot = shooting.shoot(z, periods, tolerance, max_iterations, jacobian)
    size = len(z)
    z = np.asarray(shot["state"], dtype=float)
    jac = np.asarray(shot["monodromy"], dtype=float).reshape(size, size)
    if moved:
        # Back on the scenario's section at the orbit's own point: the rest of its
        # periods from the moved section (its run's open contact is carried to the
        # recording below), and the monodromy there, conjugated by the flow over that
        # rest (the same multipliers).
        rest = (periods - moved) * run.period
        flow = np.asarray(shooting.tangent(z, rest)["matrix"], dtype=float)
        z = np.asarray(shooting._run(z, rest, record=False, strobe=False)["final_state"])
        jac = flow @ jac @ np.linalg.inv(flow)
    converged = bool(shot["converged"])
    iterations = int(shot["iterations"])
    residual = float(shot["residual"])
    multipliers = np.linalg.eigvals(jac)
    # The last map's grazings: the orbit's (the returned state's own map).
    grazings = [tuple(g) for g in shot.get("grazings", [])]
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
        jacobian=jacobian,
        grazings=grazings,
        point_amplitude=point_amplitude,
        moment_amplitude=moment_amplitude,
        periods=periods,
    )
