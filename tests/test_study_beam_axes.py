"""A study over a cantilever's section or density (``structure.height``, ...): each run
is the single run of the beam with that dimension, bit for bit, and an axis the beam
cannot take is refused naming it."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import vibroimpact as vi
from vibroimpact import study as st
from vibroimpact.study import StudyError

BEAM = """
[structure]
kind = "cantilever"
length = 0.5
{section}
material = "steel"
modes = 2

[[damper]]
mass = 0.02
at = 0.5
clearance = 5e-4
law = "hertz-damped"
stiffness = 1e8
restitution = 0.6

[[excitation]]
kind = "force"
at = 0.5
signal = "harmonic"
amplitude = 0.5
frequency = 16.0

[solver]
method = "dopri5"
t_end = 0.3

[output]
record_from = 0.0
"""
RECTANGLE = 'section = "rectangle"\nwidth = 0.025\nheight = 0.005'
TUBE = 'section = "tube"\nouter_diameter = 0.012\ninner_diameter = 0.008'


def study_text(section: str, axes: str) -> str:
    return (
        BEAM.format(section=section)
        + '\n[study]\nanalysis = "run"\nmetrics = ["peak", "impacts"]\n\n[study.axes]\n'
        + axes
    )


@pytest.mark.parametrize(
    ("section", "key", "line", "values"),
    [
        (RECTANGLE, "height", "height = 0.005", (0.004, 0.005, 0.006)),
        (TUBE, "inner_diameter", "inner_diameter = 0.008", (0.0, 0.004, 0.008)),
    ],
)
def test_each_run_is_the_single_run_of_the_beam_with_that_dimension(
    section: str, key: str, line: str, values: tuple[float, ...], tmp_path: Path
) -> None:
    # Which bug: the dimension's value not reaching the core (every run the base beam),
    # the second moment or the mass per length resolved from the wrong value, or the
    # columns of the other axes shifted by the resolved ones.
    start, stop, count = values[0], values[-1], len(values)
    if key == "inner_diameter":
        start = 0.002  # a tube's inner diameter is > 0
        values = tuple(np.linspace(start, stop, count))
    axes = (
        f'"structure.{key}" = {{ start = {start}, stop = {stop}, count = {count} }}\n'
        '"damper.0.clearance" = { start = 4e-4, stop = 6e-4, count = 2 }\n'
    )
    system = vi.loads(study_text(section, axes))
    out = tmp_path / "beam.nc"
    data = st.run(st.study_of(system), out)
    peaks = data["peak"].values
    impacts = data["impacts"].values
    # The dimension changes the runs (the clearance may not, where nothing touches).
    assert len(set(peaks[:, 0, 0].tolist())) == count
    for i, value in enumerate(data[f"structure.{key}"].values):
        for j, clearance in enumerate(data["damper.0.clearance"].values):
            text = BEAM.format(section=section).replace(line, f"{key} = {float(value)!r}")
            text = text.replace("clearance = 5e-4", f"clearance = {float(clearance)!r}")
            sol = vi.simulate(vi.loads(text))
            assert peaks[i, j].tolist() == sol.peak.tolist()
            assert impacts[i, j] == len(sol.contacts)


@pytest.mark.parametrize(
    ("section", "axes", "says"),
    [
        # A dimension the section does not have.
        (RECTANGLE, '"structure.diameter" = [0.01, 0.02]', "structure.diameter"),
        # A dimension out of range.
        (RECTANGLE, '"structure.height" = [-0.001, 0.005]', "structure.height"),
        # Both ways of one quantity.
        (
            RECTANGLE,
            '"structure.height" = [0.004, 0.005]\n"structure.second_moment" = [1e-10, 2e-10]',
            "structure.second_moment",
        ),
        # A tube's inner diameter at its outer one.
        (TUBE, '"structure.inner_diameter" = [0.008, 0.012]', "inner_diameter"),
    ],
)
def test_an_axis_the_beam_cannot_take_is_refused_naming_it(
    section: str, axes: str, says: str
) -> None:
    with pytest.raises(StudyError, match=says):
        st.study_of(vi.loads(study_text(section, axes)))


def test_a_section_axis_on_a_structure_that_is_no_cantilever_is_refused() -> None:
    text = """
[structure]
kind = "oscillator"
mass = 1.0
stiffness = 3947.8

[solver]
method = "rk4"
dt = 1e-3
t_end = 0.1

[study]
analysis = "run"
metrics = ["peak"]

[study.axes]
"structure.height" = [0.004, 0.005]
"""
    with pytest.raises(StudyError, match="cantilever"):
        st.study_of(vi.loads(text))


def test_the_command_line_runs_a_section_study(tmp_path: Path) -> None:
    import subprocess
    import sys

    path = tmp_path / "beam.toml"
    path.write_text(study_text(RECTANGLE, '"structure.height" = [0.004, 0.006]\n'))
    done = subprocess.run(
        [sys.executable, "-m", "vibroimpact", "study", str(path), "--out", str(tmp_path / "o.nc")],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert done.returncode == 0, done.stderr
    assert (tmp_path / "o.nc").exists()
