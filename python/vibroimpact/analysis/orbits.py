"""Periodic orbits found by shooting (Newton's method on the stroboscopic map, in the
core), with their Floquet multipliers and stability."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from vibroimpact import arguments
from vibroimpact.analysis.limits import MAX_ITERATIONS, MAX_PERIODS, relative_tolerance, whole_count
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


@arguments.typed()
def orbit(
    run: Runner | System,
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
    shot = run.shoot(z, periods, tolerance, max_iterations, jacobian)
    size = len(z)
    z = np.asarray(shot["state"], dtype=float)
    jac = np.asarray(shot["monodromy"], dtype=float).reshape(size, size)
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
