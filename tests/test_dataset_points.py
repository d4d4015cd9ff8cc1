"""sol.to_xarray() of a run that follows points and bending moments carries them (as
the CSV of --out does): over ``point`` and ``moment_position``, labelled by where they
are, with units and the recorded peaks and RMS.

Independent references: the CSV the command line writes of the same scenario, and the
clamped-free beam's closed-form mode shapes and curvatures (roots of 1 + cos cosh = 0)
applied to the modal coordinates."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest

import vibroimpact as vi

LENGTH = 0.4
ROOTS = (1.8751040687119611, 4.6940911329741746, 7.8547574382376126)


def shape(mode: int, x: float, derivative: int = 0) -> float:
    """The clamped-free mode ``cosh bx - cos bx - s (sinh bx - sin bx)`` (|phi(L)| = 2)
    or its second derivative."""
    b = ROOTS[mode] / LENGTH
    c = ROOTS[mode]
    s = (math.cosh(c) + math.cos(c)) / (math.sinh(c) + math.sin(c))
    if derivative == 0:
        return math.cosh(b * x) - math.cos(b * x) - s * (math.sinh(b * x) - math.sin(b * x))
    return b**2 * (math.cosh(b * x) + math.cos(b * x) - s * (math.sinh(b * x) + math.sin(b * x)))


SYSTEM = vi.System(
    structure=vi.Cantilever(
        length=LENGTH,
        section="rectangle",
        width=0.02,
        height=0.004,
        material="aluminium",
        modes=3,
        damping_ratio=0.01,
    ),
    dampers=[
        vi.Damper(
            mass=0.01, at=LENGTH, clearance=5e-4, law="hertz-damped", stiffness=1e9, restitution=0.5
        )
    ],
    excitations=[vi.Force(at=LENGTH, signal=vi.Harmonic(amplitude=1.0, frequency=20.0))],
    solver=vi.Solver(method="dop853", t_end=0.3),
    output=vi.Output(points=[LENGTH, 0.15], moments=[0.0, 0.1], record_from=0.1),
)


def test_the_dataset_holds_the_points_and_moments_with_units() -> None:
    sol = vi.simulate(SYSTEM)
    ds = sol.to_xarray()
    assert list(ds.point.values) == [LENGTH, 0.15]
    assert ds.point.attrs["units"] == "m" and ds.moment_position.attrs["units"] == "m"
    assert ds.point_displacement.dims == ("time", "point")
    assert ds.point_displacement.attrs["units"] == "m"
    assert ds.bending_moment.attrs["units"] == "N m"
    q = sol.structure_displacement
    for x in (LENGTH, 0.15):
        closed = q @ [shape(i, x) for i in range(3)]
        np.testing.assert_allclose(ds.point_displacement.sel(point=x), closed, rtol=1e-9, atol=0)
    r = SYSTEM.structure.resolved()  # type: ignore[union-attr]
    bending = r["youngs_modulus"] * r["second_moment"]
    for x in (0.0, 0.1):
        closed = bending * q @ [shape(i, x, 2) for i in range(3)]
        np.testing.assert_allclose(ds.bending_moment.sel(moment_position=x), closed, rtol=1e-9)
    # The located peak is at least the sampled one, from record_from on.
    recorded = ds.point_displacement.sel(time=slice(0.1, None))
    sampled = np.abs(recorded).max("time").values
    assert np.all(sampled <= ds.point_peak.values * (1 + 1e-12))
    assert ds.point_peak.values == pytest.approx(sampled, rel=1e-2)
    assert ds.moment_rms.attrs["units"] == "N m"


def test_the_dataset_matches_the_command_line_csv(tmp_path: Any, run_cli: Any) -> None:
    (tmp_path / "beam.toml").write_text(SYSTEM.to_toml(), encoding="utf-8")
    done = run_cli("simulate", "beam.toml", "--out", "h.csv")
    assert done.returncode == 0, done.stderr
    table = np.genfromtxt(tmp_path / "h.csv", delimiter=",", names=True)
    ds = vi.simulate(SYSTEM).to_xarray()
    np.testing.assert_allclose(table["t"], ds.time, rtol=1e-12)
    for j, x in enumerate((LENGTH, 0.15)):
        np.testing.assert_allclose(
            table[f"point_displacement_{j}"], ds.point_displacement.sel(point=x), rtol=1e-12
        )
    for j, x in enumerate((0.0, 0.1)):
        np.testing.assert_allclose(
            table[f"bending_moment_{j}"], ds.bending_moment.sel(moment_position=x), rtol=1e-12
        )


def test_an_oscillator_point_is_labelled_by_its_index() -> None:
    system = vi.System(
        structure=vi.Matrices(mass=[[1, 0], [0, 1]], stiffness=[[200, -100], [-100, 200]]),
        excitations=[vi.Force(at=0, signal=vi.Harmonic(amplitude=1.0, frequency=2.0))],
        solver=vi.Solver(method="exact", t_end=1.0),
        output=vi.Output(points=[1]),
    )
    sol = vi.simulate(system)
    ds = sol.to_xarray()
    assert ds.point.attrs["units"] == "1"
    np.testing.assert_array_equal(
        ds.point_displacement.sel(point=1), sol.structure_displacement[:, 1]
    )
    assert "bending_moment" not in ds
    # Nothing followed: nothing added.
    plain = vi.simulate(system.replace(output=None)).to_xarray()
    assert "point" not in plain.dims and "point_displacement" not in plain
