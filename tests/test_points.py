"""Amplitudes at points of the structure (``[output] points``): a cantilever's
deflection where a user measures it, not its modal coordinates.

References: the forced linear beam's steady deflection at a point, ``|w . Q|`` with
``Q`` solved here from the modal equations (frequencies and shapes from the public
mode functions, each mode's equation written here), and the RMS of a sinusoid,
amplitude / sqrt 2. Where the beam carries dampers, the reductions at the tip are
checked against the history's own deflection there, sampled densely.
"""

from __future__ import annotations

import json
import math
import time
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import xarray as xr

import vibroimpact as vi
from vibroimpact.analysis import orbit, runner, sweep
from vibroimpact.analysis.datasets import sweep_dataset

LENGTH, YOUNG, SECOND, MASS_PER_LENGTH, ZETA = 0.5, 7e10, 1e-10, 0.27, 0.01
FORCE = 0.5

BEAM: dict[str, Any] = {
    "kind": "cantilever",
    "length": LENGTH,
    "youngs_modulus": YOUNG,
    "second_moment": SECOND,
    "mass_per_length": MASS_PER_LENGTH,
    "modes": 3,
    "damping_ratio": ZETA,
}


def tip_force(frequency: float) -> dict[str, Any]:
    return {
        "kind": "force",
        "at": LENGTH,
        "signal": "harmonic",
        "amplitude": FORCE,
        "frequency": frequency,
    }


def beam_toml(frequency: float = 10.0) -> str:
    """The beam and its tip force as TOML sections."""
    return f"""
[structure]
kind = "cantilever"
length = {LENGTH}
youngs_modulus = {YOUNG}
second_moment = {SECOND}
mass_per_length = {MASS_PER_LENGTH}
modes = 3
damping_ratio = {ZETA}
[[excitation]]
kind = "force"
at = {LENGTH}
signal = "harmonic"
amplitude = {FORCE}
frequency = {frequency}
"""


def linear_deflection(frequency: float, at: float, modes: int = 3, derivative: int = 0) -> float:
    """The steady deflection amplitude (m) at ``at`` of the beam alone under the tip
    force (of its ``derivative``-th derivative in x, 1/m^k): each mode ``q_i'' + 2 zeta
    w_i q_i' + w_i^2 q_i = phi_i(L) F / (rho A L)`` with shapes normalised to ``int
    phi_i^2 dx = L`` (checked below)."""
    w = 2 * math.pi * frequency
    total = 0j
    for i in range(1, modes + 1):
        # Density MASS_PER_LENGTH over an area of 1 m^2: rho A is the mass per length.
        mode = vi.cantilever_mode(LENGTH, YOUNG, SECOND, MASS_PER_LENGTH, 1.0, i)
        assert mode.modal_mass == pytest.approx(MASS_PER_LENGTH * LENGTH, rel=1e-12)
        wi = math.sqrt(mode.modal_stiffness / mode.modal_mass)
        modal_force = vi.cantilever_mode_shape(LENGTH, i, LENGTH) * FORCE
        q = modal_force / mode.modal_mass / (wi * wi - w * w + 2j * ZETA * wi * w)
        total += vi.cantilever_mode_shape(LENGTH, i, at, derivative) * q
    return abs(total)


def test_the_shapes_normalisation_the_reference_assumes() -> None:
    # int_0^L phi^2 dx = L: the modal mass is then rho A L, as linear_deflection takes it.
    xs, ws = np.polynomial.legendre.leggauss(60)
    x = 0.5 * LENGTH * (xs + 1)
    for mode in (1, 2, 3):
        phi = np.array([vi.cantilever_mode_shape(LENGTH, mode, float(v)) for v in x])
        assert 0.5 * LENGTH * float(np.sum(ws * phi * phi)) == pytest.approx(LENGTH, rel=1e-10)


@pytest.mark.parametrize("method", ["exact", "dop853", "rk4"])
def test_a_run_follows_the_deflection_at_its_points(method: str) -> None:
    frequency, points = 9.0, [LENGTH, 0.3, 0.1]
    sol = vi.simulate_system(
        BEAM,
        excitation=[tip_force(frequency)],
        t_end=30.0,
        method=method,
        dt=1e-4 if method == "rk4" else None,
        rtol=1e-10,
        record_from=28.0,
        points=points,
        history=False,
        max_steps=2_000_000,
    )
    assert list(sol.points) == points
    for at, peak, rms in zip(points, sol.point_peak, sol.point_rms, strict=True):
        expected = linear_deflection(frequency, at)
        # Transients have decayed to e^-(zeta w1 28 s) ~ 1e-9 of the start.
        assert peak == pytest.approx(expected, rel=1e-6), at
        assert rms == pytest.approx(expected / math.sqrt(2), rel=1e-5), at
    # The tip is no coordinate: its deflection is not the first mode's amplitude.
    assert sol.point_peak[0] > 1.5 * sol.peak[0]


def test_a_sweep_reports_and_stores_the_deflection_at_its_points() -> None:
    data = {
        "structure": BEAM,
        "excitation": [tip_force(8.0)],
        "solver": {"method": "exact", "t_end": 1.0},
        "output": {"points": [LENGTH, 0.25]},
    }
    values = [8.0, 10.0, 14.0]
    found = sweep(data, "excitation.0.frequency", values, settle_periods=400, record_periods=5)
    for p in found:
        for j, at in enumerate((LENGTH, 0.25)):
            expected = linear_deflection(p.value, at)
            assert p.linear_point_amplitude[j] == pytest.approx(expected, rel=1e-9)
            assert p.point_amplitude[j] == pytest.approx(expected, rel=1e-6)
            assert p.point_rms[j] == pytest.approx(expected / math.sqrt(2), rel=1e-5)
        d = p.to_dict()
        assert d["points"] == [LENGTH, 0.25]
        assert d["point_reduction"][0] == pytest.approx(0.0, abs=1e-5)
    ds = sweep_dataset(found, "excitation.0.frequency")
    assert list(ds["at"].values) == [LENGTH, 0.25]
    assert ds["point_amplitude"].dims == ("point", "at")
    np.testing.assert_allclose(
        ds["point_amplitude"].values, [p.point_amplitude for p in found], rtol=0
    )


def test_an_orbit_and_a_study_report_their_points(tmp_path: Path, run_cli: Any) -> None:
    frequency = 11.0
    data = {
        "structure": BEAM,
        "excitation": [tip_force(frequency)],
        "solver": {"method": "exact", "t_end": 1.0},
        "output": {"points": [LENGTH]},
    }
    found = orbit(runner(data))
    assert found.converged
    assert found.point_amplitude[0] == pytest.approx(linear_deflection(frequency, LENGTH), 1e-8)
    scenario = tmp_path / "beam.toml"
    scenario.write_text(
        beam_toml(frequency)
        + f"""
[solver]
method = "exact"
t_end = 30.0
[output]
points = [{LENGTH}, 0.2]
[study]
analysis = "run"
record_from = 28.0
metrics = ["peak", "rms"]
[study.axes]
"excitation.0.frequency" = [7.0, {frequency}]
""",
        encoding="utf-8",
    )
    done = run_cli("study", str(scenario), "--out", "beam.nc")
    assert done.returncode == 0, done.stderr
    with xr.open_dataset(tmp_path / "beam.nc") as ds:
        assert list(ds["at"].values) == [LENGTH, 0.2]
        for f in (7.0, frequency):
            for at in (LENGTH, 0.2):
                peak = float(ds["point_peak"].sel({"excitation.0.frequency": f, "at": at}))
                assert peak == pytest.approx(linear_deflection(f, at), rel=1e-6)
        assert ds["peak"].sizes["coordinate"] == 3
    shown = run_cli("orbit", str(scenario), "--json")
    assert shown.returncode == 0, shown.stderr
    summary = json.loads(shown.stdout)
    assert summary["points"] == [LENGTH, 0.2]
    assert summary["point_amplitude"][0] == pytest.approx(
        linear_deflection(frequency, LENGTH), rel=1e-8
    )


def test_with_dampers_the_points_peaks_are_the_history_s(tmp_path: Path) -> None:
    # Dampers at the tip and mid-span: no closed form, but the deflection there is
    # the history's (sampled every step of a fine dop853 run), whose largest value
    # the located peak may only exceed by what falls between samples.
    sol = vi.simulate_system(
        BEAM,
        damper=[
            {
                "mass": 0.01,
                "at": LENGTH,
                "clearance": 2e-4,
                "law": "hertz-damped",
                "stiffness": 1e7,
                "restitution": 0.6,
            }
        ],
        excitation=[tip_force(8.0)],
        t_end=1.0,
        method="dop853",
        rtol=1e-10,
        record_from=0.5,
        points=[LENGTH, 0.25],
        max_steps=2_000_000,
    )
    recorded = sol.t >= 0.5
    for j, at in enumerate((LENGTH, 0.25)):
        sampled = float(np.max(np.abs(sol.displacement_at(at)[recorded])))
        assert sampled <= sol.point_peak[j] <= sampled * (1 + 1e-4)
        deflection = sol.displacement_at(at)[recorded]
        times = sol.t[recorded]
        mean_square = np.trapezoid(deflection**2, times) / (times[-1] - times[0])
        assert sol.point_rms[j] == pytest.approx(math.sqrt(mean_square), rel=1e-3)


def test_points_off_the_structure_are_refused_naming_the_key(run_cli: Any) -> None:
    with pytest.raises(ValueError, match=r"\[output\] points\[1\] must be a position along"):
        vi.simulate_system(BEAM, t_end=0.1, method="dop853", points=[0.1, 0.6])
    oscillator = {"kind": "oscillator", "mass": 1.0, "stiffness": 1.0}
    for key, given, message in (
        ("points", [1], r"points\[0\] must be a coordinate index"),
        ("moments", [0], r"\[output\] moments: only a cantilever"),
    ):
        with pytest.raises(ValueError, match=message):
            vi.simulate_system(oscillator, t_end=0.1, method="dop853", **{key: given})
    with pytest.raises(ValueError, match=r"\[output\] moments\[0\] must be a position along"):
        vi.simulate_system(BEAM, t_end=0.1, method="dop853", moments=[-0.1])
    with pytest.raises(ValueError, match=r"\[output\] points: must be an array of numbers"):
        vi.simulate_system(BEAM, t_end=0.1, method="dop853", points="tip")
    with pytest.raises(ValueError, match=r"\[output\] points, moments: 10001 in all"):
        vi.simulate_system(BEAM, t_end=0.1, method="dop853", points=[0.1] * (vi.MAX_POINTS + 1))


def test_loads_of_one_frequency_add_as_phasors_in_the_linear_reference() -> None:
    # Two equal tip loads in quadrature: sqrt 2 of one; in opposition: nothing (user
    # trial: their amplitudes were added, a 29 % "reduction" with no damper at all).
    for phase, factor in ((math.pi / 2, math.sqrt(2)), (math.pi, 0.0)):
        second = tip_force(10.0) | {"phase": phase}
        data = {
            "structure": BEAM,
            "excitation": [tip_force(10.0), second],
            "solver": {"method": "exact", "t_end": 1.0},
            "output": {"points": [LENGTH]},
        }
        (found,) = sweep(data, "excitation.0.amplitude", [FORCE], settle_periods=300)
        expected = factor * linear_deflection(10.0, LENGTH)
        assert found.linear_point_amplitude[0] == pytest.approx(expected, rel=1e-9, abs=1e-15)
        assert found.point_amplitude[0] == pytest.approx(expected, rel=1e-5, abs=1e-12)


def test_points_without_a_window_record_the_whole_run(tmp_path: Path, run_cli: Any) -> None:
    sol = vi.simulate_system(
        BEAM,
        excitation=[tip_force(9.0)],
        t_end=0.5,
        method="dop853",
        rtol=1e-10,
        points=[LENGTH],
    )
    sampled = float(np.max(np.abs(sol.displacement_at(LENGTH))))
    assert sampled <= sol.point_peak[0] <= sampled * (1 + 1e-6)
    assert sol.recorded_time == pytest.approx(0.5)
    with pytest.raises(ValueError, match=r"\[output\] points: 0.25 is given twice"):
        vi.simulate_system(BEAM, t_end=0.1, method="dop853", points=[0.25, 0.5, 0.25])
    # The CSV carries the deflection at each point.
    scenario = tmp_path / "beam.toml"
    scenario.write_text(
        beam_toml() + "[solver]\nmethod = 'dop853'\nt_end = 0.2\n[output]\npoints = [0.5, 0.2]\n",
        encoding="utf-8",
    )
    done = run_cli("simulate", str(scenario), "--out", "h.csv")
    assert done.returncode == 0, done.stderr
    table = np.genfromtxt(tmp_path / "h.csv", delimiter=",", names=True)
    assert table.dtype.names[-2:] == ("point_displacement_0", "point_displacement_1")
    modes = np.column_stack([table[f"structure_displacement_{i}"] for i in range(3)])
    shape = [vi.cantilever_mode_shape(LENGTH, i + 1, 0.2) for i in range(3)]
    np.testing.assert_allclose(table["point_displacement_1"], modes @ shape, rtol=1e-12, atol=0)


def test_a_study_records_the_scenario_s_window_and_maps_a_point(
    tmp_path: Path, run_cli: Any
) -> None:
    scenario = tmp_path / "beam.toml"
    scenario.write_text(
        beam_toml()
        + """
[solver]
method = "exact"
t_end = 2.0
[output]
record_from = 1.5
points = [0.5]
[study]
analysis = "run"
metrics = ["peak"]
[study.axes]
"excitation.0.frequency" = [9.0, 10.0]
"excitation.0.amplitude" = [0.25, 0.5]
""",
        encoding="utf-8",
    )
    done = run_cli("study", str(scenario), "--out", "s.nc", "--plot", "map.png")
    assert done.returncode == 0, done.stderr
    assert (tmp_path / "map.png").stat().st_size > 0
    # The run the study made at 10 Hz, 0.5 N is the scenario's own: the same window.
    sol = exact_run(10.0, 2.0, 1.5, points=[LENGTH])
    with xr.open_dataset(tmp_path / "s.nc") as ds:
        peak = ds["point_peak"].sel(
            {"excitation.0.frequency": 10.0, "excitation.0.amplitude": 0.5, "at": LENGTH}
        )
        assert float(peak) == sol.point_peak[0]
    refused = run_cli("study", str(scenario), "--out", "t.nc", "--plot", "m.png", "--metric", "x")
    assert refused.returncode == 2
    assert "point_peak" in refused.stderr


def test_a_failed_sweep_point_is_strict_json(tmp_path: Path, run_cli: Any) -> None:
    # Each point's 25 periods take some 1,250 steps of 2 ms, over max_steps (the file's own
    # run, 500 steps, within it): every point's run stops there.
    scenario = tmp_path / "beam.toml"
    scenario.write_text(
        beam_toml()
        + """
[solver]
method = "rk4"
dt = 2e-3
t_end = 1.0
max_steps = 600
[output]
points = [0.5]
[sweep]
parameter = "excitation.0.frequency"
start = 9.0
stop = 10.0
count = 2
settle_periods = 20
record_periods = 5
""",
        encoding="utf-8",
    )
    done = run_cli("sweep", str(scenario), "--json")
    # Every point failed: exit 1 (as bifurcation's), the JSON of each point's error first.
    assert done.returncode == 1, done.stderr
    assert "sweep: the run failed at every value" in done.stderr

    def refuse(constant: str) -> None:
        raise AssertionError(f"{constant} is no JSON")

    points = json.loads(done.stdout, parse_constant=refuse)["points"]
    assert all(p["error"] for p in points)
    assert points[0]["impacts_per_period"] is None


def exact_run(frequency: float, t_end: float, record_from: float, **more: Any) -> Any:
    """The beam alone under the tip force, by the exact flow, reduced from ``record_from``."""
    return vi.simulate_system(
        more.pop("structure", BEAM),
        excitation=[tip_force(frequency)],
        t_end=t_end,
        method="exact",
        record_from=record_from,
        history=False,
        **more,
    )


def linear_moment(frequency: float, at: float) -> float:
    """The steady bending moment amplitude (N m) ``E I w''`` at ``at`` of the beam
    alone under the tip force, mode by mode as :func:`linear_deflection`."""
    return YOUNG * SECOND * linear_deflection(frequency, at, derivative=2)


def test_bending_moments_are_followed_in_runs_sweeps_and_studies(
    tmp_path: Path, run_cli: Any
) -> None:
    # Quasi-static first: at 0.2 Hz, far below the first mode (11.4 Hz), the root
    # carries the tip force's moment F L, to the few percent that three modes and
    # the dynamic factor 1/(1 - (0.2/11.4)^2) leave.
    slow = exact_run(0.2, 60.0, 50.0, structure=BEAM | {"modes": 8}, moments=[0.0])
    assert slow.moment_peak[0] == pytest.approx(FORCE * LENGTH, rel=2e-2)
    sol = exact_run(9.0, 30.0, 28.0, points=[LENGTH], moments=[0.0, 0.2])
    for at, peak, rms in zip((0.0, 0.2), sol.moment_peak, sol.moment_rms, strict=True):
        assert peak == pytest.approx(linear_moment(9.0, at), rel=1e-6)
        assert rms == pytest.approx(linear_moment(9.0, at) / math.sqrt(2), rel=1e-5)
    assert sol.point_peak[0] == pytest.approx(linear_deflection(9.0, LENGTH), rel=1e-6)
    data = {
        "structure": BEAM,
        "excitation": [tip_force(8.0)],
        "solver": {"method": "exact", "t_end": 1.0},
        "output": {"moments": [0.0]},
    }
    found = sweep(data, "excitation.0.frequency", [8.0, 14.0], settle_periods=400, record_periods=5)
    for p in found:
        assert p.linear_moment_amplitude[0] == pytest.approx(linear_moment(p.value, 0.0), 1e-9)
        assert p.moment_amplitude[0] == pytest.approx(linear_moment(p.value, 0.0), rel=1e-5)
        assert p.to_dict()["moments"] == [0.0]
    ds = sweep_dataset(found, "excitation.0.frequency")
    assert ds["moment_amplitude"].dims == ("point", "moment_at")
    assert ds["moment_amplitude"].attrs["units"] == "N m"
    scenario = tmp_path / "beam.toml"
    scenario.write_text(
        beam_toml(9.0)
        + """
[solver]
method = "exact"
t_end = 30.0
[output]
record_from = 28.0
moments = [0.0]
[study]
analysis = "run"
metrics = ["peak"]
[study.axes]
"excitation.0.frequency" = [9.0]
""",
        encoding="utf-8",
    )
    done = run_cli("study", str(scenario), "--out", "m.nc")
    assert done.returncode == 0, done.stderr
    with xr.open_dataset(tmp_path / "m.nc") as ds:
        assert float(ds["moment_peak"].squeeze()) == pytest.approx(linear_moment(9.0, 0.0), 1e-6)
    csv = run_cli("simulate", str(scenario), "--out", "h.csv")
    assert csv.returncode == 0, csv.stderr
    table = np.genfromtxt(tmp_path / "h.csv", delimiter=",", names=True)
    assert float(np.max(np.abs(table["bending_moment_0"][table["t"] >= 28.0]))) == pytest.approx(
        linear_moment(9.0, 0.0), rel=1e-3
    )


def test_a_study_moves_a_damper_and_the_force_along_the_beam(tmp_path: Path, run_cli: Any) -> None:
    # Where to put the damper: each run is the scenario written with that position,
    # bit for bit; a position off the beam fails its run alone, naming the key.
    damper = {
        "mass": 0.01,
        "clearance": 2e-4,
        "law": "hertz-damped",
        "stiffness": 1e7,
        "restitution": 0.6,
    }
    scenario = tmp_path / "beam.toml"
    scenario.write_text(
        beam_toml(11.0)
        + """
[[damper]]
mass = 0.01
at = 0.5
clearance = 2e-4
law = "hertz-damped"
stiffness = 1e7
restitution = 0.6
[solver]
method = "dopri5"
t_end = 0.5
[output]
record_from = 0.25
points = [0.5]
[study]
analysis = "run"
# Without the RMS the run below keeps: the same bits all the same.
metrics = ["peak"]
[study.axes]
"damper.0.at" = [0.2, 0.45, 0.6]
"excitation.0.at" = [0.3, 0.5]
""",
        encoding="utf-8",
    )
    done = run_cli("study", str(scenario), "--out", "at.nc")
    assert done.returncode == 0, done.stderr
    assert "damper 0 at must be a position along the beam in [0, 0.5] m, got 0.6" in done.stdout
    with xr.open_dataset(tmp_path / "at.nc") as ds:
        assert ds["damper.0.at"].attrs["units"] == "m"
        for at in (0.2, 0.45):
            for force_at in (0.3, 0.5):
                sol = vi.simulate_system(
                    BEAM,
                    damper=[damper | {"at": at}],
                    excitation=[tip_force(11.0) | {"at": force_at}],
                    t_end=0.5,
                    method="dopri5",
                    record_from=0.25,
                    points=[LENGTH],
                    history=False,
                )
                chosen = {"damper.0.at": at, "excitation.0.at": force_at, "at": LENGTH}
                assert float(ds["point_peak"].sel(chosen)) == sol.point_peak[0]
        assert np.isnan(ds["point_peak"].sel({"damper.0.at": 0.6})).all()


def test_moment_trial_fixes(tmp_path: Path, run_cli: Any) -> None:
    # A CSV of 10,000 moment columns over 2e5 fixed steps: 15 GB written in 9 minutes
    # (user trial). Refused before the run, naming --out.
    many = ", ".join(f"{LENGTH * i / 9000:.6f}" for i in range(9000))
    scenario = tmp_path / "many.toml"
    scenario.write_text(
        beam_toml() + f"[solver]\nmethod = 'rk4'\ndt = 1e-5\nt_end = 2.0\n"
        f"[output]\nmoments = [{many}]\n",
        encoding="utf-8",
    )
    started = time.monotonic()
    done = run_cli("simulate", str(scenario), "--out", "big.csv")
    assert done.returncode == 2 and "Traceback" not in done.stderr
    assert "--out: the history would hold" in done.stderr and "MiB" in done.stderr
    assert time.monotonic() - started < 20 and not (tmp_path / "big.csv").exists()
    # The moment at a free tip is round-off: no reduction of it (it read -17.5).
    data = {
        "structure": BEAM,
        "excitation": [tip_force(8.0)],
        "solver": {"method": "exact", "t_end": 1.0},
        "output": {"moments": [0.0, LENGTH]},
    }
    (found,) = sweep(data, "excitation.0.frequency", [8.0], settle_periods=20, record_periods=2)
    assert found.linear_moment_amplitude[1] < 1e-12 * found.linear_moment_amplitude[0]
    assert found.to_dict()["moment_reduction"][1] is None
    assert found.to_dict()["moment_reduction"][0] is not None
    assert np.isnan(sweep_dataset([found], "f")["moment_reduction"].values[0, 1])
    # A study asks for the moments by name; without [output] moments it is told why.
    text = beam_toml(9.0) + (
        '[solver]\nmethod = "exact"\nt_end = 1.0\n[output]\nmoments = [0.0]\npoints = [0.25]\n'
        '[study]\nanalysis = "run"\nmetrics = ["moment_rms", "point_rms"]\n'
        '[study.axes]\n"excitation.0.frequency" = [9.0, 10.0]\n'
    )
    scenario.write_text(text, encoding="utf-8")
    done = run_cli("study", str(scenario), "--out", "m.nc")
    assert done.returncode == 0, done.stderr
    with xr.open_dataset(tmp_path / "m.nc") as ds:
        assert ds["moment_rms"].dims == ("excitation.0.frequency", "moment_at")
        # A cantilever's points are positions along it, in metres (the coordinate had
        # no units).
        assert ds["at"].attrs["units"] == ds["moment_at"].attrs["units"] == "m"
        assert ds["point_rms"].attrs["units"] == "m"
    scenario.write_text(text.replace("moments = [0.0]\n", ""), encoding="utf-8")
    done = run_cli("study", str(scenario), "--out", "n.nc")
    assert done.returncode == 2
    assert "[study] metrics: moment_rms needs [output] moments" in done.stderr
    # With moments and no points, the sweep's table shows the first moment's.
    scenario.write_text(
        beam_toml() + '[solver]\nmethod = "exact"\nt_end = 1.0\n[output]\nmoments = [0.0]\n'
        '[sweep]\nparameter = "excitation.0.frequency"\nstart = 8.0\nstop = 9.0\ncount = 2\n'
        "settle_periods = 400\nrecord_periods = 2\n",
        encoding="utf-8",
    )
    done = run_cli("sweep", str(scenario))
    assert done.returncode == 0, done.stderr
    assert "(bending moment amplitude at [output] moments[0] = 0 m, N m)" in done.stdout
    row = next(line for line in done.stdout.splitlines() if line.strip().startswith("8 "))
    assert float(row.split()[2]) == pytest.approx(linear_moment(8.0, 0.0), rel=1e-4)
