"""Messages and Python types (issue 23): a recorded CSV read by NumPy within a bounded
memory, its errors naming the file and the line as a user counts them; every public
function refusing a value of the wrong type with InvalidInputError naming the argument;
keys' ranges, sizes and steps refused with their real range, numbers written short."""

from __future__ import annotations

import subprocess
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import vibroimpact as vi
from test_hostile_inputs import RECORDED, refused
from vibroimpact.scenario.two_mass import ScenarioError, parse_scenario
from vibroimpact.system.record_file import MAX_RECORDED_FILE_BYTES

Cli = Callable[..., subprocess.CompletedProcess[str]]


def record_error(tmp_path: Path, csv: str, extra: str = "") -> str:
    (tmp_path / "rec.csv").write_text(csv, encoding="utf-8")
    with pytest.raises(ScenarioError) as caught:
        parse_scenario(RECORDED.format(file="rec.csv") + extra, "s.toml", tmp_path)
    message = str(caught.value)
    assert "\n" not in message
    return message


def record(tmp_path: Path, csv: str) -> tuple[list[float], list[float]]:
    (tmp_path / "rec.csv").write_text(csv, encoding="utf-8")
    scenario = parse_scenario(RECORDED.format(file="rec.csv"), "s.toml", tmp_path)
    excitation = scenario.prepared.spec["excitation"][0]
    return list(excitation["time"]), list(excitation["value"])


# 1. A recorded CSV: numbers as a CSV writes them, errors naming the file's line.


@pytest.mark.parametrize("cell", ["1_0", "0x10", "1d0", "\u0661", "1e", "+-1"])
def test_a_cell_python_would_read_but_a_csv_does_not_hold_is_refused(
    tmp_path: Path, cell: str
) -> None:
    # float("1_0") is 10, float("\u0661") (an Arabic-Indic one) is 1: not numbers in a CSV.
    message = record_error(tmp_path, f"time,value\n0,0\n1,{cell}\n2,0\n")
    assert "[[excitation]] 0: file: rec.csv line 3:" in message, message
    assert repr(cell) in message and "not a number" in message, message


def test_a_value_beyond_floating_point_names_the_file_line(tmp_path: Path, run_cli: Cli) -> None:
    (tmp_path / "rec.csv").write_text("time,value\n0,0\n1,1e308\n2,0\n")
    (tmp_path / "s.toml").write_text(RECORDED.format(file="rec.csv"))
    # The core said "row 1" (a 0-based index of the samples) for line 3.
    message = refused(run_cli("simulate", "s.toml"), "rec.csv line 3:", "1e+308")
    assert "row" not in message


def test_a_value_times_scale_beyond_floating_point_names_the_line_and_scale(
    tmp_path: Path,
) -> None:
    message = record_error(tmp_path, "# t, a\n0,0\n1,2e300\n2,0\n", "scale = 1e10")
    assert "rec.csv line 3:" in message and "2e+300" in message, message
    assert "scale 10000000000.0" in message, message


@pytest.mark.parametrize(
    "text",
    [
        # The usual file, read by NumPy at once.
        "time,value\n0,1\n0.5,-2e-3\n1,3\n",
        # Comments, blank lines, CRLF, other separators: line by line, the same values.
        "# a record\r\n\r\ntime;value\r\n0;1\r\n0.5;-2e-3\r\n# a pause\r\n1;3\r\n",
        "0 1\n0.5,\t-2e-3\n1\t3\n",
        "  # header comment\n t v \n0 1\n\n0.5   -2e-3\n1 3\n",
    ],
)
def test_every_way_of_writing_a_record_reads_the_same_samples(tmp_path: Path, text: str) -> None:
    assert record(tmp_path, text) == ([0.0, 0.5, 1.0], [1.0, -2e-3, 3.0])


@pytest.mark.parametrize(
    ("text", "line", "words"),
    [
        # Found by the check of the samples NumPy read: the line counted as in the file.
        ("# a\n\n\nt,v\n0,0\n1,0\n1,2\n", 7, "increase strictly"),
        ("t,v\r\n0,0\r\n1,nan\r\n", 3, "finite"),
        # Found line by line.
        ("t,v\n0,0\n# a pause\n1,0\n0.5,2\n", 5, "increase strictly"),
        ("t,v\n0,0\n1,2 # a note\n", 3, "not a number"),
        ("t,v\n0,0\n1,,2\n", 3, "not a number"),
        ("t,v\n0;0\n1,2,3\n", 3, "two columns"),
    ],
)
def test_record_errors_name_the_line_as_the_file_numbers_it(
    tmp_path: Path, text: str, line: int, words: str
) -> None:
    message = record_error(tmp_path, text)
    assert f"rec.csv line {line}:" in message and words in message, message


def test_a_record_at_the_size_limit_is_parsed_within_bounded_memory(tmp_path: Path) -> None:
    # 64 MiB of samples: lists of Python floats (and a label per line) took 1.4 GB and 17 s.
    count = 6_700_000
    text = "time,value\n" + "".join(f"{k},{k % 10}\n" for k in range(count))
    assert MAX_RECORDED_FILE_BYTES * 0.9 < len(text) <= MAX_RECORDED_FILE_BYTES
    (tmp_path / "rec.csv").write_text(text)
    del text
    (tmp_path / "s.toml").write_text(RECORDED.format(file="rec.csv"))
    child = (
        "import sys\n"
        "from vibroimpact.scenario.two_mass import load_scenario\n"
        "e = load_scenario('s.toml').prepared.spec['excitation'][0]\n"
        "t, v = e['time'], e['value']\n"
        "assert len(t) == len(v) == int(sys.argv[1]), len(t)\n"
        "assert t[-1] == int(sys.argv[1]) - 1 and v[-1] == (int(sys.argv[1]) - 1) % 10\n"
        # VmHWM, this process's peak (ru_maxrss would count the parent's before exec).
        "print(next(l.split()[1] for l in open('/proc/self/status') if l.startswith('VmHWM')))\n"
    )
    done = subprocess.run(
        [sys.executable, "-c", child, str(count)],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=50,
        check=False,
    )
    assert done.returncode == 0, done.stderr
    peak = int(done.stdout) * 1024  # bytes
    # About 3 times the file, with Python and NumPy themselves (40 MB).
    assert peak < 5 * MAX_RECORDED_FILE_BYTES, f"{peak / 2**20:.0f} MiB"


def test_a_record_file_beyond_the_limit_is_refused_before_it_is_read(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from vibroimpact.system import record_file

    monkeypatch.setattr(record_file, "MAX_RECORDED_FILE_BYTES", 20)
    message = record_error(tmp_path, "".join(f"{k},0\n" for k in range(10)))
    assert "larger than" in message and "limit of a recorded signal" in message, message


def test_record_arrays_given_in_python_are_checked_the_same(tmp_path: Path) -> None:
    import vibroimpact as vi

    excitation = {"kind": "base", "signal": "recorded", "time": [0.0, 1.0], "value": [0, 1e308]}
    with pytest.raises(vi.InvalidInputError, match=r"0: value\[1\]: value 1e\+308 is beyond"):
        vi.simulate_system(
            {"kind": "oscillator", "mass": 1.0, "stiffness": 1.0},
            excitation=[excitation],
            t_end=0.1,
            method="dopri5",
        )
    assert np.isfinite(0.5 * sys.float_info.max)


# 2. Every public function refuses an argument of the wrong type naming it.

SECTIONS: dict[str, Any] = {
    "structure": {"kind": "oscillator", "mass": 1.0, "stiffness": 3947.8, "damping": 2.5},
    "damper": [{"mass": 0.05, "at": 0, "clearance": 0.005, "law": "rigid", "restitution": 0.6}],
    "excitation": [
        {"kind": "force", "at": 0, "signal": "harmonic", "amplitude": 1.0, "frequency": 10.0}
    ],
    "solver": {"method": "exact", "t_end": 0.1},
}
NONE_FOR_NUMBER = [None, "1", [1.0], {}, True, np.zeros(2)]
NOT_A_COUNT = [None, "5", 2.5, [5], {}, True]
NOT_VALUES = [None, "abc", {"a": 1}, [[1.0, 2.0], [3.0, 4.0]], np.zeros((2, 2)), ["a"], 5.0, [None]]
NOT_SECTIONS = [None, "x", [1], 5]
NOT_TEXT = [None, 5, ["a"], {"a": 1}]
NOT_A_STATE = ["x", {}, [[1.0]], [None], np.zeros((2, 2)), np.zeros(5), 5.0]
NOT_A_FUNCTION = [5, "x"]
NOT_A_FOLDER = [5, ["a"]]
NOT_AN_AXIS = [None, 5, "x", (0,), (0, "abc"), ("a", [0.0]), (0, [[0.0, 1.0]]), (-1, [0.0])]


def _calls() -> list[Any]:
    """(function, valid keyword arguments, argument, bad values) over the public API."""
    import vibroimpact as vi
    from vibroimpact import analysis, study
    from vibroimpact.analysis import continuation, maps

    run = analysis.runner(SECTIONS)
    sweep = {"data": SECTIONS, "parameter": "excitation.0.frequency", "values": [10.0]}
    bifurcation = {**sweep, "settle_periods": 1, "sample_periods": 1}
    basins = {"run": run, "first": (0, [0.0]), "second": (1, [0.0]), "settle_periods": 1}
    system = vi.ImpactDamper(
        main_mass=1.0, stiffness=1.0, damping=0.01, impact_mass=0.25, clearance=0.01
    )
    simulate = {
        "system": system,
        "contact": vi.Contact("hertz", stiffness=3000.0),
        "initial": vi.InitialState(),
        "method": "rk4",
        "dt": 1e-3,
        "t_end": 0.01,
    }
    structure = {"structure": SECTIONS["structure"], "t_end": 0.01, "method": "dopri5"}
    continued = {"data": SECTIONS, "parameter": "excitation.0.frequency", "stop": 11.0}
    table: list[tuple[Any, dict[str, Any], str, list[Any]]] = [
        (analysis.sweep, sweep, "data", NOT_SECTIONS),
        (analysis.sweep, sweep, "parameter", NOT_TEXT),
        (analysis.sweep, sweep, "values", NOT_VALUES),
        (analysis.sweep, sweep, "direction", [5, "sideways"]),  # None: [sweep]'s or default
        (analysis.sweep, sweep, "settle_periods", NOT_A_COUNT[1:]),
        (analysis.sweep, sweep, "record_periods", NOT_A_COUNT[1:]),
        (analysis.sweep, sweep, "tolerance", NONE_FOR_NUMBER[1:]),
        (analysis.sweep, sweep, "base_dir", NOT_A_FOLDER),
        (analysis.sweep, sweep, "progress", NOT_A_FUNCTION),
        (analysis.runner, {"data": SECTIONS}, "data", NOT_SECTIONS),
        (analysis.runner, {"data": SECTIONS}, "base_dir", NOT_A_FOLDER),
        (analysis.forcing_period, {"data": SECTIONS}, "data", NOT_SECTIONS),
        (analysis.linear_amplitude, {"data": SECTIONS}, "data", NOT_SECTIONS),
        (analysis.linear_response, {"data": SECTIONS}, "base_dir", NOT_A_FOLDER),
        (analysis.steady_state, {"run": run}, "run", [None, "x", 5]),
        (analysis.steady_state, {"run": run}, "state", NOT_A_STATE),
        (analysis.steady_state, {"run": run}, "settle_periods", NOT_A_COUNT),
        (analysis.steady_state, {"run": run}, "record_periods", NOT_A_COUNT),
        (analysis.steady_state, {"run": run}, "max_period", NOT_A_COUNT),
        (analysis.steady_state, {"run": run}, "tolerance", NONE_FOR_NUMBER),
        (analysis.orbit, {"run": run}, "run", [None, "x", 5]),
        (analysis.orbit, {"run": run}, "state", NOT_A_STATE),
        (analysis.orbit, {"run": run}, "periods", NOT_A_COUNT),
        (analysis.orbit, {"run": run}, "tolerance", NONE_FOR_NUMBER),
        (analysis.orbit, {"run": run}, "max_iterations", NOT_A_COUNT),
        (
            analysis.with_parameter,
            {"data": SECTIONS, "path": "excitation.0.frequency", "value": 5.0},
            "value",
            NONE_FOR_NUMBER,
        ),
        (
            analysis.with_parameter,
            {"data": SECTIONS, "path": "x.y", "value": 5.0},
            "path",
            NOT_TEXT,
        ),
        (analysis.with_parameter, {"data": SECTIONS, "path": "x.y", "value": 5.0}, "data", [None]),
        (analysis.state_index, {"path": "structure_velocity.0", "n": 1, "k": 1}, "path", NOT_TEXT),
        (analysis.state_index, {"path": "structure_velocity.0", "n": 1, "k": 1}, "n", NOT_A_COUNT),
        (analysis.state_index, {"path": "structure_velocity.0", "n": 1, "k": 1}, "k", NOT_A_COUNT),
        (analysis.reductions, {"amplitude": [1.0], "linear": [2.0]}, "linear", [None, "x", {}]),
        (maps.poincare, {"run": run, "periods": 1}, "run", [None, 5]),
        (maps.poincare, {"run": run, "periods": 1}, "state", NOT_A_STATE),
        (maps.poincare, {"run": run, "periods": 1}, "settle_periods", NOT_A_COUNT),
        (maps.poincare, {"run": run, "periods": 1}, "periods", NOT_A_COUNT),
        (maps.bifurcation, bifurcation, "data", NOT_SECTIONS),
        (maps.bifurcation, bifurcation, "parameter", NOT_TEXT),
        (maps.bifurcation, bifurcation, "values", NOT_VALUES),
        (maps.bifurcation, bifurcation, "settle_periods", NOT_A_COUNT),
        (maps.bifurcation, bifurcation, "sample_periods", NOT_A_COUNT),
        (maps.bifurcation, bifurcation, "base_dir", NOT_A_FOLDER),
        (maps.bifurcation, bifurcation, "progress", NOT_A_FUNCTION),
        (maps.basins, basins, "run", [None, 5]),
        (maps.basins, basins, "first", NOT_AN_AXIS),
        (maps.basins, basins, "second", NOT_AN_AXIS),
        (maps.basins, basins, "state", NOT_A_STATE),
        (maps.basins, basins, "tolerance", NONE_FOR_NUMBER[1:]),  # None: the table's
        (maps.basins, basins, "progress", NOT_A_FUNCTION),
        (
            continuation.continue_orbit,
            continued,
            "data",
            NOT_SECTIONS,
        ),
        (
            continuation.continue_orbit,
            continued,
            "parameter",
            NOT_TEXT,
        ),
        (
            continuation.continue_orbit,
            continued,
            "stop",
            NONE_FOR_NUMBER,
        ),
        (
            continuation.continue_orbit,
            continued,
            "step",
            ["1", [1.0], {}, True],
        ),
        (
            continuation.continue_orbit,
            continued,
            "tolerance",
            NONE_FOR_NUMBER[1:],  # None: the [continuation] table's, or the default
        ),
        (
            continuation.continue_orbit,
            continued,
            "progress",
            NOT_A_FUNCTION,
        ),
        (vi.simulate, simulate, "system", [None, "x", {}]),
        (vi.simulate, simulate, "contact", [None, "hertz"]),
        (vi.simulate, simulate, "initial", [None, {}]),
        # None: the core registry's default (RUN_DEFAULTS["two-mass"]), as for stepping.
        (vi.simulate, simulate, "method", [5, ["rk4"]]),
        (vi.simulate, simulate, "contact_timing", [5]),
        (vi.simulate, simulate, "stepping", [5]),
        (vi.simulate, simulate, "t_end", [None, "1", [1.0]]),
        (vi.check_solver, {"t_end": 1.0, "method": "dopri5"}, "method", [5]),
        (vi.simulate_system, structure, "structure", [None, "x", 5]),
        (vi.simulate_system, structure, "excitation", ["x", 5, [5]]),
        (vi.simulate_system, structure, "method", [None, 5]),
        (vi.simulate_system, structure, "base_dir", NOT_A_FOLDER),
        (vi.cantilever_mode_shape, {"length": 1.0, "mode": 1, "x": 0.5}, "derivative", [None, "1"]),
        (
            vi.goldsmith_contact_duration,
            {"impact_mass": 1.0, "main_mass": 1.0, "hertz_stiffness": 1.0, "approach_speed": 1.0},
            "exact_constant",
            [None, "yes"],
        ),
        (vi.parse_scenario, {"text": ""}, "text", [None, 5, b"x"]),
        (vi.parse_scenario, {"text": ""}, "source", [None, 5]),
        (vi.parse_scenario, {"text": ""}, "base_dir", NOT_A_FOLDER),
        (vi.load_scenario, {"path": "s.toml"}, "path", [None, 5, ["a"]]),
        (study.study_of, {"data": SECTIONS}, "data", NOT_SECTIONS),
    ]
    return [
        pytest.param(function, kwargs, name, bad, id=f"{function.__name__}-{name}-{i}")
        for function, kwargs, name, bads in table
        for i, bad in enumerate(bads)
    ]


@pytest.mark.parametrize(("function", "kwargs", "name", "bad"), _calls())
def test_a_public_function_refuses_a_wrong_type_naming_the_argument(
    function: Callable[..., Any], kwargs: dict[str, Any], name: str, bad: Any
) -> None:
    import vibroimpact as vi

    with pytest.raises(vi.InvalidInputError) as caught:
        function(**{**kwargs, name: bad})
    message = str(caught.value)
    assert name in message and "\n" not in message, message


def test_the_issue_s_calls_name_their_argument() -> None:
    import vibroimpact as vi
    from vibroimpact import analysis

    with pytest.raises(vi.InvalidInputError, match=r"^parameter: must be a string, got 5"):
        analysis.sweep(SECTIONS, 5, [1.0])  # type: ignore[arg-type]
    with pytest.raises(vi.InvalidInputError, match=r"^values: must be a list or 1-D array"):
        analysis.sweep(SECTIONS, "excitation.0.frequency", [[1.0, 2.0]])
    with pytest.raises(vi.InvalidInputError, match=r"^data: must be a scenario's sections"):
        analysis.runner(None)  # type: ignore[arg-type]


# 3. Ranges: a key's real range, numbers written short.


@pytest.mark.parametrize("step", [1e300, 2.0, 1e-300])
def test_a_continuation_step_beyond_its_range_is_refused(step: float) -> None:
    import vibroimpact as vi
    from vibroimpact.analysis import continue_orbit

    # From 10 Hz to 11 Hz: a step is at most the whole range, at least 1e-9 of it.
    with pytest.raises(vi.InvalidInputError, match=r"^step: must be in \[1e-09, 1.0\]"):
        continue_orbit(SECTIONS, "excitation.0.frequency", stop=11.0, step=step, max_points=3)


def test_a_continuation_step_of_1e300_is_refused_on_the_command_line(
    tmp_path: Path, run_cli: Cli
) -> None:
    root = Path(__file__).resolve().parents[1]
    text = (root / "examples" / "ball_table_continuation.toml").read_text(encoding="utf-8")
    lines = ["step = 1e300" if line.startswith("step =") else line for line in text.splitlines()]
    assert "step = 1e300" in lines
    (tmp_path / "c.toml").write_text("\n".join(lines) + "\n")
    refused(
        run_cli("continue", "c.toml"), "c.toml: [continuation] step: must be in [", "got 1e+300"
    )


@pytest.mark.parametrize(
    ("section", "key", "value", "wanted"),
    [
        ("structure", "modes", -3, "[structure] modes: must be a whole number in [1, 200], got -3"),
        ("output", "every", -1, "[output] every: must be a whole number in [1, 2^63 - 1], got -1"),
        ("output", "every", 0, "[output] every: must be a whole number in [1, 2^63 - 1], got 0"),
        ("solver", "max_steps", -5, "max_steps: must be a whole number in [1, 2^63 - 1], got -5"),
    ],
)
def test_a_whole_number_out_of_range_is_refused_with_the_key_s_own_range(
    section: str, key: str, value: int, wanted: str
) -> None:
    import vibroimpact as vi

    beam = {
        "kind": "cantilever",
        "length": 1.0,
        "youngs_modulus": 2e11,
        "second_moment": 1e-8,
        "mass_per_length": 1.0,
        "modes": 3,
    }
    solver: dict[str, Any] = {"t_end": 0.01, "method": "dopri5"}
    if section == "structure":
        beam[key] = value
    elif section == "output":
        solver[key] = value
    else:
        solver[key] = value
    with pytest.raises(vi.InvalidInputError) as caught:
        vi.simulate_system(beam, **solver)
    assert wanted in str(caught.value)


def test_analysis_counts_out_of_range_name_their_real_range() -> None:
    from vibroimpact.analysis import continuation_settings, sweep_settings

    sweep = {"parameter": "excitation.0.frequency", "start": 1.0, "stop": 2.0, "count": 3}
    with pytest.raises(ValueError, match=r"settle_periods: .* in \[0, 10000000\], got -1"):
        sweep_settings({**sweep, "settle_periods": -1})
    with pytest.raises(ValueError, match=r"\[sweep\] count: .* in \[1, 100000\], got -3"):
        sweep_settings({**sweep, "count": -3})
    with pytest.raises(ValueError, match=r"max_points: .* in \[2, 100000\], got -1"):
        continuation_settings(
            {"parameter": "excitation.0.frequency", "stop": 2.0, "max_points": -1}
        )


@pytest.mark.parametrize(
    ("key", "shown"), [("rtol", "1e-300"), ("rtol", "1e+300"), ("beta", "-1e-300")]
)
def test_the_core_s_messages_write_numbers_short(key: str, shown: str) -> None:
    import vibroimpact as vi

    system = vi.ImpactDamper(
        main_mass=1.0, stiffness=1.0, damping=0.01, impact_mass=0.25, clearance=0.01
    )
    with pytest.raises(vi.InvalidInputError) as caught:
        vi.simulate(
            system,
            vi.Contact("hertz", stiffness=3000.0),
            vi.InitialState(),
            method="dopri5",
            t_end=0.01,
            **{key: float(shown)},
        )
    message = str(caught.value)
    # Rust wrote 1e-300 as a fraction of 300 zeros, 1e300 as a 301-digit integer.
    assert message.endswith(f"got {shown}") and len(message) < 80, message


@pytest.mark.parametrize(
    ("mass", "words"),
    [
        # Each mass positive: the smaller is round-off of the larger in double precision.
        ([[1e308, 0.0], [0.0, 1e-308]], ["lightest mode (about 1e-308 kg)", "1e+308 kg", "units"]),
        ([[1e20, 0.0], [0.0, 1.0]], ["below 1e-14 of its largest", "1e+20 kg"]),
        ([[1.0, 0.0], [0.0, -0.5]], ["positive definite", "entry [1][1] is -0.5 kg"]),
        ([[1.0, 2.0], [2.0, 1.0]], ["positive definite", "lowest eigenvalue is -1.0000"]),
    ],
)
def test_a_mass_matrix_without_a_factor_says_what_is_wrong(
    mass: list[list[float]], words: list[str]
) -> None:
    import vibroimpact as vi

    structure = {"kind": "matrices", "mass": mass, "stiffness": [[1.0, 0.0], [0.0, 1.0]]}
    with pytest.raises(vi.InvalidInputError) as caught:
        vi.simulate_system(structure, t_end=0.01, method="dopri5")
    message = str(caught.value)
    for word in words:
        assert word in message, message
    assert "it is not" not in message


# 4. A run's forcing periods: settle and record together within the limit, up front.


def test_poincare_settle_and_periods_beyond_the_limit_together_are_refused_up_front(
    run_cli: Cli,
) -> None:
    root = Path(__file__).resolve().parents[1]
    scenario = str(root / "examples" / "bouncing_ball_table.toml")
    # Each within 10 million, together twice it: had run 21 s into 1.6 GB of contacts,
    # then advised every, history, t_end and max_rows.
    done = run_cli("poincare", scenario, "--settle", "10000000", "--periods", "10000000")
    message = refused(done, "--settle 10000000", "--periods 10000000", "at most 10000000")
    assert "max_rows" not in message and "every" not in message


def _ball() -> dict[str, Any]:
    import tomllib

    root = Path(__file__).resolve().parents[1]
    text = (root / "examples" / "bouncing_ball_table.toml").read_text(encoding="utf-8")
    return tomllib.loads(text)


@pytest.mark.parametrize("analysis", ["poincare", "steady_state", "bifurcation", "basins"])
def test_every_analysis_refuses_settle_and_record_beyond_the_limit_together(
    analysis: str,
) -> None:
    import vibroimpact as vi
    from vibroimpact import analysis as an
    from vibroimpact.analysis import maps

    data = _ball()
    run = an.runner(data)
    half = an.MAX_PERIODS // 2 + 1
    calls: dict[str, Callable[[], Any]] = {
        "poincare": lambda: maps.poincare(run, settle_periods=half, periods=half),
        "steady_state": lambda: an.steady_state(run, settle_periods=half, record_periods=half),
        "bifurcation": lambda: maps.bifurcation(
            data, "excitation.0.amplitude", [12.0], settle_periods=half, sample_periods=half
        ),
        "basins": lambda: maps.basins(
            run, (0, [0.01]), (1, [0.1]), settle_periods=half, record_periods=half
        ),
    }
    with pytest.raises(vi.InvalidInputError, match=rf"settle_periods {half} and \w+ {half}: "):
        calls[analysis]()


@pytest.mark.parametrize("section", ["sweep", "basins", "study"])
def test_settings_of_settle_and_record_beyond_the_limit_together_are_refused(
    section: str,
) -> None:
    from vibroimpact.analysis import MAX_PERIODS, basins_settings, sweep_settings
    from vibroimpact.study import study_settings

    half = {"settle_periods": MAX_PERIODS // 2 + 1, "record_periods": MAX_PERIODS // 2 + 1}
    tables: dict[str, Callable[[], Any]] = {
        "sweep": lambda: sweep_settings(
            {"parameter": "excitation.0.frequency", "start": 1.0, "stop": 2.0, "count": 2, **half}
        ),
        "basins": lambda: basins_settings(
            {
                "x": {"state": "structure_displacement.0", "start": 0.0, "stop": 1.0, "count": 2},
                "y": {"state": "structure_velocity.0", "start": 0.0, "stop": 1.0, "count": 2},
                **half,
            }
        ),
        "study": lambda: study_settings(
            {
                "analysis": "steady-state",
                "axes": {"damper.0.clearance": {"start": 0.01, "stop": 0.02, "count": 2}},
                **half,
            }
        ),
    }
    with pytest.raises(ValueError, match=rf"\[{section}\] settle_periods \d+ and record_periods"):
        tables[section]()


def test_a_long_settling_map_keeps_no_contacts_beyond_its_chunk(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    import vibroimpact as vi
    from vibroimpact import analysis
    from vibroimpact.analysis import runs

    data = _ball()
    data["solver"]["max_rows"] = 60  # two impacts a period: 30 periods' contacts
    run = analysis.runner(data)
    z = run.initial_state()
    # One run of 100 periods keeps 200 contacts: the row limit, worded for an analysis.
    with pytest.raises(vi.SimulationError) as caught:
        run.periods(z, 100)
    message = str(caught.value)
    assert "100 forcing periods" in message and "settle or record fewer" in message, message
    assert "raise every" not in message
    # Settling 100 periods 20 at a time never holds more than 40.
    monkeypatch.setattr(runs, "SETTLE_CHUNK", 20)  # where Runner.map reads it
    settled = run.map(z, 100)
    reference = analysis.runner({**data, "solver": {**data["solver"], "max_rows": 10_000}})
    whole = np.asarray(reference.periods(z, 100)["final_state"], dtype=float)  # one run
    np.testing.assert_allclose(settled, whole, rtol=1e-9, atol=1e-12)


# 5. A forcing frequency whose period no run can step through.


def test_a_forcing_period_beyond_what_a_run_can_step_through_is_refused_naming_it() -> None:
    import vibroimpact as vi
    from vibroimpact import analysis

    # The oscillator's mode is 10 Hz: a run of max_steps = 1e9 steps covers 1e8 s.
    for frequency in (1e-300, 1e-30, 5e-9):
        changed = analysis.with_parameter(SECTIONS, "excitation.0.frequency", frequency)
        with pytest.raises(vi.InvalidInputError) as caught:
            analysis.runner(changed)
        message = str(caught.value)
        assert message.startswith(f"forcing frequency {frequency!r} Hz: its period"), message
        assert "least 1e-08 Hz" in message and "reduce dt" not in message, message
    analysis.runner(analysis.with_parameter(SECTIONS, "excitation.0.frequency", 2e-8))
    # A body on no spring (a ball on a table) has no mode to bound the period by.
    ball = _ball()
    analysis.runner(analysis.with_parameter(ball, "excitation.0.frequency", 1e-6))


def test_a_sweep_from_1e_300_hz_is_refused_naming_the_frequency(
    tmp_path: Path, run_cli: Cli
) -> None:
    root = Path(__file__).resolve().parents[1]
    text = (root / "examples" / "frf_impact_damper.toml").read_text(encoding="utf-8")
    changed = []
    for line in text.splitlines():
        for key, value in (("start", "1e-300"), ("stop", "2e-300"), ("count", "2")):
            if line.startswith(f"{key} = "):
                line = f"{key} = {value}"
        changed.append(line)
    (tmp_path / "f.toml").write_text("\n".join(changed) + "\n")
    message = refused(run_cli("sweep", "f.toml"), "forcing frequency 1e-300 Hz", "at least")
    assert "reduce dt" not in message


def test_study_and_runner_helpers_refuse_wrong_types_naming_the_argument() -> None:
    import vibroimpact as vi
    from vibroimpact import analysis, study

    run = analysis.runner(SECTIONS)
    assert study.output_kind("x.nc") == ".nc"  # type: ignore[arg-type]  # a str is a path
    calls: list[tuple[str, Callable[[], Any]]] = [
        ("out", lambda: study.output_kind(None)),  # type: ignore[arg-type]
        ("study", lambda: study.chunk_part(None, 0, 1)),  # type: ignore[arg-type]
        ("count", lambda: run.periods(run.initial_state(), None)),  # type: ignore[arg-type]
        ("count", lambda: run.periods(run.initial_state(), 2.5)),  # type: ignore[arg-type]
        ("count", lambda: run.map(run.initial_state(), "3")),  # type: ignore[arg-type]
        ("state", lambda: run.periods("x", 1)),  # type: ignore[arg-type]
        ("count", lambda: run.shoot(run.initial_state(), None, 1e-9, 3)),  # type: ignore[arg-type]
    ]
    for name, call in calls:
        with pytest.raises(vi.InvalidInputError, match=rf"^{name}: "):
            call()


def test_a_study_axis_of_frequencies_no_run_can_step_through_is_refused() -> None:
    import tomllib

    import vibroimpact as vi
    from vibroimpact.study import study_of

    root = Path(__file__).resolve().parents[1]
    text = (root / "examples" / "clearance_study.toml").read_text(encoding="utf-8")
    data = tomllib.loads(text)
    data["study"]["axes"] = {"excitation.0.frequency": [1e-300, 10.0]}
    # Each run had failed as a numerical blow-up, its reason naming no frequency.
    with pytest.raises(vi.InvalidInputError) as caught:
        study_of(data, "s.toml", root / "examples")
    message = str(caught.value)
    assert message.startswith("s.toml: [study.axes] 'excitation.0.frequency': forcing frequency")
    assert "1e-300 Hz" in message and "at least" in message, message
    data["study"]["axes"] = {"excitation.0.frequency": [1e-6, 10.0]}
    study_of(data, "s.toml", root / "examples")


@pytest.mark.parametrize("header", ["time,value\n", ""])
def test_a_record_with_a_byte_order_mark_keeps_its_first_sample(
    tmp_path: Path, header: str
) -> None:
    # A spreadsheet's UTF-8 CSV starts with U+FEFF: "\ufeff0" was no number, so the
    # first sample was taken for a header and dropped.
    assert record(tmp_path, "\ufeff" + header + "0,1\n0.5,2\n1,3\n") == (
        [0.0, 0.5, 1.0],
        [1.0, 2.0, 3.0],
    )


def test_a_record_with_old_mac_line_ends_is_read_line_by_line(tmp_path: Path) -> None:
    # "\r" alone ends a line as an editor counts it; with a comment between samples
    # the file is read line by line (the arrays had been sized by "\n" alone).
    assert record(tmp_path, "t,v\r0,1\r# pause\r0.5,2\r1,3\r") == ([0.0, 0.5, 1.0], [1.0, 2.0, 3.0])
    message = record_error(tmp_path, "t,v\r0,1\r# pause\r1,2\r1,3\r")
    assert "rec.csv line 5: times must increase" in message, message


def test_the_binding_s_own_messages_write_numbers_short() -> None:
    import vibroimpact as vi
    from vibroimpact import analysis

    system = analysis.runner(SECTIONS).system()
    with pytest.raises(vi.InvalidInputError, match=r"strobe_period .* got -1e-300$"):
        system.run([0.0] * 4, 1.0, strobe_period=-1e-300)
    with pytest.raises(vi.InvalidInputError, match=r"tolerance .* got -1e\+300$"):
        system.shoot([0.0] * 4, 1.0, tolerance=-1e300, max_iterations=3)


@pytest.mark.parametrize(
    ("name", "bad"), [("spec", None), ("threads", "two"), ("analysis", 5), ("values", "abc")]
)
def test_run_study_names_an_argument_of_the_wrong_type(name: str, bad: Any) -> None:
    import vibroimpact as vi
    from vibroimpact import analysis

    spec = analysis.runner(SECTIONS).prepared.binding_spec()
    kwargs: dict[str, Any] = {
        "spec": spec,
        "initial": [[0.0], [0.0], [0.0], [0.0]],
        "paths": ["damper.0.clearance"],
        "values": np.array([0.005]),
        "method": "exact",
        "dt": None,
        "rtol": 1e-8,
        "atol": 1e-12,
        "beta": 0.25,
        "gamma": 0.5,
        "spectral_radius": 0.9,
        "max_steps": 10**6,
        "energy_tolerance": 0.05,
        "analysis": "run",
        "t_end": 0.01,
        "record_from": 0.0,
        "settle_periods": 1,
        "record_periods": 1,
        "tolerance": 1e-6,
        "threads": 1,
    }
    vi.run_study(**kwargs)  # valid as given
    # PyO3's TypeError named the argument only in a note.
    with pytest.raises(vi.InvalidInputError, match=rf"^{name} has the wrong type"):
        vi.run_study(**{**kwargs, name: bad})


@pytest.mark.parametrize("name", ["orbit", "lyapunov", "poincare"])
def test_too_many_periods_are_refused_naming_periods(name: str) -> None:
    # vi.orbit(s, periods=10**12) was told "count: must be >= 1 and at most ...", a
    # name from inside the runner it never gave.
    import vibroimpact as vi

    system = vi.load(Path(__file__).resolve().parents[1] / "examples" / "frf_impact_damper.toml")
    with pytest.raises(ValueError, match=r"^periods: must be a whole number in \[1, 10000000\]"):
        getattr(vi, name)(system, periods=10**12)


def test_a_section_written_as_a_list_of_tables_says_so() -> None:
    # [[structure]]: dict() of the list had said "dictionary update sequence element #0
    # has length 3; 2 is required", naming nothing (an adversarial pass).
    oscillator = {"kind": "oscillator", "mass": 1.0, "stiffness": 1.0}
    cases = [
        ({"structure": [oscillator]}, "[structure] must be a table, got a list of 1 table"),
        ({"structure": oscillator, "output": [{}]}, "[output] must be a table, got a list"),
    ]
    for sections, expected in cases:
        with pytest.raises(vi.InvalidInputError) as caught:
            vi.System.from_dict(sections)
        assert str(caught.value).startswith(expected), caught.value
    with pytest.raises(ValueError, match=r"\[\[structure\]\]\): write \[structure\], once$"):
        vi.loads('[[structure]]\nkind = "oscillator"\nmass = 1.0\nstiffness = 1.0\n')
