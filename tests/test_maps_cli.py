"""The commands continue, bifurcation, poincare and basins on their examples (their
JSON, plots and one-line errors), against the closed forms of :mod:`maps_checks`
(the ball on the vibrating table, Holmes 1982); the API's side is test_maps.py.
"""

from __future__ import annotations

import json
import shlex
import shutil
import subprocess
import sys
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import docs_blocks
from maps_checks import (
    AMPLITUDE,
    BALL_TABLE,
    BASINS,
    BIFURCATION,
    CONTINUATION,
    EXAMPLES,
    PNG_SIGNATURE,
    STATE_KEYS,
    RunCli,
    Table,
    angle_between,
    assert_one_line_error,
    assert_png,
    edited,
    load,
    release_flight_amplitude,
    write,
)
from orbit_checks import state_error  # noqa: E402


def run_json(run_cli: RunCli, *args: str) -> Any:
    done = run_cli(*args, "--json")
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout)


BRANCH_POINT_FIELDS = {
    "value",
    "state",
    "floquet_multipliers",
    "stable",
    "impacts_per_period",
    "amplitude",
    "flags",
    "crossings",
}


def test_continue_command_on_its_example(run_cli: RunCli, tmp_path: Path) -> None:
    table = Table(load(CONTINUATION))
    flip = table.flip() * table.g
    plot = tmp_path / "branch.png"
    out = run_json(run_cli, "continue", str(CONTINUATION), "--plot", str(plot))
    assert_png(plot)
    assert set(out) == {
        "parameter",
        "periods",
        "stopped",
        "points",
        "bifurcations",
        "switched",
        "cpu_time",
    }
    assert out["parameter"] == AMPLITUDE and out["periods"] == 1
    assert out["stopped"] == "reached stop"
    points = out["points"]
    for p in points:
        assert set(p) == BRANCH_POINT_FIELDS
        assert set(p["state"]) == STATE_KEYS
        assert p["state"]["damper_displacement"] == p["state"]["damper_velocity"] == []
        expected = table.orbit_state(table.gamma(p["value"]))
        got = np.array(
            [p["state"]["structure_displacement"][0], p["state"]["structure_velocity"][0]]
        )
        assert state_error(got, expected) < 1e-7
        assert all(len(m) == 2 for m in p["floquet_multipliers"])
        assert p["stable"] == (p["value"] < flip)
        assert p["impacts_per_period"] == 1
    (flagged,) = [p for p in points if p["flags"]]
    assert flagged["flags"] == ["flip"] and set(flagged["crossings"]) == {"flip"}
    # Located by Newton on the extended system: Holmes's closed form to round-off.
    assert flagged["crossings"]["flip"] == pytest.approx(flip, rel=1e-12)
    (located,) = out["bifurcations"]
    assert located["kind"] == "flip" and located["value"] == flagged["crossings"]["flip"]
    assert set(located) == {"kind", "value", "state", "floquet_multipliers"}
    # switch = true: the period-two branch born there, each orbit two impacts in two
    # periods, its product of multipliers e^4 (two impacts, no damping).
    doubled = out["switched"]
    assert doubled["periods"] == 2 and doubled["points"]
    e = table.e
    for p in doubled["points"]:
        assert p["impacts_per_period"] == 1
        m = [complex(*v) for v in p["floquet_multipliers"]]
        assert abs(m[0] * m[1] - e**4) < 1e-9
        assert p["value"] > located["value"]
    text = run_cli("continue", str(CONTINUATION))
    assert text.returncode == 0 and "flip at" in text.stdout and "reached stop" in text.stdout


def test_bifurcation_command_on_its_example(run_cli: RunCli, tmp_path: Path) -> None:
    data = load(BIFURCATION)
    table = Table(data)
    settings = data["sweep"]
    flip = table.flip() * table.g
    plot = tmp_path / "bifurcation.png"
    out = run_json(run_cli, "bifurcation", str(BIFURCATION), "--plot", str(plot))
    assert_png(plot)
    assert set(out) == {"parameter", "sample", "sample_units", "pair", "points", "cpu_time"}
    assert out["parameter"] == AMPLITUDE
    assert (out["sample"], out["sample_units"], out["pair"]) == ("displacement", "m", None)
    points = out["points"]
    assert len(points) == settings["count"]
    for p in points:
        assert set(p) == {"value", "direction", "strobe_displacement", "samples"}
        assert p["direction"] == "up"
        assert len(p["strobe_displacement"]) == settings["record_periods"]
        assert p["samples"] == p["strobe_displacement"]
    # (Within a percent of the flip a multiplier near -1 slows the settling down.)
    below = [p for p in points if p["value"] < 0.99 * flip]
    (first_above,) = [p for p in points if flip < p["value"] < 1.02 * flip]
    assert below
    for p in below:
        x = np.array(p["strobe_displacement"])
        expected = table.orbit_state(table.gamma(p["value"]))[0]
        assert x == pytest.approx(np.full(len(x), expected), rel=1e-6)
    x = np.array(first_above["strobe_displacement"])
    assert len(np.unique(np.round(x / np.max(x), 6))) == 2


def test_poincare_command_on_its_example(run_cli: RunCli, tmp_path: Path) -> None:
    table = Table(load(BIFURCATION))
    plot = tmp_path / "section.png"
    out = run_json(
        run_cli, "poincare", str(BIFURCATION), "--settle", "100", "--periods", "40",
        "--plot", str(plot),
    )  # fmt: skip
    assert_png(plot)
    assert set(out) == {
        "forcing_period",
        "strobe",
        "impact_phase",
        "impact_speed",
        "impact_pair",
        "cpu_time",
    }
    assert out["forcing_period"] == pytest.approx(table.period, rel=1e-15)
    assert len(out["strobe"]) == 40 and all(len(row) == 2 for row in out["strobe"])
    assert out["impact_pair"] == ["stop 0"] * 40
    phase = table.impact_phase(table.gamma())
    assert np.max(angle_between(np.array(out["impact_phase"]), phase)) < 1e-8
    np.testing.assert_allclose(out["impact_speed"], table.closing(), rtol=1e-8)


def small_basins(folder: Path, *changes: tuple[str, str]) -> Path:
    """The basins example on a 3 x 3 grid with shorter runs, plus ``changes``."""
    text = edited(
        BASINS,
        ("stop = 0.03, count = 21", "stop = 0.03, count = 3"),
        ("stop = 0.4, count = 21", "stop = 0.4, count = 3"),
        ("settle_periods = 200", "settle_periods = 100"),
        ("record_periods = 20", "record_periods = 5"),
        *changes,
    )
    return write(folder, "basins.toml", text)


def test_basins_command_on_its_example(run_cli: RunCli, tmp_path: Path) -> None:
    table = Table(load(BASINS))
    path = small_basins(tmp_path)
    plot = tmp_path / "basins.png"
    out = run_json(run_cli, "basins", str(path), "--plot", str(plot))
    assert_png(plot)
    assert set(out) == {
        "x",
        "y",
        "x_values",
        "y_values",
        "labels",
        "attractors",
        "cpu_time",
    }
    assert out["x"] == "structure_displacement.0" and out["y"] == "structure_velocity.0"
    assert out["x_values"] == pytest.approx([0.0, 0.015, 0.03], abs=1e-15)
    assert out["y_values"] == pytest.approx([-0.4, 0.0, 0.4], abs=1e-15)
    labels = out["labels"]
    assert len(labels) == 3 and all(len(row) == 3 for row in labels)
    for a in out["attractors"]:
        assert set(a) == {"period", "impacts_per_period", "amplitude"}
    # At rest on the table (0, 0): the chattering attractor.
    rest = out["attractors"][labels[0][1]]
    assert rest["impacts_per_period"] > 2
    assert rest["amplitude"][0] == pytest.approx(release_flight_amplitude(table), rel=1e-8)
    # Every start settles on one of the two attractors, the orbit's among them.
    assert {label for row in labels for label in row} <= {0, 1}
    amplitudes = sorted(a["amplitude"][0] for a in out["attractors"])
    assert amplitudes[-1] == pytest.approx(table.amplitude(table.gamma()), rel=1e-8)
    text = run_cli("basins", str(path))
    assert text.returncode == 0 and "impacts per period" in text.stdout


def continuation_file(folder: Path, *changes: tuple[str, str]) -> Path:
    return write(folder, "branch.toml", edited(CONTINUATION, *changes))


CONTINUATION_BAD = [
    (("periods = 1", "periods = 1\nsteps = 0.1"), ["[continuation]", "steps", "'step'"]),
    (("step = 0.3 ", 'step = "big" '), ["[continuation] step", "big"]),
    (("periods = 1", "periods = 1.5"), ["[continuation] periods", "1.5"]),
    (("stop = 17.0 ", "# stop = 17.0 "), ["[continuation]", "stop"]),
    (("step = 0.3 ", "step = 0.0 "), ["[continuation] step", "> 0"]),
    (("periods = 1", "periods = 0"), ["[continuation] periods", "in [1, 10000000]"]),
    (
        ("periods = 1", "periods = 1\nmax_points = 1"),
        ["[continuation] max_points", "in [2, 100000]"],
    ),
    (
        ('parameter = "excitation.0.amplitude"', 'parameter = "nonsense"'),
        ["[continuation] parameter", "nonsense"],
    ),
    (
        ('parameter = "excitation.0.amplitude"', 'parameter = "damper.0.clearance"'),
        ["parameter", "damper.0.clearance"],
    ),
    # Named by its table, as the table's own checks name theirs (a probe).
    (("stop = 17.0 ", "stop = 11.772 "), ["[continuation] stop", "other than the start"]),
]


@pytest.mark.parametrize(
    ("change", "fragments"),
    CONTINUATION_BAD,
    ids=[
        "unknown key",
        "wrong type",
        "not whole",
        "missing stop",
        "step 0",
        "periods 0",
        "max_points 1",
        "nonsense parameter",
        "no such entry",
        "stop at the start",
    ],
)
def test_bad_continuation_sections_exit_2_naming_the_key(
    run_cli: RunCli, tmp_path: Path, change: tuple[str, str], fragments: list[str]
) -> None:
    path = continuation_file(tmp_path, change)
    assert_one_line_error(run_cli("continue", str(path)), str(path), *fragments)


BASINS_BAD = [
    (
        ("record_periods = 5", "record_periods = 5\nrecord = 3"),
        ["[basins]", "record", "'record_periods'"],
    ),
    (("settle_periods = 100", 'settle_periods = "many"'), ["[basins] settle_periods", "many"]),
    (
        ('x = { state = "structure_displacement.0", start = 0.0, stop = 0.03, count = 3 }', ""),
        ["[basins]", "'x'"],
    ),
    (
        ('state = "structure_displacement.0"', 'state = "nonsense.0"'),
        ["[basins] x.state", "nonsense.0"],
    ),
    (("stop = 0.03, count = 3", "stop = 0.03, count = 0"), ["[basins] x.count", ">= 1"]),
    (("stop = 0.4, count = 3", 'stop = 0.4, count = "3"'), ["[basins] y.count", "'3'"]),
    (("stop = 0.4, count = 3", "stop = 0.4, count = 3, stpo = 1"), ["[basins] y", "stpo"]),
    # Said as "[basins] y: ... missing key 'stop'" (it had read "[basins] y.missing key").
    (("start = -0.4, stop = 0.4, ", "start = -0.4, "), ["[basins] y: ", "missing key 'stop'"]),
    (("record_periods = 5", "record_periods = 0"), ["[basins] record_periods", "in [1, 10000000]"]),
    # One value is start alone: stop had been dropped without a word.
    (("stop = 0.03, count = 3", "stop = 0.03, count = 1"), ["[basins] x.count", ">= 2", "0.03"]),
]


@pytest.mark.parametrize(
    ("change", "fragments"),
    BASINS_BAD,
    ids=[
        "unknown key",
        "wrong type",
        "missing x",
        "nonsense state",
        "count 0",
        "count a string",
        "unknown axis key",
        "missing axis stop",
        "record_periods 0",
        "count 1 dropping stop",
    ],
)
def test_bad_basins_sections_exit_2_naming_the_key(
    run_cli: RunCli, tmp_path: Path, change: tuple[str, str], fragments: list[str]
) -> None:
    path = small_basins(tmp_path, change)
    assert_one_line_error(run_cli("basins", str(path)), str(path), *fragments)


def test_a_basins_state_index_out_of_range_names_the_key(run_cli: RunCli, tmp_path: Path) -> None:
    path = small_basins(
        tmp_path, ('state = "structure_displacement.0"', 'state = "structure_displacement.3"')
    )
    assert_one_line_error(run_cli("basins", str(path)), str(path), "[basins] x.state")


@pytest.mark.parametrize(
    ("command", "source", "section"),
    [
        ("continue", BALL_TABLE, "[continuation]"),
        ("basins", BALL_TABLE, "[basins]"),
        ("bifurcation", BALL_TABLE, "[sweep]"),
    ],
)
def test_commands_without_their_section_exit_2(
    run_cli: RunCli, command: str, source: Path, section: str
) -> None:
    assert_one_line_error(run_cli(command, str(source)), str(source), section)


def test_bad_bifurcation_sweep_and_poincare_arguments_exit_2(
    run_cli: RunCli, tmp_path: Path
) -> None:
    path = write(
        tmp_path, "bif.toml", edited(BIFURCATION, ('direction = "up"', 'direction = "left"'))
    )
    assert_one_line_error(run_cli("bifurcation", str(path)), str(path), "[sweep] direction")
    assert_one_line_error(run_cli("poincare", str(BALL_TABLE), "--settle", "-1"), "--settle")
    assert_one_line_error(run_cli("poincare", str(BALL_TABLE), "--periods", "0"), "--periods")
    # Samples beyond a run's memory limit, refused before any run (1e5 points of 1e6
    # periods had grown until the allocator aborted; trial).
    huge = write(
        tmp_path,
        "huge.toml",
        edited(
            BIFURCATION,
            ("count = ", "count = 100000 #"),
            ("record_periods = ", "record_periods = 1000000 #"),
        ),
    )
    assert_one_line_error(run_cli("bifurcation", str(huge)), "[sweep] record_periods", "MiB")


def test_help_lists_the_new_commands(run_cli: RunCli) -> None:
    done = run_cli("--help")
    assert done.returncode == 0
    for command in ("continue", "bifurcation", "poincare", "basins"):
        assert command in done.stdout
        sub = run_cli(command, "--help")
        assert sub.returncode == 0 and "--plot" in sub.stdout and "--json" in sub.stdout


def test_the_docs_map_commands_work_as_written(tmp_path: Path) -> None:
    # The section's "sh" block holds the orbit and sweep commands (test_analysis_cli);
    # the commands of these analyses are in its "shell" block.
    analyses = docs_blocks.section("analyses", "Forced response and periodic orbits")
    (block,) = docs_blocks.blocks(analyses, "shell")
    commands = [line for line in block.splitlines() if line.strip()]
    verbs = {shlex.split(c)[1] for c in commands}
    assert verbs == {"continue", "bifurcation", "poincare", "basins"}
    shutil.copytree(EXAMPLES, tmp_path / "examples")
    plots = []
    for command in commands:
        argv = shlex.split(command)
        assert argv[0] == "vibroimpact", command
        done = subprocess.run(
            [sys.executable, "-m", "vibroimpact", *argv[1:]],
            cwd=tmp_path,
            capture_output=True,
            text=True,
            timeout=50,
            check=False,
        )
        assert done.returncode == 0, (command, done.stderr)
        if "--json" in argv:
            json.loads(done.stdout)
        if "--plot" in argv:
            plots.append(argv[argv.index("--plot") + 1])
    assert len(plots) == 4
    for name in plots:
        assert_png(tmp_path / name)


def test_the_basins_plot_of_starts_all_inside_the_wall(tmp_path: Path) -> None:
    # No attractor at all (every start inside the table): the colour bar had one
    # colour more than its labels, a matplotlib traceback from `basins --plot` (trial).
    from vibroimpact.analysis import Basins
    from vibroimpact.analysis.plots import plot_basins

    grid = np.array([-0.03, -0.02, -0.01])
    result = Basins(grid, grid, np.full((3, 3), -3), [])
    png = tmp_path / "b.png"
    plot_basins(png, result, "structure_displacement 0", "structure_velocity 0")
    data = png.read_bytes()
    assert data[:8] == PNG_SIGNATURE and data.endswith(b"IEND\xaeB`\x82")


def test_the_bifurcation_command_prints_a_failed_points_error(
    run_cli: RunCli, tmp_path: Path
) -> None:
    # With max_steps = 60 the runs at the middle amplitude fail and the others do not:
    # the failed point had been printed as "0 distinct stroboscopic displacement(s) of 0".
    text = BALL_TABLE.read_text().replace("[solver]", "[solver]\nmax_steps = 60", 1)
    text += (
        '\n[sweep]\nparameter = "excitation.0.amplitude"\nstart = 5.0\nstop = 20.0\n'
        "count = 3\nsettle_periods = 4\nrecord_periods = 4\n"
    )
    path = tmp_path / "failing.toml"
    path.write_text(text)
    result = run_cli("bifurcation", str(path))
    assert result.returncode == 0, result.stderr
    lines = [line for line in result.stdout.splitlines() if " up: " in line]
    assert len(lines) == 3, result.stdout
    failed = lines[1]
    assert "failed: " in failed and "max_steps" in failed, failed
    assert "distinct" not in failed
    for line in (lines[0], lines[2]):
        assert "distinct stroboscopic displacement(s) of 4" in line, line
