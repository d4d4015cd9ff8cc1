"""The ``orbit`` and ``sweep`` commands: the examples against closed forms, the
plot written whole, and bad input refused with exit status 2 and one line naming
the key (never a traceback)."""

from __future__ import annotations

import json
import math
import re
import shlex
import shutil
import subprocess
import sys
import tomllib
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

import docs_blocks
import vibroimpact as vi

ROOT = Path(__file__).resolve().parents[1]
BALL_TABLE = ROOT / "examples" / "bouncing_ball_table.toml"
FRF = ROOT / "examples" / "frf_impact_damper.toml"
PAPER = ROOT / "examples" / "paper_collision.toml"
UNFORCED_BALL = ROOT / "examples" / "bouncing_ball.toml"

RunCli = Callable[..., subprocess.CompletedProcess[str]]

STATE_KEYS = {
    "structure_displacement",
    "structure_velocity",
    "damper_displacement",
    "damper_velocity",
}
ORBIT_FIELDS = {
    "converged",
    "state",
    "floquet_multipliers",
    "stable",
    "jacobian",
    "grazings",
    "impacts_per_period",
    "amplitude",
    "periods",
    "forcing_period",
    "iterations",
    "residual",
    "cpu_time",
}
POINT_FIELDS = {
    "value",
    "direction",
    "amplitude",
    "rms",
    "impacts_per_period",
    "settled",
    "linear_amplitude",
    "reduction",
}
PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"
PNG_END = b"IEND\xaeB`\x82"  # the IEND chunk's type and CRC close every PNG


def edited(source: Path, *changes: tuple[str, str]) -> str:
    """The text of ``source`` with each ``old`` replaced once by ``new``."""
    text = source.read_text(encoding="utf-8")
    for old, new in changes:
        assert old in text, old
        text = text.replace(old, new, 1)
    return text


def write(folder: Path, name: str, text: str) -> Path:
    path = folder / name
    path.write_text(text, encoding="utf-8")
    return path


def small_frf(folder: Path, *changes: tuple[str, str]) -> Path:
    """The FRF example with 5 points each way and short runs, plus ``changes``."""
    text = edited(
        FRF,
        ("count = 61", "count = 5"),
        ("settle_periods = 200", "settle_periods = 20"),
        ("record_periods = 50", "record_periods = 5"),
        *changes,
    )
    return write(folder, "frf.toml", text)


def assert_one_line_error(done: subprocess.CompletedProcess[str], *fragments: str) -> None:
    assert done.returncode == 2, (done.returncode, done.stdout, done.stderr)
    assert "Traceback" not in done.stderr, done.stderr
    assert done.stderr.startswith("vibroimpact: error: "), done.stderr
    assert done.stderr.count("\n") == 1 and done.stderr.endswith("\n"), done.stderr
    for fragment in fragments:
        assert fragment in done.stderr, (fragment, done.stderr)
    assert done.stdout == ""


def run_json(run_cli: RunCli, *args: str) -> Any:
    done = run_cli(*args, "--json")
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout)


# ------------------------------------------------------------------------- orbit


def test_holmes_orbit_of_the_ball_on_the_table_has_multipliers_of_modulus_e(
    run_cli: RunCli,
) -> None:
    e = tomllib.loads(BALL_TABLE.read_text(encoding="utf-8"))["stop"][0]["restitution"]
    assert e == 0.5
    out = run_json(run_cli, "orbit", str(BALL_TABLE))
    assert set(out) == ORBIT_FIELDS
    assert set(out["state"]) == STATE_KEYS
    assert len(out["state"]["structure_displacement"]) == 1
    assert out["state"]["damper_displacement"] == out["state"]["damper_velocity"] == []
    assert out["converged"] is True and out["stable"] is True
    assert out["impacts_per_period"] == 1
    assert out["periods"] == 1 and out["forcing_period"] == pytest.approx(0.1, rel=1e-15)
    assert out["residual"] <= 1e-10
    # The impact map has determinant e^2 and complex multipliers: both of modulus e.
    for pair in out["floquet_multipliers"]:
        assert len(pair) == 2 and all(isinstance(v, float) for v in pair)
    multipliers = [complex(re, im) for re, im in out["floquet_multipliers"]]
    assert len(multipliers) == 2
    for m in multipliers:
        assert abs(m) == pytest.approx(e, abs=1e-6)
        assert abs(m.imag) > 0.1
    assert multipliers[0] == pytest.approx(multipliers[1].conjugate(), abs=1e-6)
    assert multipliers[0] * multipliers[1] == pytest.approx(e * e, abs=1e-6)
    amplitude = out["amplitude"]
    assert len(amplitude) == 1 and amplitude[0] >= out["state"]["structure_displacement"][0] > 0


def test_the_orbit_state_returns_after_one_period_with_holmes_impact_speed(
    run_cli: RunCli, tmp_path: Path
) -> None:
    out = run_json(run_cli, "orbit", str(BALL_TABLE))
    x = out["state"]["structure_displacement"][0]
    v = out["state"]["structure_velocity"][0]
    text = edited(
        BALL_TABLE,
        ("structure_displacement = [0.015]", f"structure_displacement = [{x!r}]"),
        ("structure_velocity = [0.16]", f"structure_velocity = [{v!r}]"),
        ("t_end = 1.0", f"t_end = {out['forcing_period']!r}"),
    )
    run = run_json(run_cli, "simulate", str(write(tmp_path, "orbit.toml", text)))
    assert run["final_state"]["structure_displacement"][0] == pytest.approx(x, rel=1e-9)
    assert run["final_state"]["structure_velocity"][0] == pytest.approx(v, rel=1e-9)
    # One flight of one period T between impacts on the table: the ball meets the
    # table at gT/(1 + e) relative speed and leaves at e times it.
    (contact,) = run["contacts"]
    g, e, period = 9.81, 0.5, out["forcing_period"]
    assert contact["kind"] == "impact"
    assert contact["approach_speed"] == pytest.approx(g * period / (1 + e), rel=1e-9)
    assert contact["rebound_speed"] == pytest.approx(e * g * period / (1 + e), rel=1e-9)


def test_an_orbit_over_two_periods_has_the_squared_multipliers(run_cli: RunCli) -> None:
    one = run_json(run_cli, "orbit", str(BALL_TABLE))
    two = run_json(run_cli, "orbit", str(BALL_TABLE), "--periods", "2")
    assert two["converged"] is True and two["stable"] is True and two["periods"] == 2
    assert two["impacts_per_period"] == 1
    for key in ("structure_displacement", "structure_velocity"):
        assert two["state"][key] == pytest.approx(one["state"][key], rel=1e-8)
    squares = sorted(
        (complex(re, im) ** 2 for re, im in one["floquet_multipliers"]), key=lambda z: z.imag
    )
    got = sorted((complex(re, im) for re, im in two["floquet_multipliers"]), key=lambda z: z.imag)
    for a, b in zip(got, squares, strict=True):
        assert a == pytest.approx(b, abs=1e-6)
        assert abs(a) == pytest.approx(0.25, abs=1e-6)


def test_orbit_prints_a_readable_summary(run_cli: RunCli) -> None:
    done = run_cli("orbit", str(BALL_TABLE))
    assert done.returncode == 0, done.stderr
    assert "converged" in done.stdout and "Floquet multipliers" in done.stdout
    assert "|0.5|" in done.stdout and "structure_displacement = [" in done.stdout


def test_an_orbit_not_found_says_its_figures_are_of_the_last_iterate(
    capsys: pytest.CaptureFixture[str],
) -> None:
    from vibroimpact.cli import command as cli

    # One Newton iteration from a start off the orbit cannot converge.
    assert cli.main(["orbit", str(BALL_TABLE), "--max-iterations", "1"]) == 0
    out = capsys.readouterr().out
    assert "did NOT converge" in out
    assert "last Newton iterate, not of an orbit; start nearer it with --settle N" in out
    # A converged one does not say so.
    assert cli.main(["orbit", str(BALL_TABLE)]) == 0
    assert "last Newton iterate" not in capsys.readouterr().out


def test_orbit_settles_before_shooting_where_asked(capsys: pytest.CaptureFixture[str]) -> None:
    # The command shot from [initial] alone, with no bound on its iterations: a new
    # user's cantilever ran 86 s to no orbit, with no way to start nearer it.
    from vibroimpact.cli import command as cli

    assert cli.main(["orbit", str(BALL_TABLE), "--settle", "30", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    run = vi.runner(tomllib.loads(BALL_TABLE.read_text(encoding="utf-8")))
    expected = vi.orbit(run, run.map(run.initial_state(), 30))
    assert out["converged"] and out["iterations"] == expected.iterations
    assert out["state"] == expected.arrays(run.n, run.k)


# ------------------------------------------------------------------------- sweep


def test_frf_example_sweeps_up_and_down_and_matches_the_linear_closed_form(
    run_cli: RunCli,
) -> None:
    data = tomllib.loads(FRF.read_text(encoding="utf-8"))
    structure, force, settings = data["structure"], data["excitation"][0], data["sweep"]
    out = run_json(run_cli, "sweep", str(FRF))
    assert set(out) == {"parameter", "points", "cpu_time"}
    assert out["parameter"] == settings["parameter"] == "excitation.0.frequency"
    points = out["points"]
    count = settings["count"]
    assert len(points) == 2 * count
    for p in points:
        assert set(p) == POINT_FIELDS, p
    up = [p for p in points if p["direction"] == "up"]
    down = [p for p in points if p["direction"] == "down"]
    assert points == up + down and len(up) == len(down) == count
    values = [p["value"] for p in up]
    assert values == sorted(values) and [p["value"] for p in down] == values[::-1]
    assert values[0] == pytest.approx(settings["start"], rel=1e-15)
    assert values[-1] == pytest.approx(settings["stop"], rel=1e-15)

    # The structure alone: F / |K - w^2 M + i w C| at every point.
    mass, stiffness, damping = structure["mass"], structure["stiffness"], structure["damping"]
    for p in points:
        w = 2 * math.pi * p["value"]
        closed = force["amplitude"] / abs(stiffness - w * w * mass + 1j * w * damping)
        assert p["linear_amplitude"][0] == pytest.approx(closed, rel=1e-9), p["value"]

    # At the lowest frequency, swept up from rest, the loose mass never touches its
    # walls: the structure responds as if it were not there, harmonically.
    low = up[0]
    assert low["impacts_per_period"] == 0 and low["settled"] is True
    assert low["amplitude"][0] == pytest.approx(low["linear_amplitude"][0], rel=1e-6)
    assert low["reduction"][0] == pytest.approx(0.0, abs=1e-6)
    assert low["rms"][0] == pytest.approx(low["amplitude"][0] / math.sqrt(2), rel=1e-6)

    # At resonance the impacts take a large part of the response, either way.
    for leg in (up, down):
        (resonance,) = [p for p in leg if p["value"] == pytest.approx(10.0)]
        assert resonance["impacts_per_period"] > 0
        assert resonance["reduction"][0] > 0.3
        assert resonance["reduction"][0] == pytest.approx(
            1 - resonance["amplitude"][0] / resonance["linear_amplitude"][0], rel=1e-12
        )


def test_sweep_direction_up_or_down_runs_one_leg(run_cli: RunCli, tmp_path: Path) -> None:
    for direction in ("up", "down"):
        path = small_frf(tmp_path, ('direction = "both"', f'direction = "{direction}"'))
        points = run_json(run_cli, "sweep", str(path))["points"]
        assert [p["direction"] for p in points] == [direction] * 5
        values = [p["value"] for p in points]
        assert values == sorted(values, reverse=direction == "down")


def test_log_spacing_is_geometric(run_cli: RunCli, tmp_path: Path) -> None:
    path = small_frf(
        tmp_path,
        ("count = 5", 'count = 3\nspacing = "log"'),
        ('direction = "both"', 'direction = "up"'),
    )
    values = [p["value"] for p in run_json(run_cli, "sweep", str(path))["points"]]
    assert values == pytest.approx([7.0, math.sqrt(7.0 * 13.0), 13.0], rel=1e-12)


def test_sweep_plot_is_a_png_that_replaces_an_existing_file_whole(
    run_cli: RunCli, tmp_path: Path
) -> None:
    path = small_frf(tmp_path)
    plot = tmp_path / "frf.png"
    plot.write_bytes(b"old plot " * 200_000)  # longer than the new PNG
    done = run_cli("sweep", str(path), "--plot", str(plot))
    assert done.returncode == 0, done.stderr
    assert f"plot written to {plot}" in done.stdout
    # The table's units, above it (its columns had none).
    units = "(value: excitation.0.frequency, Hz; amplitude, linear and rms: m)"
    assert done.stdout.splitlines()[1] == units, done.stdout
    data = plot.read_bytes()
    assert data.startswith(PNG_SIGNATURE) and data.endswith(PNG_END)
    assert b"old plot" not in data
    # Nothing else left beside it (no temporary file).
    assert sorted(p.name for p in tmp_path.iterdir()) == ["frf.png", "frf.toml"]
    # --json and --plot together: the JSON on stdout alone, the plot written again.
    plot.write_bytes(b"stale")
    out = run_json(run_cli, "sweep", str(path), "--plot", str(plot))
    assert len(out["points"]) == 10
    assert plot.read_bytes().startswith(PNG_SIGNATURE)


@pytest.mark.parametrize(
    ("change", "message"),
    [
        (('direction = "both"', 'direction = "sideways"'), "direction"),
        (
            ('parameter = "excitation.0.frequency"', 'parameter = "damper.7.clearance"'),
            "damper.7",
        ),
    ],
    ids=["bad scenario", "sweep failing at its first point"],
)
def test_a_failing_sweep_leaves_an_existing_plot_untouched(
    run_cli: RunCli, tmp_path: Path, change: tuple[str, str], message: str
) -> None:
    path = small_frf(tmp_path, change)
    plot = tmp_path / "frf.png"
    plot.write_bytes(b"the previous plot")
    done = run_cli("sweep", str(path), "--plot", str(plot))
    assert_one_line_error(done, message)
    assert plot.read_bytes() == b"the previous plot"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["frf.png", "frf.toml"]


def test_an_unwritable_plot_exits_2(run_cli: RunCli, tmp_path: Path) -> None:
    path = small_frf(tmp_path)
    done = run_cli("sweep", str(path), "--plot", str(tmp_path / "missing" / "frf.png"))
    assert_one_line_error(done, "frf.png")


# --------------------------------------------------------------------- bad input

SWEEP_BAD = [
    (
        ("count = 5", "count = 5\nsetle_periods = 3"),
        ["[sweep]", "setle_periods", "did you mean 'settle_periods'"],
    ),
    (("count = 5", 'count = "ten"'), ["[sweep] count", "ten"]),
    (('direction = "both"', 'direction = "sideways"'), ["[sweep] direction", "sideways"]),
    (("count = 5", "count = 0"), ["[sweep] count", "in [1, 100000]"]),
    (
        ('parameter = "excitation.0.frequency"', 'parameter = "nonsense"'),
        ["[sweep] parameter", "nonsense"],
    ),
    (
        ('parameter = "excitation.0.frequency"', 'parameter = "damper.7.clearance"'),
        ["parameter", "damper.7"],
    ),
]


@pytest.mark.parametrize(
    ("change", "fragments"),
    SWEEP_BAD,
    ids=["unknown key", "wrong type", "direction", "count 0", "nonsense", "no such entry"],
)
def test_bad_sweep_sections_exit_2_naming_the_key(
    run_cli: RunCli, tmp_path: Path, change: tuple[str, str], fragments: list[str]
) -> None:
    path = small_frf(tmp_path, change)
    assert_one_line_error(run_cli("sweep", str(path)), str(path), *fragments)


@pytest.mark.parametrize(
    ("change", "fragments"),
    [
        (
            ('parameter = "excitation.0.frequency"', 'parameter = "excitation.0.freq"'),
            ["[sweep] parameter", "[excitation] has no key 'freq'", "did you mean 'frequency'"],
        ),
        (
            ("[sweep]", '[continuation]\nparameter = "structure.stifness"\nstop = 1.0\n[sweep]'),
            ["[continuation] parameter", "[structure] has no key 'stifness'"],
        ),
        (
            ("[sweep]", '[study.axes]\n"damper.0.mas" = [0.05]\n[sweep]'),
            ["[study.axes]", "[damper] has no key 'mas'", "did you mean 'mass'"],
        ),
        # An entry the scenario does not have, a value that is no number (a new user:
        # a plain run took the first; the sweep said 'law: must be a string, got 7.0').
        (
            ('parameter = "excitation.0.frequency"', 'parameter = "excitation.1.frequency"'),
            ["[sweep] parameter", "the scenario has 1 [[excitation]] (index 0)"],
        ),
        (
            ('parameter = "excitation.0.frequency"', 'parameter = "damper.0.law"'),
            ["[sweep] parameter", "'damper.0.law' is 'rigid' in the scenario, not a number"],
        ),
    ],
    ids=["sweep", "continuation", "study axis", "missing entry", "not a number"],
)
def test_a_misspelt_parameter_key_is_refused_when_the_file_is_read(
    run_cli: RunCli, tmp_path: Path, change: tuple[str, str], fragments: list[str]
) -> None:
    # A plain run of the file had taken it; only the analysis refused it, later.
    path = small_frf(tmp_path, change)
    assert_one_line_error(run_cli("simulate", str(path)), str(path), *fragments)
    with pytest.raises(ValueError, match=re.escape(fragments[1])):
        vi.load(path)


def test_a_misspelt_derivative_key_is_told_the_closest(run_cli: RunCli, tmp_path: Path) -> None:
    # `--derivative damper.0.clearence` said only "not set in the scenario".
    path = small_frf(tmp_path, ("count = 5", "count = 5"))
    done = run_cli("orbit", str(path), "--derivative", "damper.0.clearence")
    assert_one_line_error(done, "[damper] has no key 'clearence'", "did you mean 'clearance'")
    done = run_cli("orbit", str(path), "--derivative", "damper.3.clearance")
    assert_one_line_error(done, "'damper.3.clearance': the scenario has 1 [[damper]] (index 0)")


def test_sweep_without_a_sweep_section_exits_2(run_cli: RunCli, tmp_path: Path) -> None:
    text = FRF.read_text(encoding="utf-8").split("[sweep]")[0]
    path = write(tmp_path, "frf.toml", text)
    assert_one_line_error(run_cli("sweep", str(path)), str(path), "[sweep]")


@pytest.mark.parametrize("command", ["orbit", "sweep"])
def test_orbit_and_sweep_refuse_a_two_mass_scenario(run_cli: RunCli, command: str) -> None:
    assert_one_line_error(run_cli(command, str(PAPER)), str(PAPER), "[structure]")


def test_orbit_needs_a_harmonic_excitation(run_cli: RunCli, tmp_path: Path) -> None:
    assert_one_line_error(run_cli("orbit", str(UNFORCED_BALL)), "needs a harmonic excitation")
    swept = edited(
        BALL_TABLE,
        ('signal = "harmonic"', 'signal = "sweep"'),
        ("frequency = 10.0", "start_frequency = 9.0\nend_frequency = 11.0"),
    )
    path = write(tmp_path, "swept.toml", swept)
    assert_one_line_error(
        run_cli("orbit", str(path)), 'excitation 0: a "sweep" signal has no period'
    )


@pytest.mark.parametrize(
    ("second", "fragment"),
    [
        (
            'signal = "harmonic"\namplitude = 1.0\nfrequency = 14.142135623730951',
            "has no common period with 10",
        ),
        ('signal = "harmonic"\namplitude = 1.0\nfrequency = 15.0', None),
        ('signal = "harmonics"\namplitudes = [1.0, 0.5]\nfrequencies = [0.0, 20.0]', None),
        ('signal = "recorded"\ntime = [0.0, 1.0]\nvalue = [0.0, 1.0]', '"recorded" signal has no'),
    ],
    ids=[
        "10 Hz and 10 sqrt(2) Hz: no common period",
        "10 Hz and 15 Hz: a period of 0.2 s",
        "a constant and 20 Hz beside 10 Hz",
        "a recorded force",
    ],
)
def test_orbit_needs_forcing_with_a_period(
    run_cli: RunCli, tmp_path: Path, second: str, fragment: str | None
) -> None:
    # The 10 Hz table plus a second force on the ball.
    text = BALL_TABLE.read_text(encoding="utf-8")
    head, tail = text.split("[solver]")
    extra = f'[[excitation]]\nkind = "force"\nat = 0\n{second}\n\n'
    path = write(tmp_path, "two.toml", head + extra + "[solver]" + tail)
    done = run_cli("orbit", str(path), "--json")
    if fragment is None:
        assert done.returncode == 0, done.stderr
        out = json.loads(done.stdout)
        # The common period: 1 / 5 Hz with 15 Hz beside 10 Hz, else 1 / 10 Hz.
        expected = 0.2 if "15.0" in second else 0.1
        assert out["forcing_period"] == pytest.approx(expected, rel=1e-12)
        assert "converged" in out
    else:
        assert_one_line_error(done, "excitation 1", fragment)


@pytest.mark.parametrize(
    ("args", "fragment"),
    [
        (("--periods", "0"), "--periods"),
        (("--periods", "-3"), "--periods"),
        (("--tolerance", "0"), "--tolerance"),
        (("--settle", "-1"), "--settle"),
        (("--max-iterations", "0"), "--max-iterations"),
    ],
)
def test_bad_orbit_arguments_exit_2(run_cli: RunCli, args: tuple[str, str], fragment: str) -> None:
    assert_one_line_error(run_cli("orbit", str(BALL_TABLE), *args), fragment)


def compliant_frf(folder: Path, method: str = "exact") -> Path:
    """The FRF example with a Hertz contact instead of rigid impacts."""
    return small_frf(
        folder,
        ('law = "rigid"            # "rigid"', 'law = "hertz"            # "rigid"'),
        ("restitution = 0.6", "stiffness = 1e7          # N/m^1.5"),
        ('method = "exact" ', f'method = "{method}" '),
    )


@pytest.mark.parametrize("command", ["simulate", "orbit", "sweep"])
def test_exact_refuses_a_compliant_law(run_cli: RunCli, tmp_path: Path, command: str) -> None:
    path = compliant_frf(tmp_path)
    assert_one_line_error(run_cli(command, str(path)), '"exact"', "rigid")


FILE_NAMED = [
    pytest.param("simulate", "compliant", id="simulate, exact with a compliant law"),
    pytest.param(
        "orbit",
        "compliant",
        id="orbit, exact with a compliant law",
    ),
    pytest.param(
        "sweep",
        "compliant",
        id="sweep, exact with a compliant law",
    ),
    pytest.param(
        "orbit",
        "unforced",
        id="orbit without a harmonic excitation",
    ),
]


@pytest.mark.parametrize(("command", "case"), FILE_NAMED)
def test_errors_from_a_scenario_name_its_file(
    run_cli: RunCli, tmp_path: Path, command: str, case: str
) -> None:
    # The command line's convention: an error in a scenario names the file.
    path = compliant_frf(tmp_path) if case == "compliant" else UNFORCED_BALL
    assert_one_line_error(run_cli(command, str(path)), str(path))


def test_a_sweep_with_a_compliant_contact_completes(run_cli: RunCli, tmp_path: Path) -> None:
    path = compliant_frf(tmp_path, "dop853")
    text = edited(
        path,
        ("count = 5", "count = 7"),
        ("settle_periods = 20", "settle_periods = 200"),
        ("record_periods = 5", "record_periods = 50"),
    )
    done = run_cli("sweep", str(write(tmp_path, "frf.toml", text)), "--json")
    assert done.returncode == 0, done.stderr
    points = json.loads(done.stdout)["points"]
    assert len(points) == 14 and all("error" not in p for p in points)
    assert points[0]["amplitude"][0] == pytest.approx(points[0]["linear_amplitude"][0], rel=1e-6)


# -------------------------------------------------------------------------- help


def test_help_lists_orbit_and_sweep(run_cli: RunCli) -> None:
    done = run_cli("--help")
    assert done.returncode == 0, done.stderr
    assert "orbit" in done.stdout and "sweep" in done.stdout
    orbit_help = run_cli("orbit", "--help")
    assert orbit_help.returncode == 0 and "Floquet" in orbit_help.stdout
    assert "--periods" in orbit_help.stdout and "--tolerance" in orbit_help.stdout
    sweep_help = run_cli("sweep", "--help")
    assert sweep_help.returncode == 0 and "[sweep]" in sweep_help.stdout
    assert "--plot" in sweep_help.stdout


# ------------------------------------------------------- the documentation's analyses page

ANALYSES = docs_blocks.section("analyses", "Forced response and periodic orbits")


def test_the_docs_analysis_commands_work_as_written(tmp_path: Path) -> None:
    shutil.copytree(ROOT / "examples", tmp_path / "examples")
    blocks = docs_blocks.blocks(ANALYSES, "sh")
    commands = [line for block in blocks for line in block.splitlines() if line.strip()]
    assert {shlex.split(c)[1] for c in commands} == {
        "orbit",
        "sweep",
        "lyapunov",
        "continue",
        "curve",
    }
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
    assert (tmp_path / "frf.png").read_bytes().startswith(PNG_SIGNATURE)
    assert (tmp_path / "convergence.png").read_bytes().startswith(PNG_SIGNATURE)
    assert (tmp_path / "flip_curve.png").read_bytes().startswith(PNG_SIGNATURE)


def test_the_docs_analysis_snippet_runs_and_its_comments_are_true(
    capsys: pytest.CaptureFixture[str],
) -> None:
    (code,) = docs_blocks.blocks(ANALYSES, "python")
    exec(compile(code, "analyses.rst", "exec"), {})
    lines = capsys.readouterr().out.splitlines()
    claims = [m.group(1).strip() for m in re.finditer(r"print\(.*?#(.*)$", code, flags=re.M)]
    assert len(lines) == len(claims) == 4
    numbers = re.compile(r"-?[0-9]+(?:\.[0-9]+)?(?:e-?[0-9]+)?|True|False|\(250, 4\)")
    for printed, claim in zip(lines, claims, strict=True):
        got, want = numbers.findall(printed), numbers.findall(claim)
        assert len(got) == len(want), (printed, claim)
        for g, w in zip(got, want, strict=True):
            if w[0].isdigit() or w[0] == "-":
                digits = len(w.split(".")[1]) if "." in w else 0
                assert abs(float(g) - float(w)) <= 0.5 * 10.0**-digits, (printed, claim)
            else:
                assert g == w, (printed, claim)


def test_the_docs_sweep_block_is_the_example_with_every_key() -> None:
    (block,) = docs_blocks.blocks(ANALYSES, "toml")
    documented = tomllib.loads(block)
    example = tomllib.loads(FRF.read_text(encoding="utf-8"))
    assert documented["sweep"].keys() >= {
        "parameter",
        "start",
        "stop",
        "count",
        "spacing",
        "direction",
        "settle_periods",
        "record_periods",
        "tolerance",
    }
    for section in ("structure", "damper", "excitation", "solver"):
        assert documented[section] == example[section], section
    for key, value in example["sweep"].items():
        assert documented["sweep"][key] == value, key


def test_a_poincare_section_too_long_to_keep_is_refused_early(
    run_cli: RunCli, tmp_path: Path
) -> None:
    # Holmes's ball at Gamma 1.7 keeps about 4.2 contacts a period: 10 million periods
    # (within the 10-million cap on periods) had run 15.5 s into 1.24 GB before the
    # row limit stopped it; the first thousand periods foretell it.
    text = (ROOT / "examples" / "ball_table_basins.toml").read_text()
    scenario = write(tmp_path, "g17.toml", text.replace("amplitude = 11.772", "amplitude = 16.677"))
    # Within 10 s (the whole run took 15.5 s): the run's timeout is the bound.
    done = run_cli("poincare", str(scenario), "--settle", "0", "--periods", "10000000", timeout=10)
    assert_one_line_error(
        done, "--periods 10000000", "max_rows (20000000)", "a period over the first 1000"
    )
    # One that fits runs.
    section = run_json(run_cli, "poincare", str(scenario), "--settle", "0", "--periods", "10000")
    assert len(section["strobe"]) == 10000


@pytest.mark.parametrize(
    ("command", "extra"),
    [
        ("orbit", []),
        ("sweep", []),
        ("bifurcation", []),
        ("poincare", []),
        ("basins", []),
        ("continue", []),
        ("lyapunov", []),
        ("curve", []),
        ("study", ["--out", "result.nc"]),
    ],
)
def test_a_two_mass_file_is_refused_naming_the_command_and_structure(
    table1_toml: str,
    write_scenario: Callable[[str, str], Path],
    run_cli: Callable[..., subprocess.CompletedProcess[str]],
    command: str,
    extra: list[str],
) -> None:
    # The message said "orbit and sweep take a 0.2 scenario" whatever the command, in a
    # version's jargon the README never uses.
    path = write_scenario(table1_toml, "two_mass.toml")
    proc = run_cli(command, str(path), *extra)
    assert proc.returncode == 2, proc.stderr
    said = f"{command} takes a scenario with a [structure] section (a system on a structure)"
    assert said in proc.stderr and "0.2" not in proc.stderr, proc.stderr
    assert len(proc.stderr.strip().splitlines()) == 1 and "Traceback" not in proc.stderr


@pytest.mark.parametrize(
    ("command", "example", "said"),
    [
        ("continue", "ball_table_continuation", "along excitation.0.amplitude (m s-2) in"),
        ("bifurcation", "ball_table_bifurcation", "values of excitation.0.amplitude (m s-2) in"),
        ("curve", "ball_table_flip_curve", "stop.0.restitution  excitation.0.amplitude (m s-2)"),
    ],
)
def test_the_parameters_printed_state_their_units(
    run_cli: RunCli, command: str, example: str, said: str
) -> None:
    # The text outputs named the parameter without its unit (a restitution's, 1, is
    # not written).
    done = run_cli(command, str(ROOT / "examples" / f"{example}.toml"))
    assert done.returncode == 0, done.stderr
    assert said in done.stdout, done.stdout


def test_an_output_that_cannot_be_written_is_refused_before_the_run(
    run_cli: RunCli, tmp_path: Path
) -> None:
    # A legal 246-character name whose temporary file's name is too long was refused only
    # when written, after the whole analysis (basins: 2.7 s; an unwritable folder too).
    path = small_frf(tmp_path, ("count = 5", "count = 5"))
    long = tmp_path / ("a" * 246 + ".png")
    done = run_cli("sweep", str(path), "--plot", str(long))
    assert_one_line_error(done, "--plot", "cannot be written there", "shorter name")
    assert sorted(p.name for p in tmp_path.iterdir()) == [path.name]
    done = run_cli("simulate", str(path), "--out", str(tmp_path / ("b" * 250 + ".csv")))
    assert_one_line_error(done, "--out", "cannot be written there")
    assert sorted(p.name for p in tmp_path.iterdir()) == [path.name]


def test_a_whole_number_written_as_a_float_is_told_how_to_write_it(
    run_cli: RunCli, tmp_path: Path
) -> None:
    # "count: must be a whole number, got 5.0" read as a contradiction (5.0 is whole); a
    # file written from JSON or pandas has them. TOML tells an integer by its decimal point.
    path = small_frf(tmp_path, ("count = 5", "count = 5.0"))
    done = run_cli("sweep", str(path))
    assert_one_line_error(done, "[sweep] count", "written as an integer (5, not 5.0)")
    path = small_frf(tmp_path, ("count = 5", "count = 5.5"))
    done = run_cli("sweep", str(path))
    assert_one_line_error(done, "[sweep] count: must be a whole number, got 5.5")
