"""Coulomb friction (issue 27): stick-slip located as events in every event-stepped
method, checked against closed forms (the free decay's amplitude lost per half cycle
and its stop inside the static band, a block sliding to rest, a block bouncing between
walls, Den Hartog's forced response sliding throughout) and scipy's event-driven
integration of a horizontal impact damper with friction (tests/friction_reference.py)."""

from __future__ import annotations

import dataclasses
import math
import subprocess
import sys
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import vibroimpact as vi
import vibroimpact.analysis as an
from friction_reference import HorizontalDamper, horizontal_damper_at

ROOT = Path(__file__).resolve().parents[1]
G = 9.81
FREE = {"lower_clearance": math.inf, "upper_clearance": math.inf}
# Methods that step by events (fixed stepping refuses friction).
METHODS = ["exact", "dop853", "dopri5", "newmark-implicit"]


def _step(method: str) -> dict[str, Any]:
    return {"dt": 2e-4} if method in ("newmark-implicit", "rk4") else {}


def _decay_system(x0: float, kinetic: float, held: float, normal: float) -> vi.System:
    return vi.System(
        structure=vi.Oscillator(mass=2.0, stiffness=800.0, damping=0.0),
        frictions=[
            vi.Friction(at=0, coefficient=kinetic, static_coefficient=held, normal_force=normal)
        ],
        initial=vi.Initial(structure_displacement=[x0]),
    )


def _turning_points(x0: float, slide: float, band: float) -> list[float]:
    """Each half cycle about the kinetic force's offset ``slide`` (m) loses ``2 slide``
    of amplitude; the motion stops at the first turning point inside ``band``."""
    points, x = [x0], x0
    while abs(x) > band:
        x = -(x - 2.0 * slide * math.copysign(1.0, x))
        points.append(x)
    return points


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.timeout(30)
def test_free_decay_loses_twice_the_friction_offset_each_half_cycle(method: str) -> None:
    x0, kinetic, held, normal, k = 0.0513, 0.3, 0.4, 10.0, 800.0
    expected = _turning_points(x0, kinetic * normal / k, held * normal / k)
    sol = vi.simulate(
        _decay_system(x0, kinetic, held, normal), method=method, t_end=1.2, **_step(method)
    )
    x, v = sol.structure_displacement[:, 0], sol.structure_velocity[:, 0]
    # Each stop is an event (a kept row): where the speed reaches zero or turns.
    stops = [x[0]]
    for i in range(1, len(v)):
        if (v[i] == 0.0 or v[i] * v[i - 1] < 0) and abs(x[i] - stops[-1]) > 1e-9:
            stops.append(x[i])
    tolerance = 1e-12 if method == "exact" else 1e-7
    assert len(stops) >= len(expected)
    assert np.allclose(stops[: len(expected)], expected, rtol=0, atol=tolerance)
    # At rest at the last, inside the static band, which a kinetic-only rule would
    # have left (0.0063 m > 0.0038 m).
    final = sol.final_state
    assert final["structure_displacement"][0] == pytest.approx(expected[-1], abs=tolerance)
    assert final["structure_velocity"][0] == 0.0
    # The ledger: the spring's energy went to friction, and nothing else.
    lost = 0.5 * k * (x0**2 - expected[-1] ** 2)
    assert sol.energy["friction"] == pytest.approx(lost, rel=1e-6)
    assert sol.energy["contact"] == 0.0 and sol.energy["impact"] == 0.0
    assert abs(sol.energy["residual"]) < 1e-6
    # The stuck interval from the last stop on is in the contact table.
    table = sol.contacts.to_pandas()
    assert list(table["pair"]) == ["friction 0"] and list(table["kind"]) == ["sticking"]


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.timeout(30)
def test_a_block_slides_to_rest_in_v_squared_over_two_mu_g(method: str) -> None:
    m, mu, v0 = 0.5, 0.25, 1.2
    system = vi.System(
        # A carrier held still: heavy and stiff (its reaction moves it by 1e-13 m).
        structure=vi.Oscillator(mass=1e9, stiffness=1e15, damping=0.0),
        dampers=[
            vi.Damper(
                mass=m, at=0, law="rigid", restitution=0.5, friction=mu, normal_force=m * G, **FREE
            )
        ],
        initial=vi.Initial(damper_velocity=[v0]),
    )
    t_stop = v0 / (mu * G)
    sol = vi.simulate(system, method=method, t_end=1.5 * t_stop, **_step(method))
    final = sol.final_state
    slid = final["damper_displacement"][0] - final["structure_displacement"][0]
    # The carrier's own motion changes the slide by 1e-12 of it.
    tolerance = 1e-10 if method == "exact" else 1e-7
    assert slid == pytest.approx(v0**2 / (2 * mu * G), rel=tolerance)
    (stuck,) = sol.contacts.to_pandas().itertuples()
    assert stuck.pair == "damper 0 friction" and stuck.kind == "sticking"
    assert stuck.onset == pytest.approx(t_stop, rel=tolerance)
    assert sol.energy["friction"] == pytest.approx(0.5 * m * v0**2, rel=1e-6)


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.timeout(30)
def test_a_block_bounces_off_a_wall_and_slides_to_rest(method: str) -> None:
    # From the middle towards the upper wall 0.2 m away: it arrives at
    # sqrt(v0^2 - 2 mu g d), leaves at e times that and slides back to rest.
    m, mu, v0, d, e = 0.2, 0.2, 1.5, 0.2, 0.6
    system = vi.System(
        structure=vi.Oscillator(mass=1e9, stiffness=1e15, damping=0.0),
        dampers=[
            vi.Damper(
                mass=m,
                at=0,
                clearance=d,
                law="rigid",
                restitution=e,
                friction=mu,
                normal_force=m * G,
            )
        ],
        initial=vi.Initial(damper_velocity=[v0]),
    )
    sol = vi.simulate(system, method=method, t_end=2.0, **_step(method))
    arrival = math.sqrt(v0**2 - 2 * mu * G * d)
    back = (e * arrival) ** 2 / (2 * mu * G)
    table = sol.contacts.to_pandas()
    impact = table[table.kind == "impact"].iloc[0]
    tolerance = 1e-8 if method == "exact" else 1e-6
    assert impact.approach_speed == pytest.approx(arrival, rel=tolerance)
    assert impact.rebound_speed == pytest.approx(e * arrival, rel=tolerance)
    final = sol.final_state
    rest = final["damper_displacement"][0] - final["structure_displacement"][0]
    assert rest == pytest.approx(d - back, rel=tolerance)
    assert list(table.kind) == ["impact", "sticking"]
    lost = 0.5 * m * v0**2
    energy = sol.energy
    assert energy["friction"] + energy["impact"] == pytest.approx(lost, rel=1e-6)
    assert energy["impact"] == pytest.approx(0.5 * m * (1 - e**2) * arrival**2, rel=1e-6)


@pytest.mark.parametrize(("beta", "method"), [(0.8, "exact"), (1.5, "exact"), (0.8, "dop853")])
@pytest.mark.timeout(60)
def test_den_hartog_s_forced_response_with_dry_friction(beta: float, method: str) -> None:
    system, amplitude = _den_hartog(beta, 0.2)
    period = 2 * math.pi / (beta * 10.0)
    sol = vi.simulate(
        system, method=method, t_end=300 * period, history=False, record_from=280 * period
    )
    assert sol.peak[0] == pytest.approx(amplitude, rel=1e-7)
    # It never sticks (each stop reverses at once): no stuck interval.
    assert len(sol.contacts) == 0


@pytest.mark.timeout(90)
def test_a_horizontal_damper_with_friction_follows_scipy() -> None:
    # One test for both methods: scipy's event-driven reference takes some 20 s.
    params = HorizontalDamper()
    t_end = 2.0  # 20 forcing periods: impacts, chattering, stick-slip
    reference, events = horizontal_damper_at(t_end)
    assert events > 300
    system = vi.System.from_dict(params.toml_sections())
    for method, tight in [("exact", {}), ("dop853", {"rtol": 1e-12, "atol": 1e-15})]:
        sol = vi.simulate(system, method=method, t_end=t_end, history=False, **tight)
        f = sol.final_state
        ours = [
            f["structure_displacement"][0],
            f["damper_displacement"][0],
            f["structure_velocity"][0],
            f["damper_velocity"][0],
        ]
        assert np.allclose(ours[:2], reference[:2], rtol=0, atol=1e-6), method
        assert np.allclose(ours[2:], reference[2:], rtol=0, atol=1e-4), method
        energy = sol.energy
        assert energy["friction"] > 0 and energy["impact"] > 0
        assert abs(energy["residual"]) < 1e-8 * energy["input_work"]
        table = sol.contacts.to_pandas()
        assert set(table.pair) == {"damper 0", "damper 0 friction"}
        stuck = table[table.pair == "damper 0 friction"]
        assert (stuck.kind == "sticking").all() and (stuck.duration.dropna() > 0).all()


@pytest.mark.parametrize(
    ("damper", "message"),
    [
        (
            {"friction": 0.3, "static_friction": 0.2, "normal_force": 1.0},
            "static_friction must be >=",
        ),
        ({"friction": 0.3}, "normal_force is required"),
        ({"friction": -0.1, "normal_force": 1.0}, "friction must be >= 0"),
        ({"friction": 0.1, "normal_force": -1.0}, "normal_force must be a finite number >= 0"),
        ({"static_friction": 0.1}, "static_friction needs friction"),
        ({"normal_force": 1.0}, "normal_force needs friction"),
    ],
)
@pytest.mark.timeout(30)
def test_bad_friction_keys_are_refused_naming_them(damper: dict[str, Any], message: str) -> None:
    sections = HorizontalDamper().toml_sections()
    for key in ("friction", "static_friction", "normal_force"):
        del sections["damper"][0][key]
    sections["damper"][0].update(damper)
    with pytest.raises(ValueError, match=message) as error:
        vi.System.from_dict(sections)
    assert "[[damper]] 0" in str(error.value) and "\n" not in str(error.value)


@pytest.mark.timeout(30)
def test_a_bad_friction_element_is_refused_naming_its_key() -> None:
    base = {"structure": {"kind": "oscillator", "mass": 1.0, "stiffness": 100.0}}
    for element, message in [
        ({"at": 0, "coefficient": 0.2}, "missing key 'normal_force'"),
        ({"at": 3, "coefficient": 0.2, "normal_force": 1.0}, "friction 0 at"),
        (
            {"at": 0, "coefficient": 0.2, "static_coefficient": 0.1, "normal_force": 1.0},
            "static_coefficient must be >=",
        ),
    ]:
        with pytest.raises(ValueError, match=message) as error:
            vi.System.from_dict(base | {"friction": [element]})
        assert "\n" not in str(error.value)


@pytest.mark.parametrize(
    ("settings", "message"),
    [
        ({"method": "rk4", "dt": 1e-4, "stepping": "fixed"}, "cannot locate stick-slip"),
        ({"method": "newmark", "dt": 1e-4}, "dry friction"),
    ],
)
@pytest.mark.timeout(30)
def test_methods_that_cannot_locate_stick_slip_refuse_friction(
    settings: dict[str, Any], message: str
) -> None:
    system = vi.System.from_dict(HorizontalDamper().toml_sections())
    damper = dataclasses.replace(system.dampers[0], law="hertz", stiffness=1e8, restitution=None)
    system = system.replace(dampers=[damper])
    with pytest.raises(ValueError, match=message):
        vi.simulate(system, t_end=0.01, **settings)


def _den_hartog(beta: float, F: float) -> tuple[vi.System, float]:
    """An undamped oscillator (1 kg, 100 N/m) with dry friction ``F`` (N) to the ground,
    forced by 1 N at ``beta`` times its natural frequency, and Den Hartog's amplitude of
    its steady response sliding throughout (two stops a cycle): (P / k) sqrt(V^2 - (F /
    P)^2 U^2), V = 1 / (1 - b^2), U = sin(pi / b) / (b (1 + cos(pi / b))) (J. P. Den
    Hartog, Trans. ASME 53, 1931)."""
    m, k, P = 1.0, 100.0, 1.0
    frequency = beta * math.sqrt(k / m) / (2 * math.pi)
    system = vi.System(
        structure=vi.Oscillator(mass=m, stiffness=k, damping=0.0),
        frictions=[vi.Friction(at=0, coefficient=F, normal_force=1.0)],
        excitations=[vi.Force(at=0, signal=vi.Harmonic(amplitude=P, frequency=frequency))],
        initial=vi.Initial(structure_velocity=[1e-3]),
    )
    V = 1 / (1 - beta**2)
    U = math.sin(math.pi / beta) / (beta * (1 + math.cos(math.pi / beta)))
    return system, P / k * math.sqrt(V**2 - (F / P) ** 2 * U**2)


def _stick_slip_oscillator() -> vi.System:
    """A forced oscillator (1 kg, 100 N/m, 0.5 N s/m; 4 N at 0.8 Hz) on a friction
    element (kinetic 1 N, static 1.6 N) that sticks once a cycle and slips again."""
    return vi.System(
        structure=vi.Oscillator(mass=1.0, stiffness=100.0, damping=0.5),
        frictions=[vi.Friction(at=0, coefficient=1.0, static_coefficient=1.6, normal_force=1.0)],
        excitations=[vi.Force(at=0, signal=vi.Harmonic(amplitude=4.0, frequency=0.8))],
        initial=vi.Initial(structure_velocity=[1e-3]),
        solver=vi.Solver(t_end=1.0, method="exact"),
    )


@pytest.mark.timeout(120)
@pytest.mark.parametrize("case", ["den-hartog", "stick-slip"])
def test_orbits_through_stick_slip_take_the_tangent_flow_as_differences_agree(case: str) -> None:
    """The orbit's monodromy by the tangent flow (saltations at each stop, stick and
    slip) equals central differences of whole runs; Den Hartog's orbit (sliding
    throughout) has his amplitude; where the orbit sticks, the stick loses the
    velocity: a Floquet multiplier is zero."""
    if case == "den-hartog":
        system, amplitude = _den_hartog(0.8, 0.2)
        system = system.replace(solver=vi.Solver(t_end=1.0, method="exact"))
    else:
        system, amplitude = _stick_slip_oscillator(), None
    tangent = an.orbit(system)
    differences = an.orbit(system, tangent.state, jacobian="differences")
    assert tangent.jacobian == "tangent" and tangent.converged and tangent.stable
    assert differences.converged
    assert np.allclose(differences.state, tangent.state, rtol=0, atol=1e-9)
    # Scaled as the coordinates are (m, m/s: the velocity about 2 pi f the
    # displacement's).
    omega = 2 * math.pi * 0.8 if amplitude is None else 10.0
    scale = np.diag([1.0, omega])
    unscaled = np.linalg.inv(scale)
    gap = scale @ (tangent.monodromy - differences.monodromy) @ unscaled
    assert np.abs(gap).max() < 1e-6 * max(1.0, np.abs(scale @ tangent.monodromy @ unscaled).max())
    if amplitude is not None:
        assert tangent.amplitude[0] == pytest.approx(amplitude, rel=1e-7)
        # Sliding throughout: no stick to lose a direction.
        assert np.abs(tangent.floquet_multipliers).min() > 1e-3
    else:
        stuck = vi.simulate(system.replace(solver=vi.Solver(t_end=5.0, method="exact")))
        assert (stuck.contacts.to_pandas()["kind"] == "sticking").sum() >= 3
        assert np.abs(tangent.floquet_multipliers).min() < 1e-9


def _coupled_rubbing() -> vi.System:
    """Two masses (1 and 0.5 kg) on springs, each rubbing (one on the ground, one on
    the other) with kinetic 1 N and static 2 N, the second forced with 3 N at 0.7 Hz:
    at one instant the first stops while the second is stuck, and holding both would
    take more than the second's static force, so both slide on."""
    return vi.System(
        structure=vi.Matrices(
            mass=[[1.0, 0.0], [0.0, 0.5]],
            stiffness=[[200.0, -100.0], [-100.0, 100.0]],
            damping=[[0.4, -0.1], [-0.1, 0.2]],
        ),
        frictions=[
            vi.Friction(at=0, coefficient=1.0, static_coefficient=2.0, normal_force=1.0),
            vi.Friction(at=0, against=1, coefficient=1.0, static_coefficient=2.0, normal_force=1.0),
        ],
        excitations=[vi.Force(at=1, signal=vi.Harmonic(amplitude=3.0, frequency=0.7))],
        solver=vi.Solver(t_end=1.0, method="exact"),
    )


def _end_differences(
    run: an.Runner, state: np.ndarray, t_end: float, scales: np.ndarray, step: float = 1e-7
) -> np.ndarray:
    """Central differences of the end state at ``t_end`` s (steps of ``step`` times
    ``scales``)."""
    columns = []
    for c, scale in enumerate(scales):
        shift = np.zeros(len(state))
        shift[c] = step * scale
        up, down = (np.asarray(run.tangent(state + s, t_end)["state"]) for s in (shift, -shift))
        columns.append((up - down) / (2 * shift[c]))
    return np.array(columns).T


@pytest.mark.timeout(120)
@pytest.mark.parametrize("case", ["both-slide-at-once", "starts-stuck", "slips-from-zero"])
def test_the_tangent_map_through_stick_slip_corners_is_the_runs_differences(case: str) -> None:
    """Where several elements switch at one instant (the run ends that event in modes
    that hold, not a stuck interval of no length), a run that starts stuck (the flow
    carries no velocity along the stuck row), and a slip from a state of zero (the
    holding force's gradient taken on the force's own scale)."""
    if case == "both-slide-at-once":
        system, t_end = _coupled_rubbing(), 1.0
        state = np.array([0.01, -0.02, 0.1, 0.3])
        scales = np.array([0.01, 0.01, 0.1, 0.1])
    else:
        system, t_end = _stick_slip_oscillator(), 1.0
        if case == "slips-from-zero":
            signal = vi.Harmonic(amplitude=4.0, frequency=0.8, phase=-math.pi / 2)
            system = system.replace(excitations=[vi.Force(at=0, signal=signal)])
        state = np.array([0.03 if case == "starts-stuck" else 0.0, 0.0])
        scales = np.array([0.01, 0.1])
    run = an.runner(system)
    tangent = run.tangent(state, t_end)
    assert not tangent["grazings"]
    matrix = tangent["matrix"]
    differences = _end_differences(run, state, t_end, scales)
    if case == "starts-stuck":
        # Started at rest and held, a push along the row stops within its square:
        # the map's derivative by the start's velocity is zero (its differences
        # shrink with their step), the displacement's is the differences'.
        assert np.abs(matrix[:, 1]).max() == 0.0
        coarse = _end_differences(run, state, t_end, scales, step=1e-5)
        assert np.abs(differences[:, 1]).max() < np.abs(coarse[:, 1]).max()
        matrix, differences, scales = matrix[:, :1], differences[:, :1], scales
    scaled = (matrix - differences) * scales[: matrix.shape[1]] / scales[:, None]
    size = np.abs(differences * scales[: matrix.shape[1]] / scales[:, None]).max()
    assert np.abs(scaled).max() < 1e-5 * max(1.0, size)
    if case == "both-slide-at-once":
        # No stuck interval of no length at that instant.
        initial = vi.Initial(
            structure_displacement=list(state[:2]), structure_velocity=list(state[2:])
        )
        stuck = vi.simulate(system.replace(initial=initial)).contacts.to_pandas()
        assert (stuck["separation"] > stuck["onset"]).all()


@pytest.mark.timeout(60)
def test_lyapunov_exponents_through_stick_slip_are_the_orbits_floquet_exponents() -> None:
    """From a stable orbit the spectrum is its Floquet exponents, log|mu| / T: sliding
    throughout (Den Hartog), their sum is log|det M| / T to round-off (the product of
    whole periods' maps); sticking once a cycle, the stick loses a direction (minus
    infinity) and the other tends to log|mu| / T (within 1/N of the N periods)."""
    system, _ = _den_hartog(0.8, 0.2)
    system = system.replace(solver=vi.Solver(t_end=1.0, method="exact"))
    for case in (system, _stick_slip_oscillator()):
        found = an.orbit(case)
        period = an.runner(case).period
        spectrum = an.lyapunov(case, found.state, settle=0, periods=500)
        assert not spectrum.grazings
        largest = np.log(np.abs(found.floquet_multipliers).max()) / period
        if case is system:
            total = np.log(abs(np.linalg.det(found.monodromy))) / period
            assert spectrum.exponents.sum() == pytest.approx(total, rel=1e-9)
        else:
            assert spectrum.exponents[1] == -math.inf
            assert spectrum.exponents[0] == pytest.approx(largest, rel=0.02)


@pytest.mark.timeout(120)
def test_a_stick_slip_orbit_s_derivatives_are_the_differences_of_its_neighbours() -> None:
    """The orbit's derivatives by parameters (the tangent flow's columns through each
    stop, stick and slip, then the implicit function theorem) against the central
    differences of the orbits found at p +- 1e-4 p."""
    system = _stick_slip_oscillator()
    found = an.orbit(system)
    assert found.converged
    paths = {
        "friction.0.static_coefficient": 1.6,
        "friction.0.coefficient": 1.0,
        "excitation.0.amplitude": 4.0,
    }
    derivatives = an.orbit_derivatives(system, found, list(paths))
    data = system.to_dict()
    for path, value in paths.items():
        step = 1e-4 * value
        states = []
        for sign in (1.0, -1.0):
            shifted = an.with_parameter(data, path, value + sign * step)
            states.append(an.orbit(vi.System.from_dict(shifted), found.state).state)
        difference = (states[0] - states[1]) / (2 * step)
        # m and m/s per unit of the parameter, scaled as the orbit's own state.
        scale = np.array([0.01, 0.05])
        assert np.abs((derivatives[path].state - difference) / scale).max() < 1e-4, path


@pytest.mark.timeout(30)
def test_a_system_with_friction_round_trips_through_toml() -> None:
    system = vi.System.from_dict(HorizontalDamper().toml_sections())
    system = system.replace(frictions=[vi.Friction(at=0, coefficient=0.1, normal_force=2.0)])
    text = system.to_toml()
    assert "[[friction]]" in text and "static_friction = 0.3" in text
    assert vi.load(text) == system


@pytest.mark.timeout(60)
def test_a_study_varies_a_damper_s_friction(tmp_path: Path) -> None:
    from vibroimpact.study import run

    data = HorizontalDamper().toml_sections()
    data["solver"] = {"t_end": 0.5, "method": "exact"}
    data["study"] = {
        "axes": {"damper.0.friction": [0.05, 0.25]},
        "metrics": ["impacts"],
    }
    result = run(vi.study_of(data), tmp_path / "friction.nc")
    impacts = result["impacts"].values
    assert result["damper.0.friction"].values.tolist() == [0.05, 0.25]
    for value, count in zip([0.05, 0.25], impacts, strict=True):
        one = {k: v for k, v in data.items() if k != "study"}
        one["damper"] = [one["damper"][0] | {"friction": value, "static_friction": 0.3}]
        alone = vi.simulate(vi.System.from_dict(one))
        assert count == int((alone.contacts.to_pandas().kind == "impact").sum())


def test_a_study_s_friction_above_the_static_names_the_damper_s_keys(tmp_path: Path) -> None:
    import json

    from vibroimpact.study import run

    data = HorizontalDamper().toml_sections()
    data["solver"] = {"t_end": 0.1, "method": "exact"}
    data["study"] = {"axes": {"damper.0.friction": [0.5]}, "metrics": ["impacts"]}
    result = run(vi.study_of(data), tmp_path / "friction.nc")
    # It had named the friction element's keys, which a damper does not have.
    (reason,) = json.loads(result.attrs["reasons"])
    assert "damper 0 static_friction: must be >= friction 0.5" in reason, reason


def _stick_slip_reference(t_end: float) -> float:
    """scipy's event-driven integration of ``x'' + 100 x + F sgn(x') = 1.2 sin(2 pi t)``
    (1 kg; 0.9 N sliding, 1 N static), stuck from rest until the spring and force pass
    1 N: the displacement at ``t_end``."""
    from scipy.integrate import solve_ivp

    k, kinetic, held, omega = 100.0, 0.9, 1.0, 2 * math.pi

    def load(t: float, x: float) -> float:
        return 1.2 * math.sin(omega * t) - k * x

    def slide(t, y, s):
        return [y[1], load(t, y[0]) - s * kinetic]

    def stopped(t, y, s):
        return y[1]

    def slips(t, y):
        return held - abs(load(t, y[0]))

    stopped.terminal = slips.terminal = True
    slips.direction = -1
    t, y, mode = 0.0, [0.0, 0.0], ("stuck", 0.0)
    while t < t_end:
        kind, s = mode
        if kind == "stuck":
            sol = solve_ivp(
                lambda t, y: [0.0, 0.0],
                (t, t_end),
                y,
                events=slips,
                rtol=1e-12,
                atol=1e-15,
                max_step=1e-3,
            )
        else:
            stopped.direction = -s
            sol = solve_ivp(
                slide,
                (t, t_end),
                y,
                args=(s,),
                events=stopped,
                rtol=1e-12,
                atol=1e-15,
                max_step=1e-3,
            )
        if sol.status != 1:
            return float(sol.y[0, -1])
        t = float(sol.t_events[0][0])
        y = [float(sol.y_events[0][0][0]), 0.0]
        force = load(t, y[0])
        if kind == "slide" and abs(force) <= held:
            mode = ("stuck", 0.0)
        else:
            # Slipping (or sliding back): along the net force; a few ulps of speed
            # that way, so that solve_ivp does not find its stop at the start.
            s = math.copysign(1.0, force)
            y[1] = s * 1e-15
            mode = ("slide", s)
    return float(y[0])


@pytest.mark.parametrize("method", METHODS + ["generalized-alpha"])
@pytest.mark.timeout(60)
def test_a_forced_oscillator_sticks_and_slips_as_scipy_integrates_it(method: str) -> None:
    # Stuck from rest, it slips where the force passes the static 1 N (t = 0.157 s) and
    # sticks again within the period: every method locates both (an adaptive step
    # stays short while stuck, as a slip shows only at a step's end).
    system = vi.System(
        structure=vi.Oscillator(mass=1.0, stiffness=100.0, damping=0.0),
        frictions=[vi.Friction(at=0, coefficient=0.9, static_coefficient=1.0, normal_force=1.0)],
        excitations=[
            vi.Force(at=0, signal=vi.Harmonic(amplitude=1.2, frequency=1.0, phase=-math.pi / 2))
        ],
    )
    step = {"dt": 1e-4} if method in ("newmark-implicit", "generalized-alpha") else {}
    sol = vi.simulate(system, method=method, t_end=3.0, history=False, **step)
    expected = _stick_slip_reference(3.0)
    tolerance = 1e-9 if method in ("exact", "dop853") else 1e-6
    assert sol.final_state["structure_displacement"][0] == pytest.approx(expected, abs=tolerance)
    stuck = sol.contacts.to_pandas()
    assert len(stuck) >= 3 and (stuck.duration.dropna() > 1e-3).all()
    assert sol.energy["friction"] > 0.05


@pytest.mark.timeout(30)
def test_two_pads_on_one_row_act_as_one_with_their_forces_summed() -> None:
    def decay(pads: list[vi.Friction]) -> vi.SystemSolution:
        system = vi.System(
            structure=vi.Oscillator(mass=2.0, stiffness=800.0, damping=0.0),
            frictions=pads,
            initial=vi.Initial(structure_displacement=[0.0165]),
        )
        return vi.simulate(system, method="exact", t_end=1.0, history=False)

    two = decay(
        [
            vi.Friction(at=0, coefficient=0.3, static_coefficient=0.4, normal_force=10.0),
            vi.Friction(at=0, coefficient=0.1, static_coefficient=0.2, normal_force=10.0),
        ]
    )
    one = decay([vi.Friction(at=0, coefficient=0.4, static_coefficient=0.6, normal_force=10.0)])
    x = two.final_state["structure_displacement"][0]
    assert x == pytest.approx(one.final_state["structure_displacement"][0], abs=1e-15)
    # The closed form: one half cycle about 5 mm loses 10 mm, then 6 N holds it.
    assert x == pytest.approx(-0.0065, abs=1e-14)


@pytest.mark.timeout(60)
def test_a_cantilever_rubbing_at_its_tip_on_the_exact_flow_and_dop853() -> None:
    # A stop that is never reached must not change the exact flow's stuck
    # configurations (each is made again where the element sticks).
    data = {
        "structure": {
            "kind": "cantilever",
            "length": 0.5,
            "youngs_modulus": 7e10,
            "second_moment": 1e-10,
            "mass_per_length": 0.27,
            "modes": 3,
            "damping_ratio": 0.01,
        },
        "excitation": [
            {"kind": "force", "at": 0.5, "signal": "harmonic", "amplitude": 2.0, "frequency": 8.0}
        ],
        "friction": [
            {"at": 0.5, "coefficient": 0.3, "static_coefficient": 0.4, "normal_force": 1.0}
        ],
    }
    far = data | {
        "stop": [{"at": 0.5, "side": "lower", "gap": 1.0, "law": "rigid", "restitution": 0.5}]
    }
    tips = []
    for sections, method in ((data, "exact"), (far, "exact"), (data, "dop853")):
        tight = {"rtol": 1e-12, "atol": 1e-15} if method == "dop853" else {}
        sol = vi.simulate(
            vi.System.from_dict(sections),
            method=method,
            t_end=0.9,
            history=False,
            points=[0.5],
            **tight,
        )
        energy = sol.energy
        assert abs(energy["residual"]) < 1e-9 * energy["input_work"]
        tips.append(sol.final_state["structure_displacement"])
    assert np.allclose(tips[0], tips[1], rtol=0, atol=1e-14)
    assert np.allclose(tips[0], tips[2], rtol=0, atol=1e-9)


@pytest.mark.timeout(60)
def test_masses_held_together_by_friction_move_as_one_body_by_the_exact_flow() -> None:
    # Two masses on a spring, held by a [[friction]] element that never slips (0.16 N of
    # spring force, 0.4 N held), under a constant load: one 1.6 kg body. With both
    # masses stuck the only mode left is rigid, whose stiffness came out as round-off
    # (1e-29, with no stiffer mode to judge it by): its static response F / w2 swamped the
    # motion. The exact flow returned the start's positions at every t (input work 0,
    # missed by the 5 % ledger), or an energy error under gravity.
    structure = {
        "kind": "matrices",
        "mass": [[1.0, 0.0], [0.0, 0.6]],
        "stiffness": [[400.0, -400.0], [-400.0, 400.0]],
    }
    held = [{"at": 1, "against": 0, "coefficient": 0.3, "static_coefficient": 0.4}]
    held[0]["normal_force"] = 1.0
    x0, v0, t_end = np.array([0.0, 4e-4]), 1.0, 0.5
    force = [{"kind": "force", "at": 1, "signal": "harmonics"}]
    force[0].update(amplitudes=[0.03], frequencies=[0.0])  # a constant 0.03 N
    loads = {"excitation": force}, {"gravity": {"acceleration": 9.81}}
    accelerations = 0.03 / 1.6, -9.81
    for load, a in zip(loads, accelerations, strict=True):
        sol = vi.simulate_system(
            structure,
            method="exact",
            friction=held,
            initial={"structure_displacement": x0.tolist(), "structure_velocity": [v0, v0]},
            t_end=t_end,
            **load,
        )
        f = sol.final_state
        expected = x0 + v0 * t_end + 0.5 * a * t_end**2
        assert np.allclose(f["structure_displacement"], expected, rtol=0, atol=1e-12), load
        assert np.allclose(f["structure_velocity"], v0 + a * t_end, rtol=0, atol=1e-12)
        assert abs(sol.energy["residual"]) < 1e-12


@pytest.mark.timeout(60)
def test_a_continuation_ending_on_a_damper_with_friction_ends_without_a_traceback(
    tmp_path: Path,
) -> None:
    # Where the corrector failed, the grazings ahead were sought on every pair named
    # "damper ...": the damper's friction, "damper 0 friction", was taken for a damper's
    # wall ("damper 0 friction upper"), a KeyError and a traceback (exit 1).
    from vibroimpact.analysis.grazing import walls

    names = ["damper 0", "damper 0 friction", "stop 1", "friction 0", "collision 0"]
    assert walls(names) == ["damper 0 upper", "damper 0 lower", "stop 1"]
    text = """
[structure]
kind = "oscillator"
mass = 1.0
stiffness = 4000.0
damping = 2.0
[[damper]]
mass = 0.1
at = 0
clearance = 0.01
law = "rigid"
restitution = 0.6
friction = 0.2
static_friction = 0.3
normal_force = 0.981
[[excitation]]
kind = "force"
at = 0
signal = "harmonic"
amplitude = 50.0
frequency = 4.0
[solver]
method = "exact"
t_end = 1.0
[initial]
structure_displacement = [0.01521499070420853]
damper_displacement = [0.01600750284188991]
structure_velocity = [-0.0335928489612893]
damper_velocity = [0.29798609918843927]
[continuation]
parameter = "excitation.0.frequency"
stop = 9.0
step = 0.1
"""
    path = tmp_path / "continue.toml"
    path.write_text(text)
    done = subprocess.run(
        [sys.executable, "-m", "vibroimpact", "continue", str(path)],
        capture_output=True,
        text=True,
        timeout=50,
    )
    assert done.returncode == 0, done.stderr
    assert "Traceback" not in done.stderr and "orbits of 1 period" in done.stdout
