"""docs/methods.rst stays true: its examples run as written, and every test and source file
it names as the proof of a claim exists (a renamed test would otherwise leave the page citing
nothing)."""

from __future__ import annotations

import doctest
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PAGE = ROOT / "docs" / "methods.rst"
CORE = ROOT / "crates" / "vibroimpact-core" / "src"
TEXT = PAGE.read_text(encoding="utf-8")
# ``tests/test_x.py::test_name``, as the page cites a proof.
CITED_TESTS = sorted(set(re.findall(r"``(tests/[\w/]+\.py)::(test_\w+)``", TEXT)))
# ``kernel/events.rs``, ``methods/exact/``: paths under the core's src/.
CORE_PATH = r"(?:model|kernel|methods|numerics|analysis)/[\w/]*"
CITED_SOURCES = sorted(set(re.findall(rf"``({CORE_PATH}(?:\.rs|/))``", TEXT)))
# ``analysis/tangent/tests.rs::the_name``: a Rust test in the core.
CITED_CORE_TESTS = sorted(set(re.findall(rf"``({CORE_PATH}\.rs)::(\w+)``", TEXT)))


@pytest.mark.timeout(120)
def test_the_page_examples_pass() -> None:
    result = doctest.testfile(str(PAGE), module_relative=False, verbose=False)
    assert result.attempted >= 10 and result.failed == 0, result


def test_the_page_cites_tests_and_sources() -> None:
    # The regexes found the citations: a page that stopped citing would pass the tests below.
    assert len(CITED_TESTS) >= 30 and len(CITED_SOURCES) >= 15 and len(CITED_CORE_TESTS) >= 2


@pytest.mark.parametrize(("path", "name"), CITED_TESTS, ids=[n for _, n in CITED_TESTS])
def test_every_cited_test_exists(path: str, name: str) -> None:
    source = (ROOT / path).read_text(encoding="utf-8")
    assert re.search(rf"^def {name}\(", source, flags=re.M), f"{path}::{name}"


@pytest.mark.parametrize("path", CITED_SOURCES)
def test_every_cited_source_exists(path: str) -> None:
    assert (CORE / path).exists(), path


@pytest.mark.parametrize(("path", "name"), CITED_CORE_TESTS, ids=[n for _, n in CITED_CORE_TESTS])
def test_every_cited_core_test_exists(path: str, name: str) -> None:
    source = (CORE / path).read_text(encoding="utf-8")
    assert re.search(rf"#\[test\]\s*\n\s*fn {name}\(", source), f"{path}::{name}"
