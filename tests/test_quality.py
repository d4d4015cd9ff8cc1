"""Code-quality gates that run with the tests: the extension's stub matches the
compiled module, the Python sources pass ruff and mypy, the Rust sources are
formatted."""

import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def run(*argv: str) -> None:
    done = subprocess.run(argv, cwd=ROOT, capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stdout + done.stderr


def test_stub_matches_the_extension_module() -> None:
    run(sys.executable, "-m", "mypy.stubtest", "vibroimpact._core")


def test_python_sources_pass_ruff() -> None:
    run(sys.executable, "-m", "ruff", "check", "python", "tests", "benchmarks")
    run(sys.executable, "-m", "ruff", "format", "--check", "python", "tests", "benchmarks")


def test_python_package_passes_mypy_strict() -> None:
    run(sys.executable, "-m", "mypy")


@pytest.mark.skipif(shutil.which("cargo") is None, reason="needs cargo")
def test_rust_sources_are_formatted() -> None:
    run("cargo", "fmt", "--all", "--check")


def test_every_rust_test_runs_under_a_time_limit() -> None:
    """cargo test has no per-test timeout: each #[test], in crates/*/tests and in the
    sources' unit tests, must run its body through the testing module's timeout, so
    that a hang fails in seconds."""
    import re

    test = re.compile(r"#\[test\]\s*\n(?:\s*#\[[^\n]*\]\s*\n)*\s*fn (\w+)\(\) \{\n\s*(\S+)")
    found = 0
    for path in sorted((ROOT / "crates").glob("**/*.rs")):
        text = path.read_text(encoding="utf-8")
        expected = text.count("#[test]")
        tests = test.findall(text)
        assert len(tests) == expected, path.name
        for name, first in tests:
            assert first.startswith(("common::timeout(", "crate::testing::timeout(")), (
                f"{path.name}: {name}"
            )
        found += expected
    assert found >= 80


#: The tree's limits (issue 24, and the developers' guide): split along concerns first.
MAX_FILE_LINES, MAX_FUNCTION_LINES = 800, 150
#: The folders whose Rust and Python sources the limits hold for.
SOURCES = ("crates", "python", "tests", "benchmarks", "docs", "examples")


def _sources(suffix: str) -> list[Path]:
    return sorted(
        p
        for folder in SOURCES
        for p in (ROOT / folder).glob(f"**/*{suffix}")
        if not {"target", "_build", "build", ".ipynb_checkpoints"} & set(p.parts)
    )


def _rust_functions(text: str) -> list[tuple[str, int]]:
    """Each function of rustfmt-formatted ``text``, from its ``fn`` line to the brace
    that closes it at the same indentation, with its length in lines."""
    import re

    lines = text.split("\n")
    found = []
    start = re.compile(r"^(\s*)(?:pub(?:\([a-z]+\))? )?(?:const )?(?:unsafe )?fn (\w+)")
    for i, line in enumerate(lines):
        match = start.match(line)
        if match is None:
            continue
        close = match.group(1) + "}"
        end = next((j for j in range(i + 1, len(lines)) if lines[j] == close), i)
        found.append((match.group(2), end - i + 1))
    return found


def test_no_source_file_or_function_is_over_the_tree_s_limits() -> None:
    import ast

    rust, python = _sources(".rs"), _sources(".py")
    assert len(rust) > 50 and len(python) > 100
    too_long = [
        f"{p.relative_to(ROOT)}: {n} lines"
        for p in rust + python
        if (n := p.read_text(encoding="utf-8").count("\n")) > MAX_FILE_LINES
    ]
    for p in rust:
        too_long += [
            f"{p.relative_to(ROOT)}: fn {name}, {n} lines"
            for name, n in _rust_functions(p.read_text(encoding="utf-8"))
            if n > MAX_FUNCTION_LINES
        ]
    for p in python:
        too_long += [
            f"{p.relative_to(ROOT)}: def {node.name}, {n} lines"
            for node in ast.walk(ast.parse(p.read_text(encoding="utf-8")))
            if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef)
            and (n := (node.end_lineno or node.lineno) - node.lineno + 1) > MAX_FUNCTION_LINES
        ]
    assert not too_long, "split along concerns: " + "; ".join(too_long)


def test_the_rust_functions_are_measured_to_their_closing_brace() -> None:
    # The measure the limit relies on: a function's length runs to its own closing
    # brace (not a nested one, not the file's end).
    text = "impl A {\n    pub(crate) fn a() {\n        if x {\n        }\n    }\n}\nfn b() {\n}\n"
    assert _rust_functions(text) == [("a", 4), ("b", 2)]
