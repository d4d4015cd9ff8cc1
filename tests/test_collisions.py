"""Loose masses that collide with each other (issue 27): ``[[collision]]`` pairs between
dampers, checked against closed forms (Newton's restitution with momentum kept, the
simultaneous impact of a row of touching masses) and scipy's integration of the same
equations of motion (a Hertz chain, a compliant particle column in a forced cavity)."""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import vibroimpact as vi
import vibroimpact.analysis as an
from system_checks import cli

ROOT = Path(__file__).resolve().parents[1]
COLUMN = ROOT / "examples" / "particle_column.toml"
FREE = {"lower_clearance": math.inf, "upper_clearance": math.inf}


def forced_column(count: int, law: dict[str, Any], masses: list[float] | None = None) -> vi.System:
    """``count`` 10 g particles (or of ``masses``, kg) stacked 2 mm apart in the cavity
    of examples/particle_column.toml (a 1 kg, 15 Hz, 5 % damped structure forced with
    30 N at 10 Hz, under gravity): the lowest 2 mm above the floor, the highest 30 mm
    below the ceiling, each pair of neighbours a ``[[collision]]``, all of ``law``
    (also the column of benchmarks/bench_collisions.py)."""
    return vi.System(
        structure=vi.Oscillator(mass=1.0, stiffness=8883.0, damping=9.42),
        dampers=[
            vi.Damper(
                mass=0.01 if masses is None else masses[j],
                at=0,
                lower_clearance=0.002 if j == 0 else math.inf,
                upper_clearance=0.03 if j == count - 1 else math.inf,
                **law,
            )
            for j in range(count)
        ],
        collisions=[vi.Collision(dampers=(j, j + 1), gap=0.002, **law) for j in range(count - 1)],
        gravity=vi.Gravity(acceleration=9.81),
        excitations=[vi.Force(at=0, signal=vi.Harmonic(amplitude=30.0, frequency=10.0))],
    )


def _masses(masses: list[float], law: dict[str, Any], gaps: list[float], v0: float) -> vi.System:
    """Loose masses in a row on a still carrier (no wall within reach: the first has a
    floor 1 m below, the last a ceiling 1 m above), each striking the next across
    ``gaps``; the first thrown at the others at ``v0`` m/s."""
    last = len(masses) - 1
    dampers = [
        vi.Damper(
            mass=m,
            at=0,
            lower_clearance=1.0 if j == 0 else math.inf,
            upper_clearance=1.0 if j == last else math.inf,
            **law,
        )
        for j, m in enumerate(masses)
    ]
    collisions = [vi.Collision(dampers=(j, j + 1), gap=g, **law) for j, g in enumerate(gaps)]
    return vi.System(
        structure=vi.Oscillator(mass=1.0, stiffness=100.0, damping=0.0),
        dampers=dampers,
        collisions=collisions,
        initial=vi.Initial(damper_velocity=[v0] + [0.0] * last),
    )


@pytest.mark.parametrize("method", ["exact", "dop853", "rk4"])
@pytest.mark.timeout(30)
def test_two_loose_masses_collide_by_newton_s_restitution_keeping_momentum(method: str) -> None:
    m1, m2, e, gap = 0.1, 0.3, 0.7, 0.01
    system = _masses([m1, m2], {"law": "rigid", "restitution": e}, [gap], 1.0)
    system = system.replace(initial=vi.Initial(damper_velocity=[1.0, -0.5]))
    step = {"dt": 1e-4} if method == "rk4" else {}
    sol = vi.simulate(system, method=method, t_end=0.05, **step)
    (contact,) = sol.contacts.to_pandas().itertuples()
    closing = 1.5
    assert contact.pair == "collision 0"
    assert contact.onset == pytest.approx(gap / closing, rel=1e-12)
    assert contact.approach_speed == pytest.approx(closing, rel=1e-12)
    assert contact.rebound_speed == pytest.approx(e * closing, rel=1e-12)
    reduced = m1 * m2 / (m1 + m2)
    lost = 0.5 * reduced * (1 - e * e) * closing**2
    assert contact.energy_dissipated == pytest.approx(lost, rel=1e-12)
    assert sol.energy["impact"] == pytest.approx(lost, rel=1e-12)
    # Momentum kept, the relative speed reversed times e.
    v1, v2 = sol.final_state["damper_velocity"]
    assert m1 * v1 + m2 * v2 == pytest.approx(m1 * 1.0 + m2 * -0.5, abs=1e-14)
    assert v2 - v1 == pytest.approx(e * closing, rel=1e-12)


@pytest.mark.timeout(30)
def test_a_rigid_row_struck_at_once_is_not_a_newton_s_cradle() -> None:
    # Three equal masses, the last two touching, the first arriving at v with e = 1.
    # Both contacts close at once: the simultaneous impact (one complementarity
    # problem) leaves the touching pair touching, so the two move as one. Momentum and
    # energy then give the first -v/3 and the pair 2v/3 each; a Newton's cradle (the
    # first stops, the last leaves at v) needs the impacts one after the other.
    for method in ("exact", "dop853"):
        sol = vi.simulate(
            _masses([0.1] * 3, {"law": "rigid", "restitution": 1.0}, [0.01, 0.0], 1.0),
            method=method,
            t_end=0.05,
        )
        assert sol.final_state["damper_velocity"] == pytest.approx(
            [-1 / 3, 2 / 3, 2 / 3], abs=1e-14
        )
        assert abs(sol.energy["residual"]) < 1e-15


def _squeeze_oracle(
    masses: tuple[float, float, float], gaps: tuple[float, float], v: float, e: float
) -> tuple[float, np.ndarray, int]:
    """A free floor (its body of ``masses[0]``), a particle ``gaps[0]`` above it and a
    third body ``gaps[1]`` above that arriving at ``v``, all at rest otherwise and free of
    forces: each impact in turn, Newton's at ``e``, until the sequence ends or 20,000
    impacts (an inelastic collapse then: every flight shorter than round-off). The
    impacts' time, the velocities and how many there were."""
    m = np.asarray(masses)
    x, u = np.array([0.0, gaps[0], gaps[0] + gaps[1]]), np.array([0.0, 0.0, v])
    t = 0.0
    for k in range(20_000):
        rates = np.diff(u)
        times = [np.diff(x)[p] / -rates[p] if rates[p] < 0 else np.inf for p in (0, 1)]
        p = int(np.argmin(times))
        if not np.isfinite(times[p]):
            return t, u, k
        x, t = x + u * times[p], t + times[p]
        impulse = -(1 + e) * (u[p + 1] - u[p]) / (1 / m[p] + 1 / m[p + 1])
        u[p] -= impulse / m[p]
        u[p + 1] += impulse / m[p + 1]
    return t, u, 20_000


@pytest.mark.parametrize("method", ["exact", "dop853"])
@pytest.mark.parametrize("restitution", [0.3, 0.6, 0.9])
@pytest.mark.timeout(30)
def test_a_particle_squeezed_between_its_floor_and_a_heavier_one_collapses_as_one(
    method: str, restitution: float
) -> None:
    # A 1 g particle between a free 1 kg floor and a 100 g body arriving at 1 m/s, no
    # other force: it strikes each in turn ever faster. At e = 0.3 and 0.6 the impacts
    # close in on one instant (the oracle's velocities agree to round-off after 20,000),
    # where all three move as one: momentum gives each -0.1 / 1.101 m/s. That run had
    # stopped as chattering (a sequence no one pair's flights sum). At e = 0.9 the
    # sequence ends after 34 impacts, the bodies apart: no collapse may be made of it.
    masses, gaps = (1.0, 1e-3, 0.1), (1e-3, 1e-3)
    when, velocities, impacts = _squeeze_oracle(masses, gaps, -1.0, restitution)
    system = vi.System(
        structure=vi.Oscillator(mass=masses[0], stiffness=0.0),
        dampers=[
            vi.Damper(
                mass=masses[1],
                at=0,
                lower_clearance=gaps[0],
                upper_clearance=math.inf,
                law="rigid",
                restitution=restitution,
            ),
            vi.Damper(
                mass=masses[2],
                at=0,
                lower_clearance=math.inf,
                upper_clearance=1.0,
                law="rigid",
                restitution=restitution,
            ),
        ],
        collisions=[
            vi.Collision(dampers=(0, 1), gap=gaps[1], law="rigid", restitution=restitution)
        ],
        initial=vi.Initial(damper_velocity=[0.0, -1.0]),
    )
    sol = vi.simulate(system, method=method, t_end=0.01)
    final = sol.final_state
    end = [final["structure_velocity"][0], *final["damper_velocity"]]
    assert end == pytest.approx(velocities, rel=1e-9, abs=1e-12)
    if impacts < 20_000:
        assert impacts == 34 and len(sol.contacts) == impacts
        assert set(sol.contacts.kind) == {"impact"}
    else:
        assert end == pytest.approx([-0.1 / 1.101] * 3, rel=1e-12)
        # The collapse is made at the last impact its sequence is followed to: before
        # the oracle's instant of collapse, by less than a millionth of the run's time.
        assert 0.0 <= when - max(sol.contacts.onset) < 1e-6 * when
    assert abs(sol.energy["residual"]) < 1e-12


def _stack_on_a_forced_floor(masses: list[float], ceiling: float) -> vi.System:
    """Rigid particles (e = 0.3) stacked touching on the floor of the forced cavity of
    :func:`forced_column`, 2 mm apart at rest, under gravity, the top one ``ceiling`` (m)
    below the ceiling."""
    law = {"law": "rigid", "restitution": 0.3}
    last = len(masses) - 1
    return vi.System(
        structure=vi.Oscillator(mass=1.0, stiffness=8883.0, damping=9.42),
        dampers=[
            vi.Damper(
                mass=m,
                at=0,
                lower_clearance=0.002 if j == 0 else math.inf,
                upper_clearance=ceiling if j == last else math.inf,
                **law,
            )
            for j, m in enumerate(masses)
        ],
        collisions=[vi.Collision(dampers=(j, j + 1), gap=0.002, **law) for j in range(last)],
        gravity=vi.Gravity(acceleration=9.81),
        excitations=[vi.Force(at=0, signal=vi.Harmonic(amplitude=30.0, frequency=10.0))],
        initial=vi.Initial(damper_displacement=[-0.002 - 0.002 * j for j in range(len(masses))]),
    )


@pytest.mark.parametrize("method", ["exact", "dop853"])
@pytest.mark.timeout(30)
def test_a_stack_lifts_off_its_floor_as_the_one_body_it_is(method: str) -> None:
    # A 1 g particle between two 50 g ones, all resting on a forced floor: at lift-off
    # every pair's force reaches zero at once, and releasing each pair alone closed the
    # light one's other gap, events 1e-17 s apart until the run stopped as chattering.
    # Together they fly as one body: the floor's release and its next impact come when
    # they do for one particle of the stack's mass (no collision in it at all).
    stack = _stack_on_a_forced_floor([0.05, 0.001, 0.05], ceiling=0.03)
    block = _stack_on_a_forced_floor([0.101], ceiling=0.034)  # the same ceiling
    stack_run = vi.simulate(stack, method=method, t_end=0.1)
    block_run = vi.simulate(block, method=method, t_end=0.1)

    def floor(sol: Any) -> list[tuple[str, float, float]]:
        rows = sol.contacts.to_dicts()
        return [(r["kind"], r["onset"], r["separation"]) for r in rows if r["pair"] == "damper 0"]

    ours, one = floor(stack_run)[:2], floor(block_run)[:2]
    assert len(ours) == len(one) == 2 and [k for k, *_ in ours] == [k for k, *_ in one]
    for (_, onset, separation), (_, onset_one, separation_one) in zip(ours, one, strict=True):
        assert onset == pytest.approx(onset_one, rel=1e-9, abs=1e-12)
        assert separation == pytest.approx(separation_one, rel=1e-9, abs=1e-12)


def _hertz_chain(masses: list[float], stiffness: float, gaps: list[float], v0: float) -> Any:
    """scipy's integration of the masses' Hertz contacts (a test-only oracle): each
    pair pushes apart with ``stiffness * overlap^1.5`` while they overlap."""
    k = len(masses)

    def rates(t: float, y: np.ndarray) -> np.ndarray:
        x, v = y[:k], y[k:]
        force = np.zeros(k)
        for j, g in enumerate(gaps):
            overlap = x[j] - x[j + 1] - g
            if overlap > 0:
                push = stiffness * overlap**1.5
                force[j] -= push
                force[j + 1] += push
        return np.concatenate([v, force / np.array(masses)])

    y0 = np.zeros(2 * k)
    y0[k] = v0
    return solve_ivp(rates, (0, 0.05), y0, method="DOP853", rtol=1e-12, atol=1e-15, max_step=1e-6)


@pytest.mark.timeout(60)
def test_a_hertz_row_carries_the_wave_as_scipy_integrates_it() -> None:
    # The compliant answer for the same row: the contacts act one after the other as
    # the wave runs along it, nearly a cradle (about -0.07, 0.08, 0.99 of v for three
    # equal Hertz masses), and no energy is lost.
    masses, stiffness = [0.1, 0.1, 0.1], 1e9
    system = _masses(masses, {"law": "hertz", "stiffness": stiffness}, [0.01, 0.0], 1.0)
    sol = vi.simulate(system, method="dop853", t_end=0.05, rtol=1e-11, atol=1e-14)
    reference = _hertz_chain(masses, stiffness, [0.01, 0.0], 1.0)
    velocities = sol.final_state["damper_velocity"]
    assert velocities == pytest.approx(reference.y[3:, -1], abs=1e-8)
    assert velocities[2] > 0.99 and -0.08 < velocities[0] < -0.06
    assert sol.energy["stored_end"] == pytest.approx(sol.energy["stored_start"], rel=1e-10)
    assert list(sol.contacts.pair) == ["collision 0", "collision 1"]


def _column_oracle(data: dict[str, Any], t_end: float) -> np.ndarray:
    """scipy's integration of a Hertz column (no contact damping) in its forced cavity:
    the cavity's oscillator, gravity on every mass, each particle's floor and ceiling
    where it has one, each neighbour's contact."""
    s, force = data["structure"], data["excitation"][0]
    dampers, collisions = data["damper"], data["collision"]
    k = len(dampers)
    masses = np.array([d["mass"] for d in dampers])
    w, g = 2 * math.pi * force["frequency"], data["gravity"]["acceleration"]

    def hertz(overlap: float, stiffness: float) -> float:
        return stiffness * overlap**1.5 if overlap > 0 else 0.0

    def rates(t: float, y: np.ndarray) -> np.ndarray:
        x, z, vx, vz = y[0], y[1 : k + 1], y[k + 1], y[k + 2 :]
        on_cavity = force["amplitude"] * math.cos(w * t) - s["stiffness"] * x
        on_cavity -= s["damping"] * vx + s["mass"] * g
        on = -masses * g
        for j, d in enumerate(dampers):
            relative = z[j] - x
            below = hertz(-d["lower_clearance"] - relative, d["stiffness"])
            above = hertz(relative - d["upper_clearance"], d["stiffness"])
            on[j] += below - above
            on_cavity += above - below
        for c in collisions:
            i, j = c["dampers"]
            push = hertz(z[i] - z[j] - c["gap"], c["stiffness"])
            on[i] -= push
            on[j] += push
        return np.concatenate([[vx], vz, [on_cavity / s["mass"]], on / masses])

    # Radau at tight tolerance: DOP853 with these tolerances wanders by 4e-9 m/s as its
    # step cap changes, over the column's contacts.
    sol = solve_ivp(
        rates, (0, t_end), np.zeros(2 * k + 2), method="Radau", rtol=1e-10, atol=1e-13,
        max_step=2e-5,
    )  # fmt: skip
    return np.asarray(sol.y[:, -1])


@pytest.mark.timeout(120)
def test_a_hertz_column_in_a_forced_cavity_follows_scipy() -> None:
    data = vi.load(COLUMN).to_dict()
    for table in data["damper"] + data["collision"]:
        table.update(law="hertz", damping=0.0)
        table.pop("restitution", None)
    # 50 ms: the floor's contact and each collision's; later, the column's contacts
    # amplify any difference as a chaotic motion does.
    t_end = 0.05
    data["solver"] = {"method": "dop853", "t_end": t_end, "rtol": 1e-11, "atol": 1e-14}
    sol = vi.simulate(vi.System.from_dict(data))
    assert {"damper 0", "collision 0", "collision 1", "collision 2", "collision 3"} <= set(
        sol.contacts.pair
    )
    ours = np.concatenate(
        [
            sol.final_state["structure_displacement"],
            sol.final_state["damper_displacement"],
            sol.final_state["structure_velocity"],
            sol.final_state["damper_velocity"],
        ]
    )
    theirs = _column_oracle(data, t_end)
    k = len(data["damper"])
    assert np.max(np.abs(ours[: k + 1] - theirs[: k + 1])) < 1e-10
    assert np.max(np.abs(ours[k + 1 :] - theirs[k + 1 :])) < 1e-8


@pytest.mark.timeout(60)
def test_the_particle_column_example_runs_from_the_cli_with_its_ledger_closed(
    tmp_path: Path,
) -> None:
    done = cli("simulate", str(COLUMN), "--json")
    assert done.returncode == 0, done.stderr
    out = json.loads(done.stdout)
    pairs = {c["pair"] for c in out["contacts"]}
    assert {f"collision {j}" for j in range(4)} <= pairs and "damper 0" in pairs
    energy = out["energy"]
    assert abs(energy["residual"]) < 1e-6 * energy["input_work"]
    # Each collision's loss is a contact's: the ledger's contact column sums them.
    losses = sum(c["energy_dissipated"] for c in out["contacts"])
    assert energy["contact"] == pytest.approx(losses, rel=1e-6)


@pytest.mark.timeout(30)
def test_a_system_with_collisions_round_trips_through_toml() -> None:
    system = vi.load(COLUMN)
    assert len(system.collisions) == 4
    assert system.collisions[0] == vi.Collision(
        dampers=(0, 1), gap=0.002, law="hertz-damped", stiffness=1e8, restitution=0.6
    )
    assert vi.load(system.to_toml()) == system
    assert math.isinf(system.dampers[2].lower_clearance)


@pytest.mark.timeout(60)
def test_a_study_varies_a_collision_s_gap(tmp_path: Path) -> None:
    from vibroimpact.study import run

    data = vi.load(COLUMN).to_dict()
    data["solver"]["t_end"] = 0.3
    data["study"] = {
        "axes": {"collision.0.gap": {"start": 0.001, "stop": 0.003, "count": 2}},
        "metrics": ["impacts"],
    }
    result = run(vi.study_of(data), tmp_path / "gap.nc")

    # The scenario kept with the result is strict JSON: its infinite clearances are
    # written as TOML writes them, not as JSON's non-standard Infinity.
    def refuse(constant: str) -> None:
        raise ValueError(f"not strict JSON: {constant}")

    kept = json.loads(result.attrs["scenario"], parse_constant=refuse)
    assert kept["damper"][2]["lower_clearance"] == "inf"
    impacts = result["impacts"].values
    assert result["collision.0.gap"].values.tolist() == [0.001, 0.003]
    assert impacts.shape == (2,) and impacts[0] != impacts[1]
    # The first run is the example's own system with that gap.
    data["collision"][0]["gap"] = 0.001
    alone = vi.simulate(vi.System.from_dict({k: v for k, v in data.items() if k != "study"}))
    assert impacts[0] == len(alone.contacts)


@pytest.mark.parametrize(
    ("collision", "message"),
    [
        ({"dampers": [0, 0], "gap": 0.01}, "two different"),
        ({"dampers": [0, 5], "gap": 0.01}, "two different"),
        ({"dampers": [0, 1, 2], "gap": 0.01}, "two different"),
        ({"dampers": [0.5, 1], "gap": 0.01}, "two different"),
        ({"dampers": [0, 1], "gap": -0.01}, "gap must be >= 0"),
        ({"dampers": [0, 1], "gap": 0.01, "side": "upper"}, "unknown key 'side'"),
        ({"dampers": [0, 1]}, "missing key 'gap'"),
    ],
)
@pytest.mark.timeout(30)
def test_a_bad_collision_is_refused_naming_its_key(collision: dict[str, Any], message: str) -> None:
    data = vi.load(COLUMN).to_dict()
    data["collision"] = [collision | {"law": "rigid", "restitution": 0.5}]
    with pytest.raises(ValueError, match=message) as error:
        an.runner(data)
    assert "[[collision]] 0" in str(error.value) and "\n" not in str(error.value)


@pytest.mark.parametrize("dampers", [0, 1])
@pytest.mark.timeout(30)
def test_a_collision_without_two_dampers_says_so(dampers: int) -> None:
    """With no damper it said "indices (0 to -1)"."""
    data = vi.load(COLUMN).to_dict()
    data["damper"] = data["damper"][:dampers]
    data["collision"] = data["collision"][:1]
    with pytest.raises(ValueError, match=f"between two \\[\\[damper\\]\\] .* has {dampers}:"):
        an.runner(data)


@pytest.mark.parametrize("clearance", [-math.inf, math.nan, "-inf"])
@pytest.mark.timeout(30)
def test_a_side_s_clearance_is_a_number_or_inf_only(clearance: Any) -> None:
    """inf means no wall on that side; -inf and nan are refused saying what is allowed."""
    data = vi.load(COLUMN).to_dict()
    data["damper"][0]["lower_clearance"] = clearance
    with pytest.raises(ValueError) as error:
        an.runner(data)
    message = str(error.value)
    assert "[[damper]] 0" in message and "lower_clearance" in message and "\n" not in message
    allowed = "must be a number" if isinstance(clearance, str) else ">= 0 m, or inf for no wall"
    assert allowed in message


@pytest.mark.timeout(30)
def test_a_damper_with_no_wall_needs_a_collision_or_friction_to_hold_it() -> None:
    data = vi.load(COLUMN).to_dict()
    data["collision"] = data["collision"][:1]  # particles 2 and 3 now held by nothing
    held = r"\[\[damper\]\] 2: .*neither a \[\[collision\]\] nor friction holds it"
    with pytest.raises(ValueError, match=held):
        an.runner(data)
    # Friction on its carrier holds it (a mass sliding on a floor with no side walls).
    for j in (2, 3):
        data["damper"][j] |= {"friction": 0.2, "normal_force": 0.1}
    an.runner(data)
    # Static friction alone too (a kinetic coefficient of 0: it had been refused as held
    # by nothing; a physicist's probe).
    for j in (2, 3):
        data["damper"][j] |= {"friction": 0.0, "static_friction": 2.0}
    an.runner(data)


def still_table(g: float) -> tuple[vi.Oscillator, float]:
    """A table too heavy for loose masses of grams to move (1e6 kg on a 50 Hz spring),
    and its sag (m) at rest under gravity ``g`` (m/s^2)."""
    return (
        vi.Oscillator(mass=1e6, stiffness=1e6 * (2 * math.pi * 50) ** 2, damping=0.0),
        -g / (2 * math.pi * 50) ** 2,
    )


@pytest.mark.parametrize("method", ["exact", "dop853"])
@pytest.mark.timeout(30)
def test_a_touching_rigid_column_dropped_on_the_floor_lands_as_one_ball(method: str) -> None:
    # Five touching particles dropped together from h onto the floor of a cavity too
    # heavy to move: each landing is one impact of the whole column (its contacts
    # touch at that instant; resolved one after the other they had run up and down the
    # column 1e-14 s apart without end), so it bounces as one ball of restitution e:
    # landings at t1 (1 + 2 e + ... + 2 e^(k-1)), t1 = sqrt(2 h / g), at sqrt(2 g h)
    # e^k, and at rest from t1 (1 + e) / (1 - e).
    h, e, g, count = 0.05, 0.5, 9.81, 5
    table, sag = still_table(g)
    law = {"law": "rigid", "restitution": e}
    system = vi.System(
        structure=table,
        dampers=[
            vi.Damper(
                mass=0.01,
                at=0,
                lower_clearance=h if j == 0 else math.inf,
                upper_clearance=math.inf,
                **law,
            )
            for j in range(count)
        ],
        collisions=[vi.Collision(dampers=(j, j + 1), gap=0.0, **law) for j in range(count - 1)],
        gravity=vi.Gravity(acceleration=g),
        initial=vi.Initial(structure_displacement=[sag], damper_displacement=[sag] * count),
    )
    sol = vi.simulate(system, method=method, t_end=0.5)
    floor = sol.contacts.to_pandas().query("pair == 'damper 0'")
    t1, v1 = math.sqrt(2 * h / g), math.sqrt(2 * g * h)
    landings = t1 * (1 + 2 * np.cumsum([0.0, e, e**2]))
    impacts = floor.query("kind == 'impact'")
    assert impacts.onset.to_numpy()[:3] == pytest.approx(landings, rel=1e-6)
    assert impacts.approach_speed.to_numpy()[:3] == pytest.approx(v1 * e ** np.arange(3), rel=1e-6)
    (rest,) = floor.query("kind == 'sticking'").onset
    assert rest == pytest.approx(t1 * (1 + e) / (1 - e), rel=1e-6)
    # No particle ever left another: no collision is an impact; at rest, they stick.
    collisions = sol.contacts.to_pandas().query("pair != 'damper 0'")
    assert set(collisions.kind) == {"sticking"} and len(collisions) == count - 1
    assert collisions.onset.to_numpy() == pytest.approx(rest, rel=1e-4)
    z = sol.damper_displacement
    assert np.max(np.abs(z - z[:, :1])) < 1e-12


@pytest.mark.parametrize("restitution", [0.3, 0.6])
@pytest.mark.timeout(60)
def test_a_forced_rigid_column_of_ten_runs_with_its_ledger_closed(restitution: float) -> None:
    # A low restitution collapses a column inelastically (impacts ever closer between
    # three or more particles): the touching particles then move as one, and the run
    # goes on; the impacts' losses are the ledger's.
    count = 10
    law = {"law": "rigid", "restitution": restitution}
    system = forced_column(count, law)
    for method in ("exact", "dop853"):
        sol = vi.simulate(system, method=method, t_end=5.0, history=False)
        energy = sol.energy
        assert len(sol.contacts) > 100
        assert abs(energy["residual"]) < 1e-6 * energy["input_work"]
        losses = float(np.sum(sol.contacts.energy_dissipated))
        assert energy["impact"] == pytest.approx(losses, rel=1e-9)


@pytest.mark.parametrize(
    "masses",
    [
        [0.0023714579673772417, 0.022133661705517747, 0.0024559232859605444, 0.014301308826832997],
        [0.011707442870516453, 0.0021451729100136104, 0.0411467805346885, 0.0011097395422445284],
        [0.02391131572197735, 0.0051436827294168985, 0.06764523810252324, 0.031847795449327365],
    ],
    ids=["2-22-2-14g", "12-2-41-1g", "24-5-68-32g"],
)
@pytest.mark.timeout(60)
def test_a_collapse_whose_impacts_repeat_at_one_instant_is_resolved(masses: list[float]) -> None:
    # Three of 200 random forced columns (masses 1-100 g, e = 0.3) stopped as chattering
    # near 0.06 s: a light particle's impacts on its two neighbours fell at one instant
    # to the time's round-off, intervals of zero that no longer shrink, so the collapse
    # watch never armed. Independent check: the ledger (input work = stored change +
    # losses) and the impacts' losses summed from the contacts.
    system = forced_column(len(masses), {"law": "rigid", "restitution": 0.3}, masses)
    sol = vi.simulate(system, method="exact", t_end=0.3, history=False)
    energy = sol.energy
    assert abs(energy["residual"]) < 1e-6 * energy["input_work"]
    losses = float(np.sum(sol.contacts.energy_dissipated))
    assert energy["impact"] == pytest.approx(losses, rel=1e-9)


@pytest.mark.parametrize(
    ("law", "tolerance"),
    [
        ({"law": "rigid", "restitution": 0.7}, 1e-6),
        ({"law": "hertz", "stiffness": 1e7}, 5e-5),
    ],
    ids=["rigid", "hertz"],
)
@pytest.mark.timeout(60)
def test_the_tangent_map_goes_through_collisions(law: dict[str, Any], tolerance: float) -> None:
    # Two particles in a forced cavity, the lower on its floor, the upper under its
    # ceiling, striking each other: the tangent map over a forcing period against
    # central differences of whole runs; rigid, its determinant is the phase volume's
    # identity e^(2 N) exp(-c t / M) (N impacts, the cavity's damper c on its mass M).
    method = {"method": "exact"} if law["law"] == "rigid" else {"method": "dop853"}
    tight = {} if law["law"] == "rigid" else {"rtol": 1e-11, "atol": 1e-14}
    system = vi.System(
        structure=vi.Oscillator(mass=1.0, stiffness=8883.0, damping=9.42),
        dampers=[
            vi.Damper(mass=0.01, at=0, lower_clearance=0.002, upper_clearance=math.inf, **law),
            vi.Damper(mass=0.02, at=0, lower_clearance=math.inf, upper_clearance=0.01, **law),
        ],
        collisions=[vi.Collision(dampers=(0, 1), gap=0.002, **law)],
        gravity=vi.Gravity(acceleration=9.81),
        excitations=[vi.Force(at=0, signal=vi.Harmonic(amplitude=30.0, frequency=10.0))],
        solver=vi.Solver(t_end=1.0, **method, **tight),
    )
    run = an.runner(system)
    state, period = np.array([0.001, 0.0005, 0.001, 0.05, 0.3, -0.2]), 0.1
    raw = run.tangent(state, period)
    contacts = run.periods(state, 1, record=True)
    struck = {contacts["pairs"][p] for p in contacts["contacts"]["pair"]}
    assert "collision 0" in struck and len(contacts["contacts"]["pair"]) >= 10
    columns = []
    for i in range(len(state)):
        step = np.zeros(len(state))
        step[i] = 1e-7 * max(abs(state[i]), 1e-3)
        ahead = run.system().run(list(state + step), period)["final_state"]
        behind = run.system().run(list(state - step), period)["final_state"]
        columns.append((np.asarray(ahead) - np.asarray(behind)) / (2 * step[i]))
    differences = np.array(columns).T
    error = np.max(np.abs(raw["matrix"] - differences)) / np.max(np.abs(differences))
    assert error < tolerance
    if law["law"] == "rigid":
        impacts = raw["impacts"]
        volume = law["restitution"] ** (2 * impacts) * math.exp(-9.42 * period / 1.0)
        assert np.linalg.det(raw["matrix"]) / volume == pytest.approx(1.0, abs=1e-9)


@pytest.mark.timeout(30)
def test_the_column_s_natural_modes_and_notebook_view_take_its_collisions() -> None:
    # Its middle particles have no wall: only the collisions hold them.
    system = vi.load(COLUMN)
    modes = vi.natural_modes(system)
    expected = math.sqrt(8883.0 / 1.0) / (2 * math.pi)
    assert modes.frequencies[0] == pytest.approx(expected, rel=1e-12)
    html = system._repr_html_()
    assert "collision 3" in html


@pytest.mark.timeout(120)
def test_damped_linear_contacts_of_a_chain_on_the_exact_flow_match_dop853() -> None:
    # Three particles whose damped linear contacts touch two at a time: the chain then
    # moves as one body, a mode with no stiffness whose damping is round-off (it had
    # been taken as damping, and its constant force's response F t / c lost every
    # digit: the exact flow was 1e-2 of the input work off its ledger).
    count = 3
    law = {"law": "linear", "stiffness": 2e5, "damping": 5.0}
    system = forced_column(count, law)
    exact = vi.simulate(system, method="exact", t_end=1.0, history=False)
    reference = vi.simulate(
        system, method="dop853", t_end=1.0, history=False, rtol=1e-13, atol=1e-16
    )
    energy = exact.energy
    assert abs(energy["residual"]) < 1e-10 * energy["input_work"]
    assert np.allclose(
        exact.final_state["damper_displacement"],
        reference.final_state["damper_displacement"],
        rtol=0,
        atol=1e-7,
    )


@pytest.mark.timeout(60)
def test_a_rigid_column_set_down_touching_at_displacement_zero_moves_as_one_body() -> None:
    # Three particles resting on the floor of a sprung cavity and on each other (every gap
    # 0, every coordinate 0), released under gravity: the floor never accelerates down
    # faster than g, so all four move as one damped oscillator of the total mass. By the
    # exact flow 55 of 100 random triples stopped as chattering at t ~ 1e-7 s: a pair at
    # rest at displacement 0 had a round-off of 0, and the modal transform's round-off
    # of the common motion (4e-15 m/s^2) read as impacts at 1e-82 m/s.
    stiffness, damping, g = 8883.0, 9.42, 9.81
    rng = np.random.default_rng(1)
    for _ in range(20):
        masses = rng.uniform(0.005, 0.05, 3).round(4)
        system = vi.System(
            structure=vi.Oscillator(mass=1.0, stiffness=stiffness, damping=damping),
            dampers=[
                vi.Damper(
                    mass=float(m),
                    at=0,
                    lower_clearance=0.0 if j == 0 else math.inf,
                    upper_clearance=0.03 if j == 2 else math.inf,
                    law="rigid",
                    restitution=0.6,
                )
                for j, m in enumerate(masses)
            ],
            collisions=[
                vi.Collision(dampers=[j, j + 1], gap=0.0, law="rigid", restitution=0.6)
                for j in range(2)
            ],
            gravity=vi.Gravity(acceleration=g),
        )
        sol = vi.simulate(system, method="exact", t_end=0.5, history=False)
        total = 1.0 + masses.sum()
        w = math.sqrt(stiffness / total)
        zeta = damping / (2 * math.sqrt(stiffness * total))
        wd = w * math.sqrt(1 - zeta**2)
        decay = math.exp(-zeta * w * 0.5)
        response = 1 - decay * (
            math.cos(wd * 0.5) + zeta / math.sqrt(1 - zeta**2) * math.sin(wd * 0.5)
        )
        expected = -total * g / stiffness * response
        state = sol.final_state
        assert sol.final_time == 0.5
        assert state["structure_displacement"][0] == pytest.approx(expected, rel=1e-9)
        assert np.allclose(state["damper_displacement"], expected, rtol=1e-9, atol=0)
