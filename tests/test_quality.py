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
