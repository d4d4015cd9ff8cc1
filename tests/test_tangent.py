"""The tangent flow through impacts (issue 26): Floquet multipliers against the closed
forms of shared/reference/forced-oracles.md (the ball on a vibrating table, Shaw and
Holmes' impact oscillator, Masri and Caughey's damper), the phase-space volume each impact
and the damping take (det = e^(2N) exp(-c t / M)), Lyapunov exponents against those
identities and against an independent two-trajectory estimate made with the plain kernel,
and the ``lyapunov`` command."""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from numpy.typing import NDArray
from scipy.linalg import expm

import vibroimpact as vi
from masri_caughey import MC_M, masri_caughey, mc_scenario, mc_si
from orbit_checks import spectrum_distance, state_error
from test_analyses import holmes, holmes_flip
from test_analysis_cli import BALL_TABLE, UNFORCED_BALL, RunCli, assert_one_line_error, write
from vibroimpact import analysis as an
from vibroimpact.analysis.parameters import with_parameter

Array = NDArray[np.float64]
ROOT = Path(__file__).resolve().parents[1]
TWO_MASS = ROOT / "examples" / "rattling_damper.toml"
G = 9.81  # m/s^2
TABLE_HZ = 10.0
EXACT: dict[str, Any] = {"method": "exact", "t_end": 1.0}


# ------------------------------------------------------- ball on a vibrating table


def table_scenario(e: float, gamma: float) -> dict[str, Any]:
    """Holmes' ball on a table at ``TABLE_HZ`` (``t = 0`` mid-flight of the period-one
    orbit, see ``test_analyses.holmes``) with ``[initial]`` on that orbit."""
    data, state, _ = holmes(gamma, e, TABLE_HZ)
    data["initial"] = {
        "structure_displacement": [float(state[0])],
        "structure_velocity": [float(state[1])],
    }
    return data


def holmes_multipliers(e: float, gamma: float) -> Array:
    """The eigenvalues of the impact map's Jacobian (Holmes 1982) on the orbit."""
    out: Array = np.linalg.eigvals(holmes(gamma, e, TABLE_HZ)[2])
    return out


# (e, Gamma) on the stable branch: complex multipliers, real ones near the flip, and a
# lightly dissipating ball.
HOLMES = [(0.5, 1.2), (0.5, 1.5), (0.3, 1.9), (0.8, 0.7)]


@pytest.mark.parametrize(("e", "gamma"), HOLMES, ids=[f"e={e}, Gamma={g}" for e, g in HOLMES])
def test_ball_on_a_table_multipliers_are_holmes_closed_form(e: float, gamma: float) -> None:
    assert math.pi * (1 - e) / (1 + e) < gamma < holmes_flip(e)  # the orbit exists, stable
    expected = holmes_multipliers(e, gamma)
    run = an.runner(table_scenario(e, gamma))
    start = run.initial_state()
    # One period from the closed-form state returns to it (so the scenario is the orbit).
    mapped = run.tangent(start, run.period)
    assert state_error(np.asarray(mapped["state"]), start) < 1e-12
    assert mapped["impacts"] == 1 and mapped["grazings"] == []
    assert spectrum_distance(np.linalg.eigvals(mapped["matrix"]), expected) < 1e-11
    assert np.linalg.det(mapped["matrix"]) == pytest.approx(e * e, rel=1e-11)
    # Shot from a state off the orbit, with the tangent flow and with differences.
    tangent = an.orbit(run, start * 1.01, jacobian="tangent")
    assert tangent.converged and tangent.stable and tangent.jacobian == "tangent"
    assert tangent.grazings == [] and tangent.impacts_per_period == 1
    assert state_error(tangent.state, start) < 1e-9
    assert spectrum_distance(tangent.floquet_multipliers, expected) < 1e-11
    differences = an.orbit(run, start * 1.01, jacobian="differences")
    assert differences.converged and differences.jacobian == "differences"
    gap = spectrum_distance(differences.floquet_multipliers, tangent.floquet_multipliers)
    assert gap < 1e-7
    # "auto" takes the tangent flow for rigid pairs.
    assert an.orbit(run, start, jacobian="auto").jacobian == "tangent"


# --------------------------------------------------- one-sided impact oscillator

# Shaw and Holmes (1983): m x'' + c x' + k x = F0 cos(w t), a rigid stop at x = gap.
SH_M, SH_K, SH_C, SH_F0, SH_W, SH_GAP, SH_E = 1.0, 100.0, 0.4, 20.0, 8.0, 0.2, 0.7


def shaw_holmes() -> list[dict[str, Any]]:
    """The period-one orbits (impact speed V > 0 at time t0 in the force's time): each
    with its admissibility, the monodromy S Phi and the state half a period after the
    impact."""
    m, k, c, f0, w, gap, e = SH_M, SH_K, SH_C, SH_F0, SH_W, SH_GAP, SH_E
    period = 2 * math.pi / w
    a = np.array([[0.0, 1.0], [-k / m, -c / m]])
    phi = expm(a * period)
    amp = f0 / math.hypot(k - m * w * w, c * w)
    theta = math.atan2(c * w, k - m * w * w)

    def steady(t: float) -> Array:
        return amp * np.array([math.cos(w * t - theta), -w * math.sin(w * t - theta)])

    # (gap, V) - z_p(t0) = Phi ((gap, -e V) - z_p(t0)) gives z_p(t0) = p0 + V p1 ...
    inverse = np.linalg.inv(np.eye(2) - phi)
    p0 = inverse @ (np.array([gap, 0.0]) - phi @ np.array([gap, 0.0]))
    p1 = inverse @ (np.array([0.0, 1.0]) + e * phi[:, 1])
    # ... on the ellipse the steady response traces: a quadratic in V.
    scale = np.array([1 / amp**2, 1 / (w * amp) ** 2])
    roots = np.roots([scale @ p1**2, 2 * scale @ (p0 * p1), scale @ p0**2 - 1])
    out = []
    for v in roots[(np.abs(roots.imag) < 1e-12) & (roots.real > 0)].real:
        p = p0 + v * p1
        t0 = (math.atan2(-p[1] / (w * amp), p[0] / amp) + theta) / w
        after = np.array([gap, -e * v]) - steady(t0)

        def z(t: float, t0: float = t0, after: Array = after) -> Array:
            return steady(t) + expm(a * (t - t0)) @ after

        flight = [z(t0 + s)[0] for s in np.linspace(1e-6, period - 1e-6, 400)]
        force = f0 * math.cos(w * t0)
        a_minus = (force - c * v - k * gap) / m
        a_plus = (force + c * e * v - k * gap) / m
        saltation = np.array([[-e, 0.0], [(a_plus + e * a_minus) / v, -e]])
        out.append(
            {
                "speed": v,
                "t0": t0,
                "admissible": max(flight) < gap,
                "monodromy": saltation @ phi,
                "mid": z(t0 + period / 2),
                "returns": z(t0 + period),
            }
        )
    return out


def shaw_scenario(t0: float, mid: Array) -> dict[str, Any]:
    w = SH_W
    return {
        "structure": {"kind": "oscillator", "mass": SH_M, "stiffness": SH_K, "damping": SH_C},
        "stop": [{"at": 0, "side": "upper", "gap": SH_GAP, "law": "rigid", "restitution": SH_E}],
        "excitation": [
            {
                "kind": "force",
                "at": 0,
                "signal": "harmonic",
                "amplitude": SH_F0,
                "frequency": w / (2 * math.pi),
                # The scenario's t = 0 is half a period after the impact at t0.
                "phase": (w * t0 + math.pi) % (2 * math.pi),
            }
        ],
        "initial": {"structure_displacement": [mid[0]], "structure_velocity": [mid[1]]},
        "solver": dict(EXACT),
    }


def test_impact_oscillator_multipliers_are_those_of_s_phi() -> None:
    orbits = [o for o in shaw_holmes() if o["admissible"]]
    assert len(orbits) == 1
    found = orbits[0]
    assert found["returns"] == pytest.approx([SH_GAP, found["speed"]], rel=1e-12)
    expected = np.linalg.eigvals(found["monodromy"])
    period = 2 * math.pi / SH_W
    assert np.prod(expected).real == pytest.approx(
        SH_E**2 * math.exp(-SH_C * period / SH_M), rel=1e-12
    )
    assert np.all(np.abs(expected) < 1)
    run = an.runner(shaw_scenario(found["t0"], found["mid"]))
    start = run.initial_state()
    assert np.array_equal(start, found["mid"])
    mapped = run.tangent(start, run.period)
    assert state_error(np.asarray(mapped["state"]), start) < 1e-11
    assert mapped["impacts"] == 1
    assert spectrum_distance(np.linalg.eigvals(mapped["matrix"]), expected) < 1e-11
    o = an.orbit(run, start + [1e-3, -1e-2], jacobian="tangent")
    assert o.converged and o.stable and o.impacts_per_period == 1
    assert state_error(o.state, start) < 1e-9
    assert spectrum_distance(o.floquet_multipliers, expected) < 1e-11


# ----------------------------------------------- phase-space volume: det = e^(2N) ...


def damped_mc(c: float) -> tuple[an.Runner, Array, float]:
    """Masri and Caughey's damper (mu 0.05, r 0.6, d 6, e 0.3) with a dashpot ``c``
    (N s/m) on the primary only, seeded on the undamped stable orbit."""
    mu, r, d, e = 0.05, 0.6, 6.0, 0.3
    root = masri_caughey(mu, r, d, e)[0]
    data = mc_scenario(mu, r, d, e, root["phase"])
    data["structure"]["damping"] = c
    return an.runner(data), mc_si(root["mid"]), e


def test_determinant_is_restitution_squared_per_impact_times_damping_decay() -> None:
    c = 0.3  # N s/m, on the primary (mass MC_M) only
    run, seed, e = damped_mc(c)
    o = an.orbit(run, seed, jacobian="tangent")
    assert o.converged and o.impacts_per_period == 2  # counted on the plain kernel's run
    n = 2
    expected = e ** (2 * n) * math.exp(-c * run.period / MC_M)
    assert np.linalg.det(o.monodromy) == pytest.approx(expected, rel=1e-10)
    assert np.prod(o.floquet_multipliers).real == pytest.approx(expected, rel=1e-10)
    # Off the orbit too: a transient of seven periods from a disturbed state, the
    # impacts counted on the plain kernel's own run of it.
    start = seed * [1.3, 0.7, 1.0, 1.2]
    t_end = 7 * run.period
    mapped = run.tangent(start, t_end)
    plain = run.periods(start, 7, record=True)
    impacts = sum(1 for kind in plain["contacts"]["kind"] if kind == "impact")
    assert impacts >= 10 and mapped["impacts"] == impacts
    assert np.asarray(mapped["state"]) == pytest.approx(plain["final_state"], rel=1e-9, abs=1e-12)
    det = np.linalg.det(mapped["matrix"])
    assert det == pytest.approx(e ** (2 * impacts) * math.exp(-c * t_end / MC_M), rel=1e-10)


@pytest.mark.parametrize(
    "params", [(0.05, 0.6, 6.0, 0.3), (0.2, 1.2, 4.0, 0.6)], ids=["below", "above resonance"]
)
def test_undamped_masri_caughey_multipliers_multiply_to_e_to_the_fourth(
    params: tuple[float, float, float, float],
) -> None:
    mu, r, d, e = params
    root = masri_caughey(mu, r, d, e)[0]
    assert root["admissible"]
    run = an.runner(mc_scenario(mu, r, d, e, root["phase"]))
    o = an.orbit(run, mc_si(root["mid"]) * 1.001, jacobian="tangent")
    assert o.converged and o.impacts_per_period == 2
    assert np.prod(o.floquet_multipliers).real == pytest.approx(e**4, rel=1e-10)
    assert abs(np.prod(o.floquet_multipliers).imag) < 1e-12
    # The closed form's own monodromy (scaled time: the same matrix up to units).
    expected = np.linalg.eigvals(root["monodromy"])
    assert spectrum_distance(o.floquet_multipliers, expected) < 1e-9


# ------------------------------------------------------------------------ Lyapunov


def test_exponents_sum_to_the_volume_each_impact_and_the_damping_take() -> None:
    c = 0.3  # N s/m on the primary (mass MC_M); the loose mass is undamped
    run, seed, e = damped_mc(c)
    # Settled on the damped orbit: two impacts a period, counted by the physics.
    settled = vi.lyapunov(run, seed, settle=50, periods=400)
    assert settled.impacts == 2 * 400 and settled.grazings == []
    assert settled.time == pytest.approx(400 * run.period, rel=1e-14)
    total = 2 * settled.impacts * math.log(e) - c * settled.time / MC_M
    assert np.sum(settled.exponents) * settled.time == pytest.approx(total, rel=1e-9)
    # A rattling transient from a disturbed state, the impacts as the flow counted them.
    shaken = vi.lyapunov(run, seed * [1.0, 1.0, 3.0, -2.0], settle=0, periods=30)
    assert np.all(np.isfinite(shaken.exponents)) and shaken.impacts > 60
    total = 2 * shaken.impacts * math.log(e) - c * shaken.time / MC_M
    assert np.sum(shaken.exponents) * shaken.time == pytest.approx(total, rel=1e-9)


@pytest.mark.parametrize(("e", "gamma"), [(0.5, 1.5), (0.8, 0.7)], ids=["real", "complex"])
def test_exponents_of_a_stable_orbit_are_its_multipliers_logarithms(e: float, gamma: float) -> None:
    run = an.lyapunov_runner(table_scenario(e, gamma))
    found = vi.lyapunov(run, settle=10, periods=1000)
    expected = np.sort(np.log(np.abs(holmes_multipliers(e, gamma))) / run.period)[::-1]
    assert found.impacts == 1000 and found.time == pytest.approx(100.0, rel=1e-14)
    tolerance = 3 * found.standard_error + 1e-3 * np.abs(expected)
    assert np.all(np.abs(found.exponents - expected) <= tolerance), (found.exponents, expected)
    assert found.largest == found.exponents[0] < 0
    # The convergence: the last running estimate is the result, over the whole time.
    assert found.running.shape == (10, 2) and found.running_time[-1] == pytest.approx(found.time)
    assert found.running[-1] == pytest.approx(found.exponents, rel=1e-12)


def benettin(run: an.Runner, state: Array, periods: int, blocks: int = 10) -> tuple[float, float]:
    """The largest exponent (1/s) and its standard error over ``blocks`` blocks, from a
    neighbour ``1e-9`` away (in units of g T^2 and g T) run beside the trajectory on the
    plain kernel and brought back to that distance every forcing period."""
    scale = np.array([G * run.period**2, G * run.period])
    distance = 1e-9
    offset = np.array([distance, 0.0])
    logs = np.zeros(blocks)
    for block in range(blocks):
        for _ in range(periods // blocks):
            image = run.map(state, 1)
            neighbour = (run.map(state + offset * scale, 1) - image) / scale
            stretch = float(np.linalg.norm(neighbour))
            logs[block] += math.log(stretch / distance)
            offset, state = neighbour * (distance / stretch), image
    estimates = logs / (periods // blocks * run.period)
    return float(estimates.mean()), float(estimates.std(ddof=1) / math.sqrt(blocks))


def test_largest_exponent_of_a_chaotic_ball_matches_two_trajectories() -> None:
    # e = 0.9, Gamma = 5: the ball bounces chaotically (no period-one orbit is stable:
    # Gamma > Gamma_flip) and never comes to rest on the table (no sticking in 2e5
    # periods, where a sticking would lose every direction).
    e, gamma, periods = 0.9, 5.0, 20_000
    assert gamma > holmes_flip(e)
    data = table_scenario(e, 1.2 * holmes_flip(e))
    data["excitation"][0]["amplitude"] = gamma * G
    run = an.lyapunov_runner(data)
    start = run.map(np.array([0.05, 0.0]), 200)
    found = vi.lyapunov(run, start, settle=0, periods=periods)
    assert np.all(np.isfinite(found.exponents)) and found.grazings == []
    independent, error = benettin(run, start, periods)
    assert independent > 10 * error  # chaos, by the plain kernel alone
    # The two follow trajectories that part after some tens of periods (chaos amplifies
    # their round-off differences): independent samples of one time average, each
    # with a standard error over 10 blocks (Student's t with 9 degrees of freedom,
    # roughly). 4 combined standard errors leave ~1e-3 odds of a false alarm, and
    # catch a stretch mis-scaled by 15 % (a saltation term lost at low-speed impacts).
    assert abs(found.largest - independent) < 4 * math.hypot(found.standard_error[0], error)
    # Volume: the sum is the impacts' e^2 each, exactly (no damping).
    assert np.sum(found.exponents) * found.time == pytest.approx(
        2 * found.impacts * math.log(e), rel=1e-9
    )


@pytest.mark.parametrize("law", ["hertz-damped", "hyster-hertz"])
def test_a_compliant_damper_s_orbit_by_the_tangent_flow_is_the_differences_one(law: str) -> None:
    # Masri and Caughey's damper with a stiff compliant contact (its hysteretic force
    # remembers the approach rate latched at each onset: a row of its own in the
    # tangent flow). The tangent monodromy against central differences of whole runs
    # (their own error ~1e-6 here); "auto" takes the tangent flow.
    mu, r, d, e = 0.05, 0.6, 6.0, 0.3
    root = masri_caughey(mu, r, d, e)[0]
    data = mc_scenario(mu, r, d, e, root["phase"])
    data["damper"][0].update(law=law, stiffness=1e9, restitution=0.6)
    data["solver"] = {"method": "dop853", "t_end": 1.0, "rtol": 1e-11, "atol": 1e-14}
    run = an.runner(data)
    seed = run.map(mc_si(root["mid"]), 50)
    by_tangent = an.orbit(run, seed)
    by_differences = an.orbit(run, seed, jacobian="differences")
    assert by_tangent.jacobian == "tangent" and by_tangent.converged
    assert by_differences.converged and by_tangent.impacts_per_period == 2
    # Its two contacts a period counted as impacts, as the plain kernel's run has them.
    assert run.tangent(by_tangent.state, run.period)["impacts"] == 2
    assert state_error(by_tangent.state, by_differences.state) < 1e-9
    size = np.max(np.abs(by_tangent.monodromy))
    assert np.max(np.abs(by_tangent.monodromy - by_differences.monodromy)) < 1e-5 * size
    assert (
        spectrum_distance(by_tangent.floquet_multipliers, by_differences.floquet_multipliers) < 1e-5
    )


@pytest.mark.timeout(120)
@pytest.mark.parametrize("law", ["hertz-damped", "hertz"])
def test_a_compliant_orbit_s_derivatives_are_the_differences_of_its_neighbours(law: str) -> None:
    # The tangent flow's columns by parameters (the forward sensitivity equations,
    # through each contact's onset, its latched approach rate and its separation)
    # give dz/dp by the implicit function theorem; independently, the orbits found by
    # Newton's method at p +- h. The clearance moves the gaps (the contacts' onsets and
    # separations), the stiffness the law, the frequency the period itself. The map's
    # derivatives agree with the differences of runs to 1e-6; I - M (condition ~110)
    # carries the compliant monodromy's own ~1e-7 into dz/dp: 2e-5 at most measured.
    mu, r, d, e = 0.05, 0.6, 6.0, 0.3
    root = masri_caughey(mu, r, d, e)[0]
    data = mc_scenario(mu, r, d, e, root["phase"])
    damper = data["damper"][0]
    if law == "hertz":
        damper.pop("restitution", None)
        damper.update(law=law, stiffness=1e9)
    else:
        damper.update(law=law, stiffness=1e9, restitution=0.6)
    data["solver"] = {"method": "dop853", "t_end": 1.0, "rtol": 1e-11, "atol": 1e-14}
    run = an.runner(data)
    found = an.orbit(run, run.map(mc_si(root["mid"]), 50), tolerance=1e-11)
    assert found.converged and found.impacts_per_period == 2
    paths = ["damper.0.clearance", "damper.0.stiffness", "excitation.0.frequency"]
    derivatives = an.orbit_derivatives(data, found, paths)
    for path in paths:
        base = float(eval_path(data, path))
        # The stiffness moves the orbit little: a longer step keeps the neighbours'
        # differences above their Newton tolerance.
        h = (1e-3 if path.endswith("stiffness") else 1e-5) * base
        sides = []
        for sign in (1.0, -1.0):
            near = an.runner(with_parameter(data, path, base + sign * h))
            orbit = an.orbit(near, found.state, tolerance=1e-11)
            assert orbit.converged
            sides.append(orbit.state)
        expected = (sides[0] - sides[1]) / (2 * h)
        assert state_error(derivatives[path].state, expected) < 5e-5, path


def eval_path(data: dict[str, Any], path: str) -> Any:
    """The value at a dotted path of a scenario's sections."""
    node: Any = data
    for part in path.split("."):
        node = node[int(part)] if isinstance(node, list) else node[part]
    return node


@pytest.mark.timeout(120)
def test_largest_exponent_of_a_ball_on_a_compliant_table_matches_two_trajectories() -> None:
    # The chaotic ball of the test above on a stiff damped Hertz table: its spectrum by
    # the tangent flow through the compliant contacts against Benettin's two runs on
    # the plain kernel (20000 periods: both about 3.6 1/s, standard errors ~0.1).
    e, gamma, periods = 0.9, 5.0, 20_000
    data = table_scenario(e, 1.2 * holmes_flip(e))
    data["excitation"][0]["amplitude"] = gamma * G
    data["stop"][0].update(law="hertz-damped", stiffness=1e8)
    data["solver"] = {"method": "dop853", "t_end": 1.0, "rtol": 1e-10, "atol": 1e-13}
    run = an.lyapunov_runner(data)
    start = run.map(np.array([0.05, 0.0]), 200)
    found = vi.lyapunov(run, start, settle=0, periods=periods)
    # A landing slower than the damped law's latched rate (a soft one) is reported as a
    # grazing: a chaotic orbit has a few among its thousands of landings (2 of 3343 at
    # the nineteenth stop, none before), which of them shifting with the engine's
    # round-off; they stay rare (an onset the tangent flow failed to take every time
    # would be one in each landing).
    assert np.all(np.isfinite(found.exponents))
    assert len(found.grazings) <= found.impacts // 100
    # Each contact counted (as its onset): a few a period (the plain kernel's run
    # parts from this one after some tens of periods, chaos amplifying round-off).
    contacts = len(run.periods(start, periods)["contacts"]["onset"])
    assert 0.8 < found.impacts / contacts < 1.25
    independent, error = benettin(run, start, periods)
    assert independent > 10 * error
    assert abs(found.largest - independent) < 4 * math.hypot(found.standard_error[0], error)
    # Dissipation: the contact's damping contracts phase space.
    assert np.sum(found.exponents) < 0


# ----------------------------------------------------------------------------- CLI

LYAPUNOV_FIELDS = {
    "exponents",
    "standard_error",
    "time",
    "impacts",
    "settle",
    "periods",
    "forcing_period",
    "grazings",
    "cpu_time",
}


def lyapunov_json(run_cli: RunCli, *args: str) -> Any:
    done = run_cli("lyapunov", *args, "--json")
    assert done.returncode == 0, done.stderr
    assert done.stderr == ""
    return json.loads(done.stdout)


def test_lyapunov_json_of_the_ball_on_the_table(run_cli: RunCli, tmp_path: Path) -> None:
    out = lyapunov_json(run_cli, str(BALL_TABLE))
    assert set(out) == LYAPUNOV_FIELDS
    assert out["settle"] == 100 and out["periods"] == 1000
    assert out["forcing_period"] == pytest.approx(0.1, rel=1e-15)
    assert out["time"] == pytest.approx(100.0, rel=1e-14)
    assert out["impacts"] == 1000 and out["grazings"] == []
    # The example's orbit (e = 0.5, Gamma = 1.2): complex multipliers of modulus e.
    expected = math.log(0.5) / 0.1
    for value, error in zip(out["exponents"], out["standard_error"], strict=True):
        assert 0 < error < 0.1
        assert abs(value - expected) <= 3 * error + 1e-3 * abs(expected)
    assert out["exponents"][0] >= out["exponents"][1]
    assert sum(out["exponents"]) * out["time"] == pytest.approx(
        2 * out["impacts"] * math.log(0.5), rel=1e-9
    )
    short = lyapunov_json(run_cli, str(BALL_TABLE), "--settle", "0", "--periods", "30")
    assert short["time"] == pytest.approx(3.0) and short["impacts"] == 30
    assert short["settle"] == 0 and short["periods"] == 30
    plot = tmp_path / "lyapunov.png"
    done = run_cli("lyapunov", str(BALL_TABLE), "--periods", "50", "--plot", str(plot))
    assert done.returncode == 0, done.stderr
    assert plot.read_bytes().startswith(b"\x89PNG\r\n\x1a\n")
    assert "largest: " in done.stdout and f"plot written to {plot}" in done.stdout


def test_lyapunov_of_an_unforced_ball(run_cli: RunCli, tmp_path: Path) -> None:
    # The dropped ball comes to rest at t_inf = sqrt(2 h / g) (1 + e) / (1 - e) = 4.06 s,
    # before t_end = 6 s: resting, it forgets every perturbation (both directions lost,
    # minus infinity, null in JSON).
    out = lyapunov_json(run_cli, str(UNFORCED_BALL))
    assert set(out) == LYAPUNOV_FIELDS
    assert out["exponents"] == [None, None] and out["standard_error"] == [None, None]
    assert out["time"] == 6.0 and out["forcing_period"] is None
    assert out["settle"] is None and out["periods"] is None
    text = run_cli("lyapunov", str(UNFORCED_BALL))
    assert text.returncode == 0 and "-inf 1/s" in text.stdout
    # Stopped at 3 s, still bouncing: finite, and the sum is the impacts' e^2 each.
    e, first = 0.8, math.sqrt(2 * 1.0 / G)
    impacts = 1 + math.floor(math.log(1 - (3.0 - first) * (1 - e) / (2 * e * first)) / math.log(e))
    source = UNFORCED_BALL.read_text(encoding="utf-8")
    assert "t_end = 6.0 " in source and "restitution = 0.8 " in source
    path = write(tmp_path, "ball.toml", source.replace("t_end = 6.0 ", "t_end = 3.0 "))
    out = lyapunov_json(run_cli, str(path))
    assert out["impacts"] == impacts and all(math.isfinite(v) for v in out["exponents"])
    assert sum(out["exponents"]) * 3.0 == pytest.approx(2 * impacts * math.log(e), rel=1e-9)
    assert_one_line_error(run_cli("lyapunov", str(path), "--settle", "3"), "--settle")
    # Its runs keep no history: with [output] history = false, a max_rows below t_end /
    # dt rows is no limit (it had been refused, advised to set the history = false that
    # it had, an adversarial probe).
    few = source.replace("t_end = 6.0 ", "max_rows = 10\nt_end = 3.0 ", 1)
    few += "\n[output]\nhistory = false\n"
    held = lyapunov_json(run_cli, str(write(tmp_path, "few.toml", few)))
    assert {**held, "cpu_time": 0} == {**out, "cpu_time": 0}


def test_lyapunov_refusals_exit_2(run_cli: RunCli, tmp_path: Path) -> None:
    # A compliant table is taken (its contacts counted as impacts), not refused.
    source = BALL_TABLE.read_text(encoding="utf-8")
    compliant = source.replace('law = "rigid" ', 'law = "hertz" ', 1)
    compliant = compliant.replace("restitution = 0.5", "stiffness = 1e6", 1)
    compliant = compliant.replace('method = "exact" ', 'method = "dopri5"', 1)
    path = write(tmp_path, "hertz.toml", compliant)
    done = run_cli("lyapunov", str(path), "--periods", "50", "--json")
    assert done.returncode == 0, done.stderr
    out = json.loads(done.stdout)
    assert out["impacts"] > 0 and all(math.isfinite(v) for v in out["exponents"])
    assert_one_line_error(run_cli("lyapunov", str(BALL_TABLE), "--settle", "-1"), "--settle")
    assert_one_line_error(run_cli("lyapunov", str(BALL_TABLE), "--periods", "0"), "--periods")
    # The analysis's own refusals name the flags too (they had said "settle 9999999 and
    # periods 2", a probe).
    both = run_cli("lyapunov", str(BALL_TABLE), "--settle", "9999999", "--periods", "2")
    assert_one_line_error(both, "--settle 9999999 and --periods 2: a run settles")
    assert_one_line_error(run_cli("lyapunov", str(TWO_MASS)), str(TWO_MASS), "[structure]")


def test_orbit_json_says_how_its_jacobian_was_made(run_cli: RunCli) -> None:
    done = run_cli("orbit", str(BALL_TABLE), "--json")
    assert done.returncode == 0, done.stderr
    out = json.loads(done.stdout)
    assert out["jacobian"] == "tangent" and out["grazings"] == []
    multipliers = [complex(re, im) for re, im in out["floquet_multipliers"]]
    assert spectrum_distance(np.array(multipliers), holmes_multipliers(0.5, 1.2)) < 1e-6


LINEAR_PAIR = """
[structure]
kind = "matrices"
mass = [[1.0, 0.0], [0.0, 0.5]]
stiffness = [[300.0, -100.0], [-100.0, 100.0]]
damping = [[30.0, 0.0], [0.0, 0.1]]

[[excitation]]
kind = "force"
at = 0
signal = "harmonic"
amplitude = 1.0
frequency = 1.0

[solver]
method = "exact"
t_end = 1.0
"""


LIGHTER_PAIR = LINEAR_PAIR.replace("[0.0, 0.5]]", "[0.0, 1.0]]").replace("30.0, 0.0", "8.0, 0.0")


@pytest.mark.parametrize("source", [LINEAR_PAIR, LIGHTER_PAIR])
def test_lyapunov_of_a_linear_structure_without_contact(
    run_cli: RunCli, tmp_path: Path, source: str
) -> None:
    # Nothing touches, so the exponents are the real parts of the state matrix's
    # eigenvalues (numpy's), and their sum its trace. Every block of 100 s is one
    # smooth stretch: carried as one factor, its fast directions were lost (-2.4/s
    # for -13.1/s here), or their squared norms underflowed to minus infinity.
    out = lyapunov_json(run_cli, str(write(tmp_path, "pair.toml", source)))
    data = vi.load(tmp_path / "pair.toml").to_dict()["structure"]
    m, k, c = (np.array(data[key], dtype=float) for key in ("mass", "stiffness", "damping"))
    a = np.block([[np.zeros((2, 2)), np.eye(2)], [-np.linalg.solve(m, k), -np.linalg.solve(m, c)]])
    expected = np.sort(np.linalg.eigvals(a).real)[::-1]
    assert out["impacts"] == 0
    got = np.array(out["exponents"], dtype=float)
    assert np.abs(got - expected).max() < 0.01, (got, expected)
    assert got.sum() == pytest.approx(np.trace(a), rel=1e-9)
