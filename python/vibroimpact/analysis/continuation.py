"""Pseudo-arclength continuation of periodic orbits of forced 0.2 systems in any
scalar parameter of the scenario (a dotted path such as ``"excitation.0.frequency"``).

Unknowns ``u = (z, p)``: the state on the orbit at t = 0 and the parameter. Each
point solves ``P_p(z) - z = 0`` (``P_p`` the stroboscopic map over K forcing periods)
together with ``t . (u - u_predicted) = 0`` (Keller's arclength condition, ``t`` the
unit tangent), so the branch is followed through folds, where the parameter turns
back. Derivatives are central finite differences through the core's runs (across
impacts they include the saltation). At each point the monodromy matrix gives the
Floquet multipliers; between points the code flags a ``fold`` (the parameter's
direction along the branch reverses), a ``flip`` (a multiplier crosses -1), a
``neimark-sacker`` (a complex pair leaves the unit circle), a ``branch`` (a real
multiplier crosses +1 without a fold) and ``grazing`` (the number of impacts per
period changes: then alone, since the two orbits lie on different smooth branches).
Each is then located by Newton's method on an extended system
(``vibroimpact.analysis.located``, and ``vibroimpact.analysis.grazing`` for grazings,
where a branch may also end).
SI units.
"""

from __future__ import annotations

import copy
import functools
import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from vibroimpact import arguments
from vibroimpact._core import InvalidInputError
from vibroimpact.analysis.crossings import _CLASSES, _flags, _kind, _largest
from vibroimpact.analysis.grazing import grazing_ahead, grazings_between
from vibroimpact.analysis.limits import (
    MAX_PERIODS,
    MAX_POINTS,
    AnalysisError,
    relative_tolerance,
    whole_count,
)
from vibroimpact.analysis.located import (
    ITERATIONS,
    PARAMETER_TOLERANCE,
    Bifurcation,
    refine,
    test_value,
)
from vibroimpact.analysis.orbits import orbit
from vibroimpact.analysis.parameters import shifted, with_parameter
from vibroimpact.analysis.runs import Runner, _impacts, runner, state_arrays
from vibroimpact.analysis.settings import chosen_settings
from vibroimpact.messages import shown
from vibroimpact.model.system import System, sections_of
from vibroimpact.summary import summarised
from vibroimpact.system.parameter_keys import check_parameter_key


@summarised
@dataclass
class BranchPoint:
    """One orbit on a branch."""

    value: float
    state: np.ndarray
    floquet_multipliers: np.ndarray
    stable: bool
    impacts_per_period: float
    amplitude: np.ndarray
    flags: list[str] = field(default_factory=list)
    #: Where each flagged bifurcation lies between the last point and this one: the
    #: parameter at which the crossing multiplier's modulus reaches 1 (bisection along
    #: the arc), or at which the parameter turns (a fold: where the stability changes
    #: there, so located; otherwise the extremum of its cubic along the arc, see
    #: ``vibroimpact.analysis.crossings._fold``).
    crossings: dict[str, float] = field(default_factory=dict)

    def to_dict(self, n: int, k: int) -> dict[str, Any]:
        return {
            "value": self.value,
            "state": state_arrays(self.state, n, k),
            "floquet_multipliers": [
                [float(m.real), float(m.imag)] for m in self.floquet_multipliers
            ],
            "stable": self.stable,
            "impacts_per_period": self.impacts_per_period,
            "amplitude": [float(a) for a in self.amplitude],
            "flags": list(self.flags),
            "crossings": dict(self.crossings),
        }


@summarised
@dataclass
class Branch:
    """A continued branch of K-period orbits, and why it stopped."""

    parameter: str
    periods: int
    points: list[BranchPoint]
    stopped: str
    n: int
    k: int
    #: The bifurcations located exactly (Newton on the extended system, where every pair
    #: is rigid), each a :class:`~vibroimpact.analysis.Bifurcation`.
    bifurcations: list[Bifurcation] = field(default_factory=list)
    #: With ``switch``: the period-doubled branch born at the first flip (None where
    #: none was found).
    switched: Branch | None = None


#: A continuation's step (arclength, in the parameter's unit) as fractions of the range
#: it continues over, ``|stop - start|``.
STEP_RANGE = (1e-9, 1.0)


def check_step(name: str, step: float, span: float) -> None:
    """Refuse a parameter ``step`` outside :data:`STEP_RANGE` of the range ``span`` it
    steps over (a step beyond the whole range leaves at once; one of 1e-9 of it never
    gets anywhere within max_points, and one of 1e-300 divided by zero)."""
    if not STEP_RANGE[0] * abs(span) <= step <= STEP_RANGE[1] * abs(span):
        raise AnalysisError(
            f"{name}: must be in [{shown(STEP_RANGE[0] * abs(span))}, {shown(abs(span))}] "
            f"(from 1e-9 of the range to the range |stop - start| = {shown(abs(span))}), "
            f"got {shown(step)}"
        )


@arguments.typed()
def continue_orbit(
    data: Mapping[str, Any] | System,
    parameter: str | None = None,
    *,
    stop: float | None = None,
    periods: int | None = None,
    step: float | None = None,
    max_points: int | None = None,
    tolerance: float | None = None,
    base_dir: Path | None = None,
    progress: Callable[[int, int], None] | None = None,
    switch: bool | None = None,
) -> Branch:
    """Continue the K-period orbit found from the scenario's ``[initial]`` (at the
    scenario's value of ``parameter``) towards ``stop``, with arclength steps of
    about ``step`` (in units of the parameter; default 1/50 of the range), at most
    ``max_points`` orbits. Stops at ``stop``, at ``max_points``, or when the
    corrector fails even with small steps. Bifurcations are located exactly where every
    pair is rigid (:attr:`Branch.bifurcations`); with ``switch``, the continuation goes
    on from the first flip along the period-doubled branch (:attr:`Branch.switched`).
    ``data``: a :class:`~vibroimpact.System` or a scenario's sections; without
    ``parameter`` and ``stop``, its ``[continuation]`` table gives them and every setting
    not given here (else ``periods`` 1, ``max_points`` 200, ``tolerance`` 1e-9)."""
    data, base_dir = sections_of(data, base_dir)
    keys = ("parameter", "stop", "periods", "step", "max_points", "tolerance", "switch")
    values = (parameter, stop, periods, step, max_points, tolerance, switch)
    given = dict(zip(keys, values, strict=True))
    chosen = chosen_settings(data, "continuation", given, ("parameter", "stop"))
    parameter, stop, periods, step, max_points, tolerance, switch = (chosen[k] for k in keys)
    arguments.text("parameter", parameter)
    stop = arguments.number("stop", stop)
    periods = whole_count("periods", periods, 1, MAX_PERIODS)
    tolerance = relative_tolerance("tolerance", tolerance)
    base_dir = arguments.directory("base_dir", base_dir)
    arguments.callback("progress", progress)
    switch = arguments.flag("switch", switch)
    start_value = _value_of(data, parameter)
    if stop == start_value:
        raise AnalysisError(f"stop: must be a finite value other than the start {start_value:g}")
    max_points = whole_count("max_points", max_points, 2, MAX_POINTS)
    span = stop - start_value
    ds = abs(span) / 50 if step is None else arguments.positive("step", step)
    check_step("step", ds, span)

    # Harmonic forcing only: its section can move (see _Arc.section).
    shiftable = all(
        isinstance(e, Mapping) and e.get("signal") in ("harmonic", "harmonics")
        for e in data.get("excitation", ()) or ()
    )
    arc = _Arc(data, parameter, periods, tolerance, base_dir, span, shiftable=shiftable)
    first_run = arc.run_at(start_value)
    try:
        # A target the scenario cannot take is refused, not followed until a corrector
        # fails there with a message that hides why.
        arc.run_at(stop)
    except AnalysisError as err:
        raise AnalysisError(f"stop: must be a value the scenario takes ({err})") from None
    first = orbit(first_run, periods=periods, tolerance=tolerance)
    if not first.converged:
        raise AnalysisError(
            f"no {periods}-period orbit found from [initial] at {parameter} = {start_value:g} "
            f"(residual {first.residual:.2e}): start nearer to one"
        )
    size = len(first.state)
    dim = size // 2
    # The orbit's own size, not its state at t = 0 (which may be near a turning
    # point, its velocity near zero): its largest displacement, and that turned at
    # the forcing frequency for the velocities.
    x_scale = max(
        float(np.max(np.abs(first.state[:dim]), initial=0.0)),
        float(np.max(first.amplitude, initial=0.0)),
        1e-12,
    )
    v_scale = max(
        float(np.max(np.abs(first.state[dim:]), initial=0.0)),
        2 * math.pi / first_run.period * x_scale,
        1e-12,
    )
    scale = np.concatenate([np.full(dim, x_scale), np.full(dim, v_scale), [abs(span)]])
    arc.size, arc.scale = size, scale
    points, stopped = arc.trace(
        first.state, start_value, first_run.period, ds, stop, max_points, progress
    )
    branch = Branch(parameter, periods, points, stopped, first_run.n, first_run.k, arc.bifurcations)
    flips = [b for b in arc.bifurcations if b.kind == "flip"]
    if switch and flips:
        branch.switched = _doubled(
            data, parameter, flips[0], (stop, periods, step, max_points, tolerance), base_dir
        )
    return branch


def _doubled(
    data: Mapping[str, Any],
    parameter: str,
    flip: Bifurcation,
    settings: tuple[float, int, float | None, int, float],
    base_dir: Path | None,
) -> Branch | None:
    """The period-doubled branch born at ``flip``, continued towards ``stop``: its first
    orbit (2K periods) shot for a little beyond the flip, from the flip's orbit moved
    along the eigenvector of its multiplier -1 (the period-two orbit's two states lie
    either side of it, at a distance growing as the square root of the parameter's
    distance). None where no period-doubled orbit is found there."""
    stop, periods, step, max_points, tolerance = settings
    span = stop - flip.value
    n = len(flip.state) // 2
    beyond = flip.value + 1e-3 * span
    changed = with_parameter(data, parameter, beyond)
    run = runner(changed, base_dir)
    monodromy = run.tangent(flip.state, periods * run.period)["matrix"]
    values, vectors = np.linalg.eig(monodromy)
    vector = np.real(vectors[:, int(np.argmin(np.abs(values + 1.0)))])
    size = max(float(np.max(np.abs(flip.state[:n]))), 1e-12)
    vector *= size / max(float(np.max(np.abs(vector[:n]))), 1e-300)
    for amount in (0.03, 0.1, 0.01, 0.3):
        for sign in (1.0, -1.0):
            start = flip.state + sign * amount * vector
            try:
                found = orbit(run, start, periods=2 * periods, tolerance=tolerance)
            except InvalidInputError:
                continue
            half = run.map(found.state, periods)
            distinct = float(np.max(np.abs(half - found.state)[:n])) > 1e-6 * size
            if not (found.converged and distinct):
                continue
            seeded = _seeded(changed, found.state, run.n)
            return continue_orbit(
                seeded,
                parameter,
                stop=stop,
                periods=2 * periods,
                step=step,
                max_points=max_points,
                tolerance=tolerance,
                base_dir=base_dir,
            )
    return None


def _seeded(data: Mapping[str, Any], state: np.ndarray, n: int) -> dict[str, Any]:
    """``data`` with its ``[initial]`` the flat ``state`` (``n`` structure
    coordinates, then the dampers'; displacements, then velocities)."""
    out = copy.deepcopy(dict(data))
    out["initial"] = state_arrays(state, n, len(state) // 2 - n)
    return out


#: The test function (a multiplier's distance from +1 or -1) within which
#: :meth:`_Arc.along` takes an orbit for the bifurcation: where two branches cross,
#: the corrector converges no closer (the FRF damper's branch point at 11.2367 Hz:
#: 2.6e-8, about 1e-8 Hz from it).
BRANCH_TOLERANCE = 1e-6


@dataclass(eq=False)
class _Arc:
    """One continuation: the scenario, its parameter and the orbits' periods; the
    unknowns' scale ``u = (z, p) / scale`` (its length ``size`` that of a state, then
    the parameter's), which grows with the orbit; and the stroboscopic ``section``."""

    data: Mapping[str, Any]
    parameter: str
    periods: int
    tolerance: float
    base_dir: Path | None
    span: float
    #: The stroboscopic section, as a fraction of the forcing period after t = 0: moved
    #: away from the impacts when one comes near it, where the map jumps (an impact
    #: just before the section or just after it), so that the branch stays smooth
    #: (:meth:`clear_of_impacts`; where ``shiftable``, the forcing being harmonic).
    section: float = 0.0
    shiftable: bool = False
    size: int = 0
    scale: np.ndarray = field(default_factory=lambda: np.zeros(0))
    #: The bifurcations located along the branch so far.
    bifurcations: list[Bifurcation] = field(default_factory=list)

    def run_at(self, p: float, fraction: float | None = None) -> Runner:
        try:
            changed = with_parameter(self.data, self.parameter, p)
            return runner(
                shifted(changed, self.section if fraction is None else fraction), self.base_dir
            )
        except InvalidInputError as err:
            raise AnalysisError(f"{self.parameter} = {p:g}: {err}") from None

    def residual(self, u: np.ndarray) -> np.ndarray:
        z = u[: self.size] * self.scale[: self.size]
        p = float(u[self.size] * self.scale[self.size])
        out: np.ndarray = (self.run_at(p).map(z, self.periods) - z) / self.scale[: self.size]
        return out

    def jacobian(self, u: np.ndarray, centre: np.ndarray | None = None) -> np.ndarray:
        # ``centre``: the residual at ``u``, where the caller has it. The state's
        # columns from the tangent flow through the impacts and contacts (exact); the
        # parameter's by central differences of the map: two runs of the exact flow cost
        # less than carrying a parameter's column through every step (the ball on the
        # table: 0.018 ms against 0.21 ms, equal to the digits a corrector needs).
        jac = np.zeros((self.size, self.size + 1))
        if centre is None:
            centre = self.residual(u)
        z = u[: self.size] * self.scale[: self.size]
        p = float(u[self.size] * self.scale[self.size])
        run = self.run_at(p)
        monodromy = run.tangent(z, self.periods * run.period)["matrix"]
        scale = self.scale[: self.size]
        jac[:, : self.size] = (monodromy - np.eye(self.size)) * scale[None, :] / scale[:, None]
        jac[:, self.size] = self._difference(u, self.size, centre)
        return jac

    def _difference(self, u: np.ndarray, j: int, centre: np.ndarray) -> np.ndarray:
        """Column ``j`` of the residual's Jacobian by central differences. Where the
        forward and backward ones disagree beyond the map's curvature, the step
        straddles a grazing (one side touches a wall the orbit misses): the column
        again with steps a hundred times shorter, the most consistent kept (as the
        core's shooting does)."""
        h = 1e-6 * max(abs(u[j]), 1e-3 if j == self.size else 1.0)
        best: tuple[float, np.ndarray] | None = None
        for _ in range(3):
            sides: list[np.ndarray | None] = []
            for sign in (1.0, -1.0):
                moved = u.copy()
                moved[j] += sign * h
                try:
                    sides.append(self.residual(moved))
                except InvalidInputError:
                    # That side starts inside a wall: one-sided from the other.
                    sides.append(None)
            up, down = sides
            if up is None and down is None:
                raise AnalysisError("both sides of a difference step start inside a wall")
            if up is None or down is None:
                one_sided: np.ndarray = (up - centre) / h if down is None else (centre - down) / h
                return one_sided
            forward, backward = (up - centre) / h, (centre - down) / h
            size_of = float(np.max(np.abs(forward) + np.abs(backward)))
            gap = float(np.max(np.abs(forward - backward)))
            disagreement = gap / size_of if size_of > 0 else 0.0
            if best is None or disagreement < best[0]:
                best = (disagreement, (up - down) / (2 * h))
            if disagreement <= 1e-2:
                break
            h *= 1e-2
        assert best is not None  # one step at least is taken
        return best[1]

    def tangent(self, jac: np.ndarray, previous: np.ndarray | None) -> np.ndarray:
        t: np.ndarray = np.asarray(np.linalg.svd(jac)[2][-1])
        if previous is None:
            return t if t[self.size] * self.span > 0 else -t
        return t if float(np.dot(t, previous)) > 0 else -t

    def multipliers_of(self, jac: np.ndarray) -> np.ndarray:
        """The Floquet multipliers from the scaled Jacobian ``jac`` of the residual: the
        monodromy D P = S (J_z + I) S^-1."""
        monodromy = (
            (jac[:, : self.size] + np.eye(self.size))
            * self.scale[: self.size, None]
            / self.scale[None, : self.size]
        )
        return np.asarray(np.linalg.eigvals(monodromy))

    def point(self, u: np.ndarray, jac: np.ndarray) -> BranchPoint:
        p = float(u[self.size] * self.scale[self.size])
        z = u[: self.size] * self.scale[: self.size]
        multipliers = self.multipliers_of(jac)
        run = self.run_at(p)
        recorded = run.periods(z, self.periods, record=True)
        impacts = _impacts(recorded) / self.periods
        return BranchPoint(
            value=p,
            state=self.at_zero(run, z),
            floquet_multipliers=multipliers,
            stable=bool(np.all(np.abs(multipliers) < 1.0)),
            impacts_per_period=impacts,
            amplitude=run.amplitudes(recorded)[0],
        )

    def at_zero(self, run: Runner, z: np.ndarray) -> np.ndarray:
        """The state at t = 0 of the scenario's forcing of the orbit through ``z`` on the
        section: the rest of the period from it (``run`` the system on the section)."""
        if not self.section:
            return z
        rest = (1.0 - self.section) * run.period
        return np.asarray(run._run(z, rest, record=False, strobe=False)["final_state"], dtype=float)

    def clear_of_impacts(self, u: np.ndarray, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``u`` and ``t`` on a section moved away from the impacts, if one is near."""
        moved = self.cleared(u)
        if moved is u:
            return u, t
        new_t = self.tangent(self.jacobian(moved), None)
        return moved, (new_t if new_t[self.size] * t[self.size] > 0 else -new_t)

    def cleared(self, u: np.ndarray, state: np.ndarray | None = None) -> np.ndarray:
        """``u`` on a section moved to the middle of the widest stretch of the orbit
        clear of contacts where an impact is near the section or a contact is open
        across it (a contact's state (x, v) does not hold its onset, nor a damped law's
        latched approach rate: the map would begin it afresh); ``u`` itself otherwise.
        ``state``: ``u``'s state unscaled, where known to the bit (a run's final state,
        whose open contacts the runners keep: scaled and back it may differ by an ulp
        and the contact would be begun afresh)."""
        if not self.shiftable:
            return u
        p = float(u[self.size] * self.scale[self.size])
        z = u[: self.size] * self.scale[: self.size] if state is None else state
        run = self.run_at(p)
        span_t = self.periods * run.period
        contacts = run.periods(z, self.periods)["contacts"]
        move = _clear_phase(
            np.asarray(contacts["onset"], dtype=float) / span_t,
            np.asarray(contacts["separation"], dtype=float) / span_t,
        )
        if move is None:
            return u
        moved = np.asarray(
            run._run(z, move * span_t, record=False, strobe=False)["final_state"], dtype=float
        )
        self.section = (self.section + move * self.periods) % 1.0
        return np.concatenate([moved / self.scale[: self.size], [u[self.size]]])

    def correct(self, predicted: np.ndarray, t: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
        """The orbit on the plane through ``predicted`` normal to ``t`` (Newton) and its
        residual, or None where the corrector fails."""
        trial = predicted.copy()
        try:
            for _ in range(8):
                f = self.residual(trial)
                arc = float(np.dot(t, trial - predicted))
                if max(float(np.max(np.abs(f))), abs(arc)) <= self.tolerance:
                    return trial, f
                jt = self.jacobian(trial, f)
                system = np.vstack([jt, t[None, :]])
                trial = trial - np.linalg.solve(system, np.concatenate([f, [arc]]))
        except (InvalidInputError, np.linalg.LinAlgError):
            return None
        except Exception:  # a run that cannot complete near a bad point
            return None
        return None

    def locate(
        self,
        measure: Callable[[np.ndarray], float],
        u: np.ndarray,
        t: np.ndarray,
        h: float,
        ends: tuple[BranchPoint, BranchPoint],
    ) -> tuple[float, np.ndarray, np.ndarray] | None:
        """Where ``measure`` of the multipliers changes sign between ``u`` (the point
        ``ends[0]``) and the point ``h`` along ``t`` (``ends[1]``): bisection on the arc
        (each trial an orbit and its multipliers) to a thousandth of the step. The
        parameter there, the multipliers on the side where ``measure`` > 0 and the
        scaled unknowns of the last trial; None where it does not change sign or a trial
        orbit cannot be found."""
        first, last = (measure(p.floquet_multipliers) for p in ends)
        if (first > 0) == (last > 0):
            return None
        lo, hi = 0.0, 1.0
        (below, low), (above, high) = ((p.value, p.floquet_multipliers) for p in ends)
        last_trial = u
        while hi - lo > 1e-3:
            mid = 0.5 * (lo + hi)
            found = self.correct(u + mid * h * t, t)
            if found is None:
                return None
            last_trial = found[0]
            multipliers = self.multipliers_of(self.jacobian(*found))
            value = float(found[0][self.size] * self.scale[self.size])
            if (measure(multipliers) > 0) == (first > 0):
                lo, below, low = mid, value, multipliers
            else:
                hi, above, high = mid, value, multipliers
        return 0.5 * (below + above), (high if last > 0 else low), last_trial

    def along(
        self,
        kind: str,
        u: np.ndarray,
        t: np.ndarray,
        h: float,
        ends: tuple[BranchPoint, BranchPoint],
    ) -> tuple[BranchPoint, np.ndarray] | None:
        """Where the test function of ``kind`` vanishes on the arc between ``u`` (the
        point ``ends[0]``) and the point ``h`` along ``t`` (``ends[1]``): the Illinois
        method on the fraction of the arc, each trial an orbit corrected on the plane
        normal to ``t``, until the orbits either side are within
        :data:`PARAMETER_TOLERANCE` of the parameter. Beside a branch point another
        branch crosses the plane and the corrector stops converging short of that: the
        trial nearest zero is kept where its test function is within
        :data:`BRANCH_TOLERANCE`. Its branch point and scaled unknowns; None where the
        test function does not change sign there or no trial comes that close."""
        g_lo, g_hi = (test_value(kind, p.floquet_multipliers) for p in ends)
        if not (np.isfinite(g_lo) and np.isfinite(g_hi)) or (g_lo > 0) == (g_hi > 0):
            return None
        p_lo, p_hi = (p.value for p in ends)
        lo, hi, kept = 0.0, 1.0, 0
        best: tuple[float, np.ndarray, np.ndarray] | None = None
        for _ in range(ITERATIONS * 5):
            s = hi - g_hi * (hi - lo) / (g_hi - g_lo)
            if not lo < s < hi:
                s = 0.5 * (lo + hi)
            found = self.correct(u + s * h * t, t)
            jac = None if found is None else self.jacobian(*found)
            g = float("nan") if jac is None else test_value(kind, self.multipliers_of(jac))
            if found is None or jac is None or not np.isfinite(g):
                break
            value = float(found[0][self.size] * self.scale[self.size])
            if best is None or abs(g) < best[0]:
                best = (abs(g), found[0], jac)
            if (g > 0) == (g_lo > 0):
                lo, g_lo, p_lo = s, g, value
                g_hi *= 0.5 if kept == -1 else 1.0
                kept = -1
            else:
                hi, g_hi, p_hi = s, g, value
                g_lo *= 0.5 if kept == 1 else 1.0
                kept = 1
            if g == 0.0 or abs(p_hi - p_lo) <= PARAMETER_TOLERANCE * max(abs(value), 1.0):
                break
        if best is None or best[0] > BRANCH_TOLERANCE:
            return None
        return self.point(best[1], best[2]), best[1]

    def ended(self, points: list[BranchPoint], u: np.ndarray) -> str:
        """Why the corrector failed beyond the last point: at a grazing (located, and
        kept among the bifurcations), or not known."""
        if len(points) >= 2:
            travel = points[-1].value - points[-2].value
            touch = grazing_ahead(self, points[-1], u, 4 * abs(travel))
            # Ahead only: one behind was passed (and located) already.
            if touch is not None and (touch.value - points[-1].value) * travel >= 0:
                self.bifurcations.append(touch.bifurcation())
                return (
                    f"grazing: the orbit touches {touch.pair} at {self.parameter} = "
                    f"{touch.value:.12g} (beyond it, it strikes it)"
                )
        return "corrector failed (the branch may end, or turn too sharply)"

    def trace(
        self,
        state: np.ndarray,
        start_value: float,
        period: float,
        ds: float,
        stop: float,
        max_points: int,
        progress: Callable[[int, int], None] | None,
    ) -> tuple[list[BranchPoint], str]:
        """The branch from the orbit ``state`` at ``start_value`` towards ``stop`` (the
        first forcing ``period``, s), steps of about ``ds``: its points and why it
        stopped."""
        dim = self.size // 2
        u = np.concatenate([state, [start_value]]) / self.scale
        # The branch's Jacobian from a section clear of contacts (see `cleared`).
        u = self.cleared(u, state)
        jac = self.jacobian(u)
        t = self.tangent(jac, None)
        points = [self.point(u, jac)]
        u, t = self.clear_of_impacts(u, t)
        h = ds / abs(self.span)
        stopped = "max_points"
        while len(points) < max_points:
            if progress is not None:
                progress(len(points), max_points)
            solved: tuple[np.ndarray, np.ndarray] | None = None
            while h >= 1e-6:
                solved = self.correct(u + h * t, t)
                if solved is not None:
                    break
                h *= 0.5
            if solved is None:
                stopped = self.ended(points, u)
                break
            corrected = solved[0]
            jac = self.jacobian(*solved)
            new_t = self.tangent(jac, t)
            candidate = self.point(corrected, jac)
            # A step that lands on another number of impacts, or turns the tangent
            # sharply, may have jumped past a fold onto another branch: shorter steps
            # first, down to a thousandth of the asked one (where a grazing is then
            # approached, and taken, from its own side).
            turned = float(np.dot(t, new_t)) < 0.9
            changed = candidate.impacts_per_period != points[-1].impacts_per_period
            if (turned or changed) and h > 1e-3 * ds / abs(self.span):
                h *= 0.5
                continue
            # The arc between the points: their chord (the step h is only its projection
            # on the tangent, up to a fifth shorter at a fold).
            chord = float(np.linalg.norm(corrected - u)) * self.scale[self.size]
            flags, crossings = _flags(points[-1], candidate, t, new_t, self.size, chord)
            ends = (points[-1], candidate)
            located_from: dict[str, np.ndarray] = {}
            if candidate.stable != points[-1].stable and "grazing" not in flags:
                # The stability changes: where the first multiplier crosses the circle,
                # and which kind it is there (two crossings of one class-based reading
                # may be one: a complex pair leaving the circle, then meeting on the real
                # axis outside it, reads as a real one crossing +1).
                found = self.locate(lambda m: float(np.max(np.abs(m))) - 1.0, u, t, h, ends)
                if found is not None:
                    name = _kind(found[1], "fold" in flags)
                    flags = [f for f in flags if f not in _CLASSES and f != name] + [name]
                    crossings = {k: v for k, v in crossings.items() if k in flags}
                    crossings[name] = found[0]
                    located_from[name] = found[2]
            else:
                for name in [f for f in flags if f in _CLASSES]:
                    found = self.locate(functools.partial(_largest, name=name), u, t, h, ends)
                    if found is not None:
                        crossings[name] = found[0]
                        located_from[name] = found[2]
            for name in [f for f in flags if f != "grazing"]:
                # Located exactly: Newton on the extended system from the bisection's
                # last orbit (or the nearer end).
                start = located_from.get(name, corrected)
                # Between the two points, or up to the arc between them beyond (a fold
                # lies beyond both, by as much as the chord: near the turn their values
                # differ by far less than their distance from it, so a reach of their
                # difference alone had refused a fold located to 1e-14).
                reach = max(abs(candidate.value - points[-1].value), chord)
                low = min(candidate.value, points[-1].value) - reach
                refined = refine(self, name, start, (low, low + 3 * reach))
                if refined is None:
                    # Newton on the extended system is singular at a branch point (the
                    # parameter's column lies in the state's range there): along the arc.
                    refined = self.along(name, u, t, h, ends)
                if refined is not None:
                    crossings[name] = refined[0].value
                    self.bifurcations.append(
                        Bifurcation(
                            name,
                            refined[0].value,
                            refined[0].state,
                            refined[0].floquet_multipliers,
                        )
                    )
            if "grazing" in flags and new_t[self.size] * (candidate.value - points[-1].value) < 0:
                # Across a grazing the two branches' tangents differ in the state (one
                # strikes the stop): the parameter goes on the way it went.
                new_t = -new_t
            if "grazing" in flags:
                reach = max(abs(candidate.value - points[-1].value), chord)
                low = min(candidate.value, points[-1].value) - reach
                for touch in grazings_between(self, ends, (u, corrected), (low, low + 3 * reach)):
                    crossings["grazing"] = touch.value
                    self.bifurcations.append(touch.bifurcation())
            candidate.flags, candidate.crossings = flags, crossings
            points.append(candidate)
            # An orbit grown well beyond the scale (towards a resonance) rescales the
            # unknowns: measured in the start's small amplitude, the arclength would be
            # all state and the parameter would crawl.
            grown = float(np.max(candidate.amplitude, initial=0.0))
            if grown > 2 * self.scale[0]:
                old = self.scale.copy()
                self.scale[:dim] = grown
                self.scale[dim : self.size] = np.maximum(
                    self.scale[dim : self.size], 2 * math.pi / period * grown
                )
                corrected = corrected * old / self.scale
                new_t = new_t * old / self.scale
                new_t /= np.linalg.norm(new_t)
            u, t = self.clear_of_impacts(corrected, new_t)
            h = min(h * 1.5, 4 * ds / abs(self.span))
            if (candidate.value - stop) * self.span >= 0:
                stopped = "reached stop"
                break
        return points, stopped


#: How near the section (a fraction of the orbit's periods) an impact moves it.
SECTION_MARGIN = 0.02


def _clear_phase(onsets: np.ndarray, separations: np.ndarray) -> float | None:
    """Where to put the section (a fraction of the run from it) given the contacts of
    one run over the orbit's periods from the section, their ``onsets`` and
    ``separations`` as fractions of that run (an onset < 0: a contact carried across
    the section; a separation NaN: one open at the run's end, across the section too):
    None where no onset is within :data:`SECTION_MARGIN` of the section and no contact
    spans it; else the middle of the widest stretch between the contacts."""
    if onsets.size == 0:
        return None
    ends = np.where(np.isnan(separations), 1.0, np.maximum(separations, onsets))
    phases = np.mod(onsets, 1.0)
    across = bool(np.any(onsets < 0.0) or np.any(ends >= 1.0))
    near = min(float(np.min(phases)), float(1.0 - np.max(phases)))
    if near > SECTION_MARGIN and not across:
        return None
    # The contacts as arcs of the circle of phases, from each onset; the stretch after
    # each arc to the next one's start, clear of them all.
    starts = phases
    stops = phases + (ends - onsets)
    order = np.argsort(starts)
    starts, stops = starts[order], np.maximum.accumulate(stops[order])
    following = np.concatenate([starts[1:], [starts[0] + 1.0]])
    clear = following - stops
    widest = int(np.argmax(clear))
    if clear[widest] <= 0.0:
        return None
    return float(stops[widest] + clear[widest] / 2) % 1.0


def _value_of(
    data: Mapping[str, Any],
    parameter: str,
    name: str = "parameter",
    why: str = "continuation starts from the scenario's value",
) -> float:
    """The scenario's value of the dotted path ``parameter``; errors name it as ``name``
    and say ``why`` the value must be set."""
    node: Any = data
    for key in parameter.split("."):
        try:
            node = node[int(key)] if isinstance(node, list) else node[key]
        except (KeyError, IndexError, ValueError, TypeError):
            # A misspelt key is told so, with the closest (else: a key left unset).
            check_parameter_key(data, name, parameter)
            raise AnalysisError(f"{name} {parameter!r}: not set in the scenario ({why})") from None
    if isinstance(node, bool) or not isinstance(node, int | float):
        raise AnalysisError(f"{name} {parameter!r}: must be a number, got {node!r}")
    return float(node)
