"""Studies: a [study] grid run by the core on all cores, against the same runs made
one by one; the same results whatever the number of threads; failed runs recorded
with their reasons while the others go on; the NetCDF file, and an interrupted study
resumed into the same file as an uninterrupted one; the command line."""

from __future__ import annotations

import contextlib
import json
import socket
import subprocess
import sys
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import xarray as xr

import docs_blocks
import vibroimpact as vi
from study_checks import FORCED_DAMPER, assert_refused  # noqa: E402
from vibroimpact import study as st
from vibroimpact.analysis import runner, steady_state
from vibroimpact.scenario.system import SystemScenario

BASE = FORCED_DAMPER

STEADY = """
[study]
analysis = "steady-state"
settle_periods = 60
record_periods = 10
metrics = ["peak", "rms", "impacts", "energy_dissipated", "amplitude",
           "impacts_per_period", "settled"]
chunk_size = 7

[study.axes]
"damper.0.clearance" = { start = 0.002, stop = 0.01, count = 4 }
"excitation.0.frequency" = [9.0, 10.0, 11.0]
"""


def scenario(tmp_path: Path, text: str, name: str = "study.toml") -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


def load(path: Path) -> st.Study:
    sc = vi.load_scenario(path)
    assert isinstance(sc, SystemScenario)
    return st.study_of(sc.data, str(path), sc.base_dir)


def without_study(study: st.Study, **changes: Any) -> dict[str, Any]:
    data = {k: v for k, v in study.data.items() if k != "study"}
    for path, value in changes.items():
        from vibroimpact.analysis import with_parameter

        data = with_parameter(data, path, value)
    return data


def single_run(data: dict[str, Any], method: str, **options: Any) -> Any:
    """The scenario ``data``'s structure, dampers and excitations run alone to 0.5 s."""
    return vi.simulate_system(
        data["structure"],
        damper=data["damper"],
        excitation=data["excitation"],
        method=method,
        t_end=0.5,
        history=False,
        **options,
    )


def test_a_run_study_equals_the_runs_made_one_by_one(tmp_path: Path) -> None:
    text = BASE + (
        '[study]\nanalysis = "run"\nrecord_from = 0.1\n'
        'metrics = ["peak", "rms", "impacts", "energy_dissipated"]\n'
        '[study.axes]\n"damper.0.mass" = [0.02, 0.05]\n'
        '"initial.structure_velocity.0" = [0.0, 0.2, -0.3]\n'
    )
    study = load(scenario(tmp_path, text))
    ds = st.run(study, tmp_path / "out.nc", threads=2)
    for mass in (0.02, 0.05):
        for velocity in (0.0, 0.2, -0.3):
            data = without_study(study, **{"damper.0.mass": mass})
            sol = vi.simulate_system(
                data["structure"],
                damper=data["damper"],
                excitation=data["excitation"],
                initial={"structure_velocity": [velocity]},
                method="exact",
                t_end=0.5,
                history=False,
                record_from=0.1,
            )
            point = ds.sel({"damper.0.mass": mass, "initial.structure_velocity.0": velocity})
            # The same computation: equal to the last bit.
            assert point["peak"].values.tolist() == sol.peak.tolist()
            assert point["rms"].values.tolist() == sol.rms.tolist()
            recorded = [
                (kind, onset, loss)
                for kind, onset, loss in zip(
                    sol.contacts.kind,
                    sol.contacts.onset,
                    sol.contacts.energy_dissipated,
                    strict=True,
                )
                if onset >= 0.1
            ]
            assert point["impacts"].item() == sum(k != "sticking" for k, _, _ in recorded)
            assert point["energy_dissipated"].values.tolist() == pytest.approx(
                [sum(loss for _, _, loss in recorded)], rel=1e-12
            )
    assert int(ds["status"].max()) == 0


def test_steady_state_metrics_match_the_analysis(tmp_path: Path) -> None:
    study = load(scenario(tmp_path, BASE + STEADY))
    ds = st.run(study, tmp_path / "out.nc")
    assert dict(ds.sizes) == {
        "damper.0.clearance": 4,
        "excitation.0.frequency": 3,
        "coordinate": 1,
        "pair": 1,
    }
    for clearance in (0.002, 0.01):
        for frequency in (9.0, 11.0):
            data = without_study(
                study,
                **{"damper.0.clearance": clearance, "excitation.0.frequency": frequency},
            )
            result = steady_state(
                runner(data), settle_periods=60, record_periods=10, tolerance=1e-6
            )
            point = ds.sel(
                {"damper.0.clearance": clearance, "excitation.0.frequency": frequency},
                method="nearest",
            )
            np.testing.assert_allclose(point["amplitude"].values, result.amplitude, rtol=1e-8)
            np.testing.assert_allclose(point["rms"].values, result.rms, rtol=1e-6)
            assert point["impacts_per_period"].item() == result.impacts_per_period
            assert point["settled"].item() == float(result.settled)


def test_results_do_not_depend_on_the_number_of_threads(tmp_path: Path) -> None:
    study = load(scenario(tmp_path, BASE + STEADY))
    one = study.run_chunk(range(0, study.runs), threads=1)
    two = study.run_chunk(range(0, study.runs), threads=2)
    for key in ("peak", "rms", "impacts", "energy_dissipated", "impacts_per_period", "settled"):
        assert np.array_equal(np.asarray(one[key]), np.asarray(two[key]), equal_nan=True), key


def peak_study(tmp_path: Path, axis: str) -> Any:
    """A "run" study of the peak along the one axis ``axis`` (a TOML line), as written."""
    text = BASE + f'[study]\nanalysis = "run"\nmetrics = ["peak"]\n[study.axes]\n{axis}\n'
    return st.run(load(scenario(tmp_path, text)), tmp_path / "out.nc")


def test_a_damped_hertz_law_s_restitution_is_an_axis(tmp_path: Path) -> None:
    # Every run failed with "the pair's law has no restitution" (exit 0; user trial).
    text = (
        BASE.replace('law = "rigid"', 'law = "hertz-damped"\nstiffness = 1e7').replace(
            'method = "exact"', 'method = "dop853"'
        )
        + '[study]\nanalysis = "run"\nmetrics = ["peak", "energy_dissipated"]\n'
        + '[study.axes]\n"damper.0.restitution" = [0.3, 0.9]\n'
    )
    study = load(scenario(tmp_path, text))
    ds = st.run(study, tmp_path / "out.nc")
    assert ds["status"].values.tolist() == [0, 0]
    losses = []
    for restitution in (0.3, 0.9):
        data = without_study(study, **{"damper.0.restitution": restitution})
        sol = single_run(data, "dop853", record_from=0.0)
        point = ds.sel({"damper.0.restitution": restitution})
        assert point["peak"].values.tolist() == sol.peak.tolist()
        losses.append(point["energy_dissipated"].item())
    # The less elastic law loses more.
    assert losses[0] > losses[1] > 0


def test_a_failed_run_is_recorded_with_its_reason_and_the_others_go_on(tmp_path: Path) -> None:
    ds = peak_study(tmp_path, '"damper.0.mass" = [0.05, -1.0, 0.1]')
    status = ds["status"].values
    assert status.tolist() == [0, 1, 0]
    reasons = json.loads(ds.attrs["reasons"])
    assert len(reasons) == 1 and "mass" in reasons[0] and "damper 0" in reasons[0]
    assert np.isnan(ds["peak"].values[1]).all() and np.isfinite(ds["peak"].values[[0, 2]]).all()


def test_more_distinct_failures_than_a_16_bit_code_holds_are_all_numbered(
    tmp_path: Path,
) -> None:
    # 33000 runs each failing for its own reason (each quotes its mass): the status was
    # int16 and the file's writing overflowed at the 32768th reason, every time it was
    # resumed too (user trial).
    ds = peak_study(tmp_path, '"damper.0.mass" = { start = -1.0, stop = -0.001, count = 33000 }')
    reasons = json.loads(ds.attrs["reasons"])
    assert len(reasons) == 33000
    status = ds["status"].values
    assert status.tolist() == list(range(1, 33001))
    # Each code names its own run's reason.
    masses = ds["damper.0.mass"].values
    for i in (0, 32767, 32999):
        assert f"{masses[i]:g}"[:5] in reasons[status[i] - 1]


def test_a_failed_runs_reason_names_the_axis_as_written(tmp_path: Path) -> None:
    # It named lower_clearance, a key the scenario did not use (user trial).
    ds = peak_study(tmp_path, '"damper.0.clearance" = [0.004, -0.004]')
    assert ds["status"].values.tolist() == [0, 1]
    (reason,) = json.loads(ds.attrs["reasons"])
    assert "damper.0.clearance" in reason and ">= 0" in reason and "lower" not in reason


def test_axis_values_are_the_decimals_written(tmp_path: Path) -> None:
    # linspace gave 0.004999999999999999 and 0.009000000000000001, and .sel(0.005)
    # raised KeyError (user trial); the runs use the coordinates as they read.
    ds = peak_study(tmp_path, '"damper.0.clearance" = { start = 0.002, stop = 0.011, count = 10 }')
    clearance = ds["damper.0.clearance"].values
    assert clearance.tolist() == [
        0.002,
        0.003,
        0.004,
        0.005,
        0.006,
        0.007,
        0.008,
        0.009,
        0.01,
        0.011,
    ]
    assert ds.sel({"damper.0.clearance": 0.005})["peak"].notnull().all()


def test_the_netcdf_file_holds_the_dataset(tmp_path: Path) -> None:
    study = load(scenario(tmp_path, BASE + STEADY))
    out = tmp_path / "out.nc"
    ds = st.run(study, out)
    with xr.open_dataset(out) as back:
        assert back.attrs["input_hash"] == study.fingerprint()
        assert back.attrs["analysis"] == "steady-state"
        for name in ("status", "peak", "amplitude", "settled", "energy_dissipated"):
            np.testing.assert_array_equal(back[name].values, ds[name].values)
        np.testing.assert_array_equal(
            back["damper.0.clearance"].values, np.linspace(0.002, 0.01, 4)
        )
        assert back["peak"].attrs["units"] == "m"
    assert not out.with_name(out.name + ".parts").exists()


class Stop(Exception):
    pass


def stop_after_two(done: int, total: int, rate: float) -> None:
    """A study's progress that stops it once two chunks of 3 runs are kept."""
    if done >= 6:
        raise Stop


def test_an_interrupted_study_resumes_into_the_same_file(tmp_path: Path) -> None:
    study = load(scenario(tmp_path, (BASE + STEADY).replace("chunk_size = 7", "chunk_size = 3")))
    whole = tmp_path / "whole.nc"
    st.run(study, whole)
    resumed = tmp_path / "resumed.nc"

    with pytest.raises(Stop):
        st.run(study, resumed, progress=stop_after_two)
    parts = resumed.with_name(resumed.name + ".parts")
    assert sorted(p.name for p in parts.glob("chunk-*.npz")) == [
        "chunk-000000.npz",
        "chunk-000001.npz",
    ]
    assert not resumed.exists()
    # A chunk damaged since it was written (cut short) is run again: it had ended
    # the resumed study with a BadZipFile traceback (user trial).
    damaged = parts / "chunk-000001.npz"
    damaged.write_bytes(damaged.read_bytes()[:100])
    computed: list[int] = []
    st.run(study, resumed, progress=lambda done, total, rate: computed.append(done))
    assert resumed.read_bytes() == whole.read_bytes()
    assert not parts.exists()
    # Every chunk but the intact first one was run: 3 runs were done at the start.
    assert computed[0] == 6


def test_chunks_of_another_study_are_refused(tmp_path: Path) -> None:
    study = load(scenario(tmp_path, BASE + STEADY))
    out = tmp_path / "out.nc"
    parts = out.with_name(out.name + ".parts")
    parts.mkdir()
    (parts / "manifest.json").write_text(json.dumps({"input_hash": "another"}))
    with pytest.raises(vi.output.UsageError, match="another study"):
        st.run(study, out)


def cli(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "vibroimpact", *args], capture_output=True, text=True, timeout=50
    )


def test_the_study_command_writes_the_file(tmp_path: Path) -> None:
    path = scenario(tmp_path, BASE + STEADY)
    out = tmp_path / "result.nc"
    done = cli("study", str(path), "--out", str(out), "--workers", "2", "--json")
    assert done.returncode == 0, done.stderr
    summary = json.loads(done.stdout)
    assert summary["runs"] == 12 and summary["failed"] == 0
    with xr.open_dataset(out) as ds:
        assert ds["amplitude"].shape == (4, 3, 1)


@pytest.mark.parametrize(
    ("change", "words"),
    [
        (("chunk_size = 7", "chunk_sise = 7"), ["[study]", "chunk_sise"]),
        (('"damper.0.clearance"', '"damper.3.clearance"'), ["damper.3.clearance", "[[damper]]"]),
        (('"damper.0.clearance"', '"structure.modes"'), ["structure.modes", "allowed"]),
        (('analysis = "steady-state"', 'analysis = "run"'), ["metrics", "steady-state"]),
        (("count = 4", "count = 0"), ["count", "[1, 10,000,000], got 0"]),
        # One value is start alone: stop had been dropped without a word.
        (("count = 4", "count = 1"), ["count", ">= 2", "set stop = start"]),
        # Both varied: the runs took the lower wall's and the coordinate said clearance.
        (
            ("count = 4 }", 'count = 4 }\n"damper.0.lower_clearance" = [0.003]'),
            ["damper.0.clearance", "damper.0.lower_clearance", "not both"],
        ),
        (('metrics = ["peak"', 'metrics = ["peek"'), ["metrics", "peek"]),
    ],
)
def test_bad_studies_exit_2_naming_the_key(
    tmp_path: Path, change: tuple[str, str], words: list[str]
) -> None:
    text = (BASE + STEADY).replace(*change)
    assert text != BASE + STEADY
    done = cli("study", str(scenario(tmp_path, text)), "--out", str(tmp_path / "r.nc"))
    assert_refused(done, words, tmp_path / "r.nc")


def test_a_study_whose_every_run_fails_exits_1_with_its_file_written(tmp_path: Path) -> None:
    # It exited 0 (trial of the analyses). One run failing of two still exits 0.
    for masses, status in (("[-1.0, -2.0]", 1), ("[-1.0, 0.05]", 0)):
        text = BASE + '[study]\nanalysis = "run"\nmetrics = ["peak"]\n'
        text += f'[study.axes]\n"damper.0.mass" = {masses}\n'
        out = tmp_path / f"r{status}.nc"
        done = cli("study", str(scenario(tmp_path, text)), "--out", str(out))
        assert done.returncode == status, done.stderr
        assert out.exists() and "Traceback" not in done.stderr
        assert ("every one of the 2 runs failed" in done.stderr) == bool(status)


def test_the_docs_study_commands_work_as_written(tmp_path: Path) -> None:
    studies = docs_blocks.section("analyses", "Studies")
    shell = docs_blocks.blocks(studies, "sh")[0].strip()
    code = docs_blocks.blocks(studies, "python")[0]
    root = Path(__file__).resolve().parents[1]
    argv = shell.split()
    assert argv[:2] == ["vibroimpact", "study"]
    # Run where the page says (the checkout's root), the output kept out of the checkout.
    (tmp_path / "examples").symlink_to(root / "examples")
    done = subprocess.run(
        [sys.executable, "-m", "vibroimpact", *argv[1:]],
        capture_output=True,
        text=True,
        timeout=50,
        cwd=tmp_path,
    )
    assert done.returncode == 0, done.stderr
    printed = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, timeout=50, cwd=tmp_path
    )
    assert printed.returncode == 0, printed.stderr
    # The best clearance for each mass: one of the axis's values, three masses.
    best = np.array(printed.stdout.strip().strip("[]").split(), dtype=float)
    assert len(best) == 3 and set(best) <= set(np.linspace(0.002, 0.011, 4).round(12))


@pytest.mark.timeout(120)
def test_a_study_on_a_local_dask_cluster_writes_the_same_file(tmp_path: Path) -> None:
    path = scenario(tmp_path, BASE + STEADY)
    local, on_dask = tmp_path / "local.nc", tmp_path / "dask.nc"
    assert cli("study", str(path), "--out", str(local)).returncode == 0
    # A cluster already running (a notebook's) holds the scheduler's default HTTP port,
    # 8787: the local cluster takes a free one, without a word (it had warned, and failed
    # under -W error).
    with socket.socket() as held:
        with contextlib.suppress(OSError):  # already held: the same case
            held.bind(("127.0.0.1", 8787))
            held.listen()
        done = cli("study", str(path), "--out", str(on_dask), "--dask", "local", "--workers", "2")
    assert done.returncode == 0, done.stderr
    assert "8787" not in done.stderr and "Warning" not in done.stderr, done.stderr
    assert on_dask.read_bytes() == local.read_bytes()


def test_a_killed_study_resumes_from_the_command_line(tmp_path: Path) -> None:
    import signal
    import time

    text = (BASE + STEADY).replace("chunk_size = 7", "chunk_size = 1")
    text = text.replace("settle_periods = 60", "settle_periods = 3000")
    path = scenario(tmp_path, text)
    whole = tmp_path / "whole.nc"
    assert cli("study", str(path), "--out", str(whole), "--workers", "1").returncode == 0
    out = tmp_path / "out.nc"
    parts = out.with_name(out.name + ".parts")
    process = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "vibroimpact",
            "study",
            str(path),
            "--out",
            str(out),
            "--workers",
            "1",
        ],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    deadline = time.monotonic() + 40
    while len(list(parts.glob("chunk-*.npz"))) < 3 and time.monotonic() < deadline:
        time.sleep(0.005)
    process.send_signal(signal.SIGKILL)
    process.wait(timeout=10)
    kept = len(list(parts.glob("chunk-*.npz")))
    assert 3 <= kept < 12 and not out.exists()
    assert cli("study", str(path), "--out", str(out)).returncode == 0
    assert out.read_bytes() == whole.read_bytes()


def test_the_study_command_plots_a_heat_map(tmp_path: Path) -> None:
    path = scenario(tmp_path, BASE + STEADY)
    png = tmp_path / "heat.png"
    done = cli(
        "study",
        str(path),
        "--out",
        str(tmp_path / "r.nc"),
        "--plot",
        str(png),
        "--metric",
        "amplitude",
        "--x",
        "excitation.0.frequency",
        "--y",
        "damper.0.clearance",
    )
    assert done.returncode == 0, done.stderr
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    bad = cli(
        "study", str(path), "--out", str(tmp_path / "s.nc"), "--plot", str(png), "--metric", "speed"
    )
    assert bad.returncode == 2 and "--metric" in bad.stderr and "amplitude" in bad.stderr
    # Without --plot they choose nothing: refused before any run (no output written).
    for flag, value in (("--metric", "amplitude"), ("--x", "damper.0.clearance")):
        out = tmp_path / "unused.nc"
        bare = cli("study", str(path), "--out", str(out), flag, value)
        assert bare.returncode == 2 and not out.exists(), bare.stderr
        assert bare.stderr.strip() == (
            f"vibroimpact: error: {flag} chooses what --plot draws: give --plot FILE.png too"
        )


MONTE_CARLO = """
[study]
analysis = "run"
record_from = 0.1
metrics = ["peak", "impacts"]
samples = 5
seed = 11

[study.axes]
"damper.0.clearance" = [0.004, 0.008]

[study.random]
"damper.0.restitution" = { uniform = [0.3, 0.9] }
"excitation.0.phase" = { normal = [0.0, 1.0] }
"""


def test_monte_carlo_samples_draw_from_the_seed_and_run_each_draw(tmp_path: Path) -> None:
    study = load(scenario(tmp_path, BASE + MONTE_CARLO))
    ds = st.run(study, tmp_path / "out.nc")
    assert dict(ds["peak"].sizes) == {"damper.0.clearance": 2, "sample": 5, "coordinate": 1}
    # The draws: numpy's PCG64 from the seed, in the order of [study.random].
    generator = np.random.default_rng(11)
    restitution = generator.uniform(0.3, 0.9, 5)
    phase = generator.normal(0.0, 1.0, 5)
    assert ds["damper.0.restitution"].values.tolist() == restitution.tolist()
    assert ds["excitation.0.phase"].values.tolist() == phase.tolist()
    for clearance in (0.004, 0.008):
        for k in (0, 3):
            data = without_study(
                study,
                **{
                    "damper.0.clearance": clearance,
                    "damper.0.restitution": float(restitution[k]),
                    "excitation.0.phase": float(phase[k]),
                },
            )
            sol = single_run(data, "exact", record_from=0.1)
            point = ds.sel({"damper.0.clearance": clearance, "sample": k})
            assert point["peak"].values.tolist() == sol.peak.tolist()


@pytest.mark.parametrize(
    ("change", "words"),
    [
        (("samples = 5", "samples = 0"), ["samples", "[study.random]"]),
        (('"excitation.0.phase" = { normal', '"damper.0.clearance" = { normal'), ["also an axis"]),
        (("uniform = [0.3, 0.9]", "uniform = [0.9, 0.3]"), ["low < high"]),
        (("normal = [0.0, 1.0]", "lognormal = [0.0, 1.0]"), ["uniform", "normal"]),
    ],
)
def test_bad_monte_carlo_sections_exit_2(
    tmp_path: Path, change: tuple[str, str], words: list[str]
) -> None:
    text = (BASE + MONTE_CARLO).replace(*change)
    assert text != BASE + MONTE_CARLO
    done = cli("study", str(scenario(tmp_path, text)), "--out", str(tmp_path / "r.nc"))
    assert done.returncode == 2, done.stdout
    assert len(done.stderr.strip().splitlines()) == 1
    for word in words:
        assert word in done.stderr, done.stderr


def test_an_unreachable_dask_scheduler_is_a_usage_error_and_leaves_nothing(
    tmp_path: Path,
) -> None:
    path = scenario(tmp_path, BASE + STEADY)
    out = tmp_path / "r.nc"
    done = cli("study", str(path), "--out", str(out), "--dask", "tcp://127.0.0.1:9")
    assert done.returncode == 2, done.stderr
    assert len(done.stderr.strip().splitlines()) == 1 and "--dask" in done.stderr
    assert not out.exists() and not out.with_name(out.name + ".parts").exists()


@pytest.mark.parametrize(
    ("args", "text", "words"),
    [
        (["--dask", "lcoal"], BASE + STEADY, ["--dask lcoal", "tcp://HOST:8786"]),
        ([], (BASE + STEADY).replace("metrics =", "metric ="), ["did you mean 'metrics'"]),
        (
            ["--plot", "p.png"],
            (BASE + STEADY).replace('"excitation.0.frequency" = [9.0, 10.0, 11.0]\n', ""),
            ["two axes", "has one"],
        ),
    ],
    ids=["misspelt dask address", "misspelt metrics key", "plot of one axis"],
)
def test_study_mistakes_found_by_a_new_user_exit_2(
    tmp_path: Path, args: list[str], text: str, words: list[str]
) -> None:
    out = tmp_path / "r.nc"
    done = cli("study", str(scenario(tmp_path, text)), "--out", str(out), *args)
    assert done.returncode == 2, done.stderr
    assert len(done.stderr.strip().splitlines()) == 1 and "Traceback" not in done.stderr
    for word in words:
        assert word in done.stderr, done.stderr
    assert not out.exists() and not out.with_name(out.name + ".parts").exists()


def test_a_study_into_a_missing_folder_is_refused(tmp_path: Path) -> None:
    out = tmp_path / "missing" / "r.nc"
    done = cli("study", str(scenario(tmp_path, BASE + STEADY)), "--out", str(out))
    assert done.returncode == 2 and "does not exist" in done.stderr, done.stderr
    assert not (tmp_path / "missing").exists()


def test_the_axes_carry_their_units(tmp_path: Path) -> None:
    ds = st.run(load(scenario(tmp_path, BASE + STEADY)), tmp_path / "out.nc")
    assert ds["damper.0.clearance"].attrs["units"] == "m"
    assert ds["excitation.0.frequency"].attrs["units"] == "Hz"
    with xr.open_dataset(tmp_path / "out.nc") as back:
        assert back["excitation.0.frequency"].attrs["units"] == "Hz"


@pytest.mark.parametrize("method", ["exact", "dop853", "newmark-implicit"])
def test_a_study_of_starts_equals_the_runs_made_one_by_one(tmp_path: Path, method: str) -> None:
    # Only the start varies: the runs share one system and, on each thread, one method,
    # which must start afresh every run (an adaptive step or a Newmark acceleration
    # left over from the last run would change the next).
    solver = f'method = "{method}"\ndt = 1e-3\n' if method != "exact" else 'method = "exact"\n'
    text = BASE.replace('method = "exact"\n', solver) + (
        '[study]\nanalysis = "run"\nmetrics = ["peak", "rms", "impacts", "energy_dissipated"]\n'
        '[study.axes]\n"initial.structure_velocity.0" = [0.3, -0.2, 0.0, 0.25, -0.1]\n'
    )
    study = load(scenario(tmp_path, text))
    ds = st.run(study, tmp_path / "out.nc", threads=2)
    data = without_study(study)
    for velocity in (0.3, -0.2, 0.0, 0.25, -0.1):
        sol = vi.simulate_system(
            data["structure"],
            damper=data["damper"],
            excitation=data["excitation"],
            initial={"structure_velocity": [velocity]},
            method=method,
            dt=None if method == "exact" else 1e-3,
            t_end=0.5,
            history=False,
            record_from=0.0,
        )
        point = ds.sel({"initial.structure_velocity.0": velocity})
        assert point["peak"].values.tolist() == sol.peak.tolist(), method
        assert point["impacts"].item() == sum(k != "sticking" for k in sol.contacts.kind)


def test_newmark_peaks_do_not_depend_on_whether_rms_is_kept(tmp_path: Path) -> None:
    text = BASE.replace('method = "exact"\n', 'method = "newmark-implicit"\ndt = 1e-3\n') + (
        '[study]\nanalysis = "run"\nmetrics = ["peak"]\n'
        '[study.axes]\n"initial.structure_velocity.0" = [0.3, -0.2]\n'
    )
    peaks = st.run(load(scenario(tmp_path, text)), tmp_path / "a.nc")["peak"].values
    with_rms = text.replace('metrics = ["peak"]', 'metrics = ["peak", "rms"]')
    other = st.run(load(scenario(tmp_path, with_rms, "b.toml")), tmp_path / "b.nc")
    assert peaks.tolist() == other["peak"].values.tolist()


@pytest.mark.parametrize("key", ["settle_periods", "record_periods", "orbit_periods"])
def test_forcing_periods_beyond_the_analyses_limit_are_refused_when_read(
    tmp_path: Path, key: str
) -> None:
    # 1e11 settle periods ran for half a minute into gigabytes of contacts (user trial);
    # the analyses' own settings are held to 1e7 periods.
    analysis = "orbit" if key == "orbit_periods" else "steady-state"
    text = BASE + (
        f'[study]\nanalysis = "{analysis}"\n{key} = 100000000000\n'
        '[study.axes]\n"damper.0.mass" = [0.05]\n'
    )
    with pytest.raises(ValueError, match=rf"\[study\] {key}: must be at most 10000000"):
        load(scenario(tmp_path, text))


STUDY_TAIL = (
    '[study]\nanalysis = "run"\nmetrics = ["peak"]\n[study.axes]\n"damper.0.mass" = [0.05]\n'
)


def test_threads_out_of_range_are_refused(tmp_path: Path) -> None:
    # threads=-1 overflowed in the binding; 100000 spawned that many threads (user trial).
    study = load(scenario(tmp_path, BASE + STUDY_TAIL))
    for threads in (-1, 100_000, 2.5, True):
        with pytest.raises(st.StudyError, match="threads: must be"):
            st.run(study, tmp_path / "out.nc", threads=threads)  # type: ignore[arg-type]
    assert not (tmp_path / "out.nc").exists()


def test_a_recorded_signals_file_is_part_of_the_studys_identity(tmp_path: Path) -> None:
    # An interrupted study resumed after its CSV changed mixed the two signals in one
    # file (user trial): the file's contents are in the input hash.
    (tmp_path / "force.csv").write_text("0,0\n1,1\n", encoding="utf-8")
    text = (
        BASE.replace('signal = "harmonic"', 'signal = "recorded"\nfile = "force.csv"')
        .replace("amplitude = 5.0\n", "")
        .replace("frequency = 10.0\n", "")
        .replace('method = "exact"', 'method = "dop853"')
        + STUDY_TAIL
    )
    first = load(scenario(tmp_path, text)).fingerprint()
    assert load(scenario(tmp_path, text)).fingerprint() == first
    (tmp_path / "force.csv").write_text("0,0\n1,2\n", encoding="utf-8")
    assert load(scenario(tmp_path, text)).fingerprint() != first


def test_a_study_the_method_cannot_take_is_refused_before_any_run(tmp_path: Path) -> None:
    # Every run would fail alike (no axis changes a signal's kind): it ran them all
    # and exited 1 (user trial). The exact flow takes harmonic signals only.
    noise = 'signal = "white-noise"\nintensity = 0.01\ncutoff_frequency = 50.0\nseed = 1'
    text = BASE.replace('signal = "harmonic"\namplitude = 5.0\nfrequency = 10.0', noise)
    assert text != BASE
    text += '[study]\nanalysis = "run"\n[study.axes]\n"damper.0.mass" = [0.01, 0.02]\n'
    done = cli("study", str(scenario(tmp_path, text)), "--out", str(tmp_path / "r.nc"))
    assert_refused(done, ['method "exact" takes harmonic', "dop853"], tmp_path / "r.nc")


def test_the_heat_map_of_a_study_whose_every_run_failed(tmp_path: Path) -> None:
    # np.nanargmin of an all-NaN map had ended `study --plot` with a traceback after
    # the file was written (trial); the map is drawn empty and says why.
    from vibroimpact.analysis.plots import plot_study

    axes = {"damper.0.mass": [0.1, 0.2], "damper.0.clearance": [1e-3, 2e-3, 3e-3]}
    dataset = xr.Dataset(
        {"peak": (tuple(axes), np.full((2, 3), np.nan))},
        coords={name: values for name, values in axes.items()},
    )
    png = tmp_path / "heat.png"
    plot_study(png, dataset, "peak", "damper.0.mass", "damper.0.clearance")
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_an_output_that_is_a_folder_is_refused_before_any_run(tmp_path: Path) -> None:
    # The command refused it up front; the Python call ran every run first, then failed,
    # and its note's way to resume failed the same way.
    study = load(scenario(tmp_path, BASE + STEADY))
    folder = tmp_path / "result.nc"
    folder.mkdir()
    progressed: list[int] = []
    with pytest.raises(ValueError, match="not a regular file"):
        st.run(study, folder, progress=lambda done, total, rate: progressed.append(done))
    assert progressed == [] and list(folder.iterdir()) == []


def test_a_scenario_read_by_a_relative_path_keeps_its_folder_wherever_the_runs_are(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # A recorded signal's relative file is read from the scenario's folder: that folder
    # had been kept as "." when the scenario was named relative to the current folder, so
    # a Dask worker started elsewhere did not find the file.
    folder = tmp_path / "case"
    folder.mkdir()
    (folder / "force.csv").write_text("time,value\n0,0\n0.1,5\n0.5,0\n")
    text = BASE.replace(
        'signal = "harmonic"\namplitude = 5.0\nfrequency = 10.0',
        'signal = "recorded"\nfile = "force.csv"',
    )
    text = text.replace('method = "exact"', 'method = "dop853"')
    text += '\n[study]\nanalysis = "run"\nmetrics = ["peak"]\n'
    text += '[study.axes]\n"damper.0.clearance" = [0.002, 0.004]\n'
    (folder / "study.toml").write_text(text)
    monkeypatch.chdir(folder)
    study = load(Path("study.toml"))
    monkeypatch.chdir(tmp_path)  # where a worker might run
    done = st.run(study, tmp_path / "out.nc")
    assert (done["status"].values == 0).all(), done.attrs.get("reasons")
    assert (done["peak"].values > 0).all()


# The forced damper's oscillator and force without the damper, by RK4 at dt = 1 ms.
LINEAR = (
    BASE.replace(BASE[BASE.index("[[damper]]") : BASE.index("[[excitation]]")], "")
    .replace('method = "exact"', 'method = "rk4"\ndt = 0.001')
    .replace("t_end = 0.5", "t_end = 0.2")
)


@pytest.mark.parametrize("stepping", ["events", "fixed"])
def test_a_point_whose_forcing_its_step_cannot_sample_fails_as_its_run_is_refused(
    tmp_path: Path, stepping: str
) -> None:
    # 2 kHz sampled by dt = 1e-3 s falls at one phase at every stage: a constant load. A
    # single run of the point is refused; the study had run it (status 0, a "settled"
    # amplitude of 126 m where the closed form gives micrometres).
    text = LINEAR + f'[study]\nanalysis = "run"\nstepping = "{stepping}"\nmetrics = ["peak"]\n'
    text += '[study.axes]\n"excitation.0.frequency" = [10.0, 2000.0]\n'
    done = st.run(load(scenario(tmp_path, text)), tmp_path / "out.nc")
    assert done["status"].values.tolist() == [0, 1]
    reasons = json.loads(done.attrs["reasons"])
    assert len(reasons) == 1 and "sampled below two steps of dt" in reasons[0], reasons
    alone = vi.simulate(vi.loads(LINEAR), stepping=stepping, history=False, record_from=0.0)
    assert done["peak"].values[0][0] == alone.peak[0]


@pytest.mark.parametrize("where", ["output", "study"])
def test_a_record_window_shorter_than_a_fixed_step_is_refused(tmp_path: Path, where: str) -> None:
    # No fixed step ends in it: the run recorded nothing, a peak of NaN (a study's lanes:
    # 0.0) with status 0.
    window = "record_from = 0.1995\n"
    if where == "output":
        text = LINEAR.replace("t_end = 0.2\n", 't_end = 0.2\nstepping = "fixed"\n')
        text += f"[output]\n{window}"
        with pytest.raises(ValueError, match=r"record_from: must leave at least one step"):
            vi.loads(text)
        return
    text = LINEAR + f'[study]\nanalysis = "run"\nstepping = "fixed"\n{window}metrics = ["peak"]\n'
    text += '[study.axes]\n"excitation.0.frequency" = [10.0]\n'
    with pytest.raises(ValueError, match=r"\[study\] record_from: must leave at least one step"):
        load(scenario(tmp_path, text))
