"""Grazings located by Newton's method on the extended system (issue 26), against the
closed form of the one-sided impact oscillator: below resonance its orbit misses the
stop at ``gap`` and is the forced linear response of amplitude
``X(f) = F0 / |k - m w^2 + i c w|``, so it grazes where ``X(f) = gap``, at the instant
its displacement peaks, with the free flow's Floquet multipliers
``exp((-zeta w_n +- i w_d) T)``."""

from __future__ import annotations

import json
import math
import subprocess
import sys
import tomllib
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from scipy.optimize import brentq

import vibroimpact.analysis as an
from vibroimpact.analysis import continue_orbit, curve_of, curve_regions

ROOT = Path(__file__).resolve().parents[1]
GRAZING = ROOT / "examples" / "impact_oscillator_grazing.toml"
FREQUENCY = "excitation.0.frequency"


def _scenario() -> dict[str, Any]:
    return tomllib.loads(GRAZING.read_text(encoding="utf-8"))


def _oscillator(data: dict[str, Any]) -> tuple[float, float, float, float, float]:
    s, e = data["structure"], data["excitation"][0]
    return s["mass"], s["stiffness"], s["damping"], e["amplitude"], data["stop"][0]["gap"]


def _amplitude(data: dict[str, Any], f: float) -> float:
    m, k, c, f0, _ = _oscillator(data)
    w = 2 * math.pi * f
    return f0 / abs(k - m * w * w + 1j * c * w)


def _grazing_frequency(data: dict[str, Any], gap: float) -> float:
    return float(brentq(lambda f: _amplitude(data, f) - gap, 0.3, 0.99, xtol=1e-15, rtol=1e-15))


@pytest.mark.timeout(60)
def test_continuation_locates_the_grazing_where_the_amplitude_reaches_the_gap() -> None:
    data = _scenario()
    m, k, c, _, gap = _oscillator(data)
    branch = continue_orbit(data, FREQUENCY, stop=data["continuation"]["stop"])
    grazings = [b for b in branch.bifurcations if b.kind == "grazing"]
    assert len(grazings) == 1
    found = grazings[0]
    f = _grazing_frequency(data, gap)
    assert found.value == pytest.approx(f, rel=1e-10)
    assert found.pair == "stop 0"
    # The branch ends there, saying why (beyond, the orbit strikes the stop).
    assert "grazing" in branch.stopped and "stop 0" in branch.stopped
    # The orbit: the linear response x = X cos(w t - theta) with X = gap.
    w = 2 * math.pi * f
    theta = math.atan2(c * w, k - m * w * w)
    assert found.state[0] == pytest.approx(gap * math.cos(theta), abs=1e-9 * gap)
    assert found.state[1] == pytest.approx(gap * w * math.sin(theta), abs=1e-9 * gap * w)
    # It touches where the displacement peaks: w tau - theta = 0 (mod 2 pi).
    assert found.time is not None
    phase = (w * found.time - theta) % (2 * math.pi)
    assert min(phase, 2 * math.pi - phase) < 1e-8
    # Its multipliers: the free damped oscillator's over one period.
    wn = math.sqrt(k / m)
    zeta = c / (2 * math.sqrt(k * m))
    wd = wn * math.sqrt(1 - zeta**2)
    period = 1 / f
    closed = np.exp((-zeta * wn + 1j * wd) * period)
    got = sorted(found.floquet_multipliers, key=lambda z: z.imag)
    assert got[1] == pytest.approx(closed, abs=1e-11)
    assert got[0] == pytest.approx(np.conj(closed), abs=1e-11)


@pytest.mark.timeout(60)
def test_the_located_grazing_orbit_is_the_system_s_own_and_touches_at_zero_speed() -> None:
    # Newton ran the system without the stop; the orbit found must be an orbit of the
    # system with it: a period of the full system from it returns to it, its least gap
    # zero to round-off and no impact whose speed is above round-off.
    data = _scenario()
    gap = data["stop"][0]["gap"]
    branch = continue_orbit(data, FREQUENCY, stop=data["continuation"]["stop"])
    found = next(b for b in branch.bifurcations if b.kind == "grazing")
    run = an.runner(an.with_parameter(data, FREQUENCY, found.value))
    raw = run.periods(found.state, 1, record=True)
    assert np.max(np.abs(raw["final_state"][:2] - found.state)) < 1e-9 * max(
        1.0, float(np.max(np.abs(found.state)))
    )
    assert float(raw["peaks"][0]) == pytest.approx(gap, rel=1e-10)
    speeds = raw["contacts"]["approach_speed"]
    assert all(abs(s) < 1e-6 for s in speeds)


def _soft_and_rigid() -> dict[str, Any]:
    """The oscillator between a soft linear stop above (30 mm, 40 N/m), struck all along
    the branch (the continuation moves its section away from the contacts), and a rigid
    one 60 mm below, grazed as the frequency rises."""
    data = _scenario()
    data["stop"] = [
        {"at": 0, "side": "upper", "gap": 0.03, "law": "linear", "stiffness": 40.0},
        {"at": 0, "side": "lower", "gap": 0.06, "law": "rigid", "restitution": 0.8},
    ]
    return data


def _soft_and_rigid_orbit(data: dict[str, Any], f: float, state: np.ndarray) -> Any:
    """One period from ``state`` of the soft-and-rigid system missing its rigid stop, by
    scipy's integration (a test-only oracle) of the piecewise-linear equation
    m x'' + c x' + k x + 40 (x - 0.03)+ = F0 cos(w t)."""
    from scipy.integrate import solve_ivp

    m, k, c, f0, _ = _oscillator(data)
    w = 2 * math.pi * f

    def rhs(t: float, y: np.ndarray) -> list[float]:
        soft = 40.0 * max(y[0] - 0.03, 0.0)
        return [y[1], (f0 * math.cos(w * t) - c * y[1] - k * y[0] - soft) / m]

    return solve_ivp(
        rhs, (0, 1 / f), state, rtol=1e-12, atol=1e-14, max_step=1e-4, dense_output=True
    )


@pytest.mark.timeout(60)
def test_a_grazing_on_a_moved_section_is_reported_on_the_scenario_s_clock() -> None:
    # The state is the orbit's at t = 0 of the scenario's forcing, and the time that of
    # the touch after it, within a period (the section had been moved off the contacts
    # with the soft stop: the state and time had been on the moved section's clock).
    data = _soft_and_rigid()
    branch = continue_orbit(data, FREQUENCY, stop=data["continuation"]["stop"])
    (found,) = [b for b in branch.bifurcations if b.kind == "grazing"]
    assert found.pair == "stop 1" and found.time is not None
    assert 0 <= found.time < 1 / found.value
    orbit = _soft_and_rigid_orbit(data, found.value, found.state)
    assert np.max(np.abs(orbit.y[:, -1] - found.state)) < 1e-7
    x, v = orbit.sol(found.time)
    assert x == pytest.approx(-0.06, abs=1e-8) and v == pytest.approx(0.0, abs=1e-7)


@pytest.mark.timeout(60)
def test_a_grazing_curve_starts_from_a_grazing_on_a_moved_section() -> None:
    # Its first guess is the located grazing's state and time (it had failed at its
    # first step when they were on the moved section's clock).
    data = _soft_and_rigid()
    data["curve"] = {**data["curve"], "second": "stop.1.gap", "second_stop": 0.064}
    found = curve_of(data, GRAZING.parent)
    assert found.stopped == "reached second_stop" and len(found.points) == 21
    for p in found.points[:: len(found.points) - 1]:
        f, gap = p.values[FREQUENCY], p.values["stop.1.gap"]
        orbit = _soft_and_rigid_orbit(data, f, p.state)
        assert np.max(np.abs(orbit.y[:, -1] - p.state)) < 1e-7
        assert float(np.min(orbit.y[0])) == pytest.approx(-gap, abs=1e-7)


@pytest.mark.timeout(60)
def test_a_grazing_crossed_from_the_impacting_side_is_located_and_the_branch_goes_on() -> None:
    # The impacting orbit continued down in the force amplitude meets the orbit that
    # misses the stop at F = gap |k - m w^2 + i c w|; the branch goes on along it (its
    # tangent had been turned back by the impacting branch's, and the corrector failed).
    k, c, f, gap = (2 * math.pi) ** 2, 0.04 * math.pi, 0.8, 0.05
    w = 2 * math.pi * f
    data = {
        "structure": {"kind": "oscillator", "mass": 1.0, "stiffness": k, "damping": c},
        "stop": [{"at": 0, "side": "upper", "gap": gap, "law": "rigid", "restitution": 0.8}],
        "excitation": [
            {"kind": "force", "at": 0, "signal": "harmonic", "amplitude": 2.0, "frequency": f}
        ],
        "initial": {"structure_displacement": [0.04023232], "structure_velocity": [-0.49373256]},
        "solver": {"method": "exact", "t_end": 50.0},
    }
    branch = continue_orbit(data, "excitation.0.amplitude", stop=0.5, step=0.05)
    assert branch.stopped == "reached stop"
    grazings = [b for b in branch.bifurcations if b.kind == "grazing"]
    assert len(grazings) == 1
    assert grazings[0].value == pytest.approx(gap * abs(k - w * w + 1j * c * w), rel=1e-10)
    flagged = [p for p in branch.points if "grazing" in p.flags]
    assert flagged[0].crossings["grazing"] == grazings[0].value
    # Beyond it, the linear response all the way down.
    for p in branch.points:
        if p.value < grazings[0].value:
            closed = p.value / abs(k - w * w + 1j * c * w)
            assert p.amplitude[0] == pytest.approx(closed, rel=1e-8)


@pytest.mark.timeout(60)
def test_the_grazing_curve_follows_amplitude_equals_gap() -> None:
    data = _scenario()
    found = curve_of(data, GRAZING.parent)
    assert found.kind == "grazing" and found.stopped == "reached second_stop"
    assert len(found.points) == 101
    for p in found.points:
        f, gap = p.values[FREQUENCY], p.values["stop.0.gap"]
        assert _amplitude(data, f) == pytest.approx(gap, rel=1e-11), gap
    assert found.points[-1].values["stop.0.gap"] == pytest.approx(0.07, abs=1e-12)
    # Either side: the orbit misses the stop below the curve and strikes it above.
    labels = sorted(
        (value, label) for label, _, value in curve_regions(found, data, GRAZING.parent)
    )
    assert len(labels) == 2
    assert labels[0][1].endswith("misses stop 0") and labels[1][1].endswith("strikes stop 0")


def _cli(*argv: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "vibroimpact", *argv],
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
    )


@pytest.mark.timeout(120)
def test_cli_reports_the_grazing_and_its_curve(tmp_path: Path) -> None:
    data = _scenario()
    done = _cli("continue", str(GRAZING), "--json")
    assert done.returncode == 0, done.stderr
    out = json.loads(done.stdout)
    (touch,) = [b for b in out["bifurcations"] if b["kind"] == "grazing"]
    assert set(touch) == {"kind", "value", "state", "floquet_multipliers", "pair", "time"}
    assert touch["value"] == pytest.approx(_grazing_frequency(data, 0.05), rel=1e-10)
    period = 1 / touch["value"]
    assert touch["pair"] == "stop 0" and 0 <= touch["time"] < period
    plot = tmp_path / "grazing.png"
    done = _cli("curve", str(GRAZING), "--json", "--plot", str(plot))
    assert done.returncode == 0, done.stderr
    points = json.loads(done.stdout)["points"]
    assert len(points) == 101
    for p in points:
        gap = p["values"]["stop.0.gap"]
        assert _amplitude(data, p["values"][FREQUENCY]) == pytest.approx(gap, rel=1e-11)
    assert plot.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


@pytest.mark.timeout(120)
def test_a_curve_whose_branch_meets_no_grazing_says_which_keys_to_widen(tmp_path: Path) -> None:
    # The grazing lies at 0.706 Hz: a search that stops at 0.6 Hz finds none.
    text = GRAZING.read_text(encoding="utf-8").replace(
        "stop = 0.95                             # ... to here",
        "stop = 0.6                              # ... to here",
    )
    assert "stop = 0.6 " in text
    path = tmp_path / "short.toml"
    path.write_text(text, encoding="utf-8")
    done = _cli("curve", str(path))
    assert done.returncode == 2 and "Traceback" not in done.stderr
    (line,) = done.stderr.strip().splitlines()
    assert "no grazing" in line and "[curve] start, stop" in line and "0.6" in line


def _grazing_arc(data: dict[str, Any]) -> tuple[Any, np.ndarray, float, float]:
    """The frequency continuation's arc of the grazing scenario, built as a curve builds
    it (one period, its scales), with the closed form's grazing: the scaled unknowns
    (state, frequency) of the orbit there, the frequency and the touch's instant (s)."""
    from vibroimpact.analysis.continuation import _Arc

    m, k, c, _, gap = _oscillator(data)
    f = _grazing_frequency(data, gap)
    w = 2 * math.pi * f
    theta = math.atan2(c * w, k - m * w * w)
    arc = _Arc(data, FREQUENCY, 1, 1e-10, None, 0.45)
    arc.size = 2
    arc.scale = np.array([gap, w * gap, 0.45])
    # Start off the grazing (1 % below in frequency, the orbit of the closed form).
    state = np.array([gap * math.cos(theta), gap * w * math.sin(theta)])
    unknowns = np.concatenate([state / arc.scale[:2], [0.99 * f / arc.scale[2]]])
    return arc, unknowns, f, (theta / w) % (1 / f)


@pytest.mark.timeout(60)
def test_newton_gives_up_where_the_touch_instant_leaves_the_orbit_s_span(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    # An iterate whose touch instant stands beyond TOUCH_SPANS orbit spans has left the
    # grazing; running the gap to it would integrate for as long (once 1e8 s, 1e9
    # steps). Newton must give up before any run reaches it, and still converge from
    # an instant within the span. Each run of the gap's flow is recorded.
    from vibroimpact.analysis import grazing

    data = _scenario()
    arc, unknowns, f, touch = _grazing_arc(data)
    asked: list[float] = []
    gap_of = grazing._Wall.gap

    def recorded(self: Any, p: float, z: np.ndarray, tau: float) -> Any:
        asked.append(tau)
        return gap_of(self, p, z, tau)

    monkeypatch.setattr(grazing._Wall, "gap", recorded)
    # From the instant within the span: the closed form's grazing.
    found = grazing.locate_grazing(arc, "stop 0", unknowns, tau=touch)
    assert found is not None
    assert found.value == pytest.approx(f, rel=1e-10)
    assert asked and max(asked) <= grazing.TOUCH_SPANS / f
    # From instants 40 orbit spans ahead, 1e8 s ahead, before the section or on it:
    # none, and no run asked.
    for far in (40 / f, 1e8, -0.25 / f, 0.0):
        asked.clear()
        assert grazing.locate_grazing(arc, "stop 0", unknowns, tau=far) is None
        assert asked == []
