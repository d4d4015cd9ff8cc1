"""Studies of random excitations and of the structure: a seed per run (an axis, or one
per Monte Carlo sample), a random signal's intensity and other inputs, and the
structure's inputs, each run the same bit for bit as the run made one by one with those
values; a Monte Carlo of white-noise base excitation against the closed form of random
vibration; bad values and paths refused naming the key."""

from __future__ import annotations

import json
import math
import subprocess
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import vibroimpact as vi
from study_checks import assert_refused  # noqa: E402
from vibroimpact import study as st
from vibroimpact.analysis import with_parameter
from vibroimpact.scenario.system import SystemScenario

# A loose mass rattling in an oscillator shaken at its base by white noise.
NOISY = """
[structure]
kind = "oscillator"
mass = 1.0
stiffness = 3947.8
damping = 2.513

[[damper]]
mass = 0.05
at = 0
clearance = 0.0005
law = "rigid"
restitution = 0.6

[[excitation]]
kind = "base"
signal = "white-noise"
intensity = 0.02
cutoff_frequency = 40.0
seed = 5

[solver]
method = "dop853"
t_end = 1.0

[study]
analysis = "run"
record_from = 0.2
metrics = ["peak", "rms", "impacts", "energy_dissipated"]
chunk_size = 3
"""


Write = Callable[..., Path]
Cli = Callable[..., subprocess.CompletedProcess[str]]


def load(path: Path) -> st.Study:
    sc = vi.load_scenario(path)
    assert isinstance(sc, SystemScenario)
    return st.study_of(sc.data, str(path), sc.base_dir)


def one_by_one(study: st.Study, **changes: float) -> vi.SystemSolution:
    """The run a scenario written with ``changes`` makes."""
    data = {k: v for k, v in study.data.items() if k != "study"}
    for path, value in changes.items():
        data = with_parameter(data, path, value)
    solver = data["solver"]
    return vi.simulate_system(
        data["structure"],
        damper=data.get("damper", ()),
        excitation=data.get("excitation", ()),
        method=solver["method"],
        dt=solver.get("dt"),
        t_end=solver["t_end"],
        history=False,
        record_from=study.settings["record_from"],
    )


def assert_same_run(point: Any, sol: vi.SystemSolution) -> None:
    """A study's point is the run ``sol``, to the last bit."""
    assert point["peak"].values.tolist() == sol.peak.tolist()
    assert point["rms"].values.tolist() == sol.rms.tolist()
    if "impacts" in point:
        record_from = 0.2
        recorded = [
            kind
            for kind, onset in zip(sol.contacts.kind, sol.contacts.onset, strict=True)
            if onset >= record_from
        ]
        assert point["impacts"].item() == sum(k != "sticking" for k in recorded)


def test_a_seed_axis_equals_the_runs_made_one_by_one(tmp_path: Path, write_scenario: Write) -> None:
    text = NOISY + (
        '[study.axes]\n"excitation.0.seed" = [0, 5, 11, 9007199254740992]\n'
        '"excitation.0.intensity" = [0.01, 0.02]\n'
    )
    study = load(write_scenario(text))
    ds = st.run(study, tmp_path / "out.nc", threads=2)
    assert int(ds["status"].max()) == 0
    for seed in (0, 5, 11, 2**53):
        for intensity in (0.01, 0.02):
            sol = one_by_one(
                study, **{"excitation.0.seed": seed, "excitation.0.intensity": intensity}
            )
            assert len(sol.contacts.onset) > 0  # the loose mass does rattle
            point = ds.sel({"excitation.0.seed": seed, "excitation.0.intensity": intensity})
            assert_same_run(point, sol)
    assert ds["excitation.0.seed"].attrs["units"] == "1"
    assert ds["excitation.0.intensity"].attrs["units"] == "m2 s-3"


def test_seeds_differ_and_repeat_whatever_the_threads_and_chunks(
    tmp_path: Path, write_scenario: Write
) -> None:
    text = NOISY + '[study.axes]\n"excitation.0.seed" = [1, 2, 1, 3, 2]\n'
    study = load(write_scenario(text))
    one = study.run_chunk(range(0, study.runs), threads=1)
    two = study.run_chunk(range(0, study.runs), threads=2)
    for key in ("peak", "rms", "impacts", "energy_dissipated"):
        assert np.array_equal(np.asarray(one[key]), np.asarray(two[key])), key
    rms = np.asarray(one["rms"])
    assert rms[0] == rms[2] and rms[1] == rms[4]
    assert len({rms[0], rms[1], rms[3]}) == 3
    # Chunks of 3 runs (the file) against chunks of 1.
    whole = tmp_path / "whole.nc"
    st.run(study, whole)
    single = load(write_scenario(text.replace("chunk_size = 3", "chunk_size = 1"), "b.toml"))
    ds = st.run(single, tmp_path / "single.nc", threads=1)
    import xarray as xr

    with xr.open_dataset(whole) as back:
        assert back["rms"].values.tolist() == ds["rms"].values.tolist()


def test_kanai_tajimi_inputs_as_axes_equal_the_runs_made_one_by_one(
    tmp_path: Path, write_scenario: Write
) -> None:
    text = NOISY.replace(
        'signal = "white-noise"',
        'signal = "kanai-tajimi"\nground_frequency = 5.0\nground_damping = 0.6',
    ) + (
        '[study.axes]\n"excitation.0.seed" = [3, 4]\n'
        '"excitation.0.ground_frequency" = [4.0, 8.0]\n'
        '"excitation.0.cutoff_frequency" = [30.0]\n'
    )
    study = load(write_scenario(text))
    ds = st.run(study, tmp_path / "out.nc")
    for seed in (3, 4):
        for ground in (4.0, 8.0):
            changes = {
                "excitation.0.seed": seed,
                "excitation.0.ground_frequency": ground,
                "excitation.0.cutoff_frequency": 30.0,
            }
            assert_same_run(ds.sel(changes), one_by_one(study, **changes))
    assert ds["excitation.0.ground_frequency"].attrs["units"] == "Hz"


def test_a_seed_per_monte_carlo_sample(tmp_path: Path, write_scenario: Write) -> None:
    text = NOISY + (
        "samples = 4\nseed = 2\n"
        '[study.axes]\n"damper.0.restitution" = [0.5]\n'
        "[study.random]\n"
        '"excitation.0.intensity" = { uniform = [0.01, 0.03] }\n'
        '"excitation.0.seed" = { from = 100 }\n'
    )
    study = load(write_scenario(text))
    ds = st.run(study, tmp_path / "out.nc")
    assert ds["excitation.0.seed"].values.tolist() == [100.0, 101.0, 102.0, 103.0]
    # The seeds take no draw: the intensities are numpy's first draws from the seed.
    intensity = np.random.default_rng(2).uniform(0.01, 0.03, 4)
    assert ds["excitation.0.intensity"].values.tolist() == intensity.tolist()
    for k in (0, 3):
        sol = one_by_one(
            study,
            **{
                "damper.0.restitution": 0.5,
                "excitation.0.seed": 100 + k,
                "excitation.0.intensity": float(intensity[k]),
            },
        )
        assert_same_run(ds.sel({"damper.0.restitution": 0.5, "sample": k}), sol)


# A linear oscillator (no damper: no contact) under white-noise base acceleration.
LINEAR = """
[structure]
kind = "oscillator"
mass = 1.0
stiffness = {stiffness}
damping = {damping}

[[excitation]]
kind = "base"
signal = "white-noise"
intensity = {intensity}
cutoff_frequency = {cutoff}
seed = 0

[solver]
method = "rk4"
dt = 0.0025
t_end = {t_end}

[study]
analysis = "run"
record_from = {record_from}
metrics = ["rms"]
chunk_size = 100000

[study.axes]
"excitation.0.seed" = {{ start = 0, stop = {last}, count = {runs} }}
"""


@pytest.mark.timeout(120)
def test_a_monte_carlo_of_white_noise_matches_random_vibration_theory(
    tmp_path: Path, write_scenario: Write
) -> None:
    """The relative displacement x of an oscillator (natural frequency wn, damping
    ratio zeta) under a base acceleration of two-sided spectral density S0 per rad/s
    has the variance sigma^2 = int S0 |H|^2 dw = pi S0 / (2 zeta wn^3).

    Estimate: the mean over N seeds of each run's mean square over T s (recorded after
    5 s, 9 time constants 1 / (zeta wn) of the start from rest). For a narrow-band
    Gaussian x, Var((1/T) int x^2 dt) = (2/T) int R(tau)^2 dtau = sigma^4 / (zeta wn T),
    so the mean's relative standard error is 1 / sqrt(N zeta wn T): 1.0 % here. The
    tolerance is 4 standard errors (4 %). The biases are far smaller: the signal's
    linear interpolation of its samples every pi / wc s filters the density by
    sinc^4(w pi / (2 wc)), 0.26 % at wn; the unrecorded start leaves e^(-2 zeta wn 5 s) =
    0.2 % of the variance, decaying; RK4's error at wn dt = 0.03 is ~1e-8."""
    zeta, fn, s0, cutoff = 0.05, 2.0, 1e-4, 50.0
    wn = 2 * math.pi * fn
    runs, recorded = 400, 40.0
    text = LINEAR.format(
        stiffness=wn**2,
        damping=2 * zeta * wn,
        intensity=s0,
        cutoff=cutoff,
        t_end=5.0 + recorded,
        record_from=5.0,
        last=runs - 1,
        runs=runs,
    )
    study = load(write_scenario(text))
    raw = study.run_chunk(range(0, study.runs), threads=0)
    assert not np.asarray(raw["status"]).any()
    mean_squares = np.asarray(raw["rms"]) ** 2
    closed_form = math.pi * s0 / (2 * zeta * wn**3)
    standard_error = 1 / math.sqrt(runs * zeta * wn * recorded)
    ratio = mean_squares.mean() / closed_form
    assert abs(ratio - 1) < 4 * standard_error, (ratio, standard_error)
    # The scatter between seeds is the one the derivation predicts (within 20 %).
    observed = mean_squares.std(ddof=1) / math.sqrt(runs) / closed_form
    assert 0.8 < observed / standard_error < 1.2, (observed, standard_error)


OSCILLATOR_AXES = """
[study.axes]
"structure.mass" = [0.8, 1.2]
"structure.stiffness" = [3000.0, 4500.0]
"structure.damping" = [0.0, 5.0]
"""


def test_oscillator_axes_equal_the_runs_made_one_by_one(
    tmp_path: Path, write_scenario: Write
) -> None:
    study = load(write_scenario(NOISY + OSCILLATOR_AXES))
    ds = st.run(study, tmp_path / "out.nc", threads=2)
    assert int(ds["status"].max()) == 0
    for mass in (0.8, 1.2):
        for stiffness in (3000.0, 4500.0):
            for damping in (0.0, 5.0):
                changes = {
                    "structure.mass": mass,
                    "structure.stiffness": stiffness,
                    "structure.damping": damping,
                }
                assert_same_run(ds.sel(changes), one_by_one(study, **changes))
    units = {path: ds[path].attrs["units"] for path in ("structure.mass", "structure.stiffness")}
    assert units == {"structure.mass": "kg", "structure.stiffness": "N m-1"}
    assert ds["structure.damping"].attrs["units"] == "N s m-1"


BEAM = """
[structure]
kind = "cantilever"
length = 0.5
youngs_modulus = 7e10
second_moment = 1e-10
mass_per_length = 0.27
modes = 2
damping_ratio = 0.01

[[damper]]
mass = 0.01
at = 0.3
clearance = 2e-4
law = "hertz-damped"
stiffness = 1e7
restitution = 0.6

[[excitation]]
kind = "force"
at = 0.3
signal = "harmonic"
amplitude = 0.5
frequency = 8.0

[solver]
method = "dop853"
t_end = 0.3

[study]
analysis = "run"
record_from = 0.2
metrics = ["peak", "rms", "impacts"]

[study.axes]
"structure.length" = [0.4, 0.5, 0.2]
"structure.youngs_modulus" = [7e10, 2e11]
"structure.mass_per_length" = [0.27]
"structure.damping_ratio" = [0.01, 0.05]
"""


def test_cantilever_axes_equal_the_runs_made_one_by_one(
    tmp_path: Path, write_scenario: Write
) -> None:
    study = load(write_scenario(BEAM))
    ds = st.run(study, tmp_path / "out.nc")
    for length in (0.4, 0.5):
        for modulus in (7e10, 2e11):
            for ratio in (0.01, 0.05):
                changes = {
                    "structure.length": length,
                    "structure.youngs_modulus": modulus,
                    "structure.mass_per_length": 0.27,
                    "structure.damping_ratio": ratio,
                }
                assert_same_run(ds.sel(changes), one_by_one(study, **changes))
    # A beam shorter than the damper's point fails those runs alone, saying why.
    status = ds["status"].sel({"structure.length": 0.2})
    assert (status > 0).all() and int(ds["status"].sel({"structure.length": 0.4}).max()) == 0
    reasons = json.loads(ds.attrs["reasons"])
    assert len(reasons) == 1 and "damper 0" in reasons[0] and "0.2" in reasons[0]
    assert ds["structure.youngs_modulus"].attrs["units"] == "Pa"


@pytest.mark.parametrize(
    ("path", "values", "words"),
    [
        ("structure.mass", "[1.0, -1.0, 1.1]", ["structure.mass", "> 0", "-1"]),
        ("structure.damping", "[0.5, -2.0, 1.0]", ["structure.damping", ">= 0", "-2"]),
        ("excitation.0.intensity", "[0.01, -1.0, 0.02]", ["excitation.0.intensity", "-1"]),
        ("excitation.0.cutoff_frequency", "[40.0, 0.0, 30.0]", ["excitation.0.cutoff"]),
    ],
)
def test_a_bad_value_fails_its_run_alone_naming_the_key(
    tmp_path: Path, write_scenario: Write, path: str, values: str, words: list[str]
) -> None:
    text = NOISY + f'[study.axes]\n"{path}" = {values}\n'
    ds = st.run(load(write_scenario(text)), tmp_path / "out.nc")
    assert ds["status"].values.tolist() == [0, 1, 0]
    reasons = json.loads(ds.attrs["reasons"])
    assert len(reasons) == 1
    for word in words:
        assert word in reasons[0], reasons[0]
    assert np.isnan(ds["rms"].values[1]).all() and np.isfinite(ds["rms"].values[[0, 2]]).all()


MATRICES = NOISY.replace(
    'kind = "oscillator"\nmass = 1.0\nstiffness = 3947.8\ndamping = 2.513',
    'kind = "matrices"\nmass = [[1.0]]\nstiffness = [[3947.8]]\ndamping = [[2.513]]',
)


@pytest.mark.parametrize(
    ("text", "axis", "words"),
    [
        (NOISY, '"structure.mas" = [1.0]', ["structure.mas", "did you mean 'mass'"]),
        (NOISY, '"structure.length" = [1.0]', ["structure.length", "allowed", "mass"]),
        (BEAM, '"structure.modes" = [3]', ["structure.modes", "cantilever", "mass_per_length"]),
        (MATRICES, '"structure.mass" = [1.0]', ["structure.mass", "matrices"]),
        (NOISY, '"excitation.0.seed" = [1, 2.5]', ["excitation.0.seed", "whole number", "2.5"]),
        (NOISY, '"excitation.0.seed" = [-1]', ["excitation.0.seed", "whole number"]),
        (NOISY, '"excitation.0.ground_damping" = [0.5]', ["ground_damping", "white-noise"]),
        (NOISY, '"excitation.0.frequency" = [1.0]', ["excitation.0.frequency", "intensity"]),
        (BEAM, '"excitation.0.seed" = [1]', ["excitation.0.seed", "allowed"]),
    ],
)
def test_bad_paths_and_seeds_exit_2_naming_the_key(
    tmp_path: Path, write_scenario: Write, run_cli: Cli, text: str, axis: str, words: list[str]
) -> None:
    if "[study.axes]" in text:
        text = text.split("[study.axes]")[0]
    path = write_scenario(f"{text}[study.axes]\n{axis}\n")
    done = run_cli("study", str(path), "--out", str(tmp_path / "r.nc"))
    assert_refused(done, words, tmp_path / "r.nc")


@pytest.mark.parametrize(
    ("entry", "words"),
    [
        ("{ uniform = [0, 10] }", ["excitation.0.seed", "from = N"]),
        ("{ from = -3 }", ["excitation.0.seed", "whole number"]),
        ('{ from = "a" }', ["excitation.0.seed", "from = N"]),
    ],
)
def test_a_random_seed_must_count_from_a_whole_number(
    tmp_path: Path, write_scenario: Write, run_cli: Cli, entry: str, words: list[str]
) -> None:
    text = NOISY + (
        'samples = 3\n[study.axes]\n"damper.0.mass" = [0.05]\n'
        f'[study.random]\n"excitation.0.seed" = {entry}\n'
    )
    done = run_cli("study", str(write_scenario(text)), "--out", str(tmp_path / "r.nc"))
    assert done.returncode == 2, done.stdout + done.stderr
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1, done.stderr
    for word in words:
        assert word in lines[0], lines[0]


@pytest.mark.timeout(120)
def test_a_seed_study_on_a_local_dask_cluster_writes_the_same_file(
    tmp_path: Path, write_scenario: Write, run_cli: Cli
) -> None:
    text = NOISY + '[study.axes]\n"excitation.0.seed" = [1, 2, 3, 4, 5]\n'
    path = write_scenario(text)
    local, on_dask = tmp_path / "local.nc", tmp_path / "dask.nc"
    assert run_cli("study", str(path), "--out", str(local), "--workers", "1").returncode == 0
    done = run_cli(
        "study", str(path), "--out", str(on_dask), "--dask", "local", "--workers", "2", timeout=100
    )
    assert done.returncode == 0, done.stderr
    assert on_dask.read_bytes() == local.read_bytes()
