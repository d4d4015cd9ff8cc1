"""Forced-response analyses (vibroimpact.analyses) against published closed forms.

Every expected value is derived here, never read from the code under test:

- Ball on a harmonically vibrating table (Holmes 1982; Luck and Mehta 1993): the
  period-one orbit, its impact map's Jacobian and the period-doubling threshold.
- One-sided impact oscillator (Shaw and Holmes 1983): the period-one orbit from the
  quadratic in the impact speed, its admissibility, and the monodromy ``S Phi``.
- Impact damper (Masri and Caughey 1966): the symmetric orbit with two impacts per
  period, its admissibility, and its multipliers from the saltation matrices.
- Forced linear baselines: ``(K - w^2 M + i w C) Q = F`` and, without contacts, the
  Floquet multipliers ``eig(expm(A T))``.
- ``method = "exact"`` against ``"dop853"`` on forced rigid pairs, and its refusals.

The formulas are those of /work/shared/reference/forced-oracles.md. Shooting seeds
start mid-flight (the forcing phase is shifted so that t = 0 is between impacts), where
the stroboscopic map is smooth.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest
from numpy.typing import NDArray
from scipy.linalg import expm

import vibroimpact as vi
from orbit_checks import spectrum_distance, state_error  # noqa: E402
from vibroimpact import analysis as an
from vibroimpact.system import SystemSolution

Array = NDArray[np.float64]
Complex = NDArray[np.complex128]

EXACT: dict[str, Any] = {"method": "exact", "t_end": 1.0}
DOP853: dict[str, Any] = {"method": "dop853", "t_end": 1.0, "rtol": 1e-12, "atol": 1e-15}


# --------------------------------------------------------------------------------------
# Ball on a vibrating table (Holmes)


def holmes(
    gamma: float, e: float, f: float, g: float = 9.81
) -> tuple[dict[str, Any], Array, Array]:
    """The scenario (t = 0 half a period after the impact), the orbit's relative state
    (ball minus table) there, and the impact map's Jacobian in scaled variables."""
    w = 2 * math.pi * f
    period = 1 / f
    a = gamma * g / w**2  # table displacement a sin(w t)
    phi = math.acos(math.pi * (1 - e) / ((1 + e) * gamma))  # stable branch: sin(phi) > 0
    closing = 2 * math.pi * g / (w * (1 + e))
    t0 = phi / w  # impact
    tm = t0 + period / 2  # mid-flight: the new t = 0
    tau = period / 2

    def s(t: float) -> float:
        return a * math.sin(w * t)

    def sd(t: float) -> float:
        return a * w * math.cos(w * t)

    up = sd(t0) + e * closing  # the ball's absolute speed just after the impact
    state = np.array(
        [s(t0) + up * tau - g * tau**2 / 2 - s(tm), up - g * tau - sd(tm)], dtype=float
    )
    data = {
        "structure": {"kind": "oscillator", "mass": 1.0, "stiffness": 0.0},
        "stop": [{"at": 0, "side": "lower", "gap": 0.0, "law": "rigid", "restitution": e}],
        "gravity": {"acceleration": g},
        # Base acceleration: the second derivative of a sin(w (t + tm)).
        "excitation": [
            {
                "kind": "base",
                "signal": "harmonic",
                "amplitude": a * w**2,
                "frequency": f,
                "phase": math.pi / 2 + w * tm,
            }
        ],
        "solver": dict(EXACT),
    }
    big_s = gamma * math.sin(phi)
    jac = np.array([[1.0, 1 + e], [-(1 + e) * big_s, e**2 - (1 + e) ** 2 * big_s]])
    return data, state, jac


def holmes_flip(e: float) -> float:
    return math.hypot(math.pi * (1 - e) / (1 + e), 2 * (1 + e**2) / (1 + e) ** 2)


@pytest.mark.parametrize(("e", "f", "gamma"), [(0.5, 10.0, 1.2), (0.8, 5.0, 0.9)])
def test_holmes_ball_orbit_state_and_multipliers(e: float, f: float, gamma: float) -> None:
    data, state, jac = holmes(gamma, e, f)
    expected = np.linalg.eigvals(jac)
    # Precondition: complex pair (so both have modulus e) on the stable side.
    assert abs(expected[0].imag) > 0.1
    assert gamma < holmes_flip(e)
    o = an.orbit(an.runner(data), state * 1.05, periods=1)
    assert o.converged
    assert state_error(o.state, state) < 1e-9
    assert o.impacts_per_period == 1
    assert spectrum_distance(o.floquet_multipliers, expected) < 1e-7
    assert np.abs(o.floquet_multipliers) == pytest.approx([e, e], abs=1e-7)
    assert o.stable


@pytest.mark.parametrize("factor", [0.97, 1.03])
def test_holmes_ball_loses_stability_by_period_doubling(factor: float) -> None:
    e, f = 0.5, 10.0
    # The oracle's threshold is where its Jacobian has the multiplier -1.
    assert np.linalg.det(holmes(holmes_flip(e), e, f)[2] + np.eye(2)) == pytest.approx(
        0.0, abs=1e-12
    )
    data, state, jac = holmes(factor * holmes_flip(e), e, f)
    o = an.orbit(an.runner(data), state * 1.05, periods=1)
    assert o.converged
    assert state_error(o.state, state) < 1e-9
    assert o.impacts_per_period == 1
    mu = o.floquet_multipliers
    assert spectrum_distance(mu, np.linalg.eigvals(jac)) < 1e-7
    assert np.all(np.abs(mu.imag) < 1e-9)  # real past the complex pair
    if factor < 1:
        assert o.stable
        assert np.all(mu.real > -1)
    else:
        assert not o.stable
        assert np.min(mu.real) < -1.05  # through -1, not +1


# --------------------------------------------------------------------------------------
# One-sided impact oscillator (Shaw and Holmes)


SH = {"m": 1.0, "k": (2 * math.pi) ** 2, "c": 0.3, "F0": 0.1 * (2 * math.pi) ** 2, "gap": 0.05}


def shaw_holmes_orbits(f: float, e: float) -> list[dict[str, Any]]:
    """Period-one orbits of ``m x'' + c x' + k x = F0 cos(w t)`` with a rigid stop at
    ``x = gap`` (x <= gap): each with the impact speed V > 0, the impact time t0, the
    flight sampled, its admissibility, and the monodromy ``S Phi``."""
    m, k, c, f0, gap = SH["m"], SH["k"], SH["c"], SH["F0"], SH["gap"]
    w = 2 * math.pi * f
    period = 1 / f
    a = np.array([[0.0, 1.0], [-k / m, -c / m]])
    phi = expm(a * period)
    amp = f0 / math.hypot(k - m * w * w, c * w)
    theta = math.atan2(c * w, k - m * w * w)

    def zp(t: float) -> Array:
        return amp * np.array([math.cos(w * t - theta), -w * math.sin(w * t - theta)])

    # (gap, V) - zp = Phi ((gap, -e V) - zp)  =>  zp = (gap, 0) + V u, with
    # u = (I - Phi)^-1 ((0, 1) + e Phi (0, 1)); zp on its ellipse: a quadratic in V.
    e1 = np.array([0.0, 1.0])
    u = np.linalg.solve(np.eye(2) - phi, e1 + e * phi @ e1)
    qa = (u[0] / amp) ** 2 + (u[1] / (w * amp)) ** 2
    qb = 2 * gap * u[0] / amp**2
    qc = (gap / amp) ** 2 - 1
    disc = qb * qb - 4 * qa * qc
    out: list[dict[str, Any]] = []
    if disc < 0:
        return out
    for v in ((-qb + math.sqrt(disc)) / (2 * qa), (-qb - math.sqrt(disc)) / (2 * qa)):
        if v <= 0:
            continue
        p = np.array([gap + v * u[0], v * u[1]])
        t0 = (theta + math.atan2(-p[1] / (w * amp), p[0] / amp)) / w
        start = np.array([gap, -e * v]) - zp(t0)
        times = np.linspace(0.0, period, 20001)
        flight = np.array([zp(t0 + s) + expm(a * s) @ start for s in times])
        # The flight closes on (gap, V): the quadratic was solved right.
        assert flight[-1] == pytest.approx([gap, v], rel=1e-9, abs=1e-12)
        force = f0 * math.cos(w * t0) - k * gap
        a_minus = (force - c * v) / m
        a_plus = (force + c * e * v) / m
        saltation = np.array([[-e, 0.0], [(a_plus + e * a_minus) / v, -e]])
        out.append(
            {
                "V": v,
                "t0": t0,
                "admissible": bool(np.all(flight[1:-1, 0] < gap)),
                "amplitude": float(np.max(np.abs(flight[:, 0]))),
                "times": times,
                "flight": flight,
                "mid": flight[len(times) // 2],  # half a period after the impact
                "monodromy": saltation @ phi,
            }
        )
    return out


def shaw_holmes_scenario(
    f: float, e: float, phase: float, solver: dict[str, Any]
) -> dict[str, Any]:
    return {
        "structure": {
            "kind": "oscillator",
            "mass": SH["m"],
            "stiffness": SH["k"],
            "damping": SH["c"],
        },
        "stop": [{"at": 0, "side": "upper", "gap": SH["gap"], "law": "rigid", "restitution": e}],
        "excitation": [
            {
                "kind": "force",
                "at": 0,
                "signal": "harmonic",
                "amplitude": SH["F0"],
                "frequency": f,
                "phase": phase,
            }
        ],
        "solver": dict(solver),
    }


@pytest.mark.parametrize("solver", [EXACT, DOP853], ids=["exact", "dop853"])
def test_shaw_holmes_period_one_orbit(solver: dict[str, Any]) -> None:
    e, f = 0.8, 1.1
    m, c = SH["m"], SH["c"]
    w = 2 * math.pi * f
    (orb,) = [o for o in shaw_holmes_orbits(f, e) if o["admissible"]]
    data = shaw_holmes_scenario(f, e, w * (orb["t0"] + 0.5 / f), solver)  # t = 0 mid-flight
    mid = orb["mid"]
    o = an.orbit(an.runner(data), mid * np.array([1.03, 0.97]), periods=1)
    assert o.converged
    assert state_error(o.state, mid) < 1e-8
    assert o.impacts_per_period == 1
    assert o.amplitude[0] == pytest.approx(orb["amplitude"], rel=1e-6)
    assert np.linalg.det(o.monodromy) == pytest.approx(e**2 * math.exp(-c / (m * f)), rel=1e-6)
    expected = np.linalg.eigvals(orb["monodromy"])
    assert spectrum_distance(o.floquet_multipliers, expected) < 1e-6
    assert o.stable == bool(np.all(np.abs(expected) < 1))


def test_shaw_holmes_inadmissible_root_is_not_an_orbit() -> None:
    # Further below resonance the only root crosses the stop mid-flight: a simulator
    # that missed that crossing would come back to where it started.
    e, f = 0.8, 0.6
    (root,) = shaw_holmes_orbits(f, e)
    assert not root["admissible"]
    # Seeded a hundredth of a period after the impact, before the crossing.
    i = len(root["times"]) // 100
    seed = root["flight"][i]
    assert seed[0] < SH["gap"]
    phase = 2 * math.pi * f * (root["t0"] + root["times"][i])
    run = an.runner(shaw_holmes_scenario(f, e, phase, EXACT))
    assert state_error(run.map(seed, 1), seed) > 1e-2


# --------------------------------------------------------------------------------------
# Impact damper (Masri and Caughey)

from masri_caughey import MC_F0, MC_K, masri_caughey, mc_scenario, mc_si  # noqa: E402

# Cases: (mu, r, d, e) and per root (larger q first): None where inadmissible, else
# whether it is stable.
MC_CASES = [
    # Two admissible orbits: the larger stable, the smaller unstable.
    ((0.05, 0.6, 6.0, 0.3), [True, False]),
    # Above resonance, one root, stable.
    ((0.2, 1.2, 4.0, 0.6), [True]),
    # The larger root crosses a wall between impacts; the smaller is admissible but
    # unstable.
    ((0.5, 0.3, 3.0, 0.3), [None, False]),
]


@pytest.mark.parametrize(("params", "expected"), MC_CASES, ids=["two", "one", "inadmissible"])
def test_masri_caughey_two_impact_orbits(
    params: tuple[float, float, float, float], expected: list[bool | None]
) -> None:
    mu, r, d, e = params
    roots = masri_caughey(mu, r, d, e)
    assert len(roots) == len(expected)
    for root, stable in zip(roots, expected, strict=True):
        mid = mc_si(root["mid"])
        run = an.runner(mc_scenario(mu, r, d, e, root["phase"]))
        if stable is None:
            assert not root["admissible"]
            # Not an orbit of the system: one period from it lands far from it.
            assert state_error(run.map(mid, 1), mid) > 1e-2
            continue
        assert root["admissible"]
        spectrum = np.linalg.eigvals(root["monodromy"])
        assert bool(np.all(np.abs(spectrum) < 1)) == stable  # the case is as labelled
        o = an.orbit(run, mid * 1.01, periods=1)
        assert o.converged
        assert state_error(o.state, mid) < 1e-8
        assert o.impacts_per_period == 2
        assert o.amplitude[0] == pytest.approx(root["amplitude"] * MC_F0 / MC_K, rel=1e-6)
        assert np.prod(o.floquet_multipliers) == pytest.approx(e**4, rel=1e-6)
        assert spectrum_distance(o.floquet_multipliers, spectrum) < 1e-6 * max(
            1.0, float(np.max(np.abs(spectrum)))
        )
        assert o.stable == stable


def test_masri_caughey_stable_orbit_attracts_a_plain_run() -> None:
    mu, r, d, e = 0.05, 0.6, 6.0, 0.3
    root = masri_caughey(mu, r, d, e)[0]
    mid = mc_si(root["mid"])
    run = an.runner(mc_scenario(mu, r, d, e, root["phase"]))
    ss = an.steady_state(run, mid * 1.02, settle_periods=60, record_periods=5)
    assert ss.settled and ss.period == 1
    assert ss.impacts_per_period == 2
    assert ss.amplitude[0] == pytest.approx(root["amplitude"] * MC_F0 / MC_K, rel=1e-6)
    assert ss.rms[0] < ss.amplitude[0]
    assert state_error(ss.state, mid) < 1e-6


# --------------------------------------------------------------------------------------
# Linear baselines

LIN_M = np.array([[2.0, 0.0], [0.0, 1.0]])
LIN_K = np.array([[3000.0, -1000.0], [-1000.0, 1000.0]])


def rayleigh(zeta: float) -> Array:
    """C = a M + b K with the damping ratio ``zeta`` in both modes."""
    wn = np.sqrt(np.sort(np.linalg.eigvals(np.linalg.solve(LIN_M, LIN_K)).real))
    a = 2 * zeta * wn[0] * wn[1] / (wn[0] + wn[1])
    b = 2 * zeta / (wn[0] + wn[1])
    out: Array = a * LIN_M + b * LIN_K
    return out


def linear_scenario(kind: str, f: float, solver: dict[str, Any]) -> dict[str, Any]:
    exc: dict[str, Any] = {
        "kind": kind,
        "signal": "harmonic",
        "amplitude": 2.0,
        "frequency": f,
        "phase": 0.4,
    }
    if kind == "force":
        exc["at"] = 1
    return {
        "structure": {
            "kind": "matrices",
            "mass": LIN_M.tolist(),
            "stiffness": LIN_K.tolist(),
            "damping": rayleigh(0.05).tolist(),
        },
        "excitation": [exc],
        "solver": dict(solver, rtol=1e-11, atol=1e-14),
    }


def linear_q(kind: str, f: float) -> Complex:
    w = 2 * math.pi * f
    load = 2.0 * np.exp(0.4j)
    # Base acceleration: every coordinate relative to the base, influence vector ones.
    force = np.array([0.0, load]) if kind == "force" else -LIN_M @ np.ones(2) * load
    q: Complex = np.linalg.solve(LIN_K - w * w * LIN_M + 1j * w * rayleigh(0.05), force)
    return q


@pytest.mark.parametrize("solver", [EXACT, DOP853], ids=["exact", "dop853"])
@pytest.mark.parametrize("kind", ["force", "base"])
def test_linear_steady_state_matches_closed_form(kind: str, solver: dict[str, Any]) -> None:
    f = 6.0  # between the modes (3.56 and 7.12 Hz)
    w = 2 * math.pi * f
    q = linear_q(kind, f)
    data = linear_scenario(kind, f, solver)
    run = an.runner(data)
    start = np.concatenate([q.real, -w * q.imag])
    ss = an.steady_state(run, start, settle_periods=3, record_periods=5)
    assert ss.settled and ss.period == 1
    assert ss.impacts_per_period == 0
    np.testing.assert_allclose(ss.amplitude, np.abs(q), rtol=1e-5)
    np.testing.assert_allclose(ss.rms, np.abs(q) / math.sqrt(2), rtol=1e-5)
    np.testing.assert_allclose(an.linear_amplitude(data), np.abs(q), rtol=1e-10)


@pytest.mark.parametrize("kind", ["force", "base"])
def test_linear_sweep_matches_closed_form(kind: str) -> None:
    values = [3.0, 4.5, 6.0, 9.0]
    points = an.sweep(
        linear_scenario(kind, values[0], EXACT),
        "excitation.0.frequency",
        # Given in any order: "up" is towards larger values (given from the top, a sweep
        # going down was labelled "up"; trial of the analyses).
        values[::-1],
        direction="both",
        settle_periods=200,
        record_periods=5,
    )
    assert [(p.value, p.direction) for p in points] == [(v, "up") for v in values] + [
        (v, "down") for v in values[::-1]
    ]
    for p in points:
        q = np.abs(linear_q(kind, p.value))
        assert p.error is None and p.settled
        assert p.impacts_per_period == 0
        np.testing.assert_allclose(p.linear_amplitude, q, rtol=1e-10)
        np.testing.assert_allclose(p.amplitude, q, rtol=1e-5)
        np.testing.assert_allclose(p.rms, q / math.sqrt(2), rtol=1e-5)


@pytest.mark.parametrize("solver", [EXACT, DOP853], ids=["exact", "dop853"])
def test_floquet_multipliers_of_a_linear_damped_oscillator(solver: dict[str, Any]) -> None:
    m, k, c, f0, f = 1.5, 600.0, 3.0, 2.0, 3.0
    w = 2 * math.pi * f
    data = {
        "structure": {"kind": "oscillator", "mass": m, "stiffness": k, "damping": c},
        "excitation": [
            {"kind": "force", "at": 0, "signal": "harmonic", "amplitude": f0, "frequency": f}
        ],
        "solver": dict(solver),
    }
    o = an.orbit(an.runner(data), np.array([0.0, 0.0]), periods=1)
    expected = np.linalg.eigvals(expm(np.array([[0.0, 1.0], [-k / m, -c / m]]) / f))
    assert o.converged and o.stable
    assert o.impacts_per_period == 0
    assert spectrum_distance(o.floquet_multipliers, expected) < 1e-7
    assert abs(expected[0]) == pytest.approx(math.exp(-c / (2 * m * f)))  # the oracle
    q = f0 / (k - m * w * w + 1j * w * c)
    assert state_error(o.state, np.array([q.real, -w * q.imag])) < 1e-8
    assert o.amplitude[0] == pytest.approx(abs(q), rel=1e-9)


# --------------------------------------------------------------------------------------
# "exact" against "dop853"

FRF_DAMPER: dict[str, Any] = {
    "structure": {"kind": "oscillator", "mass": 1.0, "stiffness": 3947.8, "damping": 2.513},
    "damper": [{"mass": 0.05, "at": 0, "clearance": 0.005, "law": "rigid", "restitution": 0.6}],
    "excitation": [
        {"kind": "force", "at": 0, "signal": "harmonic", "amplitude": 5.0, "frequency": 11.0}
    ],
    "initial": {
        "structure_displacement": [0.002],
        "structure_velocity": [0.0],
        "damper_displacement": [0.0],
        "damper_velocity": [0.1],
    },
    "t_end": 50 / 11.0,
}


def two_dof_stop_damper(amplitude: float, frequency: float, periods: float) -> dict[str, Any]:
    """The 2-DOF structure (stiffness-proportional damping: classical also with the
    damper stuck to its point) with a loose mass on coordinate 1, a stop on coordinate
    0 and a harmonic base acceleration."""
    return {
        "structure": {
            "kind": "matrices",
            "mass": LIN_M.tolist(),
            "stiffness": LIN_K.tolist(),
            "damping": (1e-3 * LIN_K).tolist(),
        },
        "damper": [{"mass": 0.1, "at": 1, "clearance": 0.004, "law": "rigid", "restitution": 0.5}],
        "stop": [{"at": 0, "side": "upper", "gap": 0.004, "law": "rigid", "restitution": 0.7}],
        "excitation": [
            {
                "kind": "base",
                "signal": "harmonic",
                "amplitude": amplitude,
                "frequency": frequency,
                "phase": 0.3,
            }
        ],
        "initial": {
            "structure_displacement": [0.0, 0.001],
            "structure_velocity": [0.0, 0.0],
            "damper_displacement": [0.0],
            "damper_velocity": [0.05],
        },
        "t_end": periods / frequency,
    }


# A chattering sequence at the lower wall (restitution 0.3) summed to sticking, then
# released: dop853 converges on it (1e-12 between rtol 1e-11 and 1e-12).
CHATTER: dict[str, Any] = {
    "structure": {"kind": "oscillator", "mass": 2.0, "stiffness": 50.0},
    "damper": [{"mass": 1.0, "at": 0, "clearance": 0.09, "law": "rigid", "restitution": 0.3}],
    "excitation": [
        {
            "kind": "force",
            "at": 0,
            "signal": "harmonic",
            "amplitude": 3.0,
            "frequency": 0.24,
            "phase": 2.9,
        }
    ],
    "initial": {
        "structure_displacement": [0.072],
        "structure_velocity": [-0.114],
        "damper_displacement": [0.049],
        "damper_velocity": [0.196],
    },
    "t_end": 2.0,
}


def final_state(sol: SystemSolution) -> Array:
    s = sol.final_state
    return np.concatenate(
        [
            s["structure_displacement"],
            s["damper_displacement"],
            s["structure_velocity"],
            s["damper_velocity"],
        ]
    )


# dop853 at rtol 1e-11 and 1e-12 agree on each to 1e-11 (well-conditioned runs).
EXACT_CASES = {
    "damper": FRF_DAMPER,
    # ~1500 contacts: both pairs, sticking and releases.
    "2dof-stop": two_dof_stop_damper(8.0, 5.0, 50),
    "2dof-stop-4Hz": two_dof_stop_damper(3.0, 4.0, 50),
    "chatter": CHATTER,
}


@pytest.mark.parametrize("name", list(EXACT_CASES))
def test_exact_matches_dop853_on_forced_rigid_impacts(name: str) -> None:
    case = EXACT_CASES[name]
    exact = vi.simulate_system(**case, method="exact", history=False)
    adaptive = vi.simulate_system(**case, method="dop853", rtol=1e-11, atol=1e-14, history=False)
    assert len(exact.contacts.kind) > 10
    assert list(exact.contacts.kind) == list(adaptive.contacts.kind)
    assert list(exact.contacts.pair) == list(adaptive.contacts.pair)
    assert set(exact.contacts.pair) == set(exact.pairs)  # every pair took part
    np.testing.assert_allclose(exact.contacts.onset, adaptive.contacts.onset, atol=1e-8)
    assert state_error(final_state(exact), final_state(adaptive)) < 1e-6
    assert abs(exact.energy["residual"]) < 1e-9 * exact.energy["input_work"]


def test_exact_does_not_pass_through_a_stop() -> None:
    # After the damper's release at 2.3566 s the structure reaches the stop at about
    # 2.367 s (dop853, rtol 1e-12): a run to 2.37 s must end outside the stop, having
    # hit it, whatever its steps.
    case = {**two_dof_stop_damper(3.0, 4.0, 50), "t_end": 2.37}
    reference = vi.simulate_system(**case, method="dop853", rtol=1e-12, atol=1e-15, history=False)
    hit = reference.contacts.onset[-1]
    assert reference.contacts.pair[-1] == "stop 0" and 2.36 < hit < 2.37
    gap = case["stop"][0]["gap"]
    assert reference.final_state["structure_displacement"][0] < gap
    exact = vi.simulate_system(**case, method="exact", history=False)
    assert exact.final_state["structure_displacement"][0] <= gap
    assert exact.contacts.pair[-1] == "stop 0"
    assert exact.contacts.onset[-1] == pytest.approx(hit, abs=1e-9)


# --------------------------------------------------------------------------------------
# What "exact" refuses

OSC = {"kind": "oscillator", "mass": 1.0, "stiffness": 100.0, "damping": 0.1}
HARMONIC = [{"kind": "force", "at": 0, "signal": "harmonic", "amplitude": 1.0, "frequency": 2.0}]
TWO_DOF_K = [[200.0, -100.0], [-100.0, 100.0]]


def damper(law: dict[str, Any]) -> list[dict[str, Any]]:
    return [{"mass": 0.1, "at": 0, "clearance": 0.01, **law}]


# (refused, the same with what exact takes)
REFUSALS: dict[str, tuple[dict[str, Any], dict[str, Any]]] = {
    "nonlinear contact": (
        {
            "structure": OSC,
            "damper": damper({"law": "hertz", "stiffness": 1e7}),
            "excitation": HARMONIC,
        },
        {
            "structure": OSC,
            "damper": damper({"law": "rigid", "restitution": 0.5}),
            "excitation": HARMONIC,
        },
    ),
    "sweep-signal": (
        {
            "structure": OSC,
            "excitation": [
                {
                    "kind": "force",
                    "at": 0,
                    "signal": "sweep",
                    "amplitude": 1.0,
                    "start_frequency": 1.0,
                    "end_frequency": 3.0,
                    "duration": 1.0,
                }
            ],
        },
        {"structure": OSC, "excitation": HARMONIC},
    ),
}


NON_CLASSICAL = {
    "kind": "matrices",
    "mass": [[1.0, 0.0], [0.0, 1.0]],
    "stiffness": TWO_DOF_K,
    "damping": [[1.0, 0.0], [0.0, 0.0]],
}


@pytest.mark.parametrize(
    "case",
    [
        {"structure": NON_CLASSICAL, "excitation": HARMONIC},
        {
            "structure": OSC,
            "damper": damper({"law": "linear", "stiffness": 1e5, "damping": 2.0}),
            "excitation": HARMONIC,
            "initial": {"damper_velocity": [0.4]},
        },
        {
            "structure": NON_CLASSICAL,
            "damper": damper({"law": "linear", "stiffness": 1e5}),
            "stop": [{"at": 1, "side": "upper", "gap": 0.02, "law": "rigid", "restitution": 0.5}],
            "excitation": HARMONIC,
            "initial": {"damper_velocity": [0.4]},
        },
    ],
    ids=["non-classical damping", "linear contact", "both, with a rigid stop"],
)
def test_exact_takes_non_classical_damping_and_linear_contacts(case: dict[str, Any]) -> None:
    # Matrix exponential where the modes are coupled through damping: the same run
    # as DOP853 at a tight tolerance, contacts and all.
    runs = [
        vi.simulate_system(**case, t_end=0.5, history=False, method="exact"),
        vi.simulate_system(
            **case, t_end=0.5, history=False, method="dop853", rtol=1e-13, atol=1e-16
        ),
    ]
    exact, reference = runs
    assert list(exact.contacts.kind) == list(reference.contacts.kind)
    np.testing.assert_allclose(exact.contacts.onset, reference.contacts.onset, atol=1e-9)
    for key in exact.final_state:
        np.testing.assert_allclose(
            exact.final_state[key], reference.final_state[key], rtol=1e-6, atol=1e-10
        )
    scale = max(abs(exact.energy["input_work"]), abs(exact.energy["stored_start"]))
    assert abs(exact.energy["residual"]) < 1e-9 * scale


@pytest.mark.parametrize("name", list(REFUSALS))
def test_exact_refuses_what_it_cannot_solve(name: str) -> None:
    refused, accepted = REFUSALS[name]
    with pytest.raises(vi.InvalidInputError, match="exact") as info:
        vi.simulate_system(**refused, method="exact", t_end=0.5, history=False)
    assert isinstance(info.value, ValueError)
    vi.simulate_system(**accepted, method="exact", t_end=0.5, history=False)
    # The same through an analysis (the sweep signal has no period to analyse).
    if name != "sweep-signal":
        run = an.runner({**refused, "solver": dict(EXACT)})
        with pytest.raises(vi.InvalidInputError, match="exact"):
            an.steady_state(run, settle_periods=1, record_periods=1)
