"""Messages and Python types (issue 23): a recorded CSV read by NumPy within a bounded
memory, its errors naming the file and the line as a user counts them; every public
function refusing a value of the wrong type with InvalidInputError naming the argument;
keys' ranges, sizes and steps refused with their real range, numbers written short."""

from __future__ import annotations

import subprocess
import sys
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

from vibroimpact.record_file import MAX_RECORDED_FILE_BYTES
from vibroimpact.scenario import ScenarioError, parse_scenario

Cli = Callable[..., subprocess.CompletedProcess[str]]

RECORDED = """
[structure]
kind = "oscillator"
mass = 1.0
stiffness = 100.0

[solver]
method = "dopri5"
t_end = 0.1

[[excitation]]
kind = "base"
signal = "recorded"
file = "rec.csv"
{extra}
"""


def refused(done: subprocess.CompletedProcess[str], *words: str) -> str:
    """The one-line error of a command refused with exit status 2, holding ``words``."""
    assert done.returncode == 2, done.stdout + done.stderr
    assert "Traceback" not in done.stderr, done.stderr
    assert len(done.stderr.strip().splitlines()) == 1, done.stderr
    for word in words:
        assert word in done.stderr, done.stderr
    return done.stderr


def record_error(tmp_path: Path, csv: str, extra: str = "") -> str:
    (tmp_path / "rec.csv").write_text(csv, encoding="utf-8")
    with pytest.raises(ScenarioError) as caught:
        parse_scenario(RECORDED.format(extra=extra), "s.toml", tmp_path)
    message = str(caught.value)
    assert "\n" not in message
    return message


def record(tmp_path: Path, csv: str) -> tuple[list[float], list[float]]:
    (tmp_path / "rec.csv").write_text(csv, encoding="utf-8")
    scenario = parse_scenario(RECORDED.format(extra=""), "s.toml", tmp_path)
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
    (tmp_path / "s.toml").write_text(RECORDED.format(extra=""))
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
    (tmp_path / "s.toml").write_text(RECORDED.format(extra=""))
    child = (
        "import sys\n"
        "from vibroimpact.scenario import load_scenario\n"
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
    assert peak < 8 * MAX_RECORDED_FILE_BYTES, f"{peak / 2**20:.0f} MiB"


def test_a_record_file_beyond_the_limit_is_refused_before_it_is_read(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from vibroimpact import record_file

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
