"""The documentation's tutorials (docs/tutorials_src/plot_*.py), each run as the site
runs it, and its result checked against a value found without the code under test:
closed forms, Newton's impact law, Holmes's ball on a table, a scipy modal solution,
random-vibration theory, and a study's bytes uninterrupted."""

from __future__ import annotations

import math
import runpy
from functools import cache
from pathlib import Path
from typing import Any

import matplotlib
import numpy as np
import pytest
from scipy.integrate import quad, solve_ivp
from scipy.optimize import brentq

from friction_reference import horizontal_damper_at

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

TUTORIALS = Path(__file__).resolve().parents[1] / "docs" / "tutorials_src"


@cache
def tutorial(name: str) -> dict[str, Any]:
    """The namespace a tutorial leaves, run once; its figures closed."""
    try:
        return runpy.run_path(str(TUTORIALS / f"plot_{name}.py"), run_name="__main__")
    finally:
        plt.close("all")


def test_every_tutorial_is_tested_here() -> None:
    # A tutorial added without a check here would go unchecked.
    names = {p.stem.removeprefix("plot_") for p in TUTORIALS.glob("plot_*.py")}
    tested = {
        "impact_damper_response",
        "frequency_response",
        "best_clearance",
        "cantilever_ground_motion",
        "impact_oscillator_maps",
        "monte_carlo_random",
        "dask_study",
        "colliding_masses",
        "friction",
    }
    assert names == tested and (TUTORIALS / "README.rst").is_file()


def linear_amplitude(ns: dict[str, Any], frequency: float) -> float:
    """|F / (K - M w^2 + i w C)| (m) of the bare one-mode structure at ``frequency`` Hz."""
    omega = 2 * math.pi * frequency
    dynamic = ns["STIFFNESS"] - ns["MASS"] * omega**2 + 1j * omega * ns["DAMPING"]
    return float(ns["FORCE"] / abs(dynamic))


# 1. Free and forced response ----------------------------------------------------------


def test_free_response_first_impact_is_the_free_decay_reaching_the_clearance() -> None:
    # Catches a wrong stiffness or damping, or an impact located off the exact flow: before
    # its first impact the structure decays freely from its release.
    ns = tutorial("impact_damper_response")
    m, k, c, x0 = ns["MASS"], ns["STIFFNESS"], ns["DAMPING"], ns["RELEASE"]
    wn = math.sqrt(k / m)
    zeta = c / (2 * math.sqrt(k * m))
    wd = wn * math.sqrt(1 - zeta**2)

    def decay(t: float) -> float:
        shape = math.cos(wd * t) + zeta / math.sqrt(1 - zeta**2) * math.sin(wd * t)
        return x0 * math.exp(-zeta * wn * t) * shape

    # The loose mass rests at x0; the upper wall reaches it when x = x0 - d.
    first = brentq(lambda t: decay(t) - (x0 - ns["CLEARANCE"]), 0.0, math.pi / wd, xtol=1e-15)
    free = ns["free"]
    assert free.contacts.onset[0] == pytest.approx(first, abs=1e-12)
    assert free.energy["stored_start"] == pytest.approx(0.5 * k * x0**2, rel=1e-14)


def test_every_impact_obeys_newtons_law() -> None:
    # Catches a wrong restitution or effective mass: each impact reverses the approach at
    # e and takes 1/2 m_eff (1 - e^2) v^2, m_eff = M m / (M + m).
    ns = tutorial("impact_damper_response")
    e, big, small = ns["RESTITUTION"], ns["MASS"], ns["LOOSE_MASS"]
    for sol in (ns["free"], ns["forced"]):
        table = sol.contacts
        assert len(table) > 20
        np.testing.assert_allclose(table.rebound_speed, e * table.approach_speed, rtol=1e-12)
        loss = 0.5 * big * small / (big + small) * (1 - e**2) * table.approach_speed**2
        np.testing.assert_allclose(table.energy_dissipated, loss, rtol=1e-10)


def test_forced_response_balances_the_work_of_the_force() -> None:
    # Conservation of energy from independent pieces: the force's work and the viscous loss
    # integrated over the history, Newton's impact losses, and the energy stored at the end
    # from the final state. Catches a wrong force (amplitude, frequency, phase) or damping.
    ns = tutorial("impact_damper_response")
    sol = ns["forced"]
    t, v = sol.t, sol.structure_velocity[:, 0]
    omega = 2 * math.pi * ns["FREQUENCY"]
    work = np.trapezoid(ns["FORCE"] * np.cos(omega * t) * v, t)
    viscous = np.trapezoid(ns["DAMPING"] * v**2, t)
    e, big, small = ns["RESTITUTION"], ns["MASS"], ns["LOOSE_MASS"]
    impacts = np.sum(
        0.5 * big * small / (big + small) * (1 - e**2) * sol.contacts.approach_speed**2
    )
    final = sol.final_state
    stored = (
        0.5 * ns["STIFFNESS"] * final["structure_displacement"][0] ** 2
        + 0.5 * big * final["structure_velocity"][0] ** 2
        + 0.5 * small * final["damper_velocity"][0] ** 2
    )
    assert work == pytest.approx(sol.energy["input_work"], rel=2e-3)
    assert work - viscous - impacts - stored == pytest.approx(0.0, abs=5e-3 * work)


def test_forced_bare_structure_follows_the_closed_form_from_rest() -> None:
    # Catches a force of the wrong amplitude, frequency or phase, or a wrong structure: the
    # bare run is the harmonic response Re(Q e^(i w t)) plus the free decay that starts it
    # from rest, at every kept time.
    ns = tutorial("impact_damper_response")
    m, k, c = ns["MASS"], ns["STIFFNESS"], ns["DAMPING"]
    omega = 2 * math.pi * ns["FREQUENCY"]
    q = ns["FORCE"] / (k - m * omega**2 + 1j * omega * c)
    wn, zeta = math.sqrt(k / m), c / (2 * math.sqrt(k * m))
    wd = wn * math.sqrt(1 - zeta**2)
    a = -q.real  # x(0) = 0
    b = (omega * q.imag + zeta * wn * a) / wd  # v(0) = 0
    bare = ns["forced_bare"]
    t = bare.t
    x = (q * np.exp(1j * omega * t)).real + np.exp(-zeta * wn * t) * (
        a * np.cos(wd * t) + b * np.sin(wd * t)
    )
    np.testing.assert_allclose(bare.structure_displacement[:, 0], x, atol=1e-10 * abs(q))
    assert ns["linear_amplitude"] == pytest.approx(abs(q), rel=1e-14)
    assert ns["forced_amplitude"] < 0.7 * abs(q)  # the damper's effect, as the text says


# 2. Frequency response ----------------------------------------------------------------


def test_bare_frequency_response_is_the_closed_form_up_and_down() -> None:
    # Catches a sweep that sets another parameter, a wrong settled amplitude, or a linear
    # amplitude (the reduction's reference) computed wrong.
    ns = tutorial("frequency_response")
    for point in ns["bare_points"]:
        expected = linear_amplitude(ns, point.value)
        assert point.settled and point.impacts_per_period == 0
        assert point.amplitude[0] == pytest.approx(expected, rel=1e-6)
    for point in ns["damped_points"]:
        assert point.linear_amplitude[0] == pytest.approx(linear_amplitude(ns, point.value))
    assert len(ns["bare_points"]) == 2 * len(ns["frequencies"])
    # The bare peak lies at the grid's point nearest sqrt(1 - 2 zeta^2) f_n = 9.996 Hz.
    best = max(ns["bare_points"], key=lambda p: p.amplitude[0])
    assert best.value == pytest.approx(10.0)


def test_damped_frequency_response_shows_jumps_and_unsettled_points() -> None:
    # What the figure must show: the damper lowers the peak, some points do not settle
    # (each with a spread), and up and down differ somewhere (hysteresis).
    ns = tutorial("frequency_response")
    damped = ns["damped_points"]
    peak = max(p.amplitude[0] for p in damped)
    assert peak < 0.9 * max(linear_amplitude(ns, p.value) for p in damped)
    assert ns["unsettled"]
    for p in ns["unsettled"]:
        assert 0 < np.min(p.least_period_peak) <= p.amplitude[0]
    up = {p.value: p.amplitude[0] for p in damped if p.direction == "up"}
    down = {p.value: p.amplitude[0] for p in damped if p.direction == "down"}
    assert max(abs(up[f] - down[f]) / up[f] for f in up) > 0.05


# 3. Best clearance ----------------------------------------------------------------------


def test_clearance_study_wide_row_is_the_bare_structure_and_the_best_beats_it() -> None:
    # Catches axes applied to the wrong key or values: at 50 mm the loose mass never strikes
    # and every amplitude over the band is the closed form; the best clearance is the argmin
    # of the worst case over the band, below the bare worst case.
    ns = tutorial("best_clearance")
    result = ns["result"]
    assert int(result["status"].max()) == 0
    wide = result.sel({"damper.0.clearance": 0.050})
    assert np.all(wide["impacts_per_period"] == 0)
    for frequency in result["excitation.0.frequency"].values:
        amplitude = float(wide["amplitude"].sel({"excitation.0.frequency": frequency})[0])
        assert amplitude == pytest.approx(linear_amplitude(ns, frequency), rel=1e-6)
    frequencies = result["excitation.0.frequency"].values
    assert frequencies[0] == 9.0 and frequencies[-1] == 11.0 and len(frequencies) == 11
    worst = result["amplitude"].values[:, :, 0].max(axis=1)
    clearances = result["damper.0.clearance"].values
    assert ns["best_clearance"] == clearances[np.argmin(worst)]
    assert worst.min() < 0.8 * max(linear_amplitude(ns, f) for f in frequencies)


# 4. Cantilever under a ground motion ---------------------------------------------------


def cantilever_modes(count: int) -> list[tuple[float, float]]:
    """(beta L, sigma) of a clamped-free beam's first modes: 1 + cos(bL) cosh(bL) = 0."""
    modes = []
    for i in range(count):
        guess = (i + 0.5) * math.pi
        bl = brentq(lambda x: 1 + math.cos(x) * math.cosh(x), guess - 1.0, guess + 1.0)
        sigma = (math.cosh(bl) + math.cos(bl)) / (math.sinh(bl) + math.sin(bl))
        modes.append((bl, sigma))
    return modes


@pytest.mark.timeout(120)
def test_cantilever_bare_response_matches_an_independent_modal_solution() -> None:
    # Catches a wrong participation (the base load on each mode), modal frequency, damping,
    # mode-shape normalisation, tip deflection or root moment (E I w''(0), its sign): the
    # same three modes integrated by scipy, each loaded by -(int phi dx / L) a(t).
    ns = tutorial("cantilever_ground_motion")
    beam, length = ns["beam"], ns["LENGTH"]
    ei = beam.youngs_modulus * beam.second_moment
    rho_a = beam.mass_per_length
    run = ns["bare_run"]
    times, record = ns["record_time"], ns["acceleration"]
    tip = np.zeros_like(run.t)
    moment = np.zeros_like(run.t)
    zeta = beam.damping_ratio
    for bl, sigma in cantilever_modes(beam.modes):
        beta = bl / length

        def shape(x: float, beta: float = beta, sigma: float = sigma) -> float:
            return (
                math.cosh(beta * x)
                - math.cos(beta * x)
                - sigma * (math.sinh(beta * x) - math.sin(beta * x))
            )

        norm = quad(lambda x: shape(x) ** 2, 0, length)[0] / length  # 1 for these shapes
        participation = quad(shape, 0, length)[0] / length / norm
        omega = beta**2 * math.sqrt(ei / rho_a)

        def rates(t: float, z: np.ndarray, omega: float = omega, p: float = participation):
            a = np.interp(t, times, record, left=0.0, right=0.0)
            return [z[1], -(omega**2) * z[0] - 2 * zeta * omega * z[1] - p * a]

        sol = solve_ivp(
            rates,
            (0.0, run.t[-1]),
            [0.0, 0.0],
            method="DOP853",
            t_eval=run.t,
            rtol=1e-11,
            atol=1e-14,
            max_step=0.005,
        )
        tip += shape(length) * sol.y[0] / math.sqrt(norm)
        moment += ei * 2 * beta**2 * sol.y[0] / math.sqrt(norm)  # phi''(0) = 2 beta^2
    assert np.max(np.abs(tip)) > 1e-3
    np.testing.assert_allclose(ns["tip"], tip, atol=1e-6 * np.max(np.abs(tip)))
    np.testing.assert_allclose(ns["root_moment"], moment, atol=1e-6 * np.max(np.abs(moment)))


# 5. Bifurcations, sections and basins of Holmes's ball on a table --------------------


def holmes(ns: dict[str, Any], gamma: float) -> dict[str, float]:
    """Holmes's period-one orbit (forced-oracles.md): the impact's phase of w t on the
    tutorial's clock (table displacement -(a/w^2) cos(w t + phase) = A sin(w t + phase -
    pi/2)), the closing speed, and the largest height above the table over a flight."""
    g, e = ns["GRAVITY"], ns["RESTITUTION"]
    omega = 2 * math.pi * ns["FREQUENCY"]
    amplitude = gamma * g / omega**2  # m
    phi = math.acos(math.pi * (1 - e) / ((1 + e) * gamma))  # sin(phi) > 0: stable branch
    speed = 2 * math.pi * g / (omega * (1 + e))
    phase_shift = ns["ball_on_table"](gamma).excitations[0].signal.phase - math.pi / 2
    impact_phase = (phi - phase_shift) % (2 * math.pi)
    table = lambda theta: amplitude * np.sin(theta)  # noqa: E731
    tau = np.linspace(0, 2 * math.pi / omega, 200001)
    launch = amplitude * omega * math.cos(phi) + e * speed  # the ball's own, after impact
    height = launch * tau - 0.5 * g * tau**2 - (table(phi + omega * tau) - table(phi))
    return {"phase": impact_phase, "speed": speed, "height": float(height.max())}


def test_period_one_section_is_holmes_orbit() -> None:
    # Catches a wrong restitution, gravity, table amplitude or forcing phase: every impact of
    # the settled section at Gamma = 1.4 has Holmes's phase and closing speed.
    ns = tutorial("impact_oscillator_maps")
    section = ns["sections"][1.4]
    orbit = holmes(ns, 1.4)
    assert len(section.impact_speed) == 400
    np.testing.assert_allclose(section.impact_speed, orbit["speed"], rtol=1e-7)
    np.testing.assert_allclose(section.impact_phase, orbit["phase"], atol=1e-6)
    chaotic = ns["sections"][2.1]
    assert np.ptp(chaotic.impact_speed) > 0.3  # spread over the attractor, as drawn


def test_bifurcation_diagram_doubles_at_holmes_flip() -> None:
    # Catches a wrong stability of the orbit or sampling: one impact speed per point below
    # Gamma_flip (the closing speed), two just above, within one grid step of Holmes's value.
    ns = tutorial("impact_oscillator_maps")
    e = ns["RESTITUTION"]
    flip = math.hypot(math.pi * (1 - e) / (1 + e), 2 * (1 + e**2) / (1 + e) ** 2)
    step = ns["gammas"][1] - ns["gammas"][0]
    distinct = []
    for point in ns["diagram"]:
        samples = np.sort(np.asarray(point.samples))
        groups = 1 + int(np.sum(np.diff(samples) > 1e-6 * samples.max()))
        distinct.append(groups)
        gamma = point.value / ns["GRAVITY"]
        if gamma < flip - step:
            np.testing.assert_allclose(samples, holmes(ns, gamma)["speed"], rtol=1e-7)
    first_doubled = ns["gammas"][distinct.index(2)]
    assert flip <= first_doubled <= flip + step
    assert max(distinct) > 8  # the cascade to chaos is drawn


def test_basins_hold_holmes_orbit_and_the_chattering_one() -> None:
    # Catches attractors grouped wrongly or the wrong orbit reached: the one-impact
    # attractor's height is that of Holmes's orbit over a flight; the other chatters (many
    # impacts a period, a small height); every start settles on one of the two.
    ns = tutorial("impact_oscillator_maps")
    basins = ns["basins"]
    assert len(basins.attractors) == 2
    by_impacts = {a["impacts_per_period"]: a for a in basins.attractors}
    period_one = by_impacts[1.0]
    assert period_one["period"] == 1
    assert period_one["amplitude"][0] == pytest.approx(holmes(ns, 1.2)["height"], rel=1e-6)
    chattering = [a for a in basins.attractors if a is not period_one][0]
    assert chattering["impacts_per_period"] > 5
    assert chattering["amplitude"][0] < 0.1 * period_one["amplitude"][0]
    assert np.all(basins.labels >= 0)
    # A start at the orbit's own state (t = 0 mid-flight) reaches the orbit.
    i = int(np.argmin(np.abs(basins.first - 0.015)))
    j = int(np.argmin(np.abs(basins.second - 0.16)))
    assert basins.attractors[basins.labels[i, j]] is period_one


# 6. Monte Carlo under white noise ------------------------------------------------------


@pytest.mark.timeout(120)
def test_monte_carlo_mean_square_is_random_vibration_theory() -> None:
    # Catches a noise intensity off by 2 pi or 2 (one- or two-sided), a wrong cutoff or
    # damping, or seeds that repeat one realisation: the mean of 400 mean squares lies
    # within 3 standard errors of the integral of |H|^2 S(w), S the noise's density with
    # its roll-off, and that integral within 0.5 % of pi S0 / (2 zeta wn^3).
    ns = tutorial("monte_carlo_random")
    bare = ns["bare"]
    assert np.unique(bare).size == ns["RUNS"]
    wn, zeta, s0 = ns["omega_n"], ns["ZETA"], ns["INTENSITY"]
    wc = 2 * math.pi * ns["CUTOFF"]

    def density(w: float) -> float:
        h2 = 1 / ((wn**2 - w**2) ** 2 + (2 * zeta * wn * w) ** 2)
        return h2 * s0 * np.sinc(w / (2 * wc)) ** 4  # sinc^4(w pi / (2 wc))

    theory = 2 * quad(density, 0, 50 * wn, points=[wn], limit=400)[0]
    white = math.pi * s0 / (2 * zeta * wn**3)
    assert theory == pytest.approx(white, rel=5e-3)
    error = bare.std(ddof=1) / math.sqrt(bare.size)
    assert abs(bare.mean() - theory) < 3 * error
    assert error < 0.02 * theory  # the ensemble is large enough to mean something
    assert ns["damped"].mean() < bare.mean()  # the damper's effect, as the text says


# 7. A study on Dask, interrupted and resumed ------------------------------------------


@pytest.mark.timeout(120)
def test_dask_study_resumed_is_byte_identical_to_an_uninterrupted_one() -> None:
    # Catches a resume that runs kept chunks again, skips or reorders some, or a Dask
    # result that differs from the local engine's: the interruption really kept 3 of 9
    # chunks and wrote no file, and the resumed file is the uninterrupted one's bytes.
    ns = tutorial("dask_study")
    assert len(ns["kept"]) == 3 and len(ns["study"].chunks()) == 9
    assert any("resuming from" in n and "6 chunks to run" in n for n in ns["notices"])
    assert ns["resumed_bytes"] == ns["uninterrupted_bytes"]
    assert int(ns["resumed"]["status"].max()) == 0


# Loose masses that collide ------------------------------------------------------------


def test_colliding_masses_obey_newton_s_law_and_a_row_is_not_a_cradle() -> None:
    from test_collisions import _hertz_chain

    ns = tutorial("colliding_masses")
    (contact,) = ns["two"].contacts.to_pandas().itertuples()
    e, lower, upper = ns["RESTITUTION"], ns["LOWER"], ns["UPPER"]
    closing = 1.0 + 0.5
    assert contact.approach_speed == pytest.approx(closing, rel=1e-12)
    assert contact.rebound_speed == pytest.approx(e * closing, rel=1e-12)
    v = ns["two"].final_state["damper_velocity"]
    assert lower * v[0] + upper * v[1] == pytest.approx(lower * 1.0 - upper * 0.5, abs=1e-15)
    reduced = lower * upper / (lower + upper)
    assert ns["two"].energy["impact"] == pytest.approx(
        0.5 * reduced * (1 - e * e) * closing**2, rel=1e-12
    )
    # The rigid row: momentum and energy with the touching pair moving as one.
    rigid = ns["ROW_RIGID"].final_state["damper_velocity"]
    assert rigid == pytest.approx([-1 / 3, 2 / 3, 2 / 3], abs=1e-14)
    # The Hertz row: scipy's integration of the same three masses.
    reference = _hertz_chain([0.1, 0.1, 0.1], 1e9, [0.01, 0.0], 1.0)
    hertz = ns["ROW_HERTZ"].final_state["damper_velocity"]
    assert hertz == pytest.approx(reference.y[3:, -1], abs=1e-8)
    # The column's ledgers close, the contacts' loss being the contacts' own.
    for sol in ns["RUNS"].values():
        energy = sol.energy
        assert abs(energy["residual"]) < 1e-6 * energy["input_work"]
        losses = float(np.sum(sol.contacts.energy_dissipated))
        assert energy["contact"] == pytest.approx(losses, rel=1e-6)


def test_friction_tutorial_decays_as_the_closed_form_and_follows_scipy() -> None:
    ns = tutorial("friction")
    turning, decay = ns["turning"], ns["decay"]
    # The closed form written afresh: each half cycle loses 2 F / k, then rest in the band.
    slide, band, x = 0.3 * 10.0 / 800.0, 0.4 * 10.0 / 800.0, 0.0513
    expected = [x]
    while abs(x) > band:
        x = -(x - 2 * slide * math.copysign(1.0, x))
        expected.append(x)
    assert turning == pytest.approx(expected, abs=1e-15)
    assert decay.final_state["structure_displacement"][0] == pytest.approx(x, abs=1e-12)
    assert decay.energy["friction"] == pytest.approx(0.5 * 800.0 * (0.0513**2 - x**2), rel=1e-9)
    # The horizontal damper against scipy's event-driven stick-slip (the same system).
    reference, _ = horizontal_damper_at(2.0)
    f = ns["response"].final_state
    ours = [f["structure_displacement"][0], f["damper_displacement"][0]]
    assert ours == pytest.approx(reference[:2], abs=1e-6)
    energy = ns["energy"]
    assert abs(energy["residual"]) < 1e-8 * energy["input_work"]
    stuck = ns["table"][ns["table"].pair == "damper 0 friction"]
    assert len(stuck) > 0 and (stuck.kind == "sticking").all()
    # The stick-slip orbit: a zero multiplier (the stick forgets the velocity), the
    # other as differences of whole runs give it, and the orbit returns on itself.
    orbit, checked = ns["orbit"], ns["checked"]
    assert orbit.converged and orbit.stable and orbit.jacobian == "tangent"
    multipliers = np.sort(np.abs(orbit.floquet_multipliers))
    assert multipliers[0] == 0.0
    assert multipliers[1] == pytest.approx(np.abs(checked.floquet_multipliers).max(), rel=1e-6)
    assert (ns["cycle"].contacts.to_pandas().kind == "sticking").sum() >= 2
