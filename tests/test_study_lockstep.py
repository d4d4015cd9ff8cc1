"""Studies with ``stepping = "fixed"``: the runs advanced in lockstep by the core's
ensemble kernel. Each run is the fixed-step RK4 run that ``vi.simulate`` makes of the
same two-mass damper, bit for bit (its contacts, and its history's peak and RMS); the
event-driven study of the same grid agrees to the methods' accuracy; the same results
whatever the number of threads; a run that blows up fails alone; scenarios the kernel
cannot take are refused naming the key."""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import vibroimpact as vi
from study_checks import assert_refused, load_study  # noqa: E402
from vibroimpact import study as st

M, K, C, MD, D, KHZ, C1 = 1.0, 1.0, 0.01, 0.25, 0.01, 3000.0, 0.01
DT, T_END = 1e-4, 3.0

BASE = f"""
[structure]
kind = "oscillator"
mass = {M}
stiffness = {K}
damping = {C}

[[damper]]
mass = {MD}
at = 0
clearance = {D}
law = "hertz"
stiffness = {KHZ}
damping = {C1}

[solver]
method = "rk4"
dt = {DT}
t_end = {T_END}
"""

STUDY = """
[study]
analysis = "run"
stepping = "fixed"
metrics = ["peak", "rms", "impacts"]
chunk_size = 5

[study.axes]
"initial.damper_velocity.0" = [0.06, 0.1, 0.14]
"damper.0.clearance" = [0.005, 0.01, 0.02]
"""


def load(tmp_path: Path, text: str) -> st.Study:
    return load_study(tmp_path / "study.toml", text)


def test_each_run_is_the_fixed_step_kernels_run(tmp_path: Path) -> None:
    ds = st.run(load(tmp_path, BASE + STUDY), tmp_path / "out.nc", threads=2)
    assert int(ds["status"].max()) == 0
    for velocity in (0.06, 0.1, 0.14):
        for clearance in (0.005, 0.01, 0.02):
            sol = vi.simulate(
                vi.ImpactDamper(
                    main_mass=M, stiffness=K, damping=C, impact_mass=MD, clearance=clearance
                ),
                vi.Contact("hertz", stiffness=KHZ, damping=C1),
                vi.InitialState(impact_velocity=velocity),
                method="rk4",
                stepping="fixed",
                dt=DT,
                t_end=T_END,
            )
            point = ds.sel({"initial.damper_velocity.0": velocity, "damper.0.clearance": clearance})
            assert point["impacts"].item() == len(sol.contacts.onset) > 0
            w = sol.main_displacement
            # RMS: the trapezoidal rule over the same step ends.
            rms = np.sqrt(np.trapezoid(w * w, dx=DT) / T_END)
            assert point["rms"].item() == pytest.approx(rms, rel=1e-12)
            # Peak: at least the largest step end, above it only by the located
            # extremum inside a step (the curvature over one step: ~ (w dt)^2).
            peak = point["peak"].item()
            assert np.abs(w).max() <= peak <= np.abs(w).max() * (1 + 1e-7)


def test_fixed_and_event_stepping_agree_to_the_methods_accuracy(tmp_path: Path) -> None:
    fixed = st.run(load(tmp_path, BASE + STUDY), tmp_path / "fixed.nc")
    events = st.run(
        load(tmp_path, BASE + STUDY.replace('stepping = "fixed"', 'stepping = "events"')),
        tmp_path / "events.nc",
    )
    assert np.array_equal(fixed["impacts"].values, events["impacts"].values)
    # The fixed steps run through each contact onset, where the contact damper's force
    # jumps (first order there); the event-driven steps end on it.
    for key in ("peak", "rms"):
        assert np.allclose(fixed[key].values, events[key].values, rtol=1e-5, atol=0), key
        assert not np.array_equal(fixed[key].values, events[key].values), key


def test_results_do_not_depend_on_the_number_of_threads(tmp_path: Path) -> None:
    study = load(tmp_path, BASE + STUDY)
    one = study.run_chunk(range(0, study.runs), threads=1)
    two = study.run_chunk(range(1, study.runs), threads=2)
    for key in ("peak", "rms", "impacts"):
        a, b = np.asarray(one[key]), np.asarray(two[key])
        assert np.array_equal(a[1:], b), key


def test_a_run_that_blows_up_fails_alone(tmp_path: Path) -> None:
    text = BASE + STUDY.replace(
        '"damper.0.clearance" = [0.005, 0.01, 0.02]',
        '"damper.0.stiffness" = [3000.0, 1e13, 3000.0]',
    )
    ds = st.run(load(tmp_path, text), tmp_path / "out.nc")
    status = ds["status"].values
    assert (status[:, 1] > 0).all() and (status[:, [0, 2]] == 0).all()
    reasons = json.loads(ds.attrs["reasons"])
    assert reasons and all("reduce dt" in r for r in reasons)
    assert np.isnan(ds["peak"].values[:, 1]).all()


def test_a_run_that_creates_energy_fails_alone(tmp_path: Path) -> None:
    # A linear contact of 1e6 N/m on the 0.25 kg mass (2000 rad/s) at dt = 1e-2 s:
    # RK4 is unstable across the contact, which rebounds with thousands of times the
    # energy it met, and the run ends (0.5 s) before a second contact could overflow
    # it: the check finds growth, not a state no longer finite. At 100 N/m
    # (20 rad/s) the step is stable. The single-run kernel refuses the same run.
    text = BASE.replace('law = "hertz"', 'law = "linear"').replace(
        f"dt = {DT}", "dt = 1e-2"
    ).replace(f"t_end = {T_END}", "t_end = 0.5") + STUDY.replace(
        '"damper.0.clearance" = [0.005, 0.01, 0.02]', '"damper.0.stiffness" = [100.0, 1e6]'
    )
    ds = st.run(load(tmp_path, text), tmp_path / "out.nc")
    status = ds["status"].values
    assert (status[:, 0] == 0).all() and (status[:, 1] > 0).all()
    reasons = json.loads(ds.attrs["reasons"])
    assert reasons and all("energy created" in r for r in reasons), reasons
    assert np.isnan(ds["peak"].values[:, 1]).all()
    with pytest.raises(vi.EnergyBalanceError):
        vi.simulate(
            vi.ImpactDamper(main_mass=M, stiffness=K, damping=C, impact_mass=MD, clearance=D),
            vi.Contact("linear", stiffness=1e6, damping=C1),
            vi.InitialState(impact_velocity=0.1),
            method="rk4",
            stepping="fixed",
            dt=1e-2,
            t_end=0.5,
        )


@pytest.mark.parametrize(
    ("change", "words"),
    [
        (('stepping = "fixed"', 'stepping = "lockstep"'), ["stepping", "fixed"]),
        (
            ('metrics = ["peak", "rms", "impacts"]', 'metrics = ["energy_dissipated"]'),
            ["energy_dissipated", "stepping"],
        ),
        (('analysis = "run"', 'analysis = "steady-state"'), ["stepping", "analysis"]),
        (('method = "rk4"', 'method = "dop853"'), ["stepping", "rk4"]),
        (
            (
                f'law = "hertz"\nstiffness = {KHZ}\ndamping = {C1}',
                'law = "rigid"\nrestitution = 0.5',
            ),
            ["stepping", "rigid"],
        ),
        (
            ("clearance = 0.01", "lower_clearance = 0.01\nupper_clearance = 0.02"),
            ["stepping", "clearances"],
        ),
        (("[solver]", "[gravity]\n[solver]"), ["stepping", "gravity"]),
    ],
)
def test_what_the_lockstep_kernel_cannot_take_exits_2_naming_the_key(
    tmp_path: Path, run_cli: Callable[..., Any], change: tuple[str, str], words: list[str]
) -> None:
    text = (BASE + STUDY).replace(*change)
    assert text != BASE + STUDY
    path = tmp_path / "study.toml"
    path.write_text(text)
    done = run_cli("study", str(path), "--out", str(tmp_path / "r.nc"))
    assert_refused(done, words, tmp_path / "r.nc")


def test_the_readme_lockstep_block_runs(tmp_path: Path) -> None:
    readme = (Path(__file__).resolve().parents[1] / "README.md").read_text()
    section = readme.split("### Lockstep ensembles", 1)[1].split("\n## ", 1)[0]
    block = section.split("```toml\n", 1)[1].split("```", 1)[0]
    # Fewer runs than the README's 10000, to keep the test short.
    assert "count = 10000" in block
    ds = st.run(
        load(tmp_path, BASE + block.replace("count = 10000", "count = 16")), tmp_path / "r.nc"
    )
    assert int(ds["status"].max()) == 0
    assert (ds["impacts"].values > 0).all()
    # A faster loose mass rattles harder: the peak grows along the axis.
    assert (np.diff(ds["peak"].values[:, 0]) > 0).all()


def test_structure_axes_run_in_lockstep_too(tmp_path: Path) -> None:
    text = BASE + STUDY.replace(
        '"damper.0.clearance" = [0.005, 0.01, 0.02]', '"structure.stiffness" = [0.5, 1.0, 4.0]'
    )
    ds = st.run(load(tmp_path, text), tmp_path / "out.nc")
    assert int(ds["status"].max()) == 0
    for stiffness in (0.5, 4.0):
        sol = vi.simulate(
            vi.ImpactDamper(
                main_mass=M, stiffness=stiffness, damping=C, impact_mass=MD, clearance=D
            ),
            vi.Contact("hertz", stiffness=KHZ, damping=C1),
            vi.InitialState(impact_velocity=0.1),
            method="rk4",
            stepping="fixed",
            dt=DT,
            t_end=T_END,
        )
        point = ds.sel({"initial.damper_velocity.0": 0.1, "structure.stiffness": stiffness})
        assert point["impacts"].item() == len(sol.contacts.onset)
        w = sol.main_displacement
        assert point["rms"].item() == pytest.approx(
            np.sqrt(np.trapezoid(w * w, dx=DT) / T_END), rel=1e-12
        )
