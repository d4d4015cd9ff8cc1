"""The comments of the example scenarios are documentation: every list of choices they
give must be exactly the values the scenario accepts for that key.

A comment such as ``law = "hertz"  # "hertz" | "hyster-hertz" | "linear"`` lists the
choices of ``law``; a comment-only line starting with ``|`` continues the list above.
What is accepted comes from the scenario's own validation (the core's names, via the
error for a value that is not a choice), so a law or method added to the core and not
listed in an example fails here.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest

import vibroimpact as vi
from docs_blocks import blocks, page

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = sorted((ROOT / "examples").glob("*.toml"))
# The README's and the documentation pages' scenario blocks document the format the same way.
DOCUMENTED_SCENARIOS = [
    (name, b)
    for name in ("README", "scenario_format", "model", "analyses")
    for b in blocks(page(name), "toml")
    if "[system]" in b or "[structure]" in b
]
NOT_A_CHOICE = "not-a-choice"
QUOTED = re.compile(r'"([^"]*)"')
KEY_LINE = re.compile(r'^\s*([A-Za-z_][A-Za-z0-9_]*)\s*=\s*("[^"]*")\s*#(.*)$')
CONTINUATION = re.compile(r"^\s*#\s*(\|.*)$")


def choice_lists(text: str) -> list[tuple[str, str, list[str]]]:
    """(key, its value as written, the choices its comment lists) for every choice list."""
    found: list[tuple[str, str, list[str]]] = []
    lines = text.splitlines()
    for i, line in enumerate(lines):
        match = KEY_LINE.match(line)
        if match is None:
            continue
        key, value, comment = match.groups()
        for following in lines[i + 1 :]:
            more = CONTINUATION.match(following)
            if more is None:
                break
            comment += " " + more.group(1)
        if "|" in comment:
            found.append((key, value, QUOTED.findall(comment)))
    return found


def accepted(text: str, key: str, value: str) -> list[str]:
    """The values the scenario accepts for ``key``, from its error for a non-choice."""
    line = re.compile(rf"^(\s*{key}\s*=\s*){re.escape(value)}", flags=re.M)
    assert len(line.findall(text)) == 1, key
    with pytest.raises(vi.ScenarioError) as err:
        vi.parse_scenario(line.sub(rf'\g<1>"{NOT_A_CHOICE}"', text), "example.toml")
    message = str(err.value)
    assert f"{key} must be one of" in message, message
    names = QUOTED.findall(message.split("one of", 1)[1])
    assert names[-1] == NOT_A_CHOICE, message  # "..., got "not-a-choice""
    return names[:-1]


def test_the_parser_finds_choice_lists_and_their_continuations() -> None:
    text = (
        'method = "rk4"   # "newmark" (the paper\'s) | "rk4"\n'
        '                 # | "dopri5"\n'
        'stiffness = 3.0  # N/m ("linear")\n'
        'law = "hertz"    # the Hertz law, "hertz"\n'
    )
    assert choice_lists(text) == [("method", '"rk4"', ["newmark", "rk4", "dopri5"])]


DOCUMENTED = [(p.name, p.read_text(encoding="utf-8")) for p in EXAMPLES] + [
    (f"{name} block {i}", text) for i, (name, text) in enumerate(DOCUMENTED_SCENARIOS)
]


def test_the_examples_and_the_docs_list_choices() -> None:
    # Otherwise the test below would check nothing.
    assert EXAMPLES and {name for name, _ in DOCUMENTED_SCENARIOS} == {
        "README",
        "scenario_format",
        "model",
        "analyses",
    }
    assert sum(len(choice_lists(text)) for _, text in DOCUMENTED) >= 6


@pytest.mark.parametrize(("name", "text"), DOCUMENTED, ids=[name for name, _ in DOCUMENTED])
def test_choice_lists_in_comments_are_exactly_the_accepted_values(name: str, text: str) -> None:
    vi.parse_scenario(text, name)  # the example itself is valid
    for key, value, listed in choice_lists(text):
        allowed = accepted(text, key, value)
        assert sorted(listed) == sorted(allowed), (
            f"{name}: the comment of {key!r} lists {listed}, the scenario accepts {allowed}"
        )
        assert value.strip('"') in listed
