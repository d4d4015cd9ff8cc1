"""A study's chunks as the tasks of a Dask cluster (a LocalCluster or a scheduler's
address)."""

from __future__ import annotations

import importlib
import logging
import os
from collections.abc import Callable
from typing import Any

from vibroimpact.output import UsageError
from vibroimpact.study.grid import Study, chunk_part


def _run_on_dask(
    study: Study,
    chunks: list[range],
    pending: list[int],
    address: str,
    workers: int,
    finished: Callable[[int, dict[str, Any]], None],
) -> None:
    """The pending chunks as tasks of a Dask cluster, each kept as it completes."""
    try:
        # Untyped: taken as Any.
        distributed: Any = importlib.import_module("dask.distributed")
    except ImportError:
        raise UsageError(
            '--dask needs dask and distributed: pip install "vibroimpact[dask]"'
        ) from None
    cluster = None
    try:
        if address == "local":
            cluster = distributed.LocalCluster(
                n_workers=workers or os.cpu_count() or 1,
                threads_per_worker=1,
                processes=True,
                dashboard_address=None,
                # No dashboard, but the scheduler still serves HTTP (health, metrics),
                # by default on 8787: a free port, so a cluster already running (a
                # notebook's) neither clashes nor is warned about.
                scheduler_kwargs={"dashboard_address": ":0"},
                # Its workers' own messages (an interrupt stops them too) are noise.
                silence_logs=logging.CRITICAL,
            )
            client = distributed.Client(cluster)
        else:
            client = distributed.Client(address, timeout="10s")
    except (OSError, ValueError, TypeError) as err:
        raise UsageError(
            f"--dask {address}: cannot reach the scheduler ({err}); give 'local' or an "
            "address such as tcp://HOST:8786"
        ) from None
    try:
        shared = client.scatter(study, broadcast=True)
        futures = {
            client.submit(chunk_part, shared, chunks[n].start, chunks[n].stop, 1, pure=False): n
            for n in pending
        }
        for future in distributed.as_completed(futures):
            finished(futures[future], future.result())
    finally:
        client.close()
        if cluster is not None:
            cluster.close()
