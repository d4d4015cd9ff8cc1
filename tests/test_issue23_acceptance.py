"""Issue 23, cases of the same kind as its items, found by an acceptance pass: a first
line of a recorded CSV that is a mistyped sample (not a header), a time beyond what the
interpolation can take, a wrong-typed argument quoted on one line, and sections an
analysis cannot take refused naming what is wrong."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from test_hostile_inputs import RECORDED
from vibroimpact.scenario.two_mass import ScenarioError, parse_scenario


def _record_error(tmp_path: Path, csv: str) -> str:
    (tmp_path / "rec.csv").write_text(csv, encoding="utf-8")
    with pytest.raises(ScenarioError) as caught:
        parse_scenario(RECORDED.format(file="rec.csv"), "s.toml", tmp_path)
    message = str(caught.value)
    assert "\n" not in message
    return message


@pytest.mark.parametrize(
    "line",
    ["0,1_0", "1_0,5", "0x10,1", "0 1e", "\u0661,2", "0,100 # start of record"]
    + ["0,", "0,e", "0,0,"],
)
def test_a_mistyped_first_sample_without_a_header_is_refused_not_dropped(
    tmp_path: Path, line: str
) -> None:
    # Taken for a header naming the columns, the sample had been dropped silently (the
    # run went on from the second line).
    message = _record_error(tmp_path, f"{line}\n11,2\n12,3\n")
    assert "rec.csv line 1:" in message and "not a number" in message, message


@pytest.mark.parametrize(
    "header",
    ["time,value", "El Centro 1940 NS", "t [s]; a [m/s2]", "1940 El Centro NS", "t,a # s, m/s2"],
)
def test_a_header_naming_the_columns_is_still_skipped(tmp_path: Path, header: str) -> None:
    (tmp_path / "rec.csv").write_text(f"{header}\n0,1\n1,2\n", encoding="utf-8")
    scenario = parse_scenario(RECORDED.format(file="rec.csv"), "s.toml", tmp_path)
    excitation = scenario.prepared.spec["excitation"][0]
    assert list(excitation["time"]) == [0.0, 1.0]
    assert list(excitation["value"]) == [1.0, 2.0]


@pytest.mark.parametrize("times", [("-1e308", "1e308"), ("0", "1.7e308")])
def test_a_time_beyond_half_the_largest_float_names_the_line(
    tmp_path: Path, times: tuple[str, str]
) -> None:
    # -1e308 to 1e308: the interval overflowed to inf and the force between the two
    # samples was read as the first value (1 N instead of 1.5 N at t = 0).
    message = _record_error(tmp_path, f"time,value\n{times[0]},1\n{times[1]},2\n")
    line = 2 if abs(float(times[0])) > 0.5 * sys.float_info.max else 3
    assert f"rec.csv line {line}:" in message and "time" in message, message


def test_a_two_dimensional_array_is_quoted_on_one_line() -> None:
    import vibroimpact as vi
    from vibroimpact import analysis

    with pytest.raises(vi.InvalidInputError) as caught:
        analysis.with_parameter({"a": {}}, "a.b", np.zeros((2, 2)))
    message = str(caught.value)
    assert "\n" not in message and message.startswith("value:"), message


@pytest.mark.parametrize(
    ("sections", "words"),
    [
        ({}, "[structure]"),
        (
            {"structure": {"kind": "oscillator", "mass": 1.0, "stiffness": 1.0}, "solver": None},
            "[solver]",
        ),
        (
            {"structure": {"kind": "oscillator", "mass": 1.0, "stiffness": 1.0}, "solver": [1]},
            "[solver]",
        ),
    ],
)
def test_an_analysis_refuses_sections_it_cannot_take_naming_them(
    sections: dict[str, Any], words: str
) -> None:
    import vibroimpact as vi
    from vibroimpact import analysis

    excitation = [
        {"kind": "force", "at": 0, "signal": "harmonic", "amplitude": 1.0, "frequency": 1.0}
    ]
    data = {**sections, "excitation": excitation}
    for call in (
        lambda: analysis.runner(data),
        lambda: analysis.linear_amplitude(data),
        lambda: analysis.sweep(data, "excitation.0.frequency", [1.0]),
    ):
        with pytest.raises(vi.InvalidInputError) as caught:
            call()
        assert words in str(caught.value) and "\n" not in str(caught.value), caught.value


def test_linear_response_refuses_a_prepared_run_of_the_wrong_type() -> None:
    import vibroimpact as vi
    from vibroimpact import analysis

    data = {
        "structure": {"kind": "oscillator", "mass": 1.0, "stiffness": 1.0},
        "excitation": [
            {"kind": "force", "at": 0, "signal": "harmonic", "amplitude": 1.0, "frequency": 1.0}
        ],
    }
    with pytest.raises(vi.InvalidInputError, match="^prepared: must be a PreparedRun"):
        analysis.linear_response(data, prepared="x")  # type: ignore[arg-type]


def _dataset_calls() -> list[Any]:
    from vibroimpact.analysis import datasets

    bad = [None, "x", [[1.0]], 5.0, {}]
    calls = [
        (datasets.sweep_dataset, ["points", "parameter", "units"], 2),
        (datasets.bifurcation_dataset, ["points", "parameter", "units"], 2),
        (datasets.section_dataset, ["section", "n", "k"], 3),
        (datasets.basins_dataset, ["result", "x_name", "y_name"], 3),
        (datasets.branch_dataset, ["branch", "units"], 1),
    ]
    return [
        pytest.param(function, names, positional, name, value, id=f"{function.__name__}-{name}-{i}")
        for function, names, positional in calls
        for name in names
        for i, value in enumerate(bad)
        # None is a valid units (told from the parameter); a str a valid name.
        if not (name == "units" and value is None)
        and not (name in ("parameter", "x_name", "y_name", "units") and value == "x")
    ]


@pytest.mark.parametrize(("function", "names", "positional", "name", "value"), _dataset_calls())
def test_the_dataset_functions_refuse_a_wrong_type_naming_the_argument(
    function: Any, names: list[str], positional: int, name: str, value: Any
) -> None:
    # Each had failed deep inside as an AttributeError or a TypeError naming nothing.
    import vibroimpact as vi
    from vibroimpact import analysis
    from vibroimpact.analysis import continuation, maps

    good: dict[str, Any] = {
        "points": [],
        "parameter": "excitation.0.frequency",
        "units": "Hz",
        "section": maps.Section(np.zeros((1, 2)), np.zeros(0), np.zeros(0), []),
        "n": 1,
        "k": 0,
        "result": maps.Basins(np.zeros(1), np.zeros(1), np.zeros((1, 1), dtype=int), []),
        "x_name": "structure_displacement.0",
        "y_name": "structure_velocity.0",
        "branch": continuation.Branch("p", 1, [], "max_points", 1, 0),
    }
    assert issubclass(analysis.AnalysisError, vi.InvalidInputError)
    kwargs = {key: good[key] for key in names}
    kwargs[name] = value
    args = [kwargs.pop(key) for key in names[:positional]]
    with pytest.raises(vi.InvalidInputError) as caught:
        function(*args, **kwargs)
    message = str(caught.value)
    assert message.startswith(name) and "\n" not in message, message


def test_a_fixed_step_method_is_bounded_by_its_steps_not_by_the_fastest_mode() -> None:
    import vibroimpact as vi
    from vibroimpact import analysis

    # A 5e5 Hz mode beside a 5 Hz one, forced at 1e-4 Hz: 5e9 periods of the fast mode
    # in one forcing period, but newmark-implicit takes 1e6 steps of 0.01 s (0.25 s),
    # and had been refused as "more than a run's max_steps steps through".
    structure = {
        "kind": "matrices",
        "mass": [[1.0, 0.0], [0.0, 1e-6]],
        "stiffness": [[1e3 + 1e7, -1e7], [-1e7, 1e7]],
        "damping": [[1.0, 0.0], [0.0, 1e-2]],
    }
    excitation = [
        {"kind": "force", "at": 0, "signal": "harmonic", "amplitude": 1.0, "frequency": 1e-4}
    ]
    for method in ("newmark-implicit", "generalized-alpha"):
        data = {
            "structure": structure,
            "excitation": excitation,
            "solver": {"method": method, "dt": 1e-2},
        }
        assert analysis.runner(data).period == pytest.approx(1e4)
        # One forcing period of more than max_steps steps of dt: refused, naming both.
        data["solver"]["max_steps"] = 999_999
        with pytest.raises(vi.InvalidInputError) as caught:
            analysis.runner(data)
        message = str(caught.value)
        assert message.startswith("forcing frequency 0.0001 Hz") and "dt = 0.01 s" in message
    # An adaptive method still steps through each period of the fast mode: refused.
    data = {"structure": structure, "excitation": excitation, "solver": {"method": "dop853"}}
    with pytest.raises(vi.InvalidInputError, match="fastest mode"):
        analysis.runner(data)


def test_an_orbit_at_exact_resonance_is_found_by_every_analysis_that_shoots(
    tmp_path: Path,
) -> None:
    import math

    from vibroimpact import analysis
    from vibroimpact import study as st
    from vibroimpact.analysis import continuation

    # The oscillator at 5.00 Hz: strobed in quadrature, its displacement at
    # the strobe is round-off (3e-10 m) and the shooting, scaled by it, had never
    # converged (orbit: residual 1.4e-5 after 40 iterations, multipliers 0 and 0.939;
    # continuation: no first orbit; an orbit study: the point failed).
    data: dict[str, Any] = {
        "structure": {"kind": "oscillator", "mass": 1.0, "stiffness": 986.96044, "damping": 0.6283},
        "excitation": [
            {"kind": "force", "at": 0, "signal": "harmonic", "amplitude": 1.0, "frequency": 5.0}
        ],
        "solver": {"method": "exact"},
    }
    # Closed forms: X = F / |k - m w^2 + i c w|, multipliers of modulus exp(-c T / 2 m).
    w = 2 * math.pi * 5.0
    amplitude = 1.0 / abs(986.96044 - w * w + 1j * 0.6283 * w)
    modulus = math.exp(-0.6283 * 0.2 / 2)
    for method in ("exact", "dop853"):
        data["solver"]["method"] = method
        found = analysis.orbit(analysis.runner(data))
        assert found.converged and found.stable
        assert found.amplitude[0] == pytest.approx(amplitude, rel=1e-7)
        assert np.abs(found.floquet_multipliers) == pytest.approx([modulus] * 2, rel=1e-7)
    branch = continuation.continue_orbit(data, "excitation.0.amplitude", stop=2.0, max_points=3)
    assert branch.points[0].amplitude[0] == pytest.approx(amplitude, rel=1e-7)
    orbit_study = {
        **data,
        "study": {
            "analysis": "orbit",
            "settle_periods": 1000,
            "metrics": ["largest_multiplier", "amplitude"],
            "axes": {"excitation.0.frequency": [4.99, 5.0, 5.01]},
        },
    }
    data["solver"]["method"] = "exact"
    ds = st.run(st.study_of(orbit_study), tmp_path / "out.nc")
    assert list(ds["status"].values) == [0, 0, 0]
    assert float(ds["amplitude"].sel({"excitation.0.frequency": 5.0}).values[0]) == (
        pytest.approx(amplitude, rel=1e-7)
    )
    assert float(ds["largest_multiplier"].values[1]) == pytest.approx(modulus, rel=1e-7)


@pytest.mark.parametrize(
    ("call", "name"),
    [
        (
            lambda bad: __import__("vibroimpact").hertz_stiffness(bad, 2e11, 0.3, 2e11, 0.3),
            "radius",
        ),
        (lambda bad: __import__("vibroimpact").cantilever_root(bad), "mode"),
        (lambda bad: __import__("vibroimpact").check_solver(t_end=bad, method="dopri5"), "t_end"),
        (lambda bad: __import__("vibroimpact").linear_contact_duration(1.0, bad, 1e6), "main_mass"),
    ],
)
def test_the_core_quotes_a_two_dimensional_array_on_one_line(call: Any, name: str) -> None:
    import vibroimpact as vi

    # The binding quoted NumPy's repr as it is, its rows on two lines.
    with pytest.raises(vi.InvalidInputError) as caught:
        call(np.zeros((2, 2)))
    message = str(caught.value)
    assert name in message and "\n" not in message, message


@pytest.mark.parametrize(
    ("call", "name"),
    [
        (lambda bad: __import__("vibroimpact.analysis").analysis.whole_count("n", bad, 1), "n"),
        (
            lambda bad: __import__("vibroimpact.analysis").analysis.bifurcation(
                {"structure": {}}, "a.b", [1.0], sample=bad
            ),
            "sample",
        ),
        (
            lambda bad: __import__("vibroimpact").simulate_system(
                {"kind": "oscillator", "mass": 1.0, "stiffness": 1.0},
                method="dopri5",
                t_end=0.1,
                initial=bad,
            ),
            "[initial]",
        ),
    ],
)
def test_an_array_for_a_count_a_choice_or_a_table_is_one_line_naming_it(
    call: Any, name: str
) -> None:
    import vibroimpact as vi

    # A count or a choice quoted NumPy's repr over two lines; [initial] as an array
    # had raised NumPy's "truth value of an array is ambiguous" (a bare ValueError).
    with pytest.raises(vi.InvalidInputError) as caught:
        call(np.zeros((2, 2)))
    message = str(caught.value)
    assert message.startswith(name) and "\n" not in message, message


# Follow-up: inputs a verification pass found accepted or wrongly named.


def test_an_absurd_atol_is_refused_with_its_range() -> None:
    import vibroimpact as vi

    oscillator = {"kind": "oscillator", "mass": 1.0, "stiffness": 1.0}
    for atol in (1e300, 1.5):
        with pytest.raises(vi.InvalidInputError, match=r"^\[solver\] atol: must be in \(0, 1\]"):
            vi.simulate_system(oscillator, t_end=1.0, method="dop853", atol=atol)
        # The two-body run's (the core's settings).
        with pytest.raises(vi.InvalidInputError, match=r"atol.*in \(0, 1\]"):
            vi.simulate(
                vi.ImpactDamper(main_mass=1.0, stiffness=1.0, impact_mass=0.25, clearance=0.01),
                vi.Contact("hertz", stiffness=3000.0, damping=0.01),
                vi.InitialState(impact_displacement=0.01, impact_velocity=0.1),
                t_end=0.01,
                method="dop853",
                atol=atol,
            )
    assert vi.simulate_system(oscillator, t_end=0.1, method="dop853", atol=1.0).t[-1] == 0.1


def _ball_runner() -> Any:
    import tomllib

    from vibroimpact import analysis as an

    root = Path(__file__).resolve().parents[1]
    return an.runner(tomllib.loads((root / "examples" / "ball_table_basins.toml").read_text()))


@pytest.mark.parametrize(
    ("call", "wanted"),
    [
        (lambda run, z: run.periods(z, None), r"^count: must be a whole number >= 1, got None"),
        (lambda run, z: run.periods(z, True), r"^count: must be a whole number >= 1, got True"),
        (lambda run, z: run.map(z, None), r"^count: must be a whole number >= 1, got None"),
        (lambda run, z: run.shoot(z, None, 1e-9, 5), r"^count: must be a whole number"),
        (lambda run, z: run.periods(z, 1, record="x"), r"^record: must be True or False, got 'x'"),
        (lambda run, z: run.periods(z, 1, strobe=1), r"^strobe: must be True or False, got 1"),
        (lambda run, z: run.amplitudes(None), r"^recorded: must be a Mapping"),
        (lambda run, z: run.rms(None), r"^recorded: must be a Mapping"),
    ],
)
def test_a_runners_arguments_are_refused_by_their_names(call: Any, wanted: str) -> None:
    import vibroimpact as vi

    run = _ball_runner()
    with pytest.raises(vi.InvalidInputError, match=wanted):
        call(run, run.initial_state())


@pytest.mark.parametrize(
    "call",
    [
        lambda vi: vi.cantilever_root(True),
        lambda vi: vi.cantilever_mode_shape(1.0, True, 0.5),
        lambda vi: vi.cantilever_mode_shape(1.0, 1, 0.5, derivative=True),
        lambda vi: vi.cantilever_mode(1.0, 1.0, 1.0, 1.0, 1.0, mode=True),
    ],
)
def test_a_boolean_is_not_a_whole_number(call: Any) -> None:
    # True is the int 1 to Python: it had been taken as mode 1 (or derivative 1).
    import vibroimpact as vi

    with pytest.raises(vi.InvalidInputError, match=r"(mode|derivative) must be .*got True"):
        call(vi)


@pytest.mark.parametrize("csv", ["0,1\n1e-320,1\n", "-1e-320,0\n0,1\n5,0\n"])
def test_samples_too_close_to_interpolate_are_refused_naming_the_line(
    tmp_path: Path, csv: str
) -> None:
    # 0 then 1e-320 s (a subnormal interval) had failed the run's energy ledger (exit 1).
    message = _record_error(tmp_path, "time,value\n" + csv)
    assert "rec.csv line 3:" in message and "samples must be at least 2.23e-308 s apart" in message
