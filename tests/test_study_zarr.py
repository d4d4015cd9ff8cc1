"""Studies into a Zarr store (``--out RESULT.zarr``): the same Dataset as the NetCDF 4 file;
written whole or not at all, an earlier store kept until the new one is in place; an
interrupted study resumed into the same store; the same store from a Dask cluster; without
zarr, or with another suffix than .nc or .zarr, the command exits 2 saying what to do."""

from __future__ import annotations

import errno
import os
import sys
from pathlib import Path
from typing import Any

import pytest
import xarray as xr

from test_study import BASE, MONTE_CARLO, STEADY, Stop, cli, load, scenario, stop_after_two
from test_user_experience import one_line_error, run_main
from vibroimpact import output
from vibroimpact import study as st
from vibroimpact.output import UsageError

pytest.importorskip("zarr")


def tree(store: Path) -> dict[str, bytes]:
    """Every file of a store, by its path inside it, with its bytes."""
    return {
        str(path.relative_to(store)): path.read_bytes()
        for path in sorted(store.rglob("*"))
        if path.is_file()
    }


def leftovers(folder: Path) -> list[str]:
    """Hidden folders or files a write left beside its output, and parts folders."""
    return sorted(p.name for p in folder.iterdir() if p.name.startswith(".") or ".parts" in p.name)


@pytest.mark.parametrize("text", [BASE + STEADY, BASE + MONTE_CARLO], ids=["grid", "samples"])
def test_the_zarr_store_holds_the_dataset_of_the_netcdf_file(tmp_path: Path, text: str) -> None:
    study = load(scenario(tmp_path, text))
    ds = st.run(study, tmp_path / "out.nc")
    st.run(study, tmp_path / "out.zarr")
    # Zarr format 2 with consolidated metadata: read in one request, no warning.
    assert (tmp_path / "out.zarr" / ".zmetadata").is_file()
    with (
        xr.open_dataset(tmp_path / "out.nc") as netcdf,
        xr.open_zarr(tmp_path / "out.zarr") as zarr,
    ):
        netcdf.load()
        zarr.load()
        xr.testing.assert_identical(zarr, netcdf)
        # The store holds the Dataset itself: every dtype as the study made it.
        xr.testing.assert_identical(zarr, ds)
        assert {name: zarr[name].dtype for name in zarr.variables} == {
            name: ds[name].dtype for name in ds.variables
        }
        # NetCDF 4 keeps every dtype too: 64-bit `coordinate` and `sample`, `pair` as
        # strings (NetCDF 3 had made them int32 and characters).
        assert {name: netcdf[name].dtype for name in netcdf.variables} == {
            name: ds[name].dtype for name in ds.variables
        }
        assert zarr.attrs["input_hash"] == study.fingerprint()
        assert zarr["peak"].attrs == {"long_name": ds["peak"].attrs["long_name"], "units": "m"}
    assert leftovers(tmp_path) == []


def test_an_interrupted_zarr_study_resumes_into_the_same_store(tmp_path: Path) -> None:
    study = load(scenario(tmp_path, (BASE + STEADY).replace("chunk_size = 7", "chunk_size = 3")))
    whole = tmp_path / "whole.zarr"
    st.run(study, whole)
    resumed = tmp_path / "resumed.zarr"

    with pytest.raises(Stop):
        st.run(study, resumed, progress=stop_after_two)
    parts = tmp_path / "resumed.zarr.parts"
    assert sorted(p.name for p in parts.glob("chunk-*.npz")) == [
        "chunk-000000.npz",
        "chunk-000001.npz",
    ]
    assert not resumed.exists()
    st.run(study, resumed)
    assert tree(resumed) == tree(whole)
    assert leftovers(tmp_path) == []


def earlier_store(tmp_path: Path) -> tuple[st.Study, Path, dict[str, bytes]]:
    """A study, and a store of another study (another chunk size) at its output."""
    out = tmp_path / "out.zarr"
    other = load(scenario(tmp_path, (BASE + STEADY).replace("chunk_size = 7", "chunk_size = 5")))
    st.run(other, out)
    study = load(scenario(tmp_path, BASE + STEADY, "new.toml"))
    return study, out, tree(out)


@pytest.mark.parametrize(
    ("failure", "raised"),
    [
        (KeyboardInterrupt(), KeyboardInterrupt),
        (OSError(errno.ENOSPC, os.strerror(errno.ENOSPC)), UsageError),
    ],
    ids=["interrupted", "disk full"],
)
def test_a_failed_write_leaves_no_partial_store_and_the_earlier_one_whole(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, failure: BaseException, raised: type
) -> None:
    study, out, before = earlier_store(tmp_path)
    write = xr.Dataset.to_zarr

    def half_written(self: xr.Dataset, store: Any, **kwargs: Any) -> Any:
        # Part of the store written, then the failure.
        write(self[["status"]], store, **kwargs)
        raise failure

    monkeypatch.setattr(xr.Dataset, "to_zarr", half_written)
    with pytest.raises(raised, match="cannot write" if raised is UsageError else None):
        st.run(study, out)
    assert tree(out) == before
    # Only the finished chunks are left, for the run that resumes.
    assert leftovers(tmp_path) == ["out.zarr.parts"]
    written_again(study, out, monkeypatch, write)


def written_again(study: st.Study, out: Path, monkeypatch: pytest.MonkeyPatch, write: Any) -> None:
    """With the store's writer ``write`` back, the study run again writes its store and
    leaves nothing beside it."""
    monkeypatch.setattr(xr.Dataset, "to_zarr", write)
    st.run(study, out)
    with xr.open_zarr(out) as back:
        assert back.attrs["input_hash"] == study.fingerprint()
    assert leftovers(out.parent) == []


def test_a_failed_rename_puts_the_earlier_store_back(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # Where the store cannot be swapped in one step (no renameat2): it is moved aside,
    # and the new one's rename fails. (The chunks' files are renamed too: only the
    # store's folder is refused, so that the study gets as far as its store.)
    study, out, before = earlier_store(tmp_path)
    replace = os.replace

    def refused(source: Any, target: Any) -> None:
        if Path(source).name.endswith(".tmp") and Path(source).is_dir():
            raise OSError(errno.EIO, os.strerror(errno.EIO))
        replace(source, target)

    monkeypatch.setattr(output, "exchange", lambda first, second: False)
    monkeypatch.setattr(os, "replace", refused)
    with pytest.raises(UsageError, match="cannot write"):
        st.run(study, out)
    monkeypatch.setattr(os, "replace", replace)
    assert tree(out) == before
    assert leftovers(tmp_path) == ["out.zarr.parts"]


@pytest.mark.timeout(120)
def test_a_zarr_study_on_a_local_dask_cluster_writes_the_same_store(tmp_path: Path) -> None:
    path = scenario(tmp_path, BASE + STEADY)
    local, on_dask = tmp_path / "local.zarr", tmp_path / "dask.zarr"
    done = cli("study", str(path), "--out", str(local), "--json")
    assert done.returncode == 0, done.stderr
    assert '"out": "' + str(local) in done.stdout
    done = cli("study", str(path), "--out", str(on_dask), "--dask", "local", "--workers", "2")
    assert done.returncode == 0, done.stderr
    assert tree(on_dask) == tree(local)


def test_without_zarr_a_zarr_output_exits_2_naming_the_extra(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    monkeypatch.setitem(sys.modules, "zarr", None)  # import zarr now raises ImportError
    path = scenario(tmp_path, BASE + STEADY)
    status, out, err = run_main(capsys, "study", str(path), "--out", str(tmp_path / "r.zarr"))
    assert status == 2 and out == ""
    assert 'pip install "vibroimpact[zarr]"' in one_line_error(err)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["study.toml"]
    # NetCDF needs no zarr.
    status, _, err = run_main(capsys, "study", str(path), "--out", str(tmp_path / "r.nc"))
    assert status == 0, err


@pytest.mark.parametrize("name", ["r.h5", "r", "r.zarr.tmp", "r.cdf"])
def test_another_suffix_exits_2_naming_out_and_the_suffixes(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], name: str
) -> None:
    path = scenario(tmp_path, BASE + STEADY)
    status, _, err = run_main(capsys, "study", str(path), "--out", str(tmp_path / name))
    line = one_line_error(err)
    assert status == 2
    for word in ("--out", ".nc", ".zarr"):
        assert word in line, line
    assert sorted(p.name for p in tmp_path.iterdir()) == ["study.toml"]


def test_the_suffix_is_read_in_any_case() -> None:
    assert st.output_kind(Path("R.NC")) == ".nc"
    assert st.output_kind(Path("r.Zarr")) == ".zarr"


@pytest.mark.parametrize("kind", ["file", "folder"])
def test_a_zarr_path_holding_something_else_is_left_alone(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], kind: str
) -> None:
    out = tmp_path / "r.zarr"
    if kind == "file":
        out.write_text("notes")
    else:
        out.mkdir()
        (out / "notes.txt").write_text("notes")
    path = scenario(tmp_path, BASE + STEADY)
    status, _, err = run_main(capsys, "study", str(path), "--out", str(out))
    assert status == 2 and "not a Zarr store" in one_line_error(err)
    assert (out.read_text() if kind == "file" else (out / "notes.txt").read_text()) == "notes"
    assert leftovers(tmp_path) == []


@pytest.mark.timeout(30)
def test_an_interrupted_store_s_folder_is_removed_though_writes_land_late(
    tmp_path: Path,
) -> None:
    # Ctrl-C during to_zarr left a hidden ".out.zarr.PID-TOKEN.tmp/" of 50 chunks:
    # zarr's threads wrote them after the one pass that removed the folder.
    import threading
    import time

    from vibroimpact.study.stores import remove_folder

    folder = tmp_path / ".out.zarr.1-00000000.tmp"

    def late_writer() -> None:
        for k in range(5):  # a chunk every 30 ms, for 120 ms
            try:
                (folder / "peak").mkdir(parents=True, exist_ok=True)
                (folder / "peak" / f"{k}.0").write_bytes(b"chunk")
            except FileNotFoundError:
                pass  # removed between the two: as zarr's own writes race the removal
            time.sleep(0.03)

    writer = threading.Thread(target=late_writer)
    writer.start()
    time.sleep(0.005)
    remove_folder(folder, late_writes=True)
    writer.join()
    assert not folder.exists()
