"""A test-only oracle: scipy's solve_ivp with events and a hand-written stick-slip
switch, for a horizontal impact damper with Coulomb friction on a forced oscillator.

The structure (mass ``M``, stiffness ``K``, damping ``C``) is forced by ``P cos(2 pi f
t)``; the loose mass ``m`` rattles between rigid walls at ``u = z - x = +-clearance``
(Newton's restitution ``e``) and rubs on the structure with Coulomb friction: a force
``mu N`` against the relative velocity ``u'`` while sliding; stuck while the force
holding it, ``m a`` (``a`` the common acceleration), is within ``mu_s N``. A chattering
sequence on a wall (rebounds slower than ``SETTLED`` m/s) ends with the mass carried by
that wall, held there by the wall and the friction together until the wall would have
to pull by more than ``mu_s N``; it then slides off. Written from the equations of
motion, independent of the engine (also the benchmark's peer).
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np
from scipy.integrate import solve_ivp

#: A rebound slower than this (m/s) ends a chattering sequence: the mass stays on the
#: wall (its remaining flights would last < 1e-6 s in all).
SETTLED = 1e-7


@dataclass(frozen=True)
class HorizontalDamper:
    """SI units throughout."""

    M: float = 1.0
    K: float = 4000.0
    C: float = 2.0
    m: float = 0.1
    clearance: float = 0.01
    restitution: float = 0.6
    mu: float = 0.2
    mu_static: float = 0.3
    normal: float = 0.981
    P: float = 30.0
    frequency: float = 10.0

    def toml_sections(self) -> dict:
        """The same system as the scenario's sections (dicts)."""
        return {
            "structure": {
                "kind": "oscillator",
                "mass": self.M,
                "stiffness": self.K,
                "damping": self.C,
            },
            "damper": [
                {
                    "mass": self.m,
                    "at": 0,
                    "clearance": self.clearance,
                    "law": "rigid",
                    "restitution": self.restitution,
                    "friction": self.mu,
                    "static_friction": self.mu_static,
                    "normal_force": self.normal,
                }
            ],
            "excitation": [
                {
                    "kind": "force",
                    "at": 0,
                    "signal": "harmonic",
                    "amplitude": self.P,
                    "frequency": self.frequency,
                }
            ],
        }


def simulate(
    p: HorizontalDamper,
    t_end: float,
    rtol: float = 1e-11,
    atol: float = 1e-14,
    y0=(0.0, 0.0, 0.0, 0.0),
    max_step: float = 1e-4,
) -> tuple[np.ndarray, int]:
    """The state ``(x, z, v, w)`` at ``t_end`` from ``y0`` at rest, and the number of
    events handled (impacts and stick-slip switches). Steps are at most ``max_step``
    (s): a longer step can pass over a stop and a return to the wall together, where
    the ends show the gap's crossing but not the sliding velocity's two."""
    omega = 2.0 * math.pi * p.frequency
    kinetic, held = p.mu * p.normal, p.mu_static * p.normal

    def force(t: float, x: float, v: float) -> float:
        return p.P * math.cos(omega * t) - p.K * x - p.C * v

    def sliding(t, y, s):
        x, z, v, w = y
        f = s * kinetic  # s = sign(u'), u' = w - v: the mass feels -f
        return [v, w, (force(t, x, v) + f) / p.M, -f / p.m]

    def stuck(t, y, s):
        x, z, v, w = y
        a = force(t, x, v) / (p.M + p.m)
        return [v, v, a, a]

    def upper(t, y, s):
        return p.clearance - (y[1] - y[0])

    def lower(t, y, s):
        return p.clearance + (y[1] - y[0])

    def stopped(t, y, s):
        return y[3] - y[2]

    def slips(t, y, s):
        a = force(t, y[0], y[2]) / (p.M + p.m)
        return held - abs(p.m * a)

    def leaves(t, y, s):
        # On the lower wall (s = 1) the wall pushes the mass by m a; on the upper one
        # (s = -1) by -m a; the friction holds on until it would pull beyond mu_s N.
        a = force(t, y[0], y[2]) / (p.M + p.m)
        return s * p.m * a + held

    for event in (upper, lower, slips, leaves):
        event.terminal, event.direction = True, -1
    stopped.terminal = True

    def holding(t, y):
        """The friction force that keeps the mass with the structure (on the mass)."""
        return p.m * force(t, y[0], y[2]) / (p.M + p.m)

    def slide(t, y, s):
        """Sliding from rest along ``s``: into a wall the mass rests on, it is carried."""
        if s > 0 and upper(t, y, s) < 1e-12:
            return ("wall", -1.0)
        if s < 0 and lower(t, y, s) < 1e-12:
            return ("wall", 1.0)
        # Set off by a few units of round-off: solve_ivp finds an event at its start
        # where the value is zero to round-off at both ends of its first step.
        y[3] = y[2] + s * 1e-14 * max(abs(y[2]), 1.0)
        return ("slide", s)

    t, y = 0.0, np.array(y0, dtype=float)
    u = y[3] - y[2]
    mode = ("slide", math.copysign(1.0, u) if u != 0 else 1.0)
    if u == 0:
        mode = ("stuck", 0.0) if abs(holding(0.0, y)) <= held else ("slide", 0.0)
    if mode == ("slide", 0.0):
        mode = ("slide", -math.copysign(1.0, holding(0.0, y)))
    events = 0
    while t < t_end:
        kind, s = mode
        if kind == "slide":
            stopped.direction = -s  # u' of sign s falls to zero
            rhs, watch = sliding, [upper, lower, stopped]
        elif kind == "wall":
            rhs, watch = stuck, [leaves]
        else:
            rhs, watch = stuck, [upper, lower, slips]
        sol = solve_ivp(
            rhs,
            (t, t_end),
            y,
            args=(s,),
            events=watch,
            rtol=rtol,
            atol=atol,
            method="DOP853",
            max_step=max_step,
        )
        hits = [(te[0], i) for i, te in enumerate(sol.t_events) if te.size]
        if not hits:
            return sol.y[:, -1], events
        t, which = min(hits)
        y = sol.y_events[which][0].copy()
        events += 1
        if kind == "slide" and which == 2:
            y[3] = y[2]
            need = holding(t, y)
            mode = ("stuck", 0.0) if abs(need) <= held else slide(t, y, -math.copysign(1.0, need))
            continue
        if kind == "stuck" and which == 2:
            need = holding(t, y)
            mode = slide(t, y, -math.copysign(1.0, need))
            continue
        if kind == "wall":
            mode = ("slide", s)  # off the lower wall (s = 1) upwards, and so on
            continue
        # An impact: the relative velocity reverses with e, the momentum is kept. The
        # mass is put 1e-16 m off the wall: solve_ivp finds an event at its start where
        # the gap is zero to round-off at both ends of its first step.
        y[1] = y[0] + (p.clearance - 1e-16 if which == 0 else -p.clearance + 1e-16)
        u = y[3] - y[2]
        total = p.M + p.m
        y[2] += p.m * (1 + p.restitution) * u / total
        y[3] -= p.M * (1 + p.restitution) * u / total
        u = y[3] - y[2]
        if abs(u) < SETTLED:
            # The chattering sequence ends: carried by the wall (lower: s = 1).
            y[3] = y[2] = (p.M * y[2] + p.m * y[3]) / total
            mode = ("wall", 1.0 if which == 1 else -1.0)
        elif u == 0:
            need = holding(t, y)
            mode = ("stuck", 0.0) if abs(need) <= held else ("slide", -math.copysign(1.0, need))
        else:
            mode = ("slide", math.copysign(1.0, u))
    return y, events


@functools.cache
def horizontal_damper_at(t_end: float) -> tuple[np.ndarray, int]:
    """``simulate(HorizontalDamper(), t_end, max_step=2e-5)``, run once per process: the
    event-driven scipy run takes some 20 s and several tests compare against it."""
    return simulate(HorizontalDamper(), t_end, max_step=2e-5)
