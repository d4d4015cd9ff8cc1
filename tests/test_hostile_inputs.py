"""Hostile inputs: device nodes and FIFOs for files, counts that would fill the memory,
values of the wrong type, negative indices, huge numbers in messages. Each is refused
with one line naming the key (exit status 2 on the command line, a ValueError in
Python), before anything large is allocated or anything is replaced."""

from __future__ import annotations

import json
import os
import re
import subprocess
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import docs_blocks
import vibroimpact as vi
from study_checks import FORCED_DAMPER
from vibroimpact.analysis import AnalysisError, with_parameter
from vibroimpact.output import UsageError, written_whole
from vibroimpact.scenario.system import SystemScenario
from vibroimpact.scenario.two_mass import ScenarioError, parse_scenario
from vibroimpact.study import study_settings
from vibroimpact.system import record_file

ROOT = Path(__file__).resolve().parents[1]
Cli = Callable[..., subprocess.CompletedProcess[str]]

BASE = FORCED_DAMPER.replace("t_end = 0.5", "t_end = 0.2")
STRUCTURE = {"kind": "oscillator", "mass": 1.0, "stiffness": 100.0}
FORCE = [{"kind": "force", "at": 0, "signal": "harmonic", "amplitude": 1.0, "frequency": 1.0}]


def write(tmp_path: Path, text: str, name: str = "s.toml") -> Path:
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


def refused(done: subprocess.CompletedProcess[str], *words: str) -> str:
    """The one-line error of a run refused with exit status 2, holding ``words``."""
    assert done.returncode == 2, done.stdout + done.stderr
    assert "Traceback" not in done.stderr, done.stderr
    assert len(done.stderr.strip().splitlines()) == 1, done.stderr
    for word in words:
        assert word in done.stderr, done.stderr
    return done.stderr


def parse_error(text: str, base_dir: Path | None = None) -> str:
    with pytest.raises(ScenarioError) as caught:
        parse_scenario(text, "s.toml", base_dir)
    assert isinstance(caught.value, ValueError)
    message = str(caught.value)
    assert "\n" not in message
    return message


# 1. --out never replaces what is not a regular file, nor the scenario.


def test_out_refuses_a_fifo_and_leaves_it_a_fifo(tmp_path: Path, run_cli: Cli) -> None:
    fifo = tmp_path / "pipe.csv"
    os.mkfifo(fifo)
    done = run_cli("simulate", str(write(tmp_path, BASE)), "--out", str(fifo))
    refused(done, "--out", "not a regular file")
    assert fifo.exists() and not fifo.is_file()


def test_out_refuses_a_folder(tmp_path: Path, run_cli: Cli) -> None:
    folder = tmp_path / "x.csv"
    folder.mkdir()
    done = run_cli("simulate", str(write(tmp_path, BASE)), "--out", str(folder))
    refused(done, "--out", "not a regular file")
    assert folder.is_dir()


def test_out_refuses_the_scenario_file_itself(tmp_path: Path, run_cli: Cli) -> None:
    scenario = write(tmp_path, BASE)
    refused(run_cli("simulate", str(scenario), "--out", str(scenario)), "--out", "scenario")
    assert scenario.read_text(encoding="utf-8") == BASE
    # Through a link too: the same file.
    link = tmp_path / "link.csv"
    link.symlink_to(scenario)
    refused(run_cli("simulate", str(scenario), "--out", str(link)), "--out")
    assert scenario.read_text(encoding="utf-8") == BASE


def test_written_whole_never_renames_over_a_fifo(tmp_path: Path) -> None:
    fifo = tmp_path / "pipe"
    os.mkfifo(fifo)
    with pytest.raises(UsageError, match="not a regular file"), written_whole(fifo) as f:
        f.write("x")
    assert fifo.exists() and not fifo.is_file()
    assert os.listdir(tmp_path) == ["pipe"]


def test_a_plot_onto_the_scenario_is_refused(tmp_path: Path, run_cli: Cli) -> None:
    scenario = write(tmp_path, BASE, "s.png")
    refused(run_cli("orbit", str(scenario), "--plot", str(scenario)), "--plot")
    assert scenario.read_text(encoding="utf-8") == BASE


@pytest.mark.parametrize("command", ["orbit", "continue", "poincare", "study"])
def test_a_plot_not_named_png_is_refused_before_anything_runs(
    tmp_path: Path, run_cli: Cli, command: str
) -> None:
    # The plots are PNG images: one written into branch.txt misleads its readers (user
    # trial). Refused before the analysis runs, the file left as it was.
    scenario = write(tmp_path, BASE)
    target = tmp_path / "branch.txt"
    target.write_text("kept", encoding="utf-8")
    extra = ["--out", str(tmp_path / "s.nc")] if command == "study" else []
    refused(run_cli(command, str(scenario), *extra, "--plot", str(target)), "--plot", ".png")
    assert target.read_text(encoding="utf-8") == "kept"
    assert not (tmp_path / "s.nc").exists()


# 2. A recorded signal's file: regular, bounded, two columns, errors naming it.

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
file = "{file}"
"""


def test_a_recorded_signal_from_a_fifo_is_refused_without_waiting(
    tmp_path: Path, run_cli: Cli
) -> None:
    fifo = tmp_path / "rec.csv"
    os.mkfifo(fifo)
    done = run_cli("simulate", str(write(tmp_path, RECORDED.format(file="rec.csv"))), timeout=20)
    refused(done, "[[excitation]] 0: file:", "not a regular file")


def test_a_recorded_signal_from_a_device_is_refused() -> None:
    # /dev/null: empty, so that the test is safe where the refusal is missing (/dev/zero
    # would be read until the memory is full).
    message = parse_error(RECORDED.format(file="/dev/null"))
    assert "[[excitation]] 0: file:" in message and "not a regular file" in message


def test_a_recorded_file_above_the_limit_is_refused(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    assert record_file.MAX_RECORDED_FILE_BYTES == 64 * 2**20
    assert "file is at most 64 MiB" in docs_blocks.prose(docs_blocks.section("limits", "Limits"))
    (tmp_path / "rec.csv").write_text("".join(f"{i},0\n" for i in range(100)))
    parse_scenario(RECORDED.format(file="rec.csv"), "s.toml", tmp_path)  # fits
    monkeypatch.setattr(record_file, "MAX_RECORDED_FILE_BYTES", 100)
    message = parse_error(RECORDED.format(file="rec.csv"), tmp_path)
    assert "[[excitation]] 0: file:" in message and "larger than" in message


def test_a_recorded_file_of_three_columns_is_refused(tmp_path: Path) -> None:
    (tmp_path / "rec.csv").write_text("t,x\n0,0,5\n1,1,7\n")
    message = parse_error(RECORDED.format(file="rec.csv"), tmp_path)
    assert "rec.csv line 2" in message and "two columns" in message and "got 3" in message


@pytest.mark.parametrize(
    ("text", "line", "words"),
    [
        ("# a record\n\ntime,value\n0,0\n0.5,1\n0.5,2\n1,0\n", 6, "increase strictly"),
        ("# a record\n0,0\nnan,1\n1,0\n", 3, "finite"),
        ("0,0\n1,inf\n", 2, "finite"),
    ],
)
def test_record_errors_name_the_excitation_and_the_file_line(
    tmp_path: Path, text: str, line: int, words: str, run_cli: Cli
) -> None:
    (tmp_path / "rec.csv").write_text(text)
    done = run_cli("simulate", str(write(tmp_path, RECORDED.format(file="rec.csv"))))
    refused(done, f"[[excitation]] 0: file: rec.csv line {line}:", words)


def test_record_arrays_errors_name_the_excitation_and_the_index() -> None:
    excitation = {"kind": "base", "signal": "recorded", "time": [0.0, 1.0], "value": [0.0]}
    with pytest.raises(ValueError, match=r"\[\[excitation\]\] 0: time and value .* 2 and 1"):
        vi.simulate_system(STRUCTURE, excitation=[excitation], t_end=0.1, method="dopri5")
    excitation = {"kind": "base", "signal": "recorded", "time": [0.0, 1.0, 1.0], "value": [0, 1, 2]}
    with pytest.raises(ValueError, match=r"\[\[excitation\]\] 0: time\[2\]: times must increase"):
        vi.simulate_system(STRUCTURE, excitation=[excitation], t_end=0.1, method="dopri5")


def test_a_recorded_signal_without_samples_asks_for_a_file_or_the_arrays() -> None:
    for given in ({}, {"time": [0.0, 1.0]}):
        excitation = {"kind": "base", "signal": "recorded", **given}
        with pytest.raises(
            ValueError, match=r"\[\[excitation\]\] 0: .*needs file .*or time and value"
        ):
            vi.simulate_system(STRUCTURE, excitation=[excitation], t_end=0.1, method="dopri5")


def test_an_unknown_excitation_key_lists_its_signal_s_keys_only() -> None:
    excitation = {**FORCE[0], "amplitud": 1.0}
    with pytest.raises(ValueError) as caught:
        vi.simulate_system(STRUCTURE, excitation=[excitation], t_end=0.1, method="dopri5")
    assert str(caught.value) == (
        "[[excitation]] 0: unknown key 'amplitud' (signal 'harmonic' takes kind, at, signal, "
        "amplitude, frequency, phase); did you mean 'amplitude'?"
    )


def test_a_scale_that_takes_a_record_beyond_floating_point_is_refused() -> None:
    excitation = {"kind": "base", "signal": "recorded", "time": [0, 1, 2], "value": [0, 1e308, 0]}
    beyond = r"0: value\[1\]: value 1e\+308 times scale 100.0 is beyond"
    with pytest.raises(ValueError, match=beyond):
        vi.simulate_system(
            STRUCTURE, excitation=[{**excitation, "scale": 100.0}], t_end=0.1, method="dopri5"
        )


def test_an_empty_file_name_is_refused_as_such() -> None:
    excitation = {"kind": "base", "signal": "recorded", "file": " "}
    with pytest.raises(ValueError, match=r"0: file: must name a CSV file .*empty string"):
        vi.simulate_system(STRUCTURE, excitation=[excitation], t_end=0.1, method="dopri5")


def test_record_arrays_beyond_the_sample_limit_are_refused_before_they_are_read() -> None:
    # Reading 2e8 values one by one took minutes; the length alone decides.
    huge = np.broadcast_to(np.float64(0.0), (vi.MAX_SIGNAL_SAMPLES + 1,))
    excitation = {"kind": "base", "signal": "recorded", "time": huge, "value": huge}
    with pytest.raises(ValueError, match=r"0: time: holds 100000001 values; at most 100000000"):
        vi.simulate_system(STRUCTURE, excitation=[excitation], t_end=0.1, method="dopri5")
    nan_inside = np.array([0.0, 1.0, np.nan])
    excitation = {"kind": "base", "signal": "recorded", "time": nan_inside, "value": np.ones(3)}
    with pytest.raises(ValueError, match=r"0: time\[2\]: must be a finite number, got nan"):
        vi.simulate_system(STRUCTURE, excitation=[excitation], t_end=0.1, method="dopri5")


@pytest.mark.parametrize("record_from", [0.1, 0.5])
def test_a_window_from_record_from_at_or_after_t_end_is_refused(record_from: float) -> None:
    with pytest.raises(
        ValueError, match=r"\[output\] record_from: must be before \[solver\] t_end"
    ):
        vi.simulate_system(STRUCTURE, t_end=0.1, method="dopri5", record_from=record_from)


@pytest.mark.parametrize("rtol", [0.5, 10.0, 1e-16])
def test_a_system_s_rtol_outside_its_range_is_refused(rtol: float) -> None:
    # rtol = 10 ran, and stopped on its energy balance ("reduce dt").
    with pytest.raises(ValueError, match=r"\[solver\] rtol: must be in \[1e-15, 0.1\]"):
        vi.simulate_system(STRUCTURE, excitation=FORCE, t_end=0.1, method="dopri5", rtol=rtol)


def test_a_scenario_without_its_structure_names_both_sections(tmp_path: Path, run_cli: Cli) -> None:
    done = run_cli(
        "simulate", str(write(tmp_path, '[solver]\nmethod = "rk4"\ndt = 1e-3\nt_end = 1.0\n'))
    )
    refused(done, "missing section [system] (or [structure]")


def test_energies_beyond_floating_point_stop_the_run_saying_so() -> None:
    force = [{**FORCE[0], "amplitude": 1e300}]
    with pytest.raises(vi.NumericalBlowUpError, match="energies are no longer finite"):
        vi.simulate_system(STRUCTURE, excitation=force, t_end=1.0, method="dopri5")


# 3. Counts bounded before anything is allocated; a study's axes made only by a study.

STUDY = (
    BASE
    + """
[study]
analysis = "run"
{extra}
[study.axes]
{axes}
"""
)


@pytest.mark.parametrize(
    ("axes", "extra", "words"),
    [
        ('"damper.0.mass" = {start = 0.01, stop = 0.1, count = 1000000000000}', "", "count"),
        ('"damper.0.mass" = {start = 0.01, stop = 0.1, count = 300000000}', "", "count"),
        (
            '"damper.0.mass" = {start = 0.01, stop = 0.1, count = 100000}\n'
            '"damper.0.clearance" = {start = 0.001, stop = 0.01, count = 100000}',
            "",
            "runs",
        ),
        (
            '"damper.0.mass" = [0.01]\n[study.random]\n"damper.0.restitution" = '
            "{uniform = [0.4, 0.8]}",
            "samples = 1000000000000",
            "samples",
        ),
    ],
)
def test_a_study_too_large_is_refused_by_every_command(
    tmp_path: Path, axes: str, extra: str, words: str, run_cli: Cli
) -> None:
    scenario = write(tmp_path, STUDY.format(axes=axes, extra=extra))
    for command in (["simulate"], ["study", "--out", str(tmp_path / "r.nc")]):
        done = run_cli(command[0], str(scenario), *command[1:])
        refused(done, words, "10,000,000")
    assert not (tmp_path / "r.nc").exists()


def test_reading_a_scenario_makes_no_axis_values() -> None:
    axes = '"damper.0.mass" = {start = 0.01, stop = 0.1, count = 5000000}'
    scenario = parse_scenario(STUDY.format(axes=axes, extra=""), "s.toml")
    assert isinstance(scenario, SystemScenario)
    read = scenario.data["study"]["axes"]["damper.0.mass"]
    assert not isinstance(read, np.ndarray) and read["count"] == 5000000
    # A study makes them.
    assert len(study_settings(scenario.data["study"])["axes"]["damper.0.mass"]) == 5000000


def test_a_seed_axis_is_still_checked_when_read() -> None:
    axes = '"excitation.0.seed" = {start = 0, stop = 10, count = 4}'
    text = STUDY.format(axes=axes, extra="").replace(
        'signal = "harmonic"\namplitude = 5.0\nfrequency = 10.0',
        'signal = "white-noise"\nintensity = 1e-4\ncutoff_frequency = 25.0\nseed = 1',
    )
    assert "a seed must be a whole number" in parse_error(text)


def test_a_sweep_of_too_many_points_is_refused(tmp_path: Path, run_cli: Cli) -> None:
    text = BASE + '[sweep]\nparameter = "excitation.0.frequency"\nstart = 7.0\nstop = 13.0\n'
    done = run_cli("sweep", str(write(tmp_path, text + "count = 1000000000000\n")))
    refused(done, "[sweep] count", "100000")
    assert "max_points" in parse_error(
        BASE + '[continuation]\nparameter = "excitation.0.amplitude"\nstop = 9.0\n'
        "max_points = 1000000000000\n"
    )


BASINS = (
    BASE
    + """
[basins]
x = {{ state = "{x}", start = 0.0, stop = 0.003, count = {count} }}
y = {{ state = "{y}", start = -0.4, stop = 0.4, count = {count} }}
"""
)


def test_basins_of_too_many_starts_are_refused(tmp_path: Path, run_cli: Cli) -> None:
    text = BASINS.format(x="structure_displacement.0", y="structure_velocity.0", count=100000)
    refused(run_cli("basins", str(write(tmp_path, text))), "x.count", "1000000")


def test_basins_over_the_same_entry_twice_are_refused() -> None:
    for y in ("structure_displacement.0", "structure_displacement.00"):
        text = BASINS.format(x="structure_displacement.0", y=y, count=2)
        assert "must differ from x.state" in parse_error(text)


# 4. Enumerated keys of the wrong type, or missing, are named.


@pytest.mark.parametrize(
    ("old", "new", "words"),
    [
        ('kind = "oscillator"', 'kind = ["oscillator"]', "[structure] kind must be one of"),
        ('kind = "oscillator"', "kind = {a = 1}", "[structure] kind must be one of"),
        ('kind = "oscillator"\n', "", "[structure] missing key 'kind'"),
        ('law = "rigid"', 'law = ["rigid"]', "law: must be a string"),
        ('kind = "force"', "kind = 1", "kind: must be a string"),
        ('signal = "harmonic"', "signal = {a = 1}", "signal: must be a string"),
        ('method = "exact"', 'method = ["exact"]', "method: must be a string"),
    ],
)
def test_enumerated_keys_of_another_type_are_named(old: str, new: str, words: str) -> None:
    assert old in BASE
    message = parse_error(BASE.replace(old, new, 1))
    assert words in message and "None" not in message


def test_a_list_for_the_structure_kind_exits_2(tmp_path: Path, run_cli: Cli) -> None:
    text = '[structure]\nkind = ["oscillator"]\n[solver]\nt_end = 1.0\n'
    refused(run_cli("simulate", str(write(tmp_path, text))), "[structure] kind")


def test_enumerated_values_from_python_of_another_type_are_named() -> None:
    stop = {"at": 0, "side": ["upper"], "gap": 0.1, "law": "rigid", "restitution": 0.5}
    with pytest.raises(ValueError, match=r"\[\[stop\]\] 0: side: must be a string"):
        vi.simulate_system(STRUCTURE, stop=[stop], t_end=0.1, method="dopri5")
    with pytest.raises(ValueError, match=r"\[structure\] kind must be one of .*got \('a',\)"):
        vi.simulate_system({**STRUCTURE, "kind": ("a",)}, t_end=0.1, method="dopri5")
    with pytest.raises(ValueError, match=r"metrics must be one of .*a string"):
        study_settings({"metrics": [["peak"]], "axes": {"damper.0.mass": [0.1]}})


# 5. Numbers in Python: NumPy real scalars accepted, booleans refused, fields named.


@pytest.mark.parametrize("mass", [np.int64(1), np.float32(1.0), np.array(1.0), np.array(1)])
def test_numpy_real_scalars_are_numbers(mass: Any) -> None:
    sol = vi.simulate_system(
        {**STRUCTURE, "mass": mass},
        excitation=FORCE,
        t_end=np.float32(0.5),
        method="dopri5",
        every=np.int64(1),
        history=np.bool_(True),
    )
    same = vi.simulate_system(STRUCTURE, excitation=FORCE, t_end=0.5, method="dopri5")
    assert np.array_equal(sol.structure_displacement, same.structure_displacement)


@pytest.mark.parametrize("mass", [True, np.bool_(True), np.array(True), "1", None, [1.0]])
def test_booleans_and_other_types_are_refused_naming_the_field(mass: Any) -> None:
    with pytest.raises(ValueError, match=r"\[structure\] mass: must be a number"):
        vi.simulate_system({**STRUCTURE, "mass": mass}, t_end=0.1, method="dopri5")


def test_whole_numbers_from_numpy_and_the_refusal_of_floats() -> None:
    sol = vi.simulate_system(
        STRUCTURE, excitation=FORCE, t_end=0.5, method="dopri5", every=np.int32(2)
    )
    assert len(sol.t) > 2
    with pytest.raises(ValueError, match=r"\[output\] every: must be a whole number"):
        vi.simulate_system(STRUCTURE, t_end=0.1, method="dopri5", every=np.float64(2.0))


# 6. Negative indices in dotted paths.


def test_a_negative_index_in_a_sweep_parameter_exits_2(tmp_path: Path, run_cli: Cli) -> None:
    text = BASE + (
        '[sweep]\nparameter = "excitation.-1.frequency"\nstart = 9.0\nstop = 11.0\ncount = 2\n'
    )
    refused(run_cli("sweep", str(write(tmp_path, text))), "[sweep] parameter", "'-1'")


def test_negative_indices_are_refused_everywhere() -> None:
    sections = {"excitation": [dict(FORCE[0])], "structure": STRUCTURE}
    with pytest.raises(AnalysisError, match="whole number from 0"):
        with_parameter(sections, "excitation.-1.frequency", 2.0)
    axes = '"excitation.-1.frequency" = [9.0, 10.0]'
    assert "whole number from 0" in parse_error(STUDY.format(axes=axes, extra=""))
    text = BASE + '[continuation]\nparameter = "damper.-1.mass"\nstop = 0.1\n'
    assert "whole number from 0" in parse_error(text)


# 7. Numbers in messages short and exact.


@pytest.mark.parametrize(
    ("at", "shown"), [("1e300", "1e+300"), ("9223372036854775807", "9223372036854775807")]
)
def test_a_huge_point_is_quoted_short_and_exact(
    tmp_path: Path, at: str, shown: str, run_cli: Cli
) -> None:
    text = BASE.replace("at = 0\nclearance", f"at = {at}\nclearance", 1)
    message = refused(run_cli("simulate", str(write(tmp_path, text))), "damper 0 at must be")
    assert message.rstrip().endswith(f"got {shown}")
    assert not re.search(r"\d{25,}", message)


def test_the_core_s_numbers_are_shortened() -> None:
    noise = {
        "kind": "base",
        "signal": "white-noise",
        "intensity": 1.0,
        "cutoff_frequency": 1e300,
        "seed": 1,
    }
    with pytest.raises(ValueError) as caught:
        vi.simulate_system(STRUCTURE, excitation=[noise], t_end=0.01, method="dopri5")
    assert "1e+300" in str(caught.value) and not re.search(r"\d{25,}", str(caught.value))


# 8. --workers bounded.


def test_a_study_with_too_many_workers_is_refused(tmp_path: Path, run_cli: Cli) -> None:
    scenario = write(tmp_path, STUDY.format(axes='"damper.0.mass" = [0.05]', extra=""))
    out = tmp_path / "r.nc"
    refused(run_cli("study", str(scenario), "--out", str(out), "--workers", "100000"), "--workers")
    assert not out.exists()


# 10. harmonics: lengths named as given.


def test_harmonics_without_phases_count_only_what_is_given() -> None:
    harmonics = {
        "kind": "force",
        "at": 0,
        "signal": "harmonics",
        "amplitudes": [1.0, 2.0],
        "frequencies": [10.0],
    }
    with pytest.raises(ValueError) as caught:
        vi.simulate_system(STRUCTURE, excitation=[harmonics], t_end=0.1, method="dopri5")
    message = str(caught.value)
    assert "amplitudes and frequencies" in message and message.endswith("got 2 and 1")
    harmonics |= {"frequencies": [10.0, 20.0], "phases": [0.0]}
    with pytest.raises(ValueError, match=r"phases must have one entry per amplitude \(2\), got 1"):
        vi.simulate_system(STRUCTURE, excitation=[harmonics], t_end=0.1, method="dopri5")


# 11. An orbit study's default metrics are its own.


def test_an_orbit_study_keeps_its_own_metrics_by_default() -> None:
    settings = study_settings({"analysis": "orbit", "axes": {"excitation.0.amplitude": [5.0]}})
    assert settings["metrics"] == [
        "amplitude",
        "impacts_per_period",
        "stable",
        "largest_multiplier",
    ]
    assert study_settings({"axes": {"damper.0.mass": [0.05]}})["metrics"] == [
        "peak",
        "rms",
        "impacts",
    ]


# 12. simulate prints what [output] record_from and strobe_period ask for.


def test_simulate_json_holds_the_reductions_output_asks_for(tmp_path: Path, run_cli: Cli) -> None:
    text = BASE + "[output]\nrecord_from = 0.1\nstrobe_period = 0.05\n"
    done = run_cli("simulate", str(write(tmp_path, text)), "--json")
    assert done.returncode == 0, done.stderr
    summary = json.loads(done.stdout)
    sol = vi.simulate_system(
        {"kind": "oscillator", "mass": 1.0, "stiffness": 3947.8, "damping": 2.513},
        damper=[{"mass": 0.05, "at": 0, "clearance": 0.005, "law": "rigid", "restitution": 0.6}],
        excitation=[
            {"kind": "force", "at": 0, "signal": "harmonic", "amplitude": 5.0, "frequency": 10.0}
        ],
        method="exact",
        t_end=0.2,
        record_from=0.1,
        strobe_period=0.05,
    )
    assert summary["peak"] == sol.peak.tolist() and summary["rms"] == sol.rms.tolist()
    assert summary["peak"][0] > 0 and summary["recorded_time"] == sol.recorded_time
    assert summary["strobe_time"] == sol.strobe_time.tolist() and len(summary["strobe"]) == 4
    assert summary["strobe"] == sol.strobe.tolist()
    text_out = run_cli("simulate", str(write(tmp_path, text)))
    assert "peak (m)" in text_out.stdout and "stroboscopic" in text_out.stdout
    # Without them, nothing is added.
    plain = json.loads(run_cli("simulate", str(write(tmp_path, BASE)), "--json").stdout)
    assert "peak" not in plain and "strobe" not in plain


# 13. What is allowed, or what is missing, said.


def test_a_negative_seed_says_what_is_allowed() -> None:
    text = BASE.replace(
        'signal = "harmonic"\namplitude = 5.0\nfrequency = 10.0',
        'signal = "white-noise"\nintensity = 1e-4\ncutoff_frequency = 25.0\nseed = -1',
    ).replace('method = "exact"', 'method = "dopri5"')
    message = parse_error(text)
    assert "seed: must be a whole number in [0, 2^63 - 1], got -1" in message


def test_a_missing_rigid_restitution_is_said_missing() -> None:
    message = parse_error(BASE.replace("restitution = 0.6\n", "", 1))
    assert "missing key 'restitution'" in message and "None" not in message


@pytest.mark.parametrize(
    ("make", "field"),
    [
        (
            lambda: vi.ImpactDamper(main_mass="1", stiffness=1.0, impact_mass=0.25, clearance=0.01),
            "main_mass",
        ),
        (
            lambda: vi.ImpactDamper(
                main_mass=True, stiffness=1.0, impact_mass=0.25, clearance=0.01
            ),
            "main_mass",
        ),
        (
            lambda: vi.ImpactDamper(
                main_mass=1.0, stiffness=[1.0], impact_mass=0.25, clearance=0.01
            ),
            "stiffness",
        ),
        (lambda: vi.Contact(None, stiffness=3000.0), "law"),  # type: ignore[arg-type]
        (lambda: vi.Contact("hertz", stiffness="3e3"), "stiffness"),
        (lambda: vi.InitialState(impact_velocity=None), "impact_velocity"),
    ],
)
def test_the_compiled_constructors_name_the_field_of_a_wrong_type(
    make: Callable[[], object], field: str
) -> None:
    # PyO3's own conversions raise a TypeError; the standard is a ValueError subclass
    # naming the field (booleans are not numbers here, as in simulate_system).
    with pytest.raises(ValueError, match=f"^{field} must be a"):
        make()


def test_the_compiled_constructors_take_numpy_reals() -> None:
    damper = vi.ImpactDamper(
        main_mass=np.float32(1.0), stiffness=np.int64(1), impact_mass=0.25, clearance=0.01
    )
    assert (damper.main_mass, damper.stiffness) == (1.0, 1.0)


@pytest.mark.parametrize("length", ["-1.0", "0.0"])
def test_a_beam_of_no_length_is_named_before_the_points_on_it(length: str) -> None:
    # "excitation 0 at must be a position along the beam in [0, -1.0] m": the point's
    # range came first, the beam's own error only where nothing had an at (user trial).
    text = """
[structure]
kind = "cantilever"
length = LENGTH
youngs_modulus = 7e10
second_moment = 1e-10
mass_per_length = 0.27
modes = 3
damping_ratio = 0.01

[[excitation]]
kind = "force"
at = 0.5
signal = "harmonic"
amplitude = 0.5
frequency = 8.0

[solver]
method = "dopri5"
t_end = 0.1
""".replace("LENGTH", length)
    message = parse_error(text)
    assert "structure.length must be a finite number > 0" in message
    assert "at must be" not in message


# From the pounding trial: what a building engineer's scenarios ran into.

BUILDINGS = """
[structure]
kind = "matrices"
mass = [[1.0e5, 0.0], [0.0, 2.0e5]]
stiffness = [[1.579e7, 0.0], [0.0, 7.896e6]]
damping = [[1.2566e5, 0.0], [0.0, 1.2566e5]]
[[stop]]
at = 0
against = 1
side = "upper"
gap = 0.01
law = "rigid"
restitution = 0.65
[[excitation]]
kind = "base"
signal = "recorded"
file = "quake.csv"
[solver]
method = "dop853"
t_end = 1.0
"""


def test_out_refuses_a_record_the_scenario_reads(tmp_path: Path, run_cli: Cli) -> None:
    record = tmp_path / "quake.csv"
    record.write_text("time,value\n0,0\n0.5,1.0\n1.0,0\n", encoding="utf-8")
    before = record.read_text(encoding="utf-8")
    scenario = write(tmp_path, BUILDINGS)
    refused(run_cli("simulate", str(scenario), "--out", str(record)), "--out", "quake.csv")
    assert record.read_text(encoding="utf-8") == before


def test_a_stop_given_twice_is_refused_naming_both(tmp_path: Path, run_cli: Cli) -> None:
    # The second of two rigid stops on one gap was silently ignored, the result
    # depending on their order; as "lower" from the other point it is the same gap.
    record = tmp_path / "quake.csv"
    record.write_text("time,value\n0,0\n0.5,1.0\n1.0,0\n", encoding="utf-8")
    again = BUILDINGS + (
        '[[stop]]\nat = 0\nagainst = 1\nside = "upper"\ngap = 0.01\nlaw = "rigid"\n'
        "restitution = 0.3\n"
    )
    mirrored = BUILDINGS + (
        '[[stop]]\nat = 1\nagainst = 0\nside = "lower"\ngap = 0.01\nlaw = "rigid"\n'
        "restitution = 0.3\n"
    )
    for text in (again, mirrored):
        refused(
            run_cli("simulate", str(write(tmp_path, text))),
            "stop 1 has the same gap as stop 0",
        )
    # Another gap is another wall.
    other = again.replace("gap = 0.01\nlaw", "gap = 0.02\nlaw").replace(
        "gap = 0.02\nlaw", "gap = 0.01\nlaw", 1
    )
    assert run_cli("simulate", str(write(tmp_path, other))).returncode == 0


def test_pairs_beyond_the_limit_are_refused_before_they_are_read(
    tmp_path: Path, run_cli: Cli
) -> None:
    # 70,000 stops aborted the process asking for 39 GB (the impact solver's matrix).
    stop = '[[stop]]\nat = 0\nside = "upper"\ngap = 0.01\nlaw = "rigid"\nrestitution = 0.5\n'
    text = BUILDINGS.split("[[stop]]")[0] + stop * (vi.MAX_PAIRS + 1)
    text += '[solver]\nmethod = "dop853"\nt_end = 1.0\n'
    refused(run_cli("simulate", str(write(tmp_path, text))), "at most 1000 pairs in all")


def test_the_exact_flow_s_steps_are_counted_before_it_runs(tmp_path: Path, run_cli: Cli) -> None:
    # dt = 1e-9 over 20 s ran for minutes: the exact flow steps at most dt.
    text = BUILDINGS.replace(
        'method = "dop853"\nt_end = 1.0', 'method = "exact"\ndt = 1e-9\nt_end = 20.0'
    )
    text = text.replace(
        'signal = "recorded"\nfile = "quake.csv"',
        'signal = "harmonic"\namplitude = 1.0\nfrequency = 1.0',
    )
    refused(run_cli("simulate", str(write(tmp_path, text))), "exceeds max_steps")


def test_a_sweep_point_the_exact_flow_cannot_take_fails_alone() -> None:
    # An undamped oscillator forced at exactly its frequency grows as t between
    # impacts, which the exact flow cannot hold: that point failed the whole sweep
    # (exit 2) though a stop bounds the motion; it now fails alone, saying what to use.
    from vibroimpact.analysis import sweep

    data = {
        "structure": {"kind": "oscillator", "mass": 1.0, "stiffness": 4 * np.pi**2},
        "stop": [{"at": 0, "side": "upper", "gap": 0.01, "law": "rigid", "restitution": 0.8}],
        "excitation": [{"kind": "base", "signal": "harmonic", "amplitude": 1.0, "frequency": 1.0}],
        "solver": {"method": "exact", "t_end": 1.0},
    }
    found = sweep(
        data, "excitation.0.frequency", [0.5, 1.0, 1.5], settle_periods=5, record_periods=2
    )
    assert [p.error is None for p in found] == [True, False, True]
    assert "1 Hz" in str(found[1].error) and "dop853" in str(found[1].error)


@pytest.mark.timeout(30)
def test_the_exact_flow_sets_up_hundreds_of_dampers_without_hanging() -> None:
    # The modal reduction summed each entry of N^T A N over both indices at once
    # (dim^2 r^2): 400 dampers ran for minutes before the first step, deaf to Ctrl-C
    # (trial). Every damper stays within its clearance, and the balance closes.
    dampers = [{"mass": 0.05, "at": 0, "clearance": 0.005, "law": "rigid", "restitution": 0.6}]
    sol = vi.simulate_system(
        {"kind": "oscillator", "mass": 1.0, "stiffness": 3947.8, "damping": 2.513},
        damper=dampers * 300,
        excitation=[
            {"kind": "force", "at": 0, "signal": "harmonic", "amplitude": 50.0, "frequency": 10.0}
        ],
        t_end=0.05,
        method="exact",
        history=False,
    )
    relative = sol.final_state["damper_displacement"] - sol.final_state["structure_displacement"]
    assert len(relative) == 300 and np.all(np.abs(relative) <= 0.005 * (1 + 1e-9))
    energy = sol.energy
    assert abs(energy["residual"]) <= 1e-9 * energy["input_work"]


def test_a_fifo_given_as_the_scenario_is_refused_without_waiting(
    run_cli: Cli, tmp_path: Path
) -> None:
    # Opening a FIFO waits for a writer: `simulate fifo` had waited for ever (trial).
    fifo = tmp_path / "fifo.toml"
    os.mkfifo(fifo)
    refused(run_cli("simulate", str(fifo)), "not a regular file", str(fifo))


def test_a_scenario_with_a_byte_order_mark_reads_as_without(tmp_path: Path, run_cli: Cli) -> None:
    # Notepad and PowerShell 5 write one: "invalid TOML: Invalid statement (at line 1,
    # column 1)" for a file that looks right. (The CSV reader already took it.)
    plain = write(tmp_path, BASE)
    marked = tmp_path / "marked.toml"
    marked.write_bytes(b"\xef\xbb\xbf" + plain.read_bytes())
    assert vi.load(marked) == vi.load(plain)
    done = run_cli("simulate", str(marked), "--json")
    assert done.returncode == 0, done.stderr
    assert (
        json.loads(done.stdout)["steps"]
        == json.loads(run_cli("simulate", str(plain), "--json").stdout)["steps"]
    )
