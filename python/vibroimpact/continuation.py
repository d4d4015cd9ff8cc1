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
import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from vibroimpact._core import InvalidInputError
from vibroimpact.analyses import (
    AnalysisError,
    Runner,
    forcing_period,
    orbit,
    runner,
    with_parameter,
)


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
    #: parameter at which the crossing multiplier's modulus reaches 1 (linear
    #: interpolation), or at which the parameter turns (a fold: the extremum of its
    #: cubic along the arc, see ``_fold``).
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


@dataclass
class Branch:
    """A continued branch of K-period orbits, and why it stopped."""

    parameter: str
    periods: int
    points: list[BranchPoint]
    stopped: str
    n: int
    k: int


def continue_orbit(
    data: Mapping[str, Any],
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
    corrector fails even with small steps."""
    start_value = _value_of(data, parameter)
    if not math.isfinite(stop) or stop == start_value:
        raise AnalysisError(f"stop: must be a finite value other than the start {start_value:g}")
    if not isinstance(max_points, int) or max_points < 2:
        raise AnalysisError(f"max_points: must be a whole number >= 2, got {max_points!r}")
    span = stop - start_value
    ds = abs(span) / 50 if step is None else float(step)
    if not ds > 0:
        raise AnalysisError(f"step: must be > 0, got {step!r}")

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
    x_scale = max(float(np.max(np.abs(first.state[:dim]), initial=0.0)), 1e-12)
    v_scale = max(float(np.max(np.abs(first.state[dim:]), initial=0.0)), 1e-12)
    scale = np.concatenate([np.full(dim, x_scale), np.full(dim, v_scale), [abs(span)]])

    def residual(u: np.ndarray) -> np.ndarray:
        z = u[:size] * scale[:size]
        p = float(u[size] * scale[size])
        out: np.ndarray = (run_at(p).map(z, periods) - z) / scale[:size]
        return out

    def jacobian(u: np.ndarray) -> np.ndarray:
        jac = np.zeros((size, size + 1))
        for j in range(size + 1):
            h = 1e-6 * max(abs(u[j]), 1e-3 if j == size else 1.0)
            plus, minus = u.copy(), u.copy()
            plus[j] += h
            minus[j] -= h
            jac[:, j] = (residual(plus) - residual(minus)) / (2 * h)
        return jac

    def tangent(jac: np.ndarray, previous: np.ndarray | None) -> np.ndarray:
        t: np.ndarray = np.asarray(np.linalg.svd(jac)[2][-1])
        if previous is None:
            return t if t[size] * span > 0 else -t
        return t if float(np.dot(t, previous)) > 0 else -t

    def point(u: np.ndarray, jac_z: np.ndarray) -> BranchPoint:
        p = float(u[size] * scale[size])
        z = u[:size] * scale[:size]
        # The monodromy from the scaled Jacobian: D P = S (J_z + I) S^-1.
        monodromy = (jac_z + np.eye(size)) * scale[:size, None] / scale[None, :size]
        multipliers = np.linalg.eigvals(monodromy)
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
            amplitude=np.asarray(recorded["peaks"], dtype=float),
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

    u = np.concatenate([first.state, [start_value]]) / scale
    jac = jacobian(u)
    t = tangent(jac, None)
    points = [point(u, jac[:, :size])]
    u, t = clear_of_impacts(u, t)
    h = ds / abs(span)
    stopped = "max_points"
    while len(points) < max_points:
        if progress is not None:
            progress(len(points), max_points)
        corrected: np.ndarray | None = None
        while h >= 1e-6:
            predicted = u + h * t
            trial = predicted.copy()
            try:
                for _ in range(8):
                    f = residual(trial)
                    arc = float(np.dot(t, trial - predicted))
                    if max(float(np.max(np.abs(f))), abs(arc)) <= tolerance:
                        corrected = trial
                        break
                    jt = jacobian(trial)
                    system = np.vstack([jt, t[None, :]])
                    trial = trial - np.linalg.solve(system, np.concatenate([f, [arc]]))
            except (InvalidInputError, np.linalg.LinAlgError):
                corrected = None
            except Exception:  # a run that cannot complete near a bad point
                corrected = None
            if corrected is not None:
                break
            h *= 0.5
        if corrected is None:
            stopped = "corrector failed (the branch may end, or turn too sharply)"
            break
        jac = jacobian(corrected)
        new_t = tangent(jac, t)
        candidate = point(corrected, jac[:, :size])
        # The arc between the points: their chord (the step h is only its projection
        # on the tangent, up to a fifth shorter at a fold).
        chord = float(np.linalg.norm(corrected - u)) * scale[size]
        candidate.flags, candidate.crossings = _flags(points[-1], candidate, t, new_t, size, chord)
        points.append(candidate)
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
    real = 1e-6
    classes: dict[str, Callable[[complex], bool]] = {
        "flip": lambda m: abs(m.imag) <= real and m.real < 0,
        "neimark-sacker": lambda m: abs(m.imag) > real,
        "branch": lambda m: abs(m.imag) <= real and m.real > 0,
    }

    def largest(multipliers: np.ndarray, member: Callable[[complex], bool]) -> float:
        chosen = [abs(m) for m in multipliers if member(m)]
        return max(chosen) - 1.0 if chosen else -1.0

    for name, member in classes.items():
        if name == "branch" and "fold" in flags:
            continue
        a = largest(before.floquet_multipliers, member)
        b = largest(after.floquet_multipliers, member)
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
