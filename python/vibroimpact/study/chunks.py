"""A study run chunk by chunk into its output: each finished chunk kept (written whole),
so that an interrupted study resumes where it stopped and gives the same file or store;
its progress on a terminal."""

from __future__ import annotations

import json
import math
import shutil
import sys
import time
import zipfile
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any

import numpy as np

from vibroimpact import arguments
from vibroimpact.netcdf import write_netcdf
from vibroimpact.output import UsageError, check_output, remove_stale, written_whole
from vibroimpact.study.assembly import assemble
from vibroimpact.study.grid import Study, chunk_part
from vibroimpact.study.limits import check_threads
from vibroimpact.study.on_dask import _run_on_dask
from vibroimpact.study.stores import _write_zarr, output_kind


def _save(path: Path, part: dict[str, Any]) -> None:
    import io

    buffer = io.BytesIO()
    np.savez(buffer, **part)
    with written_whole(path, binary=True) as f:
        f.write(buffer.getvalue())


def _load(path: Path) -> dict[str, Any]:
    # The file opened here, closed here: np.load leaves a damaged one open.
    with path.open("rb") as f, np.load(f, allow_pickle=False) as data:
        part = {key: data[key] for key in data.files}
    part["n"] = int(part["n"])
    part["pairs"] = [str(p) for p in part["pairs"]]
    part["reason"] = [str(r) for r in part["reason"]]
    return part


@arguments.typed()
def run(
    study: Study,
    out: Path,
    *,
    threads: int = 0,
    progress: Callable[[int, int, float], None] | None = None,
    dask: str | None = None,
    notice: Callable[[str], None] | None = None,
    resume: str = "run the same study into the same output again",
) -> Any:
    """Run ``study`` into ``out``, by its suffix the NetCDF 4 file ``RESULT.nc``
    (:func:`vibroimpact.write_netcdf`) or the Zarr store ``RESULT.zarr`` (needs
    zarr; see :func:`output_kind`), chunk by chunk:
    each finished chunk is kept in ``OUT.parts/`` (written whole), so a study
    interrupted or killed loses at most the chunks in flight and, run again, goes on
    where it stopped; the output is written whole at the end (the same file or store as
    an uninterrupted run) and the parts removed. ``dask``: the address of a Dask
    scheduler, or ``"local"`` for a LocalCluster of ``threads`` processes (all cores for
    0), the chunks its tasks; the results are the same. A run that resumes says so to
    ``notice`` (one line: the chunks kept before); a run that stops (interrupted, or
    failed) with chunks kept gets a note (:meth:`BaseException.add_note`) saying how
    many and how to resume (``resume``). Where every run failed, an earlier output of
    the same name is kept, not replaced by a file of failures (``notice`` is told).
    Returns the Dataset."""
    arguments.instance("study", study, Study, "vibroimpact.study.study_of(sections)")
    out = arguments.path("out", out)
    for name, function in (("progress", progress), ("notice", notice)):
        arguments.callback(name, function)
    if dask is not None:
        arguments.text("dask", dask)
    arguments.text("resume", resume)
    check_threads(threads, "threads:")
    kind = output_kind(out, "out:")
    if kind != ".zarr":
        # Refused before any run, as the command refuses it (a folder was found only
        # once every run was done, and resuming failed the same way).
        check_output(out, "out:")
    # What a killed write left: an earlier store moved aside is back before any run.
    remove_stale(out.resolve() if out.is_symlink() else out)
    earlier = out.exists() or out.is_symlink()
    parts_dir = out.with_name(out.name + ".parts")
    fingerprint = study.fingerprint()
    manifest = parts_dir / "manifest.json"
    if parts_dir.exists():
        try:
            known = json.loads(manifest.read_text())
        except (OSError, ValueError):
            known = {}
        if known.get("input_hash") != fingerprint:
            raise UsageError(
                f"{parts_dir} holds the chunks of another study (or is damaged): remove it "
                "to start this one"
            )
    else:
        try:
            parts_dir.mkdir()
        except OSError as err:
            raise UsageError(f"cannot write {str(parts_dir)!r}: {err.strerror or err}") from None
        with written_whole(manifest) as f:
            f.write(json.dumps({"input_hash": fingerprint, "runs": study.runs}))
    chunks = study.chunks()
    path_of = [parts_dir / f"chunk-{number:06d}.npz" for number in range(len(chunks))]
    parts: dict[int, dict[str, Any]] = {}
    for number, path in enumerate(path_of):
        if path.exists():
            try:
                parts[number] = _load(path)
            except (OSError, ValueError, KeyError, EOFError, zipfile.BadZipFile):
                # Written whole, so damaged since (a disk, a hand): run it again.
                pass
    pending = [number for number in range(len(path_of)) if number not in parts]
    start = time.perf_counter()
    state = {"computed": 0, "done": study.runs - sum(len(chunks[i]) for i in pending)}

    def finished(number: int, part: dict[str, Any]) -> None:
        _save(path_of[number], part)
        # As a resumed study reads it (the same types).
        parts[number] = _load(path_of[number])
        state["computed"] += len(chunks[number])
        state["done"] += len(chunks[number])
        if progress is not None:
            rate = state["computed"] / max(time.perf_counter() - start, 1e-9)
            progress(state["done"], study.runs, rate)

    try:
        # Inside the try: an interrupt just after the notice still says what is kept.
        if parts and notice is not None:
            notice(
                f"resuming from {parts_dir}: {_kept(study, chunks, parts)} by an earlier "
                f"run, {len(pending)} chunks to run"
            )
        if dask is None:
            for number in pending:
                runs = chunks[number]
                finished(number, chunk_part(study, runs.start, runs.stop, threads))
        else:
            _run_on_dask(study, chunks, pending, dask, threads, finished)
        dataset = assemble(study, [parts[number] for number in range(len(path_of))])
        if earlier and every_run_failed(dataset):
            # Nothing was computed: an earlier result of the same name is worth more
            # than a file of failures (the dataset returned has every reason).
            if notice is not None:
                notice(
                    f"every one of the {study.runs} runs failed: {out} is left as it was "
                    "(an earlier result)"
                )
        elif kind == ".zarr":
            _write_zarr(dataset, out)
        else:
            write_netcdf(dataset, out)
    except BaseException as stop:
        if any(path.exists() for path in path_of):
            stop.add_note(
                f"{_kept(study, chunks, parts)}, kept in {parts_dir}; to resume, {resume}"
            )
        else:
            # Nothing finished: leave nothing behind (a resume has nothing to go on).
            shutil.rmtree(parts_dir, ignore_errors=True)
            if not isinstance(stop, Exception):  # interrupted, not an error's one line
                stop.add_note(
                    f"{_kept(study, chunks, parts)}: nothing kept, run again it starts afresh"
                )
        raise
    shutil.rmtree(parts_dir, ignore_errors=True)
    return dataset


def every_run_failed(dataset: Any) -> bool:
    """Whether a study's every run failed (``status`` non-zero everywhere)."""
    status = np.asarray(dataset["status"].values)
    return status.size > 0 and bool(np.all(status != 0))


def _kept(study: Study, chunks: list[range], parts: Mapping[int, Any]) -> str:
    """How much of the study its kept chunks hold (``2 of 4 chunks (8 of 16 runs)
    done``): those read back (``parts``), not a damaged file, which is run again (it had
    been counted, so that kept and to run added up to more than the study)."""
    done = sum(len(chunks[number]) for number in parts)
    return f"{len(parts)} of {len(chunks)} chunks ({done} of {study.runs} runs) done"


def terminal_progress(stream: Any = sys.stderr) -> Callable[[int, int, float], None]:
    """A progress line with the rate and the time left, on a terminal only."""
    show = hasattr(stream, "isatty") and stream.isatty()

    def progress(done: int, total: int, rate: float) -> None:
        if not show:
            return
        left = (total - done) / rate if rate > 0 else math.inf
        eta = f"{left:.0f} s left" if math.isfinite(left) else ""
        stream.write(f"\r{done}/{total} runs, {rate:,.0f} runs/s, {eta}   ")
        stream.flush()
        if done == total:
            stream.write("\n")

    return progress
