"""Output files, written whole or not at all, and the error for output that cannot be written.

Shared by the command line (``--out``) and the ``vibroimpact paper`` job, so that
neither imports the other.
"""

from __future__ import annotations

import argparse
import contextlib
import errno
import json
import math
import os
import re
import secrets
import shutil
import stat
import sys
from collections.abc import Iterator, Mapping, Sequence
from pathlib import Path
from typing import IO, Any

import numpy as np

try:
    import fcntl
except ImportError:  # Windows: no advisory locks
    fcntl = None  # type: ignore[assignment]


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


class UsageError(ValueError):
    """Bad input found by the command line or the jobs it runs, such as an output
    path that cannot be written (exit status 2; a ``ValueError``, as every bad input is
    in Python)."""


def structure_needed(path: Path, command: str) -> str:
    """The error of ``command`` given a two-mass scenario at ``path``: it takes a system
    on a structure."""
    return (
        f"{path}: {command} takes a scenario with a [structure] section (a system on a "
        "structure); this one is a two-mass damper's ([system] and [contact])"
    )


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


def path_argument(text: str) -> Path:
    """A command line's path (argparse's ``type``): an empty one is refused (an unset
    shell variable: ``--out ""`` was the current folder, and ``paper`` wrote there)."""
    if not text:
        raise argparse.ArgumentTypeError("an empty path (give a file or folder name)")
    return Path(text)


def check_output(path: Path, flag: str, inputs: Sequence[Path] = ()) -> None:
    """Refuse, before anything runs, an output ``path`` given as ``flag`` (such as
    ``--out``) whose folder does not exist, that exists and is not a regular file, or
    that is one of the ``inputs`` (the scenario file, a recorded signal's file: writing
    the output there would replace it)."""
    folder = path.parent
    if not folder.is_dir():
        # Said before the run, not after it (a long run was lost to a missing folder).
        raise UsageError(
            f"{flag} {path}: the folder {str(folder)!r} does not exist; create it or give "
            "another path"
        )
    try:
        status = _regular_or_absent(path)
    except UsageError:
        raise UsageError(
            f"{flag} {path}: exists and is not a regular file (a folder, a device or a "
            "FIFO); give the path of a file to write"
        ) from None
    _check_writable(path, flag)
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


def _check_writable(path: Path, flag: str) -> None:
    """Refuse ``path`` where the temporary file it is written through (see
    :func:`claim_beside`) cannot be made: a folder without write permission, a
    read-only file system, a name that its temporary file's makes too long. Said before
    the run: every analysis had run to its end first."""
    held: list[Path] = []
    try:
        os.close(claim_beside(path, held))
    except OSError as err:
        raise UsageError(
            f"{flag} {path}: cannot be written there ({err.strerror or err}); give another "
            "folder or a shorter name"
        ) from None
    finally:
        for name in held:
            with contextlib.suppress(OSError):
                name.unlink()


def check_plot(path: Path, inputs: Sequence[Path] = ()) -> None:
    """Refuse, before anything runs, a ``--plot`` path that :func:`check_output`
    refuses or that does not name a PNG image (the only format the plots are written
    in: a PNG written under another suffix would mislead the file's readers)."""
    if path.suffix.lower() != ".png":
        raise UsageError(f"--plot {path}: plots are PNG images; give a file name ending in .png")
    check_output(path, "--plot", inputs)


def check_csv(path: Path, inputs: Sequence[Path] = ()) -> None:
    """Refuse, before anything runs, a ``--out`` history path that :func:`check_output`
    refuses or that does not name a CSV file (the history's only format: ``r.nc`` was
    written as CSV, which xarray could not open)."""
    if path.suffix.lower() != ".csv":
        raise UsageError(
            f"--out {path}: the history is written as CSV; give a file name ending in .csv "
            "(vibroimpact.simulate(...).to_xarray() gives a Dataset to write as NetCDF)"
        )
    check_output(path, "--out", inputs)


# A temporary file or folder of ours beside TARGET: ".TARGET.PID-TOKEN.tmp" (being
# written), or ".TARGET.PID-TOKEN.old" (an earlier Zarr store moved aside). The writer's
# process id lets a later run tell a stale one (its writer gone, killed with -9 or by a
# power cut) from one being written.
_OURS = re.compile(r"\.(?P<pid>[0-9]+)-[0-9a-f]{8}\.(?P<tag>tmp|old)")
_NO_FOLLOW = getattr(os, "O_NOFOLLOW", 0)


def beside(path: Path, tag: str) -> Path:
    """A name for a temporary file or folder of this process beside ``path``
    (``tag``: ``"tmp"`` or ``"old"``), hidden, that :func:`remove_stale` recognises."""
    return path.with_name(f".{path.name}.{os.getpid()}-{secrets.token_hex(4)}.{tag}")


def claim_beside(path: Path, held: list[Path], folder: bool = False) -> int:
    """Create a temporary file (or empty ``folder``) of this process beside ``path``
    (see :func:`beside`), its name appended to ``held`` before it is created (so that
    an interrupt just after the creation still finds it to remove), and return a
    descriptor open on it that holds its lock (released when it is closed, or its
    process ends: a writer in another process namespace, whose process id says nothing
    here, is still seen to be alive)."""
    while True:
        name = beside(path, "tmp")
        held.append(name)
        try:
            if folder:
                name.mkdir()
                descriptor = os.open(name, os.O_RDONLY)
            else:
                # 0o666 minus the umask: the permissions a plain open() would give.
                descriptor = os.open(name, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666)
        except FileExistsError:
            held.pop()  # not ours to remove
            continue
        _try_lock(descriptor)
        return descriptor


def _try_lock(descriptor: int) -> bool:
    """Whether an exclusive lock on ``descriptor`` was taken (not held elsewhere);
    True where the system has no such locks."""
    if fcntl is None:
        return True
    try:
        fcntl.flock(descriptor, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except OSError:
        return False
    return True


def _gone(pid: int) -> bool:
    """Whether no process ``pid`` exists (False where that cannot be told)."""
    if sys.platform == "win32" or pid <= 0:
        return False  # Windows' os.kill ends a process, whatever the signal
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return True
    except (OSError, OverflowError):
        return False  # another user's process (alive), or no process id we wrote
    return False


def remove_stale(path: Path) -> None:
    """Remove the temporaries of our naming beside ``path`` (see :func:`beside`) that a
    writer left when it was killed (kill -9, a power cut): those whose process is gone
    and that no process holds locked. An earlier Zarr store moved aside (``.old``) goes
    back to ``path`` where nothing is there (a swap killed between its two renames),
    else is removed. Those of a writer still running are left alone."""
    folder = path.parent
    prefix = f".{path.name}."
    try:
        names = [name for name in os.listdir(folder) if name.startswith(prefix)]
    except OSError:
        return  # let the write say what is wrong
    stale: list[tuple[float, Path]] = []
    for name in names:
        match = _OURS.fullmatch(name, len(prefix) - 1)
        if match is None or not _gone(int(match["pid"])):
            continue
        found = folder / name
        try:
            # Never a link (we make none), never waiting on a FIFO.
            descriptor = os.open(found, os.O_RDONLY | os.O_NONBLOCK | _NO_FOLLOW)
        except OSError:
            continue  # removed meanwhile, a link, or not ours to read
        try:
            if not _try_lock(descriptor):
                continue  # its writer lives (in another process namespace)
            status = os.fstat(descriptor)
            if match["tag"] == "old" and not os.path.lexists(path):
                stale.append((status.st_mtime, found))
            elif stat.S_ISDIR(status.st_mode):
                shutil.rmtree(found, ignore_errors=True)
            else:
                with contextlib.suppress(OSError):
                    os.unlink(found)
        finally:
            os.close(descriptor)
    # The newest earlier store back (one of several only if several swaps were killed).
    for rank, (_, found) in enumerate(sorted(stale, reverse=True)):
        if rank == 0:
            with contextlib.suppress(OSError):
                os.rename(found, path)
        else:
            shutil.rmtree(found, ignore_errors=True)


@contextlib.contextmanager
def written_whole(path: Path, binary: bool = False) -> Iterator[IO[Any]]:
    """Open a file to write ``path`` whole or not at all.

    The file is a temporary one in the same folder (so that the rename cannot
    cross file systems), renamed over ``path`` only when the ``with`` block ends
    normally and the data is on disk. If the block raises, is interrupted, or
    the disk fills up, the temporary file is removed and an existing ``path`` is
    left as it was; one left by a writer that was killed (kill -9, a power cut)
    is removed by the next write of ``path`` (:func:`remove_stale`). A file that
    cannot be written, or a ``path`` that names something other than a regular file
    (a device, a FIFO, a folder), raises :class:`UsageError` naming it; other errors
    propagate unchanged.
    """
    held: list[Path] = []
    if path.is_symlink():
        # Write the file the link points to, as open() would, and keep the link.
        path = path.resolve()
    # Never rename a file over a device, a FIFO or a folder.
    _regular_or_absent(path)
    # What a killed writer of this path left (it is never ours).
    remove_stale(path)
    try:
        descriptor = claim_beside(path, held)
        file: IO[Any] = (
            os.fdopen(descriptor, "wb")
            if binary
            else os.fdopen(descriptor, "w", encoding="utf-8", newline="")
        )
        with file:
            if path.exists():
                # Keep the permissions the user gave the file being replaced.
                os.chmod(held[0], stat.S_IMODE(path.stat().st_mode))
            yield file
            file.flush()
            os.fsync(file.fileno())
        os.replace(held[0], path)
        held.clear()
    except OSError as err:
        raise UsageError(f"cannot write {str(path)!r}: {err.strerror or err}") from None
    finally:
        for temporary in held:
            with contextlib.suppress(OSError):
                os.unlink(temporary)


# Linux's renameat2 flag that swaps two names in one step, and "relative to the
# working folder" for its folder arguments.
_RENAME_EXCHANGE = 2
_AT_FDCWD = -100


def exchange(first: Path, second: Path) -> bool:
    """Swap what ``first`` and ``second`` name in one atomic step (Linux
    ``renameat2(RENAME_EXCHANGE)``); False, with nothing done, where the system or
    the file system cannot."""
    if not sys.platform.startswith("linux"):
        return False
    import ctypes

    try:
        renameat2 = ctypes.CDLL(None, use_errno=True).renameat2
    except (OSError, AttributeError):
        return False  # a C library without it (before glibc 2.28)
    renameat2.argtypes = [ctypes.c_int, ctypes.c_char_p, ctypes.c_int, ctypes.c_char_p]
    renameat2.argtypes += [ctypes.c_uint]
    renameat2.restype = ctypes.c_int
    done = renameat2(
        _AT_FDCWD, os.fsencode(first), _AT_FDCWD, os.fsencode(second), _RENAME_EXCHANGE
    )
    if done == 0:
        return True
    code = ctypes.get_errno()
    if code in (errno.EINVAL, errno.ENOSYS, errno.EOPNOTSUPP):
        return False  # a kernel or file system without it
    raise OSError(code, os.strerror(code), str(second))


def swap_in(built: Path, path: Path) -> Path | None:
    """Put the folder ``built`` (made beside ``path``) at ``path``, whole or not at
    all, and return where the folder that was at ``path`` now is (for the caller to
    remove; None where there was none). Where the system can, one atomic exchange
    (:func:`exchange`): ``path`` always names a whole folder, the earlier one left
    at ``built``. Elsewhere the earlier folder is moved aside (``.old``) for the
    rename, put back if the rename fails, and put back by the next write
    (:func:`remove_stale`) if the process is killed between the two renames."""
    if not os.path.lexists(path):
        os.replace(built, path)
        return None
    if exchange(built, path):
        return built
    earlier = beside(path, "old")
    # Locked while aside: a run in another process namespace leaves it alone.
    hold = os.open(path, os.O_RDONLY)
    try:
        _try_lock(hold)
        os.replace(path, earlier)
        try:
            os.replace(built, path)
        except BaseException:
            os.replace(earlier, path)
            raise
    finally:
        os.close(hold)
    return earlier
