"""The Masri and Caughey (1966) impact damper's symmetric two-impacts-per-period
orbits, derived from the closed form in shared/reference/forced-oracles.md (scaled
time w_n t and lengths F0 / K), shared by the tests that check orbits against them."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest
from numpy.typing import NDArray
from scipy.linalg import expm

Array = NDArray[np.float64]
EXACT: dict[str, Any] = {"method": "exact", "t_end": 1.0}

# SI values behind the scaled parameters: primary M, K, force F0.
MC_M, MC_K, MC_F0 = 2.0, 50.0, 3.0


def masri_caughey(mu: float, r: float, d: float, e: float) -> list[dict[str, Any]]:
    """The symmetric two-impact orbits (scaled: time w_n t, lengths / (F0 / K)), each
    with its admissibility, its scaled state half-way between impacts (x, y, x', y'),
    the forcing phase there, the primary's sampled motion and the monodromy."""
    p = 1 / (1 - r**2)
    half = math.pi / r  # half a forcing period, scaled
    a1 = 1 + (2 * mu * r / math.pi) * math.tan(math.pi / (2 * r))
    b1 = (2 / math.pi) * (1 - e) * (1 + mu) / (1 + e)
    disc = (a1 * d) ** 2 - (a1**2 + b1**2) * (d**2 - 4 * p**2)
    out: list[dict[str, Any]] = []
    if disc < 0:
        return out
    flow = expm(
        np.array([[0, 0, 1, 0], [0, 0, 0, 1], [-1, 0, 0, 0], [0, 0, 0, 0]], dtype=float) * half
    )
    # Velocity reset (momentum kept, relative velocity times -e) and the gap's normal.
    g1, g2 = mu * (1 + e) / (1 + mu), (1 + e) / (1 + mu)
    reset = np.eye(4)
    reset[2:, 2:] = [[1 - g1, g1], [g2, 1 - g2]]
    normal = np.array([-1.0, 1.0, 0.0, 0.0])
    for sign in (1, -1):
        q = (a1 * d + sign * math.sqrt(disc)) / (2 * (a1**2 + b1**2))
        if q <= 0:
            continue
        phi = math.atan2(b1 * q / p, (a1 * q - d / 2) / p)
        cc = (2 * mu * r * q / math.pi) / math.cos(math.pi / (2 * r))
        speed = 2 * r * q / math.pi  # the ball's, between impacts

        def x(tau: Array, phi: float = phi, cc: float = cc) -> Array:
            return p * np.cos(r * tau + phi) + cc * np.sin(tau - math.pi / (2 * r))

        def xd(tau: float, phi: float = phi, cc: float = cc) -> float:
            return -p * r * math.sin(r * tau + phi) + cc * math.cos(tau - math.pi / (2 * r))

        taus = np.linspace(0.0, half, 4001)
        xs = x(taus)
        rel = (q - speed * taus) - xs
        # The impact at tau = 0 (upper wall, y - x = d/2): before it, by the symmetry
        # x(tau + pi/r) = -x(tau), x' = -x'(pi/r) and y' = +speed; after, x'(0), -speed.
        before = np.array([-xd(half), speed])
        after = np.array([xd(0.0), -speed])
        assert rel[0] == pytest.approx(d / 2)
        assert before @ [1, mu] == pytest.approx(after @ [1, mu], abs=1e-12)
        assert after[1] - after[0] == pytest.approx(-e * (before[1] - before[0]), abs=1e-12)
        # Saltation at that impact; the one half a period later is the same (state,
        # forcing and rates all change sign), so the monodromy is (S Phi)^2.
        accel = -xs[0] + math.cos(phi)
        f_minus = np.array([before[0], before[1], accel, 0.0])
        f_plus = np.array([after[0], after[1], accel, 0.0])
        saltation = reset + np.outer(f_plus - reset @ f_minus, normal) / (normal @ f_minus)
        one = saltation @ flow
        tm = half / 2
        out.append(
            {
                "q": q,
                "admissible": bool(np.all(np.abs(rel[1:-1]) < d / 2)),
                "mid": np.array([x(np.array(tm)), 0.0, xd(tm), -speed], dtype=float),
                "phase": r * tm + phi,
                "amplitude": float(np.max(np.abs(xs))),
                "monodromy": one @ one,
            }
        )
    return out


def mc_scenario(mu: float, r: float, d: float, e: float, phase: float) -> dict[str, Any]:
    wn = math.sqrt(MC_K / MC_M)
    xst = MC_F0 / MC_K
    return {
        "structure": {"kind": "oscillator", "mass": MC_M, "stiffness": MC_K, "damping": 0.0},
        "damper": [
            {"mass": mu * MC_M, "at": 0, "clearance": d / 2 * xst, "law": "rigid", "restitution": e}
        ],
        "excitation": [
            {
                "kind": "force",
                "at": 0,
                "signal": "harmonic",
                "amplitude": MC_F0,
                "frequency": r * wn / (2 * math.pi),
                "phase": phase,
            }
        ],
        "solver": dict(EXACT),
    }


def mc_si(state: Array) -> Array:
    xst = MC_F0 / MC_K
    vst = xst * math.sqrt(MC_K / MC_M)
    out: Array = state * np.array([xst, xst, vst, vst])
    return out
