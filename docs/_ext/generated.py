"""What the site's generated references share: reST lines, made from the code at build
time, parsed into the page where their directive stands."""

from __future__ import annotations

from docutils import nodes
from docutils.statemachine import StringList
from sphinx.util.docutils import SphinxDirective
from sphinx.util.nodes import nested_parse_with_titles


def parsed(directive: SphinxDirective, lines: list[str], source: str) -> list[nodes.Node]:
    """``lines`` of reST (their sections included) as the nodes ``directive`` puts in the
    page; ``source`` names them in the build's messages."""
    node = nodes.section()
    node.document = directive.state.document
    nested_parse_with_titles(directive.state, StringList(lines, source=source), node)
    return node.children
