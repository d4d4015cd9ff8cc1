"""What a new user tripped over (issue 7): inputs that must end in a one-line error,
output files written whole or not at all, what the paper job lists and draws, the
wording of the contact table, and the public API's loose ends."""

from __future__ import annotations

import ast
import csv
import errno
import io
import json
import math
import os
import pydoc
import random
import re
import stat
import sys
import tomllib
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import docs_blocks
import vibroimpact as vi
from vibroimpact.cli import command as cli
from vibroimpact.cli import main
from vibroimpact.output import UsageError, written_whole
from vibroimpact.paper import beyond, plots
from vibroimpact.paper import data as paper_data
from vibroimpact.paper import job as paper
from vibroimpact.scenario import two_mass as scenario

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = ROOT / "python" / "vibroimpact"
README = (ROOT / "README.md").read_text(encoding="utf-8")
HUGE = "1" + "0" * 400  # 10**400 written out
ORDERING = ("__lt__", "__le__", "__gt__", "__ge__")


def run_main(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    """The CLI in-process: an exception it lets through fails the test (a traceback)."""
    status = main(list(argv))
    captured = capsys.readouterr()
    return status, captured.out, captured.err


def one_line_error(err: str) -> str:
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert lines[0].startswith("vibroimpact: error: "), err
    return lines[0]


def set_value(text: str, section: str, key: str, literal: str) -> str:
    """``text`` with ``key = literal`` in ``[section]`` (replaced, or added to it)."""
    start = text.index(f"[{section}]\n")
    end = text.find("\n[", start)
    end = len(text) if end < 0 else end + 1
    body = text[start:end]
    line = re.compile(rf"^{key}\s*=.*$", flags=re.M)
    if line.search(body):
        body = line.sub(f"{key} = {literal}", body, count=1)
    else:
        body = body.replace(f"[{section}]\n", f"[{section}]\n{key} = {literal}\n", 1)
    return text[:start] + body + text[end:]


def files_in(folder: Path) -> list[str]:
    return sorted(p.name for p in folder.iterdir())


# ------------------------------------------------------------------ TOML inputs

NUMERIC_KEYS = [
    (section, key)
    for section, keys in scenario._SCHEMA.items()
    for key, (kind, _) in keys.items()
    if kind in (scenario._NUMBER, scenario._WHOLE)
]


def table1_with_sections(table1_toml: str) -> str:
    """The Table 1 scenario with every section of the format present (some may be empty)."""
    return table1_toml + "".join(
        f"\n[{section}]\n" for section in scenario._SCHEMA if f"[{section}]" not in table1_toml
    )


@pytest.mark.parametrize("literal", [HUGE, "-" + "9" * 30])
@pytest.mark.parametrize(("section", "key"), NUMERIC_KEYS, ids=[k for _, k in NUMERIC_KEYS])
def test_an_integer_beyond_64_bits_names_file_section_and_key(
    table1_toml: str, section: str, key: str, literal: str
) -> None:
    # Before: OverflowError (float(10**400)) or the binding's OverflowError.
    text = set_value(table1_with_sections(table1_toml), section, key, literal)
    with pytest.raises(vi.ScenarioError) as err:
        vi.parse_scenario(text, "case.toml")
    message = str(err.value)
    assert message.startswith(f"case.toml: [{section}] {key}: "), message
    assert "64-bit" in message and "\n" not in message
    assert len(message) < 200, message  # the 400 digits are not echoed


@pytest.mark.parametrize(
    ("value", "said"),
    [
        (HUGE, "[system] main_mass: an integer of 401 digits"),
        ("[" * 5000 + "]" * 5000, "invalid TOML: values nested too deeply"),
        ("{a = " * 5000 + "1" + "}" * 5000, "invalid TOML: values nested too deeply"),
        ("1" + "0" * 5000, "invalid TOML"),  # more digits than Python converts by default
    ],
    ids=["10**400", "nested-arrays", "nested-tables", "5000-digits"],
)
def test_values_beyond_toml_exit_2_in_one_line(
    table1_toml: str, tmp_path: Path, capsys: pytest.CaptureFixture[str], value: str, said: str
) -> None:
    # Before: OverflowError, RecursionError or ValueError tracebacks.
    path = tmp_path / "case.toml"
    path.write_text(set_value(table1_toml, "system", "main_mass", value), encoding="utf-8")
    status, _, err = run_main(capsys, "simulate", str(path))
    assert status == 2
    line = one_line_error(err)
    assert f"{path}: {said}" in line
    assert len(line) - len(str(path)) < 200, line


def test_values_quoted_in_errors_are_cut_short(table1_toml: str) -> None:
    long_list = "[" + ", ".join(["1"] * 100_000) + "]"
    with pytest.raises(vi.ScenarioError) as err:
        vi.parse_scenario(set_value(table1_toml, "system", "main_mass", long_list), "x.toml")
    assert "[system] main_mass: must be a number" in str(err.value)
    assert len(str(err.value)) < 200


def _binary_junk(path: Path) -> None:
    path.write_bytes(random.Random(7).randbytes(4096))


def _nul_bytes(path: Path) -> None:
    path.write_bytes(b"\x00" * 1000)  # valid UTF-8, not TOML


def _not_utf8(path: Path) -> None:
    path.write_bytes('[system]\nmain_mass = "caf\xe9"\n'.encode("latin-1"))


def _directory(path: Path) -> None:
    path.mkdir()


def _missing(path: Path) -> None:
    pass


def _huge(path: Path) -> None:
    with path.open("wb") as f:  # sparse: no disk space used
        f.truncate(scenario.MAX_SCENARIO_BYTES + 1)


BAD_FILES: dict[str, Callable[[Path], None]] = {
    "binary-junk": _binary_junk,
    "nul-bytes": _nul_bytes,
    "not-utf8": _not_utf8,
    "directory": _directory,
    "missing": _missing,
    "huge": _huge,
}


@pytest.mark.parametrize("kind", list(BAD_FILES))
def test_no_scenario_file_gives_a_traceback(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], kind: str
) -> None:
    path = tmp_path / "scenario.toml"
    BAD_FILES[kind](path)
    status, out, err = run_main(capsys, "simulate", str(path))
    assert (status, out) == (2, "")
    assert str(path) in one_line_error(err)


def test_a_path_through_a_file_exits_2(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    (tmp_path / "file").write_text("x")
    status, _, err = run_main(capsys, "simulate", str(tmp_path / "file" / "scenario.toml"))
    assert status == 2 and "scenario.toml" in one_line_error(err)


@pytest.mark.skipif(not hasattr(os, "geteuid") or os.geteuid() == 0, reason="root reads any file")
def test_an_unreadable_file_exits_2(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "secret.toml"
    path.write_text("[system]\n")
    path.chmod(0)
    status, _, err = run_main(capsys, "simulate", str(path))
    assert status == 2 and "secret.toml" in one_line_error(err)


@pytest.mark.skipif(not Path("/dev/zero").exists(), reason="no /dev/zero")
@pytest.mark.timeout(30)
def test_an_endless_file_is_refused_without_reading_it_all(
    capsys: pytest.CaptureFixture[str],
) -> None:
    # Reading /dev/zero whole would never end (or exhaust the memory): a device is
    # refused before it is read, and a file of endless text by its size limit.
    status, _, err = run_main(capsys, "simulate", "/dev/zero")
    assert status == 2 and "not a regular file" in one_line_error(err)


def test_real_bugs_are_not_swallowed(
    monkeypatch: pytest.MonkeyPatch, table1_toml: str, tmp_path: Path
) -> None:
    # The CLI catches bad input precisely; a bug in our code must still show.
    path = tmp_path / "ok.toml"
    path.write_text(table1_toml, encoding="utf-8")

    def broken(_: object) -> None:
        raise ZeroDivisionError("a bug")

    monkeypatch.setattr(cli, "load_scenario", broken)
    with pytest.raises(ZeroDivisionError):
        main(["simulate", str(path)])


# ------------------------------------------------------ files whole or not at all

REAL_CSV_WRITER = csv.writer  # the tests below replace csv.writer
OLD = b"old content,\xe2\x9c\x93\nkept byte for byte\n"


@pytest.fixture
def old_history(tmp_path: Path) -> Path:
    folder = tmp_path / "out"
    folder.mkdir()
    path = folder / "history.csv"
    path.write_bytes(OLD)
    path.chmod(0o640)
    return path


def test_out_replaces_an_existing_file_and_keeps_its_permissions(
    old_history: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    status, out, _ = run_main(capsys, "simulate", "--out", str(old_history))
    assert status == 0
    with old_history.open(newline="", encoding="utf-8") as f:
        rows = list(csv.reader(f))
    sol = vi.simulate(*beyond.table1(), method="newmark", dt=1e-4, t_end=0.3)
    assert rows[0] == [name for name, _ in cli.HISTORY_COLUMNS]
    assert len(rows) == len(sol.t) + 1
    assert float(rows[-1][0]) == sol.t[-1]
    assert stat.S_IMODE(old_history.stat().st_mode) == 0o640
    assert files_in(old_history.parent) == ["history.csv"]
    assert f"written to {old_history}" in out


class FailingWriter:
    """A csv writer that fails after ``rows`` rows, having flushed them to its file."""

    def __init__(self, f: io.TextIOBase, folder: Path, rows: int, error: BaseException) -> None:
        self.file, self.folder, self.left, self.error = f, folder, rows, error
        self.inner = REAL_CSV_WRITER(f)  # type: ignore[arg-type]
        self.seen: list[str] = []

    def writerow(self, row: Any) -> None:
        if self.left == 0:
            self.file.flush()
            self.seen = files_in(self.folder)
            raise self.error
        self.left -= 1
        self.inner.writerow(row)


@pytest.mark.parametrize(
    ("error", "status"),
    [(OSError(errno.ENOSPC, "No space left on device"), 2), (KeyboardInterrupt(), 130)],
    ids=["disk-full", "interrupted"],
)
def test_a_run_that_fails_while_writing_leaves_the_old_file_whole(
    old_history: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
    error: BaseException,
    status: int,
) -> None:
    writers: list[FailingWriter] = []

    def failing(f: io.TextIOBase) -> FailingWriter:
        writers.append(FailingWriter(f, old_history.parent, 500, error))
        return writers[-1]

    monkeypatch.setattr(cli.csv, "writer", failing)
    got, _, err = run_main(capsys, "simulate", "--out", str(old_history))
    assert got == status
    # Midway, the rows went to a temporary file beside it, not into it...
    (writer,) = writers
    temporary = [name for name in writer.seen if name != "history.csv"]
    assert len(temporary) == 1 and temporary[0].startswith(".history.csv.")
    # ...which is gone; the old file is as it was.
    assert old_history.read_bytes() == OLD
    assert files_in(old_history.parent) == ["history.csv"]
    if status == 2:
        line = one_line_error(err)
        assert str(old_history) in line and "No space left" in line


def test_out_on_a_directory_exits_2_and_leaves_nothing(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    target = tmp_path / "folder"
    target.mkdir()
    status, _, err = run_main(capsys, "simulate", "--out", str(target))
    assert status == 2 and str(target) in one_line_error(err)
    assert files_in(tmp_path) == ["folder"] and files_in(target) == []


def test_written_whole_lets_other_errors_through_and_writes_new_files(tmp_path: Path) -> None:
    path = tmp_path / "a.txt"
    path.write_bytes(OLD)
    with pytest.raises(ValueError, match="midway"), written_whole(path) as f:
        f.write("new " * 10_000)
        raise ValueError("midway")
    assert path.read_bytes() == OLD and files_in(tmp_path) == ["a.txt"]
    fresh = tmp_path / "b.bin"
    with written_whole(fresh, binary=True) as f:
        f.write(b"\x89PNG")
    assert fresh.read_bytes() == b"\x89PNG"
    umask = os.umask(0)
    os.umask(umask)
    assert stat.S_IMODE(fresh.stat().st_mode) == 0o666 & ~umask  # as open() would give
    with pytest.raises(UsageError, match="cannot write"), written_whole(tmp_path / "no" / "c"):
        pass
    # Through a symbolic link: the file it points to is written, the link stays.
    link = tmp_path / "link.txt"
    link.symlink_to(path)
    with written_whole(link) as f:
        f.write("through the link")
    assert link.is_symlink() and path.read_text(encoding="utf-8") == "through the link"


def _single_run(run: Callable[[], Any], min_repeats: int = 5, budget: float = 0.02) -> Any:
    """median_time without the repeats: the job's numbers, not its timings, are tested."""
    return run(), 1e-6


@pytest.fixture
def quick_paper(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(beyond, "median_time", _single_run)
    monkeypatch.setattr(paper, "median_time", _single_run)


def test_a_paper_job_that_fails_midway_leaves_the_old_files_whole(
    quick_paper: None,
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:
    import matplotlib.figure

    out = tmp_path / "results"
    out.mkdir()
    names = ["table2.csv", "table3.csv", "fig1.png", "fig3.png", "fig4.png", "report.md"]
    for name in names:
        (out / name).write_bytes(OLD + name.encode())

    def disk_full(self: Any, f: Any, **kwargs: Any) -> None:
        f.write(b"\x89PNG half a figure")
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(matplotlib.figure.Figure, "savefig", disk_full)
    status, _, err = run_main(capsys, "paper", "--out", str(out))
    assert status == 2
    assert f"cannot write {str(out / 'fig1.png')!r}" in one_line_error(err)
    # Every file as it was, the tables too (made before the first figure, they are
    # moved in with the rest only at the end).
    for name in names:
        assert (out / name).read_bytes() == OLD + name.encode(), name
    assert files_in(out) == sorted(names)


# ----------------------------------------------------------------- the paper job


@pytest.fixture(scope="module")
def paper_run(tmp_path_factory: pytest.TempPathFactory) -> Iterator[tuple[Path, str]]:
    """The paper job once, in-process, each run timed once."""
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(beyond, "median_time", _single_run)
        mp.setattr(paper, "median_time", _single_run)
        out = tmp_path_factory.mktemp("paper") / "results"
        stdout = io.StringIO()
        mp.setattr(sys, "stdout", stdout)
        assert paper.run_paper(out) == 0
    yield out, stdout.getvalue()


def test_the_report_lists_exactly_the_files_written(paper_run: tuple[Path, str]) -> None:
    out, stdout = paper_run
    report = (out / "report.md").read_text(encoding="utf-8")
    listed = re.search(r"Files:\s*(.*?)\. All values SI", report, flags=re.S)
    assert listed is not None
    names = re.findall(r"`([^`]+)`", listed.group(1))
    assert sorted(names) == files_in(out)
    assert "work_precision.png" in names and "report.md" in names
    wrote = re.search(r"wrote (.*) to ", stdout)
    assert wrote is not None and sorted(wrote.group(1).split(", ")) == files_in(out)
    # The command line page's description of the job names them all too.
    cli_page = docs_blocks.page("cli")
    paragraph = cli_page[cli_page.index("``vibroimpact paper`` writes") :].split("\n\n")[0]
    described = docs_blocks.prose(paragraph)
    for name in files_in(out):
        assert f"`{name}`" in described, name


def test_the_report_counts_step_differences_from_the_full_durations(
    paper_run: tuple[Path, str],
) -> None:
    out, _ = paper_run
    report = " ".join((out / "report.md").read_text(encoding="utf-8").split())
    with (out / "table2.csv").open(newline="", encoding="utf-8") as f:
        counted = {
            (r["method"].split(" ")[0], float(r["dt"])): float(r["contact_duration"])
            for r in csv.DictReader(f)
            if r["method"].endswith("(step-count)")
        }
    checked = 0
    for method, dt, paper_tc, *_ in paper_data.PAPER_TABLE2:
        claim = re.search(
            rf"{method} at dt = {dt:g} \([0-9.]+ s against [0-9.]+ s, ([+-]\d+) steps", report
        )
        if claim is None:
            continue
        # Whole steps: the paper's printed duration and ours, each in steps of dt.
        expected = round(paper_tc / dt) - round(counted[(method, dt)] / dt)
        assert int(claim.group(1)) == expected, (method, dt)
        checked += 1
    assert checked >= 4  # the paper's Newmark at 2e-5 s among them (-4, not -5)


def test_the_work_precision_comparison_with_scipy_is_there(paper_run: tuple[Path, str]) -> None:
    report = (paper_run[0] / "report.md").read_text(encoding="utf-8")
    assert "scipy RK45" in report and "scipy DOP853" in report
    assert "cannot be imported" not in report and "note:" not in paper_run[1]
    dependencies = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))
    assert any(re.match(r"scipy\b", d) for d in dependencies["project"]["dependencies"]), (
        "scipy is a runtime dependency"
    )


def test_a_missing_scipy_is_said_not_silently_left_out(
    quick_paper: None,
    monkeypatch: pytest.MonkeyPatch,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
) -> None:
    monkeypatch.setitem(sys.modules, "scipy", None)  # import scipy now raises ImportError
    monkeypatch.setitem(sys.modules, "scipy.integrate", None)
    message = beyond.scipy_missing()
    assert message is not None and "pip install scipy" in message
    assert beyond.scipy_runs(0.1) == []
    status, out, _ = run_main(capsys, "paper", "--out", str(tmp_path))
    assert status == 0
    assert f"note: {message}" in out.splitlines()
    report = (tmp_path / "report.md").read_text(encoding="utf-8")
    assert message in report and "scipy RK45" not in report


# --------------------------------------------------------------------- figures


@pytest.fixture
def figures(monkeypatch: pytest.MonkeyPatch) -> dict[str, Any]:
    """Figures drawn by plots.py, kept instead of written."""
    kept: dict[str, Any] = {}
    monkeypatch.setattr(plots, "_save", lambda fig, path: kept.__setitem__(path.name, fig))
    return kept


def test_fig3_labels_every_line_and_the_vertical_one_is_goldsmiths_maximum(
    figures: dict[str, Any],
) -> None:
    plots.fig3(Path("fig3.png"), 39.3)
    (ax,) = figures["fig3.png"].axes
    assert all(not line.get_label().startswith("_") for line in ax.lines)
    vertical = [line for line in ax.lines if np.ptp(line.get_xdata()) == 0]
    assert len(vertical) == 1 and "maximum indentation" in vertical[0].get_label()
    # Goldsmith: delta_max = (5 m* v^2 / (4 K_hz))^(2/5), m* = m M / (m + M).
    m_star = 0.25 * 1.0 / 1.25
    dmax = (5 * m_star * 0.1**2 / (4 * 3000.0)) ** 0.4
    assert vertical[0].get_xdata()[0] == pytest.approx(dmax * 1e3, rel=1e-12)


def test_fig4_says_which_steps_of_the_papers_newmark_it_marks(figures: dict[str, Any]) -> None:
    plots.fig4(Path("fig4.png"))
    (ax,) = figures["fig4.png"].axes
    assert all(not line.get_label().startswith("_") for line in ax.lines)
    markers = [line for line in ax.lines if line.get_linestyle() == "None"]
    assert len(markers) == 2
    for line in markers:
        said = re.search(r"every (\d+)\w* step", line.get_label())
        assert said is not None, line.get_label()
        # The paper's Newmark runs at dt = 1e-3 s: the markers are that many steps apart.
        np.testing.assert_allclose(np.diff(line.get_xdata()), int(said.group(1)) * 1e-3)


def test_fig1_names_the_loading_and_unloading_branches(figures: dict[str, Any]) -> None:
    plots.fig1(Path("fig1.png"))
    _, b = figures["fig1.png"].axes
    named = {a.get_text(): a.xy for a in b.texts if a.get_text()}
    assert set(named) == {"loading", "unloading"}
    (loop,) = [line for line in b.lines if line.get_label() == "e = 0.5"]
    x, y = np.asarray(loop.get_xdata()), np.asarray(loop.get_ydata())
    deepest = int(np.nanargmax(x))
    for text, before_deepest in (("loading", True), ("unloading", False)):
        i = int(np.nanargmin(np.hypot(x - named[text][0], y - named[text][1])))
        assert (x[i], y[i]) == pytest.approx(named[text])
        # Time runs along the data: loading is before the deepest point, unloading after.
        assert (i < deepest) == before_deepest, text
    # And each loop has its direction shown, loading and unloading.
    arrows = [a for a in b.texts if not a.get_text()]
    assert len(arrows) == 2 * 4


def test_work_precision_says_what_varies_along_each_line(figures: dict[str, Any]) -> None:
    def run(label: str, dt: float | None, rtol: float | None, cpu: float) -> beyond.StudyRun:
        return beyond.StudyRun(label, "", dt, rtol, 0.1, cpu * 1e-3, cpu, 0)

    study = [run("rk4 (events)", dt, None, cpu) for dt, cpu in ((1e-3, 2.0), (4e-3, 1.0))]
    study += [run("dop853", None, rtol, cpu) for rtol, cpu in ((1e-12, 3.0), (1e-4, 5.0))]
    plots.work_precision(Path("wp.png"), study, [run("scipy RK45", None, 1e-6, 9.0)])
    (ax,) = figures["wp.png"].axes
    lines = {line.get_label(): line for line in ax.lines}
    assert set(lines) == {
        "rk4 (events): dt = 4e-3 to 1e-3 s",
        "dop853: rtol = 1e-4 to 1e-12",
        "scipy RK45: rtol = 1e-6 to 1e-6",
    }
    # The data plotted are the runs', from the largest setting to the smallest.
    np.testing.assert_array_equal(lines["rk4 (events): dt = 4e-3 to 1e-3 s"].get_xdata(), [1, 2])
    np.testing.assert_array_equal(lines["dop853: rtol = 1e-4 to 1e-12"].get_xdata(), [5, 3])
    np.testing.assert_array_equal(lines["dop853: rtol = 1e-4 to 1e-12"].get_ydata(), [5e-3, 3e-3])


# ------------------------------------------------------------------ the contact table


def test_the_table_and_help_say_what_dissipated_means(
    capsys: pytest.CaptureFixture[str],
) -> None:
    status, out, _ = run_main(capsys, "simulate")
    assert status == 0
    header = next(line for line in out.splitlines() if "onset (s)" in line)
    assert len(re.split(r"\s{2,}", header.strip())) == len(vi.ContactTable.columns)
    assert "net change (J)" in header and "dissipated (J)" in header
    assert cli.ENERGY_DISSIPATED_TEXT in out and cli.ENERGY_CHANGE_TEXT in out
    with pytest.raises(SystemExit):
        main(["simulate", "--help"])
    described = " ".join(capsys.readouterr().out.split())
    assert cli.ENERGY_DISSIPATED_TEXT in described and cli.ENERGY_CHANGE_TEXT in described
    cli_page = docs_blocks.prose(docs_blocks.page("cli"))
    assert "work of the contact's dissipative forces" in cli_page
    assert "mechanical energy at separation minus at onset" in cli_page


def test_the_docs_figures_for_the_default_run_are_its_own(
    capsys: pytest.CaptureFixture[str],
) -> None:
    status, out, _ = run_main(capsys, "simulate", "--json")
    assert status == 0
    (contact,) = json.loads(out)["contacts"]
    text = docs_blocks.prose(docs_blocks.page("cli"))
    claim = re.search(
        r"rebounds at ([0-9.]+) of the approach speed while ([0-9.e-]+) J are dissipated, "
        r"and the system gains ([0-9.e-]+) J",
        text,
    )
    assert claim is not None
    assert float(claim.group(1)) == round(contact["restitution"], 4)
    assert float(claim.group(2)) == float(f"{contact['energy_dissipated']:.1e}")
    assert float(claim.group(3)) == float(f"{contact['energy_change']:.1e}")
    assert contact["restitution"] > 1 and contact["energy_dissipated"] > 0
    # A rebound faster than the approach is energy gained: the two columns agree on it.
    assert contact["energy_change"] > 0


def test_a_contact_open_at_the_end_reads_open_and_null(
    table1_toml: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = tmp_path / "open.toml"
    path.write_text(table1_toml.replace("t_end = 0.2", "t_end = 0.05"), encoding="utf-8")
    (row,) = vi.load_scenario(path).run().contacts.to_dicts()
    undefined = {name for name, value in row.items() if math.isnan(value)}
    # The columns ContactTable's documentation calls undefined for an open contact.
    assert undefined == {"separation", "duration", "rebound_speed", "restitution", "energy_change"}

    status, out, _ = run_main(capsys, "simulate", str(path))
    assert status == 0
    lines = out.splitlines()
    header = next(i for i, line in enumerate(lines) if "onset (s)" in line)
    cells = lines[header + 1].split()
    columns = list(vi.ContactTable.columns)
    assert len(cells) == len(columns) and "nan" not in lines[header + 1]
    assert {name for name, cell in zip(columns, cells, strict=True) if cell == "open"} == undefined

    status, out, _ = run_main(capsys, "simulate", str(path), "--json")
    (contact,) = json.loads(out)["contacts"]
    assert {name for name, value in contact.items() if value is None} == undefined


# -------------------------------------------------------------------------- API


@pytest.mark.parametrize("cls", [vi.ImpactDamper, vi.Contact, vi.InitialState])
def test_help_shows_equality_but_no_ordering(cls: type) -> None:
    text = pydoc.render_doc(cls, renderer=pydoc.plaintext)
    assert "__eq__" in text and "__ne__" in text
    for name in ORDERING:
        assert name not in text, name
    make = {
        vi.ImpactDamper: lambda s: vi.ImpactDamper(
            main_mass=1.0, stiffness=s, impact_mass=0.25, clearance=0.01
        ),
        vi.Contact: lambda s: vi.Contact("hertz", stiffness=s),
        vi.InitialState: lambda s: vi.InitialState(main_velocity=s),
    }[cls]
    a, b, c = make(1.0), make(1.0), make(2.0)
    assert a == b and not a != b and a != c and not a == c
    with pytest.raises(TypeError):
        _ = a < b  # type: ignore[operator]


def test_no_public_class_lists_orderings_it_does_not_have() -> None:
    for name in vi.__all__:
        value = getattr(vi, name)
        if isinstance(value, type):
            assert not set(ORDERING) & set(vars(value)), name


def test_every_public_name_of_the_extension_is_exported() -> None:
    stub = ast.parse((PACKAGE / "_core.pyi").read_text(encoding="utf-8"))
    (public,) = [
        ast.literal_eval(node.value)
        for node in stub.body
        if isinstance(node, ast.Assign) and getattr(node.targets[0], "id", "") == "__all__"
    ]
    for name in public:
        assert name in vi.__all__ and hasattr(vi, name), name
    with pytest.raises(vi.InvalidInputError, match="dt"):
        vi.check_solver(method="rk4", dt=0.0, t_end=1.0)
    assert "vi.check_solver(" in README


def _imports(path: Path) -> set[str]:
    """The package modules a module imports, anywhere but under ``if TYPE_CHECKING``."""
    found: set[str] = set()

    def visit(node: ast.AST) -> None:
        if isinstance(node, ast.If) and getattr(node.test, "id", "") == "TYPE_CHECKING":
            return
        if isinstance(node, ast.ImportFrom) and node.module == "vibroimpact":
            found.update(f"vibroimpact.{a.name}" for a in node.names)
        elif isinstance(node, ast.ImportFrom) and (node.module or "").startswith("vibroimpact."):
            found.add(node.module or "")
        elif isinstance(node, ast.Import):
            found.update(a.name for a in node.names if a.name.startswith("vibroimpact."))
        for child in ast.iter_child_nodes(node):
            visit(child)

    visit(ast.parse(path.read_text(encoding="utf-8")))
    return found


def test_the_package_modules_import_each_other_without_a_cycle() -> None:
    # paper.py imported cli.py (for UsageError) while cli.py imports paper.py; plots.py and
    # report.py imported paper.py, which imports them. Each concern in one room instead.
    # Subpackages too (vibroimpact.model): a package is its __init__, which importing
    # any of its modules runs first (an edge from every module outside it).
    graph: dict[str, set[str]] = {}
    for path in PACKAGE.rglob("*.py"):
        parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
        if parts[-1] == "__init__":
            parts = parts[:-1]
            if len(parts) == 1:
                continue  # the package itself imports everything it exports
        graph[".".join(parts)] = _imports(path)
    for name, imported in graph.items():
        for module in list(imported):
            package = module.rpartition(".")[0]
            if package in graph and not (name + ".").startswith(package + "."):
                imported.add(package)
    assert "vibroimpact.paper.data" in graph["vibroimpact.paper.plots"]  # the walk sees imports
    assert "vibroimpact.model" in graph["vibroimpact.analysis.runs"]  # and subpackages

    def reaches(start: str, goal: str) -> bool:
        # Depth first, each module visited once (a walk of every path had grown
        # exponentially with the package: 60 s at 65 modules).
        stack, seen = [start], {start}
        while stack:
            for module in graph.get(stack.pop(), set()):
                if module == goal:
                    return True
                if module not in seen:
                    seen.add(module)
                    stack.append(module)
        return False

    cycles = [module for module in graph if reaches(module, module)]
    assert cycles == []
