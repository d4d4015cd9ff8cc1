"""An adversarial pass over the typed model and the public calls (2026-12-02): every bad
input named and refused as a ValueError, and no public run without a bound. Each case
was a bare TypeError, a message naming nothing, or a run of hours at the probe."""

from __future__ import annotations

import os
import time
from pathlib import Path

import numpy as np
import pytest

import vibroimpact as vi
from vibroimpact import study as st
from vibroimpact.netcdf import write_netcdf
from vibroimpact.system import prepare_system


def _forced() -> vi.System:
    return vi.System(
        structure=vi.Oscillator(mass=1.0, stiffness=3947.8, damping=2.513),
        dampers=[vi.Damper(mass=0.05, at=0, clearance=0.005, law="rigid", restitution=0.6)],
        excitations=[vi.Force(at=0, signal=vi.Harmonic(amplitude=5.0, frequency=10.0))],
    )


def _prepared(system: vi.System) -> vi.PreparedSystem:
    prepared = prepare_system(
        **system.model_sections(),
        solver={"method": "exact", "t_end": 1.0},
        output={},
        base_dir=None,
    )
    return vi.PreparedSystem(prepared.binding_spec(), **prepared.method_arguments())


@pytest.mark.parametrize(
    ("call", "hint"),
    [
        (lambda: _forced().to_toml(solvr=None), "solver"),
        (lambda: vi.System.from_dict({"structure": {}}, basedir=None), "base_dir"),
        (lambda: st.run(None, Path("x.nc"), thread=2), "threads"),  # type: ignore[arg-type]
        (lambda: write_netcdf(None, pth="x.nc"), "path"),  # type: ignore[call-arg]
    ],
)
def test_a_misspelt_keyword_is_a_value_error_with_the_closest_name(call, hint: str) -> None:
    with pytest.raises(vi.KeywordError, match=f"did you mean '{hint}'"):
        call()


def test_a_numpy_time_is_no_number_of_seconds() -> None:
    # np.timedelta64 is an integer to NumPy; int() of one raised a bare TypeError.
    with pytest.raises(ValueError, match=r"t_end: must be a number"):
        vi.simulate(_forced(), t_end=np.timedelta64(1, "s"))
    with pytest.raises(ValueError, match=r"\[structure\] mass: must be a number"):
        vi.System(structure=vi.Oscillator(mass=np.timedelta64(1, "s"), stiffness=1.0))


def test_bad_tables_and_file_names_are_named() -> None:
    head = {"structure": {"kind": "oscillator", "mass": 1.0, "stiffness": 1.0}}
    with pytest.raises(ValueError, match=r"excitation must be a list of tables"):
        vi.System.from_dict({**head, "excitation": "abc"})
    with pytest.raises(ValueError, match=r"\[\[excitation\]\] 0: must be a table"):
        vi.System.from_dict({**head, "excitation": ["ab"]})
    with pytest.raises(ValueError, match=r"file: '.*rec\\x00.csv' holds a null character"):
        vi.System(
            structure=vi.Oscillator(mass=1.0, stiffness=1.0),
            excitations=[vi.Force(at=0, signal=vi.Recorded(file="rec\x00.csv"))],
        )
    with pytest.raises(ValueError, match=r"file: must be a string"):
        vi.System(
            structure=vi.Oscillator(mass=1.0, stiffness=1.0),
            excitations=[vi.Force(at=0, signal=vi.Recorded(file=b"rec.csv"))],  # type: ignore[arg-type]
        )


def test_a_file_name_toml_cannot_hold_is_refused_by_to_toml(tmp_path: Path) -> None:
    # A name that is not UTF-8 (legal on Linux) runs from Python; its TOML had failed
    # with a UnicodeEncodeError naming nothing.
    raw = os.fsencode(tmp_path) + b"/\xff.csv"
    with open(raw, "wb") as f:
        f.write(b"0,0\n0.5,1\n1,0\n")
    system = vi.System(
        structure=vi.Oscillator(mass=1.0, stiffness=3947.8, damping=2.513),
        excitations=[vi.Force(at=0, signal=vi.Recorded(file=os.fsdecode(raw)))],
    )
    assert vi.simulate(system, method="dop853", t_end=0.5, history=False).steps > 0
    with pytest.raises(ValueError, match=r"\[\[excitation\]\] 0 file: .* is not UTF-8"):
        system.to_toml()


@pytest.mark.timeout(20)
def test_the_tangent_runs_are_refused_before_a_step_where_too_long() -> None:
    # vi.tangent_map and vi.lyapunov_spectrum had run at t_end = 1e300 until killed
    # (memory growing); simulate refuses that length at once, and so do they now.
    prepared = _prepared(_forced())
    start = time.perf_counter()
    with pytest.raises(ValueError, match=r"^t_end = 1e\+300 s spans .* more than max_steps"):
        vi.tangent_map(prepared, [0.0, 0.0, 0.0, 0.0], 1e300)
    with pytest.raises(ValueError, match=r"^block_time x blocks = 1e\+300 s spans"):
        vi.lyapunov_spectrum(prepared, [0.0, 0.0, 0.0, 0.0], 1e300, 1)
    with pytest.raises(
        ValueError,
        match=r"^block_time x blocks = 10000000000.0 s spans .* shorten block_time x blocks",
    ):
        vi.lyapunov_spectrum(prepared, [0.0, 0.0, 0.0, 0.0], 1e4, 1_000_000)
    assert time.perf_counter() - start < 5.0
    # A run within the limits goes on as before: the map of one forcing period.
    found = vi.tangent_map(prepared, [0.0, 0.0, 0.0, 0.0], 0.1)
    assert np.asarray(found["matrix"]).shape == (16,)


def test_a_study_over_the_runs_limit_gives_its_whole_count() -> None:
    # "would make 1e+07 runs ..., more than 10,000,000" had read as the limit itself.
    from vibroimpact.study.settings import study_settings

    axes = {
        "excitation.0.frequency": {"start": 1.0, "stop": 2.0, "count": 10001},
        "damper.0.clearance": {"start": 1e-3, "stop": 2e-3, "count": 1001},
    }
    with pytest.raises(ValueError, match=r"would make 10,011,001 runs .* more than 10,000,000"):
        study_settings({"axes": axes})


def test_a_periodic_analysis_names_a_negative_forcing_frequency() -> None:
    # It had said only that a periodic analysis needs a harmonic excitation.
    sections = _forced().to_dict()
    sections["excitation"][0]["frequency"] = -10.0
    for analysis in (vi.orbit, vi.lyapunov):
        with pytest.raises(
            ValueError, match=r"^excitation 0\.frequency: must be finite and >= 0 Hz"
        ):
            analysis(sections)


@pytest.mark.parametrize("count", [-1, 0, 10_000_001])
def test_a_study_axis_count_is_told_one_range(count: int) -> None:
    # A studies probe: -1 was told [0, 2^63 - 1], and 0 then refused as ">= 1".
    from vibroimpact.study.settings import study_settings

    axes = {"damper.0.clearance": {"start": 1e-3, "stop": 2e-3, "count": count}}
    with pytest.raises(
        ValueError, match=rf"count: must be a whole number in \[1, 10,000,000\], got {count}$"
    ):
        study_settings({"axes": axes})


def test_a_drawn_path_no_study_can_vary_is_named_as_drawn() -> None:
    # It had been named "study axis" where [study.random] gave it.
    sections = _forced().to_dict()
    sections["solver"] = {"method": "exact", "t_end": 0.5}
    sections["study"] = {
        "axes": {"damper.0.clearance": [0.004, 0.005]},
        "random": {"damper.0.colour": {"uniform": [0.01, 0.02]}},
        "samples": 2,
    }
    with pytest.raises(
        ValueError, match=r"\[study.random\] 'damper.0.colour': not a path a study can vary"
    ):
        vi.study_of(sections)
