"""The command line's outputs at their edges (a new user's trial): a history is CSV and
its name says so, a missing folder is said before the run, an empty path is no path,
``paper --out`` is a folder, a study's ``.nc`` alone is a name, and a write the system
refuses (a full device) is one line, not a traceback."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from test_hostile_inputs import BASE, Cli, refused, write


def test_a_history_is_csv_and_its_name_must_say_so(tmp_path: Path, run_cli: Cli) -> None:
    # r.nc and r.zarr were written as CSV, which xarray could not open.
    scenario = write(tmp_path, BASE)
    for name in ("r.nc", "r.zarr", "r"):
        refused(run_cli("simulate", str(scenario), "--out", name), f"--out {name}", "CSV", ".csv")
        assert not (tmp_path / name).exists()
    done = run_cli("simulate", str(scenario), "--out", "r.csv")
    assert done.returncode == 0, done.stderr
    assert (tmp_path / "r.csv").read_text().startswith("t,")


def test_a_missing_folder_is_said_before_the_run(tmp_path: Path, run_cli: Cli) -> None:
    # It was said after the whole run, which a long run lost.
    scenario = write(tmp_path, BASE.replace("t_end = 0.2", "t_end = 1e6"))
    done = run_cli("simulate", str(scenario), "--out", "nodir/x.csv", timeout=20)
    refused(done, "--out nodir/x.csv: the folder 'nodir' does not exist")
    sweep = BASE + '[sweep]\nparameter = "excitation.0.frequency"\nstart = 9.0\nstop = 11.0\n'
    done = run_cli("sweep", str(write(tmp_path, sweep, "w.toml")), "--plot", "nodir/w.png")
    refused(done, "--plot nodir/w.png: the folder 'nodir' does not exist")


@pytest.mark.parametrize(
    "args",
    [
        ("paper", "--out", ""),
        ("simulate", "", "--json"),
        ("simulate", "s.toml", "--out", ""),
        ("study", "s.toml", "--out", ""),
    ],
)
def test_an_empty_path_is_refused(tmp_path: Path, run_cli: Cli, args: tuple[str, ...]) -> None:
    # An unset shell variable: paper --out "" wrote its seven files into the current
    # folder, replacing a report.md there.
    write(tmp_path, BASE)
    (tmp_path / "report.md").write_text("mine")
    refused(run_cli(*args), "an empty path")
    assert (tmp_path / "report.md").read_text() == "mine"


def test_paper_out_is_a_folder_and_a_studys_out_a_name(tmp_path: Path, run_cli: Cli) -> None:
    (tmp_path / "afile").write_text("mine")
    refused(run_cli("paper", "--out", "afile"), "--out afile: is a file; --out is the folder")
    assert (tmp_path / "afile").read_text() == "mine"
    study = write(tmp_path, BASE + '[study]\n[study.axes]\n"damper.0.clearance" = [0.005]\n')
    refused(run_cli("study", str(study), "--out", ".nc"), "--out .nc: needs a name before")


def test_a_name_with_a_line_break_is_quoted_on_the_error_s_one_line(
    tmp_path: Path, run_cli: Cli
) -> None:
    # A path holding a line break had split the error over two lines (a probe).
    scenario = write(tmp_path, BASE)
    done = run_cli("simulate", str(scenario), "--out", "no\nwhere/p.csv")
    assert done.returncode == 2 and done.stderr.count("\n") == 1, done.stderr
    assert "--out no\\nwhere/p.csv: the folder 'no\\nwhere' does not exist" in done.stderr
    usage = run_cli("simulate", str(scenario), "--colour", "a\nb")
    assert usage.returncode == 2 and usage.stderr.count("\n") == 1, usage.stderr


@pytest.mark.timeout(60)
def test_an_interrupted_paper_run_leaves_the_last_set_of_files_as_it_was(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # Interrupted after its tables, a run had replaced table2.csv and table3.csv and
    # left the last run's report.md and figures, whose figures then contradicted the
    # tables (an adversarial probe's Ctrl-C).
    from vibroimpact.paper import job, plots

    earlier = {"table2.csv": "old table", "table3.csv": "old", "report.md": "old report"}
    for name, text in earlier.items():
        (tmp_path / name).write_text(text)

    def interrupted(path: Path) -> None:
        raise KeyboardInterrupt

    monkeypatch.setattr(plots, "fig4", interrupted)
    with pytest.raises(KeyboardInterrupt):
        job.run_paper(tmp_path)
    assert {p.name: p.read_text() for p in tmp_path.iterdir()} == earlier


@pytest.mark.skipif(not os.path.exists("/dev/full"), reason="no /dev/full")
@pytest.mark.parametrize("words", [["simulate", "{scenario}", "--json"], ["--help"], ["--version"]])
def test_a_full_output_is_one_line(tmp_path: Path, words: list[str]) -> None:
    # --json > /dev/full ended in a traceback (OSError: No space left on device); --help
    # and --version ended with status 0 and nothing said (argparse drops a failed write).
    scenario = write(tmp_path, BASE)
    command = [word.format(scenario=scenario) for word in words]
    with open("/dev/full", "w") as full:
        done = subprocess.run(
            [sys.executable, "-m", "vibroimpact", *command],
            stdout=full,
            stderr=subprocess.PIPE,
            text=True,
            timeout=50,
            check=False,
        )
    assert done.returncode == 1 and "Traceback" not in done.stderr, done.stderr
    said = "vibroimpact: error: writing the output: No space left on device"
    assert done.stderr.strip() == said


def test_a_start_inside_a_wall_names_the_file(tmp_path: Path, run_cli: Cli) -> None:
    # Found when the run begins, the refusal named neither the file nor the keys' section.
    root = Path(__file__).resolve().parents[1]
    two_mass = (root / "examples" / "paper_collision.toml").read_text()
    assert "impact_displacement = 0.01" in two_mass
    path = write(
        tmp_path, two_mass.replace("impact_displacement = 0.01", "impact_displacement = 0.5")
    )
    said = refused(run_cli("simulate", str(path)), f"{path}: the initial state", "inside the wall")
    assert "impact_displacement" in said
    inside = BASE + "[initial]\ndamper_displacement = [0.01]\n"
    path = write(tmp_path, inside, "inside.toml")
    refused(run_cli("simulate", str(path)), f"{path}: initial state: damper 0 starts", "wall")


@pytest.mark.timeout(60)
def test_a_name_the_output_cannot_encode_is_escaped_not_a_traceback(tmp_path: Path) -> None:
    # Under PYTHONIOENCODING=ascii the summary's "sp ace é.toml" raised UnicodeEncodeError
    # (a traceback, exit 1) after the whole run.
    scenario = write(tmp_path, BASE, "sp ace é.toml")
    env = {**os.environ, "PYTHONIOENCODING": "ascii", "MPLBACKEND": "Agg"}
    done = subprocess.run(
        [sys.executable, "-m", "vibroimpact", "simulate", str(scenario)],
        capture_output=True,
        env=env,
        timeout=50,
        check=False,
    )
    assert done.returncode == 0, done.stderr
    assert b"sp ace \\xe9.toml: " in done.stdout and not done.stderr


def test_memory_the_machine_refuses_is_one_line_not_a_traceback(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    # Under a process limit below the machine's memory (ulimit -v) a run's arrays raised
    # MemoryError through to a traceback, exit 1.
    from vibroimpact.cli import command

    def refused_memory(args: object) -> int:
        raise MemoryError

    monkeypatch.setattr(command, "_simulate", refused_memory)
    assert command.main(["simulate", str(write(tmp_path, BASE))]) == 1
    err = capsys.readouterr().err
    assert err.startswith("vibroimpact: error: out of memory: ") and err.count("\n") == 1


@pytest.mark.timeout(120)
def test_memory_refused_under_a_process_limit_is_never_an_abort(tmp_path: Path) -> None:
    # Under `ulimit -v 400000` a two-mass run of 3 million rows aborted (SIGABRT, "memory
    # allocation of 24000008 bytes failed"): its history's columns were copied with an
    # allocation that cannot fail. Across limits either side of where the copy needs
    # memory, a run ends normally or with one line, never an abort.
    import resource

    root = Path(__file__).resolve().parents[1]
    text = (root / "examples" / "rattling_damper.toml").read_text()
    text = text.replace("t_end = 60.0", "t_end = 300.0").replace("every = 100", "every = 1")
    scenario = write(tmp_path, text)
    for megabytes in range(300, 520, 20):
        limit = megabytes << 20

        def limited(limit: int = limit) -> None:
            resource.setrlimit(resource.RLIMIT_AS, (limit, limit))

        done = subprocess.run(
            [sys.executable, "-m", "vibroimpact", "simulate", str(scenario)],
            capture_output=True,
            text=True,
            timeout=60,
            check=False,
            preexec_fn=limited,
        )
        assert done.returncode not in (-6, 134), (megabytes, done.stderr[-300:])
        assert "memory allocation of" not in done.stderr, (megabytes, done.stderr[-300:])
