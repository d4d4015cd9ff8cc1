"""``.. run-python::`` and ``.. run-command::``: code shown with the output it prints when the
site is built, so a page's example and its output cannot disagree.

``run-python`` executes its content (Python) in a fresh namespace; ``run-command`` runs each
line of its content as a ``vibroimpact`` command (``python -m vibroimpact ...``) from the
repository root. Either one failing (an exception, a non-zero exit) is a warning, an error
under ``-W``. Output files of commands go to a temporary folder, never into the checkout.
"""

from __future__ import annotations

import contextlib
import io
import shlex
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path
from typing import Any

from docutils import nodes
from sphinx.application import Sphinx
from sphinx.util import logging
from sphinx.util.docutils import SphinxDirective

LOG = logging.getLogger(__name__)
ROOT = Path(__file__).resolve().parents[2]


def _blocks(code: str, language: str, output: str) -> list[nodes.Node]:
    shown = nodes.literal_block(code, code, language=language)
    printed = nodes.literal_block(output, output, language="text")
    return [shown, nodes.paragraph(text="Output:"), printed]


class RunPython(SphinxDirective):
    has_content = True

    def run(self) -> list[nodes.Node]:
        code = "\n".join(self.content)
        out = io.StringIO()
        try:
            with contextlib.redirect_stdout(out):
                exec(compile(code, self.get_location(), "exec"), {"__name__": "__docs__"})
        except Exception as err:  # noqa: BLE001 - any failure of the example fails the build
            LOG.warning("run-python failed: %r", err, location=self.get_location())
        return _blocks(code, "python", out.getvalue().rstrip())


class RunCommand(SphinxDirective):
    has_content = True

    def run(self) -> list[nodes.Node]:
        printed: list[str] = []
        with tempfile.TemporaryDirectory() as work:
            shutil.copytree(ROOT / "examples", Path(work) / "examples")
            for line in self.content:
                command = line.split("  #")[0].strip()
                if not command:
                    continue
                argv = shlex.split(command)
                argv = [sys.executable, "-m", "vibroimpact", *argv[1:]]
                done = subprocess.run(
                    argv, cwd=work, capture_output=True, text=True, timeout=300, check=False
                )
                if done.returncode != 0:
                    LOG.warning(
                        "%s: exit %d: %s",
                        command,
                        done.returncode,
                        done.stderr,
                        location=self.get_location(),
                    )
                printed += [f"$ {command}", done.stdout.rstrip()]
        code = "\n".join(self.content)
        return _blocks(code, "sh", "\n".join(printed))


def setup(app: Sphinx) -> dict[str, Any]:
    app.add_directive("run-python", RunPython)
    app.add_directive("run-command", RunCommand)
    return {"parallel_read_safe": True, "version": "1"}
