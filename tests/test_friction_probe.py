"""A friction and collision probe's findings (a new user's trial): a damper held at no
clearance between rigid walls keeps its friction and runs, a friction stick's row has
no restitution (it never arrived), a study axis on a key the pair's law lacks is
refused before any run, a damper at rest on a carrier that slides on the ground from
the start is judged with that sliding force, and the text table reads a closed row's
undefined value as undefined, not open. Independent values: the same system without
friction (a damper held by its walls never slides, so friction does no work), the
closed form of a block sliding to rest, and scipy's integration of the carrier and
damper moving as one body."""

from __future__ import annotations

import math
import subprocess
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import vibroimpact as vi
from friction_reference import HorizontalDamper
from friction_reference import simulate as stick_slip_reference
from vibroimpact import study as st


def _held(restitution: float, **friction: float) -> vi.System:
    """A damper at no clearance between rigid walls, on a forced oscillator."""
    damper = vi.Damper(
        mass=0.15, at=0, clearance=0.0, law="rigid", restitution=restitution, **friction
    )
    return vi.System(
        structure=vi.Oscillator(mass=1.0, stiffness=4000.0, damping=0.0),
        dampers=[damper],
        excitations=[vi.Force(at=0, signal=vi.Harmonic(amplitude=5.0, frequency=6.0))],
    )


@pytest.mark.timeout(60)
@pytest.mark.parametrize("method", ["exact", "dop853", "rk4"])
@pytest.mark.parametrize("restitution", [0.0, 0.5, 1.0])
def test_a_damper_held_at_no_clearance_with_friction_runs_as_without(
    method: str, restitution: float
) -> None:
    # It stopped as "chattering at t = 2.5e-3 s": its friction was a second constraint
    # on the row its two walls hold.
    settings: dict[str, float | str] = {"method": method, "t_end": 0.5}
    if method == "rk4":
        settings["dt"] = 1e-4
    plain = vi.simulate(_held(restitution), **settings)  # type: ignore[arg-type]
    rubbing = _held(restitution, friction=0.4, static_friction=0.7, normal_force=2.8)
    ran = vi.simulate(rubbing, **settings)  # type: ignore[arg-type]
    for name in ("structure_displacement", "damper_displacement"):
        np.testing.assert_allclose(
            ran.final_state[name], plain.final_state[name], rtol=1e-9, atol=1e-12
        )
    assert ran.energy["friction"] == 0.0
    assert abs(ran.energy["residual"]) <= 1e-6 * abs(ran.energy["input_work"]) + 1e-12
    assert "damper 0 friction" in ran.pairs


@pytest.mark.timeout(60)
def test_a_friction_sticks_row_has_no_restitution() -> None:
    # A block thrown at 1 m/s on its carrier slides v^2 / (2 mu g) and sticks: that
    # row's approach is 0, and its restitution read 0.0 where the table's rule (a contact
    # that started at rest was never an impact) says NaN.
    mu, g, v = 0.3, 9.81, 1.0
    system = vi.System(
        structure=vi.Oscillator(mass=1e10, stiffness=1e10, damping=0.0),
        dampers=[
            vi.Damper(
                mass=1.0,
                at=0,
                lower_clearance=math.inf,
                upper_clearance=math.inf,
                law="rigid",
                restitution=0.5,
                friction=mu,
                normal_force=g,
            )
        ],
        initial=vi.Initial(damper_velocity=[v]),
    )
    run = vi.simulate(system, method="exact", t_end=1.0)
    assert math.isclose(
        run.final_state["damper_displacement"][0], v**2 / (2 * mu * g), rel_tol=1e-6
    )
    sticks = [i for i, kind in enumerate(run.contacts.kind) if kind == "sticking"]
    assert sticks, run.contacts
    for i in sticks:
        assert run.contacts.approach_speed[i] == 0.0
        assert math.isnan(run.contacts.restitution[i])


@pytest.mark.timeout(60)
@pytest.mark.parametrize(
    ("law", "axis", "takes"),
    [
        ({"law": "rigid", "restitution": 0.3}, "collision.0.stiffness", "takes restitution"),
        ({"law": "hertz", "stiffness": 1e8}, "collision.0.restitution", "stiffness and damping"),
    ],
)
def test_a_study_axis_the_pairs_law_lacks_is_refused_before_any_run(
    law: dict[str, object], axis: str, takes: str
) -> None:
    # Every run failed alone ("the pair's law has no stiffness"): a bad axis, refused
    # as a misspelt one is.
    system = vi.System(
        structure=vi.Oscillator(mass=1.0, stiffness=4000.0, damping=1.0),
        dampers=[
            vi.Damper(
                mass=0.05,
                at=0,
                lower_clearance=0.01,
                upper_clearance=math.inf,
                law="rigid",
                restitution=0.5,
            ),
            vi.Damper(
                mass=0.05,
                at=0,
                lower_clearance=math.inf,
                upper_clearance=0.01,
                law="rigid",
                restitution=0.5,
            ),
        ],
        collisions=[vi.Collision(dampers=[0, 1], gap=0.001, **law)],  # type: ignore[arg-type]
        excitations=[vi.Force(at=0, signal=vi.Harmonic(amplitude=5.0, frequency=6.0))],
        solver=vi.Solver(method="dop853", t_end=0.1),
        analyses={"study": {"analysis": "run", "axes": {axis: [0.5, 1e6]}}},
    )
    with pytest.raises(
        ValueError, match=rf"study axis .{axis}.: the pair's law has no \w+ \(.*{takes}\)"
    ):
        st.study_of(system)


@pytest.mark.timeout(60)
@pytest.mark.parametrize("method", ["exact", "dop853"])
def test_a_damper_at_rest_on_a_carrier_sliding_from_the_start_sticks_as_one_body(
    method: str,
) -> None:
    # At t = 0 each element at rest was judged in the rows' order: the damper's holding
    # force without the ground's sliding force (m A / (M + m) = 0.923 N > 0.9 N), so it
    # slid at once. With the ground sliding, one body of M + m needs only
    # m (A - Fg) / (M + m) = 0.808 N: it sticks until that force passes 0.9 N.
    big, small, stiffness, damping, amplitude = 1.0, 0.3, 400.0, 0.5, 4.0
    kinetic, static, ground = 0.6, 0.9, 0.5
    system = vi.System(
        structure=vi.Oscillator(mass=big, stiffness=stiffness, damping=damping),
        dampers=[
            vi.Damper(
                mass=small,
                at=0,
                lower_clearance=math.inf,
                upper_clearance=math.inf,
                law="rigid",
                restitution=0.5,
                friction=kinetic,
                static_friction=static,
                normal_force=1.0,
            )
        ],
        frictions=[vi.Friction(at=0, coefficient=ground, static_coefficient=0.8, normal_force=1.0)],
        excitations=[vi.Force(at=0, signal=vi.Harmonic(amplitude=amplitude, frequency=1.0))],
    )

    # The reference: one body of M + m sliding on the ground (v > 0 from the start),
    # until the damper's share of its acceleration needs more than the static force.
    def acceleration(t: float, y: np.ndarray) -> float:
        force = amplitude * math.cos(2 * math.pi * t) - ground - stiffness * y[0]
        return float((force - damping * y[1]) / (big + small))

    def rates(t: float, y: np.ndarray) -> list[float]:
        return [y[1], acceleration(t, y)]

    def slips(t: float, y: np.ndarray) -> float:
        return small * abs(acceleration(t, y)) - static

    def stops(t: float, y: np.ndarray) -> float:
        return float(y[1]) if t > 0 else 1.0

    slips.terminal = True  # type: ignore[attr-defined]
    stops.terminal = True  # type: ignore[attr-defined]
    reference = solve_ivp(rates, (0, 1), [0.0, 0.0], events=[slips, stops], rtol=1e-12, atol=1e-14)
    assert reference.t_events[0].size == 1, "the damper slips before the body stops"
    slip = float(reference.t_events[0][0])
    run = vi.simulate(system, method=method, t_end=slip + 0.01)
    rows = [
        i
        for i, (pair, kind) in enumerate(zip(run.contacts.pair, run.contacts.kind, strict=True))
        if pair == "damper 0 friction" and kind == "sticking"
    ]
    assert rows, run.contacts
    assert run.contacts.onset[rows[0]] == 0.0
    assert math.isclose(run.contacts.separation[rows[0]], slip, rel_tol=1e-6)


@pytest.mark.timeout(60)
def test_the_text_table_reads_a_closed_rows_undefined_value_as_undefined(
    run_cli: Callable[..., subprocess.CompletedProcess[str]],
) -> None:
    # A closed sticking interval's restitution (NaN: it never arrived) read "open",
    # which the help keeps for a contact still open at the end of the run.
    example = Path(__file__).resolve().parents[1] / "examples" / "horizontal_friction_damper.toml"
    result = run_cli("simulate", str(example))
    assert result.returncode == 0, result.stderr
    rows = [line.split() for line in result.stdout.splitlines() if "sticking" in line]
    assert rows, result.stdout
    for row in rows:
        # pair (three words), kind, onset, duration, approach, restitution, dissipated
        duration, restitution = row[5], row[7]
        if duration != "open":
            assert restitution == "-", row


def _brief_stick_on_a_carrier() -> tuple[vi.System, float, float]:
    """A 10 g mass sliding at about 1 m/s on a free 1 kg, 50 Hz carrier moving at 1 m/s
    (kinetic friction 1 mN, static 0.1 N): near t = 0.02 s their relative speed dips
    through zero by about 1e-5 m/s where the force holding the mass together with the
    carrier (some 4 mN) is far within static friction. The system, the mass's starting
    speed and the run's length."""
    stiffness = (2 * math.pi * 50.0) ** 2
    start = 1.002 - 1e-5
    system = vi.System(
        structure=vi.Oscillator(mass=1.0, stiffness=stiffness, damping=0.0),
        dampers=[
            vi.Damper(
                mass=0.01,
                at=0,
                clearance=10.0,
                law="rigid",
                restitution=0.5,
                friction=0.001,
                static_friction=0.1,
                normal_force=1.0,
            )
        ],
        initial=vi.Initial(structure_velocity=[1.0], damper_velocity=[start]),
    )
    return system, start, 0.03


@pytest.mark.timeout(60)
@pytest.mark.parametrize("method", ["exact", "dop853", "dopri5"])
def test_a_stop_inside_one_step_begins_the_stick_it_must(method: str) -> None:
    # The dip and the stick it begins (0.12 ms) lie inside one of dop853's steps at its
    # tolerances, and the ends of the step show a speed of one sign: dop853 passed over
    # it at rtol 1e-10 as at its defaults (no stick, the mass 4.9e-4 m/s too fast at the
    # end). Reference: the scipy stick-slip integration of the same equations, which
    # steps at most 2e-5 s.
    system, start, t_end = _brief_stick_on_a_carrier()
    p = HorizontalDamper(
        K=(2 * math.pi * 50.0) ** 2,
        C=0.0,
        m=0.01,
        clearance=10.0,
        restitution=0.5,
        mu=0.001,
        mu_static=0.1,
        normal=1.0,
        P=0.0,
    )
    reference, events = stick_slip_reference(
        p, t_end, rtol=1e-12, atol=1e-15, y0=(0.0, 0.0, 1.0, start), max_step=2e-5
    )
    assert events == 2  # the stick and the slip
    sol = vi.simulate(system, method=method, t_end=t_end, history=False)
    table = sol.contacts.to_pandas()
    sticks = table[table["kind"] == "sticking"]
    assert len(sticks) == 1
    assert 0.0199 < sticks["onset"].iloc[0] < sticks["separation"].iloc[0] < 0.0202
    state = sol.final_state
    assert state["damper_velocity"][0] == pytest.approx(reference[3], abs=1e-7)
    assert state["structure_velocity"][0] == pytest.approx(reference[2], abs=1e-7)


def _stack(normal_force: float, force: float = 0.0) -> vi.System:
    """A 0.1 kg block held on a vertical wall by friction (kinetic 0.4, static 0.5 of
    ``normal_force``), a 0.2 kg ball resting on its floor at t = 0, under gravity;
    ``force`` (N) a push down on the block from 0, rising as sin."""
    forcing = [
        vi.Force(at=0, signal=vi.Harmonic(amplitude=force, frequency=1.0, phase=math.pi / 2))
    ]
    return vi.System(
        structure=vi.Oscillator(mass=0.1, stiffness=0.0, damping=0.0),
        dampers=[
            vi.Damper(
                mass=0.2,
                at=0,
                lower_clearance=0.0,
                upper_clearance=0.05,
                law="rigid",
                restitution=0.5,
            )
        ],
        frictions=[
            vi.Friction(at=0, coefficient=0.4, static_coefficient=0.5, normal_force=normal_force)
        ],
        gravity=vi.Gravity(acceleration=9.81),
        excitations=forcing if force else [],
    )


@pytest.mark.timeout(60)
@pytest.mark.parametrize("method", ["exact", "dop853", "rk4"])
def test_a_stack_that_static_friction_holds_at_the_start_stays(method: str) -> None:
    # The ball resting on the held block at t = 0 had fallen for the first step's
    # round-off; its landing (1.4e-10 m/s) set the block sliding, and kinetic friction
    # (2.8 N) could not stop the stack's weight (2.943 N): it slid 0.238 m in 1 s,
    # where static friction (3.5 N) holds it still (a physicist's probe).
    settings: dict[str, Any] = {"method": method, "t_end": 1.0}
    if method == "rk4":
        settings["dt"] = 1e-4
    held = vi.simulate(_stack(7.0), **settings)
    assert np.max(np.abs(held.structure_displacement)) == 0.0
    assert held.energy["friction"] == 0.0
    resting = held.contacts.to_pandas()
    assert (resting["approach_speed"] == 0.0).all()
    # Pushed down by a force that the static force still holds (2.943 + 0.5 < 3.5 N):
    # held from the start, as a scipy run with the block stuck from t = 0 has it.
    pushed = vi.simulate(_stack(7.0, force=0.5), **settings)
    assert np.max(np.abs(pushed.structure_displacement)) < 1e-12  # the constraint's drift
    # Where the static force (0.5 * 5.5 = 2.75 N) cannot hold the weight (2.943 N), the
    # stack slides from t = 0 as one body, at g less the kinetic force's 0.4 * 5.5 N.
    slid = vi.simulate(_stack(5.5), **settings)
    acceleration = 9.81 - 0.4 * 5.5 / 0.3
    expected = -0.5 * acceleration * 1.0**2
    assert slid.final_state["structure_displacement"][0] == pytest.approx(expected, rel=1e-6)
    assert slid.final_state["damper_displacement"][0] == pytest.approx(expected, rel=1e-6)
