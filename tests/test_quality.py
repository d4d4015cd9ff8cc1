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
    """The repository's own files of ``suffix`` in :data:`SOURCES` (those git tracks,
    where it can say; else every such file there, outside build folders)."""
    done = subprocess.run(
        ["git", "ls-files", "-z", "--", *SOURCES], cwd=ROOT, capture_output=True, timeout=60
    )
    if done.returncode == 0 and done.stdout:
        names = done.stdout.decode().split("\0")
        paths = (ROOT / name for name in names if name.endswith(suffix))
        return sorted(p for p in paths if p.is_file())
    return sorted(
        p
        for folder in SOURCES
        for p in (ROOT / folder).glob(f"**/*{suffix}")
        if not {"target", "_build", ".venv", "site-packages"} & set(p.parts)
    )


def _rust_functions(text: str) -> list[tuple[str, int]]:
    """Each function with a body in rustfmt-formatted ``text``, from its ``fn`` line to
    the brace that closes it at the same indentation, with its length in lines (a
    trait's declarations, ending in ``;``, have none)."""
    import re

    lines = text.split("\n")
    found = []
    start = re.compile(
        r"^(\s*)(?:pub(?:\([a-z]+\))? )?(?:const )?(?:async )?(?:unsafe )?"
        r'(?:extern "C" )?fn (\w+)'
    )
    for i, line in enumerate(lines):
        match = start.match(line)
        if match is None:
            continue
        # The signature ends where the body opens (or closes on the same line).
        for j in range(i, len(lines)):
            tail = lines[j].rstrip()
            if tail.endswith(("{", ";", "}")):
                break
        if tail.endswith(";"):
            continue
        close = match.group(1) + "}"
        end = j
        if tail.endswith("{"):
            end = next((e for e in range(j + 1, len(lines)) if lines[e] == close), len(lines))
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
    # brace (not a nested one, not a later function's, not the file's end); a trait's
    # declaration has no body; an empty body closes on its own line.
    text = (
        "trait T {\n    fn d(&self) -> u8;\n    fn e(\n        &self,\n    ) -> u8 {\n"
        "        1\n    }\n}\n"
        "impl A {\n    pub(crate) fn a() {\n        if x {\n        }\n    }\n}\n"
        "fn b() {\n}\nfn c() {}\nasync fn f<T>(x: T)\nwhere\n    T: Copy,\n{\n    x;\n}\n"
    )
    assert _rust_functions(text) == [("e", 5), ("a", 4), ("b", 2), ("c", 1), ("f", 6)]
