"""Writes killed where no cleanup can run (kill -9, a power cut): the temporary file of
``--out`` (or ``paper --out``) that a killed writer leaves is removed by the next write of
the same file, while a writer still running keeps its own; a Zarr store is swapped in in
one step (Linux), and where it cannot be, an earlier store moved aside by a writer killed
between its two renames is put back by the next run."""

from __future__ import annotations

import errno
import os
import signal
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

import pytest

from conftest import shell_signals
from vibroimpact import output
from vibroimpact.output import beside, written_whole

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "examples" / "rattling_damper.toml"
# 1.5e6 history rows: some seconds of writing, for a kill to land in.
LONG = (
    EXAMPLE.read_text()
    .replace("t_end = 60.0", "t_end = 1500.0")
    .replace("every = 100", "every = 10")
)

pytestmark = pytest.mark.skipif(sys.platform == "win32", reason="POSIX signals and locks")


def temporaries(folder: Path) -> list[str]:
    return sorted(p.name for p in folder.iterdir() if p.name.startswith("."))


def wait_for(condition: Any, proc: subprocess.Popen[str], what: str, limit: float = 90) -> None:
    deadline = time.monotonic() + limit
    while not condition():
        assert proc.poll() is None, proc.communicate()
        assert time.monotonic() < deadline, f"{what} never appeared"
        time.sleep(0.01)


def long_writer(tmp_path: Path, out: Path) -> subprocess.Popen[str]:
    """``simulate --out out`` of 1.5e6 history rows (some seconds of writing), started."""
    scenario = tmp_path / "long.toml"
    scenario.write_text(LONG)
    return subprocess.Popen(
        [sys.executable, "-m", "vibroimpact", "simulate", str(scenario), "--out", str(out)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        preexec_fn=shell_signals,
    )


# A writer that holds its temporary file open until told to finish (a line on stdin).
HOLDING_WRITER = """
import sys
from pathlib import Path
from vibroimpact.output import written_whole
with written_whole(Path(sys.argv[1])) as f:
    f.write("LIVE WRITER\\n")
    print("writing", flush=True)
    sys.stdin.readline()
"""


@pytest.mark.timeout(150)
def test_a_killed_writers_temporary_is_removed_by_the_next_run_not_a_live_ones(
    tmp_path: Path,
) -> None:
    # kill -9 during `simulate --out` left `.h.csv.*.tmp` (58 MB) for ever; five kills,
    # 600 MB. Now the next write of h.csv removes it; a writer still at work keeps its own.
    out = tmp_path / "h.csv"
    killed = long_writer(tmp_path, out)
    try:
        # Killed once part of the history is in its temporary file.
        wait_for(
            lambda: any((tmp_path / name).stat().st_size for name in temporaries(tmp_path)),
            killed,
            "the temporary file",
        )
        killed.kill()  # SIGKILL: no cleanup runs
        killed.communicate(timeout=30)
    finally:
        if killed.poll() is None:
            killed.kill()
    left = temporaries(tmp_path)
    assert len(left) == 1 and left[0].startswith(".h.csv.") and left[0].endswith(".tmp")
    assert (tmp_path / left[0]).stat().st_size > 0
    live = subprocess.Popen(
        [sys.executable, "-c", HOLDING_WRITER, str(out)],
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        assert live.stdout is not None and live.stdout.readline().strip() == "writing"
        live_temporary = sorted(set(temporaries(tmp_path)) - set(left))
        assert len(live_temporary) == 1
        done = subprocess.run(
            [sys.executable, "-m", "vibroimpact", "simulate", str(EXAMPLE), "--out", str(out)],
            capture_output=True,
            text=True,
            timeout=60,
        )
        assert done.returncode == 0, done.stderr
        assert out.read_text().startswith("t,")
        # The killed writer's is gone; the live writer's is left alone.
        assert temporaries(tmp_path) == live_temporary
        _, err = live.communicate("\n", timeout=30)
        assert live.returncode == 0, err
    finally:
        if live.poll() is None:
            live.kill()
    assert out.read_text() == "LIVE WRITER\n"
    assert temporaries(tmp_path) == []


def dead_pid() -> int:
    """The id of a process that has ended (and been reaped)."""
    proc = subprocess.Popen([sys.executable, "-c", "pass"])
    proc.wait(timeout=30)
    return proc.pid


def test_only_temporaries_of_our_naming_whose_writer_is_gone_are_removed(
    tmp_path: Path,
) -> None:
    import fcntl

    target = tmp_path / "work_precision.png"
    gone = dead_pid()
    stale = tmp_path / f".work_precision.png.{gone}-0123abcd.tmp"
    stale.write_bytes(b"half a PNG")
    # A writer's own (this process, alive), and one a writer in another process
    # namespace holds locked (its process id means nothing here).
    alive = beside(target, "tmp")
    alive.write_bytes(b"being written")
    locked = tmp_path / f".work_precision.png.{gone}-4567abcd.tmp"
    locked.write_bytes(b"being written elsewhere")
    # Not ours: another name, another target's, and a user's file of a like name.
    others = [
        f".work_precision.png.{gone}.tmp",
        f".work_precision.png.{gone}-0123abcd.tmp.bak",
        f".other.png.{gone}-0123abcd.tmp",
        "work_precision.png.1-0123abcd.tmp",
        # No process id a writer could have had (os.kill would overflow).
        ".work_precision.png.99999999999999999999-0123abcd.tmp",
    ]
    for name in others:
        (tmp_path / name).write_text("keep")
    with open(locked, "rb") as held:
        fcntl.flock(held.fileno(), fcntl.LOCK_EX)
        with written_whole(target, binary=True) as f:
            f.write(b"PNG")
    assert target.read_bytes() == b"PNG"
    assert not stale.exists()
    assert alive.read_bytes() == b"being written"
    assert locked.exists()
    for name in others:
        assert (tmp_path / name).read_text() == "keep"
    # Its lock released (the writer gone): the next write removes it.
    with written_whole(target, binary=True) as f:
        f.write(b"PNG 2")
    assert not locked.exists() and alive.exists()


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="renameat2")
def test_the_zarr_swap_is_one_step_the_store_never_missing(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # A store was moved aside, then the new one renamed in: between the two, nothing at
    # X.zarr. Now one exchange (renameat2 RENAME_EXCHANGE): the store is never moved aside.
    old, new = tmp_path / "X.zarr", tmp_path / ".X.zarr.new"
    for folder, text in ((old, "earlier"), (new, "new")):
        folder.mkdir()
        (folder / ".zgroup").write_text(text)
    replace = os.replace

    def never_aside(source: Any, target: Any) -> None:
        assert Path(source) != old, "the store was moved aside"
        replace(source, target)

    monkeypatch.setattr(os, "replace", never_aside)
    earlier = output.swap_in(new, old)
    assert (old / ".zgroup").read_text() == "new"
    assert earlier == new and (new / ".zgroup").read_text() == "earlier"


# A study whose Zarr write is killed (SIGKILL, no cleanup) at one step of the swap.
KILLED_SWAP = """
import os, signal, sys
from pathlib import Path
import vibroimpact as vi
from vibroimpact import output, study as st
path, out, step = Path(sys.argv[1]), Path(sys.argv[2]), sys.argv[3]
sc = vi.load_scenario(path)
study = st.study_of(sc.data, str(path), sc.base_dir)
replace, exchange = os.replace, output.exchange

def kill() -> None:
    os.kill(os.getpid(), signal.SIGKILL)

if step == "between renames":
    # Where no exchange can be made: killed once the earlier store is moved aside.
    output.exchange = lambda first, second: False
    def replace_then_die(source, target):
        replace(source, target)
        if Path(source) == out:
            kill()
    os.replace = replace_then_die
else:
    def exchange_then_die(first, second):
        exchange(first, second)
        kill()
    output.exchange = exchange_then_die
st.run(study, out)
"""


@pytest.mark.parametrize("step", ["between renames", "after the exchange"])
def test_a_killed_zarr_swap_is_recovered_by_the_next_run(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, step: str
) -> None:
    pytest.importorskip("zarr")
    import xarray as xr

    from test_study_zarr import earlier_store, leftovers, tree, written_again

    if step == "after the exchange" and not sys.platform.startswith("linux"):
        pytest.skip("renameat2")
    study, out, before = earlier_store(tmp_path)
    done = subprocess.run(
        [sys.executable, "-c", KILLED_SWAP, str(tmp_path / "new.toml"), str(out), step],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert done.returncode == -signal.SIGKILL, done.stderr
    hidden = {Path(name).suffix: name for name in leftovers(tmp_path) if name.startswith(".")}
    if step == "between renames":
        # What the kill left: no store at X.zarr, the earlier one hidden beside the new.
        assert not out.exists() and sorted(hidden) == [".old", ".tmp"]
        assert tree(tmp_path / hidden[".old"]) == before
    else:
        # The new store in place, the earlier one at the temporary's name.
        assert sorted(hidden) == [".tmp"] and tree(tmp_path / hidden[".tmp"]) == before
        with xr.open_zarr(out) as back:
            assert back.attrs["input_hash"] == study.fingerprint()
    # The next run puts the earlier store back before anything else: here its write
    # fails (a full disk), and the earlier store is there, whole.
    write = xr.Dataset.to_zarr

    def disk_full(self: xr.Dataset, store: Any, **kwargs: Any) -> Any:
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    monkeypatch.setattr(xr.Dataset, "to_zarr", disk_full)
    from vibroimpact import study as st
    from vibroimpact.output import UsageError

    with pytest.raises(UsageError, match="cannot write"):
        st.run(study, out)
    if step == "between renames":
        assert tree(out) == before
    assert leftovers(tmp_path) == ["out.zarr.parts"]
    written_again(study, out, monkeypatch, write)
