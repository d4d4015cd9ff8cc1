"""Sensitivities of a periodic orbit to the scenario's parameters, by the implicit function
theorem on the shooting equations: at an orbit ``P_p(z) = z``, ``dz/dp = (I - M)^-1
dP/dp`` with ``M`` the monodromy and ``dP/dp`` the map's derivative in the parameter,
both from one run of the tangent flow through the impacts and contacts (its columns by
the parameters: the forward sensitivity equations, see
:meth:`~vibroimpact.analysis.runs.Runner.tangent`), plus the end's rate times the move
of the orbit's period where the parameter moves it (a forcing frequency). The
amplitudes' derivatives: central differences of the orbits' located peaks at ``p +- h``,
each run from the state the theorem predicts there (so no Newton solve). SI units: per
unit of the parameter. A sweep's points take theirs from the orbit through each point's
settled state (:func:`settled_derivatives`)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np

from vibroimpact import arguments
from vibroimpact._core import SimulationError
from vibroimpact.analysis.continuation import _value_of
from vibroimpact.analysis.limits import AnalysisError
from vibroimpact.analysis.orbits import Orbit, _clear_section, orbit
from vibroimpact.analysis.parameters import shifted as shifted_data
from vibroimpact.analysis.parameters import with_parameter, with_parameter_path_check
from vibroimpact.analysis.runs import Runner, runner
from vibroimpact.analysis.steady import SteadyState
from vibroimpact.messages import shown
from vibroimpact.model.system import System, sections_of

#: The parameter's step in the differences, relative to its value (absolute where the
#: value is 0): a map's central difference errs by ``h^2`` and by round-off over ``h``;
#: the tangent flow's quotients of the rates and gaps take the same step.
RELATIVE_STEP = 1e-6

#: ``I - M`` counts as singular below this smallest singular value, relative to its
#: largest: a free damper's multipliers are 1 to round-off.
SINGULAR = 1e-9


class UndefinedDerivativeError(AnalysisError):
    """An orbit with no derivatives: not converged, or ``I - M`` singular in the
    structure's state (a fold)."""


@dataclass
class Derivative:
    """The derivatives of an orbit in one parameter: of its state at t = 0 (flat,
    displacements then velocities), of its amplitude per structure coordinate (the
    largest ``|displacement|`` over the orbit, m), and of the structure's at each of
    ``[output] points`` (m) and the bending moment's at each of ``[output] moments``
    (N m), per unit of the parameter."""

    state: np.ndarray
    amplitude: np.ndarray
    point_amplitude: np.ndarray = field(default_factory=lambda: np.zeros(0))
    moment_amplitude: np.ndarray = field(default_factory=lambda: np.zeros(0))

    def to_dict(self) -> dict[str, list[float]]:
        followed = {
            key: [float(v) for v in values]
            for key, values in (
                ("point_amplitude", self.point_amplitude),
                ("moment_amplitude", self.moment_amplitude),
            )
            if len(values)
        }
        return {
            "state": [float(v) for v in self.state],
            "amplitude": [float(v) for v in self.amplitude],
            **followed,
        }


def derivative_paths(data: Mapping[str, Any], paths: Sequence[str] | str) -> list[str]:
    """``paths`` checked as parameters of the scenario ``data`` that derivatives can be
    taken in: dotted paths into its sections, each set to a number."""
    if isinstance(paths, str):
        paths = [paths]
    arguments.instance("derivatives", paths, Sequence, "a list of dotted paths")
    for path in paths:
        arguments.text("derivative", path)
        with_parameter_path_check(path, "")
        _value_of(data, path, "derivative", "the derivative is taken at its value")
    # Each once, as [study] metrics are (a path twice had made its column twice).
    return list(dict.fromkeys(paths))


def orbit_derivatives(
    data: Mapping[str, Any] | System,
    found: Orbit,
    paths: Sequence[str],
    *,
    periods: int | None = None,
    base_dir: Path | None = None,
) -> dict[str, Derivative]:
    """The derivatives of the orbit ``found`` (of the scenario ``data``; its
    ``periods``, which ``periods`` must equal where given) in each parameter of ``paths``
    (dotted paths such as ``"damper.0.clearance"``), by the implicit function theorem on
    the shooting equations (see the module). The orbit must have converged. At a
    parameter's bound (a gap of 0, a restitution of 1) the differences are one-sided."""
    data, base_dir = sections_of(data, base_dir)
    arguments.instance("found", found, Orbit, "vibroimpact.analysis.orbit(...)")
    if periods is not None and periods != found.periods:
        # The monodromy is over the orbit's own periods: a map over others would pair
        # with it into a wrong answer.
        raise AnalysisError(
            f"periods: the orbit found closes after {found.periods} forcing period(s) "
            f"(its monodromy is over those), got {shown(periods)}: leave periods out"
        )
    periods = found.periods
    if not found.converged:
        raise UndefinedDerivativeError(
            "found: the orbit did not converge; its derivatives are not defined"
        )
    paths = derivative_paths(data, paths)
    out: dict[str, Derivative] = {}
    size = len(found.state)
    base = runner(data, base_dir)
    _, moved, fraction = _clear_section(base, found.state)
    if fraction:
        # The section inside a contact whose law latches its approach rate: the map of
        # (x, v) there begins the contact afresh. On a section clear of it, then back.
        return _from_clear_section(data, found, paths, (moved, fraction), base_dir)
    sides = [_sides(data, path, base, base_dir) for path in paths]
    shifted = [(up, down, (s_up - s_down) / 2) for (up, s_up), (down, s_down) in sides]
    map_by = map_derivatives(base, found.state, periods, shifted)
    n, d = base.n, base.n + base.k
    structure = [*range(n), *range(d, d + n)]
    for column, (path, ends) in enumerate(zip(paths, sides, strict=True)):
        state = _orbit_shift(np.eye(size) - found.monodromy, map_by[:, column], structure)
        amplitudes = []
        for run, shift in ends:
            recorded = run.periods(found.state + shift * state, periods, record=True)
            amplitudes.append(run.amplitudes(recorded))
        width = ends[0][1] - ends[1][1]
        out[path] = Derivative(
            state, *((up - down) / width for up, down in zip(*amplitudes, strict=True))
        )
    return out


def _from_clear_section(
    data: Mapping[str, Any],
    found: Orbit,
    paths: list[str],
    section: tuple[np.ndarray, float],
    base_dir: Path | None,
) -> dict[str, Derivative]:
    """:func:`orbit_derivatives` of ``found`` through the state ``moved`` a ``fraction``
    of a period after its own (``section``, clear of contacts): there by the implicit
    function theorem, then carried along the flow over the rest of the orbit's periods
    to its own point, ``z0 = F(z, p)``: ``dz0/dp = (dF/dz) dz/dp + dF/dp`` (the tangent
    flow, and differences of the runs in the parameter). The amplitudes are the whole
    orbit's, on any section."""
    moved, fraction = section
    clear = shifted_data(dict(data), fraction)
    base = runner(clear, base_dir)
    monodromy = base.tangent(moved, found.periods * base.period)["matrix"]
    on_clear = orbit_derivatives(
        clear, replace(found, state=moved, monodromy=monodromy), paths, base_dir=base_dir
    )
    # To the orbit's own point: the rest of its periods.
    rest = base.tangent(moved, (found.periods - fraction) * base.period)["matrix"]
    out: dict[str, Derivative] = {}
    for path in paths:
        ends = []
        for run, shift in _sides(clear, path, base, base_dir):
            length = (found.periods - fraction) * run.period
            end = run._run(moved, length, record=False, strobe=False)
            ends.append((np.asarray(end["final_state"], dtype=float), shift))
        (up, s_up), (down, s_down) = ends
        state = rest @ on_clear[path].state + (up - down) / (s_up - s_down)
        out[path] = replace(on_clear[path], state=state)
    return out


def _sides(
    data: Mapping[str, Any], path: str, base: Runner, base_dir: Path | None
) -> list[tuple[Runner, float]]:
    """The runners of the differences in ``path``, above and below its value, each with
    its shift from the value: ``+-h``, or 0 (the value's own runner, ``base``) on a side
    where the parameter's range ends at its value (a one-sided difference)."""
    value = _value_of(data, path)
    h = RELATIVE_STEP * (abs(value) if value else 1.0)
    sides: list[tuple[Runner, float]] = []
    for shift in (h, -h):
        try:
            sides.append((runner(with_parameter(data, path, value + shift), base_dir), shift))
        except ValueError:
            sides.append((base, 0.0))
    if sides[0][1] == sides[1][1]:
        raise AnalysisError(
            f"derivative {path}: the scenario takes no value beside {value!r} on either "
            "side, so there is no derivative in it"
        )
    return sides


def map_derivatives(
    run: Runner,
    state: np.ndarray,
    periods: int,
    shifted: Sequence[tuple[Runner, Runner, float]],
) -> np.ndarray:
    """The derivatives of the stroboscopic map over ``periods`` forcing periods from
    ``state`` by each parameter of ``shifted`` (its runners at two values ``2 delta``
    apart and ``delta``), one column each: the tangent flow's columns at the fixed end, plus the
    end's rate times the move of the end where the parameter moves the period."""
    raw = run.tangent(state, periods * run.period, shifted)
    moved = np.array(
        [periods * (up.period - down.period) / (2 * delta) for up, down, delta in shifted]
    )
    out: np.ndarray = raw["parameters"] + np.outer(np.asarray(raw["rate"], dtype=float), moved)
    return out


def _orbit_shift(matrix: np.ndarray, rhs: np.ndarray, structure: list[int]) -> np.ndarray:
    """The solution of ``matrix @ x = rhs`` (``I - M`` and ``dP/dp``). Where ``matrix`` is
    singular only in the dampers' state (a damper at rest between its walls, free to sit
    anywhere: multipliers 1), the orbits form a family that moves the structure alike:
    the least-norm solution, if the equations hold. Anything else singular (a fold, whose
    orbit does not go on smoothly) has no derivative."""
    u, sigma, vt = np.linalg.svd(matrix)
    kept = sigma > SINGULAR * sigma[0]
    shift: np.ndarray = vt[kept].T @ ((u[:, kept].T @ rhs) / sigma[kept])
    if kept.all():
        return shift
    free = vt[~kept]
    residual = np.linalg.norm(matrix @ shift - rhs)
    if np.max(np.abs(free[:, structure]), initial=0.0) > 1e-6 or residual > 1e-6 * max(
        float(np.linalg.norm(rhs)), 1e-300
    ):
        raise UndefinedDerivativeError(
            "found: I - M is singular (a Floquet multiplier of 1 that moves the structure: "
            "a fold); the derivatives are not defined there"
        )
    return shift


def settled_derivatives(
    data: Mapping[str, Any],
    run: Runner,
    steady: SteadyState,
    paths: Sequence[str],
    base_dir: Path | None = None,
) -> dict[str, Derivative] | None:
    """The derivatives (see :func:`orbit_derivatives`) of the orbit through a steady
    response's last state, of its stroboscopic period (1 where none was found), or None
    where there is no such orbit to differentiate: the shooting did not converge, it
    failed, or (for a response that did not settle) the orbit it found is unstable, not
    the motion the response tends to. ``data``: the scenario's sections that ``run``
    runs."""
    periods = steady.period or 1
    try:
        found = orbit(run, steady.state, periods=periods)
        if not found.converged or not (steady.settled or found.stable):
            return None
        return orbit_derivatives(data, found, paths, periods=periods, base_dir=base_dir)
    except (SimulationError, ArithmeticError, UndefinedDerivativeError):
        # A run that blew up or cannot go on near the orbit, or I - M singular (a fold).
        return None
