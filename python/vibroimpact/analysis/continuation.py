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
from vibroimpact.analysis.limits import AnalysisError, whole_count
from vibroimpact.analysis.orbits import orbit
from vibroimpact.analysis.parameters import forcing_period, with_parameter
from vibroimpact.analysis.runs import Runner, runner
from vibroimpact.messages import shown
from vibroimpact.model.system import System, sections_of
from vibroimpact.summary import summarised


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
    #: ``_fold``).
    crossings: dict[str, float] = field(default_factory=dict)

    def to_dict(self, n: int, k: int) -> dict[str, Any]:
        d = n + k
        s = self.state
        return {
            "value": self.value,
            "state": {
                "structure_displacement": [float(v) for v in s[:n]],
                "structure_velocity": [float(v) for v in s[d : d + n]],
                "damper_displacement": [float(v) for v in s[n:d]],
                "damper_velocity": [float(v) for v in s[d + n :]],
            },
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


#: A continuation's step (arclength, in the parameter's unit) as fractions of the range
#: it continues over, ``|stop - start|``.
STEP_RANGE = (1e-9, 1.0)


def continue_orbit(
    data: Mapping[str, Any] | System,
    parameter: str,
    *,
    stop: float,
    periods: int = 1,
    step: float | None = None,
    max_points: int = 200,
    tolerance: float = 1e-9,
    base_dir: Path | None = None,
    progress: Callable[[int, int], None] | None = None,
) -> Branch:
    """Continue the K-period orbit found from the scenario's ``[initial]`` (at the
    scenario's value of ``parameter``) towards ``stop``, with arclength steps of
    about ``step`` (in units of the parameter; default 1/50 of the range), at most
    ``max_points`` orbits. Stops at ``stop``, at ``max_points``, or when the
    corrector fails even with small steps. ``data``: a :class:`~vibroimpact.System` or a
    scenario's sections."""
    data, base_dir = sections_of(data, base_dir)
    arguments.text("parameter", parameter)
    stop = arguments.number("stop", stop)
    periods = whole_count("periods", periods, 1)
    arguments.positive("tolerance", tolerance)
    base_dir = arguments.directory("base_dir", base_dir)
    arguments.callback("progress", progress)
    start_value = _value_of(data, parameter)
    if stop == start_value:
        raise AnalysisError(f"stop: must be a finite value other than the start {start_value:g}")
    max_points = whole_count("max_points", max_points, 2)
    span = stop - start_value
    ds = abs(span) / 50 if step is None else arguments.positive("step", step)
    if not STEP_RANGE[0] * abs(span) <= ds <= STEP_RANGE[1] * abs(span):
        # A step beyond the whole range leaves at once; one of 1e-9 of it never gets
        # anywhere within max_points.
        raise AnalysisError(
            f"step: must be in [{shown(STEP_RANGE[0] * abs(span))}, {shown(abs(span))}] (from "
            f"1e-9 of the range to the range |stop - start| = {shown(abs(span))}), got "
            f"{shown(ds)}"
        )

    # The stroboscopic section, as a fraction of the forcing period after t = 0: moved
    # away from the impacts when one comes near it, where the map jumps (an impact
    # just before the section or just after it), so that the branch stays smooth.
    section = [0.0]
    shiftable = all(
        isinstance(e, Mapping) and e.get("signal") in ("harmonic", "harmonics")
        for e in data.get("excitation", ()) or ()
    )

    def run_at(p: float, fraction: float | None = None) -> Runner:
        try:
            changed = with_parameter(data, parameter, p)
            return runner(_shifted(changed, section[0] if fraction is None else fraction), base_dir)
        except InvalidInputError as err:
            raise AnalysisError(f"{parameter} = {p:g}: {err}") from None

    first_run = run_at(start_value)
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

    def residual(u: np.ndarray) -> np.ndarray:
        z = u[:size] * scale[:size]
        p = float(u[size] * scale[size])
        out: np.ndarray = (run_at(p).map(z, periods) - z) / scale[:size]
        return out

    def jacobian(u: np.ndarray, centre: np.ndarray | None = None) -> np.ndarray:
        # ``centre``: the residual at ``u``, where the caller has it. Central
        # differences; where the forward and backward ones disagree beyond the map's
        # curvature, the step straddles a grazing (one side touches a wall the orbit
        # misses): that column again with steps a hundred times shorter, the most
        # consistent kept (as the core's shooting does).
        jac = np.zeros((size, size + 1))
        if centre is None:
            centre = residual(u)
        for j in range(size + 1):
            h = 1e-6 * max(abs(u[j]), 1e-3 if j == size else 1.0)
            best: tuple[float, np.ndarray] | None = None
            for _ in range(3):
                sides: list[np.ndarray | None] = []
                for sign in (1.0, -1.0):
                    moved = u.copy()
                    moved[j] += sign * h
                    try:
                        sides.append(residual(moved))
                    except InvalidInputError:
                        # That side starts inside a wall: one-sided from the other.
                        sides.append(None)
                up, down = sides
                if up is None and down is None:
                    raise AnalysisError("both sides of a difference step start inside a wall")
                if up is None or down is None:
                    one_sided = (up - centre) / h if down is None else (centre - down) / h
                    best = (0.0, one_sided)
                    break
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
            jac[:, j] = best[1]
        return jac

    def tangent(jac: np.ndarray, previous: np.ndarray | None) -> np.ndarray:
        t: np.ndarray = np.asarray(np.linalg.svd(jac)[2][-1])
        if previous is None:
            return t if t[size] * span > 0 else -t
        return t if float(np.dot(t, previous)) > 0 else -t

    def multipliers_of(jac: np.ndarray) -> np.ndarray:
        """The Floquet multipliers from the scaled Jacobian ``jac`` of the residual: the
        monodromy D P = S (J_z + I) S^-1."""
        monodromy = (jac[:, :size] + np.eye(size)) * scale[:size, None] / scale[None, :size]
        return np.asarray(np.linalg.eigvals(monodromy))

    def point(u: np.ndarray, jac: np.ndarray) -> BranchPoint:
        p = float(u[size] * scale[size])
        z = u[:size] * scale[:size]
        multipliers = multipliers_of(jac)
        run = run_at(p)
        recorded = run.periods(z, periods, record=True)
        kinds = recorded["contacts"]["kind"]
        impacts = sum(1 for kind in kinds if kind in ("impact", "compliant")) / periods
        # The state at t = 0: the rest of the period from the section.
        at_zero = z
        if section[0]:
            at_zero = np.asarray(
                run._run(z, (1.0 - section[0]) * run.period, record=False, strobe=False)[
                    "final_state"
                ],
                dtype=float,
            )
        return BranchPoint(
            value=p,
            state=at_zero,
            floquet_multipliers=multipliers,
            stable=bool(np.all(np.abs(multipliers) < 1.0)),
            impacts_per_period=impacts,
            amplitude=run.amplitudes(recorded)[0],
        )

    def clear_of_impacts(u: np.ndarray, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``u`` and ``t`` on a section moved away from the impacts, if one is near."""
        if not shiftable:
            return u, t
        p = float(u[size] * scale[size])
        z = u[:size] * scale[:size]
        run = run_at(p)
        raw = run.periods(z, periods)
        onsets = np.asarray(raw["contacts"]["onset"], dtype=float)
        if onsets.size == 0:
            return u, t
        span_t = periods * run.period
        phases = np.sort(np.mod(onsets / span_t, 1.0))
        near = min(float(phases[0]), float(1.0 - phases[-1]))
        if near > 0.02:
            return u, t
        gaps = np.diff(np.concatenate([phases, [phases[0] + 1.0]]))
        widest = int(np.argmax(gaps))
        move = float(phases[widest] + gaps[widest] / 2) % 1.0
        moved = np.asarray(
            run._run(z, move * span_t, record=False, strobe=False)["final_state"], dtype=float
        )
        section[0] = (section[0] + move * periods) % 1.0
        u = np.concatenate([moved / scale[:size], [u[size]]])
        new_t = tangent(jacobian(u), None)
        return u, (new_t if new_t[size] * t[size] > 0 else -new_t)

    def correct(predicted: np.ndarray, t: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
        """The orbit on the plane through ``predicted`` normal to ``t`` (Newton) and its
        residual, or None where the corrector fails."""
        trial = predicted.copy()
        try:
            for _ in range(8):
                f = residual(trial)
                arc = float(np.dot(t, trial - predicted))
                if max(float(np.max(np.abs(f))), abs(arc)) <= tolerance:
                    return trial, f
                jt = jacobian(trial, f)
                system = np.vstack([jt, t[None, :]])
                trial = trial - np.linalg.solve(system, np.concatenate([f, [arc]]))
        except (InvalidInputError, np.linalg.LinAlgError):
            return None
        except Exception:  # a run that cannot complete near a bad point
            return None
        return None

    def locate(
        measure: Callable[[np.ndarray], float],
        u: np.ndarray,
        t: np.ndarray,
        h: float,
        ends: tuple[BranchPoint, BranchPoint],
    ) -> tuple[float, np.ndarray] | None:
        """Where ``measure`` of the multipliers changes sign between ``u`` (the point
        ``ends[0]``) and the point ``h`` along ``t`` (``ends[1]``): bisection on the arc
        (each trial an orbit and its multipliers) to a thousandth of the step. The
        parameter there, and the multipliers on the side where ``measure`` > 0; None
        where it does not change sign or a trial orbit cannot be found."""
        first, last = (measure(p.floquet_multipliers) for p in ends)
        if (first > 0) == (last > 0):
            return None
        lo, hi = 0.0, 1.0
        (below, low), (above, high) = ((p.value, p.floquet_multipliers) for p in ends)
        while hi - lo > 1e-3:
            mid = 0.5 * (lo + hi)
            found = correct(u + mid * h * t, t)
            if found is None:
                return None
            multipliers = multipliers_of(jacobian(*found))
            value = float(found[0][size] * scale[size])
            if (measure(multipliers) > 0) == (first > 0):
                lo, below, low = mid, value, multipliers
            else:
                hi, above, high = mid, value, multipliers
        return 0.5 * (below + above), (high if last > 0 else low)

    u = np.concatenate([first.state, [start_value]]) / scale
    jac = jacobian(u)
    t = tangent(jac, None)
    points = [point(u, jac)]
    u, t = clear_of_impacts(u, t)
    h = ds / abs(span)
    stopped = "max_points"
    while len(points) < max_points:
        if progress is not None:
            progress(len(points), max_points)
        solved: tuple[np.ndarray, np.ndarray] | None = None
        while h >= 1e-6:
            solved = correct(u + h * t, t)
            if solved is not None:
                break
            h *= 0.5
        if solved is None:
            stopped = "corrector failed (the branch may end, or turn too sharply)"
            break
        corrected = solved[0]
        jac = jacobian(*solved)
        new_t = tangent(jac, t)
        candidate = point(corrected, jac)
        # A step that lands on another number of impacts, or turns the tangent
        # sharply, may have jumped past a fold onto another branch: shorter steps
        # first, down to a thousandth of the asked one (where a grazing is then
        # approached, and taken, from its own side).
        turned = float(np.dot(t, new_t)) < 0.9
        changed = candidate.impacts_per_period != points[-1].impacts_per_period
        if (turned or changed) and h > 1e-3 * ds / abs(span):
            h *= 0.5
            continue
        # The arc between the points: their chord (the step h is only its projection
        # on the tangent, up to a fifth shorter at a fold).
        chord = float(np.linalg.norm(corrected - u)) * scale[size]
        flags, crossings = _flags(points[-1], candidate, t, new_t, size, chord)
        ends = (points[-1], candidate)
        if candidate.stable != points[-1].stable and "grazing" not in flags:
            # The stability changes: where the first multiplier crosses the circle,
            # and which kind it is there (two crossings of one class-based reading
            # may be one: a complex pair leaving the circle, then meeting on the real
            # axis outside it, reads as a real one crossing +1).
            found = locate(lambda m: float(np.max(np.abs(m))) - 1.0, u, t, h, ends)
            if found is not None:
                name = _kind(found[1], "fold" in flags)
                flags = [f for f in flags if f not in _CLASSES and f != name] + [name]
                crossings = {k: v for k, v in crossings.items() if k in flags}
                crossings[name] = found[0]
        else:
            for name in [f for f in flags if f in _CLASSES]:
                found = locate(functools.partial(_largest, name=name), u, t, h, ends)
                if found is not None:
                    crossings[name] = found[0]
        candidate.flags, candidate.crossings = flags, crossings
        points.append(candidate)
        # An orbit grown well beyond the scale (towards a resonance) rescales the
        # unknowns: measured in the start's small amplitude, the arclength would be
        # all state and the parameter would crawl.
        grown = float(np.max(candidate.amplitude, initial=0.0))
        if grown > 2 * scale[0]:
            old = scale.copy()
            scale[:dim] = grown
            scale[dim:size] = np.maximum(scale[dim:size], 2 * math.pi / first_run.period * grown)
            corrected = corrected * old / scale
            new_t = new_t * old / scale
            new_t /= np.linalg.norm(new_t)
        u, t = clear_of_impacts(corrected, new_t)
        h = min(h * 1.5, 4 * ds / abs(span))
        if (candidate.value - stop) * span >= 0:
            stopped = "reached stop"
            break
    return Branch(parameter, periods, points, stopped, first_run.n, first_run.k)


def _fold(p0: float, p1: float, m0: float, m1: float) -> float:
    """Where the parameter turns between two points of a branch: the extremum of its
    cubic Hermite interpolant along the arc (values ``p0``, ``p1``, rates along the arc
    times its length ``m0``, ``m1`` of opposite signs). Beyond both points, on the side
    they turn from, as a fold is (a linear interpolation stays between them)."""
    a = 6.0 * (p0 - p1) + 3.0 * (m0 + m1)
    b = 6.0 * (p1 - p0) - 4.0 * m0 - 2.0 * m1
    # The slope a theta^2 + b theta + m0 goes from m0 to m1, of opposite signs: its one
    # root in [0, 1] by bisection (no choice between two roots to get wrong).
    lo, hi = 0.0, 1.0
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        if (a * mid * mid + b * mid + m0) * m0 > 0:
            lo = mid
        else:
            hi = mid
    theta = 0.5 * (lo + hi)
    h00, h10 = 2 * theta**3 - 3 * theta**2 + 1, theta**3 - 2 * theta**2 + theta
    h01, h11 = -2 * theta**3 + 3 * theta**2, theta**3 - theta**2
    return h00 * p0 + h10 * m0 + h01 * p1 + h11 * m1


# Below this imaginary part a multiplier is real.
_REAL = 1e-6
#: The multipliers whose crossing of the unit circle each flag reports.
_CLASSES: dict[str, Callable[[complex], bool]] = {
    "flip": lambda m: abs(m.imag) <= _REAL and m.real < 0,
    "neimark-sacker": lambda m: abs(m.imag) > _REAL,
    "branch": lambda m: abs(m.imag) <= _REAL and m.real > 0,
}


def _largest(multipliers: np.ndarray, name: str) -> float:
    """The largest modulus of the multipliers of class ``name``, less 1 (-1 for none)."""
    chosen = [abs(m) for m in multipliers if _CLASSES[name](m)]
    return max(chosen) - 1.0 if chosen else -1.0


def _kind(outside: np.ndarray, fold: bool) -> str:
    """The bifurcation of the multiplier that has just left the unit circle (the
    largest of ``outside``): a flip (real, negative), a Neimark-Sacker (complex) or, real
    and positive, a fold where the parameter turns and a branch point otherwise."""
    m = complex(outside[int(np.argmax(np.abs(outside)))])
    if abs(m.imag) > _REAL:
        return "neimark-sacker"
    if m.real < 0:
        return "flip"
    return "fold" if fold else "branch"


def _flags(
    before: BranchPoint,
    after: BranchPoint,
    t0: np.ndarray,
    t1: np.ndarray,
    size: int,
    arc: float,
) -> tuple[list[str], dict[str, float]]:
    """The bifurcations between ``before`` and ``after``, whose unit tangents are
    ``t0`` and ``t1`` (in the scaled coordinates; the parameter's component at ``size``)
    and which lie ``arc`` apart along the branch (their scaled chord times the
    parameter's scale: the rates ``t[size] * arc`` are then in the parameter's unit)."""
    if before.impacts_per_period != after.impacts_per_period:
        # A grazing: the two orbits lie on two smooth branches, whose tangents and
        # multipliers say nothing of each other (the multipliers jump there), so no
        # fold, flip or other crossing is read between them.
        return ["grazing"], {}
    flags: list[str] = []
    crossings: dict[str, float] = {}
    if t0[size] * t1[size] < 0:
        flags.append("fold")
        # The parameter's rate along the branch is zero there.
        crossings["fold"] = _fold(before.value, after.value, t0[size] * arc, t1[size] * arc)
    for name in _CLASSES:
        if name == "branch" and "fold" in flags:
            continue
        a = _largest(before.floquet_multipliers, name)
        b = _largest(after.floquet_multipliers, name)
        if (a > 0) != (b > 0):
            flags.append(name)
            crossings[name] = before.value + (after.value - before.value) * a / (a - b)
    return flags, crossings


def _shifted(data: dict[str, Any], fraction: float) -> dict[str, Any]:
    """``data`` with its harmonic excitations started ``fraction`` of the forcing period
    later (each phase advanced by its frequency times that time): t = 0 then is that
    instant of the original forcing."""
    if not fraction:
        return data
    out = copy.deepcopy(data)
    delay = fraction * forcing_period(out)
    for e in out.get("excitation", ()):
        if e.get("signal") == "harmonic":
            e["phase"] = float(e.get("phase", 0.0)) + 2 * math.pi * e["frequency"] * delay
        elif e.get("signal") == "harmonics":
            phases = list(e.get("phases", [0.0] * len(e["frequencies"])))
            e["phases"] = [
                float(ph) + 2 * math.pi * f * delay
                for ph, f in zip(phases, e["frequencies"], strict=True)
            ]
    return out


def _value_of(data: Mapping[str, Any], parameter: str) -> float:
    node: Any = data
    for key in parameter.split("."):
        try:
            node = node[int(key)] if isinstance(node, list) else node[key]
        except (KeyError, IndexError, ValueError, TypeError):
            raise AnalysisError(
                f"parameter {parameter!r}: not set in the scenario (continuation starts "
                "from the scenario's value)"
            ) from None
    if isinstance(node, bool) or not isinstance(node, int | float):
        raise AnalysisError(f"parameter {parameter!r}: must be a number, got {node!r}")
    return float(node)
