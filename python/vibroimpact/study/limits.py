"""The bounds of a study, checked before it runs: the runs it may hold and the threads
(or Dask processes) it may ask for; :class:`StudyError`, what a study that cannot be set
up raises."""

from __future__ import annotations

import os
from pathlib import Path
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


def machine_memory() -> int | None:
    """The memory this process may use, bytes: the machine's physical memory, or less
    where a limit on the process (``ulimit -v``, RLIMIT_AS) or its control group (a
    container's ``memory.max``) allows less (None where nothing says). Planning on the
    machine's alone, a study under ``ulimit -v`` failed with a traceback instead."""
    known = []
    try:
        known.append(int(os.sysconf("SC_PHYS_PAGES")) * int(os.sysconf("SC_PAGE_SIZE")))
    except (AttributeError, OSError, ValueError):
        pass
    try:
        import resource

        soft = resource.getrlimit(resource.RLIMIT_AS)[0]
        if soft != resource.RLIM_INFINITY and soft > 0:
            known.append(int(soft))
    except (ImportError, OSError, ValueError):
        pass
    for path in ("/sys/fs/cgroup/memory.max", "/sys/fs/cgroup/memory/memory.limit_in_bytes"):
        try:
            text = Path(path).read_text(encoding="ascii").strip()
        except (OSError, UnicodeDecodeError):
            continue
        if text.isdigit() and 0 < int(text) < 2**60:  # v1 writes "no limit" as ~2**63
            known.append(int(text))
    return min(known) if known else None


#: The memory a study may plan for where the machine's is not known, bytes.
UNKNOWN_MEMORY_LIMIT = 8 * 2**30


def check_study_memory(runs: int, observed: int, pairs: int, where: str) -> None:
    """Refuse a study whose results could not be held in memory: each run's metrics are
    ``2 observed + pairs + 8`` numbers (peaks and mean squares of every observed
    quantity, the pairs' energies, the scalars) and its status, held twice (the chunks'
    parts and the Dataset made of them), against half of the machine's memory. The
    count of runs alone (:data:`MAX_STUDY_RUNS`) let a study of 10 million runs, each
    following 2,000 points and moments, start towards 650 GB."""
    per_run = 8 * (2 * observed + pairs + 8) + 64
    need = 2 * runs * per_run
    memory = machine_memory()
    limit = memory // 2 if memory else UNKNOWN_MEMORY_LIMIT
    if need > limit:
        of = (
            f"half of the {memory / 1e9:.3g} GB this process may use"
            if memory
            else f"{limit / 1e9:.3g} GB"
        )
        raise StudyError(
            f"{where}: the study's results would take about {need / 1e9:.3g} GB of memory "
            f"({runs:,} runs, each of {observed} observed quantities and {pairs} pair(s)), more "
            f"than {of}; lower the axes' counts or the [output] points and moments, or split "
            "the study"
        )
