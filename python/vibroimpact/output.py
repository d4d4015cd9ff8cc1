"""Output files, written whole or not at all, and the error for output that cannot be written.

Shared by the command line (``--out``) and the ``vibroimpact paper`` job, so that
neither imports the other.
"""

from __future__ import annotations

import contextlib
import json
import math
import os
import secrets
import stat
from collections.abc import Iterator, Mapping, Sequence
from pathlib import Path
from typing import IO, Any

import numpy as np


def finite_or_none(x: float) -> float | None:
    """``x``, or None where it is NaN or infinite (JSON's null: a quantity not
    defined, such as the separation of a contact still open at the end)."""
    return x if math.isfinite(x) else None


def json_safe(value: Any) -> Any:
    """A value JSON can write: NumPy numbers as Python ones, non-finite floats as None
    (``NaN`` is no JSON: strict readers refuse the whole document)."""
    if isinstance(value, Mapping):
        return {str(key): json_safe(v) for key, v in value.items()}
    if isinstance(value, list | tuple | np.ndarray):
        return [json_safe(v) for v in value]
    if isinstance(value, bool | np.bool_):
        return bool(value)
    if isinstance(value, int | np.integer):
        return int(value)
    if isinstance(value, float | np.floating):
        return float(value) if math.isfinite(value) else None
    return value


def json_text(value: Any) -> str:
    """``value`` as strict JSON (see :func:`json_safe`): what every ``--json`` prints."""
    return json.dumps(json_safe(value), allow_nan=False)


class UsageError(Exception):
    """Bad input found by the command line or the jobs it runs, such as an output
    path that cannot be written (exit status 2)."""


def _regular_or_absent(path: Path) -> os.stat_result | None:
    """The status of what ``path`` names (links followed), None when nothing does;
    :class:`UsageError` when it is not a regular file (a device, a FIFO, a folder),
    which writing a file there would replace or block on."""
    try:
        status = os.stat(path)
    except FileNotFoundError:
        return None
    except OSError:
        return None  # let the write say what is wrong
    if not stat.S_ISREG(status.st_mode):
        raise UsageError(
            f"cannot write {str(path)!r}: it exists and is not a regular file (a folder, a "
            "device or a FIFO); choose a file name"
        )
    return status


def check_output(path: Path, flag: str, inputs: Sequence[Path] = ()) -> None:
    """Refuse, before anything runs, an output ``path`` given as ``flag`` (such as
    ``--out``) that exists and is not a regular file, or that is one of the ``inputs``
    (the scenario file, a recorded signal's file: writing the output there would
    replace it)."""
    try:
        status = _regular_or_absent(path)
    except UsageError:
        raise UsageError(
            f"{flag} {path}: exists and is not a regular file (a folder, a device or a "
            "FIFO); give the path of a file to write"
        ) from None
    if status is None:
        return
    for source in inputs:
        try:
            same = os.path.samefile(path, source)
        except OSError:
            continue
        if same:
            raise UsageError(
                f"{flag} {path}: is the input file {str(source)!r} itself (the scenario, "
                "or a record it reads), which the output would replace; choose another name"
            )


def check_plot(path: Path, inputs: Sequence[Path] = ()) -> None:
    """Refuse, before anything runs, a ``--plot`` path that :func:`check_output`
    refuses or that does not name a PNG image (the only format the plots are written
    in: a PNG written under another suffix would mislead the file's readers)."""
    if path.suffix.lower() != ".png":
        raise UsageError(f"--plot {path}: plots are PNG images; give a file name ending in .png")
    check_output(path, "--plot", inputs)


@contextlib.contextmanager
def written_whole(path: Path, binary: bool = False) -> Iterator[IO[Any]]:
    """Open a file to write ``path`` whole or not at all.

    The file is a temporary one in the same folder (so that the rename cannot
    cross file systems), renamed over ``path`` only when the ``with`` block ends
    normally and the data is on disk. If the block raises, is interrupted, or
    the disk fills up, the temporary file is removed and an existing ``path`` is
    left as it was. A file that cannot be written, or a ``path`` that names
    something other than a regular file (a device, a FIFO, a folder), raises
    :class:`UsageError` naming it; other errors propagate unchanged.
    """
    temporary = None
    if path.is_symlink():
        # Write the file the link points to, as open() would, and keep the link.
        path = path.resolve()
    # Never rename a file over a device, a FIFO or a folder.
    _regular_or_absent(path)
    try:
        while True:
            # Named before it is created, so that an interrupt (SIGTERM, Ctrl-C)
            # arriving just after the creation still finds it to remove below.
            temporary = path.with_name(f".{path.name}.{secrets.token_hex(4)}.tmp")
            try:
                # 0o666 minus the umask: the permissions a plain open() would give.
                descriptor = os.open(temporary, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666)
                break
            except FileExistsError:
                temporary = None  # someone else's: not ours to remove
        file: IO[Any] = (
            os.fdopen(descriptor, "wb")
            if binary
            else os.fdopen(descriptor, "w", encoding="utf-8", newline="")
        )
        with file:
            if path.exists():
                # Keep the permissions the user gave the file being replaced.
                os.chmod(temporary, stat.S_IMODE(path.stat().st_mode))
            yield file
            file.flush()
            os.fsync(file.fileno())
        os.replace(temporary, path)
        temporary = None
    except OSError as err:
        raise UsageError(f"cannot write {str(path)!r}: {err.strerror or err}") from None
    finally:
        if temporary is not None:
            with contextlib.suppress(OSError):
                os.unlink(temporary)
