"""``.. cli-reference::``: the command line's reference, from its parser.

Reads ``vibroimpact.cli.command._parser()`` (the one parser ``vibroimpact`` runs) and writes
every subcommand with its description, usage and each argument's flags, metavar, default,
choices and help, so the page cannot drift from what the command accepts.
"""

from __future__ import annotations

import argparse
from typing import Any

from docutils import nodes
from generated import parsed
from sphinx.application import Sphinx
from sphinx.util.docutils import SphinxDirective

from vibroimpact.cli.command import _parser


def _subcommands(parser: argparse.ArgumentParser) -> dict[str, argparse.ArgumentParser]:
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            return dict(action.choices)
    return {}


def _escaped(text: str) -> str:
    """Help text as plain reST text: its ``|``, ``*`` and backquotes are characters."""
    for char in "\\|*`_":
        text = text.replace(char, "\\" + char)
    return text


def _literal(text: str) -> str:
    return "``" + text.replace("``", "` `") + "``"


def _argument(action: argparse.Action, parser: argparse.ArgumentParser) -> list[str]:
    formatter = parser._get_formatter()
    if action.option_strings:
        name = ", ".join(action.option_strings)
        if action.nargs != 0:
            name += " " + formatter._format_args(action, action.dest.upper())
    else:
        name = formatter._format_args(action, action.dest)
    help_text = formatter._expand_help(action) if action.help else ""
    lines = [f"{_literal(name)}", f"   {_escaped(help_text) or '(no help)'}"]
    if action.choices and not isinstance(action, argparse._SubParsersAction):
        lines.append("   Choices: " + ", ".join(_literal(str(c)) for c in action.choices) + ".")
    lines.append("")
    return lines


def _command(title: str, parser: argparse.ArgumentParser) -> list[str]:
    usage = parser.format_usage().removeprefix("usage: ").strip()
    lines = [
        title,
        "-" * len(title),
        "",
        _escaped(parser.description or ""),
        "",
        ".. code-block:: text",
        "",
    ]
    lines += ["   " + line for line in usage.splitlines()] + [""]
    for action in parser._actions:
        if isinstance(action, argparse._HelpAction | argparse._SubParsersAction):
            continue
        lines += _argument(action, parser)
    if parser.epilog:
        lines += (
            [".. code-block:: text", ""]
            + ["   " + line for line in parser.epilog.splitlines()]
            + [""]
        )
    return lines


class CliReference(SphinxDirective):
    def run(self) -> list[nodes.Node]:
        parser = _parser()
        lines = _command(f"{parser.prog}", parser)
        for name, sub in _subcommands(parser).items():
            lines += _command(f"{parser.prog} {name}", sub)
        return parsed(self, lines, "<vibroimpact parser>")


def setup(app: Sphinx) -> dict[str, Any]:
    app.add_directive("cli-reference", CliReference)
    return {"parallel_read_safe": True, "version": "1"}
