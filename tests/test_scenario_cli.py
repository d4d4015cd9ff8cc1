"""TOML scenarios and the ``vibroimpact`` command line."""

from __future__ import annotations

import csv
import json
import math
import subprocess
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

import vibroimpact as vi
from conftest import limit_memory
from vibroimpact.cli import main

REPO = Path(__file__).resolve().parent.parent
# The two-mass examples ([system]); those of 0.2 systems ([structure]) run in test_system_inputs.py.
EXAMPLES = sorted(
    p for p in (REPO / "examples").glob("*.toml") if "[system]" in p.read_text(encoding="utf-8")
)

# The reference page's high-accuracy Table 1 collision: duration (s).
REF_DURATION = 0.1089819
CONTACT_FIELDS = (
    "onset",
    "separation",
    "duration",
    "max_indentation",
    "approach_speed",
    "rebound_speed",
)

RK4_SOLVER = 'method = "rk4"\ndt = 1e-4\nt_end = 0.2\nbeta = 0.25\ngamma = 0.5'
NEWMARK_SOLVER = 'method = "newmark"\ndt = 1e-4\nt_end = 0.2\nbeta = 0.25\ngamma = 0.5'

RunCli = Callable[..., subprocess.CompletedProcess[str]]
WriteScenario = Callable[..., Path]


def replace_line(text: str, old: str, new: str) -> str:
    assert old in text, old
    return text.replace(old, new, 1)


def direct_table1(**overrides: object) -> vi.Solution:
    """The equivalent of conftest's TABLE1_TOML as a direct simulate call."""
    system = vi.ImpactDamper(
        main_mass=1.0, stiffness=1.0, damping=0.01, impact_mass=0.25, clearance=0.01
    )
    contact = vi.Contact("hertz", stiffness=3000.0, damping=0.01)
    state = vi.InitialState(impact_displacement=0.01, impact_velocity=0.1)
    settings: dict[str, object] = dict(
        method="rk4", dt=1e-4, t_end=0.2, every=7, contact_timing="located"
    )
    settings.update(overrides)
    return vi.simulate(system, contact, state, **settings)  # type: ignore[arg-type]


def expected_rows(steps: int, every: int) -> int:
    """Rows kept: the start, every every-th step, and the last step always."""
    return 1 + steps // every + (1 if steps % every else 0)


# ----------------------------------------------------------------------- scenarios


def test_full_scenario_matches_direct_call(table1_toml: str, write_scenario: WriteScenario) -> None:
    scenario = vi.load_scenario(write_scenario(table1_toml))
    assert scenario == vi.parse_scenario(table1_toml)
    assert scenario.system == vi.ImpactDamper(
        main_mass=1.0, stiffness=1.0, damping=0.01, impact_mass=0.25, clearance=0.01
    )
    assert scenario.contact == vi.Contact("hertz", stiffness=3000.0, damping=0.01)
    assert scenario.initial == vi.InitialState(impact_displacement=0.01, impact_velocity=0.1)
    assert (scenario.method, scenario.dt, scenario.t_end, scenario.every) == ("rk4", 1e-4, 0.2, 7)
    got, want = scenario.run(), direct_table1()
    for name in (
        "t",
        "main_displacement",
        "main_velocity",
        "impact_displacement",
        "impact_velocity",
        "contact_force",
    ):
        np.testing.assert_array_equal(getattr(got, name), getattr(want, name))
    assert got.contacts.to_dicts() == want.contacts.to_dicts()
    assert got.steps == want.steps == 2000
    assert len(got.t) == expected_rows(2000, 7)
    # And the physics is right: the reference page's duration.
    assert got.contacts.duration[0] == pytest.approx(REF_DURATION, rel=1e-6)


def test_minimal_scenario_uses_documented_defaults() -> None:
    text = """
[system]
main_mass = 2
stiffness = 5
impact_mass = 0.5
clearance = 0.02

[contact]
law = "hyster-hertz"
stiffness = 1e4
restitution = 0.8

[solver]
dt = 1e-4
t_end = 0.05
"""
    s = vi.parse_scenario(text)
    assert s.system == vi.ImpactDamper(
        main_mass=2.0, stiffness=5.0, impact_mass=0.5, clearance=0.02, damping=0.0
    )
    assert s.contact == vi.Contact("hyster-hertz", stiffness=1e4, restitution=0.8, damping=0.0)
    assert s.initial == vi.InitialState()
    assert (s.method, s.beta, s.gamma, s.contact_timing, s.every) == (
        "newmark",
        0.25,
        0.5,
        "located",
        1,
    )
    # Integers are accepted for numbers.
    assert isinstance(s.system.main_mass, float)


def scenario_error(text: str, source: str = "case.toml") -> str:
    with pytest.raises(vi.ScenarioError) as err:
        vi.parse_scenario(text, source)
    assert isinstance(err.value, ValueError)
    message = str(err.value)
    assert message.startswith(source), message
    assert "\n" not in message
    return message


@pytest.mark.parametrize(
    ("old", "new", "expected"),
    [
        # Unknown section and key, with a did-you-mean.
        ("[output]", "[outputs]", ["outputs", "did you mean 'output'"]),
        ("stiffness = 1.0", "stifness = 1.0", ["[system]", "stifness", "did you mean 'stiffness'"]),
        ("dt = 1e-4", "dt = 1e-4\nmethd = 'rk4'", ["[solver]", "methd", "did you mean 'method'"]),
        # Wrong types.
        ("stiffness = 1.0", 'stiffness = "1.0"', ["[system]", "stiffness", "number"]),
        ("stiffness = 1.0", "stiffness = true", ["[system]", "stiffness", "number"]),
        ("every = 7", "every = 7.0", ["[output]", "every", "whole number"]),
        ("every = 7", "every = true", ["[output]", "every", "whole number"]),
        ('law = "hertz"', "law = 3", ["[contact]", "law", "string"]),
        ('method = "rk4"', 'method = ["rk4"]', ["[solver]", "method", "string"]),
        # Non-finite values.
        ("stiffness = 1.0", "stiffness = nan", ["[system]", "stiffness", "finite"]),
        ("dt = 1e-4", "dt = inf", ["[solver]", "dt", "finite"]),
        ("impact_velocity = 0.1", "impact_velocity = -nan", ["[initial]", "impact_velocity"]),
        # Missing keys.
        ("stiffness = 1.0\n", "", ["[system]", "missing", "stiffness"]),
        ('law = "hertz"\n', "", ["[contact]", "missing", "law"]),
        ("t_end = 0.2\n", "", ["[solver]", "missing", "t_end"]),
        # Values the model refuses, named with their section.
        ("main_mass = 1.0", "main_mass = -1.0", ["[system]", "main_mass"]),
        ("clearance = 0.01", "clearance = -0.01", ["[system]", "clearance"]),
        ('law = "hertz"', 'law = "hurtz"', ["[contact]", "law"]),
        ('law = "hertz"', 'law = "hyster-hertz"', ["[contact]", "restitution"]),
        ('law = "hertz"', 'law = "hertz"\nrestitution = 0.9', ["[contact]", "restitution"]),
        ("dt = 1e-4", "dt = 0", ["[solver]", "dt"]),
        ("t_end = 0.2", "t_end = -1", ["[solver]", "t_end"]),
        ('method = "rk4"', 'method = "rk5"', ["[solver]", "method"]),
        ('contact_timing = "located"', 'contact_timing = "late"', ["[solver]", "contact_timing"]),
        (RK4_SOLVER, NEWMARK_SOLVER.replace("0.25", "0.75"), ["[solver]", "beta"]),
        (RK4_SOLVER, NEWMARK_SOLVER.replace("0.5", "0.25"), ["[solver]", "gamma"]),
        ("every = 7", "every = 0", ["[output]", "every"]),
        # Invalid TOML.
        ("[solver]", "[solver", ["invalid TOML"]),
        ("dt = 1e-4", "dt = ", ["invalid TOML"]),
        ("dt = 1e-4", "dt = 1e-4\ndt = 2e-4", ["invalid TOML"]),
    ],
)
def test_bad_scenarios(table1_toml: str, old: str, new: str, expected: list[str]) -> None:
    message = scenario_error(replace_line(table1_toml, old, new))
    for part in expected:
        assert part in message, message


@pytest.mark.parametrize("section", ["system", "contact", "solver"])
def test_missing_required_section(table1_toml: str, section: str) -> None:
    start = table1_toml.index(f"[{section}]")
    end = table1_toml.find("\n[", start + 1)
    text = table1_toml[:start] + table1_toml[end + 1 :]
    message = scenario_error(text)
    assert f"missing section [{section}]" in message


@pytest.mark.parametrize("example", ["frf_impact_damper.toml", "particle_column.toml"])
def test_a_structure_s_file_without_its_structure_says_so(example: str) -> None:
    # Without [structure] the file was read as a two-mass one, whose error named the
    # first section it does not know ([damper]) as an unknown key.
    text = (Path(__file__).resolve().parents[1] / "examples" / example).read_text()
    start = text.index("[structure]")
    end = text.find("\n[", start + 1)
    message = scenario_error(text[:start] + text[end + 1 :])
    assert "missing section [structure]: [" in message and "unknown key" not in message, message


def test_optional_sections_may_be_left_out(table1_toml: str) -> None:
    for section in ("initial", "output"):
        start = table1_toml.index(f"[{section}]")
        end = table1_toml.find("\n[", start + 1)
        text = table1_toml[:start] + (table1_toml[end + 1 :] if end >= 0 else "")
        vi.parse_scenario(text)


def test_top_level_keys_and_non_table_sections(table1_toml: str) -> None:
    assert "title" in scenario_error('title = "x"\n' + table1_toml)
    message = scenario_error("output = 7\n" + table1_toml.replace("[output]\nevery = 7\n", ""))
    assert "output" in message and "table" in message


def test_load_scenario_names_the_file(
    table1_toml: str, write_scenario: WriteScenario, tmp_path: Path
) -> None:
    path = write_scenario(table1_toml.replace("stiffness = 1.0", "stifness = 1.0"), "bad.toml")
    with pytest.raises(vi.ScenarioError) as err:
        vi.load_scenario(path)
    assert str(path) in str(err.value)
    assert "[system]" in str(err.value) and "stifness" in str(err.value)


@pytest.mark.parametrize("kind", ["missing", "directory", "not-utf8"])
def test_unreadable_scenario_file(tmp_path: Path, kind: str) -> None:
    path = tmp_path / "scenario.toml"
    if kind == "directory":
        path.mkdir()
    elif kind == "not-utf8":
        path.write_bytes(b"[system]\nmain_mass = \xff\xfe\n")
    with pytest.raises(vi.ScenarioError) as err:
        vi.load_scenario(path)
    assert isinstance(err.value, ValueError)
    assert str(path) in str(err.value)
    assert "\n" not in str(err.value)


def test_huge_integer_is_a_scenario_error(table1_toml: str) -> None:
    message = scenario_error(table1_toml.replace("every = 7", "every = 99999999999999999999"))
    assert "[output]" in message and "every" in message


# -------------------------------------------------------------------- CLI: simulate


def test_simulate_json_default_scenario(run_cli: RunCli) -> None:
    proc = run_cli("simulate", "--json")
    assert proc.returncode == 0, proc.stderr
    lines = proc.stdout.strip().splitlines()
    assert len(lines) == 1
    summary = json.loads(lines[0])
    assert summary["steps"] == 3000  # 0.3 s at dt = 1e-4
    assert summary["history_rows"] == 3001
    (contact,) = summary["contacts"]
    for field in CONTACT_FIELDS:
        assert isinstance(contact[field], float)
    assert contact["onset"] == 0.0
    assert contact["duration"] == pytest.approx(contact["separation"] - contact["onset"])
    # Newmark at dt = 1e-4: within 0.1 % of the exact duration (page: 0.05 %).
    assert contact["duration"] == pytest.approx(REF_DURATION, rel=1e-3)
    assert contact["approach_speed"] == pytest.approx(0.1, rel=1e-12)
    assert contact["max_indentation"] == pytest.approx(3.69668e-3, rel=5e-3)


def test_simulate_json_scenario_and_csv(
    run_cli: RunCli, table1_toml: str, write_scenario: WriteScenario, tmp_path: Path
) -> None:
    path = write_scenario(table1_toml)
    out = tmp_path / "history.csv"
    proc = run_cli("simulate", str(path), "--json", "--out", str(out))
    assert proc.returncode == 0, proc.stderr
    summary = json.loads(proc.stdout)
    want = direct_table1()
    assert summary["steps"] == want.steps == 2000
    assert summary["method"] == "rk4"
    assert [{k: c[k] for k in CONTACT_FIELDS} for c in summary["contacts"]] == [
        {k: c[k] for k in CONTACT_FIELDS} for c in want.contacts.to_dicts()
    ]
    assert summary["contacts"][0]["duration"] == pytest.approx(REF_DURATION, rel=1e-6)
    check_csv(out, want, expected_rows(2000, 7))


def check_csv(path: Path, want: vi.Solution, rows: int) -> None:
    with path.open(newline="", encoding="utf-8") as f:
        table = list(csv.reader(f))
    header, body = table[0], table[1:]
    assert header == [
        "t",
        "main_displacement",
        "main_velocity",
        "impact_displacement",
        "impact_velocity",
        "contact_force",
    ]
    assert len(body) == rows
    data = np.array(body, dtype=float)
    for i, name in enumerate(header):
        np.testing.assert_array_equal(data[:, i], getattr(want, name))
    assert data[0, 0] == 0.0
    assert data[-1, 0] == pytest.approx(want.final_time, rel=1e-12)


def test_simulate_text_output_through_main(
    capsys: pytest.CaptureFixture[str],
    table1_toml: str,
    write_scenario: WriteScenario,
    tmp_path: Path,
) -> None:
    path = write_scenario(table1_toml.replace("every = 7", "every = 1"))
    out = tmp_path / "h.csv"
    assert main(["simulate", str(path), "--out", str(out)]) == 0
    captured = capsys.readouterr()
    assert "1 contact(s)" in captured.out
    assert str(out) in captured.out
    assert captured.err == ""
    check_csv(out, direct_table1(every=1), 2001)


def test_both_formats_tables_of_contacts_state_their_units(
    capsys: pytest.CaptureFixture[str], table1_toml: str, write_scenario: WriteScenario
) -> None:
    # A [structure] system's table had bare column names (approach_speed, ...).
    system = REPO / "examples" / "frf_impact_damper.toml"
    for path in (write_scenario(table1_toml), system):
        assert main(["simulate", str(path)]) == 0
        lines = capsys.readouterr().out.splitlines()
        at = next(i for i, line in enumerate(lines) if line.endswith("contact(s)"))
        header = lines[at + 1]
        for cell in ("onset (s)", "duration (s)", "approach (m/s)", "dissipated (J)"):
            assert cell in header, header
        assert not {"approach_speed", "energy_dissipated"} & set(header.split()), header


def test_simulate_json_through_main(
    capsys: pytest.CaptureFixture[str], table1_toml: str, write_scenario: WriteScenario
) -> None:
    assert main(["simulate", str(write_scenario(table1_toml)), "--json"]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["steps"] == 2000
    assert set(CONTACT_FIELDS) <= set(summary["contacts"][0])


@pytest.mark.parametrize(
    ("old", "new"),
    [
        ("stiffness = 1.0", "stifness = 1.0"),
        ("dt = 1e-4", "dt = -1e-4"),
        ("[solver]", "[solver"),
        ("every = 7", "every = 7.5"),
    ],
)
def test_bad_scenario_exits_2_through_main(
    capsys: pytest.CaptureFixture[str],
    table1_toml: str,
    write_scenario: WriteScenario,
    old: str,
    new: str,
) -> None:
    path = write_scenario(replace_line(table1_toml, old, new))
    assert main(["simulate", str(path)]) == 2
    captured = capsys.readouterr()
    assert captured.out == ""
    lines = captured.err.strip().splitlines()
    assert len(lines) == 1
    assert lines[0].startswith("vibroimpact: error:")
    assert str(path) in lines[0]


def test_bad_scenario_exits_2_in_a_subprocess(
    run_cli: RunCli, table1_toml: str, write_scenario: WriteScenario
) -> None:
    path = write_scenario(table1_toml.replace("stiffness = 1.0", "stiffness = nan"))
    proc = run_cli("simulate", str(path), "--json")
    assert proc.returncode == 2
    assert proc.stdout == ""
    assert "Traceback" not in proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and "[system] stiffness" in lines[0] and str(path) in lines[0]


def test_missing_scenario_file_exits_2(run_cli: RunCli, tmp_path: Path) -> None:
    proc = run_cli("simulate", str(tmp_path / "nope.toml"))
    assert proc.returncode == 2
    assert "Traceback" not in proc.stderr
    assert len(proc.stderr.strip().splitlines()) == 1
    assert "nope.toml" in proc.stderr


def test_unwritable_output_exits_2(
    run_cli: RunCli, table1_toml: str, write_scenario: WriteScenario, tmp_path: Path
) -> None:
    path = write_scenario(table1_toml)
    proc = run_cli("simulate", str(path), "--out", str(tmp_path / "no-such-dir" / "h.csv"))
    assert proc.returncode == 2
    assert "Traceback" not in proc.stderr
    assert len(proc.stderr.strip().splitlines()) == 1


def test_blow_up_exits_1(run_cli: RunCli, table1_toml: str, write_scenario: WriteScenario) -> None:
    text = replace_line(table1_toml, "stiffness = 3000.0", "stiffness = 3e9")
    text = replace_line(text, "dt = 1e-4", "dt = 0.05")
    proc = run_cli("simulate", str(write_scenario(text)))
    assert proc.returncode == 1
    assert "Traceback" not in proc.stderr
    # A Hertz contact of 3e9 N/m^1.5 (a few 1e-4 s) under steps of 0.05 s: stopped
    # where it begins, naming dt.
    assert "a fixed step cannot resolve it" in proc.stderr and "dt" in proc.stderr
    assert len(proc.stderr.strip().splitlines()) == 1


def test_bad_arguments_exit_2_in_one_line(run_cli: RunCli) -> None:
    # argparse printed its usage lines before the error; every other error is one line.
    cases = [
        (("simulate", "--no-such-option"), "vibroimpact: error: unrecognized arguments"),
        (("no-such-command",), "vibroimpact: error: argument COMMAND: invalid choice"),
        ((), "vibroimpact: error: the following arguments are required: COMMAND"),
        (
            ("orbit", "x.toml", "--periods", "1.5"),
            "vibroimpact orbit: error: argument --periods: invalid int value: '1.5'",
        ),
    ]
    for args, said in cases:
        proc = run_cli(*args)
        assert proc.returncode == 2, args
        assert "Traceback" not in proc.stderr and "usage:" not in proc.stderr, proc.stderr
        lines = proc.stderr.strip().splitlines()
        assert len(lines) == 1 and lines[0].startswith(said), proc.stderr
        assert lines[0].endswith("--help)"), proc.stderr


@pytest.mark.parametrize("args", [[], ["simulate"], ["paper"]])
def test_help(run_cli: RunCli, capsys: pytest.CaptureFixture[str], args: list[str]) -> None:
    proc = run_cli(*args, "--help")
    assert proc.returncode == 0
    assert proc.stdout.startswith("usage: vibroimpact")
    assert proc.stderr == ""
    with pytest.raises(SystemExit) as exit_info:
        main([*args, "--help"])
    assert exit_info.value.code == 0
    assert capsys.readouterr().out == proc.stdout


def test_help_mentions_the_options(run_cli: RunCli) -> None:
    top = run_cli("--help").stdout
    assert "simulate" in top and "paper" in top
    sim = run_cli("simulate", "--help").stdout
    assert "--out" in sim and "--json" in sim and "SCENARIO" in sim.upper()
    assert "--out" in run_cli("paper", "--help").stdout


# ----------------------------------------------------------------------- CLI: paper


@pytest.fixture(scope="module")
def paper_dir(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, str]:
    """Run ``vibroimpact paper`` once for the module."""
    import os
    import sys

    out = tmp_path_factory.mktemp("paper") / "results"
    env = {**os.environ, "MPLBACKEND": "Agg", "PYTHONWARNINGS": "error"}
    proc = subprocess.run(
        [sys.executable, "-m", "vibroimpact", "paper", "--out", str(out)],
        capture_output=True,
        text=True,
        env=env,
        # Below pytest's 60 s per test; it takes about 4 s.
        timeout=50,
        check=False,
        preexec_fn=limit_memory,
    )
    assert proc.returncode == 0, proc.stderr
    assert "Traceback" not in proc.stderr
    return out, proc.stdout


def read_csv(path: Path) -> list[dict[str, str]]:
    with path.open(newline="", encoding="utf-8") as f:
        return list(csv.DictReader(f))


def test_paper_writes_all_files(paper_dir: tuple[Path, str]) -> None:
    out, stdout = paper_dir
    for name in ("table2.csv", "table3.csv", "report.md"):
        assert (out / name).stat().st_size > 0
    for name in ("fig1.png", "fig3.png", "fig4.png"):
        data = (out / name).read_bytes()
        assert data.startswith(b"\x89PNG\r\n\x1a\n") and len(data) > 5000
    assert "Table 2" in stdout and "Table 3" in stdout
    assert not (out / ".write-test").exists()


def test_paper_table2(paper_dir: tuple[Path, str]) -> None:
    rows = read_csv(paper_dir[0] / "table2.csv")
    assert list(rows[0]) == [
        "method",
        "dt",
        "contact_duration",
        "cpu_time",
        "error_percent",
        "error_vs_exact_percent",
    ]
    # Closed forms have no CPU time (and no dt); adaptive runs have a CPU time but no dt.
    closed = [r for r in rows if r["cpu_time"] == ""]
    numerical = [r for r in rows if r["cpu_time"] != ""]
    assert len(closed) == 2 and len(numerical) >= 6
    assert all(r["dt"] == "" for r in closed)
    assert all(r["cpu_time"] == "" for r in closed)
    assert all(float(r["cpu_time"]) > 0 for r in numerical)
    # The closed forms, recomputed: Goldsmith (printed constant) and the linear model.
    k_star = 1.25 / 0.25
    goldsmith = 2.9432 / 0.1**0.2 * (5 / (4 * k_star * 3000.0)) ** 0.4
    linear = 2 * 0.25 * math.pi / (math.sqrt(1.25) * math.sqrt(4 * 0.25 * 49.05 - 0.01**2 * 1.25))
    durations = sorted(float(r["contact_duration"]) for r in closed)
    assert durations[0] == pytest.approx(goldsmith, rel=1e-12)
    assert durations[1] == pytest.approx(linear, rel=1e-12)
    for r in rows:
        tc = float(r["contact_duration"])
        assert float(r["error_percent"]) == pytest.approx(abs(tc / goldsmith - 1) * 100, abs=2e-6)
        assert float(r["error_vs_exact_percent"]) == pytest.approx(
            abs(tc / REF_DURATION - 1) * 100, abs=1e-4
        )
    for r in numerical:
        tc = float(r["contact_duration"])
        if "step-count" in r["method"]:
            dt = float(r["dt"])
            assert tc / dt == pytest.approx(round(tc / dt), abs=1e-6)
        if r["method"] == "rk4 (located)":
            assert tc == pytest.approx(REF_DURATION, rel=2e-6)
        if r["method"].startswith(("dopri5", "dop853")):
            assert r["dt"] == "" and "rtol=" in r["method"]


def test_paper_table3_is_eq15_of_table2(paper_dir: tuple[Path, str]) -> None:
    numerical = [r for r in read_csv(paper_dir[0] / "table2.csv") if r["cpu_time"] != ""]
    # The paper's two methods (as it ran them) and then every method.
    paper_rows = [r for r in numerical if r["method"].endswith(("(step-count)", "(located)"))]
    table3 = read_csv(paper_dir[0] / "table3.csv")
    weights = [0.0, 0.2, 0.4, 0.6, 0.8, 1.0]
    assert list(table3[0]) == ["method", "dt", "error_basis"] + [f"wf1_{w:.1f}" for w in weights]
    blocks = {
        "goldsmith": ("error_percent", paper_rows),
        "exact": ("error_vs_exact_percent", paper_rows),
        "exact, all methods": ("error_vs_exact_percent", numerical),
    }
    assert {r["error_basis"] for r in table3} == set(blocks)
    assert len(paper_rows) == 12 and len(numerical) > len(paper_rows)
    for basis, (column, table2) in blocks.items():
        block = [r for r in table3 if r["error_basis"] == basis]
        assert [(r["method"], r["dt"]) for r in block] == [(r["method"], r["dt"]) for r in table2]
        # Maxima over the compared numerical runs (both methods, all steps).
        max_err = max(float(r[column]) for r in table2)
        max_cpu = max(float(r["cpu_time"]) for r in table2)
        for r2, r3 in zip(table2, block, strict=True):
            err, cpu = float(r2[column]), float(r2["cpu_time"])
            for w in weights:
                expected = ((1 - err / max_err) * w + (1 - cpu / max_cpu) * (1 - w)) * 100
                assert float(r3[f"wf1_{w:.1f}"]) == pytest.approx(expected, abs=0.006)


def test_paper_report_lists_its_files(paper_dir: tuple[Path, str]) -> None:
    report = (paper_dir[0] / "report.md").read_text(encoding="utf-8")
    assert report.startswith("# ")
    for name in (
        "table2.csv",
        "table3.csv",
        "fig1.png",
        "fig3.png",
        "fig4.png",
        "work_precision.png",
    ):
        assert name in report, name
        assert (paper_dir[0] / name).stat().st_size > 0


def test_paper_unwritable_out_exits_2(run_cli: RunCli, tmp_path: Path) -> None:
    blocker = tmp_path / "file"
    blocker.write_text("x")
    proc = run_cli("paper", "--out", str(blocker / "sub"))
    assert proc.returncode == 2
    assert "Traceback" not in proc.stderr
    assert len(proc.stderr.strip().splitlines()) == 1


# --------------------------------------------------------------------- examples


@pytest.mark.parametrize(
    "path",
    EXAMPLES or [pytest.param(None, marks=pytest.mark.skip(reason="no examples/*.toml yet"))],
    ids=lambda p: p.name if isinstance(p, Path) else "none",
)
def test_example_scenarios_run(path: Path) -> None:
    scenario = vi.load_scenario(path)
    sol = scenario.run()
    if scenario.dt is not None and sol.stepping == "fixed":
        steps = math.ceil(scenario.t_end / scenario.dt * (1 - 1e-9))
        assert sol.steps == steps
        assert len(sol.t) == expected_rows(steps, scenario.every)
    if scenario.method in ("dopri5", "dop853"):
        assert sol.final_time == pytest.approx(scenario.t_end, rel=1e-12)
    else:
        # A fixed-step method ends on its grid: t_end rounded up to whole steps.
        assert scenario.dt is not None
        whole_steps = math.ceil(scenario.t_end / scenario.dt * (1 - 1e-9))
        assert sol.final_time == pytest.approx(whole_steps * scenario.dt, rel=1e-12)
        assert scenario.t_end * (1 - 1e-9) <= sol.final_time < scenario.t_end + scenario.dt
    # Every example's contacts start by an approach (none starts indented).
    assert np.all(sol.contacts.approach_speed > 0)
    assert np.all(np.isfinite(sol.contacts.restitution[:-1]))
    for name in ("main_displacement", "main_velocity", "impact_displacement", "impact_velocity"):
        assert np.all(np.isfinite(getattr(sol, name)))
    assert np.all(np.diff(sol.t) > 0)


def test_simulate_notes_energy_the_method_created(
    table1_toml: str, write_scenario: Callable[[str, str], Path], run_cli: RunCli
) -> None:
    # No structural damping, the paper's Newmark at a coarse step: it gains energy.
    text = table1_toml.replace("damping = 0.01", "damping = 0.0").replace("dt = 1e-4", "dt = 1e-3")
    text = text.replace("t_end = 0.2", "t_end = 1.0\nenergy_tolerance = 1.0").replace(
        'method = "rk4"', 'method = "newmark"'
    )
    assert 'method = "newmark"' in text and "t_end = 1.0" in text
    path = write_scenario(text, "gain.toml")
    proc = run_cli("simulate", str(path))
    assert proc.returncode == 0, proc.stderr
    assert "note: the energy of this unforced system grew by" in proc.stdout
    summary = json.loads(run_cli("simulate", str(path), "--json").stdout)
    assert summary["energy_growth"] > 0.01
