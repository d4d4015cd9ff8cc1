"""The bounds of a study, checked before it runs: the runs it may hold and the threads
(or Dask processes) it may ask for; :class:`StudyError`, what a study that cannot be set
up raises."""

from __future__ import annotations

import os
from typing import Any

from vibroimpact.analysis.limits import AnalysisError


class StudyError(AnalysisError):
    """A study that cannot be set up as asked (a ValueError)."""


#: The most threads (or Dask processes) a study may ask for: more than any machine's
#: cores, far fewer than would exhaust its threads.
MAX_WORKERS = 1024


def check_threads(threads: Any, name: str) -> None:
    """Refuse ``threads`` (given as ``name``: ``"threads:"``, ``"--workers"``) that is
    not a whole number in [0, MAX_WORKERS] (0: all cores)."""
    if isinstance(threads, bool) or not isinstance(threads, int):
        raise StudyError(f"{name} must be a whole number, got {threads!r}")
    if not 0 <= threads <= MAX_WORKERS:
        raise StudyError(
            f"{name} must be in [0, {MAX_WORKERS}] (0: all cores, {os.cpu_count() or 1} "
            f"here), got {threads}"
        )


#: The most runs a study may hold (the product of its axes' counts, times ``samples``):
#: its metrics and their reasons are gathered in memory at the end (about 100 bytes a
#: run and metric), and ten million runs are hours of computing already.
MAX_STUDY_RUNS = 10_000_000
