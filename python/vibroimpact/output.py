"""Output files, written whole or not at all, and the error for output that cannot be written.

Shared by the command line (``--out``) and the ``vibroimpact paper`` job, so that
neither imports the other.
"""

from __future__ import annotations

import contextlib
import math
import os
import secrets
import stat
from collections.abc import Iterator
from pathlib import Path
from typing import IO, Any


def finite_or_none(x: float) -> float | None:
    """``x``, or None where it is NaN or infinite (JSON's null: a quantity not
    defined, such as the separation of a contact still open at the end)."""
    return x if math.isfinite(x) else None


class UsageError(Exception):
    """Bad input found by the command line or the jobs it runs, such as an output
    path that cannot be written (exit status 2)."""


@contextlib.contextmanager
def written_whole(path: Path, binary: bool = False) -> Iterator[IO[Any]]:
    """Open a file to write ``path`` whole or not at all.

    The file is a temporary one in the same folder (so that the rename cannot
    cross file systems), renamed over ``path`` only when the ``with`` block ends
    normally and the data is on disk. If the block raises, is interrupted, or
    the disk fills up, the temporary file is removed and an existing ``path`` is
    left as it was. A file that cannot be written raises :class:`UsageError`
    naming it; other errors propagate unchanged.
    """
    temporary = None
    if path.is_symlink():
        # Write the file the link points to, as open() would, and keep the link.
        path = path.resolve()
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
