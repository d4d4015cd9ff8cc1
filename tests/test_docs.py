"""The README's and the documentation pages' snippets and commands, and the package docstring,
run as written; the README's links and figure are there."""

from __future__ import annotations

import doctest
import re
import shlex
import shutil
import subprocess
import sys
import tomllib
from pathlib import Path

import numpy as np
import pytest

import vibroimpact
from docs_blocks import ROOT, blocks, page, section
from vibroimpact.analysis import sweep

README = page("README")


def run_commands(block: str, cwd: Path) -> None:
    """Each line of a block of ``vibroimpact``/``python`` commands, run from ``cwd``: exit 0."""
    for line in block.splitlines():
        command = line.split("#")[0].strip()
        if not command:
            continue
        argv = shlex.split(command)
        if argv[0] == "python":
            argv[0] = sys.executable
        else:
            assert argv[0] == "vibroimpact", command
            argv = [sys.executable, "-m", "vibroimpact", *argv[1:]]
        done = subprocess.run(argv, cwd=cwd, capture_output=True, text=True, timeout=120)
        assert done.returncode == 0, (command, done.stderr)


def test_package_docstring_examples_pass() -> None:
    result = doctest.testmod(vibroimpact, raise_on_error=False, verbose=False)
    assert result.attempted > 0 and result.failed == 0


@pytest.mark.parametrize("name", ["README", "getting_started"])
def test_the_two_mass_snippet_runs_and_its_comment_is_true(
    name: str, capsys: pytest.CaptureFixture[str]
) -> None:
    code = next(b for b in blocks(page(name), "python") if "vi.ImpactDamper(" in b)
    exec(compile(code, name, "exec"), {})
    printed = capsys.readouterr().out.splitlines()
    claimed = re.search(r"# s, ([0-9.]+)", code)
    assert claimed is not None
    assert abs(float(printed[0]) - float(claimed.group(1))) < 5e-8
    assert "vi.check_solver(" in code
    if name == "getting_started":
        assert "energy_dissipated" in printed[1]


@pytest.mark.parametrize("name", ["README", "getting_started"])
def test_the_typed_model_snippet_runs_and_its_comment_is_true(
    name: str, capsys: pytest.CaptureFixture[str]
) -> None:
    code = next(b for b in blocks(page(name), "python") if "vi.System(" in b)
    exec(compile(code, name, "exec"), {})
    steps, contacts = capsys.readouterr().out.splitlines()[0].split()
    claimed = re.search(r"# (\d+) steps, (\d+) contacts", code)
    assert claimed is not None and (steps, contacts) == claimed.groups()


@pytest.mark.timeout(120)
def test_the_command_line_page_examples_work(tmp_path: Path) -> None:
    shutil.copytree(ROOT / "examples", tmp_path / "examples")
    (block,) = [b for b in blocks(page("cli"), "sh") if "vibroimpact simulate" in b]
    run_commands(block, tmp_path)
    assert (tmp_path / "history.csv").exists()
    assert (tmp_path / "paper-results" / "report.md").exists()


def test_the_readme_commands_work(tmp_path: Path) -> None:
    shutil.copytree(ROOT / "examples", tmp_path / "examples")
    (block,) = [b for b in blocks(README, "sh") if "vibroimpact sweep" in b]
    run_commands(block, tmp_path)
    assert (tmp_path / "history.csv").exists()
    assert (tmp_path / "frf.png").read_bytes().startswith(b"\x89PNG\r\n\x1a\n")


def test_the_readme_scenario_is_the_frf_example() -> None:
    (block,) = blocks(README, "toml")
    path = ROOT / "examples" / "frf_impact_damper.toml"
    assert vibroimpact.load(block) == vibroimpact.load(path)
    written, example = tomllib.loads(block), tomllib.loads(path.read_text(encoding="utf-8"))
    assert written["sweep"] == example["sweep"]


def test_the_readme_figure_and_its_caption_are_the_examples_sweep() -> None:
    figure = re.search(r"!\[[^]]*\]\(([^)]+)\)\n\n\*(.*?)\*\n", README, flags=re.S)
    assert figure is not None
    assert (ROOT / figure.group(1)).read_bytes().startswith(b"\x89PNG\r\n\x1a\n")
    caption = " ".join(figure.group(2).split())
    claim = re.search(
        r"lowers the peak by (\d+) % and moves it from (\d+) to ([0-9.]+) Hz", caption
    )
    assert claim is not None and "--plot" in caption
    data = tomllib.loads((ROOT / "examples" / "frf_impact_damper.toml").read_text("utf-8"))
    settings = data.pop("sweep")
    values = np.linspace(settings["start"], settings["stop"], settings["count"])
    points = sweep(data, settings["parameter"], values, direction=settings["direction"])
    damped = max(points, key=lambda p: p.amplitude[0])
    bare = max(points, key=lambda p: p.linear_amplitude[0])
    # The linear peak is the closed form's |Q| at its own resonance, read off the same grid.
    assert round(100 * (1 - damped.amplitude[0] / bare.linear_amplitude[0])) == int(claim[1])
    assert (bare.value, damped.value) == pytest.approx((float(claim[2]), float(claim[3])))
    assert any(not p.settled for p in points)


def test_the_readme_links_lead_to_pages_that_exist() -> None:
    links = re.findall(r"\]\(([^)]+)\)", README)
    pages = [link for link in links if link.startswith("docs/") and link.endswith(".rst")]
    # Every page of the site's table of contents, but the generated gallery and tutorials
    # (linked by their sources' folders).
    toctree = section("index", "vibroimpact").split(":caption: Contents", 1)[1].split()
    listed = {f"docs/{name}.rst" for name in toctree if "/" not in name}
    assert set(pages) == listed
    for link in links:
        assert (ROOT / link).exists(), link


def test_the_model_pages_scenario_blocks_run() -> None:
    (two_mass,) = [b for b in blocks(page("scenario_format"), "toml") if "[system]" in b]
    scenario = vibroimpact.parse_scenario(two_mass, "scenario_format.rst")
    assert scenario.contact.law == "hyster-hertz" and scenario.every == 1
    (general,) = [b for b in blocks(page("model"), "toml") if "[structure]" in b]
    sol = vibroimpact.parse_scenario(general, "model.rst").run()
    assert {"damper 0", "stop 0", "collision 0"} >= set(sol.contacts.pair) and len(sol.contacts) > 0
    e = sol.energy
    scale = abs(e["input_work"]) + e["dissipated"] + abs(e["stored_start"]) + abs(e["stored_end"])
    assert abs(e["residual"]) < 1e-6 * scale


def test_the_model_pages_system_snippet_runs_and_its_comments_are_true(
    capsys: pytest.CaptureFixture[str],
) -> None:
    code = next(b for b in blocks(page("model"), "python") if "simulate_system" in b)
    exec(compile(code, "model.rst", "exec"), {})
    kind, onset = capsys.readouterr().out.splitlines()[0].split()
    # The ball's accumulation time t1 (1 + e) / (1 - e), t1 = sqrt(2 h / g).
    assert kind == "sticking"
    assert abs(float(onset) - (2 / 9.81) ** 0.5 * 1.8 / 0.2) < 1e-8


@pytest.mark.parametrize("name", ["README", "getting_started"])
def test_the_test_command_is_what_ci_runs(name: str) -> None:
    setup = next(b for b in blocks(page(name), "sh") if "pytest" in b)
    command = next(line for line in setup.splitlines() if "pytest" in line)
    ci = (ROOT / ".ci" / "run").read_text(encoding="utf-8")
    assert command.strip() in ci


def test_the_model_pages_restitution_above_one_is_the_forcings_slow_contacts() -> None:
    # Which bug: a page explaining restitution > 1 by slow contacts on a forced structure
    # while the run shows none above 1 (the claim false), or fast contacts far from the
    # law's e (a law that no longer rebounds at e, the explanation hiding it).
    code = next(b for b in blocks(page("model"), "python") if "restitution > 1" in b)
    namespace: dict[str, object] = {}
    exec(compile(code.replace("print(", "(lambda *a, **k: None)("), "model.rst", "exec"), namespace)
    fast, above = namespace["fast"], namespace["above"]
    assert abs(fast.restitution.median() - 0.5) < 0.1  # type: ignore[attr-defined]
    assert fast.duration.median() < 2e-4  # type: ignore[attr-defined]
    assert len(above) >= 1 and above.restitution.max() > 10  # type: ignore[arg-type,attr-defined]
    assert (above.approach_speed < 0.01).all() and (above.duration > 2e-3).all()  # type: ignore[attr-defined]


def test_the_getting_started_study_runs_and_reads_back() -> None:
    # Which bug: a documented study call that no longer exists or writes no readable file.
    code = next(b for b in blocks(page("getting_started"), "python") if "vi.study.run(" in b)
    namespace: dict[str, object] = {}
    exec(compile(code, "getting_started.rst", "exec"), namespace)
    amplitude = namespace["amplitude"]
    assert amplitude.shape == (3, 5)  # type: ignore[attr-defined]
    # The resonance, 10 Hz (sqrt(k / m) / 2 pi = 10.0 Hz), has the largest amplitude.
    assert float(amplitude.idxmax("excitation.0.frequency")[0]) == 10.0  # type: ignore[attr-defined]
