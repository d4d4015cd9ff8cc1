"""0.2 systems run from Python: results against closed forms and a SciPy oracle
(Zeno and rest, base excitation, rattling, pounding, sticking, recorded and random
signals, rows and limits). Their scenarios, the command line's names and refusals are
in test_system_inputs.py; every method on every kind in test_system_methods.py."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import vibroimpact as vi
from system_checks import BALL, FREE_PAIR
from vibroimpact.system import simulate_system

FLOOR = {"at": 0, "side": "lower", "gap": 1.0, "law": "rigid", "restitution": 0.8}


def test_bouncing_ball_accumulates_at_the_zeno_time_and_rests() -> None:
    # t_inf = t1 (1 + e) / (1 - e), t1 = sqrt(2 h / g); all of m g h lost in impacts.
    g, h, e = 9.81, 1.0, 0.8
    t_inf = math.sqrt(2 * h / g) * (1 + e) / (1 - e)
    for method, dt in (("rk4", 1e-3), ("dop853", None)):
        sol = simulate_system(
            BALL, stop=[FLOOR], gravity={}, t_end=6.0, method=method, dt=dt, history=False
        )
        assert len(sol.t) == 0
        kinds = sol.contacts.kind
        assert kinds[-1] == "sticking" and set(kinds[:-1]) == {"impact"}
        assert sol.contacts.onset[-1] == pytest.approx(t_inf, abs=1e-8)
        assert sol.final_state["structure_displacement"][0] == pytest.approx(-h, abs=1e-9)
        assert sol.energy["impact"] == pytest.approx(0.2 * g * h, rel=1e-12)
        assert abs(sol.energy["residual"]) < 1e-12


def test_base_excited_oscillator_matches_its_steady_state() -> None:
    # m x'' + c x' + k x = -m a0 cos(w t), started on Re(X e^(i w t)).
    m, k, c, a0, f = 0.5, 200.0, 0.4, 3.0, 2.2
    w = 2 * math.pi * f
    x = -m * a0 / (k - m * w * w + 1j * c * w)
    sol = simulate_system(
        {"kind": "oscillator", "mass": m, "stiffness": k, "damping": c},
        excitation=[{"kind": "base", "signal": "harmonic", "amplitude": a0, "frequency": f}],
        initial={"structure_displacement": [x.real], "structure_velocity": [-w * x.imag]},
        t_end=1.0,
        method="dop853",
        rtol=1e-12,
        atol=1e-15,
    )
    exact = (x * np.exp(1j * w * sol.t)).real
    assert np.max(np.abs(sol.structure_displacement[:, 0] - exact)) < 1e-10 * abs(x)


def test_rattling_damper_matches_a_scipy_event_oracle() -> None:
    """A harmonically forced oscillator with a loose mass and rigid walls, against
    solve_ivp with terminal events and the impact map written out here."""
    scipy = pytest.importorskip("scipy.integrate")
    M, K, C, m, d, e, F, f = 1.0, 40.0, 0.2, 0.15, 0.01, 0.7, 2.0, 1.3
    w = 2 * math.pi * f

    def rhs(t: float, y: np.ndarray) -> list[float]:
        return [y[1], (F * math.cos(w * t) - C * y[1] - K * y[0]) / M, y[3], 0.0]

    def upper(t: float, y: np.ndarray) -> float:
        return d - (y[2] - y[0])

    def lower(t: float, y: np.ndarray) -> float:
        return d + (y[2] - y[0])

    for event in (upper, lower):
        event.terminal = True  # type: ignore[attr-defined]
        event.direction = -1  # type: ignore[attr-defined]
    t, y, impacts = 0.0, np.array([0.0, 0.0, 0.0, 0.0]), []
    while t < 2.0 and len(impacts) < 12:
        r = scipy.solve_ivp(rhs, (t, 2.0), y, events=(upper, lower), rtol=1e-12, atol=1e-14)
        t, y = r.t[-1], r.y[:, -1].copy()
        if r.status == 1:
            # Newton's law on the relative velocity, momentum conserved.
            after = -e * (y[3] - y[1])
            momentum = M * y[1] + m * y[3]
            y[1] = (momentum - m * after) / (M + m)
            y[3] = y[1] + after
            impacts.append(t)
    sol = simulate_system(
        {"kind": "oscillator", "mass": M, "stiffness": K, "damping": C},
        damper=[{"mass": m, "at": 0, "clearance": d, "law": "rigid", "restitution": e}],
        excitation=[
            {"kind": "force", "at": 0, "signal": "harmonic", "amplitude": F, "frequency": f}
        ],
        t_end=2.0,
        method="dop853",
        rtol=1e-12,
        atol=1e-15,
    )
    onsets, kinds = sol.contacts.onset, sol.contacts.kind
    ours = [c for c, kind in zip(onsets, kinds, strict=True) if kind == "impact"]
    assert len(impacts) >= 4
    np.testing.assert_allclose(ours[: len(impacts)], impacts, atol=1e-8)


@pytest.mark.parametrize("method", ["dop853", "dopri5"])
def test_an_adaptive_step_does_not_pass_over_a_short_flight(method: str) -> None:
    # A vertical forced oscillator with a loose mass under gravity (user trial): after an
    # impact at 0.5139695 s two flights of 0.4 ms and 0.5 ms follow, inside one 3 ms step
    # of dop853 (its step after an event being 1e-3 t_end). A smooth flight gives the
    # error control no reason to shorten it and the gap is open at both ends: the two
    # impacts were missed at t_end = 3 s (not at 0.6 s), whatever the rtol. Against the
    # exact flow (every rebound landed on its parabola), to 0.6 s whatever t_end.
    sections: dict[str, Any] = {
        "structure": {"kind": "oscillator", "mass": 1.0, "stiffness": 4000.0, "damping": 2.0},
        "damper": [{"mass": 0.1, "at": 0, "clearance": 0.002, "law": "rigid", "restitution": 0.6}],
        "gravity": {"acceleration": 9.81},
        "excitation": [
            {"kind": "force", "at": 0, "signal": "harmonic", "amplitude": 30.0, "frequency": 8.0}
        ],
    }

    def onsets(t_end: float, method: str, **options: float) -> np.ndarray:
        sol = simulate_system(**sections, t_end=t_end, method=method, history=False, **options)
        on = np.asarray(sol.contacts.onset)
        return on[on < 0.6]

    exact = onsets(0.6, "exact")
    assert np.count_nonzero((exact > 0.5139) & (exact < 0.515)) == 3
    for t_end in (0.6, 3.0):
        ours = onsets(t_end, method, rtol=1e-12, atol=1e-14)
        assert len(ours) == len(exact), t_end
        np.testing.assert_allclose(ours, exact, atol=1e-8)


def test_a_cantilevers_deflection_at_a_point_is_the_static_closed_form() -> None:
    # A constant tip force P on a heavily damped beam (10 modes, zeta 0.7: settled to
    # 1e-11 in 0.5 s): the deflection at the tip is P L^3 / 3 EI and at mid-span
    # 5 P L^3 / 48 EI (Euler-Bernoulli), to the modal truncation's 4e-5.
    length, youngs, second, rho_a, p = 0.5, 7e10, 1e-10, 0.27, 0.3
    ei = youngs * second
    sol = simulate_system(
        {
            "kind": "cantilever",
            "length": length,
            "youngs_modulus": youngs,
            "second_moment": second,
            "mass_per_length": rho_a,
            "modes": 10,
            "damping_ratio": 0.7,
        },
        excitation=[
            {"kind": "force", "at": length, "signal": "harmonic", "amplitude": p, "frequency": 0.0}
        ],
        t_end=0.5,
        method="exact",
    )
    tip = sol.displacement_at(length)
    assert tip[-1] == pytest.approx(p * length**3 / (3 * ei), rel=1e-4)
    assert sol.displacement_at(length / 2)[-1] == pytest.approx(
        5 * p * length**3 / (48 * ei), rel=1e-4
    )
    # The modal sum itself, and the velocity (at rest by then).
    shape = [vi.cantilever_mode_shape(length, i + 1, length) for i in range(10)]
    np.testing.assert_allclose(tip, sol.structure_displacement @ shape, rtol=1e-14)
    assert abs(sol.velocity_at(length)[-1]) < 1e-9
    with pytest.raises(ValueError, match="at must be a position along the beam in"):
        sol.displacement_at(0.6)


def test_momentum_through_rigid_impacts_of_a_free_pair() -> None:
    sol = simulate_system(
        {"kind": "matrices", "mass": [[1.5]], "stiffness": [[0.0]]},
        damper=[{"mass": 0.4, "at": 0, "clearance": 0.01, "law": "rigid", "restitution": 0.6}],
        initial={"structure_velocity": [0.3], "damper_velocity": [-0.5]},
        t_end=0.5,
        method="rk4",
        dt=1e-3,
    )
    momentum = 1.5 * sol.structure_velocity[:, 0] + 0.4 * sol.damper_velocity[:, 0]
    assert np.ptp(momentum) < 1e-13
    assert len(sol.contacts) >= 3
    np.testing.assert_allclose(sol.contacts.restitution, 0.6, rtol=1e-12)


@pytest.mark.parametrize("method", ["exact", "dop853", "rk4", "newmark-implicit"])
def test_two_points_pounding_rigidly_follow_the_impact_law(method: str) -> None:
    # Masses 1 and 3 kg closing at 1.5 m/s over a 1 cm gap: the impact at 1 cm / 1.5 m/s,
    # momentum kept, the relative speed reversed times e, and the reduced mass
    # mu = 3/4 kg losing (1 - e^2) mu v^2 / 2.
    e, gap, closing = 0.7, 0.01, 1.5
    stop = {"at": 0, "against": 1, "side": "upper", "gap": gap, "law": "rigid"}
    settings = {"dt": 1e-4} if method in ("rk4", "newmark-implicit") else {}
    sol = simulate_system(
        FREE_PAIR,
        stop=[stop | {"restitution": e}],
        initial={"structure_velocity": [1.0, -0.5]},
        t_end=0.05,
        method=method,
        **settings,
    )
    v = sol.final_state["structure_velocity"]
    assert len(sol.contacts) == 1 and sol.contacts.pair == ["stop 0"]
    assert sol.contacts.onset[0] == pytest.approx(gap / closing, rel=1e-9)
    assert 1.0 * v[0] + 3.0 * v[1] == pytest.approx(1.0 - 1.5, abs=1e-12)
    assert v[1] - v[0] == pytest.approx(e * closing, rel=1e-12)
    mu = 3.0 / 4.0
    lost = 0.5 * mu * (1 - e * e) * closing**2
    assert sol.contacts.energy_dissipated[0] == pytest.approx(lost, rel=1e-12)


def test_pounding_on_the_lower_side_closes_when_at_falls_below_against() -> None:
    # side = "lower" keeps x_0 - x_1 >= -gap: closing as x_0 falls behind at 1.5 m/s.
    e, gap = 0.6, 0.01
    sol = simulate_system(
        FREE_PAIR,
        stop=[
            {"at": 0, "against": 1, "side": "lower", "gap": gap, "law": "rigid", "restitution": e}
        ],
        initial={"structure_velocity": [-1.0, 0.5]},
        t_end=0.05,
        method="exact",
    )
    v = sol.final_state["structure_velocity"]
    assert len(sol.contacts) == 1
    assert sol.contacts.onset[0] == pytest.approx(gap / 1.5, rel=1e-12)
    assert v[0] - v[1] == pytest.approx(e * 1.5, rel=1e-12)
    assert 1.0 * v[0] + 3.0 * v[1] == pytest.approx(-1.0 + 1.5, abs=1e-12)


def test_two_points_pounding_through_a_linear_law_last_half_a_period() -> None:
    # A linear contact of k between the free masses: half a period of the reduced mass,
    # pi sqrt(mu / k), indentation v sqrt(mu / k) at most, elastic (e = 1).
    k, closing, mu = 1e5, 1.5, 0.75
    sol = simulate_system(
        FREE_PAIR,
        stop=[
            {"at": 0, "against": 1, "side": "upper", "gap": 0.01, "law": "linear", "stiffness": k}
        ],
        initial={"structure_velocity": [1.0, -0.5]},
        t_end=0.05,
        method="dop853",
        rtol=1e-12,
        atol=1e-15,
    )
    assert len(sol.contacts) == 1
    assert sol.contacts.duration[0] == pytest.approx(math.pi * math.sqrt(mu / k), rel=1e-9)
    # The peak is the method's own state at the turning point: to 1e-9 here.
    assert sol.contacts.max_indentation[0] == pytest.approx(closing * math.sqrt(mu / k), rel=1e-9)
    assert sol.contacts.restitution[0] == pytest.approx(1.0, rel=1e-9)


@pytest.mark.parametrize(
    ("method", "solver", "tolerance"),
    [
        ("exact", {}, 1e-10),
        ("dop853", {"rtol": 1e-10, "atol": 1e-14}, 1e-8),
        ("dopri5", {"rtol": 1e-10, "atol": 1e-14}, 1e-8),
        ("rk4", {"dt": 1e-5}, 1e-8),
    ],
)
def test_the_deepest_indentation_of_a_damped_linear_contact_is_its_closed_form(
    method: str, solver: dict[str, float], tolerance: float
) -> None:
    # A free mass at v into a linear stop of k with contact damping c: until it turns,
    # x(t) = (v / wd) exp(-zeta wn t) sin(wd t), deepest where wd t = atan2(wd, zeta wn).
    # Read off the steps' interpolant instead, dop853's value erred by 1e-4.
    m, k, c, v = 1.0, 1e5, 20.0, 1.0
    wn = math.sqrt(k / m)
    zeta = c / (2 * math.sqrt(k * m))
    wd = wn * math.sqrt(1 - zeta * zeta)
    turn = math.atan2(wd, zeta * wn) / wd
    deepest = v / wd * math.exp(-zeta * wn * turn) * math.sin(wd * turn)
    sol = simulate_system(
        {"kind": "oscillator", "mass": m, "stiffness": 0.0},
        stop=[
            {"at": 0, "side": "upper", "gap": 0.01, "law": "linear", "stiffness": k, "damping": c}
        ],
        initial={"structure_velocity": [v]},
        t_end=0.03,
        method=method,
        **solver,
    )
    assert len(sol.contacts) == 1
    assert sol.contacts.max_indentation[0] == pytest.approx(deepest, rel=tolerance)


@pytest.mark.parametrize("dt", [2e-6, 1e-6])
def test_rk4_at_fine_steps_goes_through_a_sticking_release(dt: float) -> None:
    # A rigid damper under gravity and base motion sticks to its wall after a chattering
    # sequence and is released where the constraint force crosses zero. Held there only
    # to round-off, the released pair sat a hair inside the wall: at these steps every
    # step read that as a new contact, and the run stopped as "chattering". The run must
    # go through and agree with the exact flow.
    system = {"kind": "oscillator", "mass": 0.0675, "stiffness": 346.3, "damping": 0.0967}
    common: dict[str, Any] = {
        "damper": [{"mass": 0.01, "at": 0, "clearance": 2e-3, "law": "rigid", "restitution": 0.3}],
        "gravity": {"acceleration": 9.81},
        "excitation": [
            {"kind": "base", "signal": "harmonic", "amplitude": 15.0, "frequency": 11.0}
        ],
        "t_end": 0.1,
        "history": False,
    }
    exact = simulate_system(system, method="exact", **common)
    sol = simulate_system(system, method="rk4", dt=dt, **common)
    sticking = [i for i, kind in enumerate(exact.contacts.kind) if kind == "sticking"]
    assert sticking, "the scenario must stick and release"
    released = [i for i, kind in enumerate(sol.contacts.kind) if kind == "sticking"]
    assert sol.contacts.separation[released[0]] == pytest.approx(
        exact.contacts.separation[sticking[0]], abs=10 * dt
    )
    for key in ("structure_displacement", "damper_displacement"):
        assert sol.final_state[key] == pytest.approx(exact.final_state[key], rel=1e-8)
    assert sol.energy["input_work"] == pytest.approx(exact.energy["input_work"], rel=1e-8)


def test_recorded_file_reproduces_the_harmonic_it_samples(tmp_path: Path) -> None:
    # A CSV sampling 2 cos(2 pi 3 t) every 1e-4 s: linear interpolation errs by
    # at most A (2 pi f dt)^2 / 8 = 9e-7 N, so the responses agree to ~1e-6 relative.
    times = np.arange(0.0, 1.0 + 1e-4, 1e-4)
    rows = "\n".join(f"{float(t)!r},{2 * math.cos(2 * math.pi * 3 * t)!r}" for t in times)
    (tmp_path / "force.csv").write_text("time,force\n" + rows + "\n")
    structure = {"kind": "oscillator", "mass": 1.0, "stiffness": 100.0, "damping": 0.5}
    recorded = {"kind": "force", "at": 0, "signal": "recorded", "file": "force.csv"}
    harmonic = {"kind": "force", "at": 0, "signal": "harmonic", "amplitude": 2.0, "frequency": 3.0}
    a = simulate_system(
        structure, excitation=[recorded], t_end=1.0, method="rk4", dt=1e-4, base_dir=tmp_path
    )
    b = simulate_system(structure, excitation=[harmonic], t_end=1.0, method="rk4", dt=1e-4)
    scale = np.max(np.abs(b.structure_displacement))
    assert np.max(np.abs(a.structure_displacement - b.structure_displacement)) < 1e-6 * scale


def run_each(structure: dict[str, Any], excitations: list[Any], **options: Any) -> list[Any]:
    """A run by RK4 without history under each of ``excitations`` alone."""
    return [
        simulate_system(structure, excitation=[e], method="rk4", history=False, **options)
        for e in excitations
    ]


@pytest.mark.parametrize("separator", [",", ";", "\t", "  ", ", "])
def test_recorded_columns_apart_by_any_usual_separator_read_alike(
    tmp_path: Path, separator: str
) -> None:
    rows = [
        "time" + separator + "force",
        *(f"{t}{separator}{v}" for t, v in [(0.0, 0.0), (0.1, 2.0), (0.3, -1.0), (0.4, 0.0)]),
    ]
    (tmp_path / "f.csv").write_text("\n".join(rows) + "\n")
    recorded = {"kind": "force", "at": 0, "signal": "recorded", "file": "f.csv"}
    arrays = {
        "kind": "force",
        "at": 0,
        "signal": "recorded",
        "time": [0.0, 0.1, 0.3, 0.4],
        "value": [0.0, 2.0, -1.0, 0.0],
    }
    structure = {"kind": "oscillator", "mass": 1.0, "stiffness": 100.0, "damping": 0.5}
    a, b = run_each(structure, [recorded, arrays], t_end=0.5, dt=1e-3, base_dir=tmp_path)
    assert a.final_state["structure_displacement"][0] != 0.0
    for key, value in a.final_state.items():
        np.testing.assert_array_equal(value, b.final_state[key])


def test_an_overdamped_kanai_tajimi_ground_passes_the_white_noise_through() -> None:
    # With zg = 35 the ground's filter |H|^2 = (wg^4 + 4 zg^2 wg^2 w^2) / ((wg^2 - w^2)^2 +
    # 4 zg^2 wg^2 w^2) is 1 to within 1e-3 up to the cutoff: the run, which the filter's
    # unstable substeps made fail on a NaN energy, sees nearly the white noise itself.
    structure = {"kind": "oscillator", "mass": 1.0, "stiffness": 1579.1, "damping": 2.5}
    noise = {
        "kind": "base",
        "signal": "white-noise",
        "intensity": 0.01,
        "cutoff_frequency": 20.0,
        "seed": 3,
    }
    ground = {**noise, "signal": "kanai-tajimi", "ground_frequency": 3.0, "ground_damping": 35.0}
    a, b = run_each(structure, [ground, noise], t_end=20.0, dt=1e-3, record_from=2.0)
    residual = a.energy["residual"]
    assert math.isfinite(residual) and abs(residual) < 1e-6 * a.energy["input_work"]
    assert a.rms[0] == pytest.approx(b.rms[0], rel=0.05)


def test_masri_caughey_two_impacts_per_cycle_steady_state() -> None:
    """Masri and Caughey (1966), restated in shared/reference/forced-oracles.md: the
    symmetric orbit of a harmonically forced undamped primary with a loose mass, two
    rigid impacts per forcing period. Started on the orbit just after an impact on
    the upper wall, the run must stay on it: impacts every half period, the primary's
    motion x(tau) of the closed form, the same approach speed at every impact."""
    M, K, F0, m, e = 1.0, 100.0, 1.0, 0.1, 0.6
    wn, xst, mu = math.sqrt(K / M), F0 / K, m / M
    r, d = 0.8, 2.0  # forcing over natural frequency; clearance over static deflection
    w, clearance = r * wn, d * xst
    P = 1 / (1 - r * r)
    a1 = 1 + (2 * mu * r / math.pi) * math.tan(math.pi / (2 * r))
    b1 = (2 / math.pi) * (1 - e) * (1 + mu) / (1 + e)
    root = math.sqrt((a1 * d) ** 2 - (a1 * a1 + b1 * b1) * (d * d - 4 * P * P))
    q = (a1 * d + root) / (2 * (a1 * a1 + b1 * b1))
    phi = math.atan2(b1 * q, a1 * q - d / 2)
    amplitude = 2 * mu * r * q / math.pi / math.cos(math.pi / (2 * r))

    def primary(tau: np.ndarray) -> np.ndarray:
        return P * np.cos(r * tau + phi) + amplitude * np.sin(tau - math.pi / (2 * r))

    def primary_rate(tau: float) -> float:
        return -P * r * math.sin(r * tau + phi) + amplitude * math.cos(tau - math.pi / (2 * r))

    # Admissible: the ball stays inside the container between impacts.
    tau = np.linspace(0, math.pi / r, 2001)
    ball = q - 2 * r * q / math.pi * tau
    assert np.max(np.abs(ball - primary(tau))) <= d / 2 * (1 + 1e-12)
    sol = simulate_system(
        {"kind": "oscillator", "mass": M, "stiffness": K},
        damper=[{"mass": m, "at": 0, "clearance": clearance / 2, "law": "rigid", "restitution": e}],
        excitation=[
            {
                "kind": "force",
                "at": 0,
                "signal": "harmonic",
                "amplitude": F0,
                "frequency": w / (2 * math.pi),
                "phase": phi,
            }
        ],
        initial={
            "structure_displacement": [xst * float(primary(np.array(0.0)))],
            "structure_velocity": [wn * xst * primary_rate(0.0)],
            "damper_displacement": [xst * q],
            "damper_velocity": [wn * xst * (-2 * r * q / math.pi)],
        },
        t_end=6 * math.pi / w,
        method="dop853",
        rtol=1e-12,
        atol=1e-15,
    )
    half = math.pi / w
    np.testing.assert_allclose(sol.contacts.onset, half * np.arange(1, 6), rtol=1e-11)
    approach = wn * xst * abs(-2 * r * q / math.pi - primary_rate(math.pi / r))
    np.testing.assert_allclose(sol.contacts.approach_speed, approach, rtol=1e-9)
    scaled = wn * sol.t
    k = np.floor(scaled / (math.pi / r))
    exact = xst * np.where(k % 2 == 0, 1.0, -1.0) * primary(scaled - k * math.pi / r)
    assert np.max(np.abs(sol.structure_displacement[:, 0] - exact)) < 1e-9 * np.max(np.abs(exact))


def test_long_adaptive_runs_stop_at_the_row_cap_and_history_off_keeps_none() -> None:
    """An undamped rattler to t_end = 1e12 s would fill the memory: it stops at max_rows
    with a message naming the keys to change; with history=False only the contacts count."""
    rattler = {
        "structure": {"kind": "oscillator", "mass": 1.0, "stiffness": 100.0},
        "damper": [{"mass": 0.1, "at": 0, "clearance": 0.01, "law": "rigid", "restitution": 0.9}],
        "initial": {"damper_velocity": [1.0]},
        "method": "dop853",
    }
    with pytest.raises(vi.SimulationError, match="max_rows = 2000") as err:
        # max_steps raised: 1e12 s spans 1.6e12 periods of the 1.59 Hz mode, refused up
        # front at the default max_steps (1e9).
        simulate_system(**rattler, t_end=1e12, max_rows=2000, max_steps=10**13)
    assert "history = false" in str(err.value) and "\n" not in str(err.value)
    sol = simulate_system(**rattler, t_end=50.0, history=False)
    assert len(sol.t) == 0 and len(sol.contacts) > 0
    with_history = simulate_system(**rattler, t_end=50.0)
    np.testing.assert_array_equal(sol.contacts.onset, with_history.contacts.onset)


def test_fixed_step_history_beyond_the_cap_is_refused_before_running() -> None:
    osc = {"kind": "oscillator", "mass": 1.0, "stiffness": 100.0}
    with pytest.raises(vi.InvalidInputError, match=r"t_end / dt / every.*max_rows = 1000"):
        simulate_system(osc, t_end=1.0, dt=1e-4, method="rk4", max_rows=1000)
    # The same run keeping every 20th step, or no history, fits.
    assert (
        len(simulate_system(osc, t_end=1.0, dt=1e-4, method="rk4", max_rows=1000, every=20).t)
        == 501
    )
    assert (
        len(simulate_system(osc, t_end=1.0, dt=1e-4, method="rk4", max_rows=1000, history=False).t)
        == 0
    )


def test_lossless_runs_through_rest_keep_a_closed_balance() -> None:
    """An undamped oscillator forced off resonance passes through near-zero energy: the
    balance is judged against the largest energy in play, so exact runs are not
    stopped (they were, by round-off, when judged against the energy of the moment)."""
    w0 = 2 * math.pi
    for method, dt in (("rk4", 1e-3), ("dop853", None), ("generalized-alpha", 1e-4)):
        sol = simulate_system(
            {"kind": "oscillator", "mass": 2.0, "stiffness": 2.0 * w0 * w0},
            excitation=[
                {"kind": "force", "at": 0, "signal": "harmonic", "amplitude": 1.0, "frequency": 3.0}
            ],
            t_end=3.0,
            method=method,
            dt=dt,
            energy_tolerance=1e-6,
        )
        assert abs(sol.energy["residual"]) < 1e-6 * max(abs(sol.energy["input_work"]), 1e-3)


@pytest.mark.parametrize(
    "method", ["rk4", "newmark-implicit", "generalized-alpha", "dopri5", "dop853", "exact"]
)
def test_a_zero_clearance_rigid_damper_moves_with_its_structure(method: str) -> None:
    """A loose mass with no clearance on either side (e = 1) is held by one wall or the
    other: structure and mass move as one body, x = x0 cos(sqrt(k / (M + m)) t). It once
    looped on the same touch at the instant the wall's force turned (newmark-implicit),
    and stopped as "chattering" with the others."""
    stiffness, total = 100.0, 2.0
    dt = 1e-4
    done = simulate_system(
        {"kind": "oscillator", "mass": 1.0, "stiffness": stiffness},
        damper=[{"mass": 1.0, "at": 0, "clearance": 0.0, "law": "rigid", "restitution": 1.0}],
        initial={"structure_displacement": [0.01], "damper_displacement": [0.01]},
        t_end=1.0,
        method=method,
        dt=dt,
        history=False,
    )
    w = math.sqrt(stiffness / total)
    x, v = 0.01 * math.cos(w), -0.01 * w * math.sin(w)
    # Second order for the Newmark family (w dt = 7e-4: 1e-8 relative), near round-off
    # for the others.
    tolerance = 1e-6 if method in ("newmark-implicit", "generalized-alpha") else 1e-8
    final = done.final_state
    for key, exact in (
        ("structure_displacement", x),
        ("damper_displacement", x),
        ("structure_velocity", v),
        ("damper_velocity", v),
    ):
        scale = 0.01 if "displacement" in key else 0.01 * w
        assert abs(final[key][0] - exact) < tolerance * scale, (key, final[key][0], exact)
    assert set(done.contacts.kind) == {"sticking"}
    # Within the adaptive methods' rtol (1e-8) of the energy.
    assert abs(done.energy["residual"]) < 1e-7 * done.energy["stored_start"]


def test_sampling_every_period_does_not_change_whether_a_chattering_run_completes() -> None:
    """A damper chattering on a 10 Hz structure (found by a user trial): with a strobe
    every forcing period, a step shortened to land on one left a rebounding pair a hair
    inside its wall, and the gap's own rise through zero was found again and again
    ('chattering ... 2.7e-20 s apart'), where the run without strobes completes."""
    frequency = 9.889447236180905
    common = {
        "damper": [{"mass": 0.02, "at": 0, "clearance": 0.003, "law": "rigid", "restitution": 0.6}],
        "excitation": [
            {
                "kind": "force",
                "at": 0,
                "signal": "harmonic",
                "amplitude": 5.0,
                "frequency": frequency,
            }
        ],
        "method": "exact",
        "t_end": 7.2,
        "history": False,
    }
    structure = {"kind": "oscillator", "mass": 1.0, "stiffness": 3947.8, "damping": 2.513}
    strobed = simulate_system(structure, strobe_period=1.0 / frequency, **common)
    plain = simulate_system(structure, **common)
    assert len(strobed.strobe_time) == 71
    for key, values in plain.final_state.items():
        assert np.allclose(strobed.final_state[key], values, rtol=1e-5, atol=0), key
    assert abs(len(strobed.contacts.kind) - len(plain.contacts.kind)) <= 2


def test_two_dampers_on_one_point_rattle_to_the_end() -> None:
    """Two rigid dampers on one oscillator (found by fuzzing): just after damper 0's
    impact, damper 1's crossing later in the step was located, and damper 0, on its
    wall to round-off and leaving it, was then 'located' at the step's start by
    Newton's steps back down its rise: 'chattering ... 2.9e-17 s apart'. The event is
    where a value reaches its wall moving towards it."""
    dampers = [
        {"mass": 0.1455, "at": 0, "clearance": 0.0005, "law": "rigid", "restitution": 0.6},
        {"mass": 0.1888, "at": 0, "clearance": 0.01, "law": "rigid", "restitution": 0.9},
    ]
    force = {"kind": "force", "at": 0, "signal": "harmonic", "amplitude": 21.99}
    done = simulate_system(
        {"kind": "oscillator", "mass": 1.0, "stiffness": 3947.8, "damping": 2.513},
        damper=dampers,
        excitation=[{**force, "frequency": 8.804753706433235}],
        method="dop853",
        t_end=10.0,
        history=False,
    )
    assert done.final_time == 10.0 and len(done.contacts.kind) > 1000
    energy = done.energy
    assert abs(energy["residual"]) < 1e-6 * energy["input_work"]


def test_a_start_on_the_wall_to_round_off_is_accepted() -> None:
    x0 = -1.1 * 9.81 / 1000  # the damper placed exactly on its lower wall, in floats
    sol = simulate_system(
        {"kind": "oscillator", "mass": 1.0, "stiffness": 1000.0},
        damper=[{"mass": 0.1, "at": 0, "clearance": 0.01, "law": "rigid", "restitution": 0.5}],
        gravity={},
        initial={"structure_displacement": [x0], "damper_displacement": [x0 - 0.01]},
        t_end=0.1,
        method="rk4",
        dt=1e-3,
    )
    assert sol.final_time == pytest.approx(0.1)
