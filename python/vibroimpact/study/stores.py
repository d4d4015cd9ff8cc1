"""Where a study is written: its output's kind (a NetCDF 4 file or a Zarr store) checked
before it runs, and a Zarr store written whole or not at all."""

from __future__ import annotations

import importlib
import os
import shutil
import time
from pathlib import Path
from typing import Any

from vibroimpact import arguments
from vibroimpact.netcdf import netcdf4_missing
from vibroimpact.output import UsageError, claim_beside, remove_stale, swap_in

#: What a study's output may end in, and what each suffix writes.
OUTPUTS = {".nc": "a NetCDF 4 file", ".zarr": "a Zarr store"}


def output_kind(out: Path, flag: str = "--out") -> str:
    """The suffix of ``out`` that decides its format (``.nc`` or ``.zarr``), checked
    before a study runs: another suffix, a NetCDF file without h5netcdf and h5py (see
    ``vibroimpact.netcdf.netcdf4_missing``), a Zarr store without the zarr package,
    or a ``.zarr`` path that holds something other than a Zarr store (which the store
    would replace) raise :class:`UsageError`, naming ``out`` as ``flag``."""
    out = arguments.path("out", out)
    kind = out.suffix.lower()
    if kind not in OUTPUTS:
        allowed = " or ".join(f"{suffix} ({what})" for suffix, what in OUTPUTS.items())
        if out.name.lower() in OUTPUTS:
            # ".nc" alone is a hidden file's name, with no suffix.
            raise UsageError(f"{flag} {out}: needs a name before its suffix (such as study.nc)")
        raise UsageError(f"{flag} {out}: must end in {allowed}")
    if kind == ".nc" and (missing := netcdf4_missing()) is not None:
        raise UsageError(f"{flag} {out}: {missing}")
    if kind == ".zarr":
        try:
            importlib.import_module("zarr")
        except ImportError:
            raise UsageError(
                f'{flag} {out}: a Zarr store needs zarr: pip install "vibroimpact[zarr]"'
            ) from None
        _replaceable_store(out, flag)
    return kind


def _replaceable_store(out: Path, flag: str) -> None:
    """Refuse a ``.zarr`` path that holds a file, or a folder that is neither empty nor
    a Zarr store: writing the study there would replace what is not a result."""
    if out.is_symlink():
        out = out.resolve()
    if not out.exists():
        return
    if out.is_dir() and (
        not any(out.iterdir()) or any((out / name).is_file() for name in _STORE_MARKS)
    ):
        return
    raise UsageError(
        f"{flag} {out}: exists and is not a Zarr store; remove it or choose another name"
    )


# What marks a folder as a Zarr store: format 2's group or consolidated metadata, or 3's.
_STORE_MARKS = (".zgroup", ".zmetadata", "zarr.json")


def _write_zarr(dataset: Any, out: Path) -> None:
    """Write ``dataset`` as the Zarr store ``out`` whole or not at all: built in a hidden
    folder beside ``out`` (so that the rename cannot cross file systems), its files on
    disk, then swapped in (:func:`vibroimpact.output.swap_in`: on Linux one atomic
    exchange, ``out`` never missing), the earlier store removed once the new one stands
    in its place. A write that fails or is interrupted removes the folder and leaves
    ``out`` as it was; what a killed one leaves (the folder, or elsewhere an earlier
    store moved aside) the next write removes (or puts back, where ``out`` is missing).

    Zarr format 2 with consolidated metadata: its specification covers every dtype of
    the Dataset (format 3 has none yet for fixed-width strings, and zarr warns), and
    ``xr.open_zarr`` reads it in one request, with no warning."""
    if out.is_symlink():
        # Replace the store the link points to, and keep the link.
        out = out.resolve()
    remove_stale(out)
    _replaceable_store(out, "out:")
    # The new store's folder until it is swapped in, then the earlier store's.
    held: list[Path] = []
    lock: int | None = None
    swapped = False
    try:
        lock = claim_beside(out, held, folder=True)
        # Into the empty folder made (and locked) above: "w" would make it again.
        dataset.to_zarr(held[0], mode="w-", zarr_format=2, consolidated=True)
        _sync(held[0])
        earlier = swap_in(held[0], out)
        held[:] = [] if earlier is None else [earlier]
        swapped = True
        _sync_folder(out.parent)
    except OSError as err:
        raise UsageError(f"cannot write {str(out)!r}: {err.strerror or err}") from None
    finally:
        if lock is not None:
            os.close(lock)
        for folder in held:
            remove_folder(folder, late_writes=not swapped)


def remove_folder(folder: Path, late_writes: bool = False, patience: float = 2.0) -> None:
    """Remove ``folder`` and what is in it. With ``late_writes`` (an interrupted
    ``to_zarr``, whose threads write chunks after the interrupt: one pass left 50 of them
    in a hidden folder), again while they fill or make it again, until it stays gone for
    50 ms, for up to ``patience`` s."""
    deadline = time.monotonic() + patience
    while True:
        shutil.rmtree(folder, ignore_errors=True)
        if not late_writes or time.monotonic() > deadline:
            return
        time.sleep(0.05)
        if not os.path.lexists(folder):
            return


def _sync(folder: Path) -> None:
    """The files below ``folder`` and the folders themselves on disk."""
    for root, _, files in os.walk(folder):
        for name in files:
            with open(os.path.join(root, name), "rb") as f:
                os.fsync(f.fileno())
        _sync_folder(Path(root))


def _sync_folder(folder: Path) -> None:
    # A folder's entries on disk, where the system can (not on Windows).
    try:
        descriptor = os.open(folder, os.O_RDONLY)
    except OSError:
        return
    try:
        os.fsync(descriptor)
    except OSError:
        pass
    finally:
        os.close(descriptor)
