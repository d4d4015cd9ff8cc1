"""Grazings located exactly: the parameter at which a periodic orbit that misses a wall
(a stop, or one side of a damper) comes to touch it at zero speed (the gap's minimum
over the orbit reaching zero), by Newton's method on the extended system

    P_p(z) - z = 0,    g(x(tau)) = 0,    g'(x(tau)) = 0

in the unknowns ``(z, p, tau)``: the orbit's state at t = 0, the parameter and the
instant of the touch. ``g = offset + h . x`` is the wall's gap. The runs are of the
system without that wall (a stop removed, a damper's side given an infinite clearance):
on the grazing orbit its impulse is zero, so the orbit found is the system's own;
without it, an iterate a little beyond the grazing meets no impact (whose speed, growing
as the square root of the overshoot, would break Newton's convergence). The state's
columns come from the tangent flow (``P``'s monodromy and the flow's derivative up to
``tau``), the instant's from the state's rate there, the parameter's from central
differences. SI units."""

from __future__ import annotations

import copy
import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from vibroimpact._core import interactions
from vibroimpact.analysis.located import Bifurcation
from vibroimpact.analysis.parameters import shifted, with_parameter
from vibroimpact.analysis.runs import Runner, begun, runner
from vibroimpact.model.system import listed_tables

if TYPE_CHECKING:
    from vibroimpact.analysis.continuation import BranchPoint, _Arc

#: Newton iterations, and the parameter's tolerance relative to its size.
ITERATIONS = 16
PARAMETER_TOLERANCE = 1e-12
#: The farthest a Newton iterate's touch instant may stand from the section, in the
#: orbit's spans (beyond it Newton has left the grazing: None).
TOUCH_SPANS = 4.0
#: The samples of a gap over the orbit that give Newton its first instant.
SAMPLES = 64


@dataclass
class Grazing:
    """A grazing located: the parameter's ``value``, the orbit's ``state`` at t = 0,
    its Floquet multipliers (of the flow that misses the wall: at the grazing the
    wall's impulse is zero), the wall grazed as ``pair`` (``"stop 0"``, ``"damper 0
    upper"``) and the ``time`` of the
    touch after t = 0 (s)."""

    value: float
    state: np.ndarray
    floquet_multipliers: np.ndarray
    pair: str
    time: float
    #: The scaled unknowns ``(z, p, tau)`` Newton converged to (a curve's next guess).
    unknowns: np.ndarray

    def bifurcation(self) -> Bifurcation:
        """As a branch lists it."""
        return Bifurcation(
            "grazing", self.value, self.state, self.floquet_multipliers, self.pair, self.time
        )


#: A damper's two walls, in the order the core lists them, and the sign of each one's
#: gap row on the loose mass's own coordinate (the upper wall's gap closes as it rises).
SIDES = {"upper": -1.0, "lower": 1.0}


def _kind(pair: str) -> str:
    """``"damper"`` or ``"stop"`` for a damper's walls or a stop (``"damper 0"``,
    ``"stop 1"``), else ``""``: a damper's friction (``"damper 0 friction"``), a friction
    element or a collision has no wall."""
    words = pair.split()
    return words[0] if len(words) == 2 and words[0] in ("damper", "stop") else ""


def walls(pairs: list[str]) -> list[str]:
    """The walls of the pairs named ``pairs`` whose grazing is located: a stop is its
    own wall (``"stop 0"``), a damper has two (``"damper 0 upper"``, ``"damper 0
    lower"``); collisions between loose masses and friction are not located."""
    out: list[str] = []
    for pair in pairs:
        if _kind(pair) == "damper":
            out.extend(f"{pair} {side}" for side in SIDES)
        elif _kind(pair) == "stop":
            out.append(pair)
    return out


def _without_wall(data: Mapping[str, Any], wall: str) -> dict[str, Any]:
    """``data`` without the wall named ``wall``: a stop removed, or a damper's side
    given an infinite clearance (no wall there; the other side's kept as it was)."""
    out = copy.deepcopy(dict(data))
    words = wall.split()
    index = int(words[1])
    if words[0] == "stop":
        out["stop"] = listed_tables(out.get("stop"))
        del out["stop"][index]
        return out
    out["damper"] = listed_tables(out.get("damper"))
    table = dict(out["damper"][index])
    if "clearance" in table:
        both = table.pop("clearance")
        table["lower_clearance"] = table["upper_clearance"] = both
    table[f"{words[2]}_clearance"] = math.inf
    out["damper"][index] = table
    return out


def _wall_row(system: Any, wall: str, dampers: int) -> dict[str, Any] | None:
    """The gap row (``h``, ``offset``) of the wall named ``wall`` in the prepared
    ``system`` with ``dampers`` loose masses: a stop's own, or of a damper's two the one
    whose ``h`` has the side's sign on the loose mass's coordinate; None where that
    side has no wall."""
    words = wall.split()
    pair = " ".join(words[:2])
    rows = [r for r in interactions(system) if r["pair"] == pair]
    if words[0] == "stop":
        return rows[0]
    # The dampers' coordinates are the last, in order: damper j's is dim - k + j.
    coordinate = len(rows[0]["h"]) - dampers + int(words[1])
    return next((r for r in rows if np.sign(r["h"][coordinate]) == SIDES[words[2]]), None)


class _Wall:
    """One wall (a stop, or one side of a damper) of a continuation's system at any
    parameter: the system's runs without it, and its gap's row (from the system with
    it, whose offset may be the very parameter)."""

    def __init__(self, arc: _Arc, pair: str) -> None:
        self.arc, self.pair = arc, pair
        self._cache: dict[float, tuple[Runner, np.ndarray, float]] = {}

    def at(self, p: float) -> tuple[Runner, np.ndarray, float]:
        """The runs without the wall at ``p``, and its gap's ``h`` and offset (m)."""
        if p not in self._cache:
            arc = self.arc
            changed = shifted(with_parameter(arc.data, arc.parameter, p), arc.section)
            full = runner(changed, arc.base_dir)
            row = _wall_row(full.system(), self.pair, full.k)
            if row is None:
                raise StopIteration(f"{self.pair}: no such wall")
            free = runner(_without_wall(changed, self.pair), arc.base_dir)
            if len(self._cache) > 8:
                self._cache.clear()
            self._cache[p] = (free, np.asarray(row["h"], dtype=float), float(row["offset"]))
        return self._cache[p]

    def gap(self, p: float, z: np.ndarray, tau: float) -> tuple[np.ndarray, dict[str, Any]]:
        """The gap and its rate (m, m/s) at ``tau`` s from ``z``, and that run's tangent
        map."""
        free, h, offset = self.at(p)
        raw = free.tangent(z, tau)
        d = len(h)
        x = raw["state"]
        return np.array([offset + h @ x[:d], h @ x[d:]]), raw

    def first_instant(self, p: float, z: np.ndarray) -> float:
        """Where over the orbit from ``z`` the gap is least (s after t = 0): the least of
        ``SAMPLES`` samples, refined by the parabola through it and its neighbours; near
        t = 0 taken a period later (an instant Newton keeps positive)."""
        free, h, offset = self.at(p)
        span = self.arc.periods * free.period
        raw = free.system().run(
            [float(v) for v in z], span, strobe_period=span / SAMPLES, record_from=None
        )
        d = len(h)
        states = np.asarray(raw["strobe"], dtype=float).reshape(-1, 2 * d)
        times = np.asarray(raw["strobe_time"], dtype=float)
        gaps = offset + states[:, :d] @ h
        i = int(np.argmin(gaps))
        tau = float(times[i])
        if 0 < i < len(gaps) - 1:
            below, here, above = gaps[i - 1], gaps[i], gaps[i + 1]
            curvature = below - 2 * here + above
            if curvature > 0:
                tau += 0.5 * (below - above) / curvature * (times[1] - times[0])
        return away_from_zero(tau, span)


def away_from_zero(tau: float, span: float) -> float:
    """A touch's instant ``tau`` in [0, ``span``) as Newton starts from it: near t = 0
    a ``span`` later (Newton keeps the instant positive)."""
    return tau + span if tau < 0.05 * span else tau


def struck(run: Runner, state: np.ndarray, periods: int) -> set[str]:
    """The walls the orbit from ``state`` strikes over ``periods`` forcing periods
    (:func:`walls`' names): a damper's side is the wall whose gap is closed at the
    contact's onset."""
    raw = run.periods(state, periods, record=True)
    names = raw["pairs"]
    contacts = raw["contacts"]
    hit: set[str] = set()
    rows = zip(contacts["pair"], contacts["kind"], contacts["onset"], begun(contacts), strict=True)
    for p, kind, onset, new in rows:
        name = names[p]
        # A contact carried from the run before (or in progress at its start) strikes
        # again later.
        if kind not in ("impact", "compliant") or not new:
            continue
        if _kind(name) != "damper":
            hit.add(name)
        elif not {f"{name} {side}" for side in SIDES} <= hit:
            hit.add(_side_struck(run, state, name, float(onset)))
    return hit


def _side_struck(run: Runner, state: np.ndarray, damper: str, onset: float) -> str:
    """Which wall of ``damper`` a contact at ``onset`` s after ``state``'s t = 0
    strikes: the one whose gap is the nearer to closed then."""
    system = run.system()
    at = np.asarray(state, dtype=float)
    if onset > 0:
        at = np.asarray(system.run([float(v) for v in state], onset)["final_state"], dtype=float)
    gaps = {}
    for wall in (f"{damper} {side}" for side in SIDES):
        row = _wall_row(system, wall, run.k)
        if row is not None:
            h = np.asarray(row["h"], dtype=float)
            gaps[wall] = abs(float(row["offset"]) + h @ at[: len(h)])
    return min(gaps, key=lambda wall: gaps[wall])


def grazings_between(
    arc: _Arc,
    ends: tuple[BranchPoint, BranchPoint],
    unknowns: tuple[np.ndarray, np.ndarray],
    within: tuple[float, float],
) -> list[Grazing]:
    """The grazings between two points of a branch (scaled ``unknowns`` of each, in
    the arc's current section) whose number of impacts differs: of each wall one end
    strikes and the other misses, located from the end that misses it, kept where the
    parameter lies ``within`` the interval."""
    hit = [
        struck(arc.run_at(p.value), u[: arc.size] * arc.scale[: arc.size], arc.periods)
        for p, u in zip(ends, unknowns, strict=True)
    ]
    found = []
    for pair in sorted(set(walls(sorted(hit[0] | hit[1]))) & (hit[0] ^ hit[1])):
        start = unknowns[0] if pair in hit[1] else unknowns[1]
        located = locate_grazing(arc, pair, start)
        if located is not None and min(within) <= located.value <= max(within):
            found.append(located)
    return found


def locate_grazing(
    arc: _Arc, pair: str, start: np.ndarray, tau: float | None = None
) -> Grazing | None:
    """The grazing of the wall ``pair`` (:func:`walls`' names) near the scaled unknowns
    ``start`` (state and parameter, as a continuation scales them, and optionally the
    touch's instant in ``periods`` forcing periods, as :attr:`Grazing.unknowns` holds
    it; an orbit that misses the wall), by Newton's method on the extended system (see
    the module); ``tau`` the touch's instant (s) where known, else the orbit's least gap.
    None where Newton does not converge or a run fails there."""
    try:
        return _newton(arc, _Wall(arc, pair), start, tau)
    except (ValueError, ArithmeticError, RuntimeError, np.linalg.LinAlgError, StopIteration):
        return None


def _newton(arc: _Arc, wall: _Wall, start: np.ndarray, tau: float | None) -> Grazing | None:
    size = arc.size
    z_scale, p_scale = arc.scale[:size], float(arc.scale[size])
    w = np.asarray(start[: size + 1], dtype=float).copy()
    p = float(w[size] * p_scale)
    free = wall.at(p)[0]
    t_scale = arc.periods * free.period
    if tau is None and len(start) > size + 1:
        tau = float(start[size + 1]) * t_scale
    if tau is None:
        tau = wall.first_instant(p, w[:size] * z_scale)
    x_scale, v_scale = float(z_scale[0]), float(z_scale[size // 2])
    g_scale = np.array([x_scale, v_scale])
    w = np.concatenate([w, [tau / t_scale]])
    for _ in range(ITERATIONS):
        z, p, tau = w[:size] * z_scale, float(w[size] * p_scale), float(w[size + 1] * t_scale)
        # The touch lies within the orbit's span; an iterate far beyond it has left
        # the grazing (and would have the gap's run integrate for as long: once 1e8 s).
        if not 0 < tau <= TOUCH_SPANS * t_scale:
            return None
        free, h, _ = wall.at(p)
        d = len(h)
        whole = free.tangent(z, arc.periods * free.period)
        touch, part = wall.gap(p, z, tau)
        rows = np.zeros((2, 2 * d))
        rows[0, :d], rows[1, d:] = h, h
        f = np.concatenate([(whole["state"] - z) / z_scale, touch / g_scale])
        jac = np.zeros((size + 2, size + 2))
        jac[:size, :size] = (whole["matrix"] - np.eye(size)) * z_scale[None, :] / z_scale[:, None]
        jac[size:, :size] = rows @ part["matrix"] * z_scale[None, :] / g_scale[:, None]
        jac[size:, size + 1] = rows @ part["rate"] * t_scale / g_scale
        step = 1e-6 * max(abs(p), 1e-3 * p_scale, 1e-12)
        sides = []
        for sign in (1.0, -1.0):
            moved = p + sign * step
            run = wall.at(moved)[0]
            ends = run.map(z, arc.periods)
            sides.append(np.concatenate([ends / z_scale, wall.gap(moved, z, tau)[0] / g_scale]))
        jac[:, size] = (sides[0] - sides[1]) / (2 * step) * p_scale
        delta = np.linalg.solve(jac, f)
        w = w - delta
        p = float(w[size] * p_scale)
        moved_by = abs(float(delta[size] * p_scale))
        if (
            moved_by <= PARAMETER_TOLERANCE * max(abs(p), 1.0)
            and np.max(np.abs(f)) <= arc.tolerance
        ):
            z, tau = w[:size] * z_scale, float(w[size + 1] * t_scale)
            free = wall.at(p)[0]
            span = arc.periods * free.period
            monodromy = free.tangent(z, span)["matrix"]
            # Reported on the scenario's clock (the arc's section may have moved): the
            # state at t = 0, the touch within the orbit's span after it.
            instant = (tau - (1.0 - arc.section) * free.period) % span
            return Grazing(
                p, arc.at_zero(free, z), np.linalg.eigvals(monodromy), wall.pair, instant, w
            )
    return None


def grazing_ahead(arc: _Arc, last: BranchPoint, u: np.ndarray, reach: float) -> Grazing | None:
    """The grazing where a branch's corrector failed (past a grazing the map has no
    derivative: the orbit strikes with a speed growing as the square root of the
    overshoot): of any wall, located from the last point's scaled unknowns ``u``, the
    nearest within ``reach`` of its parameter; None where there is none."""
    names = arc.run_at(last.value).periods(last.state, 1, record=True)["pairs"]
    found = [
        located
        for pair in walls(names)
        if (located := locate_grazing(arc, pair, u)) is not None
        and abs(located.value - last.value) <= reach
    ]
    return min(found, key=lambda g: abs(g.value - last.value), default=None)
