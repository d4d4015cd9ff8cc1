"""What a study tells its user (a new user's trial): an interrupted study says how many
chunks it kept and the command that resumes it, and the resumed run says that it
resumed; ``settled`` and ``stable`` are booleans in the Dataset, the NetCDF file and the
Zarr store (a failed run's false, its ``status`` saying it failed), and the heat map
draws them."""

from __future__ import annotations

import json
import signal
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import xarray as xr

from conftest import shell_signals
from study_checks import FORCED_DAMPER  # noqa: E402
from test_study import BASE, STEADY, Stop, cli, load, scenario, stop_after_two
from test_study_orbit import LINEAR
from vibroimpact import study as st
from vibroimpact.analysis import runner, steady_state, with_parameter

# A child that takes Ctrl-C, its output read as text.
INTERRUPTIBLE: dict[str, Any] = {
    "stdout": subprocess.PIPE,
    "stderr": subprocess.PIPE,
    "text": True,
    "preexec_fn": shell_signals,
}

# Four runs of a chunk each: the first two fail at once (a clearance below zero fails
# its run alone), the other two run for 1e6 s, so the interrupt finds two chunks kept.
SLOW = FORCED_DAMPER.replace('method = "exact"', 'method = "dopri5"').replace(
    "t_end = 0.5", "t_end = 1e6"
) + (
    '[study]\nanalysis = "run"\nmetrics = ["peak"]\nchunk_size = 1\n'
    '[study.axes]\n"damper.0.clearance" = [-1.0, -1.0, 0.005, 0.006]\n'
)


def started(proc: subprocess.Popen[str], ready: Path) -> None:
    deadline = time.monotonic() + 60
    while not ready.exists():
        assert proc.poll() is None, proc.communicate()
        assert time.monotonic() < deadline, f"{ready} never appeared"
        time.sleep(0.05)


@pytest.mark.timeout(120)
@pytest.mark.skipif(sys.platform == "win32", reason="SIGINT semantics")
def test_an_interrupted_study_names_the_chunks_kept_and_the_resume_command(
    tmp_path: Path,
) -> None:
    path = scenario(tmp_path, SLOW)
    out = tmp_path / "out.nc"
    command = [sys.executable, "-m", "vibroimpact", "study", str(path), "--out", str(out)]
    proc = subprocess.Popen(command, **INTERRUPTIBLE)
    parts = tmp_path / "out.nc.parts"
    started(proc, parts / "chunk-000001.npz")
    time.sleep(0.3)
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 130, err
    lines = err.strip().splitlines()
    assert lines[0] == "vibroimpact: interrupted" and "Traceback" not in err
    assert lines[1] == (
        f"vibroimpact: 2 of 4 chunks (2 of 4 runs) done, kept in {parts}; to resume, run "
        f"again: vibroimpact study {path} --out {out}"
    )
    # The command it gives resumes, and says so.
    proc = subprocess.Popen(command, **INTERRUPTIBLE)
    assert proc.stderr is not None
    first = proc.stderr.readline()
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=60)
    assert first == (
        f"vibroimpact: resuming from {parts}: 2 of 4 chunks (2 of 4 runs) done by an earlier "
        "run, 2 chunks to run\n"
    )
    assert proc.returncode == 130 and "2 of 4 chunks (2 of 4 runs) done, kept in" in err
    assert sorted(p.name for p in parts.iterdir()) == [
        "chunk-000000.npz",
        "chunk-000001.npz",
        "manifest.json",
    ]


def test_a_stopped_study_notes_its_chunks_and_a_resumed_one_says_so(tmp_path: Path) -> None:
    study = load(scenario(tmp_path, (BASE + STEADY).replace("chunk_size = 7", "chunk_size = 5")))
    out = tmp_path / "out.nc"

    def stop_after_one(done: int, total: int, rate: float) -> None:
        raise Stop

    with pytest.raises(Stop) as stopped:
        st.run(study, out, progress=stop_after_one)
    parts = tmp_path / "out.nc.parts"
    assert stopped.value.__notes__ == [
        f"1 of 3 chunks (5 of 12 runs) done, kept in {parts}; to resume, run the same study "
        "into the same output again"
    ]
    # Interrupted at the very moment it says it resumes (Ctrl-C just after that line):
    # it still says what is kept (the notice was made before the guarded run, so such
    # an interrupt went out bare, as the CLI test above once saw under load).

    def interrupted(line: str) -> None:
        raise Stop

    with pytest.raises(Stop) as stopped:
        st.run(study, out, notice=interrupted)
    assert stopped.value.__notes__ == [
        f"1 of 3 chunks (5 of 12 runs) done, kept in {parts}; to resume, run the same study "
        "into the same output again"
    ]
    notices: list[str] = []
    st.run(study, out, notice=notices.append)
    assert notices == [
        f"resuming from {parts}: 1 of 3 chunks (5 of 12 runs) done by an earlier run, 2 "
        "chunks to run"
    ]
    # A kept chunk damaged since is run again, and not counted as kept: "2 of 3
    # chunks ... done, 2 chunks to run" had added up to more than the study.
    with pytest.raises(Stop):
        st.run(study, out, progress=stop_after_one)
    kept = sorted(parts.glob("chunk-*.npz"))
    assert len(kept) == 1
    kept[0].write_bytes(b"damaged")
    notices.clear()
    st.run(study, out, notice=notices.append)
    assert notices == []  # nothing read back: it starts afresh, silently
    for _ in range(2):
        with pytest.raises(Stop):
            st.run(study, out, progress=stop_after_one)
    kept = sorted(parts.glob("chunk-*.npz"))
    assert len(kept) == 2
    kept[0].write_bytes(b"damaged")
    st.run(study, out, notice=notices.append)
    assert notices == [
        f"resuming from {parts}: 1 of 3 chunks (5 of 12 runs) done by an earlier run, 2 "
        "chunks to run"
    ]
    # The command line says it on stderr; a study that starts afresh says nothing.
    done = cli("study", str(tmp_path / "study.toml"), "--out", str(tmp_path / "again.nc"))
    assert done.returncode == 0 and done.stderr == ""


FAILING = (BASE + STEADY).replace(
    '"damper.0.clearance" = { start = 0.002, stop = 0.01, count = 4 }',
    '"damper.0.clearance" = [-1.0, 0.002, 0.01]',
)


def test_settled_is_a_boolean_in_the_file_and_the_store_a_failed_runs_false(
    tmp_path: Path,
) -> None:
    # It was stored as 0.0 / 1.0 floats (NaN for a failed run).
    path = scenario(tmp_path, FAILING)
    study = load(path)
    ds = st.run(study, tmp_path / "out.nc")
    assert ds["settled"].dtype == bool
    failed = ds["status"].values != 0
    assert failed[0].all() and not failed[1:].any()
    assert not ds["settled"].values[0].any()
    for frequency in (9.0, 11.0):
        data = {k: v for k, v in study.data.items() if k != "study"}
        data = with_parameter(data, "damper.0.clearance", 0.01)
        data = with_parameter(data, "excitation.0.frequency", frequency)
        result = steady_state(runner(data), settle_periods=60, record_periods=10, tolerance=1e-6)
        point = ds.sel({"damper.0.clearance": 0.01, "excitation.0.frequency": frequency})
        assert point["settled"].item() is result.settled
    stores = [xr.open_dataset(tmp_path / "out.nc")]
    try:
        import zarr  # noqa: F401

        st.run(study, tmp_path / "out.zarr")
        stores.append(xr.open_zarr(tmp_path / "out.zarr"))
    except ImportError:
        pass
    for back in stores:
        with back:
            assert back["settled"].dtype == bool
            np.testing.assert_array_equal(back["settled"].values, ds["settled"].values)
    # The heat map of it: 1 / 0, the failed runs blank.
    plot = tmp_path / "settled.png"
    done = cli(
        "study",
        str(path),
        "--out",
        str(tmp_path / "c.nc"),
        "--plot",
        str(plot),
        "--metric",
        "settled",
    )
    assert done.returncode == 0, done.stderr
    assert plot.read_bytes().startswith(b"\x89PNG")


def test_an_orbits_stable_is_a_boolean(tmp_path: Path) -> None:
    ds = st.run(load(scenario(tmp_path, LINEAR)), tmp_path / "out.nc")
    assert ds["stable"].dtype == bool and ds["stable"].values.all()


def test_the_heat_map_of_settled_draws_1_and_0_and_failed_runs_blank(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # A failed run's settled is false in the Dataset: the map leaves it blank, not
    # "not settled".
    import matplotlib

    matplotlib.use("Agg")
    from matplotlib.axes import Axes

    from vibroimpact.analysis.plots import plot_study

    drawn: list[np.ndarray] = []
    pcolormesh = Axes.pcolormesh

    def recorded(self: Axes, *args: object, **kwargs: object) -> object:
        drawn.append(np.ma.filled(np.ma.asarray(args[2], dtype=float), np.nan))
        return pcolormesh(self, *args, **kwargs)  # type: ignore[arg-type]

    monkeypatch.setattr(Axes, "pcolormesh", recorded)
    dims = ("damper.0.mass", "damper.0.clearance")
    dataset = xr.Dataset(
        {
            "settled": (dims, [[True, False, False], [True, True, False]]),
            "status": (dims, [[0, 0, 1], [0, 0, 1]]),
        },
        coords={"damper.0.mass": [0.1, 0.2], "damper.0.clearance": [1e-3, 2e-3, 3e-3]},
    )
    png = tmp_path / "heat.png"
    plot_study(png, dataset, "settled", *dims)
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    np.testing.assert_array_equal(drawn[0], [[1.0, 1.0], [0.0, 1.0], [np.nan, np.nan]])


def test_a_study_whose_every_run_fails_keeps_an_earlier_result(tmp_path: Path) -> None:
    # A study whose every run failed had written its file of failures over an earlier
    # result of the same name (an adversarial pass): the earlier file is kept, to the
    # byte, the command says it did not write, and exits 1 with every reason in --json.
    good = FORCED_DAMPER + (
        '[study]\nanalysis = "run"\nmetrics = ["peak"]\n'
        '[study.axes]\n"damper.0.restitution" = [0.5, 0.6]\n'
    )
    bad = good.replace("[0.5, 0.6]", "[1.1, 1.2]")
    out = tmp_path / "r.nc"
    done = cli("study", str(scenario(tmp_path, good)), "--out", str(out))
    assert done.returncode == 0, done.stdout + done.stderr
    earlier = out.read_bytes()
    for extra in ([], ["--json"]):
        done = cli("study", str(scenario(tmp_path, bad)), "--out", str(out), *extra)
        assert done.returncode == 1, done.stdout + done.stderr
        assert "is left as it was" in done.stderr and "Traceback" not in done.stderr
        assert out.read_bytes() == earlier
    summary = json.loads(done.stdout)
    assert summary["written"] is False and len(summary["reasons"]) == 2
    # With no earlier result the file of failures is written, as before.
    fresh = tmp_path / "fresh.nc"
    done = cli("study", str(scenario(tmp_path, bad)), "--out", str(fresh))
    assert done.returncode == 1 and f"written to {fresh}" in done.stdout
    with xr.open_dataset(fresh) as ds:
        assert sorted(np.unique(ds["status"].values)) == [1, 2]
    # The Python call keeps it too, and returns the failures.
    dataset = st.run(load(scenario(tmp_path, bad)), out)
    assert int(np.count_nonzero(dataset["status"].values)) == 2
    assert out.read_bytes() == earlier


def test_a_large_failed_region_lists_a_few_reasons_and_counts_the_rest(tmp_path: Path) -> None:
    # One line per distinct reason had printed one per refused value: a thousand lines
    # for a wide invalid region. The file keeps every reason.
    text = FORCED_DAMPER + (
        '[study]\nanalysis = "run"\nmetrics = ["peak"]\n'
        '[study.axes]\n"damper.0.restitution" = { start = 1.1, stop = 2.0, count = 10 }\n'
        '"damper.0.mass" = [0.05]\n'
    )
    out = tmp_path / "r.nc"
    done = cli("study", str(scenario(tmp_path, text)), "--out", str(out))
    assert done.returncode == 1, done.stdout + done.stderr  # every run failed
    listed = [line for line in done.stdout.splitlines() if line.startswith("  failed: ")]
    assert len(listed) == 5 and "restitution must be in [0, 1], got 1.1" in listed[0]
    assert "... and 5 more reasons" in done.stdout
    with xr.open_dataset(out) as ds:
        reasons = json.loads(ds.attrs["reasons"])
        assert len(reasons) == 10 and sorted(np.unique(ds["status"].values)) == list(range(1, 11))
    done = cli("study", str(scenario(tmp_path, text)), "--out", str(out), "--json")
    assert len(json.loads(done.stdout)["reasons"]) == 10


def test_a_study_begun_in_python_resumes_from_the_command_line(tmp_path: Path) -> None:
    """``vi.study_of(vi.load(path))`` and ``vibroimpact study path`` are one study: the
    command line resumes the chunks Python kept (an adversarial probe: its fingerprint
    had hashed the [study] table with its defaults filled in, Python's as written, so
    the resume was refused as "another study"), and the file equals a whole run's."""
    import vibroimpact as vi

    path = scenario(tmp_path, (BASE + STEADY).replace("chunk_size = 7", "chunk_size = 3"))
    study = vi.study_of(vi.load(path))
    whole = tmp_path / "whole.nc"
    assert cli("study", str(path), "--out", str(whole)).returncode == 0
    out = tmp_path / "out.nc"

    with pytest.raises(Stop):
        st.run(study, out, progress=stop_after_two)
    assert (out.with_name("out.nc.parts") / "chunk-000000.npz").exists()
    proc = cli("study", str(path), "--out", str(out))
    assert proc.returncode == 0, proc.stderr
    assert "resum" in proc.stderr
    assert xr.open_dataset(out).attrs["input_hash"] == xr.open_dataset(whole).attrs["input_hash"]
    assert out.read_bytes() == whole.read_bytes()
