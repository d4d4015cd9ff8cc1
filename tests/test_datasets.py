"""The analyses' results as xarray Datasets (vibroimpact.datasets): dimensions,
coordinates and units, values equal to the dataclasses' arrays bit for bit, and a
NetCDF 4 round trip (vi.write_netcdf, h5netcdf: no netCDF C library) that reads back
identical with xarray's default engine, every dtype kept.

Every result comes from a short real analysis of an example (few points, few periods);
a failed point, which no short run produces, is added by hand where padding is tested.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import h5py
import numpy as np
import pytest
import xarray as xr

import vibroimpact as vi
from vibroimpact import analysis as an
from vibroimpact.analysis import (
    AnalysisError,
    Basins,
    BifurcationPoint,
    Branch,
    Section,
    SweepPoint,
    basins,
    bifurcation,
    continue_orbit,
    poincare,
)
from vibroimpact.analysis.datasets import (
    basins_dataset,
    bifurcation_dataset,
    branch_dataset,
    parameter_units,
    section_dataset,
    state_names,
    sweep_dataset,
)
from vibroimpact.scenario.system import SystemScenario

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"
FREQUENCY = "excitation.0.frequency"
AMPLITUDE = "excitation.0.amplitude"


def scenario(name: str) -> dict[str, Any]:
    loaded = vi.load_scenario(EXAMPLES / name)
    assert isinstance(loaded, SystemScenario)
    return dict(loaded.data)


@pytest.fixture(scope="module")
def ball() -> dict[str, Any]:
    return scenario("bouncing_ball_table.toml")


@pytest.fixture(scope="module")
def frf() -> dict[str, Any]:
    return scenario("frf_impact_damper.toml")


@pytest.fixture(scope="module")
def beam() -> dict[str, Any]:
    return scenario("beam_two_dampers.toml")


def round_trip(ds: xr.Dataset, path: Path) -> xr.Dataset:
    """Write ``ds`` with :func:`vibroimpact.write_netcdf`, check the file is NetCDF 4 as
    h5py reads it (int64 as int64, strings as variable-length strings, booleans int8,
    every numeric variable with elements gzip-compressed), read it back with xarray's
    default engine and check it is identical, every dtype kept."""
    vi.write_netcdf(ds, path)
    assert_netcdf4(ds, path)
    with xr.open_dataset(path) as opened:
        back = opened.load()
    xr.testing.assert_identical(back, ds)
    assert {name: back[name].dtype for name in back.variables} == {
        name: ds[name].dtype for name in ds.variables
    }
    return back


def assert_netcdf4(ds: xr.Dataset, path: Path) -> None:
    """``path`` is the NetCDF 4 file of ``ds``: HDF5, each variable stored in its own
    dtype (booleans as int8, strings variable-length), numeric ones compressed."""
    assert path.read_bytes()[:8] == b"\x89HDF\r\n\x1a\n"
    with h5py.File(path, "r") as raw:
        for name, variable in ds.variables.items():
            stored = raw[str(name)]
            kind = variable.dtype.kind
            if kind == "U":
                assert h5py.check_string_dtype(stored.dtype) is not None, name
                assert h5py.check_string_dtype(stored.dtype).length is None, name
            elif kind == "b":
                assert stored.dtype == np.int8 and stored.attrs["dtype"] == "bool", name
            else:
                assert stored.dtype == variable.dtype, name
            if kind in "biuf" and variable.size > 0 and variable.ndim > 0:
                assert (stored.compression, stored.compression_opts) == ("gzip", 4), name
                assert stored.shuffle, name


def assert_attrs(variable: xr.DataArray, units: str | None) -> None:
    assert variable.attrs["long_name"]
    if units is None:
        assert "units" not in variable.attrs, variable.name
    else:
        assert variable.attrs["units"] == units, variable.name


# ------------------------------------------------------------------------ sweep


@pytest.fixture(scope="module")
def frf_sweep(frf: dict[str, Any]) -> list[SweepPoint]:
    return an.sweep(frf, FREQUENCY, [9.0, 10.0, 11.0], direction="both", settle_periods=40)


def test_sweep_dataset_labels_the_points_and_coordinates(
    frf_sweep: list[SweepPoint], tmp_path: Path
) -> None:
    ds = sweep_dataset(frf_sweep, FREQUENCY)
    assert dict(ds.sizes) == {"point": 6, "coordinate": 1}
    assert ds.attrs["parameter"] == FREQUENCY
    assert ds["value"].dims == ("point",)
    assert ds["value"].attrs == {"long_name": FREQUENCY, "units": "Hz", "name": FREQUENCY}
    assert ds["value"].values.tolist() == [9.0, 10.0, 11.0, 11.0, 10.0, 9.0]
    assert ds["direction"].values.tolist() == ["up"] * 3 + ["down"] * 3
    assert ds["coordinate"].values.tolist() == [0]
    for name in ("amplitude", "rms", "linear_amplitude", "reduction"):
        assert ds[name].dims == ("point", "coordinate"), name
        assert_attrs(ds[name], "1" if name == "reduction" else "m")
    for name in ("impacts_per_period", "settled", "error"):
        assert ds[name].dims == ("point",), name
    assert_attrs(ds["impacts_per_period"], "1")
    assert_attrs(ds["settled"], None)
    assert ds["settled"].dtype == bool

    for i, p in enumerate(frf_sweep):
        np.testing.assert_array_equal(ds["amplitude"].values[i], p.amplitude)
        np.testing.assert_array_equal(ds["rms"].values[i], p.rms)
        np.testing.assert_array_equal(ds["linear_amplitude"].values[i], p.linear_amplitude)
        reduction = [math.nan if r is None else r for r in p.to_dict()["reduction"]]
        np.testing.assert_array_equal(ds["reduction"].values[i], reduction)
        assert ds["impacts_per_period"].values[i] == p.impacts_per_period
        assert ds["settled"].values[i] == p.settled
        assert ds["error"].values[i] == ""
    # The run settles at some points and not at others: both booleans go through.
    assert set(ds["settled"].values.tolist()) == {True, False}
    round_trip(ds, tmp_path / "sweep.nc")


def test_sweep_dataset_of_several_coordinates_and_a_failed_point(
    beam: dict[str, Any], tmp_path: Path
) -> None:
    points = an.sweep(beam, FREQUENCY, [5.0, 6.0], settle_periods=10, record_periods=3)
    nan = np.full(3, np.nan)
    failed = SweepPoint(7.0, "up", False, nan, nan, math.nan, points[-1].linear_amplitude, "x")
    points.append(failed)
    ds = sweep_dataset(points, FREQUENCY)
    assert dict(ds.sizes) == {"point": 3, "coordinate": 3}
    np.testing.assert_array_equal(ds["amplitude"].values, np.vstack([p.amplitude for p in points]))
    np.testing.assert_array_equal(ds["rms"].values, np.vstack([p.rms for p in points]))
    assert ds["error"].values.tolist() == ["", "", "x"]
    assert np.isnan(ds["reduction"].values[2]).all()
    assert np.isnan(ds["impacts_per_period"].values[2])
    round_trip(ds, tmp_path / "beam.nc")


def test_sweep_dataset_takes_the_units_it_is_given(frf_sweep: list[SweepPoint]) -> None:
    ds = sweep_dataset(frf_sweep, AMPLITUDE, units="N")
    assert ds["value"].attrs["units"] == "N"
    # Without the scenario an amplitude's unit cannot be told (N or m s-2): none is set.
    assert "units" not in sweep_dataset(frf_sweep, AMPLITUDE)["value"].attrs
    with pytest.raises(AnalysisError, match="no points"):
        sweep_dataset([], FREQUENCY)


# ----------------------------------------------------------------- bifurcation


@pytest.fixture(scope="module")
def ball_bifurcation(ball: dict[str, Any]) -> list[BifurcationPoint]:
    # Gamma = 1.2 (period one) and Gamma = 1.63 (period two, past the flip at 1.5268).
    return bifurcation(ball, AMPLITUDE, [11.772, 16.0], settle_periods=100, sample_periods=4)


def test_bifurcation_dataset_names_the_state_and_pads_with_nan(
    ball_bifurcation: list[BifurcationPoint], tmp_path: Path
) -> None:
    short = BifurcationPoint(18.0, "up", ball_bifurcation[1].strobe[:2].copy())
    failed = BifurcationPoint(20.0, "up", np.zeros((0, 0)), "the run failed")
    points = [*ball_bifurcation, short, failed]
    ds = bifurcation_dataset(points, AMPLITUDE, n=1, k=0)
    assert dict(ds.sizes) == {"point": 4, "sample": 4, "state": 2}
    assert ds["strobe"].dims == ("point", "sample", "state")
    assert ds["state"].values.tolist() == ["structure_displacement_0", "structure_velocity_0"]
    assert ds["state_units"].values.tolist() == ["m", "m s-1"]
    assert ds["sample"].values.tolist() == [1, 2, 3, 4]
    assert ds["value"].values.tolist() == [11.772, 16.0, 18.0, 20.0]
    assert ds["direction"].values.tolist() == ["up"] * 4
    # A parameter whose unit depends on the scenario (base: m s-2) is then not guessed.
    assert "units" not in ds["value"].attrs
    assert ds["value"].attrs["name"] == AMPLITUDE
    assert_attrs(ds["strobe"], None)  # mixed m and m s-1: see state_units
    for i in (0, 1):
        np.testing.assert_array_equal(ds["strobe"].values[i], ball_bifurcation[i].strobe)
    # Period one repeats each period; period two every other one.
    strobe = ds["strobe"].values
    np.testing.assert_allclose(strobe[0, 1:], strobe[0, :-1], rtol=1e-6)
    assert abs(strobe[1, 1, 0] - strobe[1, 0, 0]) > 1e-3
    np.testing.assert_allclose(strobe[1, 2], strobe[1, 0], rtol=1e-4)
    np.testing.assert_array_equal(strobe[2, :2], short.strobe)
    assert np.isnan(strobe[2, 2:]).all() and np.isnan(strobe[3]).all()
    assert ds["sample_count"].values.tolist() == [4, 4, 2, 0]
    assert ds["error"].values.tolist() == ["", "", "", "the run failed"]
    round_trip(ds, tmp_path / "bifurcation.nc")

    given = bifurcation_dataset(points, AMPLITUDE, units="m s-2")
    assert given["state"].values.tolist() == ["displacement_0", "velocity_0"]
    assert given["value"].attrs["units"] == "m s-2"
    np.testing.assert_array_equal(given["strobe"].values, strobe)


def test_bifurcation_dataset_refuses_a_state_of_another_size(
    ball_bifurcation: list[BifurcationPoint],
) -> None:
    with pytest.raises(AnalysisError, match="4 columns"):
        bifurcation_dataset(ball_bifurcation, AMPLITUDE, n=1, k=1)
    with pytest.raises(AnalysisError, match="both n and k"):
        bifurcation_dataset(ball_bifurcation, AMPLITUDE, n=1)


def test_bifurcation_dataset_of_failed_points_only(tmp_path: Path) -> None:
    failed = [BifurcationPoint(v, "down", np.zeros((0, 0)), "no") for v in (1.0, 2.0)]
    ds = bifurcation_dataset(failed, AMPLITUDE, n=1, k=1)
    assert dict(ds.sizes) == {"point": 2, "sample": 1, "state": 4}
    assert np.isnan(ds["strobe"].values).all()
    round_trip(ds, tmp_path / "failed.nc")


# ---------------------------------------------------------------------- section


def test_section_dataset_of_an_impact_damper(frf: dict[str, Any], tmp_path: Path) -> None:
    section = poincare(an.runner(frf), settle_periods=20, periods=10)
    ds = section_dataset(section, 1, 1)
    assert ds.sizes["sample"] == 10 and ds.sizes["state"] == 4
    assert ds.sizes["impact"] == len(section.impact_phase) > 10
    assert ds["strobe"].dims == ("sample", "state")
    assert ds["state"].values.tolist() == [
        "structure_displacement_0",
        "damper_displacement_0",
        "structure_velocity_0",
        "damper_velocity_0",
    ]
    assert ds["state_units"].values.tolist() == ["m", "m", "m s-1", "m s-1"]
    assert ds["sample"].values.tolist() == list(range(1, 11))
    for name, units in (("impact_phase", "rad"), ("impact_speed", "m s-1"), ("impact_pair", None)):
        assert ds[name].dims == ("impact",)
        assert_attrs(ds[name], units)
    np.testing.assert_array_equal(ds["strobe"].values, section.strobe)
    np.testing.assert_array_equal(ds["impact_phase"].values, section.impact_phase)
    np.testing.assert_array_equal(ds["impact_speed"].values, section.impact_speed)
    assert (
        ds["impact_pair"].values.tolist()
        == section.impact_pair
        == ["damper 0"] * len(section.impact_pair)
    )
    assert ds.attrs["structure_coordinates"] == 1 and ds.attrs["dampers"] == 1
    round_trip(ds, tmp_path / "section.nc")


def test_section_dataset_without_impacts(frf: dict[str, Any], tmp_path: Path) -> None:
    # A clearance of 1 m: the loose mass never reaches a wall.
    loose = an.with_parameter(frf, "damper.0.clearance", 1.0)
    section = poincare(an.runner(loose), settle_periods=2, periods=3)
    ds = section_dataset(section, 1, 1)
    assert ds.sizes["impact"] == 0 and ds.sizes["sample"] == 3
    back = round_trip(ds, tmp_path / "quiet.nc")
    assert back["impact_pair"].values.tolist() == []


def test_section_dataset_of_a_beam_with_two_dampers(beam: dict[str, Any], tmp_path: Path) -> None:
    section = poincare(an.runner(beam), settle_periods=2, periods=3)
    ds = section_dataset(section, 3, 2)
    assert ds["state"].values.tolist() == state_names(3, 2)
    assert state_names(3, 2) == [
        "structure_displacement_0",
        "structure_displacement_1",
        "structure_displacement_2",
        "damper_displacement_0",
        "damper_displacement_1",
        "structure_velocity_0",
        "structure_velocity_1",
        "structure_velocity_2",
        "damper_velocity_0",
        "damper_velocity_1",
    ]
    np.testing.assert_array_equal(ds["strobe"].values, section.strobe)
    assert set(ds["impact_pair"].values.tolist()) <= {"damper 0", "damper 1"}
    round_trip(ds, tmp_path / "beam_section.nc")
    with pytest.raises(AnalysisError, match="10 columns"):
        section_dataset(Section(np.zeros((3, 4)), np.zeros(0), np.zeros(0), []), 3, 2)


# ----------------------------------------------------------------------- basins


@pytest.fixture(scope="module")
def ball_basins(ball: dict[str, Any]) -> Basins:
    run = an.runner(ball)
    heights = np.linspace(0.0, 0.03, 3)
    speeds = np.linspace(-0.4, 0.4, 4)
    return basins(run, (0, heights), (1, speeds), settle_periods=60, record_periods=5)


def test_basins_dataset(ball_basins: Basins, tmp_path: Path) -> None:
    x_name, y_name = "structure_displacement.0", "structure_velocity.0"
    ds = basins_dataset(ball_basins, x_name, y_name)
    assert dict(ds.sizes) == {"x": 3, "y": 4}
    assert ds["label"].dims == ("x", "y") and ds["label"].dtype == np.int64
    np.testing.assert_array_equal(ds["label"].values, ball_basins.labels)
    np.testing.assert_array_equal(ds["x"].values, ball_basins.first)
    np.testing.assert_array_equal(ds["y"].values, ball_basins.second)
    assert ds["x"].attrs == {"long_name": x_name, "units": "m", "name": x_name}
    assert ds["y"].attrs == {"long_name": y_name, "units": "m s-1", "name": y_name}
    assert ds.attrs["x_name"] == x_name and ds.attrs["y_name"] == y_name
    assert json.loads(ds.attrs["attractors"]) == ball_basins.attractors
    assert len(ball_basins.attractors) >= 2  # the period-one orbit and a chatter
    label = ds["label"].attrs
    assert label["flag_values"].tolist() == [-3, -2, -1]
    assert label["flag_meanings"].split() == ["inadmissible_start", "run_failed", "not_settled"]
    for words in ("did not settle", "failed", "not admissible", "attractors"):
        assert words in ds.attrs["label_meanings"] and words in label["comment"]
    back = round_trip(ds, tmp_path / "basins.nc")
    assert json.loads(back.attrs["attractors"]) == ball_basins.attractors


def test_basins_dataset_keeps_the_negative_labels(tmp_path: Path) -> None:
    labels = np.array([[-1, -2], [-3, 0]])
    result = Basins(np.array([0.0, 1.0]), np.array([2.0, 3.0]), labels, [])
    ds = basins_dataset(result, "damper_displacement.0", "damper_velocity.0")
    np.testing.assert_array_equal(ds["label"].values, labels)
    assert json.loads(ds.attrs["attractors"]) == []
    round_trip(ds, tmp_path / "labels.nc")


# ----------------------------------------------------------------------- branch


@pytest.fixture(scope="module")
def ball_branch(ball: dict[str, Any]) -> Branch:
    # From Gamma = 1.2 past the flip at Gamma_flip g = 14.978 m/s^2.
    return continue_orbit(ball, AMPLITUDE, stop=16.0, step=0.5, max_points=20)


def test_branch_dataset(ball_branch: Branch, tmp_path: Path) -> None:
    points = ball_branch.points
    ds = branch_dataset(ball_branch, units="m s-2")
    assert dict(ds.sizes) == {
        "point": len(points),
        "state": 2,
        "multiplier": 2,
        "coordinate": 1,
        "bifurcation": 4,
    }
    assert ds.attrs["parameter"] == AMPLITUDE
    assert ds.attrs["periods"] == 1 and ds.attrs["stopped"] == ball_branch.stopped
    assert ds["value"].attrs == {"long_name": AMPLITUDE, "units": "m s-2", "name": AMPLITUDE}
    assert ds["value"].values.tolist() == [p.value for p in points]
    assert ds["state"].values.tolist() == ["structure_displacement_0", "structure_velocity_0"]
    assert ds["orbit_state"].dims == ("point", "state")
    np.testing.assert_array_equal(ds["orbit_state"].values, [p.state for p in points])
    multipliers = np.array([p.floquet_multipliers for p in points])
    assert ds["multiplier_real"].dims == ("point", "multiplier")
    np.testing.assert_array_equal(ds["multiplier_real"].values, multipliers.real)
    np.testing.assert_array_equal(ds["multiplier_imag"].values, multipliers.imag)
    np.testing.assert_array_equal(ds["amplitude"].values, [p.amplitude for p in points])
    assert ds["stable"].values.tolist() == [p.stable for p in points]
    assert ds["impacts_per_period"].values.tolist() == [p.impacts_per_period for p in points]
    assert ds["flags"].values.tolist() == [",".join(p.flags) for p in points]
    for name, units in (
        ("multiplier_real", "1"),
        ("multiplier_imag", "1"),
        ("amplitude", "m"),
        ("impacts_per_period", "1"),
        ("crossing", "m s-2"),
        ("stable", None),
        ("flags", None),
        ("orbit_state", None),
    ):
        assert_attrs(ds[name], units)
    # The flip is flagged, where the multiplier crosses -1, and the branch loses stability.
    (flip,) = [i for i, p in enumerate(points) if "flip" in p.flags]
    assert ds["flags"].values[flip] == "flip"
    crossing = ds["crossing"].sel(bifurcation="flip").values
    assert crossing[flip] == points[flip].crossings["flip"]
    assert abs(crossing[flip] - 14.978) < 0.1
    assert np.isnan(np.delete(crossing, flip)).all()
    assert np.isnan(ds["crossing"].sel(bifurcation="fold").values).all()
    assert bool(ds["stable"].values[0]) and not bool(ds["stable"].values[flip])
    round_trip(ds, tmp_path / "branch.nc")


# ------------------------------------------------------------------------ units


def test_parameter_units(ball: dict[str, Any], frf: dict[str, Any], beam: dict[str, Any]) -> None:
    assert parameter_units(FREQUENCY) == "Hz"
    assert parameter_units("damper.0.clearance") == "m"
    assert parameter_units("damper.1.upper_clearance") == "m"
    assert parameter_units("structure.mass.0.1") == "kg"
    assert parameter_units("structure.stiffness") == "N m-1"
    assert parameter_units("structure.youngs_modulus") == "Pa"
    assert parameter_units("gravity.acceleration") == "m s-2"
    assert parameter_units("initial.structure_velocity.0") == "m s-1"
    assert parameter_units("damper.0.restitution") == "1"
    assert parameter_units("excitation.0.phase") == "rad"
    assert parameter_units(AMPLITUDE) is None  # N or m s-2: it takes the scenario
    assert parameter_units(AMPLITUDE, ball) == "m s-2"  # a base acceleration
    assert parameter_units(AMPLITUDE, frf) == "N"  # a force
    assert parameter_units("damper.0.stiffness", beam) == "N m-1.5"  # hertz-damped
    assert parameter_units("damper.1.stiffness", beam) is None  # rigid: none
    assert parameter_units("damper.0.at", beam) == "m"  # along a cantilever
    assert parameter_units("damper.0.at", frf) == "1"  # a coordinate's index
    assert parameter_units("damper.5.stiffness", beam) is None
    assert parameter_units("solver.max_steps") is None


def test_plot_axes_take_their_units_from_the_datasets() -> None:
    # The plots had a table of their own that labelled every amplitude "N or m/s^2"
    # (user trial); one table now serves both, resolved with the scenario's sections.
    from vibroimpact.analysis.plots import _unit

    harmonic = {"signal": "harmonic", "amplitude": 1.0, "frequency": 1.0}
    force = {"excitation": [{"kind": "force", "at": 0, **harmonic}]}
    base = {"excitation": [{"kind": "base", **harmonic}]}
    assert _unit("excitation.0.amplitude", force) == " (N)"
    assert _unit("excitation.0.amplitude", base) == " (m s-2)"
    assert _unit("damper.0.clearance") == " (m)"
    assert _unit("excitation.0.amplitude") == ""  # unknown without the scenario
