"""NetCDF 4 output (vibroimpact.netcdf): a study's file is HDF5 that h5py and xarray's
default engine read, its 64-bit integers and strings kept, its numbers compressed; the
same bytes for the same Dataset (written twice, in another process, by 1 or 2 threads,
in chunks of any size, resumed); the NetCDF 3 files of earlier versions still read;
bad arguments and a missing h5netcdf refused in one line."""

from __future__ import annotations

import subprocess
import sys
import time
from pathlib import Path

import h5py
import numpy as np
import pytest
import xarray as xr

import vibroimpact as vi
from test_study import BASE, MONTE_CARLO, STEADY, Stop, load, scenario
from test_user_experience import one_line_error, run_main
from vibroimpact import netcdf
from vibroimpact import study as st
from vibroimpact.output import UsageError

HDF5_SIGNATURE = b"\x89HDF\r\n\x1a\n"
ROOT = Path(__file__).resolve().parents[1]


def test_a_study_file_is_netcdf4_keeping_int64_and_strings_compressed(tmp_path: Path) -> None:
    study = load(scenario(tmp_path, BASE + MONTE_CARLO))
    out = tmp_path / "out.nc"
    ds = st.run(study, out)
    assert ds["sample"].dtype == np.int64 and ds["pair"].dtype.kind == "U"
    assert out.read_bytes()[:8] == HDF5_SIGNATURE
    with h5py.File(out, "r") as raw:
        # What NetCDF 3 could not hold: 64-bit integers and variable-length strings.
        assert raw["sample"].dtype == np.int64
        assert raw["coordinate"].dtype == np.int64
        string = h5py.check_string_dtype(raw["pair"].dtype)
        assert string is not None and string.length is None
        assert [p.decode() for p in raw["pair"][...]] == ds["pair"].values.tolist()
        for name in ("peak", "impacts", "status", "sample"):
            assert raw[name].compression == "gzip", name
            assert raw[name].compression_opts == netcdf.COMPRESSION_LEVEL, name
            assert raw[name].shuffle, name
            # Our chunk rule, not h5py's guess: these are whole (far below 1 MiB).
            assert raw[name].chunks == raw[name].shape, name
    # xarray's default engine opens it, every dtype as the study made it.
    with xr.open_dataset(out) as back:
        back.load()
    xr.testing.assert_identical(back, ds)
    assert {k: back[k].dtype for k in back.variables} == {k: ds[k].dtype for k in ds.variables}


def test_compression_shrinks_a_repetitive_variable() -> None:
    # 800 kB of float64 with 10 distinct values: gzip after shuffle leaves a few kB.
    values = np.tile(np.linspace(0.0, 1.0, 10), 10_000)
    data = netcdf.netcdf_bytes(xr.Dataset({"v": ("x", values)}))
    assert len(data) < values.nbytes / 20


@pytest.mark.parametrize(
    ("shape", "itemsize"), [((3000, 100), 8), ((10,), 8), ((1, 2**20), 1), ((7, 5, 2**16), 8)]
)
def test_chunks_are_the_largest_halvings_within_the_limit(
    shape: tuple[int, ...], itemsize: int
) -> None:
    chunk = netcdf.chunks(shape, itemsize)
    assert len(chunk) == len(shape)
    assert all(1 <= c <= s for c, s in zip(chunk, shape, strict=True))
    assert int(np.prod(chunk)) * itemsize <= netcdf.CHUNK_BYTES
    if int(np.prod(shape)) * itemsize <= netcdf.CHUNK_BYTES:
        assert chunk == shape
    else:
        # Halved no more than needed: the chunk before the last halving (at most twice
        # this one) held more than the limit.
        assert int(np.prod(chunk)) * itemsize * 2 > netcdf.CHUNK_BYTES


def test_a_large_variable_is_written_in_the_chunks_of_the_rule(tmp_path: Path) -> None:
    ds = xr.Dataset({"a": (("x", "y"), np.zeros((3000, 100)))})
    vi.write_netcdf(ds, tmp_path / "a.nc")
    with h5py.File(tmp_path / "a.nc", "r") as raw:
        assert raw["a"].chunks == netcdf.chunks((3000, 100), 8) != (3000, 100)


def test_the_same_dataset_writes_the_same_bytes_at_another_time_and_in_another_process(
    tmp_path: Path,
) -> None:
    study = load(scenario(tmp_path, BASE + STEADY))
    ds = st.run(study, tmp_path / "out.nc")
    first = netcdf.netcdf_bytes(ds)
    # A second later: a creation or modification time in the file would differ.
    time.sleep(1.1)
    assert netcdf.netcdf_bytes(ds) == first == (tmp_path / "out.nc").read_bytes()
    # Another process (other memory, other object addresses) reads and writes it again.
    code = (
        "import sys, xarray as xr, vibroimpact as vi\n"
        "ds = xr.load_dataset(sys.argv[1])\n"
        "vi.write_netcdf(ds, sys.argv[2])\n"
    )
    again = tmp_path / "again.nc"
    done = subprocess.run(
        [sys.executable, "-c", code, str(tmp_path / "out.nc"), str(again)],
        capture_output=True,
        text=True,
        timeout=50,
        cwd=ROOT,
    )
    assert done.returncode == 0, done.stderr
    assert again.read_bytes() == first


@pytest.mark.timeout(120)
def test_one_or_two_threads_and_any_chunk_size_write_the_same_file(tmp_path: Path) -> None:
    text = BASE + STEADY
    one = tmp_path / "one.nc"
    st.run(load(scenario(tmp_path, text)), one, threads=1)
    two = tmp_path / "two.nc"
    st.run(load(scenario(tmp_path, text)), two, threads=2)
    single = tmp_path / "single.nc"
    small = text.replace("chunk_size = 7", "chunk_size = 1")
    st.run(load(scenario(tmp_path, small, "small.toml")), single, threads=2)
    assert one.read_bytes()[:8] == HDF5_SIGNATURE
    assert two.read_bytes() == one.read_bytes()
    # The scenario's path is an attribute: compare the Datasets but for it.
    with xr.open_dataset(one) as a, xr.open_dataset(single) as b:
        xr.testing.assert_identical(a.drop_attrs(deep=False), b.drop_attrs(deep=False))


def test_a_study_resumed_over_an_earlier_netcdf3_file_writes_netcdf4(tmp_path: Path) -> None:
    # An earlier version's NetCDF 3 result where the study writes, and the chunks an
    # interrupted run kept: the run goes on from the chunks, and replaces the file with
    # the NetCDF 4 file of an uninterrupted run.
    study = load(scenario(tmp_path, (BASE + STEADY).replace("chunk_size = 7", "chunk_size = 3")))
    whole = tmp_path / "whole.nc"
    ds = st.run(study, whole)
    out = tmp_path / "out.nc"
    ds.to_netcdf(out, engine="scipy")
    assert out.read_bytes()[:3] == b"CDF"

    def stop_after_two(done: int, total: int, rate: float) -> None:
        if done >= 6:
            raise Stop

    with pytest.raises(Stop):
        st.run(study, out, progress=stop_after_two)
    assert out.read_bytes()[:3] == b"CDF"  # left as it was
    computed: list[int] = []
    st.run(study, out, progress=lambda done, total, rate: computed.append(done))
    assert computed[0] == 9  # two chunks of 3 kept, the third run now
    assert out.read_bytes() == whole.read_bytes()
    assert out.read_bytes()[:8] == HDF5_SIGNATURE


def test_an_earlier_netcdf3_study_file_reads_with_the_default_engine(tmp_path: Path) -> None:
    # What vibroimpact wrote before NetCDF 4: xarray's scipy engine, NetCDF 3.
    ds = st.run(load(scenario(tmp_path, BASE + MONTE_CARLO)), tmp_path / "new.nc")
    old = tmp_path / "old.nc"
    ds.to_netcdf(old, engine="scipy", format="NETCDF3_64BIT")
    assert old.read_bytes()[:4] == b"CDF\x02"
    with xr.open_dataset(old) as back:
        back.load()
    # The same values; NetCDF 3 had made the int64 indices int32.
    xr.testing.assert_equal(back, ds)
    assert back["sample"].dtype == np.int32
    # Written again, it is NetCDF 4 with strings as strings (its characters' encoding
    # dropped), and reads back equal.
    vi.write_netcdf(back, tmp_path / "converted.nc")
    with h5py.File(tmp_path / "converted.nc", "r") as raw:
        string = h5py.check_string_dtype(raw["pair"].dtype)
        assert string is not None and string.length is None
    with xr.open_dataset(tmp_path / "converted.nc") as converted:
        xr.testing.assert_identical(converted.load(), back)


def test_write_netcdf_is_whole_or_nothing_and_refuses_bad_arguments(tmp_path: Path) -> None:
    out = tmp_path / "keep.nc"
    out.write_bytes(b"earlier")
    with pytest.raises(vi.InvalidInputError, match="dataset: must be"):
        vi.write_netcdf({"a": [1]}, out)
    with pytest.raises(vi.InvalidInputError, match="path: must be a path"):
        vi.write_netcdf(xr.Dataset(), 3)
    # A Dataset xarray cannot write (a slash in a name) fails before the file is touched.
    with pytest.raises(ValueError):
        vi.write_netcdf(xr.Dataset({"a/b": ("x", [1.0])}), out)
    assert out.read_bytes() == b"earlier"
    assert [p.name for p in tmp_path.iterdir()] == ["keep.nc"]
    with pytest.raises(UsageError, match="cannot write"):
        vi.write_netcdf(xr.Dataset({"a": ("x", [1.0])}), tmp_path / "missing" / "a.nc")


def test_a_study_without_h5netcdf_exits_2_saying_what_to_install(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    path = scenario(tmp_path, BASE + STEADY)
    monkeypatch.setitem(sys.modules, "h5netcdf", None)  # importing it raises ImportError
    status, _, err = run_main(capsys, "study", str(path), "--out", str(tmp_path / "r.nc"))
    assert status == 2
    line = one_line_error(err)
    for word in ("--out", "h5netcdf", "pip install"):
        assert word in line, line
    assert list(tmp_path.iterdir()) == [path]
