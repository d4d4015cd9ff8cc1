"""The ``vibroimpact`` command (also ``python -m vibroimpact``): :func:`main`, the parser
and ``simulate`` in :mod:`~vibroimpact.cli.command`, the analyses' commands in
:mod:`~vibroimpact.cli.analysis_parsers` (their arguments) and
:mod:`~vibroimpact.cli.analysis_commands`, ``study`` in :mod:`~vibroimpact.cli.study_commands`.
"""

from vibroimpact.cli.command import main

__all__ = ["main"]
