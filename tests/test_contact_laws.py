"""The damped Hertz laws: what two bodies alone rebound at, against the exact relation.

For any law ``F = K delta^n (1 + alpha delta' / delta'_minus)`` acting alone between two
free bodies, the rebound/approach speed ratio ``e*`` satisfies exactly
``alpha (1 + e*) = ln((1 + alpha) / (1 - alpha e*))`` (reference page), whatever the
masses, the stiffness and the approach speed. "hertz-damped" solves alpha from that
relation for the requested e, so the rebound must be e; the paper's "hyster-hertz"
sets alpha = 3/4 (1 - e^2) and rebounds faster. Every expected value here comes from
SciPy's brentq on the relation, from SciPy's integration of the law's force, or from
the speeds and the kinetic energy of the run.
"""

from __future__ import annotations

import math
import pickle
import warnings
from typing import Any

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

import vibroimpact as vi

RESTITUTIONS = [0.05, 0.1, 0.3, 0.5, 0.7, 0.9, 1.0]

# (main mass kg, impact mass kg, K_hz N/m^1.5, approach speed m/s, which body moves)
COLLISIONS = [
    (1.0, 0.25, 3000.0, 0.1, "impact"),
    (2.0, 0.5, 1.0e5, 0.3, "main"),
    (0.01, 3.0, 50.0, 0.02, "both"),
]
COLLISION_IDS = ["table1", "stiff", "light-main"]


def relation(alpha: float, e: float) -> float:
    """alpha (1 + e) - ln((1 + alpha) / (1 - alpha e)), zero on the law's rebound."""
    return alpha * (1 + e) - (math.log1p(alpha) - math.log1p(-alpha * e))


def rebound_of(alpha: float) -> float:
    """The rebound ratio of hysteresis alpha: the root in e of the relation."""
    if alpha == 0.0:
        return 1.0
    upper = min(1.0, (1 - 1e-15) / alpha)  # the logarithm needs alpha e < 1
    return float(brentq(lambda e: relation(alpha, e), 0.0, upper, xtol=1e-16))


def hysteresis_for(e: float) -> float:
    """The alpha that rebounds at e: the root in (0, 1/e) of the relation."""
    if e == 1.0:
        return 0.0
    return float(brentq(lambda a: relation(a, e), 1e-6, (1 - 1e-13) / e, xtol=1e-15))


def two_body_run(
    contact: vi.Contact,
    main_mass: float,
    impact_mass: float,
    k_hz: float,
    speed: float,
    moving: str,
    **settings: Any,
) -> vi.Solution:
    """Two free bodies (K = C = 0) from contact onset at relative speed ``speed``.

    The clearance is wide enough that nothing else happens within 12 Hertz durations
    (a slow rebound at low e lasts several of them).
    """
    # The elastic Hertz duration (Goldsmith), a time scale for the run.
    tc = vi.goldsmith_contact_duration(impact_mass, main_mass, k_hz, speed)
    clearance = 20 * tc * speed
    system = vi.ImpactDamper(
        main_mass=main_mass, stiffness=0.0, impact_mass=impact_mass, clearance=clearance
    )
    velocities = {
        "impact": (0.0, speed),
        "main": (-speed, 0.0),
        "both": (-0.25 * speed, 0.75 * speed),
    }[moving]
    start = vi.InitialState(
        main_velocity=velocities[0], impact_displacement=clearance, impact_velocity=velocities[1]
    )
    if "dt" in settings:
        settings["dt"] *= tc
    return vi.simulate(system, contact, start, t_end=12 * tc, **settings)


def one_contact(sol: vi.Solution, speed: float) -> vi.ContactTable:
    c = sol.contacts
    assert len(c) == 1 and np.isfinite(c.separation[0])
    assert c.onset[0] == 0.0
    assert c.approach_speed[0] == pytest.approx(speed, rel=1e-14)
    return c


# ------------------------------------------------------------- the law itself


def rebound_of_law_force(contact: vi.Contact, reduced_mass: float, speed: float) -> float:
    """Two free bodies pressed together by ``contact.law_force`` alone, integrated by
    SciPy (DOP853, rtol 1e-12) from onset at ``speed`` until the indentation returns
    to zero: the rebound/approach speed ratio. The law is a black box here, so this
    checks the force the package computes against the relation, not its formula."""

    def rhs(_t: float, s: np.ndarray) -> list[float]:
        return [s[1], -contact.law_force(float(s[0]), float(s[1]), speed) / reduced_mass]

    def separation(_t: float, s: np.ndarray) -> float:
        return float(s[0])

    separation.terminal = True  # type: ignore[attr-defined]
    separation.direction = -1  # type: ignore[attr-defined]
    sol = solve_ivp(
        rhs,
        (0.0, 100.0),
        [0.0, speed],
        method="DOP853",
        rtol=1e-12,
        atol=1e-18,
        events=separation,
    )
    assert sol.status == 1
    return float(-sol.y_events[0][0][1] / speed)


@pytest.mark.parametrize("e", RESTITUTIONS)
def test_hertz_damped_force_rebounds_two_bodies_at_e(e: float) -> None:
    contact = vi.Contact("hertz-damped", stiffness=2500.0, restitution=e)
    # The reduced mass of 1 kg on 0.25 kg, and another: e does not depend on it.
    for reduced_mass, speed in [(0.2, 0.1), (3.0, 0.7)]:
        assert rebound_of_law_force(contact, reduced_mass, speed) == pytest.approx(e, rel=1e-9)
    # At zero rate it is the elastic Hertz force, K delta^1.5, by definition.
    assert contact.law_force(1e-3, 0.0, 0.1) == pytest.approx(2500.0 * 1e-3**1.5, rel=1e-15)
    # Never a pull: clamped at zero when separating fast; nothing without indentation.
    if e < 1.0:
        fast = -10.0 / hysteresis_for(e)
        assert contact.law_force(1e-3, fast, 0.1) == 0.0
    assert contact.law_force(0.0, 0.05, 0.1) == 0.0
    assert contact.law_force(-1e-3, 0.05, 0.1) == 0.0


@pytest.mark.parametrize("gap", [1e-6, 1e-9])
def test_hertz_damped_rebounds_at_e_within_a_billionth_of_elastic(gap: float) -> None:
    """Its hysteresis was the root of a relation summed in closed form, whose sign near
    e = 1 was round-off: e = 1 - 1e-9 rebounded at 1 - 2.8e-13, losing nothing. The
    rebound of the law's force (SciPy, 1e-12) loses 1 - e of the speed."""
    e = 1.0 - gap
    contact = vi.Contact("hertz-damped", stiffness=1e6, restitution=e)
    rebound = rebound_of_law_force(contact, 0.2, 1.0)
    assert (1.0 - rebound) == pytest.approx(1.0 - e, rel=1e-2)
    assert 1.0 - contact.effective_restitution == pytest.approx(1.0 - e, rel=1e-6)


@pytest.mark.parametrize("e", [0.1, 0.5, 0.9])
def test_hyster_hertz_force_rebounds_two_bodies_above_e(e: float) -> None:
    """The paper's law rebounds at the relation's root for alpha = 3/4 (1 - e^2)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", vi.RestitutionWarning)
        contact = vi.Contact("hyster-hertz", stiffness=2500.0, restitution=e)
    expected = rebound_of(0.75 * (1 - e**2))
    assert rebound_of_law_force(contact, 0.2, 0.1) == pytest.approx(expected, rel=1e-9)


@pytest.mark.parametrize("e", RESTITUTIONS)
def test_hertz_damped_effective_restitution_is_e(e: float) -> None:
    for damping in (0.0, 0.3):  # the law's property, without the contact damper
        contact = vi.Contact("hertz-damped", stiffness=3000.0, damping=damping, restitution=e)
        assert contact.effective_restitution == pytest.approx(e, rel=1e-12)


HYSTER_RESTITUTIONS = [1e-9, 0.01, 0.1, 0.3, 0.5, 0.69, 0.7, 0.9, 0.99, 1.0]


@pytest.mark.parametrize("e", HYSTER_RESTITUTIONS)
def test_hyster_hertz_effective_restitution_obeys_the_relation(e: float) -> None:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", vi.RestitutionWarning)
        contact = vi.Contact("hyster-hertz", stiffness=3000.0, restitution=e)
    expected = rebound_of(0.75 * (1 - e**2))
    assert contact.effective_restitution == pytest.approx(expected, rel=1e-12, abs=1e-15)
    # The reference page: e = 0.9 -> 0.9132, e = 0.5 -> 0.7252.
    if e in (0.9, 0.5):
        assert round(contact.effective_restitution, 4) == {0.9: 0.9132, 0.5: 0.7252}[e]
    if e < 1.0:
        assert contact.effective_restitution > e


def test_hyster_hertz_never_rebounds_below_its_e_to_zero_limit() -> None:
    """alpha <= 3/4, so e* >= the root for alpha = 3/4: 0.66296 ('never below 0.663'
    on the reference page, rounded)."""
    floor = rebound_of(0.75)
    assert round(floor, 3) == 0.663
    grid = np.concatenate([np.geomspace(1e-12, 0.1, 12), np.linspace(0.1, 1.0, 46)])
    values = []
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", vi.RestitutionWarning)
        for e in grid:
            values.append(
                vi.Contact("hyster-hertz", 1.0, restitution=float(e)).effective_restitution
            )
    values_array = np.array(values)
    assert np.all(values_array >= floor * (1 - 1e-12))
    assert np.all(np.diff(values_array) >= -1e-15)  # grows with e
    assert values_array[0] == pytest.approx(floor, rel=1e-9)


@pytest.mark.parametrize("law", ["hertz", "linear"])
def test_elastic_laws_rebound_at_one(law: str) -> None:
    assert vi.Contact(law, stiffness=10.0).effective_restitution == 1.0
    assert vi.Contact(law, stiffness=10.0, damping=2.0).effective_restitution == 1.0


# ------------------------------------------------------------ RestitutionWarning


def restitution_warnings(law: str, e: float) -> list[warnings.WarningMessage]:
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        vi.Contact(law, stiffness=3000.0, restitution=e)
    return [w for w in caught if issubclass(w.category, vi.RestitutionWarning)]


def test_restitution_warning_is_a_user_warning() -> None:
    assert issubclass(vi.RestitutionWarning, UserWarning)


@pytest.mark.parametrize("e", [1e-9, 0.01, 0.3, 0.5, 0.69, 0.6999999])
def test_hyster_hertz_below_0_7_warns(e: float) -> None:
    with pytest.warns(vi.RestitutionWarning) as record:
        contact = vi.Contact("hyster-hertz", stiffness=3000.0, restitution=e)
    message = str(record[0].message)
    # It says what the law really rebounds at, and what to use instead.
    assert f"{contact.effective_restitution:.4f}" in message
    assert "hertz-damped" in message
    assert len(restitution_warnings("hyster-hertz", e)) == 1


@pytest.mark.parametrize("e", [0.7, 0.8, 0.9, 1.0])
def test_hyster_hertz_from_0_7_is_silent(e: float) -> None:
    assert restitution_warnings("hyster-hertz", e) == []


@pytest.mark.parametrize("e", RESTITUTIONS)
def test_hertz_damped_never_warns(e: float) -> None:
    assert restitution_warnings("hertz-damped", e) == []


# --------------------------------------------------------- two bodies, simulated

REBOUND_METHODS = [
    ({"method": "dop853", "rtol": 1e-10}, 1e-8),
    ({"method": "rk4", "dt": 1e-3, "stepping": "events"}, 1e-7),  # dt in Hertz durations
]


@pytest.mark.parametrize("e", RESTITUTIONS)
@pytest.mark.parametrize(("collision"), COLLISIONS, ids=COLLISION_IDS)
@pytest.mark.parametrize(
    ("settings", "tolerance"), REBOUND_METHODS, ids=[s["method"] for s, _ in REBOUND_METHODS]
)
def test_hertz_damped_two_bodies_rebound_at_e(
    settings: dict[str, Any], tolerance: float, collision: tuple[Any, ...], e: float
) -> None:
    big_m, m, k_hz, v, moving = collision
    contact = vi.Contact("hertz-damped", stiffness=k_hz, restitution=e)
    sol = two_body_run(contact, big_m, m, k_hz, v, moving, **settings)
    c = one_contact(sol, v)
    assert c.restitution[0] == pytest.approx(e, rel=tolerance)
    # The column is the ratio of the reported speeds, and the final relative
    # speed of the run is the rebound speed.
    assert c.restitution[0] == pytest.approx(c.rebound_speed[0] / c.approach_speed[0], rel=1e-15)
    final = sol.impact_velocity[-1] - sol.main_velocity[-1]
    assert -final == pytest.approx(c.rebound_speed[0], rel=1e-12)


@pytest.mark.parametrize("e", [0.3, 0.5, 0.7, 0.9, 1.0])
@pytest.mark.parametrize("method", ["newmark-implicit", "generalized-alpha"])
def test_hertz_damped_rebound_with_the_implicit_methods(method: str, e: float) -> None:
    """Second order: 1000 steps per contact give the rebound to ~1e-6."""
    contact = vi.Contact("hertz-damped", stiffness=3000.0, restitution=e)
    sol = two_body_run(contact, 1.0, 0.25, 3000.0, 0.1, "impact", method=method, dt=1e-3)
    assert one_contact(sol, 0.1).restitution[0] == pytest.approx(e, rel=1e-5)


@pytest.mark.parametrize(
    ("method", "e"),
    [("newmark-implicit", 0.05), ("generalized-alpha", 0.05), ("generalized-alpha", 0.1)],
)
def test_hertz_damped_low_e_with_the_implicit_methods(method: str, e: float) -> None:
    contact = vi.Contact("hertz-damped", stiffness=3000.0, restitution=e)
    sol = two_body_run(contact, 1.0, 0.25, 3000.0, 0.1, "impact", method=method, dt=1e-3)
    assert one_contact(sol, 0.1).restitution[0] == pytest.approx(e, rel=1e-4)


@pytest.mark.parametrize("e", [0.01, 0.5, 0.9])
@pytest.mark.parametrize("collision", COLLISIONS, ids=COLLISION_IDS)
def test_hyster_hertz_two_bodies_rebound_at_its_effective_restitution(
    collision: tuple[Any, ...], e: float
) -> None:
    big_m, m, k_hz, v, moving = collision
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", vi.RestitutionWarning)
        contact = vi.Contact("hyster-hertz", stiffness=k_hz, restitution=e)
    sol = two_body_run(contact, big_m, m, k_hz, v, moving, method="dop853", rtol=1e-10)
    c = one_contact(sol, v)
    assert c.restitution[0] == pytest.approx(rebound_of(0.75 * (1 - e**2)), rel=1e-8)
    assert c.restitution[0] == pytest.approx(contact.effective_restitution, rel=1e-8)


# ------------------------------------------------------- energy and the table


@pytest.mark.parametrize("e", [0.05, 0.3, 0.7, 0.9, 1.0])
@pytest.mark.parametrize("damping", [0.0, 0.2])
@pytest.mark.parametrize(
    ("settings", "tolerance"),
    [({"method": "rk4", "dt": 1e-3, "stepping": "events"}, 1e-7), ({"method": "dop853"}, 1e-6)],
    ids=["rk4", "dop853"],
)
def test_energy_dissipated_is_the_kinetic_energy_lost(
    settings: dict[str, Any], tolerance: float, damping: float, e: float
) -> None:
    big_m, m, k_hz, v = 1.0, 0.25, 3000.0, 0.1
    contact = vi.Contact("hertz-damped", stiffness=k_hz, damping=damping, restitution=e)
    sol = two_body_run(contact, big_m, m, k_hz, v, "impact", **settings)
    c = one_contact(sol, v)
    m_eff = big_m * m / (big_m + m)
    lost = 0.5 * m_eff * (c.approach_speed[0] ** 2 - c.rebound_speed[0] ** 2)
    kinetic = 0.5 * big_m * sol.main_velocity**2 + 0.5 * m * sol.impact_velocity**2
    initial = 0.5 * m_eff * v**2
    if e == 1.0 and damping == 0.0:
        assert abs(c.energy_dissipated[0]) < 1e-12 * initial
        assert c.restitution[0] == pytest.approx(1.0, rel=1e-7)
        return
    assert c.energy_dissipated[0] == pytest.approx(lost, rel=tolerance)
    assert c.energy_dissipated[0] == pytest.approx(kinetic[0] - kinetic[-1], rel=tolerance)
    if damping == 0.0:
        # Only the law acts: the lost fraction is 1 - e^2.
        assert c.energy_dissipated[0] == pytest.approx(initial * (1 - e**2), rel=tolerance)
    else:
        # The contact damper takes more on top of the law.
        assert c.restitution[0] < e


def test_restitution_column_is_rebound_over_approach() -> None:
    """A rattling run on the Table 1 masses with several contacts, the last still open."""
    system = vi.ImpactDamper(
        main_mass=1.0, stiffness=40.0, damping=0.01, impact_mass=0.25, clearance=0.01
    )
    contact = vi.Contact("hertz-damped", stiffness=3000.0, damping=0.01, restitution=0.6)
    start = vi.InitialState(main_displacement=0.05, impact_displacement=0.05)
    sol = vi.simulate(system, contact, start, method="dop853", t_end=3.0)
    c = sol.contacts
    assert len(c) >= 5
    assert "restitution" in vi.ContactTable.columns
    closed = np.isfinite(c.separation)
    np.testing.assert_allclose(
        c.restitution[closed], c.rebound_speed[closed] / c.approach_speed[closed], rtol=1e-15
    )
    assert np.all(np.isnan(c.restitution[~closed]) == np.isnan(c.rebound_speed[~closed]))
    rows = c.to_dicts()
    assert [r["restitution"] for r in rows[: closed.sum()]] == list(c.restitution[closed])
    # The bodies do separate (with the main spring moving, the ratio is not e).
    assert np.all(c.restitution[closed] > 0)


# ------------------------------------------------------------ value semantics


def test_hertz_damped_contact_keeps_its_restitution() -> None:
    contact = vi.Contact("hertz-damped", stiffness=3000.0, damping=0.01, restitution=0.7)
    assert contact.restitution == 0.7
    assert "restitution=0.7" in repr(contact)
    assert pickle.loads(pickle.dumps(contact)) == contact
    assert eval(repr(contact), {"Contact": vi.Contact}) == contact
    assert contact != vi.Contact("hertz-damped", stiffness=3000.0, damping=0.01, restitution=0.71)


@pytest.mark.parametrize("stepping", ["fixed", "events"])
def test_a_contact_open_at_rest_has_no_restitution(stepping: str) -> None:
    """Starting at the wall (to round-off) with the bodies at rest, the first contact had no
    approach: its restitution is undefined (NaN), not a division by zero. (A start indented
    further is refused: tests/test_run_limits.py.)"""
    system = vi.ImpactDamper(main_mass=1.0, stiffness=0.0, impact_mass=0.25, clearance=0.01)
    contact = vi.Contact("hertz", stiffness=3000.0)
    start = vi.InitialState(impact_displacement=math.nextafter(0.01, 1.0))  # at rest, 1 ulp in
    sol = vi.simulate(system, contact, start, method="rk4", dt=1e-4, t_end=0.2, stepping=stepping)
    assert sol.contacts.approach_speed[0] == 0.0
    assert math.isnan(sol.contacts.restitution[0])


def _stop_rebound(mass: float, spring: float, gap: float, law: tuple[float, float], speed: float):
    """A mass on a spring striking a ``linear`` stop (stiffness, contact damper) at
    ``gap`` with ``speed``: the contact's duration and rebound speed in closed form.
    In contact ``m x'' = -K x - k (x - gap) - c x'``, a damped oscillation about
    ``k gap / (K + k)``; it separates where ``x`` is back at ``gap`` (Newton from
    half a damped period)."""
    stiffness, damping = law
    omega = math.sqrt((spring + stiffness) / mass)
    zeta = damping / (2.0 * mass * omega)
    damped = omega * math.sqrt(1.0 - zeta * zeta)
    u0 = spring * gap / (spring + stiffness)
    a, b = u0, (speed + zeta * omega * u0) / damped

    def u_and_rate(t: float) -> tuple[float, float]:
        decay, c, s = math.exp(-zeta * omega * t), math.cos(damped * t), math.sin(damped * t)
        u = decay * (a * c + b * s)
        rate = decay * ((-a * damped + b * -zeta * omega) * s + (b * damped - zeta * omega * a) * c)
        return u, rate

    t = math.pi / damped
    for _ in range(50):
        u, rate = u_and_rate(t)
        t -= (u - u0) / rate
    return t, -u_and_rate(t)[1]


@pytest.mark.parametrize("damping", [20.0, 100.0])
def test_dop853_rebound_off_a_damped_linear_stop_is_within_rtol(damping: float) -> None:
    """The step located onto the separation takes its last stages about the wall; the
    linear law held on its straight line there (not clamped at zero past the wall) keeps
    dop853's order: the rebound within rtol at every rtol. It had been off by 9 to 30
    times rtol at some of them (1e-7 and 1e-8 with c = 20, 3e-9 and 1e-9 with c = 100)."""
    mass, spring, gap, stiffness, speed = 1.0, 100.0, 0.01, 1e5, 1.0
    duration, rebound = _stop_rebound(mass, spring, gap, (stiffness, damping), speed)
    system = vi.System(
        structure=vi.Oscillator(mass=mass, stiffness=spring, damping=0.0),
        stops=[
            vi.Stop(at=0, side="upper", gap=gap, law="linear", stiffness=stiffness, damping=damping)
        ],
        initial=vi.Initial(structure_displacement=[gap], structure_velocity=[speed]),
    )
    errors = {}
    for rtol in np.logspace(-6, -12, 13):
        sol = vi.simulate(system, method="dop853", t_end=0.02, rtol=rtol, atol=1e-16)
        contact = sol.contacts.to_pandas().iloc[0]
        assert contact["separation"] == pytest.approx(duration, abs=100 * rtol * duration)
        errors[rtol] = abs(contact["rebound_speed"] - rebound) / rebound / rtol
    assert max(errors.values()) < 1.0, errors
