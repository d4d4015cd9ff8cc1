"""A damper's wall grazed (issue 26): a ball in a box on a vibrating table. The table is
a forced oscillator (1 kg, 30 Hz, 5 % damping, driven at 10 Hz, all under gravity); the
ball (20 g, a rigid damper with restitution 0.5) bounces on the box's floor
(``lower_clearance = 0``) once a forcing period, and as the force grows its flight
reaches the box's ceiling (``upper_clearance``), where the orbit grazes the damper's
upper wall. The oracle is scipy's integration of the two masses with the floor's
impacts (momentum kept, the relative speed reversed times e), written here from the
equations of motion alone; and, for a damper with no upper wall (``inf``), a ball
bouncing on a table too heavy to move, whose impacts are the dropped ball's closed
form."""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

import vibroimpact as vi
import vibroimpact.analysis as an
from system_checks import cli
from test_collisions import still_table
from vibroimpact.analysis import continue_orbit
from vibroimpact.analysis.curves import curve
from vibroimpact.analysis.grazing import struck

TABLE_MASS, TABLE_STIFFNESS, TABLE_DAMPING = 1.0, 35530.0, 18.8
BALL_MASS, RESTITUTION, G = 0.02, 0.5, 9.81
CEILING = 0.016  # m above the floor
AMPLITUDE = "excitation.0.amplitude"
#: The period-one bouncing orbit at 100 N (it misses the ceiling: its flight peaks
#: 15.2 mm above the floor).
ORBIT = [0.00295421, 0.00837801, 0.03030872, 0.29990679]


def _box(force: float = 100.0, frequency: float = 10.0) -> dict[str, Any]:
    return {
        "structure": {
            "kind": "oscillator",
            "mass": TABLE_MASS,
            "stiffness": TABLE_STIFFNESS,
            "damping": TABLE_DAMPING,
        },
        "damper": [
            {
                "mass": BALL_MASS,
                "at": 0,
                "lower_clearance": 0.0,
                "upper_clearance": CEILING,
                "law": "rigid",
                "restitution": RESTITUTION,
            }
        ],
        "gravity": {"acceleration": G},
        "excitation": [
            {"kind": "force", "at": 0, "signal": "harmonic", "amplitude": force}
            | {"frequency": frequency}
        ],
        "initial": {
            "structure_displacement": [ORBIT[0]],
            "damper_displacement": [ORBIT[1]],
            "structure_velocity": [ORBIT[2]],
            "damper_velocity": [ORBIT[3]],
        },
        "solver": {"method": "exact", "t_end": 1.0},
    }


def _period(state: Any, force: float, frequency: float = 10.0) -> tuple[np.ndarray, list[Any]]:
    """One forcing period from ``state`` (table's and ball's displacements, then
    velocities) by scipy, the ball striking the floor only: the end state and the
    flights' dense solutions."""
    w = 2 * math.pi * frequency

    def rates(t: float, y: np.ndarray) -> list[float]:
        force_now = force * math.cos(w * t) - TABLE_DAMPING * y[2] - TABLE_STIFFNESS * y[0]
        return [y[2], y[3], force_now / TABLE_MASS - G, -G]

    def floor(t: float, y: np.ndarray) -> float:
        return float(y[1] - y[0])

    floor.terminal, floor.direction = True, -1  # type: ignore[attr-defined]
    t, y, flights = 0.0, np.array(state, dtype=float), []
    while t < 1 / frequency and len(flights) < 20:
        sol = solve_ivp(
            rates, (t, 1 / frequency), y, events=floor, rtol=1e-12, atol=1e-15, dense_output=True
        )
        flights.append(sol)
        t, y = float(sol.t[-1]), sol.y[:, -1].copy()
        if sol.status == 1:
            closing = y[3] - y[2]
            total = TABLE_MASS + BALL_MASS
            y[3] -= (1 + RESTITUTION) * closing * TABLE_MASS / total
            y[2] += (1 + RESTITUTION) * closing * BALL_MASS / total
    return y, flights


def _highest(flights: list[Any], near: float) -> tuple[float, float]:
    """The ball's highest point above the floor within 5 ms of ``near`` s, where its
    speed relative to the table changes sign: its instant (s) and height (m)."""
    sol = next(s for s in flights if s.t[0] <= near <= s.t[-1])
    low, high = max(sol.t[0], near - 5e-3), min(sol.t[-1], near + 5e-3)
    instant = brentq(lambda t: sol.sol(t)[3] - sol.sol(t)[2], low, high, xtol=1e-15)
    y = sol.sol(instant)
    return float(instant), float(y[1] - y[0])


@pytest.mark.timeout(60)
def test_the_ceiling_s_grazing_is_located_and_is_the_box_s_own_orbit() -> None:
    branch = continue_orbit(_box(), AMPLITUDE, stop=130.0)
    grazings = [b for b in branch.bifurcations if b.kind == "grazing"]
    assert len(grazings) == 1
    found = grazings[0]
    assert found.pair == "damper 0 upper"
    assert "grazing" in branch.stopped and "damper 0 upper" in branch.stopped
    # Newton ran the box without its ceiling; scipy runs it with the floor alone,
    # which the orbit strikes once: the state returns after a period, and the flight
    # peaks at the ceiling, at the instant reported, rising at zero speed.
    end, flights = _period(found.state, found.value)
    assert np.max(np.abs(end - found.state) / np.array([1e-3, 1e-2, 1e-1, 1.0])) < 1e-9
    assert len(flights) == 2
    assert found.time is not None
    instant, height = _highest(flights, found.time)
    assert height == pytest.approx(CEILING, abs=1e-12)
    assert instant == pytest.approx(found.time, abs=1e-9)
    # Its multipliers: those of scipy's period map, by central differences.
    step = 1e-7
    columns = []
    for i in range(4):
        moved = np.zeros(4)
        moved[i] = step
        ahead = _period(found.state + moved, found.value)[0]
        behind = _period(found.state - moved, found.value)[0]
        columns.append((ahead - behind) / (2 * step))
    multipliers = np.sort_complex(np.linalg.eigvals(np.array(columns).T))
    assert np.sort_complex(found.floquet_multipliers) == pytest.approx(multipliers, abs=1e-5)


@pytest.mark.timeout(60)
def test_either_side_of_the_grazing_the_orbit_misses_or_strikes_the_ceiling() -> None:
    # The walls struck are told apart by side: both are the one pair "damper 0".
    branch = continue_orbit(_box(), AMPLITUDE, stop=130.0)
    found = next(b for b in branch.bifurcations if b.kind == "grazing")
    below = an.runner(an.with_parameter(_box(), AMPLITUDE, found.value - 0.5))
    shot = an.orbit(below, found.state, periods=1)
    assert shot.converged and shot.stable
    assert struck(below, shot.state, 1) == {"damper 0 lower"}
    # Above it no orbit of one period is near (the flight would have to rebound from
    # the ceiling at once): a run from the grazing orbit strikes both walls.
    above = an.runner(an.with_parameter(_box(), AMPLITUDE, found.value + 0.5))
    assert struck(above, found.state, 4) == {"damper 0 lower", "damper 0 upper"}
    # Without gravity and with a table almost still, a ball thrown at one wall from
    # 1 mm away strikes that wall alone within the period (it comes back at half the
    # speed, 2 mm at most).
    weightless = _box(force=1.0)
    weightless["gravity"] = {"acceleration": 0.0}
    run = an.runner(weightless)
    up = np.array([0.0, CEILING - 1e-3, 0.0, 0.05])
    assert struck(run, up, 1) == {"damper 0 upper"}
    down = np.array([0.0, 1e-3, 0.0, -0.05])
    assert struck(run, down, 1) == {"damper 0 lower"}


@pytest.mark.timeout(60)
def test_the_ceiling_s_grazing_curve_in_force_and_frequency_is_the_box_s_grazing() -> None:
    found = curve(
        _box(),
        "grazing",
        AMPLITUDE,
        start=100.0,
        stop=120.0,
        second="excitation.0.frequency",
        second_stop=10.4,
        step=0.1,
    )
    assert found.stopped == "reached second_stop"
    assert len(found.points) >= 5
    for point in found.points[::2]:
        force, frequency = point.values[AMPLITUDE], point.values["excitation.0.frequency"]
        end, flights = _period(point.state, force, frequency)
        assert np.max(np.abs(end - point.state) / np.array([1e-3, 1e-2, 1e-1, 1.0])) < 1e-9
        flight = max(flights, key=lambda s: s.t[-1] - s.t[0])
        apex = _highest(flights, 0.5 * (flight.t[0] + flight.t[-1]))
        assert apex[1] == pytest.approx(CEILING, abs=1e-11)


@pytest.mark.timeout(30)
def test_a_damper_with_no_upper_wall_is_a_ball_bouncing_on_its_floor() -> None:
    # A table of 1e6 kg on a 50 Hz spring at rest, the ball (10 g) thrown up at 1 m/s
    # from its floor: no ceiling stops it (it rises 51 mm); it lands after 2 v / g,
    # each bounce e times faster and shorter than the last.
    table, sag = still_table(G)
    system = vi.System(
        structure=table,
        dampers=[
            vi.Damper(
                mass=0.01,
                at=0,
                lower_clearance=0.0,
                upper_clearance=math.inf,
                law="rigid",
                restitution=RESTITUTION,
            )
        ],
        gravity=vi.Gravity(acceleration=G),
        initial=vi.Initial(
            structure_displacement=[sag], damper_displacement=[sag], damper_velocity=[1.0]
        ),
    )
    assert vi.load(system.to_toml()) == system
    contacts = vi.simulate(system, method="exact", t_end=0.5).contacts
    speeds = RESTITUTION ** np.arange(4)
    onsets = np.cumsum(2 * speeds / G)
    assert contacts.onset[:4] == pytest.approx(onsets, rel=1e-7)
    assert contacts.approach_speed[:4] == pytest.approx(speeds, rel=1e-6)


@pytest.mark.parametrize(
    ("sides", "message"),
    [
        ({"lower_clearance": math.inf, "upper_clearance": math.inf}, "both inf"),
        ({"lower_clearance": -math.inf, "upper_clearance": 0.01}, "lower_clearance"),
        ({"lower_clearance": 0.01, "upper_clearance": math.nan}, "upper_clearance"),
        ({"lower_clearance": -0.01, "upper_clearance": 0.01}, "lower_clearance"),
        ({"clearance": math.inf}, "clearance"),
    ],
)
@pytest.mark.timeout(30)
def test_a_damper_s_clearances_are_numbers_or_inf_on_one_side(
    sides: dict[str, float], message: str
) -> None:
    data = _box()
    damper = data["damper"][0]
    del damper["lower_clearance"], damper["upper_clearance"]
    damper.update(sides)
    with pytest.raises(ValueError, match=message) as error:
        an.runner(data)
    assert "[[damper]] 0" in str(error.value) and "\n" not in str(error.value)


@pytest.mark.timeout(120)
def test_cli_reports_the_ceiling_s_grazing_and_its_curve(tmp_path: Path) -> None:
    scenario = tmp_path / "box.toml"
    text = vi.System.from_dict(_box()).to_toml()
    text += '\n[continuation]\nparameter = "excitation.0.amplitude"\nstop = 130.0\n'
    text += (
        '\n[curve]\nkind = "grazing"\nparameter = "excitation.0.amplitude"\n'
        'start = 100.0\nstop = 120.0\nsecond = "excitation.0.frequency"\n'
        "second_stop = 10.2\nstep = 0.05\n"
    )
    scenario.write_text(text, encoding="utf-8")
    done = cli("continue", str(scenario), "--json")
    assert done.returncode == 0, done.stderr
    (touch,) = [b for b in json.loads(done.stdout)["bifurcations"] if b["kind"] == "grazing"]
    assert touch["pair"] == "damper 0 upper" and 0 <= touch["time"] < 0.1
    state = [touch["state"][key][0] for key in ("structure_displacement", "damper_displacement")]
    state += [touch["state"][key][0] for key in ("structure_velocity", "damper_velocity")]
    end, flights = _period(state, touch["value"])
    assert np.max(np.abs(end - state) / np.array([1e-3, 1e-2, 1e-1, 1.0])) < 1e-9
    assert _highest(flights, touch["time"])[1] == pytest.approx(CEILING, abs=1e-12)
    plot = tmp_path / "curve.png"
    done = cli("curve", str(scenario), "--json", "--plot", str(plot))
    assert done.returncode == 0, done.stderr
    points = json.loads(done.stdout)["points"]
    assert len(points) == 5
    assert plot.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


@pytest.mark.timeout(30)
def test_walls_are_stops_and_damper_sides_and_a_one_walled_damper_is_struck_on_it() -> None:
    from vibroimpact.analysis.grazing import walls

    assert walls(["stop 0", "damper 0", "collision 0"]) == [
        "stop 0",
        "damper 0 upper",
        "damper 0 lower",
    ]
    # A box with no ceiling: its ball strikes the floor, the one wall it has.
    data = _box()
    data["damper"][0]["upper_clearance"] = math.inf
    run = an.runner(data)
    assert struck(run, np.array(ORBIT), 1) == {"damper 0 lower"}
