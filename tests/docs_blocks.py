"""The sections, prose and code blocks of the documentation's pages and of the README.

The tests that run the documentation's snippets and commands read them here, so that a
snippet that breaks, or a page that loses it, fails a test. A docs page is named by its
source, ``docs/NAME.rst``; the README is ``"README"``.
"""

from __future__ import annotations

import re
import textwrap
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"

# The directives whose content is code of a language: the site's own run-python and
# run-command (docs/_ext/run_output.py) show Python and vibroimpact commands.
_DIRECTIVES = {
    "python": ("code-block:: python", "run-python::"),
    "sh": ("code-block:: sh", "run-command::"),
}
_UNDERLINE = re.compile(r"^([=\-~^\"'`#*+])\1{2,}\s*$")


def page(name: str) -> str:
    """The source text of the README (``"README"``) or of ``docs/NAME.rst``."""
    path = ROOT / "README.md" if name == "README" else DOCS / f"{name}.rst"
    return path.read_text(encoding="utf-8")


def section(name: str, title: str) -> str:
    """The part of a page from the heading ``title`` to the next heading of its level or above."""
    text = page(name)
    lines = text.split("\n")
    if name == "README":
        return _markdown_section(lines, title)
    headings: list[tuple[int, str, str]] = []  # (line, title, underline character)
    for i, line in enumerate(lines[:-1]):
        underline = _UNDERLINE.match(lines[i + 1])
        if line.strip() and underline and len(lines[i + 1].rstrip()) >= len(line.rstrip()):
            headings.append((i, line.strip(), underline.group(1)))
    order = list(dict.fromkeys(char for _, _, char in headings))  # levels, outermost first
    found = [h for h in headings if h[1] == title]
    assert len(found) == 1, f"docs/{name}.rst has {len(found)} sections {title!r}"
    start, _, char = found[0]
    ends = [i for i, _, c in headings if i > start and order.index(c) <= order.index(char)]
    return "\n".join(lines[start : ends[0] if ends else len(lines)])


def _markdown_section(lines: list[str], title: str) -> str:
    """A README section: its "#" headings, the lines of code fences (sh comments) left out."""
    headings: list[tuple[int, str, int]] = []  # (line, title, level)
    fenced = False
    for i, line in enumerate(lines):
        fenced ^= line.startswith("```")
        heading = re.match(r"(#+) (.*)$", line)
        if heading and not fenced:
            headings.append((i, heading.group(2).strip(), len(heading.group(1))))
    found = [h for h in headings if h[1] == title]
    assert len(found) == 1, f"README.md has {len(found)} sections {title!r}"
    start, _, level = found[0]
    ends = [i for i, _, depth in headings if i > start and depth <= level]
    return "\n".join(lines[start : ends[0] if ends else len(lines)])


def blocks(text: str, language: str) -> list[str]:
    """The code blocks of ``language`` in a page's text (reST, or the README's fences)."""
    found = re.findall(rf"^```{language}\n(.*?)^```", text, flags=re.S | re.M)
    lines = text.split("\n")
    starts = _DIRECTIVES.get(language, (f"code-block:: {language}",))
    for i, line in enumerate(lines):
        if line.rstrip() not in {f".. {s}" for s in starts}:
            continue
        body: list[str] = []
        for following in lines[i + 1 :]:
            if following.strip() and not following.startswith(" "):
                break
            body.append(following)
        # Options (":lines: 1-30") come first, then a blank line, then the code.
        code = textwrap.dedent("\n".join(body)).strip("\n").split("\n")
        while code and code[0].startswith(":"):
            code.pop(0)
        found.append("\n".join(code).strip("\n") + "\n")
    return found


def prose(text: str) -> str:
    """Text with its whitespace collapsed and reST's double backquotes written as single."""
    return " ".join(text.replace("``", "`").split())
