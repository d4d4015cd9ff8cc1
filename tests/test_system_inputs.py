"""0.2 systems' scenarios from TOML and the command line: the names the outside
checks use (--json, --out), the examples that run, and bad scenarios refused with
exit status 2 (a ValueError from Python) naming the key.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

import vibroimpact as vi
from system_checks import BALL, FREE_PAIR, ROOT, cli
from vibroimpact.system import simulate_system


@pytest.mark.parametrize(
    ("against", "message"),
    [(0, "stop 0 against: 0 moves as at = 0 does"), (2, "stop 0 against must be a coordinate")],
)
def test_a_stop_against_no_other_point_is_refused(against: int, message: str) -> None:
    with pytest.raises(ValueError, match=message):
        simulate_system(
            FREE_PAIR,
            stop=[
                {"at": 0, "against": against, "side": "upper", "gap": 0.01, "law": "rigid"}
                | {"restitution": 0.5}
            ],
            t_end=0.05,
            method="exact",
        )


SCENARIO = """
[structure]
kind = "matrices"
mass = [[1.0, 0.0], [0.0, 0.5]]
stiffness = [[300.0, -100.0], [-100.0, 100.0]]

[[damper]]
mass = 0.05
at = 1
clearance = 0.002
law = "rigid"
restitution = 0.5

[[stop]]
at = 0
side = "upper"
gap = 0.004
law = "hertz-damped"
stiffness = 1e8
restitution = 0.7

[[excitation]]
kind = "force"
at = 0
signal = "harmonic"
amplitude = 1.5
frequency = 2.5

[initial]
structure_displacement = [0.001, 0.0]

[solver]
method = "dopri5"
t_end = 1.0
"""


def test_cli_json_and_out_use_the_names_of_the_issue(tmp_path: Path) -> None:
    path = tmp_path / "run.toml"
    path.write_text(SCENARIO)
    done = cli("simulate", str(path), "--json", "--out", str(tmp_path / "h.csv"))
    assert done.returncode == 0, done.stderr
    out = json.loads(done.stdout)
    assert set(out["final_state"]) == {
        "structure_displacement",
        "structure_velocity",
        "damper_displacement",
        "damper_velocity",
    }
    assert len(out["final_state"]["structure_displacement"]) == 2
    assert len(out["final_state"]["damper_velocity"]) == 1
    energy = out["energy"]
    for key in ("input_work", "dissipated", "stored_start", "stored_end", "residual"):
        assert isinstance(energy[key], float)
    balance = (
        energy["stored_end"] - energy["stored_start"] - energy["input_work"] + energy["dissipated"]
    )
    assert balance == pytest.approx(energy["residual"], abs=1e-15)
    assert abs(energy["residual"]) < 1e-6 * energy["input_work"]
    pairs = {c["pair"] for c in out["contacts"]}
    assert pairs <= {"damper 0", "stop 0"} and "damper 0" in pairs
    for c in out["contacts"]:
        if c["kind"] == "impact":
            assert c["duration"] == 0.0 and c["onset"] == c["separation"]
    header = (tmp_path / "h.csv").read_text().splitlines()[0].split(",")
    assert header == [
        "t",
        "structure_displacement_0",
        "structure_displacement_1",
        "structure_velocity_0",
        "structure_velocity_1",
        "damper_displacement_0",
        "damper_velocity_0",
    ]


BAD = [
    ('kind = "matrices"', 'kind = "truss"', 'kind must be one of "oscillator"'),
    ("[-100.0, 100.0]]", "[-90.0, 100.0]]", "structure.stiffness must be symmetric"),
    ("[[300.0, -100.0]", "[[-300.0, -100.0]", "structure.stiffness must be positive semi-definite"),
    (
        "mass = [[1.0, 0.0], [0.0, 0.5]]",
        "mass = [[1.0, 0.0], [0.0, -0.5]]",
        "structure.mass must be positive definite",
    ),
    ("at = 1\n", "at = 2\n", "damper 0 at must be a coordinate index"),
    ('side = "upper"', 'side = "above"', 'side must be one of "upper", "lower"'),
    ('law = "rigid"', 'law = "glue"', 'law must be one of "rigid"'),
    ("restitution = 0.5", "restitution = 1.5", "restitution in [0, 1]"),
    ('signal = "harmonic"', 'signal = "chirp"', 'signal must be one of "harmonic"'),
    (
        "structure_displacement = [0.001, 0.0]",
        "structure_displacement = [0.001]",
        "[initial] structure_displacement: must have 2 values",
    ),
    (
        "structure_displacement = [0.001, 0.0]",
        "structure_displacement = [0.0, 0.01]",
        "damper 0 starts",
    ),
    ("clearance = 0.002", "clearence = 0.002", "did you mean 'clearance'"),
    ('method = "dopri5"', 'method = "newmark-beta"', 'method must be one of "'),
]


@pytest.mark.parametrize(("old", "new", "message"), BAD, ids=[m for _, _, m in BAD])
def test_bad_system_scenarios_exit_2_naming_the_key(
    tmp_path: Path, old: str, new: str, message: str
) -> None:
    assert old in SCENARIO
    path = tmp_path / "bad.toml"
    path.write_text(SCENARIO.replace(old, new, 1))
    done = cli("simulate", str(path))
    assert done.returncode == 2, (done.stdout, done.stderr)
    assert message in done.stderr and "Traceback" not in done.stderr
    assert done.stderr.count("\n") == 1


@pytest.mark.parametrize(
    ("rows", "message"),
    [
        ("0.0,1.0\n0.0,2.0\n", "increase strictly"),
        ("0.0,1.0\n", "at least 2"),
        ("0.0,1.0\nx,y\n", "not two numbers"),
    ],
)
def test_bad_recorded_series_exit_2(tmp_path: Path, rows: str, message: str) -> None:
    (tmp_path / "ground.csv").write_text(rows)
    text = SCENARIO.replace(
        'signal = "harmonic"\namplitude = 1.5\nfrequency = 2.5',
        'signal = "recorded"\nfile = "ground.csv"',
    )
    (tmp_path / "run.toml").write_text(text)
    done = cli("simulate", "run.toml", cwd=tmp_path)
    assert done.returncode == 2, done.stderr
    assert message in done.stderr and "Traceback" not in done.stderr


SYSTEM_EXAMPLES = sorted(
    p for p in (ROOT / "examples").glob("*.toml") if "[structure]" in p.read_text(encoding="utf-8")
)


def test_examples_of_systems_run() -> None:
    assert len(SYSTEM_EXAMPLES) >= 2
    for path in SYSTEM_EXAMPLES:
        done = cli("simulate", str(path), "--json")
        assert done.returncode == 0, done.stderr
        out = json.loads(done.stdout)
        assert abs(out["energy"]["residual"]) < 1e-6 * max(
            out["energy"]["dissipated"], out["energy"]["input_work"]
        )


def test_simulate_system_is_exported() -> None:
    assert vi.simulate_system is simulate_system


@pytest.mark.parametrize(
    ("change", "message"),
    [
        ({"stiffness": 1e6}, 'stiffness applies to compliant laws only, not to law "rigid"'),
        ({"damping": 0.1}, 'damping applies to compliant laws only, not to law "rigid"'),
    ],
)
def test_keys_a_rigid_law_does_not_use_are_refused(change: dict[str, float], message: str) -> None:
    damper = {"mass": 0.1, "at": 0, "clearance": 0.01, "law": "rigid", "restitution": 0.5}
    with pytest.raises(vi.InvalidInputError, match=message):
        simulate_system(BALL, damper=[{**damper, **change}], t_end=0.1, method="rk4", dt=1e-3)


def test_a_negative_clearance_is_refused_naming_the_key_given() -> None:
    damper = {"mass": 0.1, "at": 0, "clearance": -0.005, "law": "rigid", "restitution": 0.5}
    with pytest.raises(vi.InvalidInputError, match=r"\[\[damper\]\] 0: clearance must be >= 0"):
        simulate_system(BALL, damper=[damper], t_end=0.1, method="rk4", dt=1e-3)


def test_keys_an_excitation_does_not_use_are_refused() -> None:
    force = {"kind": "force", "at": 0, "signal": "harmonic", "amplitude": 1.0, "frequency": 2.0}
    with pytest.raises(vi.InvalidInputError, match="duration not used by signal 'harmonic'"):
        simulate_system(
            BALL, excitation=[{**force, "duration": 1.0}], t_end=0.1, method="rk4", dt=1e-3
        )
    base = {**force, "kind": "base"}
    with pytest.raises(vi.InvalidInputError, match='at applies to kind "force" only'):
        simulate_system(BALL, excitation=[base], t_end=0.1, method="rk4", dt=1e-3)


def test_values_nested_thousands_deep_are_invalid_input() -> None:
    nested: object = [1.0]
    for _ in range(100_000):
        nested = [nested]
    with pytest.raises(vi.InvalidInputError, match="nested too deeply"):
        simulate_system(
            {"kind": "matrices", "mass": nested, "stiffness": [[1.0]]},
            t_end=1.0,
            method="rk4",
            dt=1e-3,
        )


def test_the_cli_prints_a_warning_on_one_line(tmp_path: Path) -> None:
    # The paper's law at low restitution warns; on the command line that is one line like
    # an error's, not Python's "file:line: Category" with the source line under it.
    scenario = tmp_path / "low_e.toml"
    scenario.write_text(
        '[structure]\nkind = "oscillator"\nmass = 1.0\nstiffness = 100.0\n'
        '[[damper]]\nmass = 0.1\nat = 0\nclearance = 0.01\nlaw = "hyster-hertz"\n'
        "stiffness = 1e6\nrestitution = 0.2\n"
        '[solver]\nmethod = "dop853"\nt_end = 0.01\n',
        encoding="utf-8",
    )
    done = cli("simulate", str(scenario))
    assert done.returncode == 0, done.stderr
    lines = done.stderr.strip().splitlines()
    assert lines == [lines[0]] and lines[0].startswith("vibroimpact: warning: law")
    assert ".py" not in done.stderr
