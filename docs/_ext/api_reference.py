"""``.. public-api:: MODULE``: the reference of every name in ``MODULE.__all__``.

Each class, function and constant of ``__all__`` is documented with autodoc, in the order of
``__all__``, so a public name cannot be left out of the reference. A name already documented
under an earlier module (``vibroimpact.Scenario`` is ``vibroimpact.scenario.Scenario``) is
listed as a link to that entry. A class or function without a docstring, or a constant
without a ``#:`` comment where it is defined (its module's package, or the core's stub
``_core.pyi``), is a warning, so the build (``-W``) fails.
"""

from __future__ import annotations

import importlib
import inspect
from pathlib import Path
from typing import Any

from docutils import nodes
from generated import parsed
from sphinx.application import Sphinx
from sphinx.pycode import ModuleAnalyzer
from sphinx.util import logging
from sphinx.util.docutils import SphinxDirective

LOG = logging.getLogger(__name__)


def public_names(module: Any) -> list[str]:
    """The names of ``__all__`` a user is meant to use: dunders such as ``__version__``
    and plain names, not the ``_private`` ones a package re-exports for its own modules."""
    return [n for n in module.__all__ if not n.startswith("_") or n.startswith("__")]


def _attribute_docs(package_dir: Path) -> dict[str, str]:
    """The ``#:`` comments (or docstrings after) of module-level names in the package's
    own files (``*.py``, ``*.pyi``; not its subpackages'), by name."""
    found: dict[str, str] = {}
    for path in sorted(package_dir.glob("*.py*")):
        if path.suffix not in (".py", ".pyi"):
            continue
        docs = ModuleAnalyzer.for_string(path.read_text(encoding="utf-8"), path.stem)
        for (namespace, name), lines in docs.find_attr_docs().items():
            if namespace == "" and any(line.strip() for line in lines):
                found.setdefault(name, " ".join(line.strip() for line in lines).strip())
    return found


class PublicApi(SphinxDirective):
    required_arguments = 1

    def run(self) -> list[nodes.Node]:
        name = self.arguments[0]
        module = importlib.import_module(name)
        documented: dict[int, str] = self.env.temp_data.setdefault("public_api_seen", {})
        comments = _attribute_docs(Path(module.__file__).parent)
        lines: list[str] = []
        for attr in public_names(module):
            obj = getattr(module, attr)
            qualified = f"{name}.{attr}"
            kind = "class" if inspect.isclass(obj) else "function" if callable(obj) else "data"
            if kind != "data" and id(obj) in documented:
                role = "class" if kind == "class" else "func"
                lines += [f"- ``{attr}``: :py:{role}:`{documented[id(obj)]}`", ""]
                continue
            if kind == "data":
                text = comments.get(attr)
                if not text:
                    LOG.warning(
                        "public name %s has no #: comment", qualified, location=self.get_location()
                    )
                    text = ""
                value = repr(obj)
                if len(value) > 60:
                    value = f"{type(obj).__name__} (see the text)"
                lines += [
                    f".. py:data:: {attr}",
                    f"   :module: {name}",
                    f"   :value: {value}",
                    "",
                    f"   {text}",
                    "",
                ]
                continue
            if not inspect.getdoc(obj):
                LOG.warning(
                    "public name %s has no docstring", qualified, location=self.get_location()
                )
            documented[id(obj)] = qualified
            if kind == "class":
                lines += [f".. autoclass:: {qualified}", "   :members:", ""]
            else:
                lines += [f".. autofunction:: {qualified}", ""]
        return parsed(self, lines, f"<{name}.__all__>")


def resolve_short_name(
    app: Sphinx, env: Any, node: Any, contnode: nodes.Element
) -> nodes.Element | None:
    """A docstring's short reference (``:class:`Runner```, ``:func:`sweep```, written
    relative to the module that defines it) to the one public entry of that name, the
    package's own (``vibroimpact.X``) first. None (a warning under nitpicky) where the
    reference names nothing in the reference."""
    if node.get("refdomain") != "py":
        return None
    target = str(node["reftarget"]).lstrip("~.")
    short = target.rsplit(".", 1)[-1]
    domain = env.domains["py"]
    names = [n for n in domain.objects if n.rsplit(".", 1)[-1] == short]
    if "." in target:  # a dotted path: only an entry ending in the same path
        names = [n for n in names if n.endswith(target.split(".", 1)[1]) or n == target]
    if not names:
        return None
    names.sort(key=lambda n: (n.count("."), n))
    entry = domain.objects[names[0]]
    from sphinx.util.nodes import make_refnode

    return make_refnode(
        app.builder, node["refdoc"], entry.docname, entry.node_id, contnode, names[0]
    )


def setup(app: Sphinx) -> dict[str, Any]:
    app.add_directive("public-api", PublicApi)
    app.connect("missing-reference", resolve_short_name)
    return {"parallel_read_safe": False, "version": "1"}
