"""The README's snippets and commands, and the package docstring, run as written."""

from __future__ import annotations

import doctest
import re
import shlex
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

import vibroimpact

ROOT = Path(__file__).resolve().parents[1]
README = (ROOT / "README.md").read_text(encoding="utf-8")


def blocks(language: str) -> list[str]:
    return re.findall(rf"```{language}\n(.*?)```", README, flags=re.S)


def test_package_docstring_examples_pass() -> None:
    result = doctest.testmod(vibroimpact, raise_on_error=False, verbose=False)
    assert result.attempted > 0 and result.failed == 0


def test_readme_python_snippet_runs_and_its_comment_is_true(
    capsys: pytest.CaptureFixture[str],
) -> None:
    code = blocks("python")[0]
    namespace: dict[str, object] = {}
    exec(compile(code, "README.md", "exec"), namespace)
    printed = capsys.readouterr().out.splitlines()
    claimed = re.search(r"# s, ([0-9.]+)", code)
    assert claimed is not None
    assert abs(float(printed[0]) - float(claimed.group(1))) < 5e-8
    assert "energy_dissipated" in printed[1]


def test_readme_command_line_examples_work(tmp_path: Path) -> None:
    shutil.copytree(ROOT / "examples", tmp_path / "examples")
    cli_block = next(b for b in blocks("sh") if "vibroimpact simulate" in b)
    for line in cli_block.splitlines():
        command = line.split("#")[0].strip()
        if not command:
            continue
        argv = shlex.split(command)
        if argv[0] == "python":
            argv[0] = sys.executable
        else:
            argv = [sys.executable, "-m", "vibroimpact", *argv[1:]]
        done = subprocess.run(argv, cwd=tmp_path, capture_output=True, text=True, timeout=120)
        assert done.returncode == 0, (command, done.stderr)
    assert (tmp_path / "history.csv").exists()
    assert (tmp_path / "paper-results" / "report.md").exists()


def test_readme_scenario_block_is_a_valid_scenario() -> None:
    toml = next(b for b in blocks("toml") if "[system]" in b)
    scenario = vibroimpact.parse_scenario(toml, "README.md")
    assert scenario.contact.law == "hyster-hertz" and scenario.every == 1


def test_readme_system_snippet_runs_and_its_comments_are_true(
    capsys: pytest.CaptureFixture[str],
) -> None:
    code = next(b for b in blocks("python") if "simulate_system" in b)
    exec(compile(code, "README.md", "exec"), {})
    kind, onset = capsys.readouterr().out.splitlines()[0].split()
    # The ball's accumulation time t1 (1 + e) / (1 - e), t1 = sqrt(2 h / g).
    assert kind == "sticking"
    assert abs(float(onset) - (2 / 9.81) ** 0.5 * 1.8 / 0.2) < 1e-8


def test_readme_system_scenario_block_runs() -> None:
    toml = next(b for b in blocks("toml") if "[structure]" in b)
    scenario = vibroimpact.parse_scenario(toml, "README.md")
    sol = scenario.run()
    assert {"damper 0", "stop 0"} >= set(sol.contacts.pair) and len(sol.contacts) > 0
    e = sol.energy
    scale = abs(e["input_work"]) + e["dissipated"] + abs(e["stored_start"]) + abs(e["stored_end"])
    assert abs(e["residual"]) < 1e-6 * scale


def test_readme_test_command_is_what_ci_runs() -> None:
    setup = next(b for b in blocks("sh") if "pytest" in b)
    command = next(line for line in setup.splitlines() if "pytest" in line)
    ci = (ROOT / ".ci" / "run").read_text(encoding="utf-8")
    assert command.strip() in ci


def test_readme_typed_model_snippet_runs_and_its_comment_is_true(
    capsys: pytest.CaptureFixture[str],
) -> None:
    code = next(b for b in blocks("python") if "vi.System(" in b)
    exec(compile(code, "README.md", "exec"), {})
    steps, contacts = capsys.readouterr().out.splitlines()[0].split()
    claimed = re.search(r"# (\d+) steps, (\d+) contacts", code)
    assert claimed is not None and (steps, contacts) == claimed.groups()
